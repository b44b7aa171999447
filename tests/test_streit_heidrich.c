// Streit–Heidrich generator: key barb interpolation (eq. 1), degree elevation,
// defaults Bdf1/Bdf2, clamping, angles, spacing, growth, types, afterfeather,
// texture modes, level of detail, scans, specs and bad input.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model/feather_internal.h"
#include "plume/streit_heidrich.h"
#include "support.h"

#define PI 3.14159265358979323846

static plume_sh_key_barb key(double position, int count, const double (*cvs)[3])
{
	plume_sh_key_barb k = {.position = position, .cv_count = count, .plumulaceous = 0.0};
	for (int i = 0; i < count; ++i)
		k.cvs[i] = plume_v3(cvs[i][0], cvs[i][1], cvs[i][2]);
	return k;
}

static const double straight2[2][3] = {{0, 0, 0}, {1, 0, 0}};
static const double curved4[4][3] = {{0, 0, 0}, {0.3, 0.2, -0.1}, {0.6, 0.25, -0.1}, {0.9, 0.2, 0.1}};
static const double curved5[5][3] = {{0, 0, 0}, {0.2, -0.1, 0.05}, {0.5, 0.1, 0.1}, {0.7, 0.05, 0}, {0.95, 0, 0}};

/// A straight rachis and straight key barbs at both ends: every barb a straight segment of its length.
static plume_sh_def plain_def(void)
{
	plume_sh_def def = plume_sh_default_def();
	def.main.rachis_side_curvature = 0.0;
	def.main.rachis_front_curvature = 0.0;
	def.main.key_barb_count = 2;
	def.main.key_barbs[0] = key(0.0, 2, straight2);
	def.main.key_barbs[1] = key(1.0, 2, straight2);
	def.main.barb_length[0] = def.main.barb_length[1] = (plume_sh_length_profile){.count = 1, .length = {0.02}};
	return def;
}

static plume_feather *generate(const plume_sh_def *def, uint64_t seed, double stage)
{
	plume_feather *feather = NULL;
	plume_error err = {0};
	if (plume_sh_generate(def, seed, stage, &feather, &err) != PLUME_OK)
		fail_msg("generate failed: %s", err.message);
	return feather;
}

// ---------------------------------------------------------------------------
// Interpolation (4.2.1)

static void test_key_barbs_returned_at_their_positions(void **state)
{
	(void)state;
	plume_sh_params p = plume_sh_default_def().main;
	p.key_barb_count = 3;
	p.key_barbs[0] = key(0.2, 4, curved4);
	p.key_barbs[1] = key(0.5, 5, curved5);
	p.key_barbs[2] = key(0.8, 4, curved4);
	p.key_barbs[2].cvs[3] = plume_v3(0.8, -0.3, 0.0);
	for (int j = 0; j < 3; ++j) {
		plume_vec3 cvs[PLUME_SH_MAX_CVS];
		int count = plume_sh_barb_cvs(&p, 1, p.key_barbs[j].position, j, cvs);
		// Where the neighbour has more control vertices the key barb comes back elevated: the same curve.
		for (int s = 0; s <= 20; ++s) {
			double t = s / 20.0;
			plume_vec3 a = plume_bezier_eval(cvs, count, t);
			plume_vec3 b = plume_bezier_eval(p.key_barbs[j].cvs, p.key_barbs[j].cv_count, t);
			assert_close(plume_v3_distance(a, b), 0.0, 1e-12);
		}
	}
	// Halfway between two key barbs of equal degree: the mean of their control vertices (eq. 1, t = 1/2).
	p.key_barbs[1] = key(0.5, 4, curved4);
	p.key_barbs[1].cvs[2] = plume_v3(0.5, -0.2, 0.3);
	plume_vec3 cvs[PLUME_SH_MAX_CVS];
	assert_int_equal(plume_sh_barb_cvs(&p, 1, 0.35, 0, cvs), 4);
	for (int i = 0; i < 4; ++i) {
		plume_vec3 mean = plume_v3_scale(plume_v3_add(p.key_barbs[0].cvs[i], p.key_barbs[1].cvs[i]), 0.5);
		assert_close(plume_v3_distance(cvs[i], mean), 0.0, 1e-15);
	}
}

static void test_degree_elevation_keeps_the_curve(void **state)
{
	(void)state;
	plume_vec3 cvs[PLUME_BEZIER_MAX_POINTS];
	for (int i = 0; i < 4; ++i)
		cvs[i] = plume_v3(curved4[i][0], curved4[i][1], curved4[i][2]);
	plume_vec3 original[4];
	memcpy(original, cvs, sizeof original);
	// 4 -> 40 control vertices, one elevation at a time, in place.
	for (int count = 4; count < 40; ++count)
		plume_bezier_elevate(cvs, count, cvs);
	for (int s = 0; s <= 100; ++s) {
		double t = s / 100.0;
		assert_close(plume_v3_distance(plume_bezier_eval(cvs, 40, t), plume_bezier_eval(original, 4, t)), 0.0, 1e-12);
	}
	// The ends stay exact.
	assert_true(cvs[0].x == original[0].x && cvs[39].y == original[3].y);
}

static void test_default_key_barbs(void **state)
{
	(void)state;
	plume_sh_params p = plume_sh_default_def().main;
	// None at all: Bdf1 everywhere, a different random barb for each barb, the same for the same seed.
	p.key_barb_count = 0;
	plume_vec3 a[PLUME_SH_MAX_CVS], b[PLUME_SH_MAX_CVS], c[PLUME_SH_MAX_CVS];
	assert_int_equal(plume_sh_barb_cvs(&p, 9, 0.4, 3, a), 4);
	plume_sh_barb_cvs(&p, 9, 0.4, 4, b);
	plume_sh_barb_cvs(&p, 9, 0.7, 3, c);
	assert_true(plume_v3_distance(a[3], b[3]) > 1e-3);
	assert_close(plume_v3_distance(a[3], c[3]), 0.0, 1e-15); // one table entry per barb, whatever rp
	// One key barb in the middle: Bdf2 above it (at rp = 1), Bdf1 below it (at rp = 0).
	p.key_barb_count = 1;
	p.key_barbs[0] = key(0.5, 4, curved4);
	plume_sh_barb_cvs(&p, 9, 1.0, 0, a);
	assert_close(a[1].x, 1.0 / 3.0, 1e-15);
	assert_close(a[1].z, -0.06, 1e-15);
	assert_close(a[3].x, 1.0, 1e-15);
	plume_sh_barb_cvs(&p, 9, 0.0, 3, b);
	plume_sh_params none = p;
	none.key_barb_count = 0;
	plume_sh_barb_cvs(&none, 9, 0.0, 3, c);
	for (int i = 0; i < 4; ++i)
		assert_close(plume_v3_distance(b[i], c[i]), 0.0, 0.0);
}

static void test_clamping_and_length_scaling(void **state)
{
	(void)state;
	plume_sh_def def = plain_def();
	// A key barb twice too long is clamped to |cv0 - cvn| = 1: the barb spans exactly its length.
	static const double twice[2][3] = {{0, 0, 0}, {2, 0, 0}};
	def.main.key_barbs[0] = key(0.0, 2, twice);
	def.main.key_barbs[1] = key(1.0, 2, twice);
	plume_feather *feather = generate(&def, 1, 1.0);
	plume_feather_info info = plume_feather_get_info(feather);
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		assert_close(plume_v3_distance(barb.curve.points[0], barb.curve.points[barb.curve.count - 1]), 0.02, 1e-12);
	}
	plume_feather_destroy(feather);
	// A key barb whose ends are 0.5 apart spans half the barb length: the vane discontinuity of 4.2.1.
	static const double half[2][3] = {{0, 0, 0}, {0.5, 0, 0}};
	def.main.key_barbs[1] = key(1.0, 2, half);
	def.main.key_barbs[0] = key(0.0, 2, half);
	feather = generate(&def, 1, 1.0);
	plume_barb barb = plume_feather_barb(feather, 3);
	assert_close(plume_v3_distance(barb.curve.points[0], barb.curve.points[barb.curve.count - 1]), 0.01, 1e-12);
	plume_feather_destroy(feather);
}

/// Angle between a barb's chord and the rachis below its root.
static double barb_angle(const plume_feather *feather, const plume_barb *barb)
{
	plume_vec3 chord = plume_v3_sub(barb->curve.points[barb->curve.count - 1], barb->curve.points[0]);
	(void)feather;
	plume_vec3 down = plume_v3(0.0, -1.0, 0.0); // the plain rachis is straight along +y
	return acos(plume_v3_dot(plume_v3_normalize(chord), down));
}

static void test_barb_angles_follow_base_and_tip(void **state)
{
	(void)state;
	plume_sh_def def = plain_def();
	def.main.barb_angle[0][0] = 100.0 * PI / 180.0;
	def.main.barb_angle[0][1] = 160.0 * PI / 180.0;
	def.main.barb_angle[1][0] = 120.0 * PI / 180.0;
	def.main.barb_angle[1][1] = 150.0 * PI / 180.0;
	plume_feather *feather = generate(&def, 1, 1.0);
	plume_feather_info info = plume_feather_get_info(feather);
	double shaft_length = info.shaft_length, calamus = def.main.calamus_length;
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		double rp = (barb.rachis_t * shaft_length - calamus) / def.main.rachis_length;
		double expected = (1.0 - rp) * def.main.barb_angle[barb.side][0] + rp * def.main.barb_angle[barb.side][1];
		assert_close(barb_angle(feather, &barb), expected, 1e-9);
		// The left vane lies on -x, the right on +x.
		double x = barb.curve.points[barb.curve.count - 1].x;
		assert_true(barb.side == PLUME_SIDE_LEFT ? x < 0.0 : x > 0.0);
	}
	// The angle field's ends are the parameters themselves.
	plume_barb first = plume_feather_barb(feather, 0);
	assert_true(fabs(barb_angle(feather, &first) - def.main.barb_angle[0][0]) < 0.01);
	plume_feather_destroy(feather);
}

static void test_spacing_gives_the_barb_count(void **state)
{
	(void)state;
	plume_sh_def def = plain_def();
	def.main.rachis_length = 0.1;
	def.main.spacing_base = def.main.spacing_tip = 0.001;
	plume_feather *feather = generate(&def, 1, 1.0);
	plume_feather_info info = plume_feather_get_info(feather);
	assert_int_equal(info.barb_count_left, 100);
	assert_int_equal(info.barb_count_right, 100);
	double cl = def.main.calamus_length;
	for (int k = 0; k < 100; ++k) {
		plume_barb barb = plume_feather_barb(feather, k);
		assert_close(barb.curve.points[0].y, cl + (k + 0.5) * 0.001, 1e-12);
	}
	plume_feather_destroy(feather);
	// Spacing from 1 mm to 0.5 mm: the count integrates the density, ln(spt / spb) L / (spt - spb).
	def.main.spacing_tip = 0.0005;
	feather = generate(&def, 1, 1.0);
	info = plume_feather_get_info(feather);
	int expected = (int)floor(log(0.5) * 0.1 / (0.0005 - 0.001) + 0.5);
	assert_int_equal(expected, 139);
	assert_int_equal(info.barb_count_left, expected);
	// Neighbours are as far apart as the spacing halfway between them.
	for (int k = 0; k + 1 < info.barb_count_left; k += 17) {
		double y0 = plume_feather_barb(feather, k).curve.points[0].y - cl;
		double y1 = plume_feather_barb(feather, k + 1).curve.points[0].y - cl;
		double spacing = 0.001 + (0.0005 - 0.001) * 0.5 * (y0 + y1) / 0.1;
		assert_close(y1 - y0, spacing, 1e-3 * spacing);
	}
	plume_feather_destroy(feather);
}

static void test_barbs_sit_at_arc_length_positions(void **state)
{
	(void)state;
	// A strongly curved rachis: barb k's root is (k + 1/2) spacings along the rachis, in arc length.
	plume_sh_def def = plain_def();
	def.main.rachis_side_curvature = 0.3;
	def.main.rachis_front_curvature = -0.2;
	def.main.spacing_base = def.main.spacing_tip = 0.002;
	double cl = def.main.calamus_length, rl = def.main.rachis_length;
	plume_vec3 rachis[4] = {plume_v3(0, cl, 0), plume_v3(0.3 * rl, cl + rl / 3, -0.2 * rl),
	                        plume_v3(0.3 * rl, cl + 2 * rl / 3, -0.2 * rl), plume_v3(0, cl + rl, 0)};
	double length = plume_bezier_length(rachis, 4, 0.0, 1.0);
	plume_feather *feather = generate(&def, 1, 1.0);
	plume_feather_info info = plume_feather_get_info(feather);
	assert_int_equal(info.barb_count_left, (int)floor(length / 0.002 + 0.5));
	for (int k = 0; k < info.barb_count_left; k += 5) {
		plume_vec3 root = plume_feather_barb(feather, k).curve.points[0];
		double u = plume_bezier_closest_param(rachis, 4, root);
		assert_close(plume_v3_distance(plume_bezier_eval(rachis, 4, u), root), 0.0, 1e-12);
		assert_close(plume_bezier_length(rachis, 4, 0.0, u), (k + 0.5) * 0.002, 1e-12);
	}
	plume_feather_destroy(feather);
}

// ---------------------------------------------------------------------------
// Geometry, texture coordinates, level of detail

static void test_shaft_is_continuous(void **state)
{
	(void)state;
	plume_sh_def def = plume_sh_default_def();
	plume_feather *feather = generate(&def, 1, 1.0);
	plume_feather_info info = plume_feather_get_info(feather);
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	int junction = info.calamus_sample_count - 1;
	// The calamus widens from rw to cwr rw towards its base; no step where it meets the rachis.
	assert_close(shaft[junction].width, def.main.rachis_width, 1e-15);
	assert_close(shaft[junction + 1].width, def.main.rachis_width, 0.05 * def.main.rachis_width);
	assert_close(shaft[0].width, def.main.calamus_width_ratio * def.main.rachis_width, 1e-15);
	assert_close(shaft[junction].position.y, def.main.calamus_length, 1e-15);
	assert_close(shaft[info.shaft_sample_count - 1].width, 0.0, 0.0); // the rachis tip is a point
	assert_close(shaft[info.shaft_sample_count - 1].position.y, def.main.calamus_length + def.main.rachis_length,
	             1e-15);
	for (int i = 1; i < info.shaft_sample_count; ++i)
		assert_true(shaft[i].t > shaft[i - 1].t);
	plume_feather_destroy(feather);
}

static void test_level_of_detail(void **state)
{
	(void)state;
	plume_sh_def def = plume_sh_default_def();
	plume_sh_lod low = {.barb_elevations = 0, .rachis_elevations = 0, .calamus_samples = 2};
	plume_feather *coarse = NULL, *fine = NULL;
	plume_error err;
	assert_int_equal(plume_sh_generate_lod(&def, 1, 1.0, &low, &coarse, &err), PLUME_OK);
	assert_int_equal(plume_sh_generate(&def, 1, 1.0, &fine, &err), PLUME_OK);
	plume_feather_info a = plume_feather_get_info(coarse), b = plume_feather_get_info(fine);
	// Figure 8, left: four control vertices per barb and rachis.
	assert_int_equal(a.shaft_sample_count, 2 + 3);
	assert_int_equal(plume_feather_barb(coarse, a.barb_count / 2).curve.count, 4);
	assert_int_equal(plume_feather_barb(fine, b.barb_count / 2).curve.count, 4 + 8);
	assert_int_equal(a.barb_count, b.barb_count);
	// The same barbs: the ends of every polyline coincide at any level of detail.
	for (int i = 0; i < a.barb_count; i += 11) {
		plume_barb p = plume_feather_barb(coarse, i), q = plume_feather_barb(fine, i);
		assert_close(plume_v3_distance(p.curve.points[0], q.curve.points[0]), 0.0, 1e-15);
		assert_close(plume_v3_distance(p.curve.points[p.curve.count - 1], q.curve.points[q.curve.count - 1]), 0.0,
		             1e-15);
	}
	plume_feather_destroy(coarse);
	plume_feather_destroy(fine);
}

static void test_shaft_cylinder(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_sh_def def = plume_sh_default_def();
	plume_feather *feather = generate(&def, 1, 1.0);
	plume_feather_info info = plume_feather_get_info(feather);
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	plume_error err;
	for (int sides = 3; sides <= 12; sides += 9) {
		plume_mesh *mesh = NULL;
		assert_int_equal(plume_sh_shaft_mesh(feather, sides, &mesh, &err), PLUME_OK);
		assert_int_equal(mesh->vertex_count, info.shaft_sample_count * sides);
		assert_int_equal(mesh->face_count, 2 * (info.shaft_sample_count - 1) * sides);
		// Every ring vertex is half the width from its sample, perpendicular to the shaft.
		for (int r = 0; r < info.shaft_sample_count; ++r)
			for (int k = 0; k < sides; ++k) {
				plume_vec3 offset = plume_v3_sub(mesh->rest[r * sides + k], shaft[r].position);
				assert_close(plume_v3_length(offset), 0.5 * shaft[r].width, 1e-15);
				assert_close(plume_v3_dot(offset, shaft[r].tangent), 0.0, 1e-15);
			}
		plume_mesh_destroy(mesh);
	}
	plume_mesh *mesh = NULL;
	assert_int_equal(plume_sh_shaft_mesh(feather, 2, &mesh, &err), PLUME_ERROR_SPEC);
	assert_null(mesh);
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_texture_modes(void **state)
{
	(void)state;
	plume_sh_def def = plume_sh_default_def();
	for (int mode = 0; mode < 3; ++mode) {
		def.texture_mode = (plume_sh_texture_mode)mode;
		plume_feather *feather = generate(&def, 1, 1.0);
		plume_feather_info info = plume_feather_get_info(feather);
		double lowest_tip_t = 1.0;
		for (int i = 0; i < info.barb_count; ++i) {
			plume_barb barb = plume_feather_barb(feather, i);
			for (int k = 0; k < barb.curve.count; ++k) {
				assert_true(barb.curve.uv[k].x >= 0.0 && barb.curve.uv[k].x <= 1.0);
				assert_true(barb.curve.uv[k].y >= 0.0 && barb.curve.uv[k].y <= 1.0);
			}
			if (mode == PLUME_SH_TEXTURE_BARB) {
				assert_close(barb.curve.uv[barb.curve.count - 1].y, barb.rachis_t, 0.0);
				assert_close(barb.curve.uv[barb.curve.count - 1].x, 1.0, 1e-15);
			}
			if (mode == PLUME_SH_TEXTURE_VANE) // at the rachis, s = 0
				assert_close(barb.curve.uv[0].x, 0.0, 1e-12);
			if (mode == PLUME_SH_TEXTURE_GROWTH) {
				// Along a barb, t falls: its tip left the collar first.
				assert_true(barb.curve.uv[barb.curve.count - 1].y < barb.curve.uv[0].y);
				lowest_tip_t = fmin(lowest_tip_t, barb.curve.uv[barb.curve.count - 1].y);
			}
		}
		if (mode == PLUME_SH_TEXTURE_GROWTH)
			assert_close(lowest_tip_t, 0.0, 1e-12);
		plume_feather_destroy(feather);
	}
}

// ---------------------------------------------------------------------------
// Growth (4.2.4, Figure 6)

static void test_growth_schedule(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_sh_def def = plume_sh_default_def();
	plume_feather *full = generate(&def, 4, 1.0);
	plume_feather_info full_info = plume_feather_get_info(full);

	// 15%: half the shaft, no barbs yet.
	plume_feather *early = generate(&def, 4, 0.15);
	plume_feather_info info = plume_feather_get_info(early);
	assert_int_equal(info.barb_count, 0);
	const plume_shaft_sample *shaft = plume_feather_shaft(early);
	assert_close(shaft[info.shaft_sample_count - 1].position.y,
	             0.5 * (def.main.calamus_length + def.main.rachis_length), 1e-15);
	assert_close(shaft[0].width, 0.5 * def.main.calamus_width_ratio * def.main.rachis_width, 1e-15);
	plume_feather_destroy(early);

	// 40%: barbs at half length, straight and closed along the rachis near the base and tip.
	plume_feather *middle = generate(&def, 4, 0.4);
	info = plume_feather_get_info(middle);
	assert_int_equal(info.barb_count, full_info.barb_count);
	plume_barb barb = plume_feather_barb(middle, 0);
	assert_close(barb_angle(middle, &barb), PI, 0.05); // near the base: 180 degrees
	double rp = barb.rachis_t * info.shaft_length - def.main.calamus_length;
	rp /= def.main.rachis_length;
	double length = plume_v3_distance(barb.curve.points[0], barb.curve.points[barb.curve.count - 1]);
	double full_length = 0.0;
	for (int i = 0; i < def.main.barb_length[0].count - 1; ++i)
		if (rp >= def.main.barb_length[0].position[i] && rp <= def.main.barb_length[0].position[i + 1]) {
			double f = (rp - def.main.barb_length[0].position[i]) /
			           (def.main.barb_length[0].position[i + 1] - def.main.barb_length[0].position[i]);
			full_length = (1 - f) * def.main.barb_length[0].length[i] + f * def.main.barb_length[0].length[i + 1];
		}
	assert_close(length, 0.5 * full_length, 1e-12); // straight: the chord is the whole length
	plume_feather_destroy(middle);

	// 100% is the finished feather, and the last stages approach it continuously.
	plume_feather *grown = generate(&def, 4, 1.0);
	assert_true(plume_feather_equal(grown, full));
	plume_feather *almost = generate(&def, 4, 1.0 - 1e-9);
	info = plume_feather_get_info(almost);
	assert_int_equal(info.point_count, full_info.point_count);
	for (int i = 0; i < info.barb_count; i += 7) {
		plume_barb p = plume_feather_barb(almost, i), q = plume_feather_barb(full, i);
		for (int k = 0; k < p.curve.count; ++k)
			assert_close(plume_v3_distance(p.curve.points[k], q.curve.points[k]), 0.0, 1e-9);
	}
	plume_feather_destroy(almost);
	plume_feather_destroy(grown);
	plume_feather_destroy(full);
	assert_int_equal(plume_bytes_in_use(), before);
}

// ---------------------------------------------------------------------------
// Types (4.2.3) and afterfeathers

static void assert_feathers_close(const plume_feather *a, const plume_feather *b, double tolerance)
{
	plume_feather_info p = plume_feather_get_info(a), q = plume_feather_get_info(b);
	assert_int_equal(p.barb_count, q.barb_count);
	assert_int_equal(p.shaft_sample_count, q.shaft_sample_count);
	for (int i = 0; i < p.shaft_sample_count; ++i)
		assert_close(plume_v3_distance(plume_feather_shaft(a)[i].position, plume_feather_shaft(b)[i].position), 0.0,
		             tolerance);
	for (int i = 0; i < p.barb_count; ++i) {
		plume_barb x = plume_feather_barb(a, i), y = plume_feather_barb(b, i);
		assert_int_equal(x.curve.count, y.curve.count);
		for (int k = 0; k < x.curve.count; ++k)
			assert_close(plume_v3_distance(x.curve.points[k], y.curve.points[k]), 0.0, tolerance);
	}
}

static plume_sh_def read_preset(const char *name)
{
	char path[512];
	snprintf(path, sizeof path, "%s/examples/streit-heidrich/%s.json", PLUME_SOURCE_DIR, name);
	plume_sh_def def;
	uint64_t seed;
	plume_error err;
	if (plume_sh_def_read(path, &def, &seed, NULL, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	return def;
}

static void test_type_interpolation_ends(void **state)
{
	(void)state;
	// Down has no key barbs (Bdf1 only), contour two: down is inflated to contour's count.
	plume_sh_def down = read_preset("down"), contour = read_preset("contour");
	plume_sh_def blended;
	plume_error err;
	plume_feather *a = generate(&down, 3, 1.0), *b = generate(&contour, 3, 1.0);
	for (int end = 0; end <= 1; ++end) {
		assert_int_equal(plume_sh_def_interpolate(&down, &contour, end, &blended, &err), PLUME_OK);
		plume_feather *f = generate(&blended, 3, 1.0);
		assert_feathers_close(f, end == 0 ? a : b, 1e-12);
		plume_feather_destroy(f);
	}
	// Halfway: every scalar parameter is the mean.
	assert_int_equal(plume_sh_def_interpolate(&down, &contour, 0.5, &blended, &err), PLUME_OK);
	assert_close(blended.main.rachis_length, 0.5 * (down.main.rachis_length + contour.main.rachis_length), 1e-15);
	assert_close(blended.main.barb_angle[1][0], 0.5 * (down.main.barb_angle[1][0] + contour.main.barb_angle[1][0]),
	             1e-15);
	plume_feather_destroy(a);
	plume_feather_destroy(b);
	// Bad weights are refused.
	assert_int_equal(plume_sh_def_interpolate(&down, &contour, 1.5, &blended, &err), PLUME_ERROR_SPEC);
}

static void test_inflation_keeps_the_feather(void **state)
{
	(void)state;
	// Blending a feather with itself inflated (three extra key barbs) gives the feather back.
	plume_sh_def peacock = read_preset("peacock"), filoplume = read_preset("filoplume");
	plume_sh_def blended;
	plume_error err;
	const plume_sh_def *defs[2] = {&filoplume, &peacock};
	double weights[2] = {1.0, 0.0};
	assert_int_equal(plume_sh_def_blend(defs, weights, 2, &blended, &err), PLUME_OK);
	assert_true(blended.main.key_barb_count >= peacock.main.key_barb_count);
	plume_feather *a = generate(&filoplume, 2, 1.0), *b = generate(&blended, 2, 1.0);
	assert_feathers_close(a, b, 1e-12);
	plume_feather_destroy(a);
	plume_feather_destroy(b);
}

static void test_afterfeather_attaches_at_the_calamus(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_sh_def def = read_preset("semiplume");
	assert_true(def.has_afterfeather);
	plume_feather *feather = generate(&def, 5, 1.0);
	plume_feather_info info = plume_feather_get_info(feather);
	assert_true(info.has_afterfeather);
	const plume_feather *after = plume_feather_afterfeather(feather);
	const plume_shaft_sample *junction = &plume_feather_shaft(feather)[info.calamus_sample_count - 1];
	assert_close(plume_feather_afterfeather_t(feather), junction->t, 0.0);
	assert_close(junction->position.y, def.main.calamus_length, 1e-15);
	// Its base sits on the back of the shaft at the junction.
	plume_vec3 root = plume_feather_shaft(after)[0].position;
	assert_close(plume_v3_distance(root, junction->position), 0.5 * junction->width, 1e-15);
	assert_true(root.z < junction->position.z);
	plume_feather_info after_info = plume_feather_get_info(after);
	assert_true(after_info.barb_count > 0);
	assert_close(after_info.shaft_length, def.afterfeather.rachis_length, 0.01 * def.afterfeather.rachis_length);
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_determinism(void **state)
{
	(void)state;
	plume_sh_def def = read_preset("down");
	plume_feather *a = generate(&def, 11, 1.0), *b = generate(&def, 11, 1.0), *c = generate(&def, 12, 1.0);
	assert_true(plume_feather_equal(a, b));
	assert_false(plume_feather_equal(a, c));
	plume_feather_destroy(a);
	plume_feather_destroy(b);
	plume_feather_destroy(c);
}

// ---------------------------------------------------------------------------
// Scans (4.2.2)

/// Where the 2D renderer puts feather point (x, y): its fit of the bounds into the image.
static void project(plume_feather_info info, const plume_render2d_def *def, double x, double y, double out[2])
{
	double margin = def->margin * (def->width < def->height ? def->width : def->height);
	double sx = (def->width - 2 * margin) / (info.bounds_max.x - info.bounds_min.x);
	double sy = (def->height - 2 * margin) / (info.bounds_max.y - info.bounds_min.y);
	double scale = fmin(sx, sy);
	out[0] = 0.5 * def->width + scale * (x - 0.5 * (info.bounds_min.x + info.bounds_max.x));
	out[1] = 0.5 * def->height - scale * (y - 0.5 * (info.bounds_min.y + info.bounds_max.y));
}

static void test_scan_round_trip(void **state)
{
	(void)state;
	// A silhouette plume renders itself: dense straight barbs with known lengths, in solid black.
	plume_sh_def def = plain_def();
	def.main.rachis_length = 0.1;
	def.main.calamus_length = 0.0;
	def.main.spacing_base = def.main.spacing_tip = 0.0002;
	static const double pos[] = {0.0, 0.3, 0.6, 1.0};
	static const double left[] = {0.01, 0.03, 0.025, 0.008};
	static const double right[] = {0.015, 0.02, 0.035, 0.01};
	for (int i = 0; i < 4; ++i) {
		def.main.barb_length[0].position[i] = def.main.barb_length[1].position[i] = pos[i];
		def.main.barb_length[0].length[i] = left[i];
		def.main.barb_length[1].length[i] = right[i];
	}
	def.main.barb_length[0].count = def.main.barb_length[1].count = 4;
	def.main.barb_angle[0][0] = def.main.barb_angle[1][0] = 110.0 * PI / 180.0;
	def.main.barb_angle[0][1] = def.main.barb_angle[1][1] = 140.0 * PI / 180.0;
	def.barb_width_base = def.barb_width_tip = 3e-4;
	plume_feather *feather = generate(&def, 1, 1.0);
	char dir[256], image[300];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(image, sizeof image, "%s/scan.png", dir);
	plume_render2d_def render = plume_render2d_default_def();
	render.width = 900;
	render.height = 1000;
	render.barb_color = render.shaft_color = (plume_color){0, 0, 0, 1};
	plume_error err;
	assert_int_equal(plume_render2d(feather, &render, PLUME_IMAGE_PNG, image, &err), PLUME_OK);
	plume_feather_info info = plume_feather_get_info(feather);

	plume_sh_scan_def scan = plume_sh_default_scan_def();
	project(info, &render, 0.0, 0.0, scan.base_px);
	project(info, &render, 0.0, 0.1, scan.tip_px);
	plume_sh_params measured = def.main;
	assert_int_equal(plume_sh_scan_barb_lengths(image, &scan, &measured, &err), PLUME_OK);
	double worst = 0.0;
	for (int side = 0; side < 2; ++side)
		for (int j = 0; j < measured.barb_length[side].count; ++j) {
			double rp = measured.barb_length[side].position[j];
			if (rp < 0.05 || rp > 0.95) // no barb sits at the very ends
				continue;
			double truth = 0.0;
			for (int i = 0; i < 3; ++i)
				if (rp >= pos[i] && rp <= pos[i + 1]) {
					double f = (rp - pos[i]) / (pos[i + 1] - pos[i]);
					truth =
					    (1 - f) * def.main.barb_length[side].length[i] + f * def.main.barb_length[side].length[i + 1];
				}
			double error = fabs(measured.barb_length[side].length[j] - truth) / truth;
			worst = fmax(worst, error);
		}
	printf("scan round trip: worst relative barb length error %.4f\n", worst);
	assert_true(worst < 0.02);

	// An empty scan (all background) and an unreadable one are errors.
	char blank[300];
	snprintf(blank, sizeof blank, "%s/blank.png", dir);
	plume_feather *tiny = generate(&def, 1, 0.0); // shaft only
	render.barb_color = render.shaft_color = (plume_color){1, 1, 1, 1};
	assert_int_equal(plume_render2d(tiny, &render, PLUME_IMAGE_PNG, blank, &err), PLUME_OK);
	assert_int_equal(plume_sh_scan_barb_lengths(blank, &scan, &measured, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "empty"));
	char junk[300];
	snprintf(junk, sizeof junk, "%s/junk.png", dir);
	test_write_file(junk, "not a png");
	assert_int_equal(plume_sh_scan_barb_lengths(junk, &scan, &measured, &err), PLUME_ERROR_SYNTAX);
	assert_int_equal(plume_sh_scan_barb_lengths("/nonexistent/scan.png", &scan, &measured, &err), PLUME_ERROR_IO);
	plume_feather_destroy(tiny);
	plume_feather_destroy(feather);
	test_remove_tree(dir);
}

// ---------------------------------------------------------------------------
// Specs and bad input (item 10)

static const char *const preset_names[] = {"down",      "semiplume", "contour", "flight",
                                           "filoplume", "bristle",   "peacock", "continuum"};
enum { PRESET_COUNT = sizeof preset_names / sizeof preset_names[0] };

static void test_presets_generate(void **state)
{
	(void)state;
	const char *const *names = preset_names;
	for (size_t i = 0; i < PRESET_COUNT; ++i) {
		char path[512];
		snprintf(path, sizeof path, "%s/examples/streit-heidrich/%s.json", PLUME_SOURCE_DIR, names[i]);
		plume_feather *feather = NULL;
		plume_error err;
		plume_spec_options options = {0};
		if (plume_spec_generate(path, &options, &feather, &err) != PLUME_OK)
			fail_msg("%s: %s", names[i], err.message);
		assert_true(plume_feather_get_info(feather).barb_count > 0);
		plume_feather_destroy(feather);
		// Growth stages through the spec dispatch; unfurling is another model's.
		options.stage_kind = PLUME_STAGE_GROWTH;
		options.stage = 0.5;
		assert_int_equal(plume_spec_generate(path, &options, &feather, &err), PLUME_OK);
		plume_feather_destroy(feather);
		options.stage_kind = PLUME_STAGE_UNFURL;
		assert_int_equal(plume_spec_generate(path, &options, &feather, &err), PLUME_ERROR_UNSUPPORTED);
		assert_null(feather);
	}
}

/// plume_sh_estimate_bytes is counted before the work: it must cover the feather built, at full growth and
/// half-way, for every preset, and stay within 5 times it (bristle's
/// silhouette is zero above 20% of the rachis, and a barb without length is dropped).
static void test_estimate_covers_presets(void **state)
{
	(void)state;
	const char *const *names = preset_names;
	for (size_t i = 0; i < PRESET_COUNT; ++i) {
		char path[512];
		snprintf(path, sizeof path, "%s/examples/streit-heidrich/%s.json", PLUME_SOURCE_DIR, names[i]);
		plume_sh_def *def = test_malloc(sizeof *def);
		uint64_t seed;
		plume_sh_lod lod;
		plume_error err;
		if (plume_sh_def_read(path, def, &seed, &lod, &err) != PLUME_OK)
			fail_msg("%s", err.message);
		double estimate = plume_sh_estimate_bytes(def, &lod);
		for (int stage = 1; stage <= 2; ++stage) {
			plume_feather *feather = NULL;
			assert_int_equal(plume_sh_generate_lod(def, seed, stage / 2.0, &lod, &feather, &err), PLUME_OK);
			double bytes = plume_feather_bytes(feather);
			print_message("%s stage %.1f: estimate %.0f bytes, feather %.0f bytes\n", names[i], stage / 2.0, estimate,
			              bytes);
			assert_true(bytes <= estimate);
			if (stage == 2)
				assert_true(estimate <= 5.0 * bytes);
			plume_feather_destroy(feather);
		}
		test_free(def);
	}
}

/// The densest feather the keys allow (PLUME_SH_MAX_BARBS barbs of 32 control vertices elevated 60 times,
/// with an afterfeather) is estimated past 16 MB and refused with PLUME_ERROR_LIMIT before the work.
static void test_estimate_refuses_dense(void **state)
{
	(void)state;
	const char *json = "{\"model\": \"streit-heidrich\", \"spacing_base\": 1e-6, \"spacing_tip\": 1e-6,"
	                   " \"rachis_length\": 0.5, \"lod\": {\"barb_elevations\": 60},"
	                   " \"key_barbs\": [{\"position\": 0.5, \"cvs\": [[0,0,0],[0.1,0,0],[0.2,0,0],[0.3,0,0],"
	                   "[0.4,0,0],[0.5,0,0],[0.6,0,0],[0.7,0,0],[0.8,0,0],[0.9,0,0],[1,0,0]]}]}";
	plume_spec_options options = {.max_memory = 16u << 20};
	plume_feather *feather = NULL;
	plume_error err;
	assert_int_equal(plume_spec_parse(json, "dense.json", &options, &feather, &err), PLUME_ERROR_LIMIT);
	assert_null(feather);
	print_message("%s\n", err.message);
	assert_non_null(strstr(err.message, "dense.json: $.rachis_length / $.spacing_base"));
	assert_non_null(strstr(err.message, "the limit is 0.0168 GB (raise it with --max-memory"));
}

static void expect_spec_error(const char *json, plume_status status, const char *fragment)
{
	char dir[256], path[300];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/bad.json", dir);
	test_write_file(path, json);
	plume_feather *feather = NULL;
	plume_error err = {0};
	plume_spec_options options = {0};
	assert_int_equal(plume_spec_generate(path, &options, &feather, &err), status);
	assert_null(feather);
	if (strstr(err.message, fragment) == NULL || strstr(err.message, "bad.json") == NULL)
		fail_msg("message '%s' lacks '%s' or the file name", err.message, fragment);
	test_remove_tree(dir);
}

static void test_bad_specs(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	expect_spec_error(
	    "{\"model\": \"streit-heidrich\", \"key_barbs\": [{\"position\": 0.6, \"cvs\": [[0,0,0],[1,0,0]]},"
	    " {\"position\": 0.2, \"cvs\": [[0,0,0],[1,0,0]]}]}",
	    PLUME_ERROR_SPEC, "$.key_barbs[1].position is 0.2, below the key barb before it");
	expect_spec_error(
	    "{\"model\": \"streit-heidrich\", \"key_barbs\": [{\"position\": 1.2, \"cvs\": [[0,0,0],[1,0,0]]}]}",
	    PLUME_ERROR_SPEC, "$.key_barbs[0].position is 1.2, allowed [0, 1]");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"key_barbs\": [{\"position\": 0.5, \"cvs\": [[0,0,0]]}]}",
	                  PLUME_ERROR_SPEC, "$.key_barbs[0].cvs: a key barb needs 2 to 32 control vertices");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"rachis_length\": 0}", PLUME_ERROR_SPEC,
	                  "$.rachis_length is 0, must be a positive length");
	// A 1500 km rachis (fuzz/corpus/feather_spec/sh-rachis-1500-km.json): a barb count past int's range,
	// refused before any conversion, with the rachis named.
	expect_spec_error("{\"model\": \"streit-heidrich\", \"rachis_length\": 1500002}", PLUME_ERROR_SPEC,
	                  "puts more than 4000 barbs on a vane along a rachis of arc length 1.50561e+06 m (rachis_length "
	                  "1.5e+06 m)");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"calamus_length\": -0.01}", PLUME_ERROR_SPEC,
	                  "$.calamus_length is -0.01, must be a non-negative length");
	// A constant is a number, not an array: no index (it read "$.barb_length[0]").
	expect_spec_error("{\"model\": \"streit-heidrich\", \"barb_length\": -0.01}", PLUME_ERROR_SPEC,
	                  "$.barb_length has length -0.01");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"barb_length\": [[0, 0.01], [1, -0.01]]}", PLUME_ERROR_SPEC,
	                  "$.barb_length[1] has length -0.01");
	// The range is open at 0 (it read "is 0, allowed [0, 100]").
	expect_spec_error("{\"model\": \"streit-heidrich\", \"calamus_width_ratio\": 0}", PLUME_ERROR_SPEC,
	                  "$.calamus_width_ratio is 0, allowed (0, 100]");
	// The key the spec gave, not the per-vane one it sets (it read "$.left_base_angle_deg is 200").
	expect_spec_error("{\"model\": \"streit-heidrich\", \"base_angle_deg\": 200}", PLUME_ERROR_SPEC,
	                  "$.base_angle_deg is 200, allowed (0, 180]");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"afterfeather\": {\"tip_angle_deg\": 180.0001}}",
	                  PLUME_ERROR_SPEC, "$.afterfeather.tip_angle_deg is 180.0001, allowed (0, 180]");
	// Keys of the whole feather in the afterfeather: said so, not "did you mean tip_angle_deg?".
	expect_spec_error("{\"model\": \"streit-heidrich\", \"afterfeather\": {\"texture_mode\": \"vane\"}}",
	                  PLUME_ERROR_SPEC,
	                  "$.afterfeather.texture_mode: is a key of the whole feather, not of its afterfeather: give it "
	                  "at the spec's top level ($.texture_mode)");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"afterfeather\": {\"model\": \"streit-heidrich\"}}",
	                  PLUME_ERROR_SPEC, "$.afterfeather.model: is a key of the whole feather");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"afterfeather\": {\"colour\": 1}}", PLUME_ERROR_SPEC,
	                  "$.afterfeather.colour: unknown key; the keys here are: calamus_length, ");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"spacing_tip\": -1}", PLUME_ERROR_SPEC, "$.spacing_tip is -1");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"afterfeather\": {\"rachis_length\": -2}}", PLUME_ERROR_SPEC,
	                  "$.afterfeather.rachis_length is -2");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"rachis_lenght\": 0.1}", PLUME_ERROR_SPEC,
	                  "did you mean \"rachis_length\"");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"tip_angle_deg\": 200}", PLUME_ERROR_SPEC,
	                  "tip_angle_deg is 200, allowed (0, 180]");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"texture_mode\": \"vain\"}", PLUME_ERROR_SPEC,
	                  "did you mean \"vane\"");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"barb_length_scan\": {\"image\": \"missing.png\", "
	                  "\"base_px\": [10, 100], \"tip_px\": [10, 10]}}",
	                  PLUME_ERROR_IO, "missing.png: cannot read");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"blend\": {\"feathers\": [\"bad.json\", \"bad.json\"], \"t\": "
	                  "0.5}}",
	                  PLUME_ERROR_SPEC, "nest more than");
	// Inline specs in a blend are part of the file: messages name where they sit in it (they named
	// the root: "bad.json: $.rachis_length is -1").
	expect_spec_error("{\"model\": \"streit-heidrich\", \"blend\": {\"feathers\": [{\"model\": \"streit-heidrich\", "
	                  "\"rachis_length\": -1}, {}], \"t\": 0.5}}",
	                  PLUME_ERROR_SPEC, "bad.json: $.blend.feathers[0].rachis_length is -1, must be a positive length");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"blend\": {\"feathers\": [{}, {\"rachis_lenght\": 0.1}], "
	                  "\"t\": 0.5}}",
	                  PLUME_ERROR_SPEC, "bad.json: $.blend.feathers[1].rachis_lenght: unknown key");
	expect_spec_error(
	    "{\"model\": \"streit-heidrich\", \"blend\": {\"feathers\": [{\"afterfeather\": {\"spacing_tip\": "
	    "-1}}, {}], \"t\": 0.5}}",
	    PLUME_ERROR_SPEC, "bad.json: $.blend.feathers[0].afterfeather.spacing_tip is -1");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"blend\": {\"feathers\": [{\"blend\": {\"feathers\": [{}, "
	                  "{\"spacing_base\": 0}], \"t\": 0.5}}, {}], \"t\": 0.5}}",
	                  PLUME_ERROR_SPEC, "bad.json: $.blend.feathers[0].blend.feathers[1].spacing_base is 0");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"blend\": {\"feathers\": [{}, {\"blend\": {\"t\": 2, "
	                  "\"feathers\": [{}, {}]}}], \"t\": 0.5}}",
	                  PLUME_ERROR_SPEC, "bad.json: $.blend.feathers[1].blend.t: is 2, allowed [0, 1]");
	expect_spec_error("{\"model\": \"streit-heidrich\", \"blend\": {\"feathers\": [{\"model\": \"zhang-kanai\"}, {}], "
	                  "\"t\": 0.5}}",
	                  PLUME_ERROR_SPEC, "bad.json: $.blend.feathers[0].model: \"zhang-kanai\" cannot be blended");
	assert_int_equal(plume_bytes_in_use(), before);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_key_barbs_returned_at_their_positions),
	    cmocka_unit_test(test_degree_elevation_keeps_the_curve),
	    cmocka_unit_test(test_default_key_barbs),
	    cmocka_unit_test(test_clamping_and_length_scaling),
	    cmocka_unit_test(test_barb_angles_follow_base_and_tip),
	    cmocka_unit_test(test_spacing_gives_the_barb_count),
	    cmocka_unit_test(test_barbs_sit_at_arc_length_positions),
	    cmocka_unit_test(test_shaft_is_continuous),
	    cmocka_unit_test(test_level_of_detail),
	    cmocka_unit_test(test_shaft_cylinder),
	    cmocka_unit_test(test_texture_modes),
	    cmocka_unit_test(test_growth_schedule),
	    cmocka_unit_test(test_type_interpolation_ends),
	    cmocka_unit_test(test_inflation_keeps_the_feather),
	    cmocka_unit_test(test_afterfeather_attaches_at_the_calamus),
	    cmocka_unit_test(test_determinism),
	    cmocka_unit_test(test_scan_round_trip),
	    cmocka_unit_test(test_presets_generate),
	    cmocka_unit_test(test_estimate_covers_presets),
	    cmocka_unit_test(test_estimate_refuses_dense),
	    cmocka_unit_test(test_bad_specs),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

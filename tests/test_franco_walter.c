// Franco–Walter generator: counts, attachment, outlines, symmetry, uniformity,
// determinism, validation and memory.
#include <math.h>
#include <string.h>

#include "support.h"

static plume_vec3 lift(plume_vec2 p) { return plume_v3(p.x, p.y, 0.0); }

/// A straight vertical shaft with mirror-image outlines: the geometry in which
/// S_v must give an exact mirror image across x = 0.
static plume_fw_def symmetric_def(void)
{
	plume_fw_def def = plume_fw_default_def();
	def.shaft[0] = (plume_vec2){0.0, 0.0};
	def.shaft[1] = (plume_vec2){0.0, 0.04};
	def.shaft[2] = (plume_vec2){0.0, 0.08};
	def.shaft[3] = (plume_vec2){0.0, 0.12};
	plume_vec2 outline[5] = {{-0.002, 0.03}, {-0.02, 0.04}, {-0.03, 0.09}, {-0.015, 0.13}, {0.0, 0.125}};
	memcpy(def.left_outline, outline, sizeof outline);
	def.mirror_right_outline = true;
	def.segments[0] = (plume_fw_segment){30, 0.2, 0.5, true, false, false};
	def.segments[1] = (plume_fw_segment){120, 0.05, 0.3, true, true, false};
	return def;
}

static plume_feather *generate(const plume_fw_def *def, uint64_t seed)
{
	plume_feather *feather = NULL;
	plume_error err = {0};
	plume_status status = plume_fw_generate(def, seed, &feather, &err);
	if (status != PLUME_OK)
		fail_msg("generate failed: %s", err.message);
	return feather;
}

static void test_barb_counts_per_segment(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_fw_def def = symmetric_def();
	def.segments[0].barb_count = 17;
	def.segments[1].barb_count = 203;
	def.segments[0].symmetric_vanes = false;
	plume_feather *feather = generate(&def, 5);
	plume_feather_info info = plume_feather_get_info(feather);
	assert_int_equal(info.barb_count_left, 220);
	assert_int_equal(info.barb_count_right, 220);
	int counts[2][2] = {{0, 0}, {0, 0}};
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		counts[barb.side][barb.segment]++;
		assert_int_equal(barb.curve.count, def.barb_samples);
	}
	assert_int_equal(counts[PLUME_SIDE_LEFT][0], 17);
	assert_int_equal(counts[PLUME_SIDE_LEFT][1], 203);
	assert_int_equal(counts[PLUME_SIDE_RIGHT][0], 17);
	assert_int_equal(counts[PLUME_SIDE_RIGHT][1], 203);
	assert_int_equal(info.shaft_sample_count, def.shaft_samples);
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_segment_boundary_follows_is(void **state)
{
	(void)state;
	plume_fw_def def = symmetric_def();
	def.second_segment_start = 0.85; // the filoplume's split
	plume_feather *feather = generate(&def, 5);
	plume_feather_info info = plume_feather_get_info(feather);
	double boundary = def.calamus_fraction + (1.0 - def.calamus_fraction) * def.second_segment_start;
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		if (barb.segment == 0)
			assert_true(barb.rachis_t < boundary);
		else
			assert_true(barb.rachis_t > boundary);
		assert_true(barb.rachis_t > def.calamus_fraction && barb.rachis_t < 1.0);
	}
	plume_feather_destroy(feather);
}

static void test_every_barb_starts_on_the_rachis(void **state)
{
	(void)state;
	plume_fw_def def = plume_fw_default_def(); // curved shaft
	def.segments[0].barb_count = 50;
	def.segments[1].barb_count = 300;
	plume_feather *feather = generate(&def, 11);
	plume_vec3 shaft[4];
	for (int i = 0; i < 4; ++i)
		shaft[i] = lift(def.shaft[i]);
	plume_feather_info info = plume_feather_get_info(feather);
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		plume_vec3 root = barb.curve.points[0];
		double t = plume_bezier_closest_param(shaft, 4, root);
		assert_true(plume_v3_distance(plume_bezier_eval(shaft, 4, t), root) < 1e-12);
		// rachis_t is the root's arc-length fraction along the shaft.
		assert_close(plume_bezier_length(shaft, 4, 0.0, t) / plume_bezier_length(shaft, 4, 0.0, 1.0), barb.rachis_t,
		             1e-9);
	}
	plume_feather_destroy(feather);
}

static void test_unperturbed_barbs_end_on_their_outline(void **state)
{
	(void)state;
	plume_fw_def def = plume_fw_default_def();
	for (int s = 0; s < 2; ++s) {
		def.segments[s].length_variation = 0.0;
		def.segments[s].shape_variation = 0.0;
		def.segments[s].barb_count = 150;
	}
	plume_feather *feather = generate(&def, 3);
	plume_vec3 outline[2][5];
	for (int i = 0; i < 5; ++i) {
		outline[PLUME_SIDE_LEFT][i] = lift(def.left_outline[i]);
		outline[PLUME_SIDE_RIGHT][i] = lift(def.right_outline[i]);
	}
	plume_feather_info info = plume_feather_get_info(feather);
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		plume_vec3 tip = barb.curve.points[barb.curve.count - 1];
		const plume_vec3 *edge = outline[barb.side];
		double t = plume_bezier_closest_param(edge, 5, tip);
		assert_true(plume_v3_distance(plume_bezier_eval(edge, 5, t), tip) < 1e-9);
		// F_b = 0 leaves P1 = P0 and P2 = P3: a straight barb.
		plume_vec3 root = barb.curve.points[0];
		plume_vec3 axis = plume_v3_normalize(plume_v3_sub(tip, root));
		for (int k = 0; k < barb.curve.count; ++k) {
			plume_vec3 offset = plume_v3_sub(barb.curve.points[k], root);
			plume_vec3 off_axis = plume_v3_mad(offset, -plume_v3_dot(offset, axis), axis);
			assert_true(plume_v3_length(off_axis) < 1e-12);
		}
	}
	plume_feather_destroy(feather);
}

/// A straight barb's length over the distance from its root to its unscaled tip
/// on the outline: the factor 1 + r that F_pv drew.
static double length_ratio(const plume_barb *barb, const plume_fw_def *def, const plume_vec3 *outline)
{
	plume_vec3 root = barb->curve.points[0], tip = barb->curve.points[barb->curve.count - 1];
	double q = (barb->rachis_t - def->calamus_fraction) / (1.0 - def->calamus_fraction);
	plume_vec3 edge = plume_bezier_eval(outline, 5, plume_bezier_param_at_length(outline, 5, q));
	return plume_v3_distance(root, tip) / plume_v3_distance(root, edge);
}

static void test_length_variation_stays_in_range(void **state)
{
	(void)state;
	plume_fw_def def = symmetric_def();
	def.segments[1].length_variation = 0.3;
	def.segments[1].shape_variation = 0.0;
	def.segments[1].uniform_length = false;
	def.segments[0].barb_count = 0;
	def.second_segment_start = 0.0;
	plume_feather *feather = generate(&def, 8);
	plume_vec3 outline[5];
	for (int i = 0; i < 5; ++i)
		outline[i] = lift(def.left_outline[i]);
	plume_feather_info info = plume_feather_get_info(feather);
	double lo = INFINITY, hi = -INFINITY;
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		if (barb.side != PLUME_SIDE_LEFT)
			continue;
		double ratio = length_ratio(&barb, &def, outline);
		lo = fmin(lo, ratio);
		hi = fmax(hi, ratio);
	}
	assert_true(lo >= 0.7 - 1e-12 && hi <= 1.3 + 1e-12);
	assert_true(hi - lo > 0.4); // 120 draws cover most of [0.7, 1.3]
	plume_feather_destroy(feather);

	def.segments[1].uniform_length = true; // U_c: one value for the segment
	feather = generate(&def, 8);
	double first = -1.0;
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		if (barb.side != PLUME_SIDE_LEFT)
			continue;
		double ratio = length_ratio(&barb, &def, outline);
		if (first < 0.0)
			first = ratio;
		assert_close(ratio, first, 1e-9);
	}
	plume_feather_destroy(feather);
}

static void test_symmetric_vanes_mirror(void **state)
{
	(void)state;
	plume_fw_def def = symmetric_def();
	plume_feather *feather = generate(&def, 21);
	plume_feather_info info = plume_feather_get_info(feather);
	int per_vane = info.barb_count_left;
	for (int i = 0; i < per_vane; ++i) {
		plume_barb left = plume_feather_barb(feather, i), right = plume_feather_barb(feather, per_vane + i);
		assert_int_equal(left.side, PLUME_SIDE_LEFT);
		assert_int_equal(right.side, PLUME_SIDE_RIGHT);
		for (int k = 0; k < left.curve.count; ++k) {
			plume_vec3 a = left.curve.points[k], b = right.curve.points[k];
			assert_close(a.x, -b.x, 1e-12);
			assert_close(a.y, b.y, 1e-12);
		}
	}
	plume_feather_destroy(feather);

	// Without S_v the vanes differ.
	def.segments[0].symmetric_vanes = def.segments[1].symmetric_vanes = false;
	feather = generate(&def, 21);
	double largest = 0.0;
	for (int i = 0; i < per_vane; ++i) {
		plume_barb left = plume_feather_barb(feather, i), right = plume_feather_barb(feather, per_vane + i);
		plume_vec3 a = left.curve.points[left.curve.count / 2], b = right.curve.points[right.curve.count / 2];
		largest = fmax(largest, fabs(a.x + b.x) + fabs(a.y - b.y));
	}
	assert_true(largest > 1e-4);
	plume_feather_destroy(feather);
}

/// The barb's points in its own frame: origin at the root, x towards the tip,
/// y in the vane plane towards the feather's tip, lengths divided by d.
static plume_vec3 relative_point(const plume_barb *barb, int k)
{
	plume_vec3 root = barb->curve.points[0], tip = barb->curve.points[barb->curve.count - 1];
	double d = plume_v3_distance(root, tip);
	plume_vec3 x = plume_v3_scale(plume_v3_sub(tip, root), 1.0 / d);
	plume_vec3 normal = plume_v3(0, 0, 1);
	plume_vec3 y = barb->side == PLUME_SIDE_LEFT ? plume_v3_cross(x, normal) : plume_v3_cross(normal, x);
	plume_vec3 offset = plume_v3_sub(barb->curve.points[k], root);
	return plume_v3(plume_v3_dot(offset, x) / d, plume_v3_dot(offset, y) / d, 0.0);
}

static void test_uniform_shape_gives_one_relative_form(void **state)
{
	(void)state;
	plume_fw_def def = plume_fw_default_def();
	def.segments[1] = (plume_fw_segment){300, 0.2, 0.6, false, true, false};
	plume_feather *feather = generate(&def, 4);
	plume_feather_info info = plume_feather_get_info(feather);
	const plume_barb *reference[2] = {NULL, NULL};
	plume_barb first[2];
	double spread_other_segment = 0.0;
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		if (barb.segment != 1)
			continue;
		if (reference[barb.side] == NULL) {
			first[barb.side] = barb;
			reference[barb.side] = &first[barb.side];
			continue;
		}
		for (int k = 0; k < barb.curve.count; ++k) {
			plume_vec3 a = relative_point(reference[barb.side], k), b = relative_point(&barb, k);
			assert_true(plume_v3_distance(a, b) < 1e-9);
		}
	}
	// Segment 0 has U_f false: its barbs' forms differ.
	plume_barb a = plume_feather_barb(feather, 0), b = plume_feather_barb(feather, 1);
	for (int k = 0; k < a.curve.count; ++k)
		spread_other_segment =
		    fmax(spread_other_segment, plume_v3_distance(relative_point(&a, k), relative_point(&b, k)));
	assert_true(spread_other_segment > 1e-3);
	plume_feather_destroy(feather);
}

static void test_texture_coordinates_and_widths(void **state)
{
	(void)state;
	plume_fw_def def = symmetric_def();
	plume_feather *feather = generate(&def, 2);
	plume_feather_info info = plume_feather_get_info(feather);
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		assert_close(barb.curve.uv[0].x, 0.0, 0.0);
		assert_close(barb.curve.uv[barb.curve.count - 1].x, 1.0, 1e-15);
		assert_close(barb.curve.widths[0], def.barb_width_base, 1e-18);
		assert_close(barb.curve.widths[barb.curve.count - 1], def.barb_width_tip, 1e-18);
		for (int k = 0; k < barb.curve.count; ++k) {
			assert_close(barb.curve.uv[k].y, barb.rachis_t, 0.0);
			if (k > 0) {
				assert_true(barb.curve.uv[k].x > barb.curve.uv[k - 1].x);
				assert_close(barb.curve.arc_length[k] - barb.curve.arc_length[k - 1],
				             plume_v3_distance(barb.curve.points[k], barb.curve.points[k - 1]), 1e-15);
			}
		}
	}
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	assert_close(shaft[0].t, 0.0, 0.0);
	assert_close(shaft[info.shaft_sample_count - 1].t, 1.0, 0.0);
	assert_close(shaft[0].width, def.shaft_width_base, 1e-18);
	assert_close(info.shaft_length, 0.12, 1e-6);
	for (int i = 0; i < info.shaft_sample_count; ++i) {
		assert_close(plume_v3_length(shaft[i].tangent), 1.0, 1e-12);
		assert_close(plume_v3_dot(shaft[i].tangent, shaft[i].normal), 0.0, 1e-12);
		assert_true(shaft[i].binormal.x < 0.0); // towards the left vane
	}
	assert_true(info.calamus_sample_count > 0 && shaft[info.calamus_sample_count - 1].t <= def.calamus_fraction);
	plume_feather_destroy(feather);
}

static void test_same_seed_same_feather(void **state)
{
	(void)state;
	plume_fw_def def = plume_fw_default_def();
	plume_feather *a = generate(&def, 99), *b = generate(&def, 99), *c = generate(&def, 100);
	assert_true(plume_feather_equal(a, b));
	assert_false(plume_feather_equal(a, c));
	plume_feather *copy = plume_feather_clone(a);
	assert_true(plume_feather_equal(a, copy));
	plume_feather_destroy(copy);
	plume_feather_destroy(a);
	plume_feather_destroy(b);
	plume_feather_destroy(c);
}

static void expect_invalid(plume_fw_def def, const char *fragment)
{
	plume_feather *feather = (plume_feather *)0x1;
	plume_error err = {0};
	assert_int_equal(plume_fw_generate(&def, 1, &feather, &err), PLUME_ERROR_SPEC);
	assert_null(feather);
	if (strstr(err.message, fragment) == NULL)
		fail_msg("message '%s' lacks '%s'", err.message, fragment);
}

static void test_ranges_are_enforced(void **state)
{
	(void)state;
	plume_fw_def def = plume_fw_default_def();
	def.segments[1].barb_count = 5001;
	expect_invalid(def, "$.segments[1].barb_count is 5001, allowed [0, 5000]");
	def = plume_fw_default_def();
	def.segments[0].barb_count = -1;
	expect_invalid(def, "$.segments[0].barb_count");
	def = plume_fw_default_def();
	def.segments[0].length_variation = 1.5;
	expect_invalid(def, "$.segments[0].length_variation is 1.5, allowed [0, 1]");
	def = plume_fw_default_def();
	def.segments[1].shape_variation = -0.1;
	expect_invalid(def, "$.segments[1].shape_variation");
	def = plume_fw_default_def();
	def.second_segment_start = 1.2;
	expect_invalid(def, "$.second_segment_start is 1.2, allowed [0, 1]");
	def = plume_fw_default_def();
	def.barb_samples = 1;
	expect_invalid(def, "$.barb_samples");
	def = plume_fw_default_def();
	def.shaft_width_tip = 0.0;
	expect_invalid(def, "$.shaft_width_tip");
	def = plume_fw_default_def();
	def.shaft[3] = def.shaft[0];
	expect_invalid(def, "$.shaft");
	def = plume_fw_default_def();
	def.left_outline[2].x = NAN;
	expect_invalid(def, "$.left_outline[2]");
	// Base != tip, but far too short: once accepted, with tangents of rounding noise.
	def = plume_fw_default_def();
	def.shaft[0] = def.shaft[1] = (plume_vec2){0.0, 0.0};
	def.shaft[2] = def.shaft[3] = (plume_vec2){0.0, 1e-300};
	expect_invalid(def, "$.shaft is 1e-300 m long; allowed at least 0.0001 m (0.1 mm)");
	def.shaft[2] = def.shaft[3] = (plume_vec2){0.0, 9e-5};
	expect_invalid(def, "$.shaft is 9e-05 m long; allowed at least 0.0001 m");
	def.shaft[2] = def.shaft[3] = (plume_vec2){0.0, 1e-4};
	plume_feather_destroy(generate(&def, 1));
}

/// Coincident control points at the shaft's ends make B' vanish there: the tangent comes
/// from the next derivative that does not, so every sample has a unit tangent towards the
/// tip and a unit binormal ([0, 0, 0] at samples 0 and 99 before).
static void test_shaft_tangents_at_coincident_control_points(void **state)
{
	(void)state;
	static const plume_vec2 shafts[][4] = {
	    {{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.2}, {0.0, 0.2}},          // P0 = P1, P2 = P3
	    {{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}, {0.01, 0.2}},         // P0 = P1 = P2: B''' gives it
	    {{0.0, 0.0}, {0.03, 0.1}, {0.01, 0.2}, {0.01, 0.2}},       // curved, P2 = P3
	    {{0.0, 0.0}, {0.0, 1e-19}, {0.0, 0.2}, {0.0, 0.2}},        // P1 a rounding error from P0
	    {{0.0, 0.0}, {0.0015, 0.07}, {0.005, 0.14}, {0.004, 0.2}}, // the hawk: unchanged
	};
	for (size_t k = 0; k < sizeof shafts / sizeof shafts[0]; ++k) {
		plume_fw_def def = plume_fw_default_def();
		memcpy(def.shaft, shafts[k], sizeof def.shaft);
		def.segments[0].barb_count = 5;
		def.segments[1].barb_count = 5;
		plume_feather *feather = generate(&def, 1);
		int count = plume_feather_get_info(feather).shaft_sample_count;
		const plume_shaft_sample *shaft = plume_feather_shaft(feather);
		for (int i = 0; i < count; ++i) {
			if (fabs(plume_v3_length(shaft[i].tangent) - 1.0) > 1e-12 ||
			    fabs(plume_v3_length(shaft[i].binormal) - 1.0) > 1e-12)
				fail_msg("shaft %zu, sample %d: tangent (%g, %g, %g), binormal (%g, %g, %g)", k, i, shaft[i].tangent.x,
				         shaft[i].tangent.y, shaft[i].tangent.z, shaft[i].binormal.x, shaft[i].binormal.y,
				         shaft[i].binormal.z);
			// Towards the tip: along the chord to the next sample (from the one before at the tip).
			plume_vec3 chord = i + 1 < count ? plume_v3_sub(shaft[i + 1].position, shaft[i].position)
			                                 : plume_v3_sub(shaft[i].position, shaft[i - 1].position);
			assert_true(plume_v3_dot(shaft[i].tangent, plume_v3_normalize(chord)) > 0.9);
		}
		plume_feather_destroy(feather);
	}
}

static void test_extreme_counts(void **state)
{
	(void)state;
	plume_fw_def def = plume_fw_default_def();
	def.segments[0].barb_count = 0;
	def.segments[1].barb_count = 0;
	plume_feather *feather = generate(&def, 1);
	assert_int_equal(plume_feather_get_info(feather).barb_count, 0);
	plume_feather_destroy(feather);
	def.segments[1].barb_count = PLUME_FW_MAX_BARBS;
	def.segments[0].barb_count = PLUME_FW_MAX_BARBS;
	feather = generate(&def, 1);
	assert_int_equal(plume_feather_get_info(feather).barb_count, 4 * PLUME_FW_MAX_BARBS);
	plume_feather_destroy(feather);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_barb_counts_per_segment),
	    cmocka_unit_test(test_segment_boundary_follows_is),
	    cmocka_unit_test(test_every_barb_starts_on_the_rachis),
	    cmocka_unit_test(test_unperturbed_barbs_end_on_their_outline),
	    cmocka_unit_test(test_length_variation_stays_in_range),
	    cmocka_unit_test(test_symmetric_vanes_mirror),
	    cmocka_unit_test(test_uniform_shape_gives_one_relative_form),
	    cmocka_unit_test(test_texture_coordinates_and_widths),
	    cmocka_unit_test(test_same_seed_same_feather),
	    cmocka_unit_test(test_ranges_are_enforced),
	    cmocka_unit_test(test_extreme_counts),
	    cmocka_unit_test(test_shaft_tangents_at_coincident_control_points),
	};
	return cmocka_run_group_tests_name("franco_walter", tests, NULL, NULL);
}

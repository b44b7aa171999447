// Franco & Walter 2002, "Modeling and Rendering of Individual Feathers", section 4.
//
// Shaft: a cubic Bézier. Vanes: quartic Bézier outlines. Barbs: cubic Béziers
// P0 P1 P2 P3 with P0 = P1 on the rachis and P2 = P3 on the outline before
// perturbation (section 4.2). In the barb's frame (x from the rachis towards
// the outline, y in the vane plane towards the feather's tip):
//   P3 <- P0 + (1 + r)(P3 - P0),           r  in [-F_pv, F_pv]   (length, 4.3)
//   d   = |P3 - P0|
//   P1  = P0 + v1 x + v2 y,   v1 in [-d F_b, 0], v2 in [-d F_b, d F_b]
//   P2  = P3 + v4 x + v3 y,   v3 in [0, d F_b],  v4 in [-d F_b, d F_b]
// The paper prints v3 in [0, F_b]; NOTES.md reads [0, d F_b] (a missing d).
// The paper does not say which way +y points; plume takes it towards the tip,
// so that v3 >= 0 bends barb ends tipwards as real barbs do, and mirrors the
// frame between vanes so that S_v gives mirror-image vanes.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/asserts.h"
#include "../core/alloc.h"
#include "feather_internal.h"
#include "plume/model.h"

plume_fw_def plume_fw_default_def(void)
{
	// A 0.2 m hawk contour feather: Table 2's "Hawk Feather" rows, with a gently
	// curved shaft and a vane widest below its middle, the outer (left) vane narrower.
	return (plume_fw_def){
	    .cookie = PLUME_DEF_COOKIE,
	    .shaft = {{0.0, 0.0}, {0.0015, 0.07}, {0.005, 0.14}, {0.004, 0.2}},
	    .left_outline = {{-0.003, 0.045}, {-0.024, 0.06}, {-0.03, 0.15}, {-0.022, 0.21}, {0.004, 0.205}},
	    .right_outline = {{0.003, 0.045}, {0.03, 0.06}, {0.04, 0.15}, {0.03, 0.215}, {0.004, 0.205}},
	    .mirror_right_outline = false,
	    .calamus_fraction = 0.15,
	    .segments =
	        {
	            {.barb_count = 200,
	             .length_variation = 0.2,
	             .shape_variation = 0.3,
	             .symmetric_vanes = false,
	             .uniform_shape = false,
	             .uniform_length = false},
	            {.barb_count = 2000,
	             .length_variation = 0.03,
	             .shape_variation = 0.2,
	             .symmetric_vanes = true,
	             .uniform_shape = true,
	             .uniform_length = false},
	        },
	    .second_segment_start = 0.2,
	    .shaft_samples = 100,
	    .barb_samples = 30,
	    .shaft_width_base = 3e-3,
	    .shaft_width_tip = 4e-4,
	    .barb_width_base = 1.5e-4,
	    .barb_width_tip = 3e-5,
	};
}

// ---------------------------------------------------------------------------
// Validation: messages name the spec's JSON path so that the spec reader can
// pass them on unchanged.

static plume_status check_range(double value, double lo, double hi, const char *path, plume_error *err)
{
	if (value >= lo && value <= hi)
		return PLUME_OK;
	// With the digits it takes to show the value outside: "%g" printed 0.9500001 as 0.95.
	char text[32];
	for (int digits = 6; digits <= 17; ++digits) {
		snprintf(text, sizeof text, "%.*g", digits, value);
		double printed = strtod(text, NULL);
		if (printed == value || (printed != lo && printed != hi))
			break;
	}
	return plume_error_set(err, PLUME_ERROR_SPEC, "%s is %s, allowed [%g, %g]", path, text, lo, hi);
}

static plume_status check_positive(double value, const char *path, plume_error *err)
{
	if (!(value > 0.0 && isfinite(value)))
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s is %g, must be a positive length in metres", path, value);
	return PLUME_OK;
}

/// The shortest shaft accepted, m. Real feathers are millimetres long at least (and plume's
/// units are metres): a shorter shaft is a unit error, and one of 1e-300 m once passed the
/// base != tip check with tangents of rounding noise.
#define MIN_SHAFT_LENGTH 1e-4

static plume_status check_points(const plume_vec2 *points, int count, const char *name, plume_error *err)
{
	for (int i = 0; i < count; ++i)
		if (!isfinite(points[i].x) || !isfinite(points[i].y))
			return plume_error_set(err, PLUME_ERROR_SPEC, "$.%s[%d] is not a finite point", name, i);
	return PLUME_OK;
}

plume_status plume_fw_def_validate(const plume_fw_def *def, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	plume_status status;
	if ((status = check_points(def->shaft, 4, "shaft", err)) != PLUME_OK ||
	    (status = check_points(def->left_outline, 5, "left_outline", err)) != PLUME_OK ||
	    (!def->mirror_right_outline &&
	     (status = check_points(def->right_outline, 5, "right_outline", err)) != PLUME_OK))
		return status;
	if (def->shaft[0].x == def->shaft[3].x && def->shaft[0].y == def->shaft[3].y)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "$.shaft starts and ends at the same point; the shaft needs a length");
	// Measured on the control points scaled to about 1 (relative to the base), so that a
	// shaft of 1e-300 m reports its length instead of an underflow to 0.
	double extent = 0.0;
	for (int i = 1; i < 4; ++i)
		extent = fmax(extent, fmax(fabs(def->shaft[i].x - def->shaft[0].x), fabs(def->shaft[i].y - def->shaft[0].y)));
	plume_vec3 shaft[4];
	for (int i = 0; i < 4; ++i)
		shaft[i] =
		    plume_v3((def->shaft[i].x - def->shaft[0].x) / extent, (def->shaft[i].y - def->shaft[0].y) / extent, 0.0);
	double length = extent * plume_bezier_length(shaft, 4, 0.0, 1.0);
	if (!(length >= MIN_SHAFT_LENGTH))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "$.shaft is %g m long; allowed at least %g m (0.1 mm): lengths are in metres", length,
		                       MIN_SHAFT_LENGTH);
	for (int s = 0; s < 2; ++s) {
		const plume_fw_segment *segment = def->segments + s;
		char path[64];
		snprintf(path, sizeof path, "$.segments[%d].barb_count", s);
		if ((status = check_range(segment->barb_count, 0, PLUME_FW_MAX_BARBS, path, err)) != PLUME_OK)
			return status;
		snprintf(path, sizeof path, "$.segments[%d].length_variation", s);
		if ((status = check_range(segment->length_variation, 0.0, 1.0, path, err)) != PLUME_OK)
			return status;
		snprintf(path, sizeof path, "$.segments[%d].shape_variation", s);
		if ((status = check_range(segment->shape_variation, 0.0, 1.0, path, err)) != PLUME_OK)
			return status;
	}
	if ((status = check_range(def->second_segment_start, 0.0, 1.0, "$.second_segment_start", err)) != PLUME_OK ||
	    (status = check_range(def->calamus_fraction, 0.0, 0.95, "$.calamus_fraction", err)) != PLUME_OK ||
	    (status = check_range(def->shaft_samples, 2, 100000, "$.shaft_samples", err)) != PLUME_OK ||
	    (status = check_range(def->barb_samples, 2, 1000, "$.barb_samples", err)) != PLUME_OK ||
	    (status = check_positive(def->shaft_width_base, "$.shaft_width_base", err)) != PLUME_OK ||
	    (status = check_positive(def->shaft_width_tip, "$.shaft_width_tip", err)) != PLUME_OK ||
	    (status = check_positive(def->barb_width_base, "$.barb_width_base", err)) != PLUME_OK ||
	    (status = check_positive(def->barb_width_tip, "$.barb_width_tip", err)) != PLUME_OK)
		return status;
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// Generation

/// The random values of one barb, normalized: the length factor r, and the
/// shape values u1..u4 that scale to v_i = u_i d F_b.
typedef struct barb_draw {
	double r;
	double u1, u2, u3, u4;
} barb_draw;

/// What a vane keeps between barbs of one segment (for U_f and U_c).
typedef struct vane_draws {
	barb_draw kept;
	bool have_shape, have_length;
} vane_draws;

static void draw_barb(plume_rng *rng, const plume_fw_segment *segment, vane_draws *vane, barb_draw *out)
{
	if (!segment->uniform_length || !vane->have_length) {
		vane->kept.r = plume_rng_range(rng, -segment->length_variation, segment->length_variation);
		vane->have_length = true;
	}
	if (!segment->uniform_shape || !vane->have_shape) {
		vane->kept.u1 = plume_rng_range(rng, -1.0, 0.0);
		vane->kept.u2 = plume_rng_range(rng, -1.0, 1.0);
		vane->kept.u3 = plume_rng_range(rng, 0.0, 1.0);
		vane->kept.u4 = plume_rng_range(rng, -1.0, 1.0);
		vane->have_shape = true;
	}
	*out = vane->kept;
}

static plume_vec3 lift(plume_vec2 p) { return plume_v3(p.x, p.y, 0.0); }

/// Reflection of p across the line through a and b.
static plume_vec3 mirror_across(plume_vec3 p, plume_vec3 a, plume_vec3 b)
{
	plume_vec3 axis = plume_v3_normalize(plume_v3_sub(b, a));
	plume_vec3 offset = plume_v3_sub(p, a);
	plume_vec3 along = plume_v3_scale(axis, plume_v3_dot(offset, axis));
	return plume_v3_add(a, plume_v3_sub(plume_v3_scale(along, 2.0), offset));
}

typedef struct fw_geometry {
	plume_vec3 shaft[4];
	plume_vec3 outline[2][5]; // [side]
	plume_bezier_arc shaft_arc;
	plume_bezier_arc outline_arc[2];
} fw_geometry;

static const plume_vec3 vane_normal = {0.0, 0.0, 1.0};

/// Unit tangent of the shaft at u, towards the tip. B'(u) vanishes where control points
/// coincide (P0 = P1 makes B'(0) = 3 (P1 - P0) = 0), and normalizing it gave [0, 0, 0].
/// There the curve still has a direction: B(u + h) - B(u) = h B' + h^2/2 B'' + h^3/6 B''',
/// so the first derivative that does not vanish gives it. In the shaft's upper half the
/// curve is taken from below (the tip, u = 1, has nothing above it):
/// B(u) - B(u - h) = h B' - h^2/2 B'' + h^3/6 B''', and B'' turns round. A derivative
/// "vanishes" below 1e-9 of the shaft's length (u has no unit: every derivative is in
/// metres), so control points a rounding error apart count as one.
static plume_vec3 shaft_tangent(const plume_vec3 shaft[4], double u, double length)
{
	for (int order = 1; order <= 3; ++order) {
		plume_vec3 d = plume_bezier_derivative(shaft, 4, order, u);
		if (order == 2 && u >= 0.5)
			d = plume_v3_scale(d, -1.0);
		if (plume_v3_length(d) > 1e-9 * length)
			return plume_v3_normalize(d);
	}
	// Unreachable for a validated shaft (at least MIN_SHAFT_LENGTH long): its chord.
	return plume_v3_normalize(plume_v3_sub(shaft[3], shaft[0]));
}

static plume_status build_shaft(plume_feather *feather, const plume_fw_def *def, const fw_geometry *geometry)
{
	int count = def->shaft_samples;
	plume_shaft_sample *samples = plume_feather_add_shaft(feather, count);
	if (samples == NULL)
		return PLUME_ERROR_MEMORY;
	for (int i = 0; i < count; ++i) {
		double t = (double)i / (count - 1);
		double u = plume_bezier_arc_param(&geometry->shaft_arc, t);
		plume_shaft_sample *sample = samples + i;
		sample->position = plume_bezier_eval(geometry->shaft, 4, u);
		sample->tangent = shaft_tangent(geometry->shaft, u, geometry->shaft_arc.length);
		sample->normal = vane_normal;
		sample->binormal = plume_v3_cross(vane_normal, sample->tangent);
		sample->width = def->shaft_width_base + t * (def->shaft_width_tip - def->shaft_width_base);
		sample->t = t;
		if (t <= def->calamus_fraction)
			feather->calamus_count = i + 1;
	}
	return PLUME_OK;
}

/// Appends one barb at vane fraction q on the given side.
static plume_status build_barb(plume_feather *feather, const plume_fw_def *def, const fw_geometry *geometry,
                               plume_side side, int segment_index, double q, const barb_draw *draw)
{
	const plume_fw_segment *segment = def->segments + segment_index;
	double rachis_t = def->calamus_fraction + (1.0 - def->calamus_fraction) * q;
	plume_vec3 p0 = plume_bezier_eval(geometry->shaft, 4, plume_bezier_arc_param(&geometry->shaft_arc, rachis_t));
	plume_vec3 tip =
	    plume_bezier_eval(geometry->outline[side], 5, plume_bezier_arc_param(&geometry->outline_arc[side], q));

	plume_vec3 p3 = plume_v3_mad(p0, 1.0 + draw->r, plume_v3_sub(tip, p0));
	double d = plume_v3_distance(p0, p3);
	plume_vec3 x = d > 0.0 ? plume_v3_scale(plume_v3_sub(p3, p0), 1.0 / d) : plume_v3(0.0, 0.0, 0.0);
	plume_vec3 y = side == PLUME_SIDE_LEFT ? plume_v3_cross(x, vane_normal) : plume_v3_cross(vane_normal, x);
	double scale = d * segment->shape_variation;
	plume_vec3 control[4];
	control[0] = p0;
	control[1] =
	    plume_v3_add(p0, plume_v3_add(plume_v3_scale(x, draw->u1 * scale), plume_v3_scale(y, draw->u2 * scale)));
	control[2] =
	    plume_v3_add(p3, plume_v3_add(plume_v3_scale(x, draw->u4 * scale), plume_v3_scale(y, draw->u3 * scale)));
	control[3] = p3;

	int count = def->barb_samples;
	int first = plume_feather_add_points(feather, count);
	if (first < 0)
		return PLUME_ERROR_MEMORY;
	for (int i = 0; i < count; ++i) {
		double t = (double)i / (count - 1);
		feather->points[first + i] = plume_bezier_eval(control, 4, t);
		feather->normals[first + i] = vane_normal;
		feather->uv[first + i].y = rachis_t;
	}
	// The ends are exact: P0 on the rachis and P3 on the (rescaled) outline.
	feather->points[first] = p0;
	feather->points[first + count - 1] = p3;
	plume_curve_range range = {first, count};
	plume_feather_measure_curve(feather, range);
	for (int i = 0; i < count; ++i) {
		double s = feather->uv[first + i].x;
		feather->widths[first + i] = def->barb_width_base + s * (def->barb_width_tip - def->barb_width_base);
	}
	plume_barb_record record = {
	    .curve = range,
	    .side = side,
	    .rachis_t = rachis_t,
	    .segment = segment_index,
	    .barbule_first = 0,
	    .barbule_count = 0,
	};
	return plume_feather_add_barb(feather, &record) < 0 ? PLUME_ERROR_MEMORY : PLUME_OK;
}

double plume_fw_estimate_bytes(const plume_fw_def *def)
{
	double barbs = 2.0 * ((double)def->segments[0].barb_count + (double)def->segments[1].barb_count);
	double points = (double)def->shaft_samples + barbs * (double)def->barb_samples;
	return plume_feather_layout_bytes(points, barbs, 0.0, def->shaft_samples);
}

plume_status plume_fw_generate(const plume_fw_def *def, uint64_t seed, plume_feather **out, plume_error *err)
{
	*out = NULL;
	plume_status status = plume_fw_def_validate(def, err);
	if (status != PLUME_OK)
		return status;

	fw_geometry geometry;
	for (int i = 0; i < 4; ++i)
		geometry.shaft[i] = lift(def->shaft[i]);
	for (int i = 0; i < 5; ++i) {
		geometry.outline[PLUME_SIDE_LEFT][i] = lift(def->left_outline[i]);
		geometry.outline[PLUME_SIDE_RIGHT][i] =
		    def->mirror_right_outline ? mirror_across(lift(def->left_outline[i]), geometry.shaft[0], geometry.shaft[3])
		                              : lift(def->right_outline[i]);
	}
	plume_bezier_arc_init(&geometry.shaft_arc, geometry.shaft, 4);
	for (int side = 0; side < 2; ++side)
		plume_bezier_arc_init(&geometry.outline_arc[side], geometry.outline[side], 5);

	plume_feather *feather = plume_feather_create_empty();
	if (feather == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");

	int barbs_per_vane = def->segments[0].barb_count + def->segments[1].barb_count;
	// One reservation up front so that the point pool never moves while barbs are built.
	if (plume_feather_reserve_points(feather, 2 * barbs_per_vane * def->barb_samples) != 0 ||
	    (status = build_shaft(feather, def, &geometry)) != PLUME_OK)
		goto fail;

	// Random values are drawn segment by segment, barb by barb, left vane then
	// right (unless S_v shares them), so a seed fixes every barb.
	plume_rng rng = plume_rng_seed(seed);
	barb_draw(*draws)[2] = plume_alloc((size_t)(barbs_per_vane > 0 ? barbs_per_vane : 1) * sizeof *draws);
	if (draws == NULL)
		goto fail;
	double fractions[2][2] = {{0.0, def->second_segment_start}, {def->second_segment_start, 1.0}};
	int index = 0;
	for (int s = 0; s < 2; ++s) {
		vane_draws vanes[2];
		memset(vanes, 0, sizeof vanes);
		for (int k = 0; k < def->segments[s].barb_count; ++k, ++index) {
			draw_barb(&rng, def->segments + s, vanes + PLUME_SIDE_LEFT, &draws[index][PLUME_SIDE_LEFT]);
			if (def->segments[s].symmetric_vanes)
				draws[index][PLUME_SIDE_RIGHT] = draws[index][PLUME_SIDE_LEFT];
			else
				draw_barb(&rng, def->segments + s, vanes + PLUME_SIDE_RIGHT, &draws[index][PLUME_SIDE_RIGHT]);
		}
	}
	// Barbs sit at the centres of N equal cells of their segment's vane interval,
	// so the two segments never share a barb and none has zero length at the tip.
	for (int side = 0; side < 2 && status == PLUME_OK; ++side) {
		index = 0;
		for (int s = 0; s < 2 && status == PLUME_OK; ++s) {
			int count = def->segments[s].barb_count;
			double lo = fractions[s][0], hi = fractions[s][1];
			for (int k = 0; k < count && status == PLUME_OK; ++k, ++index) {
				double q = lo + (hi - lo) * (k + 0.5) / count;
				status = build_barb(feather, def, &geometry, (plume_side)side, s, q, &draws[index][side]);
			}
		}
	}
	plume_free(draws);
	if (status != PLUME_OK)
		goto fail;
	*out = feather;
	return PLUME_OK;
fail:
	plume_feather_destroy(feather);
	return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory while generating a feather");
}

// Zhang & Kanai, "Biological Modeling of Feathers by Morphogenesis
// Simulation", section IV: defaults, validation, and the feather the three
// stages (zhang_kanai_growth.c, _unfurl.c, _expand.c) produce.
//
// The rachis is plume's: the paper leaves it to other software ("a simple
// cylinder in CG software", section V). It stands on the middle of the
// anterior interval's chord, where the barb roots are (the rachidial ridge,
// Figure 2 C), runs from the calamus below the collar to the highest barb
// root, and tapers from the chord's width.
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/asserts.h"
#include "../core/number_text.h"
#include "../core/alloc.h"
#include "feather_internal.h"
#include "zhang_kanai_internal.h"

static const double deg = 3.14159265358979323846 / 180.0;

static plume_zk_curve curve3(double s0, double v0, double s1, double v1, double s2, double v2, double s3, double v3,
                             double s4, double v4)
{
	return (plume_zk_curve){.count = 5, .s = {s0, s1, s2, s3, s4}, .value = {v0, v1, v2, v3, v4}};
}

plume_zk_def plume_zk_default_def(void)
{
	plume_zk_def def = {
	    .cookie = PLUME_DEF_COOKIE,
	    .collar_kind = PLUME_ZK_COLLAR_CIRCLE,
	    .collar_radius = 0.01,
	    .collar_point_count = 0,
	    .anterior = {0.98, 0.02},
	    .posterior = {0.51, 0.49},
	    .ridge_width = 8e-4,
	    .ridge_width_variation = 0.0,
	    // Convex downward at s = 0.5: the emitters slow down as they near the BGZ (Figure 9 left).
	    .emitter_speed = curve3(0.0, 0.012, 0.25, 0.008, 0.5, 0.004, 0.75, 0.008, 1.0, 0.012),
	    .barb_speed = plume_zk_constant(0.008),
	    .growth_speed = 0.005,
	    .step = 0.02,
	    .barb_count = 100,
	    .downsample = 4,
	    .growth_stage = 1.0,
	    .unfurl_weight = 1.0,
	    .sheath = false,
	    .sheath_height = 0.0,
	    .sheath_ramp = 0.01,
	    .expansion = false,
	    .theta_distal = 30.0 * deg,
	    .theta_proximal = 150.0 * deg,
	    .azimuth = 90.0 * deg,
	    .ridge_height = curve3(0.0, 3.5e-4, 0.25, 3.25e-4, 0.5, 3e-4, 0.75, 3.25e-4, 1.0, 3.5e-4),
	    .split_count = 0,
	    .keep_barbules = true,
	    .calamus_length = 0.015,
	    .rachis_taper = 0.25,
	    .shaft_samples = 100,
	    .barb_width_base = 1.5e-4,
	    .barb_width_tip = 3e-5,
	    .barbule_width = 1e-5,
	};
	return def;
}

// ---------------------------------------------------------------------------
// Validation: messages name the spec's JSON path.

static plume_status check_range(double value, double lo, double hi, const char *path, plume_error *err)
{
	char text[32];
	if (!(value >= lo && value <= hi))
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s is %s, allowed [%g, %g]", path,
		                       plume_number_outside(text, sizeof text, value, lo, hi), lo, hi);
	return PLUME_OK;
}

static plume_status check_positive(double value, const char *path, const char *what, plume_error *err)
{
	if (!(value > 0.0 && isfinite(value)))
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s is %g, must be a positive %s", path, value, what);
	return PLUME_OK;
}

static plume_status check_curve(const plume_zk_curve *curve, const char *key, const char *what, plume_error *err)
{
	if (curve->count < 1 || curve->count > PLUME_ZK_MAX_CURVE_POINTS)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.%s has %d control points, allowed 1 to %d", key, curve->count,
		                       PLUME_ZK_MAX_CURVE_POINTS);
	for (int k = 0; k < curve->count; ++k) {
		char path[96];
		if (curve->count == 1)
			snprintf(path, sizeof path, "$.%s", key);
		else
			snprintf(path, sizeof path, "$.%s[%d]", key, k);
		if (!(curve->s[k] >= 0.0 && curve->s[k] <= 1.0))
			return plume_error_set(err, PLUME_ERROR_SPEC, "%s: locus %g is outside the collar's [0, 1]", path,
			                       curve->s[k]);
		if (k > 0 && !(curve->s[k] > curve->s[k - 1]))
			return plume_error_set(err, PLUME_ERROR_SPEC, "%s: locus %g does not follow %g; loci must increase", path,
			                       curve->s[k], curve->s[k - 1]);
		if (!(curve->value[k] > 0.0 && isfinite(curve->value[k])))
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "%s: %s %g must be positive (> 0) everywhere; the curve stays between its control "
			                       "values, so every control value must be positive",
			                       path, what, curve->value[k]);
	}
	return PLUME_OK;
}

static plume_status check_collar(const plume_zk_def *def, plume_error *err)
{
	if (def->collar_kind == PLUME_ZK_COLLAR_CIRCLE)
		return check_positive(def->collar_radius, "$.collar.radius", "radius in metres", err);
	if (def->collar_kind != PLUME_ZK_COLLAR_BEZIER)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.collar: unknown collar kind %d", (int)def->collar_kind);
	int n = def->collar_point_count;
	if (n < 4 || n > PLUME_ZK_MAX_COLLAR_POINTS)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "$.collar.points has %d control points; a closed composite cubic Bézier collar needs 4 "
		                       "to %d",
		                       n, PLUME_ZK_MAX_COLLAR_POINTS);
	double area = 0.0;
	for (int k = 0; k < n; ++k) {
		plume_vec2 a = def->collar_points[k], b = def->collar_points[(k + 1) % n];
		if (!isfinite(a.x) || !isfinite(a.y))
			return plume_error_set(err, PLUME_ERROR_SPEC, "$.collar.points[%d] is not a finite point", k);
		if (a.x == b.x && a.y == b.y)
			return plume_error_set(err, PLUME_ERROR_SPEC, "$.collar.points[%d] repeats the point before it",
			                       (k + 1) % n);
		area += a.x * b.y - b.x * a.y;
	}
	// Eq. 1 runs from -z towards +x: a positive shoelace sum in (x, z).
	if (!(area > 0.0))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "$.collar.points run the wrong way round: list them like eq. 1, from -z towards +x "
		                       "(x = sin 2 pi s, z = -cos 2 pi s)");
	return PLUME_OK;
}

static plume_status check_intervals(const plume_zk_def *def, plume_error *err)
{
	plume_status status;
	if ((status = check_range(def->anterior[0], 0.0, 1.0, "$.anterior[0]", err)) != PLUME_OK ||
	    (status = check_range(def->anterior[1], 0.0, 1.0, "$.anterior[1]", err)) != PLUME_OK ||
	    (status = check_range(def->posterior[0], 0.0, 1.0, "$.posterior[0]", err)) != PLUME_OK ||
	    (status = check_range(def->posterior[1], 0.0, 1.0, "$.posterior[1]", err)) != PLUME_OK)
		return status;
	double al = def->anterior[0], ar = def->anterior[1], pl = def->posterior[0], pr = def->posterior[1];
	if (!(ar < pr && pr <= pl && pl < al))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "$.posterior <%g, %g> and $.anterior <%g, %g> overlap or are out of order: I_A = <left, "
		                       "right> contains s = 0 and the loci must satisfy anterior.right < posterior.right <= "
		                       "posterior.left < anterior.left, e.g. anterior [0.98, 0.02], posterior [0.51, 0.49]",
		                       pl, pr, al, ar);
	if (!((1.0 - al) + ar > 0.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.anterior <%g, %g> is empty; the rachidial ridge needs a width",
		                       al, ar);
	return PLUME_OK;
}

plume_status plume_zk_def_validate(const plume_zk_def *def, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	plume_status status;
	if ((status = check_collar(def, err)) != PLUME_OK || (status = check_intervals(def, err)) != PLUME_OK ||
	    (status = check_positive(def->ridge_width, "$.ridge_width", "width in metres", err)) != PLUME_OK ||
	    (status = check_range(def->ridge_width_variation, 0.0, 0.9, "$.ridge_width_variation", err)) != PLUME_OK ||
	    (status = check_curve(&def->emitter_speed, "emitter_speed", "speed", err)) != PLUME_OK ||
	    (status = check_curve(&def->barb_speed, "barb_speed", "speed", err)) != PLUME_OK ||
	    (status = check_positive(def->growth_speed, "$.growth_speed", "speed in m/s", err)) != PLUME_OK ||
	    (status = check_positive(def->step, "$.step", "time step in seconds", err)) != PLUME_OK ||
	    (status = check_range(def->barb_count, 1, PLUME_ZK_MAX_BARBS, "$.barb_count", err)) != PLUME_OK ||
	    (status = check_range(def->downsample, 1, 1000, "$.downsample", err)) != PLUME_OK ||
	    (status = check_range(def->growth_stage, 0.0, 1.0, "$.growth_stage", err)) != PLUME_OK ||
	    (status = check_range(def->unfurl_weight, 0.0, 1.0, "$.unfurl_weight", err)) != PLUME_OK ||
	    (status = check_range(def->sheath_height, 0.0, 1e3, "$.sheath.height", err)) != PLUME_OK ||
	    (status = check_positive(def->sheath_ramp, "$.sheath.ramp", "length in metres", err)) != PLUME_OK ||
	    (status = check_curve(&def->ridge_height, "ridge_height", "ridge height", err)) != PLUME_OK ||
	    (status = check_positive(def->calamus_length, "$.calamus_length", "length in metres", err)) != PLUME_OK ||
	    (status = check_range(def->shaft_samples, 2, 100000, "$.shaft_samples", err)) != PLUME_OK ||
	    (status = check_positive(def->barb_width_base, "$.barb_width_base", "width in metres", err)) != PLUME_OK ||
	    (status = check_positive(def->barb_width_tip, "$.barb_width_tip", "width in metres", err)) != PLUME_OK ||
	    (status = check_positive(def->barbule_width, "$.barbule_width", "width in metres", err)) != PLUME_OK)
		return status;
	char text[32];
	if (!(def->rachis_taper > 0.0 && def->rachis_taper <= 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.rachis_taper is %s, allowed (0, 1]",
		                       plume_number_outside(text, sizeof text, def->rachis_taper, 0.0, 1.0));
	if (!(def->theta_distal > 0.0 && def->theta_distal < 180.0 * deg))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.theta_distal_deg is %s, allowed (0, 180)",
		                       plume_number_outside(text, sizeof text, def->theta_distal / deg, 0.0, 180.0));
	if (!(def->theta_proximal > 0.0 && def->theta_proximal < 180.0 * deg))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.theta_proximal_deg is %s, allowed (0, 180)",
		                       plume_number_outside(text, sizeof text, def->theta_proximal / deg, 0.0, 180.0));
	if ((status = check_range(def->azimuth / deg, 0.0, 180.0, "$.azimuth_deg", err)) != PLUME_OK)
		return status;
	if (def->split_count < 0 || def->split_count > PLUME_ZK_MAX_SPLITS)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.splits has %d entries, allowed at most %d", def->split_count,
		                       PLUME_ZK_MAX_SPLITS);
	// A split bends a barb before snapping (IV-C, Figure 11 bottom), which only expansion runs: without
	// it a split did nothing, silently.
	if (def->split_count > 0 && !def->expansion)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "$.splits: a split bends a barb before snapping (IV-C), which runs with "
		                       "\"expansion\": true only; set $.expansion to true or remove $.splits");
	for (int k = 0; k < def->split_count; ++k) {
		const plume_zk_split *split = def->splits + k;
		char path[64];
		if (split->side != PLUME_SIDE_LEFT && split->side != PLUME_SIDE_RIGHT)
			return plume_error_set(err, PLUME_ERROR_SPEC, "$.splits[%d].side must be \"left\" or \"right\"", k);
		// A vane of the finished feather has at most N barbs (N = barb_count on the vane that ends
		// the growth); zk_check_splits checks the vane's own count once it has grown.
		if (split->barb < 0 || split->barb >= def->barb_count)
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "$.splits[%d].barb is %d, allowed [0, %d]: a vane has at most $.barb_count (%d) "
			                       "barbs, numbered in emission order from 0, the most distal",
			                       k, split->barb, def->barb_count - 1, def->barb_count);
		snprintf(path, sizeof path, "$.splits[%d].at", k);
		if ((status = check_range(split->at, 0.0, 1.0, path, err)) != PLUME_OK)
			return status;
		if (!(fabs(split->angle) < 180.0 * deg))
			return plume_error_set(err, PLUME_ERROR_SPEC, "$.splits[%d].angle_deg is %s, allowed (-180, 180)", k,
			                       plume_number_outside(text, sizeof text, split->angle / deg, -180.0, 180.0));
	}
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// The feather

typedef struct zk_result {
	const plume_zk_def *def;
	const zk_growth *growth;
	const zk_shape *shape;
	const zk_barbules *barbules;
	double base_width; ///< the anterior interval's chord
} zk_result;

static double root_y(const zk_result *r, int barb) { return r->shape->p[r->growth->barbs[barb].first].y; }

static plume_status build_shaft(plume_feather *feather, const zk_result *r, double y0, double y1, double y_low)
{
	int count = r->def->shaft_samples;
	plume_shaft_sample *samples = plume_feather_add_shaft(feather, count);
	if (samples == NULL)
		return PLUME_ERROR_MEMORY;
	feather->calamus_count = 1;
	for (int i = 0; i < count; ++i) {
		double t = (double)i / (count - 1);
		double y = y0 + (y1 - y0) * t;
		samples[i] = (plume_shaft_sample){
		    .position = {0.0, y, 0.0},
		    .tangent = {0.0, 1.0, 0.0},
		    .normal = {0.0, 0.0, 1.0},
		    .binormal = {-1.0, 0.0, 0.0}, // normal x tangent: towards the left vane
		    .width = r->base_width * (1.0 - (1.0 - r->def->rachis_taper) * t),
		    .t = t,
		};
		if (y < y_low && i + 1 > feather->calamus_count)
			feather->calamus_count = i + 1;
	}
	return PLUME_OK;
}

/// Fills the two pool points from first (added already) with a barbule from `from` along vector, and
/// records it.
static plume_status add_barbule(plume_feather *feather, int first, int barb_index, plume_vec3 from, plume_vec3 vector,
                                plume_vec3 normal, double barb_s, double rachis_t, plume_barbule_kind kind,
                                double width)
{
	feather->points[first] = from;
	feather->points[first + 1] = plume_v3_add(from, vector);
	for (int k = 0; k < 2; ++k) {
		feather->normals[first + k] = normal;
		feather->widths[first + k] = width;
		feather->uv[first + k].y = rachis_t;
	}
	plume_curve_range range = {first, 2};
	plume_feather_measure_curve(feather, range);
	plume_barbule_record record = {.curve = range, .barb = barb_index, .barb_s = barb_s, .kind = kind};
	return plume_feather_add_barbule(feather, &record) < 0 ? PLUME_ERROR_MEMORY : PLUME_OK;
}

static plume_status build_barb(plume_feather *feather, const zk_result *r, int g, double y0, double y1, bool barbules)
{
	const plume_zk_def *def = r->def;
	const zk_barb *barb = r->growth->barbs + g;
	double dir = barb->side == PLUME_SIDE_LEFT ? -1.0 : 1.0;
	double rachis_t = y1 > y0 ? (root_y(r, g) - y0) / (y1 - y0) : 0.0;
	int first = plume_feather_append_points(feather, barb->count);
	if (first < 0)
		return PLUME_ERROR_MEMORY;
	for (int j = 0; j < barb->count; ++j) {
		int v = barb->first + j;
		feather->points[first + j] = r->shape->p[v];
		// The side that faced the follicle's axis is the front: -dir n, +z once unfurled.
		feather->normals[first + j] = plume_v3_scale(r->shape->frame[v].n, -dir);
		feather->uv[first + j].y = rachis_t;
	}
	plume_curve_range range = {first, barb->count};
	plume_feather_measure_curve(feather, range);
	for (int j = 0; j < barb->count; ++j) {
		double s = feather->uv[first + j].x;
		feather->widths[first + j] = def->barb_width_base + s * (def->barb_width_tip - def->barb_width_base);
	}
	plume_barb_record record = {
	    .curve = range,
	    .side = barb->side,
	    .rachis_t = rachis_t,
	    .segment = 0,
	    .barbule_first = feather->barbule_count,
	    .barbule_count = barbules ? 2 * barb->count : 0,
	};
	int index = plume_feather_add_barb(feather, &record);
	if (index < 0)
		return PLUME_ERROR_MEMORY;
	if (!barbules)
		return PLUME_OK;
	// Two barbules per vertex, distal then proximal, after the barb in the pool.
	int pool = plume_feather_append_points(feather, 4 * barb->count);
	if (pool < 0)
		return PLUME_ERROR_MEMORY;
	for (int j = 0; j < barb->count; ++j) {
		int v = barb->first + j;
		plume_vec3 p = feather->points[first + j], normal = feather->normals[first + j];
		double s = feather->uv[first + j].x;
		plume_status status;
		if ((status = add_barbule(feather, pool + 4 * j, index, p, r->barbules->distal[v], normal, s, rachis_t,
		                          PLUME_BARBULE_DISTAL, def->barbule_width)) != PLUME_OK ||
		    (status = add_barbule(feather, pool + 4 * j + 2, index, p, r->barbules->proximal[v], normal, s, rachis_t,
		                          PLUME_BARBULE_PROXIMAL, def->barbule_width)) != PLUME_OK)
			return status;
	}
	return PLUME_OK;
}

/// Growth index of the feather's barb k: each vane base to tip, i.e. its
/// emission order reversed.
static int growth_index(const zk_growth *growth, int k)
{
	int left = growth->side_count[PLUME_SIDE_LEFT];
	if (k < left)
		return left - 1 - k;
	return left + (growth->barb_count - 1 - k);
}

static plume_status build_feather(const zk_result *r, plume_feather **out)
{
	const zk_growth *growth = r->growth;
	const plume_zk_def *def = r->def;
	bool barbules = def->expansion && def->keep_barbules;
	double y_top = 0.0, y_low = INFINITY;
	for (int i = 0; i < growth->barb_count; ++i) {
		y_top = fmax(y_top, root_y(r, i));
		y_low = fmin(y_low, root_y(r, i));
	}
	if (growth->barb_count == 0)
		y_low = 0.0;
	double y0 = -def->calamus_length, y1 = y_top;
	plume_feather *feather = plume_feather_create_empty();
	if (feather == NULL)
		return PLUME_ERROR_MEMORY;
	long points = (long)growth->vertex_count * (barbules ? 5 : 1);
	plume_status status = PLUME_ERROR_MEMORY;
	// Every record in one allocation: a feather of 2 x 400 barbs has 60,000 barbules.
	if (points > 0x7fffffffL || plume_feather_reserve_points(feather, (int)points) != 0 ||
	    PLUME_GROW(feather->barbs, feather->barb_capacity, growth->barb_count) != 0 ||
	    (barbules && PLUME_GROW(feather->barbules, feather->barbule_capacity, 2 * growth->vertex_count) != 0) ||
	    (status = build_shaft(feather, r, y0, y1, y_low)) != PLUME_OK)
		goto fail;
	for (int k = 0; k < growth->barb_count; ++k)
		if ((status = build_barb(feather, r, growth_index(growth, k), y0, y1, barbules)) != PLUME_OK)
			goto fail;
	*out = feather;
	return PLUME_OK;
fail:
	plume_feather_destroy(feather);
	return status;
}

// ---------------------------------------------------------------------------
// Report and summary

void plume_zk_report_free(plume_zk_report *report)
{
	if (report == NULL)
		return;
	plume_free(report->barbs);
	plume_free(report->unsnapped);
	memset(report, 0, sizeof *report);
}

static plume_status fill_report(const zk_result *r, plume_zk_report *report)
{
	const zk_growth *growth = r->growth;
	memset(report, 0, sizeof *report);
	report->t_end = growth->t_end;
	report->t_curr = growth->t_curr;
	report->unfurl_weight = r->def->unfurl_weight;
	report->barb_count = growth->barb_count;
	report->barb_count_side[0] = growth->side_count[0];
	report->barb_count_side[1] = growth->side_count[1];
	report->developing_count = growth->developing_count;
	report->clamp_time[0] = growth->clamp_time[0];
	report->clamp_time[1] = growth->clamp_time[1];
	size_t n = (size_t)(growth->barb_count > 0 ? growth->barb_count : 1);
	report->barbs = plume_calloc(n, sizeof *report->barbs);
	report->unsnapped = plume_calloc(n, sizeof *report->unsnapped);
	if (report->barbs == NULL || report->unsnapped == NULL) {
		plume_zk_report_free(report);
		return PLUME_ERROR_MEMORY;
	}
	for (int k = 0; k < growth->barb_count; ++k) {
		int g = growth_index(growth, k);
		const zk_barb *barb = growth->barbs + g;
		plume_zk_barb_report *out = report->barbs + k;
		*out = (plume_zk_barb_report){
		    .side = barb->side,
		    .index = barb->index,
		    .feather_barb = k,
		    .emit_time = barb->emit_time,
		    .emit_locus = barb->emit_locus,
		    .mature_time = barb->mature ? barb->mature_time : INFINITY,
		    .mature = barb->mature,
		    .vertex_count = barb->count,
		    .unfurl_weight = r->shape->weight[g],
		    .snap = r->barbules->snap[g],
		    .snapped_vertices = r->barbules->snapped[g],
		};
		if (out->snap == PLUME_ZK_SNAP_FULL)
			report->snapped_count++;
		else if (out->snap == PLUME_ZK_SNAP_PARTIAL)
			report->partial_count++;
		else if (out->snap == PLUME_ZK_SNAP_SKIPPED)
			report->unsnapped[report->unsnapped_count++] = k;
	}
	return PLUME_OK;
}

/// A growing text buffer for the summary.
typedef struct text {
	char *data;
	size_t length, capacity;
	bool failed;
} text;

static void text_add(text *t, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void text_add(text *t, const char *format, ...)
{
	if (t->failed)
		return;
	for (;;) {
		va_list args;
		va_start(args, format);
		int n = vsnprintf(t->data != NULL ? t->data + t->length : NULL, t->data != NULL ? t->capacity - t->length : 0,
		                  format, args);
		va_end(args);
		if (n < 0) {
			t->failed = true;
			return;
		}
		if (t->data != NULL && t->length + (size_t)n < t->capacity) {
			t->length += (size_t)n;
			return;
		}
		size_t capacity = t->capacity > 0 ? t->capacity : 512;
		while (capacity <= t->length + (size_t)n)
			capacity *= 2;
		char *data = plume_realloc(t->data, capacity);
		if (data == NULL) {
			t->failed = true;
			return;
		}
		t->data = data;
		t->capacity = capacity;
	}
}

static const char *side_name(plume_side side) { return side == PLUME_SIDE_LEFT ? "left" : "right"; }

/// JSON has no infinity: a time that never came is null.
static void text_time(text *t, const char *key, double value)
{
	if (isfinite(value))
		text_add(t, "\"%s\": %.9g", key, value);
	else
		text_add(t, "\"%s\": null", key);
}

static int set_summary(plume_feather *feather, const plume_zk_report *report, const plume_zk_def *def)
{
	text t = {0};
	text_add(&t, "{\"model\": \"zhang-kanai\", ");
	text_time(&t, "t_end", report->t_end);
	text_add(&t, ", ");
	text_time(&t, "t_curr", report->t_curr);
	text_add(&t, ", \"unfurl_weight\": %.9g, \"barbs\": {\"left\": %d, \"right\": %d}, ", report->unfurl_weight,
	         report->barb_count_side[0], report->barb_count_side[1]);
	text_add(&t, "\"developing\": %d, \"developing_kept\": %s, ", report->developing_count,
	         def->growth_stage < 1.0 ? "true" : "false");
	text_add(&t, "\"emitter_clamp_time\": {");
	text_time(&t, "left", report->clamp_time[0]);
	text_add(&t, ", ");
	text_time(&t, "right", report->clamp_time[1]);
	text_add(&t, "}, \"expansion\": %s", def->expansion ? "true" : "false");
	if (def->expansion) {
		text_add(&t, ", \"snapping\": {\"full\": %d, \"partial\": %d, \"unsnapped\": %d, \"unsnapped_barbs\": [",
		         report->snapped_count, report->partial_count, report->unsnapped_count);
		for (int k = 0; k < report->unsnapped_count; ++k) {
			const plume_zk_barb_report *b = report->barbs + report->unsnapped[k];
			text_add(&t, "%s{\"barb\": %d, \"side\": \"%s\", \"emission_index\": %d}", k > 0 ? ", " : "",
			         b->feather_barb, side_name(b->side), b->index);
		}
		text_add(&t, "]}");
	}
	text_add(&t, "}");
	int result = t.failed ? -1 : plume_feather_set_summary(feather, t.data);
	plume_free(t.data);
	return result;
}

/// A split of a barb the finished feather does not have: refused, where it once gave the feather
/// without the split. The vane that does not end the growth can have fewer than N barbs (its barb
/// N - 1 still developing at t_end). Below stage 1 a split waits for its barb to be emitted: a
/// growth sequence shows it from the frame that has the barb.
static plume_status check_splits(const plume_zk_def *def, const zk_growth *growth, plume_error *err)
{
	if (def->growth_stage < 1.0)
		return PLUME_OK;
	for (int k = 0; k < def->split_count; ++k) {
		const plume_zk_split *split = def->splits + k;
		int count = growth->side_count[split->side];
		if (split->barb >= count)
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "$.splits[%d].barb is %d, but the %s vane has %d barbs (0 to %d): its barb %d is "
			                       "still developing when the growth ends",
			                       k, split->barb, split->side == PLUME_SIDE_LEFT ? "left" : "right", count, count - 1,
			                       count);
	}
	return PLUME_OK;
}

static bool vec_is_finite(plume_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/// Whether every number of the feather that an exporter writes is finite. The growth keeps
/// its times finite, but a speed near zero at I_P gives finite emission times near 1e300
/// and heights v_grow (t_curr - t) (eq. 5) past the largest double.
static bool feather_is_finite(const plume_feather *feather)
{
	for (int i = 0; i < feather->shaft_count; ++i) {
		const plume_shaft_sample *q = feather->shaft + i;
		if (!vec_is_finite(q->position) || !isfinite(q->width) || !isfinite(q->t))
			return false;
	}
	for (int i = 0; i < feather->point_count; ++i)
		if (!vec_is_finite(feather->points[i]) || !vec_is_finite(feather->normals[i]) ||
		    !isfinite(feather->arc_length[i]) || !isfinite(feather->widths[i]) || !isfinite(feather->uv[i].x) ||
		    !isfinite(feather->uv[i].y))
			return false;
	return true;
}

// ---------------------------------------------------------------------------

plume_status plume_zk_generate(const plume_zk_def *def, uint64_t seed, plume_feather **out, plume_zk_report *report,
                               plume_error *err)
{
	*out = NULL;
	if (report != NULL)
		memset(report, 0, sizeof *report);
	plume_status status = plume_zk_def_validate(def, err);
	if (status != PLUME_OK)
		return status;
	zk_collar collar;
	zk_growth growth = {0};
	zk_shape shape = {0};
	zk_barbules barbules = {0};
	plume_zk_report local = {0};
	plume_feather *feather = NULL;
	if ((status = zk_collar_init(&collar, def)) != PLUME_OK)
		return plume_error_set(err, status, "out of memory");
	if ((status = zk_grow(def, &collar, seed, &growth, err)) != PLUME_OK) {
		zk_collar_free(&collar);
		return status;
	}
	if ((status = check_splits(def, &growth, err)) != PLUME_OK) {
		zk_growth_free(&growth);
		zk_collar_free(&collar);
		return status;
	}
	if ((status = zk_unfurl(def, &collar, &growth, &shape)) != PLUME_OK ||
	    (status = zk_expand(def, &growth, &shape, &barbules)) != PLUME_OK)
		goto done;
	zk_result result = {.def = def, .growth = &growth, .shape = &shape, .barbules = &barbules};
	result.base_width =
	    plume_v3_distance(zk_collar_point(&collar, def->anterior[0]), zk_collar_point(&collar, def->anterior[1]));
	if ((status = build_feather(&result, &feather)) != PLUME_OK)
		goto done;
	if (!feather_is_finite(feather)) {
		plume_error_set(err, PLUME_ERROR_SPEC,
		                "the feather's heights overflow: v_grow (t_curr - t) (eq. 5) is not finite with t_end = %g s; "
		                "raise $.emitter_speed where it is slow (at I_P, $.posterior) or lower $.growth_speed",
		                growth.t_end);
		status = PLUME_ERROR_SPEC;
		goto done;
	}
	if ((status = fill_report(&result, &local)) != PLUME_OK)
		goto done;
	if (set_summary(feather, &local, def) != 0) {
		status = PLUME_ERROR_MEMORY;
		goto done;
	}
	*out = feather;
	feather = NULL;
	if (report != NULL) {
		*report = local;
		memset(&local, 0, sizeof local);
	}
done:
	plume_feather_destroy(feather);
	plume_zk_report_free(&local);
	zk_barbules_free(&barbules);
	zk_shape_free(&shape);
	zk_growth_free(&growth);
	zk_collar_free(&collar);
	if (status == PLUME_ERROR_SPEC)
		return status; // the message is set
	if (status != PLUME_OK)
		return plume_error_set(err, status, "out of memory while building a zhang-kanai feather");
	return PLUME_OK;
}

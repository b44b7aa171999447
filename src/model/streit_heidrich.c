// Streit & Heidrich 2002, sections 4.1-4.3: parameters, growth schedule and
// geometry. Key barbs and blending are in streit_heidrich_keys.c, scans in
// streit_heidrich_scan.c.
//
// Geometry (4.3.1): the shaft is a straight calamus of length cl followed by
// the cubic rachis of NOTES.md, cv0 = (0, 0, cl), cv1 = (rvdc rl, rlc rl,
// cl + rl/3), cv2 = (rvdc rl, rlc rl, cl + 2 rl/3), cv3 = (0, 0, cl + rl) in the
// paper's frame (plume's x = rlc rl, y along, z = rvdc rl). Its width falls
// from rw where it meets the calamus to a point at the tip; the calamus runs
// from cwr rw at its base to rw, so the two meet without a step.
//
// Barbs sit along the rachis at spacings from spb to spt. The barb at rachis
// fraction rp takes its control vertices from eq. 1, is translated so cv0 is
// on the rachis, tilted so that cv0 -> cv(n-2) lies in the vane plane, turned
// by its barb angle in that plane, and scaled by its barb length (4.2.1,
// 4.3.1). Curves are drawn as their control polygons after a chosen number of
// degree elevations (4.3.2).
#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/asserts.h"
#include "../core/number_text.h"
#include "../core/alloc.h"
#include "../core/vec_inline.h"
#include "feather_internal.h"
#include "streit_heidrich_internal.h"

#define PI 3.14159265358979323846

// ---------------------------------------------------------------------------
// Defaults

static plume_sh_key_barb straight_key(double position, double bend_y, double bend_z)
{
	plume_sh_key_barb key = {.position = position, .cv_count = 4, .plumulaceous = 0.0};
	key.cvs[0] = plume_v3(0.0, 0.0, 0.0);
	key.cvs[1] = plume_v3(1.0 / 3.0, 0.5 * bend_y, bend_z);
	key.cvs[2] = plume_v3(2.0 / 3.0, bend_y, bend_z);
	key.cvs[3] = plume_v3(1.0, 0.8 * bend_y, 0.0);
	return key;
}

/// An ovate silhouette: barbs short at the base, longest a third of the way up, short at the tip.
static plume_sh_length_profile ovate_profile(double longest)
{
	static const double position[] = {0.0, 0.15, 0.35, 0.6, 0.8, 0.93, 1.0};
	static const double fraction[] = {0.45, 0.85, 1.0, 0.92, 0.7, 0.4, 0.12};
	plume_sh_length_profile profile;
	memset(&profile, 0, sizeof profile);
	profile.count = 7;
	for (int i = 0; i < 7; ++i) {
		profile.position[i] = position[i];
		profile.length[i] = fraction[i] * longest;
	}
	return profile;
}

void sh_default_afterfeather(const plume_sh_params *main, plume_sh_params *after)
{
	memset(after, 0, sizeof *after);
	after->calamus_length = 0.0;
	after->calamus_width_ratio = 1.0;
	after->rachis_length = 0.4 * main->rachis_length;
	after->rachis_width = 0.4 * main->rachis_width;
	after->rachis_side_curvature = 0.0;
	after->rachis_front_curvature = 0.0;
	for (int side = 0; side < 2; ++side) {
		double longest = 0.0;
		for (int i = 0; i < main->barb_length[side].count; ++i)
			longest = fmax(longest, main->barb_length[side].length[i]);
		after->barb_length[side] = ovate_profile(0.5 * longest);
		after->barb_angle[side][0] = main->barb_angle[side][0];
		after->barb_angle[side][1] = main->barb_angle[side][1];
	}
	after->spacing_base = main->spacing_base;
	after->spacing_tip = main->spacing_tip;
	after->key_barb_count = 0; // afterfeathers are always plumulaceous (3.2)
}

plume_sh_params plume_sh_default_afterfeather(const plume_sh_params *main)
{
	plume_sh_params after;
	sh_default_afterfeather(main, &after);
	return after;
}

plume_sh_def plume_sh_default_def(void)
{
	plume_sh_def def;
	memset(&def, 0, sizeof def);
	plume_sh_params *p = &def.main;
	p->calamus_length = 0.012;
	p->calamus_width_ratio = 1.2;
	p->rachis_length = 0.1;
	p->rachis_width = 2e-3;
	p->rachis_side_curvature = 0.04;
	p->rachis_front_curvature = -0.03;
	p->barb_length[0] = ovate_profile(0.035);
	p->barb_length[1] = ovate_profile(0.035);
	for (int side = 0; side < 2; ++side) {
		p->barb_angle[side][0] = 2.4;
		p->barb_angle[side][1] = 2.75;
	}
	p->spacing_base = 8e-4;
	p->spacing_tip = 5e-4;
	p->key_barb_count = 2;
	p->key_barbs[0] = straight_key(0.3, 0.12, -0.05);
	p->key_barbs[1] = straight_key(0.9, 0.04, -0.02);
	def.has_afterfeather = false;
	sh_default_afterfeather(p, &def.afterfeather);
	def.barb_width_base = 1e-4;
	def.barb_width_tip = 2.5e-5;
	def.texture_mode = PLUME_SH_TEXTURE_BARB;
	def.cookie = PLUME_DEF_COOKIE;
	return def;
}

plume_sh_lod plume_sh_default_lod(void)
{
	return (plume_sh_lod){.barb_elevations = 8, .rachis_elevations = 36, .calamus_samples = 4};
}

// ---------------------------------------------------------------------------
// Validation

/// "is value, allowed [lo, hi]", with "(" for a range open at lo (value must be above it).
static plume_status fail_range(plume_error *err, const char *prefix, const char *key, double value, double lo,
                               double hi, bool open_lo)
{
	char text[32];
	return plume_error_set(err, PLUME_ERROR_SPEC, "%s.%s is %s, allowed %c%g, %g]", prefix, key,
	                       plume_number_outside(text, sizeof text, value, lo, hi), open_lo ? '(' : '[', lo, hi);
}

static plume_status check_length(plume_error *err, const char *prefix, const char *key, double value, bool zero_ok)
{
	if (!isfinite(value) || value < 0.0 || (!zero_ok && value == 0.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s.%s is %g, must be a %s length in metres", prefix, key, value,
		                       zero_ok ? "non-negative" : "positive");
	return PLUME_OK;
}

static plume_status check_profile(const plume_sh_length_profile *profile, const char *prefix, const char *key,
                                  plume_error *err)
{
	if (profile->count < 1 || profile->count > PLUME_SH_MAX_PROFILE)
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s.%s has %d points, allowed [1, %d]", prefix, key,
		                       profile->count, PLUME_SH_MAX_PROFILE);
	for (int i = 0; i < profile->count; ++i) {
		double p = profile->position[i], l = profile->length[i];
		char text[32];
		if (profile->count > 1 && !(p >= 0.0 && p <= 1.0))
			return plume_error_set(err, PLUME_ERROR_SPEC, "%s.%s[%d] is at rachis position %s, allowed [0, 1]", prefix,
			                       key, i, plume_number_outside(text, sizeof text, p, 0.0, 1.0));
		if (profile->count > 1 && i > 0 && !(p > profile->position[i - 1]))
			return plume_error_set(err, PLUME_ERROR_SPEC, "%s.%s[%d]: rachis positions must increase (%g follows %g)",
			                       prefix, key, i, p, profile->position[i - 1]);
		// A constant (one value) is a number in the spec, not an array: no index.
		char where[16] = "";
		if (profile->count > 1)
			snprintf(where, sizeof where, "[%d]", i);
		if (!(l >= 0.0 && isfinite(l)))
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "%s.%s%s has length %g, must be a non-negative length in metres", prefix, key, where,
			                       l);
	}
	return PLUME_OK;
}

static plume_status check_key_barb(const plume_sh_key_barb *key, const char *prefix, int index, double previous,
                                   plume_error *err)
{
	char text[32];
	if (!(key->position >= 0.0 && key->position <= 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s.key_barbs[%d].position is %s, allowed [0, 1]", prefix, index,
		                       plume_number_outside(text, sizeof text, key->position, 0.0, 1.0));
	if (key->position < previous)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s.key_barbs[%d].position is %g, below the key barb before it (%g); key barbs go "
		                       "from the base to the tip",
		                       prefix, index, key->position, previous);
	if (key->cv_count < 2 || key->cv_count > PLUME_SH_MAX_CVS)
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s.key_barbs[%d].cvs has %d control vertices, allowed [2, %d]",
		                       prefix, index, key->cv_count, PLUME_SH_MAX_CVS);
	for (int i = 0; i < key->cv_count; ++i)
		if (!isfinite(key->cvs[i].x) || !isfinite(key->cvs[i].y) || !isfinite(key->cvs[i].z))
			return plume_error_set(err, PLUME_ERROR_SPEC, "%s.key_barbs[%d].cvs[%d] is not a finite point", prefix,
			                       index, i);
	if (!(key->plumulaceous >= 0.0 && key->plumulaceous <= 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s.key_barbs[%d].plumulaceous is %s, allowed [0, 1]", prefix,
		                       index, plume_number_outside(text, sizeof text, key->plumulaceous, 0.0, 1.0));
	return PLUME_OK;
}

plume_status sh_params_validate(const plume_sh_params *p, const char *prefix, plume_error *err)
{
	plume_status status;
	if ((status = check_length(err, prefix, "calamus_length", p->calamus_length, true)) != PLUME_OK ||
	    (status = check_length(err, prefix, "rachis_length", p->rachis_length, false)) != PLUME_OK ||
	    (status = check_length(err, prefix, "rachis_width", p->rachis_width, false)) != PLUME_OK ||
	    (status = check_length(err, prefix, "spacing_base", p->spacing_base, false)) != PLUME_OK ||
	    (status = check_length(err, prefix, "spacing_tip", p->spacing_tip, false)) != PLUME_OK)
		return status;
	if (!(p->calamus_width_ratio > 0.0 && p->calamus_width_ratio <= 100.0))
		return fail_range(err, prefix, "calamus_width_ratio", p->calamus_width_ratio, 0.0, 100.0, true);
	if (!(fabs(p->rachis_side_curvature) <= 1.0))
		return fail_range(err, prefix, "rachis_side_curvature", p->rachis_side_curvature, -1.0, 1.0, false);
	if (!(fabs(p->rachis_front_curvature) <= 1.0))
		return fail_range(err, prefix, "rachis_front_curvature", p->rachis_front_curvature, -1.0, 1.0, false);
	static const char *const angle_keys[2][2] = {{"left_base_angle_deg", "left_tip_angle_deg"},
	                                             {"right_base_angle_deg", "right_tip_angle_deg"}};
	for (int side = 0; side < 2; ++side)
		for (int end = 0; end < 2; ++end) {
			double angle = p->barb_angle[side][end];
			char text[32];
			if (!(angle > 0.0 && angle <= PI))
				return plume_error_set(err, PLUME_ERROR_SPEC, "%s.%s is %s, allowed (0, 180]", prefix,
				                       angle_keys[side][end],
				                       plume_number_outside(text, sizeof text, angle * 180.0 / PI, 0.0, 180.0));
		}
	static const char *const length_keys[2] = {"barb_length", "barb_length_right"};
	for (int side = 0; side < 2; ++side)
		if ((status = check_profile(&p->barb_length[side], prefix, length_keys[side], err)) != PLUME_OK)
			return status;
	if (p->key_barb_count < 0 || p->key_barb_count > PLUME_SH_MAX_KEY_BARBS)
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s.key_barbs has %d key barbs, allowed [0, %d]", prefix,
		                       p->key_barb_count, PLUME_SH_MAX_KEY_BARBS);
	double previous = 0.0;
	for (int j = 0; j < p->key_barb_count; ++j) {
		if ((status = check_key_barb(&p->key_barbs[j], prefix, j, previous, err)) != PLUME_OK)
			return status;
		previous = p->key_barbs[j].position;
	}
	// Blending makes the default key barbs explicit; they must fit too.
	int n = p->key_barb_count;
	int effective = n == 0 ? 2 : n + (p->key_barbs[0].position > 0.0) + (p->key_barbs[n - 1].position < 1.0);
	if (effective > PLUME_SH_MAX_KEY_BARBS)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s.key_barbs has %d key barbs; with Bdf1 below and Bdf2 above that is %d, more than %d "
		                       "(put the first at 0 and the last at 1)",
		                       prefix, n, effective, PLUME_SH_MAX_KEY_BARBS);
	return PLUME_OK;
}

plume_status plume_sh_def_validate(const plume_sh_def *def, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	plume_status status = sh_params_validate(&def->main, "$", err);
	if (status == PLUME_OK && def->has_afterfeather)
		status = sh_params_validate(&def->afterfeather, "$.afterfeather", err);
	if (status != PLUME_OK)
		return status;
	if ((status = check_length(err, "$", "barb_width_base", def->barb_width_base, false)) != PLUME_OK ||
	    (status = check_length(err, "$", "barb_width_tip", def->barb_width_tip, false)) != PLUME_OK)
		return status;
	if (def->texture_mode != PLUME_SH_TEXTURE_BARB && def->texture_mode != PLUME_SH_TEXTURE_VANE &&
	    def->texture_mode != PLUME_SH_TEXTURE_GROWTH)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.texture_mode is %d, allowed barb, vane or growth",
		                       (int)def->texture_mode);
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// Growth (4.2.4, Figure 6)

/// What a growth stage changes. The finished feather (stage 1) has every factor 1 and the linear
/// base-to-tip barb angles, computed by the same formulas as any other stage.
typedef struct sh_stage {
	double shaft_scale; ///< lengths and widths of calamus and rachis (first 30%)
	double barb_scale;  ///< barb lengths (30% to 50%)
	double actual;      ///< weight of the actual key barb shapes, barb angles and rachis curvatures (last 20%)
	/// Barb angles: piecewise linear through (position[i], angle[side][i]).
	int angle_count;
	double angle_position[3];
	double angle[2][3];
} sh_stage;

static double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

/// Figure 6's schedule as plume reads it (the figure itself is lost in the text):
/// - [0, 0.3]: shaft length and width from nothing (a thousandth) to full;
/// - [0.3, 0.5]: barb lengths from 0 to full; spacing stays at its full value;
/// - [0.3, 0.8]: the barbs are straight and closed in the sheath; extra straight key barbs at the base and tip
///   have 180 degrees, a third migrates from the tip (at 0.3) to the base (at 0.8) with the barb angle of
///   where it is (between the tip and base angles), and barb angles are linear between the three: the
///   sheath opens from the tip downwards;
/// - [0.8, 1]: the extras are gone; rachis curvatures, key barb shapes (from straight) and barb angles (from
///   180 degrees) go to their actual values.
static sh_stage stage_at(const plume_sh_params *p, double g)
{
	sh_stage s;
	s.shaft_scale = fmax(fmin(g / 0.3, 1.0), 1e-3);
	s.barb_scale = clamp01((g - 0.3) / 0.2);
	if (g < 0.8) {
		double migrating = clamp01(1.0 - (g - 0.3) / 0.5);
		s.actual = 0.0;
		s.angle_count = 3;
		s.angle_position[0] = 0.0;
		s.angle_position[1] = migrating;
		s.angle_position[2] = 1.0;
		for (int side = 0; side < 2; ++side) {
			s.angle[side][0] = PI;
			s.angle[side][1] = sh_barb_angle(p, (plume_side)side, migrating);
			s.angle[side][2] = PI;
		}
	} else {
		double w = clamp01((g - 0.8) / 0.2);
		s.actual = w;
		s.angle_count = 2;
		s.angle_position[0] = 0.0;
		s.angle_position[1] = 1.0;
		for (int side = 0; side < 2; ++side) {
			s.angle[side][0] = (1.0 - w) * PI + w * p->barb_angle[side][0];
			s.angle[side][1] = (1.0 - w) * PI + w * p->barb_angle[side][1];
		}
	}
	return s;
}

static double stage_angle(const sh_stage *s, plume_side side, double rp)
{
	int i = 0;
	while (i + 2 < s->angle_count && s->angle_position[i + 1] <= rp)
		++i;
	double gap = s->angle_position[i + 1] - s->angle_position[i];
	double t = gap > 0.0 ? clamp01((rp - s->angle_position[i]) / gap) : 1.0;
	return (1.0 - t) * s->angle[side][i] + t * s->angle[side][i + 1];
}

// ---------------------------------------------------------------------------
// Barb positions (4.3.1: "computed as a function of rachis length rl and the barb spacing spb, spt")

/// Positions (arc length from the rachis base) of the barbs of a rachis of length L whose spacing grows
/// linearly from spb to spt: barb k sits where the barb density 1 / spacing integrates to k + 1/2, and
/// the count is that integral over the whole rachis, rounded. Returns the count, or -1 when it is above
/// max; writes the positions when out is not NULL.
static int barb_positions(double length, double spb, double spt, double *out, int max)
{
	double slope = (spt - spb) / length;
	double total = fabs(slope) < 1e-12 ? length / spb : log1p(slope * length / spb) / slope;
	// Compared as a double first: a count beyond int's range (a 1500 km rachis, found by
	// fuzz/feather_spec) must not be converted.
	double rounded = floor(total + 0.5);
	if (!(rounded <= max))
		return -1;
	int count = (int)rounded;
	for (int k = 0; k < count && out != NULL; ++k) {
		double n = k + 0.5;
		out[k] = fabs(slope) < 1e-12 ? n * spb : spb * expm1(slope * n) / slope;
	}
	return count;
}

// ---------------------------------------------------------------------------
// Generation

// ---------------------------------------------------------------------------
// Arc length of the cubic rachis. Barbs sit at arc-length fractions; plume_bezier_arc's 256 intervals are
// more than a cubic needs and, per feather of a 10,000-feather coat, cost more than its barbs. 32 intervals
// of 8-point Gauss-Legendre integrate |B'| (the root of a quartic, smooth) to about 1e-15 relative here, and
// Newton's method on s(t) = target inverts it.

#define RACHIS_INTERVALS 32

typedef struct rachis_arc {
	plume_vec3 hodograph[3];
	double cumulative[RACHIS_INTERVALS + 1]; ///< length from 0 to t = j / intervals
	double length;
} rachis_arc;

static double rachis_speed(const rachis_arc *arc, double t)
{
	return core_v3_length(core_bezier_quadratic(arc->hodograph, t));
}

/// Length between t0 and t1 by 8-point Gauss-Legendre.
static double rachis_piece(const rachis_arc *arc, double t0, double t1)
{
	static const double node[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
	static const double weight[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
	double half = 0.5 * (t1 - t0), middle = 0.5 * (t0 + t1), sum = 0.0;
	for (int i = 0; i < 4; ++i)
		sum += weight[i] * (rachis_speed(arc, middle - half * node[i]) + rachis_speed(arc, middle + half * node[i]));
	return half * sum;
}

static void rachis_arc_init(rachis_arc *arc, const plume_vec3 *rachis)
{
	plume_bezier_hodograph(rachis, 4, arc->hodograph);
	arc->cumulative[0] = 0.0;
	for (int j = 0; j < RACHIS_INTERVALS; ++j)
		arc->cumulative[j + 1] =
		    arc->cumulative[j] + rachis_piece(arc, (double)j / RACHIS_INTERVALS, (double)(j + 1) / RACHIS_INTERVALS);
	arc->length = arc->cumulative[RACHIS_INTERVALS];
}

/// Parameter where the arc length from 0 is fraction * length.
static double rachis_arc_param(const rachis_arc *arc, double fraction)
{
	double target = fraction * arc->length;
	if (fraction <= 0.0)
		return 0.0;
	if (fraction >= 1.0)
		return 1.0;
	int lo = 0, hi = RACHIS_INTERVALS;
	while (hi - lo > 1) {
		int mid = (lo + hi) / 2;
		if (arc->cumulative[mid] <= target)
			lo = mid;
		else
			hi = mid;
	}
	double t0 = (double)lo / RACHIS_INTERVALS, t1 = (double)hi / RACHIS_INTERVALS;
	double piece = arc->cumulative[hi] - arc->cumulative[lo];
	double t = piece > 0.0 ? t0 + (t1 - t0) * (target - arc->cumulative[lo]) / piece : t0;
	for (int iteration = 0; iteration < 8; ++iteration) {
		double speed = rachis_speed(arc, t);
		if (!(speed > 0.0))
			break;
		double step = (arc->cumulative[lo] + rachis_piece(arc, t0, t) - target) / speed;
		t = fmin(fmax(t - step, t0), t1);
		if (fabs(step) < 1e-15)
			break;
	}
	return t;
}

typedef struct sh_builder {
	const plume_sh_def *def;
	const plume_sh_params *params;
	const plume_sh_lod *lod;
	sh_stage stage;
	sh_key_list keys;
	sh_bdf1_table table;
	plume_vec3 rachis[4];
	rachis_arc rachis_arc;
	double calamus_length, rachis_width, shaft_length;
	double longest_barb; ///< m, for the vane texture mode
} sh_builder;

static const plume_vec3 front = {0.0, 0.0, 1.0};

/// Unit tangent of the rachis at parameter u: the normalized hodograph (the rachis arc's own copy of it).
static plume_vec3 rachis_tangent(const sh_builder *b, double u)
{
	return core_v3_normalize(core_bezier_quadratic(b->rachis_arc.hodograph, u));
}

/// Unit front normal at a shaft point: +z made perpendicular to the tangent.
static plume_vec3 front_normal(plume_vec3 tangent)
{
	plume_vec3 n = core_v3_normalize(plume_v3_mad(front, -plume_v3_dot(front, tangent), tangent));
	return n.x == 0.0 && n.y == 0.0 && n.z == 0.0 ? plume_v3(1.0, 0.0, 0.0) : n;
}

static plume_status build_shaft(plume_feather *feather, sh_builder *b)
{
	const plume_sh_params *p = b->params;
	int calamus = b->calamus_length > 0.0 ? b->lod->calamus_samples : 1;
	int rachis = 4 + b->lod->rachis_elevations;
	if (rachis > PLUME_BEZIER_MAX_POINTS)
		rachis = PLUME_BEZIER_MAX_POINTS;
	plume_vec3 polygon[PLUME_BEZIER_MAX_POINTS];
	memcpy(polygon, b->rachis, sizeof b->rachis);
	sh_elevate_to(polygon, 4, rachis);
	int count = calamus + rachis - 1; // the rachis's first control vertex is the calamus's last sample
	plume_shaft_sample *shaft = plume_feather_add_shaft(feather, count);
	if (shaft == NULL)
		return PLUME_ERROR_MEMORY;
	double base_width = p->calamus_width_ratio * b->rachis_width;
	for (int i = 0; i < calamus; ++i) {
		double f = calamus > 1 ? (double)i / (calamus - 1) : 1.0;
		shaft[i].position = plume_v3(0.0, f * b->calamus_length, 0.0);
		shaft[i].tangent = plume_v3(0.0, 1.0, 0.0);
		shaft[i].width = (1.0 - f) * base_width + f * b->rachis_width;
	}
	// The rachis polygon's point i sits over the curve's Greville parameter i / degree: the tangent there.
	double rachis_run = 0.0;
	double run[PLUME_BEZIER_MAX_POINTS];
	run[0] = 0.0;
	for (int i = 1; i < rachis; ++i)
		run[i] = rachis_run += plume_v3_distance(polygon[i - 1], polygon[i]);
	for (int i = 1; i < rachis; ++i) {
		plume_shaft_sample *s = shaft + calamus - 1 + i;
		s->position = polygon[i];
		s->tangent = rachis_tangent(b, (double)i / (rachis - 1));
		double f = rachis_run > 0.0 ? run[i] / rachis_run : 1.0;
		s->width = (1.0 - f) * b->rachis_width; // the rachis tip forms a point (4.1)
	}
	shaft[calamus - 1].tangent = rachis_tangent(b, 0.0);
	double total = 0.0;
	for (int i = 0; i < count; ++i) {
		plume_shaft_sample *s = shaft + i;
		if (i > 0)
			total += plume_v3_distance(shaft[i - 1].position, s->position);
		s->t = total;
		s->normal = front_normal(s->tangent);
		s->binormal = plume_v3_cross(s->normal, s->tangent);
	}
	for (int i = 0; i < count; ++i)
		shaft[i].t = total > 0.0 ? shaft[i].t / total : 0.0;
	shaft[count - 1].t = 1.0;
	feather->calamus_count = calamus;
	return PLUME_OK;
}

/// Tilts cvs (cv0 at the origin) about an axis in the vane plane so that cv0 -> cv(n-2) lies in the vane
/// plane z = 0 (4.3.1); for barbs of fewer than four control vertices, cv0 -> cvn.
static void tilt_into_plane(plume_vec3 *cvs, int count)
{
	int n = count - 1;
	plume_vec3 d = cvs[n - 2 >= 1 ? n - 2 : n];
	plume_vec3 flat = plume_v3(d.x, d.y, 0.0);
	plume_vec3 axis = plume_v3_cross(d, flat);
	double axis_length = core_v3_length(axis);
	if (!(axis_length > 1e-15) || core_v3_length(flat) == 0.0)
		return;
	double angle = atan2(axis_length, plume_v3_dot(d, flat));
	plume_mat3 rotation = core_m3_rotation_cs(plume_v3_scale(axis, 1.0 / axis_length), cos(angle), sin(angle));
	for (int i = 1; i < count; ++i)
		cvs[i] = core_m3_apply(&rotation, cvs[i]);
}

/// The frame where a barb meets the rachis: T along the rachis, N to the front, B = N x T towards the left
/// vane. Both vanes' barbs k share it.
typedef struct sh_root {
	plume_vec3 position, tangent, normal, binormal;
} sh_root;

static sh_root root_at(const sh_builder *b, double rp)
{
	double u = rachis_arc_param(&b->rachis_arc, rp);
	sh_root r = {.position = core_bezier_cubic(b->rachis, u), .tangent = rachis_tangent(b, u)};
	r.normal = front_normal(r.tangent);
	r.binormal = plume_v3_cross(r.normal, r.tangent);
	return r;
}

/// Appends the barb at arc length s along the rachis on one side, rooted at r (at rp).
static plume_status build_barb(plume_feather *feather, sh_builder *b, plume_side side, double rp, int index,
                               double rachis_arc_length, const sh_root *r)
{
	const plume_sh_params *p = b->params;
	double length = b->stage.barb_scale * sh_profile_eval(&p->barb_length[side], rp);
	if (!(length > 0.0))
		return PLUME_OK; // a barb without length is no barb (a silhouette's zero, or growth before 30%)
	plume_vec3 cvs[PLUME_BEZIER_MAX_POINTS];
	int count = sh_barb_cvs(&b->keys, &b->table, rp, index + (int)side * PLUME_SH_MAX_BARBS, cvs);
	// Growth: key barbs straighten out of the sheath in the last 20% (sh_stage.actual).
	if (b->stage.actual < 1.0) {
		for (int i = 0; i < count; ++i) {
			plume_vec3 straight = plume_v3((double)i / (count - 1), 0.0, 0.0);
			cvs[i] =
			    plume_v3_add(plume_v3_scale(straight, 1.0 - b->stage.actual), plume_v3_scale(cvs[i], b->stage.actual));
		}
	}
	plume_vec3 origin = cvs[0];
	for (int i = 0; i < count; ++i)
		cvs[i] = plume_v3_sub(cvs[i], origin);
	tilt_into_plane(cvs, count);

	plume_vec3 root = r->position, tangent = r->tangent, normal = r->normal, binormal = r->binormal;
	double angle = stage_angle(&b->stage, side, rp);
	double outward = side == PLUME_SIDE_LEFT ? 1.0 : -1.0;
	plume_vec3 along =
	    plume_v3_add(plume_v3_scale(tangent, -cos(angle)), plume_v3_scale(binormal, outward * sin(angle)));
	plume_vec3 across = side == PLUME_SIDE_LEFT ? plume_v3_cross(along, normal) : plume_v3_cross(normal, along);
	for (int i = 0; i < count; ++i) {
		plume_vec3 c = cvs[i];
		plume_vec3 offset = plume_v3_add(plume_v3_add(plume_v3_scale(along, c.x), plume_v3_scale(across, c.y)),
		                                 plume_v3_scale(normal, c.z));
		cvs[i] = plume_v3_mad(root, length, offset);
	}
	int points = count + b->lod->barb_elevations;
	if (points > PLUME_BEZIER_MAX_POINTS)
		points = PLUME_BEZIER_MAX_POINTS;
	sh_elevate_to(cvs, count, points);

	int first = plume_feather_append_points(feather, points);
	if (first < 0)
		return PLUME_ERROR_MEMORY;
	double rachis_t = (b->calamus_length + rachis_arc_length) / b->shaft_length;
	for (int i = 0; i < points; ++i) {
		feather->points[first + i] = cvs[i];
		feather->normals[first + i] = normal;
	}
	plume_curve_range range = {first, points};
	plume_feather_measure_curve(feather, range);
	const plume_sh_def *def = b->def;
	for (int i = 0; i < points; ++i) {
		double s = feather->uv[first + i].x;
		feather->widths[first + i] = (1.0 - s) * def->barb_width_base + s * def->barb_width_tip;
		plume_vec2 *uv = &feather->uv[first + i];
		switch (def->texture_mode) {
		case PLUME_SH_TEXTURE_BARB: uv->y = rachis_t; break;
		case PLUME_SH_TEXTURE_VANE: {
			// Ignoring rachis curvature: distance from the rachis and height along it in the root's frame.
			plume_vec3 offset = plume_v3_sub(cvs[i], root);
			double height = rachis_arc_length + plume_v3_dot(offset, tangent);
			double total = b->rachis_arc.length;
			uv->x = b->longest_barb > 0.0 ? clamp01(fabs(plume_v3_dot(offset, binormal)) / b->longest_barb) : 0.0;
			uv->y = total > 0.0 ? clamp01(height / total) : 0.0;
			break;
		}
		case PLUME_SH_TEXTURE_GROWTH:
			// s: around the sheath (the barb's arc fraction); t: filled in by growth_texture once all barbs exist.
			uv->y = rachis_arc_length + feather->arc_length[first + i];
			break;
		}
	}
	plume_barb_record record = {
	    .curve = range,
	    .side = side,
	    .rachis_t = rachis_t,
	    .segment = 0,
	    .barbule_first = 0,
	    .barbule_count = 0,
	};
	return plume_feather_add_barb(feather, &record) < 0 ? PLUME_ERROR_MEMORY : PLUME_OK;
}

/// Growth texture mode: t is the time a point left the collar. In the closed sheath a barb point lies its
/// arc length above its root; the sheath's tip is the oldest, so t = 1 - position / the highest position.
static void growth_texture(plume_feather *feather)
{
	double highest = 0.0;
	for (int i = 0; i < feather->point_count; ++i)
		highest = fmax(highest, feather->uv[i].y);
	for (int i = 0; i < feather->point_count; ++i)
		feather->uv[i].y = highest > 0.0 ? 1.0 - feather->uv[i].y / highest : 0.0;
}

static plume_status build_feather(const plume_sh_def *def, const plume_sh_params *params, uint64_t seed, double stage,
                                  const plume_sh_lod *lod, plume_feather **out, plume_error *err);

/// Builds one feather (main or afterfeather) from its parameters.
static plume_status build_feather(const plume_sh_def *def, const plume_sh_params *params, uint64_t seed, double stage,
                                  const plume_sh_lod *lod, plume_feather **out, plume_error *err)
{
	*out = NULL;
	sh_builder *b = plume_alloc(sizeof *b);
	double *positions = NULL;
	sh_root *roots = NULL;
	plume_feather *feather = plume_feather_create_empty();
	plume_status status = PLUME_OK;
	if (b == NULL || feather == NULL) {
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory while generating a feather");
		goto done;
	}
	b->def = def;
	b->params = params;
	b->lod = lod;
	b->stage = stage_at(params, stage);
	sh_key_list_build(params, &b->keys);
	sh_bdf1_table_init(&b->table, seed);
	b->calamus_length = b->stage.shaft_scale * params->calamus_length;
	b->rachis_width = b->stage.shaft_scale * params->rachis_width;
	double rl = b->stage.shaft_scale * params->rachis_length;
	double side_bend = b->stage.actual * params->rachis_side_curvature * rl;
	double front_bend = b->stage.actual * params->rachis_front_curvature * rl;
	double cl = b->calamus_length;
	// NOTES.md's rachis control vertices, in plume's frame (x side-to-side, y along, z front-to-back).
	b->rachis[0] = plume_v3(0.0, cl, 0.0);
	b->rachis[1] = plume_v3(side_bend, cl + rl / 3.0, front_bend);
	b->rachis[2] = plume_v3(side_bend, cl + 2.0 * rl / 3.0, front_bend);
	b->rachis[3] = plume_v3(0.0, cl + rl, 0.0);
	rachis_arc_init(&b->rachis_arc, b->rachis);
	b->shaft_length = cl + b->rachis_arc.length;
	b->longest_barb = 0.0;
	for (int side = 0; side < 2; ++side)
		for (int i = 0; i < params->barb_length[side].count; ++i)
			b->longest_barb = fmax(b->longest_barb, b->stage.barb_scale * params->barb_length[side].length[i]);

	int count =
	    barb_positions(b->rachis_arc.length, params->spacing_base, params->spacing_tip, NULL, PLUME_SH_MAX_BARBS);
	if (count < 0) {
		status = plume_error_set(err, PLUME_ERROR_SPEC,
		                         "the barb spacing (spacing_base %g m, spacing_tip %g m) puts more than %d barbs on a "
		                         "vane along a rachis of arc length %g m (rachis_length %g m); widen the spacing or "
		                         "shorten the rachis",
		                         params->spacing_base, params->spacing_tip, PLUME_SH_MAX_BARBS, b->rachis_arc.length,
		                         params->rachis_length);
		goto done;
	}
	// One reservation, exact enough: no barb has more control vertices than the widest key barb (four when
	// Bdf1's table takes part), plus the elevations.
	int points_per_barb = 2;
	for (int j = 0; j < b->keys.count; ++j) {
		int cvs = b->keys.keys[j].cv_count;
		if (b->keys.keys[j].plumulaceous > 0.0 && cvs < 4)
			cvs = 4;
		if (cvs > points_per_barb)
			points_per_barb = cvs;
	}
	points_per_barb += lod->barb_elevations;
	if (points_per_barb > PLUME_BEZIER_MAX_POINTS)
		points_per_barb = PLUME_BEZIER_MAX_POINTS;
	// Barb k of either vane sits at positions[k] along the rachis, on roots[k].
	positions = plume_alloc((size_t)(count > 0 ? count : 1) * sizeof *positions);
	roots = plume_alloc((size_t)(count > 0 ? count : 1) * sizeof *roots);
	if (positions == NULL || roots == NULL || plume_feather_reserve_points(feather, 2 * count * points_per_barb) != 0 ||
	    build_shaft(feather, b) != PLUME_OK) {
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory while generating a feather");
		goto done;
	}
	barb_positions(b->rachis_arc.length, params->spacing_base, params->spacing_tip, positions, count);
	for (int k = 0; k < count; ++k)
		roots[k] = root_at(b, positions[k] / b->rachis_arc.length);
	for (int side = 0; side < 2 && status == PLUME_OK; ++side)
		for (int k = 0; k < count && status == PLUME_OK; ++k)
			status = build_barb(feather, b, (plume_side)side, positions[k] / b->rachis_arc.length, k, positions[k],
			                    roots + k);
	if (status != PLUME_OK) {
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory while generating a feather");
		goto done;
	}
	if (def->texture_mode == PLUME_SH_TEXTURE_GROWTH)
		growth_texture(feather);
	*out = feather;
	feather = NULL;
done:
	plume_feather_destroy(feather);
	plume_free(roots);
	plume_free(positions);
	plume_free(b);
	return status;
}

/// Moves every point of a feather by offset.
static void translate_feather(plume_feather *feather, plume_vec3 offset)
{
	for (int i = 0; i < feather->shaft_count; ++i)
		feather->shaft[i].position = plume_v3_add(feather->shaft[i].position, offset);
	for (int i = 0; i < feather->point_count; ++i)
		feather->points[i] = plume_v3_add(feather->points[i], offset);
}

static plume_status check_lod(const plume_sh_lod *lod, plume_error *err)
{
	if (lod->barb_elevations < 0 || lod->barb_elevations > 60)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.lod.barb_elevations is %d, allowed [0, 60]",
		                       lod->barb_elevations);
	if (lod->rachis_elevations < 0 || lod->rachis_elevations > 60)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.lod.rachis_elevations is %d, allowed [0, 60]",
		                       lod->rachis_elevations);
	if (lod->calamus_samples < 2 || lod->calamus_samples > 64)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.lod.calamus_samples is %d, allowed [2, 64]",
		                       lod->calamus_samples);
	return PLUME_OK;
}

/// Barbs, points and shaft samples of one feather of plume_sh_estimate_bytes, added to counts[3].
static void sh_estimate_feather(const plume_sh_params *p, const plume_sh_lod *lod, double counts[3])
{
	// build_feather's rachis: cl + [0, rl] with the bends rlc rl and rvdc rl at the inner control vertices,
	// scaled down (never up) by the growth stage.
	double rl = p->rachis_length;
	double bend = sqrt(rl * rl / 9.0 + pow(p->rachis_side_curvature * rl, 2) + pow(p->rachis_front_curvature * rl, 2));
	double polygon = 2.0 * bend + rl / 3.0;
	// barb_positions: barb k where the density 1 / spacing integrates to k + 1/2.
	double barbs = fmin(PLUME_SH_MAX_BARBS, polygon / fmin(p->spacing_base, p->spacing_tip) + 1.0);
	int cvs = 4;
	for (int j = 0; j < p->key_barb_count && j < PLUME_SH_MAX_KEY_BARBS; ++j)
		if (p->key_barbs[j].cv_count > cvs)
			cvs = p->key_barbs[j].cv_count;
	double per_barb = fmin(PLUME_BEZIER_MAX_POINTS, (double)cvs + lod->barb_elevations);
	counts[0] += 2.0 * barbs;
	counts[1] += 2.0 * barbs * per_barb;
	counts[2] += (double)lod->calamus_samples + 4.0 + lod->rachis_elevations;
}

double plume_sh_estimate_bytes(const plume_sh_def *def, const plume_sh_lod *lod)
{
	plume_sh_lod default_lod = plume_sh_default_lod();
	if (lod == NULL)
		lod = &default_lod;
	double counts[3] = {0.0, 0.0, 0.0}; // barbs, points, shaft samples
	sh_estimate_feather(&def->main, lod, counts);
	if (def->has_afterfeather)
		sh_estimate_feather(&def->afterfeather, lod, counts);
	return plume_feather_layout_bytes(counts[1], counts[0], 0.0, counts[2]);
}

plume_status plume_sh_generate_lod(const plume_sh_def *def, uint64_t seed, double stage, const plume_sh_lod *lod,
                                   plume_feather **out, plume_error *err)
{
	*out = NULL;
	plume_sh_lod default_lod = plume_sh_default_lod();
	if (lod == NULL)
		lod = &default_lod;
	plume_status status = plume_sh_def_validate(def, err);
	if (status != PLUME_OK || (status = check_lod(lod, err)) != PLUME_OK)
		return status;
	if (!(stage >= 0.0 && stage <= 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "growth stage is %g, allowed [0, 1]", stage);
	plume_feather *feather = NULL;
	if ((status = build_feather(def, &def->main, seed, stage, lod, &feather, err)) != PLUME_OK)
		return status;
	if (def->has_afterfeather) {
		// The afterfeather grows from the underside where the calamus meets the rachis (3.1): its base sits
		// on the back of the shaft there, half the shaft's width behind the centre line.
		plume_rng rng = plume_rng_seed(seed);
		uint64_t after_seed = plume_rng_next(&rng);
		plume_feather *after = NULL;
		status = build_feather(def, &def->afterfeather, after_seed, stage, lod, &after, err);
		if (status != PLUME_OK) {
			plume_feather_destroy(feather);
			return status;
		}
		const plume_shaft_sample *junction = &feather->shaft[feather->calamus_count - 1];
		translate_feather(after, plume_v3_mad(junction->position, -0.5 * junction->width, junction->normal));
		feather->afterfeather = after;
		feather->afterfeather_t = junction->t;
	}
	*out = feather;
	return PLUME_OK;
}

plume_status plume_sh_generate(const plume_sh_def *def, uint64_t seed, double stage, plume_feather **out,
                               plume_error *err)
{
	return plume_sh_generate_lod(def, seed, stage, NULL, out, err);
}

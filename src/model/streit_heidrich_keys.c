// Streit & Heidrich 4.2.1 and 4.2.3: key barbs, the default key barbs Bdf1 and
// Bdf2, interpolation of intermediate barbs (eq. 1) with degree elevation, and
// the blending of feather types.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/asserts.h"
#include "../core/alloc.h"
#include "../core/vec_inline.h"
#include "streit_heidrich_internal.h"

/// Most feathers one blend takes.
#define MAX_BLEND 64

// ---------------------------------------------------------------------------
// Default key barbs

void sh_bdf1_table_init(sh_bdf1_table *table, uint64_t seed)
{
	// Bdf1 (4.2.1, 4.3.1): "four randomly generated control vertices", from a
	// table precomputed once per seed so that every frame of a growth sequence
	// draws the same plumulaceous barbs. The draws give short, curly barbs
	// that leave the rachis outwards and wander in and out of the vane plane.
	plume_rng rng = plume_rng_seed(seed ^ 0x5bd1e995b0f1ULL);
	for (int k = 0; k < SH_BDF1_TABLE; ++k) {
		double reach = plume_rng_range(&rng, 0.55, 0.95);
		double heading = plume_rng_range(&rng, -0.45, 0.45);
		double lift = plume_rng_range(&rng, -0.25, 0.25);
		plume_vec3 end =
		    plume_v3(reach * cos(heading) * cos(lift), reach * sin(heading) * cos(lift), reach * sin(lift));
		plume_vec3 *cvs = table->cvs[k];
		cvs[0] = plume_v3(0.0, 0.0, 0.0);
		for (int i = 1; i <= 2; ++i) {
			plume_vec3 on_chord = plume_v3_scale(end, i / 3.0);
			plume_vec3 wiggle = plume_v3(plume_rng_range(&rng, -0.1, 0.1), plume_rng_range(&rng, -0.35, 0.35),
			                             plume_rng_range(&rng, -0.3, 0.3));
			cvs[i] = plume_v3_add(on_chord, wiggle);
		}
		cvs[3] = end;
	}
}

/// Bdf2 (4.2.1): a straight barb with slight front-to-back curvature (towards the back, as vanes curve
/// into the bird's surface).
static plume_sh_key_barb bdf2_at(double position)
{
	plume_sh_key_barb key = {.position = position, .cv_count = 4, .plumulaceous = 0.0};
	key.cvs[0] = plume_v3(0.0, 0.0, 0.0);
	key.cvs[1] = plume_v3(1.0 / 3.0, 0.0, -0.06);
	key.cvs[2] = plume_v3(2.0 / 3.0, 0.0, -0.06);
	key.cvs[3] = plume_v3(1.0, 0.0, 0.0);
	return key;
}

/// Bdf1 as a key of the list: zero control vertices and the whole weight on the barb's table entry.
static plume_sh_key_barb bdf1_at(double position)
{
	plume_sh_key_barb key = {.position = position, .cv_count = 4, .plumulaceous = 1.0};
	for (int i = 0; i < 4; ++i)
		key.cvs[i] = plume_v3(0.0, 0.0, 0.0);
	return key;
}

/// 4.1: "The Euclidean distance between cv0 and cvn is clamped to [0, 1]": a longer key barb is scaled
/// back about cv_0 to distance 1.
static void clamp_key(plume_sh_key_barb *key)
{
	double distance = plume_v3_distance(key->cvs[0], key->cvs[key->cv_count - 1]);
	if (distance <= 1.0)
		return;
	for (int i = 1; i < key->cv_count; ++i)
		key->cvs[i] = plume_v3_add(key->cvs[0], plume_v3_scale(plume_v3_sub(key->cvs[i], key->cvs[0]), 1.0 / distance));
}

void sh_key_list_build(const plume_sh_params *params, sh_key_list *list)
{
	list->count = 0;
	int n = params->key_barb_count;
	// 4.2.1: Bdf1 below the lowest key barb (and everywhere when there is none), Bdf2 above the highest.
	if (n == 0 || params->key_barbs[0].position > 0.0)
		list->keys[list->count++] = bdf1_at(0.0);
	for (int j = 0; j < n; ++j) {
		list->keys[list->count] = params->key_barbs[j];
		clamp_key(&list->keys[list->count]);
		list->count++;
	}
	if (n == 0)
		list->keys[list->count++] = bdf1_at(1.0);
	else if (params->key_barbs[n - 1].position < 1.0)
		list->keys[list->count++] = bdf2_at(1.0);
}

// ---------------------------------------------------------------------------
// Interpolation

void sh_elevate_to(plume_vec3 *cvs, int count, int target)
{
	// Degree elevation n -> n + 1 (4.2.1, NOTES.md) as often as needed; the curve does not move.
	for (int c = count; c < target; ++c)
		core_bezier_elevate(cvs, c, cvs);
}

/// Index i of the interval [keys[i], keys[i + 1]] holding rp.
static int find_interval(const sh_key_list *list, double rp)
{
	int i = 0;
	while (i + 2 < list->count && list->keys[i + 1].position <= rp)
		++i;
	return i;
}

int sh_barb_cvs(const sh_key_list *list, const sh_bdf1_table *table, double rp, int barb_index, plume_vec3 *cvs)
{
	int i = find_interval(list, rp);
	const plume_sh_key_barb *below = &list->keys[i], *above = &list->keys[i + 1];
	int count = below->cv_count > above->cv_count ? below->cv_count : above->cv_count;
	double gap = above->position - below->position;
	// Eq. 1 as printed weights B_a by (1 - t) with t = (rp - B_b.rp) / (B_a.rp - B_b.rp), which would give
	// the key barb above at the position of the one below. plume weights the key barb below by (1 - t), the
	// reading under which every key barb is returned exactly at its own position (the requirement).
	double t = gap > 0.0 ? (rp - below->position) / gap : 1.0;
	if (t < 0.0)
		t = 0.0;
	if (t > 1.0)
		t = 1.0;
	double rho = (1.0 - t) * below->plumulaceous + t * above->plumulaceous;
	if (rho > 0.0 && count < 4)
		count = 4;
	plume_vec3 a[PLUME_SH_MAX_CVS], b[PLUME_SH_MAX_CVS];
	memcpy(a, below->cvs, (size_t)below->cv_count * sizeof *a);
	memcpy(b, above->cvs, (size_t)above->cv_count * sizeof *b);
	sh_elevate_to(a, below->cv_count, count);
	sh_elevate_to(b, above->cv_count, count);
	for (int k = 0; k < count; ++k)
		cvs[k] = plume_v3_add(plume_v3_scale(a[k], 1.0 - t), plume_v3_scale(b[k], t));
	if (rho > 0.0) {
		// Bdf1's share: this barb's own random table entry, elevated to the barb's degree.
		unsigned entry = (unsigned)(((uint64_t)(unsigned)barb_index * 2654435761u) % SH_BDF1_TABLE);
		plume_vec3 random[PLUME_SH_MAX_CVS];
		memcpy(random, table->cvs[entry], 4 * sizeof *random);
		sh_elevate_to(random, 4, count);
		for (int k = 0; k < count; ++k)
			cvs[k] = plume_v3_mad(cvs[k], rho, random[k]);
	}
	return count;
}

int plume_sh_barb_cvs(const plume_sh_params *params, uint64_t seed, double rp, int barb_index, plume_vec3 *cvs)
{
	sh_key_list list;
	sh_bdf1_table table;
	sh_key_list_build(params, &list);
	sh_bdf1_table_init(&table, seed);
	return sh_barb_cvs(&list, &table, rp, barb_index, cvs);
}

// ---------------------------------------------------------------------------
// Profiles and angles

double sh_profile_eval(const plume_sh_length_profile *profile, double rp)
{
	int n = profile->count;
	if (n <= 1 || rp <= profile->position[0])
		return profile->length[0];
	if (rp >= profile->position[n - 1])
		return profile->length[n - 1];
	int i = 0;
	while (i + 2 < n && profile->position[i + 1] <= rp)
		++i;
	double t = (rp - profile->position[i]) / (profile->position[i + 1] - profile->position[i]);
	return (1.0 - t) * profile->length[i] + t * profile->length[i + 1];
}

plume_sh_length_profile sh_profile_constant(double length)
{
	plume_sh_length_profile profile;
	memset(&profile, 0, sizeof profile);
	profile.count = 1;
	profile.length[0] = length;
	return profile;
}

double sh_barb_angle(const plume_sh_params *params, plume_side side, double rp)
{
	// 4.1: "The barb angle is then linearly interpolated at run-time."
	return (1.0 - rp) * params->barb_angle[side][0] + rp * params->barb_angle[side][1];
}

// ---------------------------------------------------------------------------
// Feather types (4.2.3)

/// Inserts key barbs into the largest gaps of list until it has target keys. Each new key barb is what
/// the list's own interpolation gives at the gap's middle (with Bdf1's share kept as a weight), so the
/// feather it generates does not change: eq. 1 is linear between neighbouring key barbs.
static void inflate(sh_key_list *list, int target)
{
	while (list->count < target) {
		int widest = 0;
		double widest_gap = -1.0;
		for (int i = 0; i + 1 < list->count; ++i) {
			double gap = list->keys[i + 1].position - list->keys[i].position;
			if (gap > widest_gap) {
				widest_gap = gap;
				widest = i;
			}
		}
		const plume_sh_key_barb *below = &list->keys[widest], *above = &list->keys[widest + 1];
		plume_sh_key_barb middle = {.position = 0.5 * (below->position + above->position)};
		int count = below->cv_count > above->cv_count ? below->cv_count : above->cv_count;
		plume_vec3 a[PLUME_SH_MAX_CVS], b[PLUME_SH_MAX_CVS];
		memcpy(a, below->cvs, (size_t)below->cv_count * sizeof *a);
		memcpy(b, above->cvs, (size_t)above->cv_count * sizeof *b);
		sh_elevate_to(a, below->cv_count, count);
		sh_elevate_to(b, above->cv_count, count);
		middle.cv_count = count;
		for (int k = 0; k < count; ++k)
			middle.cvs[k] = plume_v3_add(plume_v3_scale(a[k], 0.5), plume_v3_scale(b[k], 0.5));
		middle.plumulaceous = 0.5 * (below->plumulaceous + above->plumulaceous);
		memmove(&list->keys[widest + 2], &list->keys[widest + 1],
		        (size_t)(list->count - widest - 1) * sizeof list->keys[0]);
		list->keys[widest + 1] = middle;
		list->count++;
	}
}

/// The union of the profiles' points, or an even resampling when that is too many.
static void blend_profiles(const plume_sh_length_profile *const *profiles, const double *weights, int count,
                           plume_sh_length_profile *out)
{
	double nodes[PLUME_SH_MAX_PROFILE];
	int node_count = 0;
	bool overflow = false;
	for (int f = 0; f < count && !overflow; ++f) {
		for (int i = 0; i < profiles[f]->count && !overflow; ++i) {
			double p = profiles[f]->count == 1 ? 0.0 : profiles[f]->position[i];
			int at = 0;
			while (at < node_count && nodes[at] < p)
				++at;
			if (at < node_count && nodes[at] == p)
				continue;
			if (node_count == PLUME_SH_MAX_PROFILE) {
				overflow = true;
				break;
			}
			memmove(nodes + at + 1, nodes + at, (size_t)(node_count - at) * sizeof *nodes);
			nodes[at] = p;
			node_count++;
		}
	}
	if (overflow) {
		node_count = PLUME_SH_MAX_PROFILE;
		for (int i = 0; i < node_count; ++i)
			nodes[i] = (double)i / (node_count - 1);
	}
	memset(out, 0, sizeof *out);
	out->count = node_count;
	for (int i = 0; i < node_count; ++i) {
		out->position[i] = nodes[i];
		double length = 0.0;
		for (int f = 0; f < count; ++f)
			length += weights[f] * sh_profile_eval(profiles[f], nodes[i]);
		out->length[i] = length;
	}
}

/// Weighted sum of the parameters of count feathers (weights normalized, >= 0); lists is scratch for count
/// key lists.
static void blend_params(const plume_sh_params *const *params, const double *weights, int count, sh_key_list *lists,
                         plume_sh_params *out)
{
	memset(out, 0, sizeof *out);
#define BLEND(field)                                                                                                   \
	do {                                                                                                               \
		double sum = 0.0;                                                                                              \
		for (int f = 0; f < count; ++f)                                                                                \
			sum += weights[f] * params[f]->field;                                                                      \
		out->field = sum;                                                                                              \
	} while (0)
	BLEND(calamus_length);
	BLEND(calamus_width_ratio);
	BLEND(rachis_length);
	BLEND(rachis_width);
	BLEND(rachis_side_curvature);
	BLEND(rachis_front_curvature);
	BLEND(barb_angle[0][0]);
	BLEND(barb_angle[0][1]);
	BLEND(barb_angle[1][0]);
	BLEND(barb_angle[1][1]);
	BLEND(spacing_base);
	BLEND(spacing_tip);
#undef BLEND
	for (int side = 0; side < 2; ++side) {
		const plume_sh_length_profile *profiles[MAX_BLEND];
		for (int f = 0; f < count; ++f)
			profiles[f] = &params[f]->barb_length[side];
		blend_profiles(profiles, weights, count, &out->barb_length[side]);
	}

	// Key barbs: complete with the defaults, inflate to a common count, blend pairwise by order.
	static const int max_keys = PLUME_SH_MAX_KEY_BARBS;
	int target = 0;
	for (int f = 0; f < count; ++f) {
		sh_key_list_build(params[f], &lists[f]);
		if (lists[f].count > target)
			target = lists[f].count;
	}
	if (target > max_keys)
		target = max_keys;
	for (int f = 0; f < count; ++f)
		inflate(&lists[f], target);
	out->key_barb_count = target;
	for (int k = 0; k < target; ++k) {
		plume_sh_key_barb *key = &out->key_barbs[k];
		int cv_count = 0;
		for (int f = 0; f < count; ++f)
			if (lists[f].keys[k].cv_count > cv_count)
				cv_count = lists[f].keys[k].cv_count;
		key->cv_count = cv_count;
		for (int f = 0; f < count; ++f) {
			plume_sh_key_barb source = lists[f].keys[k];
			sh_elevate_to(source.cvs, source.cv_count, cv_count);
			key->position += weights[f] * source.position;
			key->plumulaceous += weights[f] * source.plumulaceous;
			for (int i = 0; i < cv_count; ++i)
				key->cvs[i] = plume_v3_mad(key->cvs[i], weights[f], source.cvs[i]);
		}
		// Weights sum to 1 only up to rounding: keep the blend inside the ranges of what it blends.
		key->position = fmin(fmax(key->position, 0.0), 1.0);
		key->plumulaceous = fmin(fmax(key->plumulaceous, 0.0), 1.0);
	}
}

plume_status plume_sh_def_blend(const plume_sh_def *const *defs, const double *weights, int count, plume_sh_def *out,
                                plume_error *err)
{
	PLUME_ASSERT(count >= 1 && defs != NULL && weights != NULL && out != NULL);
	for (int f = 0; f < count; ++f)
		PLUME_ASSERT_DEF(defs[f]);
	if (count < 1 || count > MAX_BLEND)
		return plume_error_set(err, PLUME_ERROR_SPEC, "blend: %d feathers, allowed [1, %d]", count, MAX_BLEND);
	double total = 0.0;
	for (int f = 0; f < count; ++f) {
		if (!(weights[f] >= 0.0 && isfinite(weights[f])))
			return plume_error_set(err, PLUME_ERROR_SPEC, "blend: weight %d is %g, must be >= 0", f, weights[f]);
		total += weights[f];
	}
	if (!(total > 0.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "blend: the weights sum to 0");
	for (int f = 0; f < count; ++f) {
		plume_status status = plume_sh_def_validate(defs[f], err);
		if (status != PLUME_OK) {
			char prefix[48];
			snprintf(prefix, sizeof prefix, "blend: feather %d", f);
			plume_error_prefix(err, prefix);
			return status;
		}
	}
	double normalized[MAX_BLEND];
	int heaviest = 0;
	for (int f = 0; f < count; ++f) {
		normalized[f] = weights[f] / total;
		if (weights[f] > weights[heaviest])
			heaviest = f;
	}
	// The blend is written straight into out (a definition is tens of kilobytes: a coat blends one per
	// feather), through a copy only when out is one of the definitions it reads.
	bool aliased = false;
	for (int f = 0; f < count; ++f)
		aliased = aliased || defs[f] == out;
	plume_sh_def *result = aliased ? plume_alloc(sizeof *result) : out;
	sh_key_list *lists = plume_alloc((size_t)count * sizeof *lists);
	if (result == NULL || lists == NULL) {
		if (aliased)
			plume_free(result);
		plume_free(lists);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "blend: out of memory");
	}
	const plume_sh_params *params[MAX_BLEND];
	for (int f = 0; f < count; ++f)
		params[f] = &defs[f]->main;
	blend_params(params, normalized, count, lists, &result->main);

	// Afterfeathers blend among the feathers that have one, and the result has one when they weigh at least half.
	double after_weight = 0.0;
	for (int f = 0; f < count; ++f)
		if (defs[f]->has_afterfeather)
			after_weight += normalized[f];
	result->has_afterfeather = after_weight >= 0.5;
	if (after_weight > 0.0) {
		double after_weights[MAX_BLEND];
		int n = 0;
		for (int f = 0; f < count; ++f)
			if (defs[f]->has_afterfeather) {
				params[n] = &defs[f]->afterfeather;
				after_weights[n++] = normalized[f] / after_weight;
			}
		blend_params(params, after_weights, n, lists, &result->afterfeather);
	} else {
		sh_default_afterfeather(&result->main, &result->afterfeather);
	}
	result->barb_width_base = 0.0;
	result->barb_width_tip = 0.0;
	for (int f = 0; f < count; ++f) {
		result->barb_width_base += normalized[f] * defs[f]->barb_width_base;
		result->barb_width_tip += normalized[f] * defs[f]->barb_width_tip;
	}
	result->texture_mode = defs[heaviest]->texture_mode;
	result->cookie = PLUME_DEF_COOKIE;
	if (aliased) {
		*out = *result;
		plume_free(result);
	}
	plume_free(lists);
	return PLUME_OK;
}

plume_status plume_sh_def_interpolate(const plume_sh_def *a, const plume_sh_def *b, double t, plume_sh_def *out,
                                      plume_error *err)
{
	if (!(t >= 0.0 && t <= 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "interpolate: t is %g, allowed [0, 1]", t);
	const plume_sh_def *defs[2] = {a, b};
	double weights[2] = {1.0 - t, t};
	return plume_sh_def_blend(defs, weights, 2, out, err);
}

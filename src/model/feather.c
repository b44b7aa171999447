// The shared feather structure: storage, builders and read-only views.
#include <math.h>
#include <string.h>

#include "../core/asserts.h"
#include "../core/alloc.h"
#include "../core/vec_inline.h"
#include "feather_internal.h"

double plume_feather_layout_bytes(double points, double barbs, double barbules, double shaft)
{
	return points * (2.0 * sizeof(plume_vec3) + 2.0 * sizeof(double) + sizeof(plume_vec2)) +
	       barbs * sizeof(plume_barb_record) + barbules * sizeof(plume_barbule_record) +
	       shaft * sizeof(plume_shaft_sample);
}

double plume_feather_bytes(const plume_feather *feather)
{
	if (feather == NULL)
		return 0.0;
	return plume_feather_layout_bytes(feather->point_count, feather->barb_count, feather->barbule_count,
	                                  feather->shaft_count) +
	       plume_feather_bytes(feather->afterfeather);
}

plume_feather *plume_feather_create_empty(void)
{
	plume_feather *feather = plume_calloc(1, sizeof *feather);
	if (feather != NULL) {
		feather->magic = PLUME_HANDLE_MAGIC;
		feather->afterfeather_t = 0.0;
	}
	return feather;
}

void plume_feather_destroy(plume_feather *feather)
{
	if (feather == NULL)
		return;
	PLUME_ASSERT_HANDLE(feather);
	feather->magic = 0;
	plume_feather_destroy(feather->afterfeather);
	plume_free(feather->shaft);
	plume_free(feather->points);
	plume_free(feather->normals);
	plume_free(feather->arc_length);
	plume_free(feather->widths);
	plume_free(feather->uv);
	plume_free(feather->barbs);
	plume_free(feather->barbules);
	plume_free(feather->summary);
	plume_free(feather);
}

int plume_feather_set_summary(plume_feather *feather, const char *json)
{
	char *copy = NULL;
	if (json != NULL) {
		size_t size = strlen(json) + 1;
		if ((copy = plume_alloc(size)) == NULL)
			return -1;
		memcpy(copy, json, size);
	}
	plume_free(feather->summary);
	feather->summary = copy;
	return 0;
}

const char *plume_feather_summary(const plume_feather *feather)
{
	PLUME_ASSERT_HANDLE(feather);
	return feather->summary;
}

plume_shaft_sample *plume_feather_add_shaft(plume_feather *feather, int count)
{
	if (PLUME_GROW(feather->shaft, feather->shaft_capacity, feather->shaft_count + count) != 0)
		return NULL;
	plume_shaft_sample *first = feather->shaft + feather->shaft_count;
	feather->shaft_count += count;
	return first;
}

static int resize(void **array, int capacity, size_t item_size)
{
	void *memory = plume_realloc(*array, (size_t)capacity * item_size);
	if (memory == NULL)
		return -1;
	*array = memory;
	return 0;
}

int plume_feather_reserve_points(plume_feather *feather, int capacity)
{
	if (capacity <= feather->point_capacity)
		return 0;
	// Five parallel arrays share one capacity.
	if (resize((void **)&feather->points, capacity, sizeof *feather->points) != 0 ||
	    resize((void **)&feather->normals, capacity, sizeof *feather->normals) != 0 ||
	    resize((void **)&feather->arc_length, capacity, sizeof *feather->arc_length) != 0 ||
	    resize((void **)&feather->widths, capacity, sizeof *feather->widths) != 0 ||
	    resize((void **)&feather->uv, capacity, sizeof *feather->uv) != 0)
		return -1; // arrays already grown keep their contents; capacity stays the smallest
	feather->point_capacity = capacity;
	return 0;
}

int plume_feather_append_points(plume_feather *feather, int count)
{
	int needed = feather->point_count + count;
	if (count == 0)
		return feather->point_count;
	if (needed > feather->point_capacity) {
		int capacity = feather->point_capacity > 0 ? feather->point_capacity : 256;
		while (capacity < needed)
			capacity *= 2;
		if (plume_feather_reserve_points(feather, capacity) != 0)
			return -1;
	}
	int first = feather->point_count;
	feather->point_count = needed;
	return first;
}

int plume_feather_add_points(plume_feather *feather, int count)
{
	int first = plume_feather_append_points(feather, count);
	if (first < 0 || count == 0)
		return first;
	memset(feather->points + first, 0, (size_t)count * sizeof *feather->points);
	memset(feather->normals + first, 0, (size_t)count * sizeof *feather->normals);
	memset(feather->arc_length + first, 0, (size_t)count * sizeof *feather->arc_length);
	memset(feather->widths + first, 0, (size_t)count * sizeof *feather->widths);
	memset(feather->uv + first, 0, (size_t)count * sizeof *feather->uv);
	return first;
}

int plume_feather_add_barb(plume_feather *feather, const plume_barb_record *barb)
{
	if (PLUME_GROW(feather->barbs, feather->barb_capacity, feather->barb_count + 1) != 0)
		return -1;
	feather->barbs[feather->barb_count] = *barb;
	return feather->barb_count++;
}

int plume_feather_add_barbule(plume_feather *feather, const plume_barbule_record *barbule)
{
	// A builder that reserved its records (Zhang-Kanai: 60,000 of them) skips the call.
	if (feather->barbule_count >= feather->barbule_capacity &&
	    PLUME_GROW(feather->barbules, feather->barbule_capacity, feather->barbule_count + 1) != 0)
		return -1;
	feather->barbules[feather->barbule_count] = *barbule;
	return feather->barbule_count++;
}

// ---------------------------------------------------------------------------
// Views

static plume_polyline polyline_view(const plume_feather *feather, plume_curve_range range)
{
	return (plume_polyline){
	    .count = range.count,
	    .points = feather->points + range.first,
	    .normals = feather->normals + range.first,
	    .arc_length = feather->arc_length + range.first,
	    .widths = feather->widths + range.first,
	    .uv = feather->uv + range.first,
	};
}

static void grow_bounds(plume_vec3 *lo, plume_vec3 *hi, plume_vec3 p, double radius)
{
	lo->x = fmin(lo->x, p.x - radius);
	lo->y = fmin(lo->y, p.y - radius);
	lo->z = fmin(lo->z, p.z - radius);
	hi->x = fmax(hi->x, p.x + radius);
	hi->y = fmax(hi->y, p.y + radius);
	hi->z = fmax(hi->z, p.z + radius);
}

plume_feather_info plume_feather_get_info(const plume_feather *feather)
{
	PLUME_ASSERT_HANDLE(feather);
	plume_feather_info info = {
	    .shaft_sample_count = feather->shaft_count,
	    .calamus_sample_count = feather->calamus_count,
	    .barb_count = feather->barb_count,
	    .barbule_count = feather->barbule_count,
	    .point_count = feather->point_count,
	    .has_afterfeather = feather->afterfeather != NULL,
	};
	for (int i = 0; i < feather->barb_count; ++i) {
		if (feather->barbs[i].side == PLUME_SIDE_LEFT)
			info.barb_count_left++;
		else
			info.barb_count_right++;
	}
	for (int i = 1; i < feather->shaft_count; ++i)
		info.shaft_length += plume_v3_distance(feather->shaft[i - 1].position, feather->shaft[i].position);

	plume_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
	for (int i = 0; i < feather->shaft_count; ++i)
		grow_bounds(&lo, &hi, feather->shaft[i].position, 0.5 * feather->shaft[i].width);
	for (int i = 0; i < feather->point_count; ++i)
		grow_bounds(&lo, &hi, feather->points[i], 0.5 * feather->widths[i]);
	if (feather->afterfeather != NULL) {
		plume_feather_info sub = plume_feather_get_info(feather->afterfeather);
		if (sub.shaft_sample_count + sub.point_count > 0) {
			grow_bounds(&lo, &hi, sub.bounds_min, 0.0);
			grow_bounds(&lo, &hi, sub.bounds_max, 0.0);
		}
	}
	if (lo.x > hi.x) // empty feather
		lo = hi = plume_v3(0.0, 0.0, 0.0);
	info.bounds_min = lo;
	info.bounds_max = hi;
	return info;
}

const plume_shaft_sample *plume_feather_shaft(const plume_feather *feather)
{
	PLUME_ASSERT_HANDLE(feather);
	return feather->shaft;
}

plume_barb plume_feather_barb(const plume_feather *feather, int i)
{
	PLUME_ASSERT_HANDLE(feather);
	PLUME_ASSERT_INDEX(i, feather->barb_count);
	const plume_barb_record *record = feather->barbs + i;
	return (plume_barb){
	    .curve = polyline_view(feather, record->curve),
	    .side = record->side,
	    .rachis_t = record->rachis_t,
	    .segment = record->segment,
	    .barbule_first = record->barbule_first,
	    .barbule_count = record->barbule_count,
	};
}

plume_barbule plume_feather_barbule(const plume_feather *feather, int i)
{
	PLUME_ASSERT_HANDLE(feather);
	PLUME_ASSERT_INDEX(i, feather->barbule_count);
	const plume_barbule_record *record = feather->barbules + i;
	return (plume_barbule){
	    .curve = polyline_view(feather, record->curve),
	    .barb = record->barb,
	    .barb_s = record->barb_s,
	    .kind = record->kind,
	};
}

const plume_feather *plume_feather_afterfeather(const plume_feather *feather)
{
	PLUME_ASSERT_HANDLE(feather);
	return feather->afterfeather;
}

double plume_feather_afterfeather_t(const plume_feather *feather)
{
	PLUME_ASSERT_HANDLE(feather);
	return feather->afterfeather_t;
}

// ---------------------------------------------------------------------------
// Equality and copies

static bool same_bytes(const void *a, const void *b, size_t size) { return size == 0 || memcmp(a, b, size) == 0; }

/// Two curves hold the same points, bit for bit, wherever they sit in their pools.
static bool same_curve(const plume_feather *a, plume_curve_range p, const plume_feather *b, plume_curve_range q)
{
	if (p.count != q.count)
		return false;
	if (p.count == 0)
		return true;
	size_t n = (size_t)p.count;
	return same_bytes(a->points + p.first, b->points + q.first, n * sizeof *a->points) &&
	       same_bytes(a->normals + p.first, b->normals + q.first, n * sizeof *a->normals) &&
	       same_bytes(a->arc_length + p.first, b->arc_length + q.first, n * sizeof *a->arc_length) &&
	       same_bytes(a->widths + p.first, b->widths + q.first, n * sizeof *a->widths) &&
	       same_bytes(a->uv + p.first, b->uv + q.first, n * sizeof *a->uv);
}

// Equality is that of what the views show, bit for bit (so -0 differs from 0
// and a NaN equals itself), not of the storage behind them: a
// curve's offset in the point pool, pool points no curve uses, an empty barb's
// barbule_first and the attachment parameter of an absent afterfeather are
// not part of a feather, nor is the generator's summary (diagnostics, not
// shape). So a feather rebuilt from a file (whose pool order
// need not be the generator's) equals the original.
bool plume_feather_equal(const plume_feather *a, const plume_feather *b)
{
	if (a == NULL || b == NULL)
		return a == b;
	PLUME_ASSERT_HANDLE(a);
	PLUME_ASSERT_HANDLE(b);
	if (a->shaft_count != b->shaft_count || a->calamus_count != b->calamus_count || a->barb_count != b->barb_count ||
	    a->barbule_count != b->barbule_count)
		return false;
	if (a->afterfeather != NULL && b->afterfeather != NULL &&
	    !same_bytes(&a->afterfeather_t, &b->afterfeather_t, sizeof a->afterfeather_t))
		return false;
	// Records are compared field by field: struct padding is not data.
	for (int i = 0; i < a->shaft_count; ++i) {
		const plume_shaft_sample *p = a->shaft + i, *q = b->shaft + i;
		if (!same_bytes(&p->position, &q->position, sizeof p->position) ||
		    !same_bytes(&p->tangent, &q->tangent, sizeof p->tangent) ||
		    !same_bytes(&p->normal, &q->normal, sizeof p->normal) ||
		    !same_bytes(&p->binormal, &q->binormal, sizeof p->binormal) ||
		    !same_bytes(&p->width, &q->width, sizeof p->width) || !same_bytes(&p->t, &q->t, sizeof p->t))
			return false;
	}
	for (int i = 0; i < a->barb_count; ++i) {
		const plume_barb_record *p = a->barbs + i, *q = b->barbs + i;
		if (p->side != q->side || !same_bytes(&p->rachis_t, &q->rachis_t, sizeof p->rachis_t) ||
		    p->segment != q->segment || p->barbule_count != q->barbule_count ||
		    (p->barbule_count > 0 && p->barbule_first != q->barbule_first) || !same_curve(a, p->curve, b, q->curve))
			return false;
	}
	for (int i = 0; i < a->barbule_count; ++i) {
		const plume_barbule_record *p = a->barbules + i, *q = b->barbules + i;
		if (p->barb != q->barb || !same_bytes(&p->barb_s, &q->barb_s, sizeof p->barb_s) || p->kind != q->kind ||
		    !same_curve(a, p->curve, b, q->curve))
			return false;
	}
	return plume_feather_equal(a->afterfeather, b->afterfeather);
}

void plume_feather_move(plume_feather *feather, plume_mat3 rotation, plume_vec3 translation)
{
	for (; feather != NULL; feather = feather->afterfeather) {
		PLUME_ASSERT_HANDLE(feather);
		for (int i = 0; i < feather->shaft_count; ++i) {
			plume_shaft_sample *s = feather->shaft + i;
			s->position = plume_v3_add(plume_m3_apply(rotation, s->position), translation);
			s->tangent = plume_m3_apply(rotation, s->tangent);
			s->normal = plume_m3_apply(rotation, s->normal);
			s->binormal = plume_m3_apply(rotation, s->binormal);
		}
		for (int i = 0; i < feather->point_count; ++i) {
			feather->points[i] = plume_v3_add(plume_m3_apply(rotation, feather->points[i]), translation);
			feather->normals[i] = plume_m3_apply(rotation, feather->normals[i]);
		}
	}
}

double plume_feather_distance(const plume_feather *a, const plume_feather *b)
{
	double worst = 0.0;
	for (; a != NULL && b != NULL; a = a->afterfeather, b = b->afterfeather) {
		PLUME_ASSERT_HANDLE(a);
		PLUME_ASSERT_HANDLE(b);
		if (a->shaft_count != b->shaft_count || a->calamus_count != b->calamus_count ||
		    a->point_count != b->point_count || a->barb_count != b->barb_count ||
		    a->barbule_count != b->barbule_count || (a->afterfeather == NULL) != (b->afterfeather == NULL))
			return INFINITY;
		for (int i = 0; i < a->shaft_count; ++i) {
			if (!same_bytes(&a->shaft[i].width, &b->shaft[i].width, sizeof a->shaft[i].width))
				return INFINITY;
			worst = fmax(worst, plume_v3_distance(a->shaft[i].position, b->shaft[i].position));
		}
		for (int i = 0; i < a->barb_count; ++i) {
			const plume_barb_record *p = a->barbs + i, *q = b->barbs + i;
			if (p->curve.first != q->curve.first || p->curve.count != q->curve.count || p->side != q->side ||
			    p->segment != q->segment || p->barbule_count != q->barbule_count)
				return INFINITY;
		}
		for (int i = 0; i < a->barbule_count; ++i)
			if (a->barbules[i].curve.first != b->barbules[i].curve.first ||
			    a->barbules[i].curve.count != b->barbules[i].curve.count || a->barbules[i].kind != b->barbules[i].kind)
				return INFINITY;
		if (!same_bytes(a->widths, b->widths, (size_t)a->point_count * sizeof *a->widths) ||
		    !same_bytes(a->uv, b->uv, (size_t)a->point_count * sizeof *a->uv))
			return INFINITY;
		for (int i = 0; i < a->point_count; ++i)
			worst = fmax(worst, plume_v3_distance(a->points[i], b->points[i]));
	}
	return a == NULL && b == NULL ? worst : INFINITY;
}

plume_feather *plume_feather_clone(const plume_feather *feather)
{
	PLUME_ASSERT_HANDLE(feather);
	plume_feather *copy = plume_feather_create_empty();
	if (copy == NULL)
		return NULL;
	copy->calamus_count = feather->calamus_count;
	copy->afterfeather_t = feather->afterfeather_t;
	plume_shaft_sample *shaft = plume_feather_add_shaft(copy, feather->shaft_count);
	int first = plume_feather_add_points(copy, feather->point_count);
	if ((feather->shaft_count > 0 && shaft == NULL) || first < 0)
		goto fail;
	size_t points = (size_t)feather->point_count;
	if (feather->shaft_count > 0)
		memcpy(shaft, feather->shaft, (size_t)feather->shaft_count * sizeof *shaft);
	if (points > 0) {
		memcpy(copy->points, feather->points, points * sizeof *copy->points);
		memcpy(copy->normals, feather->normals, points * sizeof *copy->normals);
		memcpy(copy->arc_length, feather->arc_length, points * sizeof *copy->arc_length);
		memcpy(copy->widths, feather->widths, points * sizeof *copy->widths);
		memcpy(copy->uv, feather->uv, points * sizeof *copy->uv);
	}
	for (int i = 0; i < feather->barb_count; ++i)
		if (plume_feather_add_barb(copy, feather->barbs + i) < 0)
			goto fail;
	for (int i = 0; i < feather->barbule_count; ++i)
		if (plume_feather_add_barbule(copy, feather->barbules + i) < 0)
			goto fail;
	if (feather->afterfeather != NULL && (copy->afterfeather = plume_feather_clone(feather->afterfeather)) == NULL)
		goto fail;
	if (plume_feather_set_summary(copy, feather->summary) != 0)
		goto fail;
	return copy;
fail:
	plume_feather_destroy(copy);
	return NULL;
}

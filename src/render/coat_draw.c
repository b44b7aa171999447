// The coat's picture: its feathers drawn as one 2D scene, seen from +z
// (moved from model/coat_export.c: drawing is render's layer).
#include <math.h>
#include <stdlib.h>

#include "../core/asserts.h"
#include "../core/alloc.h"
#include "plume/coat.h"
#include "plume/render.h"

typedef struct depth_entry {
	double depth;
	int index;
} depth_entry;

static int compare_depth(const void *a, const void *b)
{
	const depth_entry *x = a, *y = b;
	if (x->depth != y->depth)
		return x->depth < y->depth ? -1 : 1;
	return (x->index > y->index) - (x->index < y->index);
}

/// Sets def's view to the xy bounds of all of the coat's feathers, widened where they have no extent.
static void frame_all(const plume_coat *coat, plume_render2d_def *def)
{
	plume_feather_info info = plume_feather_get_info(plume_coat_feather(coat, 0));
	plume_vec2 lo = {info.bounds_min.x, info.bounds_min.y}, hi = {info.bounds_max.x, info.bounds_max.y};
	for (int i = 1; i < plume_coat_feather_count(coat); ++i) {
		info = plume_feather_get_info(plume_coat_feather(coat, i));
		lo = (plume_vec2){fmin(lo.x, info.bounds_min.x), fmin(lo.y, info.bounds_min.y)};
		hi = (plume_vec2){fmax(hi.x, info.bounds_max.x), fmax(hi.y, info.bounds_max.y)};
	}
	double pad = 0.5 * fmax(fmax(hi.x - lo.x, hi.y - lo.y), 1e-3);
	if (!(hi.x > lo.x))
		lo.x -= pad, hi.x += pad;
	if (!(hi.y > lo.y))
		lo.y -= pad, hi.y += pad;
	def->view_min = lo;
	def->view_max = hi;
}

plume_status plume_coat_render2d(const plume_coat *coat, const plume_render2d_def *def, plume_image_format format,
                                 const char *path, plume_error *err)
{
	PLUME_ASSERT(coat != NULL);
	PLUME_ASSERT_DEF(def);
	// Seen from +z: feathers on the far side of the surface (normal away from the camera) are hidden by it;
	// the others are painted from the farthest root to the nearest, and in the coat's own bottom-to-top
	// order where roots are equally far (a plane facing the camera).
	int count = plume_coat_feather_count(coat), shown = 0;
	const plume_feather **feathers = plume_alloc((size_t)(count > 0 ? count : 1) * sizeof *feathers);
	depth_entry *order = plume_alloc((size_t)(count > 0 ? count : 1) * sizeof *order);
	if (feathers == NULL || order == NULL) {
		plume_free(feathers);
		plume_free(order);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	}
	for (int i = 0; i < count; ++i) {
		plume_vec3 position, normal;
		plume_coat_follicle(coat, i, &position, &normal);
		if (normal.z > -0.05)
			order[shown++] = (depth_entry){position.z, i};
	}
	qsort(order, (size_t)shown, sizeof *order, compare_depth);
	for (int i = 0; i < shown; ++i)
		feathers[i] = plume_coat_feather(coat, order[i].index);
	// Every follicle faces away (a surface seen from behind): the picture is the background, framed
	// as the whole coat would be, unless the caller frames it.
	plume_render2d_def empty = *def;
	if (shown == 0 && !(def->view_max.x > def->view_min.x && def->view_max.y > def->view_min.y))
		frame_all(coat, &empty);
	plume_status status = plume_render2d_feathers(feathers, shown, &empty, format, path, err);
	plume_free(feathers);
	plume_free(order);
	return status;
}

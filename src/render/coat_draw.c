// The coat's picture: its feathers drawn as one 2D scene, seen from +z
// (moved from model/coat_export.c: drawing is render's layer).
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
	plume_status status = plume_render2d_feathers(feathers, shown, def, format, path, err);
	plume_free(feathers);
	plume_free(order);
	return status;
}

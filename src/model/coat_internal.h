// Private: a coat's definition, filled by the coat spec reader (src/io/spec_coat.c)
// and built by src/model/coat.c.
#ifndef PLUME_COAT_INTERNAL_H
#define PLUME_COAT_INTERNAL_H

#include "plume/coat.h"
#include "plume/streit_heidrich.h"

typedef enum coat_surface_kind {
	COAT_SURFACE_PLANE = 0, ///< [0, width] x [0, height] in the z = 0 plane, normal +z
	COAT_SURFACE_SPHERE,    ///< centre and radius, normal outwards
	COAT_SURFACE_MESH,      ///< a triangle mesh; normals from the faces' winding, smoothed at vertices
} coat_surface_kind;

typedef enum coat_layout {
	COAT_LAYOUT_HEXAGONAL = 0,
	COAT_LAYOUT_POISSON,
} coat_layout;

typedef enum coat_weighting {
	COAT_WEIGHTS_AUTO = 0, ///< bilinear with 4 key feathers, barycentric with 3, else inverse distance
	COAT_WEIGHTS_BILINEAR,
	COAT_WEIGHTS_BARYCENTRIC,
	COAT_WEIGHTS_INVERSE_DISTANCE,
} coat_weighting;

#define COAT_MAX_KEYS 16

typedef struct coat_def {
	coat_surface_kind surface;
	double plane_size[2];
	plume_vec3 sphere_centre;
	double sphere_radius;
	plume_mesh *mesh; ///< COAT_SURFACE_MESH: owned by the definition until the coat takes it

	coat_layout layout;
	/// Hexagonal: distance between neighbouring follicles; Poisson: the smallest distance between two, m.
	double spacing;
	/// Poisson only: the spacing grows linearly to spacing * spacing_factor from spacing_from to spacing_to
	/// (projected on that segment, clamped). 1: uniform.
	double spacing_factor;
	plume_vec3 spacing_from, spacing_to;

	int key_count;
	plume_vec3 key_at[COAT_MAX_KEYS];
	plume_sh_def *key_defs; ///< key_count definitions, owned by the definition
	uint64_t key_seeds[COAT_MAX_KEYS];
	coat_weighting weighting;
	double power; ///< inverse-distance exponent

	bool direction_towards; ///< towards direction_point, else along direction_vector
	plume_vec3 direction_vector, direction_point;
	double lift; ///< radians, (0, pi/2]

	plume_sh_lod lod;
	uint64_t seed;
	double stage;                ///< growth stage of every feather, 1 finished
	uint64_t max_memory;         ///< bytes the coat may take (estimated before the layout and before the feathers)
	plume_progress_fn *progress; ///< after each feather (plume_spec_options), may be NULL
	void *progress_user;
} coat_def;

/// Builds the coat; takes the mesh out of def (def->mesh is NULL afterwards). key_defs stay with def.
plume_status coat_build(coat_def *def, plume_coat **out, plume_error *err);

/// The follicles of a definition's surface and layout, in layout order, with their normals. Caller frees
/// both arrays with plume_free. For tests of layouts.
plume_status coat_follicles(const coat_def *def, const plume_mesh *surface, plume_vec3 **positions,
                            plume_vec3 **normals, int *count, plume_error *err);

/// Bytes any one feather of the coat takes at most, allocations included: plume_sh_estimate_bytes of
/// a definition at least as wide as every blend of the key feathers, and the records' growth.
double coat_feather_bound(const coat_def *def);

/// Bytes the coat takes at most with follicle_count follicles on surface: their feathers (coat_feather_bound),
/// the coat's and the build's arrays, the threads' scratch and the surface. coat_build refuses a coat
/// past def->max_memory before it builds a feather.
double coat_estimate_bytes(const coat_def *def, int follicle_count, const plume_mesh *surface);

#endif

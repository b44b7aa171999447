// plume — feather coats (Streit & Heidrich 4.4).
//
// Follicles are laid out on a surface (a plane patch, a sphere, or a triangle
// mesh read from OBJ) in a regular hexagonal or a seeded Poisson-disk
// distribution. A few key feathers sit at chosen follicles; every other
// feather is interpolated from them (bilinearly inside the key feathers'
// quadrilateral as in the paper, barycentrically inside a key triangle, or by
// inverse-distance weights for any layout), rooted at its follicle, oriented
// by the surface normal and a direction field, lifted off the surface, and
// kept in drawing order from the bottom feather to the top one.
#ifndef PLUME_COAT_H
#define PLUME_COAT_H

#include "plume/feather.h"
#include "plume/mesh.h"
#include "plume/model.h"
#include "plume/render.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

typedef struct plume_coat plume_coat;

/// Reads a coat spec ("model": "coat", docs/coats.md) and builds the coat. options->seed overrides the
/// spec's seed; options->stage_kind PLUME_STAGE_GROWTH grows every feather to options->stage.
plume_status plume_coat_spec_generate(const char *path, const plume_spec_options *options, plume_coat **out,
                                      plume_error *err);

int plume_coat_feather_count(const plume_coat *coat);

/// Feather index in world coordinates (already placed), in drawing order from bottom to top.
const plume_feather *plume_coat_feather(const plume_coat *coat, int index);

/// The follicle of feather index: its root on the surface and the surface's outward unit normal there.
void plume_coat_follicle(const plume_coat *coat, int index, plume_vec3 *position, plume_vec3 *normal);

/// The rigid motion that placed feather index: its points are rotation * (the point in the
/// feather's own frame, docs/feather-json.md) + origin; origin is the follicle.
void plume_coat_feather_frame(const plume_coat *coat, int index, plume_mat3 *rotation, plume_vec3 *origin);

/// True when feather index is one of the key feathers (placed as designed, not interpolated).
bool plume_coat_is_key(const plume_coat *coat, int index);

/// The surface as a triangle mesh (rest = positions), never NULL. Owned by the coat.
const plume_mesh *plume_coat_surface(const plume_coat *coat);

void plume_coat_destroy(plume_coat *coat);

/// Wavefront OBJ: one object per feather (feather_00000 ...) in drawing order, its shaft, barbs and
/// afterfeather as polylines with texture coordinates; world coordinates, metres. Atomic.
plume_status plume_coat_write_obj(const plume_coat *coat, const char *path, plume_error *err);

/// USD text: the surface as a Mesh and one linear BasisCurves prim per feather (widths, st), in drawing
/// order. Atomic.
plume_status plume_coat_write_usda(const plume_coat *coat, const char *path, plume_error *err);

/// The coat seen from +z, orthographically (plume_render2d_feathers): feathers drawn bottom to top, those
/// whose follicle faces away from the camera left out.
plume_status plume_coat_render2d(const plume_coat *coat, const plume_render2d_def *def, plume_image_format format,
                                 const char *path, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_COAT_H

// plume — barb-level feathers carried by a deforming shell (issue 7, item 4).
//
// The simulator moves a coarse triangle shell; the generated feather has
// thousands of barbs. Every point of the feather (shaft samples, barb and
// barbule points, the afterfeather's too) is embedded once in the rest shell:
// the nearest triangle, the barycentric coordinates of the point's projection
// on that triangle's plane, and the signed offset along the triangle's unit
// normal. Any later shell position then carries the points along:
//     p = b0 x0 + b1 x1 + b2 x2 + h n,
// with n the deformed triangle's unit normal. Directions (shaft tangents and
// normals, barb normals) turn with the triangle's frame. On the rest shell
// the formula gives back the rest points (to rounding, about 1e-16 m), and a
// rigidly moved shell moves the feather rigidly.
#ifndef PLUME_EMBED_H
#define PLUME_EMBED_H

#include "plume/feather.h"
#include "plume/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

typedef struct plume_barb_embedding plume_barb_embedding;

/// Embeds every point of the feather's shaft, barbs and barbules in the rest shell (mesh->rest):
/// nearest triangle, barycentric coordinates, signed offset along the triangle normal. The mesh must
/// stay alive and unchanged (only its face list and vertex count are used later). Errors:
/// PLUME_ERROR_SPEC for a mesh without faces or with degenerate faces only, PLUME_ERROR_MEMORY.
plume_status plume_embedding_create(const plume_feather *feather, const plume_mesh *mesh, plume_barb_embedding **out,
                                    plume_error *err);

/// plume_embedding_create restricted to the faces [first_face, first_face + face_count) of mesh: the
/// feathers of a scene share one joined shell (plume_scene's mesh, each feather's vertex and face
/// range), and each is embedded in its own piece, so where feathers overlap a barb never hangs on
/// another feather's triangle. plume_embedding_create is this with all of the mesh's faces.
/// plume_embedding_apply still takes positions of all of the mesh's vertices.
plume_status plume_embedding_create_faces(const plume_feather *feather, const plume_mesh *mesh, int first_face,
                                          int face_count, plume_barb_embedding **out, plume_error *err);

/// The feather carried by the shell at `positions` (mesh vertex order): a new plume_feather, the
/// caller's to destroy. Widths and texture coordinates are kept; arc lengths are measured anew.
/// PLUME_ERROR_NUMERIC when a position is not finite, PLUME_ERROR_MEMORY.
plume_status plume_embedding_apply(const plume_barb_embedding *embedding, const plume_vec3 *positions,
                                   plume_feather **out, plume_error *err);

/// Number of embedded points (shaft samples and pool points, afterfeather included).
int plume_embedding_point_count(const plume_barb_embedding *embedding);

/// Largest distance from an embedded point to its triangle, m (how far the feather sits off the shell).
double plume_embedding_max_offset(const plume_barb_embedding *embedding);

void plume_embedding_destroy(plume_barb_embedding *embedding);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_EMBED_H

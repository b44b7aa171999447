// Private: mesh definitions and explicit barb guides read from JSON specs
// (docs/meshing.md), for `plume mesh` and the scene reader.
#ifndef PLUME_SPEC_MESH_H
#define PLUME_SPEC_MESH_H

#include "plume/mesh.h"
#include "spec.h"

/// Reads the keys edge_length, rachis_width_base, rachis_width_tip (m; 0 or
/// absent: from the feather) and include_calamus of object into def; absent
/// keys keep def's values. Returns reader->status == PLUME_OK.
bool plume_spec_mesh_def(plume_spec_reader *reader, const json_t *object, const char *path, plume_mesh_def *def);

/// Explicit guides and the arrays they point into.
typedef struct plume_mesh_guides_storage {
	plume_mesh_guides guides; ///< points into the arrays below
	plume_vec2 *boundary;
	plume_vec2 *rachis;
	int *guide_offsets;
	plume_vec2 *guide_points;
} plume_mesh_guides_storage;

/// Reads "boundary" (array of [x, y]), "rachis" (a spline) and "guides" (array
/// of splines) of object. A spline is an array of points (a polyline) or an
/// object {"type": "polyline" | "catmull-rom" | "bezier", "points": [...],
/// "samples": n}. Other keys of object are the caller's to check. On failure
/// storage is empty and the reader holds the error.
plume_status plume_spec_mesh_guides(plume_spec_reader *reader, const json_t *object, const char *path,
                                    plume_mesh_guides_storage *storage);

void plume_mesh_guides_storage_free(plume_mesh_guides_storage *storage);

#endif

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
/// "samples": n}. Other keys of object are the caller's to check. Splines that
/// would sample into more than max_memory bytes (0: PLUME_DEFAULT_MAX_MEMORY) at
/// PLUME_MESH_BYTES_PER_GUIDE_POINT a point are refused before any is sampled
/// (PLUME_ERROR_LIMIT). On failure storage is empty and the reader holds the error.
plume_status plume_spec_mesh_guides(plume_spec_reader *reader, const json_t *object, const char *path,
                                    uint64_t max_memory, plume_mesh_guides_storage *storage);

/// Bytes a sampled guide point takes while read and meshed: 16 in the list, up to twice
/// that while it grows, and 24 in the mesher's copy (measured about 40: 16 million points,
/// 635 MB).
#define PLUME_MESH_BYTES_PER_GUIDE_POINT 64

void plume_mesh_guides_storage_free(plume_mesh_guides_storage *storage);

#endif

// Private: reading a body (docs/body.md) from a JSON object, for body files and for
// the "body" member of a scene.
#ifndef PLUME_IO_SPEC_BODY_H
#define PLUME_IO_SPEC_BODY_H

#include <jansson.h>

#include "plume/body.h"

/// Reads the body object found at `path` ("$" for a body file, "$.body" in a scene) of
/// the spec `file`, and creates the body. A relative OBJ path is taken relative to
/// `folder` (NULL: the current folder). Errors read "file: path.key: ..." (path included,
/// e.g. "scene.json: $.body.bones[2].parent: ...") or "mesh.obj:LINE: ..." for the OBJ.
plume_status plume_spec_body(const char *file, const json_t *object, const char *path, const char *folder,
                             plume_body **out, plume_error *err);

/// Reads a Wavefront OBJ as a body's rest mesh: "v x y z" and "f" lines (a/b/c corner
/// syntax, 1-based or negative indices, polygons fanned into triangles from their first
/// corner); other lines are ignored. Errors name file:line: a bad number, a non-finite
/// vertex, an index out of range, a face of fewer than 3 corners, a degenerate
/// (zero-area) triangle, no faces at all. mesh is freed with plume_body_mesh_free.
plume_status plume_body_read_obj(const char *path, plume_body_mesh *mesh, plume_error *err);

#endif // PLUME_IO_SPEC_BODY_H

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

/// Reads a Wavefront OBJ as a body's rest mesh with plume_obj_read (obj_reader.h), positions
/// only: "v" and "f" lines (polygons fanned into triangles from their first corner), texture
/// coordinates not read. Errors name file:line: plume_obj_read's, and a degenerate (zero-area)
/// triangle, naming its face. On any error mesh is empty; else it is freed with
/// plume_body_mesh_free.
plume_status plume_body_read_obj(const char *path, plume_body_mesh *mesh, plume_error *err);

#endif // PLUME_IO_SPEC_BODY_H

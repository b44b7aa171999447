// Private: the one Wavefront OBJ reader of plume's polygon meshes, shared by
// plume_mesh_read_obj (mesh_obj.c) and the body meshes of scenes (spec_body.c).
// What only one caller needs stays with it: materials from group names with the
// mesh, the zero-area check with the body.
#ifndef PLUME_IO_OBJ_READER_H
#define PLUME_IO_OBJ_READER_H

#include "plume/core.h"

/// Bytes kept of a "g" line's first name (the rest is cut).
#define PLUME_OBJ_GROUP_SIZE 64

/// What a caller takes from a file besides the positions and faces. A body's mesh has
/// positions only: its files' texture coordinates are not read (nor checked), as normals
/// never are.
typedef enum plume_obj_content {
	PLUME_OBJ_POSITIONS,
	PLUME_OBJ_POSITIONS_AND_UVS,
} plume_obj_content;

/// One OBJ file's polygons, fanned into triangles. Indices are 0-based.
typedef struct plume_obj {
	int vertex_count;
	plume_vec3 *vertices; ///< the "v" lines, in order
	int uv_count;
	/// The "vt" lines, in order (v = 0 when a line has only u); none for PLUME_OBJ_POSITIONS.
	plume_vec2 *uvs;
	int triangle_count;
	/// 3 vertices per triangle: face (c0, c1, ..., c_n-1) gives (c0, c_i, c_i+1) for
	/// i = 1 .. n-2, so every triangle keeps the polygon's winding.
	int *triangles;
	/// 3 per triangle, into uvs; -1 for a corner without one (every corner for PLUME_OBJ_POSITIONS).
	int *triangle_uvs;
	int *triangle_face; ///< the face (the "f" line, counted from 0) each triangle comes from
	int face_count;
	long *face_line; ///< each face's line in the file (1-based), for callers' messages
	int *face_group; ///< each face's "g" line, counted from 0 into groups; -1 before the first
	int group_count;
	char (*groups)[PLUME_OBJ_GROUP_SIZE]; ///< each "g" line's first name ("" when none)
} plume_obj;

/// Reads path's "v", "vt" (for PLUME_OBJ_POSITIONS_AND_UVS), "f" and "g" lines into obj;
/// other lines (normals, objects, materials), everything from a '#' to the end of its
/// line, blank lines and the '\r' of CRLF files are ignored. Numbers are read in the "C"
/// locale. A face corner is v, v/vt, v//vn or v/vt/vn, each index 1-based or negative
/// (counted back from the last one read so far); normal indices (and texture indices for
/// PLUME_OBJ_POSITIONS) are checked for syntax only. A "v" needs 3 numbers and a "vt" 1
/// or 2 (further numbers, a w or a colour, must be numbers and are not used); those used
/// are finite and within PLUME_SPEC_MAX_MAGNITUDE (1e12).
/// PLUME_ERROR_SYNTAX "path:line: what" on: a token that is not a number, a coordinate
/// that is not finite or too large, a corner that is not an index, an index out of
/// range, a face of fewer than 3 corners, a file without faces. PLUME_ERROR_IO on a file
/// that cannot be read, PLUME_ERROR_MEMORY. On any error *obj is left empty.
plume_status plume_obj_read(const char *path, plume_obj_content content, plume_obj *obj, plume_error *err);

void plume_obj_free(plume_obj *obj);

#endif // PLUME_IO_OBJ_READER_H

// plume meshes: the triangle shells the simulator deforms.
//
// A plume_mesh is plain data: the caller reads its arrays directly. It keeps
// two rest states: `reference`, the flat material coordinates in the feather
// plane that the membrane energy measures strain against, and `rest`, the 3D
// shape of the feather at rest whose curvature is the bending energy's rest
// curvature (Jouve thesis 6.2-6.3). Meshes are made from a plume_feather
// (its rachis and barbs are the guides), from explicit guides, or by the lab's
// sample builders; plume_mesh_create gives empty arrays for any other builder.
#ifndef PLUME_MESH_H
#define PLUME_MESH_H

#include "plume/core.h"
#include "plume/feather.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

/// Material of a face.
typedef enum plume_material_id {
	PLUME_MATERIAL_VANE = 0,
	PLUME_MATERIAL_RACHIS = 1,
} plume_material_id;

/// A named set of vertices, for handles and measurements.
typedef struct plume_vertex_group {
	char name[32];
	int count;
	int *vertices;
} plume_vertex_group;

typedef struct plume_mesh {
	int vertex_count;
	int face_count;
	/// Material coordinates in the reference plane, m (vertex_count).
	plume_vec2 *reference;
	/// 3D rest shape, m (vertex_count). Equal to (reference, 0) for a flat feather.
	plume_vec3 *rest;
	/// Texture coordinates carried over from the feather (vertex_count).
	plume_vec2 *uv;
	/// Three vertex indices per face, counter-clockwise in the reference plane (3 * face_count).
	int *faces;
	/// Per face: index into the simulation's material table. Feathers use
	/// plume_material_id (vane 0, rachis 1); the lab's band samples use their own indices.
	unsigned char *material;
	/// Per face: barb direction in the reference plane, radians from the +x axis,
	/// in [0, pi). Rachis faces keep the rachis direction (unused by isotropic materials).
	double *barb_angle;
	/// Per face: local index k (0..2) of the edge (faces[3f+k], faces[3f+(k+1)%3]) that lies on a barb
	/// guide, or -1 when the face has none (rachis faces, unaligned meshes).
	signed char *barb_edge;
	/// Unique barb-aligned edges, two vertex indices each (2 * barb_edge_count): the edges the
	/// inextensibility constraint holds at their reference length.
	int barb_edge_count;
	int *barb_edges;
	int group_count;
	plume_vertex_group *groups;
} plume_mesh;

/// Parameters of the barb-aligned mesher (Jouve thesis 6.2, paper Figure 7).
typedef struct plume_mesh_def {
	/// e: target edge length, m, > 0. Default 5e-3 (thesis Table 6.1).
	double edge_length;
	/// w_b: rachis band width at the base, m, > 0. Default: the feather's shaft width at the base of the vane.
	/// A value <= 0 means "take it from the feather".
	double rachis_width_base;
	/// w_e: rachis band width at the tip, m. <= 0 means "take it from the feather".
	double rachis_width_tip;
	/// Keep the bare calamus below the vane as rachis faces. Default true.
	bool include_calamus;
	/// Bytes the mesher may use, estimated before it places the guide vertices
	/// (plume_mesh_estimate_feather); PLUME_ERROR_LIMIT past it. 0 (the default)
	/// means PLUME_DEFAULT_MAX_MEMORY.
	uint64_t max_memory;
	/// PLUME_DEF_COOKIE, set by plume_mesh_default_def; do not change.
	uint32_t cookie;
} plume_mesh_def;

plume_mesh_def plume_mesh_default_def(void);

/// The smallest vane angle the aligned mesher keeps outside junction faces, degrees.
#define PLUME_MESH_QUALITY_ANGLE_DEG 20.0

/// What the mesher measured.
typedef struct plume_mesh_report {
	/// Smallest interior angle over all faces, radians.
	double min_angle;
	/// Fraction of vane faces with an edge on a barb guide; the aligned mesher always reaches 1.
	double aligned_fraction;
	/// Input barbs left out of the guide set: those whose (smoothed) guide crossed the
	/// previous kept guide, and those with no length in the feather plane or non-finite points.
	int guides_dropped;
	/// Guides the mesher used, per vane (left, right): one interpolated guide per rachis row
	/// that has vane vertices.
	int guide_count[2];
	/// Input barbs rooted within one edge length of each other along the rachis and averaged
	/// into one smoothed guide (dense or randomly shaped barbs, Franco & Walter 4.3).
	int barbs_averaged;
	/// Guide vertices cut off where two neighbouring guides came too close to give valid
	/// triangles (0 for well-formed input).
	int vertices_trimmed;
	/// The target edge length e used, m.
	double edge_length;
	/// Smallest interior angle over the vane faces that are not junction faces, radians.
	/// pi when there are none (every vane face is a junction face, or there is no vane
	/// face): no triangle has that angle, so vane_min_angle >= pi tells the case apart;
	/// `plume mesh` writes null in report.json then. The aligned mesher keeps it at or
	/// above PLUME_MESH_QUALITY_ANGLE_DEG.
	double vane_min_angle;
	/// Junction faces: vane faces with an angle under PLUME_MESH_QUALITY_ANGLE_DEG where every such angle
	/// lies between the face's barb edge and an edge on the vane's border (the rachis
	/// band or the outline), that is where a guide meets the rachis or the outline at a
	/// shallow angle that the feather's shape, not the mesher, sets, or faces the rachis
	/// tip edge (group rachis_tip), where the two vanes' last guides meet the rachis: the
	/// angle the shaft's width at its tip subtends (docs/meshing.md).
	int excepted_count;
} plume_mesh_report;

/// Meshes a generated feather: the shaft is the rachis centre line, the barbs are
/// the barb guides. The feather's 3D shape is the rest shape; its projection on
/// the feather plane is the reference. report may be NULL.
plume_status plume_mesh_from_feather(const plume_feather *feather, const plume_mesh_def *def, plume_mesh **out,
                                     plume_mesh_report *report, plume_error *err);

/// Explicit guides in the feather plane (thesis 6.2: boundary, rachis spline, barb guide splines).
typedef struct plume_mesh_guides {
	/// Closed boundary polygon of the feather, counter-clockwise, m.
	int boundary_count;
	const plume_vec2 *boundary;
	/// Rachis centre line, base first (a polyline; pass a sampled spline).
	int rachis_count;
	const plume_vec2 *rachis;
	/// Barb guides: guide_count polylines, each from its root near the rachis outward,
	/// stored back to back in guide_points with guide_offsets[i]..guide_offsets[i+1].
	int guide_count;
	const int *guide_offsets;
	const plume_vec2 *guide_points;
} plume_mesh_guides;

plume_status plume_mesh_from_guides(const plume_mesh_guides *guides, const plume_mesh_def *def, plume_mesh **out,
                                    plume_mesh_report *report, plume_error *err);

/// What meshing would build, counted before the work: the rows along the rachis
/// and the guide vertices every edge length along each row's guide, as the mesher
/// places them before any trimming (so an upper bound of the mesh's vertices).
typedef struct plume_mesh_estimate {
	double rows;          ///< rachis rows, two rachis vertices each
	double vertices;      ///< guide and rachis vertices, at most
	double faces;         ///< faces, at most (two per vertex)
	double bytes;         ///< the mesher's peak memory, about PLUME_MESH_BYTES_PER_VERTEX a vertex
	double rachis_length; ///< plane arc length of the rachis, m
	double longest_guide; ///< the longest guide line, m (clipped to, or extended to, the boundary)
} plume_mesh_estimate;

/// Bytes the mesher and its mesh take per vertex, about: the point pool (grown
/// by doubling), its spatial index, the mesh's arrays and two faces with their
/// overlap check.
#define PLUME_MESH_BYTES_PER_VERTEX 320

/// Counts what plume_mesh_from_feather (def) would build, without building it;
/// fails as it would on a feather it cannot mesh (a shaft too short, no width).
plume_status plume_mesh_estimate_feather(const plume_feather *feather, const plume_mesh_def *def,
                                         plume_mesh_estimate *out, plume_error *err);
/// The same for plume_mesh_from_guides.
plume_status plume_mesh_estimate_guides(const plume_mesh_guides *guides, const plume_mesh_def *def,
                                        plume_mesh_estimate *out, plume_error *err);

/// Options of plume_mesh_spec_read.
typedef struct plume_mesh_spec_options {
	/// > 0: overrides the spec's edge length, m. Default 0 (the spec's, else plume_mesh_default_def's).
	double edge_length;
	/// Overrides a feather spec's "seed" when seed_given is true.
	uint64_t seed;
	bool seed_given;
	/// Bytes generating the feather and meshing it may take (plume_spec_options.max_memory,
	/// plume_mesh_def.max_memory). Default 0: PLUME_DEFAULT_MAX_MEMORY.
	uint64_t max_memory;
} plume_mesh_spec_options;

plume_mesh_spec_options plume_mesh_spec_default_options(void);

/// Reads and meshes a spec file: a guides spec (an object with "guides",
/// "rachis", "boundary" and an optional "mesh" definition, docs/meshing.md),
/// or else any feather spec, generated with plume_spec_generate and meshed with
/// the default definition. Errors name the file and the JSON path.
plume_status plume_mesh_spec_read(const char *path, const plume_mesh_spec_options *options, plume_mesh **out,
                                  plume_mesh_report *report, plume_error *err);

/// Allocates a mesh with zeroed arrays of the given sizes (barb_edges, groups empty).
/// The builder fills them. Returns NULL when out of memory.
plume_mesh *plume_mesh_create(int vertex_count, int face_count);

/// Adds a vertex group (copies the indices). Names are at most 31 bytes.
plume_status plume_mesh_add_group(plume_mesh *mesh, const char *name, const int *vertices, int count, plume_error *err);

/// Adds group `name` holding the vertices of group `source` whose reference position lies
/// within radius (m) of near. PLUME_ERROR_SPEC when source is unknown or no vertex is that close.
plume_status plume_mesh_add_group_near(plume_mesh *mesh, const char *name, const char *source, plume_vec2 near,
                                       double radius, plume_error *err);

/// One piece of plume_mesh_concatenate: a mesh and the rigid placement of its rest shape.
typedef struct plume_mesh_part {
	const plume_mesh *mesh;
	/// Rest positions go to rotation * rest + translation (a rotation: orthonormal, det +1).
	/// reference and uv are material coordinates and stay as they are.
	plume_mat3 rotation;
	plume_vec3 translation;
	/// Prefix of this part's vertex groups: "f3" names group "rachis_clamp" "f3/rachis_clamp".
	const char *prefix;
} plume_mesh_part;

/// One mesh of the parts, back to back: part i's vertices follow part i-1's, its faces and
/// barb edges are offset accordingly, its rest positions placed by its rigid motion. Vertex
/// groups: first one group per name found in any part holding that name's vertices of every
/// part (in part order: "rachis_clamp" is every part's clamp), then each part's own groups
/// as "prefix/name". PLUME_ERROR_SPEC when a prefixed name passes 31 bytes, two prefixes are
/// equal or two groups would share a name; PLUME_ERROR_LIMIT when the counts overflow an int;
/// PLUME_ERROR_MEMORY. Time O(n log n) in the number of groups.
plume_status plume_mesh_concatenate(const plume_mesh_part *parts, int count, plume_mesh **out, plume_error *err);

/// Rebuilds barb_edges from the faces' barb_edge marks (unique edges, sorted).
plume_status plume_mesh_collect_barb_edges(plume_mesh *mesh, plume_error *err);

/// The group with that name, or NULL.
const plume_vertex_group *plume_mesh_find_group(const plume_mesh *mesh, const char *name);

/// Minimum angle, aligned fraction, vane minimum angle and junction faces of any mesh
/// (faces with no barb edge are never junction faces).
plume_mesh_report plume_mesh_measure(const plume_mesh *mesh);

void plume_mesh_destroy(plume_mesh *mesh);

/// Reads a polygon mesh from Wavefront OBJ (docs/formats.md, "Reading OBJ meshes"):
/// v, vt, f and g lines; f corners v, v/vt, v//vn or v/vt/vn, 1-based or negative
/// (counted back from the last one so far); comments, blank lines, CRLF and other
/// lines (normals, objects, materials) ignored; numbers in the "C" locale. A face of
/// n >= 3 corners (c0, ..., c_n-1) is fan-triangulated from its first corner into the
/// n - 2 triangles (c0, c_i, c_i+1), i = 1 .. n-2, in that order (exact for convex
/// planar polygons). rest holds the positions, reference their (x, y), uv the texture
/// coordinates when every corner has one (else zero; a vertex with several keeps its
/// first). Each triangle gets its face's material from the group name the writer gives
/// it ("rachis", "material_N"; else the vane's, 0) and barb_edge -1.
/// PLUME_ERROR_SYNTAX "file:line: what" on a token that is not a number, a coordinate
/// that is not finite or beyond 1e12, a corner that is not an index, an index out of
/// range, a face of fewer than 3 corners or no faces at all; PLUME_ERROR_IO when the
/// file cannot be read. On any error *out is NULL.
plume_status plume_mesh_read_obj(const char *path, plume_mesh **out, plume_error *err);

/// Writes the mesh with the given vertex positions (rest when positions is NULL)
/// as Wavefront OBJ with UVs and one group per material, atomically.
plume_status plume_mesh_write_obj(const plume_mesh *mesh, const plume_vec3 *positions, const char *path,
                                  plume_error *err);

/// Writes many frames of one mesh (plume simulate's frames/NNNN.obj): the same
/// bytes as plume_mesh_write_obj, but the lines that do not change from frame to
/// frame (texture coordinates, groups, faces) are formatted once, at creation.
/// The writer keeps a pointer to mesh, which must outlive it and not change.
typedef struct plume_mesh_obj_writer plume_mesh_obj_writer;
plume_status plume_mesh_obj_writer_create(const plume_mesh *mesh, plume_mesh_obj_writer **out, plume_error *err);
plume_status plume_mesh_obj_writer_write(const plume_mesh_obj_writer *writer, const plume_vec3 *positions,
                                         const char *path, plume_error *err);
void plume_mesh_obj_writer_destroy(plume_mesh_obj_writer *writer);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_MESH_H

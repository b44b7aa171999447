// plume bodies: the animated triangle meshes feathers hang on and collide with
// (docs/body.md). A body is a rest mesh (an OBJ file or a built-in shape), moved
// rigidly by keyframes or by a small skeleton of bones with keyframed rotations
// that skins the mesh and carries the feathers' follicles.
//
// Motion. The body as a whole (bone -1) moves like a scene handle: at time t a rest
// point x goes to R(t) (x - pivot) + pivot + T(t). A bone b with parent p turns about
// its head h_b, in its parent's frame: M_b(x) = M_p(R_b(t) (x - h_b) + h_b + T_b(t)),
// roots taking the body's motion as parent. Every transform maps rest (world)
// coordinates to posed ones, so they compose by plain function composition.
// Skinning is linear blend skinning: a vertex goes to sum_i w_i M_{b_i}(x).
#ifndef PLUME_BODY_H
#define PLUME_BODY_H

#include "plume/core.h"
// plume_keyframe and plume_interpolation: a body moves by the same keys as a scene's
// handles. (scene.h only needs `typedef struct plume_body plume_body;` to hold a body.)
#include "plume/scene.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

typedef struct plume_body plume_body;

/// The most bones a body may have, and the longest bone name (with its terminating 0).
#define PLUME_BODY_MAX_BONES 256
#define PLUME_BODY_NAME_SIZE 32
/// The most bones one vertex may be skinned to.
#define PLUME_BODY_MAX_INFLUENCES 4

/// One bone of a body's skeleton.
typedef struct plume_body_bone_def {
	/// Unique, non-empty, at most PLUME_BODY_NAME_SIZE - 1 bytes.
	char name[PLUME_BODY_NAME_SIZE];
	/// Index of the parent bone, -1 for a root (which follows the body's rigid motion).
	int parent;
	/// The joint the bone turns about, rest position, m.
	plume_vec3 head;
	/// The bone's other end at rest, m: with the head, the segment automatic skinning
	/// measures distances to. Equal to head for a point-like bone.
	plume_vec3 tail;
	/// Rotation (about head) and translation, in the parent's frame; keyframe times
	/// increasing. None: the bone keeps its rest pose relative to its parent.
	plume_interpolation interpolation;
	int keyframe_count;
	const plume_keyframe *keyframes;
} plume_body_bone_def;

typedef enum plume_body_skinning {
	/// Each vertex follows its two nearest bones (distance to the head–tail segments), with
	/// weights proportional to d^-4, normalised: a vertex at a joint is shared half and half,
	/// one halfway along a bone of length 4 r (r its distance to the bone) gets under 4 % from
	/// the next bone. A vertex on a segment follows that bone alone. Ties go to the lower index.
	PLUME_BODY_SKIN_BLEND = 0,
	/// Each vertex follows its nearest bone alone (rigid segments).
	PLUME_BODY_SKIN_NEAREST,
} plume_body_skinning;

/// What plume_body_create reads; the arrays are copied.
typedef struct plume_body_def {
	/// The rest mesh: vertex_count >= 3 finite positions, m, and triangle_count >= 1
	/// triangles (3 indices each, counter-clockwise seen from outside), none of zero area
	/// (area <= 1e-12 of its longest edge squared) or with an index out of range.
	int vertex_count;
	const plume_vec3 *vertices;
	int triangle_count;
	const int *triangles;
	/// The body's rigid motion (bone -1): keys as for a scene handle, rotation about pivot.
	/// Default: no keys (the body stays at rest), pivot at the origin, linear.
	plume_vec3 pivot;
	plume_interpolation interpolation;
	int keyframe_count;
	const plume_keyframe *keyframes;
	/// The skeleton, at most PLUME_BODY_MAX_BONES bones. Default none: every vertex follows
	/// the rigid motion.
	int bone_count;
	const plume_body_bone_def *bones;
	/// How vertices are weighted to bones when skin_bones is NULL. Default BLEND.
	plume_body_skinning skinning;
	/// Given skin weights (optional): skin_influences (1 to PLUME_BODY_MAX_INFLUENCES) bone
	/// indices and weights per vertex, vertex-major; a bone index of -1 is an unused slot.
	/// Weights >= 0 with a positive sum; they are normalised to sum 1.
	int skin_influences;
	const int *skin_bones;
	const double *skin_weights;
	/// PLUME_DEF_COOKIE, set by plume_body_default_def; do not change.
	uint32_t cookie;
} plume_body_def;

plume_body_def plume_body_default_def(void);

/// Checks def and creates the body. Errors (PLUME_ERROR_SPEC) start with the field at
/// fault in the definition's own terms, which are those of the JSON spec:
/// "vertices[4]: ...", "triangles[12]: ...", "bones[2].parent: ...",
/// "bones[1].keyframes[3].time: ...", "keyframes[0].axis: ...", "skin_weights[7]: ...".
plume_status plume_body_create(const plume_body_def *def, plume_body **out, plume_error *err);
void plume_body_destroy(plume_body *body);

/// A closed triangle mesh for a body, owned by the caller (plume_body_mesh_free).
typedef struct plume_body_mesh {
	int vertex_count;
	plume_vec3 *vertices;
	int triangle_count;
	int *triangles;
} plume_body_mesh;

/// The ellipsoid ((x-c_x)/r_x)^2 + ((y-c_y)/r_y)^2 + ((z-c_z)/r_z)^2 = 1 as a latitude–
/// longitude mesh: `segments` (>= 3) meridians, max(2, segments / 2) bands of latitude
/// from the pole at -z to the pole at +z, every vertex on the surface; closed and
/// counter-clockwise seen from outside. 2 + (bands - 1) segments vertices.
/// PLUME_ERROR_SPEC on radii that are not finite and positive or on segments < 3 or > 4096.
plume_status plume_body_ellipsoid(plume_vec3 center, plume_vec3 radii, int segments, plume_body_mesh *out,
                                  plume_error *err);
/// A capsule: the points within radius of the segment a–b, `segments` (>= 3) vertices
/// around, max(1, segments / 4) bands of latitude on each hemispherical cap and, along the
/// cylinder, bands no longer than the edges around it (at most 4096), so that a capsule
/// skinned to a chain of bones bends between rings; every vertex on the surface; closed,
/// counter-clockwise seen from outside. a != b.
plume_status plume_body_capsule(plume_vec3 a, plume_vec3 b, double radius, int segments, plume_body_mesh *out,
                                plume_error *err);
void plume_body_mesh_free(plume_body_mesh *mesh);

int plume_body_vertex_count(const plume_body *body);
int plume_body_triangle_count(const plume_body *body);
/// 3 vertex indices per triangle, counter-clockwise seen from outside.
const int *plume_body_triangles(const plume_body *body);
const plume_vec3 *plume_body_rest_positions(const plume_body *body);

/// The body's vertex positions at time t, s (keyframes interpolated, skinning applied),
/// into out[vertex_count]. Deterministic; t before the first key holds the first pose.
///
/// Interpolation between two keys (linear, or smoothstep 3 s^2 - 2 s^3 of the key
/// fraction s): translations linearly; rotations by angle when both keys have the same
/// axis (so one key interval may turn more than half a turn), otherwise by spherical
/// linear interpolation of the keys' quaternions (the shorter arc).
void plume_body_pose(const plume_body *body, double t, plume_vec3 *out);

/// Number of bones (0 for a body without a skeleton) and the index of a named bone
/// (-1 when there is none). Bone -1 stands for the body's rigid motion as a whole.
int plume_body_bone_count(const plume_body *body);
int plume_body_find_bone(const plume_body *body, const char *name);
const char *plume_body_bone_name(const plume_body *body, int bone);

/// Where a point fixed to a bone (bone -1: to the whole body) at rest goes at time t:
/// rotation * rest_point + translation.
void plume_body_bone_transform(const plume_body *body, int bone, double t, plume_mat3 *rotation,
                               plume_vec3 *translation);

/// The bone a follicle at this rest point rides on: the one with the largest sum of skin
/// weights over the corners of the nearest rest triangle (ties: the lower index); -1 for a
/// body without bones.
int plume_body_nearest_bone(const plume_body *body, plume_vec3 point);

/// Distance, m, from a rest-pose point to the rest surface (unsigned), and the
/// closest triangle (may be NULL): for checking that a follicle lies on the body.
double plume_body_rest_distance(const plume_body *body, plume_vec3 point, int *triangle);

/// Reads a body from a JSON file (docs/body.md); a relative "mesh" path is relative to
/// the file's folder. Errors name the file and the JSON path ("body.json: $.bones[1].parent:
/// ..."), or the OBJ file and line.
plume_status plume_body_load(const char *path, plume_body **out, plume_error *err);
/// The same from JSON text; name stands for the file in messages, and a relative mesh
/// path is relative to the current folder.
plume_status plume_body_parse(const char *text, const char *name, plume_body **out, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_BODY_H

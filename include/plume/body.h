// plume bodies: the animated triangle meshes feathers hang on and collide with
// (docs/scene.md). A body is a rest mesh (an OBJ file or a built-in shape), moved
// rigidly by keyframes or by a small skeleton of bones with keyframed rotations
// that skins the mesh and carries the feathers' follicles.
// (Contract written before the implementation; the body helper owns this file.)
#ifndef PLUME_BODY_H
#define PLUME_BODY_H

#include "plume/core.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

typedef struct plume_body plume_body;

void plume_body_destroy(plume_body *body);

int plume_body_vertex_count(const plume_body *body);
int plume_body_triangle_count(const plume_body *body);
/// 3 vertex indices per triangle, counter-clockwise seen from outside.
const int *plume_body_triangles(const plume_body *body);
const plume_vec3 *plume_body_rest_positions(const plume_body *body);

/// The body's vertex positions at time t, s (keyframes interpolated, skinning applied),
/// into out[vertex_count]. Deterministic; t before the first key holds the first pose.
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

/// Distance, m, from a rest-pose point to the rest surface (unsigned), and the
/// closest triangle (may be NULL): for checking that a follicle lies on the body.
double plume_body_rest_distance(const plume_body *body, plume_vec3 point, int *triangle);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_BODY_H

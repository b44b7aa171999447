// Private: what a scene adds to contact — its body as an obstacle, with the skin around
// each follicle left out — and the independent intersection check of its frames
// (docs/contact.md, "Contact in scenes").
#ifndef PLUME_SIM_SCENE_CONTACT_H
#define PLUME_SIM_SCENE_CONTACT_H

#include "plume/scene.h"

/// Which faces of the scene's mesh sit on the body at a follicle: the faces with a vertex
/// in the rachis_clamp group of a feather the body carries (the calamus, which enters the
/// skin). into follicle_face[scene->mesh->face_count].
void plume_scene_follicle_faces(const plume_scene *scene, bool *follicle_face);

typedef struct plume_scene_surfaces plume_scene_surfaces;

/// Prepares a run's contact and checks: with contact on and a body, the body posed at t = 0
/// becomes an obstacle of sim (less its triangles at the follicles); the soup of the
/// intersection check holds the shell's faces and every body triangle.
plume_status plume_scene_surfaces_create(const plume_scene *scene, plume_sim *sim, const plume_vec3 *body_rest_pose,
                                         plume_scene_surfaces **out, plume_error *err);
void plume_scene_surfaces_destroy(plume_scene_surfaces *surfaces);

/// The body posed at the end of the next step (no-op without a body obstacle).
void plume_scene_surfaces_move_body(plume_scene_surfaces *surfaces, plume_sim *sim, const plume_vec3 *body_pose);

/// Exact count (plume_find_intersections) of the pairs of triangles that intersect among
/// the shell at shell_positions and the body at body_pose (NULL without a body): every
/// pair counts except a follicle face against the body and the body against itself. With a pair, *first_pair gets
/// its two triangles (shell faces first, then body triangles from face_count on).
plume_status plume_scene_surfaces_intersections(plume_scene_surfaces *surfaces, const plume_vec3 *shell_positions,
                                                const plume_vec3 *body_pose, int *count, int first_pair[2],
                                                plume_error *err);

#endif // PLUME_SIM_SCENE_CONTACT_H

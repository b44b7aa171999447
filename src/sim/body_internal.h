// Private: the checks that plume_body_create makes on a rest mesh, shared with the
// readers that can name a file and line (the OBJ reader of src/io/spec_body.c).
#ifndef PLUME_SIM_BODY_INTERNAL_H
#define PLUME_SIM_BODY_INTERNAL_H

#include <stdbool.h>

#include "plume/core.h"
#include "plume/scene.h"

/// True when the triangle has (numerically) zero area: |(b - a) x (c - a)| at most
/// 1e-12 times its longest edge squared, which also catches repeated vertices and
/// collinear ones. A triangle with a non-finite corner counts as degenerate.
bool plume_body_triangle_degenerate(plume_vec3 a, plume_vec3 b, plume_vec3 c);

/// The keys' translation and rotation at t (identity without keys): a body's, a bone's and a
/// scene handle's keys move alike (docs/body.md "Interpolation"). Before the first key its
/// pose, from the last on the last's; between two, translations interpolate linearly, a key
/// without rotation takes the other's axis, a shared axis interpolates the angle and two
/// different axes slerp along the shorter arc.
void plume_keyframes_pose(const plume_keyframe *keys, int count, plume_interpolation interpolation, double t,
                          plume_vec3 *translation, plume_mat3 *rotation);

#endif // PLUME_SIM_BODY_INTERNAL_H

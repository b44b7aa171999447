// Private: the checks that plume_body_create makes on a rest mesh, shared with the
// readers that can name a file and line (the OBJ reader of src/io/spec_body.c).
#ifndef PLUME_SIM_BODY_INTERNAL_H
#define PLUME_SIM_BODY_INTERNAL_H

#include <stdbool.h>

#include "plume/core.h"

/// True when the triangle has (numerically) zero area: |(b - a) x (c - a)| at most
/// 1e-12 times its longest edge squared, which also catches repeated vertices and
/// collinear ones. A triangle with a non-finite corner counts as degenerate.
bool plume_body_triangle_degenerate(plume_vec3 a, plume_vec3 b, plume_vec3 c);

#endif // PLUME_SIM_BODY_INTERNAL_H

// Private: continuous collision detection for contact (helper-owned; contract).
// Additive CCD (Li, Kaufman, Jiang 2021, "Codimensional Incremental Potential
// Contact", section 5 and Algorithm 1): conservative advancement on the distance
// functions of sim/contact_distance.h, so a returned time of impact is never later
// than the true one.
#ifndef PLUME_SIM_CCD_H
#define PLUME_SIM_CCD_H

#include "plume/core.h"

/// The primitives move linearly from start[i] to end[i] over t in [0, 1]: point p =
/// [0], triangle a b c = [1..3]. Returns the largest t in [0, 1] such that, for every
/// time in [0, t], the distance stays above separation * (distance at t = 0), with the
/// conservative bound of additive CCD; 1 when no such approach happens. 0 <= separation < 1
/// (IPC uses 0.1-0.2: a line search step then leaves room for the barrier).
double plume_ccd_point_triangle(const plume_vec3 start[4], const plume_vec3 end[4], double separation);

/// The same for edges a0 a1 = [0..1] and b0 b1 = [2..3].
double plume_ccd_edge_edge(const plume_vec3 start[4], const plume_vec3 end[4], double separation);

#endif // PLUME_SIM_CCD_H

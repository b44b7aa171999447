// Private: the contact energy of one pair of primitives (helper-owned; contract).
// IPC's log barrier on squared distances (Li et al. 2020, "Incremental Potential
// Contact", eq. 6 and section 4): b(d²) = -(d² - d̂²)² ln(d² / d̂²) for d < d̂, 0 beyond,
// C² at d̂ and infinite at contact; edge-edge pairs are multiplied by the mollifier of
// IPC section 4.3 (eq. 14-15) so the energy stays smooth as two edges turn parallel.
#ifndef PLUME_SIM_CONTACT_BARRIER_H
#define PLUME_SIM_CONTACT_BARRIER_H

#include "sim/contact_distance.h"

#include <stdbool.h>

/// A pair of primitives: a point against a triangle (x[0] the point, x[1..3] the
/// triangle) or two edges (x[0..1] and x[2..3]).
typedef enum plume_contact_pair_type {
	PLUME_CONTACT_POINT_TRIANGLE = 0,
	PLUME_CONTACT_EDGE_EDGE,
} plume_contact_pair_type;

/// The barrier b(d²) of IPC eq. 6 with its first and second derivatives in d², for
/// 0 < d² ; zero (and zero derivatives) for d² >= d̂².
double plume_barrier(double d2, double dhat2, double *db, double *d2b);

/// The squared distance of a pair as a smooth function of its 12 coordinates, in the
/// region kind (plume_point_triangle_distance2 / plume_edge_edge_distance2 choose it):
/// gradient[12] and hessian[144] (row-major; either may be NULL).
double plume_pair_distance2(plume_contact_pair_type type, plume_distance_kind kind, const plume_vec3 x[4],
                            double *gradient, double *hessian);

/// Energy of one pair, stiffness * mollifier * b(d²), with its gradient[12] and
/// hessian[144] in the 12 coordinates of x (either may be NULL). rest holds the pair's
/// rest positions (the mollifier's threshold is 1e-3 times the product of the rest
/// squared edge lengths, IPC eq. 15); ignored for point-triangle pairs. With
/// project_psd the Hessian is projected to the nearest positive semi-definite matrix.
/// Zero beyond d̂. x must not be in contact (d > 0).
double plume_contact_pair_energy(plume_contact_pair_type type, const plume_vec3 x[4], const plume_vec3 rest[4],
                                 double dhat, double stiffness, bool project_psd, double *gradient,
                                 double *hessian);

#endif // PLUME_SIM_CONTACT_BARRIER_H

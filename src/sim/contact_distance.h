// Private: distances between the primitives of triangle surfaces, for contact
// (Li et al. 2020, "Incremental Potential Contact", section 4): a point and a
// triangle, two edges. Squared distances throughout, as IPC's barrier takes them:
// they are polynomial where the closest points are interior, so their derivatives
// are cheap and exact.
#ifndef PLUME_SIM_CONTACT_DISTANCE_H
#define PLUME_SIM_CONTACT_DISTANCE_H

#include "plume/core.h"

/// Which features of the two primitives are closest: the squared distance is a smooth
/// function of the points involved inside each region (IPC section 4.2, Figure 4).
typedef enum plume_distance_kind {
	/// Point-triangle: the point against vertex a, b or c; edge ab, bc or ca; the interior.
	PLUME_PT_A = 0,
	PLUME_PT_B,
	PLUME_PT_C,
	PLUME_PT_AB,
	PLUME_PT_BC,
	PLUME_PT_CA,
	PLUME_PT_PLANE,
	/// Edge-edge (a0 a1 against b0 b1): an endpoint against an endpoint, an endpoint
	/// against the other edge, or the two lines.
	PLUME_EE_A0_B0,
	PLUME_EE_A0_B1,
	PLUME_EE_A1_B0,
	PLUME_EE_A1_B1,
	PLUME_EE_A0_B,
	PLUME_EE_A1_B,
	PLUME_EE_A_B0,
	PLUME_EE_A_B1,
	PLUME_EE_LINES,
} plume_distance_kind;

/// Squared distance from p to the triangle abc (closed), and which region is closest.
/// A degenerate triangle (zero area) is measured against its edges. kind may be NULL.
double plume_point_triangle_distance2(plume_vec3 p, plume_vec3 a, plume_vec3 b, plume_vec3 c,
                                      plume_distance_kind *kind);

/// Squared distance between the closed segments a0 a1 and b0 b1, and which features are
/// closest. Parallel segments are measured between endpoints and edges (never LINES).
/// kind may be NULL.
double plume_edge_edge_distance2(plume_vec3 a0, plume_vec3 a1, plume_vec3 b0, plume_vec3 b1,
                                 plume_distance_kind *kind);

#endif // PLUME_SIM_CONTACT_DISTANCE_H

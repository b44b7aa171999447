// Private: plane St-Venant-Kirchhoff samples on quadratic triangles: the mesoscale band
// model (Jouve thesis 5.2) and, for a converged tilted test, the macroscale vane (4.1).
//
// The barb bands are 6.5e4 times stiffer than the barbule bands and only one or two
// element rows wide. In the tilted test the barbs clamped at one end must bend in plane
// to rotate, and linear triangles a row or two across a band cannot bend without
// shearing (shear locking): their tilted slope fell from 11.2 to 5.1 E_b between 500 and
// 8000 triangles and was still falling. Quadratic triangles hold a strain that varies
// linearly across the band, which is pure bending, so the band model converges at a
// few thousand elements. The macroscale vane without the barb constraint has the same
// trouble in the tilted test on linear triangles (E_vv / E_ww = 7500): its slope fell
// by 3 % from 2000 to 16000 triangles and rose again at 32000 (docs/lab.md). This solver
// is planar (two unknowns per node), clamps the sample's "bottom" and "top" groups and
// minimises a St-Venant-Kirchhoff energy with a Voigt tensor per element (and Kikuuwe's
// term) by Newton's method on CHOLMOD's simplicial Cholesky factorisation.
#ifndef PLUME_LAB_QUADRATIC_H
#define PLUME_LAB_QUADRATIC_H

#include "plume/lab.h"

typedef struct plume_quadratic plume_quadratic;

/// One static solve.
typedef struct plume_quadratic_report {
	bool converged;
	int newton_iterations;
	/// Load increments the solve needed (1 unless it was retried in smaller ones).
	int substeps;
	/// Largest free force component over the largest clamp force component at the end.
	double relative_residual;
	/// y force of the top clamp on the sample, N.
	double force;
} plume_quadratic_report;

/// Builds the quadratic model of a sample mesh (plume_sample_mesh): edge midpoints become
/// nodes; face f has the plane Voigt tensor voigt[9 f .. 9 f + 8] (Pa, (xx, yy, 2xy),
/// row-major, as plume_isotropic_tensor and plume_orthotropic_tensor give it) and every face
/// Kikuuwe's compression term with coefficient kappa (Pa, 0 for none).
plume_status plume_quadratic_create(const plume_mesh *mesh, const double *voigt, double kappa, double thickness,
                                    const plume_solver_def *solver, plume_quadratic **out, plume_error *err);
void plume_quadratic_destroy(plume_quadratic *model);

/// Moves the top clamp to y = H + displacement (the bottom one stays) and solves the static
/// problem from the previous solution, retrying in 2, 4 ... increments when Newton fails.
/// PLUME_ERROR_NUMERIC: not converged; the state is then the best iterate (finite).
plume_status plume_quadratic_solve(plume_quadratic *model, double displacement, plume_quadratic_report *report,
                                   plume_error *err);

/// Deformed positions of the mesh's vertices (the triangles' corners), z = 0.
void plume_quadratic_positions(const plume_quadratic *model, plume_vec3 *out);

/// For the finite-difference tests: the nodes (reference x, y per node; corners first), the six
/// nodes of an element (corners, then the midpoints of edges 01, 12, 20), and one element's
/// energy at node coordinates x (2 per node) with its gradient (12) and Hessian (144,
/// row-major) over the element's coordinates when not NULL.
int plume_quadratic_node_count(const plume_quadratic *model);
const int *plume_quadratic_element_nodes(const plume_quadratic *model, int element);
double plume_quadratic_element_energy(const plume_quadratic *model, int element, const double *x, double *gradient,
                                      double *hessian);

#endif

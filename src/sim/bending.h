// Anisotropic discrete-shell bending (Grinspun et al. 2003; thesis section 6.3, eqs.
// 6.2-6.5; paper section 7, eqs. 6-8): one energy per interior edge (hinge),
// stiffness (eta - eta0)^2 with eta = 3 e chi / (A1 + A2) (NOTES.md).
//
// Normalisation: eq. 6.2 read literally, (A1 + A2)/6 D (eta - eta0)^2, sums on a mesh of
// equilateral triangles with uniform principal curvatures k1, k2 to the energy density
// (3/2) D (k1^2 + k2^2 - (2/3) k1 k2) in every mesh orientation (the dihedral angle across
// an edge is h (k_nn - k_tt/3), h the triangle height), i.e. THREE times the continuum
// (1/2) D k^2 of a cylinder; test_energies measures the ratio 2.95 at 32 triangles across
// a rolled strip, 3.000 when extrapolated. NOTES.md and the issue take D as the continuum
// modulus (a cylinder stores (1/2) D A / R^2), so the stiffness here is (A1 + A2)/18 D(beta):
// cylindrical bending is then exact as the mesh is refined (the discrete energy behaves
// like a plate of Poisson ratio -1/3 in doubly curved bending).
#ifndef PLUME_SIM_BENDING_H
#define PLUME_SIM_BENDING_H

#include <stdbool.h>

#include "plume/core.h"

typedef struct plume_hinge {
	/// Shared edge x0-x1; x2 opposite in face A, x3 opposite in face B.
	int vertices[4];
	/// (A1 + A2)/18 * D(beta), N m (energy = stiffness * (eta - eta0)^2, thesis eq. 6.2 with
	/// the continuum normalisation explained above).
	double stiffness;
	/// 3 e / (A1 + A2), 1/m, so that eta = scale * chi (thesis eq. 6.3, NOTES.md).
	double scale;
	/// chi_0: the signed dihedral angle in the 3D rest shape, radians.
	double rest_angle;
} plume_hinge;

/// D(beta) = (D_along - D_across)/2 cos(2 beta) + (D_along + D_across)/2 (thesis eq. 6.4;
/// NOTES.md: along = edge parallel to the barbs, beta = 0, the soft value).
double plume_bending_modulus(double along, double across, double beta);

/// Areas and edge length from the reference (material) triangles; rest angle from the 3D
/// rest positions; beta = area-weighted average of the tilt angles between the edge and
/// each face's barb direction (cos a, sin a) in the reference plane (thesis eq. 6.5), each
/// tilt taken in [0, pi/2]. Returns false when either reference triangle is degenerate or
/// the rest shape has a degenerate face.
bool plume_hinge_init(plume_hinge *hinge, const int vertices[4], const plume_vec2 reference[4],
                      const plume_vec3 rest[4], double barb_angle_a, double barb_angle_b, double along, double across);

/// Signed dihedral angle chi in (-pi, pi] of the hinge x0-x1 with wings x2 (face A) and x3
/// (face B): 0 when flat; positive when the wings fold towards the side that face A's
/// normal n_A = (x1 - x0) x (x2 - x0) points to (a valley seen from that side).
double plume_dihedral_angle(const plume_vec3 x[4]);

/// chi with its gradient (12, vertex-major) and exact Hessian (144, row-major, symmetric);
/// either may be NULL. Derivatives are zero when a face is degenerate.
double plume_dihedral_angle_derivatives(const plume_vec3 x[4], double gradient[12], double hessian[144]);

/// Energy stiffness * scale^2 * (chi - chi0)^2 (chi - chi0 wrapped into (-pi, pi]), with
/// gradient (12) / hessian (144, NOT projected), either may be NULL.
double plume_hinge_energy(const plume_hinge *hinge, const plume_vec3 x[4], double gradient[12], double hessian[144]);

#endif // PLUME_SIM_BENDING_H

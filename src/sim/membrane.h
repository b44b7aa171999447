// In-plane energies of one shell triangle: the St-Venant-Kirchhoff membrane with an
// orthotropic (paper eq. 5, thesis A.2) or isotropic elasticity tensor, and the
// Kikuuwe compression term (thesis eq. 6.6). Each returns the energy and, on request,
// its exact gradient and Hessian with respect to the three vertex positions.
#ifndef PLUME_SIM_MEMBRANE_H
#define PLUME_SIM_MEMBRANE_H

#include <stdbool.h>

#include "plume/core.h"

/// One triangle's reference data, computed once from the planar (material) mesh.
typedef struct plume_membrane_element {
	int vertices[3];
	/// Inverse of Dm = [X1-X0 | X2-X0] (2x2, columns are reference edges), row-major.
	double inverse_rest[4];
	/// Reference area, m^2.
	double area;
	/// thickness * E in the reference (x, y) frame, Voigt (xx, yy, 2xy), row-major, Pa m.
	double stiffness[9];
	/// thickness * kappa, Pa m; 0 disables the Kikuuwe term.
	double compression;
} plume_membrane_element;

/// E(theta): the orthotropic tensor diag(E_vv, E_ww, E_vw) of the barb frame expressed in
/// the reference frame, the barb running along (cos theta, sin theta) in reference
/// coordinates (thesis section 6.2: theta is the angle from the x axis to the barb).
/// Voigt (xx, yy, 2xy) with sigma_vw = E_vw * 2 eps_vw (paper eq. 4, thesis eq. 4.1).
void plume_orthotropic_tensor(double E_vv, double E_ww, double E_vw, double theta, double voigt[9]);

/// Plane-stress isotropic St-Venant-Kirchhoff: E/(1-nu^2) [[1,nu,0],[nu,1,0],[0,0,(1-nu)/2]].
void plume_isotropic_tensor(double E, double nu, double voigt[9]);

/// Fills element from its reference triangle. kappa is the Kikuuwe coefficient, Pa.
/// Returns false when the reference triangle is degenerate (or not finite).
bool plume_membrane_element_init(plume_membrane_element *element, const int vertices[3], const plume_vec2 reference[3],
                                 double thickness, const double voigt[9], double kappa);

/// Energy A * (1/2) eps : E : eps (thickness folded into element->stiffness), eps the Green
/// strain (F^T F - I)/2 with F = [x1-x0 | x2-x0] Dm^-1 (3x2) (paper eq. 5).
/// gradient (9, vertex-major xyz) and hessian (9x9 row-major, symmetric, NOT projected)
/// may be NULL; they are overwritten, not accumulated.
double plume_membrane_energy(const plume_membrane_element *element, const plume_vec3 x[3], double gradient[9],
                             double hessian[81]);

/// Kikuuwe term A * thickness*kappa/12 * ((1-J)/6)^3 for J < 1, else 0 (thesis eq. 6.6), with
/// J = deformed area / reference area = sqrt(det(F^T F)). gradient/hessian as above; at a
/// triangle collapsed to zero area (J = 0) the derivatives do not exist and are returned as 0.
double plume_compression_energy(const plume_membrane_element *element, const plume_vec3 x[3], double gradient[9],
                                double hessian[81]);

/// The triangle's J = deformed area / reference area, as the Kikuuwe term measures it.
double plume_compression_area_ratio(const plume_membrane_element *element, const plume_vec3 x[3]);

/// Kikuuwe density psi per unit reference area at Green strain (Voigt, reference frame):
/// *psi always; with dpsi != NULL also its first (3) and second (3 x 3) strain derivatives,
/// returning true when they were written, false when they are zero.
///
/// secant_J = 1 gives the exact derivatives (written where 0 < J < 1). A secant_J below
/// J and below 1 replaces d2 psi / dJ2 in d2psi by the slope of the secant of d psi / dJ
/// from J to secant_J, a modified Hessian (psi and dpsi stay exact): psi is a cubic in
/// 1 - J with no curvature at J = 1, so the exact model of a triangle the step's start
/// left stretched has no compression stiffness, and Newton's step compresses it several
/// times as far as it will end (docs/simulation.md, "What the ordinary steps' iterations
/// go to"). The secant's model has the true force at secant_J, the triangle's J at the
/// last solution (newton.c, the first iteration).
bool plume_compression_density(const plume_membrane_element *element, const double strain[3], double secant_J,
                               double *psi, double dpsi[3], double d2psi[9]);

/// A shell triangle's in-plane energy: membrane plus compression (when element->compression
/// > 0), with gradient and Hessian as above on one evaluation of the strain. With project,
/// the Hessian is made positive semidefinite in strain space rather than by a 9 x 9
/// eigen-decomposition: area (J^T P(d2psi) J + (B^T S+ B) x I3), with S+ the positive part
/// of the 2 x 2 stress (closed form) and P(d2psi) d2psi projected when the compression term
/// makes it indefinite (3 x 3). Not the nearest PSD matrix, but a PSD one that equals the
/// exact Hessian wherever the element is in tension (S PSD, no compression term): the
/// projected Newton steps are descent steps, and the exact ones are unchanged. secant_J
/// modifies the compression term's Hessian (plume_compression_density; 1 for the exact one).
double plume_triangle_energy(const plume_membrane_element *element, const plume_vec3 x[3], double secant_J,
                             double gradient[9], double hessian[81], bool project);

/// Green strain of a deformed triangle and its derivatives: the kinematics shared by every
/// energy density psi(strain) of a triangle (library-internal).
typedef struct plume_green_strain {
	/// Voigt (eps_xx, eps_yy, 2 eps_xy) in the reference frame.
	double strain[3];
	/// d strain / d x: 3 x 9 row-major.
	double jacobian[27];
	/// Gradients of the three linear shape functions in the reference frame, (x, y) per vertex.
	double shape[6];
} plume_green_strain;

void plume_green_strain_eval(const plume_membrane_element *element, const plume_vec3 x[3], plume_green_strain *out);

/// Chain rule for W = area * psi(strain): gradient = area J^T dpsi and
/// hessian = area (J^T d2psi J + sum_k dpsi_k d2strain_k/dx2). Either output may be NULL.
void plume_green_strain_chain(const plume_green_strain *strain, double area, const double dpsi[3],
                              const double d2psi[9], double gradient[9], double hessian[81]);

#endif // PLUME_SIM_MEMBRANE_H

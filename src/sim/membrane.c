// The St-Venant-Kirchhoff membrane of the vane (orthotropic, paper eqs. 4-5, thesis 6.2
// and A.2) and of the rachis (isotropic, thesis 6.1) on linear triangles.
//
// Every in-plane energy of a triangle is area * psi(eps) with eps the Green strain in
// Voigt form, so the kinematics (eps, d eps/dx, d2 eps/dx2) live here once and each
// energy only supplies psi and its first two derivatives in eps.
#include "sim/membrane.h"

#include <math.h>
#include <string.h>

#include "sim/dense.h"

void plume_orthotropic_tensor(double E_vv, double E_ww, double E_vw, double theta, double voigt[9])
{
	// The barb-frame strain (eps_vv, eps_ww, 2 eps_vw) is T * (eps_xx, eps_yy, 2 eps_xy) with
	// v = (c, s), w = (-s, c):
	//   T = [[c^2, s^2, s c], [s^2, c^2, -s c], [-2 s c, 2 s c, c^2 - s^2]],
	// and the energy density (1/2) (T eps)^T D (T eps) gives E(theta) = T^T D T with
	// D = diag(E_vv, E_ww, E_vw). Written out:
	//   E11 = E_vv c^4 + E_ww s^4 + E_vw sin^2(2 theta)
	//   E13 = E_vv s c^3 - E_ww s^3 c - E_vw sin(4 theta) / 2
	// Thesis eq. A.5 has the same form and signs but E_vw/2 where this has E_vw (and
	// E_vw/4 in E13/E23): A.5 rotates diag(E_vv, E_ww, E_vw/2). We follow the Voigt
	// definition of eq. 4.1 (sigma_vw = E_vw 2 eps_vw), which the patch tests check, so that
	// E_vw keeps the meaning of eq. 4.1 at every angle.
	double c = cos(theta), s = sin(theta);
	double T[9] = {c * c, s * s, s * c, s * s, c * c, -s * c, -2.0 * s * c, 2.0 * s * c, c * c - s * s};
	double D[3] = {E_vv, E_ww, E_vw};
	for (int i = 0; i < 3; ++i) {
		for (int j = 0; j < 3; ++j) {
			double sum = 0.0;
			for (int k = 0; k < 3; ++k)
				sum += T[3 * k + i] * D[k] * T[3 * k + j];
			voigt[3 * i + j] = sum;
		}
	}
	// T^T D T is symmetric in exact arithmetic; make it so bit for bit.
	voigt[3] = voigt[1];
	voigt[6] = voigt[2];
	voigt[7] = voigt[5];
}

void plume_isotropic_tensor(double E, double nu, double voigt[9])
{
	double scale = E / (1.0 - nu * nu);
	double values[9] = {scale, scale * nu, 0.0, scale * nu, scale, 0.0, 0.0, 0.0, scale * 0.5 * (1.0 - nu)};
	memcpy(voigt, values, sizeof values);
}

bool plume_membrane_element_init(plume_membrane_element *element, const int vertices[3], const plume_vec2 reference[3],
                                 double thickness, const double voigt[9], double kappa)
{
	double e1x = reference[1].x - reference[0].x, e1y = reference[1].y - reference[0].y;
	double e2x = reference[2].x - reference[0].x, e2y = reference[2].y - reference[0].y;
	// Dm = [[e1x, e2x], [e1y, e2y]].
	double det = e1x * e2y - e2x * e1y;
	double scale = fmax(e1x * e1x + e1y * e1y, e2x * e2x + e2y * e2y);
	if (!isfinite(det) || !(fabs(det) > 1e-12 * scale))
		return false;
	memset(element, 0, sizeof *element);
	for (int i = 0; i < 3; ++i)
		element->vertices[i] = vertices[i];
	element->inverse_rest[0] = e2y / det;
	element->inverse_rest[1] = -e2x / det;
	element->inverse_rest[2] = -e1y / det;
	element->inverse_rest[3] = e1x / det;
	element->area = 0.5 * fabs(det);
	for (int i = 0; i < 9; ++i)
		element->stiffness[i] = thickness * voigt[i];
	element->compression = thickness * kappa;
	return true;
}

void plume_green_strain_eval(const plume_membrane_element *element, const plume_vec3 x[3], plume_green_strain *out)
{
	const double *B = element->inverse_rest;
	// F = [e1 | e2] B, so column beta of F is f_beta = sum_i x_i b_i[beta] with b_1 = row 0
	// of B, b_2 = row 1 and b_0 = -(b_1 + b_2): the shape-function gradients.
	double *b = out->shape;
	b[2] = B[0];
	b[3] = B[1];
	b[4] = B[2];
	b[5] = B[3];
	b[0] = -(B[0] + B[2]);
	b[1] = -(B[1] + B[3]);
	double f1[3] = {0.0, 0.0, 0.0}, f2[3] = {0.0, 0.0, 0.0};
	for (int i = 0; i < 3; ++i) {
		double p[3] = {x[i].x, x[i].y, x[i].z};
		for (int a = 0; a < 3; ++a) {
			f1[a] += b[2 * i] * p[a];
			f2[a] += b[2 * i + 1] * p[a];
		}
	}
	double f11 = f1[0] * f1[0] + f1[1] * f1[1] + f1[2] * f1[2];
	double f22 = f2[0] * f2[0] + f2[1] * f2[1] + f2[2] * f2[2];
	double f12 = f1[0] * f2[0] + f1[1] * f2[1] + f1[2] * f2[2];
	out->strain[0] = 0.5 * (f11 - 1.0);
	out->strain[1] = 0.5 * (f22 - 1.0);
	out->strain[2] = f12;
	// d eps_xx/dx_i = b_i0 f1, d eps_yy/dx_i = b_i1 f2, d (2 eps_xy)/dx_i = b_i0 f2 + b_i1 f1.
	for (int i = 0; i < 3; ++i) {
		for (int a = 0; a < 3; ++a) {
			int column = 3 * i + a;
			out->jacobian[column] = b[2 * i] * f1[a];
			out->jacobian[9 + column] = b[2 * i + 1] * f2[a];
			out->jacobian[18 + column] = b[2 * i] * f2[a] + b[2 * i + 1] * f1[a];
		}
	}
}

void plume_green_strain_chain(const plume_green_strain *strain, double area, const double dpsi[3],
                              const double d2psi[9], double gradient[9], double hessian[81])
{
	const double *G = strain->jacobian;
	if (gradient) {
		for (int c = 0; c < 9; ++c)
			gradient[c] = area * (G[c] * dpsi[0] + G[9 + c] * dpsi[1] + G[18 + c] * dpsi[2]);
	}
	if (!hessian)
		return;
	// Material part J^T d2psi J.
	double CG[27];
	for (int k = 0; k < 3; ++k)
		for (int c = 0; c < 9; ++c)
			CG[9 * k + c] = d2psi[3 * k] * G[c] + d2psi[3 * k + 1] * G[9 + c] + d2psi[3 * k + 2] * G[18 + c];
	// The upper triangle, mirrored at the end: exactly symmetric for the callers that rely
	// on it, at half the products.
	for (int r = 0; r < 9; ++r)
		for (int c = r; c < 9; ++c)
			hessian[9 * r + c] = area * (G[r] * CG[c] + G[9 + r] * CG[9 + c] + G[18 + r] * CG[18 + c]);
	// Geometric part: d2 eps_k / dx_i dx_j is a multiple of the 3x3 identity, so the
	// (i, j) block gains (b_i^T S b_j) I with S = [[s0, s2], [s2, s1]] the stress dpsi.
	const double *b = strain->shape;
	for (int i = 0; i < 3; ++i) {
		for (int j = i; j < 3; ++j) {
			double bi0 = b[2 * i], bi1 = b[2 * i + 1], bj0 = b[2 * j], bj1 = b[2 * j + 1];
			double w = dpsi[0] * bi0 * bj0 + dpsi[1] * bi1 * bj1 + dpsi[2] * (bi0 * bj1 + bi1 * bj0);
			for (int a = 0; a < 3; ++a)
				hessian[9 * (3 * i + a) + 3 * j + a] += area * w;
		}
	}
	for (int r = 0; r < 9; ++r)
		for (int c = r + 1; c < 9; ++c)
			hessian[9 * c + r] = hessian[9 * r + c];
}

double plume_membrane_energy(const plume_membrane_element *element, const plume_vec3 x[3], double gradient[9],
                             double hessian[81])
{
	plume_green_strain strain;
	plume_green_strain_eval(element, x, &strain);
	const double *C = element->stiffness;
	const double *e = strain.strain;
	// psi = (1/2) e^T C e (paper eq. 5), stress dpsi = C e, d2psi = C.
	double stress[3];
	for (int k = 0; k < 3; ++k)
		stress[k] = C[3 * k] * e[0] + C[3 * k + 1] * e[1] + C[3 * k + 2] * e[2];
	double energy = element->area * 0.5 * (stress[0] * e[0] + stress[1] * e[1] + stress[2] * e[2]);
	if (gradient || hessian)
		plume_green_strain_chain(&strain, element->area, stress, C, gradient, hessian);
	return energy;
}

/// The positive semidefinite part of the 2 x 2 symmetric stress [[s0, s2], [s2, s1]] in place
/// (Voigt order s0, s1, s2): with eigenvalues m -/+ r, S+ = 0 when m + r <= 0, S when
/// m - r >= 0, and otherwise lambda+ v v^T = lambda+ (S - lambda- I) / (2 r).
static void clamp_stress(double s[3])
{
	double mean = 0.5 * (s[0] + s[1]), half = 0.5 * (s[0] - s[1]);
	double r = sqrt(half * half + s[2] * s[2]);
	double low = mean - r, high = mean + r;
	if (low >= 0.0)
		return;
	if (high <= 0.0) {
		s[0] = s[1] = s[2] = 0.0;
		return;
	}
	double scale = high / (2.0 * r);
	s[0] = scale * (s[0] - low);
	s[1] = scale * (s[1] - low);
	s[2] = scale * s[2];
}

double plume_triangle_energy(const plume_membrane_element *element, const plume_vec3 x[3], double secant_J,
                             double gradient[9], double hessian[81], bool project)
{
	plume_green_strain strain;
	plume_green_strain_eval(element, x, &strain);
	const double *C = element->stiffness;
	const double *e = strain.strain;
	// Membrane (paper eq. 5): psi = (1/2) e^T C e, dpsi = C e, d2psi = C.
	double dpsi[3], d2psi[9];
	for (int k = 0; k < 3; ++k)
		dpsi[k] = C[3 * k] * e[0] + C[3 * k + 1] * e[1] + C[3 * k + 2] * e[2];
	double energy = element->area * 0.5 * (dpsi[0] * e[0] + dpsi[1] * e[1] + dpsi[2] * e[2]);
	memcpy(d2psi, C, sizeof d2psi);
	// Kikuuwe compression (thesis eq. 6.6), on the same strain.
	double psi_c, dpsi_c[3], d2psi_c[9];
	bool has_compression_terms = plume_compression_density(element, e, hessian ? secant_J : 1.0, &psi_c,
	                                                       (gradient || hessian) ? dpsi_c : NULL, d2psi_c);
	energy += element->area * psi_c;
	if (has_compression_terms)
		for (int k = 0; k < 3; ++k) {
			dpsi[k] += dpsi_c[k];
			for (int l = 0; l < 3; ++l)
				d2psi[3 * k + l] += d2psi_c[3 * k + l];
		}
	if (!project || hessian == NULL) {
		if (gradient || hessian)
			plume_green_strain_chain(&strain, element->area, dpsi, d2psi, gradient, hessian);
		return energy;
	}
	if (gradient)
		plume_green_strain_chain(&strain, element->area, dpsi, d2psi, gradient, NULL);
	// H = area (J^T d2psi J + (B^T S B) x I3), S the 2 x 2 stress: positive semidefinite
	// when d2psi and S are. C is; the compression term may not be (then a 3 x 3
	// projection), and S is not under compression (then clamped, closed form).
	if (has_compression_terms && !plume_is_positive_semidefinite(d2psi, 3))
		plume_project_psd(d2psi, 3);
	clamp_stress(dpsi);
	plume_green_strain_chain(&strain, element->area, dpsi, d2psi, NULL, hessian);
	return energy;
}

// The Kikuuwe compression term (Kikuuwe et al. 2009; thesis section 6.5, eq. 6.6):
// b kappa/12 ((1 - J)/6)^3 per unit reference area, added to the St-Venant-Kirchhoff
// membrane only under compression (J < 1, NOTES.md). St-Venant-Kirchhoff softens under
// strong compression and lets elements collapse (thesis Figure 6.7); this cubic term
// stiffens them instead, so that the shell buckles out of plane.
#include "sim/membrane.h"

#include <math.h>
#include <string.h>

/// J^2 = det(F^T F) from the Green strain: F^T F = I + 2 eps, so J^2 = (1 + 2 e0)(1 + 2 e1) -
/// e2^2 with e2 = 2 eps_xy. Returns J; a, b are the diagonal's 1 + 2 e0 and 1 + 2 e1.
static double area_ratio(const double e[3], double *a, double *b)
{
	*a = 1.0 + 2.0 * e[0];
	*b = 1.0 + 2.0 * e[1];
	return sqrt(fmax(*a * *b - e[2] * e[2], 0.0));
}

double plume_compression_area_ratio(const plume_membrane_element *element, const plume_vec3 x[3])
{
	plume_green_strain strain;
	plume_green_strain_eval(element, x, &strain);
	double a, b;
	return area_ratio(strain.strain, &a, &b);
}

bool plume_compression_density(const plume_membrane_element *element, const double strain[3], double secant_J,
                               double *psi, double dpsi[3], double d2psi[9])
{
	*psi = 0.0;
	if (element->compression == 0.0)
		return false;
	const double *e = strain;
	double a, b;
	double J = area_ratio(e, &a, &b);
	// psi(J) = c u^3 with u = (1 - J)/6 and c = b kappa / 12; zero for J >= 1.
	double c = element->compression / 12.0;
	double u = (1.0 - J) / 6.0, compressed = fmax(u, 0.0);
	double psi_JJ = c * compressed / 6.0; // d2 psi / dJ2
	// The slope of the secant of d psi / dJ from J to secant_J (membrane.h), c (u_s^2 - u+^2)
	// / (12 (u_s - u)) with u+ = max(u, 0): above the exact curvature c u / 6 wherever
	// secant_J is the more compressed, and the only compression stiffness a stretched
	// triangle's model can have.
	double u_secant = (1.0 - secant_J) / 6.0;
	if (u_secant > compressed)
		psi_JJ = c * (u_secant * u_secant - compressed * compressed) / (12.0 * (u_secant - u));
	if (J < 1.0)
		*psi = c * u * u * u;
	if (dpsi == NULL || !(J > 0.0) || psi_JJ == 0.0)
		return false;
	double psi_J = -0.5 * c * compressed * compressed; // d psi / dJ
	// d = J^2 and its strain derivatives; then J = sqrt(d).
	double dd[3] = {2.0 * b, 2.0 * a, -2.0 * e[2]};
	double d2d[9] = {0.0, 4.0, 0.0, 4.0, 0.0, 0.0, 0.0, 0.0, -2.0};
	double dJ[3], d2J[9];
	for (int k = 0; k < 3; ++k)
		dJ[k] = dd[k] / (2.0 * J);
	for (int k = 0; k < 3; ++k)
		for (int l = 0; l < 3; ++l)
			d2J[3 * k + l] = d2d[3 * k + l] / (2.0 * J) - dd[k] * dd[l] / (4.0 * J * J * J);
	for (int k = 0; k < 3; ++k) {
		dpsi[k] = psi_J * dJ[k];
		for (int l = 0; l < 3; ++l)
			d2psi[3 * k + l] = psi_JJ * dJ[k] * dJ[l] + psi_J * d2J[3 * k + l];
	}
	return true;
}

double plume_compression_energy(const plume_membrane_element *element, const plume_vec3 x[3], double gradient[9],
                                double hessian[81])
{
	if (gradient)
		memset(gradient, 0, 9 * sizeof(double));
	if (hessian)
		memset(hessian, 0, 81 * sizeof(double));
	if (element->compression == 0.0)
		return 0.0;
	plume_green_strain strain;
	plume_green_strain_eval(element, x, &strain);
	double psi, dpsi[3], d2psi[9];
	bool derivatives =
	    plume_compression_density(element, strain.strain, 1.0, &psi, (gradient || hessian) ? dpsi : NULL, d2psi);
	double energy = element->area * psi;
	if (derivatives)
		plume_green_strain_chain(&strain, element->area, dpsi, d2psi, gradient, hessian);
	return energy;
}

// Closed forms and small solves of the mesoscale model in the longitudinal and
// transverse scenarios (Jouve thesis 5.2 and appendix C.1), the measures of the
// traction test (thesis 3.3) and the slope of a stress-strain curve.
#include <math.h>

#include "plume/lab.h"

double plume_lab_longitudinal_modulus(double barb_fraction, double E_B, double E_b)
{
	// Thesis eq. 5.2: the bands stretch alike along the pulling axis and, with zero
	// Poisson ratio, carry their stresses side by side.
	return barb_fraction * E_B + (1.0 - barb_fraction) * E_b;
}

double plume_lab_measured_strain(double height, double displacement)
{
	double stretch = 1.0 + displacement / height;
	return 0.5 * (stretch * stretch - 1.0);
}

double plume_lab_measured_stress(double width, double height, double thickness, double displacement, double force)
{
	// Thesis section 3.3: sigma = H f / (b W (H + d)), the second Piola-Kirchhoff stress
	// of a uniform deformation.
	return height * force / (thickness * width * (height + displacement));
}

double plume_lab_displacement_for_strain(double height, double strain)
{
	return height * (sqrt(1.0 + 2.0 * strain) - 1.0);
}

double plume_lab_transverse_stress_rigid(double barb_fraction, double E_b, double strain)
{
	// Thesis eq. 5.4 with lambda = 1 + d/H = sqrt(2 eps + 1) (the thesis writes d/H for
	// the stretch): the barbule bands take all the stretch, lambda_b = (lambda - Phi)/(1 - Phi).
	double phi = barb_fraction;
	double lambda = sqrt(2.0 * strain + 1.0);
	double a = phi - lambda;
	double c = phi - 1.0;
	return E_b * a * (a * a - c * c) / (2.0 * lambda * c * c * c);
}

double plume_lab_transverse_slope_rigid(double barb_fraction, double E_b, double strain_max)
{
	// Thesis eq. 5.5 (= eq. C.1).
	double p = barb_fraction;
	double l = sqrt(2.0 * strain_max + 1.0);
	double c = p - 1.0;
	double c3 = c * c * c;
	double l1 = l + 1.0;
	double numerator = -15.0 * p * p * l - 25.0 * p * p + 18.0 * p * l * l + 39.0 * p * l + 23.0 * p;
	return E_b * (numerator / (5.0 * c3 * l1 * l1 * l1) - 1.0 / c3);
}

// One band's force per unit reference width and thickness at stretch s: the first
// Piola-Kirchhoff stress s S = s E (s^2 - 1)/2 of a Saint-Venant-Kirchhoff bar (eq. C.3).
static double band_force(double modulus, double stretch) { return 0.5 * modulus * stretch * (stretch * stretch - 1.0); }

double plume_lab_transverse_stress_stiff(double barb_fraction, double E_B, double E_b, double strain)
{
	// Appendix C.1: lambda = Phi lambda_B + (1 - Phi) lambda_b (eq. C.2) and equal forces in
	// the two bands (eq. C.3). The force mismatch is monotone in lambda_b between the rigid
	// barbs (lambda_B = 1) and equal stretches (lambda_B = lambda_b = lambda), which bracket
	// the root: bisection to the last bit is simpler and safer than the cubic's closed form C.4.
	double phi = barb_fraction;
	double lambda = sqrt(2.0 * strain + 1.0);
	double lo = (lambda - phi) / (1.0 - phi);
	double hi = lambda;
	if (lo > hi) {
		double t = lo;
		lo = hi;
		hi = t;
	}
	for (int i = 0; i < 200 && hi - lo > 0.0; ++i) {
		double mid = 0.5 * (lo + hi);
		if (mid <= lo || mid >= hi)
			break;
		double stretch_barb = (lambda - (1.0 - phi) * mid) / phi;
		double mismatch = band_force(E_B, stretch_barb) - band_force(E_b, mid);
		// mismatch decreases with lambda_b: positive means lambda_b is too small.
		if (mismatch > 0.0)
			lo = mid;
		else
			hi = mid;
	}
	double stretch_barbule = 0.5 * (lo + hi);
	// Eq. C.6: sigma = f / (W lambda) with f / W the band force.
	return band_force(E_b, stretch_barbule) / lambda;
}

plume_status plume_lab_mesoscale_moduli(double barb_fraction, double slope_longitudinal, double slope_transverse,
                                        double transverse_strain_max, double *E_B, double *E_b, plume_error *err)
{
	if (!(barb_fraction > 0.0 && barb_fraction < 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "barb fraction Phi_B is %g, allowed in (0, 1)", barb_fraction);
	if (!(slope_longitudinal > 0.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "longitudinal slope is %g Pa, allowed > 0", slope_longitudinal);
	if (!(slope_transverse > 0.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "transverse slope is %g Pa, allowed > 0", slope_transverse);
	if (!(transverse_strain_max > 0.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "transverse strain_max is %g, allowed > 0",
		                       transverse_strain_max);
	// Eq. 5.5 is linear in E_b; eq. 5.3 then gives E_B.
	double barbule = slope_transverse / plume_lab_transverse_slope_rigid(barb_fraction, 1.0, transverse_strain_max);
	double barb = (slope_longitudinal - (1.0 - barb_fraction) * barbule) / barb_fraction;
	if (!(barb > 0.0))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "the slopes give E_B = %g Pa: the longitudinal slope %g Pa must exceed "
		                       "(1 - Phi_B) E_b = %g Pa",
		                       barb, slope_longitudinal, (1.0 - barb_fraction) * barbule);
	*E_B = barb;
	*E_b = barbule;
	return PLUME_OK;
}

// Weight of sample i of n + 1 evenly spaced ones in a composite Newton-Cotes rule:
// Simpson's 1/3 rule, with Simpson's 3/8 rule on the last three intervals when n is odd
// (the trapezoid rule when n = 1). The common factor h is left out.
static double quadrature_weight(int i, int n)
{
	if (n == 1)
		return 0.5;
	int simpson_end = n % 2 == 0 ? n : n - 3; // samples 0..simpson_end take Simpson's 1/3 rule
	double w = 0.0;
	if (i <= simpson_end && simpson_end > 0) {
		if (i == 0 || i == simpson_end)
			w += 1.0 / 3.0;
		else
			w += i % 2 ? 4.0 / 3.0 : 2.0 / 3.0;
	}
	if (n % 2 == 1 && i >= n - 3) {
		static const double three_eighths[4] = {3.0 / 8.0, 9.0 / 8.0, 9.0 / 8.0, 3.0 / 8.0};
		w += three_eighths[i - (n - 3)];
	}
	return w;
}

double plume_lab_slope(const double *strain, const double *stress, int count)
{
	// Least squares through the origin, min over s of int (sigma - s eps)^2 d eps
	// (thesis eq. C.7), by quadrature on the samples: s = int sigma eps / int eps^2.
	int n = count - 1;
	double num = 0.0, den = 0.0;
	for (int i = 0; i <= n; ++i) {
		double w = quadrature_weight(i, n);
		num += w * stress[i] * strain[i];
		den += w * strain[i] * strain[i];
	}
	return den > 0.0 ? num / den : 0.0;
}

// Scalar distributions on the collar: a monotone piecewise cubic Hermite
// interpolant (Fritsch & Carlson 1980). On each interval the cubic is
// monotone, so it stays between its two control values: positive control
// values give a positive speed everywhere, which the pathlines need (a speed
// that touched zero would stall an emitter for ever).
#include <math.h>

#include "zhang_kanai_internal.h"

plume_zk_curve plume_zk_constant(double value)
{
	plume_zk_curve curve = {.count = 1};
	curve.s[0] = 0.0;
	curve.value[0] = value;
	return curve;
}

void zk_curve_init(zk_curve *curve, const plume_zk_curve *points)
{
	curve->points = *points;
	int n = points->count;
	const double *x = points->s, *y = points->value;
	double *m = curve->tangent;
	if (n < 2) {
		m[0] = 0.0;
		return;
	}
	double secant[PLUME_ZK_MAX_CURVE_POINTS];
	for (int k = 0; k + 1 < n; ++k)
		secant[k] = (y[k + 1] - y[k]) / (x[k + 1] - x[k]);
	m[0] = secant[0];
	m[n - 1] = secant[n - 2];
	for (int k = 1; k + 1 < n; ++k)
		m[k] = secant[k - 1] * secant[k] <= 0.0 ? 0.0 : 0.5 * (secant[k - 1] + secant[k]);
	// Fritsch–Carlson: flat where the data is flat, and tangents limited to the
	// circle alpha^2 + beta^2 <= 9 so that each cubic stays monotone.
	for (int k = 0; k + 1 < n; ++k) {
		if (secant[k] == 0.0) {
			m[k] = m[k + 1] = 0.0;
			continue;
		}
		double alpha = m[k] / secant[k], beta = m[k + 1] / secant[k];
		if (alpha < 0.0)
			m[k] = alpha = 0.0;
		if (beta < 0.0)
			m[k + 1] = beta = 0.0;
		double r2 = alpha * alpha + beta * beta;
		if (r2 > 9.0) {
			double tau = 3.0 / sqrt(r2);
			m[k] = tau * alpha * secant[k];
			m[k + 1] = tau * beta * secant[k];
		}
	}
}

double zk_curve_eval(const zk_curve *curve, double s)
{
	const plume_zk_curve *c = &curve->points;
	int n = c->count;
	if (n == 1 || s <= c->s[0])
		return c->value[0];
	if (s >= c->s[n - 1])
		return c->value[n - 1];
	int k = 0;
	while (k + 2 < n && s >= c->s[k + 1])
		++k;
	double h = c->s[k + 1] - c->s[k];
	double u = (s - c->s[k]) / h;
	double u2 = u * u, u3 = u2 * u;
	return (2 * u3 - 3 * u2 + 1) * c->value[k] + (u3 - 2 * u2 + u) * h * curve->tangent[k] +
	       (-2 * u3 + 3 * u2) * c->value[k + 1] + (u3 - u2) * h * curve->tangent[k + 1];
}

double plume_zk_curve_eval(const plume_zk_curve *curve, double s)
{
	zk_curve c;
	zk_curve_init(&c, curve);
	return zk_curve_eval(&c, s);
}

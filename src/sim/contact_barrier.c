// The contact energy of one pair of primitives (sim/contact_barrier.h).
//
// Every squared distance is written in a few difference vectors of the pair's points
// (r = p - a, e = b - a, ...), differentiated there in closed form, then scattered into
// the 12 coordinates: a difference vector x_i - x_j adds its derivative to point i and
// subtracts it from point j. Four closed forms cover the 16 regions of plume_distance_kind
// (IPC Figure 4; 7 point-triangle, 9 edge-edge):
//   point-point  |r|²
//   point-line   |r x e|² / |e|²                        (r = p - a, e = b - a)
//   point-plane  (r . (e1 x e2))² / |e1 x e2|²          (r = p - a, e1 = b - a, e2 = c - a)
//   line-line    the same with r = b0 - a0, e1 = a1 - a0, e2 = b1 - b0
// The squared cross products are differentiated through Lagrange's identity
// |u x v|² = |u|²|v|² - (u.v)², a polynomial with simple derivatives, and the quotients
// by the quotient rule; values are taken from the cross products, which lose less to
// cancellation when the vectors are nearly parallel.
#include "sim/contact_barrier.h"

#include "core/asserts.h"
#include "sim/dense.h"

#include <math.h>
#include <string.h>

enum {
	/// The most local variables: three difference vectors.
	LOCAL_MAX = 9,
};

/// IPC eq. 15: the mollifier is active below 1e-3 of the product of the rest squared
/// edge lengths, i.e. where sin² of the angle between the edges is below about 1e-3.
static const double MOLLIFIER_FRACTION = 1e-3;

double plume_barrier(double d2, double dhat2, double *db, double *d2b)
{
	PLUME_ASSERT(dhat2 > 0);
	if (d2 >= dhat2) {
		if (db != NULL)
			*db = 0;
		if (d2b != NULL)
			*d2b = 0;
		return 0;
	}
	// b(t) = -(t - h)² ln(t / h) with t = d², h = d̂²:
	// b'(t) = -2 (t - h) ln(t / h) - (t - h)² / t,
	// b''(t) = -2 ln(t / h) - 4 (t - h) / t + (t - h)² / t²; all three vanish at t = h.
	double u = d2 - dhat2, log_ratio = log(d2 / dhat2);
	if (db != NULL)
		*db = -2 * u * log_ratio - u * u / d2;
	if (d2b != NULL)
		*d2b = -2 * log_ratio - 4 * u / d2 + (u * u) / (d2 * d2);
	return -u * u * log_ratio;
}

// ---------------------------------------------------------------------------
// Closed forms in local variables

static void store3(double *out, plume_vec3 v)
{
	out[0] = v.x;
	out[1] = v.y;
	out[2] = v.z;
}

static double component(plume_vec3 v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }

/// The cross-product matrix [a]x, with [a]x b = a x b.
static void cross_matrix(plume_vec3 a, double out[3][3])
{
	out[0][0] = 0, out[0][1] = -a.z, out[0][2] = a.y;
	out[1][0] = a.z, out[1][1] = 0, out[1][2] = -a.x;
	out[2][0] = -a.y, out[2][1] = a.x, out[2][2] = 0;
}

/// |u x v|² = |u|²|v|² - (u.v)² with its gradient and Hessian in (u, v), added at the
/// local variables u_at.. and v_at.. of an n-variable gradient and Hessian.
static double lagrange(plume_vec3 u, plume_vec3 v, int u_at, int v_at, int n, double *gradient, double *hessian)
{
	double uu = plume_v3_dot(u, u), vv = plume_v3_dot(v, v), uv = plume_v3_dot(u, v);
	for (int i = 0; i < 3; ++i) {
		gradient[u_at + i] += 2 * vv * component(u, i) - 2 * uv * component(v, i);
		gradient[v_at + i] += 2 * uu * component(v, i) - 2 * uv * component(u, i);
	}
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j) {
			double identity = i == j ? 1 : 0;
			double ui = component(u, i), uj = component(u, j), vi = component(v, i), vj = component(v, j);
			hessian[(u_at + i) * n + u_at + j] += 2 * vv * identity - 2 * vi * vj;
			hessian[(v_at + i) * n + v_at + j] += 2 * uu * identity - 2 * ui * uj;
			// d/dv of the u gradient, and its transpose.
			double mixed = 4 * ui * vj - 2 * vi * uj - 2 * uv * identity;
			hessian[(u_at + i) * n + v_at + j] += mixed;
			hessian[(v_at + j) * n + u_at + i] += mixed;
		}
	plume_vec3 c = plume_v3_cross(u, v);
	return plume_v3_dot(c, c);
}

/// f = N / D with its gradient and Hessian from those of N and D (quotient rule):
/// grad f = (grad N - f grad D) / D,
/// hess f = (hess N - f hess D - grad f grad Dᵀ - grad D grad fᵀ) / D.
static double quotient(double numerator, const double *n_gradient, const double *n_hessian, double denominator,
                       const double *d_gradient, const double *d_hessian, int n, double *gradient, double *hessian)
{
	double f = numerator / denominator;
	for (int i = 0; i < n; ++i)
		gradient[i] = (n_gradient[i] - f * d_gradient[i]) / denominator;
	for (int i = 0; i < n; ++i)
		for (int j = 0; j < n; ++j)
			hessian[i * n + j] = (n_hessian[i * n + j] - f * d_hessian[i * n + j] - gradient[i] * d_gradient[j] -
			                      d_gradient[i] * gradient[j]) /
			                     denominator;
	return f;
}

/// Point-point: |r|², one local vector.
static double point_point_local(plume_vec3 r, double *gradient, double *hessian)
{
	store3(gradient, plume_v3_scale(r, 2));
	memset(hessian, 0, 9 * sizeof *hessian);
	hessian[0] = hessian[4] = hessian[8] = 2;
	return plume_v3_dot(r, r);
}

/// Point-line: |r x e|² / |e|², local vectors (r, e).
static double point_line_local(plume_vec3 r, plume_vec3 e, double *gradient, double *hessian)
{
	enum { N = 6 };
	double ng[N] = {0}, nh[N * N] = {0}, dg[N] = {0}, dh[N * N] = {0};
	double numerator = lagrange(r, e, 0, 3, N, ng, nh);
	store3(dg + 3, plume_v3_scale(e, 2));
	for (int i = 3; i < N; ++i)
		dh[i * N + i] = 2;
	return quotient(numerator, ng, nh, plume_v3_dot(e, e), dg, dh, N, gradient, hessian);
}

/// Point-plane and line-line: (r . (e1 x e2))² / |e1 x e2|², local vectors (r, e1, e2).
static double triple_local(plume_vec3 r, plume_vec3 e1, plume_vec3 e2, double *gradient, double *hessian)
{
	enum { N = 9 };
	// g = r . (e1 x e2): grad g = (e1 x e2, e2 x r, r x e1); its Hessian has the
	// off-diagonal blocks d²g/dr de1 = -[e2]x, d²g/dr de2 = [e1]x, d²g/de1 de2 = -[r]x.
	plume_vec3 normal = plume_v3_cross(e1, e2);
	double g = plume_v3_dot(r, normal);
	double gg[N], gh[N * N] = {0};
	store3(gg, normal);
	store3(gg + 3, plume_v3_cross(e2, r));
	store3(gg + 6, plume_v3_cross(r, e1));
	double block[3][3];
	const int at[3][2] = {{0, 3}, {0, 6}, {3, 6}};
	const plume_vec3 by[3] = {e2, e1, r};
	const double sign[3] = {-1, 1, -1};
	for (int k = 0; k < 3; ++k) {
		cross_matrix(by[k], block);
		for (int i = 0; i < 3; ++i)
			for (int j = 0; j < 3; ++j) {
				gh[(at[k][0] + i) * N + at[k][1] + j] = sign[k] * block[i][j];
				gh[(at[k][1] + j) * N + at[k][0] + i] = sign[k] * block[i][j];
			}
	}
	// N = g²: grad N = 2 g grad g, hess N = 2 grad g grad gᵀ + 2 g hess g.
	double ng[N], nh[N * N];
	for (int i = 0; i < N; ++i) {
		ng[i] = 2 * g * gg[i];
		for (int j = 0; j < N; ++j)
			nh[i * N + j] = 2 * gg[i] * gg[j] + 2 * g * gh[i * N + j];
	}
	double dg[N] = {0}, dh[N * N] = {0};
	double denominator = lagrange(e1, e2, 3, 6, N, dg, dh);
	return quotient(g * g, ng, nh, denominator, dg, dh, N, gradient, hessian);
}

// ---------------------------------------------------------------------------
// Regions

/// A squared distance in local difference vectors: vector k is x[plus[k]] - x[minus[k]].
typedef struct local_form {
	int count;
	int plus[3], minus[3];
} local_form;

static local_form form1(int plus0, int minus0) { return (local_form){1, {plus0}, {minus0}}; }

static local_form form2(int plus0, int minus0, int plus1, int minus1)
{
	return (local_form){2, {plus0, plus1}, {minus0, minus1}};
}

static local_form form3(int plus0, int minus0, int plus1, int minus1, int plus2, int minus2)
{
	return (local_form){3, {plus0, plus1, plus2}, {minus0, minus1, minus2}};
}

/// The local form of each region. Point-triangle: x = (p, a, b, c); edge-edge:
/// x = (a0, a1, b0, b1).
static local_form region_form(plume_contact_pair_type type, plume_distance_kind kind)
{
	if (type == PLUME_CONTACT_POINT_TRIANGLE) {
		PLUME_ASSERT(kind >= PLUME_PT_A && kind <= PLUME_PT_PLANE);
		switch (kind) {
		case PLUME_PT_A: return form1(0, 1);
		case PLUME_PT_B: return form1(0, 2);
		case PLUME_PT_C: return form1(0, 3);
		case PLUME_PT_AB: return form2(0, 1, 2, 1);
		case PLUME_PT_BC: return form2(0, 2, 3, 2);
		case PLUME_PT_CA: return form2(0, 3, 1, 3);
		default: return form3(0, 1, 2, 1, 3, 1);
		}
	}
	PLUME_ASSERT(type == PLUME_CONTACT_EDGE_EDGE);
	PLUME_ASSERT(kind >= PLUME_EE_A0_B0 && kind <= PLUME_EE_LINES);
	switch (kind) {
	case PLUME_EE_A0_B0: return form1(0, 2);
	case PLUME_EE_A0_B1: return form1(0, 3);
	case PLUME_EE_A1_B0: return form1(1, 2);
	case PLUME_EE_A1_B1: return form1(1, 3);
	case PLUME_EE_A0_B: return form2(0, 2, 3, 2);
	case PLUME_EE_A1_B: return form2(1, 2, 3, 2);
	case PLUME_EE_A_B0: return form2(2, 0, 1, 0);
	case PLUME_EE_A_B1: return form2(3, 0, 1, 0);
	default: return form3(2, 0, 1, 0, 3, 2);
	}
}

/// Adds the local gradient and Hessian of a form to the 12 coordinates (either may be NULL).
static void scatter(local_form form, const double *local_gradient, const double *local_hessian, double *gradient,
                    double *hessian)
{
	int n = 3 * form.count;
	for (int k = 0; k < form.count; ++k)
		for (int i = 0; i < 3; ++i) {
			double value = local_gradient[3 * k + i];
			if (gradient != NULL) {
				gradient[3 * form.plus[k] + i] += value;
				gradient[3 * form.minus[k] + i] -= value;
			}
		}
	if (hessian == NULL)
		return;
	for (int k = 0; k < form.count; ++k)
		for (int l = 0; l < form.count; ++l)
			for (int i = 0; i < 3; ++i)
				for (int j = 0; j < 3; ++j) {
					double value = local_hessian[(3 * k + i) * n + 3 * l + j];
					int pk = 3 * form.plus[k] + i, mk = 3 * form.minus[k] + i;
					int pl = 3 * form.plus[l] + j, ml = 3 * form.minus[l] + j;
					hessian[pk * 12 + pl] += value;
					hessian[pk * 12 + ml] -= value;
					hessian[mk * 12 + pl] -= value;
					hessian[mk * 12 + ml] += value;
				}
}

/// Copies the upper triangle onto the lower one, so that a Hessian summed in different
/// orders on either side of the diagonal is exactly symmetric.
static void symmetrize(double *hessian)
{
	for (int i = 0; i < 12; ++i)
		for (int j = 0; j < i; ++j)
			hessian[i * 12 + j] = hessian[j * 12 + i];
}

double plume_pair_distance2(plume_contact_pair_type type, plume_distance_kind kind, const plume_vec3 x[4],
                            double *gradient, double *hessian)
{
	local_form form = region_form(type, kind);
	plume_vec3 v[3];
	for (int k = 0; k < form.count; ++k)
		v[k] = plume_v3_sub(x[form.plus[k]], x[form.minus[k]]);
	double local_gradient[LOCAL_MAX], local_hessian[LOCAL_MAX * LOCAL_MAX];
	double d2 = form.count == 1   ? point_point_local(v[0], local_gradient, local_hessian)
	            : form.count == 2 ? point_line_local(v[0], v[1], local_gradient, local_hessian)
	                              : triple_local(v[0], v[1], v[2], local_gradient, local_hessian);
	if (gradient != NULL)
		memset(gradient, 0, 12 * sizeof *gradient);
	if (hessian != NULL)
		memset(hessian, 0, 144 * sizeof *hessian);
	scatter(form, local_gradient, local_hessian, gradient, hessian);
	if (hessian != NULL)
		symmetrize(hessian);
	return d2;
}

// ---------------------------------------------------------------------------
// The pair's energy

/// IPC eq. 14: m(x) = -x²/ε² + 2x/ε below ε, 1 above (C¹ at ε, zero at parallel
/// edges), with m' and m''.
static double mollifier(double x, double epsilon, double *dm, double *d2m)
{
	if (x >= epsilon) {
		*dm = 0;
		*d2m = 0;
		return 1;
	}
	double s = x / epsilon;
	*dm = (2 - 2 * s) / epsilon;
	*d2m = -2 / (epsilon * epsilon);
	return s * (2 - s);
}

/// Projects the Hessian to the nearest PSD matrix by projecting only the rows and
/// columns of the points it involves, on the complement of their common translations
/// (plume_project_psd_translation_free): the other rows are zero and every term is a
/// function of differences of points, so both are exact invariant subspaces of
/// eigenvalue zero and the result is plume_project_psd's up to rounding, from a 3x3
/// (point-point) to a 9x9 (four points) eigen-decomposition instead of a 12x12.
static void project_involved_psd(double *hessian, const bool involved[4])
{
	int index[4], count = 0;
	for (int i = 0; i < 4; ++i)
		if (involved[i])
			index[count++] = i;
	int n = 3 * count;
	double compact[144];
	for (int a = 0; a < n; ++a)
		for (int b = 0; b < n; ++b)
			compact[a * n + b] = hessian[(3 * index[a / 3] + a % 3) * 12 + 3 * index[b / 3] + b % 3];
	plume_project_psd_translation_free(compact, count);
	for (int a = 0; a < n; ++a)
		for (int b = 0; b < n; ++b)
			hessian[(3 * index[a / 3] + a % 3) * 12 + 3 * index[b / 3] + b % 3] = compact[a * n + b];
}

double plume_contact_pair_energy(plume_contact_pair_type type, const plume_vec3 x[4], const plume_vec3 rest[4],
                                 double dhat, double stiffness, bool project_psd, double *gradient, double *hessian)
{
	PLUME_ASSERT(dhat > 0);
	if (gradient != NULL)
		memset(gradient, 0, 12 * sizeof *gradient);
	if (hessian != NULL)
		memset(hessian, 0, 144 * sizeof *hessian);
	plume_distance_kind kind;
	double dhat2 = dhat * dhat;
	double d2 = type == PLUME_CONTACT_POINT_TRIANGLE ? plume_point_triangle_distance2(x[0], x[1], x[2], x[3], &kind)
	                                                 : plume_edge_edge_distance2(x[0], x[1], x[2], x[3], &kind);
	if (d2 >= dhat2)
		return 0;
	double dg[12], dh[144];
	d2 = plume_pair_distance2(type, kind, x, dg, dh);
	PLUME_ASSERT(d2 > 0);
	double db, d2b;
	double b = plume_barrier(d2, dhat2, &db, &d2b);
	if (b == 0 && db == 0 && d2b == 0)
		return 0;
	// The mollifier of edge-edge pairs, m(x) with x = |e0 x e1|² (IPC eq. 14-15).
	double m = 1, dm = 0, d2m = 0;
	bool mollified = false;
	double xg[12] = {0}, xh[144] = {0}; // x = |e0 x e1|²
	if (type == PLUME_CONTACT_EDGE_EDGE) {
		PLUME_ASSERT(rest != NULL);
		plume_vec3 r0 = plume_v3_sub(rest[1], rest[0]), r1 = plume_v3_sub(rest[3], rest[2]);
		double epsilon = MOLLIFIER_FRACTION * plume_v3_dot(r0, r0) * plume_v3_dot(r1, r1);
		PLUME_ASSERT(epsilon > 0);
		plume_vec3 e0 = plume_v3_sub(x[1], x[0]), e1 = plume_v3_sub(x[3], x[2]);
		double lg[6] = {0}, lh[36] = {0};
		double cross2 = lagrange(e0, e1, 0, 3, 6, lg, lh);
		m = mollifier(cross2, epsilon, &dm, &d2m);
		mollified = m < 1;
		if (mollified)
			scatter(form2(1, 0, 3, 2), lg, lh, xg, xh);
	}
	// E = k m b: grad E = k (b grad m + m grad b), with grad m = m' grad x and
	// grad b = b' grad d²; hess E = k (b hess m + grad m grad bᵀ + grad b grad mᵀ + m hess b),
	// hess m = m'' grad x grad xᵀ + m' hess x, hess b = b'' grad d² grad d²ᵀ + b' hess d².
	if (gradient != NULL)
		for (int i = 0; i < 12; ++i)
			gradient[i] = stiffness * (b * dm * xg[i] + m * db * dg[i]);
	if (hessian != NULL) {
		for (int i = 0; i < 12; ++i)
			for (int j = i; j < 12; ++j) {
				double hess_m = d2m * xg[i] * xg[j] + dm * xh[i * 12 + j];
				double hess_b = d2b * dg[i] * dg[j] + db * dh[i * 12 + j];
				double cross_terms = dm * db * (xg[i] * dg[j] + dg[i] * xg[j]);
				hessian[i * 12 + j] = stiffness * (b * hess_m + cross_terms + m * hess_b);
			}
		symmetrize(hessian);
		if (project_psd) {
			// The region's points, and all four where the mollifier varies.
			local_form form = region_form(type, kind);
			bool involved[4] = {mollified, mollified, mollified, mollified};
			for (int k = 0; k < form.count; ++k)
				involved[form.plus[k]] = involved[form.minus[k]] = true;
			project_involved_psd(hessian, involved);
		}
	}
	return stiffness * m * b;
}

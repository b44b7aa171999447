// Anisotropic discrete-shell bending: per interior edge, (A1 + A2)/6 D(beta) (eta - eta0)^2
// with eta = 3 e chi / (A1 + A2) (thesis eqs. 6.2-6.3 as read in NOTES.md; Grinspun et al.
// 2003), D(beta) of eq. 6.4 and the area-weighted tilt angle of eq. 6.5.
//
// The dihedral angle is atan2(sin, cos) of the two face normals, accurate at every angle.
// Its gradient is the classical one (Bridson et al. 2003): the wing vertices move along
// their face normals with rate 1/height, the edge vertices by the weights that make the
// gradient invariant under translation and rotation. Every term of that gradient is a
// scalar c (an edge length or a projection onto the edge) times m = n / |n|^2 for a face
// normal n, so the exact Hessian is the sum of m (dc)^T + c dm with
// dm = (I - 2 n^ n^T) dn / |n|^2 and dn a cross-product matrix (Tamstorf & Grinspun 2013
// derive the same Hessian in another form). No Gauss-Newton approximation. It is built by
// 3 x 3 vertex blocks, each face's over its own three vertices (the wings share no face, so
// their block is zero): half the time of the dense 3 x 12 form it replaced, whose zeroed
// temporaries and strided mirror stores made the angle's Hessian the largest item of the
// fundamental-form assembly.
#include "sim/bending.h"

#include <math.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

static void vec_of(plume_vec3 v, double out[3])
{
	out[0] = v.x;
	out[1] = v.y;
	out[2] = v.z;
}

double plume_bending_modulus(double along, double across, double beta)
{
	return 0.5 * (along - across) * cos(2.0 * beta) + 0.5 * (along + across);
}

double plume_dihedral_angle(const plume_vec3 x[4]) { return plume_dihedral_angle_derivatives(x, NULL, NULL); }

/// dm/dx_j for m = n / |n|^2, where dn/dx_j = [a]x (the matrix of u -> a x u):
/// (I - 2 n n^T / |n|^2) [a]x / |n|^2 = ([a]x - 2 n (n x a)^T / |n|^2) / |n|^2, row-major.
static void normal_over_square_block(const double n[3], double inverse_square, const double a[3], double q[9])
{
	double na[3] = {n[1] * a[2] - n[2] * a[1], n[2] * a[0] - n[0] * a[2], n[0] * a[1] - n[1] * a[0]};
	double cross[9] = {0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0};
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
			q[3 * r + c] = (cross[3 * r + c] - 2.0 * n[r] * na[c] * inverse_square) * inverse_square;
}

double plume_dihedral_angle_derivatives(const plume_vec3 x[4], double gradient[12], double hessian[144])
{
	plume_vec3 edge = plume_v3_sub(x[1], x[0]);
	plume_vec3 nA = plume_v3_cross(edge, plume_v3_sub(x[2], x[0]));
	plume_vec3 nB = plume_v3_cross(plume_v3_sub(x[3], x[0]), edge);
	double length = plume_v3_length(edge);
	double nA2 = plume_v3_dot(nA, nA), nB2 = plume_v3_dot(nB, nB);
	if (!(length > 0.0) || !(nA2 > 0.0) || !(nB2 > 0.0)) {
		// A degenerate stencil has no angle: zero, and zero derivatives. (Otherwise both
		// are written whole below.)
		if (gradient)
			memset(gradient, 0, 12 * sizeof(double));
		if (hessian)
			memset(hessian, 0, 144 * sizeof(double));
		return 0.0;
	}
	plume_vec3 ehat_v = plume_v3_scale(edge, 1.0 / length);
	// Positive when the wings fold towards n_A (see bending.h).
	double sine = plume_v3_dot(plume_v3_cross(nB, nA), ehat_v);
	double cosine = plume_v3_dot(nA, nB);
	double angle = atan2(sine, cosine);
	if (!gradient && !hessian)
		return angle;

	// Face f (A: wing x2, B: wing x3) holds vertices 0, 1 and its wing w = 2 + f.
	double p[12], n[2][3], m[2][3], ehat[3], square[2] = {nA2, nB2};
	for (int i = 0; i < 4; ++i)
		vec_of(x[i], p + 3 * i);
	vec_of(nA, n[0]);
	vec_of(nB, n[1]);
	vec_of(ehat_v, ehat);
	// Coefficients c[f][i] of m_f in the gradient of vertex i (zero at the other face's wing).
	double c[2][3];
	for (int f = 0; f < 2; ++f) {
		const double *w = p + 3 * (2 + f);
		double from1 = 0.0, from0 = 0.0; // (w - x1) . e^, (w - x0) . e^
		for (int a = 0; a < 3; ++a) {
			// A division, not a product with 1 / |n|^2: the gradient's bits are those it always
			// had (scenes solved to their roundoff floor stay where they were).
			m[f][a] = n[f][a] / square[f];
			from1 += (w[a] - p[3 + a]) * ehat[a];
			from0 += (w[a] - p[a]) * ehat[a];
		}
		c[f][0] = from1;
		c[f][1] = -from0;
		c[f][2] = length;
	}
	if (gradient) {
		for (int a = 0; a < 3; ++a) {
			gradient[a] = c[0][0] * m[0][a] + c[1][0] * m[1][a];
			gradient[3 + a] = c[0][1] * m[0][a] + c[1][1] * m[1][a];
			gradient[6 + a] = c[0][2] * m[0][a];
			gradient[9 + a] = c[1][2] * m[1][a];
		}
	}
	if (!hessian)
		return angle;

	// The Hessian's 3x3 block (i, j) is the sum over the faces holding both vertices of
	// m_f (dc_f[i]/dx_j)^T + c_f[i] dm_f/dx_j. With the wing's offset perpendicular to
	// the edge, u_f = (I - e^ e^T)(w - x0) / |e| (the same from x1), the coefficients'
	// gradients (rows i = 0, 1, wing; columns j = 0, 1, wing) are
	//   c_f[0] = (w - x1) . e^:  -u_f,       u_f - e^,  e^
	//   c_f[1] = -(w - x0) . e^: u_f + e^,  -u_f,      -e^
	//   c_f[2] = |e|:            -e^,        e^,        0
	// and dn_f/dx_j = [a_j]x with, for n_A = (x2 - x0) x (x2 - x1), a = x2 - x1,
	// -(x2 - x0), e, and for n_B = (x3 - x1) x (x3 - x0), a = -(x3 - x1), x3 - x0, -e.
	// The two wings share no face: block (2, 3) is zero.
	double dc[2][3][3][3], q[2][3][9];
	for (int f = 0; f < 2; ++f) {
		const double *w = p + 3 * (2 + f);
		double sign = f == 0 ? 1.0 : -1.0, u[3], a[3][3], along = 0.0;
		for (int k = 0; k < 3; ++k)
			along += (w[k] - p[k]) * ehat[k];
		for (int k = 0; k < 3; ++k) {
			u[k] = (w[k] - p[k] - along * ehat[k]) / length;
			a[0][k] = sign * (w[k] - p[3 + k]);
			a[1][k] = -sign * (w[k] - p[k]);
			a[2][k] = sign * (p[3 + k] - p[k]);
			dc[f][0][0][k] = -u[k];
			dc[f][0][1][k] = u[k] - ehat[k];
			dc[f][0][2][k] = ehat[k];
			dc[f][1][0][k] = u[k] + ehat[k];
			dc[f][1][1][k] = -u[k];
			dc[f][1][2][k] = -ehat[k];
			dc[f][2][0][k] = -ehat[k];
			dc[f][2][1][k] = ehat[k];
			dc[f][2][2][k] = 0.0;
		}
		for (int j = 0; j < 3; ++j)
			normal_over_square_block(n[f], 1.0 / square[f], a[j], q[f][j]);
	}
	// Blocks with i <= j, written with their mirror (j, i); a diagonal block's upper
	// triangle is mirrored too, so the Hessian is exactly symmetric.
	static const int slot_in_face[2][4] = {{0, 1, 2, -1}, {0, 1, -1, 2}};
	for (int i = 0; i < 4; ++i) {
		for (int j = i; j < 4; ++j) {
			double block[9] = {0};
			for (int f = 0; f < 2; ++f) {
				int fi = slot_in_face[f][i], fj = slot_in_face[f][j];
				if (fi < 0 || fj < 0)
					continue;
				const double *g = dc[f][fi][fj], *qj = q[f][fj];
				for (int r = 0; r < 3; ++r)
					for (int col = 0; col < 3; ++col)
						block[3 * r + col] += m[f][r] * g[col] + c[f][fi] * qj[3 * r + col];
			}
			for (int r = 0; r < 3; ++r)
				for (int col = 0; col < 3; ++col) {
					if (i == j && col < r)
						continue;
					hessian[12 * (3 * i + r) + 3 * j + col] = hessian[12 * (3 * j + col) + 3 * i + r] =
					    block[3 * r + col];
				}
		}
	}
	return angle;
}

static double tilt_angle(plume_vec2 edge, double barb_angle)
{
	// Angle between the edge line and the barb line, in [0, pi/2] (lines, not directions,
	// so that averaging two faces' tilts in eq. 6.5 is meaningful).
	double bx = cos(barb_angle), by = sin(barb_angle);
	double along = fabs(edge.x * bx + edge.y * by);
	double across = fabs(edge.x * by - edge.y * bx);
	return atan2(across, along);
}

static double triangle_area2(plume_vec2 a, plume_vec2 b, plume_vec2 c)
{
	return 0.5 * fabs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
}

bool plume_hinge_init(plume_hinge *hinge, const int vertices[4], const plume_vec2 reference[4],
                      const plume_vec3 rest[4], double barb_angle_a, double barb_angle_b, double along, double across)
{
	plume_vec2 edge = {reference[1].x - reference[0].x, reference[1].y - reference[0].y};
	double length2 = edge.x * edge.x + edge.y * edge.y;
	double area_a = triangle_area2(reference[0], reference[1], reference[2]);
	double area_b = triangle_area2(reference[0], reference[1], reference[3]);
	if (!isfinite(length2 + area_a + area_b) || !(area_a > 1e-12 * length2) || !(area_b > 1e-12 * length2))
		return false;
	plume_vec3 rest_edge = plume_v3_sub(rest[1], rest[0]);
	double rest_length2 = plume_v3_dot(rest_edge, rest_edge);
	plume_vec3 nA = plume_v3_cross(rest_edge, plume_v3_sub(rest[2], rest[0]));
	plume_vec3 nB = plume_v3_cross(plume_v3_sub(rest[3], rest[0]), rest_edge);
	if (!(plume_v3_length(nA) > 1e-12 * rest_length2) || !(plume_v3_length(nB) > 1e-12 * rest_length2))
		return false;
	double length = sqrt(length2);
	double area = area_a + area_b;
	// Eq. 6.5: the tilt angle is the area-weighted mean of the two faces' tilts.
	double beta = (area_a * tilt_angle(edge, barb_angle_a) + area_b * tilt_angle(edge, barb_angle_b)) / area;
	for (int i = 0; i < 4; ++i)
		hinge->vertices[i] = vertices[i];
	// Normalisation (see the file comment of bending.h): the literal (A1 + A2)/6 of eq. 6.2
	// with eta = 3 e chi/(A1 + A2) stores three times the continuum energy; dividing by 3
	// makes D the continuum modulus, (1/2) D A / R^2 for a cylinder.
	hinge->stiffness = area / 18.0 * plume_bending_modulus(along, across, beta);
	hinge->scale = 3.0 * length / area;
	hinge->rest_angle = plume_dihedral_angle(rest);
	return true;
}

double plume_hinge_energy(const plume_hinge *hinge, const plume_vec3 x[4], double gradient[12], double hessian[144])
{
	double angle_gradient[12];
	double angle = plume_dihedral_angle_derivatives(x, (gradient || hessian) ? angle_gradient : NULL, hessian);
	double delta = angle - hinge->rest_angle;
	// Both angles are in (-pi, pi]; their difference is taken the short way round.
	if (delta > PI)
		delta -= 2.0 * PI;
	else if (delta <= -PI)
		delta += 2.0 * PI;
	// energy = stiffness (scale chi - scale chi0)^2 = k delta^2
	double k = hinge->stiffness * hinge->scale * hinge->scale;
	if (hessian) {
		for (int r = 0; r < 12; ++r)
			for (int c = 0; c < 12; ++c)
				hessian[12 * r + c] = 2.0 * k * (angle_gradient[r] * angle_gradient[c] + delta * hessian[12 * r + c]);
	}
	if (gradient)
		for (int r = 0; r < 12; ++r)
			gradient[r] = 2.0 * k * delta * angle_gradient[r];
	return k * delta * delta;
}

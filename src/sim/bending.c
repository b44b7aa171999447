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
// derive the same Hessian in another form). No Gauss-Newton approximation.
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

// Adds the 3x3 block s [v]x (the matrix of u -> s v x u) into the 3 x 12 matrix D at vertex k.
static void add_cross_block(double D[36], int k, const double v[3], double s)
{
	// [v]x = [[0, -vz, vy], [vz, 0, -vx], [-vy, vx, 0]]
	D[0 * 12 + 3 * k + 1] += -s * v[2];
	D[0 * 12 + 3 * k + 2] += s * v[1];
	D[1 * 12 + 3 * k + 0] += s * v[2];
	D[1 * 12 + 3 * k + 2] += -s * v[0];
	D[2 * 12 + 3 * k + 0] += -s * v[1];
	D[2 * 12 + 3 * k + 1] += s * v[0];
}

// dm/dx (3 x 12) for m = n / |n|^2 given dn/dx (3 x 12).
static void normal_over_square_derivative(const double n[3], const double dn[36], double dm[36])
{
	// One division, not two per entry: 144 divisions an edge were a sixth of the angle's Hessian.
	double inverse = 1.0 / (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
	for (int a = 0; a < 3; ++a) {
		for (int c = 0; c < 12; ++c) {
			// (I - 2 n n^T / |n|^2) dn / |n|^2
			double ndn = n[0] * dn[c] + n[1] * dn[12 + c] + n[2] * dn[24 + c];
			dm[12 * a + c] = (dn[12 * a + c] - 2.0 * n[a] * ndn * inverse) * inverse;
		}
	}
}

// Gradient of s = (x_y - x_z) . e^ over the 12 coordinates (e = x1 - x0), added with
// factor sign into ds.
static void add_projection_gradient(double ds[12], int y, int z, const double *p, const double ehat[3], double length,
                                    double sign)
{
	double d[3], along = 0.0;
	for (int a = 0; a < 3; ++a) {
		d[a] = p[3 * y + a] - p[3 * z + a];
		along += d[a] * ehat[a];
	}
	for (int a = 0; a < 3; ++a) {
		double perpendicular = (d[a] - along * ehat[a]) / length; // (I - e^ e^T) d / |e|
		ds[3 * y + a] += sign * ehat[a];
		ds[3 * z + a] -= sign * ehat[a];
		ds[3 * 1 + a] += sign * perpendicular;
		ds[3 * 0 + a] -= sign * perpendicular;
	}
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

	double p[12], n[2][3], m[2][3], ehat[3];
	for (int i = 0; i < 4; ++i)
		vec_of(x[i], p + 3 * i);
	vec_of(nA, n[0]);
	vec_of(nB, n[1]);
	vec_of(ehat_v, ehat);
	for (int a = 0; a < 3; ++a) {
		m[0][a] = n[0][a] / nA2;
		m[1][a] = n[1][a] / nB2;
	}
	// Coefficients c[f][i] of m_f in the gradient of vertex i, and their gradients dc.
	double c[2][4], dc[2][4][12];
	memset(dc, 0, sizeof dc);
	double pA0 = 0.0, pA1 = 0.0, pB0 = 0.0, pB1 = 0.0;
	for (int a = 0; a < 3; ++a) {
		pA0 += (p[6 + a] - p[3 + a]) * ehat[a]; // (x2 - x1) . e^
		pA1 += (p[6 + a] - p[a]) * ehat[a];     // (x2 - x0) . e^
		pB0 += (p[9 + a] - p[3 + a]) * ehat[a]; // (x3 - x1) . e^
		pB1 += (p[9 + a] - p[a]) * ehat[a];     // (x3 - x0) . e^
	}
	c[0][0] = pA0;
	c[0][1] = -pA1;
	c[0][2] = length;
	c[0][3] = 0.0;
	c[1][0] = pB0;
	c[1][1] = -pB1;
	c[1][2] = 0.0;
	c[1][3] = length;
	if (gradient) {
		for (int i = 0; i < 4; ++i)
			for (int a = 0; a < 3; ++a)
				gradient[3 * i + a] = c[0][i] * m[0][a] + c[1][i] * m[1][a];
	}
	if (!hessian)
		return angle;

	add_projection_gradient(dc[0][0], 2, 1, p, ehat, length, 1.0);
	add_projection_gradient(dc[0][1], 2, 0, p, ehat, length, -1.0);
	add_projection_gradient(dc[1][0], 3, 1, p, ehat, length, 1.0);
	add_projection_gradient(dc[1][1], 3, 0, p, ehat, length, -1.0);
	for (int a = 0; a < 3; ++a) {
		// d|e| = e^ . (dx1 - dx0)
		dc[0][2][3 + a] = ehat[a];
		dc[0][2][a] = -ehat[a];
		dc[1][3][3 + a] = ehat[a];
		dc[1][3][a] = -ehat[a];
	}
	// dn/dx: n_A = (x2 - x0) x (x2 - x1) gives [x2 - x1]x at x0, -[x2 - x0]x at x1, [e]x at x2;
	// n_B = (x3 - x1) x (x3 - x0) gives -[x3 - x1]x at x0, [x3 - x0]x at x1, -[e]x at x3.
	double dn[2][36], dm[2][36];
	memset(dn, 0, sizeof dn);
	double x21[3], x20[3], x31[3], x30[3];
	for (int a = 0; a < 3; ++a) {
		x21[a] = p[6 + a] - p[3 + a];
		x20[a] = p[6 + a] - p[a];
		x31[a] = p[9 + a] - p[3 + a];
		x30[a] = p[9 + a] - p[a];
	}
	double e[3] = {p[3] - p[0], p[4] - p[1], p[5] - p[2]};
	add_cross_block(dn[0], 0, x21, 1.0);
	add_cross_block(dn[0], 1, x20, -1.0);
	add_cross_block(dn[0], 2, e, 1.0);
	add_cross_block(dn[1], 0, x31, -1.0);
	add_cross_block(dn[1], 1, x30, 1.0);
	add_cross_block(dn[1], 3, e, -1.0);
	normal_over_square_derivative(n[0], dn[0], dm[0]);
	normal_over_square_derivative(n[1], dn[1], dm[1]);
	// The exact Hessian is symmetric: its upper triangle, mirrored.
	for (int i = 0; i < 4; ++i) {
		for (int a = 0; a < 3; ++a) {
			int r = 3 * i + a;
			for (int col = r; col < 12; ++col) {
				double h = m[0][a] * dc[0][i][col] + c[0][i] * dm[0][12 * a + col] + m[1][a] * dc[1][i][col] +
				           c[1][i] * dm[1][12 * a + col];
				hessian[12 * r + col] = hessian[12 * col + r] = h;
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

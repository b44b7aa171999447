// Fundamental-form bending (see fundamental_form.h for the discretisation and why).
// The energy is a constant quadratic form in the face's three dihedral angles, so its
// derivatives are those of the angles (sim/bending.h: exact gradient and Hessian of chi)
// combined by M.
#include "sim/fundamental_form.h"

#include <math.h>
#include <string.h>

#include "sim/bending.h"

static const double PI = 3.14159265358979323846;

double plume_ff_tensor_form(const double a[3], const double b[3], double barb_angle, double along, double across)
{
	double c = cos(barb_angle), s = sin(barb_angle);
	// Components in the barb frame: v = (c, s) along the barb, w = (-s, c) across.
	double a_vv = c * c * a[0] + s * s * a[1] + 2 * c * s * a[2];
	double a_ww = s * s * a[0] + c * c * a[1] - 2 * c * s * a[2];
	double a_vw = c * s * (a[1] - a[0]) + (c * c - s * s) * a[2];
	double b_vv = c * c * b[0] + s * s * b[1] + 2 * c * s * b[2];
	double b_ww = s * s * b[0] + c * c * b[1] - 2 * c * s * b[2];
	double b_vw = c * s * (b[1] - b[0]) + (c * c - s * s) * b[2];
	return across * a_vv * b_vv + along * a_ww * b_ww + (along + across) * a_vw * b_vw;
}

// Stencil positions of edge i's hinge in plume_dihedral_angle's order: the edge
// v_{i+1} -> v_{i+2}, then v_i (so that n_A is the face's own normal for every i) and
// the vertex across.
static void hinge_indices(int i, int out[4])
{
	out[0] = (i + 1) % 3;
	out[1] = (i + 2) % 3;
	out[2] = i;
	out[3] = 3 + i;
}

// Removes boundary edge b from the quadratic form by minimising over its angle (the
// Schur complement); a zero pivot means the edge is not coupled at all.
static void condense(double M[9], int b)
{
	double pivot = M[4 * b];
	if (pivot > 0)
		for (int i = 0; i < 3; ++i)
			for (int j = 0; j < 3; ++j)
				if (i != b && j != b)
					M[3 * i + j] -= M[3 * i + b] * M[3 * b + j] / pivot;
	for (int k = 0; k < 3; ++k)
		M[3 * k + b] = M[3 * b + k] = 0;
}

// t t^T of the unit in-plane normal of the edge opposite vertex i, as (xx, yy, xy).
static void edge_normal_form(const plume_vec2 reference[3], int i, double form[3])
{
	plume_vec2 p = reference[(i + 1) % 3], q = reference[(i + 2) % 3];
	double ex = q.x - p.x, ey = q.y - p.y, length = hypot(ex, ey);
	double tx = -ey / length, ty = ex / length;
	form[0] = tx * tx;
	form[1] = ty * ty;
	form[2] = tx * ty;
}

bool plume_ff_face_init(plume_ff_face *face, const int vertices[6], const plume_vec2 reference[3],
                        const plume_vec3 rest[6], double barb_angle, double along, double across)
{
	double area = 0.5 * ((reference[1].x - reference[0].x) * (reference[2].y - reference[0].y) -
	                     (reference[2].x - reference[0].x) * (reference[1].y - reference[0].y));
	area = fabs(area);
	// l_i t_i t_i^T as (xx, yy, xy): t_i is the edge direction turned by 90 degrees, and the
	// sign of t_i does not matter.
	double form[3][3], scale = 0;
	for (int i = 0; i < 3; ++i) {
		plume_vec2 p = reference[(i + 1) % 3], q = reference[(i + 2) % 3];
		double length = hypot(q.x - p.x, q.y - p.y);
		scale = fmax(scale, length * length);
		if (!(length > 0))
			return false;
		edge_normal_form(reference, i, form[i]);
		for (int k = 0; k < 3; ++k)
			form[i][k] *= length;
	}
	if (!isfinite(area) || !(area > 1e-12 * scale))
		return false;
	memcpy(face->vertices, vertices, sizeof face->vertices);
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			face->stiffness[3 * i + j] = plume_ff_tensor_form(form[i], form[j], barb_angle, along, across) / (4 * area);
	for (int i = 0; i < 3; ++i) {
		face->rest_angle[i] = 0;
		face->edge_scale[i] = face->border_scale[i] = 1;
		face->edge[i] = -1;
		if (vertices[3 + i] < 0) {
			condense(face->stiffness, i);
			continue;
		}
		int h[4];
		hinge_indices(i, h);
		plume_vec3 local[4] = {rest[h[0]], rest[h[1]], rest[h[2]], rest[h[3]]};
		face->rest_angle[i] = plume_dihedral_angle(local);
	}
	return true;
}

double plume_ff_edge_modulus(const plume_vec2 reference[3], int i, double barb_angle, double along, double across)
{
	double form[3];
	edge_normal_form(reference, i, form);
	return plume_ff_tensor_form(form, form, barb_angle, along, across);
}

void plume_ff_face_border(plume_ff_face *face, int i, double own_modulus, double other_modulus)
{
	double sum = own_modulus + other_modulus;
	face->border_scale[i] = face->edge_scale[i] = sum > 0 ? 2 * other_modulus / sum : 1;
}

void plume_ff_face_clamp(plume_ff_face *face, const bool held[6])
{
	bool clamped = held[0] && held[1] && held[2];
	for (int i = 0; i < 3; ++i) {
		bool neighbour_clamped = face->vertices[3 + i] >= 0 && held[(i + 1) % 3] && held[(i + 2) % 3] && held[3 + i];
		face->edge_scale[i] = clamped ? 0 : neighbour_clamped ? 2 : face->border_scale[i];
	}
}

/// One edge's angle and derivatives as a face sees them: chi in the face's sign,
/// gradient (12) and Hessian (144, NULL when not needed) in some stencil order, slot
/// order[k] holding the face's hinge vertex k, each derivative times sign.
typedef struct edge_view {
	double chi;
	const double *gradient;
	const double *hessian;
	const unsigned char *order;
	double sign;
} edge_view;

static const unsigned char IDENTITY_ORDER[4] = {0, 1, 2, 3};

// The change of edge i's angle from its rest value, the short way round, times the edge's
// clamp scale. Zero for a boundary edge.
static double angle_change(const plume_ff_face *face, int i, double chi)
{
	if (face->vertices[3 + i] < 0)
		return 0;
	double delta = chi - face->rest_angle[i];
	if (delta > PI)
		delta -= 2 * PI;
	else if (delta <= -PI)
		delta += 2 * PI;
	return face->edge_scale[i] * delta;
}

// The upper triangle of J^T M J (row r, columns c >= r), the part the solver's scatter
// reads (plume_sim_scatter_block). Writing the lower one too, a column of 18 strided stores
// a row into a buffer of every face's blocks that is not in cache, took 40 % of combine's
// time (perf, Figure 1): the full-Hessian entry points mirror it (evaluate).
static void gauss_newton_upper(const double M[9], const double J[54], double hessian[324])
{
	for (int r = 0; r < 18; ++r) {
		double MJ[3]; // (M J)_{:, r}
		for (int i = 0; i < 3; ++i)
			MJ[i] = M[3 * i] * J[r] + M[3 * i + 1] * J[18 + r] + M[3 * i + 2] * J[36 + r];
		for (int c = r; c < 18; ++c)
			hessian[18 * r + c] = J[c] * MJ[0] + J[18 + c] * MJ[1] + J[36 + c] * MJ[2];
	}
}

static void mirror_upper(double hessian[324])
{
	for (int r = 1; r < 18; ++r)
		for (int c = 0; c < r; ++c)
			hessian[18 * r + c] = hessian[18 * c + r];
}

// Energy 1/2 dchi^T M dchi, gradient (M dchi)^T J and the Gauss-Newton Hessian J^T M J
// (its upper triangle) from the three edges' views (J: the stencil gradients of the
// scaled angle changes, 3 x 18), and each edge's weight (M dchi)_i s_i sign_i: the exact
// Hessian is J^T M J + sum_i weight_i Hess chi_i (plume_ff_face_energy_from_edges).
static double combine(const plume_ff_face *face, const edge_view view[3], double gradient[18], double hessian[324],
                      double weight[3])
{
	double delta[3], J[54];
	bool derivatives = gradient != NULL || hessian != NULL;
	if (derivatives)
		memset(J, 0, sizeof J);
	for (int i = 0; i < 3; ++i) {
		delta[i] = angle_change(face, i, view[i].chi);
		if (!derivatives || face->vertices[3 + i] < 0)
			continue;
		int h[4];
		hinge_indices(i, h);
		double scale = face->edge_scale[i] * view[i].sign;
		for (int k = 0; k < 4; ++k)
			for (int a = 0; a < 3; ++a)
				J[18 * i + 3 * h[k] + a] = scale * view[i].gradient[3 * view[i].order[k] + a];
	}
	const double *M = face->stiffness;
	double force[3];
	for (int i = 0; i < 3; ++i) {
		force[i] = M[3 * i] * delta[0] + M[3 * i + 1] * delta[1] + M[3 * i + 2] * delta[2];
		weight[i] = face->vertices[3 + i] < 0 ? 0 : force[i] * face->edge_scale[i] * view[i].sign;
	}
	if (gradient)
		for (int r = 0; r < 18; ++r)
			gradient[r] = force[0] * J[r] + force[1] * J[18 + r] + force[2] * J[36 + r];
	if (hessian)
		gauss_newton_upper(M, J, hessian);
	return 0.5 * (force[0] * delta[0] + force[1] * delta[1] + force[2] * delta[2]);
}

// Adds sum_i weight_i Hess chi_i, each angle's Hessian in its view's stencil order.
static void add_angle_curvature(const plume_ff_face *face, const edge_view view[3], const double weight[3],
                                double hessian[324])
{
	for (int i = 0; i < 3; ++i) {
		if (weight[i] == 0 || face->vertices[3 + i] < 0)
			continue;
		int h[4], face_row[12], edge_row[12];
		hinge_indices(i, h);
		for (int a = 0; a < 12; ++a) {
			face_row[a] = 3 * h[a / 3] + a % 3;
			edge_row[a] = 3 * view[i].order[a / 3] + a % 3;
		}
		for (int a = 0; a < 12; ++a) {
			double *out = hessian + 18 * face_row[a];
			const double *in = view[i].hessian + 12 * edge_row[a];
			for (int b = 0; b < 12; ++b)
				out[face_row[b]] += weight[i] * in[edge_row[b]];
		}
	}
}

// The face's three angles with their derivatives (hinge order) from the positions.
static double evaluate(const plume_ff_face *face, const plume_vec3 x[6], bool exact, double gradient[18],
                       double hessian[324])
{
	double local_gradient[3][12], local_hessian[3][144];
	bool want_hessian = exact && hessian != NULL, derivatives = gradient != NULL || hessian != NULL;
	edge_view view[3];
	for (int i = 0; i < 3; ++i) {
		view[i] = (edge_view){0, local_gradient[i], local_hessian[i], IDENTITY_ORDER, 1};
		if (face->vertices[3 + i] < 0)
			continue;
		int h[4];
		hinge_indices(i, h);
		plume_vec3 local[4] = {x[h[0]], x[h[1]], x[h[2]], x[h[3]]};
		view[i].chi = plume_dihedral_angle_derivatives(local, derivatives ? local_gradient[i] : NULL,
		                                               want_hessian ? local_hessian[i] : NULL);
	}
	double weight[3];
	double energy = combine(face, view, gradient, hessian, weight);
	if (hessian != NULL)
		mirror_upper(hessian);
	if (want_hessian)
		add_angle_curvature(face, view, weight, hessian);
	return energy;
}

double plume_ff_face_energy_gauss_newton(const plume_ff_face *face, const plume_vec3 x[6], double gradient[18],
                                         double hessian[324])
{
	return evaluate(face, x, false, gradient, hessian);
}

double plume_ff_face_energy(const plume_ff_face *face, const plume_vec3 x[6], double gradient[18], double hessian[324])
{
	return evaluate(face, x, true, gradient, hessian);
}

void plume_ff_hinge_vertices(const plume_ff_face *face, int i, int out[4])
{
	int h[4];
	hinge_indices(i, h);
	for (int k = 0; k < 4; ++k)
		out[k] = face->vertices[h[k]];
}

void plume_ff_face_link(plume_ff_face *face, int i, int edge, const int stencil[4])
{
	int own[4];
	plume_ff_hinge_vertices(face, i, own);
	for (int k = 0; k < 4; ++k)
		for (int slot = 0; slot < 4; ++slot)
			if (stencil[slot] == own[k])
				face->edge_order[i][k] = (unsigned char)slot;
	face->edge[i] = edge;
	// plume_dihedral_angle is unchanged when the edge's direction and the wings are both
	// swapped (n_A and n_B trade places), and changes sign when only one of them is.
	bool edge_swapped = face->edge_order[i][0] != 0, wings_swapped = face->edge_order[i][2] != 2;
	face->edge_sign[i] = edge_swapped == wings_swapped ? 1 : -1;
}

double plume_ff_face_energy_from_edges(const plume_ff_face *face, const double *chi, const double *gradients,
                                       double gradient[18], double gauss_newton[324], double weight[3])
{
	edge_view view[3];
	for (int i = 0; i < 3; ++i) {
		int e = face->edge[i];
		if (face->vertices[3 + i] < 0 || e < 0) {
			view[i] = (edge_view){0, NULL, NULL, IDENTITY_ORDER, 1};
			continue;
		}
		double sign = face->edge_sign[i];
		view[i] = (edge_view){sign * chi[e], gradients + 12 * (size_t)e, NULL, face->edge_order[i], sign};
	}
	return combine(face, view, gradient, gauss_newton, weight);
}

// The mesoscale band model on quadratic (six-node) triangles: why, in quadratic.h.
//
// Per element the energy is the integral of the plane St-Venant-Kirchhoff density
//   psi = (1 / 2) e^T C e,   e = (E11, E22, 2 E12),
// E = (F^T F - I) / 2 the Green strain and C the element's Voigt tensor times the
// thickness: the mesoscale bands' isotropic one with zero Poisson ratio (thesis 5.2),
// C = k diag(1, 1, 1/2), or the macroscale vane's orthotropic one rotated to the barbs
// (thesis eq. 4.1, paper eq. 5), which the caller takes from sim/membrane.h so that both
// solvers hold the same material. F is linear over a quadratic element, psi of degree
// four: the six-point rule of degree four (Dunavant 1985) integrates it exactly. With
// s = C e (the second Piola-Kirchhoff stress times the thickness, S = [[s0, s2], [s2, s1]])
// and g_a the reference gradient of shape function a:
//   dW/dx_a      = F S g_a
//   d2W/dx_a dx_b = B_a^T C B_b + (g_a . S g_b) I,
// B_a the 3x2 derivative of e with respect to x_a.
// Kikuuwe's compression term (thesis eq. 6.6) is added on J = det F (element_evaluate).
// Where the barbules are compressed the Hessian can be indefinite; Newton then shifts
// it by mu diag(H) (factor_newton_matrix).
// The degree-4 rule is exact for the St-Venant-Kirchhoff part; the cubic Kikuuwe term
// on J (degree 2 in x) is of degree six and is integrated approximately, consistently
// in the energy and its derivatives.
#include "lab/quadratic.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "sim/sparse.h"

enum { NODES = 6, DOFS = 12, POINTS = 6, BLOCK = DOFS * DOFS };

// Dunavant's degree-4 rule: barycentric points and weights summing to one.
static const double rule_a[2] = {0.445948490915965, 0.091576213509771};
static const double rule_w[2] = {0.223381589678011, 0.109951743655322};

struct plume_quadratic {
	int node_count;
	int corner_count;
	int element_count;
	/// Six nodes per element: corners 0, 1, 2, then the midpoints of edges 01, 12, 20.
	int *elements;
	plume_vec2 *reference;
	/// Per element and quadrature point: area * weight, and the six shape gradients (x, y).
	double *weight;
	double *gradients;
	/// thickness * Voigt tensor (9, row-major) and thickness * Kikuuwe coefficient per element, Pa m.
	double *stiffness;
	double *compression;
	/// Per node: 0 free, 1 bottom clamp, 2 top clamp.
	unsigned char *clamp;
	/// Free unknown of each of the 2 node_count coordinates, or -1 on a clamp.
	int *free_index;
	int free_count;
	double height;
	/// Levenberg shift of the last indefinite Hessian, and scratch for the Hessian's diagonal.
	double shift;
	double *diagonal;
	plume_solver_def solver;

	/// Current, last converged and second-last converged coordinates (2 per node).
	double *x;
	double *converged;
	double *converged_before;
	double displacement_converged;
	double displacement_before;
	bool has_before;
	/// Scratch: trial coordinates, full gradient, element outputs.
	double *trial;
	double *gradient;
	double *element_energy;
	double *element_gradient;
	double *element_hessian;

	/// H over the free unknowns (upper triangle) and its factorisation; Newton's right-hand side.
	plume_sparse system;
	/// Slot of each element block entry in system.matrix->x (upper part over free unknowns), else -1.
	int *slots;
};

// ---------------------------------------------------------------------------
// Element kinematics and energy

static void shape_gradients(double dL[3][2], const double L[3], double out[NODES][2])
{
	for (int i = 0; i < 3; ++i)
		for (int d = 0; d < 2; ++d)
			out[i][d] = (4.0 * L[i] - 1.0) * dL[i][d];
	for (int i = 0; i < 3; ++i) {
		int j = (i + 1) % 3;
		for (int d = 0; d < 2; ++d)
			out[3 + i][d] = 4.0 * (L[j] * dL[i][d] + L[i] * dL[j][d]);
	}
}

// Barycentric gradients of a reference triangle; false when it is degenerate.
static bool barycentric_gradients(const plume_vec2 p[3], double dL[3][2], double *area)
{
	double det = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
	double scale = fmax(fabs(p[1].x - p[0].x) + fabs(p[1].y - p[0].y), fabs(p[2].x - p[0].x) + fabs(p[2].y - p[0].y));
	if (!(fabs(det) > 1e-12 * scale * scale))
		return false;
	for (int i = 0; i < 3; ++i) {
		const plume_vec2 *a = p + (i + 1) % 3, *b = p + (i + 2) % 3;
		dL[i][0] = (a->y - b->y) / det;
		dL[i][1] = (b->x - a->x) / det;
	}
	*area = 0.5 * fabs(det);
	return true;
}

// Energy of element e at coordinates x; gradient (12) and hessian (144) when not NULL.
static double element_evaluate(const plume_quadratic *m, int e, const double *x, double *gradient, double *hessian)
{
	const int *nodes = m->elements + NODES * e;
	double local[DOFS];
	for (int a = 0; a < NODES; ++a) {
		local[2 * a] = x[2 * nodes[a]];
		local[2 * a + 1] = x[2 * nodes[a] + 1];
	}
	const double *C = m->stiffness + 9 * (size_t)e;
	double c = m->compression[e] / 12.0, energy = 0.0;
	if (gradient != NULL)
		memset(gradient, 0, sizeof(double) * DOFS);
	if (hessian != NULL)
		memset(hessian, 0, sizeof(double) * BLOCK);
	for (int q = 0; q < POINTS; ++q) {
		const double *g = m->gradients + ((size_t)e * POINTS + q) * NODES * 2;
		double w = m->weight[(size_t)e * POINTS + q];
		// F columns f1 = dx/dX, f2 = dx/dY.
		double f1[2] = {0.0, 0.0}, f2[2] = {0.0, 0.0};
		for (int a = 0; a < NODES; ++a) {
			f1[0] += local[2 * a] * g[2 * a];
			f1[1] += local[2 * a + 1] * g[2 * a];
			f2[0] += local[2 * a] * g[2 * a + 1];
			f2[1] += local[2 * a + 1] * g[2 * a + 1];
		}
		double strain[3] = {0.5 * (f1[0] * f1[0] + f1[1] * f1[1] - 1.0), 0.5 * (f2[0] * f2[0] + f2[1] * f2[1] - 1.0),
		                    f1[0] * f2[0] + f1[1] * f2[1]};
		double stress[3];
		for (int i = 0; i < 3; ++i)
			stress[i] = C[3 * i] * strain[0] + C[3 * i + 1] * strain[1] + C[3 * i + 2] * strain[2];
		energy += w * 0.5 * (stress[0] * strain[0] + stress[1] * strain[1] + stress[2] * strain[2]);
		// Kikuuwe's term (thesis eq. 6.6) on the signed area ratio J = det F, so that an
		// inverted element costs more than a flat one: c ((1 - J) / 6)^3 for J < 1.
		double J = f1[0] * f2[1] - f1[1] * f2[0], dpsi_c = 0.0, d2psi_c = 0.0;
		if (c > 0.0 && J < 1.0) {
			double u = (1.0 - J) / 6.0;
			energy += w * c * u * u * u;
			dpsi_c = -0.5 * c * u * u;
			d2psi_c = c * u / 6.0;
		}
		if (gradient == NULL)
			continue;
		double S11 = stress[0], S22 = stress[1], S12 = stress[2];
		// dJ/dx_a = (g_a1 f2y - g_a2 f1y, g_a2 f1x - g_a1 f2x).
		double dJ[DOFS];
		for (int a = 0; a < NODES; ++a) {
			dJ[2 * a] = g[2 * a] * f2[1] - g[2 * a + 1] * f1[1];
			dJ[2 * a + 1] = g[2 * a + 1] * f1[0] - g[2 * a] * f2[0];
			// F S g_a
			double s1 = S11 * g[2 * a] + S12 * g[2 * a + 1], s2 = S12 * g[2 * a] + S22 * g[2 * a + 1];
			gradient[2 * a] += w * (f1[0] * s1 + f2[0] * s2 + dpsi_c * dJ[2 * a]);
			gradient[2 * a + 1] += w * (f1[1] * s1 + f2[1] * s2 + dpsi_c * dJ[2 * a + 1]);
		}
		if (hessian == NULL)
			continue;
		// B_a rows: (g_a1 f1), (g_a2 f2), (g_a2 f1 + g_a1 f2).
		double B[NODES][3][2];
		for (int a = 0; a < NODES; ++a)
			for (int d = 0; d < 2; ++d) {
				B[a][0][d] = g[2 * a] * f1[d];
				B[a][1][d] = g[2 * a + 1] * f2[d];
				B[a][2][d] = g[2 * a + 1] * f1[d] + g[2 * a] * f2[d];
			}
		// CB_b = C B_b.
		double CB[NODES][3][2];
		for (int b = 0; b < NODES; ++b)
			for (int r = 0; r < 3; ++r)
				for (int d = 0; d < 2; ++d)
					CB[b][r][d] = C[3 * r] * B[b][0][d] + C[3 * r + 1] * B[b][1][d] + C[3 * r + 2] * B[b][2][d];
		for (int a = 0; a < NODES; ++a)
			for (int b = a; b < NODES; ++b) {
				double geometric = g[2 * a] * (S11 * g[2 * b] + S12 * g[2 * b + 1]) +
				                   g[2 * a + 1] * (S12 * g[2 * b] + S22 * g[2 * b + 1]);
				// d2J/dx_a dx_b = (g_a1 g_b2 - g_a2 g_b1) [[0, 1], [-1, 0]].
				double twist = dpsi_c * (g[2 * a] * g[2 * b + 1] - g[2 * a + 1] * g[2 * b]);
				for (int i = 0; i < 2; ++i)
					for (int j = 0; j < 2; ++j) {
						double value = B[a][0][i] * CB[b][0][j] + B[a][1][i] * CB[b][1][j] + B[a][2][i] * CB[b][2][j] +
						               d2psi_c * dJ[2 * a + i] * dJ[2 * b + j];
						if (i == j)
							value += geometric;
						else
							value += i == 0 ? twist : -twist;
						hessian[(2 * a + i) * DOFS + 2 * b + j] += w * value;
					}
			}
	}
	if (hessian != NULL)
		for (int r = 0; r < DOFS; ++r)
			for (int c2 = 0; c2 < r; ++c2)
				hessian[r * DOFS + c2] = hessian[c2 * DOFS + r];
	return energy;
}

// ---------------------------------------------------------------------------
// Setup

typedef struct edge_key {
	int lo, hi, slot; // slot = 3 * face + local edge
} edge_key;

static int compare_edges(const void *a, const void *b)
{
	const edge_key *p = a, *q = b;
	if (p->lo != q->lo)
		return p->lo < q->lo ? -1 : 1;
	if (p->hi != q->hi)
		return p->hi < q->hi ? -1 : 1;
	return (p->slot > q->slot) - (p->slot < q->slot);
}

// Nodes: the corners, then one per unique edge at its midpoint.
static plume_status build_nodes(plume_quadratic *m, const plume_mesh *mesh, plume_error *err)
{
	int face_count = mesh->face_count;
	edge_key *edges = plume_alloc(sizeof *edges * 3 * (size_t)face_count);
	m->elements = plume_alloc(sizeof(int) * NODES * (size_t)face_count);
	if (edges == NULL || m->elements == NULL) {
		plume_free(edges);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building quadratic elements");
	}
	for (int f = 0; f < face_count; ++f)
		for (int i = 0; i < 3; ++i) {
			int a = mesh->faces[3 * f + i], b = mesh->faces[3 * f + (i + 1) % 3];
			edges[3 * f + i] = (edge_key){a < b ? a : b, a < b ? b : a, 3 * f + i};
			m->elements[NODES * f + i] = mesh->faces[3 * f + i];
		}
	qsort(edges, 3 * (size_t)face_count, sizeof *edges, compare_edges);
	int node = mesh->vertex_count;
	for (int e = 0; e < 3 * face_count; ++e) {
		if (e > 0 && (edges[e].lo != edges[e - 1].lo || edges[e].hi != edges[e - 1].hi))
			++node;
		int f = edges[e].slot / 3, i = edges[e].slot % 3;
		m->elements[NODES * f + 3 + i] = node;
	}
	m->corner_count = mesh->vertex_count;
	m->node_count = face_count > 0 ? node + 1 : mesh->vertex_count;
	m->reference = plume_alloc(sizeof *m->reference * (size_t)m->node_count);
	m->clamp = plume_calloc((size_t)m->node_count, 1);
	if (m->reference == NULL || m->clamp == NULL) {
		plume_free(edges);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building quadratic nodes");
	}
	memcpy(m->reference, mesh->reference, sizeof *m->reference * (size_t)mesh->vertex_count);
	const char *names[2] = {"bottom", "top"};
	for (int c = 0; c < 2; ++c) {
		const plume_vertex_group *group = plume_mesh_find_group(mesh, names[c]);
		if (group == NULL) {
			plume_free(edges);
			return plume_error_set(err, PLUME_ERROR_SPEC, "the sample mesh has no \"%s\" group", names[c]);
		}
		for (int i = 0; i < group->count; ++i)
			m->clamp[group->vertices[i]] = (unsigned char)(c + 1);
	}
	for (int e = 0; e < 3 * face_count; ++e) {
		int f = edges[e].slot / 3, i = edges[e].slot % 3;
		int mid = m->elements[NODES * f + 3 + i];
		plume_vec2 a = mesh->reference[edges[e].lo], b = mesh->reference[edges[e].hi];
		m->reference[mid] = (plume_vec2){0.5 * (a.x + b.x), 0.5 * (a.y + b.y)};
		// Both ends on one clamp: the edge lies on that straight side.
		if (m->clamp[edges[e].lo] != 0 && m->clamp[edges[e].lo] == m->clamp[edges[e].hi])
			m->clamp[mid] = m->clamp[edges[e].lo];
	}
	plume_free(edges);
	return PLUME_OK;
}

static plume_status build_quadrature(plume_quadratic *m, const plume_mesh *mesh, const double *voigt, double kappa,
                                     double thickness, plume_error *err)
{
	int count = m->element_count;
	m->weight = plume_alloc(sizeof(double) * POINTS * (size_t)count);
	m->gradients = plume_alloc(sizeof(double) * POINTS * NODES * 2 * (size_t)count);
	m->stiffness = plume_alloc(sizeof(double) * 9 * (size_t)count);
	m->compression = plume_alloc(sizeof(double) * (size_t)count);
	if (m->weight == NULL || m->gradients == NULL || m->stiffness == NULL || m->compression == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building quadratic elements");
	for (int e = 0; e < count; ++e) {
		plume_vec2 p[3];
		for (int i = 0; i < 3; ++i)
			p[i] = mesh->reference[mesh->faces[3 * e + i]];
		double dL[3][2], area;
		if (!barycentric_gradients(p, dL, &area))
			return plume_error_set(err, PLUME_ERROR_NUMERIC, "sample triangle %d is degenerate", e);
		for (int q = 0; q < POINTS; ++q) {
			// Points 0-2: (1 - 2a, a, a) rotated, with a = rule_a[0]; 3-5 likewise with rule_a[1].
			int group = q / 3, rotation = q % 3;
			double a = rule_a[group], L[3];
			for (int i = 0; i < 3; ++i)
				L[i] = i == rotation ? 1.0 - 2.0 * a : a;
			double g[NODES][2];
			shape_gradients(dL, L, g);
			memcpy(m->gradients + ((size_t)e * POINTS + q) * NODES * 2, g, sizeof g);
			m->weight[(size_t)e * POINTS + q] = area * rule_w[group];
		}
		for (int i = 0; i < 9; ++i)
			m->stiffness[9 * (size_t)e + i] = thickness * voigt[9 * (size_t)e + i];
		m->compression[e] = thickness * kappa;
	}
	return PLUME_OK;
}

// The free unknowns' upper-triangle pattern (fixed per mesh), its slots and the symbolic analysis.
static plume_status build_matrix(plume_quadratic *m, plume_error *err)
{
	size_t capacity = (size_t)m->element_count * (DOFS * (DOFS + 1) / 2);
	plume_sparse_entry *entries = plume_alloc(sizeof *entries * (capacity > 0 ? capacity : 1));
	m->slots = plume_alloc(sizeof(int) * BLOCK * (size_t)(m->element_count > 0 ? m->element_count : 1));
	if (entries == NULL || m->slots == NULL) {
		plume_free(entries);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building the band model's matrix");
	}
	// At most DOFS (DOFS + 1) / 2 pairs i <= j per element: every unordered pair and the diagonal.
	size_t count = 0;
	for (int e = 0; e < m->element_count; ++e) {
		const int *nodes = m->elements + NODES * e;
		for (int r = 0; r < DOFS; ++r)
			for (int c = 0; c < DOFS; ++c) {
				int i = m->free_index[2 * nodes[r / 2] + r % 2], j = m->free_index[2 * nodes[c / 2] + c % 2];
				if (i >= 0 && j >= 0 && i <= j)
					entries[count++] = (plume_sparse_entry){j, i};
			}
	}
	// LL': H is meant to be positive definite, and where it is not Newton shifts it.
	plume_status status =
	    plume_sparse_init(&m->system, m->free_count, entries, count, true, "the band model's matrix", err);
	plume_free(entries);
	if (status != PLUME_OK)
		return status;
	for (int el = 0; el < m->element_count; ++el) {
		const int *nodes = m->elements + NODES * el;
		for (int r = 0; r < DOFS; ++r)
			for (int c = 0; c < DOFS; ++c) {
				int i = m->free_index[2 * nodes[r / 2] + r % 2], j = m->free_index[2 * nodes[c / 2] + c % 2];
				// Each unordered pair once: (r, c) with i < j; i == j only on the diagonal r == c.
				m->slots[(size_t)el * BLOCK + r * DOFS + c] =
				    i >= 0 && j >= 0 && i <= j ? plume_sparse_find(&m->system, i, j) : -1;
			}
	}
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// Newton's method

static double sum_energies(const plume_quadratic *m)
{
	// In element order, so that the total does not depend on the thread count.
	double sum = 0.0;
	for (int e = 0; e < m->element_count; ++e)
		sum += m->element_energy[e];
	return sum;
}

static double energy_at(plume_quadratic *m, const double *x)
{
#pragma omp parallel for schedule(static) if (m->element_count >= 1024)
	for (int e = 0; e < m->element_count; ++e)
		m->element_energy[e] = element_evaluate(m, e, x, NULL, NULL);
	return sum_energies(m);
}

// Energy, the full gradient and the exact Hessian's free block (into the matrix) at x.
static double assemble(plume_quadratic *m, const double *x)
{
#pragma omp parallel for schedule(static) if (m->element_count >= 1024)
	for (int e = 0; e < m->element_count; ++e)
		m->element_energy[e] =
		    element_evaluate(m, e, x, m->element_gradient + (size_t)DOFS * e, m->element_hessian + (size_t)BLOCK * e);
	memset(m->gradient, 0, sizeof(double) * 2 * (size_t)m->node_count);
	for (int e = 0; e < m->element_count; ++e) {
		const int *nodes = m->elements + NODES * e;
		for (int r = 0; r < DOFS; ++r)
			m->gradient[2 * nodes[r / 2] + r % 2] += m->element_gradient[(size_t)DOFS * e + r];
	}
	double *values = m->system.matrix->x;
	memset(values, 0, sizeof(double) * (size_t)((int *)m->system.matrix->p)[m->free_count]);
	for (int e = 0; e < m->element_count; ++e) {
		const int *slots = m->slots + (size_t)BLOCK * e;
		const double *block = m->element_hessian + (size_t)BLOCK * e;
		for (int k = 0; k < BLOCK; ++k)
			if (slots[k] >= 0)
				values[slots[k]] += block[k];
	}
	return sum_energies(m);
}

// Factors the assembled exact Hessian H. Where it is not positive definite (the
// barbules' compression softens the St-Venant-Kirchhoff energy and a shear band forms),
// H + mu diag(H) with the smallest mu in a decade ladder that factors: unlike a
// projected Hessian it keeps the soft directions soft, so Newton walks along them in
// a few steps instead of crawling. m->shift remembers the last mu to start near it.
static bool factor_newton_matrix(plume_quadratic *m)
{
	if (plume_sparse_factor(&m->system)) {
		m->shift = 0.0;
		return true;
	}
	double *values = m->system.matrix->x;
	const int *slots = m->system.diagonal;
	int n = m->free_count;
	for (int j = 0; j < n; ++j)
		m->diagonal[j] = values[slots[j]];
	double mu = m->shift > 0.0 ? 0.01 * m->shift : 1e-10;
	for (; mu <= 1e4; mu *= 10.0) {
		for (int j = 0; j < n; ++j)
			values[slots[j]] = m->diagonal[j] + mu * fabs(m->diagonal[j]);
		if (plume_sparse_factor(&m->system)) {
			m->shift = mu;
			return true;
		}
	}
	return false;
}

// Largest free force component and largest clamp force component at the last assembly.
static void residual_of(const plume_quadratic *m, double *free_force, double *clamp_force)
{
	*free_force = 0.0, *clamp_force = 0.0;
	for (int k = 0; k < 2 * m->node_count; ++k) {
		double g = fabs(m->gradient[k]);
		if (m->free_index[k] >= 0)
			*free_force = fmax(*free_force, g);
		else
			*clamp_force = fmax(*clamp_force, g);
	}
}

// Minimises the energy with the clamps where m->x has them. Returns convergence.
static bool newton(plume_quadratic *m, int *iterations, double *relative_residual)
{
	bool converged = false;
	*iterations = 0;
	*relative_residual = INFINITY;
	for (int it = 0;; ++it) {
		double energy = assemble(m, m->x);
		double free_force, clamp_force;
		residual_of(m, &free_force, &clamp_force);
		double scale = clamp_force > 0.0 ? clamp_force : 1.0;
		*relative_residual = free_force / scale;
		if (!isfinite(energy))
			break;
		if (free_force <= m->solver.tolerance * scale) {
			converged = true;
			break;
		}
		if (it == m->solver.max_iterations || !factor_newton_matrix(m))
			break;
		*iterations = it + 1;
		double *b = m->system.rhs->x;
		for (int k = 0; k < 2 * m->node_count; ++k)
			if (m->free_index[k] >= 0)
				b[m->free_index[k]] = -m->gradient[k];
		if (!plume_sparse_solve(&m->system))
			break;
		const double *dx = m->system.solution->x;
		double slope = 0.0;
		for (int i = 0; i < m->free_count; ++i)
			slope -= b[i] * dx[i];
		// Backtracking (Armijo) on the energy. Near the solution the energy's changes fall
		// below its round-off: a full step that does not raise it beyond that is taken.
		bool accepted = false;
		for (double alpha = 1.0; alpha > 1e-10; alpha *= 0.5) {
			memcpy(m->trial, m->x, sizeof(double) * 2 * (size_t)m->node_count);
			for (int k = 0; k < 2 * m->node_count; ++k)
				if (m->free_index[k] >= 0)
					m->trial[k] += alpha * dx[m->free_index[k]];
			double trial_energy = energy_at(m, m->trial);
			accepted = trial_energy <= energy + 1e-4 * alpha * slope ||
			           (alpha == 1.0 && trial_energy <= energy + 1e-13 * fabs(energy));
			if (accepted)
				break;
		}
		if (!accepted)
			break;
		memcpy(m->x, m->trial, sizeof(double) * 2 * (size_t)m->node_count);
	}
	return converged;
}

// ---------------------------------------------------------------------------
// Load stepping

// Puts the clamps at displacement d and the free nodes where the last two solutions
// extrapolate to (or, from rest, where a uniform stretch along y puts them).
static void predict(plume_quadratic *m, double d)
{
	double step = d - m->displacement_converged;
	double previous = m->displacement_converged - m->displacement_before;
	bool secant = m->has_before && previous != 0.0;
	for (int node = 0; node < m->node_count; ++node) {
		double *x = m->x + 2 * node;
		const double *c = m->converged + 2 * node, *b = m->converged_before + 2 * node;
		plume_vec2 X = m->reference[node];
		if (m->clamp[node] != 0) {
			x[0] = X.x;
			x[1] = X.y + (m->clamp[node] == 2 ? d : 0.0);
		} else if (secant) {
			x[0] = c[0] + step / previous * (c[0] - b[0]);
			x[1] = c[1] + step / previous * (c[1] - b[1]);
		} else {
			x[0] = c[0];
			x[1] = c[1] + step * X.y / m->height;
		}
	}
}

static void commit(plume_quadratic *m, double d)
{
	size_t size = sizeof(double) * 2 * (size_t)m->node_count;
	memcpy(m->converged_before, m->converged, size);
	memcpy(m->converged, m->x, size);
	m->displacement_before = m->displacement_converged;
	m->displacement_converged = d;
	m->has_before = true;
}

plume_status plume_quadratic_solve(plume_quadratic *m, double displacement, plume_quadratic_report *report,
                                   plume_error *err)
{
	memset(report, 0, sizeof *report);
	int pieces = 1, max_pieces = 1 << m->solver.max_substep_halvings;
	bool converged = false;
	for (;;) {
		double next = pieces == 1 ? displacement
		                          : m->displacement_converged + (displacement - m->displacement_converged) / pieces;
		predict(m, next);
		int iterations = 0;
		converged = newton(m, &iterations, &report->relative_residual);
		report->newton_iterations += iterations;
		report->substeps += 1;
		if (converged) {
			commit(m, next);
			if (pieces == 1)
				break;
			--pieces;
		} else if (pieces >= max_pieces) {
			break;
		} else {
			pieces *= 2;
		}
	}
	report->converged = converged;
	// Every Newton exit follows an assembly at the current state: the gradient is current.
	double force = 0.0;
	for (int node = 0; node < m->node_count; ++node)
		if (m->clamp[node] == 2)
			force += m->gradient[2 * node + 1];
	report->force = force;
	if (!converged)
		return plume_error_set(err, PLUME_ERROR_NUMERIC,
		                       "Newton did not converge in %d iterations (free forces %.3g of the clamp forces)",
		                       m->solver.max_iterations, report->relative_residual);
	return PLUME_OK;
}

int plume_quadratic_node_count(const plume_quadratic *m) { return m->node_count; }

const int *plume_quadratic_element_nodes(const plume_quadratic *m, int element)
{
	return m->elements + NODES * element;
}

double plume_quadratic_element_energy(const plume_quadratic *m, int element, const double *x, double *gradient,
                                      double *hessian)
{
	return element_evaluate(m, element, x, gradient, hessian);
}

void plume_quadratic_positions(const plume_quadratic *m, plume_vec3 *out)
{
	for (int i = 0; i < m->corner_count; ++i)
		out[i] = plume_v3(m->x[2 * i], m->x[2 * i + 1], 0.0);
}

// ---------------------------------------------------------------------------
// Lifetime

plume_status plume_quadratic_create(const plume_mesh *mesh, const double *voigt, double kappa, double thickness,
                                    const plume_solver_def *solver, plume_quadratic **out, plume_error *err)
{
	*out = NULL;
	plume_quadratic *m = plume_calloc(1, sizeof *m);
	if (m == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating the band model");
	m->element_count = mesh->face_count;
	m->solver = *solver;
	double top = 0.0;
	for (int i = 0; i < mesh->vertex_count; ++i)
		top = fmax(top, mesh->reference[i].y);
	m->height = top;
	plume_status status = build_nodes(m, mesh, err);
	if (status == PLUME_OK)
		status = build_quadrature(m, mesh, voigt, kappa, thickness, err);
	if (status == PLUME_OK) {
		size_t dofs = 2 * (size_t)m->node_count;
		m->free_index = plume_alloc(sizeof(int) * dofs);
		m->x = plume_alloc(sizeof(double) * dofs);
		m->converged = plume_alloc(sizeof(double) * dofs);
		m->converged_before = plume_alloc(sizeof(double) * dofs);
		m->trial = plume_alloc(sizeof(double) * dofs);
		m->gradient = plume_alloc(sizeof(double) * dofs);
		m->diagonal = plume_alloc(sizeof(double) * dofs);
		m->element_energy = plume_alloc(sizeof(double) * (size_t)(m->element_count + 1));
		m->element_gradient = plume_alloc(sizeof(double) * DOFS * (size_t)(m->element_count + 1));
		m->element_hessian = plume_alloc(sizeof(double) * BLOCK * (size_t)(m->element_count + 1));
		if (!m->free_index || !m->x || !m->converged || !m->converged_before || !m->trial || !m->gradient ||
		    !m->diagonal || !m->element_energy || !m->element_gradient || !m->element_hessian)
			status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating the band model");
	}
	if (status == PLUME_OK) {
		for (int node = 0; node < m->node_count; ++node)
			for (int d = 0; d < 2; ++d)
				m->free_index[2 * node + d] = m->clamp[node] != 0 ? -1 : m->free_count++;
		for (int node = 0; node < m->node_count; ++node) {
			m->x[2 * node] = m->reference[node].x;
			m->x[2 * node + 1] = m->reference[node].y;
		}
		memcpy(m->converged, m->x, sizeof(double) * 2 * (size_t)m->node_count);
		memcpy(m->converged_before, m->x, sizeof(double) * 2 * (size_t)m->node_count);
		if (m->free_count == 0)
			status = plume_error_set(err, PLUME_ERROR_SPEC, "the sample has no free nodes between its clamps");
	}
	if (status == PLUME_OK)
		status = build_matrix(m, err);
	if (status != PLUME_OK) {
		plume_quadratic_destroy(m);
		return status;
	}
	*out = m;
	return PLUME_OK;
}

void plume_quadratic_destroy(plume_quadratic *m)
{
	if (m == NULL)
		return;
	plume_sparse_free(&m->system);
	plume_free(m->elements);
	plume_free(m->slots);
	plume_free(m->reference);
	plume_free(m->weight);
	plume_free(m->gradients);
	plume_free(m->stiffness);
	plume_free(m->compression);
	plume_free(m->clamp);
	plume_free(m->free_index);
	plume_free(m->x);
	plume_free(m->converged);
	plume_free(m->converged_before);
	plume_free(m->trial);
	plume_free(m->gradient);
	plume_free(m->diagonal);
	plume_free(m->element_energy);
	plume_free(m->element_gradient);
	plume_free(m->element_hessian);
	plume_free(m);
}

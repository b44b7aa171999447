// The potential Newton minimises, its gradient and its projected Hessian.
//
// Statics: Phi(x) = E_membrane + E_compression + E_bending - sum m_i g . x_i.
// A dynamic step minimises the incremental potential (integrator.c)
//   Phi(x) + inertia/2 sum m_i |x_i - x_pred_i|^2 + R(v(x)) / s,   v(x) = s (x - base),
// whose stationarity is the integrator's update (for implicit Euler, inertia = 1/h^2 and
// s = 1/h: M (v_{n+1} - v_n) / h = f(x_{n+1}), thesis B.2), with R the Rayleigh dissipation
// of the linear drag, (1/2) c A_i (v_i . n_i)^2, normals frozen at the start of the step,
// plus the quadratic air model's (air.c), added per face. With contact, IPC's barrier over
// the pairs of primitives within reach (contact.c) is added to Phi in statics and dynamics.
//
// Elements are evaluated in parallel into per-element buffers and summed in a
// fixed order, so results do not depend on the number of threads.
#include <math.h>
#include <string.h>

#include "sim/sim_internal.h"

static void gather(const plume_vec3 *x, const int *vertices, int count, plume_vec3 *out)
{
	for (int i = 0; i < count; ++i)
		out[i] = vertices[i] >= 0 ? x[vertices[i]] : plume_v3(0, 0, 0);
}

void plume_sim_area_ratios(const plume_sim *sim, const plume_vec3 *x, double *area_ratio)
{
	for (int f = 0; f < sim->face_count; ++f) {
		const plume_membrane_element *element = sim->membranes + f;
		plume_vec3 local[3];
		gather(x, element->vertices, 3, local);
		area_ratio[f] = element->compression > 0 ? plume_compression_area_ratio(element, local) : 1.0;
	}
}

/// secant_J: each face's J for the Kikuuwe term's secant curvature (membrane.h), or NULL
/// for the exact Hessian.
static void evaluate_faces(plume_sim *sim, const plume_vec3 *x, const double *secant_J, bool gradient, bool hessian,
                           bool project)
{
	int count = sim->face_count;
#pragma omp parallel for schedule(static) if (count >= 4096)
	for (int f = 0; f < count; ++f) {
		const plume_membrane_element *element = sim->membranes + f;
		plume_vec3 local[3];
		gather(x, element->vertices, 3, local);
		double *g = gradient ? sim->face_gradient + 9 * f : NULL;
		double *h = hessian ? sim->face_hessian + 81 * f : NULL;
		sim->face_energy[f] = plume_triangle_energy(element, local, secant_J ? secant_J[f] : 1.0, g, h, project);
	}
}

int plume_sim_bending_count(const plume_sim *sim)
{
	return sim->def.bending_model == PLUME_BENDING_PAPER_HINGE ? sim->hinge_count : sim->ff_count;
}

int plume_sim_bending_size(const plume_sim *sim) { return sim->def.bending_model == PLUME_BENDING_PAPER_HINGE ? 4 : 6; }

int plume_sim_bending_stride(const plume_sim *sim)
{
	return sim->def.bending_model == PLUME_BENDING_PAPER_HINGE ? (int)sizeof(plume_hinge) : (int)sizeof(plume_ff_face);
}

const int *plume_sim_bending_vertices(const plume_sim *sim, int e)
{
	return sim->def.bending_model == PLUME_BENDING_PAPER_HINGE ? sim->hinges[e].vertices : sim->ff_faces[e].vertices;
}

double plume_sim_bending_energy(const plume_sim *sim, const plume_vec3 *x, int e)
{
	plume_vec3 local[6];
	gather(x, plume_sim_bending_vertices(sim, e), plume_sim_bending_size(sim), local);
	return sim->def.bending_model == PLUME_BENDING_PAPER_HINGE
	           ? plume_hinge_energy(sim->hinges + e, local, NULL, NULL)
	           : plume_ff_face_energy(sim->ff_faces + e, local, NULL, NULL);
}

static void evaluate_hinges(plume_sim *sim, const plume_vec3 *x, bool gradient, bool hessian, bool project)
{
	int count = sim->hinge_count;
#pragma omp parallel for schedule(static) if (count >= 4096)
	for (int e = 0; e < count; ++e) {
		const plume_hinge *hinge = sim->hinges + e;
		plume_vec3 local[4];
		gather(x, hinge->vertices, 4, local);
		double *g = gradient ? sim->hinge_gradient + 12 * e : NULL;
		double *h = hessian ? sim->hinge_hessian + 144 * e : NULL;
		if (h == NULL || !project) {
			sim->hinge_energy[e] = plume_hinge_energy(hinge, local, g, h);
			continue;
		}
		// The positive semidefinite part of E = k (s chi - eta0)^2 is its Gauss–Newton
		// term 2 k s^2 grad chi grad chi^T; the rest, 2 k s (s chi - eta0) Hess chi, is the
		// indefinite part a projection would clamp anyway. This is far cheaper than an
		// eigen-decomposition of the 12 x 12 block, and exact at the rest angle.
		sim->hinge_energy[e] = plume_hinge_energy(hinge, local, g, NULL);
		double chi_gradient[12];
		plume_dihedral_angle_derivatives(local, chi_gradient, NULL);
		double k = 2 * hinge->stiffness * hinge->scale * hinge->scale;
		for (int a = 0; a < 12; ++a)
			for (int b = 0; b < 12; ++b)
				h[12 * a + b] = k * chi_gradient[a] * chi_gradient[b];
	}
}

static void evaluate_ff_faces(plume_sim *sim, const plume_vec3 *x, bool gradient, bool hessian, bool project)
{
	// Each shared edge's angle and derivatives once (fundamental_form.h, Shared edges): the
	// exact Hessian needs its angle's Hessian, the projected one (Gauss-Newton J^T M J,
	// for the reason given for the hinges) only gradients.
	bool derivatives = gradient || hessian, angle_hessians = hessian && !project;
	int edges = sim->ff_edge_count;
#pragma omp parallel for schedule(static) if (edges >= 4096)
	for (int e = 0; e < edges; ++e) {
		plume_vec3 local[4];
		gather(x, sim->ff_edge_vertices + 4 * e, 4, local);
		sim->ff_edge_chi[e] =
		    plume_dihedral_angle_derivatives(local, derivatives ? sim->ff_edge_gradient + 12 * (size_t)e : NULL,
		                                     angle_hessians ? sim->ff_edge_hessian + 144 * (size_t)e : NULL);
	}
	int count = sim->ff_count;
#pragma omp parallel for schedule(static) if (count >= 4096)
	for (int e = 0; e < count; ++e) {
		double *g = gradient ? sim->hinge_gradient + 18 * e : NULL;
		double *h = hessian ? sim->hinge_hessian + 324 * e : NULL;
		sim->hinge_energy[e] = plume_ff_face_energy_from_edges(
		    sim->ff_faces + e, sim->ff_edge_chi, sim->ff_edge_gradient, g, h, sim->ff_face_weight + 3 * e);
	}
}

/// Every vertex of the element present and none of its unknowns held.
static bool all_free(const plume_sim *sim, const int *vertices, int count)
{
	for (int k = 0; k < count; ++k) {
		if (vertices[k] < 0)
			return false;
		const unsigned char *fixed = sim->fixed + 3 * vertices[k];
		if (fixed[0] || fixed[1] || fixed[2])
			return false;
	}
	return true;
}

void plume_sim_scatter_block(const plume_sim *sim, double *values, const int *vertices, int count, const int *slots,
                             double scale, const double *block)
{
	int n = 3 * count;
	if (all_free(sim, vertices, count)) {
		// Most elements: no test per entry (the tests below were most of the scatter's time).
		for (int a = 0; a < n; ++a)
			for (int b = a; b < n; ++b)
				values[*slots++] += scale * block[a * n + b];
		return;
	}
	for (int a = 0; a < n; slots += n - a, ++a) {
		if (vertices[a / 3] < 0 || sim->fixed[3 * vertices[a / 3] + a % 3])
			continue;
		for (int b = a; b < n; ++b) {
			int slot = slots[b - a]; // -1 for absent vertices
			if (slot >= 0 && !sim->fixed[3 * vertices[b / 3] + b % 3])
				values[slot] += scale * block[a * n + b];
		}
	}
}

/// The exact fundamental-form Hessian's angle curvature: each shared edge's angle Hessian
/// once, times the sum of its two faces' weights (fundamental_form.h, Shared edges),
/// summed in face order so that the bits do not depend on the thread count.
static void scatter_angle_curvature(plume_sim *sim, double *values)
{
	double *weight = sim->ff_edge_weight;
	memset(weight, 0, sizeof(double) * (size_t)sim->ff_edge_count);
	for (int f = 0; f < sim->ff_count; ++f)
		for (int i = 0; i < 3; ++i)
			if (sim->ff_faces[f].edge[i] >= 0)
				weight[sim->ff_faces[f].edge[i]] += sim->ff_face_weight[3 * f + i];
	for (int e = 0; e < sim->ff_edge_count; ++e)
		if (weight[e] != 0)
			plume_sim_scatter_block(sim, values, sim->ff_edge_vertices + 4 * e, 4, sim->kkt.edge_slots + 78 * (size_t)e,
			                        weight[e], sim->ff_edge_hessian + 144 * (size_t)e);
}

static void scatter_gradient(double *gradient, const int *vertices, int count, const double *local)
{
	for (int a = 0; a < 3 * count; ++a)
		if (vertices[a / 3] >= 0)
			gradient[3 * vertices[a / 3] + a % 3] += local[a];
}

double plume_sim_potential(plume_sim *sim, const sim_problem *problem, const plume_vec3 *x, double *gradient,
                           bool hessian, bool project)
{
	int n = sim->vertex_count;
	bool want_gradient = gradient != NULL;
	evaluate_faces(sim, x, problem->start_area_ratio, want_gradient, hessian, project);
	if (sim->def.bending && sim->def.bending_model == PLUME_BENDING_PAPER_HINGE)
		evaluate_hinges(sim, x, want_gradient, hessian, project);
	else if (sim->def.bending)
		evaluate_ff_faces(sim, x, want_gradient, hessian, project);
	if (problem->dynamic && sim->air.active)
		plume_air_add(sim, problem, x, want_gradient, hessian);
	// Contact first: it may rebuild the matrix's pattern (contact.c).
	bool contact = plume_contact_on(sim);
	double contact_energy = contact ? plume_contact_evaluate(sim, x, want_gradient, hessian, problem->dynamic) : 0;
	if (!isfinite(contact_energy))
		return NAN; // out of memory, or a pair in contact: outside the barrier's domain

	double *values = hessian ? plume_kkt_values(&sim->kkt) : NULL;
	if (hessian)
		plume_kkt_zero(&sim->kkt);
	if (want_gradient)
		memset(gradient, 0, sizeof(double) * 3 * (size_t)n);

	double energy = 0;
	for (int f = 0; f < sim->face_count; ++f) {
		energy += sim->face_energy[f];
		const int *vertices = sim->membranes[f].vertices;
		if (want_gradient)
			scatter_gradient(gradient, vertices, 3, sim->face_gradient + 9 * f);
		if (hessian)
			plume_sim_scatter_block(sim, values, vertices, 3, sim->kkt.face_slots + 45 * f, 1,
			                        sim->face_hessian + 81 * f);
	}
	int size = plume_sim_bending_size(sim), dofs = 3 * size, upper = plume_kkt_upper_size(size);
	for (int e = 0; sim->def.bending && e < plume_sim_bending_count(sim); ++e) {
		energy += sim->hinge_energy[e];
		const int *vertices = plume_sim_bending_vertices(sim, e);
		size_t block = (size_t)dofs * (size_t)dofs * (size_t)e;
		if (want_gradient)
			scatter_gradient(gradient, vertices, size, sim->hinge_gradient + (size_t)dofs * e);
		if (hessian)
			plume_sim_scatter_block(sim, values, vertices, size, sim->kkt.bending_slots + (size_t)upper * e, 1,
			                        sim->hinge_hessian + block);
	}
	if (hessian && !project && sim->def.bending && sim->def.bending_model != PLUME_BENDING_PAPER_HINGE)
		scatter_angle_curvature(sim, values);

	plume_vec3 g = sim->def.gravity;
	double inertia = problem->dynamic ? problem->inertia : 0;
	for (int i = 0; i < n; ++i) {
		double m = sim->mass[i];
		plume_vec3 load = sim->load[i];
		energy -= m * plume_v3_dot(g, x[i]) + plume_v3_dot(load, x[i]);
		double local_gradient[3] = {-m * g.x - load.x, -m * g.y - load.y, -m * g.z - load.z};
		double block[9] = {0};
		if (problem->dynamic) {
			plume_vec3 d = plume_v3_sub(x[i], problem->predicted[i]);
			energy += 0.5 * m * inertia * plume_v3_dot(d, d);
			local_gradient[0] += m * inertia * d.x;
			local_gradient[1] += m * inertia * d.y;
			local_gradient[2] += m * inertia * d.z;
			block[0] = block[4] = block[8] = m * inertia;
			double c = sim->def.drag * sim->vertex_area[i];
			if (c > 0) {
				// R(v) / s with v . n = s (x - base) . n: (1/2) c (v . n)^2 / s.
				double s = problem->velocity_scale;
				plume_vec3 normal = problem->drag_normals[i];
				double along = s * plume_v3_dot(plume_v3_sub(x[i], problem->velocity_base[i]), normal);
				energy += 0.5 * c * along * along / s;
				const double nv[3] = {normal.x, normal.y, normal.z};
				for (int a = 0; a < 3; ++a) {
					local_gradient[a] += c * along * nv[a];
					for (int b = 0; b < 3; ++b)
						block[3 * a + b] += c * s * nv[a] * nv[b];
				}
			}
		}
		if (want_gradient)
			for (int a = 0; a < 3; ++a)
				gradient[3 * i + a] += local_gradient[a];
		if (hessian)
			plume_sim_scatter_block(sim, values, &i, 1, sim->kkt.vertex_slots + 6 * i, 1, block);
	}

	if (contact && plume_contact_any(sim)) {
		// The IPC barrier over the pairs in reach (Li et al. 2020, eq. 6), Hessian projected,
		// and the lagged friction of a dynamic step.
		energy += contact_energy;
		plume_contact_scatter(sim, gradient, values);
	}
	if (hessian)
		for (int i = 0; i < 3 * n; ++i)
			if (sim->fixed[i])
				values[sim->kkt.system.diagonal[i]] = 1;
	return isfinite(energy) ? energy : NAN;
}

double plume_sim_max_barb_strain(const plume_sim *sim, const plume_vec3 *x)
{
	double worst = 0;
	for (int e = 0; e < sim->barb_edge_count; ++e) {
		double length = plume_v3_distance(x[sim->barb_edges[2 * e]], x[sim->barb_edges[2 * e + 1]]);
		double strain = fabs(length - sim->barb_length[e]) / sim->barb_length[e];
		if (strain > worst)
			worst = strain;
	}
	return worst;
}

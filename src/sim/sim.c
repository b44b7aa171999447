// The simulation object: definitions, set-up from a mesh, handles, statics and
// dynamic steps (integrator.c) with substep retries, and measurements.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "sim/sim_internal.h"

plume_sim_def plume_sim_default_def(void)
{
	plume_sim_def def;
	memset(&def, 0, sizeof def);
	def.materials[PLUME_MATERIAL_VANE] = plume_material_vane();
	def.materials[PLUME_MATERIAL_RACHIS] = plume_material_rachis();
	def.material_count = 2;
	def.gravity = plume_v3(0, -9.81, 0);
	def.drag = 0;
	def.air.density = 0;
	def.air.normal_drag = 1.17;
	def.air.tangential_drag = 0.07;
	def.air.centre_of_pressure = true;
	def.air.gust_length = 0.1;
	def.air.gust_time = 0.5;
	def.time_step = 0.011;
	def.integrator = PLUME_INTEGRATOR_BDF2;
	def.bending = true;
	def.bending_model = PLUME_BENDING_FUNDAMENTAL_FORM;
	def.planar = false;
	def.solver.tolerance = 1e-7;
	def.solver.max_iterations = 50;
	def.solver.max_substep_halvings = 4;
	def.contact.enabled = false;
	def.contact.distance = 1.2e-4;
	def.contact.stiffness = 1e6;
	def.contact.adaptive_stiffness = true;
	def.contact.self_contact = true;
	def.contact.ccd_separation = 0.1;
	def.contact.friction = 0;
	def.cookie = PLUME_DEF_COOKIE;
	return def;
}

static const char *material_path(int index, char *buffer, size_t size)
{
	if (index == PLUME_MATERIAL_VANE)
		return "$.materials.vane";
	if (index == PLUME_MATERIAL_RACHIS)
		return "$.materials.rachis";
	snprintf(buffer, size, "$.materials[%d]", index);
	return buffer;
}

static plume_status check_material(const plume_material *material, const char *path, plume_error *err)
{
#define REQUIRE(condition, field, allowed)                                                                             \
	if (!(condition))                                                                                                  \
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s.%s is %g, allowed " allowed, path, #field,                   \
		                       (double)material->field);
	// Floors and ceilings, not just > 0: a 1e-300 m shell or step makes the stiffness or the
	// inertia term (mass / h^2) underflow or overflow, and Newton then works on NaN.
	REQUIRE(material->thickness >= 1e-9 && material->thickness <= 1.0, thickness, "[1e-09, 1] m");
	REQUIRE(material->surface_density >= 0 && isfinite(material->surface_density), surface_density, ">= 0");
	REQUIRE(material->bending_along >= 0 && isfinite(material->bending_along), bending_along, ">= 0");
	REQUIRE(isfinite(material->bending_across), bending_across, "finite");
	REQUIRE(material->compression_coefficient >= 0 && isfinite(material->compression_coefficient),
	        compression_coefficient, ">= 0");
	if (material->kind == PLUME_MATERIAL_ORTHOTROPIC) {
		REQUIRE(material->bending_across >= 0, bending_across, ">= 0");
		REQUIRE(material->E_ww > 0 && isfinite(material->E_ww), E_ww, "> 0");
		REQUIRE(material->E_vw > 0 && isfinite(material->E_vw), E_vw, "> 0");
		REQUIRE(material->barb_constraint || (material->E_vv > 0 && isfinite(material->E_vv)), E_vv,
		        "> 0 (or barb_constraint true)");
	} else if (material->kind == PLUME_MATERIAL_ISOTROPIC) {
		REQUIRE(material->youngs_modulus > 0 && isfinite(material->youngs_modulus), youngs_modulus, "> 0");
		REQUIRE(material->poisson_ratio >= 0 && material->poisson_ratio < 0.5, poisson_ratio, "[0, 0.5)");
	} else {
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s.kind is %d, allowed orthotropic or isotropic", path,
		                       (int)material->kind);
	}
#undef REQUIRE
	return PLUME_OK;
}

static plume_status check_contact(const plume_contact_def *contact, plume_error *err)
{
	// Ceilings keep the barrier's energy (stiffness d-hat^4 scale) and its Hessian finite.
	if (!(contact->distance >= 1e-9 && contact->distance <= 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.contact.distance is %g, allowed [1e-09, 1] m",
		                       contact->distance);
	if (!(contact->stiffness > 0 && contact->stiffness <= 1e30))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.contact.stiffness is %g, allowed (0, 1e30]",
		                       contact->stiffness);
	if (!(contact->ccd_separation > 0 && contact->ccd_separation < 1))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.contact.ccd_separation is %g, allowed (0, 1)",
		                       contact->ccd_separation);
	if (!(contact->friction >= 0 && contact->friction <= 1e3))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.contact.friction is %g, allowed [0, 1000]", contact->friction);
	return PLUME_OK;
}

plume_status plume_sim_def_validate(const plume_sim_def *def, int mesh_material_count, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	plume_status status = PLUME_OK;
	if (def->material_count < 1 || def->material_count > PLUME_MAX_MATERIALS)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.materials: %d materials, allowed 1 to %d", def->material_count,
		                       PLUME_MAX_MATERIALS);
	if (mesh_material_count > def->material_count)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.materials: the mesh uses %d materials but only %d are defined",
		                       mesh_material_count, def->material_count);
	char buffer[32];
	for (int i = 0; i < def->material_count; ++i) {
		status = check_material(def->materials + i, material_path(i, buffer, sizeof buffer), err);
		if (status != PLUME_OK)
			return status;
	}
	if (!(def->time_step >= 1e-9 && def->time_step <= 100.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.time_step is %g, allowed [1e-09, 100] s", def->time_step);
	if (def->bending_model != PLUME_BENDING_FUNDAMENTAL_FORM && def->bending_model != PLUME_BENDING_PAPER_HINGE)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.bending is model %d, allowed fundamental-form or paper-hinge",
		                       (int)def->bending_model);
	if (!(def->drag >= 0) || !isfinite(def->drag))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.drag is %g, allowed >= 0", def->drag);
	if (def->integrator != PLUME_INTEGRATOR_IMPLICIT_EULER && def->integrator != PLUME_INTEGRATOR_BDF2)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.integrator is %d, allowed implicit-euler or bdf2",
		                       (int)def->integrator);
	status = plume_air_def_validate(&def->air, err);
	if (status != PLUME_OK)
		return status;
	if (!isfinite(def->gravity.x) || !isfinite(def->gravity.y) || !isfinite(def->gravity.z))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.gravity must be finite");
	if (!(def->solver.tolerance > 0) || !(def->solver.tolerance < 1))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.solver.tolerance is %g, allowed (0, 1)",
		                       def->solver.tolerance);
	if (def->solver.max_iterations < 1 || def->solver.max_iterations > 100000)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.solver.max_iterations is %d, allowed [1, 100000]",
		                       def->solver.max_iterations);
	if (def->solver.max_substep_halvings < 0 || def->solver.max_substep_halvings > 12)
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.solver.max_substep_halvings is %d, allowed [0, 12]",
		                       def->solver.max_substep_halvings);
	return check_contact(&def->contact, err);
}

// ---------------------------------------------------------------------------
// Set-up

typedef struct half_edge {
	int low, high;
	int face;
	int local; ///< edge k of the face: (faces[3f+k], faces[3f+(k+1)%3])
} half_edge;

static int compare_half_edges(const void *a, const void *b)
{
	const half_edge *p = a, *q = b;
	if (p->low != q->low)
		return p->low < q->low ? -1 : 1;
	if (p->high != q->high)
		return p->high < q->high ? -1 : 1;
	return (p->face > q->face) - (p->face < q->face);
}

static int compare_pairs(const void *a, const void *b)
{
	const int *p = a, *q = b;
	if (p[0] != q[0])
		return p[0] < q[0] ? -1 : 1;
	return (p[1] > q[1]) - (p[1] < q[1]);
}

/// Sorted unique edges (low, high) of the faces' barb-edge marks that pass the filter.
static int collect_barb_edges(const plume_mesh *mesh, const plume_sim_def *def, bool constrained_only, int **out)
{
	int *pairs = plume_alloc(sizeof(int) * 2 * (size_t)(mesh->face_count > 0 ? mesh->face_count : 1));
	if (pairs == NULL)
		return -1;
	int count = 0;
	for (int f = 0; f < mesh->face_count; ++f) {
		int k = mesh->barb_edge[f];
		if (k < 0)
			continue;
		const plume_material *material = def->materials + mesh->material[f];
		if (constrained_only && !(material->kind == PLUME_MATERIAL_ORTHOTROPIC && material->barb_constraint))
			continue;
		int a = mesh->faces[3 * f + k], b = mesh->faces[3 * f + (k + 1) % 3];
		pairs[2 * count] = a < b ? a : b;
		pairs[2 * count + 1] = a < b ? b : a;
		++count;
	}
	qsort(pairs, (size_t)count, 2 * sizeof(int), compare_pairs);
	int unique = 0;
	for (int e = 0; e < count; ++e)
		if (unique == 0 || compare_pairs(pairs + 2 * (unique - 1), pairs + 2 * e) != 0) {
			pairs[2 * unique] = pairs[2 * e];
			pairs[2 * unique + 1] = pairs[2 * e + 1];
			++unique;
		}
	*out = pairs;
	return unique;
}

static void face_voigt(const plume_material *material, double barb_angle, double voigt[9])
{
	if (material->kind == PLUME_MATERIAL_ISOTROPIC) {
		plume_isotropic_tensor(material->youngs_modulus, material->poisson_ratio, voigt);
		return;
	}
	// With the constraint, E_vv is no stiffness any more (paper footnote 3: set to E_ww).
	double along = material->barb_constraint ? material->E_ww : material->E_vv;
	plume_orthotropic_tensor(along, material->E_ww, material->E_vw, barb_angle, voigt);
}

static void bending_moduli(const plume_material *material, double *along, double *across)
{
	*along = material->bending_along;
	*across = material->bending_across >= 0 ? material->bending_across : material->bending_along;
}

static double harmonic_mean(double a, double b) { return a + b > 0 ? 2 * a * b / (a + b) : 0; }

// The plain two-face edges (non-manifold fans left out: only they bend), in the order of
// their sorted vertex pair: pairs of face edges 3 f + k, edge k of face f being
// (faces[3f+k], faces[3f+(k+1)%3]). Returns the number of pairs, -1 when out of memory.
static int pair_face_edges(const plume_mesh *mesh, int **out)
{
	int count = 3 * mesh->face_count;
	half_edge *edges = plume_alloc(sizeof(half_edge) * (size_t)(count > 0 ? count : 1));
	int *pairs = plume_alloc(sizeof(int) * (size_t)(count > 0 ? count : 1));
	if (edges == NULL || pairs == NULL) {
		plume_free(edges);
		plume_free(pairs);
		return -1;
	}
	for (int f = 0; f < mesh->face_count; ++f)
		for (int k = 0; k < 3; ++k) {
			int a = mesh->faces[3 * f + k], b = mesh->faces[3 * f + (k + 1) % 3];
			edges[3 * f + k] = (half_edge){a < b ? a : b, a < b ? b : a, f, k};
		}
	qsort(edges, (size_t)count, sizeof *edges, compare_half_edges);
	int pair_count = 0;
	for (int e = 0; e + 1 < count; ++e) {
		const half_edge *p = edges + e, *q = edges + e + 1;
		if (p->low != q->low || p->high != q->high)
			continue;
		if ((e + 2 < count && edges[e + 2].low == p->low && edges[e + 2].high == p->high) ||
		    (e > 0 && edges[e - 1].low == p->low && edges[e - 1].high == p->high))
			continue;
		pairs[2 * pair_count] = 3 * p->face + p->local;
		pairs[2 * pair_count + 1] = 3 * q->face + q->local;
		++pair_count;
		++e;
	}
	plume_free(edges);
	*out = pairs;
	return pair_count;
}

/// True when two rest lengths, one measured in the reference plane and one in the 3D rest
/// shape, are the same up to rounding: the rest shape there is the reference moved rigidly.
static bool same_length(double plane, double rest) { return fabs(rest - plane) <= 1e-12 * plane; }

/// The distance of vertices a and b in the reference plane.
static double plane_length(const plume_mesh *mesh, int a, int b)
{
	plume_vec2 p = mesh->reference[a], q = mesh->reference[b];
	return hypot(q.x - p.x, q.y - p.y);
}

/// The distance of vertices a and b in the 3D rest shape.
static double shape_length(const plume_mesh *mesh, int a, int b)
{
	return plume_v3_length(plume_v3_sub(mesh->rest[b], mesh->rest[a]));
}

/// A material length between two vertices: the 3D rest shape's (a curved feather is at rest
/// in its curved shape), or the reference plane's where they are the same up to rounding,
/// so that a flat feather's lengths are the reference's bit for bit.
static double rest_length(const plume_mesh *mesh, int a, int b)
{
	double plane = plane_length(mesh, a, b), rest = shape_length(mesh, a, b);
	return same_length(plane, rest) ? plane : rest;
}

/// The face's rest triangle laid flat in the feather plane: its side lengths are those of
/// the 3D rest shape, and it lies on the reference triangle along the face's barb edge
/// (edge 0 of a rachis face), turned as the reference is, so that the barb angle holds.
/// A Streit-Heidrich or Zhang-Kanai feather is at rest in its curved shape; measured in
/// the plane, its membrane started strained (a held Streit-Heidrich semiplume, with no
/// gravity, fell to a principal stretch of 0.88 in one step). Where the rest triangle is
/// the reference moved rigidly (every Franco-Walter feather) it is the reference exactly.
static void rest_triangle(const plume_mesh *mesh, int f, plume_vec2 out[3])
{
	const int *v = mesh->faces + 3 * f;
	bool flat = true;
	for (int k = 0; k < 3; ++k) {
		out[k] = mesh->reference[v[k]];
		int next = v[(k + 1) % 3];
		flat &= same_length(plane_length(mesh, v[k], next), shape_length(mesh, v[k], next));
	}
	plume_vec2 r0 = out[0], r1 = out[1], r2 = out[2];
	double twice_area = (r1.x - r0.x) * (r2.y - r0.y) - (r2.x - r0.x) * (r1.y - r0.y);
	if (flat || !(twice_area != 0)) // a degenerate reference: the element's check reports it
		return;
	int k = mesh->barb_edge[f] >= 0 ? mesh->barb_edge[f] : 0;
	int a = v[k], b = v[(k + 1) % 3], c = v[(k + 2) % 3];
	plume_vec3 ab = plume_v3_sub(mesh->rest[b], mesh->rest[a]), ac = plume_v3_sub(mesh->rest[c], mesh->rest[a]);
	double length = plume_v3_length(ab);
	plume_vec3 u = plume_v3_scale(ab, 1 / length);
	double along = plume_v3_dot(ac, u);
	double across = plume_v3_length(plume_v3_sub(ac, plume_v3_scale(u, along)));
	plume_vec2 p = mesh->reference[a], q = mesh->reference[b], r = mesh->reference[c];
	double dx = q.x - p.x, dy = q.y - p.y, plane = hypot(dx, dy);
	plume_vec2 d = {dx / plane, dy / plane}, n = {-d.y, d.x};
	double side = dx * (r.y - p.y) - dy * (r.x - p.x) >= 0 ? 1 : -1; // keeps the reference's orientation
	out[k] = p;
	out[(k + 1) % 3] = (plume_vec2){p.x + length * d.x, p.y + length * d.y};
	out[(k + 2) % 3] = (plume_vec2){p.x + along * d.x + side * across * n.x, p.y + along * d.y + side * across * n.y};
}

// The paper's hinges (sim/bending.h): one per plain two-face edge.
static plume_status build_hinges(plume_sim *sim, const plume_mesh *mesh, const int *pairs, int pair_count,
                                 plume_error *err)
{
	sim->hinges = plume_alloc(sizeof(plume_hinge) * (size_t)(pair_count > 0 ? pair_count : 1));
	if (sim->hinges == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building hinges");
	for (int e = 0; e < pair_count; ++e) {
		int pf = pairs[2 * e] / 3, pk = pairs[2 * e] % 3, qf = pairs[2 * e + 1] / 3, qk = pairs[2 * e + 1] % 3;
		const int *fa = mesh->faces + 3 * pf, *fb = mesh->faces + 3 * qf;
		int vertices[4] = {fa[pk], fa[(pk + 1) % 3], fa[(pk + 2) % 3], fb[(qk + 2) % 3]};
		plume_vec2 reference[4];
		plume_vec3 rest[4];
		for (int i = 0; i < 4; ++i) {
			reference[i] = mesh->reference[vertices[i]];
			rest[i] = mesh->rest[vertices[i]];
		}
		double along_a, across_a, along_b, across_b;
		bending_moduli(sim->def.materials + mesh->material[pf], &along_a, &across_a);
		bending_moduli(sim->def.materials + mesh->material[qf], &along_b, &across_b);
		// A hinge between two materials (the rachis border) bends where the softer side
		// bends: the harmonic mean, about twice the softer modulus when they differ a lot.
		if (plume_hinge_init(sim->hinges + sim->hinge_count, vertices, reference, rest, mesh->barb_angle[pf],
		                     mesh->barb_angle[qf], harmonic_mean(along_a, along_b), harmonic_mean(across_a, across_b)))
			++sim->hinge_count;
	}
	return PLUME_OK;
}

// The fundamental-form elements (sim/fundamental_form.h): one per face, each with its
// own material's moduli and barb direction (no averaging across a material border).
static plume_status build_ff_faces(plume_sim *sim, const plume_mesh *mesh, const int *pairs, int pair_count,
                                   plume_error *err)
{
	int faces = mesh->face_count;
	int *across = plume_alloc(sizeof(int) * 3 * (size_t)faces);
	sim->ff_faces = plume_alloc(sizeof(plume_ff_face) * (size_t)faces);
	if (across == NULL || sim->ff_faces == NULL) {
		plume_free(across);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building the bending elements");
	}
	for (int i = 0; i < 3 * faces; ++i)
		across[i] = -1;
	for (int e = 0; e < pair_count; ++e) {
		int p = pairs[2 * e], q = pairs[2 * e + 1];
		across[p] = mesh->faces[3 * (q / 3) + (q % 3 + 2) % 3];
		across[q] = mesh->faces[3 * (p / 3) + (p % 3 + 2) % 3];
	}
	for (int f = 0; f < faces; ++f) {
		const int *v = mesh->faces + 3 * f;
		// Edge k of the face is opposite vertex (k + 2) % 3.
		int vertices[6] = {v[0], v[1], v[2], across[3 * f + 1], across[3 * f + 2], across[3 * f]};
		plume_vec2 reference[3];
		rest_triangle(mesh, f, reference);
		plume_vec3 rest[6];
		for (int i = 0; i < 6; ++i)
			rest[i] = vertices[i] >= 0 ? mesh->rest[vertices[i]] : plume_v3(0, 0, 0);
		double along, across_modulus;
		bending_moduli(sim->def.materials + mesh->material[f], &along, &across_modulus);
		if (!plume_ff_face_init(sim->ff_faces + f, vertices, reference, rest, mesh->barb_angle[f], along,
		                        across_modulus)) {
			plume_free(across);
			return plume_error_set(err, PLUME_ERROR_NUMERIC, "mesh face %d is degenerate in the reference plane", f);
		}
	}
	sim->ff_count = faces;
	// Each interior edge once, in its first side's hinge order; both sides linked to it.
	sim->ff_edge_count = pair_count;
	size_t edges = (size_t)(pair_count > 0 ? pair_count : 1);
	sim->ff_edge_vertices = plume_alloc(sizeof(int) * 4 * edges);
	sim->ff_edge_chi = plume_alloc(sizeof(double) * edges);
	sim->ff_edge_gradient = plume_alloc(sizeof(double) * 12 * edges);
	sim->ff_edge_hessian = plume_alloc(sizeof(double) * 144 * edges);
	sim->ff_face_weight = plume_alloc(sizeof(double) * 3 * (size_t)(faces > 0 ? faces : 1));
	sim->ff_edge_weight = plume_alloc(sizeof(double) * edges);
	if (!sim->ff_edge_vertices || !sim->ff_edge_chi || !sim->ff_edge_gradient || !sim->ff_edge_hessian ||
	    !sim->ff_face_weight || !sim->ff_edge_weight) {
		plume_free(across);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building the bending elements");
	}
	for (int e = 0; e < pair_count; ++e) {
		int *stencil = sim->ff_edge_vertices + 4 * e;
		int side[2] = {pairs[2 * e], pairs[2 * e + 1]};
		plume_ff_hinge_vertices(sim->ff_faces + side[0] / 3, (side[0] % 3 + 2) % 3, stencil);
		for (int k = 0; k < 2; ++k)
			plume_ff_face_link(sim->ff_faces + side[k] / 3, (side[k] % 3 + 2) % 3, e, stencil);
	}
	// Material borders (fundamental_form.h): each face's share of the edge's angle.
	for (int e = 0; e < pair_count; ++e) {
		int side[2] = {pairs[2 * e], pairs[2 * e + 1]};
		if (mesh->material[side[0] / 3] == mesh->material[side[1] / 3])
			continue;
		double modulus[2];
		for (int k = 0; k < 2; ++k) {
			int f = side[k] / 3;
			plume_vec2 reference[3];
			rest_triangle(mesh, f, reference);
			double along, across_modulus;
			bending_moduli(sim->def.materials + mesh->material[f], &along, &across_modulus);
			modulus[k] =
			    plume_ff_edge_modulus(reference, (side[k] % 3 + 2) % 3, mesh->barb_angle[f], along, across_modulus);
		}
		for (int k = 0; k < 2; ++k)
			plume_ff_face_border(sim->ff_faces + side[k] / 3, (side[k] % 3 + 2) % 3, modulus[k], modulus[1 - k]);
	}
	plume_free(across);
	return PLUME_OK;
}

static plume_status build_bending(plume_sim *sim, const plume_mesh *mesh, plume_error *err)
{
	int *pairs = NULL;
	int pair_count = pair_face_edges(mesh, &pairs);
	if (pair_count < 0)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building the bending elements");
	plume_status status = sim->def.bending_model == PLUME_BENDING_PAPER_HINGE
	                          ? build_hinges(sim, mesh, pairs, pair_count, err)
	                          : build_ff_faces(sim, mesh, pairs, pair_count, err);
	plume_free(pairs);
	return status;
}

static plume_status build_elements(plume_sim *sim, const plume_mesh *mesh, plume_error *err)
{
	int faces = mesh->face_count;
	sim->membranes = plume_alloc(sizeof(plume_membrane_element) * (size_t)faces);
	if (sim->membranes == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building elements");
	for (int f = 0; f < faces; ++f) {
		const plume_material *material = sim->def.materials + mesh->material[f];
		const int *vertices = mesh->faces + 3 * f;
		plume_vec2 reference[3];
		rest_triangle(mesh, f, reference);
		double voigt[9];
		face_voigt(material, mesh->barb_angle[f], voigt);
		if (!plume_membrane_element_init(sim->membranes + f, vertices, reference, material->thickness, voigt,
		                                 material->compression_coefficient))
			return plume_error_set(err, PLUME_ERROR_NUMERIC, "mesh face %d is degenerate in the reference plane", f);
		double share = material->surface_density * sim->membranes[f].area / 3;
		for (int i = 0; i < 3; ++i) {
			sim->mass[vertices[i]] += share;
			sim->vertex_area[vertices[i]] += sim->membranes[f].area / 3;
		}
	}
	return build_bending(sim, mesh, err);
}

static plume_status copy_groups(plume_sim *sim, const plume_mesh *mesh, plume_error *err)
{
	sim->groups = plume_calloc((size_t)(mesh->group_count > 0 ? mesh->group_count : 1), sizeof(plume_vertex_group));
	if (sim->groups == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory copying vertex groups");
	for (int g = 0; g < mesh->group_count; ++g) {
		plume_vertex_group *copy = sim->groups + g;
		*copy = mesh->groups[g];
		copy->vertices = plume_alloc(sizeof(int) * (size_t)(copy->count > 0 ? copy->count : 1));
		if (copy->vertices == NULL)
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory copying vertex groups");
		memcpy(copy->vertices, mesh->groups[g].vertices, sizeof(int) * (size_t)copy->count);
		sim->group_count = g + 1;
	}
	return PLUME_OK;
}

static bool allocate_state(plume_sim *sim)
{
	size_t n = (size_t)sim->vertex_count, f = (size_t)(sim->face_count > 0 ? sim->face_count : 1);
	size_t unknowns = 3 * n + (size_t)sim->constraint_count;
	sim->x = plume_alloc(sizeof(plume_vec3) * n);
	sim->v = plume_calloc(n, sizeof(plume_vec3));
	sim->rest = plume_alloc(sizeof(plume_vec3) * n);
	sim->mass = plume_calloc(n, sizeof(double));
	sim->load = plume_calloc(n, sizeof(plume_vec3));
	sim->vertex_area = plume_calloc(n, sizeof(double));
	sim->fixed = plume_calloc(3 * n, 1);
	sim->face_energy = plume_alloc(sizeof(double) * f);
	sim->face_start_area_ratio = plume_alloc(sizeof(double) * f);
	sim->face_gradient = plume_alloc(sizeof(double) * 9 * f);
	sim->face_hessian = plume_alloc(sizeof(double) * 81 * f);
	sim->gradient = plume_alloc(sizeof(double) * unknowns);
	sim->residual = plume_alloc(sizeof(double) * unknowns);
	sim->rhs = plume_alloc(sizeof(double) * unknowns);
	sim->step = plume_alloc(sizeof(double) * unknowns);
	sim->trial = plume_alloc(sizeof(plume_vec3) * n);
	sim->scratch = plume_alloc(sizeof(plume_vec3) * n);
	sim->saved_x = plume_alloc(sizeof(plume_vec3) * n);
	sim->saved_v = plume_alloc(sizeof(plume_vec3) * n);
	sim->previous = plume_alloc(sizeof(plume_vec3) * n);
	sim->predicted = plume_alloc(sizeof(plume_vec3) * n);
	sim->normals = plume_alloc(sizeof(plume_vec3) * n);
	sim->lambda = plume_calloc((size_t)(sim->constraint_count > 0 ? sim->constraint_count : 1), sizeof(double));
	return sim->x && sim->v && sim->rest && sim->mass && sim->load && sim->vertex_area && sim->fixed &&
	       sim->face_energy && sim->face_start_area_ratio && sim->face_gradient && sim->face_hessian && sim->gradient &&
	       sim->residual && sim->rhs && sim->step && sim->trial && sim->scratch && sim->saved_x && sim->saved_v &&
	       sim->previous && sim->predicted && sim->normals && sim->lambda &&
	       plume_integrator_init(&sim->integrator, sim->def.integrator, sim->vertex_count) &&
	       plume_air_init(&sim->air, &sim->def.air, sim->face_count);
}

static bool allocate_hinge_buffers(plume_sim *sim)
{
	int size = plume_sim_bending_size(sim);
	size_t h = (size_t)(plume_sim_bending_count(sim) > 0 ? plume_sim_bending_count(sim) : 1);
	sim->hinge_energy = plume_alloc(sizeof(double) * h);
	sim->hinge_gradient = plume_alloc(sizeof(double) * 3 * (size_t)size * h);
	sim->hinge_hessian = plume_alloc(sizeof(double) * 9 * (size_t)(size * size) * h);
	return sim->hinge_energy && sim->hinge_gradient && sim->hinge_hessian;
}

static double bounding_diagonal(const plume_mesh *mesh)
{
	plume_vec2 lo = mesh->reference[0], hi = mesh->reference[0];
	for (int i = 1; i < mesh->vertex_count; ++i) {
		plume_vec2 p = mesh->reference[i];
		lo.x = fmin(lo.x, p.x), lo.y = fmin(lo.y, p.y);
		hi.x = fmax(hi.x, p.x), hi.y = fmax(hi.y, p.y);
	}
	return hypot(hi.x - lo.x, hi.y - lo.y);
}

plume_status plume_sim_create(const plume_mesh *mesh, const plume_sim_def *def, plume_sim **out, plume_error *err)
{
	PLUME_ASSERT(mesh != NULL && out != NULL);
	PLUME_ASSERT_DEF(def);
	PLUME_ASSERT(mesh->vertex_count >= 0 && mesh->face_count >= 0);
	*out = NULL;
	if (mesh->vertex_count < 3 || mesh->face_count < 1)
		return plume_error_set(err, PLUME_ERROR_SPEC, "the mesh has no faces to simulate");
	int material_count = 0;
	for (int f = 0; f < mesh->face_count; ++f)
		material_count = mesh->material[f] + 1 > material_count ? mesh->material[f] + 1 : material_count;
	plume_status status = plume_sim_def_validate(def, material_count, err);
	if (status != PLUME_OK)
		return status;

	plume_sim *sim = plume_calloc(1, sizeof *sim);
	if (sim == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating the simulation");
	sim->magic = PLUME_HANDLE_MAGIC;
	sim->def = *def;
	sim->vertex_count = mesh->vertex_count;
	sim->face_count = mesh->face_count;
	sim->length_scale = bounding_diagonal(mesh);
	sim->constraint_count = collect_barb_edges(mesh, def, true, &sim->constraint_vertices);
	sim->barb_edge_count = collect_barb_edges(mesh, def, false, &sim->barb_edges);
	if (sim->constraint_count < 0 || sim->barb_edge_count < 0 || !allocate_state(sim)) {
		plume_sim_destroy(sim);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating the simulation");
	}
	sim->constraint_length = plume_alloc(sizeof(double) * (size_t)(sim->constraint_count + 1));
	sim->barb_length = plume_alloc(sizeof(double) * (size_t)(sim->barb_edge_count + 1));
	sim->faces = plume_alloc(sizeof(int) * 3 * (size_t)mesh->face_count);
	sim->face_material = plume_alloc((size_t)mesh->face_count);
	if (!sim->constraint_length || !sim->barb_length || !sim->faces || !sim->face_material ||
	    !plume_sim_held_init(sim)) {
		plume_sim_destroy(sim);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating the simulation");
	}
	memcpy(sim->faces, mesh->faces, sizeof(int) * 3 * (size_t)mesh->face_count);
	memcpy(sim->face_material, mesh->material, (size_t)mesh->face_count);
	for (int i = 0; i < mesh->vertex_count; ++i)
		sim->x[i] = sim->rest[i] = mesh->rest[i];
	// Barb lengths are material lengths: the rest shape's (rest_length).
	for (int k = 0; k < sim->constraint_count; ++k)
		sim->constraint_length[k] =
		    rest_length(mesh, sim->constraint_vertices[2 * k], sim->constraint_vertices[2 * k + 1]);
	for (int k = 0; k < sim->barb_edge_count; ++k)
		sim->barb_length[k] = rest_length(mesh, sim->barb_edges[2 * k], sim->barb_edges[2 * k + 1]);
	if (def->planar)
		for (int i = 0; i < mesh->vertex_count; ++i)
			sim->fixed[3 * i + 2] = 1;

	status = build_elements(sim, mesh, err);
	if (status == PLUME_OK && !allocate_hinge_buffers(sim))
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating the simulation");
	if (status == PLUME_OK)
		status = copy_groups(sim, mesh, err);
	if (status == PLUME_OK && !plume_contact_init(sim))
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating the simulation");
	if (status == PLUME_OK)
		status = plume_kkt_init(&sim->kkt, sim->vertex_count, sim->face_count, sim->faces,
		                        def->bending ? plume_sim_bending_count(sim) : 0, plume_sim_bending_vertices(sim, 0),
		                        plume_sim_bending_stride(sim), plume_sim_bending_size(sim),
		                        def->bending ? sim->ff_edge_count : 0, sim->ff_edge_vertices, sim->constraint_count,
		                        sim->constraint_vertices, err);
	if (status != PLUME_OK) {
		plume_sim_destroy(sim);
		return status;
	}
	*out = sim;
	return PLUME_OK;
}

void plume_sim_destroy(plume_sim *sim)
{
	if (sim == NULL)
		return;
	PLUME_ASSERT_HANDLE(sim);
	sim->magic = 0;
	plume_kkt_free(&sim->kkt);
	plume_integrator_free(&sim->integrator);
	plume_air_free(&sim->air);
	plume_contact_free(&sim->contact);
	plume_sim_held_free(sim);
	void *arrays[] = {sim->x,
	                  sim->v,
	                  sim->rest,
	                  sim->mass,
	                  sim->load,
	                  sim->vertex_area,
	                  sim->faces,
	                  sim->face_material,
	                  sim->membranes,
	                  sim->hinges,
	                  sim->ff_faces,
	                  sim->ff_edge_vertices,
	                  sim->ff_edge_chi,
	                  sim->ff_edge_gradient,
	                  sim->ff_edge_hessian,
	                  sim->ff_face_weight,
	                  sim->ff_edge_weight,
	                  sim->constraint_vertices,
	                  sim->constraint_length,
	                  sim->lambda,
	                  sim->barb_edges,
	                  sim->barb_length,
	                  sim->fixed,
	                  sim->face_energy,
	                  sim->face_start_area_ratio,
	                  sim->face_gradient,
	                  sim->face_hessian,
	                  sim->hinge_energy,
	                  sim->hinge_gradient,
	                  sim->hinge_hessian,
	                  sim->gradient,
	                  sim->residual,
	                  sim->rhs,
	                  sim->step,
	                  sim->trial,
	                  sim->scratch,
	                  sim->saved_x,
	                  sim->saved_v,
	                  sim->previous,
	                  sim->predicted,
	                  sim->normals};
	for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i)
		plume_free(arrays[i]);
	for (int h = 0; h < sim->handle_count; ++h) {
		plume_free(sim->handles[h].vertices);
		plume_free(sim->handles[h].anchor);
		plume_free(sim->handles[h].start);
		plume_free(sim->handles[h].end);
	}
	plume_free(sim->handles);
	for (int g = 0; g < sim->group_count; ++g)
		plume_free(sim->groups[g].vertices);
	plume_free(sim->groups);
	plume_free(sim);
}

// ---------------------------------------------------------------------------
// Handles

const plume_vertex_group *plume_sim_find_group(const plume_sim *sim, const char *name)
{
	for (int g = 0; g < sim->group_count; ++g)
		if (strcmp(sim->groups[g].name, name) == 0)
			return sim->groups + g;
	return NULL;
}

// Fundamental-form faces next to or inside the faces that handles hold (fundamental_form.h).
static void update_clamps(plume_sim *sim)
{
	for (int e = 0; e < sim->ff_count; ++e) {
		plume_ff_face *face = sim->ff_faces + e;
		bool held[6];
		for (int k = 0; k < 6; ++k) {
			int v = face->vertices[k];
			held[k] = v >= 0 && sim->fixed[3 * v] && sim->fixed[3 * v + 1] && sim->fixed[3 * v + 2];
		}
		plume_ff_face_clamp(face, held);
	}
}

int plume_sim_add_handle(plume_sim *sim, const char *group_name, plume_error *err)
{
	PLUME_ASSERT_HANDLE(sim);
	PLUME_ASSERT(group_name != NULL);
	const plume_vertex_group *group = plume_sim_find_group(sim, group_name);
	if (group == NULL) {
		char known[512] = "";
		for (int g = 0; g < sim->group_count; ++g) {
			size_t used = strlen(known);
			snprintf(known + used, sizeof known - used, "%s%s", g > 0 ? ", " : "", sim->groups[g].name);
		}
		plume_error_set(err, PLUME_ERROR_SPEC, "unknown vertex group \"%s\" (the mesh has: %s)", group_name, known);
		return -1;
	}
	if (group->count == 0) {
		plume_error_set(err, PLUME_ERROR_SPEC, "vertex group \"%s\" is empty", group_name);
		return -1;
	}
	if (PLUME_GROW(sim->handles, sim->handle_capacity, sim->handle_count + 1) != 0) {
		plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory adding a handle");
		return -1;
	}
	sim_handle *handle = sim->handles + sim->handle_count;
	size_t n = (size_t)group->count;
	handle->count = group->count;
	handle->vertices = plume_alloc(sizeof(int) * n);
	handle->anchor = plume_alloc(sizeof(plume_vec3) * n);
	handle->start = plume_alloc(sizeof(plume_vec3) * n);
	handle->end = plume_alloc(sizeof(plume_vec3) * n);
	if (!handle->vertices || !handle->anchor || !handle->start || !handle->end) {
		plume_free(handle->vertices);
		plume_free(handle->anchor);
		plume_free(handle->start);
		plume_free(handle->end);
		plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory adding a handle");
		return -1;
	}
	for (int i = 0; i < group->count; ++i) {
		int v = group->vertices[i];
		handle->vertices[i] = v;
		handle->anchor[i] = handle->start[i] = handle->end[i] = sim->x[v];
		sim->fixed[3 * v] = sim->fixed[3 * v + 1] = sim->fixed[3 * v + 2] = 1;
		sim->v[v] = plume_v3(0, 0, 0);
	}
	update_clamps(sim);
	return sim->handle_count++;
}

/// Shares force among the group's vertices: replacing their loads, or adding to them.
static plume_status group_load(plume_sim *sim, const char *group_name, plume_vec3 force, bool add, plume_error *err)
{
	PLUME_ASSERT_HANDLE(sim);
	PLUME_ASSERT(group_name != NULL);
	const plume_vertex_group *group = plume_sim_find_group(sim, group_name);
	if (group == NULL || group->count == 0)
		return plume_error_set(err, PLUME_ERROR_SPEC, "no vertices in group \"%s\" to load", group_name);
	if (!(isfinite(force.x) && isfinite(force.y) && isfinite(force.z)))
		return plume_error_set(err, PLUME_ERROR_SPEC, "the load on group \"%s\" is (%g, %g, %g) N; allowed finite",
		                       group_name, force.x, force.y, force.z);
	plume_vec3 share = plume_v3_scale(force, 1.0 / group->count);
	for (int i = 0; i < group->count; ++i) {
		plume_vec3 *load = sim->load + group->vertices[i];
		*load = add ? plume_v3_add(*load, share) : share;
	}
	return PLUME_OK;
}

plume_status plume_sim_set_group_load(plume_sim *sim, const char *group_name, plume_vec3 force, plume_error *err)
{
	return group_load(sim, group_name, force, false, err);
}

plume_status plume_sim_add_group_load(plume_sim *sim, const char *group_name, plume_vec3 force, plume_error *err)
{
	return group_load(sim, group_name, force, true, err);
}

void plume_sim_set_handle(plume_sim *sim, int index, plume_vec3 translation, plume_mat3 rotation, plume_vec3 pivot)
{
	PLUME_ASSERT_HANDLE(sim);
	PLUME_ASSERT_INDEX(index, sim->handle_count); // an index from plume_sim_add_handle
	PLUME_ASSERT(isfinite(translation.x) && isfinite(translation.y) && isfinite(translation.z));
	PLUME_ASSERT(isfinite(pivot.x) && isfinite(pivot.y) && isfinite(pivot.z));
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c)
			PLUME_ASSERT(isfinite(rotation.m[r][c]));
	sim_handle *handle = sim->handles + index;
	for (int i = 0; i < handle->count; ++i) {
		plume_vec3 arm = plume_m3_apply(rotation, plume_v3_sub(handle->anchor[i], pivot));
		handle->end[i] = plume_v3_add(plume_v3_add(pivot, arm), translation);
	}
}

void plume_sim_place_handles(plume_sim *sim, double s)
{
	PLUME_ASSERT(sim != NULL && s >= 0.0 && s <= 1.0);
	for (int h = 0; h < sim->handle_count; ++h) {
		const sim_handle *handle = sim->handles + h;
		for (int i = 0; i < handle->count; ++i)
			sim->x[handle->vertices[i]] = s == 1 ? handle->end[i] : plume_v3_lerp(handle->start[i], handle->end[i], s);
	}
}

static void finish_handles(plume_sim *sim)
{
	for (int h = 0; h < sim->handle_count; ++h)
		memcpy(sim->handles[h].start, sim->handles[h].end, sizeof(plume_vec3) * (size_t)sim->handles[h].count);
}

// ---------------------------------------------------------------------------
// Solves

static void add_report(plume_solve_report *total, const plume_solve_report *part)
{
	total->newton_iterations += part->newton_iterations;
	total->seconds_assembly += part->seconds_assembly;
	total->seconds_factor += part->seconds_factor;
	total->seconds_solve += part->seconds_solve;
	total->seconds_contact += part->seconds_contact;
	total->gradient_norm = part->gradient_norm;
	total->energy = part->energy;
	total->converged = part->converged;
	total->contact_pairs = part->contact_pairs;
	total->min_distance = fmin(total->min_distance, part->min_distance);
}

/// Contact's continuation rounds a substep may take (contact.h: plume_contact_begin).
enum { MAX_CONTACT_ROUNDS = 64 };

/// One substep's solve from fraction s0 to s1 of the step, sim->x at its start iterate.
/// With contact, the start iterate must be reached without passing through anything; when
/// the prescribed motion cannot be taken at once, it is taken in rounds, each solved.
static plume_status solve_substep(plume_sim *sim, const sim_problem *problem, double s0, double s1,
                                  plume_solve_report *total, plume_error *err)
{
	double reached = 0;
	if (!plume_contact_lag_friction(sim, s0, problem->dynamic ? problem->h : 0))
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory finding friction pairs");
	for (int round = 0; round < MAX_CONTACT_ROUNDS; ++round) {
		double t0 = omp_get_wtime();
		plume_status status = plume_contact_begin(sim, s0, s1, &reached, err);
		total->seconds_contact += omp_get_wtime() - t0;
		if (status != PLUME_OK)
			return status;
		plume_solve_report part = {0};
		status = plume_sim_newton(sim, problem, &part, err);
		add_report(total, &part);
		sim->contact.rounds += round > 0;
		if (status != PLUME_OK || reached >= 1)
			return status;
	}
	return plume_error_set(err, PLUME_ERROR_NUMERIC,
	                       "the prescribed motion (handles, obstacles) needed more than %d contact rounds: subdividing",
	                       MAX_CONTACT_ROUNDS);
}

plume_status plume_sim_solve_static(plume_sim *sim, plume_solve_report *report, plume_error *err)
{
	PLUME_ASSERT_HANDLE(sim);
	plume_solve_report total = {0};
	static const sim_problem statics = {.dynamic = false};
	size_t bytes = sizeof(plume_vec3) * (size_t)sim->vertex_count;
	memcpy(sim->saved_x, sim->x, bytes);
	plume_status status = PLUME_ERROR_NUMERIC;
	// Load stepping: the handles' motion split into 1, 2, 4 ... increments.
	for (int halvings = 0; halvings <= sim->def.solver.max_substep_halvings; ++halvings) {
		int substeps = 1 << halvings;
		sim->retrying = halvings > 0;
		if (halvings > 0)
			memcpy(sim->x, sim->saved_x, bytes);
		total.substeps = substeps;
		total.min_distance = INFINITY;
		for (int s = 1; s <= substeps; ++s) {
			memcpy(sim->previous, sim->x, bytes);
			plume_sim_place_handles(sim, (double)s / substeps);
			status = plume_sim_check_held_barbs(sim, err);
			if (status == PLUME_OK)
				status = solve_substep(sim, &statics, (double)(s - 1) / substeps, (double)s / substeps, &total, err);
			if (status != PLUME_OK)
				break;
		}
		// Substeps help a step that did not converge, not one that ran out of memory:
		// a retry that then succeeded would make the result depend on the allocator.
		if (status != PLUME_ERROR_NUMERIC)
			break;
	}
	sim->retrying = false;
	total.max_barb_strain = plume_sim_max_barb_strain(sim, sim->x);
	if (status == PLUME_OK) {
		finish_handles(sim);
		plume_contact_finish(sim);
	}
	if (report != NULL)
		*report = total;
	return status;
}

static void vertex_normals(const plume_sim *sim, const plume_vec3 *x, plume_vec3 *normals)
{
	memset(normals, 0, sizeof(plume_vec3) * (size_t)sim->vertex_count);
	for (int f = 0; f < sim->face_count; ++f) {
		const int *v = sim->faces + 3 * f;
		plume_vec3 n = plume_v3_cross(plume_v3_sub(x[v[1]], x[v[0]]), plume_v3_sub(x[v[2]], x[v[0]]));
		for (int i = 0; i < 3; ++i)
			normals[v[i]] = plume_v3_add(normals[v[i]], n);
	}
	for (int i = 0; i < sim->vertex_count; ++i)
		normals[i] = plume_v3_normalize(normals[i]);
}

plume_status plume_sim_step(plume_sim *sim, plume_solve_report *report, plume_error *err)
{
	PLUME_ASSERT_HANDLE(sim);
	plume_solve_report total = {0};
	size_t bytes = sizeof(plume_vec3) * (size_t)sim->vertex_count;
	memcpy(sim->saved_x, sim->x, bytes);
	memcpy(sim->saved_v, sim->v, bytes);
	plume_integrator_save(&sim->integrator, sim->vertex_count);
	plume_status status = PLUME_ERROR_NUMERIC;
	plume_error last = {0};
	for (int halvings = 0; halvings <= sim->def.solver.max_substep_halvings; ++halvings) {
		int substeps = 1 << halvings;
		double h = sim->def.time_step / substeps;
		sim->retrying = halvings > 0;
		memcpy(sim->x, sim->saved_x, bytes);
		memcpy(sim->v, sim->saved_v, bytes);
		plume_integrator_restore(&sim->integrator, sim->vertex_count);
		total.substeps = substeps;
		total.min_distance = INFINITY;
		for (int s = 1; s <= substeps; ++s) {
			sim_problem problem;
			plume_integrator_begin(sim, h, &problem);
			if (sim->def.drag > 0)
				vertex_normals(sim, sim->x, sim->normals);
			if (sim->air.active)
				plume_air_begin(sim, sim->time + s * h);
			plume_sim_area_ratios(sim, sim->x, sim->face_start_area_ratio);
			problem.start_area_ratio = sim->face_start_area_ratio;
			// Free vertices start from the prediction, handle vertices at their targets.
			memcpy(sim->x, sim->predicted, bytes);
			plume_sim_place_handles(sim, (double)s / substeps);
			status = plume_sim_check_held_barbs(sim, &last);
			if (status == PLUME_OK)
				status = solve_substep(sim, &problem, (double)(s - 1) / substeps, (double)s / substeps, &total, &last);
			if (status != PLUME_OK)
				break;
			plume_integrator_end(sim, &problem);
		}
		// Substeps help a step that did not converge, not one that ran out of memory:
		// a retry that then succeeded would make the result depend on the allocator.
		if (status != PLUME_ERROR_NUMERIC)
			break;
	}
	sim->retrying = false;
	if (status != PLUME_OK) {
		memcpy(sim->x, sim->saved_x, bytes);
		memcpy(sim->v, sim->saved_v, bytes);
		plume_integrator_restore(&sim->integrator, sim->vertex_count);
		if (report != NULL)
			*report = total;
		// Both ends: "at t" read as the step's time, which stats.csv and summary.json's failed_time
		// give as its end.
		return plume_error_set(err, status, "the step from t = %.6g s to %.6g s failed with %d substeps: %s", sim->time,
		                       sim->time + sim->def.time_step, total.substeps, last.message);
	}
	sim->time += sim->def.time_step;
	finish_handles(sim);
	plume_contact_finish(sim);
	total.max_barb_strain = plume_sim_max_barb_strain(sim, sim->x);
	if (report != NULL)
		*report = total;
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// Measurements

int plume_sim_vertex_count(const plume_sim *sim)
{
	PLUME_ASSERT_HANDLE(sim);
	return sim->vertex_count;
}

int plume_sim_handle_count(const plume_sim *sim)
{
	PLUME_ASSERT_HANDLE(sim);
	return sim->handle_count;
}

int plume_sim_constraint_count(const plume_sim *sim)
{
	PLUME_ASSERT_HANDLE(sim);
	return sim->constraint_count;
}

const plume_vec3 *plume_sim_positions(const plume_sim *sim)
{
	PLUME_ASSERT_HANDLE(sim);
	return sim->x;
}

const plume_vec3 *plume_sim_velocities(const plume_sim *sim)
{
	PLUME_ASSERT_HANDLE(sim);
	return sim->v;
}

double plume_sim_time(const plume_sim *sim)
{
	PLUME_ASSERT_HANDLE(sim);
	return sim->time;
}

bool plume_sim_group_reaction(plume_sim *sim, const char *group_name, plume_vec3 *force)
{
	return plume_sim_group_reactions(sim, &group_name, 1, force);
}

bool plume_sim_group_reactions(plume_sim *sim, const char *const *groups, int count, plume_vec3 *forces)
{
	PLUME_ASSERT_HANDLE(sim);
	PLUME_ASSERT(count >= 0 && (count == 0 || (groups != NULL && forces != NULL)));
	for (int k = 0; k < count; ++k)
		if (groups[k] == NULL || plume_sim_find_group(sim, groups[k]) == NULL)
			return false;
	static const sim_problem statics = {.dynamic = false};
	double *g = sim->gradient;
	plume_sim_potential(sim, &statics, sim->x, g, false, false);
	plume_sim_add_constraint_forces(sim, sim->x, g);
	for (int k = 0; k < count; ++k) {
		const plume_vertex_group *group = plume_sim_find_group(sim, groups[k]);
		plume_vec3 sum = {0, 0, 0};
		for (int i = 0; i < group->count; ++i) {
			int v = group->vertices[i];
			sum = plume_v3_add(sum, plume_v3(g[3 * v], g[3 * v + 1], g[3 * v + 2]));
		}
		forces[k] = sum;
	}
	return true;
}

plume_sim_energies plume_sim_energy(plume_sim *sim)
{
	PLUME_ASSERT_HANDLE(sim);
	plume_sim_energies out = {0};
	for (int f = 0; f < sim->face_count; ++f) {
		const plume_membrane_element *element = sim->membranes + f;
		plume_vec3 local[3] = {sim->x[element->vertices[0]], sim->x[element->vertices[1]],
		                       sim->x[element->vertices[2]]};
		out.membrane += plume_membrane_energy(element, local, NULL, NULL);
		if (element->compression > 0)
			out.compression += plume_compression_energy(element, local, NULL, NULL);
	}
	for (int e = 0; sim->def.bending && e < plume_sim_bending_count(sim); ++e)
		out.bending += plume_sim_bending_energy(sim, sim->x, e);
	for (int i = 0; i < sim->vertex_count; ++i) {
		out.gravity -= sim->mass[i] * plume_v3_dot(sim->def.gravity, sim->x[i]) + plume_v3_dot(sim->load[i], sim->x[i]);
		out.kinetic += 0.5 * sim->mass[i] * plume_v3_dot(sim->v[i], sim->v[i]);
	}
	plume_contact_energies(sim, sim->x, &out.contact, &out.friction);
	return out;
}

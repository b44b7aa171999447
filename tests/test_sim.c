// The shell simulator: statics against beam theory, the barb constraint,
// monotone Newton, handles, free fall under implicit Euler, reactions,
// determinism and bad definitions.
#include <math.h>
#include <omp.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/sim_internal.h"
#include "support.h"

// ---------------------------------------------------------------------------
// Fixture: a flat strip of near-equilateral triangles in the z = 0 plane.
// Columns of vertices at x = i dx (dx = dy sqrt(3)/2), odd columns shifted by
// dy/2, so each triangle has exactly one edge along a column (along y): that
// edge is marked as its barb edge (barbs along y, barb angle pi/2).
// Groups: "clamp" (the first two columns: a clamped end), "tip" (last column).

typedef struct strip {
	double length, width;
	int columns, rows;
} strip;

static int strip_vertex(const strip *s, int i, int j) { return i * s->rows + j; }

static plume_mesh *make_strip(double length, double width, int rows)
{
	strip s = {length, width, 0, rows};
	double dy = width / (rows - 1);
	double dx = dy * sqrt(3) / 2;
	s.columns = (int)lround(length / dx) + 1;
	dx = length / (s.columns - 1);
	int vertex_count = s.columns * rows;
	int face_count = (s.columns - 1) * 2 * (rows - 1);
	plume_mesh *mesh = plume_mesh_create(vertex_count, face_count);
	assert_non_null(mesh);
	for (int i = 0; i < s.columns; ++i)
		for (int j = 0; j < rows; ++j) {
			int v = strip_vertex(&s, i, j);
			double y = j * dy + (i % 2 ? 0.5 * dy : 0) - 0.25 * dy;
			mesh->reference[v] = (plume_vec2){i * dx, y};
			mesh->rest[v] = plume_v3(i * dx, y, 0);
			mesh->uv[v] = (plume_vec2){i * dx / length, y / width};
		}
	int f = 0;
	for (int i = 0; i + 1 < s.columns; ++i)
		for (int j = 0; j + 1 < rows; ++j) {
			int a0 = strip_vertex(&s, i, j), a1 = strip_vertex(&s, i, j + 1);
			int b0 = strip_vertex(&s, i + 1, j), b1 = strip_vertex(&s, i + 1, j + 1);
			int tri[2][3];
			if (i % 2 == 0) { // right column higher
				int t0[3] = {a0, b0, a1}, t1[3] = {b0, b1, a1};
				memcpy(tri[0], t0, sizeof t0), memcpy(tri[1], t1, sizeof t1);
			} else {
				int t0[3] = {a0, b0, b1}, t1[3] = {a0, b1, a1};
				memcpy(tri[0], t0, sizeof t0), memcpy(tri[1], t1, sizeof t1);
			}
			for (int t = 0; t < 2; ++t, ++f) {
				memcpy(mesh->faces + 3 * f, tri[t], sizeof tri[t]);
				mesh->material[f] = 0;
				mesh->barb_angle[f] = acos(0.0);
				mesh->barb_edge[f] = -1;
				for (int k = 0; k < 3; ++k) {
					plume_vec2 p = mesh->reference[tri[t][k]], q = mesh->reference[tri[t][(k + 1) % 3]];
					if (fabs(p.x - q.x) < 1e-12 * length)
						mesh->barb_edge[f] = (signed char)k;
				}
				assert_true(mesh->barb_edge[f] >= 0);
			}
		}
	int *clamp = malloc(sizeof(int) * 2 * rows), *tip = malloc(sizeof(int) * rows);
	for (int j = 0; j < rows; ++j) {
		clamp[j] = strip_vertex(&s, 0, j);
		clamp[rows + j] = strip_vertex(&s, 1, j);
		tip[j] = strip_vertex(&s, s.columns - 1, j);
	}
	assert_int_equal(plume_mesh_add_group(mesh, "clamp", clamp, 2 * rows, NULL), PLUME_OK);
	assert_int_equal(plume_mesh_add_group(mesh, "tip", tip, rows, NULL), PLUME_OK);
	free(clamp);
	free(tip);
	assert_int_equal(plume_mesh_collect_barb_edges(mesh, NULL), PLUME_OK);
	return mesh;
}

/// An isotropic plate material: membrane E t, bending D the same in every direction.
static plume_material plate(double youngs_modulus, double thickness, double bending, double density)
{
	plume_material m = plume_material_rachis();
	m.kind = PLUME_MATERIAL_ISOTROPIC;
	m.youngs_modulus = youngs_modulus;
	m.poisson_ratio = 0;
	m.thickness = thickness;
	m.surface_density = density;
	m.bending_along = m.bending_across = bending;
	m.compression_coefficient = 0;
	m.barb_constraint = false;
	return m;
}

static plume_sim_def plate_def(plume_material material)
{
	plume_sim_def def = plume_sim_default_def();
	def.materials[0] = material;
	def.material_count = 1;
	def.gravity = plume_v3(0, 0, 0);
	return def;
}

static double mean_z(const plume_sim *sim, const plume_mesh *mesh, const char *group)
{
	const plume_vertex_group *g = plume_mesh_find_group(mesh, group);
	double sum = 0;
	for (int i = 0; i < g->count; ++i)
		sum += plume_sim_positions(sim)[g->vertices[i]].z;
	return sum / g->count;
}

// ---------------------------------------------------------------------------

/// Euler–Bernoulli: a cantilever plate of bending stiffness EI = D W under a tip load P
/// deflects P L^3 / (3 D W). The clamp holds two columns of vertices; the fundamental-form
/// bending (the default) makes the faces between them a clamp whose edge normals the free
/// faces see (sim/fundamental_form.h), so the beam's root is the second column
/// (L = length - dx). The deflection is read on the middle half of the tip edge.
/// Measured errors: 2.4%, 0.70%, 0.22% for 9, 17, 33 rows (the paper's hinge, root at
/// length - dx/2: 0.6%, 0.4%, 0.7%, not converging).
static void test_cantilever_matches_euler_bernoulli(void **state)
{
	(void)state;
	const double length = 0.05, width = 0.1, bending = 1e-3, load = 1e-5;
	int resolutions[3] = {9, 17, 33};
	const double tolerance[3] = {0.03, 0.01, 0.004};
	for (int r = 0; r < 3; ++r) {
		plume_mesh *mesh = make_strip(length, width, resolutions[r]);
		// Clamped over the first two columns: the beam starts at the second.
		double free_length = length - mesh->reference[resolutions[r]].x;
		double expected = load * pow(free_length, 3) / (3 * bending * width);
		plume_sim_def def = plate_def(plate(1e7, 1e-3, bending, 0));
		plume_sim *sim = NULL;
		plume_error err = {0};
		assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
		assert_true(plume_sim_add_handle(sim, "clamp", &err) >= 0);
		assert_int_equal(plume_sim_set_group_load(sim, "tip", plume_v3(0, 0, -load), &err), PLUME_OK);
		plume_solve_report report;
		assert_int_equal(plume_sim_solve_static(sim, &report, &err), PLUME_OK);
		// The middle half of the tip edge: away from the free sides' boundary layer.
		const plume_vertex_group *tip = plume_mesh_find_group(mesh, "tip");
		double sum = 0;
		int count = 0;
		for (int i = 0; i < tip->count; ++i)
			if (fabs(mesh->reference[tip->vertices[i]].y - width / 2) < width / 4)
				sum += plume_sim_positions(sim)[tip->vertices[i]].z, ++count;
		double deflection = -sum / count;
		double error = fabs(deflection - expected) / expected;
		printf("cantilever rows %d: deflection %.6g m, Euler-Bernoulli %.6g m, error %.4f, %d Newton iterations\n",
		       resolutions[r], deflection, expected, error, report.newton_iterations);
		assert_true(error < tolerance[r]);
		plume_sim_destroy(sim);
		plume_mesh_destroy(mesh);
	}
}

/// With the constraint, every barb edge keeps its length to 1e-8 under a load that
/// would stretch it, and the multipliers carry the load.
/// The Table 6.1 vane (barbs constrained) under gravity g.
static plume_sim_def vane_def(plume_vec3 gravity)
{
	plume_sim_def def = plume_sim_default_def();
	def.gravity = gravity;
	def.material_count = 1;
	def.materials[0] = plume_material_vane();
	return def;
}

/// A simulation of the strip held at its clamp, with its barbs constrained.
static plume_sim *clamped_strip(const plume_mesh *mesh, const plume_sim_def *def)
{
	plume_sim *sim = NULL;
	plume_error err = {0};
	assert_int_equal(plume_sim_create(mesh, def, &sim, &err), PLUME_OK);
	assert_true(sim->constraint_count > 0);
	assert_true(plume_sim_add_handle(sim, "clamp", &err) >= 0);
	return sim;
}

static void test_barb_constraint_holds(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.05, 0.1, 7); // barbs along y, the long direction
	plume_sim_def def = vane_def(plume_v3(0, 0, 0));
	plume_sim *sim = clamped_strip(mesh, &def);
	plume_error err = {0};
	// Pull the free end along x (across the barbs) and along y (along them) and out of plane.
	assert_int_equal(plume_sim_set_group_load(sim, "tip", plume_v3(2e-3, 5e-3, -1e-4), &err), PLUME_OK);
	plume_solve_report report;
	assert_int_equal(plume_sim_solve_static(sim, &report, &err), PLUME_OK);
	printf("constrained solve: %d iterations, barb strain %.3g\n", report.newton_iterations, report.max_barb_strain);
	assert_true(report.max_barb_strain < 1e-8);
	// The tip moved: the shell did deform.
	assert_true(fabs(mean_z(sim, mesh, "tip")) > 1e-4);
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// Handles that pull two held vertices farther apart than the chain of barb edges between
/// them is long ask for the impossible (sim/held.c): the strip's barbs run along y, six
/// edges from its bottom row to its top row, and holding both rows and lifting the top one
/// 1 mm along them stretches every chain by 1 %. The step is refused, saying which chain,
/// and the state stays; moving both rows together, which the barbs allow, steps.
static void test_held_chain_cannot_stretch(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.05, 0.1, 7);
	strip s = {0.05, 0.1, mesh->vertex_count / 7, 7};
	int bottom[64], top[64];
	assert_true(s.columns <= 64);
	for (int i = 0; i < s.columns; ++i) {
		bottom[i] = strip_vertex(&s, i, 0);
		top[i] = strip_vertex(&s, i, s.rows - 1);
	}
	assert_int_equal(plume_mesh_add_group(mesh, "bottom", bottom, s.columns, NULL), PLUME_OK);
	assert_int_equal(plume_mesh_add_group(mesh, "top", top, s.columns, NULL), PLUME_OK);
	plume_sim_def def = vane_def(plume_v3(0, 0, 0));
	plume_sim *sim = NULL;
	plume_error err = {0};
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	int lower = plume_sim_add_handle(sim, "bottom", &err), upper = plume_sim_add_handle(sim, "top", &err);
	assert_true(lower >= 0 && upper >= 0);
	plume_mat3 identity = plume_m3_identity();
	plume_sim_set_handle(sim, upper, plume_v3(0, 1e-3, 0), identity, plume_v3(0, 0, 0));
	assert_int_equal(plume_sim_step(sim, NULL, &err), PLUME_ERROR_SPEC);
	printf("%s\n", err.message);
	assert_non_null(strstr(err.message, "the chain of 6 barb edges between them is 0.1 m long"));
	for (int v = 0; v < mesh->vertex_count; ++v)
		assert_true(plume_v3_distance(plume_sim_positions(sim)[v], mesh->rest[v]) == 0);
	// Both rows lifted together: a rigid motion the barbs allow.
	plume_sim_set_handle(sim, lower, plume_v3(0, 1e-3, 0), identity, plume_v3(0, 0, 0));
	assert_int_equal(plume_sim_step(sim, NULL, &err), PLUME_OK);
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// A Newton step below the tolerance (times the shell's size) ends a solve, but it moves
/// the barbs' ends to second order: the solve may end there only if the barbs still hold.
/// With a tolerance of 0.5 every step of the static sag is "below tolerance" (5.6 cm on
/// this strip) while the residual is not (the first residual is the force scale itself).
static void test_small_step_keeps_the_barbs(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.05, 0.1, 7);
	plume_sim_def def = vane_def(plume_v3(0, 0, -9.81));
	def.solver.tolerance = 0.5;
	plume_sim *sim = clamped_strip(mesh, &def);
	plume_error err = {0};
	plume_solve_report report;
	assert_int_equal(plume_sim_solve_static(sim, &report, &err), PLUME_OK);
	printf("tolerance 0.5, statics: %d iterations, barb strain %.3g, tip %.3g m\n", report.newton_iterations,
	       report.max_barb_strain, mean_z(sim, mesh, "tip"));
	assert_true(report.converged && report.max_barb_strain <= 1e-10);
	assert_true(mean_z(sim, mesh, "tip") < -1e-4); // it did sag
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

/// A curved feather is at rest in its 3D shape. The strip's rest shape is bent across its
/// barbs into z = y^2 / (2 R), R = 5 cm (a Streit-Heidrich or Zhang-Kanai vane is curved
/// like this), so each barb edge is longer in 3D than in the reference plane, by up to
/// 0.5 % at the strip's far edge. Held at its clamp with no load, it must not move: the
/// membrane's and the barbs' rest lengths are the 3D ones. Measured in the plane, they made
/// the first solve shorten the barbs and fold the strip (a Streit-Heidrich semiplume held
/// without gravity fell to a principal stretch of 0.88 in one step).
static void test_curved_rest_shape_is_at_rest(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.05, 0.1, 7);
	const double radius = 0.05;
	for (int v = 0; v < mesh->vertex_count; ++v) {
		double y = mesh->reference[v].y;
		mesh->rest[v].z = y * y / (2 * radius);
	}
	plume_sim_def def = vane_def(plume_v3(0, 0, 0));
	for (int dynamic = 0; dynamic < 2; ++dynamic) {
		plume_sim *sim = clamped_strip(mesh, &def);
		plume_error err = {0};
		plume_solve_report report;
		assert_int_equal(dynamic ? plume_sim_step(sim, &report, &err) : plume_sim_solve_static(sim, &report, &err),
		                 PLUME_OK);
		double moved = 0;
		for (int v = 0; v < mesh->vertex_count; ++v)
			moved = fmax(moved, plume_v3_length(plume_v3_sub(sim->x[v], mesh->rest[v])));
		plume_sim_energies energies = plume_sim_energy(sim);
		double elastic = energies.membrane + energies.bending + energies.compression;
		printf("curved rest, %s: %d iterations, largest move %.3g m, elastic energy %.3g J, barb strain %.3g\n",
		       dynamic ? "one step" : "statics", report.newton_iterations, moved, elastic, report.max_barb_strain);
		assert_true(moved < 1e-9);
		assert_true(fabs(elastic) < 1e-15);
		assert_true(report.max_barb_strain < 1e-10);
		plume_sim_destroy(sim);
	}
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// Without constraints the line search only accepts steps that lower the potential.
static void test_potential_decreases_every_step(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.1, 0.02, 5);
	plume_sim_def def = plate_def(plate(1e5, 1e-4, 1e-6, 0.03));
	def.gravity = plume_v3(0, 0, -9.81);
	plume_sim *sim = NULL;
	plume_error err = {0};
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	assert_true(plume_sim_add_handle(sim, "clamp", &err) >= 0);
	plume_solve_report report;
	assert_int_equal(plume_sim_solve_static(sim, &report, &err), PLUME_OK);
	assert_true(sim->trace_count >= 3);
	for (int i = 0; i + 1 < sim->trace_count; i += 2)
		assert_true(sim->trace[i + 1] <= sim->trace[i]);
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

/// Free fall: with no handle a rigid translation stores no elastic energy, and implicit
/// Euler gives v_n = n h g and y_n = h^2 g n (n + 1) / 2 exactly.
static void test_free_fall_is_exact(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.05, 0.02, 4);
	plume_sim_def def = plate_def(plate(1e5, 1e-4, 1e-6, 0.03));
	def.gravity = plume_v3(0, -9.81, 0);
	def.time_step = 0.01;
	def.integrator = PLUME_INTEGRATOR_IMPLICIT_EULER;
	plume_sim *sim = NULL;
	plume_error err = {0};
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	const int steps = 5;
	for (int n = 0; n < steps; ++n)
		assert_int_equal(plume_sim_step(sim, NULL, &err), PLUME_OK);
	double h = def.time_step, expected = -9.81 * h * h * steps * (steps + 1) / 2;
	for (int i = 0; i < mesh->vertex_count; ++i) {
		assert_close(plume_sim_positions(sim)[i].y - mesh->rest[i].y, expected, 1e-9);
		assert_close(plume_sim_velocities(sim)[i].y, -9.81 * h * steps, 1e-8);
	}
	assert_close(plume_sim_time(sim), steps * h, 1e-15);
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

/// A scripted handle lands exactly on its target; the rest follows dynamically.
static void test_handle_reaches_keyframe(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.1, 0.02, 5);
	plume_sim_def def = plate_def(plate(1e5, 1e-4, 1e-6, 0.03));
	plume_sim *sim = NULL;
	plume_error err = {0};
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	int handle = plume_sim_add_handle(sim, "clamp", &err);
	assert_true(handle >= 0);
	plume_vec3 pivot = plume_v3(0, 0.01, 0);
	plume_mat3 rotation = plume_m3_rotation(plume_v3(0, 1, 0), 0.1);
	plume_vec3 translation = plume_v3(0.001, 0.002, -0.003);
	plume_sim_set_handle(sim, handle, translation, rotation, pivot);
	assert_int_equal(plume_sim_step(sim, NULL, &err), PLUME_OK);
	const plume_vertex_group *clamp = plume_mesh_find_group(mesh, "clamp");
	for (int i = 0; i < clamp->count; ++i) {
		int v = clamp->vertices[i];
		plume_vec3 want = plume_v3_add(
		    plume_v3_add(pivot, plume_m3_apply(rotation, plume_v3_sub(mesh->rest[v], pivot))), translation);
		plume_vec3 got = plume_sim_positions(sim)[v];
		assert_true(got.x == want.x && got.y == want.y && got.z == want.z);
	}
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

/// In equilibrium the clamp's reaction balances the applied load.
static void test_reaction_balances_load(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.1, 0.02, 5);
	plume_sim_def def = plate_def(plate(1e6, 1e-4, 1e-5, 0));
	plume_sim *sim = NULL;
	plume_error err = {0};
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	assert_true(plume_sim_add_handle(sim, "clamp", &err) >= 0);
	plume_vec3 load = plume_v3(1e-3, 2e-5, -1e-5);
	assert_int_equal(plume_sim_set_group_load(sim, "tip", load, &err), PLUME_OK);
	assert_int_equal(plume_sim_solve_static(sim, NULL, &err), PLUME_OK);
	plume_vec3 reaction;
	assert_true(plume_sim_group_reaction(sim, "clamp", &reaction));
	// The clamp holds the strip against the load: its force is minus the load.
	assert_close(reaction.x, -load.x, 1e-9);
	assert_close(reaction.y, -load.y, 1e-9);
	assert_close(reaction.z, -load.z, 1e-9);
	assert_false(plume_sim_group_reaction(sim, "nowhere", &reaction));
	// Many groups on one evaluation: the same clamp bits, and nothing on the free tip, whose
	// forces balance (to the solver's tolerance, relative to the load).
	const char *groups[2] = {"tip", "clamp"};
	plume_vec3 reactions[2];
	assert_true(plume_sim_group_reactions(sim, groups, 2, reactions));
	assert_true(reactions[1].x == reaction.x && reactions[1].y == reaction.y && reactions[1].z == reaction.z);
	assert_true(plume_v3_length(reactions[0]) < 1e-6 * plume_v3_length(load));
	const char *unknown[2] = {"clamp", "nowhere"};
	reactions[0] = plume_v3(7, 7, 7);
	assert_false(plume_sim_group_reactions(sim, unknown, 2, reactions));
	assert_true(reactions[0].x == 7); // nothing written
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

static void run_swing(plume_vec3 *out, int count)
{
	plume_mesh *mesh = make_strip(0.1, 0.03, 5);
	plume_sim_def def = plume_sim_default_def();
	def.material_count = 1;
	def.drag = 0.5;
	plume_sim *sim = NULL;
	plume_error err = {0};
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	assert_true(plume_sim_add_handle(sim, "clamp", &err) >= 0);
	for (int n = 0; n < 3; ++n)
		assert_int_equal(plume_sim_step(sim, NULL, &err), PLUME_OK);
	assert_int_equal(plume_sim_vertex_count(sim), count);
	memcpy(out, plume_sim_positions(sim), sizeof(plume_vec3) * (size_t)count);
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

static void test_steps_are_deterministic(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.1, 0.03, 5);
	int count = mesh->vertex_count;
	plume_mesh_destroy(mesh);
	plume_vec3 *a = malloc(sizeof(plume_vec3) * (size_t)count), *b = malloc(sizeof(plume_vec3) * (size_t)count);
	run_swing(a, count);
	run_swing(b, count);
	assert_memory_equal(a, b, sizeof(plume_vec3) * (size_t)count);
	free(a);
	free(b);
}

static void test_kkt_factor_reports_indefinite(void **state)
{
	(void)state;
	// Without constraints the Newton matrix is H alone, factored by Cholesky: an indefinite
	// or non-finite H must not pass as a factorisation (Newton would not descend).
	plume_kkt kkt;
	memset(&kkt, 0, sizeof kkt);
	plume_error err = {0};
	assert_int_equal(plume_kkt_init(&kkt, 2, 0, NULL, 0, NULL, 0, 4, 0, NULL, 0, NULL, &err), PLUME_OK);
	double *values = plume_kkt_values(&kkt);
	double shift = -1.0, rhs[6] = {1, 2, 3, 4, 5, 6}, x[6];
	plume_kkt_zero(&kkt);
	for (int v = 0; v < 2; ++v)
		for (int d = 0; d < 3; ++d)
			values[kkt.system.diagonal[3 * v + d]] = 2.0;
	assert_int_equal(plume_kkt_factor(&kkt, 0, 0, &shift, &err), PLUME_OK);
	assert_true(shift == 0.0);
	assert_int_equal(plume_kkt_solve(&kkt, rhs, NULL, 1e-14, x, &err), PLUME_OK);
	for (int i = 0; i < 6; ++i)
		assert_close(x[i], rhs[i] / 2.0, 1e-15);

	// One negative pivot, mean |diagonal| 11/6: the ladder 1e-10, 1e-9, ... times the mean
	// first passes 1 at 1 (11/6 added); started at 10, it stops there (110/6 added).
	for (int first = 0; first <= 1; ++first) {
		for (int i = 0; i < 6; ++i)
			values[kkt.system.diagonal[i]] = i == 5 ? -1.0 : 2.0;
		assert_int_equal(plume_kkt_factor(&kkt, 0, 0, &shift, &err), PLUME_ERROR_NUMERIC);
		assert_non_null(strstr(err.message, "not positive definite"));
		assert_int_equal(plume_kkt_factor(&kkt, first ? 10.0 : 0.0, 1e2, &shift, &err), PLUME_OK);
		assert_close(shift, first ? 10.0 : 1.0, 1e-12);
		assert_int_equal(plume_kkt_solve(&kkt, rhs, NULL, 1e-14, x, &err), PLUME_OK);
		assert_close(x[5], 6.0 / (shift * 11.0 / 6.0 - 1.0), 1e-12);
		assert_close(x[0], 1.0 / (2.0 + shift * 11.0 / 6.0), 1e-12);
	}
	// The limit is the last rung whatever the rungs before it: in decades from 0.1 times it
	// (what Newton passes after a ladder ran out; 0.1 * 1e-5 * 10 rounds above 1e-5) and in
	// hundredfold rungs from nothing (1e-6, then 1e-4 clamped), a pivot of -1.5e-5 against
	// the mean |diagonal| 10/6 needs s > 9e-6.
	for (int first = 0; first <= 1; ++first) {
		for (int i = 0; i < 6; ++i)
			values[kkt.system.diagonal[i]] = i == 5 ? -1.5e-5 : 2.0;
		assert_int_equal(plume_kkt_factor(&kkt, first ? 0.1 * 1e-5 : 0.0, 1e-5, &shift, &err), PLUME_OK);
		assert_true(shift == 1e-5);
	}
	// A ladder that stops below the shift it needs fails.
	for (int i = 0; i < 6; ++i)
		values[kkt.system.diagonal[i]] = i == 5 ? -1.0 : 2.0;
	assert_int_equal(plume_kkt_factor(&kkt, 0, 0.1, &shift, &err), PLUME_ERROR_NUMERIC);
	assert_non_null(strstr(err.message, "even after regularisation"));

	plume_kkt_zero(&kkt);
	for (int v = 0; v < 2; ++v)
		for (int d = 0; d < 3; ++d)
			values[kkt.system.diagonal[3 * v + d]] = v == 1 && d == 1 ? NAN : 2.0;
	assert_int_equal(plume_kkt_factor(&kkt, 0, 0, &shift, &err), PLUME_ERROR_NUMERIC);
	plume_kkt_free(&kkt);
}

/// A Newton matrix of two vertices joined by one barb along u: H = diag(k0 I, k1 I),
/// C = [-u^T u^T].
static void one_barb_init(plume_kkt *kkt)
{
	memset(kkt, 0, sizeof *kkt);
	plume_error err = {0};
	static const int pair[2] = {0, 1}; // the matrix keeps the pointer
	assert_int_equal(plume_kkt_init(kkt, 2, 0, NULL, 0, NULL, 4, 0, 0, NULL, 1, pair, &err), PLUME_OK);
}

static void one_barb_load(plume_kkt *kkt, double k0, double k1, const double u[3])
{
	double *values = plume_kkt_values(kkt);
	plume_kkt_zero(kkt);
	for (int d = 0; d < 3; ++d) {
		values[kkt->system.diagonal[d]] = k0;
		values[kkt->system.diagonal[3 + d]] = k1;
		values[kkt->constraint_slots[d]] = -u[d];
		values[kkt->constraint_slots[3 + d]] = u[d];
	}
}

static void test_kkt_factor_inertia(void **state)
{
	(void)state;
	// With constraints the exact Hessian is accepted iff it is positive definite on the
	// constraints' tangent space, read from the Cholesky factors of H + C^T R C: one barb
	// between two vertices along x (C = [-1 0 0 1 0 0]), H = 2 I with one entry changed.
	plume_kkt kkt;
	one_barb_init(&kkt);
	plume_error err = {0};
	double *values = plume_kkt_values(&kkt), shift;
	for (int trial = 0; trial < 2; ++trial) {
		one_barb_load(&kkt, 2.0, 2.0, (const double[3]){1, 0, 0});
		// Trial 0: H_x0x0 = -1 makes H indefinite, but the tangent space sees x0 only with
		// x1 ((-1 + 2) / 2 > 0 along x0 = x1): accepted. Trial 1: H_y0y0 = -1 is a tangent
		// direction: refused.
		values[kkt.system.diagonal[trial]] = -1.0;
		plume_status status = plume_kkt_factor(&kkt, 0, 0, &shift, &err);
		if (trial == 1) {
			assert_int_equal(status, PLUME_ERROR_NUMERIC);
			assert_non_null(strstr(err.message, "tangent space"));
			continue;
		}
		assert_int_equal(status, PLUME_OK);
		double rhs[7] = {1, 2, 3, 4, 5, 6, 0.5}, x[7];
		assert_int_equal(plume_kkt_solve(&kkt, rhs, NULL, 1e-14, x, &err), PLUME_OK);
		assert_close(x[3] - x[0], 0.5, 1e-14);  // the linearised constraint, to rounding
		assert_close(-x[0] - x[6], 1.0, 1e-12); // H dx + C^T lambda = rhs on x0
	}
	plume_kkt_free(&kkt);
}

static void test_kkt_barb_between_stiff_and_soft(void **state)
{
	(void)state;
	// A barb rooted on the rachis: one end held by a stiffness many decades above the
	// other's (a sliver of the stiff rachis band, the soft vane). H = diag(k0 I, I), the
	// barb along u = (1, 1, 0) / sqrt(2), C = [-u^T u^T]. Closed form: along u the barb
	// stays at length r and the forces split by the stiffnesses, lambda = a1 - dx1.u with
	// dx0.u = (a0 + a1 - r) / (k0 + 1), dx1.u = dx0.u + r (a_i = g_i.u); then each row,
	// k0 dx0 - lambda u = g0 and dx1 + lambda u = g1. The regularisation's rho, 1e6 times
	// the stiffer end's stiffness, must stay within reach of the softer end's: unbounded,
	// rho u u^T swamps the soft end's own stiffness across the barb (1 against 1e6 k0),
	// which rounding then loses, and at k0 = 1e12 the matrix no longer factors (the
	// Streit-Heidrich peacock's rachis tip, 40 um wide against 5 mm rows, did not
	// converge in a single step).
	plume_kkt kkt;
	one_barb_init(&kkt);
	plume_error err = {0};
	double shift;
	const double u[3] = {sqrt(0.5), sqrt(0.5), 0}, g0[3] = {0.3, -0.1, 0.2}, g1[3] = {0.7, 0.4, -0.5}, r = 0.25;
	for (int decades = 0; decades <= 12; decades += 4) {
		double k0 = pow(10.0, decades);
		one_barb_load(&kkt, k0, 1.0, u);
		assert_int_equal(plume_kkt_factor(&kkt, 0, 0, &shift, &err), PLUME_OK);
		assert_true(shift == 0.0);
		double rhs[7] = {g0[0], g0[1], g0[2], g1[0], g1[1], g1[2], r}, x[7];
		assert_int_equal(plume_kkt_solve(&kkt, rhs, NULL, 1e-14, x, &err), PLUME_OK);
		double a0 = g0[0] * u[0] + g0[1] * u[1], a1 = g1[0] * u[0] + g1[1] * u[1];
		double along0 = (a0 + a1 - r) / (k0 + 1), lambda = a1 - (along0 + r);
		for (int d = 0; d < 3; ++d) {
			assert_close(x[d], (g0[d] + lambda * u[d]) / k0, 1e-12 / k0);
			assert_close(x[3 + d], g1[d] - lambda * u[d], 1e-12);
		}
		assert_close(x[6], lambda, 1e-12);
	}
	plume_kkt_free(&kkt);
}

/// Largest |(K v)_i - (d/dt grad L(x + t v))_i| over free unknowns, by central differences
/// of step `step`, where K is the assembled matrix and grad L = grad Phi + C^T lambda; the
/// constraint rows' (C v)_k against differences of c_k. Largest differences in *scale.
static double lagrangian_hessian_error(plume_sim *sim, const sim_problem *problem, const double *v, double step,
                                       double *scale)
{
	int n = sim->vertex_count, n3 = 3 * n, m = sim->constraint_count;
	double *kv = calloc((size_t)(n3 + m), sizeof(double)), *gp = calloc((size_t)n3, sizeof(double));
	double *gm = calloc((size_t)n3, sizeof(double)), *cp = calloc((size_t)m, sizeof(double));
	double *cm = calloc((size_t)m, sizeof(double));
	plume_vec3 *x = malloc(sizeof(plume_vec3) * (size_t)n);
	plume_kkt_multiply_add(&sim->kkt, v, kv);
	for (int sign = -1; sign <= 1; sign += 2) {
		double *g = sign > 0 ? gp : gm, *c = sign > 0 ? cp : cm;
		for (int i = 0; i < n; ++i)
			x[i] = plume_v3(sim->x[i].x + sign * step * v[3 * i], sim->x[i].y + sign * step * v[3 * i + 1],
			                sim->x[i].z + sign * step * v[3 * i + 2]);
		plume_sim_potential(sim, problem, x, g, false, false);
		plume_sim_add_constraint_forces(sim, x, g);
		for (int k = 0; k < m; ++k) {
			const int *e = sim->constraint_vertices + 2 * k;
			c[k] = plume_v3_length(plume_v3_sub(x[e[1]], x[e[0]])) - sim->constraint_length[k];
		}
	}
	double worst = 0;
	*scale = 0;
	for (int i = 0; i < n3; ++i) {
		if (sim->fixed[i])
			continue; // a held unknown has no row in K
		double fd = (gp[i] - gm[i]) / (2 * step);
		worst = fmax(worst, fabs(fd - kv[i]));
		*scale = fmax(*scale, fabs(fd));
	}
	for (int k = 0; k < m; ++k) {
		double fd = (cp[k] - cm[k]) / (2 * step);
		worst = fmax(worst, fabs(fd - kv[n3 + k]) * fabs(sim->lambda[k]));
	}
	free(kv), free(gp), free(gm), free(cp), free(cm), free(x);
	return worst;
}

static void test_shared_edge_bending_matches_finite_differences(void **state)
{
	(void)state;
	// The fundamental-form faces take their dihedral angles from the shared-edge pass
	// (fundamental_form.h, Shared edges). On a bent strip with one face wound the other
	// way (so that some faces see their edge's angle with the opposite sign), the
	// assembled energy, gradient and exact Hessian must be those of the faces evaluated
	// on their own, and the gradient and Hessian those of central differences.
	plume_mesh *mesh = make_strip(0.1, 0.02, 4);
	int *flipped = mesh->faces + 3 * 7, t = flipped[1];
	flipped[1] = flipped[2];
	flipped[2] = t;
	plume_sim_def def = plume_sim_default_def();
	def.gravity = plume_v3(0, 0, 0);
	def.materials[0].barb_constraint = false;
	plume_sim *sim = NULL;
	plume_error err = {0};
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	int n = sim->vertex_count, n3 = 3 * n, size = n3 + sim->constraint_count;
	for (int i = 0; i < n; ++i)
		sim->x[i].z += 0.004 * sin(40 * sim->x[i].x) + 0.002 * cos(90 * sim->x[i].y + 0.3 * i);
	static const sim_problem statics = {.dynamic = false};
	double *g = calloc((size_t)size, sizeof(double)), *v = calloc((size_t)size, sizeof(double));
	plume_vec3 *x = malloc(sizeof(plume_vec3) * (size_t)n);
	plume_sim_potential(sim, &statics, sim->x, g, true, false);
	for (int i = 0; i < n3; ++i)
		v[i] = sim->fixed[i] ? 0 : cos(0.37 * i);

	double energy_difference = 0, energy_largest = 0;
	int negative = 0;
	for (int e = 0; e < sim->ff_count; ++e) {
		const plume_ff_face *face = sim->ff_faces + e;
		plume_vec3 local[6];
		for (int k = 0; k < 6; ++k)
			local[k] = face->vertices[k] >= 0 ? sim->x[face->vertices[k]] : plume_v3(0, 0, 0);
		double direct = plume_ff_face_energy(face, local, NULL, NULL);
		energy_difference = fmax(energy_difference, fabs(direct - sim->hinge_energy[e]));
		energy_largest = fmax(energy_largest, fabs(direct));
		for (int i = 0; i < 3; ++i)
			negative += face->edge[i] >= 0 && face->edge_sign[i] < 0;
	}
	assert_true(negative > 0);
	assert_true(energy_largest > 0 && energy_difference <= 1e-12 * energy_largest);

	double worst = 0, largest = 0, step = 1e-7;
	for (int i = 0; i < n3; ++i)
		largest = fmax(largest, fabs(g[i]));
	for (int i = 0; i < n3; ++i) {
		if (sim->fixed[i])
			continue;
		memcpy(x, sim->x, sizeof(plume_vec3) * (size_t)n);
		double *c = &x[i / 3].x + i % 3, saved = *c;
		*c = saved + step;
		double plus = plume_sim_potential(sim, &statics, x, NULL, false, false);
		*c = saved - step;
		double minus = plume_sim_potential(sim, &statics, x, NULL, false, false);
		worst = fmax(worst, fabs((plus - minus) / (2 * step) - g[i]));
	}
	double hlargest, hworst = lagrangian_hessian_error(sim, &statics, v, step, &hlargest);
	printf("shared-edge bending (%d faces see their edge's angle negated): energy %.3g of %.3g, gradient error %.3g of "
	       "%.3g, Hessian error %.3g of %.3g\n",
	       negative, energy_difference, energy_largest, worst, largest, hworst, hlargest);
	assert_true(largest > 0 && worst <= 1e-6 * largest);
	assert_true(hlargest > 0 && hworst <= 1e-6 * hlargest);
	free(g), free(v), free(x);
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

static void test_lagrangian_hessian_matches_finite_differences(void **state)
{
	(void)state;
	// Newton's exact matrix is the Hessian of the Lagrangian Phi + lambda . c of a dynamic
	// step: every element's exact block (the Kikuuwe term active: the strip is compressed
	// across its barbs, J about 0.95), the inertia, and the barbs' curvature, for barbs in
	// tension and in compression alike. Checked against central differences of the
	// assembled gradient plus C^T lambda along a direction, as Newton uses it. Without
	// `exact` the compressed barbs' curvature is left out, and the same check must see it.
	plume_mesh *mesh = make_strip(0.1, 0.02, 4);
	plume_sim_def def = plume_sim_default_def();
	plume_sim *sim = NULL;
	plume_error err = {0};
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	int n = sim->vertex_count, n3 = 3 * n, m = sim->constraint_count;
	assert_true(m > 0 && sim->def.materials[PLUME_MATERIAL_VANE].compression_coefficient > 0);
	for (int i = 0; i < n; ++i) {
		sim->x[i].x *= 0.95;
		sim->x[i].z += 0.002 * sin(40 * sim->x[i].x) + 0.001 * cos(90 * sim->x[i].y + 0.3 * i);
		sim->v[i] = plume_v3(0.01 * cos(i), 0.02 * sin(2.0 * i), 0.05 * cos(0.7 * i));
	}
	int compressed = 0;
	for (int k = 0; k < m; ++k) {
		sim->lambda[k] = (k % 3 == 0 ? -0.2 : 0.1) * (1 + k % 5);
		compressed += sim->lambda[k] < 0;
	}
	sim_problem problem;
	plume_integrator_begin(sim, 0.011, &problem);
	double *v = calloc((size_t)(n3 + m), sizeof(double));
	for (int i = 0; i < n3; ++i)
		v[i] = sim->fixed[i] ? 0 : cos(0.37 * i);

	double errors[2], scales[2];
	for (int exact = 1; exact >= 0; --exact) {
		plume_sim_potential(sim, &problem, sim->x, NULL, true, false);
		plume_sim_add_constraint_rows(sim, sim->x, exact);
		errors[exact] = lagrangian_hessian_error(sim, &problem, v, 1e-7, &scales[exact]);
	}
	printf("Lagrangian Hessian (%d barbs, %d compressed): exact error %.3g of %.3g; without the compressed barbs' "
	       "curvature %.3g\n",
	       m, compressed, errors[1], scales[1], errors[0]);
	assert_true(compressed > 0 && scales[1] > 0);
	assert_true(errors[1] <= 1e-6 * scales[1]);
	assert_true(errors[0] >= 1e-3 * scales[0]);
	free(v);
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

/// y = A x for the grid Laplacian plus the identity, A = 5 I - (the four neighbours), on
/// an m x m grid (unknown i = m r + c), written from the stencil.
static void grid_operator(int m, const double *x, double *y)
{
	for (int r = 0; r < m; ++r)
		for (int c = 0; c < m; ++c) {
			int i = m * r + c;
			y[i] = 5 * x[i] - (r > 0 ? x[i - m] : 0) - (r + 1 < m ? x[i + m] : 0) - (c > 0 ? x[i - 1] : 0) -
			       (c + 1 < m ? x[i + 1] : 0);
		}
}

/// The grid matrix through plume_sparse, factored, solved and multiplied; returns whether
/// CHOLMOD chose its supernodal factorisation.
static bool check_grid_system(int m)
{
	int n = m * m;
	plume_sparse_entry *entries = malloc(sizeof *entries * 3 * (size_t)n);
	double *x = malloc(sizeof(double) * (size_t)n), *b = malloc(sizeof(double) * (size_t)n);
	double *y = calloc((size_t)n, sizeof(double));
	assert_true(entries && x && b && y);
	int count = 0;
	for (int i = 0; i < n; ++i) {
		entries[count++] = (plume_sparse_entry){i, i};
		if (i % m + 1 < m)
			entries[count++] = (plume_sparse_entry){i + 1, i};
		if (i + m < n)
			entries[count++] = (plume_sparse_entry){i + m, i};
	}
	plume_sparse matrix;
	plume_error err = {0};
	assert_int_equal(plume_sparse_init(&matrix, n, entries, (size_t)count, true, "the grid", &err), PLUME_OK);
	double *values = matrix.matrix->x;
	for (int i = 0; i < n; ++i) {
		values[matrix.diagonal[i]] = 5;
		if (i % m + 1 < m)
			values[plume_sparse_find(&matrix, i + 1, i)] = -1; // either order finds the entry
		if (i + m < n)
			values[plume_sparse_find(&matrix, i, i + m)] = -1;
		x[i] = sin(0.37 * i) + 0.1 * i / n;
	}
	// The stored triangle is the one the factorisation reads in place (sim/sparse.h).
	bool supernodal = matrix.factor->is_super;
	assert_int_equal(matrix.matrix->stype, supernodal ? -1 : 1);
	grid_operator(m, x, b);
	plume_sparse_multiply_add(&matrix, x, y);
	for (int i = 0; i < n; ++i)
		assert_true(fabs(y[i] - b[i]) <= 1e-12 * 6);
	assert_true(plume_sparse_factor(&matrix));
	memcpy(matrix.rhs->x, b, sizeof(double) * (size_t)n);
	assert_true(plume_sparse_solve(&matrix));
	const double *solved = matrix.solution->x;
	for (int i = 0; i < n; ++i)
		assert_true(fabs(solved[i] - x[i]) <= 1e-12);
	plume_sparse_free(&matrix);
	free(entries), free(x), free(b), free(y);
	return supernodal;
}

static void test_sparse_simplicial_and_supernodal(void **state)
{
	(void)state;
	// A small grid factors simplicially, a large one supernodally (CHOLMOD_AUTO); both
	// solve A x = b to rounding (A is well conditioned: its eigenvalues lie in [1, 9]).
	assert_false(check_grid_system(6));
	assert_true(check_grid_system(120));
}

/// Factors a 3 x 3 diagonal matrix 2000 times; returns non-NULL when every one succeeded,
/// and then the calling thread's OpenMP limit must be what it was (the next test).
static void *factor_repeatedly(void *unused)
{
	(void)unused;
	int levels = omp_get_max_active_levels();
	plume_sparse matrix;
	plume_error err = {0};
	plume_sparse_entry entries[3] = {{0, 0}, {1, 1}, {2, 2}};
	bool ok = plume_sparse_init(&matrix, 3, entries, 3, true, "the test's matrix", &err) == PLUME_OK;
	for (int k = 0; k < 3 && ok; ++k)
		((double *)matrix.matrix->x)[k] = 1 + k;
	for (int round = 0; round < 2000 && ok; ++round)
		ok = plume_sparse_factor(&matrix);
	plume_sparse_free(&matrix);
	static int success;
	return ok && omp_get_max_active_levels() == levels ? &success : NULL;
}

static void test_factorisation_restores_openmp_levels(void **state)
{
	(void)state;
	// A factorisation switches CHOLMOD's OpenMP regions off (sim/sparse.c) and must hand the
	// caller's limit back, on every thread, also while another thread factors.
	int levels = omp_get_max_active_levels();
	assert_true(levels > 0);
	pthread_t threads[2];
	for (int t = 0; t < 2; ++t)
		assert_int_equal(pthread_create(threads + t, NULL, factor_repeatedly, NULL), 0);
	for (int t = 0; t < 2; ++t) {
		void *result = NULL;
		assert_int_equal(pthread_join(threads[t], &result), 0);
		assert_non_null(result);
	}
	assert_int_equal(omp_get_max_active_levels(), levels);
	assert_non_null(factor_repeatedly(NULL));
	assert_int_equal(omp_get_max_active_levels(), levels);
}

static void test_bad_definitions(void **state)
{
	(void)state;
	plume_mesh *mesh = make_strip(0.1, 0.02, 4);
	plume_sim *sim = NULL;
	plume_error err = {0};
	plume_sim_def def = plume_sim_default_def();
	def.materials[0].thickness = -1;
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "$.materials.vane.thickness is -1, allowed [1e-09, 1] m"));
	assert_null(sim);
	def = plume_sim_default_def();
	def.materials[1].youngs_modulus = -5;
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "$.materials.rachis.youngs_modulus"));
	def = plume_sim_default_def();
	def.time_step = 0;
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "$.time_step is 0, allowed [1e-09, 100] s"));
	def = plume_sim_default_def();
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	assert_int_equal(plume_sim_add_handle(sim, "rachis_bse", &err), -1);
	assert_non_null(strstr(err.message, "unknown vertex group \"rachis_bse\" (the mesh has: clamp, tip)"));
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_cantilever_matches_euler_bernoulli),
	    cmocka_unit_test(test_barb_constraint_holds),
	    cmocka_unit_test(test_held_chain_cannot_stretch),
	    cmocka_unit_test(test_small_step_keeps_the_barbs),
	    cmocka_unit_test(test_curved_rest_shape_is_at_rest),
	    cmocka_unit_test(test_potential_decreases_every_step),
	    cmocka_unit_test(test_free_fall_is_exact),
	    cmocka_unit_test(test_handle_reaches_keyframe),
	    cmocka_unit_test(test_reaction_balances_load),
	    cmocka_unit_test(test_steps_are_deterministic),
	    cmocka_unit_test(test_kkt_factor_reports_indefinite),
	    cmocka_unit_test(test_shared_edge_bending_matches_finite_differences),
	    cmocka_unit_test(test_lagrangian_hessian_matches_finite_differences),
	    cmocka_unit_test(test_factorisation_restores_openmp_levels),
	    cmocka_unit_test(test_sparse_simplicial_and_supernodal),
	    cmocka_unit_test(test_kkt_factor_inertia),
	    cmocka_unit_test(test_kkt_barb_between_stiff_and_soft),
	    cmocka_unit_test(test_bad_definitions),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

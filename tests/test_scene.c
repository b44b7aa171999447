// Scenes: the paper's Figure 1 scenario in a short, coarse version (the
// anisotropic vane bends the rachis, the isotropic one much less), handle
// keyframes, and the errors of bad scene specs.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

/// The positions after the last step of run_scene.
static plume_vec3 *final_positions;
static int final_count;

static plume_status keep_positions(void *user, int step, double time, const plume_sim *sim,
                                   const plume_solve_report *report, double wall_seconds, plume_error *err)
{
	(void)user, (void)step, (void)time, (void)report, (void)wall_seconds, (void)err;
	final_count = plume_sim_vertex_count(sim);
	final_positions = realloc(final_positions, sizeof(plume_vec3) * (size_t)final_count);
	memcpy(final_positions, plume_sim_positions(sim), sizeof(plume_vec3) * (size_t)final_count);
	return PLUME_OK;
}

/// Loads a scene of tests/data (the test fails on an error).
static plume_scene *load_scene(const char *name)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/tests/data/%s", PLUME_SOURCE_DIR, name);
	plume_scene *scene = NULL;
	plume_error err = {0};
	if (plume_scene_load(path, NULL, &scene, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	return scene;
}

/// Runs a scene of tests/data; a vane shear modulus E_vw > 0 replaces the scene's.
static plume_scene_summary run_scene(const char *name, double E_vw)
{
	plume_scene *scene = load_scene(name);
	plume_error err = {0};
	if (E_vw > 0)
		scene->sim.materials[PLUME_MATERIAL_VANE].E_vw = E_vw;
	plume_scene_summary summary;
	if (plume_scene_run(scene, keep_positions, NULL, &summary, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	assert_true(scene->mesh_report.aligned_fraction == 1);
	plume_scene_destroy(scene);
	return summary;
}

/// Compares final_positions with a fixture of positions recorded by an earlier solver
/// (issue 15: a faster linear algebra must converge to the same state, to 1e-9 m).
/// PLUME_RECORD_POSITIONS=1 in the environment rewrites the fixture instead.
static void compare_positions(const char *name)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/tests/data/%s", PLUME_SOURCE_DIR, name);
	const char *record = getenv("PLUME_RECORD_POSITIONS");
	FILE *file = fopen(path, record && record[0] == '1' ? "w" : "r");
	assert_non_null(file);
	double worst = 0;
	for (int i = 0; i < final_count; ++i) {
		plume_vec3 p = final_positions[i], q;
		if (record && record[0] == '1') {
			fprintf(file, "%.17g %.17g %.17g\n", p.x, p.y, p.z);
			continue;
		}
		assert_int_equal(fscanf(file, "%lf %lf %lf", &q.x, &q.y, &q.z), 3);
		worst = fmax(worst, plume_v3_distance(p, q));
	}
	double extra;
	assert_true(record || fscanf(file, "%lf", &extra) == EOF); // as many vertices as recorded
	fclose(file);
	free(final_positions);
	final_positions = NULL;
	printf("%s: largest distance to the recorded positions %.3g m\n", name, worst);
	assert_true(worst <= 1e-9);
}

/// Paper Figure 1: with inextensible barbs the pull on the vane tip bends the rachis;
/// an isotropic vane (E = E_ww) stretches instead. Measured with the default vane
/// (E_vw = 1.99e4 Pa): 4.426 cm against 1.471 cm (ratio 3.0) on this coarse mesh; the
/// barbs hold their length to 1e-10.
static void test_figure1_anisotropic_bends_the_rachis(void **state)
{
	(void)state;
	// The recorded positions come from the solver before issue 15, with the vane's E_vw of
	// then (1.02e4 Pa, pinned in the scene): a solver change must reach the same state.
	plume_scene_summary recorded = run_scene("figure1-coarse-anisotropic.json", 0);
	compare_positions("figure1-coarse-anisotropic-positions.txt");
	plume_scene_summary anisotropic = run_scene("figure1-coarse-anisotropic.json", plume_material_vane().E_vw);
	free(final_positions);
	final_positions = NULL;
	plume_scene_summary isotropic = run_scene("figure1-coarse-isotropic.json", 0);
	free(final_positions);
	final_positions = NULL;
	printf("rachis tip deflection: anisotropic %.6g m (%d steps, %d Newton iterations, barb strain %.3g; "
	       "%.6g m with E_vw = 1.02e4 Pa), isotropic %.4g m (barb strain %.3g), ratio %.3f\n",
	       anisotropic.rachis_tip_deflection, anisotropic.steps, anisotropic.newton_iterations,
	       anisotropic.max_barb_strain, recorded.rachis_tip_deflection, isotropic.rachis_tip_deflection,
	       isotropic.max_barb_strain, anisotropic.rachis_tip_deflection / isotropic.rachis_tip_deflection);
	assert_int_equal(anisotropic.steps, 30);
	assert_true(anisotropic.max_barb_strain < 1e-8);
	assert_true(isotropic.max_barb_strain > 0.1);
	assert_true(anisotropic.rachis_tip_deflection > 0.02);
	assert_true(anisotropic.rachis_tip_deflection > 2.5 * isotropic.rachis_tip_deflection);
	// The inextensible barbs carry the pull to the rachis; the vane's shear stiffness
	// (E_vw b = 2.4 N/m) is small against the rachis's, so doubling E_vw barely moves the
	// tip (measured 3e-5; 1.02e4 -> 1.99e4 Pa moved vane vertices by up to 0.7 mm).
	assert_close(anisotropic.rachis_tip_deflection / recorded.rachis_tip_deflection, 1.0, 1e-2);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// The vane's state over a run: the smallest principal stretch and the most Newton iterations
/// of any step.
typedef struct vane_watch {
	double min_stretch;
	int most_iterations;
} vane_watch;

static plume_status watch_vane(void *user, int step, double time, const plume_sim *sim,
                               const plume_solve_report *report, double wall_seconds, plume_error *err)
{
	vane_watch *watch = user;
	if (report != NULL) {
		watch->min_stretch =
		    fmin(watch->min_stretch, plume_sim_vane_shape_measure(sim, "rachis_clamp").min_principal_stretch);
		watch->most_iterations =
		    report->newton_iterations > watch->most_iterations ? report->newton_iterations : watch->most_iterations;
	}
	return keep_positions(user, step, time, sim, report, wall_seconds, err);
}

/// Issue 13, item 4: Figure 1 at the paper's amplitude with the default vane (Table 6.1's
/// Kikuuwe coefficient read as N/m, docs/physics-energies.md), on the coarse scene, whose
/// handle moves 3 cm. Read as Pa, the same run collapses in plane (smallest principal
/// stretch 0.023) and stays within 20 um of its plane. Measured: every step converged with
/// at most 20 Newton iterations and no substeps, smallest stretch 0.788, the vane 5.5 mm out
/// of its rest plane 2.9 cm from the handle (the tip of the unpulled half), rachis tip
/// 3.77 cm against the isotropic vane's 1.47 cm (ratio 2.56).
static void test_figure1_full_amplitude_buckles_without_collapse(void **state)
{
	(void)state;
	plume_scene *scene = load_scene("figure1-coarse-anisotropic.json");
	plume_error err = {0};
	plume_material vane = plume_material_vane();
	scene->sim.materials[PLUME_MATERIAL_VANE].E_vw = vane.E_vw;
	scene->sim.materials[PLUME_MATERIAL_VANE].compression_coefficient = vane.compression_coefficient;
	vane_watch watch = {INFINITY, 0};
	plume_scene_summary anisotropic;
	if (plume_scene_run(scene, watch_vane, &watch, &anisotropic, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	// Out of plane away from the pulled handle: the feather lies in z = 0 with its clamp held,
	// so the rest plane does not move. Vane vertices more than 2.5 handle radii from its centre.
	const plume_scene_handle *pulled = &scene->handles[1];
	assert_true(pulled->near_given);
	const plume_mesh *mesh = scene->mesh;
	double far_lift = 0;
	for (int f = 0; f < mesh->face_count; ++f) {
		if (mesh->material[f] != PLUME_MATERIAL_VANE)
			continue;
		for (int k = 0; k < 3; ++k) {
			int v = mesh->faces[3 * f + k];
			plume_vec3 rest = mesh->rest[v];
			assert_true(fabs(rest.z) < 1e-12);
			if (hypot(rest.x - pulled->near.x, rest.y - pulled->near.y) > 2.5 * pulled->radius)
				far_lift = fmax(far_lift, fabs(final_positions[v].z));
		}
	}
	free(final_positions);
	final_positions = NULL;
	plume_scene_destroy(scene);
	plume_scene_summary isotropic = run_scene("figure1-coarse-isotropic.json", 0);
	free(final_positions);
	final_positions = NULL;
	printf("full amplitude: %d steps, %d Newton iterations (at most %d a step, %d retried), smallest vane stretch "
	       "%.4g, %.3g m out of plane away from the handle, barb strain %.3g, rachis tip %.5g m against %.5g m "
	       "(ratio %.3f)\n",
	       anisotropic.steps, anisotropic.newton_iterations, watch.most_iterations, anisotropic.retried_steps,
	       watch.min_stretch, far_lift, anisotropic.max_barb_strain, anisotropic.rachis_tip_deflection,
	       isotropic.rachis_tip_deflection, anisotropic.rachis_tip_deflection / isotropic.rachis_tip_deflection);
	assert_int_equal(anisotropic.steps, 30);
	assert_int_equal(anisotropic.retried_steps, 0);
	assert_true(watch.most_iterations <= 50); // Table 6.1's Newton steps
	assert_true(watch.min_stretch >= 0.7);    // no in-plane collapse
	assert_true(far_lift > 1e-3);             // the vane buckles out of its plane
	assert_true(anisotropic.max_barb_strain < 1e-8);
	// The issue asked for 3 times; the vane that no longer collapses bends the rachis less
	// than the collapsing one did (4.43 cm, ratio 3.0): 2.56 here, 2.49 at e = 5 mm.
	assert_true(anisotropic.rachis_tip_deflection > 2.4 * isotropic.rachis_tip_deflection);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// Newton through the vane's buckling on a finer mesh (docs/simulation.md, Newton's method):
/// the coarse fixture's 3 cm pull in 0.3 s at e = 3.5 mm with the default vane. Projecting
/// an indefinite exact Hessian and correcting only the full step onto the barbs, the run
/// stopped at t = 0.066 s (16 substeps of 50 iterations each); shifting the Hessian and
/// correcting every trial of the line search, it completes (no step retried, at most 50
/// iterations in a step, measured).
static void test_newton_through_buckling_on_a_finer_mesh(void **state)
{
	(void)state;
	plume_scene *scene = load_scene("figure1-fast-pull-fine.json");
	plume_error err = {0};
	vane_watch watch = {INFINITY, 0};
	plume_scene_summary summary;
	if (plume_scene_run(scene, watch_vane, &watch, &summary, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	printf("finer mesh: %d vertices, %d steps, %d Newton iterations (at most %d a step, %d retried), smallest vane "
	       "stretch %.4g, barb strain %.3g, rachis tip %.5g m\n",
	       summary.vertex_count, summary.steps, summary.newton_iterations, watch.most_iterations, summary.retried_steps,
	       watch.min_stretch, summary.max_barb_strain, summary.rachis_tip_deflection);
	assert_int_equal(summary.steps, 30);
	assert_true(summary.retried_steps <= 2);
	assert_true(summary.max_barb_strain < 1e-8);
	assert_true(watch.min_stretch >= 0.6); // buckled, not collapsed in plane (0.69 measured)
	// The rachis tip as on the coarse mesh (3.77 cm) and at e = 5 mm (3.92 cm in 1.1 s): 3.94 cm.
	assert_true(summary.rachis_tip_deflection > 0.037 && summary.rachis_tip_deflection < 0.042);
	free(final_positions);
	final_positions = NULL;
	plume_scene_destroy(scene);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// A step that stalls near an unstable equilibrium is retried keeping the exact Hessian
/// (docs/simulation.md, "The 0.9 mm stop"): Figure 1 at e = 2.5 mm with at most 20 Newton
/// iterations a solve. The step at t = 0.561 s does not converge in its first try. Retried
/// as the first try runs, with a projected Hessian after every shortened step, it failed
/// with 1 to 16 substeps and the run stopped there (measured); keeping the exact Hessian
/// in the retries, it converges in substeps and the run completes.
static void test_retry_keeps_the_exact_hessian(void **state)
{
	(void)state;
	plume_scene *scene = load_scene("figure1-fine-stall.json");
	plume_error err = {0};
	plume_scene_summary summary;
	if (plume_scene_run(scene, NULL, NULL, &summary, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	printf("stalling step: %d steps, %d Newton iterations, %d retried, barb strain %.3g\n", summary.steps,
	       summary.newton_iterations, summary.retried_steps, summary.max_barb_strain);
	assert_int_equal(summary.steps, 52);
	assert_true(summary.retried_steps >= 1);
	assert_true(summary.max_barb_strain < 1e-8);
	plume_scene_destroy(scene);
	assert_int_equal(plume_bytes_in_use(), 0);
}

static void test_handle_pose_interpolation(void **state)
{
	(void)state;
	plume_keyframe keys[2] = {{0, {0, 0, 0}, {0, 0, 1}, 0}, {2, {1, -2, 4}, {0, 0, 1}, 1}};
	plume_scene_handle handle = {0};
	handle.keyframe_count = 2;
	handle.keyframes = keys;
	plume_vec3 t;
	plume_mat3 r;
	plume_scene_handle_pose(&handle, 1, &t, &r);
	assert_close(t.x, 0.5, 1e-15);
	assert_close(t.y, -1, 1e-15);
	handle.interpolation = PLUME_INTERPOLATION_SMOOTH;
	plume_scene_handle_pose(&handle, 0.5, &t, &r);
	assert_close(t.x, 0.15625, 1e-15); // 3 s^2 - 2 s^3 at s = 1/4
	plume_scene_handle_pose(&handle, 5, &t, &r);
	assert_close(t.z, 4, 0);
	assert_close(r.m[0][0], cos(1), 1e-15);
	assert_close(r.m[1][0], sin(1), 1e-15);
}

/// A key without rotation (its axis the default z) takes the other key's axis, as a body's
/// keys do (docs/body.md "Interpolation"): from rest to 90 degrees about x, a quarter of the
/// way is 22.5 degrees about x. The handle's pose took the nearer key's axis, so it turned
/// about z for the first half and jumped to x at the middle.
static void test_handle_pose_axis_of_a_key_without_rotation(void **state)
{
	(void)state;
	double pi = acos(-1.0);
	plume_keyframe keys[2] = {{0, {0, 0, 0}, {0, 0, 1}, 0}, {1, {0, 0, 0}, {1, 0, 0}, pi / 2}};
	plume_scene_handle handle = {0};
	handle.keyframe_count = 2;
	handle.keyframes = keys;
	plume_vec3 t;
	plume_mat3 r;
	plume_scene_handle_pose(&handle, 0.25, &t, &r);
	assert_close(r.m[0][0], 1, 1e-15);
	assert_close(r.m[1][1], cos(pi / 8), 1e-15);
	assert_close(r.m[2][1], sin(pi / 8), 1e-15);
	// Two different axes: the shorter arc between the keys (slerp), continuous at the middle.
	plume_keyframe turned[2] = {{0, {0, 0, 0}, {1, 0, 0}, pi / 2}, {1, {0, 0, 0}, {0, 1, 0}, pi / 2}};
	handle.keyframes = turned;
	plume_mat3 before, after;
	plume_scene_handle_pose(&handle, 0.5 - 1e-9, &t, &before);
	plume_scene_handle_pose(&handle, 0.5 + 1e-9, &t, &after);
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			assert_close(before.m[i][j], after.m[i][j], 1e-7);
}

/// Loads a scene from text (written to a temporary file, so relative paths are the source tree's).
static plume_scene *load_text(const char *text)
{
	char dir[512], path[1024];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/scene.json", dir);
	test_write_file(path, text);
	plume_scene *scene = NULL;
	plume_error err = {0};
	if (plume_scene_load(path, NULL, &scene, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	test_remove_tree(dir);
	return scene;
}

/// Every step's positions of a run, back to back (steps + 1 states of vertex_count each).
typedef struct trajectory {
	int vertex_count;
	int states;
	plume_vec3 *positions;
} trajectory;

static plume_status record_state(void *user, int step, double time, const plume_sim *sim,
                                 const plume_solve_report *report, double wall_seconds, plume_error *err)
{
	(void)step, (void)time, (void)report, (void)wall_seconds, (void)err;
	trajectory *path = user;
	path->vertex_count = plume_sim_vertex_count(sim);
	path->positions =
	    realloc(path->positions, sizeof(plume_vec3) * (size_t)path->vertex_count * (size_t)(path->states + 1));
	memcpy(path->positions + (size_t)path->states * (size_t)path->vertex_count, plume_sim_positions(sim),
	       sizeof(plume_vec3) * (size_t)path->vertex_count);
	path->states++;
	return PLUME_OK;
}

static trajectory run_text(const char *text, plume_scene **keep)
{
	plume_scene *scene = load_text(text);
	trajectory path = {0, 0, NULL};
	plume_scene_summary summary;
	plume_error err = {0};
	if (plume_scene_run(scene, record_state, &path, &summary, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	if (keep != NULL)
		*keep = scene;
	else
		plume_scene_destroy(scene);
	return path;
}

#define BLUE "\"" PLUME_SOURCE_DIR "/examples/franco-walter/blue.json\""
#define HAWK "\"" PLUME_SOURCE_DIR "/examples/franco-walter/hawk.json\""
/// Held at the calamus, under gravity across the vane, 6 steps; Newton solved to 1e-11 so that
/// two runs agree to well under the test's 1e-10 m wherever they agree physically. (At 1e-12
/// the two feathers together stall at the residual's roundoff floor in step 2, which the
/// stiff Kikuuwe term of slightly compressed faces sets, and the step is retried in substeps.)
#define SETTINGS                                                                                                       \
	"\"mesh\": {\"edge_length\": 0.01, \"rachis_width_base\": 0.006, \"rachis_width_tip\": 0.003}, "                   \
	"\"handles\": [{\"group\": \"rachis_clamp\"}], \"gravity\": [0.5, -2, -9.81], \"duration\": 0.066, "               \
	"\"solver\": {\"tolerance\": 1e-11, \"max_iterations\": 100}"
#define ENTRY_A "{\"feather\": " BLUE ", \"position\": [-0.4, 0.1, 0]}"
#define ENTRY_B                                                                                                        \
	"{\"feather\": " HAWK ", \"position\": [0.4, 0, 0.2], \"rotation_axis\": [1, 1, 0], \"rotation_deg\": 40, "        \
	"\"mesh\": {\"edge_length\": 0.012}}"

/// Issue 14: feathers that never touch move as when simulated one by one. Two feathers
/// 0.8 m apart (no contact, no shared vertex) in one simulation against each alone (with
/// the same placement and mesh), every step, to 1e-10 m.
static void test_far_apart_feathers_do_not_interact(void **state)
{
	(void)state;
	plume_scene *both_scene = NULL;
	trajectory both = run_text("{\"feathers\": [" ENTRY_A ", " ENTRY_B "], " SETTINGS "}", &both_scene);
	trajectory alone[2] = {run_text("{\"feathers\": [" ENTRY_A "], " SETTINGS "}", NULL),
	                       run_text("{\"feathers\": [" ENTRY_B "], " SETTINGS "}", NULL)};
	assert_int_equal(both_scene->feather_count, 2);
	assert_int_equal(both.vertex_count, alone[0].vertex_count + alone[1].vertex_count);
	double worst = 0, moved = 0;
	for (int f = 0; f < 2; ++f) {
		assert_int_equal(both.states, alone[f].states);
		assert_int_equal(both_scene->feathers[f].vertex_count, alone[f].vertex_count);
		int offset = both_scene->feathers[f].vertex_offset;
		for (int s = 0; s < both.states; ++s)
			for (int v = 0; v < alone[f].vertex_count; ++v) {
				plume_vec3 p = both.positions[(size_t)s * (size_t)both.vertex_count + (size_t)(offset + v)];
				plume_vec3 q = alone[f].positions[(size_t)s * (size_t)alone[f].vertex_count + (size_t)v];
				worst = fmax(worst, plume_v3_distance(p, q));
				moved = fmax(moved, plume_v3_distance(q, alone[f].positions[v]));
			}
		free(alone[f].positions);
	}
	printf("two feathers together against each alone: %d steps, largest difference %.3g m (largest motion %.3g m)\n",
	       both.states - 1, worst, moved);
	assert_int_equal(both.states, 7);
	assert_true(moved > 1e-4); // they do move: the comparison means something
	assert_true(worst <= 1e-10);
	free(both.positions);
	plume_scene_destroy(both_scene);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// A one-entry "feathers" list at the origin is the "feather" scene: same mesh, same steps.
static void test_one_entry_list_is_the_single_feather_scene(void **state)
{
	(void)state;
	trajectory listed = run_text("{\"feathers\": [{\"feather\": " BLUE "}], " SETTINGS "}", NULL);
	trajectory single = run_text("{\"feather\": " BLUE ", " SETTINGS "}", NULL);
	assert_int_equal(listed.vertex_count, single.vertex_count);
	assert_int_equal(listed.states, single.states);
	size_t n = (size_t)listed.states * (size_t)listed.vertex_count;
	assert_memory_equal(listed.positions, single.positions, n * sizeof(plume_vec3));
	free(listed.positions);
	free(single.positions);
	assert_int_equal(plume_bytes_in_use(), 0);
}

static plume_mesh *square_mesh(double size)
{
	plume_mesh *mesh = plume_mesh_create(4, 2);
	plume_vec2 corners[4] = {{0, 0}, {size, 0}, {size, size}, {0, size}};
	int faces[6] = {0, 1, 2, 0, 2, 3};
	for (int v = 0; v < 4; ++v) {
		mesh->reference[v] = corners[v];
		mesh->rest[v] = plume_v3(corners[v].x, corners[v].y, 0.25 * v);
		mesh->uv[v] = (plume_vec2){0.1 * v, 0.2 * v};
	}
	memcpy(mesh->faces, faces, sizeof faces);
	mesh->material[1] = PLUME_MATERIAL_RACHIS;
	mesh->barb_angle[0] = 0.5;
	mesh->barb_edge[0] = 0;
	plume_error err = {0};
	assert_int_equal(plume_mesh_collect_barb_edges(mesh, &err), PLUME_OK);
	int base[2] = {0, 1}, tip[1] = {3};
	assert_int_equal(plume_mesh_add_group(mesh, "rachis_clamp", base, 2, &err), PLUME_OK);
	assert_int_equal(plume_mesh_add_group(mesh, "rachis_tip", tip, 1, &err), PLUME_OK);
	return mesh;
}

/// plume_mesh_concatenate against the parts, entry by entry: counts add up, faces and barb
/// edges are offset, rest positions placed by R p + T (computed here by hand), groups kept
/// under their prefix and joined under their own name.
static void test_mesh_concatenate(void **state)
{
	(void)state;
	plume_mesh *a = square_mesh(1), *b = square_mesh(2);
	int extra[1] = {2};
	plume_error err = {0};
	assert_int_equal(plume_mesh_add_group(b, "left_edge", extra, 1, &err), PLUME_OK);
	// A quarter turn about z: (x, y, z) -> (-y, x, z).
	plume_mat3 quarter = {{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}};
	plume_mesh_part parts[2] = {{a, plume_m3_identity(), {0, 0, 0}, "f0"}, {b, quarter, {10, 20, 30}, "f1"}};
	plume_mesh *mesh = NULL;
	assert_int_equal(plume_mesh_concatenate(parts, 2, &mesh, &err), PLUME_OK);
	assert_int_equal(mesh->vertex_count, 8);
	assert_int_equal(mesh->face_count, 4);
	assert_int_equal(mesh->barb_edge_count, 2);
	assert_int_equal(mesh->barb_edges[2], b->barb_edges[0] + 4);
	assert_int_equal(mesh->faces[9], 4); // b's face {0, 2, 3} after a's 4 vertices
	assert_int_equal(mesh->faces[10], 6);
	assert_int_equal(mesh->faces[11], 7);
	assert_int_equal(mesh->material[3], PLUME_MATERIAL_RACHIS);
	assert_close(mesh->barb_angle[2], 0.5, 0);
	assert_int_equal(mesh->barb_edge[2], 0);
	for (int v = 0; v < 4; ++v) {
		assert_memory_equal(&mesh->rest[v], &a->rest[v], sizeof(plume_vec3));
		plume_vec3 p = b->rest[v];
		assert_close(mesh->rest[4 + v].x, -p.y + 10, 1e-15);
		assert_close(mesh->rest[4 + v].y, p.x + 20, 1e-15);
		assert_close(mesh->rest[4 + v].z, p.z + 30, 1e-15);
		assert_memory_equal(&mesh->reference[4 + v], &b->reference[v], sizeof(plume_vec2)); // material plane kept
		assert_memory_equal(&mesh->uv[4 + v], &b->uv[v], sizeof(plume_vec2));
	}
	// rachis_clamp, rachis_tip, left_edge joined, then f0/ and f1/ groups.
	assert_int_equal(mesh->group_count, 3 + 2 + 3);
	const plume_vertex_group *all = plume_mesh_find_group(mesh, "rachis_clamp");
	assert_non_null(all);
	assert_int_equal(all->count, 4);
	int expected[4] = {0, 1, 4, 5};
	assert_memory_equal(all->vertices, expected, sizeof expected);
	const plume_vertex_group *left = plume_mesh_find_group(mesh, "left_edge");
	assert_int_equal(left->count, 1);
	assert_int_equal(left->vertices[0], 6);
	const plume_vertex_group *own = plume_mesh_find_group(mesh, "f1/rachis_tip");
	assert_non_null(own);
	assert_int_equal(own->count, 1);
	assert_int_equal(own->vertices[0], 7);
	assert_non_null(plume_mesh_find_group(mesh, "f0/rachis_clamp"));
	assert_null(plume_mesh_find_group(mesh, "f0/left_edge"));
	plume_mesh_destroy(mesh);
	// Prefixes that collide, or names past 31 bytes, are refused.
	parts[1].prefix = "f0";
	assert_int_equal(plume_mesh_concatenate(parts, 2, &mesh, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "share the group prefix \"f0\""));
	parts[1].prefix = "a_prefix_much_too_long_for";
	assert_int_equal(plume_mesh_concatenate(parts, 2, &mesh, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "longer than 31 bytes"));
	assert_null(mesh);
	// Group "tip/a" of part "x" and group "a" of part "x/tip" would both be "x/tip/a".
	int one[1] = {0};
	assert_int_equal(plume_mesh_add_group(a, "tip/a", one, 1, &err), PLUME_OK);
	assert_int_equal(plume_mesh_add_group(b, "a", one, 1, &err), PLUME_OK);
	parts[0].prefix = "x";
	parts[1].prefix = "x/tip";
	assert_int_equal(plume_mesh_concatenate(parts, 2, &mesh, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "two vertex groups would be named \"x/tip/a\""));
	assert_null(mesh);
	plume_mesh_destroy(a);
	plume_mesh_destroy(b);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// A handle on "f1/rachis_clamp" holds only the second feather: the first one falls freely.
static void test_prefixed_group_handle(void **state)
{
	(void)state;
	plume_scene *scene = NULL;
	trajectory path = run_text("{\"feathers\": [" ENTRY_A ", " ENTRY_B "], "
	                           "\"mesh\": {\"edge_length\": 0.01, \"rachis_width_base\": 0.006, \"rachis_width_tip\": "
	                           "0.003}, \"handles\": [{\"group\": \"f1/rachis_clamp\"}], \"gravity\": [0, 0, -9.81], "
	                           "\"duration\": 0.022}",
	                           &scene);
	const plume_vertex_group *held = plume_mesh_find_group(scene->mesh, "f1/rachis_clamp");
	const plume_vertex_group *free_clamp = plume_mesh_find_group(scene->mesh, "f0/rachis_clamp");
	const plume_vertex_group *both = plume_mesh_find_group(scene->mesh, "rachis_clamp");
	assert_non_null(held);
	assert_non_null(free_clamp);
	assert_int_equal(both->count, held->count + free_clamp->count);
	const plume_vec3 *last = path.positions + (size_t)(path.states - 1) * (size_t)path.vertex_count;
	for (int i = 0; i < held->count; ++i)
		assert_memory_equal(&last[held->vertices[i]], &scene->mesh->rest[held->vertices[i]], sizeof(plume_vec3));
	// The free feather falls with the gravity's acceleration as a whole (no drag): its clamp's
	// drop after 2 steps is of the order of g t^2 / 2 = 2.4 mm.
	for (int i = 0; i < free_clamp->count; ++i) {
		int v = free_clamp->vertices[i];
		double drop = scene->mesh->rest[v].z - last[v].z;
		assert_true(drop > 1e-3 && drop < 5e-3);
	}
	free(path.positions);
	plume_scene_destroy(scene);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// A coat's feathers become entries: each meshed feather starts at its coat follicle.
static void test_coat_entry(void **state)
{
	(void)state;
	plume_scene *scene = load_text("{\"feathers\": [{\"coat\": \"" PLUME_SOURCE_DIR
	                               "/examples/coats/figure15-hexagonal.json\"}], \"mesh\": {\"edge_length\": 0.004, "
	                               "\"rachis_width_base\": 0.001, \"rachis_width_tip\": 0.0005}}");
	plume_spec_options options = {0};
	plume_coat *coat = NULL;
	plume_error err = {0};
	assert_int_equal(
	    plume_coat_spec_generate(PLUME_SOURCE_DIR "/examples/coats/figure15-hexagonal.json", &options, &coat, &err),
	    PLUME_OK);
	assert_int_equal(scene->feather_count, plume_coat_feather_count(coat));
	double worst = 0, worst_tip = 0;
	int vertices = 0;
	for (int k = 0; k < scene->feather_count; ++k) {
		char name[48];
		snprintf(name, sizeof name, "f%d/rachis_base", k);
		const plume_vertex_group *base = plume_mesh_find_group(scene->mesh, name);
		assert_non_null(base);
		plume_vec3 centre = {0, 0, 0}, root, normal;
		for (int i = 0; i < base->count; ++i)
			centre = plume_v3_add(centre, plume_v3_scale(scene->mesh->rest[base->vertices[i]], 1.0 / base->count));
		plume_coat_follicle(coat, k, &root, &normal);
		worst = fmax(worst, plume_v3_distance(centre, root));
		// The rotation too: the rachis tip row lies at the coat feather's shaft tip.
		snprintf(name, sizeof name, "f%d/rachis_tip", k);
		const plume_vertex_group *tip = plume_mesh_find_group(scene->mesh, name);
		centre = plume_v3(0, 0, 0);
		for (int i = 0; i < tip->count; ++i)
			centre = plume_v3_add(centre, plume_v3_scale(scene->mesh->rest[tip->vertices[i]], 1.0 / tip->count));
		const plume_feather *feather = plume_coat_feather(coat, k);
		plume_vec3 shaft_tip =
		    plume_feather_shaft(feather)[plume_feather_get_info(feather).shaft_sample_count - 1].position;
		worst_tip = fmax(worst_tip, plume_v3_distance(centre, shaft_tip));
		assert_int_equal(scene->feathers[k].vertex_offset, vertices);
		vertices += scene->feathers[k].vertex_count;
	}
	assert_int_equal(vertices, scene->mesh->vertex_count);
	printf("coat of %d feathers, %d vertices: the rachis base is at most %.3g m from its follicle, the rachis tip "
	       "%.3g m from the shaft's tip\n",
	       scene->feather_count, vertices, worst, worst_tip);
	assert_true(worst < 1e-3);
	assert_true(worst_tip < 2e-3);
	plume_coat_destroy(coat);
	plume_scene_destroy(scene);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// A sphere of radius 5 cm turning about z (30 degrees in 0.1 s) with a bone "crest" at its top
/// that nods about x (-20 degrees in 0.1 s); one feather rides on the crest, one on the body
/// as a whole (on its bottom pole). Their calamus vertices must follow, at every step,
/// Rz(theta) Rx(phi) (x - h) + h for the crest and Rz(theta) x for the body, computed here.
#define BODY                                                                                                           \
	"\"body\": {\"mesh\": {\"shape\": \"ellipsoid\", \"center\": [0, 0, 0], \"radii\": [0.05, 0.05, 0.05], "           \
	"\"segments\": 16}, \"keyframes\": [{\"time\": 0}, {\"time\": 0.1, \"rotation_axis\": [0, 0, 1], "                 \
	"\"rotation_deg\": 30}], \"bones\": [{\"name\": \"crest\", \"head\": [0, 0, 0.05], \"keyframes\": [{\"time\": "    \
	"0}, "                                                                                                             \
	"{\"time\": 0.1, \"rotation_axis\": [1, 0, 0], \"rotation_deg\": -20}]}]}"

static plume_vec3 turn_z(plume_vec3 p, double angle)
{
	return plume_v3(cos(angle) * p.x - sin(angle) * p.y, sin(angle) * p.x + cos(angle) * p.y, p.z);
}

static plume_vec3 turn_x(plume_vec3 p, double angle)
{
	return plume_v3(p.x, cos(angle) * p.y - sin(angle) * p.z, sin(angle) * p.y + cos(angle) * p.z);
}

static void test_follicles_follow_the_body(void **state)
{
	(void)state;
	plume_scene *scene = NULL;
	trajectory path = run_text("{" BODY ", \"feathers\": [{\"feather\": " BLUE ", \"position\": [0, 0, 0.05], "
	                           "\"follicle\": {\"bone\": \"crest\"}}, {\"feather\": " BLUE
	                           ", \"position\": [0, 0, -0.05], \"rotation_axis\": [1, 0, 0], \"rotation_deg\": 180, "
	                           "\"follicle\": {}}], \"mesh\": {\"edge_length\": 0.01}, \"gravity\": [0, 0, -9.81], "
	                           "\"duration\": 0.121}",
	                           &scene);
	assert_non_null(scene->body);
	assert_int_equal(scene->feathers[0].bone, 0);
	assert_int_equal(scene->feathers[1].bone, -1); // the body as a whole
	const plume_vertex_group *clamps[2] = {plume_mesh_find_group(scene->mesh, "f0/rachis_clamp"),
	                                       plume_mesh_find_group(scene->mesh, "f1/rachis_clamp")};
	const double degree = acos(-1.0) / 180, dt = scene->sim.time_step;
	double worst = 0;
	assert_int_equal(path.states, 12);
	for (int s = 0; s < path.states; ++s) {
		double t = s * dt, key = fmin(t / 0.1, 1.0); // linear keys, held after the last
		const plume_vec3 *x = path.positions + (size_t)s * (size_t)path.vertex_count;
		for (int f = 0; f < 2; ++f)
			for (int i = 0; i < clamps[f]->count; ++i) {
				int v = clamps[f]->vertices[i];
				plume_vec3 rest = scene->mesh->rest[v], expected;
				if (f == 0) {
					plume_vec3 head = plume_v3(0, 0, 0.05);
					expected = turn_z(plume_v3_add(turn_x(plume_v3_sub(rest, head), -20 * degree * key), head),
					                  30 * degree * key);
				} else {
					expected = turn_z(rest, 30 * degree * key);
				}
				worst = fmax(worst, plume_v3_distance(x[v], expected));
			}
	}
	printf("calamus vertices against the body's motion computed by hand: largest difference %.3g m\n", worst);
	assert_true(worst < 1e-12);
	free(path.positions);
	plume_scene_destroy(scene);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// Feathers that pass through each other at rest are refused with the pair and where
/// (plume_find_intersections, exact); one 1 mm above the other is fine.
static void test_rest_intersections(void **state)
{
	(void)state;
	plume_scene *scene = load_text("{\"feathers\": [{\"feather\": " HAWK "}, {\"feather\": " HAWK
	                               ", \"position\": [0, 0, 0.001]}], \"mesh\": {\"edge_length\": 0.01}}");
	assert_int_equal(scene->feather_count, 2);
	plume_scene_destroy(scene);
	// The second one turned a quarter about its shaft (+y) and lifted 5 cm along it: the two
	// vanes cross along the shaft line x = z = 0, from y = 5 cm up.
	char dir[512], path[1024];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/scene.json", dir);
	test_write_file(path, "{\"feathers\": [{\"feather\": " HAWK "}, {\"feather\": " HAWK
	                      ", \"name\": \"crossed\", \"position\": [0, 0.05, 0], \"rotation_axis\": [0, 1, 0], "
	                      "\"rotation_deg\": 90}], \"mesh\": {\"edge_length\": 0.01}}");
	plume_error err = {0};
	assert_int_equal(plume_scene_load(path, NULL, &scene, &err), PLUME_ERROR_SPEC);
	assert_null(scene);
	printf("%s\n", err.message);
	assert_non_null(strstr(err.message, "$.feathers: feathers \"f0\" and \"crossed\" intersect at rest: face "));
	double x, y, z;
	const char *near = strstr(err.message, "near (");
	assert_non_null(near);
	assert_int_equal(sscanf(near, "near (%lf, %lf, %lf)", &x, &y, &z), 3);
	// The midpoint of two crossing faces' centroids: within an edge length of the crossing line.
	assert_true(fabs(x) < 0.01 && fabs(z) < 0.01 && y > 0.04);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), 0);
}

/// "shaft" and "front" place a feather as the rotation that takes +y and +z to them: shaft +z,
/// front -y is a quarter turn about +x (y -> z, z -> -y), written the other way.
static void test_shaft_and_front(void **state)
{
	(void)state;
	plume_scene *turned = load_text("{\"feathers\": [{\"feather\": " BLUE ", \"position\": [0.1, 0.2, 0.3], "
	                                "\"rotation_axis\": [1, 0, 0], \"rotation_deg\": 90}]}");
	plume_scene *framed = load_text("{\"feathers\": [{\"feather\": " BLUE ", \"position\": [0.1, 0.2, 0.3], "
	                                "\"shaft\": [0, 0, 2], \"front\": [0, -1, 0.5]}]}");
	assert_int_equal(turned->mesh->vertex_count, framed->mesh->vertex_count);
	double worst = 0;
	for (int v = 0; v < turned->mesh->vertex_count; ++v)
		worst = fmax(worst, plume_v3_distance(turned->mesh->rest[v], framed->mesh->rest[v]));
	assert_true(worst < 1e-15);
	plume_scene_destroy(turned);
	plume_scene_destroy(framed);
	assert_int_equal(plume_bytes_in_use(), 0);
}

static void expect_error(const char *text, plume_status status, const char *message)
{
	char dir[512], path[1024];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/scene.json", dir);
	test_write_file(path, text);
	plume_scene *scene = NULL;
	plume_error err = {0};
	assert_int_equal(plume_scene_load(path, NULL, &scene, &err), status);
	assert_null(scene);
	if (strstr(err.message, message) == NULL)
		fail_msg("expected \"%s\" in \"%s\"", message, err.message);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), 0);
}

#define FEATHER                                                                                                        \
	"\"feather\": \"" PLUME_SOURCE_DIR "/examples/franco-walter/blue.json\", \"mesh\": {\"edge_length\": 0.01}"

/// The forces of a scene add up where their groups share vertices, as forces do: two forces
/// on the rachis tip move it as their sum does. Each replaced the load of the one before on
/// the vertices they shared (plume_sim_set_group_load), so only the last one pulled.
static void test_forces_add_up(void **state)
{
	(void)state;
#define PULLED "{\"feather\": " BLUE ", " SETTINGS ", \"forces\": ["
	trajectory two = run_text(PULLED "{\"group\": \"rachis_tip\", \"force\": [0, 0, 0.002]}, "
	                                 "{\"group\": \"rachis_tip\", \"force\": [0.001, 0, 0]}]}",
	                          NULL);
	trajectory sum = run_text(PULLED "{\"group\": \"rachis_tip\", \"force\": [0.001, 0, 0.002]}]}", NULL);
	trajectory last = run_text(PULLED "{\"group\": \"rachis_tip\", \"force\": [0.001, 0, 0]}]}", NULL);
#undef PULLED
	assert_int_equal(two.states, sum.states);
	double worst = 0, apart = 0;
	for (size_t i = 0; i < (size_t)two.states * (size_t)two.vertex_count; ++i) {
		worst = fmax(worst, plume_v3_length(plume_v3_sub(two.positions[i], sum.positions[i])));
		apart = fmax(apart, plume_v3_length(plume_v3_sub(sum.positions[i], last.positions[i])));
	}
	printf("two forces against their sum: %.3g m (their sum against the last alone: %.3g m)\n", worst, apart);
	assert_true(worst < 1e-10);
	assert_true(apart > 1e-6);
	free(two.positions);
	free(sum.positions);
	free(last.positions);
}

static void test_bad_scenes(void **state)
{
	(void)state;
	expect_error("{" FEATHER ", \"handles\": [{\"group\": \"rachis_bse\"}]}", PLUME_ERROR_SPEC,
	             "$.handles[0].group: unknown vertex group \"rachis_bse\"; did you mean \"rachis_base\"?");
	expect_error("{" FEATHER ", \"materials\": {\"vane\": {\"E_ww\": -5}}}", PLUME_ERROR_SPEC,
	             "$.materials.vane.E_ww is -5, allowed > 0");
	expect_error("{" FEATHER ", \"materials\": {\"rachis\": {\"thickness\": 0}}}", PLUME_ERROR_SPEC,
	             "$.materials.rachis.thickness is 0, allowed [1e-09, 1] m");
	expect_error("{" FEATHER ", \"time_step\": 0}", PLUME_ERROR_SPEC, "$.time_step is 0, allowed [1e-09, 100] s");
	expect_error("{" FEATHER ", \"time_step\": -0.01}", PLUME_ERROR_SPEC,
	             "$.time_step is -0.01, allowed [1e-09, 100] s");
	expect_error("{" FEATHER ", \"materials\": {\"vane\": {\"model\": \"orthotropc\"}}}", PLUME_ERROR_SPEC,
	             "did you mean \"orthotropic\"?");
	expect_error("{" FEATHER ", \"duraton\": 1}", PLUME_ERROR_SPEC, "duration");
	// A modulus of the other model was ignored unchecked.
	expect_error("{" FEATHER ", \"materials\": {\"vane\": {\"poisson_ratio\": -0.5}}}", PLUME_ERROR_SPEC,
	             "$.materials.vane.poisson_ratio: belongs to the isotropic model, and this material is orthotropic; "
	             "set \"model\": \"isotropic\"");
	expect_error("{" FEATHER ", \"materials\": {\"rachis\": {\"E_ww\": 1e5}}}", PLUME_ERROR_SPEC,
	             "$.materials.rachis.E_ww: belongs to the orthotropic model, and this material is isotropic");
	expect_error("{\"mesh\": {}}", PLUME_ERROR_SPEC, "exactly one of \"feather\"");
	expect_error("{" FEATHER
	             ", \"handles\": [{\"group\": \"rachis_tip\", \"keyframes\": [{\"time\": 1}, {\"time\": 0.5}]}]}",
	             PLUME_ERROR_SPEC, "keyframe times must be >= 0 and increasing");
	expect_error("{" FEATHER ", \"bending\": \"paper_hinge\"}", PLUME_ERROR_SPEC,
	             "$.bending: unknown value \"paper_hinge\"; did you mean \"paper-hinge\"? (allowed: fundamental-form, "
	             "paper-hinge)");
	expect_error("{" FEATHER ", \"bending\": 1}", PLUME_ERROR_SPEC,
	             "$.bending: expected true, false or a model's name (fundamental-form, paper-hinge), got a number");
	// A vertex follows one handle: two handles holding it were resolved by the later one.
	expect_error("{" FEATHER ", \"handles\": [{\"group\": \"rachis_clamp\"}, {\"group\": \"rachis\", \"keyframes\": "
	             "[{\"time\": 0}, {\"time\": 1, \"translation\": [0, 0, 0.01]}]}]}",
	             PLUME_ERROR_SPEC, "$.handles[1].group: \"rachis\" holds vertex ");
	expect_error("{" FEATHER ", \"handles\": [{\"group\": \"rachis_clamp\"}, {\"group\": \"rachis_clamp\"}]}",
	             PLUME_ERROR_SPEC, "which $.handles[0] (\"rachis_clamp\") holds too; a vertex follows one handle");
	// Many feathers.
	expect_error("{\"feathers\": [{\"feather\": " BLUE ", \"name\": \"wing\"}, {\"feather\": " BLUE
	             ", \"name\": \"wing\"}]}",
	             PLUME_ERROR_SPEC,
	             "$.feathers[1]: the feather name \"wing\" is also the name of $.feathers[0]; names must differ");
	expect_error("{\"feathers\": [{\"feather\": " BLUE "}, {\"feather\": " BLUE ", \"name\": \"f0\"}]}",
	             PLUME_ERROR_SPEC, "$.feathers[1]: the feather name \"f0\" is also the name of $.feathers[0]");
	expect_error("{\"feathers\": [{\"feather\": " BLUE ", \"name\": \"a/b\"}]}", PLUME_ERROR_SPEC,
	             "$.feathers[0].name: \"a/b\" is not a feather name");
	expect_error("{\"feathers\": [], \"feather\": " BLUE "}", PLUME_ERROR_SPEC,
	             "exactly one of \"feather\" (a feather spec), \"feathers\"");
	expect_error("{\"feathers\": []}", PLUME_ERROR_SPEC, "$.feathers: is empty");
	expect_error("{\"feathers\": [{\"position\": [0, 0, 0]}]}", PLUME_ERROR_SPEC,
	             "$.feathers[0]: an entry needs exactly one of \"feather\"");
	expect_error("{\"feathers\": [{\"feather\": " BLUE ", \"positon\": [0, 0, 0]}]}", PLUME_ERROR_SPEC,
	             "did you mean \"position\"");
	expect_error("{\"feathers\": [{\"feather\": " BLUE ", \"rotation_deg\": 10, \"rotation_axis\": [0, 0, 0]}]}",
	             PLUME_ERROR_SPEC, "$.feathers[0].rotation_axis: is the zero vector");
	// An axis alone placed the feather unturned, silently.
	expect_error("{\"feathers\": [{\"feather\": " BLUE ", \"rotation_axis\": [1, 0, 0]}]}", PLUME_ERROR_SPEC,
	             "$.feathers[0].rotation_axis: given without \"rotation_deg\"");
	expect_error("{\"feathers\": [{\"feather\": " BLUE "}, {\"feather\": " BLUE
	             ", \"position\": [0.1, 0, 0]}], \"handles\": [{\"group\": \"f2/rachis_clamp\"}]}",
	             PLUME_ERROR_SPEC, "$.handles[0].group: unknown vertex group \"f2/rachis_clamp\"");
	expect_error("{\"feathers\": [{\"feather\": " BLUE ", \"follicle\": {\"bone\": \"wrist\"}}]}", PLUME_ERROR_SPEC,
	             "$.feathers[0].follicle: the scene has no \"body\" to carry feather \"f0\"");
	expect_error("{" BODY ", \"feathers\": [{\"feather\": " BLUE ", \"position\": [0, 0, 0.06], \"follicle\": {}}]}",
	             PLUME_ERROR_SPEC,
	             "$.feathers[0].follicle: feather \"f0\"'s follicle (0, 0, 0.06) is 0.01 m from the body's rest "
	             "surface; allowed at most 0.001 m");
	expect_error("{" BODY ", \"feathers\": [{\"feather\": " BLUE
	             ", \"position\": [0, 0, 0.05], \"follicle\": {\"bone\": \"cret\"}}]}",
	             PLUME_ERROR_SPEC,
	             "$.feathers[0].follicle.bone: unknown bone \"cret\"; did you mean \"crest\"? (the body has: crest)");
	// An empty name followed the body as a whole, silently; a name past a bone's 31 bytes was cut
	// to them (and could then name another bone).
	expect_error("{" BODY ", \"feathers\": [{\"feather\": " BLUE
	             ", \"position\": [0, 0, 0.05], \"follicle\": {\"bone\": \"\"}}]}",
	             PLUME_ERROR_SPEC, "$.feathers[0].follicle.bone: \"\" is not a bone's name; allowed 1 to 31 bytes");
	expect_error("{" BODY ", \"feathers\": [{\"feather\": " BLUE
	             ", \"position\": [0, 0, 0.05], \"follicle\": {\"bone\": \"crest-crest-crest-crest-crest-crest\"}}]}",
	             PLUME_ERROR_SPEC,
	             "$.feathers[0].follicle.bone: \"crest-crest-crest-crest-crest-crest\" is not a bone's name");
	expect_error("{" BODY ", \"feathers\": [{\"feather\": " BLUE
	             ", \"position\": [0, 0, 0.05], \"follicle\": {}}], \"handles\": [{\"group\": \"rachis_clamp\"}]}",
	             PLUME_ERROR_SPEC, "$.handles[0].group: \"rachis_clamp\" holds feather \"f0\"'s calamus");
	expect_error("{\"body\": {\"mesh\": {\"shape\": \"ellipsoid\", \"radii\": [0.05, -1, 0.05]}}, \"feather\": " BLUE
	             "}",
	             PLUME_ERROR_SPEC, "$.body.mesh.radii");
	// Into the body: turned to point its shaft down (-z) from the top pole, through the sphere.
	expect_error("{" BODY ", \"feathers\": [{\"feather\": " BLUE
	             ", \"position\": [0, 0, 0.05], \"rotation_axis\": [1, 0, 0], \"rotation_deg\": -90, \"follicle\": "
	             "{}}]}",
	             PLUME_ERROR_SPEC, "$.feathers: feather \"f0\" passes through the body at rest: its face ");
	// Touching counts: a feather on the body that the body does not carry touches it at its calamus.
	expect_error("{" BODY ", \"feathers\": [{\"feather\": " BLUE ", \"position\": [0, 0, 0.05]}]}", PLUME_ERROR_SPEC,
	             "$.feathers: feather \"f0\" passes through the body at rest");
	expect_error("{\"feathers\": [{\"feather\": " BLUE ", \"shaft\": [0, 0, 1], \"front\": [0, 0, -2]}]}",
	             PLUME_ERROR_SPEC, "$.feathers[0].front: is along the shaft (or zero)");
	expect_error("{\"feathers\": [{\"feather\": " BLUE ", \"shaft\": [0, 0, 1]}]}", PLUME_ERROR_SPEC,
	             "$.feathers[0]: a feather is turned by \"shaft\" and \"front\" together");
	expect_error("{\"feathers\": [{\"feather\": " BLUE
	             ", \"shaft\": [0, 0, 1], \"front\": [0, 1, 0], \"rotation_deg\": 5}]}",
	             PLUME_ERROR_SPEC, "or by \"rotation_axis\" and \"rotation_deg\", not both");
	expect_error("{\"feathers\": [{\"coat\": \"missing-coat.json\"}]}", PLUME_ERROR_IO, "$.feathers[0].coat");
	expect_error("{" FEATHER ", \"cycle_period\": 0}", PLUME_ERROR_SPEC, "$.cycle_period: is 0, allowed > 0");
}

/// "bending": a model's name selects it (and bending stays on); true/false switch it.
static void test_bending_key(void **state)
{
	(void)state;
	const char *texts[4] = {"{" FEATHER "}", "{" FEATHER ", \"bending\": \"paper-hinge\"}",
	                        "{" FEATHER ", \"bending\": \"fundamental-form\"}", "{" FEATHER ", \"bending\": false}"};
	const plume_bending_model models[4] = {PLUME_BENDING_FUNDAMENTAL_FORM, PLUME_BENDING_PAPER_HINGE,
	                                       PLUME_BENDING_FUNDAMENTAL_FORM, PLUME_BENDING_FUNDAMENTAL_FORM};
	for (int k = 0; k < 4; ++k) {
		char dir[512], path[1024];
		test_make_temp_dir(dir, sizeof dir);
		snprintf(path, sizeof path, "%s/scene.json", dir);
		test_write_file(path, texts[k]);
		plume_scene *scene = NULL;
		plume_error err = {0};
		assert_int_equal(plume_scene_load(path, NULL, &scene, &err), PLUME_OK);
		assert_int_equal(scene->sim.bending_model, models[k]);
		assert_true(scene->sim.bending == (k != 3));
		plume_scene_destroy(scene);
		test_remove_tree(dir);
	}
	assert_int_equal(plume_bytes_in_use(), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_handle_pose_interpolation),
	    cmocka_unit_test(test_handle_pose_axis_of_a_key_without_rotation),
	    cmocka_unit_test(test_bad_scenes),
	    cmocka_unit_test(test_forces_add_up),
	    cmocka_unit_test(test_bending_key),
	    cmocka_unit_test(test_figure1_anisotropic_bends_the_rachis),
	    cmocka_unit_test(test_figure1_full_amplitude_buckles_without_collapse),
	    cmocka_unit_test(test_newton_through_buckling_on_a_finer_mesh),
	    cmocka_unit_test(test_retry_keeps_the_exact_hessian),
	    cmocka_unit_test(test_mesh_concatenate),
	    cmocka_unit_test(test_one_entry_list_is_the_single_feather_scene),
	    cmocka_unit_test(test_far_apart_feathers_do_not_interact),
	    cmocka_unit_test(test_prefixed_group_handle),
	    cmocka_unit_test(test_coat_entry),
	    cmocka_unit_test(test_follicles_follow_the_body),
	    cmocka_unit_test(test_rest_intersections),
	    cmocka_unit_test(test_shaft_and_front),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

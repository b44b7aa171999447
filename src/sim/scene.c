// Running a scene: handles follow their keyframes, each step is an implicit-Euler
// step (or a static solve for quasi-static scenes), and the caller sees every step.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <omp.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "plume/body.h"
#include "plume/scene.h"
#include "sim/body_internal.h"
#include "sim/scene_contact.h"

void plume_scene_destroy(plume_scene *scene)
{
	if (scene == NULL)
		return;
	if (scene->feathers != NULL) { // scene->feather is feathers[0]'s when there is one
		for (int i = 0; i < scene->feather_count; ++i)
			plume_feather_destroy(scene->feathers[i].feather);
		plume_free(scene->feathers);
	} else {
		plume_feather_destroy(scene->feather);
	}
	plume_mesh_destroy(scene->mesh);
	plume_body_destroy(scene->body);
	for (int h = 0; h < scene->handle_count; ++h)
		plume_free(scene->handles[h].keyframes);
	plume_free(scene->handles);
	plume_free(scene->forces);
	plume_free(scene);
}

void plume_scene_handle_pose(const plume_scene_handle *handle, double t, plume_vec3 *translation, plume_mat3 *rotation)
{
	// A handle's keys move as a body's (docs/body.md "Interpolation"): taking the nearer key's
	// axis turned a handle keyed from rest to a rotation about x about z for half the interval.
	plume_keyframes_pose(handle->keyframes, handle->keyframe_count, handle->interpolation, t, translation, rotation);
}

void plume_scene_body_pose(const plume_scene *scene, double t, plume_vec3 *out)
{
	PLUME_ASSERT(scene != NULL && scene->body != NULL && out != NULL);
	plume_body_pose(scene->body, t, out);
}

/// ids: the scene's handles, then one per feather carried by a follicle (-1 for the others).
static void pose_handles(const plume_scene *scene, plume_sim *sim, const int *ids, double t)
{
	for (int h = 0; h < scene->handle_count; ++h) {
		plume_vec3 translation;
		plume_mat3 rotation;
		plume_scene_handle_pose(scene->handles + h, t, &translation, &rotation);
		plume_sim_set_handle(sim, ids[h], translation, rotation, scene->handles[h].pivot);
	}
	// A follicle's bone maps a rest point x to R x + T (plume_body_bone_transform); the handle
	// maps its rest vertices to R (x - pivot) + pivot + translation: pivot 0, translation T.
	for (int i = 0; i < scene->feather_count; ++i) {
		int id = ids[scene->handle_count + i];
		if (id < 0)
			continue;
		plume_mat3 rotation;
		plume_vec3 translation;
		plume_body_bone_transform(scene->body, scene->feathers[i].bone, t, &rotation, &translation);
		plume_sim_set_handle(sim, id, translation, rotation, plume_v3(0, 0, 0));
	}
}

/// The handles of the feathers carried by the body: each one's "NAME/rachis_clamp".
static plume_status add_follicle_handles(const plume_scene *scene, plume_sim *sim, int *ids, plume_error *err)
{
	for (int i = 0; i < scene->feather_count; ++i) {
		ids[scene->handle_count + i] = -1;
		if (!scene->feathers[i].follicle)
			continue;
		char group[64];
		snprintf(group, sizeof group, "%s/rachis_clamp", scene->feathers[i].name);
		ids[scene->handle_count + i] = plume_sim_add_handle(sim, group, err);
		if (ids[scene->handle_count + i] < 0)
			return err != NULL ? err->status : PLUME_ERROR_SPEC;
	}
	return PLUME_OK;
}

static double rachis_tip_deflection(const plume_scene *scene, const plume_sim *sim)
{
	const plume_vertex_group *tip = plume_mesh_find_group(scene->mesh, "rachis_tip");
	if (tip == NULL || tip->count == 0)
		return 0;
	plume_vec3 sum = {0, 0, 0};
	for (int i = 0; i < tip->count; ++i) {
		int v = tip->vertices[i];
		sum = plume_v3_add(sum, plume_v3_sub(plume_sim_positions(sim)[v], scene->mesh->rest[v]));
	}
	return plume_v3_length(plume_v3_scale(sum, 1.0 / tip->count));
}

/// Whether a run checks its frames for intersecting surfaces: with contact, several feathers
/// or a body (a single free feather without contact has nothing to keep apart).
static bool checks_intersections(const plume_scene *scene)
{
	return scene->sim.contact.enabled || scene->feather_count > 1 || scene->body != NULL;
}

/// The independent check of one output frame (docs/contact.md): the count goes into the
/// summary as the largest over the frames; the first frame with a pair is named in the
/// summary's step.
static plume_status check_frame(plume_scene_surfaces *surfaces, const plume_sim *sim, const plume_vec3 *body_pose,
                                int step, plume_scene_summary *summary, plume_error *err)
{
	int count = 0, pair[2] = {-1, -1};
	plume_status status =
	    plume_scene_surfaces_intersections(surfaces, plume_sim_positions(sim), body_pose, &count, pair, err);
	if (status != PLUME_OK) {
		plume_error_prefix(err, "the intersection check");
		return status;
	}
	summary->intersections_checked = true;
	summary->frames_checked += 1;
	if (count > summary->intersecting_pairs)
		summary->intersecting_pairs = count;
	if (count > 0 && summary->first_intersecting_step < 0)
		summary->first_intersecting_step = step;
	return PLUME_OK;
}

/// A scene being run: its simulation, the handles' ids, the body's pose and the contact
/// surfaces, and the summary so far. plume_scene_run and the Python package both step a
/// scene through it, so a script sees exactly the run `plume simulate` makes.
struct plume_scene_runner {
	const plume_scene *scene;
	plume_sim *sim;
	/// The scene's handles, then one per feather carried by a follicle (-1 for the others).
	int *ids;
	/// The body's pose at the last step's time (contact takes it as an obstacle there), or NULL.
	plume_vec3 *body_positions;
	plume_scene_surfaces *surfaces;
	plume_scene_summary summary;
	int step_count; ///< the scene's steps: ceil(duration / time_step), at least 1
	double start;   ///< omp_get_wtime() at creation
};

void plume_scene_runner_destroy(plume_scene_runner *runner)
{
	if (runner == NULL)
		return;
	plume_scene_surfaces_destroy(runner->surfaces);
	plume_free(runner->body_positions);
	plume_free(runner->ids);
	plume_sim_destroy(runner->sim);
	plume_free(runner);
}

/// The handles, the loads, the summary's sizes, the contact surfaces and the check of the
/// initial frame.
static plume_status runner_begin(plume_scene_runner *runner, plume_error *err)
{
	const plume_scene *scene = runner->scene;
	plume_sim *sim = runner->sim;
	plume_scene_summary *summary = &runner->summary;
	plume_status status = PLUME_OK;
	for (int h = 0; h < scene->handle_count && status == PLUME_OK; ++h) {
		runner->ids[h] = plume_sim_add_handle(sim, scene->handles[h].group, err);
		if (runner->ids[h] < 0)
			status = err != NULL ? err->status : PLUME_ERROR_SPEC;
	}
	if (status == PLUME_OK)
		status = add_follicle_handles(scene, sim, runner->ids, err);
	for (int l = 0; l < scene->force_count && status == PLUME_OK; ++l)
		status = plume_sim_add_group_load(sim, scene->forces[l].group, scene->forces[l].force, err); // they add up
	summary->vertex_count = scene->mesh->vertex_count;
	summary->feather_count = scene->feather_count;
	summary->face_count = scene->mesh->face_count;
	summary->constraint_count = plume_sim_constraint_count(sim);
	summary->first_intersecting_step = -1;
	summary->min_distance = INFINITY;
	summary->contact_measured = scene->sim.contact.enabled;
	if (runner->body_positions != NULL)
		plume_scene_body_pose(scene, 0, runner->body_positions);
	if (status == PLUME_OK && (checks_intersections(scene) || scene->sim.contact.enabled))
		status = plume_scene_surfaces_create(scene, sim, runner->body_positions, &runner->surfaces, err);
	if (status == PLUME_OK && checks_intersections(scene))
		status = check_frame(runner->surfaces, sim, runner->body_positions, 0, summary, err);
	if (status != PLUME_OK)
		return status;
	// At least one step: a duration below 1e-9 of a step rounded to none, and the run wrote
	// frame 0 alone as a completed simulation.
	double step_count = fmax(1.0, ceil(scene->duration / scene->sim.time_step - 1e-9));
	if (!(step_count >= 0.0 && step_count <= PLUME_SCENE_MAX_STEPS))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "scene: duration %g s in steps of %g s is %.3g steps; "
		                       "allowed at most %d",
		                       scene->duration, scene->sim.time_step, step_count, PLUME_SCENE_MAX_STEPS);
	runner->step_count = (int)step_count;
	return PLUME_OK;
}

plume_status plume_scene_runner_create(const plume_scene *scene, plume_scene_runner **out, plume_error *err)
{
	PLUME_ASSERT(scene != NULL && out != NULL);
	*out = NULL;
	plume_scene_runner *runner = plume_calloc(1, sizeof *runner);
	if (runner == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory starting the scene");
	runner->scene = scene;
	runner->start = omp_get_wtime();
	plume_status status = plume_sim_create(scene->mesh, &scene->sim, &runner->sim, err);
	if (status != PLUME_OK) {
		plume_scene_runner_destroy(runner);
		return status;
	}
	runner->ids = plume_alloc(sizeof(int) * (size_t)(scene->handle_count + scene->feather_count + 1));
	if (scene->body != NULL)
		runner->body_positions = plume_alloc(sizeof(plume_vec3) * (size_t)plume_body_vertex_count(scene->body));
	if (runner->ids == NULL || (scene->body != NULL && runner->body_positions == NULL))
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory starting the scene");
	if (status == PLUME_OK)
		status = runner_begin(runner, err);
	if (status != PLUME_OK) {
		plume_scene_runner_destroy(runner);
		return status;
	}
	*out = runner;
	return PLUME_OK;
}

plume_sim *plume_scene_runner_sim(plume_scene_runner *runner)
{
	PLUME_ASSERT(runner != NULL);
	return runner->sim;
}

int plume_scene_runner_steps_done(const plume_scene_runner *runner)
{
	PLUME_ASSERT(runner != NULL);
	return runner->summary.steps;
}

int plume_scene_runner_step_count(const plume_scene_runner *runner)
{
	PLUME_ASSERT(runner != NULL);
	return runner->step_count;
}

const plume_vec3 *plume_scene_runner_body_positions(const plume_scene_runner *runner)
{
	PLUME_ASSERT(runner != NULL);
	return runner->body_positions;
}

plume_status plume_scene_runner_step(plume_scene_runner *runner, plume_solve_report *report, plume_error *err)
{
	PLUME_ASSERT(runner != NULL);
	const plume_scene *scene = runner->scene;
	plume_sim *sim = runner->sim;
	plume_scene_summary *summary = &runner->summary;
	int n = summary->steps + 1;
	double t = n * scene->sim.time_step;
	pose_handles(scene, sim, runner->ids, t);
	// The body where it is at the end of the step: with contact, the obstacle's positions
	// for this step (plume_sim_set_obstacle_positions; plume_sim_add_obstacle takes the
	// pose at t = 0 when the simulation is created).
	if (runner->body_positions != NULL) {
		plume_scene_body_pose(scene, t, runner->body_positions);
		plume_scene_surfaces_move_body(runner->surfaces, sim, runner->body_positions);
	}
	plume_solve_report local;
	if (report == NULL)
		report = &local;
	plume_status status =
	    scene->quasi_static ? plume_sim_solve_static(sim, report, err) : plume_sim_step(sim, report, err);
	if (status != PLUME_OK) {
		plume_error_prefix(err, scene->quasi_static ? "quasi-static solve" : "simulation");
		return status;
	}
	summary->steps = n;
	summary->newton_iterations += report->newton_iterations;
	summary->seconds_assembly += report->seconds_assembly;
	summary->seconds_factor += report->seconds_factor;
	summary->seconds_solve += report->seconds_solve;
	summary->seconds_contact += report->seconds_contact;
	summary->max_barb_strain = fmax(summary->max_barb_strain, report->max_barb_strain);
	summary->retried_steps += report->substeps > 1;
	if (scene->sim.contact.enabled) {
		summary->contact_pairs_max =
		    report->contact_pairs > summary->contact_pairs_max ? report->contact_pairs : summary->contact_pairs_max;
		summary->min_distance = fmin(summary->min_distance, report->min_distance);
	}
	if (checks_intersections(scene) && (n % scene->frame_every == 0 || n == runner->step_count))
		status = check_frame(runner->surfaces, sim, runner->body_positions, n, summary, err);
	return status;
}

void plume_scene_runner_summary(const plume_scene_runner *runner, plume_scene_summary *out)
{
	PLUME_ASSERT(runner != NULL && out != NULL);
	*out = runner->summary;
	out->rachis_tip_deflection = rachis_tip_deflection(runner->scene, runner->sim);
	out->wall_seconds = omp_get_wtime() - runner->start;
}

plume_status plume_scene_run(const plume_scene *scene, plume_scene_step_fn *on_step, void *user,
                             plume_scene_summary *summary, plume_error *err)
{
	memset(summary, 0, sizeof *summary);
	double start = omp_get_wtime();
	plume_scene_runner *runner = NULL;
	plume_status status = plume_scene_runner_create(scene, &runner, err);
	if (status != PLUME_OK)
		return status;
	plume_sim *sim = runner->sim;
	if (on_step != NULL)
		status = on_step(user, 0, 0, sim, NULL, omp_get_wtime() - start, err);
	for (int n = 1; n <= runner->step_count && status == PLUME_OK; ++n) {
		plume_solve_report report;
		double step_start = omp_get_wtime();
		status = plume_scene_runner_step(runner, &report, err);
		if (status == PLUME_OK && on_step != NULL)
			status = on_step(user, n, n * scene->sim.time_step, sim, &report, omp_get_wtime() - step_start, err);
	}
	plume_scene_runner_summary(runner, summary);
	summary->wall_seconds = omp_get_wtime() - start;
	plume_scene_runner_destroy(runner);
	return status;
}

// plume simulate SCENE.json -o DIR [--seed N] [--duration T] [--frames-every N] [--png] [--size WxH]
#define _POSIX_C_SOURCE 200809L
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "cli.h"

void cli_help_simulate(void)
{
	puts("Usage: plume simulate SCENE.json -o DIR [options]\n"
	     "\n"
	     "Simulates the feather a scene describes as an anisotropic elastic shell\n"
	     "(Jouve et al. 2024) and writes:\n"
	     "  DIR/mesh.obj          the rest shell (UVs, rachis and vane groups)\n"
	     "  DIR/feather.json      the generated feather (barb-level geometry; its numbers\n"
	     "                        in DIR/feather.bin, docs/feather-json.md)\n"
	     "  DIR/feathers/NAME.json  instead, for a scene that lists \"feathers\": each\n"
	     "                        distinct feather once, in its own frame; DIR/feathers.json\n"
	     "                        maps every feather to its dump and its placement\n"
	     "  DIR/frames/NNNN.obj   the shell at every written step (0000: the start); every\n"
	     "                        feather of the scene in one mesh\n"
	     "  DIR/body.obj, DIR/frames/body-NNNN.obj  the scene's body at rest and at every\n"
	     "                        written step, when it has one\n"
	     "  DIR/sim.glb           all frames as one animated glTF 2.0 file (morph\n"
	     "                        targets, animation \"simulation\"; Blender, three.js;\n"
	     "                        the body too, node \"body\")\n"
	     "  DIR/sim.usda          the same as USD text: time-sampled points (the body as\n"
	     "                        prim \"body\"; not the carried feathers of --glb-feather)\n"
	     "  DIR/frames/NNNN.png   a shaded view of each frame, with --png\n"
	     "  DIR/stats.csv         per step: time, Newton iterations, gradient norm,\n"
	     "                        energy, largest barb-edge strain, wall seconds, the\n"
	     "                        kinetic, elastic and gravitational energy (J), the\n"
	     "                        substeps (above 1 for a retried step), and\n"
	     "                        per handle N (in the scene's order) the reaction force\n"
	     "                        handleN_f{x,y,z} (N) and displacement handleN_d{x,y,z} (m)\n"
	     "  DIR/summary.json      steps, iterations, timings, largest barb strain,\n"
	     "                        rachis tip deflection, feather and vertex counts\n"
	     "Bad input writes nothing. If a step fails even with substeps, the frames\n"
	     "before it are kept, summary.json says where it stopped, and the exit\n"
	     "status is 1.\n"
	     "\n"
	     "Options:\n"
	     "  -o, --output DIR    output folder (created if missing)\n"
	     "  -s, --seed N        seed of the scene's feather (overrides the specs)\n"
	     "      --duration T    simulate T seconds instead of the scene's $.duration (> 0)\n"
	     "      --frames-every N  write every N-th step instead of the scene's\n"
	     "                      $.frame_every (N >= 1; the last step is always written)\n"
	     "      --png           also write a shaded PNG of every frame\n"
	     "      --size WxH      PNG size (default 800x800)\n"
	     "      --view AZ,EL    PNG camera azimuth about +y and elevation, degrees\n"
	     "                      (default 34,20; 0,0 looks at the vane face on)\n"
	     "      --render        ray-trace every frame at barb level (the feather's barbs\n"
	     "                      carried by the shell; every feather, and the body) to\n"
	     "                      frames/NNNN-rt.png, and make DIR/movie.mp4 when ffmpeg\n"
	     "                      is installed\n"
	     "      --spp N         samples per pixel of --render (default 4)\n"
	     "      --glb-feather   sim.glb also carries the feather's barbs (line segments\n"
	     "                      moved by the shell, one morph target per frame; every\n"
	     "                      feather of a list, node feather_NAME each; large:\n"
	     "                      about 12 bytes per barb point and frame)\n"
	     "      --fields        also write DIR/fields/NNNN.vtu and DIR/fields.pvd for\n"
	     "                      ParaView: per face Green strain and 2nd Piola-Kirchhoff\n"
	     "                      stress in the barb frame, barb angle, material, membrane,\n"
	     "                      compression and bending energy densities; per vertex\n"
	     "                      velocity and handle (docs/formats.md)\n"
	     "      --max-memory SIZE  refuse a run whose frames and sim.glb (with what writing it\n"
	     "                      holds) would pass SIZE bytes (default 4G); a sim.glb past\n"
	     "                      4 GiB or 65536 frames is refused too (docs/cli.md)\n"
	     "  -h, --help          this help\n"
	     "\n"
	     "Scenes are described in docs/scene.md; examples/scenes/ has ready ones.");
}

plume_raytrace_def cli_sequence_render_def(plume_vec3 lo, plume_vec3 hi, int width, int height, int spp)
{
	plume_raytrace_def def = plume_raytrace_default_def();
	def.camera.width = width;
	def.camera.height = height;
	def.spp = spp;
	def.camera = plume_camera_frame_bounds(&def.camera, lo, hi);
	return def;
}

typedef struct run_state {
	const plume_scene *scene;
	cli_output *output;
	FILE *stats;
	bool png;
	bool render;
	plume_raytrace_def render_def; ///< --render: the camera frames the whole sequence
	plume_shell_view_def view;
	int frames;
	int total_steps;
	bool progress;
	cli_progress bar; ///< the progress line (cli/progress.c)
	double max_strain;
	plume_mesh_animation *animation; ///< every frame, for DIR/sim.glb
	plume_mesh_obj_writer *obj;      ///< frames/NNNN.obj, the lines shared by all frames formatted once
	cli_writer *writer;              ///< writes the feather and the OBJ and PNG frames beside the run (cli/writer.c)
	bool fields;                     ///< --fields: DIR/fields/NNNN.vtu and DIR/fields.pvd
	bool glb_feather;                ///< --glb-feather: sim.glb also carries the feather
	plume_barb_embedding *carried;   ///< its embedding
	double *field_times;             ///< the time of every frame written, for the .pvd
	int field_capacity;
	const char *vane_base; ///< the group the vane's plane moves with (vane_base_group)
	double min_stretch;    ///< extremes over the steps, for summary.json (NaN: none yet)
	double max_out_of_plane;
	double max_kinetic;
	double max_elastic;
	double *max_reaction;                 ///< per handle: the largest |reaction|, N
	const char **handle_groups;           ///< per handle: its group, for plume_sim_group_reactions
	plume_vec3 *reactions;                ///< per handle: this step's reaction, N
	plume_vec3 *body_positions;           ///< the scene's body posed at a frame's time
	plume_mesh *body_mesh;                ///< the body at rest, for sim.glb
	plume_mesh_animation *body_animation; ///< the body's frames, node "body" of sim.glb
	cli_carried glb_carried;              ///< --glb-feather of many feathers: their embeddings
	cli_carried rendered;                 ///< --render: every feather and the body (cli/carry.c)
} run_state;

/// The body's rest mesh as a plume_mesh (for drawing and sim.glb), or NULL when memory runs out.
static plume_mesh *body_mesh(const plume_body *body)
{
	plume_mesh *mesh = plume_mesh_create(plume_body_vertex_count(body), plume_body_triangle_count(body));
	if (mesh != NULL) {
		memcpy(mesh->rest, plume_body_rest_positions(body), sizeof(plume_vec3) * (size_t)mesh->vertex_count);
		memcpy(mesh->faces, plume_body_triangles(body), sizeof(int) * 3 * (size_t)mesh->face_count);
	}
	return mesh;
}

/// Every feather of the scene embedded in its own faces of the joined shell (cli/carry.c, the
/// path `plume render` takes for the run folder), and the body when with_body.
static plume_status carry_feathers(const plume_scene *scene, bool with_body, cli_carried *carried, plume_error *err)
{
	const plume_feather **feathers = calloc((size_t)scene->feather_count, sizeof *feathers);
	int *faces = calloc(2 * (size_t)scene->feather_count, sizeof *faces);
	plume_mesh *body = with_body && scene->body != NULL ? body_mesh(scene->body) : NULL;
	plume_status status = PLUME_OK;
	if (feathers == NULL || faces == NULL || (with_body && scene->body != NULL && body == NULL))
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "simulate: out of memory");
	for (int i = 0; i < scene->feather_count && status == PLUME_OK; ++i) {
		feathers[i] = scene->feathers[i].feather;
		faces[2 * i] = scene->feathers[i].face_offset;
		faces[2 * i + 1] = scene->feathers[i].face_count;
	}
	if (status == PLUME_OK)
		status = cli_carried_begin(carried, scene->mesh, scene->feather_count, feathers, faces, false, body, err);
	plume_mesh_destroy(body);
	free(feathers);
	free(faces);
	return status;
}

plume_status cli_carry_scene(const plume_scene *scene, cli_carried *carried, plume_error *err)
{
	return carry_feathers(scene, true, carried, err);
}

/// Every feather carried by the shell at positions, and the body posed at time, to path (PNG).
static plume_status render_frame(run_state *run, const plume_vec3 *positions, double time, const char *path,
                                 plume_error *err)
{
	if (run->scene->body != NULL)
		plume_scene_body_pose(run->scene, time, run->body_positions);
	plume_raytrace_scene picture;
	plume_status status = cli_carried_pose(&run->rendered, positions,
	                                       run->scene->body != NULL ? run->body_positions : NULL, &picture, err);
	if (status == PLUME_OK)
		status = plume_raytrace_render_png(&picture, &run->render_def, path, NULL, err);
	return status;
}

/// The body at the given positions as Wavefront OBJ (object "body", metres), for renders.
static plume_status write_body_obj(const plume_body *body, const plume_vec3 *positions, const char *path,
                                   plume_error *err)
{
	FILE *file = fopen(path, "wb");
	if (file == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	fputs("o body\n", file);
	for (int v = 0; v < plume_body_vertex_count(body); ++v)
		fprintf(file, "v %.17g %.17g %.17g\n", positions[v].x, positions[v].y, positions[v].z);
	const int *triangles = plume_body_triangles(body);
	for (int f = 0; f < plume_body_triangle_count(body); ++f)
		fprintf(file, "f %d %d %d\n", triangles[3 * f] + 1, triangles[3 * f + 1] + 1, triangles[3 * f + 2] + 1);
	if (fclose(file) != 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	return PLUME_OK;
}

/// A job of the background writer: files from a copy of the positions they need (the
/// simulator moves on while they are written).
typedef enum write_kind {
	WRITE_FEATHER, ///< the feather's dump (feather.json + feather.bin)
	WRITE_SHELL,   ///< a frame of the shell: its OBJ, and with --png its shaded view
	WRITE_BODY,    ///< a frame of the body: its OBJ
} write_kind;

typedef struct write_job {
	write_kind kind;
	char path[4352];                  ///< the file (the OBJ for a frame)
	char png_path[4352];              ///< WRITE_SHELL with --png: the shaded view; "" without
	const plume_feather *feather;     ///< WRITE_FEATHER
	const plume_mesh_obj_writer *obj; ///< WRITE_SHELL: the OBJ writer of the scene's mesh
	const plume_mesh *mesh;           ///< WRITE_SHELL with --png: the scene's mesh
	const plume_shell_view_def *view; ///< and the view
	const plume_body *body;           ///< WRITE_BODY
	plume_vec3 *positions;            ///< the frame's (owned by the job); NULL for the feather
} write_job;

static plume_status write_shell_frame(const write_job *job, plume_error *err)
{
	plume_status status = plume_mesh_obj_writer_write(job->obj, job->positions, job->path, err);
	if (status == PLUME_OK && job->png_path[0] != '\0')
		status = plume_render_shell_png(job->mesh, job->positions, job->view, job->png_path, err);
	return status;
}

static plume_status run_write_job(void *data, plume_error *err)
{
	const write_job *job = data;
	switch (job->kind) {
	case WRITE_FEATHER: return plume_write_json_binary(job->feather, job->path, err);
	case WRITE_SHELL: return write_shell_frame(job, err);
	case WRITE_BODY: return write_body_obj(job->body, job->positions, job->path, err);
	}
	return PLUME_OK; // unreachable: every kind is handled above
}

static void release_write_job(void *data)
{
	write_job *job = data;
	if (job != NULL)
		free(job->positions);
	free(job);
}

/// Hands job to the background writer, with a copy of count positions from job->positions
/// (none for the feather's dump).
static plume_status submit_write(run_state *run, const write_job *job, int count, plume_error *err)
{
	write_job *copy = malloc(sizeof *copy);
	if (copy != NULL) {
		*copy = *job;
		copy->positions = NULL;
		if (count > 0 && (copy->positions = malloc(sizeof(plume_vec3) * (size_t)count)) != NULL)
			memcpy(copy->positions, job->positions, sizeof(plume_vec3) * (size_t)count);
	}
	if (copy == NULL || (count > 0 && copy->positions == NULL)) {
		release_write_job(copy);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", job->path);
	}
	cli_writer_submit(run->writer, run_write_job, release_write_job, copy);
	return PLUME_OK;
}

// time: the scene's time of the step (plume_sim_time stays 0 in quasi-static scenes,
// whose keyframed handles still move with it).
static plume_status write_frame(run_state *run, int frame, double time, const plume_sim *sim, plume_error *err)
{
	char name[64], path[4352];
	// The shell's OBJ and --png view: one job, from one copy of the positions.
	write_job job = {.kind = WRITE_SHELL,
	                 .obj = run->obj,
	                 .mesh = run->scene->mesh,
	                 .view = &run->view,
	                 .positions = (plume_vec3 *)plume_sim_positions(sim)};
	snprintf(name, sizeof name, "frames/%04d.obj", frame);
	cli_output_path(run->output, name, job.path, sizeof job.path);
	if (run->png) {
		snprintf(name, sizeof name, "frames/%04d.png", frame);
		cli_output_path(run->output, name, job.png_path, sizeof job.png_path);
	}
	plume_status status = submit_write(run, &job, plume_sim_vertex_count(sim), err);
	if (status == PLUME_OK && run->scene->body != NULL) {
		plume_scene_body_pose(run->scene, time, run->body_positions);
		job = (write_job){.kind = WRITE_BODY, .body = run->scene->body, .positions = run->body_positions};
		snprintf(name, sizeof name, "frames/body-%04d.obj", frame);
		cli_output_path(run->output, name, job.path, sizeof job.path);
		status = submit_write(run, &job, plume_body_vertex_count(run->scene->body), err);
	}
	if (status == PLUME_OK)
		status = plume_mesh_animation_add_frame(run->animation, time, plume_sim_positions(sim), err);
	if (status == PLUME_OK && run->body_animation != NULL) // body_positions posed above
		status = plume_mesh_animation_add_frame(run->body_animation, time, run->body_positions, err);
	if (status == PLUME_OK && run->fields) {
		if (frame >= run->field_capacity) {
			int capacity = run->field_capacity > 0 ? 2 * run->field_capacity : 64;
			double *times = realloc(run->field_times, (size_t)capacity * sizeof *times);
			if (times == NULL)
				return plume_error_set(err, PLUME_ERROR_MEMORY, "fields: out of memory");
			run->field_times = times;
			run->field_capacity = capacity;
		}
		run->field_times[frame] = time;
		status = cli_fields_write_frame(run->output, run->scene, sim, frame, err);
	}
	if (status == PLUME_OK && run->render) {
		snprintf(name, sizeof name, "frames/%04d-rt.png", frame);
		cli_output_path(run->output, name, path, sizeof path);
		status = render_frame(run, plume_sim_positions(sim), time, path, err);
	}
	run->frames = frame + 1;
	return status;
}

/// Per handle: the reaction force it applies (N) and its displacement (the pose's
/// translation, m) at this step, appended to the stats row.
static void write_handle_columns(run_state *run, double time, const plume_sim *sim)
{
	// plume_scene_run hands its own (non-const) simulator to the callback as const; the
	// reactions only re-evaluate forces at the current state and change nothing it reports.
	// One evaluation for every handle (cli_simulate: handle_groups).
	int count = run->scene->handle_count;
	for (int h = 0; h < count; ++h)
		run->reactions[h] = (plume_vec3){NAN, NAN, NAN};
	if (count > 0)
		plume_sim_group_reactions((plume_sim *)sim, run->handle_groups, count, run->reactions);
	for (int h = 0; h < count; ++h) {
		const plume_scene_handle *handle = &run->scene->handles[h];
		plume_vec3 force = run->reactions[h], translation;
		plume_mat3 rotation;
		run->max_reaction[h] = fmax(run->max_reaction[h], plume_v3_length(force));
		plume_scene_handle_pose(handle, time, &translation, &rotation);
		fprintf(run->stats, ",%.9e,%.9e,%.9e,%.9g,%.9g,%.9g", force.x, force.y, force.z, translation.x, translation.y,
		        translation.z);
	}
}

static void show_progress(run_state *run, int step, double time)
{
	char note[64];
	if (run->scene->feather_count > 1)
		snprintf(note, sizeof note, "t = %.3f s, %d feathers", time, run->scene->feather_count);
	else
		snprintf(note, sizeof note, "t = %.3f s", time);
	cli_progress_update_note(&run->bar, step, note);
}

static plume_status on_step(void *user, int step, double time, const plume_sim *sim, const plume_solve_report *report,
                            double wall_seconds, plume_error *err)
{
	run_state *run = user;
	plume_status written = cli_writer_status(run->writer, err);
	if (written != PLUME_OK)
		return written; // a frame or the feather could not be written: stop here
	if (report != NULL) {
		// The energies of the state (docs/simulation.md): kinetic, elastic (membrane, compression,
		// bending), gravitational (with the scene's constant forces), and contact's barrier and
		// friction potential. Like the reactions, they re-evaluate the const simulator's state and
		// change nothing it reports.
		plume_sim_energies e = plume_sim_energy((plume_sim *)sim);
		double elastic = e.membrane + e.compression + e.bending;
		plume_sim_vane_shape vane = plume_sim_vane_shape_measure(sim, run->vane_base);
		fprintf(run->stats, "%.9g,%d,%.6e,%.12e,%.6e,%.6f,%.9e,%.9e,%.9e,%.9e,%.9e,%.9g,%.9e", time,
		        report->newton_iterations, report->gradient_norm, report->energy, report->max_barb_strain, wall_seconds,
		        e.kinetic, elastic, e.gravity, e.contact, e.friction, vane.min_principal_stretch,
		        vane.max_out_of_plane);
		fprintf(run->stats, ",%d", report->substeps); // 1, or 2, 4, ... for a retried step
		// fmin/fmax skip NaN: a measure that is never defined stays NaN (null in summary.json).
		run->min_stretch = fmin(run->min_stretch, vane.min_principal_stretch);
		run->max_out_of_plane = fmax(run->max_out_of_plane, vane.max_out_of_plane);
		run->max_kinetic = fmax(run->max_kinetic, e.kinetic);
		run->max_elastic = fmax(run->max_elastic, elastic);
		write_handle_columns(run, time, sim);
		fputc('\n', run->stats);
		run->max_strain = fmax(run->max_strain, report->max_barb_strain);
	}
	if (run->progress)
		show_progress(run, step, time);
	bool last = step == run->total_steps;
	if (step % run->scene->frame_every == 0 || last)
		return write_frame(run, run->frames, time, sim, err);
	return PLUME_OK;
}

void cli_scene_bounds(const plume_scene *scene, plume_vec3 *lo, plume_vec3 *hi)
{
	const plume_mesh *mesh = scene->mesh;
	*lo = *hi = mesh->rest[0];
	for (int i = 1; i < mesh->vertex_count; ++i) {
		plume_vec3 p = mesh->rest[i];
		*lo = plume_v3(fmin(lo->x, p.x), fmin(lo->y, p.y), fmin(lo->z, p.z));
		*hi = plume_v3(fmax(hi->x, p.x), fmax(hi->y, p.y), fmax(hi->z, p.z));
	}
	double reach = 0;
	for (int h = 0; h < scene->handle_count; ++h)
		for (int k = 0; k < scene->handles[h].keyframe_count; ++k)
			reach = fmax(reach, plume_v3_length(scene->handles[h].keyframes[k].translation));
	double pad = fmax(reach, 0.1 * plume_v3_length(plume_v3_sub(*hi, *lo)));
	// A handle that turns the feather takes it out of that box (a clamp turned 180 degrees
	// about z showed the calamus alone): the rest box's corners as each handle carries them,
	// at 64 times over the run and at every key, are in the picture too.
	plume_vec3 rest_lo = *lo, rest_hi = *hi;
	*lo = plume_v3(lo->x - pad, lo->y - pad, lo->z - pad);
	*hi = plume_v3(hi->x + pad, hi->y + pad, hi->z + pad);
	for (int h = 0; h < scene->handle_count; ++h) {
		const plume_scene_handle *handle = scene->handles + h;
		for (int j = 0; j <= 64 + handle->keyframe_count; ++j) {
			double t = j <= 64 ? scene->duration * j / 64 : handle->keyframes[j - 65].time;
			plume_vec3 translation;
			plume_mat3 rotation;
			plume_scene_handle_pose(handle, t, &translation, &rotation);
			// A translation alone stays within the box above (its reach is in pad): unchanged.
			double margin = memcmp(&rotation, &(plume_mat3){{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, sizeof rotation) != 0
			                    ? 0.1 * plume_v3_length(plume_v3_sub(rest_hi, rest_lo))
			                    : 0;
			for (int c = 0; c < 8; ++c) {
				plume_vec3 corner = plume_v3(c & 1 ? rest_hi.x : rest_lo.x, c & 2 ? rest_hi.y : rest_lo.y,
				                             c & 4 ? rest_hi.z : rest_lo.z);
				plume_vec3 arm = plume_m3_apply(rotation, plume_v3_sub(corner, handle->pivot));
				plume_vec3 p = plume_v3_add(plume_v3_add(handle->pivot, arm), translation);
				*lo = plume_v3(fmin(lo->x, p.x - margin), fmin(lo->y, p.y - margin), fmin(lo->z, p.z - margin));
				*hi = plume_v3(fmax(hi->x, p.x + margin), fmax(hi->y, p.y + margin), fmax(hi->z, p.z + margin));
			}
		}
	}
}

/// The group whose rigid motion carries the rest vane's plane for vane_max_out_of_plane: the
/// rachis clamp (the first two rows of rachis vertices at the calamus) when the mesh has it,
/// else the first handle's group (docs/simulation.md). Many feathers have no one vane plane:
/// a group the mesh lacks leaves the measure undefined (NaN, null in summary.json).
static const char *vane_base_group(const plume_scene *scene)
{
	if (scene->feather_count > 1)
		return "";
	if (plume_mesh_find_group(scene->mesh, "rachis_clamp") != NULL || scene->handle_count == 0)
		return "rachis_clamp";
	return scene->handles[0].group;
}

/// A JSON number, or null for NaN (a measure never defined in the run).
static json_t *json_measure(double value) { return !isfinite(value) ? json_null() : json_real(value); }

static plume_status write_summary(cli_output *output, const plume_scene *scene, const plume_scene_summary *summary,
                                  const run_state *run, const plume_error *failure, plume_error *err)
{
	json_t *root = json_object();
	json_object_set_new(root, "completed", json_boolean(failure == NULL));
	if (failure != NULL) {
		json_object_set_new(root, "error", json_string(failure->message));
		// Where it stopped: the first step that did not converge, and its time.
		json_object_set_new(root, "failed_step", json_integer(summary->steps + 1));
		json_object_set_new(root, "failed_time", json_real((summary->steps + 1) * scene->sim.time_step));
	}
	json_object_set_new(root, "steps", json_integer(summary->steps));
	json_object_set_new(root, "frames", json_integer(run->frames));
	json_object_set_new(root, "time", json_real(summary->steps * scene->sim.time_step));
	json_object_set_new(root, "newton_iterations", json_integer(summary->newton_iterations));
	json_object_set_new(root, "newton_iterations_per_step",
	                    json_real(summary->steps > 0 ? (double)summary->newton_iterations / summary->steps : 0));
	json_object_set_new(root, "retried_steps", json_integer(summary->retried_steps));
	json_object_set_new(root, "wall_seconds", json_real(summary->wall_seconds));
	json_object_set_new(root, "seconds_assembly", json_real(summary->seconds_assembly));
	json_object_set_new(root, "seconds_factorization", json_real(summary->seconds_factor));
	json_object_set_new(root, "seconds_solve", json_real(summary->seconds_solve));
	json_object_set_new(root, "seconds_contact", json_real(summary->seconds_contact));
	json_object_set_new(root, "max_barb_strain", json_real(summary->max_barb_strain));
	json_object_set_new(root, "rachis_tip_deflection", json_real(summary->rachis_tip_deflection));
	json_object_set_new(root, "vertices", json_integer(summary->vertex_count));
	json_object_set_new(root, "vertex_count", json_integer(summary->vertex_count));
	json_object_set_new(root, "feather_count", json_integer(scene->feather_count));
	json_object_set_new(root, "duration", json_real(scene->duration));
	// The cost of one cycle of a cyclic scene: the wall time over the cycles simulated, the
	// steps' time (the duration asked for, which the last step may pass, was not what ran).
	double simulated = summary->steps * scene->sim.time_step;
	if (scene->cycle_period > 0) {
		json_object_set_new(root, "cycle_period", json_real(scene->cycle_period));
		if (simulated > 0)
			json_object_set_new(root, "seconds_per_cycle",
			                    json_real(summary->wall_seconds / (simulated / scene->cycle_period)));
	}
	// Written only by runs that measure them (contact, the independent intersection check).
	if (summary->contact_measured) {
		json_object_set_new(root, "contact_pairs_max", json_integer(summary->contact_pairs_max));
		json_object_set_new(root, "min_distance", json_measure(summary->min_distance));
	}
	if (summary->intersections_checked) {
		json_object_set_new(root, "intersecting_pairs", json_integer(summary->intersecting_pairs));
		json_object_set_new(root, "frames_checked", json_integer(summary->frames_checked));
		json_object_set_new(root, "first_intersecting_step",
		                    summary->first_intersecting_step >= 0 ? json_integer(summary->first_intersecting_step)
		                                                          : json_null());
	}
	json_t *feathers = json_array();
	for (int i = 0; i < scene->feather_count; ++i) {
		const plume_scene_feather *f = scene->feathers + i;
		json_t *entry = json_object();
		json_object_set_new(entry, "name", json_string(f->name));
		json_object_set_new(entry, "vertex_offset", json_integer(f->vertex_offset));
		json_object_set_new(entry, "vertex_count", json_integer(f->vertex_count));
		json_object_set_new(entry, "face_offset", json_integer(f->face_offset));
		json_object_set_new(entry, "face_count", json_integer(f->face_count));
		json_array_append_new(feathers, entry);
	}
	json_object_set_new(root, "feathers", feathers);
	json_object_set_new(root, "faces", json_integer(summary->face_count));
	json_object_set_new(root, "barb_constraints", json_integer(summary->constraint_count));
	json_object_set_new(root, "vane_min_principal_stretch", json_measure(run->min_stretch));
	json_object_set_new(root, "vane_max_out_of_plane", json_measure(run->max_out_of_plane));
	json_object_set_new(root, "max_kinetic_energy", json_measure(run->max_kinetic));
	json_object_set_new(root, "max_elastic_energy", json_measure(run->max_elastic));
	json_t *reactions = json_array();
	for (int h = 0; h < scene->handle_count; ++h)
		json_array_append_new(reactions, json_real(run->max_reaction[h]));
	json_object_set_new(root, "handle_max_reaction", reactions);
	json_object_set_new(root, "mesh_min_angle_deg", json_real(scene->mesh_report.min_angle * 180 / acos(-1.0)));
	// null when every vane face is a junction face, as mesh's report.json (plume_mesh_report holds pi).
	int vane_faces = 0;
	for (int f = 0; f < scene->mesh->face_count; ++f)
		vane_faces += scene->mesh->material[f] == PLUME_MATERIAL_VANE;
	json_object_set_new(root, "mesh_vane_min_angle_deg",
	                    vane_faces > scene->mesh_report.excepted_count
	                        ? json_real(scene->mesh_report.vane_min_angle * 180 / acos(-1.0))
	                        : json_null());
	json_object_set_new(root, "mesh_excepted_count", json_integer(scene->mesh_report.excepted_count));
	json_object_set_new(root, "mesh_aligned_fraction", json_real(scene->mesh_report.aligned_fraction));
	json_object_set_new(root, "mesh_guides_dropped", json_integer(scene->mesh_report.guides_dropped));
	char path[4352];
	cli_output_path(output, "summary.json", path, sizeof path);
	int failed = json_dump_file(root, path, JSON_INDENT(2) | JSON_REAL_PRECISION(10));
	json_decref(root);
	if (failed != 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write the summary", path);
	return PLUME_OK;
}

/// DIR/movie.mp4 from the ray-traced frames when ffmpeg is on the PATH (never required:
/// without it, or if it fails, the frames are the result).
static void make_movie(cli_output *output)
{
	// The path goes into a shell command in single quotes: a quote in it cannot.
	if (strchr(output->stage, '\'') != NULL || system("command -v ffmpeg >/dev/null 2>&1") != 0)
		return;
	char command[9000];
	snprintf(command, sizeof command,
	         "ffmpeg -loglevel error -y -framerate 30 -i '%s/frames/%%04d-rt.png' -pix_fmt yuv420p "
	         "-vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' '%s/movie.mp4' </dev/null",
	         output->stage, output->stage);
	if (system(command) != 0) {
		char path[4352];
		snprintf(path, sizeof path, "%s/movie.mp4", output->stage);
		remove(path);
	}
}

/// A scene that lists "feathers": each distinct feather once, in its own frame, as
/// DIR/feathers/NAME.json (and NAME.bin; NAME: the first feather of that geometry), and
/// DIR/feathers.json mapping every feather to its dump and its placement
/// (docs/scene.md "Outputs"). Copies of one spec differ only by their placement: in their
/// own frame they agree to rounding (1e-9 m is far above it and far below any real difference).
static plume_status write_feathers(const plume_scene *scene, cli_output *output, plume_error *err)
{
	char path[4352], name[64];
	snprintf(path, sizeof path, "%s/feathers", output->stage);
	if (mkdir(path, 0777) != 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot create: %s", path, "mkdir failed");
	const int n = scene->feather_count;
	plume_feather **own = calloc((size_t)n, sizeof *own); // per feather in its own frame; NULL: guides or a copy
	int *dump = calloc((size_t)n, sizeof *dump);          // per feather: the feather whose dump it uses
	json_t *index = json_object(), *list = json_array();
	json_object_set_new(index, "version", json_integer(1));
	json_object_set(index, "feathers", list);
	plume_status status = own != NULL && dump != NULL && index != NULL && list != NULL
	                          ? PLUME_OK
	                          : plume_error_set(err, PLUME_ERROR_MEMORY, "simulate: out of memory");
	for (int i = 0; i < n && status == PLUME_OK; ++i) {
		const plume_scene_feather *f = scene->feathers + i;
		json_t *entry =
		    json_pack("{s:s, s:i, s:i, s:i, s:i}", "name", f->name, "vertex_offset", f->vertex_offset, "vertex_count",
		              f->vertex_count, "face_offset", f->face_offset, "face_count", f->face_count);
		json_array_append_new(list, entry);
		if (f->feather == NULL)
			continue;
		// Back to its own frame: own = R^T (world - t).
		own[i] = plume_feather_clone(f->feather);
		if (own[i] == NULL) {
			status = plume_error_set(err, PLUME_ERROR_MEMORY, "simulate: out of memory");
			break;
		}
		plume_mat3 back = plume_m3_transpose(f->rotation);
		plume_feather_move(own[i], back, plume_v3_scale(plume_m3_apply(back, f->translation), -1.0));
		dump[i] = i;
		for (int k = 0; k < i; ++k)
			if (own[k] != NULL && plume_feather_distance(own[k], own[i]) <= 1e-9) {
				dump[i] = k;
				break;
			}
		json_t *rotation = json_array(),
		       *translation = json_pack("[f, f, f]", f->translation.x, f->translation.y, f->translation.z);
		for (int r = 0; r < 9; ++r)
			json_array_append_new(rotation, json_real(f->rotation.m[r / 3][r % 3]));
		snprintf(name, sizeof name, "%s.json", scene->feathers[dump[i]].name);
		json_object_set_new(entry, "dump", json_string(name));
		json_object_set_new(entry, "rotation", rotation);
		json_object_set_new(entry, "translation", translation);
		if (dump[i] != i) {
			plume_feather_destroy(own[i]);
			own[i] = NULL;
			continue;
		}
		snprintf(name, sizeof name, "feathers/%s.json", f->name);
		status = plume_write_json_binary(own[i], cli_output_path(output, name, path, sizeof path), err);
	}
	if (status == PLUME_OK && json_dump_file(index, cli_output_path(output, "feathers.json", path, sizeof path),
	                                         JSON_INDENT(1) | JSON_REAL_PRECISION(17)) != 0)
		status = plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	for (int i = 0; i < n && own != NULL; ++i)
		plume_feather_destroy(own[i]);
	free(own);
	free(dump);
	json_decref(list);
	json_decref(index);
	return status;
}

/// Writes the rest shell and the feather, then runs the scene into frames/ and stats.csv.
/// The feather's dump and the OBJ and --png frames go to run->writer, which may still be
/// writing them when this returns.
static plume_status run_scene(const plume_scene *scene, cli_output *output, run_state *run,
                              plume_scene_summary *summary, plume_error *failure, plume_error *err)
{
	char path[4352];
	plume_status status =
	    plume_mesh_write_obj(scene->mesh, NULL, cli_output_path(output, "mesh.obj", path, sizeof path), err);
	if (status == PLUME_OK && scene->feather != NULL) { // the largest file: written beside the run
		write_job job = {.kind = WRITE_FEATHER, .feather = scene->feather};
		cli_output_path(output, "feather.json", job.path, sizeof job.path);
		status = submit_write(run, &job, 0, err);
	} else if (status == PLUME_OK)
		status = write_feathers(scene, output, err);
	if (status == PLUME_OK && scene->body != NULL) {
		run->body_positions = malloc(sizeof(plume_vec3) * (size_t)plume_body_vertex_count(scene->body));
		if (run->body_positions == NULL)
			return plume_error_set(err, PLUME_ERROR_MEMORY, "simulate: out of memory");
		status = write_body_obj(scene->body, plume_body_rest_positions(scene->body),
		                        cli_output_path(output, "body.obj", path, sizeof path), err);
	}
	if (status != PLUME_OK)
		return status;
	snprintf(path, sizeof path, "%s/frames", output->stage);
	status = plume_mesh_animation_create(scene->mesh, NULL, &run->animation, err);
	if (status == PLUME_OK)
		status = plume_mesh_obj_writer_create(scene->mesh, &run->obj, err);
	if (status == PLUME_OK && run->glb_feather && scene->feather != NULL) {
		status = plume_embedding_create(scene->feather, scene->mesh, &run->carried, err);
		if (status == PLUME_OK)
			plume_mesh_animation_set_feather(run->animation, run->carried);
	} else if (status == PLUME_OK && run->glb_feather) { // many feathers: node feather_NAME each
		status = carry_feathers(scene, false, &run->glb_carried, err);
		for (int i = 0; i < scene->feather_count && status == PLUME_OK; ++i)
			if (run->glb_carried.embeddings[i] != NULL)
				status = plume_mesh_animation_add_feather(run->animation, run->glb_carried.embeddings[i],
				                                          scene->feathers[i].name, err);
	}
	if (status == PLUME_OK && scene->body != NULL) { // the body moves in sim.glb too
		run->body_mesh = body_mesh(scene->body);
		status = run->body_mesh != NULL ? plume_mesh_animation_create(run->body_mesh, NULL, &run->body_animation, err)
		                                : plume_error_set(err, PLUME_ERROR_MEMORY, "simulate: out of memory");
		if (status == PLUME_OK)
			plume_mesh_animation_set_body(run->animation, run->body_animation);
	}
	if (status != PLUME_OK)
		return status;
	if (mkdir(path, 0777) != 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot create: %s", path, "mkdir failed");
	snprintf(path, sizeof path, "%s/fields", output->stage);
	if (run->fields && mkdir(path, 0777) != 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot create: %s", path, "mkdir failed");
	run->vane_base = vane_base_group(scene);
	run->min_stretch = run->max_out_of_plane = run->max_kinetic = run->max_elastic = NAN;
	size_t handles = (size_t)(scene->handle_count > 0 ? scene->handle_count : 1);
	run->max_reaction = calloc(handles, sizeof *run->max_reaction);
	run->handle_groups = calloc(handles, sizeof *run->handle_groups);
	run->reactions = calloc(handles, sizeof *run->reactions);
	if (run->max_reaction == NULL || run->handle_groups == NULL || run->reactions == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "simulate: out of memory");
	for (int h = 0; h < scene->handle_count; ++h)
		run->handle_groups[h] = scene->handles[h].group;
	run->stats = fopen(cli_output_path(output, "stats.csv", path, sizeof path), "wb");
	if (run->stats == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	fprintf(run->stats,
	        "time,newton_iterations,gradient_norm,energy,max_barb_strain,wall_seconds,kinetic_energy,"
	        "elastic_energy,gravitational_energy,contact_energy,friction_potential,vane_min_principal_stretch,"
	        "vane_max_out_of_plane,substeps");
	for (int h = 0; h < scene->handle_count; ++h)
		fprintf(run->stats, ",handle%d_fx,handle%d_fy,handle%d_fz,handle%d_dx,handle%d_dy,handle%d_dz", h, h, h, h, h,
		        h);
	fputc('\n', run->stats);
	plume_status run_status = plume_scene_run(scene, on_step, run, summary, failure);
	cli_progress_end(&run->bar);
	if (fclose(run->stats) != 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	if (run_status != PLUME_OK && run_status != PLUME_ERROR_NUMERIC)
		*err = *failure;
	return run_status;
}

/// run_scene, then, once the writer has written everything, the files made from all the
/// frames (sim.glb, sim.usda, fields.pvd, the movie) and summary.json.
static plume_status simulate(const plume_scene *scene, cli_output *output, run_state *run, plume_scene_summary *summary,
                             plume_error *failure, plume_error *err)
{
	char path[4352];
	run->output = output;
	plume_status status = cli_writer_start(&run->writer, err);
	if (status != PLUME_OK)
		return status;
	plume_status run_status = run_scene(scene, output, run, summary, failure, err);
	plume_error write_error;
	status = cli_writer_finish(run->writer, &write_error);
	run->writer = NULL;
	// A run that failed part way keeps what it wrote; input and I/O errors keep nothing.
	// A failed first step keeps frame 0 and a summary saying so (docs/cli.md).
	if (run_status != PLUME_OK && run_status != PLUME_ERROR_NUMERIC)
		return run_status;
	if (status != PLUME_OK) {
		*err = write_error;
		return status;
	}
	if (run->render)
		make_movie(output);
	status = plume_mesh_animation_write_glb(run->animation, cli_output_path(output, "sim.glb", path, sizeof path), err);
	if (status == PLUME_OK)
		status = plume_mesh_animation_write_usda(run->animation, cli_output_path(output, "sim.usda", path, sizeof path),
		                                         err);
	if (status == PLUME_OK && run->fields)
		status = cli_fields_write_pvd(output, run->field_times, run->frames, err);
	if (status != PLUME_OK)
		return status;
	status = write_summary(output, scene, summary, run, run_status == PLUME_OK ? NULL : failure, err);
	return status == PLUME_OK ? run_status : status;
}

/// The most frames sim.glb holds: its sparse weights are indexed in 32 bits, frames^2 - 1 at
/// most (src/io/gltf_mesh.c, which refuses more at the end; this refuses them before the run).
#define SIM_GLB_MAX_FRAMES 65536

/// Upper bounds for sim.glb of `frames` frames: the file's bytes, and the memory that writing
/// it takes, measured on the examples (docs/cli.md, Limits).
typedef struct glb_estimate {
	size_t file;   ///< bytes of sim.glb
	size_t memory; ///< bytes held: the frames kept for it, its buffer as it grows, the JSON
} glb_estimate;

/// The line vertices of a feather carried into sim.glb (--glb-feather): one per shaft sample,
/// barb and barbule point, the afterfeather's too.
static size_t carried_points(const plume_feather *feather)
{
	size_t points = 0;
	for (const plume_feather *f = feather; f != NULL; f = f == feather ? plume_feather_afterfeather(feather) : NULL) {
		plume_feather_info info = plume_feather_get_info(f);
		points += (size_t)info.shaft_sample_count + (size_t)info.point_count;
	}
	return points;
}

static glb_estimate estimate_glb(const plume_scene *scene, bool glb_feather, size_t frames)
{
	// A shell of v vertices and f triangles: base positions and texture coordinates (20 B
	// a vertex) and indices (12 B a triangle) once; per frame a morph target (12 B a
	// vertex), a key time (4 B), a sparse weight (8 B) and at most 400 B of JSON.
	size_t v = (size_t)scene->mesh->vertex_count, f = (size_t)scene->mesh->face_count;
	size_t vb = scene->body != NULL ? (size_t)plume_body_vertex_count(scene->body) : 0;
	size_t fb = scene->body != NULL ? (size_t)plume_body_triangle_count(scene->body) : 0;
	size_t nodes = 1 + (scene->body != NULL ? 1 : 0);
	size_t file = 65536 + 20 * (v + vb) + 12 * (f + fb) + frames * (12 * (v + vb) + 12);
	// Kept while the run goes: every frame of the shell and the body, 12 B a vertex.
	size_t memory = frames * 12 * (v + vb);
	size_t points = 0;
	if (glb_feather) {
		// A carried feather: per line vertex position, texture coordinates, colour and at
		// most two indices (44 B) once, and a morph target (12 B) per frame.
		for (int i = 0; i < scene->feather_count; ++i)
			if (scene->feathers[i].feather != NULL) {
				points += carried_points(scene->feathers[i].feather);
				++nodes;
			}
		file += 44 * points + frames * 12 * points;
		// Writing them: the shell's frames in double (24 B a vertex), and one frame's
		// feather carried and turned into lines twice over (at most 800 B a point).
		memory += frames * 24 * v + 800 * points;
	}
	file += frames * 400 * nodes;
	// The buffer doubles as it grows, copying: up to twice the file at once; the JSON
	// objects take at most 4 KB a frame and node (2 KB measured).
	memory += 2 * file + frames * 4096 * nodes;
	return (glb_estimate){.file = file, .memory = memory};
}

int cli_simulate(int argc, char **argv)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'},
	    {"seed", required_argument, NULL, 's'},
	    {"png", no_argument, NULL, 'p'},
	    {"size", required_argument, NULL, 'S'},
	    {"view", required_argument, NULL, 'V'},
	    {"render", no_argument, NULL, 'R'},
	    {"spp", required_argument, NULL, 'P'},
	    {"fields", no_argument, NULL, 'F'},
	    {"glb-feather", no_argument, NULL, 'G'},
	    {"help", no_argument, NULL, 'h'},
	    {"max-memory", required_argument, NULL, 'M'},
	    {"duration", required_argument, NULL, 'D'},
	    {"frames-every", required_argument, NULL, 'E'},
	    {NULL, 0, NULL, 0},
	};
	const char *output_dir = NULL;
	plume_spec_options spec_options = {0};
	uint64_t max_bytes = PLUME_DEFAULT_MAX_MEMORY;
	run_state run = {0};
	run.view = plume_shell_view_default_def();
	int spp = 4;
	bool size_given = false, view_given = false, spp_given = false;
	double duration = 0; // 0: the scene's
	int frames_every = 0;
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:s:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 's':
			if (!cli_parse_seed("simulate", optarg, &spec_options.seed))
				return CLI_EXIT_USAGE;
			spec_options.seed_given = true;
			break;
		case 'p': run.png = true; break;
		case 'S':
			if (!cli_parse_size("simulate", optarg, &run.view.width, &run.view.height))
				return CLI_EXIT_USAGE;
			size_given = true;
			break;
		case 'V': {
			double azimuth, elevation;
			char tail;
			// sscanf takes "nan" and "inf": a camera of NaN directions draws nothing.
			if (sscanf(optarg, "%lf,%lf%c", &azimuth, &elevation, &tail) != 2 || !isfinite(azimuth) ||
			    !(fabs(elevation) <= 90))
				return cli_usage_error(
				    "simulate",
				    "--view takes AZIMUTH,ELEVATION in degrees (a finite azimuth, |elevation| <= 90), got '%s'",
				    optarg);
			run.view.azimuth = azimuth * acos(-1.0) / 180;
			run.view.elevation = elevation * acos(-1.0) / 180;
			view_given = true;
			break;
		}
		case 'R': run.render = true; break;
		case 'F': run.fields = true; break;
		case 'G': run.glb_feather = true; break;
		case 'P': {
			char *end = NULL;
			long value = strtol(optarg, &end, 10);
			if (end == optarg || *end != '\0' || value < 1 || value > 4096)
				return cli_usage_error("simulate", "--spp takes a whole number in [1, 4096], got '%s'", optarg);
			spp = (int)value;
			spp_given = true;
			break;
		}
		case 'M':
			if (!cli_parse_memory("simulate", optarg, &max_bytes))
				return CLI_EXIT_USAGE;
			break;
		case 'D': {
			char *end = NULL;
			duration = strtod(optarg, &end);
			if (end == optarg || *end != '\0' || !(duration > 0) || !isfinite(duration))
				return cli_usage_error("simulate", "--duration takes a time in seconds > 0, got '%s'", optarg);
			break;
		}
		case 'E': {
			char *end = NULL;
			long value = strtol(optarg, &end, 10);
			if (end == optarg || *end != '\0' || value < 1 || value > PLUME_SCENE_MAX_STEPS)
				return cli_usage_error("simulate", "--frames-every takes a whole number in [1, %d], got '%s'",
				                       PLUME_SCENE_MAX_STEPS, optarg);
			frames_every = (int)value;
			break;
		}
		case 'h': cli_help_simulate(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("simulate", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("simulate", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (!cli_check_arguments("simulate", argc, argv, "SCENE.json", output_dir))
		return CLI_EXIT_USAGE;
	// A picture's options without the pictures were ignored: refused, so that a run asked for
	// pictures of some size or view does not finish without any.
	if (size_given && !run.png && !run.render)
		return cli_usage_error("simulate", "--size sets the pictures of --png and --render; give one of them");
	if (view_given && !run.png)
		return cli_usage_error("simulate", "--view sets the camera of --png (--render's camera frames the whole "
		                                   "sequence); give --png");
	if (spp_given && !run.render)
		return cli_usage_error("simulate", "--spp sets the samples per pixel of --render; give --render");

	plume_error err = {0}, failure = {0};
	plume_scene *scene = NULL;
	spec_options.max_memory = max_bytes; // the feather and its mesh too
	// Many feathers take a while to generate and mesh: a progress line of its own.
	cli_progress meshing;
	cli_progress_begin(&meshing, "simulate: meshing feathers", 1);
	spec_options.progress = cli_progress_callback;
	spec_options.progress_user = &meshing;
	plume_status status = plume_scene_load(argv[optind], &spec_options, &scene, &err);
	cli_progress_end(&meshing);
	if (status != PLUME_OK)
		return cli_fail(&err);
	if (duration > 0) {
		// The scene's own duration passed the same limit when it was read (spec_scene.c).
		double dt = scene->sim.time_step;
		if (!(duration / dt <= PLUME_SCENE_MAX_STEPS)) {
			plume_scene_destroy(scene);
			return cli_usage_error("simulate",
			                       "--duration %g s in steps of %g s ($.time_step) is %.3g steps; allowed at most %.0e",
			                       duration, dt, duration / dt, (double)PLUME_SCENE_MAX_STEPS);
		}
		scene->duration = duration;
	}
	if (frames_every > 0)
		scene->frame_every = frames_every;
	run.scene = scene;
	run.total_steps = (int)fmax(1.0, ceil(scene->duration / scene->sim.time_step - 1e-9)); // as the runner's
	// Before the run: the frames' bytes (an OBJ line is at most about 80 bytes, three
	// %.17g coordinates; a PNG at most its raw pixels) and what sim.glb holds in memory
	// (glb_estimate). size_t products: nothing here wraps.
	// Frame 0, every frame_every-th step, and the last step always (on_step).
	size_t every = (size_t)scene->frame_every, steps = (size_t)run.total_steps;
	size_t frame_count = 1 + steps / every + (steps % every != 0 ? 1 : 0);
	size_t body_vertices = scene->body != NULL ? (size_t)plume_body_vertex_count(scene->body) : 0;
	size_t body_faces = scene->body != NULL ? (size_t)plume_body_triangle_count(scene->body) : 0;
	size_t frame_bytes =
	    80 * ((size_t)scene->mesh->vertex_count + (size_t)scene->mesh->face_count + body_vertices + body_faces) +
	    (size_t)((run.png ? 1 : 0) + (run.render ? 1 : 0)) * 4 * (size_t)run.view.width * (size_t)run.view.height;
	glb_estimate glb = estimate_glb(scene, run.glb_feather, frame_count);
	size_t total = frame_count * frame_bytes + glb.memory;
	// The keys that set the frames: the options when given, else the scene's.
	const char *duration_key = duration > 0 ? "--duration" : "$.duration";
	const char *every_key = frames_every > 0 ? "--frames-every" : "$.frame_every";
	if (total > max_bytes) {
		fprintf(stderr,
		        "plume: %s: %s: %zu frames of up to %.3g MB each would write %.3g GB, and sim.glb%s would hold "
		        "%.3g GB in memory: %.3g GB; the limit is %.3g GB (raise it with --max-memory, or raise %s "
		        "or $.time_step%s)\n",
		        argv[optind], duration_key, frame_count, (double)frame_bytes / 1e6,
		        (double)(frame_count * frame_bytes) / 1e9,
		        run.glb_feather ? " with the carried feathers (--glb-feather)" : "", (double)glb.memory / 1e9,
		        (double)total / 1e9, (double)max_bytes / 1e9, every_key,
		        run.glb_feather ? ", or leave out --glb-feather" : "");
		plume_scene_destroy(scene);
		return CLI_EXIT_LIMIT;
	}
	if (frame_count > SIM_GLB_MAX_FRAMES || glb.file > UINT32_MAX) {
		fprintf(stderr,
		        "plume: %s: %s: %zu frames%s make a sim.glb of about %.3g GB; a GLB file holds at most 4 GiB "
		        "and %d frames (one morph target each) (raise %s or $.time_step, or shorten the run%s)\n",
		        argv[optind], duration_key, frame_count, run.glb_feather ? " with --glb-feather" : "",
		        (double)glb.file / 1e9, SIM_GLB_MAX_FRAMES, every_key,
		        run.glb_feather ? ", or leave out --glb-feather" : "");
		plume_scene_destroy(scene);
		return CLI_EXIT_LIMIT;
	}
	cli_progress_begin(&run.bar, "simulate", run.total_steps);
	run.progress = run.bar.shown;
	// Handles keep the feather in place: one framing for the whole sequence. A free
	// feather (falling) is followed frame by frame.
	plume_vec3 lo, hi;
	cli_scene_bounds(scene, &lo, &hi);
	if (scene->handle_count > 0) {
		run.view.bounds_min = lo;
		run.view.bounds_max = hi;
	}
	bool generated = false;
	for (int i = 0; i < scene->feather_count; ++i)
		generated = generated || scene->feathers[i].feather != NULL;
	if (run.glb_feather && !generated) {
		plume_scene_destroy(scene);
		return cli_usage_error("simulate", "--glb-feather needs a scene whose feathers are generated (not guides)");
	}
	if (run.render) {
		if (!generated) {
			plume_scene_destroy(scene);
			return cli_usage_error("simulate", "--render needs a scene whose feathers are generated (not guides)");
		}
		if (scene->body != NULL) // the camera sees the body too
			for (int v = 0; v < plume_body_vertex_count(scene->body); ++v) {
				plume_vec3 p = plume_body_rest_positions(scene->body)[v];
				lo = plume_v3(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
				hi = plume_v3(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
			}
		run.scene = scene;
		run.render_def = cli_sequence_render_def(lo, hi, run.view.width, run.view.height, spp);
		status = cli_carry_scene(scene, &run.rendered, &err);
		if (status != PLUME_OK) {
			cli_carried_end(&run.rendered);
			plume_scene_destroy(scene);
			return cli_fail(&err);
		}
	}

	cli_output output;
	plume_scene_summary summary = {0};
	status = cli_output_begin(&output, output_dir, &err);
	if (status == PLUME_OK) {
		plume_status run_status = simulate(scene, &output, &run, &summary, &failure, &err);
		bool keep = run_status == PLUME_OK || run_status == PLUME_ERROR_NUMERIC;
		status = keep ? cli_output_commit(&output, &err) : (cli_output_abort(&output, &err), run_status);
		if (status == PLUME_OK)
			status = run_status;
	}
	if (status == PLUME_OK || status == PLUME_ERROR_NUMERIC)
		printf("%d steps, %d Newton iterations (%.2f a step), %.2f s wall; largest barb strain %.3g; "
		       "rachis tip deflection %.6g m; %d frames in %s\n",
		       summary.steps, summary.newton_iterations,
		       summary.steps > 0 ? (double)summary.newton_iterations / summary.steps : 0.0, summary.wall_seconds,
		       summary.max_barb_strain, summary.rachis_tip_deflection, run.frames, output_dir);
	plume_scene_destroy(scene);
	plume_mesh_animation_destroy(run.animation);
	plume_mesh_obj_writer_destroy(run.obj);
	plume_embedding_destroy(run.carried);
	free(run.field_times);
	free(run.max_reaction);
	free(run.handle_groups);
	free(run.reactions);
	free(run.body_positions);
	plume_mesh_animation_destroy(run.body_animation);
	plume_mesh_destroy(run.body_mesh);
	cli_carried_end(&run.glb_carried);
	cli_carried_end(&run.rendered);
	if (status != PLUME_OK)
		return cli_fail(status == PLUME_ERROR_NUMERIC && failure.message[0] ? &failure : &err);
	return CLI_EXIT_OK;
}

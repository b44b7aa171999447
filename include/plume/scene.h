// plume scenes: a feather, how to mesh it, its materials, handles and loads,
// and how long to simulate — read from JSON (docs/scene.md) and run.
#ifndef PLUME_SCENE_H
#define PLUME_SCENE_H

#include "plume/feather.h"
#include "plume/mesh.h"
#include "plume/model.h"
#include "plume/sim.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

typedef struct plume_body plume_body; // plume/body.h

/// A follicle may lie this far from the body's rest surface, m: feathers are attached at their
/// calamus, on the skin (docs/scene.md "Bodies").
#define PLUME_SCENE_FOLLICLE_TOLERANCE 1e-3

/// One key of a handle's scripted motion: at `time` the handle's vertices are at
/// rotation(axis, angle) (rest - pivot) + pivot + translation.
typedef struct plume_keyframe {
	double time;
	plume_vec3 translation;
	plume_vec3 axis;
	double angle;
} plume_keyframe;

typedef enum plume_interpolation {
	/// Piecewise linear between keys.
	PLUME_INTERPOLATION_LINEAR = 0,
	/// Smoothstep 3s^2 - 2s^3 between keys: zero velocity at every key.
	PLUME_INTERPOLATION_SMOOTH,
} plume_interpolation;

/// A Dirichlet handle: a vertex group, optionally only its vertices within `radius`
/// of `near` (reference plane, m), moved by keyframes (none: held still).
typedef struct plume_scene_handle {
	/// The group the handle holds (for a `near` selection, the derived group "handle N").
	char group[32];
	/// With `near`: the group named in the spec that the selection was taken from.
	char source_group[32];
	bool near_given;
	plume_vec2 near;
	double radius;
	plume_vec3 pivot;
	plume_interpolation interpolation;
	int keyframe_count;
	plume_keyframe *keyframes;
} plume_scene_handle;

/// A constant force, N, shared by a group's vertices.
typedef struct plume_scene_force {
	char group[32];
	plume_vec3 force;
} plume_scene_force;

/// One feather of a scene (docs/scene.md "Many feathers"): where its piece of the scene's
/// mesh is, how it was placed and what holds it.
typedef struct plume_scene_feather {
	/// Its name and the prefix of its vertex groups ("f3": "f3/rachis_clamp"); "f<index>"
	/// unless the scene names it. Letters, digits, '-' and '_', at most 15 bytes.
	char name[16];
	/// The feather at rest, placed (world coordinates, like its rest mesh); NULL for guides.
	plume_feather *feather;
	/// The placement of the feather's own frame (docs/feather-json.md): world = rotation * own
	/// + translation. Identity for a one-feather scene written with "feather".
	plume_mat3 rotation;
	plume_vec3 translation;
	/// Its vertices and faces in the scene's mesh: [offset, offset + count).
	int vertex_offset;
	int vertex_count;
	int face_offset;
	int face_count;
	plume_mesh_report mesh_report;
	/// Carried by the body at its calamus ("follicle"): its rachis_clamp group follows
	/// bone `bone` of the body (-1: the body's motion as a whole).
	bool follicle;
	/// The bone's name as the scene gives it ("": the body as a whole) and its index.
	char bone_name[32];
	int bone;
	/// The follicle at rest, m: where the feather's own origin (the calamus) is placed.
	plume_vec3 follicle_point;
} plume_scene_feather;

/// The most steps one scene may take (duration / time_step): the count is an int.
#define PLUME_SCENE_MAX_STEPS 10000000

typedef struct plume_scene {
	/// The generated feather of a scene written with "feather" (an alias of feathers[0].feather);
	/// NULL when the scene gives explicit guides or lists "feathers".
	plume_feather *feather;
	/// Every feather's mesh, one after the other (plume_mesh_concatenate); for a scene written
	/// with "feather" or "guides", that feather's mesh as the mesher made it.
	plume_mesh *mesh;
	/// The worst over the feathers: smallest angle and aligned fraction, guides dropped summed.
	plume_mesh_report mesh_report;
	/// At least 1.
	int feather_count;
	plume_scene_feather *feathers;
	/// The body the feathers hang on ("body"), or NULL. Its pose at time t: plume_scene_body_pose.
	plume_body *body;
	plume_sim_def sim;
	int handle_count;
	plume_scene_handle *handles;
	int force_count;
	plume_scene_force *forces;
	/// Simulated time, s, > 0; duration / sim.time_step at most PLUME_SCENE_MAX_STEPS.
	double duration;
	/// Write every n-th step as a frame, >= 1. Default 1.
	int frame_every;
	/// Solve each step as a static equilibrium at the handles' positions (quasi-static
	/// loading, no inertia) instead of implicit Euler. Default false.
	bool quasi_static;
	/// The period of a cyclic motion (a wing beat), s; 0 when the scene is not cyclic.
	/// Gives summary.json its seconds_per_cycle.
	double cycle_period;
} plume_scene;

/// Reads a scene: generates its feather (seed from options or the feather spec)
/// and meshes it. Errors name the file and the JSON path. For a scene that lists
/// "feathers", options->progress (when set) is called after each feather is meshed.
plume_status plume_scene_load(const char *path, const plume_spec_options *options, plume_scene **out, plume_error *err);
/// The same from JSON text; name stands for the file in messages, and relative paths
/// in the text are relative to the current folder.
plume_status plume_scene_parse(const char *text, const char *name, const plume_spec_options *options, plume_scene **out,
                               plume_error *err);
void plume_scene_destroy(plume_scene *scene);

/// Where a handle is at time t: translation and rotation for plume_sim_set_handle.
/// Between keys as a body's keys (docs/body.md "Interpolation").
void plume_scene_handle_pose(const plume_scene_handle *handle, double t, plume_vec3 *translation, plume_mat3 *rotation);

/// The body's vertex positions at time t (plume_body_pose) into out[plume_body_vertex_count];
/// the scene must have a body. The run poses it at every step's time, where contact with
/// the body takes its obstacle.
void plume_scene_body_pose(const plume_scene *scene, double t, plume_vec3 *out);

/// What a run measured.
typedef struct plume_scene_summary {
	int steps;
	int newton_iterations;
	double wall_seconds;
	double seconds_assembly;
	double seconds_factor;
	double seconds_solve;
	double seconds_contact;
	double max_barb_strain;
	/// Mean displacement of the rachis_tip group from rest at the end, m (0 without that group).
	double rachis_tip_deflection;
	/// Steps that needed substeps.
	int retried_steps;
	int vertex_count;
	int face_count;
	int constraint_count;
	int feather_count;
	/// Contact and the independent intersection check, when the run has them (contact_measured,
	/// intersections_checked); left false and 0 otherwise, and summary.json leaves them out.
	bool contact_measured;
	int contact_pairs_max;
	/// Smallest distance between contact primitives over the run, m.
	double min_distance;
	bool intersections_checked;
	/// The most pairs of intersecting triangles in any checked frame (must be 0), the
	/// frames checked (the output frames: step 0, every frame_every steps and the last)
	/// and the first step with a pair (-1: none).
	int intersecting_pairs;
	int frames_checked;
	int first_intersecting_step;
} plume_scene_summary;

/// Called after the initial state (step 0, report NULL) and after every step.
typedef plume_status plume_scene_step_fn(void *user, int step, double time, const plume_sim *sim,
                                         const plume_solve_report *report, double wall_seconds, plume_error *err);

/// Creates the simulation, runs it for the scene's duration, calling on_step.
/// A step that fails (even with substeps) ends the run with its error; what was
/// reported before stays valid, and nothing after it is reported.
plume_status plume_scene_run(const plume_scene *scene, plume_scene_step_fn *on_step, void *user,
                             plume_scene_summary *summary, plume_error *err);

/// A scene being run step by step, exactly as plume_scene_run runs it: the scene's handles
/// posed from their keyframes, the feathers carried by the body's follicles, the body's
/// pose and contact with it, the intersection check of the output frames and the summary.
/// The scene must outlive its runner. (plume_scene_run is this runner in a loop; the
/// Python package's Simulation steps one.)
typedef struct plume_scene_runner plume_scene_runner;

/// Creates the simulation with the scene's handles (ids 0 .. handle_count - 1, in the
/// scene's order; the follicles' after them), loads and contact surfaces, at t = 0.
plume_status plume_scene_runner_create(const plume_scene *scene, plume_scene_runner **out, plume_error *err);
void plume_scene_runner_destroy(plume_scene_runner *runner);
/// The running simulation: positions, reactions, more handles or loads. A scene handle
/// moved with plume_sim_set_handle goes back to its keyframes at the next step.
plume_sim *plume_scene_runner_sim(plume_scene_runner *runner);
/// Steps taken so far, and the scene's: ceil(duration / time_step). Stepping past the
/// scene's duration is allowed (handles stay at their last keys, the body keeps moving).
int plume_scene_runner_steps_done(const plume_scene_runner *runner);
int plume_scene_runner_step_count(const plume_scene_runner *runner);
/// The body's vertex positions at the last step's time (plume_body_vertex_count of them),
/// or NULL for a scene without a body.
const plume_vec3 *plume_scene_runner_body_positions(const plume_scene_runner *runner);
/// One step: handles and body posed at the step's end time, then an implicit step (a
/// static solve for a quasi-static scene). report may be NULL. A step that fails (even
/// with substeps) leaves the state as it was, and may be tried again.
plume_status plume_scene_runner_step(plume_scene_runner *runner, plume_solve_report *report, plume_error *err);
/// What the run measured so far (rachis tip deflection now, wall time since creation).
void plume_scene_runner_summary(const plume_scene_runner *runner, plume_scene_summary *out);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_SCENE_H

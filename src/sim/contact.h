// Private: contact in the simulator (contact.c). IPC's barrier (Li et al. 2020,
// "Incremental Potential Contact") between the shell's primitives and those of the
// obstacles, evaluated on candidate pairs from the broad phase (sim/bvh.h), and the
// continuous collision detection (sim/ccd.h) that bounds every step.
#ifndef PLUME_SIM_CONTACT_H
#define PLUME_SIM_CONTACT_H

#include "plume/sim.h"
#include "sim/bvh.h"
#include "sim/contact_barrier.h"

struct plume_sim;

/// A candidate pair. Vertices are in the combined numbering: below the shell's vertex
/// count a shell vertex, from it on obstacle vertex (index - vertex_count).
typedef struct sim_contact_pair {
	plume_contact_pair_type type;
	int vertices[4];
	double distance2;
	/// The barrier's reach for this pair, m: d-hat, or less for a pair close at rest.
	double dhat;
} sim_contact_pair;

/// A pair of IPC's lagged friction (Li et al. 2020, section 5.3), fixed at a step's start:
/// the relative sliding u = sum_j weights[j] (x_j - x_j at the start) of the pair's closest
/// points, its tangent plane, and the normal force the barrier pressed with there.
typedef struct sim_friction_pair {
	int vertices[4];
	double weights[4];
	plume_vec3 tangent[2];
	double normal_force;
} sim_friction_pair;

/// One obstacle: a range of the concatenated obstacle vertices and triangles.
typedef struct sim_obstacle {
	int first_vertex, vertex_count;
	int first_face, face_count;
} sim_obstacle;

enum {
	SIM_TREE_VERTEX = 0,
	SIM_TREE_FACE,
	SIM_TREE_EDGE,
	SIM_TREE_BODY_VERTEX,
	SIM_TREE_BODY_FACE,
	SIM_TREE_BODY_EDGE,
	SIM_TREE_COUNT
};

typedef struct sim_contact {
	/// The shell's unique edges (low, high), sorted.
	int edge_count;
	int *edges;
	/// Obstacles, concatenated: rest (at creation: the mollifier's reference), positions at
	/// the step's start and end, and where they are in the current solve.
	int obstacle_count, obstacle_capacity;
	sim_obstacle *obstacles;
	int body_vertex_count, body_vertex_capacity;
	plume_vec3 *body_rest, *body_start, *body_end, *body_x, *body_from, *body_lag;
	int body_face_count, body_face_capacity;
	int *body_faces;
	int body_edge_count;
	int *body_edges;
	/// Broad phase: one tree per primitive kind, refit before every query.
	plume_bvh *trees[SIM_TREE_COUNT];
	int tree_size[SIM_TREE_COUNT];
	plume_aabb *boxes;
	int box_capacity;
	plume_pair_list overlaps;
	/// Candidates of the last query, and the active ones (within reach) of the last evaluation
	/// with their energies, gradients (12) and projected Hessians (144).
	int pair_count, pair_capacity;
	sim_contact_pair *pairs;
	int active_count, active_capacity;
	int *active;
	double *energy, *gradient, *hessian;
	int buffer_capacity;
	/// Friction (def.contact.friction > 0, dynamic steps): the lagged pairs, the smoothing
	/// width epsilon_v h, m, and per-pair gradients and Hessians of the last evaluation.
	int friction_count, friction_capacity;
	sim_friction_pair *friction;
	double friction_epsilon;
	double *friction_gradient, *friction_hessian;
	int friction_buffer_capacity;
	bool friction_used;
	/// The smallest pair distance of the last evaluation, m (+inf when no pair is in reach).
	double min_distance;
	/// Times the KKT pattern was rebuilt for new contact couplings, and continuation rounds
	/// taken beyond the first solve of a substep (plume_contact_begin), since creation.
	int pattern_rebuilds;
	int rounds;
	/// The candidates hold every pair within reach of the positions the next evaluations see
	/// (newton.c sets it after a step's CCD, for the points of that step's segment): the
	/// evaluations skip the broad phase.
	bool reuse_candidates;
	/// The barrier's stiffness (docs/contact.md "Stiffness"): with def.contact.adaptive_stiffness,
	/// a pair's kappa is acceleration * (its shell vertices' mean mass) / (4.33 d-hat^3), so
	/// the barrier at d-hat / 2 holds that mass at that acceleration; `acceleration` (m/s^2) is
	/// fixed at each (sub)step's start (plume_contact_lag_friction) and `acceleration_floor`
	/// (m/s^2) is raised after a step whose pairs came closer than d-hat / 10 (IPC's doubling).
	double acceleration, acceleration_floor;
	/// Self-contact pairs closer than d-hat at rest (sorted by type and vertices) and their
	/// reach: half their rest distance, so the barrier does not push on the rest shape and still
	/// keeps them apart (docs/contact.md "Pairs close at rest").
	int rest_close_count, rest_close_capacity;
	sim_contact_pair *rest_close;
	/// The smallest pair distance over the accepted iterates since the last
	/// plume_contact_finish, m (drives the floor's doubling).
	double step_min_distance;
	/// Why the last evaluation failed (out of memory: PLUME_ERROR_MEMORY; primitives touching:
	/// PLUME_ERROR_NUMERIC), for the caller's error; PLUME_OK when it did not.
	plume_status failure;
	char message[160];
} sim_contact;

bool plume_contact_init(struct plume_sim *sim);
void plume_contact_free(sim_contact *contact);

/// True when the sim evaluates contact: enabled and something to collide (self-contact or obstacles).
bool plume_contact_on(const struct plume_sim *sim);

/// Contact energy at shell positions x (obstacles at body_x): finds the pairs in reach,
/// evaluates them (energies, gradients, PSD-projected Hessians) and, with hessian, makes
/// sure the KKT pattern holds their blocks (rebuilding it when it does not). Returns the
/// energy, +inf when a pair is in contact (distance 0), NaN when out of memory.
/// Gradients only when asked for (or with hessian). With friction (dynamic problems), also the
/// lagged friction of plume_contact_lag_friction.
double plume_contact_evaluate(struct plume_sim *sim, const plume_vec3 *x, bool gradient, bool hessian, bool friction);

/// Fixes what a (sub)step from fraction s0 of the step, of length h (0 in statics), keeps
/// constant: the barrier's stiffness (adaptive: from the shell's speeds, loads and gravity at
/// its start) and the friction pairs, those within reach at its start (sim->previous, obstacles
/// at s0; none in statics or without friction). False when out of memory.
bool plume_contact_lag_friction(struct plume_sim *sim, double s0, double h);
/// The contact energies at shell positions x (obstacles at body_x), J: the barrier's (+inf when a
/// pair touches) and the friction dissipation potential of the last (sub)step's lagged pairs
/// (0 without friction, in statics and before the first step).
void plume_contact_energies(struct plume_sim *sim, const plume_vec3 *x, double *barrier, double *friction);
/// The last evaluation found pairs in reach or used friction (something to scatter).
bool plume_contact_any(const struct plume_sim *sim);
/// Adds the last evaluation's gradient (when gradient != NULL) and Hessian blocks (when
/// values != NULL) on free shell unknowns.
void plume_contact_scatter(struct plume_sim *sim, double *gradient, double *values);

/// The largest t in [0, 1] such that the shell moving linearly from x0 to x1 and the
/// obstacles from body0 to body1 keep every pair above ccd_separation times its starting
/// distance (continuous collision detection over the broad phase's candidates). NaN when
/// out of memory.
double plume_contact_step_bound(struct plume_sim *sim, const plume_vec3 *x0, const plume_vec3 *x1,
                                const plume_vec3 *body0, const plume_vec3 *body1);

/// Before a (sub)step from fraction s0 to s1 of the step, with *reached = 0: places the
/// obstacles at s1 and checks, by continuous collision detection, the motion from
/// sim->previous (shell) and the obstacles at s0 to the start iterate in sim->x (free vertices
/// at their inertial prediction, handles at their targets). When that path closes a gap, the
/// free vertices start where they were; when the prescribed motion alone closes one, it is
/// taken only as far as CCD allows and *reached says which fraction of it that is (1: all).
/// The caller then solves and calls again (with the free vertices where the solve left
/// them) until *reached is 1: a continuation in which the barrier pushes the shell ahead
/// of the handles and obstacles. PLUME_ERROR_NUMERIC when the motion cannot advance (the
/// caller subdivides the step).
plume_status plume_contact_begin(struct plume_sim *sim, double s0, double s1, double *reached, plume_error *err);
/// After a successful step or solve: the obstacles' end positions become their start, and the
/// adaptive stiffness's floor doubles when the step's pairs came closer than d-hat / 10.
void plume_contact_finish(struct plume_sim *sim);

/// IPC's doubling within a solve: when the closest pair distance at an accepted iterate,
/// `closest` (m), is below d-hat / 10 and below `previous`, the one at the accepted iterate
/// before (+inf for the first), doubles the adaptive stiffness (up to its ceiling). True when it
/// changed.
bool plume_contact_stiffen(struct plume_sim *sim, double previous, double closest);

/// The barrier stiffness kappa of a pair (J/m^4) and its reach d-hat (m).
double plume_contact_pair_stiffness(const struct plume_sim *sim, const sim_contact_pair *pair);
double plume_contact_pair_reach(const struct plume_sim *sim, const sim_contact_pair *pair);

/// Force the shell exerts on an obstacle through the barrier at shell positions x, N: minus the
/// barrier's gradient with respect to the obstacle's vertices (which the solver never uses).
plume_vec3 plume_contact_obstacle_force(struct plume_sim *sim, int obstacle, const plume_vec3 *x);

#endif // PLUME_SIM_CONTACT_H

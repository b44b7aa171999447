// Private: the simulation's state, shared by sim.c (lifecycle, handles),
// potential.c (energy, gradient and Hessian assembly), kkt.c (the sparse
// solver) and newton.c (the constrained Newton iteration and time stepping).
#ifndef PLUME_SIM_INTERNAL_H
#define PLUME_SIM_INTERNAL_H

#include "plume/sim.h"
#include "sim/air.h"
#include "sim/bending.h"
#include "sim/contact.h"
#include "sim/integrator.h"
#include "sim/fundamental_form.h"
#include "sim/kkt.h"
#include "sim/membrane.h"

enum { PLUME_SIM_TRACE = 256 };

typedef struct sim_handle {
	int count;
	int *vertices;
	/// Vertex positions the motion is applied to (the rest shape at creation).
	plume_vec3 *anchor;
	/// Targets at the start and at the end of the current step; a substep interpolates.
	plume_vec3 *start;
	plume_vec3 *end;
} sim_handle;

/// What a solve minimises: statics (no inertia) or one (sub)step of the integrator
/// (integrator.c): inertia |x - predicted|^2_M * inertia / 2, with the velocity at the
/// end of the step an affine function of the unknowns, v(x) = velocity_scale (x - velocity_base),
/// which the dissipation terms (drag, air) are written in.
typedef struct sim_problem {
	bool dynamic;
	/// Step length, s (dynamic only).
	double h;
	/// 1 / (beta h^2): h^-2 for implicit Euler, 9/4 h^-2 for BDF2 with equal steps.
	double inertia;
	/// Where the vertices go without forces (dynamic only).
	const plume_vec3 *predicted;
	double velocity_scale;
	const plume_vec3 *velocity_base;
	/// Vertex normals at the start of the step, for the linear drag (dynamic only).
	const plume_vec3 *drag_normals;
	/// Each face's area ratio J at the start of the step (dynamic only, else NULL): newton.c's
	/// first iteration takes the Kikuuwe term's secant curvature towards it (membrane.h).
	const double *start_area_ratio;
} sim_problem;

struct plume_sim {
	uint32_t magic; ///< PLUME_HANDLE_MAGIC while alive (core/asserts.h)
	plume_sim_def def;
	int vertex_count;
	plume_vec3 *x;
	plume_vec3 *v;
	plume_vec3 *rest;
	double *mass;
	/// External force on each vertex, N (plume_sim_set_group_load).
	plume_vec3 *load;
	/// Each vertex's third of its faces' reference area, m^2 (for drag).
	double *vertex_area;

	int face_count;
	int *faces;
	unsigned char *face_material;
	plume_membrane_element *membranes;
	/// The bending elements of def.bending_model: the paper's hinges, or one
	/// fundamental-form element per face.
	int hinge_count;
	plume_hinge *hinges;
	int ff_count;
	plume_ff_face *ff_faces;
	/// The interior edges the fundamental-form faces share (fundamental_form.h, Shared
	/// edges): a hinge stencil each (4 vertices), and per evaluation its angle, gradient (12)
	/// and Hessian (144), and the weight of that Hessian in the exact Hessian: each face's
	/// share (3 per face) and their sum (1 per edge).
	int ff_edge_count;
	int *ff_edge_vertices;
	double *ff_edge_chi;
	double *ff_edge_gradient;
	double *ff_edge_hessian;
	double *ff_face_weight;
	double *ff_edge_weight;

	/// Barb-aligned edges held at their reference length (constraint rows).
	int constraint_count;
	int *constraint_vertices;
	double *constraint_length;
	double *lambda;
	/// Each vertex's constraints in compressed rows (barb_incident[barb_offsets[v] ..
	/// barb_offsets[v + 1]]), and the walks' scratch: what the handles may ask of held barbs
	/// (held.c).
	int *barb_offsets;
	int *barb_incident;
	int *held_mark;
	int held_stamp;
	struct sim_chain_step *held_stack;
	/// Every barb-aligned edge, constrained or not, for the strain report.
	int barb_edge_count;
	int *barb_edges;
	double *barb_length;

	/// Per degree of freedom: held by a handle or by the planar restriction.
	unsigned char *fixed;
	int handle_count;
	int handle_capacity;
	sim_handle *handles;
	int group_count;
	plume_vertex_group *groups;

	/// Length scale for convergence: the reference bounding box diagonal, m.
	double length_scale;
	double time;

	plume_kkt kkt;
	/// Per-element outputs, computed in parallel and summed in a fixed order.
	double *face_energy;
	/// sim_problem.start_area_ratio's storage, one per face.
	double *face_start_area_ratio;
	double *face_gradient;
	double *face_hessian;
	/// Per bending element (hinge: 12 and 144 entries; fundamental-form face: 18 and 324).
	double *hinge_energy;
	double *hinge_gradient;
	double *hinge_hessian;
	/// Scratch vectors of 3 n + constraints.
	double *gradient;
	double *residual;
	double *rhs;
	double *step;
	plume_vec3 *trial;
	plume_vec3 *scratch;
	/// Step state: positions and velocities before the step (restored on failure),
	/// positions at the start of a substep, the inertial prediction, drag normals.
	plume_vec3 *saved_x;
	plume_vec3 *saved_v;
	plume_vec3 *previous;
	plume_vec3 *predicted;
	plume_vec3 *normals;
	/// The last solve's exact Hessian could not be factored even shifted (or, without
	/// constraints, gave an ascent step): the next solve starts projected (newton.c).
	bool exact_hessian_failed;
	/// Set while a failed step is retried in substeps: Newton keeps the exact Hessian after
	/// a shortened step instead of taking a projected one (newton.c).
	bool retrying;
	/// The shift s (kkt.h) the last exact factorisation needed, 0 when it needed none: the
	/// next one's ladder starts a decade below it (newton.c, factor_and_solve).
	double exact_shift;
	/// Time integration history (integrator.c) and the air's per-step state (air.c).
	sim_integrator integrator;
	sim_air air;
	/// Contact pairs, obstacles and the broad phase (contact.c).
	sim_contact contact;
	/// For each accepted Newton step of the last solve, the merit before and after it under
	/// one penalty (pairs: tests check that each step decreases it).
	double trace[PLUME_SIM_TRACE];
	int trace_count;
};

/// Potential of the problem at positions x: elastic + compression + bending + gravity
/// (+ inertia and drag for a dynamic step) (+ the contact barrier, contact.c). With gradient != NULL also fills the
/// gradient (3 n); with the KKT matrix also fills its Hessian block (projected
/// per element when project is true, exact otherwise). Returns NaN when the
/// potential is not finite.
/// Each face's area ratio J at x (plume_compression_area_ratio; 1 for faces without the
/// Kikuuwe term).
void plume_sim_area_ratios(const plume_sim *sim, const plume_vec3 *x, double *area_ratio);

double plume_sim_potential(plume_sim *sim, const sim_problem *problem, const plume_vec3 *x, double *gradient,
                           bool hessian, bool project);

/// Adds scale times a symmetric element block (n x n, n = 3 count, row-major) into the KKT
/// matrix's values through the element's upper slots (kkt.h), skipping held unknowns and
/// absent (negative) vertices.
void plume_sim_scatter_block(const plume_sim *sim, double *values, const int *vertices, int count, const int *slots,
                             double scale, const double *block);

/// The bending elements of the sim's model: how many, vertices per element (4 for a
/// hinge, 6 for a fundamental-form face, -1 entries for absent neighbours), the byte
/// stride between their vertex lists, element e's vertices and its energy at x.
int plume_sim_bending_count(const plume_sim *sim);
int plume_sim_bending_size(const plume_sim *sim);
int plume_sim_bending_stride(const plume_sim *sim);
const int *plume_sim_bending_vertices(const plume_sim *sim, int e);
double plume_sim_bending_energy(const plume_sim *sim, const plume_vec3 *x, int e);

/// Adds the constraint rows C at x and, where the multiplier is nonzero, the constraints'
/// curvature sum lambda_k Hess c_k to the assembled matrix: with plume_sim_potential's exact
/// block, the Hessian of the Lagrangian. Without `exact`, only barbs in tension (lambda > 0)
/// add their curvature (positive semidefinite; a compressed barb's is indefinite).
void plume_sim_add_constraint_rows(plume_sim *sim, const plume_vec3 *x, bool exact);

/// Adds C^T lambda, the constraint forces of the current multipliers, to forces (3 n).
void plume_sim_add_constraint_forces(const plume_sim *sim, const plume_vec3 *x, double *forces);

/// Whether barb constraint k has both ends held (every unknown of both vertices fixed):
/// Newton leaves it out, and only the handles set its length (plume_sim_step checks it).
bool plume_sim_constraint_held(const plume_sim *sim, int k);

/// A step of held.c's walk along barb chains: a vertex, the edges and length from the start.
typedef struct sim_chain_step {
	int vertex;
	int edges;
	double length;
} sim_chain_step;

/// held.c: the vertices' constraints, built once (false: out of memory), and freed.
bool plume_sim_held_init(plume_sim *sim);
void plume_sim_held_free(plume_sim *sim);
/// PLUME_ERROR_SPEC when the handles' positions change the length of a barb edge they hold
/// at both ends, or pull two held vertices farther apart than the chain of barb edges between
/// them is long (held.c).
plume_status plume_sim_check_held_barbs(plume_sim *sim, plume_error *err);

/// Largest |l - L| / L over all barb-aligned edges at positions x.
double plume_sim_max_barb_strain(const plume_sim *sim, const plume_vec3 *x);

/// The simulator's copy of the mesh's vertex group with that name, or NULL.
const plume_vertex_group *plume_sim_find_group(const plume_sim *sim, const char *name);

/// Minimises the problem from sim->x with handles at their targets for fraction s of the step.
plume_status plume_sim_newton(plume_sim *sim, const sim_problem *problem, plume_solve_report *report, plume_error *err);

/// Places the handle vertices of sim->x at their targets for the step fraction s in [0, 1].
void plume_sim_place_handles(plume_sim *sim, double s);

#endif

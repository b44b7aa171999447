// Constrained Newton (sequential quadratic programming) on the potential.
//
// Each iteration solves the KKT system of the Lagrangian Phi(x) + lambda . c(x),
// c_k = |x_j - x_i| - L_k for every constrained barb edge:
//   [ H  C^T ] [ dx      ]   [ -grad Phi ]
//   [ C  -dI ] [ lambda+ ] = [ -c        ]
// with H the Hessian of the Lagrangian: element Hessians plus each barb's constraint
// curvature lambda_k (I - t t^T) / l. A solve uses the exact H, shifted where it is not
// positive definite on the constraints' tangent space (factor_and_solve), after every
// full step (after its shifts ran out, from the second); after a shortened one,
// per-element Hessians projected to positive semidefinite with only the curvature of
// barbs in tension (lambda_k > 0). A backtracking line search on the exact l1 merit
// Phi + mu |c|_1 (mu above the largest multiplier) keeps every accepted step a descent
// step; second-order corrections at its trials follow the barbs' constraints
// (corrected_trial). With contact, continuous collision detection caps every step first
// (contact.c; IPC's filtered line search), so no iterate ever reaches a pair at
// distance 0.
//
// Why SQP and not an augmented Lagrangian or a stiff spring: the constraint is
// the limit E_vv -> infinity, whose stiffness is what makes the unconstrained
// problem ill-conditioned (paper section 6, Figure 6). A penalty or augmented
// Lagrangian with a large weight brings that conditioning back, and a small one
// needs many outer iterations to reach 1e-8 strain. SQP satisfies the linearised
// constraint exactly at every step and converges quadratically: on the Figure 1
// scenario it holds every barb edge to < 1e-10 strain in a few iterations a step.
#include <math.h>
#include <string.h>

#include <omp.h>

#include "sim/sim_internal.h"

enum { MAX_BACKTRACKS = 30 };
/// Second-order corrections a line-search trial may take (corrected_trial): the second took
/// Figure 1 at e = 2.5 mm from 9.9 to 9.2 Newton iterations a step.
enum { CORRECTIONS = 2 };
/// A solve also requires every constrained barb edge's strain below this.
static const double STRAIN_TOLERANCE = 1e-10;
/// IPC's Newton tolerance on the step per unit time, relative to the shell's size (1/s).
static const double CONTACT_VELOCITY_TOLERANCE = 1e-6;

/// c_k and the unit edge direction t_k (the constraint gradient is -t on vertex i, +t on j).
static double constraint_value(const plume_sim *sim, const plume_vec3 *x, int k, plume_vec3 *direction, double *length)
{
	plume_vec3 d = plume_v3_sub(x[sim->constraint_vertices[2 * k + 1]], x[sim->constraint_vertices[2 * k]]);
	double l = plume_v3_length(d);
	if (direction != NULL)
		*direction = plume_v3_scale(d, 1 / l);
	if (length != NULL)
		*length = l;
	return l - sim->constraint_length[k];
}

bool plume_sim_constraint_held(const plume_sim *sim, int k)
{
	int a = sim->constraint_vertices[2 * k], b = sim->constraint_vertices[2 * k + 1];
	return sim->fixed[3 * a] && sim->fixed[3 * a + 1] && sim->fixed[3 * a + 2] && sim->fixed[3 * b] &&
	       sim->fixed[3 * b + 1] && sim->fixed[3 * b + 2];
}

static double constraint_norm1(const plume_sim *sim, const plume_vec3 *x)
{
	double sum = 0;
	for (int k = 0; k < sim->constraint_count; ++k)
		if (!plume_sim_constraint_held(sim, k))
			sum += fabs(constraint_value(sim, x, k, NULL, NULL));
	return sum;
}

static double max_constraint_strain(const plume_sim *sim, const plume_vec3 *x)
{
	double worst = 0;
	for (int k = 0; k < sim->constraint_count; ++k) {
		if (plume_sim_constraint_held(sim, k))
			continue;
		double s = fabs(constraint_value(sim, x, k, NULL, NULL)) / sim->constraint_length[k];
		worst = s > worst ? s : worst;
	}
	return worst;
}

/// Puts the Lagrangian gradient g + C^T lambda in sim->residual and the right-hand side
/// [-g; -c] in rhs. Returns the residual's infinity norm over free unknowns (with the
/// current multipliers).
static double lagrangian_residual(plume_sim *sim, const plume_vec3 *x, const double *gradient, double *rhs)
{
	int n3 = 3 * sim->vertex_count;
	double *residual = sim->residual;
	memcpy(residual, gradient, sizeof(double) * (size_t)n3);
	plume_sim_add_constraint_forces(sim, x, residual);
	// A barb with both ends held by handles keeps its length (the handle is rigid): nothing
	// to solve.
	for (int k = 0; k < sim->constraint_count; ++k)
		rhs[n3 + k] = plume_sim_constraint_held(sim, k) ? 0 : -constraint_value(sim, x, k, NULL, NULL);
	double norm = 0;
	for (int i = 0; i < n3; ++i)
		if (!sim->fixed[i])
			norm = fmax(norm, fabs(residual[i]));
	for (int i = 0; i < n3; ++i)
		rhs[i] = sim->fixed[i] ? 0 : -gradient[i];
	return norm;
}

void plume_sim_add_constraint_rows(plume_sim *sim, const plume_vec3 *x, bool exact)
{
	double *values = plume_kkt_values(&sim->kkt);
	for (int k = 0; k < sim->constraint_count; ++k) {
		if (plume_sim_constraint_held(sim, k))
			continue;
		plume_vec3 t;
		double l;
		constraint_value(sim, x, k, &t, &l);
		const int *vertices = sim->constraint_vertices + 2 * k;
		const double tv[3] = {t.x, t.y, t.z};
		const int *slots = sim->kkt.constraint_slots + 6 * k;
		for (int a = 0; a < 6; ++a)
			if (!sim->fixed[3 * vertices[a / 3] + a % 3])
				values[slots[a]] += (a < 3 ? -1 : 1) * tv[a % 3];
		// Curvature of the constraint: lambda (I - t t^T) / l on the pair, PSD for lambda > 0
		// (a barb in tension). A compressed barb's part is indefinite: only the exact
		// Hessian takes it (the fallback to projection leaves it out).
		if (sim->lambda[k] > 0 || (exact && sim->lambda[k] != 0)) {
			double block[36];
			for (int a = 0; a < 6; ++a)
				for (int b = 0; b < 6; ++b) {
					double p = ((a % 3) == (b % 3) ? 1 : 0) - tv[a % 3] * tv[b % 3];
					block[6 * a + b] = ((a < 3) == (b < 3) ? 1 : -1) * sim->lambda[k] * p / l;
				}
			plume_sim_scatter_block(sim, values, vertices, 2, sim->kkt.pair_slots + 21 * k, 1, block);
		}
	}
}

void plume_sim_add_constraint_forces(const plume_sim *sim, const plume_vec3 *x, double *forces)
{
	for (int k = 0; k < sim->constraint_count; ++k) {
		if (plume_sim_constraint_held(sim, k))
			continue;
		plume_vec3 t;
		constraint_value(sim, x, k, &t, NULL);
		const int *v = sim->constraint_vertices + 2 * k;
		const double tv[3] = {t.x, t.y, t.z};
		for (int d = 0; d < 3; ++d) {
			forces[3 * v[0] + d] -= sim->lambda[k] * tv[d];
			forces[3 * v[1] + d] += sim->lambda[k] * tv[d];
		}
	}
}

/// Euclidean norm of a vector over the free unknowns.
static double free_norm2(const plume_sim *sim, const double *vector)
{
	double sum = 0;
	for (int i = 0; i < 3 * sim->vertex_count; ++i)
		if (!sim->fixed[i])
			sum += vector[i] * vector[i];
	return sqrt(sum);
}

/// g . dx over the position unknowns (held ones have g = 0).
static double free_dot(const plume_sim *sim, const double *g, const double *step)
{
	double sum = 0;
	for (int i = 0; i < 3 * sim->vertex_count; ++i)
		sum += g[i] * step[i];
	return sum;
}

static void apply_step(const plume_sim *sim, const plume_vec3 *x, const double *step, double alpha, plume_vec3 *out)
{
	for (int i = 0; i < sim->vertex_count; ++i)
		out[i] =
		    plume_v3(x[i].x + alpha * step[3 * i], x[i].y + alpha * step[3 * i + 1], x[i].z + alpha * step[3 * i + 2]);
}

/// Merit of the line search: the potential plus mu times the constraint violation.
/// The l1 merit phi + mu |c|_1 at x; its potential phi in *potential when not NULL.
static double merit(plume_sim *sim, const sim_problem *problem, const plume_vec3 *x, double mu, double *potential)
{
	double phi = plume_sim_potential(sim, problem, x, NULL, false, false);
	if (potential != NULL)
		*potential = phi;
	return sim->constraint_count > 0 ? phi + mu * constraint_norm1(sim, x) : phi;
}

/// Second-order corrections (Nocedal & Wright 2006, section 18.3) at the trial point
/// sim->trial: each is min |dx|_H such that c(y + dx) ~ 0 with the iteration's factors, one
/// solve without refinement (kkt.h), applied up to CORRECTIONS times, and again only
/// while the corrected point's potential alone is within `threshold`. Accepts the first
/// corrected point whose merit is at most `threshold` into sim->trial (its merit in
/// *accepted_merit).
///
/// Why at every trial of the line search and not only the full step's: a step along
/// compressed barbs that buckle moves their vertices sideways, which lengthens every barb
/// edge to second order, so at any step length the merit sees the violation before the
/// potential's decrease; the corrected points follow the barbs' constraint manifold, an arc
/// instead of the chord (the fast projection of Goldenthal et al. 2007 onto inextensible
/// cloth's constraints is the same idea). Measured on Figure 1 at e = 2.5 mm: with the
/// correction only at the full step the run stopped at t = 0.495 s (16 substeps, 50
/// iterations each); with it at every trial it completes (docs/simulation.md).
static bool corrected_trial(plume_sim *sim, const sim_problem *problem, const plume_vec3 *x, double mu,
                            double threshold, double *accepted_merit, plume_solve_report *report, plume_error *err)
{
	int n3 = 3 * sim->vertex_count, m = sim->constraint_count;
	size_t bytes = sizeof(plume_vec3) * (size_t)sim->vertex_count;
	double *correction_rhs = sim->rhs, *correction = sim->gradient; // neither is needed again this iteration
	memcpy(sim->scratch, sim->trial, bytes);
	for (int round = 0; round < CORRECTIONS; ++round) {
		memset(correction_rhs, 0, sizeof(double) * (size_t)n3);
		for (int k = 0; k < m; ++k)
			correction_rhs[n3 + k] =
			    plume_sim_constraint_held(sim, k) ? 0 : -constraint_value(sim, sim->scratch, k, NULL, NULL);
		double solve_start = omp_get_wtime();
		plume_status status = plume_kkt_solve_unrefined(&sim->kkt, correction_rhs, correction, err);
		report->seconds_solve += omp_get_wtime() - solve_start;
		if (status != PLUME_OK)
			return false;
		apply_step(sim, sim->scratch, correction, 1, sim->scratch);
		// The corrected point must be reached without passing through anything, too; it leaves
		// the segment, so the evaluations from here on query again.
		if (plume_contact_on(sim)) {
			sim->contact.reuse_candidates = false;
			double t0 = omp_get_wtime();
			double bound = plume_contact_step_bound(sim, x, sim->scratch, sim->contact.body_x, sim->contact.body_x);
			report->seconds_contact += omp_get_wtime() - t0;
			if (!(bound >= 1))
				return false;
		}
		double potential;
		double corrected = merit(sim, problem, sim->scratch, mu, &potential);
		if (isfinite(corrected) && corrected <= threshold) {
			memcpy(sim->trial, sim->scratch, bytes);
			*accepted_merit = corrected;
			return true;
		}
		// A further correction only moves the point onto the constraints: it can take off
		// the violation's share of the merit, not the potential's. Where the potential
		// alone is above the threshold, the next round fails too: measured, such a round
		// never succeeded (Figure 1 at 5 mm 12 times, at 2.5 mm 79, at 1.25 mm 630 of 2081;
		// coat-settle.json 28, bird-flap.json 3), and each cost a solve and an evaluation.
		if (!(potential <= threshold))
			return false;
	}
	return false;
}

static double force_scale(const plume_sim *sim, double initial_residual)
{
	double gravity = plume_v3_length(sim->def.gravity);
	double scale = initial_residual;
	for (int i = 0; i < sim->vertex_count; ++i)
		scale = fmax(scale, fmax(sim->mass[i] * gravity, plume_v3_length(sim->load[i])));
	return scale;
}

/// Evaluates the potential and its gradient at x, the Lagrangian's residual and the
/// right-hand side, and with `hessian` assembles the matrix (projected or exact Hessian).
static plume_status newton_system(plume_sim *sim, const sim_problem *problem, bool exact, bool hessian, double *phi,
                                  double *residual, plume_solve_report *report, plume_error *err)
{
	int n3 = 3 * sim->vertex_count;
	double *g = sim->gradient;
	double t0 = omp_get_wtime();
	*phi = plume_sim_potential(sim, problem, sim->x, g, hessian, !exact);
	if (isnan(*phi) && plume_contact_on(sim) && sim->contact.failure != PLUME_OK)
		return plume_error_set(err, sim->contact.failure, "%s", sim->contact.message);
	if (isnan(*phi))
		return plume_error_set(err, PLUME_ERROR_NUMERIC, "the potential is not finite (NaN or infinite)");
	if (plume_contact_on(sim)) {
		report->contact_pairs = sim->contact.active_count;
		report->min_distance = fmin(report->min_distance, sim->contact.min_distance);
		sim->contact.step_min_distance = fmin(sim->contact.step_min_distance, sim->contact.min_distance);
	}
	for (int i = 0; i < n3; ++i)
		if (sim->fixed[i])
			g[i] = 0;
	*residual = lagrangian_residual(sim, sim->x, g, sim->rhs);
	if (hessian)
		plume_sim_add_constraint_rows(sim, sim->x, exact);
	report->seconds_assembly += omp_get_wtime() - t0;
	return PLUME_OK;
}

/// Newton checks an iterate's gradient before assembling its Hessian when the iterate is
/// feasible and its quadratic convergence, measured on the last two iterates, predicts a
/// residual at most this many times its tolerance (newton, check_first). Measured, iterates
/// checked first that converged / that did not: Figure 1 at 5 mm 85 / 1 (of 100 steps), at
/// 2.5 mm 82 / 1, wing-draft.json 100 / 0, swing.json 188 / 4, bird-flap.json 209 / 0,
/// coat-settle.json 4 / 1 (its steps converge in one or two iterations, before a
/// contraction is measured). Without the feasibility test (barb strain below
/// STRAIN_TOLERANCE, known before any evaluation) 6-279 checks a scene were wasted; with
/// a threshold of 10, more; checking after every full step wasted 3 checks for each that
/// converged on Figure 1 (at 5 mm 275 of 350).
static const double CHECK_FIRST_PREDICTION = 1;

/// The largest shift (kkt.h) an exact Hessian takes; one that needs more is far from
/// positive definite, and the projected matrix serves better. Measured (Newton iterations
/// a step, wing-draft.json / Figure 1 at 2.5 mm / at 5 mm): up to 1e2, 8.60 / 6.67 / 4.00;
/// 1e-3, 8.42 / 6.56 / 4.00; 1e-4, 7.94 / 6.37 / 3.98; 1e-5, 7.78 / 5.94 / 3.97; 1e-6,
/// 7.66 / 6.25 / 4.12 (the projected fallback alone: 7.59 / stopped / 4.12).
static const double EXACT_SHIFT_LIMIT = 1e-5;
/// The projected matrix is positive semidefinite; a shift only settles free rigid motions
/// (a statics problem with nothing held) and rounding.
static const double PROJECTED_SHIFT_LIMIT = 1e2;

/// The Newton step's backward error (kkt.h): the step is the exact step of a system whose
/// entries are off by this relative amount, an inexact Newton step (Dembo, Eisenstat &
/// Steihaug 1982) with forcing term about 1e-4. Newton's convergence test measures the
/// true residual and the barbs' strain at every iterate, so the tolerance of a step
/// changes how fast Newton gets there, not where it stops. From the multipliers' guess
/// the first solve is usually within it (about 1e-5-1e-6, kkt.h), so most steps take one
/// solve, where 1e-9 took a refinement step more. Measured against 1e-9, 2026-11-28
/// (Newton iterations; largest difference of the last frame): Figure 1 at 5 mm
/// 396 / 396, 7e-12 m, 2.21 -> 1.16 solves an iteration; at 2.5 mm 596 / 598, 8e-12 m;
/// swing.json 1015 / 1013, 1.5e-10 m; wing-draft.json 772 / 772, 2e-12 m; bird-flap.json
/// 886 / 886, 7e-11 m; coat-settle.json 83 / 81, 1.1e-10 m; falling.json 615 / 617,
/// 1.75e-7 m, where a Newton tolerance ten times tighter moves the last frame by
/// 3.1e-6 m: the step's error stays well inside the solver's own. The solves' time fell
/// by 20-50 % on every scene. (Since 2026-11-25 it was 1e-9, one refinement step; before
/// that 1e-14, two or three.)
static const double STEP_BACKWARD_ERROR = 1e-4;

/// Factors the assembled matrix and solves for the step. An exact Hessian that is not
/// positive definite on the constraints' tangent space (a compressed barb's curvature, a
/// vane past its buckling load) is shifted, H + s d I (kkt.h), when a small shift does it:
/// the Levenberg-Marquardt step, which is also the trust-region step of some radius
/// (Nocedal & Wright 2006, Theorem 4.1). Unlike a projected Hessian it keeps the directions
/// that are soft soft and the one that is negative most eager, so Newton leaves the flat
/// state of a vane past its buckling load in a few steps instead of crawling away from it
/// (the lab's quadratic solver found the same, src/lab/quadratic.c). The ladder starts a
/// decade below the last shift that worked: measured on Figure 1 at 2.5 mm, 896
/// factorisations were tried from 1e-10 each time, 542 from a hundredth of the last shift
/// and 456 from a tenth, for the same 668 iterations; starting at the last shift itself
/// took 1108. A ladder that ran out leaves the limit as the last shift, so the next
/// exact Hessian, if it does not factor as it is, tries 0.1 and 1 times the limit instead
/// of the whole ladder from 1e-10 (then six decades): measured (factorisations, Newton iterations), Figure 1 at 5 mm
/// 468 / 397 -> 458 / 396, at 2.5 mm 1176 / 597 -> 1030 / 604, wing-draft.json
/// 1519 / 778 -> 1365 / 779, coat-settle.json 138 / 96 -> 120 / 94; swing.json and
/// bird-flap.json never run out (the same bits).
static plume_status factor_and_solve(plume_sim *sim, bool exact, plume_solve_report *report, plume_error *err)
{
	double t0 = omp_get_wtime(), shift;
	plume_status status = exact ? plume_kkt_factor(&sim->kkt, 0.1 * sim->exact_shift, EXACT_SHIFT_LIMIT, &shift, err)
	                            : plume_kkt_factor(&sim->kkt, 0, PROJECTED_SHIFT_LIMIT, &shift, err);
	report->seconds_factor += omp_get_wtime() - t0;
	if (exact)
		sim->exact_shift = status == PLUME_OK ? shift : EXACT_SHIFT_LIMIT;
	if (status != PLUME_OK)
		return status;
	t0 = omp_get_wtime();
	status = plume_kkt_solve(&sim->kkt, sim->rhs, sim->lambda, STEP_BACKWARD_ERROR, sim->step, err);
	report->seconds_solve += omp_get_wtime() - t0;
	return status;
}

/// A retried step keeps the exact Hessian after a shortened step (newton, below), but not
/// after one the line search cut below this fraction of its length: there the exact matrix
/// is nearly singular along a soft mode, and the next exact step runs off along it again.
/// Traced on Figure 1 at e = 1.25 mm, the step at t = 0.627 s: exact steps of 1.5 to 16 cm
/// on the 20 cm feather, cut to 1e-4 to 2e-6 of their length, one after another, 365
/// iterations in the step with its substeps. A projected step after such a cut makes the
/// progress those did not: 1163 -> 946 Newton iterations for the whole run, 72 -> 53 s
/// (two threads); 1/64 instead of 1e-3 gives 945. At 0.9 mm (the stall the retries keep
/// the exact Hessian for) the rule acts twice and the run still completes, 1098 -> 1096
/// iterations. No example scene, nor Figure 1 at 5, 2.5 or 1.75 mm, retries a step with a
/// cut so short (the same bits). tests/slow/figure1_fine.sh holds the 1.25 mm run through
/// that step to its iteration count (783 with the rule, 1000 without).
static const double RETRY_MIN_STEP_FRACTION = 1e-3;

/// Largest force component on a free unknown: elastic (the gradient) or constraint (C^T lambda).
static double largest_force(const plume_sim *sim, const double *gradient)
{
	double largest = 0;
	for (int i = 0; i < 3 * sim->vertex_count; ++i)
		if (!sim->fixed[i])
			largest = fmax(largest, fabs(gradient[i]));
	for (int k = 0; k < sim->constraint_count; ++k)
		largest = fmax(largest, fabs(sim->lambda[k]));
	return largest;
}

static plume_status newton(plume_sim *sim, const sim_problem *problem, plume_solve_report *report, plume_error *err)
{
	const plume_solver_def *solver = &sim->def.solver;
	int n3 = 3 * sim->vertex_count, m = sim->constraint_count;
	plume_vec3 *x = sim->x;
	double *g = sim->gradient, *step = sim->step;
	double mu = 0, scale = 0;
	// Projected Hessians make every step a descent step; near the solution they slow
	// Newton to a linear rate (bending's indefinite part is dropped). So a solve starts
	// exact and goes on exact after every full step, projected after a shortened one. An
	// exact Hessian that is not positive definite on the constraints' tangent space (the
	// Cholesky factorisation of H + C^T R C fails, kkt.h, free once factored) is shifted
	// until it is (factor_and_solve). (The sign of g . dx is no test: on a constrained
	// step it is positive whenever reaching the constraints costs potential, and the merit
	// still descends.)
	bool exact = !sim->exact_hessian_failed;
	sim->exact_hessian_failed = false;
	report->converged = false;
	report->newton_iterations = 0;
	report->contact_pairs = 0;
	report->min_distance = INFINITY;
	sim->trace_count = 0;
	bool contact = plume_contact_on(sim);
	// IPC's termination (Li et al. 2020, section 5.4): with pairs in reach, the barrier's
	// stiffness makes force residuals a poor test; a step below CONTACT_VELOCITY_TOLERANCE
	// of the shell's size per second (times the step length h) means the iterate has stopped.
	double h = problem->dynamic ? problem->h : 1;
	double previous_closest = INFINITY;
	// The last iterate's residual over its tolerance, q, and Newton's last measure of its
	// quadratic convergence, C in q_{k+1} = C q_k^2, from two iterates a full step apart.
	double previous_ratio = 0, contraction = 0, last_residual = 0, last_scale = 0;
	// Whether the exact Hessian ran out of shifts since the last full step: the exact one is
	// then tried again only after the full step after that. Traced on Figure 1 at 2.5 mm,
	// the next exact attempt ran out too about half the time (three more factorisations
	// each). Measured (factorisations, Newton iterations), retrying after the next full
	// step against after the one after it: Figure 1 at 2.5 mm 946 / 596 -> 863 / 596, at
	// 5 mm 442 / 397 -> 435 / 396, wing-draft.json 1246 / 774 -> 1153 / 772,
	// coat-settle.json 121 / 95 -> 111 / 96.
	bool ran_out = false;
	// The first iteration's model takes the Kikuuwe term's secant curvature towards each
	// face's J at the step's start (membrane.h, plume_compression_density), the later ones
	// the exact curvature; the gradient, and so where Newton stops, is the same. On the
	// first iteration of a step a triangle the prediction left stretched has no
	// compression stiffness in the exact model, and the exact step compresses it several
	// times as far as it ends, to be halved back over three or four iterations (thesis eq.
	// 6.6's cubic; docs/simulation.md, "What the ordinary steps' iterations go to"). Measured
	// (Newton iterations of the whole scene, exact -> secant): Figure 1 at 5 mm 396 -> 343,
	// at 2.5 mm 598 -> 505, at 1.75 mm 743 -> 594, at 1.25 mm 1036 -> 1163 (another wrinkle
	// pattern, reached through one step of 365 iterations; its first 0.165 s 112 -> 86),
	// swing.json 1013 -> 799, bird-flap.json 886 -> 772, falling.json 617 -> 583,
	// figure6.5-pull.json 267 -> 245, coat-settle.json 86 -> 71, wing-draft.json 772 -> 777.
	// The secant at every iteration took wing-draft.json to 1639.
	sim_problem exact_model = *problem;
	exact_model.start_area_ratio = NULL;

	for (int iteration = 0;; ++iteration) {
		const sim_problem *model = iteration == 0 ? problem : &exact_model;
		double phi, residual;
		// Where Newton's quadratic convergence predicts that a full step has reached the
		// tolerance, the gradient alone says whether it has, and the Hessian, several times
		// the gradient's cost, is assembled only when it has not: otherwise the iterate that
		// converges pays for a Hessian no one factors (CHECK_FIRST_PREDICTION).
		bool full_step = iteration > 0 && exact;
		bool feasible = max_constraint_strain(sim, x) <= STRAIN_TOLERANCE;
		double predicted = contraction * previous_ratio * previous_ratio;
		bool check_first = feasible && full_step && contraction > 0 && predicted <= CHECK_FIRST_PREDICTION;
		plume_status status = newton_system(sim, model, exact, !check_first, &phi, &residual, report, err);
		if (status != PLUME_OK)
			return status;
		if (iteration == 0)
			scale = force_scale(sim, residual);
		// Roundoff in the residual is relative to the forces that cancel in it.
		double tolerance_scale = fmax(scale, largest_force(sim, g));
		double ratio = residual / (solver->tolerance * tolerance_scale);
		if (full_step && previous_ratio > 0)
			contraction = ratio / (previous_ratio * previous_ratio);
		previous_ratio = ratio;
		last_residual = residual;
		last_scale = tolerance_scale;
		report->energy = phi;
		report->gradient_norm = free_norm2(sim, sim->residual);
		report->max_barb_strain = plume_sim_max_barb_strain(sim, x);
		if (feasible && residual <= solver->tolerance * tolerance_scale) {
			report->converged = true;
			return PLUME_OK;
		}
		if (iteration >= solver->max_iterations)
			break;
		if (check_first) {
			status = newton_system(sim, model, exact, true, &phi, &residual, report, err);
			if (status != PLUME_OK)
				return status;
		}

		status = factor_and_solve(sim, exact, report, err);
		double slope = status == PLUME_OK ? free_dot(sim, g, step) : 0;
		// Without constraints g . dx must be negative: a Cholesky factorisation that
		// succeeds on a matrix that is positive definite only to rounding can still give
		// an ascent step. (With constraints its sign is no test, see above.)
		if (exact && (status == PLUME_ERROR_NUMERIC || (m == 0 && status == PLUME_OK && slope >= 0))) {
			// The exact Hessian needs more than EXACT_SHIFT_LIMIT times its mean diagonal to
			// factor (kkt.h), or gave an ascent step: project. The exact one is tried again after a full step
			// (projected Newton alone is linear, too slow on the lab's locked meshes), and the next solve starts
			// projected.
			exact = false;
			sim->exact_hessian_failed = true;
			ran_out = status == PLUME_ERROR_NUMERIC;
			status = newton_system(sim, model, exact, true, &phi, &residual, report, err);
			if (status == PLUME_OK)
				status = factor_and_solve(sim, exact, report, err);
			slope = status == PLUME_OK ? free_dot(sim, g, step) : 0;
		}
		if (status != PLUME_OK)
			return status;
		++report->newton_iterations;

		double largest_multiplier = 0, step_size = 0;
		for (int k = 0; k < m; ++k)
			largest_multiplier = fmax(largest_multiplier, fabs(step[n3 + k]));
		for (int i = 0; i < n3; ++i)
			step_size = fmax(step_size, fabs(step[i]));
		mu = fmax(mu, 2 * largest_multiplier + 1e-300);
		double violation = m > 0 ? constraint_norm1(sim, x) : 0;
		slope -= mu * violation;
		double current = phi + mu * violation;

		// Continuous collision detection: the largest step fraction that keeps every pair at
		// least ccd_separation of its distance (IPC section 5, "filtered line search").
		double bound = 1;
		if (contact) {
			apply_step(sim, x, step, 1, sim->trial);
			double t0 = omp_get_wtime();
			bound = plume_contact_step_bound(sim, x, sim->trial, sim->contact.body_x, sim->contact.body_x);
			report->seconds_contact += omp_get_wtime() - t0;
			if (isnan(bound))
				return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory finding contact pairs");
			// Those candidates hold every pair in reach anywhere on the segment x -> x + step:
			// the line search's evaluations and the next iteration's assembly use them.
			sim->contact.reuse_candidates = true;
		}

		// The Newton decrement in length form: a step below tolerance of the shell's size
		// changes nothing that matters; take it and stop. With contact pairs in reach, IPC's
		// criterion on the step per unit time too.
		bool stopped =
		    step_size <= solver->tolerance * sim->length_scale ||
		    (contact && report->contact_pairs > 0 && step_size <= CONTACT_VELOCITY_TOLERANCE * sim->length_scale * h);
		if (feasible && bound >= 1 && stopped) {
			apply_step(sim, x, step, 1, sim->trial);
			memcpy(x, sim->trial, sizeof(plume_vec3) * (size_t)sim->vertex_count);
			for (int k = 0; k < m; ++k)
				sim->lambda[k] = step[n3 + k];
			// The step is below tolerance, but it moves the barbs' ends to second order: a
			// step of s on an edge of length l strains it by up to about (s / l)^2 / 2,
			// 5e-10 for 2e-8 m on a 0.9 mm edge, 1.4e-7 traced there with a tolerance of
			// 1e-6. Converged only if the barbs still hold; if not, iterate on from here.
			if (max_constraint_strain(sim, x) > STRAIN_TOLERANCE)
				continue;
			report->max_barb_strain = plume_sim_max_barb_strain(sim, x);
			report->converged = true;
			return PLUME_OK;
		}

		// Backtracking (Armijo) on the merit; second-order corrections at every trial the step
		// alone fails (corrected_trial).
		double alpha = bound, accepted_merit = current;
		bool accepted = false;
		if (!(alpha > 0))
			break; // CCD allows no motion at all (a pair that starts in contact): no step to take
		for (int backtrack = 0; backtrack < MAX_BACKTRACKS && !accepted; ++backtrack) {
			apply_step(sim, x, step, alpha, sim->trial);
			double trial = merit(sim, &exact_model, sim->trial, mu, NULL);
			if (isfinite(trial) && trial <= current + 1e-4 * alpha * fmin(slope, 0)) {
				accepted = true;
				accepted_merit = trial;
				break;
			}
			if (m > 0 && corrected_trial(sim, &exact_model, x, mu, current + 1e-4 * alpha * fmin(slope, 0),
			                             &accepted_merit, report, err)) {
				accepted = true;
				break;
			}
			alpha *= 0.5;
		}
		if (!accepted)
			break;
		// The merit before and after the step, under the same penalty (mu can grow from one
		// iteration to the next, so merits of different iterations do not compare).
		if (sim->trace_count + 2 <= PLUME_SIM_TRACE) {
			sim->trace[sim->trace_count++] = current;
			sim->trace[sim->trace_count++] = accepted_merit;
		}
		memcpy(x, sim->trial, sizeof(plume_vec3) * (size_t)sim->vertex_count);
		for (int k = 0; k < m; ++k)
			sim->lambda[k] += alpha * (step[n3 + k] - sim->lambda[k]);
		// After a shortened step the next is projected: a descent step where the exact one's
		// quadratic model did not hold. Near an unstable equilibrium that alternation stalls:
		// the projected steps move a few 1e-8 m and the exact ones are cut to 1/32 and less,
		// whatever the substeps (docs/simulation.md, "The 0.9 mm stop"). A step retried in
		// substeps has stalled so in its first try, and keeps the exact Hessian instead: the
		// 0.9 mm run completes, and the 1.25 mm run (two steps retried) takes 1036 Newton
		// iterations instead of 1081. Keeping it in every first try too took 1296 there.
		// Except after a step cut below RETRY_MIN_STEP_FRACTION, which moved nothing.
		exact = (alpha == 1 || (sim->retrying && alpha >= RETRY_MIN_STEP_FRACTION)) && !ran_out;
		if (alpha == 1)
			ran_out = false;
		// IPC's adaptive stiffness within a solve (Li et al. 2020, supplement): an accepted
		// iterate far inside the barrier's reach and closer than the one before says the barrier
		// is too soft to stop this motion: double it. The potential changes, so the merit's trace
		// (which must decrease) starts again. The last evaluation was at the accepted iterate.
		if (contact && sim->def.contact.adaptive_stiffness) {
			double closest = sim->contact.min_distance;
			if (plume_contact_stiffen(sim, previous_closest, closest))
				sim->trace_count = 0;
			previous_closest = closest;
		}
	}
	report->max_barb_strain = plume_sim_max_barb_strain(sim, x);
	// How far from converged, in the terms of the test above: a step that stalls a few times
	// above its tolerance with its barbs feasible (a vane at an unstable equilibrium, docs/
	// simulation.md, Speed) reads differently from one that is far off. The tolerance is
	// relative to the largest force, so a residual can be huge and within it: then the barbs
	// are what failed, and the message says so.
	const char *failed =
	    previous_ratio <= 1 ? "the forces balance, the barbs do not hold" : "the forces do not balance";
	return plume_error_set(err, PLUME_ERROR_NUMERIC,
	                       "Newton did not converge in %d iterations (%s: largest force residual %.3g N, %.3g times "
	                       "its tolerance, %.0e of the largest force, %.3g N; gradient norm %.3g N; barb strain %.3g, "
	                       "tolerance %.0e)",
	                       report->newton_iterations, failed, last_residual, previous_ratio, solver->tolerance,
	                       last_scale, report->gradient_norm, report->max_barb_strain, STRAIN_TOLERANCE);
}

plume_status plume_sim_newton(plume_sim *sim, const sim_problem *problem, plume_solve_report *report, plume_error *err)
{
	sim->contact.reuse_candidates = false;
	plume_status status = newton(sim, problem, report, err);
	sim->contact.reuse_candidates = false;
	return status;
}

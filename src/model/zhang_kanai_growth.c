// Helical growth (Zhang & Kanai IV-A).
//
// Two emitters start at the boundaries of I_A and move towards I_P at V_e(s);
// after moving a total distance D_i = (i + 1) d an emitter emits barb i there
// (emission continues at the rate V_e(I_P) / d once the emitter is clamped at
// I_P). A barb particle then moves back towards I_A at V_b(s) and every
// Runge–Kutta step records a point of the barb; when it reaches I_A the barb
// is mature. On the collar of perimeter L, a locus moves at
//   ds/dt = sigma V(s) / L                                          (eq. 2)
// integrated by the classic fourth-order Runge–Kutta method with the step h;
// eq. 3-4 are its integral form, clamped at I_P. Crossings of a locus inside
// a step (an emission distance, I_P, I_A) are found on the step's cubic
// Hermite interpolant, so their times do not snap to the step grid.
// The growth terminates at t_end, when N barbs of either vane are mature.
//
// A 1D autonomous flow keeps its particles in order, so barbs mature in
// emission order, and every barb emitted at the clamped emitter (s0 = I_P)
// follows the same pathline: it is integrated once and reused.
#include <math.h>
#include <string.h>

#include "../core/alloc.h"
#include "feather_internal.h"
#include "zhang_kanai_internal.h"

/// Upper bounds that turn a runaway spec into an error instead of a hang.
enum { MAX_STEPS_PER_PATH = 2000000, MAX_EMISSIONS_PER_VANE = 200000 };
/// The bound on the steps of all pathlines of one growth, both vanes. The bounds above are
/// each item's: 86,000 emissions of pathlines 10^4 steps long passed neither and took 21 s
/// (a fuzzed spec: a 9 m collar, an emitter at 800 m/s on part of it). Measured: the 2 x
/// 400-barb benchmark feather takes 5.6e4 (bench_zhang_kanai), the examples 1.4e3 to 7.8e3;
/// 4e7 take about 0.3 s.
#define MAX_GROWTH_PATHLINE_STEPS 4e7
/// An emitter may take this many steps: it crosses the whole I_A-I_P path once, where a pathline crosses part.
#define MAX_EMITTER_STEPS (8L * MAX_STEPS_PER_PATH)

/// Which bound a runaway growth passed: fail_runaway names the keys that move it.
typedef enum zk_runaway {
	RUNAWAY_PATHLINE,  ///< a barb needs more than MAX_STEPS_PER_PATH steps to reach I_A
	RUNAWAY_EMISSIONS, ///< a vane emits more than MAX_EMISSIONS_PER_VANE barbs before barb N - 1 matures
	RUNAWAY_EMITTER,   ///< an emitter needs more than MAX_EMITTER_STEPS steps to its next emission
	RUNAWAY_WORK,      ///< the pathlines together need more than MAX_GROWTH_PATHLINE_STEPS steps
} zk_runaway;

typedef struct zk_flow {
	const zk_curve *speed;
	double scale; ///< sigma / L: ds/dt = scale V(s)
} zk_flow;

static double flow_rate(const zk_flow *flow, double s) { return flow->scale * zk_curve_eval(flow->speed, s); }

static double rk4_step(const zk_flow *flow, double s, double h)
{
	double k1 = flow_rate(flow, s);
	double k2 = flow_rate(flow, s + 0.5 * h * k1);
	double k3 = flow_rate(flow, s + 0.5 * h * k2);
	double k4 = flow_rate(flow, s + h * k3);
	return s + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

/// Time in [0, h] at which the cubic Hermite interpolant of a step from s0
/// to s1 reaches target, sigma (target - s0) > 0 and sigma (s1 - target) >= 0.
static double crossing_time(const zk_flow *flow, double s0, double s1, double h, double target)
{
	double sigma = flow->scale > 0.0 ? 1.0 : -1.0;
	double d0 = h * flow_rate(flow, s0), d1 = h * flow_rate(flow, s1);
	double lo = 0.0, hi = 1.0;
	// Bisection to the last bit: a handful of cubic evaluations, once per event.
	for (int i = 0; i < 64; ++i) {
		double u = 0.5 * (lo + hi);
		if (u <= lo || u >= hi)
			break;
		double u2 = u * u, u3 = u2 * u;
		double value = (2 * u3 - 3 * u2 + 1) * s0 + (u3 - 2 * u2 + u) * d0 + (-2 * u3 + 3 * u2) * s1 + (u3 - u2) * d1;
		if (sigma * (value - target) >= 0.0)
			hi = u;
		else
			lo = u;
	}
	return hi * h;
}

// ---------------------------------------------------------------------------
// Barb pathlines

typedef struct zk_vane {
	zk_flow emitter, barb;
	double s_anterior, s_posterior; ///< this side's boundaries of I_A and I_P
	double length, h;
	int f;
	double ridge_width, variation;
	plume_rng rng;
	double *pathline_steps; ///< the steps of every pathline integrated so far, both vanes'
} zk_vane;

/// Where a pathline ends: K whole steps, then a last part of length tail.
typedef struct path_end {
	long steps;
	double tail;
	bool reached; ///< the root reached I_A (else it stopped at t_stop)
	int count;    ///< points kept after downsampling
} path_end;

/// Where a pathline writes its points: arrays of the pathline's size (grows
/// false), or arrays that keep the points of many pathlines one after the
/// other, each from first on, and grow up to MAX_KEPT_POINTS in all.
typedef struct path_points {
	double *locus, *time;
	int first, capacity;
	bool grows;
	bool full;          ///< a point did not fit: the pathline's points are incomplete
	bool out_of_memory; ///< full because growing failed (else the bound was reached)
} path_points;

/// The bound on points kept for reuse (64 MiB): a runaway spec integrates
/// again instead of holding every step it took.
enum { MAX_KEPT_POINTS = 1 << 22 };

/// Stores point `at` of the pathline being written.
static void keep_point(path_points *points, int at, double s, double t)
{
	if (points == NULL || points->full)
		return;
	int index = points->first + at;
	if (points->grows && index >= points->capacity) {
		int capacity = points->capacity > 0 ? points->capacity : 1024;
		while (capacity <= index && capacity <= MAX_KEPT_POINTS)
			capacity *= 2;
		double *locus = capacity > MAX_KEPT_POINTS ? NULL : plume_realloc(points->locus, capacity * sizeof *locus);
		if (locus != NULL)
			points->locus = locus;
		double *time = locus == NULL ? NULL : plume_realloc(points->time, capacity * sizeof *time);
		if (time == NULL) {
			points->full = true;
			points->out_of_memory = capacity <= MAX_KEPT_POINTS;
			return;
		}
		points->time = time;
		points->capacity = capacity;
	}
	points->locus[index] = s;
	points->time[index] = t;
}

/// Integrates a barb from (s0, t0) towards I_A until it arrives or t_stop.
/// Keeps every f-th step and the last point; writes them when points is not NULL.
static plume_status pathline(const zk_vane *vane, double s0, double t0, double t_stop, path_points *points,
                             path_end *end)
{
	const double h = vane->h, target = vane->s_anterior;
	const double sigma = vane->barb.scale > 0.0 ? 1.0 : -1.0;
	int count = 0;
	keep_point(points, 0, s0, t0);
	count = 1;
	double s = s0;
	long kept = 0; // the last step whose point was kept
	*end = (path_end){0};
	if (!(t0 < t_stop)) {
		end->count = 1;
		return PLUME_OK;
	}
	// What is left of the growth's budget, counted in this loop's k (the shared total once, here).
	const double budget = MAX_GROWTH_PATHLINE_STEPS - *vane->pathline_steps;
	for (long k = 0;; ++k) {
		if (k >= MAX_STEPS_PER_PATH)
			return PLUME_ERROR_NUMERIC;
		if ((double)k >= budget) {
			*vane->pathline_steps += (double)k; // fail_runaway reads which bound it was
			return PLUME_ERROR_NUMERIC;
		}
		double tk = t0 + (double)k * h;
		double step = h;
		bool last = false;
		if (tk + h >= t_stop) {
			step = t_stop - tk;
			last = true;
		}
		double next = rk4_step(&vane->barb, s, step);
		bool reached = sigma * (next - target) >= 0.0;
		if (reached || last) {
			double tail = reached ? crossing_time(&vane->barb, s, next, step, target) : step;
			// An end a rounding error away from a kept step point replaces it
			// instead of making a segment of zero length.
			int at = (tail <= 1e-9 * h && kept == k && count > 1) ? count - 1 : count;
			keep_point(points, at, reached ? target : next, reached ? tk + tail : t_stop);
			*end = (path_end){.steps = k, .tail = tail, .reached = reached, .count = at + 1};
			*vane->pathline_steps += (double)k + 1.0;
			return PLUME_OK;
		}
		s = next;
		if ((k + 1) % vane->f == 0) {
			keep_point(points, count, s, t0 + (double)(k + 1) * h);
			++count;
			kept = k + 1;
		}
	}
}

// ---------------------------------------------------------------------------
// Emitters

typedef struct emitter {
	double s, next;
	long k;
	bool have_next;
	bool clamped;
	double clamp_time;
	double variation_sum; ///< sum of the r_i drawn so far
	int emitted;
	double goal; ///< the distance from I_A it was moving to when it passed MAX_EMITTER_STEPS (the message's)
} emitter;

/// Advances the emitter's steps until its locus reaches target; returns the
/// time, or INFINITY when the step grid passes t_limit or MAX_EMITTER_STEPS first.
static double advance_to(const zk_vane *vane, emitter *em, double target, double t_limit)
{
	const double sigma = vane->emitter.scale > 0.0 ? 1.0 : -1.0, h = vane->h;
	for (;;) {
		if ((double)em->k * h > t_limit || em->k >= MAX_EMITTER_STEPS)
			return INFINITY;
		if (!em->have_next) {
			em->next = rk4_step(&vane->emitter, em->s, h);
			em->have_next = true;
		}
		if (sigma * (em->next - target) >= 0.0)
			return (double)em->k * h + crossing_time(&vane->emitter, em->s, em->next, h, target);
		em->s = em->next;
		em->have_next = false;
		em->k++;
	}
}

/// Emission i: P_0.t and P_0.locus (eq. 3-4 with the thresholds D_i). Fails
/// (PLUME_ERROR_NUMERIC) when the emission time is not finite: an emitter so slow
/// for the step that it passed MAX_EMITTER_STEPS before reaching D_i. That time
/// was once stored as the emission time, and an infinite P_0.t gave barbs at
/// y = v_grow (t_curr - t) = inf or NaN (eq. 5) and a feather written with exit 0.
static plume_status emit(zk_vane *vane, emitter *em, double *t0, double *s0)
{
	double r = vane->variation > 0.0 ? plume_rng_range(&vane->rng, -vane->variation, vane->variation) : 0.0;
	em->variation_sum += r;
	double distance = vane->ridge_width * ((double)(em->emitted + 1) + em->variation_sum);
	em->emitted++;
	double sigma = vane->emitter.scale > 0.0 ? 1.0 : -1.0;
	double target = vane->s_anterior + sigma * distance / vane->length;
	double clamp_distance = vane->length * fabs(vane->s_posterior - vane->s_anterior);
	em->goal = fmin(distance, clamp_distance);
	if (!em->clamped && sigma * (target - vane->s_posterior) < 0.0) {
		*t0 = advance_to(vane, em, target, INFINITY);
		*s0 = target;
		return isfinite(*t0) ? PLUME_OK : PLUME_ERROR_NUMERIC;
	}
	if (!em->clamped) {
		em->clamp_time = advance_to(vane, em, vane->s_posterior, INFINITY);
		if (!isfinite(em->clamp_time))
			return PLUME_ERROR_NUMERIC;
		em->clamped = true;
	}
	// Clamped at I_P, the emitter keeps "moving" at V_e(I_P) for emission.
	double extra = fmax(0.0, distance - clamp_distance);
	*t0 = em->clamp_time + extra / zk_curve_eval(vane->emitter.speed, vane->s_posterior);
	*s0 = vane->s_posterior;
	return isfinite(*t0) ? PLUME_OK : PLUME_ERROR_NUMERIC;
}

// ---------------------------------------------------------------------------
// The growth

typedef struct emission {
	double t0, s0, mature_time;
	path_end end;
	int point_first; ///< its pathline's points in the vane's kept points, or -1 when not kept
} emission;

typedef struct vane_run {
	zk_vane vane;
	emitter em;
	emission *list;
	int count, capacity;
	bool have_cache; ///< the pathline from I_P, integrated once
	path_end cache;
	/// The points of every pathline integrated to its end: the barbs that mature copy them instead of
	/// integrating their pathline a second time.
	path_points kept;
	int kept_count;
	zk_runaway runaway;  ///< the bound passed, when add_emission failed with PLUME_ERROR_NUMERIC
	int vane_barb_count; ///< N, for fail_runaway's message
} vane_run;

static plume_status add_emission(vane_run *run)
{
	run->runaway = RUNAWAY_EMISSIONS;
	if (run->count >= MAX_EMISSIONS_PER_VANE)
		return PLUME_ERROR_NUMERIC;
	if (PLUME_GROW(run->list, run->capacity, run->count + 1) != 0)
		return PLUME_ERROR_MEMORY;
	emission *e = run->list + run->count;
	run->runaway = RUNAWAY_EMITTER;
	if (emit(&run->vane, &run->em, &e->t0, &e->s0) != PLUME_OK)
		return PLUME_ERROR_NUMERIC;
	run->runaway = RUNAWAY_PATHLINE;
	e->point_first = -1;
	if (e->s0 == run->vane.s_posterior && run->have_cache) {
		e->end = run->cache;
	} else {
		run->kept.first = run->kept_count;
		run->kept.full = false;
		plume_status status = pathline(&run->vane, e->s0, e->t0, INFINITY, &run->kept, &e->end);
		if (status != PLUME_OK)
			return status;
		if (run->kept.out_of_memory)
			return PLUME_ERROR_MEMORY;
		if (!run->kept.full) {
			e->point_first = run->kept_count;
			run->kept_count += e->end.count;
		}
		if (e->s0 == run->vane.s_posterior) {
			run->cache = e->end;
			run->have_cache = true;
		}
	}
	// The same expression pathline() uses for its last point's time.
	e->mature_time = (e->t0 + (double)e->end.steps * run->vane.h) + e->end.tail;
	run->count++;
	return PLUME_OK;
}

static void vane_setup(vane_run *run, const plume_zk_def *def, const zk_collar *collar, const zk_curve *ve,
                       const zk_curve *vb, plume_side side, plume_rng rng)
{
	// The left emitter moves from I_A.left down to I_P.left (eq. 3), the right
	// one from I_A.right up to I_P.right (eq. 4); barbs elongate the other way.
	double sigma = side == PLUME_SIDE_LEFT ? -1.0 : 1.0;
	memset(run, 0, sizeof *run);
	run->vane = (zk_vane){
	    .emitter = {ve, sigma / collar->length},
	    .barb = {vb, -sigma / collar->length},
	    .s_anterior = def->anterior[side],
	    .s_posterior = def->posterior[side],
	    .length = collar->length,
	    .h = def->step,
	    .f = def->downsample,
	    .ridge_width = def->ridge_width,
	    .variation = def->ridge_width_variation,
	    .rng = rng,
	};
	run->em.s = run->vane.s_anterior;
	run->em.clamp_time = INFINITY;
	run->runaway = RUNAWAY_PATHLINE;
	run->vane_barb_count = def->barb_count;
	run->kept.grows = true;
}

static void vane_free(vane_run *run)
{
	plume_free(run->list);
	plume_free(run->kept.locus);
	plume_free(run->kept.time);
}

void zk_growth_free(zk_growth *growth)
{
	plume_free(growth->barbs);
	plume_free(growth->locus);
	plume_free(growth->time);
	memset(growth, 0, sizeof *growth);
}

/// The smallest (largest when want_max) control value of a distribution: its monotone cubic stays between them.
static double curve_extreme(const plume_zk_curve *curve, bool want_max)
{
	double value = curve->value[0];
	for (int k = 1; k < curve->count && k < PLUME_ZK_MAX_CURVE_POINTS; ++k)
		value = want_max ? fmax(value, curve->value[k]) : fmin(value, curve->value[k]);
	return value;
}

/// The collar's perimeter or, for the Bezier collar, the length of its segments' control polygons
/// (zk_collar_init's Catmull-Rom inner points), which bounds it from above.
static double collar_length_bound(const plume_zk_def *def)
{
	if (def->collar_kind != PLUME_ZK_COLLAR_BEZIER)
		return 6.283185307179586 * def->collar_radius; // 2 pi R
	int n = def->collar_point_count;
	if (n < 4 || n > PLUME_ZK_MAX_COLLAR_POINTS)
		return INFINITY; // refused by validation
	const plume_vec2 *p = def->collar_points;
	double length = 0.0;
	for (int k = 0; k < n; ++k) {
		plume_vec2 a = p[k], b = p[(k + 1) % n], before = p[(k + n - 1) % n], after = p[(k + 2) % n];
		plume_vec2 c1 = {a.x + (b.x - before.x) / 6.0, a.y + (b.y - before.y) / 6.0};
		plume_vec2 c2 = {b.x - (after.x - a.x) / 6.0, b.y - (after.y - a.y) / 6.0};
		length += hypot(c1.x - a.x, c1.y - a.y) + hypot(c2.x - c1.x, c2.y - c1.y) + hypot(b.x - c2.x, b.y - c2.y);
	}
	return length;
}

/// Points a pathline of at most length metres keeps: its first, every f-th of its whole steps, its
/// last (pathline()). RK4's increment is h times a mean of V_b at its stages, each at least the
/// curve's smallest control value v_min, so every whole step moves at least h v_min along the collar:
/// at most length / (h v_min) whole steps (one more for rounding where that is near a whole number),
/// and never more than MAX_STEPS_PER_PATH (growth refuses more).
static double pathline_points(double length, double h, double v_min, double f)
{
	return 2.0 + floor(fmin((double)MAX_STEPS_PER_PATH, floor(length / (h * v_min)) + 1.0) / f);
}

double plume_zk_estimate_bytes(const plume_zk_def *def)
{
	double perimeter = collar_length_bound(def), v_min = curve_extreme(&def->barb_speed, false);
	double h = def->step, f = (double)(def->downsample > 0 ? def->downsample : 1);
	double d = def->ridge_width, variation = def->ridge_width_variation;
	int n = def->barb_count > 0 && def->barb_count <= PLUME_ZK_MAX_BARBS ? def->barb_count : 0;
	if (!(v_min > 0.0 && h > 0.0 && d > 0.0 && perimeter >= 0.0 && variation >= 0.0 && variation < 1.0) || n == 0)
		return INFINITY; // refused by validation
	double points = 0.0, barbs = 0.0;
	for (int side = 0; side < 2; ++side) {
		// A barb grows from where it was emitted back to I_A: at most this vane's path from I_A to I_P.
		double path = perimeter * fabs(def->posterior[side] - def->anterior[side]);
		// Mature barbs: at most N a vane (N of one vane end the growth; below stage 1 fewer are), the
		// first N emitted, as barbs mature in emission order. Barb i leaves the ridge D_i =
		// d ((i + 1) + the sum of its r_j) <= d (i + 1) (1 + v) from I_A, or at I_P.
		for (int i = 0; i < n; ++i)
			points += pathline_points(fmin(path, d * (i + 1) * (1.0 + variation)), h, v_min, f);
		barbs += n;
		if (def->growth_stage >= 1.0)
			continue; // IV-A Termination: the developing barbs are discarded
		// Below stage 1 the developing barbs are kept, each as far as it grew: one younger than the
		// longest pathline time T each, emitted at least delta = d (1 - v) / max V_e apart. Their ages
		// are below T, T - delta, T - 2 delta, ...: their points sum to less than that series'.
		double t_max = path / v_min, rate_max = curve_extreme(&def->emitter_speed, true);
		double delta = d * (1.0 - variation) / rate_max;
		double count = fmin((double)MAX_EMISSIONS_PER_VANE, ceil(t_max / delta));
		double ages = count * t_max - delta * count * (count - 1.0) / 2.0;
		points += 3.0 * count + fmin(ages / h, count * (double)MAX_STEPS_PER_PATH) / f;
		barbs += count;
	}
	bool barbules = def->expansion && def->keep_barbules;
	return plume_feather_layout_bytes(points * (barbules ? 5.0 : 1.0), barbs, barbules ? 2.0 * points : 0.0,
	                                  def->shaft_samples);
}

/// A runaway growth is the spec's doing (a speed too slow or too fast for the step and the
/// ridge width): PLUME_ERROR_SPEC, naming the keys that end it.
static plume_status fail_runaway(plume_status status, const vane_run *runs, plume_error *err)
{
	if (status == PLUME_ERROR_MEMORY)
		return plume_error_set(err, status, "out of memory while growing the barbs");
	if (status != PLUME_ERROR_NUMERIC)
		return status; // the message is set
	int side = runs[PLUME_SIDE_LEFT].runaway != RUNAWAY_PATHLINE ? PLUME_SIDE_LEFT : PLUME_SIDE_RIGHT;
	const vane_run *run = runs + side;
	const char *name = side == PLUME_SIDE_LEFT ? "left" : "right";
	zk_runaway runaway = *run->vane.pathline_steps >= MAX_GROWTH_PATHLINE_STEPS ? RUNAWAY_WORK : run->runaway;
	switch (runaway) {
	case RUNAWAY_WORK:
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "the growth is too long: its pathlines need more than %g steps of $.step (%g s) in "
		                       "all (%d barbs emitted on the left vane, %d on the right, of a %g m collar); raise "
		                       "$.step, $.barb_speed or $.ridge_width, or lower $.emitter_speed or $.collar.radius",
		                       MAX_GROWTH_PATHLINE_STEPS, run->vane.h, runs[PLUME_SIDE_LEFT].count,
		                       runs[PLUME_SIDE_RIGHT].count, run->vane.length);
	case RUNAWAY_EMITTER:
		return plume_error_set(
		    err, PLUME_ERROR_SPEC,
		    "$.emitter_speed: the growth does not end: the %s emitter needs more than %ld steps of $.step (%g s) to "
		    "move %g m along the collar from I_A (for its barb %d); V_e is %g m/s where it stopped, too slow for the "
		    "step; raise $.emitter_speed or $.step",
		    name, MAX_EMITTER_STEPS, run->vane.h, run->em.goal, run->count,
		    zk_curve_eval(run->vane.emitter.speed, run->em.s));
	case RUNAWAY_EMISSIONS:
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "the growth does not end: the %s vane emits more than %d barbs before its barb %d "
		                       "matures; lower $.emitter_speed, or raise $.ridge_width or $.barb_speed",
		                       name, (int)MAX_EMISSIONS_PER_VANE, run->vane_barb_count - 1);
	case RUNAWAY_PATHLINE:
	default:
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "the growth does not end: a barb needs more than %d steps of $.step (%g s) to grow "
		                       "from where it was emitted to I_A; raise $.step or $.barb_speed",
		                       (int)MAX_STEPS_PER_PATH, run->vane.h);
	}
}

plume_status zk_grow(const plume_zk_def *def, const zk_collar *collar, uint64_t seed, zk_growth *growth,
                     plume_error *err)
{
	memset(growth, 0, sizeof *growth);
	zk_curve ve, vb;
	zk_curve_init(&ve, &def->emitter_speed);
	zk_curve_init(&vb, &def->barb_speed);
	plume_rng rng = plume_rng_seed(seed);
	vane_run runs[2];
	vane_setup(runs + PLUME_SIDE_LEFT, def, collar, &ve, &vb, PLUME_SIDE_LEFT, plume_rng_split(&rng));
	vane_setup(runs + PLUME_SIDE_RIGHT, def, collar, &ve, &vb, PLUME_SIDE_RIGHT, plume_rng_split(&rng));
	double pathline_steps = 0;
	runs[PLUME_SIDE_LEFT].vane.pathline_steps = runs[PLUME_SIDE_RIGHT].vane.pathline_steps = &pathline_steps;

	// Barb i leaves the ridge after the emitter moved (i + 1) d: a ridge wider
	// than the emitter's whole path from I_A to I_P emits every barb at the
	// clamp, at times that overflow (1e308 gave a feather with no barbs).
	for (int side = 0; side < 2; ++side) {
		const zk_vane *v = &runs[side].vane;
		double path = v->length * fabs(v->s_posterior - v->s_anterior);
		if (!(def->ridge_width <= path))
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "$.ridge_width is %g m, longer than the %s emitter's path along the collar from "
			                       "I_A to I_P (%g m); allowed (0, %g]",
			                       def->ridge_width, side == PLUME_SIDE_LEFT ? "left" : "right", path, path);
	}

	plume_status status = PLUME_OK;
	// Termination: barbs mature in emission order, so N mature barbs on a vane
	// means its barb N - 1 is mature.
	for (int side = 0; side < 2 && status == PLUME_OK; ++side)
		while (runs[side].count < def->barb_count && status == PLUME_OK)
			status = add_emission(runs + side);
	if (status != PLUME_OK)
		goto fail;
	double t_end = fmin(runs[0].list[def->barb_count - 1].mature_time, runs[1].list[def->barb_count - 1].mature_time);
	// emit() refuses an infinite P_0.t, so this holds; it is checked because every
	// height is v_grow (t_curr - t) (eq. 5): a t_end that is not finite makes no feather.
	if (!isfinite(t_end)) {
		status = plume_error_set(err, PLUME_ERROR_SPEC,
		                         "the growth does not end: barb %d of either vane never matures (t_end is %g s); "
		                         "raise $.emitter_speed, $.barb_speed or $.step",
		                         def->barb_count - 1, t_end);
		goto fail;
	}
	double t_curr = def->growth_stage >= 1.0 ? t_end : def->growth_stage * t_end;
	bool final = def->growth_stage >= 1.0;
	// Barbs emitted up to t_curr are there (developing ones are kept below the final stage).
	for (int side = 0; side < 2 && status == PLUME_OK; ++side)
		while (runs[side].list[runs[side].count - 1].t0 < t_curr && status == PLUME_OK)
			status = add_emission(runs + side);
	if (status != PLUME_OK)
		goto fail;

	growth->t_end = t_end;
	growth->t_curr = t_curr;
	int total_barbs = 0;
	for (int side = 0; side < 2; ++side) {
		vane_run *run = runs + side;
		if (!run->em.clamped)
			run->em.clamp_time = advance_to(&run->vane, &run->em, run->vane.s_posterior, t_end);
		growth->clamp_time[side] = run->em.clamp_time <= t_end ? run->em.clamp_time : INFINITY;
		total_barbs += run->count;
	}
	growth->barbs = plume_calloc((size_t)total_barbs, sizeof *growth->barbs);
	if (growth->barbs == NULL) {
		status = PLUME_ERROR_MEMORY;
		goto fail;
	}

	// Pass 1: which barbs are kept and how many points each has.
	long vertex_total = 0;
	for (int side = 0; side < 2; ++side) {
		vane_run *run = runs + side;
		for (int i = 0; i < run->count; ++i) {
			emission *e = run->list + i;
			bool mature = e->mature_time <= t_curr;
			if (!(e->t0 < t_curr))
				continue; // emitted at t_curr or later: not a curve yet
			if (!mature)
				growth->developing_count++;
			if (!mature && final)
				continue; // IV-A Termination: developing barbs are discarded
			path_end end = e->end;
			if (!mature && (status = pathline(&run->vane, e->s0, e->t0, t_curr, NULL, &end)) != PLUME_OK)
				goto fail;
			zk_barb *barb = growth->barbs + growth->barb_count++;
			*barb = (zk_barb){
			    .side = (plume_side)side,
			    .index = i,
			    .emit_time = e->t0,
			    .emit_locus = e->s0,
			    .mature_time = e->mature_time,
			    .mature = mature,
			    .first = (int)vertex_total,
			    .count = end.count,
			};
			growth->side_count[side]++;
			vertex_total += end.count;
		}
	}
	if (vertex_total > 200000000L) {
		status = PLUME_ERROR_NUMERIC;
		goto fail;
	}
	growth->vertex_count = (int)vertex_total;
	growth->locus = plume_alloc((size_t)(vertex_total > 0 ? vertex_total : 1) * sizeof *growth->locus);
	growth->time = plume_alloc((size_t)(vertex_total > 0 ? vertex_total : 1) * sizeof *growth->time);
	if (growth->locus == NULL || growth->time == NULL) {
		status = PLUME_ERROR_MEMORY;
		goto fail;
	}
	// Pass 2: the points. Barbs from I_P share one pathline: copy its loci.
	int cached[2] = {-1, -1};
	for (int b = 0; b < growth->barb_count; ++b) {
		zk_barb *barb = growth->barbs + b;
		vane_run *run = runs + barb->side;
		double *locus = growth->locus + barb->first, *time = growth->time + barb->first;
		int source = cached[barb->side];
		if (barb->mature && barb->emit_locus == run->vane.s_posterior && source >= 0) {
			const zk_barb *from = growth->barbs + source;
			memcpy(locus, growth->locus + from->first, (size_t)barb->count * sizeof *locus);
			for (int j = 0; j + 1 < barb->count; ++j)
				time[j] = barb->emit_time + (double)((long)j * run->vane.f) * run->vane.h;
			time[barb->count - 1] = barb->mature_time;
			continue;
		}
		const emission *e = run->list + barb->index;
		if (barb->mature && e->point_first >= 0) { // the same pathline as add_emission's: the same points
			memcpy(locus, run->kept.locus + e->point_first, (size_t)barb->count * sizeof *locus);
			memcpy(time, run->kept.time + e->point_first, (size_t)barb->count * sizeof *time);
		} else {
			path_end end;
			path_points points = {.locus = locus, .time = time};
			double stop = barb->mature ? INFINITY : t_curr;
			if ((status = pathline(&run->vane, barb->emit_locus, barb->emit_time, stop, &points, &end)) != PLUME_OK)
				goto fail;
		}
		if (barb->mature && barb->emit_locus == run->vane.s_posterior)
			cached[barb->side] = b;
	}
	for (int side = 0; side < 2; ++side)
		vane_free(runs + side);
	return PLUME_OK;
fail:
	for (int side = 0; side < 2; ++side)
		vane_free(runs + side);
	zk_growth_free(growth);
	return fail_runaway(status, runs, err);
}

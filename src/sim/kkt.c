// The Newton systems' sparse matrix: a pattern built once per mesh, values
// scattered into precomputed slots, the constraints' multipliers eliminated into a
// positive definite matrix that CHOLMOD factors (kkt.h says why).
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "sim/kkt.h"

typedef struct entry_list {
	plume_sparse_entry *items;
	int count;
	int capacity;
} entry_list;

static int push_block(entry_list *list, const int *vertices, int count)
{
	for (int a = 0; a < 3 * count; ++a)
		for (int b = 0; b < 3 * count; ++b) {
			int i = 3 * vertices[a / 3] + a % 3, j = 3 * vertices[b / 3] + b % 3;
			if (i > j || vertices[a / 3] < 0 || vertices[b / 3] < 0)
				continue;
			if (PLUME_GROW(list->items, list->capacity, list->count + 1) != 0)
				return -1;
			list->items[list->count++] = (plume_sparse_entry){j, i};
		}
	return 0;
}

/// The slots of an element block's upper triangle in the element's order, (a, b) for
/// a <= b, row by row (plume_kkt_upper_size entries): each pair of unknowns once, so a
/// symmetric block scatters with no test for the matrix's triangle (whose side, in the
/// permuted pattern, is a coin toss per pair that the branch predictor lost half the time).
/// -1 where a vertex is absent.
static void fill_upper_slots(const plume_sparse *system, const int *vertices, int count, int *slots)
{
	int n = 3 * count;
	for (int a = 0; a < n; ++a)
		for (int b = a; b < n; ++b) {
			int i = 3 * vertices[a / 3] + a % 3, j = 3 * vertices[b / 3] + b % 3;
			bool present = vertices[a / 3] >= 0 && vertices[b / 3] >= 0;
			*slots++ = present ? plume_sparse_find(system, i, j) : -1;
		}
}

static plume_status build(plume_kkt *kkt, int vertex_count, int face_count, const int *faces, int bending_count,
                          const int *bending_vertices, int bending_stride, int bending_size, int edge_count,
                          const int *edge_vertices, int constraint_count, const int *constraint_vertices,
                          int extra_count, const int *extra, plume_error *err)
{
	memset(kkt, 0, sizeof *kkt);
	kkt->vertex_count = vertex_count;
	kkt->face_count = face_count;
	kkt->faces = faces;
	kkt->bending_count = bending_count;
	kkt->bending_vertices = bending_vertices;
	kkt->bending_stride = bending_stride;
	kkt->edge_count = edge_count;
	kkt->edge_vertices = edge_vertices;
	kkt->constraint_vertices = constraint_vertices;
	kkt->extra_count = extra_count;
	kkt->dof_count = 3 * vertex_count;
	kkt->constraint_count = constraint_count;
	int size = kkt->dof_count + constraint_count;

	entry_list list = {0};
	int failed = 0;
	for (int v = 0; v < vertex_count && !failed; ++v)
		failed = push_block(&list, &v, 1);
	for (int f = 0; f < face_count && !failed; ++f)
		failed = push_block(&list, faces + 3 * f, 3);
	for (int h = 0; h < bending_count && !failed; ++h)
		failed =
		    push_block(&list, (const int *)((const char *)bending_vertices + (size_t)h * bending_stride), bending_size);
	for (int e = 0; e < edge_count && !failed; ++e)
		failed = push_block(&list, edge_vertices + 4 * e, 4);
	for (int k = 0; k < constraint_count && !failed; ++k)
		failed = push_block(&list, constraint_vertices + 2 * k, 2);
	for (int k = 0; k < extra_count && !failed; ++k)
		failed = push_block(&list, extra + 4 * k, 4);
	for (int k = 0; k < constraint_count && !failed; ++k) {
		int column = kkt->dof_count + k;
		if (PLUME_GROW(list.items, list.capacity, list.count + 6) != 0) {
			failed = 1;
			break;
		}
		for (int e = 0; e < 2; ++e)
			for (int d = 0; d < 3; ++d)
				list.items[list.count++] = (plume_sparse_entry){column, 3 * constraint_vertices[2 * k + e] + d};
	}
	if (failed) {
		plume_free(list.items);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building the solver's sparse pattern");
	}
	// K stored in the natural order, sorted by column: its position block (columns below
	// dof_count) comes first, and those entries, still sorted and unique in the list, are
	// the pattern of the factored matrix (C^T R C couples a constraint's two vertices,
	// whose block is already there).
	plume_status status =
	    plume_sparse_init(&kkt->system, size, list.items, (size_t)list.count, false, "the solver's matrix", err);
	int position_entries = status == PLUME_OK ? ((const int *)kkt->system.matrix->p)[kkt->dof_count] : 0;
	if (status == PLUME_OK)
		status = plume_sparse_init(&kkt->positions, kkt->dof_count, list.items, (size_t)position_entries, true,
		                           "the solver's matrix", err);
	plume_free(list.items);
	if (status != PLUME_OK) {
		plume_kkt_free(kkt);
		return status;
	}
	const plume_sparse *matrix = &kkt->system;

	size_t vertices = (size_t)(vertex_count > 0 ? vertex_count : 1);
	kkt->vertex_slots = plume_alloc(sizeof(int) * 6 * vertices);
	kkt->face_slots = plume_alloc(sizeof(int) * 45 * (size_t)(face_count > 0 ? face_count : 1));
	int block = plume_kkt_upper_size(bending_size);
	kkt->bending_size = bending_size;
	kkt->bending_slots = plume_alloc(sizeof(int) * (size_t)block * (size_t)(bending_count > 0 ? bending_count : 1));
	kkt->edge_slots = plume_alloc(sizeof(int) * 78 * (size_t)(edge_count > 0 ? edge_count : 1));
	size_t constraints = (size_t)(constraint_count > 0 ? constraint_count : 1);
	kkt->constraint_slots = plume_alloc(sizeof(int) * 6 * constraints);
	kkt->pair_slots = plume_alloc(sizeof(int) * 21 * constraints);
	kkt->augment_slots = plume_alloc(sizeof(int) * 21 * constraints);
	kkt->rho = plume_alloc(sizeof(double) * constraints);
	kkt->position_slots = plume_alloc(sizeof(int) * (size_t)(position_entries > 0 ? position_entries : 1));
	if (!kkt->vertex_slots || !kkt->face_slots || !kkt->bending_slots || !kkt->edge_slots || !kkt->constraint_slots ||
	    !kkt->pair_slots || !kkt->augment_slots || !kkt->rho || !kkt->position_slots) {
		plume_kkt_free(kkt);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating the solver's slot maps");
	}
	for (int v = 0; v < vertex_count; ++v)
		fill_upper_slots(matrix, &v, 1, kkt->vertex_slots + 6 * v);
	for (int f = 0; f < face_count; ++f)
		fill_upper_slots(matrix, faces + 3 * f, 3, kkt->face_slots + 45 * f);
	for (int h = 0; h < bending_count; ++h)
		fill_upper_slots(matrix, (const int *)((const char *)bending_vertices + (size_t)h * bending_stride),
		                 bending_size, kkt->bending_slots + (size_t)block * h);
	for (int e = 0; e < edge_count; ++e)
		fill_upper_slots(matrix, edge_vertices + 4 * e, 4, kkt->edge_slots + 78 * (size_t)e);
	for (int k = 0; k < constraint_count; ++k) {
		int column = kkt->dof_count + k;
		fill_upper_slots(matrix, constraint_vertices + 2 * k, 2, kkt->pair_slots + 21 * k);
		fill_upper_slots(&kkt->positions, constraint_vertices + 2 * k, 2, kkt->augment_slots + 21 * k);
		for (int a = 0; a < 6; ++a)
			kkt->constraint_slots[6 * k + a] =
			    plume_sparse_find(matrix, 3 * constraint_vertices[2 * k + a / 3] + a % 3, column);
	}
	const int *p = matrix->matrix->p, *rows = matrix->matrix->i;
	for (int column = 0; column < kkt->dof_count; ++column)
		for (int e = p[column]; e < p[column + 1]; ++e)
			kkt->position_slots[e] = plume_sparse_find(&kkt->positions, rows[e], column);

	return PLUME_OK;
}

plume_status plume_kkt_init(plume_kkt *kkt, int vertex_count, int face_count, const int *faces, int bending_count,
                            const int *bending_vertices, int bending_stride, int bending_size, int edge_count,
                            const int *edge_vertices, int constraint_count, const int *constraint_vertices,
                            plume_error *err)
{
	return build(kkt, vertex_count, face_count, faces, bending_count, bending_vertices, bending_stride, bending_size,
	             edge_count, edge_vertices, constraint_count, constraint_vertices, 0, NULL, err);
}

plume_status plume_kkt_set_extra_blocks(plume_kkt *kkt, int count, const int *vertices, plume_error *err)
{
	plume_kkt rebuilt;
	plume_status status =
	    build(&rebuilt, kkt->vertex_count, kkt->face_count, kkt->faces, kkt->bending_count, kkt->bending_vertices,
	          kkt->bending_stride, kkt->bending_size, kkt->edge_count, kkt->edge_vertices, kkt->constraint_count,
	          kkt->constraint_vertices, count, vertices, err);
	if (status != PLUME_OK)
		return status;
	plume_kkt_free(kkt);
	*kkt = rebuilt;
	return PLUME_OK;
}

void plume_kkt_free(plume_kkt *kkt)
{
	plume_sparse_free(&kkt->system);
	plume_sparse_free(&kkt->positions);
	plume_free(kkt->position_slots);
	plume_free(kkt->augment_slots);
	plume_free(kkt->rho);
	plume_free(kkt->vertex_slots);
	plume_free(kkt->face_slots);
	plume_free(kkt->bending_slots);
	plume_free(kkt->edge_slots);
	plume_free(kkt->constraint_slots);
	plume_free(kkt->pair_slots);
	plume_free(kkt->refine);
	memset(kkt, 0, sizeof *kkt);
}

double *plume_kkt_values(plume_kkt *kkt) { return kkt->system.matrix->x; }

void plume_kkt_zero(plume_kkt *kkt)
{
	const int *p = kkt->system.matrix->p;
	memset(kkt->system.matrix->x, 0, sizeof(double) * (size_t)p[kkt->system.matrix->ncol]);
}

static double mean_position_diagonal(const plume_kkt *kkt)
{
	const double *values = kkt->system.matrix->x;
	double sum = 0;
	for (int i = 0; i < kkt->dof_count; ++i)
		sum += fabs(values[kkt->system.diagonal[i]]);
	return kkt->dof_count > 0 ? sum / kkt->dof_count : 1;
}

static void shift_positions(plume_kkt *kkt, double amount)
{
	double *values = kkt->system.matrix->x;
	for (int i = 0; i < kkt->dof_count; ++i)
		values[kkt->system.diagonal[i]] += amount;
}

/// The smallest shift a ladder starts from: below it a shift is lost to rounding against
/// the diagonal it is added to.
static const double SMALLEST_SHIFT = 1e-10;

/// rho_k over the larger diagonal entry of H at the barb's two ends: large enough that
/// H + C^T R C is positive definite whenever H is on the constraints' tangent space and
/// that refinement converges in a few steps, small enough that the factored matrix stays
/// well conditioned. Measured on Figure 1 (docs/simulation.md, "Linear algebra"): 1e3
/// refuses exact Hessians the LDL' inertia accepted and a step fails; 1e4 converges to
/// positions 1.9e-9 m from the LDL' solver's; 1e6 to 6e-17 m with 4.4 solves an
/// iteration; 1e8 to 1e-16 m with 5.4.
static const double AUGMENTATION = 1e6;

/// rho_k over the smaller diagonal entry at the barb's ends, at most: rho_k c c^T lands on
/// both ends, and past this it swamps the softer end's own stiffness across the barb so
/// far that rounding loses it (to 1e-4 of it here, 1e12 * 2.2e-16). A barb rooted on a
/// sliver of the stiff rachis band, 1.3e10 times stiffer than the vane vertex at its
/// other end (the Streit-Heidrich peacock's shaft tapers to 40 um against rows 5 mm
/// apart), made the matrix indefinite to rounding and no step converged
/// (tests/test_sim.c, test_kkt_barb_between_stiff_and_soft). Figure 1's barbs span up to
/// 3e5 (e = 0.9 mm) and keep AUGMENTATION: scaled with the softer end alone, the 0.9 mm
/// run fails at its buckling step (docs/simulation.md).
static const double PRECISION_LIMIT = 1e12;

/// The factored matrix from K: H's entries, then C^T R C with rho_k from H's diagonal at each barb's ends.
static void load_positions(plume_kkt *kkt)
{
	const double *stored = kkt->system.matrix->x;
	double *values = kkt->positions.matrix->x;
	int position_entries = ((const int *)kkt->system.matrix->p)[kkt->dof_count];
	for (int e = 0; e < position_entries; ++e)
		values[kkt->position_slots[e]] = stored[e];
	for (int k = 0; k < kkt->constraint_count; ++k) {
		const int *vertices = kkt->constraint_vertices + 2 * k;
		// Each end's stiffness: the largest diagonal entry of H at its free unknowns the
		// barb moves (a held end has none).
		double c[6], end[2] = {0, 0};
		for (int a = 0; a < 6; ++a) {
			c[a] = stored[kkt->constraint_slots[6 * k + a]];
			if (c[a] != 0)
				end[a / 3] = fmax(end[a / 3], fabs(stored[kkt->system.diagonal[3 * vertices[a / 3] + a % 3]]));
		}
		double rho = AUGMENTATION * fmax(end[0], end[1]);
		if (end[0] > 0 && end[1] > 0)
			rho = fmin(rho, PRECISION_LIMIT * fmin(end[0], end[1]));
		kkt->rho[k] = rho = rho > 0 ? rho : AUGMENTATION;
		const int *slots = kkt->augment_slots + 21 * k;
		for (int a = 0; a < 6; ++a)
			for (int b = a; b < 6; ++b, ++slots)
				values[*slots] += rho * c[a] * c[b];
	}
}

plume_status plume_kkt_factor(plume_kkt *kkt, double first_shift, double largest_shift, double *shift, plume_error *err)
{
	*shift = 0;
	load_positions(kkt);
	if (plume_sparse_factor(&kkt->positions))
		return PLUME_OK;
	if (!(largest_shift >= fmax(first_shift, SMALLEST_SHIFT)))
		return plume_error_set(err, PLUME_ERROR_NUMERIC,
		                       kkt->constraint_count > 0
		                           ? "the Newton matrix is not positive definite on the constraints' tangent space"
		                           : "the Newton matrix is not positive definite");
	// Not positive definite on the positions (a free rigid motion in statics, a compressed
	// barb's constraint curvature, a vane past its buckling load): Levenberg-style shifts.
	// A ladder from a remembered shift climbs by decades; one from nothing known by two
	// decades, its last rung the limit itself, since most of those run out (rungs from
	// 1e-10 to 1e-5 in decades: six factorisations for nothing). Measured (factorisations,
	// Newton iterations), decades against this: Figure 1 at 5 mm 456 / 397 -> 442 / 397, at
	// 2.5 mm 1017 / 597 -> 946 / 596, wing-draft.json 1383 / 778 -> 1246 / 774,
	// coat-settle.json 126 / 95 -> 121 / 95. (In decades from 0.1 * 1e-5, the second rung
	// rounded above 1e-5 and was skipped; the rungs are clamped to the limit now.)
	double base = mean_position_diagonal(kkt);
	if (!(base > 0) || !isfinite(base))
		base = 1;
	double applied = 0, growth = first_shift > SMALLEST_SHIFT ? 10 : 100;
	for (double factor = fmax(first_shift, SMALLEST_SHIFT);; factor = fmin(factor * growth, largest_shift)) {
		double wanted = factor * base;
		shift_positions(kkt, wanted - applied);
		applied = wanted;
		load_positions(kkt);
		if (plume_sparse_factor(&kkt->positions)) {
			*shift = factor;
			return PLUME_OK;
		}
		if (factor >= largest_shift)
			break;
	}
	return plume_error_set(err, PLUME_ERROR_NUMERIC,
	                       "the Newton system could not be factored (CHOLMOD status %d) even after regularisation",
	                       kkt->positions.common.status);
}

/// [dx; lambda] = [0; g] + M^-1 ([r1; r2] - K [0; g]) for the regularised matrix
/// M = [H C^T; C -R^-1], starting from the multipliers' guess g (NULL: 0):
/// (H + C^T R C) dx = r1 + C^T (R r2 - g), lambda = g + R (C dx - r2). Its residual
/// against K is [0; (g - lambda) / rho]: the better the guess, the fewer refinement steps.
static plume_status solve_regularised(plume_kkt *kkt, const double *rhs, const double *guess, double *solution,
                                      plume_error *err)
{
	plume_sparse *positions = &kkt->positions;
	const double *stored = kkt->system.matrix->x;
	int n = kkt->dof_count;
	double *b = positions->rhs->x;
	memcpy(b, rhs, sizeof(double) * (size_t)n);
	for (int k = 0; k < kkt->constraint_count; ++k) {
		double weight = kkt->rho[k] * rhs[n + k] - (guess != NULL ? guess[k] : 0);
		for (int a = 0; a < 6; ++a)
			b[3 * kkt->constraint_vertices[2 * k + a / 3] + a % 3] += weight * stored[kkt->constraint_slots[6 * k + a]];
	}
	if (!plume_sparse_solve(positions))
		return plume_error_set(err, PLUME_ERROR_NUMERIC, "CHOLMOD solve failed (status %d)", positions->common.status);
	const double *dx = positions->solution->x;
	memcpy(solution, dx, sizeof(double) * (size_t)n);
	for (int k = 0; k < kkt->constraint_count; ++k) {
		double cdx = 0;
		for (int a = 0; a < 6; ++a)
			cdx += stored[kkt->constraint_slots[6 * k + a]] * dx[3 * kkt->constraint_vertices[2 * k + a / 3] + a % 3];
		solution[n + k] = (guess != NULL ? guess[k] : 0) + kkt->rho[k] * (cdx - rhs[n + k]);
	}
	return PLUME_OK;
}

/// At most this many refinement steps (each one solve); refinement stops earlier once
/// the backward error is below the caller's tolerance or stops falling.
enum { REFINEMENT_STEPS = 8 };

/// residual = rhs - K x and the componentwise backward error
/// max_i |residual_i| / (|K| |x| + |rhs|)_i (Arioli, Demmel & Duff 1989): the relative
/// change of K's entries and of rhs that makes x exact. Rows whose denominator is zero
/// (held unknowns, zero rows) do not count. K's upper triangle gives each column's entries
/// to two rows: the other rows' terms are scattered, the column's own row's are summed in
/// registers and added once (adding into memory on every entry chains each addition to
/// the store before it, which made this product cost more than a solve).
static double backward_error(const plume_kkt *kkt, const double *rhs, const double *x, double *restrict residual,
                             double *restrict scale)
{
	const cholmod_sparse *stored = kkt->system.matrix;
	const int *p = stored->p, *rows = stored->i;
	const double *values = stored->x;
	size_t size = stored->ncol;
	for (size_t i = 0; i < size; ++i) {
		residual[i] = rhs[i];
		scale[i] = fabs(rhs[i]);
	}
	for (size_t j = 0; j < size; ++j) {
		double xj = x[j], row_residual = 0, row_scale = 0;
		for (int e = p[j]; e < p[j + 1]; ++e) {
			size_t i = (size_t)rows[e];
			double upper = values[e] * xj;
			residual[i] -= upper;
			scale[i] += fabs(upper);
			if (i != j) {
				double lower = values[e] * x[i];
				row_residual += lower;
				row_scale += fabs(lower);
			}
		}
		residual[j] -= row_residual;
		scale[j] += row_scale;
	}
	double worst = 0;
	for (size_t i = 0; i < size; ++i)
		if (scale[i] > 0)
			worst = fmax(worst, fabs(residual[i]) / scale[i]);
	return worst;
}

plume_status plume_kkt_solve(plume_kkt *kkt, const double *rhs, const double *multipliers, double tolerance,
                             double *solution, plume_error *err)
{
	plume_status status = solve_regularised(kkt, rhs, multipliers, solution, err);
	if (status != PLUME_OK || kkt->constraint_count == 0)
		return status;
	size_t size = kkt->system.matrix->ncol;
	if (kkt->refine == NULL && (kkt->refine = plume_alloc(3 * sizeof(double) * size)) == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory refining the Newton step");
	double *residual = kkt->refine, *correction = kkt->refine + size, *scale = kkt->refine + 2 * size;
	// Two measures, each over the tolerance: the componentwise backward error, and the
	// largest force left unbalanced on a position row against the largest force asked for
	// (the inexact Newton condition |r| <= eta |g| of Dembo, Eisenstat & Steihaug 1982).
	// The first alone accepts a near-rigid step of a stiff shell whose forces cancel: |K||x|
	// counts every stiff element's force at full size, so a residual 1e-4 of that can be
	// thousands of times the load. A bristle falling freely, its 0.1 mm rachis band held to
	// its one barb, took 25 Newton iterations a step over 1 s, 4.5 with both. Figure 1 takes
	// the same iterations and solves, and the same bits at e = 5 mm (its last frame moves
	// 1.4e-11 m at 2.5 mm; docs/simulation.md, "Linear algebra").
	double previous = INFINITY, load = 0;
	for (int i = 0; i < kkt->dof_count; ++i)
		load = fmax(load, fabs(rhs[i]));
	for (int step = 0;; ++step) {
		double error = backward_error(kkt, rhs, solution, residual, scale) / tolerance;
		if (load > 0)
			for (int i = 0; i < kkt->dof_count; ++i)
				error = fmax(error, fabs(residual[i]) / (tolerance * load));
		if (step == REFINEMENT_STEPS || error <= 1 || !(error < 0.5 * previous))
			break;
		previous = error;
		if ((status = solve_regularised(kkt, residual, NULL, correction, err)) != PLUME_OK)
			return status;
		for (size_t i = 0; i < size; ++i)
			solution[i] += correction[i];
	}
	return PLUME_OK;
}

plume_status plume_kkt_solve_unrefined(plume_kkt *kkt, const double *rhs, double *solution, plume_error *err)
{
	return solve_regularised(kkt, rhs, NULL, solution, err);
}

void plume_kkt_multiply_add(const plume_kkt *kkt, const double *x, double *y)
{
	plume_sparse_multiply_add(&kkt->system, x, y);
}

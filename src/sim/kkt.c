// The Newton systems' sparse matrix: a pattern built once per mesh, values
// scattered into precomputed slots, CHOLMOD factorisation (see kkt.h for why
// simplicial LDL' with constraints and simplicial LL' without).
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "sim/kkt.h"

/// One stored entry (row <= column): sorted column-major.
typedef struct entry {
	int column;
	int row;
} entry;

static int compare_entries(const void *a, const void *b)
{
	const entry *p = a, *q = b;
	if (p->column != q->column)
		return p->column < q->column ? -1 : 1;
	return (p->row > q->row) - (p->row < q->row);
}

typedef struct entry_list {
	entry *items;
	int count;
	int capacity;
} entry_list;

static int push_block(entry_list *list, const int *vertices, int count)
{
	for (int a = 0; a < 3 * count; ++a)
		for (int b = 0; b < 3 * count; ++b) {
			int i = 3 * vertices[a / 3] + a % 3, j = 3 * vertices[b / 3] + b % 3;
			if (i > j)
				continue;
			if (PLUME_GROW(list->items, list->capacity, list->count + 1) != 0)
				return -1;
			list->items[list->count++] = (entry){j, i};
		}
	return 0;
}

int plume_csc_find(const cholmod_sparse *matrix, int row, int column)
{
	const int *p = matrix->p, *rows = matrix->i;
	int lo = p[column], hi = p[column + 1] - 1;
	while (lo <= hi) {
		int mid = (lo + hi) / 2;
		if (rows[mid] == row)
			return mid;
		if (rows[mid] < row)
			lo = mid + 1;
		else
			hi = mid - 1;
	}
	return -1;
}

static void fill_block_slots(const cholmod_sparse *matrix, const int *vertices, int count, int *slots)
{
	int n = 3 * count;
	for (int a = 0; a < n; ++a)
		for (int b = 0; b < n; ++b) {
			int i = 3 * vertices[a / 3] + a % 3, j = 3 * vertices[b / 3] + b % 3;
			slots[a * n + b] = i <= j ? plume_csc_find(matrix, i, j) : -1;
		}
}

plume_status plume_kkt_init(plume_kkt *kkt, int vertex_count, int face_count, const int *faces, int hinge_count,
                            const int *hinge_vertices, int hinge_stride, int constraint_count,
                            const int *constraint_vertices, plume_error *err)
{
	memset(kkt, 0, sizeof *kkt);
	kkt->dof_count = 3 * vertex_count;
	kkt->constraint_count = constraint_count;
	int size = kkt->dof_count + constraint_count;

	entry_list list = {0};
	int failed = 0;
	for (int v = 0; v < vertex_count && !failed; ++v)
		failed = push_block(&list, &v, 1);
	for (int f = 0; f < face_count && !failed; ++f)
		failed = push_block(&list, faces + 3 * f, 3);
	for (int h = 0; h < hinge_count && !failed; ++h)
		failed = push_block(&list, (const int *)((const char *)hinge_vertices + (size_t)h * hinge_stride), 4);
	for (int k = 0; k < constraint_count && !failed; ++k)
		failed = push_block(&list, constraint_vertices + 2 * k, 2);
	for (int k = 0; k < constraint_count && !failed; ++k) {
		int column = kkt->dof_count + k;
		if (PLUME_GROW(list.items, list.capacity, list.count + 7) != 0) {
			failed = 1;
			break;
		}
		for (int e = 0; e < 2; ++e)
			for (int d = 0; d < 3; ++d)
				list.items[list.count++] = (entry){column, 3 * constraint_vertices[2 * k + e] + d};
		list.items[list.count++] = (entry){column, column};
	}
	if (failed) {
		plume_free(list.items);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building the solver's sparse pattern");
	}
	qsort(list.items, (size_t)list.count, sizeof *list.items, compare_entries);
	int unique = 0;
	for (int e = 0; e < list.count; ++e)
		if (unique == 0 || compare_entries(list.items + unique - 1, list.items + e) != 0)
			list.items[unique++] = list.items[e];

	cholmod_start(&kkt->common);
	kkt->started = true;
	// The library never prints: failures come back through the status (DESIGN.md).
	kkt->common.print = 0;
	// Deterministic and fast enough at feather sizes; METIS is not needed.
	kkt->common.nmethods = 1;
	kkt->common.method[0].ordering = CHOLMOD_AMD;
	kkt->common.postorder = 1;
	// Simplicial, with or without constraints: with Debian's reference BLAS the supernodal
	// method was 5 times slower on Figure 1's isotropic vane (3.7 s against 0.73 s of
	// factorisation), and without BLAS the bits do not depend on the thread count.
	// LL' without constraints, so that an indefinite H reports itself (factor_ok).
	kkt->common.supernodal = CHOLMOD_SIMPLICIAL;
	kkt->common.final_ll = constraint_count == 0;
	kkt->matrix =
	    cholmod_allocate_sparse((size_t)size, (size_t)size, (size_t)unique, 1, 1, 1, CHOLMOD_REAL, &kkt->common);
	if (kkt->matrix == NULL) {
		plume_free(list.items);
		plume_kkt_free(kkt);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating the solver's matrix");
	}
	int *p = kkt->matrix->p, *rows = kkt->matrix->i;
	int e = 0;
	for (int column = 0; column < size; ++column) {
		p[column] = e;
		while (e < unique && list.items[e].column == column) {
			rows[e] = list.items[e].row;
			++e;
		}
	}
	p[size] = unique;
	plume_free(list.items);

	kkt->vertex_slots = plume_alloc(sizeof(int) * 9 * (size_t)(vertex_count > 0 ? vertex_count : 1));
	kkt->face_slots = plume_alloc(sizeof(int) * 81 * (size_t)(face_count > 0 ? face_count : 1));
	kkt->hinge_slots = plume_alloc(sizeof(int) * 144 * (size_t)(hinge_count > 0 ? hinge_count : 1));
	kkt->constraint_slots = plume_alloc(sizeof(int) * 7 * (size_t)(constraint_count > 0 ? constraint_count : 1));
	kkt->pair_slots = plume_alloc(sizeof(int) * 36 * (size_t)(constraint_count > 0 ? constraint_count : 1));
	if (!kkt->vertex_slots || !kkt->face_slots || !kkt->hinge_slots || !kkt->constraint_slots || !kkt->pair_slots) {
		plume_kkt_free(kkt);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating the solver's slot maps");
	}
	for (int v = 0; v < vertex_count; ++v)
		fill_block_slots(kkt->matrix, &v, 1, kkt->vertex_slots + 9 * v);
	for (int f = 0; f < face_count; ++f)
		fill_block_slots(kkt->matrix, faces + 3 * f, 3, kkt->face_slots + 81 * f);
	for (int h = 0; h < hinge_count; ++h)
		fill_block_slots(kkt->matrix, (const int *)((const char *)hinge_vertices + (size_t)h * hinge_stride), 4,
		                 kkt->hinge_slots + 144 * h);
	for (int k = 0; k < constraint_count; ++k) {
		int column = kkt->dof_count + k;
		fill_block_slots(kkt->matrix, constraint_vertices + 2 * k, 2, kkt->pair_slots + 36 * k);
		for (int a = 0; a < 6; ++a)
			kkt->constraint_slots[7 * k + a] =
			    plume_csc_find(kkt->matrix, 3 * constraint_vertices[2 * k + a / 3] + a % 3, column);
		kkt->constraint_slots[7 * k + 6] = plume_csc_find(kkt->matrix, column, column);
	}

	kkt->factor = cholmod_analyze(kkt->matrix, &kkt->common);
	kkt->rhs = cholmod_zeros((size_t)size, 1, CHOLMOD_REAL, &kkt->common);
	if (kkt->factor == NULL || kkt->rhs == NULL) {
		plume_kkt_free(kkt);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "CHOLMOD could not analyse the solver's matrix (status %d)",
		                       kkt->common.status);
	}
	return PLUME_OK;
}

void plume_kkt_free(plume_kkt *kkt)
{
	if (kkt->started) {
		cholmod_free_sparse(&kkt->matrix, &kkt->common);
		cholmod_free_factor(&kkt->factor, &kkt->common);
		cholmod_free_dense(&kkt->rhs, &kkt->common);
		cholmod_free_dense(&kkt->solution, &kkt->common);
		cholmod_free_dense(&kkt->work_y, &kkt->common);
		cholmod_free_dense(&kkt->work_e, &kkt->common);
		cholmod_finish(&kkt->common);
	}
	plume_free(kkt->vertex_slots);
	plume_free(kkt->face_slots);
	plume_free(kkt->hinge_slots);
	plume_free(kkt->constraint_slots);
	plume_free(kkt->pair_slots);
	plume_free(kkt->refine);
	memset(kkt, 0, sizeof *kkt);
}

double *plume_kkt_values(plume_kkt *kkt) { return kkt->matrix->x; }

void plume_kkt_zero(plume_kkt *kkt)
{
	const int *p = kkt->matrix->p;
	memset(kkt->matrix->x, 0, sizeof(double) * (size_t)p[kkt->matrix->ncol]);
}

static double mean_position_diagonal(const plume_kkt *kkt)
{
	const double *values = kkt->matrix->x;
	double sum = 0;
	int vertex_count = kkt->dof_count / 3;
	for (int v = 0; v < vertex_count; ++v)
		for (int d = 0; d < 3; ++d)
			sum += fabs(values[kkt->vertex_slots[9 * v + 4 * d]]);
	return kkt->dof_count > 0 ? sum / kkt->dof_count : 1;
}

static void shift_positions(plume_kkt *kkt, double amount)
{
	double *values = kkt->matrix->x;
	int vertex_count = kkt->dof_count / 3;
	for (int v = 0; v < vertex_count; ++v)
		for (int d = 0; d < 3; ++d)
			values[kkt->vertex_slots[9 * v + 4 * d]] += amount;
}

static bool factor_ok(const plume_kkt *kkt)
{
	if (kkt->common.status != CHOLMOD_OK)
		return false;
	// The simplicial LDL' does not pivot: a zero or non-finite pivot shows up in D (a NaN
	// in H passes LL''s positivity test too, and shows up in its diagonal).
	if (!kkt->factor->is_super) {
		const int *p = kkt->factor->p;
		const double *x = kkt->factor->x;
		for (size_t j = 0; j < kkt->factor->n; ++j) {
			double d = x[p[j]];
			if (!isfinite(d) || d == 0)
				return false;
		}
	}
	return true;
}

plume_status plume_kkt_factor(plume_kkt *kkt, bool allow_shift, double *shift, plume_error *err)
{
	*shift = 0;
	cholmod_factorize(kkt->matrix, kkt->factor, &kkt->common);
	if (factor_ok(kkt))
		return PLUME_OK;
	if (!allow_shift)
		return plume_error_set(err, PLUME_ERROR_NUMERIC, "the Newton matrix is not positive definite");
	// Not positive definite on the positions (a free rigid motion in statics, or an
	// indefinite constraint curvature term): Levenberg-style shifts, growing tenfold.
	double base = mean_position_diagonal(kkt);
	if (!(base > 0) || !isfinite(base))
		base = 1;
	double applied = 0;
	for (double factor = 1e-10; factor <= 1e2; factor *= 10) {
		double wanted = factor * base;
		shift_positions(kkt, wanted - applied);
		applied = wanted;
		cholmod_factorize(kkt->matrix, kkt->factor, &kkt->common);
		if (factor_ok(kkt)) {
			*shift = applied;
			return PLUME_OK;
		}
	}
	return plume_error_set(err, PLUME_ERROR_NUMERIC,
	                       "the Newton system could not be factored (CHOLMOD status %d) even after regularisation",
	                       kkt->common.status);
}

static plume_status solve_once(plume_kkt *kkt, const double *rhs, double *solution, plume_error *err)
{
	memcpy(kkt->rhs->x, rhs, sizeof(double) * kkt->rhs->nrow);
	if (!cholmod_solve2(CHOLMOD_A, kkt->factor, kkt->rhs, NULL, &kkt->solution, NULL, &kkt->work_y, &kkt->work_e,
	                    &kkt->common))
		return plume_error_set(err, PLUME_ERROR_NUMERIC, "CHOLMOD solve failed (status %d)", kkt->common.status);
	memcpy(solution, kkt->solution->x, sizeof(double) * kkt->rhs->nrow);
	return PLUME_OK;
}

enum { REFINEMENT_STEPS = 3 };

plume_status plume_kkt_solve(plume_kkt *kkt, const double *rhs, double *solution, plume_error *err)
{
	plume_status status = solve_once(kkt, rhs, solution, err);
	if (status != PLUME_OK || kkt->constraint_count == 0)
		return status;
	size_t size = kkt->rhs->nrow;
	if (kkt->refine == NULL && (kkt->refine = plume_alloc(2 * sizeof(double) * size)) == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory refining the Newton step");
	double *residual = kkt->refine, *correction = kkt->refine + size;
	const double *values = kkt->matrix->x;
	for (int step = 0; step < REFINEMENT_STEPS; ++step) {
		// residual = rhs - K0 x, K0 the matrix without the -d diagonal of the constraint rows.
		for (size_t i = 0; i < size; ++i)
			residual[i] = -rhs[i];
		plume_kkt_multiply_add(kkt, solution, residual);
		for (int k = 0; k < kkt->constraint_count; ++k) {
			size_t row = (size_t)(kkt->dof_count + k);
			residual[row] -= values[kkt->constraint_slots[7 * k + 6]] * solution[row];
		}
		for (size_t i = 0; i < size; ++i)
			residual[i] = -residual[i];
		if ((status = solve_once(kkt, residual, correction, err)) != PLUME_OK)
			return status;
		for (size_t i = 0; i < size; ++i)
			solution[i] += correction[i];
	}
	return PLUME_OK;
}

void plume_kkt_multiply_add(const plume_kkt *kkt, const double *x, double *y)
{
	const int *p = kkt->matrix->p, *rows = kkt->matrix->i;
	const double *values = kkt->matrix->x;
	for (size_t j = 0; j < kkt->matrix->ncol; ++j)
		for (int e = p[j]; e < p[j + 1]; ++e) {
			size_t i = (size_t)rows[e];
			y[i] += values[e] * x[j];
			if (i != j)
				y[j] += values[e] * x[i];
		}
}

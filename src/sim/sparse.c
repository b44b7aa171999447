// The CHOLMOD side of plume's sparse symmetric systems: the design, in sparse.h.
#include <assert.h>
#include <limits.h>
#include <math.h>
#include <omp.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/sort.h"
#include "sim/sparse.h"

// OpenBLAS's thread count, when the BLAS that CHOLMOD loaded is OpenBLAS (a weak
// reference: NULL with any other BLAS). Its multithreaded kernels split dense blocks
// by the thread count, which would make the factors' bits depend on it.
extern void openblas_set_num_threads(int threads) __attribute__((weak));

static bool same_entry(const plume_sparse_entry *p, const plume_sparse_entry *q)
{
	return p->column == q->column && p->row == q->row;
}

/// Sorts entries by (column, row), by counting (core/sort.h): qsort's comparisons were 1.5 %
/// of Figure 1's whole run at e = 5 mm (140 M instructions for the four sorts of the set-up).
/// False when memory runs out.
static bool sort_entries(plume_sparse_entry *entries, size_t count, int n)
{
	static_assert(sizeof(plume_sparse_entry) == 2 * sizeof(int) && offsetof(plume_sparse_entry, row) == sizeof(int),
	              "an entry is the pair (column, row)");
	return count <= INT_MAX && plume_sort_pairs((int *)entries, (int)count, n, n) == 0;
}

/// Allocates s->matrix with the pattern of the sorted, unique entries, one triangle:
/// stype 1 (upper, row <= column) or -1 (lower, row >= column).
static bool allocate_pattern(plume_sparse *s, int n, const plume_sparse_entry *entries, size_t unique, int stype)
{
	s->matrix = cholmod_allocate_sparse((size_t)n, (size_t)n, unique, 1, 1, stype, CHOLMOD_REAL, &s->common);
	if (s->matrix == NULL)
		return false;
	int *p = s->matrix->p, *rows = s->matrix->i;
	size_t e = 0;
	for (int column = 0; column < n; ++column) {
		p[column] = (int)e;
		for (; e < unique && entries[e].column == column; ++e)
			rows[e] = entries[e].row;
	}
	p[n] = (int)unique;
	return true;
}

/// The fill-reducing order of the pattern: AMD and CHOLMOD's two nested dissections
/// (METIS, and METIS with constrained AMD on the separators); the one whose factors cost
/// the fewest flops (CHOLMOD's own count, a property of the pattern, so the choice is
/// deterministic) is kept, postordered. Measured on Figure 1's matrices: AMD is best at
/// e = 5 mm, nested dissection from e = 2.5 mm on (docs/simulation.md).
static bool choose_ordering(plume_sparse *s)
{
	static const int orderings[] = {CHOLMOD_AMD, CHOLMOD_NESDIS, CHOLMOD_METIS};
	cholmod_factor *ordering = NULL;
	double best = INFINITY;
	s->common.nmethods = 1;
	s->common.postorder = 1;
	s->common.supernodal = CHOLMOD_SIMPLICIAL; // the flop count is the same, the analysis cheaper
	for (size_t k = 0; k < sizeof orderings / sizeof *orderings; ++k) {
		s->common.method[0].ordering = orderings[k];
		cholmod_factor *candidate = cholmod_analyze(s->matrix, &s->common);
		if (candidate != NULL && s->common.fl < best) {
			best = s->common.fl;
			cholmod_free_factor(&ordering, &s->common);
			ordering = candidate;
		} else {
			cholmod_free_factor(&candidate, &s->common);
		}
	}
	if (ordering == NULL)
		return false;
	size_t n = s->matrix->nrow;
	const int *perm = ordering->Perm;
	for (size_t k = 0; k < n; ++k) {
		s->permutation[k] = perm[k];
		s->inverse[perm[k]] = (int)k;
	}
	cholmod_free_factor(&ordering, &s->common);
	return true;
}

/// s->diagonal from the final pattern.
static plume_status find_diagonal(plume_sparse *s, const char *what, plume_error *err)
{
	size_t n = s->matrix->nrow;
	s->diagonal = plume_alloc(sizeof(int) * (n > 0 ? n : 1));
	if (s->diagonal == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating %s", what);
	for (size_t i = 0; i < n; ++i)
		s->diagonal[i] = plume_sparse_find(s, (int)i, (int)i);
	return PLUME_OK;
}

plume_status plume_sparse_init(plume_sparse *s, int n, plume_sparse_entry *entries, size_t count, bool factored,
                               const char *what, plume_error *err)
{
	memset(s, 0, sizeof *s);
	if (!sort_entries(entries, count, n))
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating %s", what);
	size_t unique = 0;
	for (size_t e = 0; e < count; ++e)
		if (unique == 0 || !same_entry(entries + unique - 1, entries + e))
			entries[unique++] = entries[e];

	cholmod_start(&s->common);
	s->started = true;
	s->common.print = 0; // failures come back through the status (DESIGN.md)
	s->permutation = plume_alloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
	s->inverse = plume_alloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
	if (s->permutation == NULL || s->inverse == NULL || !allocate_pattern(s, n, entries, unique, 1))
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating %s", what);
	for (int k = 0; k < n; ++k)
		s->permutation[k] = s->inverse[k] = k;
	if (!factored)
		return find_diagonal(s, what, err);

	if (!choose_ordering(s))
		return plume_error_set(err, PLUME_ERROR_MEMORY, "CHOLMOD could not order %s (status %d)", what,
		                       s->common.status);
	// Then the matrix itself in that order, P A P^T (upper triangle), analysed in its
	// natural order: the same factors, with nothing to permute per factorisation.
	for (size_t k = 0; k < unique; ++k) {
		int i = s->inverse[entries[k].row], j = s->inverse[entries[k].column];
		entries[k] = (plume_sparse_entry){i > j ? i : j, i > j ? j : i};
	}
	if (!sort_entries(entries, unique, n))
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating %s", what);
	cholmod_free_sparse(&s->matrix, &s->common);
	if (!allocate_pattern(s, n, entries, unique, 1))
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating %s", what);
	if (openblas_set_num_threads != NULL)
		openblas_set_num_threads(1);
	s->common.method[0].ordering = CHOLMOD_NATURAL;
	s->common.postorder = 0;
	s->common.supernodal = CHOLMOD_AUTO;
	s->common.final_ll = true;
	// Supernodal amalgamation: CHOLMOD merges a child supernode into its parent when the
	// merged one has at most nrelax[0] columns, or, up to nrelax[1] and nrelax[2] columns
	// and beyond, while the explicit zeros the merge stores stay under zrelax[0], [1] and
	// [2] of its entries. Its defaults (4, 16, 48 / 0.8, 0.1, 0.05) leave the supernodes
	// of a shell's 3-unknown vertex blocks small, and each small one costs a BLAS call and
	// a scalar scatter of its update into its parent. With these, the fastest
	// factorisation of Figure 1's matrix, measured in one sitting: 1.08 -> 0.87 ms at
	// e = 5 mm, 7.0 -> 6.1 ms at 2.5 mm, 19.0 -> 17.5 ms at 1.75 mm, 82 -> 64 ms at 1.25 mm
	// (docs/simulation.md, Supernodes). More (32, 64, 128 / 0.9, 0.3, 0.2) was slower
	// again from 1.75 mm on, and the solves read the stored zeros too (the 5 mm factor
	// holds 29 % more entries).
	s->common.nrelax[0] = 16;
	s->common.nrelax[1] = 48;
	s->common.nrelax[2] = 96;
	s->common.zrelax[0] = 0.9;
	s->common.zrelax[1] = 0.2;
	s->common.zrelax[2] = 0.1;
	s->factor = cholmod_analyze(s->matrix, &s->common);
	s->rhs = cholmod_zeros((size_t)n, 1, CHOLMOD_REAL, &s->common);
	s->solution = cholmod_zeros((size_t)n, 1, CHOLMOD_REAL, &s->common);
	s->permuted_rhs = cholmod_zeros((size_t)n, 1, CHOLMOD_REAL, &s->common);
	if (s->factor == NULL || s->rhs == NULL || s->solution == NULL || s->permuted_rhs == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "CHOLMOD could not analyse %s (status %d)", what,
		                       s->common.status);
	// A supernodal factorisation reads the lower triangle; given the upper one, it
	// transposes it on every call (cholmod_factorize: 4.6 % of Figure 1's run at e = 2.5 mm).
	// The simplicial one reads the upper triangle in place. The same pattern serves both
	// analyses: the factor's structure depends on the symmetric matrix, not on the triangle
	// stored.
	if (s->factor->is_super) {
		for (size_t k = 0; k < unique; ++k)
			entries[k] = (plume_sparse_entry){entries[k].row, entries[k].column};
		if (!sort_entries(entries, unique, n))
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating %s", what);
		cholmod_free_sparse(&s->matrix, &s->common);
		if (!allocate_pattern(s, n, entries, unique, -1))
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory allocating %s", what);
	}
	return find_diagonal(s, what, err);
}

void plume_sparse_free(plume_sparse *s)
{
	if (s->started) {
		cholmod_free_sparse(&s->matrix, &s->common);
		cholmod_free_factor(&s->factor, &s->common);
		cholmod_free_dense(&s->rhs, &s->common);
		cholmod_free_dense(&s->solution, &s->common);
		cholmod_free_dense(&s->work_y, &s->common);
		cholmod_free_dense(&s->work_e, &s->common);
		cholmod_free_dense(&s->permuted_rhs, &s->common);
		cholmod_free_dense(&s->permuted_solution, &s->common);
		cholmod_finish(&s->common);
	}
	plume_free(s->permutation);
	plume_free(s->inverse);
	plume_free(s->diagonal);
	memset(s, 0, sizeof *s);
}

int plume_sparse_find(const plume_sparse *s, int row, int column)
{
	int i = s->inverse[row], j = s->inverse[column];
	if ((i > j) == (s->matrix->stype > 0)) { // i: the row in column j's stored triangle
		int t = i;
		i = j;
		j = t;
	}
	const int *p = s->matrix->p, *rows = s->matrix->i;
	int lo = p[j], hi = p[j + 1] - 1;
	while (lo <= hi) {
		int mid = (lo + hi) / 2;
		if (rows[mid] == i)
			return mid;
		if (rows[mid] < i)
			lo = mid + 1;
		else
			hi = mid - 1;
	}
	return -1;
}

/// Every pivot (the factor's diagonal) finite and positive.
static bool pivots_usable(const cholmod_factor *L)
{
	const double *x = L->x;
	if (!L->is_super) {
		const int *p = L->p;
		for (size_t j = 0; j < L->n; ++j)
			if (!(isfinite(x[p[j]]) && x[p[j]] > 0)) // the diagonal leads each column
				return false;
		return true;
	}
	// A supernode holds columns super[s] .. super[s+1]-1 as a dense block of
	// pi[s+1] - pi[s] rows, column-major from px[s], its diagonal on top.
	const int *super = L->super, *pi = L->pi, *px = L->px;
	for (size_t s = 0; s < L->nsuper; ++s) {
		int rows = pi[s + 1] - pi[s];
		for (int j = 0; j < super[s + 1] - super[s]; ++j) {
			double d = x[px[s] + (size_t)j * rows + j];
			if (!(isfinite(d) && d > 0))
				return false;
		}
	}
	return true;
}

bool plume_sparse_factor(plume_sparse *s)
{
	// CHOLMOD's supernodal factorisation zeroes and scatters each large supernode in
	// OpenMP regions of four threads: on two cores their wake-ups and spinning cost more
	// than the loops (measured: a third of Figure 1's run at e = 2.5 mm), so it runs
	// with no parallel region active; the dense work is in the (one-thread) BLAS. The
	// limit is the calling thread's (an ICV of its data environment in libgomp and
	// libomp alike): other threads' parallel regions are untouched.
	int levels = omp_get_max_active_levels();
	omp_set_max_active_levels(0);
	cholmod_factorize(s->matrix, s->factor, &s->common);
	omp_set_max_active_levels(levels);
	return s->common.status == CHOLMOD_OK && s->factor->minor == s->factor->n && pivots_usable(s->factor);
}

bool plume_sparse_solve(plume_sparse *s)
{
	size_t n = s->rhs->nrow;
	const double *rhs = s->rhs->x;
	double *permuted = s->permuted_rhs->x;
	for (size_t k = 0; k < n; ++k)
		permuted[k] = rhs[s->permutation[k]];
	if (!cholmod_solve2(CHOLMOD_A, s->factor, s->permuted_rhs, NULL, &s->permuted_solution, NULL, &s->work_y,
	                    &s->work_e, &s->common))
		return false;
	const double *solved = s->permuted_solution->x;
	double *solution = s->solution->x;
	for (size_t k = 0; k < n; ++k)
		solution[s->permutation[k]] = solved[k];
	return true;
}

void plume_sparse_multiply_add(const plume_sparse *s, const double *x, double *y)
{
	const int *p = s->matrix->p, *rows = s->matrix->i, *unknown = s->permutation;
	const double *values = s->matrix->x;
	for (size_t column = 0; column < s->matrix->ncol; ++column)
		for (int e = p[column]; e < p[column + 1]; ++e) {
			size_t i = (size_t)unknown[rows[e]], j = (size_t)unknown[column];
			y[i] += values[e] * x[j];
			if (i != j)
				y[j] += values[e] * x[i];
		}
}

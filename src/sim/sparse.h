// Private: a symmetric sparse matrix with a fixed pattern, factored and solved by
// CHOLMOD's Cholesky factorisation LL'. The simulator's Newton systems (sim/kkt) and
// the lab's band model (lab/quadratic) are both built on it; a matrix can also be only
// stored (its values assembled, multiplied, never factored).
//
// Simplicial or supernodal is CHOLMOD's choice per pattern (CHOLMOD_AUTO: supernodal
// when the factor's flops per entry make dense kernels pay, on every Figure 1 mesh
// from e = 5 mm on, perf shows); the supernodal kernels run in the BLAS, OpenBLAS on Debian
// (scripts/deps.sh), held to one thread so that the bits never depend on the thread
// count (docs/simulation.md, "Linear algebra"). The fill-reducing ordering (the
// cheapest of AMD and two nested dissections, chosen once per pattern) is applied to
// the pattern itself, so that every factorisation reads the matrix in place.
// The library never prints.
#ifndef PLUME_SIM_SPARSE_H
#define PLUME_SIM_SPARSE_H

#include <stdbool.h>
#include <stddef.h>

#include <cholmod.h>

#include "plume/core.h"

/// One stored entry of the upper triangle, row <= column.
typedef struct plume_sparse_entry {
	int column;
	int row;
} plume_sparse_entry;

typedef struct plume_sparse {
	cholmod_common common;
	bool started;
	/// The fill-reducing order (postordered), applied once to the pattern (the identity
	/// for a stored-only matrix): permutation[k] is the unknown at position k, inverse[i]
	/// the position of unknown i.
	int *permutation;
	int *inverse;
	/// P A P^T, one triangle, CSC with sorted rows, factored in its natural order: the
	/// triangle the factorisation reads in place, the upper one (stype 1) for CHOLMOD's
	/// simplicial factorisation and for a stored-only matrix, the lower one (stype -1)
	/// for its supernodal one. (Given a matrix it must permute, the simplicial code copies
	/// and transposes it twice per call, 10 % of a factorisation on Figure 1; given the
	/// other triangle, either code transposes it once.) The caller writes the values, at
	/// plume_sparse_find's slots; row and column k are unknown permutation[k].
	cholmod_sparse *matrix;
	int *diagonal;          ///< per unknown i, the slot of A(i, i), or -1 when it is not in the pattern
	cholmod_factor *factor; ///< NULL for a stored-only matrix
	/// Right-hand side (the caller writes it) and solution, in the caller's order; the
	/// same permuted, and CHOLMOD's workspace, kept between solves.
	cholmod_dense *rhs;
	cholmod_dense *solution;
	cholmod_dense *permuted_rhs;
	cholmod_dense *permuted_solution;
	cholmod_dense *work_y;
	cholmod_dense *work_e;
} plume_sparse;

/// Builds the n x n pattern of the entries (sorted and deduplicated in place) and, with
/// factored, orders it and runs the symbolic analysis for LL' (the matrix is meant to be
/// positive definite; one that is not reports itself). Without, the matrix is only
/// stored, in the natural order. `what` names the matrix in error messages ("the
/// solver's matrix"). On failure, free with plume_sparse_free.
plume_status plume_sparse_init(plume_sparse *s, int n, plume_sparse_entry *entries, size_t count, bool factored,
                               const char *what, plume_error *err);
void plume_sparse_free(plume_sparse *s);

/// Index in s->matrix->x of the stored entry (row, column) of A (either triangle: it is
/// symmetric), or -1 when it is not in the pattern.
int plume_sparse_find(const plume_sparse *s, int row, int column);

/// Factors the current values. False when CHOLMOD fails, when a pivot is not positive, or
/// when one is not finite (a NaN passes the simplicial positivity test and OpenBLAS's):
/// the matrix then has no usable factorisation.
bool plume_sparse_factor(plume_sparse *s);

/// y += A x for the stored (symmetric) matrix; x and y in the caller's order.
void plume_sparse_multiply_add(const plume_sparse *s, const double *x, double *y);

/// Solves with the last factorisation: s->rhs into s->solution. False on failure.
bool plume_sparse_solve(plume_sparse *s);

#endif

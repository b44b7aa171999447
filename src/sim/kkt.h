// Private: the sparse symmetric systems of the Newton iteration, factored by CHOLMOD.
//
//   [ H   C^T ] [ dx     ]   [ -g ]
//   [ C  -dI  ] [ lambda ] = [ -c ]
//
// H is the (projected) Hessian over 3 n position unknowns, C the Jacobian of the
// barb-length constraints, d a tiny regularisation that makes the matrix
// quasi-definite. A quasi-definite matrix has an LDL' factorisation for every
// symmetric ordering (Vanderbei 1995), so CHOLMOD's simplicial LDL' factors it
// without pivoting; its supernodal mode computes LL' only and cannot. Without
// constraints the matrix is H alone, factored by Cholesky (LL', sim/sparse.h).
// The pattern is fixed per mesh, the symbolic analysis runs once, except when contact
// (sim/contact.c) couples vertices the mesh does not: plume_kkt_set_extra_blocks.
#ifndef PLUME_SIM_KKT_H
#define PLUME_SIM_KKT_H

#include <stdbool.h>

#include "plume/core.h"
#include "sim/sparse.h"

typedef struct plume_kkt {
	/// The matrix (upper triangle, values rewritten every iteration) and its factorisation.
	plume_sparse system;
	int dof_count;
	int constraint_count;
	/// Slot of the entry for each element block pair (upper part), -1 for the lower part.
	int *face_slots;       ///< 81 per face
	int *bending_slots;    ///< (3 k)^2 per bending element of k vertices
	int bending_size;      ///< k: 4 (hinge) or 6 (fundamental-form face)
	int *vertex_slots;     ///< 9 per vertex
	int *constraint_slots; ///< 7 per constraint: 6 Jacobian entries and the diagonal
	int *pair_slots;       ///< 36 per constraint: the 6x6 position block of its two vertices
	double *refine;        ///< scratch for iterative refinement (3 x size)
	/// plume_kkt_init's arguments (the caller keeps the arrays alive), for plume_kkt_set_extra_blocks.
	int vertex_count, face_count, bending_count, bending_stride;
	const int *faces, *bending_vertices, *constraint_vertices;
	/// 4-vertex blocks beyond the mesh's (contact pairs) in the current pattern.
	int extra_count;
} plume_kkt;

/// Builds the pattern from faces (3 vertices), bending elements (bending_size vertices
/// each, bending_stride bytes apart; a negative vertex is absent), per-vertex blocks and
/// constraints (2 vertices each), and runs the symbolic analysis.
plume_status plume_kkt_init(plume_kkt *kkt, int vertex_count, int face_count, const int *faces, int bending_count,
                            const int *bending_vertices, int bending_stride, int bending_size, int constraint_count,
                            const int *constraint_vertices, plume_error *err);
void plume_kkt_free(plume_kkt *kkt);

/// Rebuilds the pattern (and its symbolic analysis) with count extra blocks of 4 vertices
/// each (a negative vertex is absent) beside plume_kkt_init's: the contact pairs' couplings.
/// Slots of the old pattern are invalid afterwards. On failure the old pattern stays.
plume_status plume_kkt_set_extra_blocks(plume_kkt *kkt, int count, const int *vertices, plume_error *err);

/// Values array of the matrix (zero it, then add into slots).
double *plume_kkt_values(plume_kkt *kkt);
void plume_kkt_zero(plume_kkt *kkt);

/// Factors the current values. With allow_shift, a Hessian that is not positive
/// definite on the free unknowns is shifted by growing multiples of its mean
/// diagonal until it factors; *shift reports the shift used (0 normally). Without,
/// such a matrix returns PLUME_ERROR_NUMERIC; with constraints that is decided by the
/// inertia of the LDL' factors: the KKT matrix has exactly constraint_count negative
/// pivots iff H + C^T C / d is positive definite (Sylvester's law of inertia), that is,
/// with d tiny, iff H is positive definite on the tangent space of the constraints,
/// which is what makes the step a descent direction of the l1 merit (Nocedal & Wright,
/// Numerical Optimization, 2nd ed., sections 16.2 and 18.3).
plume_status plume_kkt_factor(plume_kkt *kkt, bool allow_shift, double *shift, plume_error *err);

/// Solves with the last factorisation: rhs and solution have dof_count + constraint_count entries.
/// With constraints, iterative refinement against the unregularised matrix (d = 0) removes
/// the regularisation's error, so the linearised constraints hold to rounding: a step
/// only while the componentwise backward error is above 1e-14 and falling, at most 3.
plume_status plume_kkt_solve(plume_kkt *kkt, const double *rhs, double *solution, plume_error *err);

/// y += K x for the assembled (symmetric) matrix.
void plume_kkt_multiply_add(const plume_kkt *kkt, const double *x, double *y);

#endif

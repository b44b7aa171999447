// Private: the sparse symmetric systems of the Newton iteration, factored by CHOLMOD.
//
//   [ H   C^T ] [ dx     ]   [ -g ]
//   [ C   0   ] [ lambda ] = [ -c ]
//
// H is the (projected) Hessian over 3 n position unknowns, C the Jacobian of the
// barb-length constraints. The callers assemble this matrix, K. It is solved through
// the regularised matrix [H C^T; C -R^-1], R = diag(rho_k), whose Schur complement
// eliminates the multipliers:
//
//   (H + C^T R C) dx = -g - C^T R c,    lambda = R (C dx + c),
//
// positive definite exactly when H is positive definite on the tangent space of the
// constraints, for rho large enough (Debreu's lemma; Nocedal & Wright, Numerical
// Optimization, 2nd ed., theorem 17.5), and then factored by Cholesky, supernodal where
// it pays (sim/sparse.h). Iterative refinement against K itself removes the
// regularisation's error (each step shrinks it by about 1/(1 + rho_k s_k), s_k the
// constraint's compliance); a guess of the multipliers (the last iterate's) starts it
// closer. This replaced a simplicial LDL' of the quasi-definite K
// (Vanderbei 1995), which CHOLMOD cannot factor supernodally: docs/simulation.md,
// "Linear algebra", measures both. Without constraints the matrix is H alone.
// The pattern is fixed per mesh, the symbolic analysis runs once, except when contact
// (sim/contact.c) couples vertices the mesh does not: plume_kkt_set_extra_blocks.
#ifndef PLUME_SIM_KKT_H
#define PLUME_SIM_KKT_H

#include <stdbool.h>

#include "plume/core.h"
#include "sim/sparse.h"

typedef struct plume_kkt {
	/// K, stored (upper triangle, natural order, values rewritten every iteration): the
	/// callers add into its slots; system.diagonal[i] is the slot of position unknown i's
	/// diagonal entry.
	plume_sparse system;
	/// H + C^T R C over the position unknowns, factored.
	plume_sparse positions;
	int *position_slots; ///< per stored entry of K's position block (they come first), its slot in positions
	int *augment_slots;  ///< 21 per constraint: positions' slots of its two vertices' 6x6 block (upper)
	double *rho;         ///< per constraint, the regularisation's rho_k of the last factorisation
	int dof_count;
	int constraint_count;
	/// Slots of each element block's upper triangle in the element's order, the pairs
	/// (a, b) with a <= b row by row (plume_kkt_upper_size); -1 where a vertex is absent.
	int *face_slots;       ///< 45 per face
	int *bending_slots;    ///< plume_kkt_upper_size(k) per bending element of k vertices
	int *edge_slots;       ///< 78 per shared edge (4 vertices)
	int bending_size;      ///< k: 4 (hinge) or 6 (fundamental-form face)
	int *vertex_slots;     ///< 6 per vertex
	int *constraint_slots; ///< 6 per constraint: its row of C
	int *pair_slots;       ///< 21 per constraint: the 6x6 position block of its two vertices
	double *refine;        ///< scratch for iterative refinement (3 x size)
	/// plume_kkt_init's arguments (the caller keeps the arrays alive), for plume_kkt_set_extra_blocks.
	int vertex_count, face_count, bending_count, bending_stride, edge_count;
	const int *faces, *bending_vertices, *edge_vertices, *constraint_vertices;
	/// 4-vertex blocks beyond the mesh's (contact pairs) in the current pattern.
	int extra_count;
} plume_kkt;

/// The number of pairs a <= b of an element of k vertices (3 k unknowns): its upper slots.
static inline int plume_kkt_upper_size(int k) { return 3 * k * (3 * k + 1) / 2; }

/// Builds the pattern from faces (3 vertices), bending elements (bending_size vertices
/// each, bending_stride bytes apart; a negative vertex is absent), the fundamental-form
/// faces' shared edges (4 vertices each, blocks of the faces' own: slots only), per-vertex
/// blocks and constraints (2 vertices each), and runs the symbolic analysis.
plume_status plume_kkt_init(plume_kkt *kkt, int vertex_count, int face_count, const int *faces, int bending_count,
                            const int *bending_vertices, int bending_stride, int bending_size, int edge_count,
                            const int *edge_vertices, int constraint_count, const int *constraint_vertices,
                            plume_error *err);
void plume_kkt_free(plume_kkt *kkt);

/// Rebuilds the pattern (and its symbolic analysis) with count extra blocks of 4 vertices
/// each (a negative vertex is absent) beside plume_kkt_init's: the contact pairs' couplings.
/// Slots of the old pattern are invalid afterwards. On failure the old pattern stays.
plume_status plume_kkt_set_extra_blocks(plume_kkt *kkt, int count, const int *vertices, plume_error *err);

/// Values array of the matrix (zero it, then add into slots).
double *plume_kkt_values(plume_kkt *kkt);
void plume_kkt_zero(plume_kkt *kkt);

/// Factors the current values. A Hessian that is not positive definite on the free
/// unknowns (with constraints, when H + C^T R C is not positive definite, which, rho_k
/// being 1e6 times the diagonal of H at the constraint's ends (kkt.c), says that H is not positive
/// definite on the tangent space of the constraints, the condition for a descent
/// direction of the l1 merit: Nocedal & Wright, sections 16.2 and 18.3) is shifted:
/// H + s d I, d the mean of H's diagonal and s the smallest of the ladder first_shift,
/// 10 first_shift, ... up to largest_shift (the last rung) that factors (first_shift at or
/// below 1e-10 starts at 1e-10 and climbs by hundredfold rungs). *shift is that s, 0 when
/// H factored as it is. PLUME_ERROR_NUMERIC when no s of the ladder factors (with
/// largest_shift 0: when H does not).
plume_status plume_kkt_factor(plume_kkt *kkt, double first_shift, double largest_shift, double *shift,
                              plume_error *err);

/// Solves K [dx; lambda] = rhs with the last factorisation: rhs and solution have
/// dof_count + constraint_count entries. With constraints, iterative refinement against
/// K: a step only while the componentwise backward error max |r_i| / (|K||x| + |rhs|)_i,
/// or the largest residual force on a position row over the largest force of rhs, is above
/// tolerance, and falling, at most 8 (1e-14: the linearised constraints hold to rounding). multipliers
/// (constraint_count entries, or NULL for 0) is a guess of the solution's lambda for the regularised solve to start
/// from: the first residual is the guess's error over rho, about 1e-5 of the system for a good guess, and each step
/// gains about five decades.
plume_status plume_kkt_solve(plume_kkt *kkt, const double *rhs, const double *multipliers, double tolerance,
                             double *solution, plume_error *err);

/// The same without refinement: one solve of the regularised system, whose constraint rows
/// hold to lambda / rho_k (relative 1e-6 of the diagonal). For steps that a merit judges
/// anyway (Newton's second-order corrections): measured on Figure 1 at 2.5 mm, the same
/// iterations with 0 refinement steps as with up to 8, and 11 % less time (10.9 -> 9.7 s).
plume_status plume_kkt_solve_unrefined(plume_kkt *kkt, const double *rhs, double *solution, plume_error *err);

/// y += K x for the assembled (symmetric) matrix.
void plume_kkt_multiply_add(const plume_kkt *kkt, const double *x, double *y);

#endif

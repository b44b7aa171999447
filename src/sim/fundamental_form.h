// Fundamental-form (mid-edge) bending: one energy per face, the continuum plate energy
//   W_f = (A/2) <II - II0, C (II - II0)>
// of the face's discrete second fundamental form II (Grinspun et al. 2006, "Computing
// discrete shape operators on general meshes"; Chen et al. 2018, "Physical simulation of
// environmentally induced thin shell deformation", the mid-edge average formulation) with
// the per-face anisotropic bending tensor C of paper eqs. 6-8 / thesis eqs. 6.2-6.5.
//
// Mid-edge normals interpolated linearly over the face (Crouzeix-Raviart) have the
// gradient sum_i (n_i - n_f) (l_i / A) t_i^T, with l_i the length of the edge opposite
// vertex i and t_i its in-plane unit normal; a mid-edge normal that is the average of the
// two face normals makes half the edge's dihedral angle chi_i with n_f, in the plane
// normal to the edge, so
//   II = sum_i (chi_i / 2) (l_i / A) t_i t_i^T
// (the half-angle replaces sin(chi/2) of the unit average; they agree to O(chi^3)).
// Lengths, normals and areas are those of the reference (material) triangle, so II - II0
// is linear in the dihedral angles and W_f = 1/2 dchi^T M dchi with a constant 3 x 3 M:
//   M_ij = l_i l_j / (4 A) B(t_i t_i^T, t_j t_j^T).
// II is exact for a quadratic surface whenever the two vertices across each edge are
// symmetric about its midpoint (every lattice triangulation: right-isosceles, equilateral,
// elongated, slanted), unlike the hinge energy, whose weight suits one triangle shape.
//
// Bending tensor (barb frame v along the barb, w across): the energy density
//   (1/2) [D_across k_vv^2 + D_along k_ww^2 + (D_along + D_across) k_vw^2]
// gives, for a fold of curvature k across an edge at tilt beta to the barbs, exactly
// (1/2) D(beta) k^2 with D(beta) of eq. 6.4; it is the Poisson-ratio-0 plate (the vane's
// membrane has no Poisson coupling either, paper eq. 5) and (1/2) D |K|^2 when isotropic.
//
// Free boundary: an edge with one face has no dihedral angle. Its mid-edge normal is left
// free (as a director would be) and minimised away: M is condensed onto the interior edges
// by the Schur complement, which is the exact energy of a face at a free edge.
//
// Material borders: the average normal splits an edge's angle half and half between its
// faces, right for one material; across a border (rachis 6.4 N m, vane 1e-7 N m) it would
// make the stiff side hold the soft side's fold. There the edge's normal is placed where
// it minimises D_f phi_f^2 + D_g phi_g^2 with phi_f + phi_g = chi (D the faces' moduli for a
// fold along the edge): face f sees s chi / 2 with s = 2 D_g / (D_f + D_g), 1 inside one
// material, 2 next to a much stiffer face, 0 next to a much softer one.
//
// Clamps: a face whose three vertices are held by handles moves rigidly, so its bending is
// prescribed (its energy is dropped), and the mid-edge normal on an edge it shares with a
// free face is the clamp's normal, not the average: the free face sees the full dihedral
// angle there. With the average the clamp would act half a cell inside it (a cantilever
// is then too soft by 3 (h/2) / L, measured).
#ifndef PLUME_SIM_FUNDAMENTAL_FORM_H
#define PLUME_SIM_FUNDAMENTAL_FORM_H

#include <stdbool.h>

#include "plume/core.h"

typedef struct plume_ff_face {
	/// The face's vertices v0 v1 v2, then for i = 0, 1, 2 the vertex across the edge opposite
	/// v_i (the other face's third vertex), -1 where that edge is on the boundary.
	int vertices[6];
	/// Dihedral angle chi_0 of each edge (opposite v_i) in the 3D rest shape, radians.
	double rest_angle[3];
	/// M, 3 x 3 row-major, symmetric positive semidefinite, N m: W = 1/2 dchi^T M dchi.
	double stiffness[9];
	/// s_i: dchi_i enters as s_i dchi_i: border_scale inside and next to free faces, 2 next to a
	/// clamped face, 0 in a clamped face.
	double edge_scale[3];
	/// 2 D_g / (D_f + D_g) of the material border rule above; 1 inside one material.
	double border_scale[3];
	/// Shared edges (plume_ff_face_link): edge i's index among the mesh's interior edges
	/// (-1 on the boundary or when unlinked), the slot in that edge's stencil of each of
	/// the four vertices of this face's hinge, and +1 or -1: this face's angle is sign
	/// times the edge's.
	int edge[3];
	unsigned char edge_order[3][4];
	signed char edge_sign[3];
} plume_ff_face;

/// The bilinear form of the bending tensor on two symmetric 2 x 2 curvatures given as
/// (k_xx, k_yy, k_xy) in the reference frame, barbs at angle barb_angle: the energy
/// density of K is 1/2 plume_ff_tensor_form(K, K). N m.
double plume_ff_tensor_form(const double a[3], const double b[3], double barb_angle, double along, double across);

/// reference: the face's three vertices in the reference plane; rest: the six stencil
/// vertices in the 3D rest shape (entries for -1 vertices are ignored). Returns false when
/// the reference triangle is degenerate.
bool plume_ff_face_init(plume_ff_face *face, const int vertices[6], const plume_vec2 reference[3],
                        const plume_vec3 rest[6], double barb_angle, double along, double across);

/// D_f for a fold along the edge opposite v_i of a face (reference triangle, barb direction
/// and moduli as for plume_ff_face_init): the material border rule's modulus, N m.
double plume_ff_edge_modulus(const plume_vec2 reference[3], int i, double barb_angle, double along, double across);

/// Sets border_scale (and edge_scale) of edge i from the two faces' moduli for folds along it.
void plume_ff_face_border(plume_ff_face *face, int i, double own_modulus, double other_modulus);

/// Sets edge_scale from which stencil vertices are held by handles (see Clamps above).
void plume_ff_face_clamp(plume_ff_face *face, const bool held[6]);

/// Energy at the six stencil positions (entries for -1 vertices are ignored), with the
/// gradient (18) and exact Hessian (324, row-major, NOT projected); either may be NULL.
/// Rows and columns of absent vertices are zero.
double plume_ff_face_energy(const plume_ff_face *face, const plume_vec3 x[6], double gradient[18], double hessian[324]);

/// plume_ff_face_energy with, in place of the Hessian, its positive semidefinite
/// Gauss-Newton part J^T M J (J: the dihedral angles' gradients), exact at the rest angles:
/// what the Newton solver assembles. One pass over the angles.
double plume_ff_face_energy_gauss_newton(const plume_ff_face *face, const plume_vec3 x[6], double gradient[18],
                                         double hessian[324]);

// Shared edges. An interior edge's dihedral angle belongs to both of its faces, and its
// Hessian is most of the cost of a fundamental-form Hessian (Figure 1: a fifth of the
// run), so the solver computes each edge's angle and derivatives once, with
// plume_dihedral_angle_derivatives on the edge's stencil, and each face combines its
// three edges' (plume_ff_face_energy_from_edges). The exact Hessian,
//   J^T M J + sum_i (M dchi)_i s_i Hess chi_i
// (J the scaled angle changes' gradients, s_i their scales and signs), takes each angle's
// Hessian times a weight: the solver sums an edge's weights over its two faces and adds
// its 12 x 12 Hessian once, instead of once into each face's 18 x 18 block (half the
// cost of combining the faces' derivatives: docs/simulation.md, "The solver's floor").

/// The vertices of face's hinge across edge i, in plume_dihedral_angle's order: the edge
/// v_{i+1} -> v_{i+2}, v_i, the vertex across (-1 on the boundary).
void plume_ff_hinge_vertices(const plume_ff_face *face, int i, int out[4]);

/// Links the face's edge i to interior edge `edge`, whose stencil is `stencil` (the same
/// four vertices in some plume_dihedral_angle order: the edge's two, then its two wings).
void plume_ff_face_link(plume_ff_face *face, int i, int edge, const int stencil[4]);

/// The face's energy from the interior edges' angles (chi, one per edge) and gradients (12
/// per edge, the edge's stencil order), with its gradient (18) and Gauss-Newton Hessian
/// J^T M J (324, row-major: only its upper triangle, row r and columns c >= r, is
/// written, the part the solver reads), either may be NULL, and weight[i], the weight of
/// edge i's angle Hessian in the face's exact Hessian (0 on the boundary):
///   plume_ff_face_energy's Hessian = J^T M J + sum_i weight[i] Hess chi_{edge[i]}.
/// Every interior edge of the face must be linked.
double plume_ff_face_energy_from_edges(const plume_ff_face *face, const double *chi, const double *gradients,
                                       double gradient[18], double gauss_newton[324], double weight[3]);

#endif // PLUME_SIM_FUNDAMENTAL_FORM_H

// plume simulation: a feather as a strongly anisotropic elastic shell
// (Jouve et al. 2024, sections 5-7; Jouve thesis chapters 4 and 6).
//
// A plume_sim owns a copy of what it needs from a plume_mesh, the current
// positions and velocities, and the sparse solver. Each step minimises an
// incremental potential (implicit Euler or BDF2) with Newton's method; statics is the
// same minimisation without inertia. Barb-aligned edges can be held at their
// reference length as hard constraints (paper section 6).
#ifndef PLUME_SIM_H
#define PLUME_SIM_H

#include "plume/core.h"
#include "plume/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

enum { PLUME_MAX_MATERIALS = 8 };

typedef enum plume_material_kind {
	/// Orthotropic St-Venant-Kirchhoff, zero Poisson ratio (paper eq. 5, thesis A.2).
	PLUME_MATERIAL_ORTHOTROPIC = 0,
	/// Isotropic St-Venant-Kirchhoff (plane stress) with a Poisson ratio.
	PLUME_MATERIAL_ISOTROPIC = 1,
} plume_material_kind;

/// One material of the shell. Faces pick theirs through plume_mesh.material.
typedef struct plume_material {
	plume_material_kind kind;
	/// Orthotropic moduli, Pa, in the barb frame (v along the barb, w across).
	/// E_vv is the stiffness along the barbs when barb_constraint is false; with
	/// the constraint it is replaced by E_ww (paper footnote 3).
	double E_vv;
	double E_ww;
	double E_vw;
	/// Isotropic Young's modulus, Pa, and Poisson ratio in [0, 0.5).
	double youngs_modulus;
	double poisson_ratio;
	/// Shell thickness, m, > 0.
	double thickness;
	/// Mass per unit reference area, kg/m^2, >= 0.
	double surface_density;
	/// Hold every barb-aligned edge of these faces at its reference length (eps_vv = 0).
	bool barb_constraint;
	/// Bending moduli, N m (thesis eq. 6.4), continuum plate moduli: a flat sheet rolled
	/// into a cylinder of radius R stores (1/2) D A / R^2 (docs/physics-energies.md): `bending_along` for an edge
	/// parallel to the barbs (a hinge that keeps the barbs straight; soft), `bending_across` for an edge across them
	/// (bends the barbs; stiff). Isotropic materials use bending_along for both when bending_across is negative.
	double bending_along;
	double bending_across;
	/// Kikuuwe coefficient kappa, Pa (thesis eq. 6.6: b kappa / 12 ((1 - J)/6)^3 per unit area);
	/// 0 disables the compression term.
	double compression_coefficient;
} plume_material;

/// The vane of thesis Table 6.1 with the inextensibility constraint: E_ww = 4.80e4 Pa,
/// E_vw = 1.99e4 Pa (plume's calibration, docs/lab.md), thickness 1.2e-4 m (mean of
/// Table 3.1), 2.6e-2 kg/m^2, bending 1e-7 / 2.5e-4 N m, kappa 4.2e11 Pa (Table 6.1's
/// 5.04e7 N/m is b kappa; docs/physics-energies.md).
plume_material plume_material_vane(void);
/// The rachis of thesis Table 6.1: isotropic, E = 34 MPa, nu = 0.49, thickness 1.2e-2 m, 0.54 kg/m^2;
/// bending D = E t^3 / (12 (1 - nu^2)) = 6.44 N m.
plume_material plume_material_rachis(void);

/// Newton solver settings (thesis Table 6.1).
typedef struct plume_solver_def {
	/// Converged when the Newton decrement and the free gradient norm, both relative to the
	/// problem's force scale, fall below this. Default 1e-7.
	double tolerance;
	/// Newton iterations per solve. Default 50.
	int max_iterations;
	/// Halvings of the step before a failed step is retried with substeps. Default 4
	/// (up to 16 substeps).
	int max_substep_halvings;
} plume_solver_def;

/// How a dynamic step advances in time (docs/simulation.md). Each is one minimisation of an
/// incremental potential, so the same Newton/SQP solver and barb constraints serve all.
typedef enum plume_integrator {
	/// First order; damps motion by about 2 pi omega h of its energy a period (thesis eq. B.2).
	PLUME_INTEGRATOR_IMPLICIT_EULER = 0,
	/// Second-order backward differentiation (variable step; implicit Euler for the first step):
	/// damps resolved motion by O((omega h)^3) a period and unresolved vibrations strongly.
	PLUME_INTEGRATOR_BDF2 = 1,
} plume_integrator;

/// Quadratic per-face aerodynamic forces (src/sim/air.c, docs/simulation.md): on a face of area A,
/// unit normal n and velocity u relative to the air, -1/2 rho A (C_n w |u.n| (u.n) n + C_t |u_t| u_t),
/// with w the face's share of a centre of pressure ahead of mid-chord (Rayleigh's flat plate).
typedef struct plume_air_def {
	/// Air density, kg/m^3, >= 0; 0 turns the model off. Default 0 (off); 1.2 for air.
	double density;
	/// Normal (pressure) drag coefficient, >= 0. Default 1.17 (flat plate broadside, Hoerner 1965).
	double normal_drag;
	/// Tangential (skin friction) coefficient, >= 0. Default 0.07 (Blasius, both sides, Re ~ 1.5e3).
	double tangential_drag;
	/// Move the normal force's centre of pressure ahead of mid-chord (Rayleigh 1876). Default true.
	bool centre_of_pressure;
	/// Uniform wind, m/s. Default 0.
	plume_vec3 wind;
	/// Turbulent gusts: RMS speed, m/s (>= 0; 0: none), length scale, m (> 0), time scale, s (> 0).
	double gust_speed;
	double gust_length;
	double gust_time;
	/// Seed of the gusts' random modes: the same seed gives the same wind.
	uint64_t seed;
} plume_air_def;

/// The discretisation of the bending energy (docs/physics-energies.md).
typedef enum plume_bending_model {
	/// Per-face second fundamental form from mid-edge normals with the anisotropic bending
	/// tensor of paper eqs. 6-8: the continuum stiffness on any lattice triangulation.
	PLUME_BENDING_FUNDAMENTAL_FORM = 0,
	/// The paper's hinge energy (thesis eqs. 6.2-6.5): exact on equilateral triangles only.
	PLUME_BENDING_PAPER_HINGE = 1,
} plume_bending_model;

/// Contact (docs/contact.md): IPC's log barrier (Li et al. 2020, "Incremental Potential Contact")
/// between the shell and itself and between the shell and obstacles, with continuous collision
/// detection bounding every Newton step, so no accepted state has two surfaces in contact.
typedef struct plume_contact_def {
	/// Turn contact on. Default false (scenes turn it on).
	bool enabled;
	/// The barrier's reach d-hat, m, > 0: pairs of primitives closer than this repel. Default
	/// 1.2e-4, the vane's thickness (thesis Table 3.1 and Table 6.1), so two vanes at rest lie
	/// about a thickness apart.
	double distance;
	/// Adapt the barrier's stiffness to the shell's mass and motion (docs/contact.md "Stiffness";
	/// after IPC's adaptive stiffness, Li et al. 2020 section 4.3 and supplement): a pair's kappa is
	/// a * m / (4.33 d-hat^3), m the mean mass of its shell vertices (kg), so the barrier at
	/// d-hat / 2 holds m at acceleration a; a (m/s^2), fixed at each (sub)step's start, is the
	/// largest of gravity, the largest load per vertex mass, the fastest shell vertex's or
	/// obstacle vertex's speed over the (sub)step's length (what stops it within one step), and
	/// a floor that doubles after a step whose pairs came closer than d-hat / 10. Default true;
	/// false uses `stiffness` for every pair (a scene's "stiffness" key sets it false).
	bool adaptive_stiffness;
	/// Barrier stiffness kappa, J/m^4, > 0, when adaptive_stiffness is false: a pair's energy is
	/// kappa b(d^2) with IPC's b(d^2) = -(d^2 - dhat^2)^2 ln(d^2 / dhat^2) (m^4). Default 1e6: a
	/// point over a plane at d = dhat / 2 is then pushed with 4.33 kappa dhat^3 = 7.5e-6 N, about
	/// the weight of a vane vertex at the default 5 mm mesh (0.026 kg/m^2 x 2.2e-5 m^2 x
	/// 9.81 m/s^2).
	double stiffness;
	/// A feather against itself and against other feathers of the same mesh. Default true;
	/// false keeps contact with obstacles only.
	bool self_contact;
	/// Every line-search step keeps each pair at least this fraction of its distance at the
	/// step's start (continuous collision detection), in (0, 1). Default 0.1 (IPC uses
	/// 0.1-0.2: the next iterate keeps room for the barrier to act).
	double ccd_separation;
	/// Coulomb friction coefficient mu, >= 0, in dynamic steps: IPC's lagged, smoothed
	/// friction (Li et al. 2020, section 5), normal forces and sliding directions taken at
	/// each step's start; below 1e-3 m/s of sliding it acts as a stiff viscous force.
	/// Default 0 (frictionless).
	double friction;
} plume_contact_def;

typedef struct plume_sim_def {
	/// Material table indexed by plume_mesh.material. Default: [vane, rachis].
	plume_material materials[PLUME_MAX_MATERIALS];
	int material_count;
	/// m/s^2. Default (0, -9.81, 0).
	plume_vec3 gravity;
	/// Linear aerodynamic drag per unit area, kg/(m^2 s): force -c A (v . n) n on each vertex's
	/// share of area A. Default 0.
	double drag;
	/// Quadratic aerodynamics and wind. Default off (density 0).
	plume_air_def air;
	/// Time step, s, > 0. Default 0.011 (thesis Table 6.1).
	double time_step;
	/// Time integration of plume_sim_step. Default BDF2; the thesis (Table 6.1) used implicit Euler.
	plume_integrator integrator;
	/// Include the bending energy. Default true.
	bool bending;
	/// How bending is discretised. Default PLUME_BENDING_FUNDAMENTAL_FORM.
	plume_bending_model bending_model;
	/// Fix every vertex's z: in-plane problems (the lab's samples). Default false.
	bool planar;
	plume_solver_def solver;
	/// Contact with itself and with obstacles. Default off.
	plume_contact_def contact;
	/// PLUME_DEF_COOKIE, set by plume_sim_default_def; do not change.
	uint32_t cookie;
} plume_sim_def;

plume_sim_def plume_sim_default_def(void);

/// Checks materials and settings; messages name the field as a JSON path of a scene
/// ("$.materials.vane.thickness is -1, allowed > 0").
plume_status plume_sim_def_validate(const plume_sim_def *def, int mesh_material_count, plume_error *err);

typedef struct plume_sim plume_sim;

/// Copies what it needs from mesh (the mesh may be destroyed afterwards).
plume_status plume_sim_create(const plume_mesh *mesh, const plume_sim_def *def, plume_sim **out, plume_error *err);
void plume_sim_destroy(plume_sim *sim);

/// Dirichlet handles: the group's vertices follow rest + motion. A vertex may be in one handle.
/// Returns the handle index, or -1 with err set (unknown group).
int plume_sim_add_handle(plume_sim *sim, const char *group, plume_error *err);
/// Moves a handle rigidly: each vertex goes to rotation * (rest - pivot) + pivot + translation.
/// handle is an index plume_sim_add_handle returned (below plume_sim_handle_count); every
/// number finite.
void plume_sim_set_handle(plume_sim *sim, int handle, plume_vec3 translation, plume_mat3 rotation, plume_vec3 pivot);
/// The handles added so far: their indices are 0 .. count - 1.
int plume_sim_handle_count(const plume_sim *sim);

/// Applies a constant external force, N, shared equally by the group's vertices (a weight
/// hung on them); replaces any load set on that group before. Unknown group, or a force that
/// is not finite: PLUME_ERROR_SPEC.
plume_status plume_sim_set_group_load(plume_sim *sim, const char *group, plume_vec3 force, plume_error *err);
/// The same force added to the loads the group's vertices already carry: forces of groups
/// that share vertices add up there (a scene's "forces", docs/scene.md).
plume_status plume_sim_add_group_load(plume_sim *sim, const char *group, plume_vec3 force, plume_error *err);

/// What one solve did.
typedef struct plume_solve_report {
	bool converged;
	int newton_iterations;
	/// Substeps the step needed (1 when the first try converged).
	int substeps;
	/// Free-DOF gradient norm at the end, N.
	double gradient_norm;
	/// Potential at the end, J (elastic + gravity, plus inertia for a step; with contact the
	/// barrier, and in a step with friction the friction dissipation potential).
	double energy;
	/// Largest |l - L| / L over barb-aligned edges.
	double max_barb_strain;
	/// Seconds in assembly, factorisation and solve.
	double seconds_assembly;
	double seconds_factor;
	double seconds_solve;
	/// Seconds in contact detection: the broad phase and CCD bounding the steps and the
	/// prescribed motion (the barrier's own terms count as assembly). 0 without contact.
	double seconds_contact;
	/// Contact (with def.contact.enabled): pairs of primitives within the barrier's reach at the
	/// end, and the smallest pair distance seen at accepted iterates, m (+inf when none was
	/// within reach).
	int contact_pairs;
	double min_distance;
} plume_solve_report;

/// Minimises the elastic + gravity potential with the handles where they are.
/// Returns PLUME_ERROR_NUMERIC when it did not converge: the positions are then
/// the last iterate (finite), and report says so. PLUME_ERROR_SPEC when the handles hold
/// both ends of a constrained barb and change its length (by more than 1e-8 of it).
plume_status plume_sim_solve_static(plume_sim *sim, plume_solve_report *report, plume_error *err);

/// One step of def.time_step with def.integrator; handles must be set for the end of the step.
/// A step that does not converge is retried with substeps (handles interpolated linearly);
/// if that fails too, the state is left as before the step and PLUME_ERROR_NUMERIC returned.
/// PLUME_ERROR_SPEC (the state left as before) when the handles hold both ends of a
/// constrained barb and change its length by more than 1e-8 of it: no solve can keep it.
plume_status plume_sim_step(plume_sim *sim, plume_solve_report *report, plume_error *err);

/// Obstacles: triangle meshes moved by prescription (bodies). The shell collides with them
/// (with def.contact.enabled); they do not move in response. Shell primitives at a vertex a
/// handle holds are left out of contact with obstacles (the attachment: a calamus in its
/// follicle), so add the handles first. The positions are copied; triangles index them.
/// Returns the obstacle's index in *obstacle. PLUME_ERROR_SPEC for out-of-range indices,
/// non-finite positions or an obstacle that touches the shell; PLUME_ERROR_MEMORY.
plume_status plume_sim_add_obstacle(plume_sim *sim, const plume_vec3 *positions, int vertex_count, const int *triangles,
                                    int triangle_count, int *obstacle, plume_error *err);
/// The obstacle's positions at the end of the next step or static solve (vertex_count of
/// them); within the step it moves linearly from where it was.
void plume_sim_set_obstacle_positions(plume_sim *sim, int obstacle, const plume_vec3 *positions);

int plume_sim_vertex_count(const plume_sim *sim);
/// Barb-aligned edges held inextensible.
int plume_sim_constraint_count(const plume_sim *sim);
const plume_vec3 *plume_sim_positions(const plume_sim *sim);
const plume_vec3 *plume_sim_velocities(const plume_sim *sim);
double plume_sim_time(const plume_sim *sim);

/// Sum over a group's vertices of the force a handle must apply to hold them where they are
/// (it balances the elastic, constraint and gravity forces on them), N, at the current state.
/// A clamp that stretches a sample in +y reports a positive y. Unknown group: returns false.
bool plume_sim_group_reaction(plume_sim *sim, const char *group, plume_vec3 *force);
/// plume_sim_group_reaction for count groups on one evaluation of the forces (each call of the
/// singular one evaluates them all): forces[k] for groups[k]. Returns false, and writes
/// nothing, when a group is unknown.
bool plume_sim_group_reactions(plume_sim *sim, const char *const *groups, int count, plume_vec3 *forces);

/// Energies at the current state, J.
typedef struct plume_sim_energies {
	double membrane;
	double bending;
	double compression;
	double gravity;
	double kinetic;
	/// Contact (def.contact.enabled; 0 otherwise): IPC's barrier over the pairs within reach
	/// (Li et al. 2020, eq. 6; +inf would mean two surfaces touch, which no accepted state has)
	/// and the friction dissipation potential D(x) of the last (sub)step (section 5.3: mu lambda
	/// f0(|T^T u|) over its lagged pairs, u the sliding since the (sub)step's start; 0 without
	/// friction and after a static solve). Both are terms of the incremental potential that the
	/// last solve minimised (plume_solve_report.energy includes them).
	double contact;
	double friction;
} plume_sim_energies;
plume_sim_energies plume_sim_energy(plume_sim *sim);

/// What one face carries at the current state (plume_sim_face_fields). Tensors are
/// in the reference plane's (x, y) frame as tensor components (not Voigt's doubled
/// shear); rotate them by the face's barb angle (plume_mesh.barb_angle) for the barb frame.
typedef struct plume_sim_face_field {
	/// Green strain E = (F^T F - I) / 2: xx, yy, xy.
	double strain[3];
	/// Second Piola-Kirchhoff stress of the St-Venant-Kirchhoff membrane, Pa: xx, yy, xy
	/// (S = C : E with the face's material tensor, divided by nothing: the shell's
	/// thickness is in the energy, not in S).
	double stress[3];
	/// Energy per unit reference area, J/m^2: St-Venant-Kirchhoff membrane, Kikuuwe
	/// compression term, and bending (half of each adjacent hinge's energy).
	double membrane_energy_density;
	double compression_energy_density;
	double bending_energy_density;
} plume_sim_face_field;

/// Fills out[f] for every face of the mesh the simulator was created from (face_count
/// entries), at the current positions. PLUME_ERROR_MEMORY when scratch cannot be allocated.
plume_status plume_sim_face_fields(const plume_sim *sim, plume_sim_face_field *out, plume_error *err);

/// The vane's shape at the current state (plume_sim_vane_shape_measure); the vane is the
/// faces of material 0.
typedef struct plume_sim_vane_shape {
	/// Smallest in-plane principal stretch over the vane faces: sqrt of the smallest
	/// eigenvalue of C = F^T F against the reference. 1 unstretched, below 1 compressed.
	/// NaN without vane faces.
	double min_principal_stretch;
	/// Largest distance of a vane vertex from the rest vane's plane moved rigidly with the
	/// base group, m. The plane passes through the rest vane's area centroid, normal to
	/// its summed face normals; the motion maps the base group's rest frame (its centroid,
	/// its vertex farthest from the centroid, the vertex farthest off that line) onto the
	/// same frame now. NaN without vane faces, or when the group is unknown or has fewer
	/// than three non-collinear vertices.
	double max_out_of_plane;
} plume_sim_vane_shape;
plume_sim_vane_shape plume_sim_vane_shape_measure(const plume_sim *sim, const char *base_group);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_SIM_H

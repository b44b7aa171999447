// plume lab: the virtual feather laboratory of Jouve's thesis (chapters 3-5,
// appendices A.3 and C.1; paper sections 4, 6 and 8.1).
//
// A sample is a rectangle [0, W] x [0, H] in the reference plane with its barbs
// at an angle theta to the pulling axis y (0: longitudinal, pi/2: transverse,
// pi/4: tilted). The traction scenario (thesis eq. 4.2) clamps the bottom edge,
// moves the top edge by d along y, leaves the sides free and solves a sequence
// of static problems. It measures the strain eps = ((1 + d/H)^2 - 1)/2 and the
// stress sigma = H f / (b W (H + d)) (thesis section 3.3), f the force on the
// moving clamp, and fits a slope through the origin.
//
// Two material models: the macroscale orthotropic membrane (thesis eq. 4.1),
// with or without the barbs' inextensibility constraint, and the mesoscale
// model (thesis 5.2): bands of stiff (E_B, the barbs) and soft (E_b, the
// barbules) isotropic material with zero Poisson ratio, period T, barb
// fraction Phi_B = w_B / T. The calibration (thesis 5.2-5.3) goes from
// measured slopes to the mesoscale moduli and from the mesoscale model to the
// macroscale moduli E_vv, E_ww, E_vw.
#ifndef PLUME_LAB_H
#define PLUME_LAB_H

#include "plume/core.h"
#include "plume/mesh.h"
#include "plume/sim.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

// ---------------------------------------------------------------------------
// Analytic references (thesis 5.2 and appendix C.1). Strains are the measured
// Green-Lagrange strain eps = ((1 + d/H)^2 - 1)/2; stresses are in Pa.

/// Longitudinal modulus of the mesoscale model (thesis eq. 5.2): Phi_B E_B + (1 - Phi_B) E_b, Pa.
double plume_lab_longitudinal_modulus(double barb_fraction, double E_B, double E_b);

/// Transverse stress with rigid barbs at measured strain eps (thesis eq. 5.4), Pa.
double plume_lab_transverse_stress_rigid(double barb_fraction, double E_b, double strain);

/// Slope of eq. 5.4 over [0, strain_max] (thesis eq. 5.5, the continuous least squares of eq. C.7), Pa.
double plume_lab_transverse_slope_rigid(double barb_fraction, double E_b, double strain_max);

/// Transverse stress with deformable barb bands (appendix C.1): solves eqs. C.2-C.3 for the
/// band stretches by Newton's method and returns eq. C.6 with the barbule stretch, Pa.
double plume_lab_transverse_stress_stiff(double barb_fraction, double E_B, double E_b, double strain);

/// Inverts eqs. 5.3 and 5.5: the mesoscale moduli from the slopes measured in the longitudinal
/// and transverse scenarios (the transverse one over [0, transverse_strain_max]).
/// Fails (PLUME_ERROR_SPEC) when Phi_B is outside (0, 1), a slope or strain is not positive, or
/// the slopes give a non-positive E_B.
plume_status plume_lab_mesoscale_moduli(double barb_fraction, double slope_longitudinal, double slope_transverse,
                                        double transverse_strain_max, double *E_B, double *E_b, plume_error *err);

/// Slope of a stress-strain curve sampled at evenly spaced strains strain[i] = i strain_max / (count - 1)
/// (strain[0] = 0): the least-squares line through the origin (reading notes), with the samples
/// weighted by the composite Simpson rule (trapezoid when count - 1 is odd) so that the discrete
/// fit is the continuous least squares of thesis eq. C.7, whose value eq. 5.5 gives in closed form.
/// count >= 2.
double plume_lab_slope(const double *strain, const double *stress, int count);

/// Measured strain and stress of the traction test (thesis section 3.3).
double plume_lab_measured_strain(double height, double displacement);
double plume_lab_measured_stress(double width, double height, double thickness, double displacement, double force);
/// The clamp displacement d that gives measured strain eps: H (sqrt(1 + 2 eps) - 1).
double plume_lab_displacement_for_strain(double height, double strain);

// ---------------------------------------------------------------------------
// Samples

typedef enum plume_sample_mesh_kind {
	/// Every triangle has an edge along the barbs (thesis Figure 4.6b, paper section 6).
	PLUME_SAMPLE_ALIGNED = 0,
	/// Delaunay triangulation (Qhull) of jittered random points (thesis Figure 4.6a).
	PLUME_SAMPLE_UNALIGNED = 1,
} plume_sample_mesh_kind;

/// A rectangular vane sample (thesis section 3.2, Table 3.1).
typedef struct plume_sample_def {
	/// W, m, > 0. Default 1.0e-2 (Table 3.1: 2 to 17 mm).
	double width;
	/// H, m, > 0. Default 1.3e-2 (aspect ratio H/W = 1.3, thesis 5.3).
	double height;
	/// b, m, > 0. Default 1.2e-4 (Table 3.1: 60 to 155 um).
	double thickness;
	/// theta: angle between the barbs and the pulling axis y, radians, in [0, pi). Default pi/4 (tilted).
	double barb_angle;
	/// Default PLUME_SAMPLE_ALIGNED.
	plume_sample_mesh_kind mesh;
	/// Target number of triangles, >= 2. Default 2000. Band samples may get more (every band is resolved).
	int element_count;
	/// Seed of the unaligned mesh's random points. Default 1.
	uint64_t seed;
	/// PLUME_DEF_COOKIE, set by plume_sample_default_def; do not change.
	uint32_t cookie;
} plume_sample_def;

plume_sample_def plume_sample_default_def(void);

/// Mesoscale bands (thesis 5.2, Figure 5.2): strips parallel to the barbs.
typedef struct plume_band_def {
	/// T: distance between barb centres, m, > 0. Default 4e-4 (25 barbs across a 1 cm sample).
	double period;
	/// Phi_B = w_B / T, in (0, 1). Default 0.14 (thesis 5.2).
	double barb_fraction;
	/// Shift of the band pattern across the barbs, in periods, [0, 1): barb bands are centred at
	/// (k + 1/2 + phase) T from the sample's lowest corner. Where a sample holds few barbs its
	/// tilted slope depends on where the bands meet its corners. Default 0.
	double phase;
	/// Element rows across each barb band, >= 1. Default 1.
	int barb_divisions;
	/// Element rows across each barbule band, >= 1. Default 3.
	int barbule_divisions;
	/// PLUME_DEF_COOKIE, set by plume_band_default_def; do not change.
	uint32_t cookie;
} plume_band_def;

plume_band_def plume_band_default_def(void);

/// Face materials of band samples: index 0 the barbules (soft), 1 the barbs (stiff).
enum { PLUME_BAND_BARBULE = 0, PLUME_BAND_BARB = 1 };

/// Builds the sample mesh: reference = rest = the rectangle, vertex groups "bottom" (y = 0) and
/// "top" (y = H), per-face barb_angle = pi/2 - theta (mod pi, from +x), barb_edge marks and the
/// barb edge list on aligned meshes. bands may be NULL (homogeneous, material 0); band samples
/// must be aligned. Errors (PLUME_ERROR_SPEC) name the field: non-positive sizes, too few
/// elements, a band narrower than the mesh can hold.
plume_status plume_sample_mesh(const plume_sample_def *sample, const plume_band_def *bands, plume_mesh **out,
                               plume_error *err);

/// Bytes a lab test holds per element of its sample mesh (mesh, quadratic dofs, sparse Hessian and its
/// factorization), with a margin: measured 8.2 KB an element from 2000 to 8000 and 9.0 KB from 8000 to
/// 32000 mesoscale (quadratic) elements (peak RSS of `plume lab traction`, docs/cli.md).
#define PLUME_LAB_BYTES_PER_ELEMENT 16384.0
/// What a lab run holds besides its meshes: the program, the plots.
#define PLUME_LAB_BYTES_FIXED (32.0 * 1024 * 1024)

/// Bytes a traction test on sample takes, counted before the work: PLUME_LAB_BYTES_FIXED plus
/// element_count x PLUME_LAB_BYTES_PER_ELEMENT (the tests run one after another: a run's
/// largest mesh sets its peak).
double plume_sample_estimate_bytes(double element_count);

/// The checks plume_sample_mesh makes before meshing.
plume_status plume_sample_validate(const plume_sample_def *sample, const plume_band_def *bands, plume_error *err);

// ---------------------------------------------------------------------------
// Lab materials

typedef enum plume_lab_model {
	/// Orthotropic membrane (thesis eq. 4.1).
	PLUME_LAB_MACROSCALE = 0,
	/// Stiff and soft isotropic bands, zero Poisson ratio (thesis 5.2), solved on quadratic
	/// triangles (six nodes), which bend the barb bands without locking.
	PLUME_LAB_MESOSCALE = 1,
} plume_lab_model;

typedef struct plume_lab_material {
	plume_lab_model model;
	/// Macroscale moduli, Pa, > 0. Defaults: thesis Table 5.2, E_vv = 3.60e8, E_ww = 4.80e4,
	/// E_vw = E_ww = 4.80e4 (the locking and conditioning studies use it; the calibrated value,
	/// 1.99e4 Pa with the barb constraint under the calibration protocol, is in docs/lab.md).
	double E_vv;
	double E_ww;
	double E_vw;
	/// Inextensible barbs (paper section 6): needs an aligned mesh. Default false.
	bool barb_constraint;
	/// Macroscale model only: solve it on quadratic (six-node) triangles instead of the
	/// simulator's linear ones. Without the barb constraint the tilted test on linear
	/// triangles converges slowly and unevenly (E_vv / E_ww = 7500); quadratic ones converge
	/// to 0.5 % at a few hundred elements (docs/lab.md). Not with barb_constraint. The
	/// mesoscale model is always quadratic. Default false (the simulator's elements).
	bool quadratic;
	/// Mesoscale moduli, Pa, > 0. Defaults: thesis Table 5.1 at Phi_B = 0.14, E_B = 2.57e9, E_b = 3.92e4.
	double E_B;
	double E_b;
	/// Band geometry of the mesoscale model.
	plume_band_def bands;
	/// Kikuuwe's compression coefficient kappa, Pa, >= 0, in both models (thesis eq. 6.6).
	/// Default: the simulator's vane, plume_material_vane().compression_coefficient (4.2e11 Pa,
	/// thesis Table 6.1's 5.04e7 N/m over the vane's thickness, 1.2e-4 m). The lab's samples
	/// are planar: without out-of-plane buckling, compressed St-Venant-Kirchhoff elements
	/// collapse and invert (thesis Figure 6.7), the solution localises on the mesh and Newton
	/// stalls; 0 gives that pure model.
	double compression_coefficient;
} plume_lab_material;

plume_lab_material plume_lab_material_default(plume_lab_model model);

// ---------------------------------------------------------------------------
// Traction (thesis section 4.2, eq. 4.2)

typedef struct plume_traction_def {
	/// eps_max: largest measured strain, > 0. Default 0.4 (thesis 3.2: transverse and tilted).
	double strain_max;
	/// Number of load steps, >= 1: strains i eps_max / steps, i = 1..steps. Default 20.
	int steps;
	/// Newton settings of each static solve (a step that fails is retried in 2, 4 ... load
	/// increments, solver.max_substep_halvings times). Default plume_sim_default_def().solver.
	plume_solver_def solver;
	/// false: keep non-converged steps (the conditioning study) instead of failing. Default true.
	bool require_convergence;
	/// Compress instead of pulling: the top clamp moves down to strains -i eps_max / steps
	/// (thesis A.3). Default false.
	bool compression;
	/// Accept a step whose Newton solve stalled (round-off on stiff problems) when its final
	/// gradient norm is at most this fraction of the clamp force; 0 never. Default 0.
	double accept_residual;
	/// PLUME_DEF_COOKIE, set by plume_traction_default_def; do not change.
	uint32_t cookie;
} plume_traction_def;

plume_traction_def plume_traction_default_def(void);

typedef struct plume_traction_result {
	/// steps + 1 samples, the first at rest: measured strain, stress (Pa), clamp displacement (m).
	int count;
	double *strain;
	double *stress;
	double *displacement;
	/// Per sample: Newton iterations, convergence of its solve (0 and true at rest) and the
	/// final free gradient norm over the clamp force.
	int *iterations;
	bool *converged;
	double *residual;
	/// plume_lab_slope of the curve, Pa.
	double slope;
	/// Static solves (including retried halves) and Newton iterations in all.
	int solve_count;
	int newton_iterations;
	/// Final deformed positions (vertex_count).
	int vertex_count;
	plume_vec3 *positions;
	/// Relative width change at mid-height in the last step, (w' - W) / W.
	double lateral_strain;
} plume_traction_result;

/// Runs the traction test of a material on a sample. Errors: PLUME_ERROR_SPEC for a bad
/// definition (the field is named), PLUME_ERROR_NUMERIC when a step fails to converge and
/// def->require_convergence is set. The result is filled only on success; free it with
/// plume_traction_result_free.
plume_status plume_lab_traction(const plume_lab_material *material, const plume_sample_def *sample,
                                const plume_traction_def *def, plume_traction_result *result, plume_error *err);

void plume_traction_result_free(plume_traction_result *result);

/// Mean slope, Pa, of the traction test over phase_count >= 1 evenly spaced band phases
/// (bands.phase = k / phase_count): the expected slope of a sample cut at a random place in
/// the vane. A mesoscale sample a few barbs wide has a slope that depends on where the bands
/// meet its corners (+-6 % in the tilted test at 10 barbs). The macroscale model has no
/// bands and runs once. solve_count, if not NULL, receives the static solves of all runs.
plume_status plume_lab_mean_slope(const plume_lab_material *material, const plume_sample_def *sample,
                                  const plume_traction_def *def, int phase_count, double *slope, int *solve_count,
                                  plume_error *err);

/// Checks a material and a sample; messages name the field ("material.E_vw is -1, allowed > 0").
plume_status plume_lab_validate(const plume_lab_material *material, const plume_sample_def *sample,
                                const plume_traction_def *traction, plume_error *err);

/// A lab file (docs/lab.md): { "sample": {...}, "material": {...}, "traction": {...} }.
typedef struct plume_lab_spec {
	plume_lab_material material;
	plume_sample_def sample;
	plume_traction_def traction;
} plume_lab_spec;

/// Reads and checks a lab file. Errors name the file and the JSON path
/// ("lab.json: $.material.E_b is -1 Pa, allowed > 0"); nothing is run.
plume_status plume_lab_spec_load(const char *path, plume_lab_spec *spec, plume_error *err);

// ---------------------------------------------------------------------------
// Calibration (thesis 5.2-5.3)

/// The calibration's protocol (docs/lab.md, "The protocol"): what is fitted where. The
/// defaults are the protocol docs/lab.md justifies with measurements; a result says whether
/// it followed them (plume_calibration_protocol_name).
typedef struct plume_calibration_def {
	/// The mesoscale model: E_B, E_b, Phi_B and the band period. Its compression_coefficient
	/// (Kikuuwe's kappa) applies to both lab models. Default: Table 5.1 at Phi_B = 0.14 with
	/// kappa = 0, the thesis's chapter-5 materials (the term is chapter 6's, for whole
	/// feathers; plume_lab_material_default gives the simulator's kappa instead).
	plume_lab_material mesoscale;
	/// Sample of the tilted test: width (default 4e-3 m, N = W / T = 10 barbs), thickness and
	/// element_count (mesoscale mesh, default 4000); the height is aspect_ratio * width.
	plume_sample_def sample;
	/// a = H / W of the tilted test, > 0. Default 1.3 (thesis 5.3).
	double aspect_ratio;
	/// eps_max of the longitudinal test (E_vv). Default 0.01 (thesis 3.2).
	double longitudinal_strain_max;
	/// eps_max of the transverse test (E_ww). Default 0.4 (thesis 3.2; eq. 5.5 and Table 5.2).
	double transverse_strain_max;
	/// eps_max of the tilted test, the fit of E_vw, in (0, 10]. Default 0.1: the chapter-5
	/// model has no solution past eps ~ 0.2 (barbule cells collapse), and at 0.1 the tilted
	/// slope responds to E_vw with a relative sensitivity of about 0.8 (0.3 at 0.4).
	double tilted_strain_max;
	/// Load steps of every test. Default 10.
	int steps;
	/// Fit E_vw with the barb constraint (the simulator's vane model). Default true.
	bool barb_constraint;
	/// Without the barb constraint, solve the macroscale tilted test on quadratic triangles
	/// (converged, docs/lab.md) instead of the simulator's linear ones. Default true.
	bool macroscale_quadratic;
	/// Relative width of the final bisection bracket on E_vw. Default 1e-4.
	double tolerance;
	/// Target number of triangles of the macroscale tilted sample. Default 2000.
	int macroscale_elements;
	/// Band phases (k / phase_count, k = 0 .. phase_count - 1) the mesoscale tilted slope is
	/// averaged over, [1, 64]. Default 4.
	int phase_count;
	/// Estimate each modulus's spread (band phase, sample width, mesh resolution) and the
	/// sensitivity of the tilted slope to E_vw: eight more traction tests. Default true.
	bool uncertainty;
	/// Called after each traction test (a mesoscale mean counts one per phase); total is an
	/// estimate while E_vw is searched. Default NULL (none).
	plume_progress_fn *progress;
	void *progress_user;
	/// Keep the stress-strain curves matched in the result (curve_*); free them with
	/// plume_calibration_result_free. Default false.
	bool keep_curves;
	/// PLUME_DEF_COOKIE, set by plume_calibration_default_def; do not change.
	uint32_t cookie;
} plume_calibration_def;

plume_calibration_def plume_calibration_default_def(void);

/// Bytes a calibration takes, counted before the work (plume_sample_estimate_bytes): its largest mesh
/// is the mesoscale sample or the macroscale one, twice that for the spreads (finer and wider meshes)
/// when def->uncertainty.
double plume_calibration_estimate_bytes(const plume_calibration_def *def);

/// "chapter-5" when def's protocol fields (strain ranges, kappa, barb constraint, element
/// kind, sample width and period, aspect ratio, phases, meshes) are the defaults, else "custom".
const char *plume_calibration_protocol_name(const plume_calibration_def *def);

/// How far a calibrated modulus moves with the choices a calibration has to make, Pa, each
/// >= 0 (docs/lab.md, "Uncertainty"). E_vw's are first order: the mesoscale tilted slope's
/// change carried to E_vw through the sensitivity of the macroscale slope.
typedef struct plume_modulus_spread {
	/// Half the range over the band phases (the tilted test: the calibration's phase_count
	/// phases; the straight ones: phases 0 and 1/2).
	double phase;
	/// Change when the sample is twice as wide and high (twice the barbs across, same aspect
	/// ratio, twice the elements; band phase 0 against band phase 0).
	double width;
	/// Change when the meshes are twice as fine (both models; band phase 0).
	double mesh;
	/// sqrt(phase^2 + width^2 + mesh^2).
	double total;
} plume_modulus_spread;

typedef struct plume_calibration_result {
	/// Macroscale moduli, Pa.
	double E_vv;
	double E_ww;
	double E_vw;
	/// Slopes of the mesoscale model, Pa: longitudinal, transverse, tilted (mean over the phases).
	double slope_longitudinal;
	double slope_transverse;
	double slope_tilted;
	/// Slope of the macroscale model with the fitted E_vw on the tilted test, Pa.
	double slope_tilted_macroscale;
	/// With def->uncertainty: the spreads, and d ln(slope) / d ln(E_vw) of the macroscale
	/// tilted test at the fitted E_vw (central difference over E_vw +- 5 %). Zero otherwise.
	plume_modulus_spread spread_vv;
	plume_modulus_spread spread_ww;
	plume_modulus_spread spread_vw;
	double sensitivity;
	/// Traction tests run (mesoscale and macroscale) and static solves in all.
	int traction_count;
	int solve_count;
	/// Bisection iterations on E_vw.
	int bisection_iterations;
	/// With def->keep_curves: the curves matched, curve_samples = steps + 1 samples each (the
	/// first at rest), strain and stress (Pa): [0] mesoscale longitudinal, [1] mesoscale
	/// transverse, [2] mesoscale tilted (the stress averaged over the band phases), [3] macroscale
	/// tilted at the fitted E_vw. NULL and 0 otherwise.
	int curve_samples;
	double *curve_strain[4];
	double *curve_stress[4];
} plume_calibration_result;

plume_status plume_lab_calibrate(const plume_calibration_def *def, plume_calibration_result *result, plume_error *err);

/// Frees the curves of a calibration result (a no-op without them) and zeroes them.
void plume_calibration_result_free(plume_calibration_result *result);

// ---------------------------------------------------------------------------
// Bending under refinement: cantilever strips on four triangulation families

typedef enum plume_strip_family {
	/// Square cells split by one diagonal (right-isosceles triangles).
	PLUME_STRIP_RIGHT = 0,
	/// Rows shifted by half an edge: equilateral triangles, one edge family along the strip.
	PLUME_STRIP_EQUILATERAL = 1,
	/// Cells 4 times longer than wide, split by one diagonal.
	PLUME_STRIP_ELONGATED = 2,
	/// Square rows sheared so that one edge family runs at 60 degrees to the strip, as the barb
	/// guides of a barb-aligned mesh do.
	PLUME_STRIP_SLANTED = 3,
} plume_strip_family;

enum { PLUME_STRIP_FAMILY_COUNT = 4 };

/// "right-isosceles", "equilateral", "elongated-4to1", "slanted-60".
const char *plume_strip_family_name(plume_strip_family family);

/// A flat strip [-c, length] x [0, width] (m), c = clamp_cells cell lengths, meshed by the
/// family with `across` (>= 1) rows of cells across the width, every face's barb direction
/// barb_angle (radians from +x), material 0. The lines x = -c, 0 and length are straight
/// vertex lines (the nearest lattice vertex of each row moved onto them, by at most half a
/// cell). Groups: "clamp" (x <= 0), "tip" (x = length), "tip_corners" (its two ends) and
/// "tip_inner" (the rest).
plume_status plume_lab_strip_mesh(plume_strip_family family, double length, double width, int clamp_cells, int across,
                                  double barb_angle, plume_mesh **out, plume_error *err);

typedef struct plume_cantilever_def {
	plume_strip_family family;
	/// Rows of cells across the width. Default 8.
	int across;
	/// Free length and width, m. Default 0.1 and 0.01.
	double length;
	double width;
	/// Barb direction, radians from the strip axis. Default 0 (bending the strip bends the barbs).
	double barb_angle;
	/// Bending moduli, N m (plume_material). Default 1e-3 and 1e-3 (isotropic).
	double bending_along;
	double bending_across;
	plume_bending_model model;
} plume_cantilever_def;

plume_cantilever_def plume_cantilever_default_def(void);

/// The strip clamped at x <= 0, a tip load P across the width at x = length (shared as a
/// line load: half shares at the corners), sized so that the deflection is 1e-4 of the length
/// (linear range), no gravity, a membrane so stiff that only bending deforms. Returns the
/// tip deflection over Euler-Bernoulli's P L^3 / (3 D W), D = D(beta) of the strip axis
/// (thesis eq. 6.4; exact for the Poisson-free plate strip of plume's bending tensor when
/// the barbs are along or across the strip).
plume_status plume_lab_cantilever(const plume_cantilever_def *def, double *ratio, plume_error *err);

// ---------------------------------------------------------------------------
// Studies (docs/lab.md)

typedef enum plume_study_kind {
	/// Relative error of the stress at 5% strain in the tilted test against the number of
	/// elements, aligned and unaligned meshes, alpha = 1, 1e2, 1e4 (thesis Figures 4.4, 4.7; paper Figure 5).
	PLUME_STUDY_LOCKING = 0,
	/// Tilted stress-strain curves, unconstrained with 50 and 100 Newton iterations and
	/// constrained with at most 50; oscillation: the total variation of the discrete slope minus its
	/// net change (zero for a monotone slope) (paper Figure 6).
	PLUME_STUDY_CONDITIONING = 1,
	/// Mesoscale and calibrated macroscale slopes over E_b for barb angles 0 to 90 degrees,
	/// Phi_B = 0.12, 0.14, 0.16 (thesis Figure 5.11, paper Figure 11).
	PLUME_STUDY_ANGLES = 2,
	/// Mesoscale longitudinal compression for several N = W / T (thesis A.3, Figures A.5-A.6).
	PLUME_STUDY_SIZE = 3,
	/// Cantilever strips on the four triangulation families under refinement, barbs along
	/// and across the strip, both bending models: delta / delta_EB (issue 13, docs/lab.md).
	PLUME_STUDY_BENDING = 4,
} plume_study_kind;

typedef struct plume_study_def {
	plume_study_kind kind;
	/// Multiplies every element count, > 0. Default 1.
	double scale;
	/// Called after each run of the study (a traction test or a calibration). Default NULL (none).
	plume_progress_fn *progress;
	void *progress_user;
	/// PLUME_DEF_COOKIE, set by plume_study_default_def; do not change.
	uint32_t cookie;
} plume_study_def;

plume_study_def plume_study_default_def(plume_study_kind kind);

/// Bytes a study takes, counted before the work (plume_sample_estimate_bytes): its largest mesh,
/// 16000 elements (the locking study's reference and the size study's widest sample) times def->scale.
double plume_study_estimate_bytes(const plume_study_def *def);

/// "locking", "conditioning", "angles", "size" or "bending".
bool plume_study_kind_from_name(const char *name, plume_study_kind *kind);
const char *plume_study_name(plume_study_kind kind);

/// Runs a study and writes its table (CSV) and plot (PNG, SVG) to the given paths; summary
/// receives a one-line JSON digest (may be NULL).
plume_status plume_lab_study(const plume_study_def *def, const char *csv_path, const char *png_path,
                             const char *svg_path, char *summary, size_t summary_size, plume_error *err);

// ---------------------------------------------------------------------------
// Outputs: plots (PLplot) and CSV tables

typedef struct plume_plot_series {
	const char *label;
	const double *x;
	const double *y;
	int count;
	/// Markers at the samples instead of a line.
	bool points;
	/// Dashed line.
	bool dashed;
} plume_plot_series;

/// Corner of the plot the legend sits in, inside the axes.
typedef enum plume_plot_legend {
	PLUME_LEGEND_TOP_LEFT = 0,
	PLUME_LEGEND_TOP_RIGHT,
	PLUME_LEGEND_BOTTOM_LEFT,
	PLUME_LEGEND_BOTTOM_RIGHT,
} plume_plot_legend;

typedef struct plume_plot {
	const char *title;
	/// Axis labels with their units, e.g. "strain #fie#fn" (PLplot escapes allowed).
	const char *x_label;
	const char *y_label;
	bool log_x;
	bool log_y;
	int series_count;
	const plume_plot_series *series;
	/// Where the legend goes: the corner the curves leave empty. Default (0) top left.
	plume_plot_legend legend;
	/// PNG size in pixels; 0 gives 960 x 720.
	int width;
	int height;
} plume_plot;

/// Draws a plot with PLplot as PNG (PLplot's "mem" raster driver, written by Cairo) and/or
/// SVG (the "svg" driver); either path may be NULL. Files appear whole or not at all.
/// PLplot keeps global state: do not plot from two threads at once. Errors:
/// PLUME_ERROR_UNSUPPORTED when this PLplot lacks a driver, PLUME_ERROR_IO on write failure.
plume_status plume_lab_plot(const plume_plot *plot, const char *png_path, const char *svg_path, plume_error *err);

/// Bytes plume_lab_format_number needs: "-1.2345678901234567e-308" and the terminator.
enum { PLUME_LAB_NUMBER_TEXT = 32 };

/// A number as the lab writes every number meant for reuse (CSV tables, traction.json,
/// calibration.json): the shortest text that strtod reads back as the same double, which
/// is the first of "%.15g", "%.16g" and "%.17g" that does ("0.1" and "359833710", never
/// "0.10000000000000001" or a rounded "3.59834e+08"), as in a sweep's results.csv.
/// Non-finite values as "%g" writes them. text holds size >= PLUME_LAB_NUMBER_TEXT bytes;
/// returns text.
const char *plume_lab_format_number(char *text, size_t size, double value);

/// Writes a CSV file: a header line (comma-separated names) and row_count rows of
/// column_count numbers (plume_lab_format_number), atomically.
plume_status plume_lab_write_csv(const char *path, const char *header, const double *const *columns, int column_count,
                                 int row_count, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_LAB_H

// The lab's numerical studies (docs/lab.md): locking (thesis 4.3, paper
// Figure 5), conditioning (paper Figure 6), the barb-angle validation sweep
// (thesis Figure 5.11, paper Figure 11) and the size effect (thesis A.3).
// Each writes a CSV table and a PLplot figure.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "plume/lab.h"

static const double PI = 3.14159265358979323846;

static const char *const study_names[] = {"locking", "conditioning", "angles", "size", "bending"};

plume_study_def plume_study_default_def(plume_study_kind kind)
{
	return (plume_study_def){.kind = kind, .scale = 1.0, .cookie = PLUME_DEF_COOKIE};
}

bool plume_study_kind_from_name(const char *name, plume_study_kind *kind)
{
	for (int k = 0; k < 5; ++k)
		if (strcmp(name, study_names[k]) == 0) {
			*kind = (plume_study_kind)k;
			return true;
		}
	return false;
}

const char *plume_study_name(plume_study_kind kind) { return kind >= 0 && kind < 5 ? study_names[kind] : "unknown"; }

static int scaled(int count, double scale)
{
	int n = (int)lround(count * scale);
	return n < 8 ? 8 : n;
}

double plume_study_estimate_bytes(const plume_study_def *def)
{
	return plume_sample_estimate_bytes(16000.0 * def->scale);
}

// A growing table of rows, written column by column.
enum { MAX_COLUMNS = 8 };
typedef struct table {
	double *columns[MAX_COLUMNS];
	int column_count, row_count, capacity;
} table;

static int table_add(table *t, const double *row)
{
	if (t->row_count == t->capacity) {
		int capacity = t->capacity ? 2 * t->capacity : 64;
		for (int c = 0; c < t->column_count; ++c) {
			double *grown = plume_realloc(t->columns[c], sizeof(double) * (size_t)capacity);
			if (grown == NULL)
				return -1;
			t->columns[c] = grown;
		}
		t->capacity = capacity;
	}
	for (int c = 0; c < t->column_count; ++c)
		t->columns[c][t->row_count] = row[c];
	t->row_count++;
	return 0;
}

static void table_free(table *t)
{
	for (int c = 0; c < t->column_count; ++c)
		plume_free(t->columns[c]);
}

// One run of a study finished: done of total (def->progress, when set).
static void study_progress(const plume_study_def *def, int *done, int total)
{
	*done += 1;
	if (def->progress != NULL)
		def->progress(def->progress_user, *done, total);
}

static plume_status memory_error(plume_error *err) { return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory"); }

// ---------------------------------------------------------------------------
// Locking

static plume_status stress_at(const plume_lab_material *material, const plume_sample_def *sample, double strain,
                              int steps, double *stress, plume_error *err)
{
	plume_traction_def def = plume_traction_default_def();
	def.strain_max = strain;
	def.steps = steps;
	def.accept_residual = 1e-6;
	// Locked meshes need more Newton iterations than the default 50.
	def.solver.max_iterations = 200;
	// A locked mesh can be too ill-conditioned for Newton: keep going, and report the run as
	// not converged (NaN) rather than plot a stress that is not an equilibrium.
	def.require_convergence = false;
	plume_traction_result r;
	plume_status status = plume_lab_traction(material, sample, &def, &r, err);
	if (status != PLUME_OK)
		return status;
	bool converged = true;
	for (int i = 1; i < r.count; ++i)
		converged &= r.converged[i] || r.residual[i] <= def.accept_residual;
	*stress = converged ? r.stress[r.count - 1] : NAN;
	plume_traction_result_free(&r);
	return PLUME_OK;
}

static plume_status study_locking(const plume_study_def *def, const char *csv, const char *png, const char *svg,
                                  char *summary, size_t summary_size, plume_error *err)
{
	static const double alphas[3] = {1.0, 1e2, 1e4};
	static const int counts[5] = {250, 500, 1000, 2000, 4000};
	// Rows: alpha, mesh (0 aligned, 1 unaligned, 2 aligned + barb constraint), elements, stress, relative error.
	table t = {.column_count = 5};
	plume_status status = PLUME_OK;
	plume_sample_def sample = plume_sample_default_def(); // 10 x 13 mm, barbs at 45 degrees
	double error_ratio = 0.0;
	int unconverged = 0;
	int done = 0, total = 3 * (1 + 2 * 5) + 5; // a reference and two meshes per alpha; the constraint at 1e4
	for (int a = 0; a < 3 && status == PLUME_OK; ++a) {
		plume_lab_material material = plume_lab_material_default(PLUME_LAB_MACROSCALE);
		material.E_vv = alphas[a] * material.E_ww;
		// Reference: a fine aligned mesh (the thesis used 128e3 elements).
		plume_sample_def fine = sample;
		fine.element_count = scaled(16000, def->scale);
		double reference;
		status = stress_at(&material, &fine, 0.05, 5, &reference, err);
		study_progress(def, &done, total);
		if (status == PLUME_OK && isnan(reference))
			status = plume_error_set(err, PLUME_ERROR_NUMERIC,
			                         "locking study: the reference (%d aligned elements, alpha %g) did not converge",
			                         fine.element_count, alphas[a]);
		for (int mesh = 0; mesh < 3 && status == PLUME_OK; ++mesh) {
			if (mesh == 2 && a != 2)
				continue; // the constraint is the alpha -> infinity limit: compare at 1e4 only
			for (int k = 0; k < 5 && status == PLUME_OK; ++k) {
				plume_sample_def s = sample;
				s.element_count = scaled(counts[k], def->scale);
				s.mesh = mesh == 1 ? PLUME_SAMPLE_UNALIGNED : PLUME_SAMPLE_ALIGNED;
				plume_lab_material m = material;
				m.barb_constraint = mesh == 2;
				double stress;
				status = stress_at(&m, &s, 0.05, 5, &stress, err);
				study_progress(def, &done, total);
				double row[5] = {alphas[a], mesh, s.element_count, stress, fabs(stress - reference) / fabs(reference)};
				unconverged += isnan(stress);
				if (status == PLUME_OK && table_add(&t, row) != 0)
					status = memory_error(err);
			}
		}
	}
	// The paper's point: at alpha = 1e4 and 1000 elements, the unaligned error over the aligned one.
	double aligned_error = NAN, unaligned_error = NAN;
	for (int r = 0; r < t.row_count; ++r)
		if (t.columns[0][r] == 1e4 && t.columns[2][r] == scaled(1000, def->scale)) {
			if (t.columns[1][r] == 0)
				aligned_error = t.columns[4][r];
			else if (t.columns[1][r] == 1)
				unaligned_error = t.columns[4][r];
		}
	error_ratio = unaligned_error / aligned_error;
	if (status == PLUME_OK) {
		// The plot: error against elements, one series per (alpha, mesh).
		plume_plot_series series[7];
		char labels[7][48];
		double *xs[7] = {0}, *ys[7] = {0};
		int n = 0;
		for (int a = 0; a < 3; ++a)
			for (int mesh = 0; mesh < 3; ++mesh) {
				if (mesh == 2 && a != 2)
					continue;
				xs[n] = plume_alloc(sizeof(double) * 5);
				ys[n] = plume_alloc(sizeof(double) * 5);
				if (xs[n] == NULL || ys[n] == NULL) {
					status = memory_error(err);
					++n;
					break;
				}
				int count = 0;
				for (int r = 0; r < t.row_count; ++r)
					if (t.columns[0][r] == alphas[a] && t.columns[1][r] == mesh && isfinite(t.columns[4][r])) {
						xs[n][count] = t.columns[2][r];
						ys[n][count] = fmax(t.columns[4][r], 1e-12);
						++count;
					}
				snprintf(labels[n], sizeof labels[n], "%s, #ga = 10#u%d#d",
				         mesh == 0   ? "aligned"
				         : mesh == 1 ? "unaligned"
				                     : "aligned + constraint",
				         2 * a);
				series[n] = (plume_plot_series){labels[n], xs[n], ys[n], count, false, mesh == 1};
				++n;
			}
		if (status == PLUME_OK) {
			plume_plot plot = {.title = "Locking: tilted test, stress at 5% strain",
			                   .x_label = "number of elements",
			                   .y_label = "relative error of #fi#gs#fn",
			                   .log_x = true,
			                   .log_y = true,
			                   .series_count = n,
			                   .series = series};
			status = plume_lab_plot(&plot, png, svg, err);
		}
		for (int i = 0; i < n; ++i) {
			plume_free(xs[i]);
			plume_free(ys[i]);
		}
	}
	if (status == PLUME_OK)
		status = plume_lab_write_csv(csv, "alpha,mesh,elements,stress_pa,relative_error",
		                             (const double *const *)t.columns, 5, t.row_count, err);
	if (status == PLUME_OK && summary != NULL) {
		// The ratio at the scaled count of the paper's 1000 elements; null if a run there failed.
		char ratio[32] = "null";
		if (isfinite(error_ratio))
			snprintf(ratio, sizeof ratio, "%.4g", error_ratio);
		snprintf(summary, summary_size,
		         "{\"study\": \"locking\", \"rows\": %d, \"unconverged_runs\": %d, "
		         "\"unaligned_over_aligned_error_alpha_1e4\": {\"elements\": %d, \"ratio\": %s}}",
		         t.row_count, unconverged, scaled(1000, def->scale), ratio);
	}
	table_free(&t);
	return status;
}

// ---------------------------------------------------------------------------
// Conditioning

// Oscillation of a stress-strain curve: the total variation of its discrete slope
// (sigma_{i+1} - sigma_i) / (eps_{i+1} - eps_i) minus the slope's net change, which is
// zero for any curve whose slope changes monotonically (the smooth stiffening of the tilted
// test) and counts every back-and-forth twice.
static double slope_oscillation(const double *strain, const double *stress, int count)
{
	double total = 0.0, previous = 0.0, first = 0.0;
	for (int i = 0; i + 1 < count; ++i) {
		double slope = (stress[i + 1] - stress[i]) / (strain[i + 1] - strain[i]);
		if (i > 0)
			total += fabs(slope - previous);
		else
			first = slope;
		previous = slope;
	}
	return total - fabs(previous - first);
}

static plume_status study_conditioning(const plume_study_def *def, const char *csv, const char *png, const char *svg,
                                       char *summary, size_t summary_size, plume_error *err)
{
	plume_sample_def sample = plume_sample_default_def();
	sample.element_count = scaled(2000, def->scale);
	plume_lab_material material = plume_lab_material_default(PLUME_LAB_MACROSCALE);
	material.E_vv = 1e4 * material.E_ww;
	const int iterations[3] = {50, 100, 50};
	plume_traction_result runs[3];
	memset(runs, 0, sizeof runs);
	plume_status status = PLUME_OK;
	double variation[3] = {0};
	int total_iterations[3] = {0}, failures[3] = {0};
	for (int k = 0; k < 3 && status == PLUME_OK; ++k) {
		plume_traction_def traction = plume_traction_default_def();
		traction.steps = 40;
		traction.solver.max_iterations = iterations[k];
		traction.solver.max_substep_halvings = 0; // each step gets exactly its iteration budget
		traction.require_convergence = false;
		plume_lab_material m = material;
		m.barb_constraint = k == 2;
		status = plume_lab_traction(&m, &sample, &traction, runs + k, err);
		study_progress(def, &(int){k}, 3);
		if (status == PLUME_OK) {
			variation[k] = slope_oscillation(runs[k].strain, runs[k].stress, runs[k].count);
			total_iterations[k] = runs[k].newton_iterations;
			for (int i = 1; i < runs[k].count; ++i)
				failures[k] += !runs[k].converged[i];
		}
	}
	if (status == PLUME_OK) {
		double *it[3];
		int count = runs[0].count;
		for (int k = 0; k < 3; ++k) {
			it[k] = plume_alloc(sizeof(double) * (size_t)count);
			if (it[k] != NULL)
				for (int i = 0; i < count; ++i)
					it[k][i] = runs[k].iterations[i];
		}
		if (it[0] == NULL || it[1] == NULL || it[2] == NULL)
			status = memory_error(err);
		if (status == PLUME_OK) {
			const double *columns[7] = {runs[0].strain, runs[0].stress, runs[1].stress, runs[2].stress,
			                            it[0],          it[1],          it[2]};
			status = plume_lab_write_csv(csv,
			                             "strain,stress_unconstrained_50_pa,stress_unconstrained_100_pa,"
			                             "stress_constrained_50_pa,iterations_unconstrained_50,"
			                             "iterations_unconstrained_100,iterations_constrained_50",
			                             columns, 7, count, err);
		}
		for (int k = 0; k < 3; ++k)
			plume_free(it[k]);
	}
	if (status == PLUME_OK) {
		plume_plot_series series[3] = {
		    {"unconstrained, 50 iterations", runs[0].strain, runs[0].stress, runs[0].count, false, false},
		    {"unconstrained, 100 iterations", runs[1].strain, runs[1].stress, runs[1].count, false, false},
		    {"constrained, at most 50", runs[2].strain, runs[2].stress, runs[2].count, false, true},
		};
		plume_plot plot = {.title = "Conditioning: tilted test, #ga = 10#u4#d",
		                   .x_label = "measured strain #fi#ge#fn",
		                   .y_label = "measured stress #fi#gs#fn [Pa]",
		                   .series_count = 3,
		                   .series = series};
		status = plume_lab_plot(&plot, png, svg, err);
	}
	if (status == PLUME_OK && summary != NULL)
		snprintf(summary, summary_size,
		         "{\"study\": \"conditioning\", \"slope_oscillation_pa\": {\"unconstrained_50\": %.6g, "
		         "\"unconstrained_100\": %.6g, \"constrained_50\": %.6g}, \"newton_iterations\": [%d, %d, %d], "
		         "\"unconverged_steps\": [%d, %d, %d]}",
		         variation[0], variation[1], variation[2], total_iterations[0], total_iterations[1],
		         total_iterations[2], failures[0], failures[1], failures[2]);
	for (int k = 0; k < 3; ++k)
		plume_traction_result_free(runs + k);
	return status;
}

// ---------------------------------------------------------------------------
// Barb angles

// The slope of a traction test, for the mesoscale model the mean over the calibration's
// band phases: the measure the calibration fitted E_vw to, so the models meet at 45 degrees.
static plume_status slope_at(const plume_lab_material *material, const plume_sample_def *sample, int steps,
                             double strain_max, int phase_count, double *slope, plume_error *err)
{
	plume_traction_def def = plume_traction_default_def();
	def.steps = steps;
	def.strain_max = strain_max;
	def.solver.tolerance = 1e-6;
	// Every step must converge: with Kikuuwe's term (below) they do, and an allowance for
	// stalled steps is what let the chapter-5 model's collapse at 15 degrees through in the
	// reduced runs (free forces 9e-5 of the clamp force at 2000 triangles).
	def.accept_residual = 0.0;
	return plume_lab_mean_slope(material, sample, &def, phase_count, slope, NULL, err);
}

static plume_status study_angles(const plume_study_def *def, const char *csv, const char *png, const char *svg,
                                 char *summary, size_t summary_size, plume_error *err)
{
	// Thesis Table 5.1.
	static const double phis[3] = {0.12, 0.14, 0.16}, E_b[3] = {4.04e4, 3.92e4, 3.79e4},
	                    E_B[3] = {2.8e9, 2.57e9, 2.25e9};
	enum { ANGLES = 7 };
	double angle_deg[ANGLES], meso[3][ANGLES], macro[3][ANGLES], E_vw[3];
	plume_status status = PLUME_OK;
	double worst = 0.0, worst_phi = 0.0, worst_angle = 0.0, strain_max = 0.0;
	int done = 0, total = 3 * (1 + 2 * ANGLES); // a calibration and two slopes per angle for each Phi_B
	for (int p = 0; p < 3 && status == PLUME_OK; ++p) {
		plume_calibration_def cal = plume_calibration_default_def();
		cal.mesoscale.bands.barb_fraction = phis[p];
		cal.mesoscale.E_b = E_b[p];
		cal.mesoscale.E_B = E_B[p];
		// The sweep pulls along the barbs too: the macroscale model keeps E_vv (no constraint).
		cal.barb_constraint = false;
		// Kikuuwe's term (thesis eq. 6.6, the simulator's coefficient) in both models at every
		// angle, the calibration included (docs/lab.md, Barb angles). Without it the chapter-5
		// St-Venant-Kirchhoff barbules by the free sides are squeezed past their limit point (a
		// principal stretch below 1/sqrt(3)): at 15 degrees (Phi_B = 0.12, band phase 1/2, 4000
		// triangles) to det F = 0.06 by 6 % strain, then they snap through to inverted states,
		// which the reflection-blind St-Venant-Kirchhoff energy counts as nearly unstrained, and
		// Newton stalls. The term acts only where J < 1: at the simulator's kappa (4.2e11 Pa) it
		// moves the 15-degree mesoscale stress by 1.8e-4 where both converge (5 %, 2000
		// triangles) and the 45-degree mesoscale slope by +0.07 %, but it stiffens the
		// macroscale tilted sample, so the sweep's E_vw is 3.6 % below the fit without it.
		cal.mesoscale.compression_coefficient = plume_material_vane().compression_coefficient;
		cal.sample.element_count = scaled(cal.sample.element_count, def->scale);
		cal.macroscale_elements = scaled(cal.macroscale_elements, def->scale);
		plume_calibration_result result;
		status = plume_lab_calibrate(&cal, &result, err);
		if (status != PLUME_OK)
			break;
		study_progress(def, &done, total);
		E_vw[p] = result.E_vw;
		strain_max = cal.tilted_strain_max;
		plume_lab_material meso_material = cal.mesoscale;
		plume_lab_material macro_material = plume_lab_material_default(PLUME_LAB_MACROSCALE);
		macro_material.E_vv = result.E_vv;
		macro_material.E_ww = result.E_ww;
		macro_material.E_vw = result.E_vw;
		// The calibration's protocol (docs/lab.md): its strain range, its compression term and
		// its elements, so that the two models meet at 45 degrees, where E_vw was fitted.
		macro_material.quadratic = !cal.barb_constraint && cal.macroscale_quadratic;
		macro_material.compression_coefficient = cal.mesoscale.compression_coefficient;
		plume_sample_def sample = cal.sample;
		sample.height = cal.aspect_ratio * sample.width;
		for (int a = 0; a < ANGLES && status == PLUME_OK; ++a) {
			angle_deg[a] = 15.0 * a;
			sample.barb_angle = angle_deg[a] * PI / 180.0;
			sample.element_count = cal.sample.element_count;
			status =
			    slope_at(&meso_material, &sample, cal.steps, cal.tilted_strain_max, cal.phase_count, &meso[p][a], err);
			study_progress(def, &done, total);
			sample.element_count = cal.macroscale_elements;
			if (status == PLUME_OK)
				status = slope_at(&macro_material, &sample, cal.steps, cal.tilted_strain_max, 1, &macro[p][a], err);
			study_progress(def, &done, total);
			if (status == PLUME_OK) {
				meso[p][a] /= E_b[p];
				macro[p][a] /= E_b[p];
				double gap = fabs(macro[p][a] - meso[p][a]) / meso[p][a];
				if (gap > worst)
					worst = gap, worst_phi = phis[p], worst_angle = angle_deg[a];
			}
		}
	}
	if (status == PLUME_OK) {
		double phi_col[3 * ANGLES], angle_col[3 * ANGLES], meso_col[3 * ANGLES], macro_col[3 * ANGLES],
		    evw_col[3 * ANGLES];
		for (int p = 0; p < 3; ++p)
			for (int a = 0; a < ANGLES; ++a) {
				int r = p * ANGLES + a;
				phi_col[r] = phis[p];
				angle_col[r] = angle_deg[a];
				meso_col[r] = meso[p][a];
				macro_col[r] = macro[p][a];
				evw_col[r] = E_vw[p];
			}
		const double *columns[5] = {phi_col, angle_col, meso_col, macro_col, evw_col};
		status = plume_lab_write_csv(csv, "phi,barb_angle_deg,mesoscale_slope_over_Eb,macroscale_slope_over_Eb,E_vw_pa",
		                             columns, 5, 3 * ANGLES, err);
	}
	if (status == PLUME_OK) {
		plume_plot_series series[6];
		char labels[6][48];
		for (int p = 0; p < 3; ++p) {
			snprintf(labels[2 * p], sizeof labels[0], "mesoscale, #gF#dB#u = %.2f", phis[p]);
			snprintf(labels[2 * p + 1], sizeof labels[0], "macroscale, #gF#dB#u = %.2f", phis[p]);
			series[2 * p] = (plume_plot_series){labels[2 * p], angle_deg, meso[p], ANGLES, true, false};
			series[2 * p + 1] = (plume_plot_series){labels[2 * p + 1], angle_deg, macro[p], ANGLES, false, p != 1};
		}
		plume_plot plot = {.title = "Slopes against barb angle (Kikuuwe's term in both models)",
		                   .x_label = "barb angle #fi#gh#fn [deg]",
		                   .y_label = "slope / #fiE#db#u#fn",
		                   .log_y = true,
		                   .legend = PLUME_LEGEND_TOP_RIGHT,
		                   .series_count = 6,
		                   .series = series};
		status = plume_lab_plot(&plot, png, svg, err);
	}
	if (status == PLUME_OK && summary != NULL)
		snprintf(summary, summary_size,
		         "{\"study\": \"angles\", \"compression_coefficient_pa\": %g, \"strain_max\": %g, \"E_vw_pa\": [%.6g, "
		         "%.6g, %.6g], \"largest_relative_gap\": %.4g, \"at\": {\"phi\": %g, \"barb_angle_deg\": %g}}",
		         plume_material_vane().compression_coefficient, strain_max, E_vw[0], E_vw[1], E_vw[2], worst, worst_phi,
		         worst_angle);
	return status;
}

// ---------------------------------------------------------------------------
// Size effect

static plume_status study_size(const plume_study_def *def, const char *csv, const char *png, const char *svg,
                               char *summary, size_t summary_size, plume_error *err)
{
	enum { SIZES = 4 };
	static const int barbs[SIZES] = {5, 10, 20, 40};
	// Thesis A.3 uses E_B / E_b = 6.2e4; Table 5.1 at Phi_B = 0.14 gives 6.6e4.
	plume_lab_material material = plume_lab_material_default(PLUME_LAB_MESOSCALE);
	material.bands.barb_divisions = 2;
	plume_traction_result runs[SIZES];
	memset(runs, 0, sizeof runs);
	double inverse_n[SIZES], stress_at_3[SIZES];
	plume_status status = PLUME_OK;
	for (int k = 0; k < SIZES && status == PLUME_OK; ++k) {
		plume_sample_def sample = plume_sample_default_def();
		// A square sample N periods wide; the barbs run from clamp to clamp, tilted by half a
		// degree so that they can buckle instead of staying on the symmetric branch.
		sample.width = barbs[k] * material.bands.period;
		sample.height = sample.width;
		sample.barb_angle = 0.5 * PI / 180.0;
		sample.element_count = scaled(400 * barbs[k], def->scale);
		plume_traction_def traction = plume_traction_default_def();
		traction.compression = true;
		traction.strain_max = 0.03;
		traction.steps = 6;
		traction.solver.tolerance = 1e-6;
		traction.accept_residual = 1e-4;
		status = plume_lab_traction(&material, &sample, &traction, runs + k, err);
		study_progress(def, &(int){k}, SIZES);
		if (status == PLUME_OK) {
			inverse_n[k] = 1.0 / barbs[k];
			stress_at_3[k] = runs[k].stress[runs[k].count - 1] / material.E_B;
			for (int i = 0; i < runs[k].count; ++i)
				runs[k].stress[i] /= material.E_B;
		}
	}
	if (status == PLUME_OK) {
		int count = runs[0].count;
		const double *columns[SIZES + 1] = {runs[0].strain, runs[0].stress, runs[1].stress, runs[2].stress,
		                                    runs[3].stress};
		status = plume_lab_write_csv(csv,
		                             "strain,stress_over_EB_N5,stress_over_EB_N10,stress_over_EB_N20,"
		                             "stress_over_EB_N40",
		                             columns, SIZES + 1, count, err);
	}
	if (status == PLUME_OK) {
		plume_plot_series series[SIZES];
		char labels[SIZES][32];
		for (int k = 0; k < SIZES; ++k) {
			snprintf(labels[k], sizeof labels[k], "N = %d", barbs[k]);
			series[k] = (plume_plot_series){labels[k], runs[k].strain, runs[k].stress, runs[k].count, false, false};
		}
		plume_plot plot = {.title = "Size effect: mesoscale longitudinal compression",
		                   .x_label = "measured strain #fi#ge#fn",
		                   .y_label = "measured stress #fi#gs#fn / #fiE#dB#u#fn",
		                   .series_count = SIZES,
		                   .series = series};
		status = plume_lab_plot(&plot, png, svg, err);
	}
	if (status == PLUME_OK && summary != NULL)
		snprintf(summary, summary_size,
		         "{\"study\": \"size\", \"inverse_N\": [%g, %g, %g, %g], \"stress_over_EB_at_minus_3pct\": [%.6g, "
		         "%.6g, %.6g, %.6g]}",
		         inverse_n[0], inverse_n[1], inverse_n[2], inverse_n[3], stress_at_3[0], stress_at_3[1], stress_at_3[2],
		         stress_at_3[3]);
	for (int k = 0; k < SIZES; ++k)
		plume_traction_result_free(runs + k);
	return status;
}

// ---------------------------------------------------------------------------
// Bending: cantilever strips under refinement (issue 13)

static plume_status study_bending(const plume_study_def *def, const char *csv, const char *png, const char *svg,
                                  char *summary, size_t summary_size, plume_error *err)
{
	enum { MAX_LEVELS = 4, SERIES = 2 * 2 * PLUME_STRIP_FAMILY_COUNT };
	static const int levels[MAX_LEVELS] = {2, 4, 8, 16};
	// A scale below 1 (a quick look, the CLI test) stops at 4 cells across.
	const int LEVELS = def->scale < 1 ? 2 : MAX_LEVELS;
	// Rows: model (0 fundamental form, 1 paper hinge), family, barbs (0 along the strip,
	// 1 across), cells across the width, delta / delta_EB.
	table t = {.column_count = 5};
	double xs[SERIES][MAX_LEVELS], ys[SERIES][MAX_LEVELS];
	double worst_finest[2] = {0, 0};
	plume_status status = PLUME_OK;
	int done = 0, total = SERIES * LEVELS;
	for (int model = 0; model < 2 && status == PLUME_OK; ++model)
		for (int family = 0; family < PLUME_STRIP_FAMILY_COUNT && status == PLUME_OK; ++family)
			for (int barbs = 0; barbs < 2 && status == PLUME_OK; ++barbs)
				for (int l = 0; l < LEVELS && status == PLUME_OK; ++l) {
					plume_cantilever_def c = plume_cantilever_default_def();
					c.model = model == 0 ? PLUME_BENDING_FUNDAMENTAL_FORM : PLUME_BENDING_PAPER_HINGE;
					c.family = (plume_strip_family)family;
					c.across = levels[l];
					// The vane's moduli (thesis Table 6.1): stiff when the strip bends the barbs.
					c.bending_along = 1e-7;
					c.bending_across = 2.5e-4;
					c.barb_angle = barbs == 0 ? 0 : 0.5 * PI;
					double ratio;
					status = plume_lab_cantilever(&c, &ratio, err);
					study_progress(def, &done, total);
					int series = (model * PLUME_STRIP_FAMILY_COUNT + family) * 2 + barbs;
					xs[series][l] = levels[l];
					ys[series][l] = ratio;
					double row[5] = {model, family, barbs, levels[l], ratio};
					if (status == PLUME_OK && table_add(&t, row) != 0)
						status = memory_error(err);
					if (l == LEVELS - 1)
						worst_finest[model] = fmax(worst_finest[model], fabs(ratio - 1));
				}
	if (status == PLUME_OK)
		status = plume_lab_write_csv(csv, "model,family,barbs_across,cells_across,deflection_over_euler_bernoulli",
		                             (const double *const *)t.columns, 5, t.row_count, err);
	if (status == PLUME_OK) {
		plume_plot_series series[SERIES];
		char labels[SERIES][64];
		for (int k = 0; k < SERIES; ++k) {
			int model = k / (2 * PLUME_STRIP_FAMILY_COUNT), family = k / 2 % PLUME_STRIP_FAMILY_COUNT;
			snprintf(labels[k], sizeof labels[k], "%s, %s, barbs %s", model == 0 ? "fundamental form" : "paper hinge",
			         plume_strip_family_name((plume_strip_family)family), k % 2 == 0 ? "along" : "across");
			series[k] = (plume_plot_series){labels[k], xs[k], ys[k], LEVELS, false, model == 1};
		}
		plume_plot plot = {.title = "Cantilever strips: tip deflection over Euler-Bernoulli",
		                   .x_label = "cells across the width",
		                   .y_label = "#gd / #gd#dEB#u",
		                   .log_x = true,
		                   .legend = PLUME_LEGEND_TOP_RIGHT,
		                   .series_count = SERIES,
		                   .series = series,
		                   .width = 1280,
		                   .height = 960};
		status = plume_lab_plot(&plot, png, svg, err);
	}
	if (status == PLUME_OK && summary != NULL)
		snprintf(summary, summary_size,
		         "{\"study\": \"bending\", \"rows\": %d, \"finest_cells_across\": %d, \"largest_error_at_finest\": "
		         "{\"fundamental_form\": %.4g, \"paper_hinge\": %.4g}}",
		         t.row_count, levels[LEVELS - 1], worst_finest[0], worst_finest[1]);
	table_free(&t);
	return status;
}

plume_status plume_lab_study(const plume_study_def *def, const char *csv_path, const char *png_path,
                             const char *svg_path, char *summary, size_t summary_size, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	if (!(def->scale > 0.0 && def->scale <= 16.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "study scale is %g, allowed in (0, 16]", def->scale);
	if (summary != NULL && summary_size > 0)
		summary[0] = '\0';
	switch (def->kind) {
	case PLUME_STUDY_LOCKING: return study_locking(def, csv_path, png_path, svg_path, summary, summary_size, err);
	case PLUME_STUDY_CONDITIONING:
		return study_conditioning(def, csv_path, png_path, svg_path, summary, summary_size, err);
	case PLUME_STUDY_ANGLES: return study_angles(def, csv_path, png_path, svg_path, summary, summary_size, err);
	case PLUME_STUDY_SIZE: return study_size(def, csv_path, png_path, svg_path, summary, summary_size, err);
	case PLUME_STUDY_BENDING: return study_bending(def, csv_path, png_path, svg_path, summary, summary_size, err);
	}
	return plume_error_set(err, PLUME_ERROR_SPEC, "unknown study %d", (int)def->kind);
}

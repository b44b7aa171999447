// Calibration of the membrane moduli (Jouve thesis 5.2-5.3): the mesoscale
// model's longitudinal and transverse slopes are E_vv and E_ww; E_vw is the
// shear modulus that makes the macroscale model's tilted slope match the
// mesoscale one at the thesis's aspect ratio (a bracketed search on E_vw).
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "lab/lab_internal.h"
#include "plume/lab.h"

static const double PI = 3.14159265358979323846;

// The range of E_vw the search may use, in units of E_ww (see plume_lab_calibrate).
static const double E_VW_RANGE_LOW = 1e-3;
static const double E_VW_RANGE_HIGH = 1e3;

plume_calibration_def plume_calibration_default_def(void)
{
	plume_calibration_def def;
	memset(&def, 0, sizeof def);
	def.mesoscale = plume_lab_material_default(PLUME_LAB_MESOSCALE);
	// The thesis's chapter-5 materials: St-Venant-Kirchhoff bands without Kikuuwe's term.
	def.mesoscale.compression_coefficient = 0.0;
	def.sample = plume_sample_default_def();
	// A 4 mm wide tilted sample (thesis Table 3.1c: 3 to 16 mm) holds 10 barb periods of
	// 0.4 mm: small enough for the mesoscale model to be solved in seconds.
	def.sample.width = 4e-3;
	def.sample.element_count = 4000;
	def.aspect_ratio = 1.3;
	def.longitudinal_strain_max = 0.01;
	def.transverse_strain_max = 0.4;
	def.tilted_strain_max = 0.1;
	def.steps = 10;
	def.barb_constraint = true;
	def.macroscale_quadratic = true;
	def.tolerance = 1e-4;
	def.macroscale_elements = 2000;
	def.phase_count = 4;
	def.uncertainty = true;
	def.cookie = PLUME_DEF_COOKIE;
	return def;
}

double plume_calibration_estimate_bytes(const plume_calibration_def *def)
{
	int largest =
	    def->sample.element_count > def->macroscale_elements ? def->sample.element_count : def->macroscale_elements;
	return plume_sample_estimate_bytes((def->uncertainty ? 2.0 : 1.0) * largest);
}

const char *plume_calibration_protocol_name(const plume_calibration_def *def)
{
	plume_calibration_def d = plume_calibration_default_def();
	bool same = def->mesoscale.compression_coefficient == d.mesoscale.compression_coefficient &&
	            def->mesoscale.bands.period == d.mesoscale.bands.period && def->sample.width == d.sample.width &&
	            def->sample.element_count == d.sample.element_count && def->aspect_ratio == d.aspect_ratio &&
	            def->longitudinal_strain_max == d.longitudinal_strain_max &&
	            def->transverse_strain_max == d.transverse_strain_max &&
	            def->tilted_strain_max == d.tilted_strain_max && def->steps == d.steps &&
	            def->barb_constraint == d.barb_constraint && def->macroscale_quadratic == d.macroscale_quadratic &&
	            def->macroscale_elements == d.macroscale_elements && def->phase_count == d.phase_count;
	return same ? "chapter-5" : "custom";
}

static plume_status check(const plume_calibration_def *def, plume_error *err)
{
	const plume_sample_def *s = &def->sample;
	// The width first: a sample 0 m wide is the width's fault, not the band period's.
	if (!(s->width >= 1e-6 && s->width <= 10.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "sample.width is %g m, allowed [1e-06, 10]", s->width);
	if (!(def->aspect_ratio > 0.0 && isfinite(def->aspect_ratio)))
		return plume_error_set(err, PLUME_ERROR_SPEC, "aspect ratio is %g, allowed > 0", def->aspect_ratio);
	// The tilted sample must hold at least one barb period across and two mesh rows along.
	double height = def->aspect_ratio * s->width;
	double spacing = sqrt(2.0 * s->width * height / fmax(def->macroscale_elements, 1));
	if (height < 2.0 * spacing || s->width < 2.0 * spacing || height > 1e3 * s->width || s->width > 1e3 * height)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "aspect ratio %g: a %g m wide sample %g m high cannot be meshed with %d elements "
		                       "(allowed: both sides at least two element sizes, ratio within 1e-3..1e3)",
		                       def->aspect_ratio, s->width, height, def->macroscale_elements);
	if (def->mesoscale.bands.period > fmin(s->width, height))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "band period %g m is larger than the tilted sample, %g m wide (sample.width) and %g m "
		                       "high (aspect ratio %g): it holds no whole barb",
		                       def->mesoscale.bands.period, s->width, height, def->aspect_ratio);
	if (!(def->longitudinal_strain_max > 0.0 && def->longitudinal_strain_max <= 10.0) ||
	    !(def->transverse_strain_max > 0.0 && def->transverse_strain_max <= 10.0) ||
	    !(def->tilted_strain_max > 0.0 && def->tilted_strain_max <= 10.0))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "strain_max is %g (longitudinal), %g (transverse) and %g (tilted), allowed in (0, 10]",
		                       def->longitudinal_strain_max, def->transverse_strain_max, def->tilted_strain_max);
	if (def->steps < 2)
		return plume_error_set(err, PLUME_ERROR_SPEC, "steps is %d, allowed >= 2", def->steps);
	if (!(def->tolerance > 0.0 && def->tolerance < 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "tolerance is %g, allowed in (0, 1)", def->tolerance);
	if (def->phase_count < 1 || def->phase_count > 64)
		return plume_error_set(err, PLUME_ERROR_SPEC, "phase count is %d, allowed in [1, 64]", def->phase_count);
	if (def->macroscale_elements < 2)
		return plume_error_set(err, PLUME_ERROR_SPEC, "macroscale elements is %d, allowed >= 2",
		                       def->macroscale_elements);
	plume_lab_material material = def->mesoscale;
	material.model = PLUME_LAB_MESOSCALE;
	plume_status status = plume_lab_validate(&material, s, NULL, err);
	// The tilted sample and its bands, before any test runs (not at the first mesh).
	plume_sample_def tilted = *s;
	tilted.height = height;
	if (status == PLUME_OK)
		status = plume_sample_validate(&tilted, &material.bands, err);
	return status;
}

// Runs one traction test (the mean over phase_count band phases for the mesoscale model)
// and returns its slope; keeps its curve as result's curve (0..3) when the result holds curves
// and curve >= 0.
static plume_status slope_of(const plume_lab_material *material, const plume_sample_def *sample, double strain_max,
                             int steps, int phase_count, plume_calibration_result *result, double *slope,
                             double *phase_slopes, int curve, plume_lab_progress *progress, plume_error *err)
{
	plume_traction_def traction = plume_traction_default_def();
	traction.strain_max = strain_max;
	traction.steps = steps;
	// The slope needs a few significant digits; 1e-6 of the force scale is plenty and
	// keeps the stiff tilted problems from stalling on round-off.
	traction.solver.tolerance = 1e-6;
	// Every step must converge (accept_residual stays 0): the protocol's tilted tests stay
	// below the strain where the pure model stalls (docs/lab.md, The protocol). Measured
	// 2026-11-25: the three Table 5.1 calibrations with their uncertainty runs, the old
	// protocol (eps_max = 0.4 with kappa = 5.04e7 Pa) and the 24 calibrations of
	// examples/sweeps/uq-calibration.json all converge with no stalled step allowed, and
	// give the same moduli as when stalls below 1e-3 of the clamp force were accepted.
	int solves = 0;
	bool keep = curve >= 0 && result->curve_samples > 0;
	plume_status status = lab_mean_curve(material, sample, &traction, phase_count, slope, phase_slopes, &solves,
	                                     keep ? result->curve_strain[curve] : NULL,
	                                     keep ? result->curve_stress[curve] : NULL, progress, err);
	if (status != PLUME_OK) {
		char context[160];
		if (material->model == PLUME_LAB_MACROSCALE)
			snprintf(context, sizeof context, "macroscale, E_vw = %.6g Pa, barbs at %.4g deg", material->E_vw,
			         sample->barb_angle * 180.0 / PI);
		else
			snprintf(context, sizeof context, "mesoscale, barbs at %.4g deg", sample->barb_angle * 180.0 / PI);
		plume_error_prefix(err, context);
		return status;
	}
	result->traction_count += material->model == PLUME_LAB_MESOSCALE ? phase_count : 1;
	result->solve_count += solves;
	return PLUME_OK;
}

// A size that holds a whole number of band periods (at least one), so that the barbs
// cover exactly Phi_B of the longitudinal and transverse samples, as eqs. 5.2 and 5.5 assume.
static double whole_periods(double size, double period)
{
	double count = fmax(1.0, round(size / period));
	return count * period;
}

// While E_vw is searched the number of tests ahead is unknown: the estimate keeps this test
// and the final one ahead of those done.
static plume_lab_progress *search_progress(plume_lab_progress *progress)
{
	if (progress->total < progress->done + 2)
		progress->total = progress->done + 2;
	return progress;
}

void plume_calibration_result_free(plume_calibration_result *result)
{
	for (int c = 0; c < 4; ++c) {
		plume_free(result->curve_strain[c]);
		plume_free(result->curve_stress[c]);
		result->curve_strain[c] = result->curve_stress[c] = NULL;
	}
	result->curve_samples = 0;
}

// Half the range of count values.
static double half_range(const double *values, int count)
{
	double lo = values[0], hi = values[0];
	for (int k = 1; k < count; ++k)
		lo = fmin(lo, values[k]), hi = fmax(hi, values[k]);
	return 0.5 * (hi - lo);
}

static void finish_spread(plume_modulus_spread *spread)
{
	spread->total = sqrt(spread->phase * spread->phase + spread->width * spread->width + spread->mesh * spread->mesh);
}

// The spread of E_vv or E_ww: the straight test (of the given strain range and slope) at
// band phase 1/2, on a sample twice as wide and high, and on a mesh twice as fine.
static plume_status straight_spread(const plume_lab_material *meso, const plume_sample_def *straight, double strain_max,
                                    double slope, int steps, plume_calibration_result *result,
                                    plume_modulus_spread *spread, plume_lab_progress *progress, plume_error *err)
{
	plume_lab_material shifted = *meso;
	shifted.bands.phase = 0.5;
	double probe[2] = {slope, 0.0};
	plume_status status =
	    slope_of(&shifted, straight, strain_max, steps, 1, result, &probe[1], NULL, -1, progress, err);
	spread->phase = half_range(probe, 2);
	plume_sample_def wide = *straight;
	wide.width *= 2.0, wide.height *= 2.0, wide.element_count *= 2;
	double other = 0.0;
	if (status == PLUME_OK)
		status = slope_of(meso, &wide, strain_max, steps, 1, result, &other, NULL, -1, progress, err);
	spread->width = fabs(other - slope);
	plume_sample_def fine = *straight;
	fine.element_count *= 2;
	if (status == PLUME_OK)
		status = slope_of(meso, &fine, strain_max, steps, 1, result, &other, NULL, -1, progress, err);
	spread->mesh = fabs(other - slope);
	finish_spread(spread);
	return status;
}

// E_vw to first order when the mesoscale target changes by the factor ratio: the macroscale
// slope goes as E_vw^sensitivity near the fit.
static double moved_E_vw(double E_vw, double ratio, double sensitivity) { return E_vw * pow(ratio, 1.0 / sensitivity); }

// The sensitivity of the macroscale tilted slope to E_vw at the fit, and E_vw's spread:
// over the band phases (each phase's target), on a sample twice as wide and high (twice the
// barbs, twice the elements) and on meshes twice as fine (both models), the last two at
// band phase 0 against band phase 0. macro holds the fitted E_vw; tilted the macroscale mesh.
static plume_status shear_spread(const plume_calibration_def *def, const plume_lab_material *meso,
                                 plume_lab_material macro, const plume_sample_def *tilted, const double *phase_slopes,
                                 plume_calibration_result *result, plume_lab_progress *progress, plume_error *err)
{
	double E_vw = macro.E_vw, up = 0.0, down = 0.0, strain_max = def->tilted_strain_max;
	int steps = def->steps;
	macro.E_vw = 1.05 * E_vw;
	plume_status status = slope_of(&macro, tilted, strain_max, steps, 1, result, &up, NULL, -1, progress, err);
	macro.E_vw = 0.95 * E_vw;
	if (status == PLUME_OK)
		status = slope_of(&macro, tilted, strain_max, steps, 1, result, &down, NULL, -1, progress, err);
	macro.E_vw = E_vw;
	if (status != PLUME_OK)
		return status;
	double S = log(up / down) / log(1.05 / 0.95);
	result->sensitivity = S;
	if (!(S > 0.0))
		return plume_error_set(
		    err, PLUME_ERROR_NUMERIC,
		    "the macroscale tilted slope does not grow with E_vw at %g Pa (%g at +5 %%, %g at -5 %%)", E_vw, up, down);
	double phase_E_vw[64] = {0.0};
	for (int k = 0; k < def->phase_count; ++k)
		phase_E_vw[k] = moved_E_vw(E_vw, phase_slopes[k] / result->slope_tilted, S);
	result->spread_vw.phase = half_range(phase_E_vw, def->phase_count);

	plume_lab_material phase0 = *meso;
	phase0.bands.phase = 0.0;
	double macro_fine = 0.0, meso_fine = 0.0, meso_wide = 0.0;
	plume_sample_def fine = *tilted;
	fine.element_count = 2 * def->macroscale_elements;
	status = slope_of(&macro, &fine, strain_max, steps, 1, result, &macro_fine, NULL, -1, progress, err);
	fine.element_count = 2 * def->sample.element_count;
	if (status == PLUME_OK)
		status = slope_of(&phase0, &fine, strain_max, steps, 1, result, &meso_fine, NULL, -1, progress, err);
	plume_sample_def wide = *tilted;
	wide.width *= 2.0, wide.height *= 2.0, wide.element_count = 2 * def->sample.element_count;
	if (status == PLUME_OK)
		status = slope_of(&phase0, &wide, strain_max, steps, 1, result, &meso_wide, NULL, -1, progress, err);
	if (status != PLUME_OK)
		return status;
	double base = phase_slopes[0];
	result->spread_vw.mesh =
	    fabs(moved_E_vw(E_vw, (meso_fine / base) / (macro_fine / result->slope_tilted_macroscale), S) - E_vw);
	// The macroscale model is homogeneous: its slope does not depend on the sample's size.
	result->spread_vw.width = fabs(moved_E_vw(E_vw, meso_wide / base, S) - E_vw);
	finish_spread(&result->spread_vw);
	return PLUME_OK;
}

plume_status plume_lab_calibrate(const plume_calibration_def *def, plume_calibration_result *result, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	PLUME_ASSERT(result != NULL);
	memset(result, 0, sizeof *result);
	plume_status status = check(def, err);
	if (status != PLUME_OK)
		return status;
	if (def->keep_curves) {
		result->curve_samples = def->steps + 1;
		for (int c = 0; c < 4; ++c) {
			result->curve_strain[c] = plume_calloc((size_t)result->curve_samples, sizeof(double));
			result->curve_stress[c] = plume_calloc((size_t)result->curve_samples, sizeof(double));
			if (result->curve_strain[c] == NULL || result->curve_stress[c] == NULL) {
				plume_calibration_result_free(result);
				return plume_error_set(err, PLUME_ERROR_MEMORY, "calibration: out of memory");
			}
		}
	}
	// Tests ahead: longitudinal, transverse, the tilted phases, then a search on E_vw that
	// typically takes about ten macroscale tests, and the final one.
	plume_lab_progress progress = {def->progress, def->progress_user, 0, 2 + def->phase_count + 11};
	plume_lab_material meso = def->mesoscale;
	meso.model = PLUME_LAB_MESOSCALE;
	double width = def->sample.width, height = def->aspect_ratio * def->sample.width;

	// Longitudinal and transverse: the bands deform uniformly, any mesh that resolves them is exact.
	plume_sample_def straight = def->sample;
	straight.width = whole_periods(width, meso.bands.period);
	straight.height = whole_periods(height, meso.bands.period);
	straight.element_count = 200;
	straight.barb_angle = 0.0;
	status = slope_of(&meso, &straight, def->longitudinal_strain_max, def->steps, 1, result,
	                  &result->slope_longitudinal, NULL, 0, &progress, err);
	plume_sample_def straight_longitudinal = straight;
	if (status == PLUME_OK) {
		straight.barb_angle = 0.5 * PI;
		status = slope_of(&meso, &straight, def->transverse_strain_max, def->steps, 1, result,
		                  &result->slope_transverse, NULL, 1, &progress, err);
	}
	double phase_slopes[64] = {0.0};
	plume_sample_def tilted = def->sample;
	tilted.height = height;
	tilted.barb_angle = 0.25 * PI;
	// The tilted slope of a sample a few barbs wide depends on where the bands meet its
	// corners: the target is its mean over band phases.
	if (status == PLUME_OK)
		status = slope_of(&meso, &tilted, def->tilted_strain_max, def->steps, def->phase_count, result,
		                  &result->slope_tilted, phase_slopes, 2, &progress, err);
	if (status != PLUME_OK) {
		plume_error_prefix(err, "calibration");
		plume_calibration_result_free(result);
		return status;
	}

	plume_lab_material macro = plume_lab_material_default(PLUME_LAB_MACROSCALE);
	macro.E_vv = result->slope_longitudinal;
	macro.E_ww = result->slope_transverse;
	macro.barb_constraint = def->barb_constraint;
	macro.quadratic = !def->barb_constraint && def->macroscale_quadratic;
	macro.compression_coefficient = meso.compression_coefficient;
	tilted.element_count = def->macroscale_elements;
	double target = result->slope_tilted;

	// The tilted slope grows with E_vw. Bracket the target in log E_vw, then shrink the
	// bracket: the Illinois variant of false position, with a bisection step whenever it
	// would shrink the bracket by less than half.
	// The search starts at E_ww / 4, near where the thesis's parameters put E_vw, and
	// widens by growing steps: very stiff shear makes the tilted test hard for Newton, so
	// the bracket should not reach further than it needs. It never leaves
	// [E_VW_RANGE_LOW, E_VW_RANGE_HIGH] E_ww (and E_vw <= E_vv): a shear modulus of the
	// barbule web a thousand times softer than its transverse modulus leaves the tilted
	// slope at its shear-free limit, and one stiffer than the barbs themselves is not a
	// vane. When the target lies outside the slopes the model reaches over that range, no
	// E_vw answers the question; the search says so with both ends instead of drifting to
	// absurd moduli (barbs running clamp to clamp once reached 1e-74 Pa).
	double log_min = log(E_VW_RANGE_LOW * macro.E_ww);
	double log_max = log(fmin(E_VW_RANGE_HIGH * macro.E_ww, macro.E_vv));
	double lo = fmin(fmax(log(0.25 * macro.E_ww), log_min), log_max), hi = lo, f_lo = 0.0, f_hi = 0.0, slope = 0.0;
	macro.E_vw = exp(lo);
	status = slope_of(&macro, &tilted, def->tilted_strain_max, def->steps, 1, result, &slope, NULL, -1,
	                  search_progress(&progress), err);
	f_lo = f_hi = slope - target;
	double step = log(2.0);
	while (status == PLUME_OK && (f_lo > 0.0) == (f_hi > 0.0)) {
		bool down = f_lo > 0.0;
		if (down ? lo <= log_min : hi >= log_max)
			break; // the end of the range: the target is out of reach
		double x = down ? fmax(lo - step, log_min) : fmin(hi + step, log_max);
		macro.E_vw = exp(x);
		status = slope_of(&macro, &tilted, def->tilted_strain_max, def->steps, 1, result, &slope, NULL, -1,
		                  search_progress(&progress), err);
		// Newton may fail on a very stiff trial: step out by half as far and try again.
		for (int retry = 0; retry < 4 && status == PLUME_ERROR_NUMERIC; ++retry) {
			step *= 0.5;
			x = down ? fmax(lo - step, log_min) : fmin(hi + step, log_max);
			macro.E_vw = exp(x);
			status = slope_of(&macro, &tilted, def->tilted_strain_max, def->steps, 1, result, &slope, NULL, -1,
			                  search_progress(&progress), err);
		}
		if (down) {
			hi = lo, f_hi = f_lo;
			lo = x, f_lo = slope - target;
		} else {
			lo = hi, f_lo = f_hi;
			hi = x, f_hi = slope - target;
		}
		step *= 1.5;
	}
	if (status == PLUME_OK && (f_lo > 0.0) == (f_hi > 0.0)) {
		// Out of reach: the slopes at both ends of the range the search may use (the far
		// end solved now if the search never went there; where Newton fails on it, the
		// furthest modulus that converged stands for it).
		bool below = f_lo > 0.0; // every slope tried is above the target
		double near_x = below ? lo : hi, near_slope = (below ? f_lo : f_hi) + target;
		double far_x = below ? log_max : log_min, far_slope = 0.0;
		double from = below ? hi : lo;
		plume_status far_status = PLUME_ERROR_NUMERIC;
		for (int retry = 0; retry < 6 && far_status == PLUME_ERROR_NUMERIC; ++retry) {
			if (retry > 0)
				far_x = 0.5 * (far_x + from);
			macro.E_vw = exp(far_x);
			far_status = slope_of(&macro, &tilted, def->tilted_strain_max, def->steps, 1, result, &far_slope, NULL, -1,
			                      search_progress(&progress), err);
		}
		if (far_status == PLUME_ERROR_NUMERIC)
			far_x = from, far_slope = (below ? f_hi : f_lo) + target;
		else if (far_status != PLUME_OK)
			status = far_status;
		if (status == PLUME_OK) {
			double x_min = below ? near_x : far_x, x_max = below ? far_x : near_x;
			double s_min = below ? near_slope : far_slope, s_max = below ? far_slope : near_slope;
			status = plume_error_set(err, PLUME_ERROR_NUMERIC,
			                         "no E_vw gives the mesoscale tilted slope %.6g Pa: the macroscale tilted slope "
			                         "(%s barb constraint) is %.6g Pa at E_vw = %.4g Pa and %.6g Pa at E_vw = %.4g "
			                         "Pa, the reachable range, so the target is %s it (check the aspect ratio and "
			                         "the barb angle of the tilted test)",
			                         target, def->barb_constraint ? "with the" : "without the", s_min, exp(x_min),
			                         s_max, exp(x_max), below ? "below" : "above");
		}
	}
	int side = 0;
	while (status == PLUME_OK && hi - lo > log1p(def->tolerance)) {
		double x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
		double width_before = hi - lo;
		if (!(x > lo && x < hi))
			x = 0.5 * (lo + hi);
		macro.E_vw = exp(x);
		status = slope_of(&macro, &tilted, def->tilted_strain_max, def->steps, 1, result, &slope, NULL, -1,
		                  search_progress(&progress), err);
		double f = slope - target;
		result->bisection_iterations += 1;
		if (f == 0.0) {
			lo = hi = x;
			break;
		}
		if ((f > 0.0) == (f_hi > 0.0)) {
			hi = x, f_hi = f;
			if (side == -1)
				f_lo *= 0.5; // Illinois: halve the stale end's value
			side = -1;
		} else {
			lo = x, f_lo = f;
			if (side == 1)
				f_hi *= 0.5;
			side = 1;
		}
		if (hi - lo > 0.5 * width_before) {
			// Slow progress: bisect once.
			double mid = 0.5 * (lo + hi);
			macro.E_vw = exp(mid);
			status = slope_of(&macro, &tilted, def->tilted_strain_max, def->steps, 1, result, &slope, NULL, -1,
			                  search_progress(&progress), err);
			result->bisection_iterations += 1;
			if ((slope - target > 0.0) == (f_hi > 0.0))
				hi = mid, f_hi = slope - target;
			else
				lo = mid, f_lo = slope - target;
			side = 0;
		}
	}
	if (status != PLUME_OK) {
		plume_error_prefix(err, "calibration");
		plume_calibration_result_free(result);
		return status;
	}
	// The final modulus: the bracket's false-position point, and its slope.
	double x = fabs(f_hi - f_lo) > 0.0 ? (lo * f_hi - hi * f_lo) / (f_hi - f_lo) : 0.5 * (lo + hi);
	if (!(x >= lo && x <= hi))
		x = 0.5 * (lo + hi);
	macro.E_vw = exp(x);
	progress.total = progress.done + 1;
	status = slope_of(&macro, &tilted, def->tilted_strain_max, def->steps, 1, result, &result->slope_tilted_macroscale,
	                  NULL, 3, &progress, err);
	if (status != PLUME_OK) {
		plume_error_prefix(err, "calibration");
		plume_calibration_result_free(result);
		return status;
	}
	if (def->uncertainty) {
		progress.total = progress.done + 6 + 5;
		status = straight_spread(&meso, &straight_longitudinal, def->longitudinal_strain_max,
		                         result->slope_longitudinal, def->steps, result, &result->spread_vv, &progress, err);
		if (status == PLUME_OK)
			status = straight_spread(&meso, &straight, def->transverse_strain_max, result->slope_transverse, def->steps,
			                         result, &result->spread_ww, &progress, err);
		if (status == PLUME_OK)
			status = shear_spread(def, &meso, macro, &tilted, phase_slopes, result, &progress, err);
		if (status != PLUME_OK) {
			plume_error_prefix(err, "calibration: uncertainty");
			plume_calibration_result_free(result);
			return status;
		}
	}
	result->E_vv = macro.E_vv;
	result->E_ww = macro.E_ww;
	result->E_vw = macro.E_vw;
	return PLUME_OK;
}

// plume lab traction LAB.json -o DIR
// plume lab calibrate --phi PHI --Eb E_b --EB E_B [--aspect A] [--period T] ...
// plume lab study locking|conditioning|angles|size|bending -o DIR [--scale S]
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "plume/lab.h"

void cli_help_lab(void)
{
	puts("Usage: plume lab traction LAB.json -o DIR\n"
	     "       plume lab calibrate --phi PHI --Eb E_b --EB E_B [options]\n"
	     "       plume lab study locking|conditioning|angles|size|bending -o DIR [--scale S]\n"
	     "\n"
	     "The virtual feather lab of Jouve's thesis (chapters 3-5): traction tests on\n"
	     "rectangular vane samples, the mesoscale band model, the calibration of the\n"
	     "membrane moduli and the numerical studies. docs/lab.md describes them.\n"
	     "\n"
	     "traction: runs the test LAB.json describes and writes DIR/traction.csv (strain,\n"
	     "  stress, displacement, Newton iterations, convergence), DIR/traction.json (the\n"
	     "  slope) and the stress-strain plot DIR/traction.png and DIR/traction.svg.\n"
	     "\n"
	     "calibrate: prints JSON with E_vv, E_ww, E_vw (Pa), the spread of each (band phase,\n"
	     "  sample width, mesh), the sensitivity of the tilted slope to E_vw, the slopes it\n"
	     "  matched, the protocol and the number of solves (docs/lab.md).\n"
	     "  --phi PHI              barb fraction Phi_B, in (0, 1) (required)\n"
	     "  --Eb PA                barbule modulus E_b, Pa (required)\n"
	     "  --EB PA                barb modulus E_B, Pa (required)\n"
	     "  --aspect A             H/W of the tilted test (default 1.3)\n"
	     "  --period T             band period, m (default 4e-4)\n"
	     "  --width W              tilted sample width, m (default 4e-3)\n"
	     "  --elements N           mesoscale tilted mesh size (default 4000)\n"
	     "  --phases K             band phases the tilted slope is averaged over (default 4)\n"
	     "  --macro-elements N     macroscale tilted mesh size (default 2000)\n"
	     "  --unconstrained        fit E_vw without the barb constraint (on quadratic triangles)\n"
	     "  --tilted-strain EPS    eps_max of the tilted test, the fit of E_vw (default 0.1)\n"
	     "  --compression KAPPA    Kikuuwe's coefficient in both lab models, Pa (default 0:\n"
	     "                         the thesis's chapter-5 materials; the simulator's is 4.2e11)\n"
	     "  --linear-macro         unconstrained fit on the simulator's linear triangles\n"
	     "  --no-uncertainty       skip the spreads and the sensitivity (eleven traction tests)\n"
	     "  -o DIR                 also write DIR/calibration.json (the printed JSON),\n"
	     "                         DIR/slopes.csv (each matched slope, Pa), DIR/curves.csv\n"
	     "                         (the stress-strain curves matched) and their plots\n"
	     "                         DIR/curves_longitudinal.png/.svg, DIR/curves_tilted.png/.svg\n"
	     "\n"
	     "study: writes DIR/<study>.csv, .png and .svg and prints a JSON summary.\n"
	     "  --scale S              element counts times S (default 1; e.g. 0.25 for a quick look)\n"
	     "\n"
	     "  --max-memory BYTES     refuse a run whose largest mesh is estimated past BYTES\n"
	     "                         (16 KiB an element; K, M, G suffixes; default 4G; docs/cli.md)\n"
	     "  -o, --output DIR       output folder (created if missing; all files or none)\n"
	     "  -h, --help             this help");
}

static bool parse_double(const char *option, const char *text, double *out)
{
	char *end = NULL;
	errno = 0;
	double value = strtod(text, &end);
	if (end == text || *end != '\0' || errno != 0 || !isfinite(value)) {
		cli_usage_error("lab", "%s expects a number, got '%s'", option, text);
		return false;
	}
	*out = value;
	return true;
}

static bool parse_int(const char *option, const char *text, int *out)
{
	double value;
	if (!parse_double(option, text, &value))
		return false;
	if (value != floor(value) || value < 1 || value > 1e8) {
		cli_usage_error("lab", "%s expects a whole number >= 1, got '%s'", option, text);
		return false;
	}
	*out = (int)value;
	return true;
}

/// A number for reuse, as plume_lab_format_number writes it; the text lives until the end
/// of the full expression that holds the call (a printf's arguments).
typedef struct number_text {
	char text[PLUME_LAB_NUMBER_TEXT];
} number_text;

static number_text number(double value)
{
	number_text n;
	plume_lab_format_number(n.text, sizeof n.text, value);
	return n;
}

// ---------------------------------------------------------------------------
// traction

static plume_status write_traction(cli_output *output, const plume_traction_result *r, const plume_lab_spec *spec,
                                   plume_error *err)
{
	char path[4352], svg[4352];
	double *iterations = malloc(sizeof(double) * (size_t)r->count);
	double *converged = malloc(sizeof(double) * (size_t)r->count);
	if (iterations == NULL || converged == NULL) {
		free(iterations);
		free(converged);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	}
	for (int i = 0; i < r->count; ++i) {
		iterations[i] = r->iterations[i];
		converged[i] = r->converged[i] ? 1.0 : 0.0;
	}
	const double *columns[5] = {r->strain, r->stress, r->displacement, iterations, converged};
	plume_status status =
	    plume_lab_write_csv(cli_output_path(output, "traction.csv", path, sizeof path),
	                        "strain,stress_pa,displacement_m,newton_iterations,converged", columns, 5, r->count, err);
	free(iterations);
	free(converged);
	if (status != PLUME_OK)
		return status;
	FILE *file = fopen(cli_output_path(output, "traction.json", path, sizeof path), "wb");
	bool written = file != NULL && fprintf(file,
	                                       "{\"slope_pa\": %s, \"strain_max\": %s, \"steps\": %d, "
	                                       "\"newton_iterations\": %d, \"lateral_strain\": %s, "
	                                       "\"model\": \"%s\", \"barb_angle_deg\": %s, \"compression\": %s}\n",
	                                       number(r->slope).text, number(spec->traction.strain_max).text,
	                                       spec->traction.steps, r->newton_iterations, number(r->lateral_strain).text,
	                                       spec->material.model == PLUME_LAB_MESOSCALE ? "mesoscale" : "macroscale",
	                                       number(spec->sample.barb_angle * 180.0 / 3.14159265358979323846).text,
	                                       spec->traction.compression ? "true" : "false") >= 0;
	if (file != NULL && fclose(file) != 0)
		written = false;
	if (!written)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	// The measured curve and the fitted line through the origin.
	double line_x[2] = {0.0, r->strain[r->count - 1]};
	double line_y[2] = {0.0, r->slope * r->strain[r->count - 1]};
	char fit_label[64];
	snprintf(fit_label, sizeof fit_label, "slope %.6g Pa", r->slope);
	plume_plot_series series[2] = {
	    {"measured", r->strain, r->stress, r->count, true, false},
	    {fit_label, line_x, line_y, 2, false, true},
	};
	plume_plot plot = {
	    .title = "Traction test",
	    .x_label = "measured strain #fi#ge#fn#d#fiyy#fn#u",
	    .y_label = "measured stress #fi#gs#fn#d#fiyy#fn#u [Pa]",
	    .series_count = 2,
	    .series = series,
	};
	return plume_lab_plot(&plot, cli_output_path(output, "traction.png", path, sizeof path),
	                      cli_output_path(output, "traction.svg", svg, sizeof svg), err);
}

/// Refuses (exit 5) a lab run whose estimate passes --max-memory (0: PLUME_DEFAULT_MAX_MEMORY); what
/// names the keys or flags that size its largest mesh.
static int check_memory(double bytes, uint64_t max_memory, const char *what)
{
	double limit = (double)(max_memory > 0 ? max_memory : PLUME_DEFAULT_MAX_MEMORY);
	if (bytes <= limit)
		return CLI_EXIT_OK;
	plume_error err = {0};
	plume_error_set(&err, PLUME_ERROR_LIMIT,
	                "%s make meshes of about %.3g GB (%.0f KiB an element); the limit is %.3g GB (raise it with "
	                "--max-memory, or lower them)",
	                what, bytes / 1e9, PLUME_LAB_BYTES_PER_ELEMENT / 1024.0, limit / 1e9);
	return cli_fail(&err);
}

static int run_traction(int argc, char **argv)
{
	static const struct option options[] = {{"output", required_argument, NULL, 'o'},
	                                        {"max-memory", required_argument, NULL, 'M'},
	                                        {"help", no_argument, NULL, 'h'},
	                                        {NULL, 0, NULL, 0}};
	const char *output_dir = NULL;
	uint64_t max_memory = 0;
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 'M':
			if (!cli_parse_memory("lab", optarg, &max_memory))
				return CLI_EXIT_USAGE;
			break;
		case 'h': cli_help_lab(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("lab", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("lab", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (!cli_check_arguments("lab", argc, argv, "LAB.json", output_dir))
		return CLI_EXIT_USAGE;
	plume_error err = {0};
	plume_lab_spec spec;
	plume_status status = plume_lab_spec_load(argv[optind], &spec, &err);
	if (status != PLUME_OK)
		return cli_fail(&err);
	char what[4352];
	snprintf(what, sizeof what, "%s: $.sample.elements (%d)", argv[optind], spec.sample.element_count);
	int code = check_memory(plume_sample_estimate_bytes(spec.sample.element_count), max_memory, what);
	if (code != CLI_EXIT_OK)
		return code;
	plume_traction_result result;
	status = plume_lab_traction(&spec.material, &spec.sample, &spec.traction, &result, &err);
	if (status != PLUME_OK) {
		plume_error_prefix(&err, argv[optind]);
		return cli_fail(&err);
	}
	cli_output output;
	status = cli_output_begin(&output, output_dir, &err);
	if (status == PLUME_OK) {
		status = write_traction(&output, &result, &spec, &err);
		if (status == PLUME_OK)
			status = cli_output_commit(&output, &err);
		else
			cli_output_abort(&output, &err);
	}
	if (status == PLUME_OK)
		printf("slope: %.10g Pa\n", result.slope);
	plume_traction_result_free(&result);
	return status == PLUME_OK ? CLI_EXIT_OK : cli_fail(&err);
}

// ---------------------------------------------------------------------------
// calibrate

static void print_spread(FILE *out, const char *name, const plume_modulus_spread *p, bool last)
{
	fprintf(out, "    \"%s\": {\"phase\": %s, \"width\": %s, \"mesh\": %s, \"total\": %s}%s\n", name,
	        number(p->phase).text, number(p->width).text, number(p->mesh).text, number(p->total).text, last ? "" : ",");
}

/// The calibration's JSON: moduli with their spreads, the slopes matched, the protocol that
/// produced them (docs/lab.md) and the counts. Every number as plume_lab_format_number
/// writes it, so that a sweep or a lab file takes the moduli and slopes bit for bit.
static void print_calibration(FILE *out, const plume_calibration_def *d, const plume_calibration_result *result)
{
	const plume_calibration_def def = *d;
	const plume_calibration_result r = *result;
	fprintf(out, "{\n  \"E_vv\": %s,\n  \"E_ww\": %s,\n  \"E_vw\": %s,\n", number(r.E_vv).text, number(r.E_ww).text,
	        number(r.E_vw).text);
	if (def.uncertainty) {
		fprintf(out, "  \"spread\": {\n");
		print_spread(out, "E_vv", &r.spread_vv, false);
		print_spread(out, "E_ww", &r.spread_ww, false);
		print_spread(out, "E_vw", &r.spread_vw, true);
		fprintf(out, "  },\n  \"sensitivity\": %s,\n", number(r.sensitivity).text);
	}
	fprintf(out,
	        "  \"slopes\": {\"longitudinal\": %s, \"transverse\": %s, \"tilted_mesoscale\": %s, "
	        "\"tilted_macroscale\": %s},\n",
	        number(r.slope_longitudinal).text, number(r.slope_transverse).text, number(r.slope_tilted).text,
	        number(r.slope_tilted_macroscale).text);
	fprintf(out,
	        "  \"phi\": %s,\n  \"E_b\": %s,\n  \"E_B\": %s,\n  \"aspect\": %s,\n  \"period\": %s,\n  \"phases\": %d,\n",
	        number(def.mesoscale.bands.barb_fraction).text, number(def.mesoscale.E_b).text,
	        number(def.mesoscale.E_B).text, number(def.aspect_ratio).text, number(def.mesoscale.bands.period).text,
	        def.phase_count);
	bool quadratic = !def.barb_constraint && def.macroscale_quadratic;
	fprintf(out,
	        "  \"protocol\": {\"name\": \"%s\", \"longitudinal_strain_max\": %s, \"transverse_strain_max\": %s, "
	        "\"tilted_strain_max\": %s, \"steps\": %d, \"compression_coefficient\": %s, \"barb_constraint\": %s, "
	        "\"macroscale_elements\": \"%s\", \"macroscale_element_count\": %d, \"mesoscale_element_count\": %d, "
	        "\"width\": %s, \"barbs_across\": %s, \"aspect\": %s, \"phases\": %d},\n",
	        plume_calibration_protocol_name(&def), number(def.longitudinal_strain_max).text,
	        number(def.transverse_strain_max).text, number(def.tilted_strain_max).text, def.steps,
	        number(def.mesoscale.compression_coefficient).text, def.barb_constraint ? "true" : "false",
	        quadratic ? "quadratic" : "linear", def.macroscale_elements, def.sample.element_count,
	        number(def.sample.width).text, number(def.sample.width / def.mesoscale.bands.period).text,
	        number(def.aspect_ratio).text, def.phase_count);
	fprintf(
	    out,
	    "  \"barb_constraint\": %s,\n  \"traction_tests\": %d,\n  \"solves\": %d,\n  \"bisection_iterations\": %d\n}\n",
	    def.barb_constraint ? "true" : "false", r.traction_count, r.solve_count, r.bisection_iterations);
}

/// DIR/curves.csv and the plots of the curves the calibration matched (r holds them).
static plume_status write_curves(cli_output *output, const plume_calibration_result *r, plume_error *err)
{
	char path[4352], svg[4352];
	const double *columns[8] = {r->curve_strain[0], r->curve_stress[0], r->curve_strain[1], r->curve_stress[1],
	                            r->curve_strain[2], r->curve_stress[2], r->curve_strain[3], r->curve_stress[3]};
	plume_status status = plume_lab_write_csv(
	    cli_output_path(output, "curves.csv", path, sizeof path),
	    "longitudinal_strain,longitudinal_stress_pa,transverse_strain,transverse_stress_pa,tilted_strain,"
	    "tilted_mesoscale_stress_pa,tilted_macroscale_strain,tilted_macroscale_stress_pa",
	    columns, 8, r->curve_samples, err);
	if (status != PLUME_OK)
		return status;
	int n = r->curve_samples;
	// The longitudinal test is a hundred times stiffer and forty times shorter: a plot of its own.
	double line_x[2] = {0.0, r->curve_strain[0][n - 1]};
	double line_y[2] = {0.0, r->slope_longitudinal * r->curve_strain[0][n - 1]};
	char fit[64];
	snprintf(fit, sizeof fit, "slope E#dvv#u = %.4g Pa", r->slope_longitudinal);
	plume_plot_series longitudinal[2] = {
	    {"mesoscale", r->curve_strain[0], r->curve_stress[0], n, true, false},
	    {fit, line_x, line_y, 2, false, true},
	};
	plume_plot plot = {
	    .title = "Calibration: longitudinal test",
	    .x_label = "measured strain #fi#ge#fn",
	    .y_label = "measured stress #fi#gs#fn [Pa]",
	    .series_count = 2,
	    .series = longitudinal,
	};
	status = plume_lab_plot(&plot, cli_output_path(output, "curves_longitudinal.png", path, sizeof path),
	                        cli_output_path(output, "curves_longitudinal.svg", svg, sizeof svg), err);
	if (status != PLUME_OK)
		return status;
	plume_plot_series tilted[3] = {
	    {"transverse, mesoscale", r->curve_strain[1], r->curve_stress[1], n, true, false},
	    {"tilted, barbs at 45 deg, mesoscale (mean over phases)", r->curve_strain[2], r->curve_stress[2], n, true,
	     false},
	    {"tilted, barbs at 45 deg, macroscale at the fitted E#dvw#u", r->curve_strain[3], r->curve_stress[3], n, false,
	     true},
	};
	plot.title = "Calibration: transverse and tilted tests";
	plot.series_count = 3;
	plot.series = tilted;
	return plume_lab_plot(&plot, cli_output_path(output, "curves_tilted.png", path, sizeof path),
	                      cli_output_path(output, "curves_tilted.svg", svg, sizeof svg), err);
}

/// -o DIR: DIR/calibration.json (what stdout shows), DIR/slopes.csv, DIR/curves.csv and the
/// curves' plots, together or not at all.
static int write_calibration(const char *dir, const plume_calibration_def *def, const plume_calibration_result *r)
{
	plume_error err = {0};
	cli_output output;
	plume_status status = cli_output_begin(&output, dir, &err);
	if (status != PLUME_OK)
		return cli_fail(&err);
	char path[4352];
	FILE *json = fopen(cli_output_path(&output, "calibration.json", path, sizeof path), "wb");
	if (json != NULL) {
		print_calibration(json, def, r);
		if (ferror(json) != 0 || fclose(json) != 0)
			status = plume_error_set(&err, PLUME_ERROR_IO, "%s: cannot write", path);
	} else {
		status = plume_error_set(&err, PLUME_ERROR_IO, "%s: cannot write", path);
	}
	FILE *csv = status == PLUME_OK ? fopen(cli_output_path(&output, "slopes.csv", path, sizeof path), "wb") : NULL;
	if (status == PLUME_OK && csv == NULL)
		status = plume_error_set(&err, PLUME_ERROR_IO, "%s: cannot write", path);
	if (csv != NULL) {
		// Each matched stress-strain slope (Pa) and the modulus it determines.
		fprintf(csv,
		        "test,model,slope_pa,determines\n"
		        "longitudinal,mesoscale,%s,E_vv\n"
		        "transverse,mesoscale,%s,E_ww\n"
		        "tilted,mesoscale,%s,target of E_vw\n"
		        "tilted,macroscale,%s,E_vw (matched to the mesoscale slope)\n",
		        number(r->slope_longitudinal).text, number(r->slope_transverse).text, number(r->slope_tilted).text,
		        number(r->slope_tilted_macroscale).text);
		if (ferror(csv) != 0 || fclose(csv) != 0)
			status = plume_error_set(&err, PLUME_ERROR_IO, "%s: cannot write", path);
	}
	if (status == PLUME_OK && r->curve_samples > 0)
		status = write_curves(&output, r, &err);
	if (status == PLUME_OK)
		status = cli_output_commit(&output, &err);
	else
		cli_output_abort(&output, &err);
	return status == PLUME_OK ? CLI_EXIT_OK : cli_fail(&err);
}

/// The largest magnitude of any number plume reads from a file (src/io/spec.h): a lab file's
/// E_B of 1e300 is refused, and so is the option's.
#define MAX_MAGNITUDE 1e12

#define FIELD(name) offsetof(plume_calibration_def, name)
const cli_calibrate_option cli_calibrate_options[CLI_CALIBRATE_OPTION_COUNT] = {
    {"phi", "--phi", "", NULL, false, 0.0, 1.0, false, false, FIELD(mesoscale.bands.barb_fraction)},
    {"Eb", "--Eb", " Pa", NULL, false, 0.0, MAX_MAGNITUDE, false, true, FIELD(mesoscale.E_b)},
    {"EB", "--EB", " Pa", NULL, false, 0.0, MAX_MAGNITUDE, false, true, FIELD(mesoscale.E_B)},
    {"compression", "--compression", " Pa", NULL, false, 0.0, MAX_MAGNITUDE, true, true,
     FIELD(mesoscale.compression_coefficient)},
    {"tilted_strain", "--tilted-strain", "", NULL, false, 0.0, 10.0, false, true, FIELD(tilted_strain_max)},
    {"width", "--width", " m", NULL, false, 1e-6, 10.0, true, true, FIELD(sample.width)},
    {"aspect", "--aspect", "", "the tilted sample's aspect ratio H/W", false, 1e-3, 1e3, true, true,
     FIELD(aspect_ratio)},
    // At most 10 m, the largest sample (--width): the period against the sample is checked below.
    {"period", "--period", " m", NULL, false, 0.0, 10.0, false, true, FIELD(mesoscale.bands.period)},
    {"elements", "--elements", "", NULL, true, 2.0, 4e6, true, true, FIELD(sample.element_count)},
    {"macro_elements", "--macro-elements", "", NULL, true, 2.0, 4e6, true, true, FIELD(macroscale_elements)},
    {"phases", "--phases", "", NULL, true, 1.0, 64.0, true, true, FIELD(phase_count)},
};
#undef FIELD

bool cli_calibrate_option_allows(const cli_calibrate_option *option, double value)
{
	bool above = option->lo_closed ? value >= option->lo : value > option->lo;
	bool below = option->hi_closed ? value <= option->hi : value < option->hi;
	return above && below && (!option->integer || value == floor(value));
}

void cli_calibrate_option_range(const cli_calibrate_option *option, char *text, size_t size)
{
	// %.10g: an integer's bound whole ("4000000", not %g's "4e+06").
	snprintf(text, size, "%c%.10g, %.10g%c", option->lo_closed ? '[' : '(', option->lo, option->hi,
	         option->hi_closed ? ']' : ')');
}

/// The value of a calibrate option in def.
static double option_value(const plume_calibration_def *def, const cli_calibrate_option *option)
{
	const char *field = (const char *)def + option->offset;
	if (option->integer) {
		int value;
		memcpy(&value, field, sizeof value);
		return value;
	}
	double value;
	memcpy(&value, field, sizeof value);
	return value;
}

/// The values of calibrate's options, each against what it is allowed alone
/// (cli_calibrate_options, which the sweep checks too) and then with the others (the tilted
/// sample, --width by --aspect x --width, must hold whole barbs that its mesh resolves): a
/// message naming the options. The library checks the same again (and what the options
/// cannot reach) in the names of plume_calibration_def's fields.
static plume_status check_calibrate_options(const plume_calibration_def *def, plume_error *err)
{
	for (int i = 0; i < CLI_CALIBRATE_OPTION_COUNT; ++i) {
		const cli_calibrate_option *option = &cli_calibrate_options[i];
		double value = option_value(def, option);
		if (!cli_calibrate_option_allows(option, value)) {
			char range[64];
			cli_calibrate_option_range(option, range, sizeof range);
			return plume_error_set(err, PLUME_ERROR_SPEC, "%s is %g%s%s%s, allowed in %s", option->option, value,
			                       option->unit, option->what != NULL ? ": " : "",
			                       option->what != NULL ? option->what : "", range);
		}
	}
	const double phi = def->mesoscale.bands.barb_fraction, period = def->mesoscale.bands.period;
	const double width = def->sample.width, aspect = def->aspect_ratio, height = aspect * width;
#define REQUIRE(condition, format, ...)                                                                                \
	if (!(condition))                                                                                                  \
		return plume_error_set(err, PLUME_ERROR_SPEC, format, __VA_ARGS__);
	REQUIRE(height >= 1e-6 && height <= 10.0,
	        "--aspect %g and --width %g m make the tilted sample %g m high, allowed in [1e-06, 10]", aspect, width,
	        height);
	REQUIRE(period <= fmin(width, height),
	        "--period is %g m, allowed in (0, %g]: at most the side of the tilted sample, %g m wide (--width) and %g m "
	        "high (--aspect x --width), so that it holds a whole barb",
	        period, fmin(width, height), width, height);
	// As plume_sample_validate: at most 100000 periods across, no band under 1e-6 of the larger side.
	REQUIRE((width + height) / period <= 1e5,
	        "--period is %g m, allowed >= %g m: at most 100000 periods across the %g x %g m tilted sample", period,
	        (width + height) / 1e5, width, height);
	double least = 1e-6 * fmax(width, height) / period;
	REQUIRE(phi >= least && phi <= 1.0 - least,
	        "--phi is %s, allowed in [%g, %g] at --period %g m: its %s bands would be %g m wide, narrower than a "
	        "millionth of the %g x %g m tilted sample",
	        number(phi).text, least, 1.0 - least, period, phi <= 0.5 ? "barb" : "barbule",
	        period * fmin(phi, 1.0 - phi), width, height);
#undef REQUIRE
	return PLUME_OK;
}

static int run_calibrate(int argc, char **argv)
{
	static const struct option options[] = {
	    {"phi", required_argument, NULL, 'p'},
	    {"Eb", required_argument, NULL, 'b'},
	    {"EB", required_argument, NULL, 'B'},
	    {"aspect", required_argument, NULL, 'a'},
	    {"period", required_argument, NULL, 'T'},
	    {"width", required_argument, NULL, 'w'},
	    {"elements", required_argument, NULL, 'e'},
	    {"macro-elements", required_argument, NULL, 'm'},
	    {"phases", required_argument, NULL, 'k'},
	    {"unconstrained", no_argument, NULL, 'u'},
	    {"tilted-strain", required_argument, NULL, 't'},
	    {"compression", required_argument, NULL, 'c'},
	    {"linear-macro", no_argument, NULL, 'l'},
	    {"no-uncertainty", no_argument, NULL, 'n'},
	    {"max-memory", required_argument, NULL, 'M'},
	    {"output", required_argument, NULL, 'o'},
	    {"help", no_argument, NULL, 'h'},
	    {NULL, 0, NULL, 0},
	};
	plume_calibration_def def = plume_calibration_default_def();
	bool phi_given = false, Eb_given = false, EB_given = false;
	uint64_t max_memory = 0;
	const char *output_dir = NULL;
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:h", options, NULL)) != -1) {
		bool ok = true;
		switch (option) {
		case 'p':
			ok = parse_double("--phi", optarg, &def.mesoscale.bands.barb_fraction);
			phi_given = true;
			break;
		case 'b':
			ok = parse_double("--Eb", optarg, &def.mesoscale.E_b);
			Eb_given = true;
			break;
		case 'B':
			ok = parse_double("--EB", optarg, &def.mesoscale.E_B);
			EB_given = true;
			break;
		case 'a': ok = parse_double("--aspect", optarg, &def.aspect_ratio); break;
		case 'T': ok = parse_double("--period", optarg, &def.mesoscale.bands.period); break;
		case 'w': ok = parse_double("--width", optarg, &def.sample.width); break;
		case 'e': ok = parse_int("--elements", optarg, &def.sample.element_count); break;
		case 'm': ok = parse_int("--macro-elements", optarg, &def.macroscale_elements); break;
		case 'k': ok = parse_int("--phases", optarg, &def.phase_count); break;
		case 'u': def.barb_constraint = false; break;
		case 't': ok = parse_double("--tilted-strain", optarg, &def.tilted_strain_max); break;
		case 'c': ok = parse_double("--compression", optarg, &def.mesoscale.compression_coefficient); break;
		case 'l': def.macroscale_quadratic = false; break;
		case 'n': def.uncertainty = false; break;
		case 'M': ok = cli_parse_memory("lab", optarg, &max_memory); break;
		case 'o': output_dir = optarg; break;
		case 'h': cli_help_lab(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("lab", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("lab", "unknown option '%s'", argv[optind - 1]);
		}
		if (!ok)
			return CLI_EXIT_USAGE;
	}
	if (optind < argc)
		return cli_usage_error("lab", "unexpected argument '%s'", argv[optind]);
	if (!phi_given || !Eb_given || !EB_given)
		return cli_usage_error("lab", "calibrate needs --phi, --Eb and --EB");
	plume_error err = {0};
	if (check_calibrate_options(&def, &err) != PLUME_OK)
		return cli_fail(&err);
	char what[160];
	snprintf(what, sizeof what, "--elements %d and --macro-elements %d (%s)", def.sample.element_count,
	         def.macroscale_elements, def.uncertainty ? "twice the larger for the spreads" : "the larger");
	int code = check_memory(plume_calibration_estimate_bytes(&def), max_memory, what);
	if (code != CLI_EXIT_OK)
		return code;
	plume_calibration_result r;
	cli_progress progress;
	cli_progress_begin(&progress, "lab calibrate", 1);
	def.progress = cli_progress_callback;
	def.progress_user = &progress;
	def.keep_curves = output_dir != NULL;
	plume_status status = plume_lab_calibrate(&def, &r, &err);
	cli_progress_end(&progress);
	if (status != PLUME_OK)
		return cli_fail(&err);
	print_calibration(stdout, &def, &r);
	code = output_dir != NULL ? write_calibration(output_dir, &def, &r) : CLI_EXIT_OK;
	plume_calibration_result_free(&r);
	return code;
}

// ---------------------------------------------------------------------------
// study

static int run_study(int argc, char **argv)
{
	static const struct option options[] = {{"output", required_argument, NULL, 'o'},
	                                        {"scale", required_argument, NULL, 's'},
	                                        {"max-memory", required_argument, NULL, 'M'},
	                                        {"help", no_argument, NULL, 'h'},
	                                        {NULL, 0, NULL, 0}};
	const char *output_dir = NULL;
	plume_study_def def = plume_study_default_def(PLUME_STUDY_LOCKING);
	double scale = 1.0;
	uint64_t max_memory = 0;
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 's':
			if (!parse_double("--scale", optarg, &scale))
				return CLI_EXIT_USAGE;
			break;
		case 'M':
			if (!cli_parse_memory("lab", optarg, &max_memory))
				return CLI_EXIT_USAGE;
			break;
		case 'h': cli_help_lab(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("lab", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("lab", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (optind >= argc)
		return cli_usage_error("lab", "missing the study: locking, conditioning, angles, size or bending");
	if (optind + 1 < argc)
		return cli_usage_error("lab", "unexpected argument '%s'", argv[optind + 1]);
	const char *name = argv[optind];
	plume_study_kind kind;
	if (!plume_study_kind_from_name(name, &kind))
		return cli_usage_error("lab", "unknown study '%s': locking, conditioning, angles, size or bending", name);
	if (output_dir == NULL)
		return cli_usage_error("lab", "missing -o DIR");
	if (!(scale > 0.0 && scale <= 16.0))
		return cli_usage_error("lab", "--scale is %g, allowed in (0, 16]", scale);
	def = plume_study_default_def(kind);
	def.scale = scale;
	char what[96];
	snprintf(what, sizeof what, "--scale %g (16000 x %g elements)", scale, scale);
	int code = check_memory(plume_study_estimate_bytes(&def), max_memory, what);
	if (code != CLI_EXIT_OK)
		return code;
	plume_error err = {0};
	cli_output output;
	plume_status status = cli_output_begin(&output, output_dir, &err);
	if (status != PLUME_OK)
		return cli_fail(&err);
	char stage_csv[4352], stage_png[4352], stage_svg[4352], file[64];
	snprintf(file, sizeof file, "%s.csv", name);
	cli_output_path(&output, file, stage_csv, sizeof stage_csv);
	snprintf(file, sizeof file, "%s.png", name);
	cli_output_path(&output, file, stage_png, sizeof stage_png);
	snprintf(file, sizeof file, "%s.svg", name);
	cli_output_path(&output, file, stage_svg, sizeof stage_svg);
	char summary[1024];
	cli_progress progress;
	cli_progress_begin(&progress, "lab study", 1);
	def.progress = cli_progress_callback;
	def.progress_user = &progress;
	status = plume_lab_study(&def, stage_csv, stage_png, stage_svg, summary, sizeof summary, &err);
	cli_progress_end(&progress);
	if (status == PLUME_OK)
		status = cli_output_commit(&output, &err);
	else
		cli_output_abort(&output, &err);
	if (status != PLUME_OK)
		return cli_fail(&err);
	printf("%s\n", summary);
	return CLI_EXIT_OK;
}

int cli_lab(int argc, char **argv)
{
	// argv[0] is "lab"; argv[1] the action.
	if (argc < 2)
		return cli_usage_error("lab", "missing the action: traction, calibrate or study");
	const char *action = argv[1];
	if (strcmp(action, "--help") == 0 || strcmp(action, "-h") == 0) {
		cli_help_lab();
		return CLI_EXIT_OK;
	}
	if (strcmp(action, "traction") == 0)
		return run_traction(argc - 1, argv + 1);
	if (strcmp(action, "calibrate") == 0)
		return run_calibrate(argc - 1, argv + 1);
	if (strcmp(action, "study") == 0)
		return run_study(argc - 1, argv + 1);
	return cli_usage_error("lab", "unknown action '%s': traction, calibrate or study", action);
}

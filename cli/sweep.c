// plume sweep SWEEP.json -o DIR [-j N]: many runs of one command over parameters.
//
// The sweep is process-level orchestration, so it lives in the CLI, not in libplume:
// each run is the plume binary itself (/proc/self/exe) started on a modified copy of
// the base spec, in its own folder, so that a crash, an abort or a non-converging run
// is isolated and recorded as a row instead of stopping the sweep. The library never
// forks, prints or exits; the CLI may. With MPI (PLUME_WITH_MPI) the same runs are
// handed to ranks: rank 0 schedules, the others run (docs/sweeps.md).
//
// Determinism: the rows of DIR/results.csv depend only on the sweep (values, seeds,
// outputs), never on the worker count, the rank count or the order runs finish in:
// rows are kept in index order and the per-run timings go to DIR/timings.csv instead.
#define _GNU_SOURCE
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <ftw.h>
#include <getopt.h>
#include <jansson.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#ifdef PLUME_WITH_MPI
#include <mpi.h>
#endif

#include "cli.h"
#include "plume/lab.h"

// Paths and messages are cut at their buffers' sizes (PATH_MAX-long folder names
// would make every buffer several pages); a cut message is still a message.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wformat-truncation"
#endif

void cli_help_sweep(void)
{
	puts("Usage: plume sweep SWEEP.json -o DIR [-j N] [--dry-run]\n"
	     "       mpirun -n N plume sweep SWEEP.json -o DIR\n"
	     "\n"
	     "Runs one plume command (generate, mesh, coat, simulate, lab traction, lab\n"
	     "calibrate, render frames) many times over values of its spec named by JSON\n"
	     "path: grids, lists, seeded random samples (uniform, normal, log-normal,\n"
	     "truncated) or the rows of another sweep's results.csv.\n"
	     "Each run is a separate plume process: a failing run is recorded with its\n"
	     "message and the sweep goes on. docs/sweeps.md describes the sweep file.\n"
	     "\n"
	     "Writes DIR/results.csv (index, parameters, outputs, status, message; in index\n"
	     "order and the same bytes for any -j or rank count), DIR/timings.csv (seconds per\n"
	     "run), DIR/sweep.json (the sweep, plume's version, the seed), DIR/stats.json\n"
	     "(mean, std, 5/50/95 percentiles of each output) and DIR/plots/*.png (each\n"
	     "output against each parameter; histograms of random sweeps). Started again\n"
	     "on the same DIR, a sweep runs only the runs results.csv lacks.\n"
	     "\n"
	     "  -o, --output DIR       output folder (required)\n"
	     "  -j, --jobs N           runs at once on this machine (default 1)\n"
	     "      --dry-run          check the sweep and print each run's parameter values\n"
	     "                         (CSV) without running anything or writing DIR\n"
	     "  -h, --help             this help\n"
	     "\n"
	     "Under mpirun or srun (plume built with MPI) rank 0 schedules and every other\n"
	     "rank runs one run at a time."
#ifdef PLUME_WITH_MPI
	     " This plume was built with MPI."
#else
	     " This plume was built without MPI."
#endif
	);
}

// ---------------------------------------------------------------------------
// Commands a sweep can run

typedef enum probe_kind {
	PROBE_FEATHER,
	PROBE_MESH,
	PROBE_COAT,
	PROBE_SCENE,
	PROBE_LAB,
	PROBE_CALIBRATION,
	PROBE_RENDER
} probe_kind;

typedef struct sweep_command {
	const char *name;
	const char *words[2]; ///< the command line words before the spec
	probe_kind probe;
	/// File (in the run's output folder) whose JSON holds the outputs; "stdout" for
	/// a command that prints its result; NULL for none.
	const char *result;
	/// Keys that file has (dotted paths into it); NULL-terminated.
	const char *const *outputs;
} sweep_command;

// These lists follow what each command writes (cli/simulate.c write_summary,
// cli/lab.c write_traction and run_calibrate, cli/mesh.c write_report,
// Zhang & Kanai's summary); tests/cli/sweep.sh checks every key against a real run.
static const char *const simulate_outputs[] = {"completed",
                                               "steps",
                                               "frames",
                                               "time",
                                               "newton_iterations",
                                               "newton_iterations_per_step",
                                               "retried_steps",
                                               "wall_seconds",
                                               "seconds_assembly",
                                               "seconds_factorization",
                                               "seconds_solve",
                                               "max_barb_strain",
                                               "rachis_tip_deflection",
                                               "vertices",
                                               "faces",
                                               "barb_constraints",
                                               "mesh_min_angle_deg",
                                               "mesh_aligned_fraction",
                                               "mesh_guides_dropped",
                                               NULL};
static const char *const traction_outputs[] = {"slope_pa",       "strain_max",     "steps",       "newton_iterations",
                                               "lateral_strain", "barb_angle_deg", "compression", NULL};
static const char *const calibrate_outputs[] = {"E_vv",
                                                "E_ww",
                                                "E_vw",
                                                "slopes.longitudinal",
                                                "slopes.transverse",
                                                "slopes.tilted_mesoscale",
                                                "slopes.tilted_macroscale",
                                                "traction_tests",
                                                "solves",
                                                "bisection_iterations",
                                                NULL};
static const char *const mesh_outputs[] = {
    "edge_length",   "vertex_count",     "face_count",     "rachis_face_count", "vane_face_count",  "barb_edge_count",
    "min_angle_deg", "aligned_fraction", "guides_dropped", "barbs_averaged",    "vertices_trimmed", NULL};
static const char *const no_outputs[] = {NULL};

static const sweep_command sweep_commands[] = {
    {"generate", {"generate", NULL}, PROBE_FEATHER, NULL, no_outputs},
    {"mesh", {"mesh", NULL}, PROBE_MESH, "report.json", mesh_outputs},
    {"coat", {"coat", NULL}, PROBE_COAT, NULL, no_outputs},
    {"simulate", {"simulate", NULL}, PROBE_SCENE, "summary.json", simulate_outputs},
    {"lab traction", {"lab", "traction"}, PROBE_LAB, "traction.json", traction_outputs},
    {"lab calibrate", {"lab", "calibrate"}, PROBE_CALIBRATION, "stdout", calibrate_outputs},
    {"render frames", {"render", NULL}, PROBE_RENDER, NULL, no_outputs},
};

// Rendering a simulation's frames in ranges: the spec names the simulation folder, the
// one output folder every range writes into, and the range of each run.
static const char *const render_keys[] = {"description", "simulation", "output", "first",  "count",
                                          "step",        "spp",        "size",   "format", NULL};
enum { SWEEP_COMMAND_COUNT = sizeof sweep_commands / sizeof sweep_commands[0] };

// The calibration has no spec file: its spec is an object of the command's options.
typedef struct calibration_key {
	const char *key;
	const char *option;
	bool integer;
	double lo; ///< allowed values: (lo, hi), integers >= lo
	double hi;
} calibration_key;

static const calibration_key calibration_keys[] = {
    {"phi", "--phi", false, 0.0, 1.0},
    {"Eb", "--Eb", false, 0.0, INFINITY},
    {"EB", "--EB", false, 0.0, INFINITY},
    {"aspect", "--aspect", false, 0.0, INFINITY},
    {"period", "--period", false, 0.0, INFINITY},
    {"width", "--width", false, 0.0, INFINITY},
    {"elements", "--elements", true, 1.0, 1e8},
    {"macro_elements", "--macro-elements", true, 1.0, 1e8},
    {"phases", "--phases", true, 1.0, 1e8},
};
enum { CALIBRATION_KEY_COUNT = sizeof calibration_keys / sizeof calibration_keys[0] };

// ---------------------------------------------------------------------------
// The sweep

typedef enum dist_kind { DIST_NONE, DIST_UNIFORM, DIST_NORMAL, DIST_LOGNORMAL } dist_kind;

typedef struct sweep_param {
	char path[256]; ///< "$.material.barb_fraction"
	char name[256]; ///< "material.barb_fraction", the CSV column
	json_t *values; ///< grid or list: an array of values
	dist_kind dist;
	double a, b;   ///< uniform: [a, b]; normal: mean, std; log-normal: mean and std of ln x
	double lo, hi; ///< truncation (or -inf, inf)
	bool integer;  ///< random values rounded to integers
	int zip_lead;  ///< columns of one CSV go together: the first such parameter; -1 for others
} sweep_param;

typedef struct sweep {
	const char *file;
	char base_dir[PATH_MAX];
	const sweep_command *command;
	json_t *root; ///< the sweep file
	json_t *spec; ///< the base spec, paths made absolute
	json_t *arguments;
	sweep_param params[32];
	int param_count;
	int random_count;
	int samples;
	uint64_t seed;
	char outputs[32][128];
	int output_count;
	bool keep_runs;
	int grid_count; ///< product of the grid/list lengths
	int run_count;
} sweep;

static bool sweep_error(const sweep *s, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static bool sweep_error(const sweep *s, const char *format, ...)
{
	va_list args;
	va_start(args, format);
	fprintf(stderr, "plume: %s: ", s->file);
	vfprintf(stderr, format, args);
	fputc('\n', stderr);
	va_end(args);
	return false;
}

static size_t edit_distance(const char *a, const char *b)
{
	size_t n = strlen(a), m = strlen(b);
	size_t *row = malloc((m + 1) * sizeof *row);
	if (row == NULL)
		return SIZE_MAX;
	for (size_t j = 0; j <= m; ++j)
		row[j] = j;
	for (size_t i = 1; i <= n; ++i) {
		size_t diagonal = row[0];
		row[0] = i;
		for (size_t j = 1; j <= m; ++j) {
			size_t above = row[j];
			size_t best = diagonal + (a[i - 1] != b[j - 1]);
			if (above + 1 < best)
				best = above + 1;
			if (row[j - 1] + 1 < best)
				best = row[j - 1] + 1;
			row[j] = best;
			diagonal = above;
		}
	}
	size_t d = row[m];
	free(row);
	return d;
}

// JSON paths: "$" followed by ".key" and "[index]" parts.

/// The value at path in root and its parent (for replacement); NULL when absent.
/// *settable: the path names a key the parent object lacks (a key left to its default).
static json_t *path_lookup(json_t *root, const char *path, json_t **parent, char *key, size_t key_size, size_t *index,
                           bool *settable)
{
	*settable = false;
	if (path[0] != '$')
		return NULL;
	json_t *node = root;
	const char *p = path + 1;
	while (*p != '\0') {
		*parent = node;
		if (*p == '.') {
			++p;
			size_t length = strcspn(p, ".[");
			if (length == 0 || length >= key_size || !json_is_object(node))
				return NULL;
			memcpy(key, p, length);
			key[length] = '\0';
			node = json_object_get(node, key);
			p += length;
			*settable = node == NULL && *p == '\0';
		} else if (*p == '[') {
			char *end = NULL;
			long i = strtol(p + 1, &end, 10);
			if (end == p + 1 || *end != ']' || i < 0 || !json_is_array(node))
				return NULL;
			key[0] = '\0';
			*index = (size_t)i;
			node = json_array_get(node, (size_t)i);
			p = end + 1;
		} else
			return NULL;
		if (node == NULL)
			return NULL;
	}
	return node;
}

static bool path_set(json_t *root, const char *path, json_t *value)
{
	json_t *parent = NULL;
	char key[256];
	size_t index = 0;
	bool settable;
	if ((path_lookup(root, path, &parent, key, sizeof key, &index, &settable) == NULL && !settable) || parent == NULL) {
		json_decref(value);
		return false;
	}
	if (json_is_object(parent))
		return json_object_set_new(parent, key, value) == 0;
	return json_array_set_new(parent, index, value) == 0;
}

/// The scalar path in root nearest to path (for "did you mean").
static void nearest_path(const json_t *node, const char *prefix, const char *path, char *best, size_t *best_distance)
{
	char child[512];
	if (json_is_object(node)) {
		const char *key;
		json_t *value;
		json_object_foreach ((json_t *)node, key, value) {
			snprintf(child, sizeof child, "%s.%s", prefix, key);
			nearest_path(value, child, path, best, best_distance);
		}
	} else if (json_is_array(node)) {
		size_t i;
		json_t *value;
		json_array_foreach (node, i, value) {
			snprintf(child, sizeof child, "%s[%zu]", prefix, i);
			nearest_path(value, child, path, best, best_distance);
		}
	} else {
		size_t d = edit_distance(prefix, path);
		if (d < *best_distance) {
			*best_distance = d;
			snprintf(best, 512, "%s", prefix);
		}
	}
}

/// Strings of the base spec that name existing files relative to its folder become
/// absolute, so the copy each run reads from its own folder still finds them.
static void absolutize_paths(json_t *node, const char *dir)
{
	if (json_is_object(node)) {
		const char *key;
		json_t *value;
		json_object_foreach (node, key, value) {
			if (json_is_string(value)) {
				const char *text = json_string_value(value);
				char candidate[PATH_MAX * 2], resolved[PATH_MAX];
				if (text[0] == '\0' || text[0] == '/')
					continue;
				snprintf(candidate, sizeof candidate, "%s/%s", dir, text);
				struct stat info;
				if (strchr(text, '/') == NULL && strchr(text, '.') == NULL)
					continue; // a word like "orthotropic", not a file name
				if (stat(candidate, &info) == 0 && S_ISREG(info.st_mode) && realpath(candidate, resolved) != NULL)
					json_object_set_new(node, key, json_string(resolved));
			} else
				absolutize_paths(value, dir);
		}
	} else if (json_is_array(node)) {
		size_t i;
		json_t *value;
		json_array_foreach (node, i, value)
			absolutize_paths(value, dir);
	}
}

/// Field k of a CSV line into out (quotes removed); false when the line is shorter.
static bool csv_field(const char *line, int k, char *out, size_t size)
{
	int field = 0;
	bool quoted = false;
	size_t n = 0;
	for (const char *c = line;; ++c) {
		if (*c == '"') {
			if (quoted && c[1] == '"' && field == k && n + 1 < size)
				out[n++] = *++c;
			else
				quoted = !quoted;
		} else if ((*c == ',' && !quoted) || *c == '\n' || *c == '\r' || *c == '\0') {
			if (field == k) {
				out[n] = '\0';
				return true;
			}
			++field;
			if (*c != ',')
				return false;
		} else if (field == k && n + 1 < size)
			out[n++] = *c;
	}
}

/// A column of another sweep's results.csv (its rows with status ok) as the values of p.
static bool read_column(const sweep *s, sweep_param *p, const json_t *item, const char *where, json_t *target)
{
	const char *file = json_string_value(json_object_get(item, "from_csv"));
	const char *column = json_string_value(json_object_get(item, "column"));
	if (file == NULL || column == NULL)
		return sweep_error(s, "%s: \"from_csv\" (a file name) and \"column\" (a header name) go together", where);
	char path[PATH_MAX * 2];
	if (file[0] == '/')
		snprintf(path, sizeof path, "%s", file);
	else
		snprintf(path, sizeof path, "%s/%s", s->base_dir, file);
	FILE *stream = fopen(path, "r");
	if (stream == NULL)
		return sweep_error(s, "%s.from_csv: %s: %s", where, path, strerror(errno));
	char *line = NULL;
	size_t capacity = 0;
	int value_column = -1, status_column = -1;
	char field[256];
	bool ok = getline(&line, &capacity, stream) > 0;
	for (int k = 0; ok && csv_field(line, k, field, sizeof field); ++k) {
		if (strcmp(field, column) == 0)
			value_column = k;
		if (strcmp(field, "status") == 0)
			status_column = k;
	}
	if (value_column < 0) {
		free(line);
		fclose(stream);
		return sweep_error(s, "%s.column: %s has no column \"%s\"", where, path, column);
	}
	p->values = json_array();
	int row = 1;
	while (getline(&line, &capacity, stream) > 0) {
		++row;
		if (status_column >= 0 && (!csv_field(line, status_column, field, sizeof field) || strcmp(field, "ok") != 0))
			continue;
		char *end = NULL;
		double x = csv_field(line, value_column, field, sizeof field) ? strtod(field, &end) : NAN;
		if (end == field || end == NULL || *end != '\0' || !isfinite(x)) {
			free(line);
			fclose(stream);
			return sweep_error(s, "%s: %s line %d: column %s is '%s', not a number", where, path, row, column, field);
		}
		bool whole = p->integer || (json_is_integer(target) && x == floor(x));
		json_array_append_new(p->values, whole ? json_integer((json_int_t)llround(x)) : json_real(x));
	}
	free(line);
	fclose(stream);
	if (json_array_size(p->values) == 0)
		return sweep_error(s, "%s: %s has no rows with status ok", where, path);
	return true;
}

static bool read_number(const sweep *s, const json_t *object, const char *where, const char *key, double *out,
                        bool required)
{
	json_t *value = json_object_get(object, key);
	if (value == NULL) {
		if (required)
			return sweep_error(s, "%s lacks \"%s\"", where, key);
		return true;
	}
	if (!json_is_number(value) || !isfinite(json_number_value(value)))
		return sweep_error(s, "%s.%s must be a number", where, key);
	*out = json_number_value(value);
	return true;
}

static bool check_keys(const sweep *s, const json_t *object, const char *where, const char *const *allowed)
{
	const char *key;
	json_t *value;
	json_object_foreach ((json_t *)object, key, value) {
		size_t best = SIZE_MAX;
		const char *nearest = NULL;
		for (int i = 0; allowed[i] != NULL; ++i) {
			if (strcmp(allowed[i], key) == 0) {
				best = 0;
				break;
			}
			size_t d = edit_distance(allowed[i], key);
			if (d < best) {
				best = d;
				nearest = allowed[i];
			}
		}
		if (best != 0)
			return sweep_error(s, "%s.%s is not a sweep key; did you mean \"%s\"?", where, key, nearest);
	}
	return true;
}

static bool parse_param(sweep *s, const json_t *item, int index)
{
	static const char *const keys[] = {"path", "values",   "grid",    "distribution", "min",      "max",    "mean",
	                                   "std",  "log_mean", "log_std", "integer",      "from_csv", "column", NULL};
	char where[64];
	snprintf(where, sizeof where, "$.parameters[%d]", index);
	if (!json_is_object(item))
		return sweep_error(s, "%s must be an object", where);
	if (!check_keys(s, item, where, keys))
		return false;
	sweep_param *p = s->params + index;
	memset(p, 0, sizeof *p);
	p->lo = -INFINITY;
	p->hi = INFINITY;
	p->zip_lead = -1;
	const char *path = json_string_value(json_object_get(item, "path"));
	if (path == NULL || path[0] != '$' || strlen(path) >= sizeof p->path)
		return sweep_error(s, "%s.path must be a JSON path such as \"$.material.barb_fraction\"", where);
	snprintf(p->path, sizeof p->path, "%s", path);
	snprintf(p->name, sizeof p->name, "%s", path[1] == '.' ? path + 2 : path + 1);
	for (int q = 0; q < index; ++q)
		if (strcmp(s->params[q].path, p->path) == 0)
			return sweep_error(s, "%s.path %s is already swept by $.parameters[%d]", where, path, q);
	json_t *parent = NULL;
	char key[256];
	size_t array_index;
	bool settable = false;
	json_t *target = path_lookup(s->spec, path, &parent, key, sizeof key, &array_index, &settable);
	// A key the base spec leaves to its default may be swept; the spec's own reader
	// (sweep_check) then says whether the key exists.
	if ((target == NULL && !settable) || parent == NULL) {
		char best[512] = "$";
		size_t distance = SIZE_MAX;
		nearest_path(s->spec, "$", path, best, &distance);
		return sweep_error(s, "%s.path: %s is not in the base spec; the nearest path there is %s", where, path, best);
	}
	if (target != NULL && (json_is_object(target) || json_is_array(target)))
		return sweep_error(s, "%s.path: %s is an %s; sweep a number, a string or a boolean in it", where, path,
		                   json_is_object(target) ? "object" : "array");
	json_t *integer = json_object_get(item, "integer");
	if (integer != NULL && !json_is_boolean(integer))
		return sweep_error(s, "%s.integer must be true or false", where);
	p->integer = json_is_true(integer);
	json_t *values = json_object_get(item, "values");
	json_t *grid = json_object_get(item, "grid");
	json_t *dist = json_object_get(item, "distribution");
	json_t *from_csv = json_object_get(item, "from_csv");
	if ((values != NULL) + (grid != NULL) + (dist != NULL) + (from_csv != NULL) != 1)
		return sweep_error(s, "%s needs exactly one of \"values\", \"grid\", \"distribution\" and \"from_csv\"", where);
	if (from_csv != NULL) {
		if (!read_column(s, p, item, where, target))
			return false;
		// Columns of one file are read row by row together, not crossed.
		json_t *all = json_object_get(s->root, "parameters");
		for (int q = 0; q < index && p->zip_lead < 0; ++q)
			if (s->params[q].zip_lead >= 0 &&
			    json_equal(json_object_get(json_array_get(all, (size_t)q), "from_csv"), from_csv)) {
				p->zip_lead = s->params[q].zip_lead;
				if (json_array_size(s->params[q].values) != json_array_size(p->values))
					return sweep_error(s, "%s: its column has %zu rows, $.parameters[%d]'s %zu", where,
					                   json_array_size(p->values), q, json_array_size(s->params[q].values));
			}
		if (p->zip_lead < 0)
			p->zip_lead = index;
	} else if (values != NULL) {
		if (!json_is_array(values) || json_array_size(values) == 0)
			return sweep_error(s, "%s.values must be a non-empty array", where);
		size_t i;
		json_t *v;
		json_array_foreach (values, i, v) {
			if (!(json_is_number(v) || json_is_string(v) || json_is_boolean(v)))
				return sweep_error(s, "%s.values[%zu] must be a number, a string or a boolean", where, i);
		}
		p->values = json_deep_copy(values);
	} else if (grid != NULL) {
		static const char *const grid_keys[] = {"from", "to", "count", NULL};
		char grid_where[80];
		snprintf(grid_where, sizeof grid_where, "%s.grid", where);
		if (!json_is_object(grid))
			return sweep_error(s, "%s must be an object {\"from\", \"to\", \"count\"}", grid_where);
		double from = 0, to = 0, count = 0;
		if (!check_keys(s, grid, grid_where, grid_keys) || !read_number(s, grid, grid_where, "from", &from, true) ||
		    !read_number(s, grid, grid_where, "to", &to, true) ||
		    !read_number(s, grid, grid_where, "count", &count, true))
			return false;
		if (count != floor(count) || count < 1 || count > 100000)
			return sweep_error(s, "%s.count is %g, allowed a whole number in [1, 100000]", grid_where, count);
		p->values = json_array();
		for (int k = 0; k < (int)count; ++k) {
			double v = count == 1 ? from : from + (to - from) * k / (count - 1);
			if (k == (int)count - 1)
				v = to; // the end exactly, whatever the rounding of the steps
			// Whole numbers stay integers where the base spec has one (a count, a seed).
			bool whole = p->integer || (json_is_integer(target) && v == floor(v));
			json_array_append_new(p->values, whole ? json_integer((json_int_t)llround(v)) : json_real(v));
		}
	} else {
		const char *name = json_string_value(dist);
		if (name == NULL)
			return sweep_error(s, "%s.distribution must be \"uniform\", \"normal\" or \"lognormal\"", where);
		if (target != NULL && !json_is_number(target))
			return sweep_error(s, "%s: %s is not a number in the base spec; only numbers take a distribution", where,
			                   path);
		if (!read_number(s, item, where, "min", &p->lo, false) || !read_number(s, item, where, "max", &p->hi, false))
			return false;
		if (strcmp(name, "uniform") == 0) {
			p->dist = DIST_UNIFORM;
			if (!isfinite(p->lo) || !isfinite(p->hi) || !(p->lo < p->hi))
				return sweep_error(s, "%s: uniform needs \"min\" < \"max\"", where);
			p->a = p->lo;
			p->b = p->hi;
		} else if (strcmp(name, "normal") == 0) {
			p->dist = DIST_NORMAL;
			if (!read_number(s, item, where, "mean", &p->a, true) || !read_number(s, item, where, "std", &p->b, true))
				return false;
		} else if (strcmp(name, "lognormal") == 0) {
			p->dist = DIST_LOGNORMAL;
			// Either the mean and std of the value, or of its logarithm.
			double mean = NAN, std = NAN;
			if (!read_number(s, item, where, "mean", &mean, false) ||
			    !read_number(s, item, where, "std", &std, false) ||
			    !read_number(s, item, where, "log_mean", &p->a, false) ||
			    !read_number(s, item, where, "log_std", &p->b, false))
				return false;
			if (!isnan(mean) || !isnan(std)) {
				if (!(mean > 0) || !(std > 0))
					return sweep_error(s, "%s: lognormal needs \"mean\" > 0 and \"std\" > 0", where);
				// ln x ~ N(mu, sigma) has mean exp(mu + sigma^2/2) and variance (exp(sigma^2) - 1) mean^2.
				double sigma2 = log1p(std * std / (mean * mean));
				p->b = sqrt(sigma2);
				p->a = log(mean) - 0.5 * sigma2;
			}
			if (p->lo < 0)
				p->lo = 0.0;
		} else
			return sweep_error(s, "%s.distribution is \"%s\"; allowed \"uniform\", \"normal\", \"lognormal\"", where,
			                   name);
		if (p->dist != DIST_UNIFORM && !(p->b > 0))
			return sweep_error(s, "%s: the standard deviation must be > 0", where);
		if (!(p->lo < p->hi))
			return sweep_error(s, "%s: \"min\" must be below \"max\"", where);
		s->random_count++;
	}
	return true;
}

/// Whether parameter i is a dimension of the grid (zipped columns share their first's).
static bool owns_dimension(const sweep_param *p, int i)
{
	return p->values != NULL && (p->zip_lead < 0 || p->zip_lead == i);
}

static bool output_known(const sweep_command *command, const char *key)
{
	for (int i = 0; command->outputs[i] != NULL; ++i)
		if (strcmp(command->outputs[i], key) == 0)
			return true;
	return false;
}

static bool sweep_load(sweep *s, const char *file)
{
	static const char *const keys[] = {"description", "command", "spec",    "arguments", "parameters",
	                                   "samples",     "seed",    "outputs", "keep_runs", NULL};
	memset(s, 0, sizeof *s);
	s->file = file;
	json_error_t jerr;
	s->root = json_load_file(file, JSON_REJECT_DUPLICATES, &jerr);
	if (s->root == NULL) {
		fprintf(stderr, "plume: %s:%d:%d: %s\n", file, jerr.line, jerr.column, jerr.text);
		return false;
	}
	if (!json_is_object(s->root))
		return sweep_error(s, "the top level must be an object");
	if (!check_keys(s, s->root, "$", keys))
		return false;
	char copy[PATH_MAX];
	snprintf(copy, sizeof copy, "%s", file);
	char *slash = strrchr(copy, '/');
	snprintf(s->base_dir, sizeof s->base_dir, "%s",
	         slash == NULL ? "." : (slash == copy ? "/" : (*slash = '\0', copy)));
	// Absolute: runs start in their own folders.
	char absolute[PATH_MAX];
	if (realpath(s->base_dir, absolute) != NULL)
		snprintf(s->base_dir, sizeof s->base_dir, "%s", absolute);

	const char *name = json_string_value(json_object_get(s->root, "command"));
	for (int i = 0; name != NULL && i < SWEEP_COMMAND_COUNT; ++i)
		if (strcmp(sweep_commands[i].name, name) == 0)
			s->command = sweep_commands + i;
	if (s->command == NULL) {
		fprintf(stderr, "plume: %s: $.command is %s%s%s; allowed", file, name ? "\"" : "", name ? name : "missing",
		        name ? "\"" : "");
		for (int i = 0; i < SWEEP_COMMAND_COUNT; ++i)
			fprintf(stderr, "%s \"%s\"", i ? "," : "", sweep_commands[i].name);
		fputc('\n', stderr);
		return false;
	}

	// The base spec: a file (relative to the sweep file) or an object.
	json_t *spec = json_object_get(s->root, "spec");
	char spec_dir[PATH_MAX];
	snprintf(spec_dir, sizeof spec_dir, "%s", s->base_dir);
	if (json_is_string(spec)) {
		char path[PATH_MAX * 2];
		const char *text = json_string_value(spec);
		if (text[0] == '/')
			snprintf(path, sizeof path, "%s", text);
		else
			snprintf(path, sizeof path, "%s/%s", s->base_dir, text);
		s->spec = json_load_file(path, JSON_REJECT_DUPLICATES, &jerr);
		if (s->spec == NULL)
			return sweep_error(s, "$.spec: %s:%d:%d: %s", path, jerr.line, jerr.column, jerr.text);
		char *cut = strrchr(path, '/');
		*cut = '\0';
		snprintf(spec_dir, sizeof spec_dir, "%s", path);
	} else if (json_is_object(spec))
		s->spec = json_deep_copy(spec);
	else
		return sweep_error(s, "$.spec must be a spec file name (relative to the sweep) or an object");
	if (!json_is_object(s->spec))
		return sweep_error(s, "$.spec: the base spec's top level must be an object");
	absolutize_paths(s->spec, spec_dir);
	if (s->command->probe == PROBE_RENDER) {
		// Folders, relative to the spec's folder (the sweep file's for an inline spec).
		static const char *const folders[] = {"simulation", "output"};
		for (int i = 0; i < 2; ++i) {
			const char *text = json_string_value(json_object_get(s->spec, folders[i]));
			if (text == NULL)
				return sweep_error(s, "$.spec.%s: a folder name is needed", folders[i]);
			if (text[0] != '/') {
				char joined[PATH_MAX * 2];
				snprintf(joined, sizeof joined, "%s/%s", spec_dir, text);
				json_object_set_new(s->spec, folders[i], json_string(joined));
			}
		}
	}
	if (s->command->probe == PROBE_CALIBRATION) {
		const char *key;
		json_t *value;
		json_object_foreach (s->spec, key, value) {
			bool known = strcmp(key, "unconstrained") == 0 || strcmp(key, "description") == 0;
			for (int i = 0; i < CALIBRATION_KEY_COUNT; ++i)
				known = known || strcmp(calibration_keys[i].key, key) == 0;
			if (!known)
				return sweep_error(s,
				                   "$.spec.%s is not a calibration option (phi, Eb, EB, aspect, period, width, "
				                   "elements, macro_elements, phases, unconstrained)",
				                   key);
		}
	}

	s->arguments = json_object_get(s->root, "arguments");
	if (s->arguments != NULL) {
		size_t i;
		json_t *v;
		if (!json_is_array(s->arguments))
			return sweep_error(s, "$.arguments must be an array of strings");
		json_array_foreach (s->arguments, i, v)
			if (!json_is_string(v))
				return sweep_error(s, "$.arguments[%zu] must be a string", i);
	}

	json_t *params = json_object_get(s->root, "parameters");
	if (!json_is_array(params) || json_array_size(params) == 0 || json_array_size(params) > 32)
		return sweep_error(s, "$.parameters must be an array of 1 to 32 parameters");
	s->param_count = (int)json_array_size(params);
	for (int i = 0; i < s->param_count; ++i)
		if (!parse_param(s, json_array_get(params, (size_t)i), i))
			return false;

	double samples = s->random_count > 0 ? 0 : 1, seed = 1;
	if (!read_number(s, s->root, "$", "samples", &samples, false) ||
	    !read_number(s, s->root, "$", "seed", &seed, false))
		return false;
	if (s->random_count > 0 && json_object_get(s->root, "samples") == NULL)
		return sweep_error(s, "$.samples is needed: parameters with a distribution draw that many samples");
	if (samples != floor(samples) || samples < 1 || samples > 1000000)
		return sweep_error(s, "$.samples is %g, allowed a whole number in [1, 1000000]", samples);
	if (seed != floor(seed) || seed < 0 || seed > 9007199254740992.0)
		return sweep_error(s, "$.seed is %g, allowed a whole number in [0, 2^53]", seed);
	s->samples = (int)samples;
	s->seed = (uint64_t)seed;
	double runs = samples;
	for (int i = 0; i < s->param_count; ++i)
		if (owns_dimension(s->params + i, i))
			runs *= (double)json_array_size(s->params[i].values);
	if (runs > 1000000)
		return sweep_error(s, "the sweep has %.0f runs; at most 1000000", runs);
	s->run_count = (int)runs;
	s->grid_count = s->run_count / s->samples;

	json_t *outputs = json_object_get(s->root, "outputs");
	if (outputs != NULL) {
		if (!json_is_array(outputs) || json_array_size(outputs) > 32)
			return sweep_error(s, "$.outputs must be an array of at most 32 output keys");
		s->output_count = (int)json_array_size(outputs);
		for (int i = 0; i < s->output_count; ++i) {
			const char *key = json_string_value(json_array_get(outputs, (size_t)i));
			if (key == NULL || strlen(key) >= sizeof s->outputs[i])
				return sweep_error(s, "$.outputs[%d] must be a key name", i);
			if (!output_known(s->command, key)) {
				if (s->command->outputs[0] == NULL)
					return sweep_error(s, "$.outputs[%d]: %s writes no outputs to collect; only status", i,
					                   s->command->name);
				fprintf(stderr, "plume: %s: $.outputs[%d]: no %s run produces \"%s\"; %s writes:", file, i,
				        s->command->name, key, s->command->name);
				for (int k = 0; s->command->outputs[k] != NULL; ++k)
					fprintf(stderr, "%s %s", k ? "," : "", s->command->outputs[k]);
				fputc('\n', stderr);
				return false;
			}
			snprintf(s->outputs[i], sizeof s->outputs[i], "%s", key);
		}
	}
	json_t *keep = json_object_get(s->root, "keep_runs");
	if (keep != NULL && !json_is_boolean(keep))
		return sweep_error(s, "$.keep_runs must be true or false");
	s->keep_runs = json_is_true(keep);
	return true;
}

static void sweep_free(sweep *s)
{
	for (int i = 0; i < s->param_count; ++i)
		json_decref(s->params[i].values);
	json_decref(s->spec);
	json_decref(s->root);
}

// ---------------------------------------------------------------------------
// Values of a run

/// Standard normal by Box-Muller from two uniforms of the parameter's own stream.
static double normal_sample(plume_rng *rng)
{
	double u1 = 1.0 - plume_rng_uniform(rng); // (0, 1]
	double u2 = plume_rng_uniform(rng);
	return sqrt(-2.0 * log(u1)) * cos(2.0 * 3.14159265358979323846 * u2);
}

/// Probability mass of [lo, hi] under the parameter's distribution (before truncation).
static double param_mass(const sweep_param *p)
{
	double lo = p->lo, hi = p->hi;
	if (p->dist == DIST_UNIFORM)
		return 1.0;
	if (p->dist == DIST_LOGNORMAL) {
		lo = lo > 0 ? log(lo) : -INFINITY;
		hi = isfinite(hi) ? log(hi) : INFINITY;
	}
	double zl = (lo - p->a) / p->b, zh = (hi - p->a) / p->b;
	return 0.5 * (erfc(-zh / sqrt(2.0)) - erfc(-zl / sqrt(2.0)));
}

/// The random value of parameter p for sample k: every sample has its own stream (seeded
/// from the sweep's seed and k) and every parameter its own split of it, so a value
/// depends on the seed, the sample and the parameter only — not on the order runs are
/// handed out, the worker count or the rank count. Truncation by rejection.
static double random_value(const sweep *s, int param, int sample)
{
	plume_rng base = plume_rng_seed(s->seed ^ (0x9E3779B97F4A7C15ull * ((uint64_t)sample + 1)));
	plume_rng rng = plume_rng_split(&base);
	for (int i = 0; i <= param; ++i)
		rng = plume_rng_split(&base);
	const sweep_param *p = s->params + param;
	for (int attempt = 0; attempt < 1000000; ++attempt) {
		double x;
		switch (p->dist) {
		case DIST_UNIFORM: x = plume_rng_range(&rng, p->a, p->b); break;
		case DIST_NORMAL: x = p->a + p->b * normal_sample(&rng); break;
		default: x = exp(p->a + p->b * normal_sample(&rng)); break;
		}
		if (p->integer)
			x = (double)llround(x);
		if (x >= p->lo && x <= p->hi)
			return x;
	}
	return p->dist == DIST_UNIFORM ? p->a : fmin(fmax(p->a, p->lo), p->hi); // unreachable: mass is checked
}

/// Value of parameter p in run index (new reference).
static json_t *run_value(const sweep *s, int param, int index)
{
	int sample = index % s->samples;
	int grid = index / s->samples;
	const sweep_param *p = s->params + param;
	if (p->values == NULL) {
		double x = random_value(s, param, sample);
		return p->integer ? json_integer((json_int_t)x) : json_real(x);
	}
	// The first grid/list parameter varies slowest.
	int lead = p->zip_lead >= 0 ? p->zip_lead : param;
	int stride = 1;
	for (int q = s->param_count - 1; q > lead; --q)
		if (owns_dimension(s->params + q, q))
			stride *= (int)json_array_size(s->params[q].values);
	size_t k = (size_t)(grid / stride) % json_array_size(p->values);
	return json_deep_copy(json_array_get(p->values, k));
}

/// CSV text of a scalar: numbers to 17 digits (they round-trip), strings quoted when needed.
static void csv_value(char *out, size_t size, const json_t *value)
{
	if (json_is_integer(value))
		snprintf(out, size, "%lld", (long long)json_integer_value(value));
	else if (json_is_real(value)) {
		// The shortest of 15, 16, 17 digits that reads back as the same double.
		double x = json_real_value(value);
		for (int digits = 15; digits <= 17; ++digits) {
			snprintf(out, size, "%.*g", digits, x);
			if (strtod(out, NULL) == x)
				break;
		}
	} else if (json_is_true(value))
		snprintf(out, size, "true");
	else if (json_is_false(value))
		snprintf(out, size, "false");
	else if (json_is_string(value)) {
		const char *text = json_string_value(value);
		if (strpbrk(text, ",\"\n\r") == NULL)
			snprintf(out, size, "%s", text);
		else {
			size_t n = 0;
			if (size > 0)
				out[n++] = '"';
			for (const char *c = text; *c != '\0' && n + 3 < size; ++c) {
				char ch = (*c == '\n' || *c == '\r') ? ' ' : *c;
				if (ch == '"')
					out[n++] = '"';
				out[n++] = ch;
			}
			out[n++] = '"';
			out[n] = '\0';
		}
	} else if (size > 0)
		out[0] = '\0';
}

/// The spec of run index (new reference).
static json_t *run_spec(const sweep *s, int index)
{
	json_t *spec = json_deep_copy(s->spec);
	for (int p = 0; p < s->param_count; ++p)
		path_set(spec, s->params[p].path, run_value(s, p, index));
	return spec;
}

// ---------------------------------------------------------------------------
// Checks before any run: each value a run will see must pass the command's own
// spec reader (which names the JSON path and the allowed range).

static bool probe_spec(const sweep *s, json_t *spec, char *message, size_t size)
{
	plume_error err = {0};
	plume_status status = PLUME_OK;
	if (s->command->probe == PROBE_CALIBRATION) {
		const char *name;
		json_t *value;
		json_object_foreach (spec, name, value) {
			size_t best = strcmp(name, "unconstrained") == 0 || strcmp(name, "description") == 0 ? 0 : SIZE_MAX;
			const char *nearest = "phi";
			for (int i = 0; i < CALIBRATION_KEY_COUNT && best != 0; ++i) {
				size_t d = edit_distance(calibration_keys[i].key, name);
				if (d < best) {
					best = d;
					nearest = calibration_keys[i].key;
				}
			}
			if (best != 0) {
				snprintf(message, size, "$.%s: not a calibration option; did you mean \"%s\"?", name, nearest);
				return false;
			}
		}
		for (int i = 0; i < CALIBRATION_KEY_COUNT; ++i) {
			const calibration_key *k = calibration_keys + i;
			json_t *v = json_object_get(spec, k->key);
			if (v == NULL)
				continue;
			double x = json_number_value(v);
			bool ok = json_is_number(v) &&
			          (k->integer ? (x == floor(x) && x >= k->lo && x <= k->hi) : (x > k->lo && x < k->hi));
			if (!ok) {
				if (k->integer)
					snprintf(message, size, "$.%s is %.10g, allowed a whole number >= %g", k->key, x, k->lo);
				else if (isinf(k->hi))
					snprintf(message, size, "$.%s is %.10g, allowed > %g", k->key, x, k->lo);
				else
					snprintf(message, size, "$.%s is %.10g, allowed in (%g, %g)", k->key, x, k->lo, k->hi);
				return false;
			}
		}
		static const char *const needed[] = {"phi", "Eb", "EB"};
		for (int i = 0; i < 3; ++i)
			if (json_object_get(spec, needed[i]) == NULL) {
				snprintf(message, size, "the calibration needs $.%s", needed[i]);
				return false;
			}
		return true;
	}
	if (s->command->probe == PROBE_RENDER) {
		const char *name;
		json_t *value;
		json_object_foreach (spec, name, value) {
			bool known = false;
			for (int i = 0; render_keys[i] != NULL; ++i)
				known = known || strcmp(render_keys[i], name) == 0;
			if (!known) {
				snprintf(message, size,
				         "$.%s: not a render frames key (simulation, output, first, count, step, spp, size, format)",
				         name);
				return false;
			}
		}
		static const char *const counts[] = {"first", "count", "step", "spp"};
		for (int i = 0; i < 4; ++i) {
			json_t *v = json_object_get(spec, counts[i]);
			double lo = i == 0 ? 0 : 1;
			if ((v != NULL || i < 2) && !(json_is_integer(v) && json_integer_value(v) >= lo)) {
				snprintf(message, size, "$.%s must be a whole number >= %g", counts[i], lo);
				return false;
			}
		}
		struct stat info;
		const char *sim = json_string_value(json_object_get(spec, "simulation"));
		if (sim == NULL || stat(sim, &info) != 0 || !S_ISDIR(info.st_mode)) {
			snprintf(message, size, "$.simulation: %s is not a simulation folder", sim ? sim : "(none)");
			return false;
		}
		return true;
	}
	char path[] = "/tmp/plume-sweep-probe-XXXXXX.json";
	int fd = mkstemps(path, 5);
	if (fd < 0) {
		snprintf(message, size, "cannot write a temporary file: %s", strerror(errno));
		return false;
	}
	close(fd);
	if (json_dump_file(spec, path, JSON_INDENT(1) | JSON_REAL_PRECISION(17)) != 0) {
		unlink(path);
		snprintf(message, size, "cannot write a temporary file");
		return false;
	}
	plume_spec_options options = {0};
	switch (s->command->probe) {
	case PROBE_FEATHER: {
		plume_feather *feather = NULL;
		status = plume_spec_generate(path, &options, &feather, &err);
		plume_feather_destroy(feather);
		break;
	}
	case PROBE_MESH: {
		plume_mesh *mesh = NULL;
		plume_mesh_report report;
		plume_mesh_spec_options mesh_options = plume_mesh_spec_default_options();
		status = plume_mesh_spec_read(path, &mesh_options, &mesh, &report, &err);
		plume_mesh_destroy(mesh);
		break;
	}
	case PROBE_COAT: {
		plume_coat *coat = NULL;
		status = plume_coat_spec_generate(path, &options, &coat, &err);
		plume_coat_destroy(coat);
		break;
	}
	case PROBE_SCENE: {
		plume_scene *scene = NULL;
		status = plume_scene_load(path, &options, &scene, &err);
		plume_scene_destroy(scene);
		break;
	}
	case PROBE_LAB: {
		plume_lab_spec lab;
		status = plume_lab_spec_load(path, &lab, &err);
		break;
	}
	default: break;
	}
	unlink(path);
	if (status == PLUME_OK)
		return true;
	// "/tmp/plume-sweep-probe-XXXX.json: $.x: ..." -> "$.x: ..."
	const char *text = err.message;
	if (strncmp(text, path, strlen(path)) == 0) {
		text += strlen(path);
		while (*text == ':' || *text == ' ')
			++text;
	}
	snprintf(message, size, "%s", text);
	return false;
}

/// Every grid/list value, and the ends of every distribution's range, through the reader.
static bool sweep_check(const sweep *s)
{
	char message[1024];
	json_t *first = run_spec(s, 0);
	bool ok = probe_spec(s, first, message, sizeof message);
	json_decref(first);
	if (!ok)
		return sweep_error(s, "the first run's spec is refused: %s", message);
	for (int p = 0; p < s->param_count; ++p) {
		const sweep_param *param = s->params + p;
		json_t *probes = json_array();
		const json_t *item = json_array_get(json_object_get(s->root, "parameters"), (size_t)p);
		size_t count = param->values != NULL ? json_array_size(param->values) : 0;
		if (json_object_get(item, "grid") != NULL) {
			// A grid is an interval: its ends, and one inside value (which may be a
			// fraction where the ends are whole), stand for all; a scene's reader
			// generates and meshes the feather, so each check costs.
			json_array_append(probes, json_array_get(param->values, 0));
			if (count > 2)
				json_array_append(probes, json_array_get(param->values, 1));
			if (count > 1)
				json_array_append(probes, json_array_get(param->values, count - 1));
		} else if (param->values != NULL) {
			for (size_t k = 0; k < count; ++k)
				json_array_append(probes, json_array_get(param->values, k));
		} else {
			// The ends of the range the samples can reach; an unbounded side of a
			// normal is checked 10 standard deviations out (probability 8e-24).
			double lo = param->lo, hi = param->hi;
			if (param->dist == DIST_NORMAL) {
				lo = fmax(lo, param->a - 10 * param->b);
				hi = fmin(hi, param->a + 10 * param->b);
			} else if (param->dist == DIST_LOGNORMAL) {
				lo = fmax(lo, exp(param->a - 10 * param->b));
				hi = fmin(hi, exp(param->a + 10 * param->b));
			}
			if (param_mass(param) < 1e-3)
				return sweep_error(s,
				                   "$.parameters[%d]: [min, max] holds %.2g of the distribution's probability; "
				                   "at least 1e-3 is needed",
				                   p, param_mass(param));
			json_array_append_new(probes, param->integer ? json_integer((json_int_t)ceil(lo)) : json_real(lo));
			json_array_append_new(probes, param->integer ? json_integer((json_int_t)floor(hi)) : json_real(hi));
		}
		for (size_t k = 0; k < json_array_size(probes); ++k) {
			json_t *spec = run_spec(s, 0);
			json_t *value = json_array_get(probes, k);
			path_set(spec, param->path, json_incref(value));
			ok = probe_spec(s, spec, message, sizeof message);
			json_decref(spec);
			if (!ok) {
				char text[128];
				csv_value(text, sizeof text, value);
				if (param->values != NULL)
					sweep_error(s, "$.parameters[%d] (%s): the value %s is refused: %s", p, param->path, text, message);
				else
					sweep_error(s,
					            "$.parameters[%d] (%s): the distribution reaches %s, which is refused: %s; "
					            "bound it with \"min\"/\"max\"%s",
					            p, param->path, text, message,
					            param->dist == DIST_NORMAL ? " or use \"lognormal\" for a positive value" : "");
				json_decref(probes);
				return false;
			}
		}
		json_decref(probes);
	}
	return true;
}

// ---------------------------------------------------------------------------
// Running one run: a child plume process in DIR/runs/NNNNNN

static int remove_entry(const char *path, const struct stat *info, int flag, struct FTW *ftw)
{
	(void)info;
	(void)flag;
	(void)ftw;
	return remove(path);
}

static void remove_tree(const char *path) { nftw(path, remove_entry, 16, FTW_DEPTH | FTW_PHYS); }

static void run_dir(const char *dir, int index, char *out, size_t size)
{
	snprintf(out, size, "%s/runs/%06d", dir, index);
}

static double now_seconds(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/// Writes the run's spec and starts plume on it; the pid, or -1 (message in row).
static pid_t run_start(const sweep *s, const char *dir, int index, char *failure, size_t size)
{
	char folder[PATH_MAX], path[PATH_MAX + 32];
	run_dir(dir, index, folder, sizeof folder);
	remove_tree(folder); // what a killed attempt left
	snprintf(path, sizeof path, "%s/runs", dir);
	mkdir(path, 0777);
	if (mkdir(folder, 0777) != 0) {
		snprintf(failure, size, "cannot create %s: %s", folder, strerror(errno));
		return -1;
	}
	json_t *spec = run_spec(s, index);
	snprintf(path, sizeof path, "%s/spec.json", folder);
	int failed = json_dump_file(spec, path, JSON_INDENT(2) | JSON_REAL_PRECISION(17));
	json_decref(spec);
	if (failed != 0) {
		snprintf(failure, size, "cannot write %s", path);
		return -1;
	}
	// The command line; relative names, so that messages do not depend on DIR.
	char *args[64];
	static char values[CALIBRATION_KEY_COUNT][64];
	int n = 0;
	args[n++] = "plume";
	for (int i = 0; i < 2 && s->command->words[i] != NULL; ++i)
		args[n++] = (char *)s->command->words[i];
	if (s->command->probe == PROBE_CALIBRATION) {
		json_t *run = run_spec(s, index);
		for (int i = 0; i < CALIBRATION_KEY_COUNT; ++i) {
			json_t *v = json_object_get(run, calibration_keys[i].key);
			if (v == NULL)
				continue;
			snprintf(values[i], sizeof values[i], "%.17g", json_number_value(v));
			args[n++] = (char *)calibration_keys[i].option;
			args[n++] = values[i];
		}
		if (json_is_true(json_object_get(run, "unconstrained")))
			args[n++] = "--unconstrained";
		json_decref(run);
	} else if (s->command->probe == PROBE_RENDER) {
		json_t *run = run_spec(s, index);
		static char render_args[5][PATH_MAX + 64];
		long long first = json_integer_value(json_object_get(run, "first"));
		long long count = json_integer_value(json_object_get(run, "count"));
		json_t *step_value = json_object_get(run, "step");
		long long step = step_value != NULL ? json_integer_value(step_value) : 1;
		snprintf(render_args[0], sizeof render_args[0], "%s", json_string_value(json_object_get(run, "simulation")));
		snprintf(render_args[1], sizeof render_args[1], "%s", json_string_value(json_object_get(run, "output")));
		snprintf(render_args[2], sizeof render_args[2], "%lld:%lld:%lld", first, first + (count - 1) * step, step);
		args[n++] = render_args[0];
		args[n++] = "-o";
		args[n++] = render_args[1];
		args[n++] = "--frames";
		args[n++] = render_args[2];
		if (json_object_get(run, "spp") != NULL) {
			snprintf(render_args[3], sizeof render_args[3], "%lld",
			         (long long)json_integer_value(json_object_get(run, "spp")));
			args[n++] = "--spp";
			args[n++] = render_args[3];
		}
		if (json_is_string(json_object_get(run, "size"))) {
			snprintf(render_args[4], sizeof render_args[4], "%s", json_string_value(json_object_get(run, "size")));
			args[n++] = "--size";
			args[n++] = render_args[4];
		}
		if (json_is_string(json_object_get(run, "format"))) {
			static char format[64];
			snprintf(format, sizeof format, "%s", json_string_value(json_object_get(run, "format")));
			args[n++] = "-f";
			args[n++] = format;
		}
		json_decref(run);
	} else {
		args[n++] = "spec.json";
		args[n++] = "-o";
		args[n++] = "out";
	}
	for (size_t i = 0; s->arguments != NULL && i < json_array_size(s->arguments) && n < 62; ++i)
		args[n++] = (char *)json_string_value(json_array_get(s->arguments, i));
	args[n] = NULL;
	fflush(NULL);
	pid_t pid = fork();
	if (pid < 0) {
		snprintf(failure, size, "cannot start a run: %s", strerror(errno));
		return -1;
	}
	if (pid == 0) {
		// The run dies with the sweep: a killed sweep leaves no run writing behind it.
		prctl(PR_SET_PDEATHSIG, SIGKILL);
		if (chdir(folder) != 0)
			_exit(127);
		int out = open("stdout.txt", O_WRONLY | O_CREAT | O_TRUNC, 0666);
		int errfd = open("stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0666);
		int null = open("/dev/null", O_RDONLY);
		if (out < 0 || errfd < 0 || null < 0)
			_exit(127);
		dup2(null, 0);
		dup2(out, 1);
		dup2(errfd, 2);
		// One thread a run: parallelism comes from the runs, and results do not
		// depend on the thread count anyway.
		setenv("OMP_NUM_THREADS", "1", 0);
		execv("/proc/self/exe", args);
		_exit(127);
	}
	return pid;
}

/// The output at a dotted key in root, as CSV text (empty when absent).
static void output_value(const json_t *root, const char *key, char *out, size_t size)
{
	char copy[128];
	snprintf(copy, sizeof copy, "%s", key);
	const json_t *node = root;
	for (char *part = strtok(copy, "."); part != NULL && node != NULL; part = strtok(NULL, "."))
		node = json_is_object(node) ? json_object_get(node, part) : NULL;
	csv_value(out, size, node);
}

/// The last non-empty line of a file, without "plume: ".
static void last_line(const char *path, char *out, size_t size)
{
	out[0] = '\0';
	FILE *file = fopen(path, "r");
	if (file == NULL)
		return;
	char line[2048];
	while (fgets(line, sizeof line, file) != NULL) {
		line[strcspn(line, "\r\n")] = '\0';
		if (line[0] != '\0' && strncmp(line, "Try 'plume", 10) != 0)
			snprintf(out, size, "%s", strncmp(line, "plume: ", 7) == 0 ? line + 7 : line);
	}
	fclose(file);
}

typedef enum row_status { ROW_OK, ROW_FAILED, ROW_SIGNAL } row_status;
static const char *const row_status_names[] = {"ok", "failed", "signal"};

/// The CSV row of a finished run (wait_status from waitpid; pid < 0: it never started).
static char *run_finish(const sweep *s, const char *dir, int index, pid_t pid, int wait_status, const char *failure)
{
	char folder[PATH_MAX], path[PATH_MAX + 64], message[1024] = "";
	run_dir(dir, index, folder, sizeof folder);
	row_status status = ROW_OK;
	if (pid < 0) {
		status = ROW_FAILED;
		snprintf(message, sizeof message, "%s", failure);
	} else if (WIFSIGNALED(wait_status)) {
		status = ROW_SIGNAL;
		snprintf(message, sizeof message, "killed by signal %d (%s)", WTERMSIG(wait_status),
		         strsignal(WTERMSIG(wait_status)));
	} else if (!WIFEXITED(wait_status) || WEXITSTATUS(wait_status) != 0) {
		status = ROW_FAILED;
		snprintf(path, sizeof path, "%s/stderr.txt", folder);
		char line[1000];
		last_line(path, line, sizeof line);
		snprintf(message, sizeof message, "exit %d: %s", WEXITSTATUS(wait_status), line);
	}
	// The outputs (a failed simulation still writes its summary up to the failure).
	json_t *result = NULL;
	if (pid >= 0 && s->command->result != NULL) {
		if (strcmp(s->command->result, "stdout") == 0)
			snprintf(path, sizeof path, "%s/stdout.txt", folder);
		else
			snprintf(path, sizeof path, "%s/out/%s", folder, s->command->result);
		result = json_load_file(path, 0, NULL);
	}
	size_t capacity = 4096 + (size_t)(s->param_count + s->output_count) * 160;
	char *row = malloc(capacity);
	if (row == NULL) {
		json_decref(result);
		return NULL;
	}
	size_t n = (size_t)snprintf(row, capacity, "%d", index);
	char text[256];
	for (int p = 0; p < s->param_count; ++p) {
		json_t *value = run_value(s, p, index);
		csv_value(text, sizeof text, value);
		json_decref(value);
		n += (size_t)snprintf(row + n, capacity - n, ",%s", text);
	}
	for (int o = 0; o < s->output_count; ++o) {
		output_value(result, s->outputs[o], text, sizeof text);
		n += (size_t)snprintf(row + n, capacity - n, ",%s", text);
	}
	json_t *message_json = json_string(message);
	char quoted[1100];
	csv_value(quoted, sizeof quoted, message_json);
	json_decref(message_json);
	snprintf(row + n, capacity - n, ",%s,%s\n", row_status_names[status], quoted);
	json_decref(result);
	if (!s->keep_runs && pid >= 0)
		remove_tree(folder);
	return row;
}

// ---------------------------------------------------------------------------
// DIR: sweep.json, results.csv (rewritten whole, atomically, as rows arrive), timings.csv

typedef struct sweep_state {
	const sweep *s;
	const char *dir;
	char **rows; ///< per index, NULL until done
	int done;
	char header[8192];
} sweep_state;

static bool write_atomic(const char *path, const char *const *parts, int count)
{
	char temp[PATH_MAX + 16];
	snprintf(temp, sizeof temp, "%s.tmp", path);
	FILE *file = fopen(temp, "wb");
	if (file == NULL)
		return false;
	bool ok = true;
	for (int i = 0; i < count; ++i)
		if (parts[i] != NULL && fputs(parts[i], file) < 0)
			ok = false;
	ok = fflush(file) == 0 && ok;
	ok = fsync(fileno(file)) == 0 && ok;
	ok = fclose(file) == 0 && ok;
	if (ok && rename(temp, path) != 0)
		ok = false;
	if (!ok)
		unlink(temp);
	return ok;
}

static bool write_results(sweep_state *state)
{
	char path[PATH_MAX + 32];
	snprintf(path, sizeof path, "%s/results.csv", state->dir);
	const sweep *s = state->s;
	const char **parts = malloc(sizeof *parts * ((size_t)s->run_count + 1));
	if (parts == NULL)
		return false;
	parts[0] = state->header;
	for (int i = 0; i < s->run_count; ++i)
		parts[i + 1] = state->rows[i];
	bool ok = write_atomic(path, parts, s->run_count + 1);
	free(parts);
	if (!ok)
		fprintf(stderr, "plume: %s: cannot write: %s\n", path, strerror(errno));
	return ok;
}

static void record_timing(const sweep_state *state, int index, double seconds, int worker)
{
	char path[PATH_MAX + 32], line[128];
	snprintf(path, sizeof path, "%s/timings.csv", state->dir);
	int fd = open(path, O_WRONLY | O_CREAT | O_APPEND, 0666);
	if (fd < 0)
		return;
	int n = snprintf(line, sizeof line, "%d,%.3f,%d\n", index, seconds, worker);
	if (write(fd, line, (size_t)n) != n) {
		// timings are informative; a failed write loses one line only
	}
	close(fd);
}

static bool record_row(sweep_state *state, int index, char *row)
{
	if (row == NULL)
		return false;
	free(state->rows[index]);
	state->rows[index] = row;
	state->done++;
	return write_results(state);
}

/// The sweep document written to DIR/sweep.json: what ran, with which plume.
static char *sweep_document(const sweep *s)
{
	json_t *doc = json_object();
	json_object_set_new(doc, "plume_version", json_string(PLUME_VERSION_STRING));
	json_object_set(doc, "sweep", s->root);
	json_object_set(doc, "base_spec", s->spec);
	json_object_set_new(doc, "seed", json_integer((json_int_t)s->seed));
	json_object_set_new(doc, "runs", json_integer(s->run_count));
	char *text = json_dumps(doc, JSON_INDENT(2) | JSON_SORT_KEYS | JSON_REAL_PRECISION(17));
	json_decref(doc);
	return text;
}

/// Splits a CSV line into its first field (the index) and its status field.
static bool parse_row(const char *line, int field_count, int *index, char *status, size_t size)
{
	char *end = NULL;
	long i = strtol(line, &end, 10);
	if (end == line || *end != ',')
		return false;
	*index = (int)i;
	int field = 0;
	bool quoted = false;
	const char *start = line;
	for (const char *c = line;; ++c) {
		if (*c == '"')
			quoted = !quoted;
		else if ((*c == ',' && !quoted) || *c == '\n' || *c == '\0') {
			if (field == field_count - 2) {
				size_t length = (size_t)(c - start);
				if (length >= size)
					return false;
				memcpy(status, start, length);
				status[length] = '\0';
			}
			++field;
			start = c + 1;
			if (*c != ',')
				break;
		}
	}
	return field == field_count;
}

/// Creates DIR or, when it holds this same sweep, reads the rows already done.
/// False after a message; *code says why (CLI_EXIT_INPUT: DIR holds another sweep).
static bool state_begin(int *code, sweep_state *state, const sweep *s, const char *dir)
{
	memset(state, 0, sizeof *state);
	state->s = s;
	state->dir = dir;
	state->rows = calloc((size_t)s->run_count, sizeof *state->rows);
	if (state->rows == NULL)
		return false;
	size_t n = (size_t)snprintf(state->header, sizeof state->header, "index");
	for (int p = 0; p < s->param_count; ++p)
		n += (size_t)snprintf(state->header + n, sizeof state->header - n, ",%s", s->params[p].name);
	for (int o = 0; o < s->output_count; ++o)
		n += (size_t)snprintf(state->header + n, sizeof state->header - n, ",%s", s->outputs[o]);
	snprintf(state->header + n, sizeof state->header - n, ",status,message\n");
	int field_count = 1 + s->param_count + s->output_count + 2;

	char path[PATH_MAX + 32];
	char *document = sweep_document(s);
	if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
		fprintf(stderr, "plume: %s: cannot create: %s\n", dir, strerror(errno));
		free(document);
		return false;
	}
	// One sweep at a time in DIR: the lock goes with the process, however it ends.
	snprintf(path, sizeof path, "%s/.sweep.lock", dir);
	int lock = open(path, O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
	if (lock < 0 || flock(lock, LOCK_EX | LOCK_NB) != 0) {
		fprintf(stderr, "plume: %s: another plume sweep is running in this folder\n", dir);
		if (lock >= 0)
			close(lock);
		free(document);
		*code = CLI_EXIT_IO;
		return false;
	}
	snprintf(path, sizeof path, "%s/sweep.json", dir);
	FILE *file = fopen(path, "rb");
	if (file != NULL) {
		// A resumed sweep: it must be the same sweep.
		char *existing = malloc(strlen(document) + 2);
		size_t got = existing ? fread(existing, 1, strlen(document) + 1, file) : 0;
		fclose(file);
		bool same = existing != NULL && got == strlen(document) + 1 && existing[got - 1] == '\n' &&
		            memcmp(existing, document, got - 1) == 0;
		free(existing);
		if (!same) {
			fprintf(stderr,
			        "plume: %s holds another sweep (its sweep.json differs): resume only with the same sweep, "
			        "spec and plume version, or choose another folder\n",
			        dir);
			free(document);
			*code = CLI_EXIT_INPUT;
			return false;
		}
		snprintf(path, sizeof path, "%s/results.csv", dir);
		file = fopen(path, "rb");
		if (file != NULL) {
			char *line = NULL;
			size_t capacity = 0;
			ssize_t length = getline(&line, &capacity, file);
			if (length < 0 || strcmp(line, state->header) != 0) {
				fprintf(stderr, "plume: %s: the header is not this sweep's\n", path);
				free(line);
				fclose(file);
				free(document);
				return false;
			}
			while ((length = getline(&line, &capacity, file)) > 0) {
				int index;
				char status[16];
				// A run killed by a signal may have been killed from outside: run it again.
				if (parse_row(line, field_count, &index, status, sizeof status) && index >= 0 && index < s->run_count &&
				    state->rows[index] == NULL && strcmp(status, "signal") != 0) {
					state->rows[index] = strdup(line);
					state->done++;
				}
			}
			free(line);
			fclose(file);
		}
	} else {
		const char *parts[2] = {document, "\n"};
		if (!write_atomic(path, parts, 2)) {
			fprintf(stderr, "plume: %s: cannot write: %s\n", path, strerror(errno));
			free(document);
			return false;
		}
	}
	free(document);
	return write_results(state);
}

static void state_end(sweep_state *state)
{
	for (int i = 0; state->rows != NULL && i < state->s->run_count; ++i)
		free(state->rows[i]);
	free(state->rows);
}

// ---------------------------------------------------------------------------
// Statistics and plots, once every run is done

static int compare_doubles(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/// Percentile q in [0, 1] of sorted values, interpolated linearly between order statistics.
static double percentile(const double *sorted, int n, double q)
{
	double h = (n - 1) * q;
	int i = (int)floor(h);
	if (i >= n - 1)
		return sorted[n - 1];
	return sorted[i] + (h - i) * (sorted[i + 1] - sorted[i]);
}

/// Field k of a CSV row as a number (NAN when empty or not a number).
static double row_number(const char *row, int k)
{
	int field = 0;
	bool quoted = false;
	const char *start = row;
	for (const char *c = row;; ++c) {
		if (*c == '"')
			quoted = !quoted;
		else if ((*c == ',' && !quoted) || *c == '\n' || *c == '\0') {
			if (field == k) {
				char *end = NULL;
				double x = strtod(start, &end);
				if (end == start || end != c)
					return NAN;
				if (strncmp(start, "true", 4) == 0)
					return 1;
				return x;
			}
			++field;
			start = c + 1;
			if (*c != ',')
				return NAN;
		}
	}
}

static void sanitize(const char *name, char *out, size_t size)
{
	size_t n = 0;
	for (const char *c = name; *c != '\0' && n + 1 < size; ++c)
		out[n++] = (isalnum((unsigned char)*c) || *c == '-' || *c == '_') ? *c : '_';
	out[n] = '\0';
}

static bool write_summary(const sweep_state *state)
{
	const sweep *s = state->s;
	char path[PATH_MAX + 256];
	snprintf(path, sizeof path, "%s/plots", state->dir);
	mkdir(path, 0777);
	double *x = malloc(sizeof(double) * (size_t)s->run_count);
	double *y = malloc(sizeof(double) * (size_t)s->run_count);
	json_t *stats = json_object();
	bool ok = x != NULL && y != NULL;
	int ok_runs = 0, failed_runs = 0;
	int field_count = 1 + s->param_count + s->output_count + 2;
	for (int i = 0; i < s->run_count; ++i) {
		int index;
		char status[16];
		ok_runs += parse_row(state->rows[i], field_count, &index, status, sizeof status) && strcmp(status, "ok") == 0;
	}
	failed_runs = s->run_count - ok_runs;
	json_object_set_new(stats, "runs", json_integer(s->run_count));
	json_object_set_new(stats, "ok", json_integer(ok_runs));
	json_object_set_new(stats, "failed", json_integer(failed_runs));
	json_t *outputs = json_object();
	json_object_set_new(stats, "outputs", outputs);
	// Samples, drawn here or read from another sweep's rows, get histograms.
	bool zipped = false;
	for (int p = 0; p < s->param_count; ++p)
		zipped = zipped || s->params[p].zip_lead >= 0;
	for (int o = 0; ok && o < s->output_count; ++o) {
		int column = 1 + s->param_count + o;
		int n = 0;
		for (int i = 0; i < s->run_count; ++i) {
			double v = row_number(state->rows[i], column);
			if (isfinite(v))
				y[n++] = v;
		}
		json_t *entry = json_object();
		json_object_set_new(entry, "count", json_integer(n));
		if (n > 0) {
			double mean = 0, var = 0;
			for (int i = 0; i < n; ++i)
				mean += y[i];
			mean /= n;
			for (int i = 0; i < n; ++i)
				var += (y[i] - mean) * (y[i] - mean);
			qsort(y, (size_t)n, sizeof(double), compare_doubles);
			json_object_set_new(entry, "mean", json_real(mean));
			json_object_set_new(entry, "std", json_real(n > 1 ? sqrt(var / (n - 1)) : 0.0));
			json_object_set_new(entry, "min", json_real(y[0]));
			json_object_set_new(entry, "p5", json_real(percentile(y, n, 0.05)));
			json_object_set_new(entry, "p50", json_real(percentile(y, n, 0.50)));
			json_object_set_new(entry, "p95", json_real(percentile(y, n, 0.95)));
			json_object_set_new(entry, "max", json_real(y[n - 1]));
		}
		json_object_set_new(outputs, s->outputs[o], entry);
		char output_name[128];
		sanitize(s->outputs[o], output_name, sizeof output_name);
		// Histogram of a random sweep: a step outline over 12 bins (or fewer for few runs).
		if ((s->random_count > 0 || zipped) && n >= 2 && y[n - 1] > y[0]) {
			int bins = n < 24 ? (n + 1) / 2 : 12;
			double hx[2 * 64 + 2], hy[2 * 64 + 2];
			double width = (y[n - 1] - y[0]) / bins;
			int m = 0;
			hx[m] = y[0];
			hy[m++] = 0;
			for (int b = 0; b < bins; ++b) {
				int count = 0;
				for (int i = 0; i < n; ++i) {
					int k = (int)((y[i] - y[0]) / width);
					count += (k >= bins ? bins - 1 : k) == b;
				}
				hx[m] = y[0] + b * width;
				hy[m++] = count;
				hx[m] = y[0] + (b + 1) * width;
				hy[m++] = count;
			}
			hx[m] = y[n - 1];
			hy[m++] = 0;
			char title[256];
			snprintf(title, sizeof title, "%s: %d runs", s->outputs[o], n);
			plume_plot_series series = {"runs per bin", hx, hy, m, false, false};
			plume_plot plot = {.title = title,
			                   .x_label = s->outputs[o],
			                   .y_label = "runs",
			                   .series_count = 1,
			                   .series = &series,
			                   .legend = PLUME_LEGEND_TOP_RIGHT};
			plume_error err = {0};
			snprintf(path, sizeof path, "%s/plots/%s-histogram.png", state->dir, output_name);
			if (plume_lab_plot(&plot, path, NULL, &err) != PLUME_OK)
				fprintf(stderr, "plume: %s\n", err.message);
		}
		for (int p = 0; p < s->param_count; ++p) {
			int m = 0;
			for (int i = 0; i < s->run_count; ++i) {
				double px = row_number(state->rows[i], 1 + p), py = row_number(state->rows[i], column);
				if (isfinite(px) && isfinite(py)) {
					x[m] = px;
					y[m++] = py;
				}
			}
			if (m == 0)
				continue;
			char param_name[256], title[512];
			sanitize(s->params[p].name, param_name, sizeof param_name);
			snprintf(title, sizeof title, "%s against %s", s->outputs[o], s->params[p].name);
			plume_plot_series series = {"runs", x, y, m, true, false};
			plume_plot plot = {.title = title,
			                   .x_label = s->params[p].name,
			                   .y_label = s->outputs[o],
			                   .series_count = 1,
			                   .series = &series,
			                   .legend = PLUME_LEGEND_TOP_RIGHT};
			plume_error err = {0};
			snprintf(path, sizeof path, "%s/plots/%s-vs-%s.png", state->dir, output_name, param_name);
			if (plume_lab_plot(&plot, path, NULL, &err) != PLUME_OK)
				fprintf(stderr, "plume: %s\n", err.message);
		}
	}
	free(x);
	free(y);
	char *text = json_dumps(stats, JSON_INDENT(2) | JSON_REAL_PRECISION(10));
	json_decref(stats);
	snprintf(path, sizeof path, "%s/stats.json", state->dir);
	const char *parts[2] = {text, "\n"};
	ok = text != NULL && write_atomic(path, parts, 2) && ok;
	free(text);
	printf("sweep: %d runs, %d ok, %d failed; %s/results.csv\n", s->run_count, ok_runs, failed_runs, state->dir);
	return ok;
}

// ---------------------------------------------------------------------------
// Schedulers

/// Runs every missing run with up to jobs children at once.
static bool run_local(sweep_state *state, int jobs)
{
	const sweep *s = state->s;
	typedef struct slot {
		pid_t pid;
		int index;
		double start;
	} slot;
	slot *slots = calloc((size_t)jobs, sizeof *slots);
	if (slots == NULL)
		return false;
	int next = 0, running = 0;
	bool ok = true;
	for (;;) {
		while (running < jobs && ok) {
			while (next < s->run_count && state->rows[next] != NULL)
				++next;
			if (next >= s->run_count)
				break;
			char failure[512] = "";
			double start = now_seconds();
			pid_t pid = run_start(s, state->dir, next, failure, sizeof failure);
			if (pid < 0) {
				ok = record_row(state, next, run_finish(s, state->dir, next, -1, 0, failure));
				++next;
				continue;
			}
			int k = 0;
			while (slots[k].pid != 0)
				++k;
			slots[k] = (slot){pid, next, start};
			++running;
			++next;
		}
		if (running == 0)
			break;
		int wait_status = 0;
		pid_t pid = waitpid(-1, &wait_status, 0);
		if (pid < 0) {
			if (errno == EINTR)
				continue;
			break;
		}
		for (int k = 0; k < jobs; ++k)
			if (slots[k].pid == pid) {
				record_timing(state, slots[k].index, now_seconds() - slots[k].start, k);
				ok = record_row(state, slots[k].index,
				                run_finish(s, state->dir, slots[k].index, pid, wait_status, "")) &&
				     ok;
				slots[k].pid = 0;
				--running;
			}
	}
	free(slots);
	return ok;
}

#ifdef PLUME_WITH_MPI
enum { TAG_READY = 1, TAG_ROW = 2, TAG_WORK = 3 };

/// Whether this process was started by an MPI launcher (mpirun, srun): only then is
/// MPI initialised, so plain `plume sweep` works without a launcher.
static bool mpi_launched(void)
{
	return getenv("OMPI_COMM_WORLD_SIZE") != NULL || getenv("PMI_SIZE") != NULL || getenv("PMIX_RANK") != NULL;
}

/// Rank 0: hands the missing runs out one at a time as ranks become free, gathers the rows.
static bool mpi_schedule(sweep_state *state, int size)
{
	const sweep *s = state->s;
	int next = 0, active = size - 1;
	bool ok = true;
	double *started = calloc((size_t)size, sizeof *started);
	int *assigned = calloc((size_t)size, sizeof *assigned);
	while (active > 0) {
		// Poll with sleeps: a blocking probe spins a core that the runs need.
		MPI_Status status;
		int arrived = 0;
		for (;;) {
			MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &arrived, &status);
			if (arrived)
				break;
			nanosleep(&(struct timespec){0, 2000000}, NULL);
		}
		int length = 0;
		MPI_Get_count(&status, MPI_CHAR, &length);
		char *message = malloc((size_t)length + 1);
		MPI_Recv(message, length, MPI_CHAR, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		message[length] = '\0';
		int source = status.MPI_SOURCE;
		if (status.MPI_TAG == TAG_ROW) {
			record_timing(state, assigned[source], now_seconds() - started[source], source);
			ok = record_row(state, assigned[source], strdup(message)) && ok;
		}
		free(message);
		while (next < s->run_count && state->rows[next] != NULL)
			++next;
		int work = next < s->run_count && ok ? next++ : -1;
		if (work >= 0) {
			assigned[source] = work;
			started[source] = now_seconds();
		} else
			--active;
		MPI_Send(&work, 1, MPI_INT, source, TAG_WORK, MPI_COMM_WORLD);
	}
	free(started);
	free(assigned);
	return ok;
}

static void mpi_work(const sweep *s, const char *dir)
{
	char ready = 0;
	MPI_Send(&ready, 0, MPI_CHAR, 0, TAG_READY, MPI_COMM_WORLD);
	for (;;) {
		int index = -1;
		MPI_Recv(&index, 1, MPI_INT, 0, TAG_WORK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		if (index < 0)
			break;
		char failure[512] = "";
		int wait_status = 0;
		pid_t pid = run_start(s, dir, index, failure, sizeof failure);
		while (pid >= 0 && waitpid(pid, &wait_status, 0) < 0 && errno == EINTR) {
		}
		char *row = run_finish(s, dir, index, pid, wait_status, failure);
		const char *text = row != NULL ? row : "";
		MPI_Send(text, (int)strlen(text), MPI_CHAR, 0, TAG_ROW, MPI_COMM_WORLD);
		free(row);
	}
}
#endif

/// --dry-run: the parameter values of every run, as the first columns of results.csv.
static void print_plan(const sweep *s)
{
	printf("index");
	for (int p = 0; p < s->param_count; ++p)
		printf(",%s", s->params[p].name);
	printf("\n");
	char text[256];
	for (int i = 0; i < s->run_count; ++i) {
		printf("%d", i);
		for (int p = 0; p < s->param_count; ++p) {
			json_t *value = run_value(s, p, i);
			csv_value(text, sizeof text, value);
			json_decref(value);
			printf(",%s", text);
		}
		printf("\n");
	}
}

int cli_sweep(int argc, char **argv)
{
	static const struct option options[] = {{"output", required_argument, NULL, 'o'},
	                                        {"jobs", required_argument, NULL, 'j'},
	                                        {"dry-run", no_argument, NULL, 'n'},
	                                        {"help", no_argument, NULL, 'h'},
	                                        {NULL, 0, NULL, 0}};
	const char *output_dir = NULL;
	int jobs = 1;
	bool dry_run = false;
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:j:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 'j': {
			char *end = NULL;
			long value = strtol(optarg, &end, 10);
			if (end == optarg || *end != '\0' || value < 1 || value > 1024)
				return cli_usage_error("sweep", "-j expects a whole number in [1, 1024], got '%s'", optarg);
			jobs = (int)value;
			break;
		}
		case 'n': dry_run = true; break;
		case 'h': cli_help_sweep(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("sweep", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("sweep", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (!cli_check_arguments("sweep", argc, argv, "SWEEP.json", output_dir))
		return CLI_EXIT_USAGE;

	if (dry_run) {
		sweep s;
		int code = sweep_load(&s, argv[optind]) && sweep_check(&s) ? CLI_EXIT_OK : CLI_EXIT_INPUT;
		if (code == CLI_EXIT_OK)
			print_plan(&s);
		sweep_free(&s);
		return code;
	}
	int rank = 0, size = 1;
#ifdef PLUME_WITH_MPI
	bool mpi = mpi_launched();
	if (mpi) {
		MPI_Init(NULL, NULL);
		MPI_Comm_rank(MPI_COMM_WORLD, &rank);
		MPI_Comm_size(MPI_COMM_WORLD, &size);
	}
#endif
	// Every rank reads and checks the sweep (it is small); only rank 0 speaks.
	FILE *saved_stderr = NULL;
	if (rank != 0)
		saved_stderr = freopen("/dev/null", "w", stderr);
	(void)saved_stderr;
	sweep s;
	int code = CLI_EXIT_OK;
	if (!sweep_load(&s, argv[optind]) || (rank == 0 && !sweep_check(&s)))
		code = CLI_EXIT_INPUT;
	sweep_state state;
	memset(&state, 0, sizeof state);
	if (code == CLI_EXIT_OK && rank == 0) {
		int begin_code = CLI_EXIT_IO;
		if (!state_begin(&begin_code, &state, &s, output_dir))
			code = begin_code;
	}
#ifdef PLUME_WITH_MPI
	if (mpi) {
		MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
		if (code == CLI_EXIT_OK) {
			if (size == 1)
				code = run_local(&state, jobs) ? CLI_EXIT_OK : CLI_EXIT_IO;
			else if (rank == 0)
				code = mpi_schedule(&state, size) ? CLI_EXIT_OK : CLI_EXIT_IO;
			else
				mpi_work(&s, output_dir);
		}
	} else
#endif
	    if (code == CLI_EXIT_OK)
		code = run_local(&state, jobs) ? CLI_EXIT_OK : CLI_EXIT_IO;
	if (rank == 0 && code == CLI_EXIT_OK)
		code = write_summary(&state) ? CLI_EXIT_OK : CLI_EXIT_IO;
	if (rank == 0 && code == CLI_EXIT_OK && !s.keep_runs) {
		char runs[PATH_MAX + 16];
		snprintf(runs, sizeof runs, "%s/runs", output_dir);
		remove_tree(runs); // and what killed attempts left of runs since done
	}
	state_end(&state);
	sweep_free(&s);
#ifdef PLUME_WITH_MPI
	if (mpi)
		MPI_Finalize();
#endif
	return code;
}

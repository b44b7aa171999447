// plume sweep: reading SWEEP.json (docs/sweeps.md) into a sweep: the command, the
// base spec, the parameters (values, grids, distributions, columns of another sweep's
// results.csv), samples, seed and outputs. Every bad key or value is named by its JSON
// path with what is allowed.
#define _GNU_SOURCE
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sweep.h"

bool sweep_error(const sweep *s, const char *format, ...)
{
	va_list args;
	va_start(args, format);
	fprintf(stderr, "plume: %s: ", s->file);
	vfprintf(stderr, format, args);
	fputc('\n', stderr);
	va_end(args);
	return false;
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
static bool read_column(sweep *s, sweep_param *p, const json_t *item, const char *where, json_t *target)
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
	if (stream == NULL) {
		s->failure_code = CLI_EXIT_IO;
		return sweep_error(s, "%s.from_csv: %s: cannot read: %s", where, path, strerror(errno));
	}
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
		if (p->integer && !(fabs(x) <= SWEEP_MAX_INTEGER)) {
			free(line);
			fclose(stream);
			return sweep_error(s,
			                   "%s: %s line %d: column %s is '%s'; an integer parameter takes values in [-2^53, 2^53]",
			                   where, path, row, column, field);
		}
		bool whole = p->integer || (json_is_integer(target) && x == floor(x) && fabs(x) <= SWEEP_MAX_INTEGER);
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
			size_t d = plume_edit_distance(allowed[i], key);
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

/// An integer parameter's distribution truncated to [-2^53, 2^53] (SWEEP_MAX_INTEGER): a "min" or "max"
/// outside is refused, an unbounded side bounded there (and the probability inside is checked as for any
/// truncation, sweep_check.c).
static bool integer_range(const sweep *s, sweep_param *p, const char *where)
{
	if (isfinite(p->lo) && p->lo < -SWEEP_MAX_INTEGER)
		return sweep_error(s, "%s.min is %g; an integer parameter takes values in [-2^53, 2^53]", where, p->lo);
	if (isfinite(p->hi) && p->hi > SWEEP_MAX_INTEGER)
		return sweep_error(s, "%s.max is %g; an integer parameter takes values in [-2^53, 2^53]", where, p->hi);
	p->lo = fmax(p->lo, -SWEEP_MAX_INTEGER);
	p->hi = fmin(p->hi, SWEEP_MAX_INTEGER);
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
	json_t *target = sweep_path_lookup(s->spec, path, &parent, key, sizeof key, &array_index, &settable);
	// A key the base spec leaves to its default may be swept; the spec's own reader
	// (sweep_check) then says whether the key exists.
	if ((target == NULL && !settable) || parent == NULL) {
		char best[512] = "$";
		size_t distance = SIZE_MAX;
		sweep_nearest_path(s->spec, "$", path, best, &distance);
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
		if (p->integer && !(fabs(from) <= SWEEP_MAX_INTEGER && fabs(to) <= SWEEP_MAX_INTEGER))
			return sweep_error(s, "%s.%s is %g; an integer parameter takes values in [-2^53, 2^53]", grid_where,
			                   fabs(from) <= SWEEP_MAX_INTEGER ? "to" : "from",
			                   fabs(from) <= SWEEP_MAX_INTEGER ? to : from);
		p->values = json_array();
		for (int k = 0; k < (int)count; ++k) {
			double v = count == 1 ? from : from + (to - from) * k / (count - 1);
			if (k == (int)count - 1)
				v = to; // the end exactly, whatever the rounding of the steps
			// Whole numbers stay integers where the base spec has one (a count, a seed).
			bool whole = p->integer || (json_is_integer(target) && v == floor(v) && fabs(v) <= SWEEP_MAX_INTEGER);
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
		if (p->integer && !integer_range(s, p, where))
			return false;
		s->random_count++;
	}
	return true;
}

/// Whether parameter i is a dimension of the grid (zipped columns share their first's).
bool sweep_owns_dimension(const sweep_param *p, int i)
{
	return p->values != NULL && (p->zip_lead < 0 || p->zip_lead == i);
}

/// A JSON file, told apart: one that cannot be read (*io, with errno's reason) from one
/// that does not parse (jansson's line and column).
static json_t *load_json(const char *path, bool *io, json_error_t *jerr)
{
	// jansson reports a missing file as a parse error at line -1; plume says "cannot read".
	FILE *file = fopen(path, "rb");
	*io = file == NULL;
	if (file == NULL)
		return NULL;
	json_t *root = json_loadf(file, JSON_REJECT_DUPLICATES, jerr);
	fclose(file);
	return root;
}

/// "$.outputs[i]: no mesh run produces "x"; mesh writes: a, b (when), ..."
static bool unknown_output(const sweep *s, int i, const char *key)
{
	const sweep_command *c = s->command;
	if (c->outputs[0].key == NULL)
		return sweep_error(s, "$.outputs[%d]: %s writes no outputs to collect; only status", i, c->name);
	fprintf(stderr, "plume: %s: $.outputs[%d]: no %s run produces \"%s\"; %s writes:", s->file, i, c->name, key,
	        c->name);
	for (int k = 0; c->outputs[k].key != NULL; ++k) {
		fprintf(stderr, "%s %s", k ? "," : "", c->outputs[k].key);
		if (c->outputs[k].when != NULL)
			fprintf(stderr, " (%s)", c->outputs[k].when);
	}
	fputc('\n', stderr);
	return false;
}

/// $.outputs: keys the command writes, each once (a column each in results.csv).
static bool read_outputs(sweep *s, const json_t *outputs)
{
	if (!json_is_array(outputs) || json_array_size(outputs) > 32)
		return sweep_error(s, "$.outputs must be an array of at most 32 output keys");
	s->output_count = (int)json_array_size(outputs);
	for (int i = 0; i < s->output_count; ++i) {
		const char *key = json_string_value(json_array_get(outputs, (size_t)i));
		if (key == NULL || strlen(key) >= sizeof s->outputs[i])
			return sweep_error(s, "$.outputs[%d] must be a key name", i);
		char hole[128];
		if (sweep_output_find(s->command, key, hole, sizeof hole) == NULL)
			return unknown_output(s, i, key);
		for (int k = 0; k < i; ++k)
			if (strcmp(s->outputs[k], key) == 0)
				return sweep_error(s, "$.outputs[%d]: \"%s\" is already collected by $.outputs[%d]", i, key, k);
		snprintf(s->outputs[i], sizeof s->outputs[i], "%s", key);
	}
	return true;
}

bool sweep_load(sweep *s, const char *file)
{
	static const char *const keys[] = {"description", "command", "spec",    "arguments", "parameters",
	                                   "samples",     "seed",    "outputs", "keep_runs", NULL};
	memset(s, 0, sizeof *s);
	s->file = file;
	s->failure_code = CLI_EXIT_INPUT;
	json_error_t jerr;
	bool io = false;
	s->root = load_json(file, &io, &jerr);
	if (s->root == NULL) {
		if (io) {
			s->failure_code = CLI_EXIT_IO;
			return sweep_error(s, "cannot read: %s", strerror(errno));
		}
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
		s->spec = load_json(path, &io, &jerr);
		if (s->spec == NULL && io) {
			s->failure_code = CLI_EXIT_IO;
			return sweep_error(s, "$.spec: %s: cannot read: %s", path, strerror(errno));
		}
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
			char list[256] = "";
			for (int i = 0; i < CLI_CALIBRATE_OPTION_COUNT; ++i) {
				known = known || strcmp(cli_calibrate_options[i].key, key) == 0;
				size_t used = strlen(list);
				snprintf(list + used, sizeof list - used, "%s, ", cli_calibrate_options[i].key);
			}
			if (!known)
				return sweep_error(s, "$.spec.%s is not a calibration option (%sunconstrained)", key, list);
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
		if (sweep_owns_dimension(s->params + i, i))
			runs *= (double)json_array_size(s->params[i].values);
	if (runs > 1000000) {
		// A resource limit like --max-runs's (docs/cli.md, Limits), but not one to raise.
		s->failure_code = CLI_EXIT_LIMIT;
		return sweep_error(
		    s, "$.samples (%d) x the grids' and lists' values (%.0f) make %.0f runs; a sweep may have at most 1000000",
		    (int)samples, runs / samples, runs);
	}
	s->run_count = (int)runs;
	s->grid_count = s->run_count / s->samples;

	json_t *outputs = json_object_get(s->root, "outputs");
	if (outputs != NULL && !read_outputs(s, outputs))
		return false;
	json_t *keep = json_object_get(s->root, "keep_runs");
	if (keep != NULL && !json_is_boolean(keep))
		return sweep_error(s, "$.keep_runs must be true or false");
	s->keep_runs = json_is_true(keep);
	return true;
}

void sweep_free(sweep *s)
{
	for (int i = 0; i < s->param_count; ++i)
		json_decref(s->params[i].values);
	json_decref(s->spec);
	json_decref(s->root);
}

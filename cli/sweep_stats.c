// plume sweep: once every run is done, DIR/stats.json (count, mean, std, min, 5/50/95
// percentiles, max of each output) and DIR/plots/*.png.
#define _GNU_SOURCE
#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sweep.h"

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

/// Field k of a CSV row as a number (NAN when empty or not a number or boolean).
static double row_number(const char *row, int k)
{
	const char *start;
	size_t length;
	if (!sweep_row_field(row, k, &start, &length))
		return NAN;
	// A true/false output (such as completed) counts as 1/0; strtod takes neither.
	if (length == 4 && strncmp(start, "true", 4) == 0)
		return 1;
	if (length == 5 && strncmp(start, "false", 5) == 0)
		return 0;
	char *end = NULL;
	double x = strtod(start, &end);
	if (end == start || end != start + length)
		return NAN;
	return x;
}

static void sanitize(const char *name, char *out, size_t size)
{
	size_t n = 0;
	for (const char *c = name; *c != '\0' && n + 1 < size; ++c)
		out[n++] = (isalnum((unsigned char)*c) || *c == '-' || *c == '_') ? *c : '_';
	out[n] = '\0';
}

int sweep_ok_count(const sweep_state *state)
{
	const sweep *s = state->s;
	int field_count = 1 + s->param_count + s->output_count + 2, ok_runs = 0;
	for (int i = 0; i < s->run_count; ++i) {
		int index;
		char status[16];
		ok_runs += state->rows[i] != NULL &&
		           sweep_parse_row(state->rows[i], field_count, &index, status, sizeof status) &&
		           strcmp(status, "ok") == 0;
	}
	return ok_runs;
}

bool sweep_write_summary(const sweep_state *state)
{
	const sweep *s = state->s;
	char path[PATH_MAX + 256];
	snprintf(path, sizeof path, "%s/plots", state->dir);
	mkdir(path, 0777);
	double *x = malloc(sizeof(double) * (size_t)s->run_count);
	double *y = malloc(sizeof(double) * (size_t)s->run_count);
	json_t *stats = json_object();
	bool ok = x != NULL && y != NULL;
	int ok_runs = sweep_ok_count(state), failed_runs = s->run_count - ok_runs;
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
		// Histogram of a random sweep: a step outline over 12 bins (or fewer for few runs). Not
		// of outputs whose span overflows a double (-1e308 to 1e308): the bins' width would be
		// infinite, and a bin index NaN.
		if ((s->random_count > 0 || zipped) && n >= 2 && y[n - 1] > y[0] && isfinite(y[n - 1] - y[0])) {
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
	ok = text != NULL && sweep_write_atomic(path, parts, 2) && ok;
	free(text);
	printf("sweep: %d runs, %d ok, %d failed; %s/results.csv\n", s->run_count, ok_runs, failed_runs, state->dir);
	return ok;
}

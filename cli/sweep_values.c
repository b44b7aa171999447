// plume sweep: the values of each run: the grid/list index of a run, its seeded random
// samples, the run's spec, and values as CSV text.
#define _GNU_SOURCE
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sweep.h"

/// Standard normal by Box-Muller from two uniforms of the parameter's own stream.
static double normal_sample(plume_rng *rng)
{
	double u1 = 1.0 - plume_rng_uniform(rng); // (0, 1]
	double u2 = plume_rng_uniform(rng);
	return sqrt(-2.0 * log(u1)) * cos(2.0 * 3.14159265358979323846 * u2);
}

/// Probability mass of [lo, hi] under the parameter's distribution (before truncation).
double sweep_param_mass(const sweep_param *p)
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
			x = round(x); // llround's, defined for any x: an unbounded normal draws past a long
		if (x >= p->lo && x <= p->hi)
			return x;
	}
	return p->dist == DIST_UNIFORM ? p->a : fmin(fmax(p->a, p->lo), p->hi); // unreachable: mass is checked
}

/// Value of parameter p in run index (new reference).
json_t *sweep_run_value(const sweep *s, int param, int index)
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
		if (sweep_owns_dimension(s->params + q, q))
			stride *= (int)json_array_size(s->params[q].values);
	size_t k = (size_t)(grid / stride) % json_array_size(p->values);
	return json_deep_copy(json_array_get(p->values, k));
}

/// CSV text of a scalar: numbers in the fewest digits that round-trip (plume_lab_format_number),
/// strings quoted when needed.
void sweep_csv_value(char *out, size_t size, const json_t *value)
{
	if (json_is_integer(value))
		snprintf(out, size, "%lld", (long long)json_integer_value(value));
	else if (json_is_real(value)) {
		char text[PLUME_LAB_NUMBER_TEXT];
		snprintf(out, size, "%s", plume_lab_format_number(text, sizeof text, json_real_value(value)));
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
json_t *sweep_run_spec(const sweep *s, int index)
{
	json_t *spec = json_deep_copy(s->spec);
	for (int p = 0; p < s->param_count; ++p)
		sweep_path_set(spec, s->params[p].path, sweep_run_value(s, p, index));
	return spec;
}

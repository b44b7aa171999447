// Bézier curves: closed forms, elevation, splitting, arc length.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <unistd.h>

#include "core/vec_inline.h"
#include "support.h"

static void test_eval_matches_bernstein_cubic(void **state)
{
	(void)state;
	plume_vec3 p[4] = {{0, 0, 0}, {1, 2, 0}, {3, 3, 1}, {4, 0, 2}};
	for (int i = 0; i <= 100; ++i) {
		double t = i / 100.0, s = 1 - t;
		plume_vec3 expect =
		    plume_v3_add(plume_v3_add(plume_v3_scale(p[0], s * s * s), plume_v3_scale(p[1], 3 * s * s * t)),
		                 plume_v3_add(plume_v3_scale(p[2], 3 * s * t * t), plume_v3_scale(p[3], t * t * t)));
		plume_vec3 got = plume_bezier_eval(p, 4, t);
		assert_close(got.x, expect.x, 1e-14);
		assert_close(got.y, expect.y, 1e-14);
		assert_close(got.z, expect.z, 1e-14);
	}
}

static void test_eval_quadratic_is_parabola(void **state)
{
	(void)state;
	// (0,0) (0.5,0) (1,1): x = t, y = t^2 — degree 2 exercises de Casteljau's general path.
	plume_vec3 p[3] = {{0, 0, 0}, {0.5, 0, 0}, {1, 1, 0}};
	for (int i = 0; i <= 50; ++i) {
		double t = i / 50.0;
		plume_vec3 q = plume_bezier_eval(p, 3, t);
		assert_close(q.x, t, 1e-15);
		assert_close(q.y, t * t, 1e-15);
		plume_vec3 d1 = plume_bezier_derivative(p, 3, 1, t);
		assert_close(d1.x, 1.0, 1e-14);
		assert_close(d1.y, 2 * t, 1e-14);
		plume_vec3 d2 = plume_bezier_derivative(p, 3, 2, t);
		assert_close(d2.y, 2.0, 1e-13);
		plume_vec3 d3 = plume_bezier_derivative(p, 3, 3, t);
		assert_close(plume_v3_length(d3), 0.0, 0.0);
	}
}

static void test_derivative_of_quintic_against_closed_form(void **state)
{
	(void)state;
	// Control points of the power curve y = t^5 in Bernstein form: b_i = [i == 5]; x = t.
	plume_vec3 p[6];
	for (int i = 0; i < 6; ++i)
		p[i] = plume_v3(i / 5.0, i == 5 ? 1.0 : 0.0, 0.0);
	for (int i = 0; i <= 40; ++i) {
		double t = i / 40.0;
		assert_close(plume_bezier_eval(p, 6, t).y, pow(t, 5), 1e-15);
		assert_close(plume_bezier_derivative(p, 6, 1, t).y, 5 * pow(t, 4), 1e-13);
		assert_close(plume_bezier_derivative(p, 6, 2, t).y, 20 * pow(t, 3), 1e-12);
		assert_close(plume_bezier_derivative(p, 6, 1, t).x, 1.0, 1e-13);
	}
}

/// The elevation weights the compiler folded are the quotients the elevation divided at run time: the
/// generators' outputs depend on every bit of them.
static void test_elevation_weights_are_the_quotients(void **state)
{
	(void)state;
	volatile double numerator, denominator; // divided here at run time, not folded
	for (int c = 1; c < PLUME_BEZIER_MAX_POINTS; ++c)
		for (int i = 0; i < c; ++i) {
			numerator = i;
			denominator = c;
			double quotient = numerator / denominator;
			assert_memory_equal(&core_elevation_weight[c][i], &quotient, sizeof quotient);
		}
	plume_rng rng = plume_rng_seed(7);
	for (int count = 2; count <= PLUME_BEZIER_MAX_POINTS - 1; ++count) {
		plume_vec3 p[PLUME_BEZIER_MAX_POINTS], fast[PLUME_BEZIER_MAX_POINTS], slow[PLUME_BEZIER_MAX_POINTS];
		for (int i = 0; i < count; ++i)
			p[i] = plume_v3(plume_rng_range(&rng, -1, 1), plume_rng_range(&rng, -1, 1), plume_rng_range(&rng, -1, 1));
		core_bezier_elevate(p, count, fast);
		// The formula of the header's comment, divided at run time.
		slow[0] = p[0];
		slow[count] = p[count - 1];
		for (int i = 1; i < count; ++i) {
			numerator = i;
			denominator = count;
			double a = numerator / denominator;
			slow[i] = plume_v3_add(plume_v3_scale(p[i - 1], a), plume_v3_scale(p[i], 1.0 - a));
		}
		assert_memory_equal(fast, slow, (size_t)(count + 1) * sizeof *fast);
	}
}

static void test_degree_elevation_keeps_curve(void **state)
{
	(void)state;
	plume_rng rng = plume_rng_seed(42);
	for (int count = 2; count <= 12; ++count) {
		plume_vec3 p[PLUME_BEZIER_MAX_POINTS], q[PLUME_BEZIER_MAX_POINTS];
		for (int i = 0; i < count; ++i)
			p[i] = plume_v3(plume_rng_range(&rng, -1, 1), plume_rng_range(&rng, -1, 1), plume_rng_range(&rng, -1, 1));
		plume_bezier_elevate(p, count, q);
		plume_vec3 r[PLUME_BEZIER_MAX_POINTS];
		plume_bezier_elevate(q, count + 1, r); // twice
		double worst = 0.0;
		for (int i = 0; i < 1000; ++i) {
			double t = i / 999.0;
			plume_vec3 a = plume_bezier_eval(p, count, t);
			worst = fmax(worst, plume_v3_distance(a, plume_bezier_eval(q, count + 1, t)));
			worst = fmax(worst, plume_v3_distance(a, plume_bezier_eval(r, count + 2, t)));
		}
		assert_true(worst < 1e-12);
		assert_close(plume_v3_distance(q[0], p[0]), 0.0, 0.0);
		assert_close(plume_v3_distance(q[count], p[count - 1]), 0.0, 0.0);
	}
}

static void test_split_halves_cover_curve(void **state)
{
	(void)state;
	plume_vec3 p[5] = {{0, 0, 0}, {1, 3, 0}, {2, -1, 1}, {4, 2, 0}, {5, 0, 0}};
	plume_vec3 left[5], right[5];
	double at = 0.3;
	plume_bezier_split(p, 5, at, left, right);
	for (int i = 0; i <= 200; ++i) {
		double u = i / 200.0;
		assert_true(plume_v3_distance(plume_bezier_eval(left, 5, u), plume_bezier_eval(p, 5, at * u)) < 1e-14);
		assert_true(plume_v3_distance(plume_bezier_eval(right, 5, u), plume_bezier_eval(p, 5, at + (1 - at) * u)) <
		            1e-14);
	}
}

static void test_length_of_line_and_quarter_circle(void **state)
{
	(void)state;
	plume_vec3 line[4] = {{0, 0, 0}, {0.1, 0.2, 0}, {1, 2, 0}, {2, 4, 0}}; // collinear, monotone, non-uniform speed
	assert_close(plume_bezier_length(line, 4, 0, 1), sqrt(20.0), 1e-12);
	// Parabola y = x^2 on [0, 1]: length = (2 sqrt 5 + asinh 2) / 4.
	plume_vec3 parabola[3] = {{0, 0, 0}, {0.5, 0, 0}, {1, 1, 0}};
	double exact = (2 * sqrt(5.0) + asinh(2.0)) / 4;
	assert_close(plume_bezier_length(parabola, 3, 0, 1), exact, 1e-13);
	// Sub-range: x in [0, 0.5]  ->  (x sqrt(1+4x^2))/2 + asinh(2x)/4.
	double half = (0.5 * sqrt(2.0)) / 2 + asinh(1.0) / 4;
	assert_close(plume_bezier_length(parabola, 3, 0, 0.5), half, 1e-13);
}

static void test_sampling_by_arc_length_is_equal(void **state)
{
	(void)state;
	plume_vec3 p[4] = {{0, 0, 0}, {0.0, 0.9, 0}, {1.0, 0.1, 0.3}, {1, 1, 0}};
	double length = plume_bezier_length(p, 4, 0, 1);
	enum { N = 41 };
	double t[N];
	plume_bezier_sample_by_length(p, 4, N, t);
	assert_close(t[0], 0.0, 0.0);
	assert_close(t[N - 1], 1.0, 0.0);
	for (int k = 1; k < N; ++k) {
		double piece = plume_bezier_length(p, 4, t[k - 1], t[k]);
		assert_close(piece, length / (N - 1), 1e-6 * length);
		assert_true(t[k] > t[k - 1]);
	}
	// And much better than the bound: 1e-9.
	for (int k = 1; k < N - 1; ++k)
		assert_close(plume_bezier_length(p, 4, 0, t[k]), length * k / (N - 1), 1e-9 * length);
	assert_close(plume_bezier_param_at_length(p, 4, 0.25), t[10], 1e-12);
}

static void test_degenerate_point_curve(void **state)
{
	(void)state;
	plume_vec3 p[3] = {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
	assert_close(plume_bezier_length(p, 3, 0, 1), 0.0, 0.0);
	double t[5];
	plume_bezier_sample_by_length(p, 3, 5, t);
	for (int k = 1; k < 5; ++k)
		assert_true(t[k] > t[k - 1]);
}

// Issue 17: a Franco-Walter shaft point of [1e308, 1e308] hung `generate`; the
// speed overflows to inf, no tolerance is ever met, and the recursion went to
// depth 30 everywhere (2^30 quadratures per interval). The subdivision budget
// bounds the work whatever the values; alarm() turns a hang into a failure.
static void test_huge_control_points_finish(void **state)
{
	(void)state;
	alarm(60);
	plume_vec3 p[4] = {{0, 0, 0}, {0.0015, 0.07, 0}, {0.005, 0.14, 0}, {1e308, 1e308, 0}};
	double t[100];
	plume_bezier_sample_by_length(p, 4, 100, t);
	assert_true(t[0] == 0.0 && t[99] == 1.0);
	for (int k = 1; k < 100; ++k)
		assert_true(t[k] >= 0.0 && t[k] <= 1.0);
	assert_false(isfinite(plume_bezier_length(p, 4, 0, 1)));
	alarm(0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_eval_matches_bernstein_cubic),
	    cmocka_unit_test(test_eval_quadratic_is_parabola),
	    cmocka_unit_test(test_derivative_of_quintic_against_closed_form),
	    cmocka_unit_test(test_elevation_weights_are_the_quotients),
	    cmocka_unit_test(test_degree_elevation_keeps_curve),
	    cmocka_unit_test(test_split_halves_cover_curve),
	    cmocka_unit_test(test_length_of_line_and_quarter_circle),
	    cmocka_unit_test(test_sampling_by_arc_length_is_equal),
	    cmocka_unit_test(test_degenerate_point_curve),
	    cmocka_unit_test(test_huge_control_points_finish),
	};
	return cmocka_run_group_tests_name("bezier", tests, NULL, NULL);
}

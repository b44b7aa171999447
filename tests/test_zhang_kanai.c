// Zhang–Kanai generator: emitters and RK4 pathlines against exact loci,
// termination, unfurling invariants, vane asymmetry, snapping, splits,
// the rachis, stages, determinism, bad input and memory.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model/feather_internal.h"
#include "model/zhang_kanai_internal.h"
#include "plume/zhang_kanai.h"
#include "support.h"

static const double two_pi = 6.283185307179586476925286766559;

typedef struct generated {
	plume_feather *feather;
	plume_zk_report report;
} generated;

static generated generate(const plume_zk_def *def, uint64_t seed)
{
	generated g = {0};
	plume_error err = {0};
	if (plume_zk_generate(def, seed, &g.feather, &g.report, &err) != PLUME_OK)
		fail_msg("generate failed: %s", err.message);
	return g;
}

static void release(generated *g)
{
	plume_feather_destroy(g->feather);
	plume_zk_report_free(&g->report);
}

/// A small feather with constant speeds: every locus has a closed form.
static plume_zk_def constant_def(void)
{
	plume_zk_def def = plume_zk_default_def();
	def.emitter_speed = plume_zk_constant(0.006);
	def.barb_speed = plume_zk_constant(0.009);
	def.step = 0.013; // does not divide any event time
	def.barb_count = 40;
	def.downsample = 3;
	return def;
}

/// Eq. 1 scaled by R, minus the feather's origin (the middle of I_A's chord).
static plume_vec3 circle_point(const plume_zk_def *def, double s)
{
	double r = def->collar_radius;
	double ox = 0.5 * r * (sin(two_pi * def->anterior[0]) + sin(two_pi * def->anterior[1]));
	double oz = -0.5 * r * (cos(two_pi * def->anterior[0]) + cos(two_pi * def->anterior[1]));
	return plume_v3(r * sin(two_pi * s) - ox, 0.0, -r * cos(two_pi * s) - oz);
}

// ---------------------------------------------------------------------------
// IV-A: emitters, pathlines, termination

static void test_emitters_monotone_and_clamped(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	generated g = generate(&def, 1);
	for (int side = 0; side < 2; ++side) {
		double sigma = side == PLUME_SIDE_LEFT ? -1.0 : 1.0;
		double previous_locus = def.anterior[side], previous_time = 0.0;
		int clamped = 0;
		// The feather lists each vane base to tip: walk it backwards, in emission order.
		for (int k = g.report.barb_count - 1; k >= 0; --k) {
			const plume_zk_barb_report *b = g.report.barbs + k;
			if ((int)b->side != side)
				continue;
			assert_true(sigma * (b->emit_locus - previous_locus) >= 0.0);
			assert_true(b->emit_time > previous_time);
			assert_true(sigma * (b->emit_locus - def.posterior[side]) <= 0.0); // never past I_P
			if (b->emit_locus == def.posterior[side])
				++clamped;
			previous_locus = b->emit_locus;
			previous_time = b->emit_time;
		}
		assert_true(clamped > 10); // the default emitters reach the BGZ and keep emitting there
		assert_true(isfinite(g.report.clamp_time[side]));
	}
	release(&g);
}

static void test_constant_speed_matches_exact_loci(void **state)
{
	(void)state;
	plume_zk_def def = constant_def();
	def.unfurl_weight = 0.0; // the helix itself
	generated g = generate(&def, 1);
	const double ve = 0.006, vb = 0.009, length = two_pi * def.collar_radius;
	double worst_emit = 0.0, worst_point = 0.0, worst_time = 0.0;
	int checked_points = 0;
	for (int k = 0; k < g.report.barb_count; ++k) {
		const plume_zk_barb_report *b = g.report.barbs + k;
		double sigma = b->side == PLUME_SIDE_LEFT ? -1.0 : 1.0;
		double s_a = def.anterior[b->side], s_p = def.posterior[b->side];
		// Eq. 3-4 in closed form: the emitter moved (i + 1) d, clamped at I_P.
		double travelled = (b->index + 1) * def.ridge_width;
		double clamp_distance = length * fabs(s_p - s_a);
		double locus = travelled < clamp_distance ? s_a + sigma * travelled / length : s_p;
		double time = travelled / ve;
		worst_emit = fmax(worst_emit, fabs(b->emit_locus - locus));
		worst_time = fmax(worst_time, fabs(b->emit_time - time));
		// Maturity: the barb covers |s0 - s_A| L at V_b.
		double mature = time + fabs(locus - s_a) * length / vb;
		worst_time = fmax(worst_time, fabs(b->mature_time - mature));
		// Every vertex of the helix (w = 0) is C(s(t)) + y u_y with s(t) exact.
		plume_barb barb = plume_feather_barb(g.feather, k);
		for (int j = 0; j < barb.curve.count; ++j) {
			plume_vec3 p = barb.curve.points[j];
			double t = g.report.t_curr - p.y / def.growth_speed; // eq. 5 inverted
			double s = locus - sigma * vb / length * (t - time);
			plume_vec3 exact = circle_point(&def, s);
			worst_point = fmax(worst_point, hypot(p.x - exact.x, p.z - exact.z));
			++checked_points;
		}
		// The root is on I_A, the tip is the emission point.
		plume_vec3 root = circle_point(&def, s_a), tip = circle_point(&def, locus);
		assert_close(barb.curve.points[0].x, root.x, 1e-15);
		assert_close(barb.curve.points[0].z, root.z, 1e-15);
		assert_close(barb.curve.points[barb.curve.count - 1].x, tip.x, 1e-15);
	}
	printf("constant speed: %d vertices, worst locus error %.2e (emission), %.2e m (vertices), %.2e s (times)\n",
	       checked_points, worst_emit, worst_point, worst_time);
	assert_true(worst_emit <= 1e-10);
	assert_true(worst_point <= 1e-10);
	assert_true(worst_time <= 1e-10);
	release(&g);
}

static void test_rk4_converges_at_fourth_order(void **state)
{
	(void)state;
	// A speed linear in s on the right arc: ds/dt = (a + b s) / L has the exact
	// solution s(t) = (s0 + a/b) exp(b t / L) - a/b; the emitter's clamp time
	// from I_A.right to I_P.right is L / b ln((s_P + a/b) / (s_A + a/b)).
	double a = 0.002, slope = 0.02;
	plume_zk_def def = plume_zk_default_def();
	def.emitter_speed = (plume_zk_curve){.count = 2, .s = {0.0, 1.0}, .value = {a, a + slope}};
	double length = two_pi * def.collar_radius;
	double exact = length / slope * log((def.posterior[1] + a / slope) / (def.anterior[1] + a / slope));
	double errors[2];
	double steps[2] = {0.2, 0.1};
	for (int k = 0; k < 2; ++k) {
		def.step = steps[k];
		generated g = generate(&def, 1);
		errors[k] = fabs(g.report.clamp_time[PLUME_SIDE_RIGHT] - exact);
		release(&g);
	}
	printf("RK4 clamp time errors: h = 0.2: %.3e s, h = 0.1: %.3e s, ratio %.1f\n", errors[0], errors[1],
	       errors[0] / errors[1]);
	assert_true(errors[1] < 1e-6);
	assert_true(errors[0] / errors[1] > 10.0); // 16 for a 4th-order method
}

static void test_termination_and_downsampling(void **state)
{
	(void)state;
	plume_zk_def def = constant_def();
	def.posterior[0] = 0.41; // asymmetric: the right vane (shorter arc) matures first
	def.posterior[1] = 0.39;
	generated g = generate(&def, 1);
	int most = g.report.barb_count_side[0] > g.report.barb_count_side[1] ? 0 : 1;
	assert_int_equal(g.report.barb_count_side[most], def.barb_count);
	assert_true(g.report.barb_count_side[1 - most] <= def.barb_count);
	assert_true(g.report.developing_count > 0);
	double latest = 0.0;
	for (int k = 0; k < g.report.barb_count; ++k) {
		assert_true(g.report.barbs[k].mature);
		latest = fmax(latest, g.report.barbs[k].mature_time);
		// Every f-th step plus both ends: ceil(K / f) + 2 points for K whole steps.
		const plume_zk_barb_report *b = g.report.barbs + k;
		double duration = b->mature_time - b->emit_time;
		long whole = (long)floor(duration / def.step);
		if (fabs(duration / def.step - (double)whole) > 1e-6) { // away from a grid tie
			long expected = whole / def.downsample + 2;
			assert_int_equal(b->vertex_count, expected);
		}
	}
	assert_close(latest, g.report.t_end, 0.0); // the last barb matured at t_end
	assert_close(g.report.t_curr, g.report.t_end, 0.0);
	release(&g);
}

// ---------------------------------------------------------------------------
// IV-B: unfurling

static void test_unfurling_keeps_segment_lengths(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.barb_count = 30;
	def.unfurl_weight = 0.0;
	generated helix = generate(&def, 1);
	double weights[3] = {0.35, 0.8, 1.0};
	for (int w = 0; w < 3; ++w) {
		def.unfurl_weight = weights[w];
		generated flat = generate(&def, 1);
		assert_int_equal(flat.report.barb_count, helix.report.barb_count);
		double worst = 0.0, worst_plane = 0.0, moved = 0.0;
		for (int k = 0; k < flat.report.barb_count; ++k) {
			plume_barb a = plume_feather_barb(helix.feather, k), b = plume_feather_barb(flat.feather, k);
			assert_int_equal(a.curve.count, b.curve.count);
			for (int j = 1; j < a.curve.count; ++j) {
				double la = plume_v3_distance(a.curve.points[j - 1], a.curve.points[j]);
				double lb = plume_v3_distance(b.curve.points[j - 1], b.curve.points[j]);
				worst = fmax(worst, fabs(la - lb));
				moved = fmax(moved, plume_v3_distance(a.curve.points[j], b.curve.points[j]));
				assert_close(a.curve.points[j].y, b.curve.points[j].y, 1e-15); // rotations about u_y only
			}
			if (weights[w] == 1.0 && b.curve.count >= 3) {
				// The plane through the root spanned by u_y and the root's tangent
				// (the first segment's horizontal direction): no best-fit plane is farther.
				plume_vec3 d = plume_v3_sub(b.curve.points[1], b.curve.points[0]);
				plume_vec3 normal = plume_v3_normalize(plume_v3(-d.z, 0.0, d.x));
				for (int j = 0; j < b.curve.count; ++j)
					worst_plane = fmax(worst_plane,
					                   fabs(plume_v3_dot(plume_v3_sub(b.curve.points[j], b.curve.points[0]), normal)));
			}
		}
		printf("w = %.2f: segment lengths kept to %.2e m, points moved up to %.3g m", weights[w], worst, moved);
		if (weights[w] == 1.0)
			printf(", largest distance to the barb's plane %.2e m", worst_plane);
		printf("\n");
		assert_true(worst <= 1e-12);
		assert_true(moved > 1e-3); // it did unfurl
		if (weights[w] == 1.0)
			assert_true(worst_plane <= 1e-12);
		release(&flat);
	}
	release(&helix);
}

static void test_zero_weight_is_the_helix(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.barb_count = 25;
	def.unfurl_weight = 0.0;
	generated g = generate(&def, 1);
	// Every vertex of the helix lies on the collar cylinder (radius R about the collar's axis).
	double worst = 0.0;
	plume_vec3 centre = circle_point(&def, 0.0);
	centre = plume_v3(centre.x, 0.0, centre.z + def.collar_radius); // C(0) is (0, -R)
	for (int k = 0; k < g.report.barb_count; ++k) {
		plume_barb barb = plume_feather_barb(g.feather, k);
		assert_close(g.report.barbs[k].unfurl_weight, 0.0, 0.0);
		for (int j = 0; j < barb.curve.count; ++j) {
			plume_vec3 p = barb.curve.points[j];
			worst = fmax(worst, fabs(hypot(p.x - centre.x, p.z - centre.z) - def.collar_radius));
		}
	}
	printf("w = 0: largest distance from the collar cylinder %.2e m\n", worst);
	assert_true(worst <= 1e-15);
	release(&g);
}

static void test_sheath_weights_per_barb(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.barb_count = 40;
	def.sheath = true;
	def.sheath_height = 0.01;
	def.sheath_ramp = 0.01;
	def.unfurl_weight = 0.9;
	generated g = generate(&def, 1);
	int helical = 0, full = 0;
	for (int k = 0; k < g.report.barb_count; ++k) {
		plume_barb barb = plume_feather_barb(g.feather, k);
		double y = barb.curve.points[0].y;
		double u = fmin(1.0, fmax(0.0, (y - 0.01) / 0.01));
		assert_close(g.report.barbs[k].unfurl_weight, 0.9 * u, 1e-15);
		helical += u == 0.0;
		full += u == 1.0;
	}
	assert_true(helical > 0 && full > 0);
	release(&g);
}

// ---------------------------------------------------------------------------
// Vane asymmetry (Figure 10)

static void vane_widths(const plume_feather *feather, double widths[2])
{
	widths[0] = widths[1] = 0.0;
	plume_feather_info info = plume_feather_get_info(feather);
	for (int k = 0; k < info.barb_count; ++k) {
		plume_barb barb = plume_feather_barb(feather, k);
		for (int j = 0; j < barb.curve.count; ++j)
			widths[barb.side] = fmax(widths[barb.side], fabs(barb.curve.points[j].x));
	}
}

static void test_posterior_shift_makes_vanes_asymmetric(void **state)
{
	(void)state;
	double posterior[3][2] = {{0.51, 0.49}, {0.41, 0.39}, {0.21, 0.19}};
	double widths[3][2];
	for (int k = 0; k < 3; ++k) {
		plume_zk_def def = plume_zk_default_def();
		def.barb_count = 200; // long enough for the wide vane's longest barbs to mature
		def.posterior[0] = posterior[k][0];
		def.posterior[1] = posterior[k][1];
		generated g = generate(&def, 1);
		vane_widths(g.feather, widths[k]);
		printf("I_P <%.2f, %.2f>: left vane %.2f mm, right vane %.2f mm wide\n", posterior[k][0], posterior[k][1],
		       1e3 * widths[k][0], 1e3 * widths[k][1]);
		release(&g);
	}
	assert_close(widths[0][0], widths[0][1], 0.02 * widths[0][0]); // nearly symmetric at 0.5
	for (int k = 1; k < 3; ++k) {
		assert_true(widths[k][1] < widths[k - 1][1]); // the right (distal) vane narrows
		assert_true(widths[k][0] > widths[k - 1][0]); // the left (proximal) vane widens
	}
	assert_true(widths[2][0] > 2.0 * widths[2][1]);
}

// ---------------------------------------------------------------------------
// IV-C: expansion and snapping

/// Distance from p to the polyline.
static double polyline_distance(plume_vec3 p, const plume_vec3 *line, int count)
{
	double best = INFINITY;
	for (int i = 0; i + 1 < count; ++i) {
		plume_vec3 d = plume_v3_sub(line[i + 1], line[i]);
		double dd = plume_v3_dot(d, d);
		double u = dd > 0.0 ? plume_v3_dot(plume_v3_sub(p, line[i]), d) / dd : 0.0;
		u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
		best = fmin(best, plume_v3_distance(p, plume_v3_mad(line[i], u, d)));
	}
	return best;
}

static plume_vec3 barbule_tip(const plume_feather *feather, const plume_barb *barb, int vertex, int kind)
{
	plume_barbule barbule = plume_feather_barbule(feather, barb->barbule_first + 2 * vertex + kind);
	assert_int_equal(barbule.kind, kind);
	return barbule.curve.points[1];
}

/// Checks every snapped vertex of every barb against the boundary of the barb
/// above; returns the worst distance.
static double check_snapping(const generated *g)
{
	double worst = 0.0;
	plume_vec3 line[4096];
	for (int k = 0; k < g->report.barb_count; ++k) {
		const plume_zk_barb_report *b = g->report.barbs + k;
		if (b->snap != PLUME_ZK_SNAP_FULL && b->snap != PLUME_ZK_SNAP_PARTIAL)
			continue;
		// The barb above is the next one in the feather's order (base to tip).
		plume_barb above = plume_feather_barb(g->feather, k + 1), below = plume_feather_barb(g->feather, k);
		assert_int_equal(above.side, below.side);
		assert_true(above.curve.count + 1 <= 4096);
		for (int j = 0; j < above.curve.count; ++j)
			line[1 + j] = barbule_tip(g->feather, &above, j, PLUME_BARBULE_PROXIMAL);
		// The first segment extended to the projection of the root below.
		plume_vec3 d = plume_v3_sub(line[2], line[1]);
		double u = plume_v3_dot(plume_v3_sub(below.curve.points[0], line[1]), d) / plume_v3_dot(d, d);
		line[0] = plume_v3_mad(line[1], fmin(u, 0.0), d);
		for (int j = 0; j < b->snapped_vertices; ++j)
			worst = fmax(worst, polyline_distance(barbule_tip(g->feather, &below, j, PLUME_BARBULE_DISTAL), line,
			                                      above.curve.count + 1));
	}
	return worst;
}

static void test_snapped_barbules_touch_the_barb_above(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.barb_count = 60;
	def.expansion = true;
	generated g = generate(&def, 1);
	double worst = check_snapping(&g);
	int full = g.report.snapped_count, partial = g.report.partial_count;
	printf("snapping: %d full, %d partial, %d unsnapped of %d barbs; distal barbule tips within %.2e m of the "
	       "boundary above\n",
	       full, partial, g.report.unsnapped_count, g.report.barb_count, worst);
	assert_true(full + partial > g.report.barb_count / 2);
	assert_true(worst <= 1e-9);
	// Expansion changes the vane: barbs moved, lengths kept.
	def.expansion = false;
	generated plain = generate(&def, 1);
	double moved = 0.0, length_change = 0.0;
	for (int k = 0; k < g.report.barb_count; ++k) {
		plume_barb a = plume_feather_barb(g.feather, k), b = plume_feather_barb(plain.feather, k);
		moved = fmax(moved, plume_v3_distance(a.curve.points[a.curve.count - 1], b.curve.points[b.curve.count - 1]));
		length_change =
		    fmax(length_change, fabs(a.curve.arc_length[a.curve.count - 1] - b.curve.arc_length[b.curve.count - 1]));
	}
	assert_true(moved > 1e-4);
	assert_true(length_change < 1e-12);
	release(&plain);
	release(&g);
}

static void test_unsnapped_barbs_are_reported(void **state)
{
	(void)state;
	// Barbules far too short to bridge the gap between barbs: Figure 12's flaw everywhere.
	plume_zk_def def = plume_zk_default_def();
	def.barb_count = 30;
	def.expansion = true;
	def.ridge_height = plume_zk_constant(1e-5);
	generated g = generate(&def, 1);
	int tops = 0, skipped = 0;
	for (int k = 0; k < g.report.barb_count; ++k) {
		tops += g.report.barbs[k].snap == PLUME_ZK_SNAP_TOP;
		skipped += g.report.barbs[k].snap == PLUME_ZK_SNAP_SKIPPED;
	}
	assert_int_equal(tops, 2);
	assert_int_equal(skipped, g.report.barb_count - 2);
	assert_int_equal(g.report.unsnapped_count, skipped);
	for (int k = 0; k < g.report.unsnapped_count; ++k)
		assert_int_equal(g.report.barbs[g.report.unsnapped[k]].snap, PLUME_ZK_SNAP_SKIPPED);
	// ... and said in the feather's summary, never silently.
	const char *summary = plume_feather_summary(g.feather);
	assert_non_null(summary);
	char expected[64];
	snprintf(expected, sizeof expected, "\"unsnapped\": %d", skipped);
	assert_non_null(strstr(summary, expected));
	assert_non_null(strstr(summary, "\"unsnapped_barbs\": [{\"barb\": "));
	// Unsnapped barbs are kept as grown.
	def.expansion = false;
	generated plain = generate(&def, 1);
	for (int k = 0; k < g.report.barb_count; ++k) {
		plume_barb a = plume_feather_barb(g.feather, k), b = plume_feather_barb(plain.feather, k);
		for (int j = 0; j < a.curve.count; ++j)
			assert_true(memcmp(a.curve.points + j, b.curve.points + j, sizeof(plume_vec3)) == 0);
	}
	release(&plain);
	release(&g);
}

static void test_split_bends_the_barbs_below(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.barb_count = 50;
	def.expansion = true;
	generated whole = generate(&def, 1);
	def.split_count = 1;
	def.splits[0] = (plume_zk_split){.side = PLUME_SIDE_RIGHT, .barb = 40, .at = 0.3, .angle = 0.3};
	generated split = generate(&def, 1);
	int split_barb = -1;
	for (int k = 0; k < split.report.barb_count; ++k)
		if (split.report.barbs[k].side == PLUME_SIDE_RIGHT && split.report.barbs[k].index == 40)
			split_barb = k;
	assert_true(split_barb >= 0);
	assert_int_equal(split.report.barbs[split_barb].snap, PLUME_ZK_SNAP_SPLIT);
	// The barbs above the split are unchanged; the split barb and the next ones below moved down.
	for (int k = split_barb + 1; k < split.report.barb_count; ++k) {
		plume_barb a = plume_feather_barb(whole.feather, k), b = plume_feather_barb(split.feather, k);
		assert_true(memcmp(a.curve.points, b.curve.points, (size_t)a.curve.count * sizeof(plume_vec3)) == 0);
	}
	for (int k = split_barb; k > split_barb - 3; --k) {
		plume_barb a = plume_feather_barb(whole.feather, k), b = plume_feather_barb(split.feather, k);
		double drop = a.curve.points[a.curve.count - 1].y - b.curve.points[b.curve.count - 1].y;
		printf("split: barb %d (%s) tip dropped by %.3g mm\n", k, k == split_barb ? "the split one" : "below",
		       1e3 * drop);
		assert_true(drop > 1e-3);
	}
	assert_true(check_snapping(&split) <= 1e-9);
	release(&whole);
	release(&split);
}

// ---------------------------------------------------------------------------
// The feather: rachis, stages, collar, determinism, validation, memory

static void test_rachis_from_barb_roots(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	generated g = generate(&def, 1);
	plume_feather_info info = plume_feather_get_info(g.feather);
	const plume_shaft_sample *shaft = plume_feather_shaft(g.feather);
	assert_int_equal(info.shaft_sample_count, def.shaft_samples);
	assert_close(shaft[0].position.y, -def.calamus_length, 0.0);
	double chord = 2.0 * def.collar_radius * sin(two_pi * 0.02);
	assert_close(shaft[0].width, chord, 1e-15);
	assert_close(shaft[info.shaft_sample_count - 1].width, def.rachis_taper * chord, 1e-15);
	double top = shaft[info.shaft_sample_count - 1].position.y, lowest = INFINITY;
	for (int k = 0; k < info.barb_count; ++k) {
		plume_barb barb = plume_feather_barb(g.feather, k);
		plume_vec3 root = barb.curve.points[0];
		// Roots sit on the rachis' edges at the anterior polarity, half the chord from its centre line.
		assert_close(fabs(root.x), 0.5 * chord, 1e-15);
		assert_true(root.y <= top);
		assert_close(barb.rachis_t, (root.y + def.calamus_length) / (top + def.calamus_length), 1e-12);
		lowest = fmin(lowest, root.y);
		// The left vane on -x, facing +z once unfurled.
		assert_true(barb.side == PLUME_SIDE_LEFT ? barb.curve.points[barb.curve.count - 1].x < 0.0
		                                         : barb.curve.points[barb.curve.count - 1].x > 0.0);
		assert_true(barb.curve.normals[0].z > 0.99);
	}
	assert_true(info.calamus_sample_count >= 1);
	assert_true(shaft[info.calamus_sample_count - 1].position.y < lowest);
	assert_true(shaft[info.calamus_sample_count].position.y >= lowest);
	release(&g);
}

static void test_growth_stages(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	generated full = generate(&def, 1);
	def.growth_stage = 0.5;
	generated half = generate(&def, 1);
	assert_close(half.report.t_end, full.report.t_end, 0.0);
	assert_close(half.report.t_curr, 0.5 * full.report.t_end, 1e-12);
	assert_true(half.report.barb_count < full.report.barb_count);
	int developing = 0;
	for (int k = 0; k < half.report.barb_count; ++k) {
		const plume_zk_barb_report *b = half.report.barbs + k;
		assert_true(b->emit_time < half.report.t_curr);
		if (!b->mature) {
			++developing;
			plume_barb barb = plume_feather_barb(half.feather, k);
			assert_close(barb.curve.points[0].y, 0.0, 1e-15); // still growing at the collar
		}
	}
	assert_true(developing > 0);
	assert_int_equal(developing, half.report.developing_count);
	def.growth_stage = 0.0;
	generated start = generate(&def, 1);
	assert_int_equal(start.report.barb_count, 0);
	assert_int_equal(plume_feather_get_info(start.feather).shaft_sample_count, def.shaft_samples);
	release(&start);
	release(&half);
	release(&full);
}

static void test_crest_stops_before_the_bgz(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.barb_count = 12;
	generated g = generate(&def, 1);
	assert_true(isinf(g.report.clamp_time[0]) && isinf(g.report.clamp_time[1]));
	assert_non_null(strstr(plume_feather_summary(g.feather), "\"left\": null"));
	release(&g);
}

static void test_bezier_collar(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.barb_count = 30;
	def.unfurl_weight = 0.0;
	def.collar_kind = PLUME_ZK_COLLAR_BEZIER;
	// An ellipse-like collar, eq. 1's orientation, wider along x.
	plume_vec2 points[6] = {{0.0, -0.008}, {0.011, -0.004}, {0.011, 0.004},
	                        {0.0, 0.008},  {-0.011, 0.004}, {-0.011, -0.004}};
	def.collar_point_count = 6;
	memcpy(def.collar_points, points, sizeof points);
	generated g = generate(&def, 1);
	assert_true(g.report.barb_count > 40);
	// The helix lies on the collar: y-free distance of every vertex to the
	// collar polygon's Bézier is not easy to state, but its extent is the collar's.
	plume_feather_info info = plume_feather_get_info(g.feather);
	assert_true(info.bounds_max.x - info.bounds_min.x < 0.026);
	assert_true(info.bounds_max.x - info.bounds_min.x > 0.018);
	release(&g);
	// The other orientation is refused.
	for (int k = 0; k < 6; ++k)
		def.collar_points[k] = points[5 - k];
	plume_feather *feather = NULL;
	plume_error err = {0};
	assert_int_equal(plume_zk_generate(&def, 1, &feather, NULL, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "$.collar.points run the wrong way"));
	assert_null(feather);
}

static void test_deterministic_and_seeded(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.expansion = true;
	def.barb_count = 40;
	generated a = generate(&def, 3), b = generate(&def, 3), c = generate(&def, 4);
	assert_true(plume_feather_equal(a.feather, b.feather));
	assert_true(plume_feather_equal(a.feather, c.feather)); // no randomness unless asked
	assert_string_equal(plume_feather_summary(a.feather), plume_feather_summary(b.feather));
	plume_feather *copy = plume_feather_clone(a.feather);
	assert_true(plume_feather_equal(copy, a.feather));
	assert_string_equal(plume_feather_summary(copy), plume_feather_summary(a.feather));
	plume_feather_destroy(copy);
	def.ridge_width_variation = 0.3;
	generated d = generate(&def, 3), e = generate(&def, 3), f = generate(&def, 4);
	assert_true(plume_feather_equal(d.feather, e.feather));
	assert_false(plume_feather_equal(d.feather, f.feather));
	release(&a);
	release(&b);
	release(&c);
	release(&d);
	release(&e);
	release(&f);
}

static void expect_invalid(const plume_zk_def *def, const char *fragment)
{
	plume_feather *feather = NULL;
	plume_error err = {0};
	plume_status status = plume_zk_generate(def, 1, &feather, NULL, &err);
	if (status != PLUME_ERROR_SPEC || strstr(err.message, fragment) == NULL)
		fail_msg("expected a spec error with '%s', got %d: %s", fragment, (int)status, err.message);
	assert_null(feather);
}

static void test_bad_definitions(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.posterior[0] = 0.99; // into I_A
	expect_invalid(&def, "$.posterior <0.99, 0.49> and $.anterior <0.98, 0.02> overlap");
	def = plume_zk_default_def();
	def.posterior[1] = 0.6; // right past left
	expect_invalid(&def, "overlap");
	def = plume_zk_default_def();
	def.emitter_speed.value[2] = 0.0;
	expect_invalid(&def, "$.emitter_speed[2]: speed 0 must be positive");
	def = plume_zk_default_def();
	def.barb_speed = plume_zk_constant(-0.01);
	expect_invalid(&def, "$.barb_speed: speed -0.01 must be positive");
	def = plume_zk_default_def();
	def.growth_speed = 0.0;
	expect_invalid(&def, "$.growth_speed is 0");
	def = plume_zk_default_def();
	def.downsample = 0;
	expect_invalid(&def, "$.downsample is 0, allowed [1, 1000]");
	def = plume_zk_default_def();
	def.barb_count = 0;
	expect_invalid(&def, "$.barb_count is 0, allowed [1, 5000]");
	def = plume_zk_default_def();
	def.collar_kind = PLUME_ZK_COLLAR_BEZIER;
	def.collar_point_count = 3;
	expect_invalid(&def, "$.collar.points has 3 control points");
	def = plume_zk_default_def();
	def.emitter_speed.s[3] = 0.4;
	expect_invalid(&def, "loci must increase");
}

/// A growth that cannot end is the spec's error, naming the keys that end it. An emitter
/// too slow for the step passed the step bound; its infinite emission time was stored and
/// gave barbs at y = inf or NaN (eq. 5), written with exit 0 (1e-9: no barbs, t_end null).
static void test_runaway_growth_is_a_spec_error(void **state)
{
	(void)state;
	static const double slow[] = {1e-8, 1e-9};
	for (int k = 0; k < 2; ++k) {
		plume_zk_def def = plume_zk_default_def();
		def.emitter_speed = plume_zk_constant(slow[k]);
		expect_invalid(&def, "$.emitter_speed: the growth does not end: the left emitter needs more than 16000000 "
		                     "steps of $.step (0.02 s)");
	}
	plume_zk_def def = plume_zk_default_def();
	def.emitter_speed = plume_zk_constant(100.0);
	expect_invalid(&def, "the left vane emits more than 200000 barbs before its barb 99 matures; lower "
	                     "$.emitter_speed");
	def = plume_zk_default_def();
	def.barb_count = 1;
	def.barb_speed = plume_zk_constant(1e-8);
	expect_invalid(&def, "a barb needs more than 2000000 steps of $.step (0.02 s)");
	// Each bound above is an item's; their product is not: a fuzzed spec (a 9 m collar, an emitter
	// at 800 m/s on part of it) emitted 86,000 barbs of pathlines 10^4 steps long, 21 s. The steps
	// of all pathlines are bounded too (4e7; the benchmark feather takes 5.6e4).
	def = plume_zk_default_def();
	def.collar_radius = 9.01;
	def.anterior[0] = 0.98, def.anterior[1] = 0.02;
	def.posterior[0] = 0.51, def.posterior[1] = 0.49;
	def.ridge_width = 0.0008;
	def.emitter_speed =
	    (plume_zk_curve){.count = 5, .s = {0.0, 0.25, 0.5, 0.75, 1.0}, .value = {0.012, 800.0, 0.004, 0.008, 0.012}};
	def.barb_speed = plume_zk_constant(0.008);
	def.growth_speed = 0.005;
	def.barb_count = 115;
	def.downsample = 4;
	expect_invalid(&def, "the growth is too long: its pathlines need more than 4e+07 steps of $.step (0.02 s) in all");
	// Finite times near 1e299 (V_e about 1e-300 at I_P, reached in one huge step) whose heights
	// v_grow (t_curr - t) overflow: refused, not built with inf vertices.
	def = plume_zk_default_def();
	def.step = 1e6;
	def.growth_speed = 1e12;
	def.emitter_speed = (plume_zk_curve){
	    .count = 6, .s = {0.0, 0.48, 0.49, 0.51, 0.52, 1.0}, .value = {0.012, 0.012, 1e-300, 1e-300, 0.012, 0.012}};
	expect_invalid(&def, "the feather's heights overflow: v_grow (t_curr - t) (eq. 5) is not finite");
}

/// Splits that cannot bend anything are refused: each gave the feather without the split.
static void test_splits_that_do_nothing_are_refused(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.barb_count = 50;
	def.expansion = true;
	def.split_count = 1;
	def.splits[0] = (plume_zk_split){.side = PLUME_SIDE_RIGHT, .barb = 500, .at = 0.5, .angle = 0.3};
	expect_invalid(&def, "$.splits[0].barb is 500, allowed [0, 49]: a vane has at most $.barb_count (50) barbs");
	// The right vane ends with 49 barbs (its barb 49 still developing at t_end): barb 49 is not there.
	def.splits[0].barb = 49;
	expect_invalid(&def, "$.splits[0].barb is 49, but the right vane has 49 barbs (0 to 48)");
	def.splits[0].side = PLUME_SIDE_LEFT; // the left vane has it
	generated left = generate(&def, 1);
	assert_int_equal(left.report.barbs[0].snap, PLUME_ZK_SNAP_SPLIT); // the left vane's base barb, emitted last
	release(&left);
	// Below stage 1 a split waits for its barb: a growth sequence is not refused for its early frames.
	def.splits[0] = (plume_zk_split){.side = PLUME_SIDE_RIGHT, .barb = 48, .at = 0.5, .angle = 0.3};
	def.growth_stage = 0.1;
	generated young = generate(&def, 1);
	for (int k = 0; k < young.report.barb_count; ++k)
		assert_true(young.report.barbs[k].snap != PLUME_ZK_SNAP_SPLIT);
	release(&young);
	// Without expansion there is no snapping for a split to come before.
	def.growth_stage = 1.0;
	def.expansion = false;
	expect_invalid(&def, "$.splits: a split bends a barb before snapping (IV-C), which runs with \"expansion\": true "
	                     "only");
}

static void test_curve_stays_positive(void **state)
{
	(void)state;
	// Steep data that a plain cubic spline would overshoot below zero.
	plume_zk_curve curve = {.count = 5, .s = {0.0, 0.1, 0.2, 0.6, 1.0}, .value = {1.0, 1.0, 1e-3, 1e-3, 2.0}};
	double lowest = INFINITY;
	for (int i = 0; i <= 10000; ++i)
		lowest = fmin(lowest, plume_zk_curve_eval(&curve, i / 10000.0));
	assert_close(lowest, 1e-3, 1e-15);
	for (int k = 0; k < curve.count; ++k)
		assert_close(plume_zk_curve_eval(&curve, curve.s[k]), curve.value[k], 1e-15);
	assert_close(plume_zk_curve_eval(&curve, 0.5), 1e-3, 1e-15); // flat between equal values
}

/// plume_zk_estimate_bytes is counted before the growth: it must cover the feather built for every example,
/// at full growth and at growth stages that keep the developing barbs, and at full growth stay close
/// (1.01 to 1.40 times the feather; it was 4.4 to 7.3 counting developing barbs the last stage discards).
static void test_estimate_covers_examples(void **state)
{
	(void)state;
	static const char *const names[] = {"figure10-asymmetry-020", "figure11-expansion",  "figure11-split",
	                                    "figure13-crest",         "figure8-contour",     "figure9-tip-angular",
	                                    "figure9-tip-pointed",    "figure9-tip-rounded", "figure11-without-expansion"};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
		char path[512];
		snprintf(path, sizeof path, "%s/examples/zhang-kanai/%s.json", PLUME_SOURCE_DIR, names[i]);
		plume_zk_def def;
		uint64_t seed;
		plume_error err;
		if (plume_zk_def_read(path, &def, &seed, &err) != PLUME_OK)
			fail_msg("%s", err.message);
		static const double stages[] = {1.0, 0.5, 0.9, 0.05};
		for (int k = 0; k < 4; ++k) {
			def.growth_stage = stages[k];
			double estimate = plume_zk_estimate_bytes(&def);
			plume_feather *feather = NULL;
			assert_int_equal(plume_zk_generate(&def, seed, &feather, NULL, &err), PLUME_OK);
			double bytes = plume_feather_bytes(feather);
			print_message("%s stage %.2f: estimate %.0f bytes, feather %.0f bytes (%.2f)\n", names[i], stages[k],
			              estimate, bytes, estimate / bytes);
			assert_true(bytes <= estimate);
			if (k == 0)
				assert_true(estimate <= 1.5 * bytes);
			plume_feather_destroy(feather);
		}
	}
}

/// Barbs ten times slower than the default grow 80 times longer: a 48 MB feather, which the estimate
/// put at 12 GB (every barb the length of the whole collar, and the 9,400 barbs developing at the end
/// that the last stage discards), refusing it at the default 4 GiB limit.
static void test_estimate_of_slow_barbs(void **state)
{
	(void)state;
	plume_zk_def def = plume_zk_default_def();
	def.barb_speed = plume_zk_constant(1e-4);
	double estimate = plume_zk_estimate_bytes(&def);
	plume_spec_options options = {0};
	plume_feather *feather = NULL;
	plume_error err;
	assert_int_equal(
	    plume_spec_parse("{\"model\": \"zhang-kanai\", \"barb_speed\": 1e-4}", "slow.json", &options, &feather, &err),
	    PLUME_OK);
	double bytes = plume_feather_bytes(feather);
	print_message("barb_speed 1e-4: estimate %.0f bytes, feather %.0f bytes\n", estimate, bytes);
	assert_true(bytes <= estimate && estimate <= 1.1 * bytes);
	plume_feather_destroy(feather);
	// Below stage 1 the developing barbs are kept, and counted.
	def.growth_stage = 0.9;
	assert_true(plume_zk_estimate_bytes(&def) > 2.0 * estimate);
}

/// The keys' own ranges allow 5000 barbs a vane traced at a microsecond step: refused before the growth.
static void test_estimate_refuses_dense(void **state)
{
	(void)state;
	const char *json = "{\"model\": \"zhang-kanai\", \"barb_count\": 5000, \"step\": 1e-6, \"downsample\": 1}";
	plume_spec_options options = {0};
	plume_feather *feather = NULL;
	plume_error err;
	assert_int_equal(plume_spec_parse(json, "dense.json", &options, &feather, &err), PLUME_ERROR_LIMIT);
	assert_null(feather);
	print_message("%s\n", err.message);
	// The collar's keys as a spec spells them (it read "$.collar_radius or $.collar_points").
	assert_non_null(strstr(err.message, "dense.json: $.barb_count (5000) and the barbs still growing ($.collar.radius "
	                                    "or $.collar.points, "));
	assert_non_null(strstr(err.message, "the limit is 4.29 GB (raise it with --max-memory"));
}

static void test_spec_stage_options(void **state)
{
	(void)state;
	const char *path = PLUME_SOURCE_DIR "/examples/zhang-kanai/figure8-contour.json";
	plume_spec_options options = {.stage_kind = PLUME_STAGE_UNFURL, .stage = 0.0};
	plume_feather *helix = NULL, *flat = NULL, *young = NULL;
	plume_error err = {0};
	assert_int_equal(plume_spec_generate(path, &options, &helix, &err), PLUME_OK);
	options.stage = 1.0;
	assert_int_equal(plume_spec_generate(path, &options, &flat, &err), PLUME_OK);
	options = (plume_spec_options){.stage_kind = PLUME_STAGE_GROWTH, .stage = 0.25};
	assert_int_equal(plume_spec_generate(path, &options, &young, &err), PLUME_OK);
	plume_feather_info h = plume_feather_get_info(helix), f = plume_feather_get_info(flat),
	                   y = plume_feather_get_info(young);
	assert_int_equal(h.barb_count, f.barb_count);
	assert_true(f.bounds_max.x - f.bounds_min.x > 1.5 * (h.bounds_max.x - h.bounds_min.x));
	assert_true(y.barb_count < f.barb_count);
	assert_true(y.shaft_length < f.shaft_length);
	options.stage = 1.5;
	plume_feather *bad = NULL;
	assert_int_equal(plume_spec_generate(path, &options, &bad, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "stage 1.5 is outside [0, 1]"));
	plume_feather_destroy(helix);
	plume_feather_destroy(flat);
	plume_feather_destroy(young);
}

static void test_no_leaks(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_zk_def def = plume_zk_default_def();
	def.expansion = true;
	def.barb_count = 30;
	generated g = generate(&def, 1);
	release(&g);
	plume_feather *feather = NULL;
	assert_int_equal(plume_zk_generate(&def, 1, &feather, NULL, NULL), PLUME_OK); // no report wanted
	plume_feather_destroy(feather);
	def.barb_count = 0;
	assert_int_equal(plume_zk_generate(&def, 1, &feather, NULL, NULL), PLUME_ERROR_SPEC);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// Unfurling wraps angle differences into (-pi, pi] (zhang_kanai_unfurl.c): a turn at a time
/// for sane values (bit for bit as before), bounded for any value (1e20 and inf looped forever).
static void test_wrap_angle_is_bounded(void **state)
{
	(void)state;
	const double pi = 3.14159265358979323846;
	assert_true(zk_wrap_angle(1.5 * pi) == 1.5 * pi - 2.0 * pi);
	assert_true(zk_wrap_angle(-pi) == -pi + 2.0 * pi);
	assert_true(zk_wrap_angle(0.25) == 0.25);
	double a = 7.0 * pi + 0.5, turned = a;
	while (turned > pi)
		turned -= 2.0 * pi;
	assert_true(zk_wrap_angle(a) == turned);
	double huge = zk_wrap_angle(1e20);
	assert_true(huge > -pi && huge <= pi);
	assert_true(huge == remainder(1e20, 2.0 * pi)); // exact: 1e20 less a whole number of turns
	assert_true(isnan(zk_wrap_angle(INFINITY)));
	assert_true(isnan(zk_wrap_angle(-INFINITY)));
	assert_true(isnan(zk_wrap_angle(NAN)));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_wrap_angle_is_bounded),
	    cmocka_unit_test(test_emitters_monotone_and_clamped),
	    cmocka_unit_test(test_constant_speed_matches_exact_loci),
	    cmocka_unit_test(test_rk4_converges_at_fourth_order),
	    cmocka_unit_test(test_termination_and_downsampling),
	    cmocka_unit_test(test_unfurling_keeps_segment_lengths),
	    cmocka_unit_test(test_zero_weight_is_the_helix),
	    cmocka_unit_test(test_sheath_weights_per_barb),
	    cmocka_unit_test(test_posterior_shift_makes_vanes_asymmetric),
	    cmocka_unit_test(test_snapped_barbules_touch_the_barb_above),
	    cmocka_unit_test(test_unsnapped_barbs_are_reported),
	    cmocka_unit_test(test_split_bends_the_barbs_below),
	    cmocka_unit_test(test_splits_that_do_nothing_are_refused),
	    cmocka_unit_test(test_rachis_from_barb_roots),
	    cmocka_unit_test(test_growth_stages),
	    cmocka_unit_test(test_crest_stops_before_the_bgz),
	    cmocka_unit_test(test_bezier_collar),
	    cmocka_unit_test(test_deterministic_and_seeded),
	    cmocka_unit_test(test_bad_definitions),
	    cmocka_unit_test(test_runaway_growth_is_a_spec_error),
	    cmocka_unit_test(test_curve_stays_positive),
	    cmocka_unit_test(test_spec_stage_options),
	    cmocka_unit_test(test_estimate_covers_examples),
	    cmocka_unit_test(test_estimate_of_slow_barbs),
	    cmocka_unit_test(test_estimate_refuses_dense),
	    cmocka_unit_test(test_no_leaks),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

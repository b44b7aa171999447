#define _POSIX_C_SOURCE 200809L // clock_gettime (bench_support.h)
// Benchmark: contact detection (issue 14). Prints
//  - additive CCD queries per second (point-triangle and edge-edge, separation 0.1) over a
//    seeded random sweep like test_ccd's: generic motions and motions forced to collide,
//    and the time of a query that runs to the iteration limit;
//  - the AABB tree's build, refit and self-overlap query times for 10^4 and 10^5 random
//    boxes sized for about ten overlaps each, beside a brute-force all-pairs count for 10^4.
// One thread; medians of repeated runs, wall and CPU time (read CPU on a shared machine).
//
// Usage: bench_ccd
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "plume/plume.h"
#include "bench_support.h"
#include "sim/bvh.h"
#include "sim/ccd.h"

static plume_vec3 random_point(plume_rng *rng, double half)
{
	return plume_v3(plume_rng_range(rng, -half, half), plume_rng_range(rng, -half, half),
	                plume_rng_range(rng, -half, half));
}

/// Random motions of four points; every other one moved so that the first primitive's
/// point at weights w meets the second's at a random time (an impact to find).
static void make_cases(plume_rng *rng, int split, int count, plume_vec3 *start, plume_vec3 *end)
{
	for (int c = 0; c < count; ++c) {
		plume_vec3 *s = start + 4 * c, *e = end + 4 * c;
		for (int i = 0; i < 4; ++i) {
			s[i] = random_point(rng, 1);
			e[i] = i < split ? random_point(rng, 1) : plume_v3_add(s[i], random_point(rng, 0.3));
		}
		if (c % 2 == 0)
			continue;
		double t = plume_rng_range(rng, 0.05, 0.95), w[4];
		if (split == 1) {
			double a = plume_rng_range(rng, 0, 1), b = plume_rng_range(rng, 0, 1 - a);
			w[0] = 1, w[1] = a, w[2] = b, w[3] = 1 - a - b;
		} else {
			double u = plume_rng_uniform(rng), v = plume_rng_uniform(rng);
			w[0] = 1 - u, w[1] = u, w[2] = 1 - v, w[3] = v;
		}
		plume_vec3 qa = {0, 0, 0}, qb = {0, 0, 0};
		for (int i = 0; i < 4; ++i) {
			plume_vec3 x = plume_v3_lerp(s[i], e[i], t);
			if (i < split)
				qa = plume_v3_mad(qa, w[i], x);
			else
				qb = plume_v3_mad(qb, w[i], x);
		}
		plume_vec3 delta = plume_v3_scale(plume_v3_sub(qb, qa), 1 / t);
		for (int i = 0; i < split; ++i)
			e[i] = plume_v3_add(e[i], delta);
	}
}

static void bench_ccd_queries(const char *name, int split)
{
	enum { CASES = 100000, RUNS = 5 };
	plume_rng rng = plume_rng_seed(14);
	plume_vec3 *start = malloc(4 * CASES * sizeof *start), *end = malloc(4 * CASES * sizeof *end);
	make_cases(&rng, split, CASES, start, end);
	double wall[RUNS], cpu[RUNS], sum = 0;
	int impacts = 0;
	for (int r = 0; r < RUNS; ++r) {
		double w0 = bench_now(), c0 = bench_cpu_now();
		sum = 0;
		impacts = 0;
		for (int c = 0; c < CASES; ++c) {
			double t = split == 1 ? plume_ccd_point_triangle(start + 4 * c, end + 4 * c, 0.1)
			                      : plume_ccd_edge_edge(start + 4 * c, end + 4 * c, 0.1);
			sum += t;
			impacts += t < 1;
		}
		wall[r] = bench_now() - w0;
		cpu[r] = bench_cpu_now() - c0;
	}
	double w = bench_median(wall, RUNS), c = bench_median(cpu, RUNS);
	printf("ccd %-14s %d queries (%d stopped before t = 1, mean t %.3f): %.2f M queries/s wall, %.2f M/s CPU, "
	       "%.0f ns each\n",
	       name, CASES, impacts, sum / CASES, CASES / w * 1e-6, CASES / c * 1e-6, 1e9 * c / CASES);
	free(start);
	free(end);
}

/// The worst case: a point sliding 10 across a triangle 1e-7 above it stops at the
/// iteration limit (about 10^8 steps of the bound would be needed).
static void bench_ccd_worst(void)
{
	plume_vec3 start[4] = {{-5, 0.3, 1e-7}, {-10, 0, 0}, {10, 0, 0}, {0, 10, 0}};
	plume_vec3 end[4] = {{5, 0.3, 1e-7}, {-10, 0, 0}, {10, 0, 0}, {0, 10, 0}};
	enum { RUNS = 5 };
	double cpu[RUNS], t = 0;
	for (int r = 0; r < RUNS; ++r) {
		double c0 = bench_cpu_now();
		t = plume_ccd_point_triangle(start, end, 0.1);
		cpu[r] = bench_cpu_now() - c0;
	}
	printf("ccd worst case (sliding 1e-7 above a face, stopped by the iteration limit at t = %.3g): %.2f ms CPU\n", t,
	       1e3 * bench_median(cpu, RUNS));
}

/// n boxes in the unit cube, sides up to 2.2 times the spacing n^(-1/3): each box
/// meets about ten others.
static plume_aabb *random_boxes(plume_rng *rng, int n)
{
	plume_aabb *boxes = malloc((size_t)n * sizeof *boxes);
	double side = 2.2 * pow(n, -1.0 / 3.0);
	for (int i = 0; i < n; ++i) {
		plume_vec3 lo = plume_v3(plume_rng_uniform(rng), plume_rng_uniform(rng), plume_rng_uniform(rng));
		plume_vec3 size =
		    plume_v3(side * plume_rng_uniform(rng), side * plume_rng_uniform(rng), side * plume_rng_uniform(rng));
		boxes[i] = (plume_aabb){lo, plume_v3_add(lo, size)};
	}
	return boxes;
}

static void bench_bvh(int n, int brute)
{
	enum { RUNS = 5 };
	plume_rng rng = plume_rng_seed((uint64_t)n);
	plume_aabb *boxes = random_boxes(&rng, n), *moved = random_boxes(&rng, n);
	plume_error err = {0};
	double build[RUNS], refit[RUNS], query[RUNS];
	plume_pair_list pairs = {0, 0, NULL};
	plume_bvh *bvh = NULL;
	for (int r = 0; r < RUNS; ++r) {
		plume_bvh_destroy(bvh);
		double c0 = bench_cpu_now();
		bench_check("bench_ccd", plume_bvh_create(boxes, n, &bvh, &err), &err);
		build[r] = bench_cpu_now() - c0;
		pairs.count = 0;
		c0 = bench_cpu_now();
		bench_check("bench_ccd", plume_bvh_overlaps(bvh, bvh, &pairs, &err), &err);
		query[r] = bench_cpu_now() - c0;
		c0 = bench_cpu_now();
		plume_bvh_refit(bvh, r % 2 ? boxes : moved);
		refit[r] = bench_cpu_now() - c0;
		plume_bvh_refit(bvh, boxes);
	}
	printf("bvh %6d boxes, %7d overlapping pairs: build %7.2f ms, refit %6.2f ms, self query %7.2f ms (CPU, median "
	       "of %d)",
	       n, pairs.count, 1e3 * bench_median(build, RUNS), 1e3 * bench_median(refit, RUNS),
	       1e3 * bench_median(query, RUNS), RUNS);
	if (brute) {
		double c0 = bench_cpu_now();
		long count = 0;
		for (int i = 0; i < n; ++i)
			for (int j = i + 1; j < n; ++j) {
				const plume_aabb *a = &boxes[i], *b = &boxes[j];
				count += a->lower.x <= b->upper.x && b->lower.x <= a->upper.x && a->lower.y <= b->upper.y &&
				         b->lower.y <= a->upper.y && a->lower.z <= b->upper.z && b->lower.z <= a->upper.z;
			}
		printf("; all pairs by brute force %.1f ms (%ld pairs)", 1e3 * (bench_cpu_now() - c0), count);
		if (count != pairs.count) {
			fprintf(stderr, "bench_ccd: the tree found %d pairs, brute force %ld\n", pairs.count, count);
			exit(1);
		}
	}
	printf("\n");
	plume_pair_list_free(&pairs);
	plume_bvh_destroy(bvh);
	free(boxes);
	free(moved);
}

int main(void)
{
	bench_ccd_queries("point-triangle", 1);
	bench_ccd_queries("edge-edge", 2);
	bench_ccd_worst();
	bench_bvh(10000, 1);
	bench_bvh(100000, 0);
	return 0;
}

#define _POSIX_C_SOURCE 200809L // clock_gettime (bench_support.h)
// Benchmark: the intersection check (plume_find_intersections, docs/contact.md) on sheets of
// n x n quads: flat in z = 0 (the floating-point filter or the zero-column shortcut decides
// every pair), flat but rotated (its neighbours are coplanar within rounding, so the exact GMP
// fallback decides most of them: the worst case), gently curved (a bent feather), and two
// curved sheets crossing. Prints the median wall-clock time of 3 runs and the pairs found.
//
// Usage: bench_intersect [N] [THREADS]   (default 200: 80,000 triangles a sheet)
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "plume/plume.h"
#include "bench_support.h"

typedef enum shape { FLAT, ROTATED, CURVED } shape;

/// A sheet of side 0.1 m at height z.
static void sheet(int n, shape kind, double z, plume_vec3 *positions, int *triangles, int offset)
{
	// A rotation by 0.3 rad about (1, 2, 3)/|.|, written out (Rodrigues).
	const double angle = 0.3, k[3] = {1 / sqrt(14.0), 2 / sqrt(14.0), 3 / sqrt(14.0)};
	const double c = cos(angle), s = sin(angle);
	for (int i = 0; i <= n; ++i)
		for (int j = 0; j <= n; ++j) {
			double x = 0.1 * i / n, y = 0.1 * j / n, h = z;
			if (kind == CURVED)
				h += 0.01 * sin(20 * x) * cos(15 * y);
			plume_vec3 p = {x, y, h};
			if (kind == ROTATED) {
				plume_vec3 axis = {k[0], k[1], k[2]};
				plume_vec3 cross = plume_v3_cross(axis, p);
				double dot = plume_v3_dot(axis, p);
				p = plume_v3_add(plume_v3_add(plume_v3_scale(p, c), plume_v3_scale(cross, s)),
				                 plume_v3_scale(axis, dot * (1 - c)));
			}
			positions[i * (n + 1) + j] = p;
		}
	int t = 0;
	for (int i = 0; i < n; ++i)
		for (int j = 0; j < n; ++j) {
			int a = offset + i * (n + 1) + j, b = a + n + 1;
			int *f = &triangles[3 * t];
			f[0] = a, f[1] = b, f[2] = b + 1, f[3] = a, f[4] = b + 1, f[5] = a + 1;
			t += 2;
		}
}

static void run(const char *name, const plume_vec3 *positions, int vertex_count, const int *triangles,
                int triangle_count)
{
	double times[3];
	int count = 0;
	for (int r = 0; r < 3; ++r) {
		plume_error err;
		double start = bench_now();
		if (plume_find_intersections(positions, vertex_count, triangles, triangle_count, 0, NULL, &count, &err) !=
		    PLUME_OK) {
			fprintf(stderr, "bench_intersect: %s\n", err.message);
			exit(1);
		}
		times[r] = bench_now() - start;
	}
	double median = bench_median(times, 3);
	printf("%-28s %8d triangles  %8.3f s  %6.2f us/triangle  %d intersecting pairs\n", name, triangle_count, median,
	       1e6 * median / triangle_count, count);
}

int main(int argc, char **argv)
{
	int n = argc > 1 ? atoi(argv[1]) : 200;
	if (argc > 2)
		omp_set_num_threads(atoi(argv[2]));
	int vertices = (n + 1) * (n + 1), faces = 2 * n * n;
	plume_vec3 *positions = malloc(2 * (size_t)vertices * sizeof *positions);
	int *triangles = malloc(6 * (size_t)faces * sizeof *triangles);
	if (positions == NULL || triangles == NULL)
		return 1;
	printf("intersection check, sheets of %d x %d quads, %d threads\n", n, n, omp_get_max_threads());
	sheet(n, FLAT, 0, positions, triangles, 0);
	run("flat sheet (z = 0)", positions, vertices, triangles, faces);
	sheet(n, ROTATED, 0, positions, triangles, 0);
	run("flat sheet, rotated", positions, vertices, triangles, faces);
	sheet(n, CURVED, 0, positions, triangles, 0);
	run("curved sheet", positions, vertices, triangles, faces);
	sheet(n, CURVED, 0.001, positions + vertices, triangles + 3 * faces, vertices);
	run("two curved sheets, 1 mm apart", positions, 2 * vertices, triangles, 2 * faces);
	sheet(n, FLAT, 0, positions + vertices, triangles + 3 * faces, vertices);
	run("curved sheet through flat", positions, 2 * vertices, triangles, 2 * faces);
	free(positions);
	free(triangles);
	return 0;
}

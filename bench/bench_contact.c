#define _POSIX_C_SOURCE 200809L // clock_gettime
// Benchmark: contact in the simulator on a real feather. The hawk of
// examples/scenes/swing.json (e = 5 mm), released flat 1 mm above a ground (two triangles)
// with self-contact on, falls and settles under gravity. Prints, per run: steps, Newton
// iterations per step, the most contact pairs, the smallest pair distance, the time
// split (assembly, factorisation, solve; the rest of a step is contact detection, line
// search and bookkeeping) and wall milliseconds per step (the report times wall time); then the same drop with contact
// off and no ground (what contact costs when it is on). `bench_contact N` runs N steps (default 60).
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "plume/plume.h"

static double wall(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int run(const plume_scene *scene, bool contact, int steps)
{
	plume_sim_def def = scene->sim;
	def.contact.enabled = contact;
	plume_sim *sim = NULL;
	plume_error err = {0};
	if (plume_sim_create(scene->mesh, &def, &sim, &err) != PLUME_OK) {
		fprintf(stderr, "bench_contact: %s\n", err.message);
		return 1;
	}
	const plume_vec3 *x = plume_sim_positions(sim);
	int n = plume_sim_vertex_count(sim);
	plume_vec3 lo = x[0], hi = x[0];
	for (int i = 1; i < n; ++i) {
		lo = plume_v3(fmin(lo.x, x[i].x), fmin(lo.y, x[i].y), fmin(lo.z, x[i].z));
		hi = plume_v3(fmax(hi.x, x[i].x), fmax(hi.y, x[i].y), fmax(hi.z, x[i].z));
	}
	if (contact) {
		// A ground 1 mm below the lowest vertex, normal to gravity (-z in swing.json).
		double z = lo.z - 1e-3, m = 0.1;
		plume_vec3 corners[4] = {plume_v3(lo.x - m, lo.y - m, z), plume_v3(hi.x + m, lo.y - m, z),
		                         plume_v3(hi.x + m, hi.y + m, z), plume_v3(lo.x - m, hi.y + m, z)};
		int triangles[6] = {0, 1, 2, 0, 2, 3}, ground = -1;
		if (plume_sim_add_obstacle(sim, corners, 4, triangles, 2, &ground, &err) != PLUME_OK) {
			fprintf(stderr, "bench_contact: %s\n", err.message);
			plume_sim_destroy(sim);
			return 1;
		}
	}
	double cpu = wall(), assembly = 0, factor = 0, solve = 0, closest = INFINITY, strain = 0;
	int iterations = 0, pairs = 0, retried = 0;
	for (int step = 0; step < steps; ++step) {
		plume_solve_report report;
		if (plume_sim_step(sim, &report, &err) != PLUME_OK) {
			fprintf(stderr, "bench_contact: step %d: %s\n", step, err.message);
			plume_sim_destroy(sim);
			return 1;
		}
		iterations += report.newton_iterations;
		assembly += report.seconds_assembly;
		factor += report.seconds_factor;
		solve += report.seconds_solve;
		pairs = report.contact_pairs > pairs ? report.contact_pairs : pairs;
		closest = fmin(closest, report.min_distance);
		strain = fmax(strain, report.max_barb_strain);
		retried += report.substeps > 1;
	}
	cpu = wall() - cpu;
	printf("%-12s %4d vertices, %d steps (%d retried), %.2f Newton iterations/step, %d pairs at most, "
	       "closest %.3g m, barb strain %.2g\n",
	       contact ? "contact on" : "contact off", n, steps, retried, (double)iterations / steps, pairs, closest,
	       strain);
	printf("             %.1f ms/step (wall): assembly %.1f, factorisation %.1f, solve %.1f, rest %.1f (contact "
	       "detection, line search)\n",
	       1e3 * cpu / steps, 1e3 * assembly / steps, 1e3 * factor / steps, 1e3 * solve / steps,
	       1e3 * (cpu - assembly - factor - solve) / steps);
	plume_sim_destroy(sim);
	return 0;
}

int main(int argc, char **argv)
{
	int steps = argc > 1 ? atoi(argv[1]) : 60;
	plume_scene *scene = NULL;
	plume_error err = {0};
	if (plume_scene_load(PLUME_SOURCE_DIR "/examples/scenes/swing.json", NULL, &scene, &err) != PLUME_OK) {
		fprintf(stderr, "bench_contact: %s\n", err.message);
		return 1;
	}
	int failed = run(scene, true, steps) || run(scene, false, steps);
	plume_scene_destroy(scene);
	return failed;
}

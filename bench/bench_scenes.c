// Benchmark: the two scenes of issue 14 run whole, as `plume simulate` runs them but
// without writing frames — examples/scenes/bird-flap.json (20 feathers on a flapping
// bird, 1.25 wing beats with contact) and examples/scenes/coat-settle.json (64 feathers
// settling on a body). Prints, per scene: feathers, vertices, steps, Newton iterations a
// step, retried steps, the most contact pairs, the closest approach, the independent
// check's intersecting pairs, wall seconds, seconds per wing beat against the issue's
// target (5 minutes a cycle; the paper took 8.5 hours), and the time split: assembly (the
// barrier's terms included), contact detection (broad phase and CCD), factorisation, solve,
// and the rest (the line search's evaluations, the intersection check of the frames).
// `bench_scenes [bird|coat]` runs one of them (default both).
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "plume/plume.h"

typedef struct scene_bench {
	const char *name;
	const char *path;
} scene_bench;

static int run(const scene_bench *bench)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/%s", PLUME_SOURCE_DIR, bench->path);
	plume_scene *scene = NULL;
	plume_error err = {0};
	plume_spec_options options = {0}; // the spec's seed, the finished feathers
	if (plume_scene_load(path, &options, &scene, &err) != PLUME_OK) {
		fprintf(stderr, "bench_scenes: %s\n", err.message);
		return 1;
	}
	plume_scene_summary summary;
	plume_status status = plume_scene_run(scene, NULL, NULL, &summary, &err);
	if (status != PLUME_OK) {
		fprintf(stderr, "bench_scenes: %s: %s\n", bench->name, err.message);
		plume_scene_destroy(scene);
		return 1;
	}
	double simulated = summary.steps * scene->sim.time_step;
	double rest = summary.wall_seconds - summary.seconds_assembly - summary.seconds_factor - summary.seconds_solve -
	              summary.seconds_contact;
	printf("%-5s %3d feathers %5d vertices %4d steps  %.2f Newton iterations a step  %d retried\n", bench->name,
	       summary.feather_count, summary.vertex_count, summary.steps,
	       summary.steps > 0 ? (double)summary.newton_iterations / summary.steps : 0.0, summary.retried_steps);
	printf("      contact pairs (most) %d  closest approach %.3g m  intersecting pairs %d over %d frames  "
	       "barb strain %.2g\n",
	       summary.contact_pairs_max, summary.min_distance, summary.intersecting_pairs, summary.frames_checked,
	       summary.max_barb_strain);
	printf("      wall %.2f s for %.4g s simulated", summary.wall_seconds, simulated);
	if (scene->cycle_period > 0 && simulated > 0) {
		double per_cycle = summary.wall_seconds / (simulated / scene->cycle_period);
		printf(": %.2f s a cycle (target 300 s: %.3f of it; the paper: 8.5 h, %.0f times longer)", per_cycle,
		       per_cycle / 300.0, 8.5 * 3600.0 / per_cycle);
	}
	printf("\n      split: assembly %.2f s (%.0f %%), contact detection (broad phase, CCD) %.2f s (%.0f %%), "
	       "factorisation %.2f s (%.0f %%), solve %.2f s (%.0f %%), the rest (line search, frame checks, "
	       "bookkeeping) %.2f s (%.0f %%)\n",
	       summary.seconds_assembly, 100 * summary.seconds_assembly / summary.wall_seconds, summary.seconds_contact,
	       100 * summary.seconds_contact / summary.wall_seconds, summary.seconds_factor,
	       100 * summary.seconds_factor / summary.wall_seconds, summary.seconds_solve,
	       100 * summary.seconds_solve / summary.wall_seconds, rest, 100 * rest / summary.wall_seconds);
	plume_scene_destroy(scene);
	return summary.intersecting_pairs == 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
	static const scene_bench benches[] = {
	    {"bird", "examples/scenes/bird-flap.json"},
	    {"coat", "examples/scenes/coat-settle.json"},
	};
	int failed = 0, ran = 0;
	for (size_t i = 0; i < sizeof benches / sizeof benches[0]; ++i) {
		if (argc > 1 && strcmp(argv[1], benches[i].name) != 0)
			continue;
		failed |= run(benches + i);
		++ran;
	}
	if (ran == 0) {
		fprintf(stderr, "bench_scenes: unknown scene \"%s\"; allowed: bird, coat\n", argv[1]);
		return 2;
	}
	return failed;
}

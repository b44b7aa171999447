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
//
// `bench_scenes feathers` runs every example feather of the three generators (examples/
// franco-walter, streit-heidrich, zhang-kanai) through two scenes at e = 5 mm with the
// mesher's default band widths and Table 6.1's materials: hanging from its calamus for 0.5 s
// (Figure 1's tilted gravity, the default integrator, BDF2) and falling through air for 1 s (falling.json's
// air, BDF2). Per feather and scene: steps completed of those asked for, Newton iterations a
// step, retried steps and wall seconds. The sweep that found the Streit-Heidrich peacock
// failing and the small feathers' slow falls (docs/simulation.md, "Linear algebra").
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
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

static int compare_names(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/// The example feather specs of one generator's folder, sorted; *count of them. NULL when
/// the folder cannot be read.
static char **list_specs(const char *folder, int *count)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/examples/%s", PLUME_SOURCE_DIR, folder);
	DIR *dir = opendir(path);
	if (dir == NULL)
		return NULL;
	char **names = NULL;
	int n = 0;
	for (struct dirent *entry; (entry = readdir(dir)) != NULL;) {
		size_t length = strlen(entry->d_name);
		if (length < 6 || strcmp(entry->d_name + length - 5, ".json") != 0)
			continue;
		char **grown = realloc(names, sizeof *names * (size_t)(n + 1));
		if (grown == NULL)
			break;
		names = grown;
		names[n] = malloc(strlen(path) + length + 2);
		if (names[n] == NULL)
			break;
		sprintf(names[n++], "%s/%s", path, entry->d_name);
	}
	closedir(dir);
	qsort(names, (size_t)n, sizeof *names, compare_names);
	*count = n;
	return names;
}

/// One feather through one scene (the scene's JSON members after "feather" and "mesh");
/// prints a row. Returns 1 when the scene cannot be read, 0 otherwise (a run that stops
/// early is reported, not failed: the sweep measures).
static int run_feather(const char *spec, const char *kind, const char *members, double duration)
{
	char text[2048];
	snprintf(text, sizeof text, "{\"feather\": \"%s\", \"mesh\": {\"edge_length\": 0.005}, %s, \"duration\": %g}", spec,
	         members, duration);
	plume_scene *scene = NULL;
	plume_error err = {0};
	plume_spec_options options = {0};
	if (plume_scene_parse(text, spec, &options, &scene, &err) != PLUME_OK) {
		fprintf(stderr, "bench_scenes: %s\n", err.message);
		return 1;
	}
	int asked = (int)ceil(duration / scene->sim.time_step - 1e-9);
	plume_scene_summary summary;
	plume_status status = plume_scene_run(scene, NULL, NULL, &summary, &err);
	const char *name = strrchr(spec, '/');
	const char *folder = name - 1;
	while (folder > spec && folder[-1] != '/')
		--folder;
	printf("%-16.*s %-32s %-5s %4d/%-4d steps %8.2f Newton iterations a step %3d retried %7.2f s wall%s%s\n",
	       (int)(name - folder), folder, name + 1, kind, summary.steps, asked,
	       summary.steps > 0 ? (double)summary.newton_iterations / summary.steps : 0.0, summary.retried_steps,
	       summary.wall_seconds, status == PLUME_OK ? "" : "  stopped: ", status == PLUME_OK ? "" : err.message);
	plume_scene_destroy(scene);
	return 0;
}

static int run_feathers(void)
{
	static const char *const folders[] = {"franco-walter", "streit-heidrich", "zhang-kanai"};
	static const char hang[] = "\"handles\": [{\"group\": \"rachis_clamp\"}], \"gravity\": [-9.661, 0, -1.703], "
	                           "\"time_step\": 0.011";
	static const char fall[] = "\"gravity\": [0, 0, -9.81], \"air\": {\"density\": 1.2, \"normal_drag\": 1.17, "
	                           "\"tangential_drag\": 0.07}, \"integrator\": \"bdf2\", \"time_step\": 0.011";
	int failed = 0;
	for (size_t f = 0; f < sizeof folders / sizeof folders[0]; ++f) {
		int count = 0;
		char **specs = list_specs(folders[f], &count);
		if (specs == NULL) {
			fprintf(stderr, "bench_scenes: cannot list examples/%s\n", folders[f]);
			return 1;
		}
		for (int i = 0; i < count; ++i) {
			failed |= run_feather(specs[i], "hang", hang, 0.5);
			failed |= run_feather(specs[i], "fall", fall, 1.0);
			free(specs[i]);
		}
		free(specs);
	}
	return failed;
}

int main(int argc, char **argv)
{
	if (argc > 1 && strcmp(argv[1], "feathers") == 0)
		return run_feathers();
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
		fprintf(stderr, "bench_scenes: unknown scene \"%s\"; allowed: bird, coat, feathers\n", argv[1]);
		return 2;
	}
	return failed;
}

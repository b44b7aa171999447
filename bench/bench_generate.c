#define _POSIX_C_SOURCE 200809L // clock_gettime (bench_support.h)
// Benchmark: the hawk preset (2 vanes x 2200 barbs x 30 samples) — generation,
// export and a 2000 x 2000 PNG render. Prints medians over repeated runs.
//
// Usage: bench_generate [SPEC.json] [OUTPUT_DIR]   (defaults: the hawk preset, /tmp)
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "plume/plume.h"
#include "bench_support.h"

int main(int argc, char **argv)
{
	const char *spec = argc > 1 ? argv[1] : PLUME_SOURCE_DIR "/examples/franco-walter/hawk.json";
	const char *dir = argc > 2 ? argv[2] : "/tmp";
	plume_error err = {0};
	plume_fw_def def;
	uint64_t seed;
	bench_check("bench_generate", plume_fw_def_read(spec, &def, &seed, &err), &err);

	enum { GENERATE_RUNS = 41, EXPORT_RUNS = 5, RENDER_RUNS = 3 };
	double times[GENERATE_RUNS];
	plume_feather *feather = NULL;
	for (int i = 0; i < GENERATE_RUNS; ++i) {
		plume_feather_destroy(feather);
		double start = bench_now();
		bench_check("bench_generate", plume_fw_generate(&def, seed, &feather, &err), &err);
		times[i] = bench_now() - start;
	}
	plume_feather_info info = plume_feather_get_info(feather);
	printf("feather: %s\n", spec);
	printf("  barbs %d (%d per vane), points %d, shaft samples %d, memory %.1f MiB\n", info.barb_count,
	       info.barb_count_left, info.point_count, info.shaft_sample_count, plume_bytes_in_use() / 1048576.0);
	double generate_median = bench_median(times, GENERATE_RUNS); // sorts: times[0] is then the minimum
	printf("generate            median %8.3f ms   (min %.3f ms, %d runs, one thread)\n", 1e3 * generate_median,
	       1e3 * times[0], GENERATE_RUNS);

	// The result is ~10 MiB: see bench_keep_heap.
	bench_keep_heap();
	for (int i = 0; i < GENERATE_RUNS; ++i) {
		plume_feather_destroy(feather);
		double start = bench_now();
		bench_check("bench_generate", plume_fw_generate(&def, seed, &feather, &err), &err);
		times[i] = bench_now() - start;
	}
	generate_median = bench_median(times, GENERATE_RUNS);
	printf("generate, heap kept median %8.3f ms   (min %.3f ms, %d runs, one thread)\n", 1e3 * generate_median,
	       1e3 * times[0], GENERATE_RUNS);

	static const char *const names[] = {"obj", "usda", "json"};
	for (int format = 0; format < 3; ++format) {
		char path[4096];
		snprintf(path, sizeof path, "%s/bench-feather.%s", dir, names[format]);
		for (int i = 0; i < EXPORT_RUNS; ++i) {
			double start = bench_now();
			plume_status status = format == 0   ? plume_write_obj(feather, path, &err)
			                      : format == 1 ? plume_write_usda(feather, path, &err)
			                                    : plume_write_json(feather, path, &err);
			bench_check("bench_generate", status, &err);
			times[i] = bench_now() - start;
		}
		FILE *file = fopen(path, "rb");
		long size = 0;
		if (file != NULL) {
			fseek(file, 0, SEEK_END);
			size = ftell(file);
			fclose(file);
		}
		printf("export %-4s         median %8.1f ms   (%.1f MiB, %d runs)\n", names[format],
		       1e3 * bench_median(times, EXPORT_RUNS), size / 1048576.0, EXPORT_RUNS);
		remove(path);
	}

	plume_render2d_def render = plume_render2d_default_def();
	render.width = render.height = 2000;
	char path[4096];
	snprintf(path, sizeof path, "%s/bench-feather.png", dir);
	for (int i = 0; i < RENDER_RUNS; ++i) {
		double start = bench_now();
		bench_check("bench_generate", plume_render2d(feather, &render, PLUME_IMAGE_PNG, path, &err), &err);
		times[i] = bench_now() - start;
	}
	printf("render PNG 2000x2000 median %8.1f ms   (%d runs)\n", 1e3 * bench_median(times, RENDER_RUNS), RENDER_RUNS);
	remove(path);

	plume_feather_destroy(feather);
	struct rusage usage;
	getrusage(RUSAGE_SELF, &usage);
	printf("peak resident memory %.1f MiB\n", usage.ru_maxrss / 1024.0);
	return 0;
}

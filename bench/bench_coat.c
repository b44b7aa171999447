#define _POSIX_C_SOURCE 200809L // clock_gettime (bench_support.h)
// Benchmark: feather coats (Streit & Heidrich 4.4). The paper's Figure 15 (64
// feathers, "computed in real time" on a 2002 PC) and a 10,000-feather coat,
// built with OpenMP over the follicles. Prints medians; the 64-feather coat
// also with the heap kept, as a long-running program sees it.
//
// Usage: bench_coat [THREADS]   (default: OpenMP's choice)
#define _GNU_SOURCE
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "plume/coat.h"
#include "plume/plume.h"
#include "bench_support.h"

/// Median seconds, wall-clock and CPU.
typedef struct coat_time {
	double wall, cpu;
} coat_time;

/// Median seconds to build the coat of spec over runs; prints its size.
static coat_time time_coat(const char *name, const char *spec, int runs)
{
	double times[32], cpu[32];
	int feathers = 0;
	long long points = 0;
	for (int r = 0; r < runs; ++r) {
		plume_coat *coat = NULL;
		plume_error err = {0};
		plume_spec_options options = {0};
		double start = bench_now(), cpu_start = bench_cpu_now();
		if (plume_coat_spec_generate(spec, &options, &coat, &err) != PLUME_OK) {
			fprintf(stderr, "bench_coat: %s\n", err.message);
			exit(1);
		}
		times[r] = bench_now() - start;
		cpu[r] = bench_cpu_now() - cpu_start;
		feathers = plume_coat_feather_count(coat);
		points = 0;
		for (int i = 0; i < feathers; ++i)
			points += plume_feather_get_info(plume_coat_feather(coat, i)).point_count;
		plume_coat_destroy(coat);
	}
	qsort(times, (size_t)runs, sizeof times[0], bench_compare);
	qsort(cpu, (size_t)runs, sizeof cpu[0], bench_compare);
	double median = times[runs / 2];
	// CPU time (all threads) tells what the cores did when other processes share them.
	printf("%-30s %6d feathers %9lld barb points  median %8.2f ms wall, %8.2f ms CPU (%d runs)\n", name, feathers,
	       points, 1e3 * median, 1e3 * cpu[runs / 2], runs);
	return (coat_time){median, cpu[runs / 2]};
}

int main(int argc, char **argv)
{
	if (argc > 1)
		omp_set_num_threads(atoi(argv[1]));
	printf("bench_coat: %d OpenMP threads\n", omp_get_max_threads());
	coat_time small =
	    time_coat("Figure 15 (64 feathers)", PLUME_SOURCE_DIR "/examples/coats/figure15-hexagonal.json", 21);

	// 10,000 feathers: a 100 x 100 hexagonal patch of the same key feathers, at the paper's low level of
	// detail for a coat this size (four control vertices per barb, Figure 8).
	char dir[] = "/tmp/plume-bench-coat-XXXXXX";
	if (mkdtemp(dir) == NULL) {
		perror("bench_coat");
		return 1;
	}
	char spec[256];
	snprintf(spec, sizeof spec, "%s/coat10k.json", dir);
	FILE *file = fopen(spec, "w");
	if (file == NULL) {
		perror("bench_coat");
		return 1;
	}
	double s = 0.01, width = 99.5 * s, height = 99.0 * s * 0.8660254037844386 + 1e-6;
	const char *keys = PLUME_SOURCE_DIR "/examples/coats/key-";
	fprintf(file,
	        "{\"model\": \"coat\", \"seed\": 1, \"surface\": {\"type\": \"plane\", \"size\": [%.17g, %.17g]},\n"
	        " \"follicles\": {\"layout\": \"hexagonal\", \"spacing\": %g},\n"
	        " \"key_feathers\": [{\"at\": [0, 0], \"feather\": \"%scontour.json\"},"
	        " {\"at\": [%.17g, 0], \"feather\": \"%splume.json\"},"
	        " {\"at\": [%.17g, %.17g], \"feather\": \"%scontour.json\"},"
	        " {\"at\": [0, %.17g], \"feather\": \"%splume.json\"}],\n"
	        " \"lift_deg\": 20, \"lod\": {\"barb_elevations\": 0, \"rachis_elevations\": 4}}\n",
	        width, height, s, keys, width, keys, width, height, keys, height, keys);
	fclose(file);
	coat_time large = time_coat("100 x 100 hexagonal (10,000)", spec, 3);
	remove(spec);
	rmdir(dir);
	// Last, as it changes the process: a coat's 6 MiB of points then come from a kept heap instead of pages
	// the kernel maps and zeroes afresh for every coat (see bench_keep_heap).
	bench_keep_heap();
	time_coat("Figure 15, heap kept", PLUME_SOURCE_DIR "/examples/coats/figure15-hexagonal.json", 21);
	// Issue 15: the 64-feather coat in 10 ms of one core (CPU time, which other processes on the machine do
	// not inflate as they do wall time); the 10,000-feather coat in 3 s wall.
	printf("targets: 64 feathers <= 10 ms CPU (%s), 10,000 < 3 s wall (%s)\n", small.cpu <= 0.010 ? "met" : "missed",
	       large.wall < 3.0 ? "met" : "missed");
	return 0;
}

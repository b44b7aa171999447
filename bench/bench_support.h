// Shared by the benchmarks: clocks, medians, and stopping on an error.
#ifndef PLUME_BENCH_SUPPORT_H
#define PLUME_BENCH_SUPPORT_H

#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "plume/core.h"

/// Wall-clock seconds (monotonic).
static inline double bench_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/// CPU seconds of the whole process, every thread.
static inline double bench_cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline int bench_compare(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/// Sorts values in place (values[0] is then the minimum) and returns their median.
static inline double bench_median(double *values, int count)
{
	qsort(values, (size_t)count, sizeof *values, bench_compare);
	return count % 2 ? values[count / 2] : 0.5 * (values[count / 2 - 1] + values[count / 2]);
}

/// Keeps freed memory in the process from now on. A result of many MiB in a few large
/// blocks is otherwise mapped fresh from the kernel each time, and zero-filling those
/// pages is a large share of a generation; a long-running program (an editor, a coat
/// builder) keeps its heap, and this measures what generation costs then (glibc).
static inline void bench_keep_heap(void)
{
	mallopt(M_MMAP_THRESHOLD, 256 << 20);
	mallopt(M_TRIM_THRESHOLD, 512 << 20);
}

/// Stops the benchmark with the error's message.
static inline void bench_check(const char *program, plume_status status, const plume_error *err)
{
	if (status != PLUME_OK) {
		fprintf(stderr, "%s: %s\n", program, err->message);
		exit(1);
	}
}

#endif

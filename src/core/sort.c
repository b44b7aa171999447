// Counting sorts of integer pairs (sort.h).
#include "core/sort.h"

#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

static int compare_pairs(const void *a, const void *b)
{
	const int *p = a, *q = b;
	if (p[0] != q[0])
		return (p[0] > q[0]) - (p[0] < q[0]);
	return (p[1] > q[1]) - (p[1] < q[1]);
}

/// One stable counting-sort pass: from's pairs into to, ordered by their component
/// (0: i, 1: j), each < range. start holds range + 1 ints of scratch.
static void counting_pass(const int *from, int *to, int count, int component, int range, int *start)
{
	memset(start, 0, ((size_t)range + 1) * sizeof *start);
	for (int k = 0; k < count; ++k)
		++start[from[2 * k + component] + 1];
	for (int r = 0; r < range; ++r)
		start[r + 1] += start[r];
	for (int k = 0; k < count; ++k) {
		int d = start[from[2 * k + component]]++;
		to[2 * d] = from[2 * k];
		to[2 * d + 1] = from[2 * k + 1];
	}
}

int plume_sort_pairs(int *pairs, int count, int ni, int nj)
{
	if (count < 2)
		return 0;
	if (count < 256 || (size_t)count < ((size_t)ni + (size_t)nj) / 8) {
		qsort(pairs, (size_t)count, 2 * sizeof *pairs, compare_pairs);
		return 0;
	}
	int range = ni > nj ? ni : nj;
	int *scratch = plume_alloc((size_t)count * 2 * sizeof *scratch);
	int *start = plume_alloc(((size_t)range + 1) * sizeof *start);
	if (scratch == NULL || start == NULL) {
		plume_free(scratch);
		plume_free(start);
		return -1;
	}
	counting_pass(pairs, scratch, count, 1, nj, start);
	counting_pass(scratch, pairs, count, 0, ni, start);
	plume_free(scratch);
	plume_free(start);
	return 0;
}

// Shared helpers for the cmocka tests: scratch folders, whole-file reads,
// hashes, and the feathers the tests build.
#ifndef PLUME_TEST_SUPPORT_H
#define PLUME_TEST_SUPPORT_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "plume/plume.h"

/// A fresh empty folder under /tmp, unique to this process; removed by test_remove_tree.
void test_make_temp_dir(char *out, size_t size);
/// rm -r path (used at teardown).
void test_remove_tree(const char *path);
/// Reads a whole file into a malloc'd buffer; NULL when missing. *size receives its length.
unsigned char *test_read_file(const char *path, size_t *size);
/// Writes text to path (fixtures).
void test_write_file(const char *path, const char *text);
/// FNV-1a 64 of a file's bytes; 0 when missing.
uint64_t test_hash_file(const char *path);
/// True when path exists.
int test_file_exists(const char *path);
/// Number of entries in a folder (hidden ones included), -1 when it does not exist.
int test_count_entries(const char *path);

/// Coordinate k of a vertex array seen as 3 n numbers (x0 y0 z0 x1 ...), for the finite
/// differences of energies over vertex positions; and its setter.
double test_coordinate(const plume_vec3 *x, int k);
void test_set_coordinate(plume_vec3 *x, int k, double value);
/// Euclidean norm of n numbers.
double test_norm(const double *v, int n);

/// Asserts that |a - b| <= tolerance, printing both on failure.
#define assert_close(a, b, tolerance)                                                                                  \
	do {                                                                                                               \
		double assert_close_a = (a), assert_close_b = (b);                                                             \
		if (!(fabs(assert_close_a - assert_close_b) <= (tolerance)))                                                   \
			fail_msg("%s = %.17g, %s = %.17g, differ by %.3g > %.3g", #a, assert_close_a, #b, assert_close_b,          \
			         fabs(assert_close_a - assert_close_b), (double)(tolerance));                                      \
	} while (0)

#endif

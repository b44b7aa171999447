// The contact broad phase (sim/bvh.h, issue 14): the overlapping pairs of a tree with
// itself and of two trees equal those of a brute-force all-pairs check, before and after a
// refit, on random boxes with touching, degenerate and repeated boxes among them; empty
// trees; the order of the pairs; out-of-memory paths.
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

#include "sim/bvh.h"

/// n random boxes in [0, 1]^3, sides up to size. Every fifth is snapped to a grid of
/// 1/8 with integer sides, so faces touch exactly; every seventh is a point; box 3k+1
/// repeats box 3k when repeat is set.
static plume_aabb *random_boxes(plume_rng *rng, int n, double size, int repeat)
{
	plume_aabb *boxes = malloc((size_t)(n > 0 ? n : 1) * sizeof *boxes);
	for (int i = 0; i < n; ++i) {
		double lo[3], hi[3];
		for (int k = 0; k < 3; ++k) {
			if (i % 5 == 0) {
				lo[k] = (double)(plume_rng_next(rng) % 8) / 8.0;
				hi[k] = lo[k] + (double)(plume_rng_next(rng) % 2) / 8.0;
			} else {
				lo[k] = plume_rng_uniform(rng);
				hi[k] = i % 7 == 0 ? lo[k] : lo[k] + size * plume_rng_uniform(rng);
			}
		}
		boxes[i] = (plume_aabb){{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
		if (repeat && i % 3 == 1)
			boxes[i] = boxes[i - 1];
	}
	return boxes;
}

/// Closed boxes overlap when their intervals overlap on every axis (touching counts).
static int brute_overlap(plume_aabb a, plume_aabb b)
{
	double al[3] = {a.lower.x, a.lower.y, a.lower.z}, au[3] = {a.upper.x, a.upper.y, a.upper.z};
	double bl[3] = {b.lower.x, b.lower.y, b.lower.z}, bu[3] = {b.upper.x, b.upper.y, b.upper.z};
	for (int k = 0; k < 3; ++k)
		if (al[k] > bu[k] || bl[k] > au[k])
			return 0;
	return 1;
}

/// All pairs (i, j) in lexicographic order, i < j when self.
static plume_pair_list brute_pairs(const plume_aabb *a, int na, const plume_aabb *b, int nb, int self)
{
	plume_pair_list list = {0, 0, NULL};
	for (int i = 0; i < na; ++i)
		for (int j = self ? i + 1 : 0; j < nb; ++j)
			if (brute_overlap(a[i], b[j])) {
				if (list.count == list.capacity) {
					list.capacity = list.capacity ? 2 * list.capacity : 64;
					list.pairs = realloc(list.pairs, (size_t)list.capacity * 2 * sizeof *list.pairs);
				}
				list.pairs[2 * list.count] = i;
				list.pairs[2 * list.count + 1] = j;
				++list.count;
			}
	return list;
}

static void assert_same_pairs(const plume_pair_list *got, int first, const plume_pair_list *expected)
{
	if (got->count - first != expected->count)
		fail_msg("%d pairs, brute force %d", got->count - first, expected->count);
	for (int k = 0; k < expected->count; ++k) {
		const int *g = got->pairs + 2 * (first + k), *e = expected->pairs + 2 * k;
		if (g[0] != e[0] || g[1] != e[1])
			fail_msg("pair %d: (%d, %d), brute force (%d, %d)", k, g[0], g[1], e[0], e[1]);
	}
}

static void check_self(const plume_bvh *bvh, const plume_aabb *boxes, int n)
{
	plume_pair_list got = {0, 0, NULL};
	plume_error err = {0};
	assert_int_equal(plume_bvh_overlaps(bvh, bvh, &got, &err), PLUME_OK);
	plume_pair_list expected = brute_pairs(boxes, n, boxes, n, 1);
	assert_same_pairs(&got, 0, &expected);
	plume_pair_list_free(&got);
	free(expected.pairs);
}

static void check_two(const plume_bvh *a, const plume_aabb *boxes_a, int na, const plume_bvh *b,
                      const plume_aabb *boxes_b, int nb)
{
	plume_pair_list got = {0, 0, NULL};
	plume_error err = {0};
	assert_int_equal(plume_bvh_overlaps(a, b, &got, &err), PLUME_OK);
	plume_pair_list expected = brute_pairs(boxes_a, na, boxes_b, nb, 0);
	assert_same_pairs(&got, 0, &expected);
	plume_pair_list_free(&got);
	free(expected.pairs);
}

static void test_self_overlaps_match_brute_force(void **state)
{
	(void)state;
	int64_t bytes = plume_bytes_in_use();
	plume_rng rng = plume_rng_seed(14);
	const int sizes[] = {1, 2, 3, 7, 64, 1000};
	for (int s = 0; s < (int)(sizeof sizes / sizeof *sizes); ++s) {
		int n = sizes[s];
		plume_aabb *boxes = random_boxes(&rng, n, 0.1, 1);
		plume_bvh *bvh = NULL;
		plume_error err = {0};
		assert_int_equal(plume_bvh_create(boxes, n, &bvh, &err), PLUME_OK);
		check_self(bvh, boxes, n);
		// New boxes, same tree: the refit tree answers for the new ones.
		free(boxes);
		boxes = random_boxes(&rng, n, 0.2, 0);
		plume_bvh_refit(bvh, boxes);
		check_self(bvh, boxes, n);
		plume_bvh_destroy(bvh);
		free(boxes);
	}
	assert_int_equal(plume_bytes_in_use(), bytes);
}

static void test_two_tree_overlaps_match_brute_force(void **state)
{
	(void)state;
	int64_t bytes = plume_bytes_in_use();
	plume_rng rng = plume_rng_seed(1414);
	const int sizes[][2] = {{1, 1}, {1, 50}, {50, 1}, {300, 700}, {700, 300}, {3000, 800}, {800, 3000}};
	for (int s = 0; s < 7; ++s) {
		int na = sizes[s][0], nb = sizes[s][1];
		plume_aabb *boxes_a = random_boxes(&rng, na, 0.08, 1), *boxes_b = random_boxes(&rng, nb, 0.05, 0);
		plume_bvh *a = NULL, *b = NULL;
		plume_error err = {0};
		assert_int_equal(plume_bvh_create(boxes_a, na, &a, &err), PLUME_OK);
		assert_int_equal(plume_bvh_create(boxes_b, nb, &b, &err), PLUME_OK);
		check_two(a, boxes_a, na, b, boxes_b, nb);
		check_two(b, boxes_b, nb, a, boxes_a, na);
		free(boxes_b);
		boxes_b = random_boxes(&rng, nb, 0.15, 1);
		plume_bvh_refit(b, boxes_b);
		check_two(a, boxes_a, na, b, boxes_b, nb);
		// Two trees over the same boxes report (i, i) too, unlike a tree with itself.
		plume_bvh *a2 = NULL;
		assert_int_equal(plume_bvh_create(boxes_a, na, &a2, &err), PLUME_OK);
		check_two(a, boxes_a, na, a2, boxes_a, na);
		plume_bvh_destroy(a2);
		plume_bvh_destroy(a);
		plume_bvh_destroy(b);
		free(boxes_a);
		free(boxes_b);
	}
	assert_int_equal(plume_bytes_in_use(), bytes);
}

/// Boxes in a mesh's grid order, in organ-pipe order (the worst case of a median-of-three
/// selection) and all equal: many equal centres along an axis, unit cells whose faces
/// touch their neighbours'.
static void test_structured_orders(void **state)
{
	(void)state;
	enum { N = 1200 };
	plume_aabb *boxes = malloc(N * sizeof *boxes);
	for (int order = 0; order < 3; ++order) {
		for (int i = 0; i < N; ++i) {
			int k = order == 1 ? (i < N / 2 ? i : N - 1 - i) : i;
			double x = order == 2 ? 0 : k % 40, y = order == 2 ? 0 : k / 40;
			boxes[i] = (plume_aabb){{x, y, 0}, {x + 1, y + 1, 1}};
		}
		plume_bvh *bvh = NULL;
		plume_error err = {0};
		assert_int_equal(plume_bvh_create(boxes, N, &bvh, &err), PLUME_OK);
		check_self(bvh, boxes, N);
		plume_bvh_destroy(bvh);
	}
	free(boxes);
}

static void test_empty_trees(void **state)
{
	(void)state;
	int64_t bytes = plume_bytes_in_use();
	plume_aabb box = {{0, 0, 0}, {1, 1, 1}};
	plume_bvh *empty = NULL, *one = NULL;
	plume_error err = {0};
	assert_int_equal(plume_bvh_create(NULL, 0, &empty, &err), PLUME_OK);
	assert_non_null(empty);
	assert_int_equal(plume_bvh_create(&box, 1, &one, &err), PLUME_OK);
	plume_bvh_refit(empty, NULL);
	plume_pair_list list = {0, 0, NULL};
	assert_int_equal(plume_bvh_overlaps(empty, empty, &list, &err), PLUME_OK);
	assert_int_equal(plume_bvh_overlaps(empty, one, &list, &err), PLUME_OK);
	assert_int_equal(plume_bvh_overlaps(one, empty, &list, &err), PLUME_OK);
	assert_int_equal(plume_bvh_overlaps(one, one, &list, &err), PLUME_OK);
	assert_int_equal(list.count, 0);
	// The same box in two trees does overlap.
	plume_bvh *other = NULL;
	assert_int_equal(plume_bvh_create(&box, 1, &other, &err), PLUME_OK);
	assert_int_equal(plume_bvh_overlaps(one, other, &list, &err), PLUME_OK);
	assert_int_equal(list.count, 1);
	assert_int_equal(list.pairs[0], 0);
	assert_int_equal(list.pairs[1], 0);
	plume_pair_list_free(&list);
	assert_null(list.pairs);
	assert_int_equal(list.count, 0);
	plume_pair_list_free(&list); // twice is harmless
	plume_bvh_destroy(empty);
	plume_bvh_destroy(one);
	plume_bvh_destroy(other);
	plume_bvh_destroy(NULL);
	assert_int_equal(plume_bytes_in_use(), bytes);
}

/// The pairs come sorted and the same on every build; a query appends after what the list
/// holds and leaves that alone.
static void test_order_and_determinism(void **state)
{
	(void)state;
	plume_rng rng = plume_rng_seed(7);
	enum { N = 2000 };
	plume_aabb *boxes = random_boxes(&rng, N, 0.06, 1);
	plume_bvh *first = NULL, *second = NULL;
	plume_error err = {0};
	assert_int_equal(plume_bvh_create(boxes, N, &first, &err), PLUME_OK);
	assert_int_equal(plume_bvh_create(boxes, N, &second, &err), PLUME_OK);
	plume_pair_list a = {0, 0, NULL}, b = {0, 0, NULL};
	assert_int_equal(plume_bvh_overlaps(first, first, &a, &err), PLUME_OK);
	assert_true(a.count > N); // the check has pairs to order
	for (int k = 1; k < a.count; ++k) {
		const int *p = a.pairs + 2 * (k - 1), *q = a.pairs + 2 * k;
		assert_true(p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]));
		assert_true(q[0] < q[1]);
	}
	// A list that already holds pairs (the first query's) keeps them, then the new ones.
	assert_int_equal(plume_bvh_overlaps(second, second, &b, &err), PLUME_OK);
	assert_int_equal(plume_bvh_overlaps(second, second, &b, &err), PLUME_OK);
	assert_int_equal(b.count, 2 * a.count);
	assert_memory_equal(b.pairs, a.pairs, (size_t)a.count * 2 * sizeof *a.pairs);
	assert_memory_equal(b.pairs + 2 * a.count, a.pairs, (size_t)a.count * 2 * sizeof *a.pairs);
	plume_pair_list_free(&a);
	plume_pair_list_free(&b);
	plume_bvh_destroy(first);
	plume_bvh_destroy(second);
	free(boxes);
}

// An allocator that fails the k-th allocation (as in test_faults.c).
static atomic_long s_count, s_fail_at;
static void *failing_alloc(size_t size)
{
	long k = atomic_fetch_add(&s_count, 1) + 1;
	return k == atomic_load(&s_fail_at) ? NULL : malloc(size);
}
static void plain_free(void *memory) { free(memory); }

/// Every allocation of a create and of a query fails in turn: a memory error, nothing
/// leaked, and a query's list as it was.
static void test_out_of_memory(void **state)
{
	(void)state;
	plume_rng rng = plume_rng_seed(3);
	enum { N = 3000 };
	plume_aabb *boxes = random_boxes(&rng, N, 0.1, 0);
	int64_t bytes = plume_bytes_in_use();
	for (long k = 1;; ++k) {
		atomic_store(&s_count, 0);
		atomic_store(&s_fail_at, k);
		plume_set_allocator(failing_alloc, plain_free);
		plume_bvh *bvh = NULL;
		plume_error err = {0};
		plume_status status = plume_bvh_create(boxes, N, &bvh, &err);
		plume_set_allocator(NULL, NULL);
		if (status == PLUME_OK) {
			plume_bvh_destroy(bvh);
			assert_true(k > 1);
			break;
		}
		assert_int_equal(status, PLUME_ERROR_MEMORY);
		assert_null(bvh);
		assert_int_equal(plume_bytes_in_use(), bytes);
	}
	plume_bvh *bvh = NULL;
	plume_error err = {0};
	assert_int_equal(plume_bvh_create(boxes, N, &bvh, &err), PLUME_OK);
	for (long k = 1;; ++k) {
		plume_pair_list list = {0, 0, NULL};
		atomic_store(&s_count, 0);
		atomic_store(&s_fail_at, k);
		plume_set_allocator(failing_alloc, plain_free);
		plume_status status = plume_bvh_overlaps(bvh, bvh, &list, &err);
		plume_set_allocator(NULL, NULL);
		if (status == PLUME_OK) {
			plume_pair_list_free(&list);
			assert_true(k > 2);
			break;
		}
		assert_int_equal(status, PLUME_ERROR_MEMORY);
		assert_int_equal(list.count, 0);
		plume_pair_list_free(&list);
	}
	plume_bvh_destroy(bvh);
	assert_int_equal(plume_bytes_in_use(), bytes);
	free(boxes);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_self_overlaps_match_brute_force),
	    cmocka_unit_test(test_two_tree_overlaps_match_brute_force),
	    cmocka_unit_test(test_structured_orders),
	    cmocka_unit_test(test_empty_trees),
	    cmocka_unit_test(test_order_and_determinism),
	    cmocka_unit_test(test_out_of_memory),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

// Fault injection (issue 17): an allocator, installed with plume_set_allocator,
// that fails the k-th allocation. Each public entry point runs once to count
// its allocations N, then once for each sampled k in [1, N]: the call must
// return an error status (no crash, no abort), and plume_bytes_in_use must
// come back to where it was (no leak on the error path).
//
// `make test` samples about SAMPLES values of k per entry point (the first
// ones, where set-up code lives, and then evenly spaced ones); with
// PLUME_FAULTS_FULL=1 in the environment every k runs (a separate .ci/run step).
// Only libplume's own allocations go through the hook: jansson, Embree, cairo
// and CHOLMOD allocate on their own.
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

enum { SAMPLES = 24 };

static _Atomic long s_count = 0;
static _Atomic long s_fail_at = 0; // 0: never

static void *failing_alloc(size_t size)
{
	long n = atomic_fetch_add(&s_count, 1) + 1;
	if (n == atomic_load(&s_fail_at))
		return NULL;
	return malloc(size);
}

static void plain_free(void *memory) { free(memory); }

typedef plume_status entry_fn(void);

/// Runs fn with the k-th allocation failing (k = 0: none); returns its status
/// and checks that nothing leaked.
static plume_status run_failing_at(entry_fn *fn, long k, const char *name)
{
	int64_t before = plume_bytes_in_use();
	atomic_store(&s_count, 0);
	atomic_store(&s_fail_at, k);
	plume_set_allocator(failing_alloc, plain_free);
	plume_status status = fn();
	plume_set_allocator(NULL, NULL);
	int64_t after = plume_bytes_in_use();
	if (after != before)
		fail_msg("%s: allocation %ld failed: %lld bytes leaked (status %s)", name, k, (long long)(after - before),
		         plume_status_name(status));
	return status;
}

static void sweep(entry_fn *fn, const char *name)
{
	assert_int_equal(run_failing_at(fn, 0, name), PLUME_OK);
	long total = atomic_load(&s_count);
	assert_true(total > 0);
	const char *full = getenv("PLUME_FAULTS_FULL");
	bool every = (full != NULL && strcmp(full, "1") == 0) || total <= SAMPLES;
	long tried = 0, first = SAMPLES / 2;
	for (long k = 1; k <= total; ++k) {
		// The first allocations, then evenly spaced ones, and always the last.
		if (!every && k > first && k != total && (k - first) % ((total - first) / (SAMPLES - first) + 1) != 0)
			continue;
		plume_status status = run_failing_at(fn, k, name);
		// A failed allocation inside a parallel loop may be skipped by a retry path
		// only if the result is still right; every entry point here must report it.
		if (status == PLUME_OK)
			fail_msg("%s: allocation %ld of %ld failed but the call returned PLUME_OK", name, k, total);
		++tried;
	}
	print_message("%s: %ld allocations, %ld failure points tried\n", name, total, tried);
}

// ---------------------------------------------------------------------------
// Entry points, each self-contained (creates and destroys what it uses)

static plume_status generate(const char *relative)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/examples/%s", PLUME_SOURCE_DIR, relative);
	plume_feather *feather = NULL;
	plume_status status = plume_spec_generate(path, NULL, &feather, NULL);
	plume_feather_destroy(feather);
	return status;
}

static plume_status generate_fw(void) { return generate("franco-walter/filoplume.json"); }
static plume_status generate_sh(void) { return generate("streit-heidrich/bristle.json"); }
static plume_status generate_zk(void) { return generate("zhang-kanai/figure9-tip-rounded.json"); }

static plume_status coat(void)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/examples/coats/figure15-hexagonal.json", PLUME_SOURCE_DIR);
	plume_coat *c = NULL;
	plume_status status = plume_coat_spec_generate(path, NULL, &c, NULL);
	plume_coat_destroy(c);
	return status;
}

/// The blue feather, made without the hook (the entry points below start from it).
static plume_feather *s_feather = NULL;
static plume_mesh *s_mesh = NULL;

static plume_status mesh(void)
{
	plume_mesh_def def = plume_mesh_default_def();
	def.edge_length = 0.01;
	plume_mesh *m = NULL;
	plume_status status = plume_mesh_from_feather(s_feather, &def, &m, NULL, NULL);
	plume_mesh_destroy(m);
	return status;
}

static plume_status sim_create_step(void)
{
	plume_sim_def def = plume_sim_default_def();
	plume_sim *sim = NULL;
	plume_status status = plume_sim_create(s_mesh, &def, &sim, NULL);
	plume_solve_report report;
	if (status == PLUME_OK)
		status = plume_sim_step(sim, &report, NULL);
	plume_sim_destroy(sim);
	return status;
}

static char s_dir[512];

static plume_status render2d(void)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/feather.png", s_dir);
	plume_render2d_def def = plume_render2d_default_def();
	def.width = 64;
	def.height = 96;
	return plume_render2d(s_feather, &def, PLUME_IMAGE_PNG, path, NULL);
}

static plume_status raytrace(void)
{
	const plume_feather *list[1] = {s_feather};
	plume_raytrace_scene scene = {.feather_count = 1, .feathers = list};
	plume_raytrace_def def = plume_raytrace_default_def();
	def.camera.width = 24;
	def.camera.height = 32;
	def.spp = 1;
	uint8_t rgba[24 * 32 * 4];
	return plume_raytrace_render(&scene, &def, rgba, NULL, NULL);
}

static plume_lab_spec s_lab;

static plume_status traction(void)
{
	plume_traction_result result;
	plume_status status = plume_lab_traction(&s_lab.material, &s_lab.sample, &s_lab.traction, &result, NULL);
	if (status == PLUME_OK)
		plume_traction_result_free(&result);
	return status;
}

static int setup(void **state)
{
	(void)state;
	char path[1024];
	snprintf(path, sizeof path, "%s/examples/franco-walter/filoplume.json", PLUME_SOURCE_DIR);
	plume_error err = {0};
	if (plume_spec_generate(path, NULL, &s_feather, &err) != PLUME_OK)
		return -1;
	plume_mesh_def def = plume_mesh_default_def();
	def.edge_length = 0.01;
	if (plume_mesh_from_feather(s_feather, &def, &s_mesh, NULL, &err) != PLUME_OK)
		return -1;
	snprintf(path, sizeof path, "%s/examples/lab/longitudinal-mesoscale.json", PLUME_SOURCE_DIR);
	if (plume_lab_spec_load(path, &s_lab, &err) != PLUME_OK)
		return -1;
	s_lab.traction.steps = 2;
	test_make_temp_dir(s_dir, sizeof s_dir);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	plume_mesh_destroy(s_mesh);
	plume_feather_destroy(s_feather);
	test_remove_tree(s_dir);
	return 0;
}

static void test_generate_franco_walter(void **state) { (void)state, sweep(generate_fw, "generate franco-walter"); }
static void test_generate_streit_heidrich(void **state) { (void)state, sweep(generate_sh, "generate streit-heidrich"); }
static void test_generate_zhang_kanai(void **state) { (void)state, sweep(generate_zk, "generate zhang-kanai"); }
static void test_coat(void **state) { (void)state, sweep(coat, "coat"); }
static void test_mesh(void **state) { (void)state, sweep(mesh, "mesh"); }
static void test_sim_create_step(void **state) { (void)state, sweep(sim_create_step, "sim create + step"); }
static void test_render2d(void **state) { (void)state, sweep(render2d, "render2d"); }
static void test_raytrace(void **state) { (void)state, sweep(raytrace, "raytrace"); }
static void test_traction(void **state) { (void)state, sweep(traction, "lab traction"); }

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_generate_franco_walter),
	    cmocka_unit_test(test_generate_streit_heidrich),
	    cmocka_unit_test(test_generate_zhang_kanai),
	    cmocka_unit_test(test_coat),
	    cmocka_unit_test(test_mesh),
	    cmocka_unit_test(test_sim_create_step),
	    cmocka_unit_test(test_render2d),
	    cmocka_unit_test(test_raytrace),
	    cmocka_unit_test(test_traction),
	};
	// PLUME_FAULTS_FILTER=test_mesh runs one entry point (to trace a finding in gdb).
	if (getenv("PLUME_FAULTS_FILTER") != NULL)
		cmocka_set_test_filter(getenv("PLUME_FAULTS_FILTER"));
	return cmocka_run_group_tests_name("faults", tests, setup, teardown);
}

// Programmer-error asserts (src/core/asserts.h), which stay on in Release builds: each
// misuse below runs in a forked child that must die of SIGABRT after printing
// "assertion failed" with a file and line; the same calls used correctly return.
// A definition struct that was never initialised from its *_default_def() is
// filled with a byte pattern (what stack garbage looks like) rather than zeros.
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "support.h"

// What a child did: exited with a status, or was killed by a signal; and what it printed.
typedef struct outcome {
	bool signaled;
	int code; ///< exit status, or the signal's number
	char stderr_text[1024];
} outcome;

typedef void misuse_fn(void);

static outcome run_child(misuse_fn *body)
{
	char path[] = "/tmp/plume-asserts-XXXXXX";
	int fd = mkstemp(path);
	assert_true(fd >= 0);
	fflush(NULL);
	pid_t pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		dup2(fd, STDERR_FILENO);
		body();
		_exit(0);
	}
	int status = 0;
	assert_int_equal(waitpid(pid, &status, 0), pid);
	outcome out = {0};
	out.signaled = WIFSIGNALED(status);
	out.code = out.signaled ? WTERMSIG(status) : WEXITSTATUS(status);
	ssize_t n = pread(fd, out.stderr_text, sizeof out.stderr_text - 1, 0);
	out.stderr_text[n > 0 ? n : 0] = '\0';
	close(fd);
	unlink(path);
	return out;
}

/// The child aborts, and its message names a source file and the failed condition.
static void expect_abort(misuse_fn *body, const char *condition_part)
{
	outcome out = run_child(body);
	if (!out.signaled || out.code != SIGABRT)
		fail_msg("expected SIGABRT, got %s %d; stderr: %s", out.signaled ? "signal" : "exit", out.code,
		         out.stderr_text);
	assert_non_null(strstr(out.stderr_text, "plume: "));
	assert_non_null(strstr(out.stderr_text, ".c:"));
	assert_non_null(strstr(out.stderr_text, "assertion failed: "));
	if (strstr(out.stderr_text, condition_part) == NULL)
		fail_msg("\"%s\" not in: %s", condition_part, out.stderr_text);
}

/// The control: the child returns normally.
static void expect_return(misuse_fn *body)
{
	outcome out = run_child(body);
	if (out.signaled || out.code != 0)
		fail_msg("expected exit 0, got %s %d; stderr: %s", out.signaled ? "signal" : "exit", out.code, out.stderr_text);
}

#define GARBAGE(type, name)                                                                                            \
	type name;                                                                                                         \
	memset(&name, 0x5a, sizeof name)

static plume_feather *small_feather(void)
{
	plume_fw_def def = plume_fw_default_def();
	def.segments[0].barb_count = 10; // a few barbs: the children stay quick
	def.segments[1].barb_count = 20;
	plume_feather *feather = NULL;
	if (plume_fw_generate(&def, 1, &feather, NULL) != PLUME_OK)
		_exit(3);
	return feather;
}

static plume_mesh *small_sample(void)
{
	plume_sample_def sample = plume_sample_default_def();
	sample.element_count = 40;
	plume_mesh *mesh = NULL;
	if (plume_sample_mesh(&sample, NULL, &mesh, NULL) != PLUME_OK)
		_exit(3);
	return mesh;
}

// ---------------------------------------------------------------------------
// Definitions not from their *_default_def(): one child per struct.

#define COOKIE "PLUME_DEF_COOKIE"

static void bad_fw(void)
{
	GARBAGE(plume_fw_def, def);
	plume_feather *out;
	plume_fw_generate(&def, 1, &out, NULL);
}

static void bad_sh(void)
{
	GARBAGE(plume_sh_def, def);
	plume_feather *out;
	plume_sh_generate(&def, 1, 1.0, &out, NULL);
}

static void bad_zk(void)
{
	GARBAGE(plume_zk_def, def);
	plume_feather *out;
	plume_zk_generate(&def, 1, &out, NULL, NULL);
}

static void bad_sim(void)
{
	plume_mesh *mesh = small_sample();
	GARBAGE(plume_sim_def, def);
	plume_sim *sim;
	plume_sim_create(mesh, &def, &sim, NULL);
}

static void bad_gltf(void)
{
	plume_feather *feather = small_feather();
	GARBAGE(plume_gltf_def, def);
	plume_write_glb(feather, &def, "/nonexistent/never-written.glb", NULL);
}

static void bad_sample(void)
{
	GARBAGE(plume_sample_def, sample);
	plume_mesh *out;
	plume_sample_mesh(&sample, NULL, &out, NULL);
}

static void bad_band(void)
{
	plume_sample_def sample = plume_sample_default_def();
	GARBAGE(plume_band_def, bands);
	plume_mesh *out;
	plume_sample_mesh(&sample, &bands, &out, NULL);
}

static void bad_traction(void)
{
	plume_lab_material material = plume_lab_material_default(PLUME_LAB_MACROSCALE);
	plume_sample_def sample = plume_sample_default_def();
	GARBAGE(plume_traction_def, def);
	plume_traction_result result;
	plume_lab_traction(&material, &sample, &def, &result, NULL);
}

static void bad_calibration(void)
{
	GARBAGE(plume_calibration_def, def);
	plume_calibration_result result;
	plume_lab_calibrate(&def, &result, NULL);
}

static void bad_study(void)
{
	GARBAGE(plume_study_def, def);
	plume_lab_study(&def, "/nonexistent/a.csv", NULL, NULL, NULL, 0, NULL);
}

static void bad_raytrace(void)
{
	GARBAGE(plume_raytrace_def, def);
	plume_raytrace_scene scene = {0};
	uint8_t rgba[4];
	plume_raytrace_render(&scene, &def, rgba, NULL, NULL);
}

static void bad_render2d(void)
{
	plume_feather *feather = small_feather();
	GARBAGE(plume_render2d_def, def);
	plume_render2d(feather, &def, PLUME_IMAGE_PNG, "/nonexistent/never-written.png", NULL);
}

static void bad_shell_view(void)
{
	plume_mesh *mesh = small_sample();
	GARBAGE(plume_shell_view_def, def);
	plume_render_shell_png(mesh, NULL, &def, "/nonexistent/never-written.png", NULL);
}

static void bad_mesh(void)
{
	plume_feather *feather = small_feather();
	GARBAGE(plume_mesh_def, def);
	plume_mesh *out;
	plume_mesh_from_feather(feather, &def, &out, NULL, NULL);
}

static void null_def(void)
{
	plume_feather *out;
	plume_fw_generate(NULL, 1, &out, NULL);
}

static void test_uninitialised_definitions(void **state)
{
	(void)state;
	misuse_fn *bodies[] = {bad_fw,       bad_sh,         bad_zk,       bad_sim,         bad_gltf,
	                       bad_sample,   bad_band,       bad_traction, bad_study,       bad_raytrace,
	                       bad_render2d, bad_shell_view, null_def,     bad_calibration, bad_mesh};
	for (size_t i = 0; i < sizeof bodies / sizeof bodies[0]; ++i)
		expect_abort(bodies[i], COOKIE);
}

// The controls: the same calls with definitions from *_default_def() do not abort.
static void good_definitions(void)
{
	plume_feather *feather = small_feather();
	plume_gltf_def gltf = plume_gltf_default_def();
	plume_render2d_def image = plume_render2d_default_def();
	plume_error err;
	// Unwritable paths: the calls return an error status instead of aborting.
	if (plume_write_glb(feather, &gltf, "/nonexistent/never-written.glb", &err) == PLUME_OK ||
	    plume_render2d(feather, &image, PLUME_IMAGE_PNG, "/nonexistent/never-written.png", &err) == PLUME_OK)
		_exit(4);
	plume_sh_def sh = plume_sh_default_def();
	plume_zk_def zk = plume_zk_default_def();
	plume_mesh *mesh = small_sample();
	plume_sim_def sim_def = plume_sim_default_def();
	plume_band_def bands = plume_band_default_def();
	plume_sample_def sample = plume_sample_default_def();
	plume_traction_def traction = plume_traction_default_def();
	plume_lab_material material = plume_lab_material_default(PLUME_LAB_MESOSCALE);
	if (plume_sh_def_validate(&sh, NULL) != PLUME_OK || plume_zk_def_validate(&zk, NULL) != PLUME_OK ||
	    plume_sim_def_validate(&sim_def, 2, NULL) != PLUME_OK ||
	    plume_sample_validate(&sample, &bands, NULL) != PLUME_OK ||
	    plume_lab_validate(&material, &sample, &traction, NULL) != PLUME_OK)
		_exit(5);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
}

static void test_default_definitions_pass(void **state)
{
	(void)state;
	expect_return(good_definitions);
}

// ---------------------------------------------------------------------------
// Indices out of range and NULL handles.

static plume_sim *small_sim(void)
{
	plume_mesh *mesh = small_sample();
	plume_sim_def def = plume_sim_default_def();
	plume_sim *sim = NULL;
	if (plume_sim_create(mesh, &def, &sim, NULL) != PLUME_OK)
		_exit(3);
	plume_mesh_destroy(mesh);
	return sim;
}

static const plume_mat3 IDENTITY = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};

static void handle_in_range(void)
{
	plume_sim *sim = small_sim();
	int handle = plume_sim_add_handle(sim, "bottom", NULL);
	if (handle != 0)
		_exit(6);
	plume_sim_set_handle(sim, handle, plume_v3(0, 1e-4, 0), IDENTITY, plume_v3(0, 0, 0));
	plume_sim_destroy(sim);
}

static void handle_past_the_end(void)
{
	plume_sim *sim = small_sim();
	int handle = plume_sim_add_handle(sim, "bottom", NULL);
	plume_sim_set_handle(sim, handle + 1, plume_v3(0, 0, 0), IDENTITY, plume_v3(0, 0, 0));
}

static void handle_negative(void)
{
	plume_sim *sim = small_sim();
	plume_sim_set_handle(sim, -1, plume_v3(0, 0, 0), IDENTITY, plume_v3(0, 0, 0));
}

static void barb_past_the_end(void)
{
	plume_feather *feather = small_feather();
	plume_feather_barb(feather, plume_feather_get_info(feather).barb_count);
}

static void barbule_negative(void)
{
	plume_feather *feather = small_feather();
	plume_feather_barbule(feather, -1);
}

static void test_index_out_of_range(void **state)
{
	(void)state;
	expect_return(handle_in_range);
	expect_abort(handle_past_the_end, "(index) < (sim->handle_count)");
	expect_abort(handle_negative, "(index) >= 0");
	expect_abort(barb_past_the_end, "feather->barb_count");
	expect_abort(barbule_negative, "(i) >= 0");
}

static void null_sim_step(void) { plume_sim_step(NULL, NULL, NULL); }
static void null_sim_positions(void) { plume_sim_positions(NULL); }
static void null_feather_info(void) { plume_feather_get_info(NULL); }
static void null_feather_barb(void) { plume_feather_barb(NULL, 0); }
static void null_embedding(void) { plume_embedding_point_count(NULL); }
static void null_coat(void) { plume_coat_feather_count(NULL); }

static void test_null_handles(void **state)
{
	(void)state;
	misuse_fn *bodies[] = {null_sim_step,     null_sim_positions, null_feather_info,
	                       null_feather_barb, null_embedding,     null_coat};
	for (size_t i = 0; i < sizeof bodies / sizeof bodies[0]; ++i)
		expect_abort(bodies[i], "!= NULL");
}

int main(void)
{
#ifdef PLUME_DISABLE_ASSERTS
	puts("test_asserts: skipped, libplume was built with PLUME_DISABLE_ASSERTS");
	return 0;
#endif
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_uninitialised_definitions),
	    cmocka_unit_test(test_default_definitions_pass),
	    cmocka_unit_test(test_index_out_of_range),
	    cmocka_unit_test(test_null_handles),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

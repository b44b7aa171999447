// Feather specs: every class of bad input gets its message and nothing else.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "support.h"

static char dir[256];

static int setup(void **state)
{
	(void)state;
	test_make_temp_dir(dir, sizeof dir);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	test_remove_tree(dir);
	return 0;
}

/// Writes text to a spec file in the scratch folder and returns its path.
static const char *spec_file(const char *name, const char *text)
{
	static char path[512];
	snprintf(path, sizeof path, "%s/%s", dir, name);
	test_write_file(path, text);
	return path;
}

static void expect_error(const char *text, plume_status status, const char *fragment)
{
	int64_t before = plume_bytes_in_use();
	const char *path = spec_file("spec.json", text);
	plume_feather *feather = NULL;
	plume_error err = {0};
	assert_int_equal(plume_spec_generate(path, NULL, &feather, &err), status);
	assert_null(feather);
	if (strstr(err.message, fragment) == NULL)
		fail_msg("message '%s' lacks '%s'", err.message, fragment);
	if (strncmp(err.message, path, strlen(path)) != 0)
		fail_msg("message '%s' does not start with the file name", err.message);
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_minimal_spec_is_the_default_feather(void **state)
{
	(void)state;
	const char *path = spec_file("minimal.json", "{\"model\": \"franco-walter\"}");
	plume_feather *from_spec = NULL, *from_def = NULL;
	assert_int_equal(plume_spec_generate(path, NULL, &from_spec, NULL), PLUME_OK);
	plume_fw_def def = plume_fw_default_def();
	assert_int_equal(plume_fw_generate(&def, 1, &from_def, NULL), PLUME_OK);
	assert_true(plume_feather_equal(from_spec, from_def));
	plume_feather_destroy(from_spec);
	plume_feather_destroy(from_def);
}

static void test_keys_reach_the_definition(void **state)
{
	(void)state;
	const char *path = spec_file(
	    "full.json", "{\"model\": \"franco-walter\", \"seed\": 77,\n"
	                 " \"shaft\": [[0,0],[0,0.01],[0,0.02],[0,0.03]],\n"
	                 " \"left_outline\": [[0,0.01],[-0.01,0.012],[-0.01,0.02],[-0.005,0.03],[0,0.031]],\n"
	                 " \"calamus_fraction\": 0.3, \"second_segment_start\": 0.5,\n"
	                 " \"shaft_samples\": 12, \"barb_samples\": 7,\n"
	                 " \"shaft_width_base\": 0.001, \"shaft_width_tip\": 0.0002,\n"
	                 " \"barb_width_base\": 0.0001, \"barb_width_tip\": 0.00002,\n"
	                 " \"segments\": [{\"barb_count\": 3, \"length_variation\": 0.1, \"shape_variation\": 0.2,\n"
	                 "   \"symmetric_vanes\": false, \"uniform_shape\": false, \"uniform_length\": true},\n"
	                 "  {\"barb_count\": 5}]}");
	plume_fw_def def;
	uint64_t seed = 0;
	plume_error err = {0};
	assert_int_equal(plume_fw_def_read(path, &def, &seed, &err), PLUME_OK);
	assert_int_equal(seed, 77);
	assert_close(def.shaft[3].y, 0.03, 0.0);
	assert_close(def.left_outline[1].x, -0.01, 0.0);
	assert_true(def.mirror_right_outline);
	assert_close(def.calamus_fraction, 0.3, 0.0);
	assert_close(def.second_segment_start, 0.5, 0.0);
	assert_int_equal(def.shaft_samples, 12);
	assert_int_equal(def.barb_samples, 7);
	assert_close(def.barb_width_tip, 0.00002, 0.0);
	assert_int_equal(def.segments[0].barb_count, 3);
	assert_false(def.segments[0].symmetric_vanes);
	assert_true(def.segments[0].uniform_length);
	assert_int_equal(def.segments[1].barb_count, 5);
	// Unset segment keys keep the defaults.
	plume_fw_def defaults = plume_fw_default_def();
	assert_close(def.segments[1].shape_variation, defaults.segments[1].shape_variation, 0.0);

	plume_feather *feather = NULL;
	assert_int_equal(plume_spec_generate(path, NULL, &feather, &err), PLUME_OK);
	assert_int_equal(plume_feather_get_info(feather).barb_count, 16);
	plume_feather_destroy(feather);
}

static void test_seed_option_overrides_spec(void **state)
{
	(void)state;
	const char *path = spec_file("seeded.json", "{\"model\": \"franco-walter\", \"seed\": 5}");
	plume_feather *a = NULL, *b = NULL, *c = NULL;
	plume_spec_options five = {.seed = 5, .seed_given = true}, six = {.seed = 6, .seed_given = true};
	assert_int_equal(plume_spec_generate(path, NULL, &a, NULL), PLUME_OK);
	assert_int_equal(plume_spec_generate(path, &five, &b, NULL), PLUME_OK);
	assert_int_equal(plume_spec_generate(path, &six, &c, NULL), PLUME_OK);
	assert_true(plume_feather_equal(a, b));
	assert_false(plume_feather_equal(a, c));
	plume_feather_destroy(a);
	plume_feather_destroy(b);
	plume_feather_destroy(c);
}

static void test_syntax_error_names_line_and_column(void **state)
{
	(void)state;
	// The missing comma is on line 3.
	expect_error("{\n  \"model\": \"franco-walter\",\n  \"seed\": 3\n  \"barb_samples\": 10\n}", PLUME_ERROR_SYNTAX,
	             "spec.json:4:");
	expect_error("{\"model\": \"franco-walter\", \"seed\": 3, \"seed\": 4}", PLUME_ERROR_SYNTAX, "duplicate");
	expect_error("", PLUME_ERROR_SYNTAX, "spec.json:");
}

// Textbook values of the Levenshtein distance, and keys longer than the old 63-byte row:
// a misspelling at byte 70 still counts (the spec reader cut both words at 63 before).
static void test_edit_distance(void **state)
{
	(void)state;
	assert_int_equal(plume_edit_distance("kitten", "sitting"), 3);
	assert_int_equal(plume_edit_distance("", "abc"), 3);
	assert_int_equal(plume_edit_distance("flaw", "lawn"), 2);
	assert_int_equal(plume_edit_distance("same", "same"), 0);
	char a[80], b[80];
	memset(a, 'x', 79);
	memset(b, 'x', 79);
	a[79] = b[79] = '\0';
	b[70] = 'y';
	assert_int_equal(plume_edit_distance(a, b), 1);
}

static void test_unknown_key_names_path_and_nearest(void **state)
{
	(void)state;
	expect_error("{\"model\": \"franco-walter\", \"barb_sample\": 10}", PLUME_ERROR_SPEC,
	             "$.barb_sample: unknown key; did you mean \"barb_samples\"?");
	expect_error("{\"model\": \"franco-walter\", \"segments\": [{}, {\"shape_varation\": 0.1}]}", PLUME_ERROR_SPEC,
	             "$.segments[1].shape_varation: unknown key; did you mean \"shape_variation\"?");
	expect_error("{\"model\": \"franco-waltr\"}", PLUME_ERROR_SPEC,
	             "$.model: unknown model \"franco-waltr\"; did you mean \"franco-walter\"?");
	expect_error("{\"seed\": 1}", PLUME_ERROR_SPEC, "$.model: missing");
	// A key cut short gets the key it begins (its nearest by edits was some other short key).
	expect_error("{\"model\": \"franco-walter\", \"calamus\": 0.1}", PLUME_ERROR_SPEC,
	             "$.calamus: unknown key; did you mean \"calamus_fraction\"?");
	// No key is near: no guess ("did you mean" once offered any nearest key), the keys allowed instead.
	expect_error("{\"model\": \"franco-walter\", \"segments\": [{}, {\"texture\": 1}]}", PLUME_ERROR_SPEC,
	             "$.segments[1].texture: unknown key; the keys here are: barb_count, length_variation, "
	             "shape_variation, symmetric_vanes, uniform_shape, uniform_length");
}

/// Out-of-range values print with the digits it takes to show them out of range ("%g" printed
/// 0.9500001 as 0.95, "is 0.95, allowed [0, 0.95]").
static void test_out_of_range_values_show_their_digits(void **state)
{
	(void)state;
	expect_error("{\"model\": \"franco-walter\", \"calamus_fraction\": 0.9500001}", PLUME_ERROR_SPEC,
	             "$.calamus_fraction is 0.9500001, allowed [0, 0.95]");
	expect_error("{\"model\": \"zhang-kanai\", \"growth_stage\": 1.0000001}", PLUME_ERROR_SPEC,
	             "$.growth_stage is 1.0000001, allowed [0, 1]");
	expect_error("{\"model\": \"zhang-kanai\", \"theta_distal_deg\": 180.00001}", PLUME_ERROR_SPEC,
	             "$.theta_distal_deg is 180.00001, allowed (0, 180)");
	expect_error("{\"model\": \"streit-heidrich\", \"left_tip_angle_deg\": 180.0001}", PLUME_ERROR_SPEC,
	             "$.left_tip_angle_deg is 180.0001, allowed (0, 180]");
	expect_error("{\"model\": \"streit-heidrich\", \"key_barbs\": [{\"position\": 1.0000001, \"cvs\": [[0, 0, 0], [1, "
	             "0, 0]]}]}",
	             PLUME_ERROR_SPEC, "$.key_barbs[0].position is 1.0000001, allowed [0, 1]");
}

static void test_out_of_range_names_path_and_range(void **state)
{
	(void)state;
	expect_error("{\"model\": \"franco-walter\", \"segments\": [{}, {\"barb_count\": 6000}]}", PLUME_ERROR_SPEC,
	             "$.segments[1].barb_count is 6000, allowed [0, 5000]");
	expect_error("{\"model\": \"franco-walter\", \"second_segment_start\": -0.5}", PLUME_ERROR_SPEC,
	             "$.second_segment_start is -0.5, allowed [0, 1]");
	expect_error("{\"model\": \"franco-walter\", \"segments\": [{\"length_variation\": 2}, {}]}", PLUME_ERROR_SPEC,
	             "$.segments[0].length_variation is 2, allowed [0, 1]");
	expect_error("{\"model\": \"franco-walter\", \"barb_width_tip\": -1e-4}", PLUME_ERROR_SPEC,
	             "$.barb_width_tip is -0.0001, must be a positive length");
}

static void test_wrong_types_name_path(void **state)
{
	(void)state;
	expect_error("{\"model\": \"franco-walter\", \"barb_samples\": \"thirty\"}", PLUME_ERROR_SPEC,
	             "$.barb_samples: expected an integer, got a string");
	expect_error("{\"model\": \"franco-walter\", \"barb_samples\": 30.5}", PLUME_ERROR_SPEC,
	             "$.barb_samples: expected an integer, got a number");
	expect_error("{\"model\": \"franco-walter\", \"segments\": [{\"symmetric_vanes\": 1}, {}]}", PLUME_ERROR_SPEC,
	             "$.segments[0].symmetric_vanes: expected true or false");
	expect_error("{\"model\": \"franco-walter\", \"shaft\": [[0,0],[0,1],[0,2]]}", PLUME_ERROR_SPEC,
	             "$.shaft: expected an array of 4 points");
	expect_error("{\"model\": \"franco-walter\", \"shaft\": [[0,0],[0,1],[0,\"2\"],[0,3]]}", PLUME_ERROR_SPEC,
	             "$.shaft[2][1]: expected a number, got a string");
	expect_error("{\"model\": \"franco-walter\", \"segments\": [{}]}", PLUME_ERROR_SPEC,
	             "$.segments: expected 2 segments");
	expect_error("{\"model\": \"franco-walter\", \"seed\": -3}", PLUME_ERROR_SPEC,
	             "$.seed: expected a non-negative integer");
	expect_error("[1, 2]", PLUME_ERROR_SPEC, "$: expected an object");
}

static void test_missing_file_is_an_io_error(void **state)
{
	(void)state;
	plume_feather *feather = NULL;
	plume_error err = {0};
	assert_int_equal(plume_spec_generate("/nonexistent/spec.json", NULL, &feather, &err), PLUME_ERROR_IO);
	assert_non_null(strstr(err.message, "/nonexistent/spec.json: cannot read: No such file or directory"));
	// A folder opens for reading, then its first read fails: it was a syntax error at 1:0.
	char folder[256];
	test_make_temp_dir(folder, sizeof folder);
	assert_int_equal(plume_spec_generate(folder, NULL, &feather, &err), PLUME_ERROR_IO);
	assert_null(feather);
	assert_non_null(strstr(err.message, ": cannot read: Is a directory"));
	test_remove_tree(folder);
}

static void test_every_preset_generates(void **state)
{
	(void)state;
	static const char *const presets[] = {"figure6a", "figure6b", "filoplume", "blue", "hawk", "peacock"};
	for (size_t i = 0; i < sizeof presets / sizeof presets[0]; ++i) {
		char path[512];
		snprintf(path, sizeof path, "%s/examples/franco-walter/%s.json", PLUME_SOURCE_DIR, presets[i]);
		plume_feather *feather = NULL;
		plume_error err = {0};
		if (plume_spec_generate(path, NULL, &feather, &err) != PLUME_OK)
			fail_msg("%s", err.message);
		assert_true(plume_feather_get_info(feather).shaft_length > 0.0);
		plume_feather_destroy(feather);
	}
}

static void test_text_spec_is_the_file_spec(void **state)
{
	(void)state;
	static const char text[] = "{\"model\": \"franco-walter\", \"seed\": 7}";
	const char *path = spec_file("text.json", text);
	plume_feather *from_file = NULL, *from_text = NULL;
	assert_int_equal(plume_spec_generate(path, NULL, &from_file, NULL), PLUME_OK);
	assert_int_equal(plume_spec_parse(text, "<text>", NULL, &from_text, NULL), PLUME_OK);
	assert_true(plume_feather_equal(from_file, from_text));
	plume_feather_destroy(from_file);
	plume_feather_destroy(from_text);

	int64_t before = plume_bytes_in_use();
	plume_feather *feather = NULL;
	plume_error err = {0};
	assert_int_equal(plume_spec_parse("{\"model\": \"franco-walter\",\n \"seed\": }", "<text>", NULL, &feather, &err),
	                 PLUME_ERROR_SYNTAX);
	assert_null(feather);
	assert_true(strncmp(err.message, "<text>:2:", 9) == 0);
	assert_int_equal(
	    plume_spec_parse("{\"model\": \"franco-walter\", \"calamus_fraction\": 2}", "<text>", NULL, &feather, &err),
	    PLUME_ERROR_SPEC);
	if (strstr(err.message, "<text>: $.calamus_fraction") == NULL)
		fail_msg("message '%s' lacks the name and the path", err.message);
	assert_int_equal(plume_bytes_in_use(), before);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_minimal_spec_is_the_default_feather),
	    cmocka_unit_test(test_keys_reach_the_definition),
	    cmocka_unit_test(test_seed_option_overrides_spec),
	    cmocka_unit_test(test_syntax_error_names_line_and_column),
	    cmocka_unit_test(test_edit_distance),
	    cmocka_unit_test(test_unknown_key_names_path_and_nearest),
	    cmocka_unit_test(test_out_of_range_names_path_and_range),
	    cmocka_unit_test(test_out_of_range_values_show_their_digits),
	    cmocka_unit_test(test_wrong_types_name_path),
	    cmocka_unit_test(test_missing_file_is_an_io_error),
	    cmocka_unit_test(test_every_preset_generates),
	    cmocka_unit_test(test_text_spec_is_the_file_spec),
	};
	return cmocka_run_group_tests_name("spec", tests, setup, teardown);
}

// Every number read from an input is finite and inside its documented range before use
// (issue 17 item 1): the readers not covered by the JSON-wide ±1e12 bound and the spec
// readers' own ranges. Each case is a value that passed before and then reached a
// computation as NaN, an underflow or an absurd size; each must now be refused with a
// message naming the file and the JSON path (or line) and the allowed range.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

static char scratch[512];

static int setup(void **state)
{
	(void)state;
	test_make_temp_dir(scratch, sizeof scratch);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	test_remove_tree(scratch);
	return 0;
}

static void expect_message(const plume_error *err, const char *fragment)
{
	if (strstr(err->message, fragment) == NULL)
		fail_msg("\"%s\" not in: %s", fragment, err->message);
}

// ---------------------------------------------------------------------------
// Cameras and lights (docs/rendering.md)

static plume_status read_camera_file(const char *text, plume_error *err)
{
	char path[600];
	snprintf(path, sizeof path, "%s/camera.json", scratch);
	test_write_file(path, text);
	plume_raytrace_def def = plume_raytrace_default_def();
	return plume_raytrace_def_read(path, &def, err);
}

static void test_camera_ranges(void **state)
{
	(void)state;
	plume_error err = {0};
	// A direction of length 1e-300 was "non-zero", but its squared length underflows:
	// normalising it gave NaN in every ray.
	assert_int_equal(read_camera_file("{\"camera\": {\"up\": [1e-300, 0, 0]}}", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "camera.json: $.camera.up: has length 0, allowed >= 1e-09");
	assert_int_equal(read_camera_file("{\"lights\": [{\"direction\": [0, 1e-200, 0]}]}", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "$.lights[0].direction: has length 0, allowed >= 1e-09");
	assert_int_equal(read_camera_file("{\"ground_normal\": [0, 0, 1e-10]}", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "$.ground_normal: has length 1e-10, allowed >= 1e-09");
	assert_int_equal(read_camera_file("{\"camera\": {\"eye\": [0, 0, 1e-10], \"target\": [0, 0, 0]}}", &err),
	                 PLUME_ERROR_SPEC);
	expect_message(&err, "$.camera.target: is 1e-10 m from the eye, allowed >= 1e-09 m");
	assert_int_equal(read_camera_file("{\"camera\": {\"turntable_deg\": 1e9}}", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "$.camera.turntable_deg: is 1e+09, allowed [-360, 360]");
	// The edges of the ranges are accepted.
	assert_int_equal(read_camera_file("{\"camera\": {\"up\": [0, 1e-9, 0], \"turntable_deg\": -360}, "
	                                  "\"lights\": [{\"direction\": [0, 0, 1e-9]}]}",
	                                  &err),
	                 PLUME_OK);
}

// ---------------------------------------------------------------------------
// Lab files (docs/lab.md)

static plume_status read_lab_file(const char *text, plume_error *err)
{
	char path[600];
	snprintf(path, sizeof path, "%s/lab.json", scratch);
	test_write_file(path, text);
	plume_lab_spec spec;
	return plume_lab_spec_load(path, &spec, err);
}

static void test_lab_ranges(void **state)
{
	(void)state;
	plume_error err = {0};
	assert_int_equal(read_lab_file("{\"sample\": {\"width\": 1e-300}}", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "lab.json: $.sample.width is 1e-300 m, allowed [1e-06, 10]");
	assert_int_equal(read_lab_file("{\"sample\": {\"height\": 1e6}}", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "$.sample.height is 1e+06 m, allowed [1e-06, 10]");
	assert_int_equal(read_lab_file("{\"sample\": {\"thickness\": 1e-300}}", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "$.sample.thickness is 1e-300 m, allowed [1e-09, 1]");
	assert_int_equal(read_lab_file("{\"traction\": {\"max_iterations\": 2000000000}}", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "$.traction.max_iterations is 2000000000, allowed [1, 100000]");
	assert_int_equal(read_lab_file("{\"traction\": {\"tolerance\": 5}}", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "$.traction.tolerance is 5, allowed (0, 1)");
	assert_int_equal(read_lab_file("{\"sample\": {\"width\": 1e-6, \"height\": 10, \"thickness\": 1e-9}}", &err),
	                 PLUME_OK);
}

// ---------------------------------------------------------------------------
// Scenes and simulator definitions (docs/scene.md)

static void test_simulation_ranges(void **state)
{
	(void)state;
	plume_error err = {0};
	plume_sim_def def = plume_sim_default_def();
	// mass / h^2 overflows to inf at h = 1e-300 s: the step's Newton worked on NaN.
	def.time_step = 1e-300;
	assert_int_equal(plume_sim_def_validate(&def, 2, &err), PLUME_ERROR_SPEC);
	expect_message(&err, "$.time_step is 1e-300, allowed [1e-09, 100] s");
	def.time_step = 1e9;
	assert_int_equal(plume_sim_def_validate(&def, 2, &err), PLUME_ERROR_SPEC);
	def = plume_sim_default_def();
	def.materials[PLUME_MATERIAL_VANE].thickness = 1e-300;
	assert_int_equal(plume_sim_def_validate(&def, 2, &err), PLUME_ERROR_SPEC);
	expect_message(&err, "$.materials.vane.thickness is 1e-300, allowed [1e-09, 1] m");
	def.materials[PLUME_MATERIAL_VANE].thickness = 1e-9;
	def.time_step = 1e-9;
	assert_int_equal(plume_sim_def_validate(&def, 2, &err), PLUME_OK);
}

// ---------------------------------------------------------------------------
// Feather JSON dumps (docs/feather-json.md)

/// Writes a small feather's JSON, replaces the first occurrence of from by to, reads it back.
static plume_status read_edited_feather(const char *from, const char *to, plume_error *err)
{
	plume_fw_def def = plume_fw_default_def();
	def.segments[0].barb_count = 4;
	def.segments[1].barb_count = 8;
	plume_feather *feather = NULL;
	assert_int_equal(plume_fw_generate(&def, 1, &feather, NULL), PLUME_OK);
	char path[600];
	snprintf(path, sizeof path, "%s/feather.json", scratch);
	assert_int_equal(plume_write_json(feather, path, NULL), PLUME_OK);
	plume_feather_destroy(feather);
	size_t size = 0;
	char *text = (char *)test_read_file(path, &size);
	assert_non_null(text);
	char *at = strstr(text, from);
	assert_non_null(at);
	char *edited = malloc(size + strlen(to) + 1);
	assert_non_null(edited);
	size_t head = (size_t)(at - text);
	memcpy(edited, text, head);
	strcpy(edited + head, to);
	strcat(edited, at + strlen(from));
	test_write_file(path, edited);
	free(edited);
	free(text);
	feather = NULL;
	plume_status status = plume_read_json(path, &feather, err);
	plume_feather_destroy(feather);
	return status;
}

static void test_feather_json_ranges(void **state)
{
	(void)state;
	plume_error err = {0};
	// The first barb's shaft fraction 0.xxx becomes 70.xxx.
	assert_int_equal(read_edited_feather("\"rachis_t\":0", "\"rachis_t\":70", &err), PLUME_ERROR_SPEC);
	expect_message(&err, "feather.json: $.barbs[0].rachis_t: is 70");
	expect_message(&err, "allowed [0, 1]");
	// The control: the same file unedited reads back.
	assert_int_equal(read_edited_feather("\"rachis_t\":0", "\"rachis_t\":0", &err), PLUME_OK);
}

// ---------------------------------------------------------------------------
// OBJ files and textures (docs/formats.md)

static void test_obj_texture_coordinates(void **state)
{
	(void)state;
	char path[600];
	snprintf(path, sizeof path, "%s/vt.obj", scratch);
	test_write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt nan 0\nvt 0 1\nf 1/1 2/2 3/3\n");
	plume_mesh *mesh = NULL;
	plume_error err = {0};
	assert_int_equal(plume_mesh_read_obj(path, &mesh, &err), PLUME_ERROR_SYNTAX);
	assert_null(mesh);
	expect_message(&err, "vt.obj:5: texture coordinate 2: coordinate 1 is nan; allowed finite, within 1e12");
	test_write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1e13 0\nf 1 2 3\n");
	assert_int_equal(plume_mesh_read_obj(path, &mesh, &err), PLUME_ERROR_SYNTAX);
	expect_message(&err, "vt.obj:3: vertex 3: coordinate 2 is 1e+13; allowed finite, within 1e12 m");
	// Normals are not read: a "vn nan" line is ignored, the mesh loads.
	test_write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan nan nan\nf 1 2 3\n");
	assert_int_equal(plume_mesh_read_obj(path, &mesh, &err), PLUME_OK);
	plume_mesh_destroy(mesh);
}

/// A PNG signature, an IHDR chunk that claims width x height and an empty IDAT chunk (no
/// pixels): the size must be refused from the header, before anything allocates
/// width * height * 4 bytes. CRCs are zero: stb does not check them.
static void write_png_header(const char *path, uint32_t width, uint32_t height)
{
	unsigned char bytes[45] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
	for (int i = 0; i < 4; ++i) {
		bytes[16 + i] = (unsigned char)(width >> (24 - 8 * i));
		bytes[20 + i] = (unsigned char)(height >> (24 - 8 * i));
	}
	bytes[24] = 8; // bit depth
	bytes[25] = 6; // RGBA
	memcpy(bytes + 33, "\0\0\0\0IDAT", 8);
	FILE *file = fopen(path, "wb");
	assert_non_null(file);
	assert_int_equal(fwrite(bytes, 1, sizeof bytes, file), sizeof bytes);
	fclose(file);
}

static void test_texture_size(void **state)
{
	(void)state;
	char path[600];
	snprintf(path, sizeof path, "%s/wide.png", scratch);
	plume_texture *texture = NULL;
	plume_error err = {0};
	int64_t before = plume_bytes_in_use();
	// Under stb's own 1 GiB bound but past plume's 16384 pixels a side.
	write_png_header(path, 20000, 100);
	assert_int_equal(plume_texture_load(path, &texture, &err), PLUME_ERROR_SPEC);
	assert_null(texture);
	expect_message(&err, "wide.png: a 20000 x 100 image; textures are at most 16384 x 16384 pixels");
	write_png_header(path, 100, 16385);
	assert_int_equal(plume_texture_load(path, &texture, &err), PLUME_ERROR_SPEC);
	expect_message(&err, "a 100 x 16385 image");
	// Past stb's bound (60000 x 60000 x 4 bytes): stb refuses it from the header.
	write_png_header(path, 60000, 60000);
	assert_int_not_equal(plume_texture_load(path, &texture, &err), PLUME_OK);
	assert_null(texture);
	assert_int_equal(plume_bytes_in_use(), before);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_camera_ranges),           cmocka_unit_test(test_lab_ranges),
	    cmocka_unit_test(test_simulation_ranges),       cmocka_unit_test(test_feather_json_ranges),
	    cmocka_unit_test(test_obj_texture_coordinates), cmocka_unit_test(test_texture_size),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}

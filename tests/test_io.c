// Geometry export and the JSON dump: exact round trips, byte-identical output
// for a seed, OBJ and USDA files parsed back and checked against the feather,
// reader errors with their positions and JSON paths, and atomic writes.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "model/feather_internal.h"
#include "support.h"

// ---------------------------------------------------------------------------
// Fixtures

static plume_feather *hawk(uint64_t seed)
{
	plume_fw_def def = plume_fw_default_def();
	plume_feather *feather = NULL;
	plume_error err;
	plume_status status = plume_fw_generate(&def, seed, &feather, &err);
	if (status != PLUME_OK)
		fail_msg("generate: %s", err.message);
	return feather;
}

/// Appends a curve of count points to the pool, filled with awkward doubles
/// (0.1, thirds, -0, a subnormal, huge and tiny magnitudes) so that a round
/// trip that is only nearly exact fails.
static plume_curve_range small_curve(plume_feather *feather, int count, double seed)
{
	int first = plume_feather_add_points(feather, count);
	assert_true(first >= 0);
	for (int i = 0; i < count; ++i) {
		double k = seed + i;
		feather->points[first + i] = plume_v3(0.1 * k, 1.0 / (3.0 + k), i == 0 ? -0.0 : 1e-300 * k);
		feather->normals[first + i] = plume_v3(0.0, 4.9e-324, 1.0);
		feather->arc_length[first + i] = sqrt(k);
		feather->widths[first + i] = 1e-4 / (1.0 + k);
		feather->uv[first + i] =
		    (plume_vec2){count > 1 ? (double)i / (count - 1) : 0.0, 3.14159265358979323846 / (7.0 + seed)};
	}
	return (plume_curve_range){first, count};
}

/// A feather built by hand: four shaft samples, three barbs (one of them a
/// single point, which no polyline format can hold), three barbules on two
/// barbs, and depth nested afterfeathers. Its pool holds all barb points first
/// and the barbules after, unlike the order the reader rebuilds in.
static plume_feather *small_feather(int depth)
{
	plume_feather *feather = plume_feather_create_empty();
	assert_non_null(feather);
	plume_shaft_sample *shaft = plume_feather_add_shaft(feather, 4);
	assert_non_null(shaft);
	for (int i = 0; i < 4; ++i) {
		shaft[i] = (plume_shaft_sample){
		    .position = plume_v3(0.001 * i * i, 0.02 * i + depth, 0.0),
		    .tangent = plume_v3(0.0, 1.0, 0.0),
		    .normal = plume_v3(0.0, 0.0, 1.0),
		    .binormal = plume_v3(-1.0, 0.0, 0.0),
		    .width = 1e-3 * (4 - i) / 3.0,
		    .t = i / 3.0,
		};
	}
	feather->calamus_count = 1;
	plume_curve_range barb_curves[3] = {small_curve(feather, 5, 1.0 + depth), small_curve(feather, 1, 2.0),
	                                    small_curve(feather, 3, 3.0)};
	plume_barb_record barbs[3] = {
	    {.curve = barb_curves[0],
	     .side = PLUME_SIDE_LEFT,
	     .rachis_t = 0.4,
	     .segment = 0,
	     .barbule_first = 0,
	     .barbule_count = 2},
	    // An empty barb's barbule_first is not part of the feather (the reader rebuilds it as 2).
	    {.curve = barb_curves[1],
	     .side = PLUME_SIDE_LEFT,
	     .rachis_t = 0.7,
	     .segment = 1,
	     .barbule_first = 0,
	     .barbule_count = 0},
	    {.curve = barb_curves[2],
	     .side = PLUME_SIDE_RIGHT,
	     .rachis_t = 1.0 / 3.0,
	     .segment = -2,
	     .barbule_first = 2,
	     .barbule_count = 1},
	};
	for (int i = 0; i < 3; ++i)
		assert_int_equal(plume_feather_add_barb(feather, barbs + i), i);
	plume_barbule_record barbules[3] = {
	    {.curve = small_curve(feather, 2, 5.0), .barb = 0, .barb_s = 0.25, .kind = PLUME_BARBULE_DISTAL},
	    {.curve = small_curve(feather, 3, 6.0), .barb = 0, .barb_s = 0.75, .kind = PLUME_BARBULE_PROXIMAL},
	    {.curve = small_curve(feather, 2, 7.0), .barb = 2, .barb_s = 0.1, .kind = PLUME_BARBULE_DISTAL},
	};
	for (int i = 0; i < 3; ++i)
		assert_int_equal(plume_feather_add_barbule(feather, barbules + i), i);
	if (depth > 0) {
		feather->afterfeather = small_feather(depth - 1);
		feather->afterfeather_t = 0.15 + 1e-16;
	}
	return feather;
}

typedef enum format { FORMAT_OBJ, FORMAT_USDA, FORMAT_JSON, FORMAT_GLB } format;
static const char *const format_extensions[] = {"obj", "usda", "json", "glb"};

static plume_status write_format(format which, const plume_feather *feather, const char *path, plume_error *err)
{
	switch (which) {
	case FORMAT_OBJ: return plume_write_obj(feather, path, err);
	case FORMAT_USDA: return plume_write_usda(feather, path, err);
	case FORMAT_JSON: return plume_write_json(feather, path, err);
	case FORMAT_GLB: return plume_write_glb(feather, NULL, path, err);
	}
	return PLUME_ERROR_UNSUPPORTED;
}

static void write_ok(format which, const plume_feather *feather, const char *path)
{
	plume_error err;
	plume_status status = write_format(which, feather, path, &err);
	if (status != PLUME_OK)
		fail_msg("writing %s: %s", path, err.message);
}

static plume_feather *read_ok(const char *path)
{
	plume_feather *feather = NULL;
	plume_error err;
	if (plume_read_json(path, &feather, &err) != PLUME_OK)
		fail_msg("reading %s: %s", path, err.message);
	return feather;
}

// ---------------------------------------------------------------------------
// JSON round trips

static void test_json_round_trip_hawk(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512], again[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/hawk.json", dir);
	snprintf(again, sizeof again, "%s/again.json", dir);

	plume_feather *original = hawk(1);
	write_ok(FORMAT_JSON, original, path);
	plume_feather *copy = read_ok(path);
	assert_true(plume_feather_equal(original, copy));
	plume_feather_info info = plume_feather_get_info(copy);
	assert_int_equal(info.barb_count, 4400);
	assert_int_equal(info.point_count, 4400 * 30);
	// The copy writes the same bytes: nothing was lost or reordered.
	write_ok(FORMAT_JSON, copy, again);
	assert_true(test_hash_file(path) == test_hash_file(again));

	plume_feather_destroy(copy);
	plume_feather_destroy(original);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_json_round_trip_small_with_barbules_and_afterfeathers(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/small.json", dir);

	plume_feather *original = small_feather(2);
	write_ok(FORMAT_JSON, original, path);
	plume_feather *copy = read_ok(path);
	assert_true(plume_feather_equal(original, copy));

	// Spot checks through the views, beyond plume_feather_equal.
	plume_barb barb = plume_feather_barb(copy, 0);
	assert_int_equal(barb.barbule_count, 2);
	assert_true(signbit(barb.curve.points[0].z) && barb.curve.points[0].z == 0.0); // -0 survived
	assert_true(barb.curve.normals[0].y == 4.9e-324);                              // a subnormal too
	assert_int_equal(plume_feather_barbule(copy, 2).barb, 2);
	assert_int_equal(plume_feather_barbule(copy, 1).kind, PLUME_BARBULE_PROXIMAL);
	const plume_feather *after = plume_feather_afterfeather(copy);
	assert_non_null(after);
	assert_true(plume_feather_afterfeather_t(copy) == 0.15 + 1e-16);
	assert_non_null(plume_feather_afterfeather(after));
	assert_null(plume_feather_afterfeather(plume_feather_afterfeather(after)));

	// Equality does see a one-bit change in a nested afterfeather's barbule.
	plume_feather *changed = plume_feather_clone(copy);
	assert_non_null(changed);
	plume_feather *inner = changed->afterfeather->afterfeather;
	inner->points[inner->barbules[1].curve.first].x = nextafter(inner->points[inner->barbules[1].curve.first].x, 1.0);
	assert_false(plume_feather_equal(original, changed));

	plume_feather_destroy(changed);
	plume_feather_destroy(copy);
	plume_feather_destroy(original);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_json_refuses_ungrouped_barbules(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/bad.json", dir);
	plume_feather *feather = small_feather(0);
	feather->barbules[1].barb = 2; // listed under barb 0, claims barb 2: would not read back
	plume_error err;
	assert_int_equal(plume_write_json(feather, path, &err), PLUME_ERROR_UNSUPPORTED);
	assert_non_null(strstr(err.message, "grouped"));
	assert_int_equal(test_count_entries(dir), 0);
	plume_feather_destroy(feather);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// Numbers are printed as jansson printed them before the writer printed its own
/// (feather_json.c, put_real): 17 significant digits, ".0" where the digits would read
/// back as an integer, exponents without leading zeros; and they read back bit for bit.
static void test_json_number_text(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/numbers.json", dir);
	plume_feather *original = small_feather(0);
	plume_vec3 *point = &original->points[original->barbs[0].curve.first];
	*point = plume_v3(1e11, -2.5e-5, 3.0); // the reader takes magnitudes up to 1e12
	write_ok(FORMAT_JSON, original, path);
	size_t size;
	char *text = (char *)test_read_file(path, &size);
	assert_non_null(text);
	assert_non_null(strstr(text, "\"position\":[100000000000.0,-2.5000000000000001e-5,3.0,"));
	assert_non_null(strstr(text, "\"rachis_t\":0.40000000000000002,"));
	free(text);
	plume_feather *copy = read_ok(path);
	assert_true(plume_feather_equal(original, copy));
	plume_feather_destroy(copy);
	plume_feather_destroy(original);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// JSON has no NaN or infinity: either version refuses the feather, names the piece that
/// has one, and writes nothing.
static void test_json_refuses_non_finite_numbers(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/bad.json", dir);
	for (int binary = 0; binary < 2; ++binary)
		for (int piece = 0; piece < 3; ++piece) {
			plume_feather *feather = small_feather(1);
			plume_feather *after = feather->afterfeather;
			const char *named = NULL;
			switch (piece) {
			case 0:
				feather->shaft[1].width = NAN;
				named = "the shaft has a NaN";
				break;
			case 1:
				after->widths[after->barbs[2].curve.first] = INFINITY;
				named = "barb 2 has a NaN";
				break;
			default:
				feather->afterfeather_t = -INFINITY;
				named = "the afterfeather's t has a NaN";
				break;
			}
			plume_error err;
			plume_status status =
			    binary ? plume_write_json_binary(feather, path, &err) : plume_write_json(feather, path, &err);
			assert_int_equal(status, PLUME_ERROR_NUMERIC);
			if (strstr(err.message, named) == NULL || strstr(err.message, path) == NULL)
				fail_msg("binary %d, piece %d: %s", binary, piece, err.message);
			assert_int_equal(test_count_entries(dir), 0);
			plume_feather_destroy(feather);
		}
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// OBJ and USD print numbers with "%.9g", which writes "nan" and "inf" that no reader takes:
/// both writers refuse such a feather (USD also a number past float, which it holds as inf),
/// name the piece, and leave the file that was there.
static void test_obj_usda_glb_refuse_non_finite_numbers(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	static const format formats[] = {FORMAT_OBJ, FORMAT_USDA, FORMAT_GLB};
	for (size_t f = 0; f < sizeof formats / sizeof formats[0]; ++f) {
		format which = formats[f];
		snprintf(path, sizeof path, "%s/feather.%s", dir, format_extensions[which]);
		plume_feather *good = small_feather(1);
		write_ok((format)which, good, path);
		uint64_t hash = test_hash_file(path);
		plume_feather_destroy(good);
		for (int piece = 0; piece < 4; ++piece) {
			plume_feather *feather = small_feather(1);
			plume_feather *after = feather->afterfeather;
			const char *named = NULL;
			switch (piece) {
			case 0:
				feather->shaft[1].position.y = NAN;
				named = ": shaft sample 1 has a NaN or infinite number";
				break;
			case 1:
				after->points[after->barbs[2].curve.first + 1].x = INFINITY;
				named = ": afterfeather's barb 2 (point 1) has a NaN or infinite number";
				break;
			case 2:
				feather->uv[feather->barbules[1].curve.first].y = NAN;
				named = ": barbule 1 (point 0) has a NaN or infinite number";
				break;
			default: // finite, but inf as USD's and glTF's float (OBJ prints the double)
				feather->points[feather->barbs[0].curve.first].z = 1e39;
				named = ": barb 0 (point 0) has a NaN or infinite number (or one past single precision";
				break;
			}
			if (which != FORMAT_OBJ || piece < 3) {
				plume_error err;
				assert_int_equal(write_format((format)which, feather, path, &err), PLUME_ERROR_NUMERIC);
				if (strstr(err.message, named) == NULL || strstr(err.message, path) == NULL)
					fail_msg("%s, piece %d: %s", format_extensions[which], piece, err.message);
				assert_true(test_hash_file(path) == hash); // the earlier file is kept
			}
			plume_feather_destroy(feather);
		}
		remove(path);
	}
	assert_int_equal(test_count_entries(dir), 0);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

static long long file_size(const char *path)
{
	struct stat info;
	assert_int_equal(stat(path, &info), 0);
	return (long long)info.st_size;
}

/// Version 2 (numbers in a sidecar, simulate's feather.json): the same feather
/// back bit for bit (-0, a subnormal, nested afterfeathers), the same bytes
/// again, and half the size of version 1 on a full feather.
static void test_json_binary_round_trip(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512], sidecar[512], again[512], text[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/small.json", dir);
	snprintf(sidecar, sizeof sidecar, "%s/small.bin", dir);
	snprintf(again, sizeof again, "%s/again.json", dir);
	snprintf(text, sizeof text, "%s/text.json", dir);
	plume_error err;

	plume_feather *original = small_feather(2);
	assert_int_equal(plume_write_json_binary(original, path, &err), PLUME_OK);
	assert_true(test_file_exists(sidecar));
	plume_feather *copy = read_ok(path);
	assert_true(plume_feather_equal(original, copy));
	plume_barb barb = plume_feather_barb(copy, 0);
	assert_true(signbit(barb.curve.points[0].z) && barb.curve.points[0].z == 0.0);
	assert_true(barb.curve.normals[0].y == 4.9e-324);
	assert_true(plume_feather_afterfeather_t(copy) == 0.15 + 1e-16);
	plume_feather_destroy(copy);
	plume_feather_destroy(original);

	// A full feather: equal to what version 1 gives back, the same bytes when written again.
	original = hawk(1);
	snprintf(path, sizeof path, "%s/hawk.json", dir);
	snprintf(sidecar, sizeof sidecar, "%s/hawk.bin", dir);
	assert_int_equal(plume_write_json_binary(original, path, &err), PLUME_OK);
	write_ok(FORMAT_JSON, original, text);
	copy = read_ok(path);
	plume_feather *from_text = read_ok(text);
	assert_true(plume_feather_equal(original, copy));
	assert_true(plume_feather_equal(from_text, copy));
	assert_int_equal(plume_write_json_binary(copy, again, &err), PLUME_OK);
	assert_true(test_hash_file(path) != test_hash_file(again)); // it names its own sidecar, again.bin
	char again_bin[512];
	snprintf(again_bin, sizeof again_bin, "%s/again.bin", dir);
	assert_true(test_hash_file(sidecar) == test_hash_file(again_bin));
	// Every double of the points, normals, arc lengths, widths and uvs: 9 a point.
	plume_feather_info info = plume_feather_get_info(original);
	assert_true(file_size(sidecar) >= (long long)info.point_count * 9 * 8);
	assert_true(file_size(path) + file_size(sidecar) < file_size(text) * 3 / 4);
	plume_feather_destroy(from_text);
	plume_feather_destroy(copy);
	plume_feather_destroy(original);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

// ---------------------------------------------------------------------------
// Determinism

static void test_same_seed_same_bytes_other_seed_other_bytes(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256];
	test_make_temp_dir(dir, sizeof dir);
	plume_feather *a = hawk(7), *b = hawk(7), *c = hawk(8);
	for (int f = 0; f < 3; ++f) {
		char pa[512], pb[512], pc[512];
		snprintf(pa, sizeof pa, "%s/a.%s", dir, format_extensions[f]);
		snprintf(pb, sizeof pb, "%s/b.%s", dir, format_extensions[f]);
		snprintf(pc, sizeof pc, "%s/c.%s", dir, format_extensions[f]);
		write_ok((format)f, a, pa);
		write_ok((format)f, b, pb);
		write_ok((format)f, c, pc);
		uint64_t ha = test_hash_file(pa), hb = test_hash_file(pb), hc = test_hash_file(pc);
		assert_true(ha != 0);
		assert_true(ha == hb);
		assert_true(ha != hc);
		// Writing again over an existing file replaces it with the same bytes.
		write_ok((format)f, a, pb);
		assert_true(test_hash_file(pb) == ha);
	}
	// Nothing but the nine outputs: no temporary file stays behind.
	assert_int_equal(test_count_entries(dir), 9);
	plume_feather_destroy(a);
	plume_feather_destroy(b);
	plume_feather_destroy(c);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

// ---------------------------------------------------------------------------
// OBJ parsed back

/// The points an exporter writes, in order: the shaft, left barbs, right barbs,
/// barbules, then the afterfeather's the same way; curves of fewer than two
/// points are left out. Also counts the two-vertex line elements (one per segment).
typedef struct expected_points {
	plume_vec3 *position;
	plume_vec2 *uv;
	int count, capacity, polylines;
} expected_points;

static void expect_point(expected_points *e, plume_vec3 p, plume_vec2 uv)
{
	if (e->count == e->capacity) {
		e->capacity = e->capacity > 0 ? 2 * e->capacity : 1024;
		e->position = realloc(e->position, (size_t)e->capacity * sizeof *e->position);
		e->uv = realloc(e->uv, (size_t)e->capacity * sizeof *e->uv);
		assert_non_null(e->position);
		assert_non_null(e->uv);
	}
	e->position[e->count] = p;
	e->uv[e->count++] = uv;
}

static void expect_curve(expected_points *e, plume_polyline curve)
{
	if (curve.count < 2)
		return;
	for (int j = 0; j < curve.count; ++j)
		expect_point(e, curve.points[j], curve.uv[j]);
	e->polylines += curve.count - 1; // one two-vertex "l" per segment
}

static void expect_feather(expected_points *e, const plume_feather *feather)
{
	plume_feather_info info = plume_feather_get_info(feather);
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	if (info.shaft_sample_count >= 2) {
		for (int i = 0; i < info.shaft_sample_count; ++i)
			expect_point(e, shaft[i].position, (plume_vec2){0.0, shaft[i].t});
		e->polylines += info.shaft_sample_count - 1;
	}
	for (int side = 0; side < 2; ++side)
		for (int i = 0; i < info.barb_count; ++i)
			if (plume_feather_barb(feather, i).side == (plume_side)side)
				expect_curve(e, plume_feather_barb(feather, i).curve);
	for (int i = 0; i < info.barbule_count; ++i)
		expect_curve(e, plume_feather_barbule(feather, i).curve);
	if (info.has_afterfeather)
		expect_feather(e, plume_feather_afterfeather(feather));
}

/// Parses the OBJ file line by line and checks it against the feather.
static void check_obj(const char *path, const plume_feather *feather, const char *const *objects, int object_count)
{
	expected_points e = {0};
	expect_feather(&e, feather);
	char *text = (char *)test_read_file(path, NULL);
	assert_non_null(text);
	assert_true(strncmp(text, "# plume ", 8) == 0);
	int v = 0, vt = 0, l = 0, o = 0;
	char *save = NULL;
	for (char *line = strtok_r(text, "\n", &save); line != NULL; line = strtok_r(NULL, "\n", &save)) {
		if (line[0] == '#')
			continue;
		if (strncmp(line, "v ", 2) == 0) {
			plume_vec3 p;
			assert_int_equal(sscanf(line + 2, "%lf %lf %lf", &p.x, &p.y, &p.z), 3);
			assert_true(v < e.count);
			assert_close(p.x, e.position[v].x, 1e-9);
			assert_close(p.y, e.position[v].y, 1e-9);
			assert_close(p.z, e.position[v].z, 1e-9);
			v++;
		} else if (strncmp(line, "vt ", 3) == 0) {
			plume_vec2 uv;
			assert_int_equal(sscanf(line + 3, "%lf %lf", &uv.x, &uv.y), 2);
			assert_true(vt < e.count);
			assert_close(uv.x, e.uv[vt].x, 1e-9);
			assert_close(uv.y, e.uv[vt].y, 1e-9);
			vt++;
		} else if (strncmp(line, "l ", 2) == 0) {
			// Two vertices (Blender 3.4's default importer reads no more) and no texture
			// index (it misreads "a/ta"), each index a vertex already written (its vt is
			// the one of the same number), consecutive along the polyline.
			int count = 0, previous = 0;
			char *item_save = NULL;
			for (char *item = strtok_r(line + 2, " ", &item_save); item != NULL;
			     item = strtok_r(NULL, " ", &item_save)) {
				int vi, end = 0;
				assert_int_equal(sscanf(item, "%d%n", &vi, &end), 1);
				assert_int_equal(item[end], '\0');
				assert_true(vi >= 1 && vi <= v && vi <= vt);
				if (count > 0)
					assert_int_equal(vi, previous + 1);
				previous = vi;
				count++;
			}
			assert_int_equal(count, 2);
			l++;
		} else if (strncmp(line, "o ", 2) == 0) {
			assert_true(o < object_count);
			assert_string_equal(line + 2, objects[o]);
			o++;
		} else {
			fail_msg("unexpected OBJ line: %.60s", line);
		}
	}
	assert_int_equal(v, e.count);
	assert_int_equal(vt, e.count);
	assert_int_equal(l, e.polylines);
	assert_int_equal(o, object_count);
	free(text);
	free(e.position);
	free(e.uv);
}

static void test_obj_parses_back_to_the_feather(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/hawk.obj", dir);

	plume_feather *feather = hawk(3);
	write_ok(FORMAT_OBJ, feather, path);
	static const char *const hawk_objects[] = {"shaft", "left_vane", "right_vane"};
	check_obj(path, feather, hawk_objects, 3);
	// 100 + 132 000 vertices; the first barb's root is exactly where the feather has it.
	plume_feather_info info = plume_feather_get_info(feather);
	assert_int_equal(info.shaft_sample_count + info.point_count, 100 + 132000);
	plume_feather_destroy(feather);

	feather = small_feather(1);
	write_ok(FORMAT_OBJ, feather, path);
	static const char *const small_objects[] = {"shaft",
	                                            "left_vane",
	                                            "right_vane",
	                                            "barbules",
	                                            "afterfeather_shaft",
	                                            "afterfeather_left_vane",
	                                            "afterfeather_right_vane",
	                                            "afterfeather_barbules"};
	check_obj(path, feather, small_objects, 8);
	plume_feather_destroy(feather);

	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

// ---------------------------------------------------------------------------
// USDA parsed back

/// The text of prim `def <type> "<name>"` up to the next "def " (prims here
/// hold no other prims before their attributes end), NUL-terminated in a copy.
static char *usda_prim(const char *text, const char *type, const char *name)
{
	char head[128];
	snprintf(head, sizeof head, "def %s \"%s\"", type, name);
	const char *start = strstr(text, head);
	if (start == NULL)
		return NULL;
	const char *end = strstr(start + strlen(head), "def ");
	size_t length = end != NULL ? (size_t)(end - start) : strlen(start);
	char *copy = malloc(length + 1);
	memcpy(copy, start, length);
	copy[length] = '\0';
	return copy;
}

/// Elements of attribute "<declaration> = [...]" in a prim: tuples "(...)"
/// when tuples is true, else numbers, whose sum goes to *sum.
static long usda_array(const char *prim, const char *declaration, bool tuples, double *sum)
{
	char head[128];
	snprintf(head, sizeof head, "%s = [", declaration);
	const char *p = strstr(prim, head);
	if (p == NULL)
		fail_msg("no %s", declaration);
	p += strlen(head);
	long count = 0;
	if (sum != NULL)
		*sum = 0.0;
	while (*p != ']') {
		assert_true(*p != '\0');
		if (tuples) {
			if (*p == '(')
				count++;
			p++;
		} else if (strchr(" ,\n", *p) != NULL) {
			p++;
		} else {
			char *next;
			double value = strtod(p, &next);
			assert_true(next != p);
			if (sum != NULL)
				*sum += value;
			count++;
			p = next;
		}
	}
	return count;
}

/// The first tuple of a point3f array.
static plume_vec3 usda_first_point(const char *prim)
{
	const char *p = strstr(prim, "point3f[] points = [");
	assert_non_null(p);
	p = strchr(p, '(');
	plume_vec3 v;
	assert_int_equal(sscanf(p, "(%lf, %lf, %lf)", &v.x, &v.y, &v.z), 3);
	return v;
}

static void test_usda_counts_match(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/hawk.usda", dir);

	plume_feather *feather = hawk(5);
	write_ok(FORMAT_USDA, feather, path);
	char *text = (char *)test_read_file(path, NULL);
	assert_non_null(text);
	assert_true(strncmp(text, "#usda 1.0\n", 10) == 0);
	assert_non_null(strstr(text, "defaultPrim = \"feather\""));
	assert_non_null(strstr(text, "metersPerUnit = 1\n"));
	assert_non_null(strstr(text, "upAxis = \"Y\""));
	assert_non_null(strstr(text, "def Xform \"feather\""));
	assert_null(strstr(text, "afterfeather\""));
	assert_null(usda_prim(text, "BasisCurves", "barbules"));

	char *shaft = usda_prim(text, "BasisCurves", "shaft");
	assert_non_null(shaft);
	assert_non_null(strstr(shaft, "uniform token type = \"linear\""));
	double sum;
	assert_int_equal(usda_array(shaft, "int[] curveVertexCounts", false, &sum), 1);
	assert_close(sum, 100, 0);
	assert_int_equal(usda_array(shaft, "point3f[] points", true, NULL), 100);
	assert_int_equal(usda_array(shaft, "float[] widths", false, NULL), 100);
	assert_int_equal(usda_array(shaft, "texCoord2f[] primvars:st", true, NULL), 100);
	assert_null(strstr(shaft, "normals")); // the shaft is a tube
	free(shaft);

	char *barbs = usda_prim(text, "BasisCurves", "barbs");
	assert_non_null(barbs);
	assert_non_null(strstr(barbs, "uniform token type = \"linear\""));
	assert_non_null(strstr(barbs, "uniform token wrap = \"nonperiodic\""));
	assert_int_equal(usda_array(barbs, "int[] curveVertexCounts", false, &sum), 4400);
	assert_close(sum, 132000, 0);
	assert_int_equal(usda_array(barbs, "point3f[] points", true, NULL), 132000);
	assert_int_equal(usda_array(barbs, "normal3f[] normals", true, NULL), 132000);
	assert_int_equal(usda_array(barbs, "float[] widths", false, NULL), 132000);
	assert_int_equal(usda_array(barbs, "texCoord2f[] primvars:st", true, NULL), 132000);
	assert_int_equal(usda_array(barbs, "int[] primvars:side", false, &sum), 4400);
	assert_close(sum, 2200, 0); // left = 0, right = 1
	assert_int_equal(usda_array(barbs, "float3[] extent", true, NULL), 2);
	assert_non_null(strstr(barbs, "interpolation = \"uniform\""));
	assert_non_null(strstr(barbs, "interpolation = \"vertex\""));
	// Points are floats: the first barb's root to float precision.
	plume_vec3 root = usda_first_point(barbs), expect = plume_feather_barb(feather, 0).curve.points[0];
	assert_close(root.x, expect.x, 1e-7 * fabs(expect.x) + 1e-12);
	assert_close(root.y, expect.y, 1e-7 * fabs(expect.y) + 1e-12);
	assert_close(root.z, expect.z, 1e-7 * fabs(expect.z) + 1e-12);
	free(barbs);
	free(text);
	plume_feather_destroy(feather);

	// Barbules, a curve too short to draw, and nested afterfeathers.
	feather = small_feather(1);
	write_ok(FORMAT_USDA, feather, path);
	text = (char *)test_read_file(path, NULL);
	barbs = usda_prim(text, "BasisCurves", "barbs");
	assert_int_equal(usda_array(barbs, "int[] curveVertexCounts", false, &sum), 2); // the 1-point barb is left out
	assert_close(sum, 8, 0);
	assert_int_equal(usda_array(barbs, "point3f[] points", true, NULL), 8);
	assert_int_equal(usda_array(barbs, "int[] primvars:side", false, &sum), 2);
	assert_close(sum, 1, 0);
	free(barbs);
	char *barbules = usda_prim(text, "BasisCurves", "barbules");
	assert_non_null(barbules);
	assert_int_equal(usda_array(barbules, "int[] curveVertexCounts", false, &sum), 3);
	assert_close(sum, 7, 0);
	assert_int_equal(usda_array(barbules, "normal3f[] normals", true, NULL), 7);
	assert_int_equal(usda_array(barbules, "int[] primvars:kind", false, &sum), 3);
	assert_close(sum, 1, 0);
	assert_int_equal(usda_array(barbules, "int[] primvars:barb", false, &sum), 3);
	assert_close(sum, 2, 0);
	free(barbules);
	char *after = usda_prim(text, "Xform", "afterfeather");
	assert_non_null(after);
	assert_non_null(strstr(after, "custom double plume:attach_t = 0.15"));
	free(after);
	free(text);
	plume_feather_destroy(feather);

	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

// ---------------------------------------------------------------------------
// Reader errors

// A small valid document; the error tests each change one piece of it.
static const char valid_document[] =
    "{\"format\": \"plume-feather\", \"version\": 1,\n"
    " \"shaft\": {\"calamus_samples\": 1, \"position\": [0, 0, 0, 0, 0.1, 0], \"tangent\": [0, 1, 0, 0, 1, 0],"
    " \"normal\": [0, 0, 1, 0, 0, 1], \"binormal\": [-1, 0, 0, -1, 0, 0], \"width\": [0.002, 0.001], \"t\": [0, 1]},\n"
    " \"barbs\": [\n"
    "  {\"side\": \"left\", \"rachis_t\": 0.5, \"segment\": 0, \"position\": [0, 0.05, 0, -0.01, 0.06, 0],"
    " \"normal\": [0, 0, 1, 0, 0, 1], \"arc_length\": [0, 0.0141], \"width\": [1e-4, 5e-5], \"uv\": [0, 0.5, 1, 0.5],"
    " \"barbules\": []},\n"
    "  {\"side\": \"right\", \"rachis_t\": 0.5, \"segment\": 1, \"position\": [0, 0.05, 0, 0.01, 0.06, 0],"
    " \"normal\": [0, 0, 1, 0, 0, 1], \"arc_length\": [0, 0.0142], \"width\": [1e-4, 5e-5], \"uv\": [0, 0.5, 1, 0.5],"
    " \"barbules\": [{\"barb_s\": 0.5, \"kind\": \"distal\", \"position\": [0.005, 0.055, 0, 0.006, 0.056, 0],"
    " \"normal\": [0, 0, 1, 0, 0, 1], \"arc_length\": [0, 0.0014], \"width\": [1e-5, 1e-5], \"uv\": [0, 0, 1, 0]}]}\n"
    " ],\n"
    " \"afterfeather\": {\"t\": 0.15, \"feather\": {\"shaft\": {\"calamus_samples\": 0, \"position\": [],"
    " \"tangent\": [], \"normal\": [], \"binormal\": [], \"width\": [], \"t\": []}, \"barbs\": [],"
    " \"afterfeather\": null}}\n"
    "}\n";

/// valid_document with its only occurrence of `from` replaced by `to`, written to path.
static void write_variant(const char *path, const char *from, const char *to)
{
	const char *at = strstr(valid_document, from);
	assert_non_null(at);
	assert_null(strstr(at + 1, from)); // the change is unambiguous
	size_t size = sizeof valid_document + strlen(to);
	char *text = malloc(size);
	snprintf(text, size, "%.*s%s%s", (int)(at - valid_document), valid_document, to, at + strlen(from));
	test_write_file(path, text);
	free(text);
}

/// Reading path fails with status, *out stays NULL, and the message has each needle.
static void expect_read_error(const char *path, plume_status status, const char *needle, const char *needle2)
{
	plume_feather *feather = (plume_feather *)&feather; // not NULL, to see that it is reset
	plume_error err = {0};
	plume_status got = plume_read_json(path, &feather, &err);
	if (got != status)
		fail_msg("expected status %s, got %s: %s", plume_status_name(status), plume_status_name(got), err.message);
	assert_null(feather);
	assert_int_equal(err.status, status);
	if (needle != NULL && strstr(err.message, needle) == NULL)
		fail_msg("message \"%s\" lacks \"%s\"", err.message, needle);
	if (needle2 != NULL && strstr(err.message, needle2) == NULL)
		fail_msg("message \"%s\" lacks \"%s\"", err.message, needle2);
}

static void test_read_json_errors(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512], message[1024];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/doc.json", dir);

	// The valid document reads, so each variant below fails for its own change only.
	test_write_file(path, valid_document);
	plume_feather *feather = read_ok(path);
	plume_feather_info info = plume_feather_get_info(feather);
	assert_int_equal(info.barb_count, 2);
	assert_int_equal(info.barbule_count, 1);
	assert_int_equal(info.calamus_sample_count, 1);
	assert_true(info.has_afterfeather);
	assert_int_equal(plume_feather_barbule(feather, 0).barb, 1);
	assert_int_equal(plume_feather_barb(feather, 1).barbule_first, 0);
	plume_feather_destroy(feather);

	// Missing file: io, "path: cannot read: reason".
	char missing[512];
	snprintf(missing, sizeof missing, "%s/none.json", dir);
	snprintf(message, sizeof message, "%s: cannot read: ", missing);
	expect_read_error(missing, PLUME_ERROR_IO, message, "No such file");
	// A folder opens but does not read.
	snprintf(message, sizeof message, "%s: cannot read: ", dir);
	expect_read_error(dir, PLUME_ERROR_IO, message, NULL);

	// Syntax: "path:line:column: text"; jansson's column is where the bad token
	// ends: the stray word spans columns 2 to 5 of line 2.
	test_write_file(path, "{\"format\": \"plume-feather\",\n oops: 1}\n");
	snprintf(message, sizeof message, "%s:2:5: ", path);
	expect_read_error(path, PLUME_ERROR_SYNTAX, message, "near 'oops'");
	test_write_file(path, "{\"format\": \"plume-feather\", \"format\": \"again\"}\n");
	snprintf(message, sizeof message, "%s:1:", path);
	expect_read_error(path, PLUME_ERROR_SYNTAX, message, "duplicate");
	test_write_file(path, "");
	expect_read_error(path, PLUME_ERROR_SYNTAX, path, NULL);

	// Schema: "path: $.json.path: what is wrong".
	snprintf(message, sizeof message, "%s: $.barbs[1].position: expected an array of 3n numbers", path);
	write_variant(path, "\"segment\": 1, \"position\": [0, 0.05, 0, 0.01, 0.06, 0]",
	              "\"segment\": 1, \"position\": [0, 0.05, 0, 0.01]");
	expect_read_error(path, PLUME_ERROR_SPEC, message, NULL);

	static const struct {
		const char *from, *to, *path, *what;
	} cases[] = {
	    {"\"version\": 1", "\"version\": 3", "$.version:", "unsupported version"},
	    {"\"format\": \"plume-feather\"", "\"format\": \"feather\"", "$.format:", "plume-feather"},
	    {"\"side\": \"left\"", "\"side\": \"up\"", "$.barbs[0].side:", "\"left\" or \"right\""},
	    {"\"segment\": 0", "\"segment\": 0.5", "$.barbs[0].segment:", "integer"},
	    {"\"segment\": 0", "\"segment\": 0, \"colour\": 3", "$.barbs[0]:",
	     "unknown key \"colour\"; the keys here are: side, rachis_t, segment, position, normal, arc_length, width, uv, "
	     "barbules"},
	    {"\"rachis_t\": 0.5, \"segment\": 0", "\"segment\": 0", "$.barbs[0]:", "missing key \"rachis_t\""},
	    {"\"arc_length\": [0, 0.0141]", "\"arc_length\": [0, 0.0141, 3]", "$.barbs[0].arc_length:", "found 3"},
	    {"\"position\": [0, 0.05, 0, -0.01", "\"position\": [0, 0.05, \"x\", -0.01",
	     "$.barbs[0].position[2]:", "expected a number"},
	    {"\"kind\": \"distal\"", "\"kind\": 1", "$.barbs[1].barbules[0].kind:", "\"distal\" or \"proximal\""},
	    {"\"uv\": [0, 0, 1, 0]", "\"uv\": [0, 0, 1]",
	     "$.barbs[1].barbules[0].uv:", "expected 4 numbers (2 per point, 2 points), found 3"},
	    {"\"calamus_samples\": 1", "\"calamus_samples\": 3", "$.shaft.calamus_samples:", "out of range [0, 2]"},
	    {"\"t\": [0, 1]", "\"t\": [0]", "$.shaft.t:", "expected 2 numbers"},
	    {"\"barbs\": [],", "\"barbs\": [7],", "$.afterfeather.feather.barbs[0]:", "expected an object"},
	    {"\"t\": 0.15", "\"t\": null", "$.afterfeather.t:", "expected a number"},
	    {"\"afterfeather\": null", "\"afterfeather\": null, \"format\": \"plume-feather\"",
	     "$.afterfeather.feather:", "unknown key \"format\"; the keys here are: shaft, barbs, afterfeather"},
	    {"\"barbules\": []", "\"barbules\": {}", "$.barbs[0].barbules:", "expected an array"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
		write_variant(path, cases[i].from, cases[i].to);
		snprintf(message, sizeof message, "%s: %s", path, cases[i].path);
		expect_read_error(path, PLUME_ERROR_SPEC, message, cases[i].what);
	}
	// Not an object at all.
	test_write_file(path, "[1, 2]");
	snprintf(message, sizeof message, "%s: $: expected an object", path);
	expect_read_error(path, PLUME_ERROR_SPEC, message, NULL);

	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

// ---------------------------------------------------------------------------
// Atomic writes

static void test_write_to_missing_folder_fails_and_creates_nothing(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	assert_false(test_file_exists("/nonexistent-dir"));
	plume_feather *feather = small_feather(0);
	for (int f = 0; f < 3; ++f) {
		char path[64];
		snprintf(path, sizeof path, "/nonexistent-dir/x.%s", format_extensions[f]);
		plume_error err;
		assert_int_equal(write_format((format)f, feather, path, &err), PLUME_ERROR_IO);
		assert_non_null(strstr(err.message, path));
		assert_false(test_file_exists(path));
	}
	assert_false(test_file_exists("/nonexistent-dir"));
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// A write that fails half-way (the file-size limit stops it after 64 KiB)
/// leaves the file that was there untouched and no temporary file behind.
static void test_failed_write_leaves_existing_file(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256];
	test_make_temp_dir(dir, sizeof dir);
	plume_feather *feather = hawk(2);

	struct rlimit saved;
	assert_int_equal(getrlimit(RLIMIT_FSIZE, &saved), 0);
	// Past the limit write() fails with EFBIG instead of raising SIGXFSZ.
	void (*saved_handler)(int) = signal(SIGXFSZ, SIG_IGN);
	for (int f = 0; f < 3; ++f) {
		char path[512];
		snprintf(path, sizeof path, "%s/out.%s", dir, format_extensions[f]);
		test_write_file(path, "what was there before\n");
		uint64_t old = test_hash_file(path);

		struct rlimit limit = saved;
		limit.rlim_cur = 64 * 1024;
		assert_int_equal(setrlimit(RLIMIT_FSIZE, &limit), 0);
		plume_error err;
		plume_status status = write_format((format)f, feather, path, &err);
		assert_int_equal(setrlimit(RLIMIT_FSIZE, &saved), 0);

		assert_int_equal(status, PLUME_ERROR_IO);
		assert_non_null(strstr(err.message, path));
		assert_true(test_hash_file(path) == old);
		assert_int_equal(test_count_entries(dir), f + 1);
	}
	signal(SIGXFSZ, saved_handler);

	plume_feather_destroy(feather);
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// Version 2's own errors: a missing or short sidecar, a name with a folder, a
/// view whose count disagrees, and views in a version 1 document.
static void test_json_binary_errors(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char dir[256], path[512], sidecar[512], message[1024];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/doc.json", dir);
	snprintf(sidecar, sizeof sidecar, "%s/doc.bin", dir);
	static const char head[] = "{\"format\": \"plume-feather\", \"version\": 2, \"buffer\": {\"uri\": \"%s\"},\n"
	                           " \"shaft\": {\"calamus_samples\": 0, \"position\": %s, \"tangent\": [0, 1, 0],"
	                           " \"normal\": [0, 0, 1], \"binormal\": [1, 0, 0], \"width\": [0.001], \"t\": [0]},"
	                           " \"barbs\": [], \"afterfeather\": null}\n";
	char document[1024];
	// 24 bytes: one point, three doubles 1, 2, 3.
	FILE *file = fopen(sidecar, "wb");
	for (int i = 1; i <= 3; ++i) {
		unsigned char bytes[8];
		uint64_t bits;
		double value = i;
		memcpy(&bits, &value, 8);
		for (int k = 0; k < 8; ++k)
			bytes[k] = (unsigned char)(bits >> (8 * k));
		fwrite(bytes, 1, 8, file);
	}
	fclose(file);
	snprintf(document, sizeof document, head, "doc.bin", "{\"offset\": 0, \"count\": 3}");
	test_write_file(path, document);
	plume_feather *feather = read_ok(path);
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	assert_true(shaft[0].position.x == 1 && shaft[0].position.y == 2 && shaft[0].position.z == 3);
	plume_feather_destroy(feather);

	snprintf(document, sizeof document, head, "doc.bin", "{\"offset\": 8, \"count\": 3}");
	test_write_file(path, document);
	snprintf(message, sizeof message, "%s: $.shaft.position: the view", path);
	expect_read_error(path, PLUME_ERROR_SPEC, message, "runs past the sidecar's 24 bytes");
	snprintf(document, sizeof document, head, "doc.bin", "{\"offset\": 0, \"count\": 2}");
	test_write_file(path, document);
	expect_read_error(path, PLUME_ERROR_SPEC, "$.shaft.position", "expected an array of 3n numbers");
	snprintf(document, sizeof document, head, "../doc.bin", "{\"offset\": 0, \"count\": 3}");
	test_write_file(path, document);
	expect_read_error(path, PLUME_ERROR_SPEC, "$.buffer.uri", "a file name in the JSON file's folder");
	snprintf(document, sizeof document, head, "none.bin", "{\"offset\": 0, \"count\": 3}");
	test_write_file(path, document);
	expect_read_error(path, PLUME_ERROR_IO, "cannot read the sidecar", "none.bin");
	// Version 1 has no sidecar: neither "buffer" nor views.
	write_variant(path, "\"version\": 1", "\"version\": 3");
	expect_read_error(path, PLUME_ERROR_SPEC, "$.version", "reads versions 1 and 2");
	write_variant(path, "\"segment\": 1, \"position\": [0, 0.05, 0, 0.01, 0.06, 0]",
	              "\"segment\": 1, \"position\": {\"offset\": 0, \"count\": 6}");
	expect_read_error(path, PLUME_ERROR_SPEC, "$.barbs[1].position", "expected an array");
	test_remove_tree(dir);
	assert_int_equal(plume_bytes_in_use(), before);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_json_round_trip_hawk),
	    cmocka_unit_test(test_json_round_trip_small_with_barbules_and_afterfeathers),
	    cmocka_unit_test(test_json_refuses_ungrouped_barbules),
	    cmocka_unit_test(test_json_binary_round_trip),
	    cmocka_unit_test(test_json_number_text),
	    cmocka_unit_test(test_json_refuses_non_finite_numbers),
	    cmocka_unit_test(test_obj_usda_glb_refuse_non_finite_numbers),
	    cmocka_unit_test(test_json_binary_errors),
	    cmocka_unit_test(test_same_seed_same_bytes_other_seed_other_bytes),
	    cmocka_unit_test(test_obj_parses_back_to_the_feather),
	    cmocka_unit_test(test_usda_counts_match),
	    cmocka_unit_test(test_read_json_errors),
	    cmocka_unit_test(test_write_to_missing_folder_fails_and_creates_nothing),
	    cmocka_unit_test(test_failed_write_leaves_existing_file),
	};
	return cmocka_run_group_tests_name("io", tests, NULL, NULL);
}

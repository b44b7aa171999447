// Feather coats (Streit & Heidrich 4.4): follicle layouts, roots on the surface,
// orientation, key feathers, interpolation, drawing order, determinism, the
// strip renderer, exports and bad input.
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "plume/coat.h"
#include "plume/streit_heidrich.h"
#include "support.h"

#define PI 3.14159265358979323846

static char scratch[256];

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

/// Writes a coat spec whose key feathers are the examples' key files.
static const char *write_coat(const char *name, const char *body)
{
	static char path[512];
	snprintf(path, sizeof path, "%s/%s", scratch, name);
	char text[8400];
	const char *keys = PLUME_SOURCE_DIR "/examples/coats/key-";
	char expanded[8192];
	// "@" stands for the key files' folder and prefix.
	size_t o = 0;
	for (const char *c = body; *c != '\0' && o + 200 < sizeof expanded; ++c) {
		if (*c == '@')
			o += (size_t)snprintf(expanded + o, sizeof expanded - o, "%s", keys);
		else
			expanded[o++] = *c;
	}
	expanded[o] = '\0';
	snprintf(text, sizeof text, "{\"model\": \"coat\", %s}", expanded);
	test_write_file(path, text);
	return path;
}

static plume_coat *build(const char *path, uint64_t seed, bool seed_given)
{
	plume_coat *coat = NULL;
	plume_error err = {0};
	plume_spec_options options = {.seed = seed, .seed_given = seed_given};
	if (plume_coat_spec_generate(path, &options, &coat, &err) != PLUME_OK)
		fail_msg("coat failed: %s", err.message);
	return coat;
}

/// Every feather's root is its follicle and its shaft leaves the surface on the outer side.
static void assert_rooted(const plume_coat *coat)
{
	for (int i = 0; i < plume_coat_feather_count(coat); ++i) {
		plume_vec3 root, normal;
		plume_coat_follicle(coat, i, &root, &normal);
		const plume_shaft_sample *shaft = plume_feather_shaft(plume_coat_feather(coat, i));
		assert_close(plume_v3_distance(shaft[0].position, root), 0.0, 1e-15);
		assert_close(plume_v3_length(normal), 1.0, 1e-12);
		assert_true(plume_v3_dot(plume_v3_sub(shaft[1].position, root), normal) > 0.0);
	}
}

static const char *figure15 = PLUME_SOURCE_DIR "/examples/coats/figure15-hexagonal.json";

static void test_hexagonal_patch(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_coat *coat = build(figure15, 0, false);
	// Figure 15: 8 rows of 8 follicles, 1 cm apart.
	int count = plume_coat_feather_count(coat);
	assert_int_equal(count, 64);
	double nearest_overall = INFINITY;
	for (int i = 0; i < count; ++i) {
		plume_vec3 p, n, q;
		plume_coat_follicle(coat, i, &p, &n);
		assert_close(p.z, 0.0, 0.0); // on the plane
		assert_close(n.z, 1.0, 0.0);
		double nearest = INFINITY;
		for (int j = 0; j < count; ++j)
			if (j != i) {
				plume_coat_follicle(coat, j, &q, &n);
				nearest = fmin(nearest, plume_v3_distance(p, q));
			}
		assert_close(nearest, 0.01, 1e-12); // every follicle has a neighbour at the spacing, none nearer
		nearest_overall = fmin(nearest_overall, nearest);
	}
	assert_close(nearest_overall, 0.01, 1e-12);
	assert_rooted(coat);
	int keys = 0;
	for (int i = 0; i < count; ++i)
		keys += plume_coat_is_key(coat, i);
	assert_int_equal(keys, 4);
	const plume_mesh *surface = plume_coat_surface(coat);
	assert_non_null(surface);
	assert_int_equal(surface->face_count, 2);
	plume_coat_destroy(coat);
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_key_feathers_are_placed_as_designed(void **state)
{
	(void)state;
	plume_coat *coat = build(figure15, 0, false);
	plume_sh_def def;
	uint64_t seed;
	plume_error err;
	assert_int_equal(plume_sh_def_read(PLUME_SOURCE_DIR "/examples/coats/key-contour.json", &def, &seed, NULL, &err),
	                 PLUME_OK);
	plume_feather *alone = NULL;
	assert_int_equal(plume_sh_generate(&def, seed, 1.0, &alone, &err), PLUME_OK);
	plume_feather_info expected = plume_feather_get_info(alone);
	// The key feather at (0, 0): the same feather, moved to its follicle and lifted off the plane by 20 degrees.
	bool found = false;
	for (int i = 0; i < plume_coat_feather_count(coat); ++i) {
		plume_vec3 p, n;
		plume_coat_follicle(coat, i, &p, &n);
		if (!plume_coat_is_key(coat, i) || plume_v3_length(p) > 1e-12)
			continue;
		found = true;
		const plume_feather *feather = plume_coat_feather(coat, i);
		plume_feather_info info = plume_feather_get_info(feather);
		assert_int_equal(info.barb_count, expected.barb_count);
		assert_close(info.shaft_length, expected.shaft_length, 1e-12);
		const plume_shaft_sample *shaft = plume_feather_shaft(feather);
		plume_vec3 along = plume_v3_normalize(plume_v3_sub(shaft[1].position, shaft[0].position));
		assert_close(along.y, cos(20.0 * PI / 180.0), 1e-12); // direction +y, lifted by lift_deg
		assert_close(along.z, sin(20.0 * PI / 180.0), 1e-12);
	}
	assert_true(found);
	plume_feather_destroy(alone);
	plume_coat_destroy(coat);
}

static void test_bilinear_interpolation_inside_the_quad(void **state)
{
	(void)state;
	// Four key feathers whose rachis lengths differ; a follicle in the middle of the square gets their mean.
	const char *path = write_coat("quad.json", "\"surface\": {\"type\": \"plane\", \"size\": [0.04, 0.0347]},"
	                                           "\"follicles\": {\"layout\": \"hexagonal\", \"spacing\": 0.01},"
	                                           "\"key_feathers\": ["
	                                           "{\"at\": [0, 0], \"feather\": {\"rachis_length\": 0.01}},"
	                                           "{\"at\": [0.04, 0], \"feather\": {\"rachis_length\": 0.02}},"
	                                           "{\"at\": [0.04, 0.0347], \"feather\": {\"rachis_length\": 0.03}},"
	                                           "{\"at\": [0, 0.0347], \"feather\": {\"rachis_length\": 0.04}}],"
	                                           "\"lod\": {\"rachis_elevations\": 0}, \"lift_deg\": 10");
	plume_coat *coat = build(path, 1, false);
	assert_rooted(coat);
	for (int i = 0; i < plume_coat_feather_count(coat); ++i) {
		plume_vec3 p, n;
		plume_coat_follicle(coat, i, &p, &n);
		// The square's corners are follicles, so bilinear coordinates are u = x / 0.04, v = y / 0.0347 (both
		// ends of each row are follicles only on even rows; the others are clamped at the edges).
		double u = fmin(fmax(p.x / 0.04, 0.0), 1.0), v = fmin(fmax(p.y / 0.0346410161513775, 0.0), 1.0);
		double expected = 0.01 * (1 - u) * (1 - v) + 0.02 * u * (1 - v) + 0.03 * u * v + 0.04 * (1 - u) * v;
		const plume_feather *feather = plume_coat_feather(coat, i);
		plume_feather_info info = plume_feather_get_info(feather);
		// A straight rachis (no curvature in the defaults? the defaults curve it): compare the tip's distance.
		const plume_shaft_sample *shaft = plume_feather_shaft(feather);
		double chord = plume_v3_distance(shaft[info.calamus_sample_count - 1].position,
		                                 shaft[info.shaft_sample_count - 1].position);
		assert_close(chord, expected, 1e-9);
	}
	plume_coat_destroy(coat);
}

static void test_poisson_keeps_its_distance(void **state)
{
	(void)state;
	plume_coat *coat = build(PLUME_SOURCE_DIR "/examples/coats/figure16-poisson.json", 0, false);
	int count = plume_coat_feather_count(coat);
	printf("poisson patch: %d follicles\n", count);
	assert_true(count > 50);
	for (int i = 0; i < count; ++i) {
		plume_vec3 p, q, n;
		plume_coat_follicle(coat, i, &p, &n);
		assert_true(p.x >= 0.0 && p.x <= 0.08 && p.y >= 0.0 && p.y <= 0.06 && p.z == 0.0);
		for (int j = i + 1; j < count; ++j) {
			plume_coat_follicle(coat, j, &q, &n);
			// The spacing grows from 6 mm on the left to 9 mm on the right: two follicles are never nearer
			// than the larger of their own spacings.
			double sp = 0.006 * (1.0 + 0.5 * fmax(p.x, q.x) / 0.08);
			assert_true(plume_v3_distance(p, q) >= sp - 1e-15);
		}
	}
	assert_rooted(coat);
	// Determinism: the same seed gives the same coat; another seed another layout.
	plume_coat *again = build(PLUME_SOURCE_DIR "/examples/coats/figure16-poisson.json", 0, false);
	assert_int_equal(plume_coat_feather_count(again), count);
	for (int i = 0; i < count; ++i)
		assert_true(plume_feather_equal(plume_coat_feather(coat, i), plume_coat_feather(again, i)));
	plume_coat *other = build(PLUME_SOURCE_DIR "/examples/coats/figure16-poisson.json", 99, true);
	plume_vec3 a, b, n;
	plume_coat_follicle(coat, 0, &a, &n);
	plume_coat_follicle(other, 0, &b, &n);
	assert_true(plume_coat_feather_count(other) != count || plume_v3_distance(a, b) > 0.0);
	plume_coat_destroy(other);
	plume_coat_destroy(again);
	plume_coat_destroy(coat);
}

static void test_sphere_coat(void **state)
{
	(void)state;
	plume_coat *coat = build(PLUME_SOURCE_DIR "/examples/coats/sphere.json", 0, false);
	int count = plume_coat_feather_count(coat);
	// A geodesic grid of frequency n has 10 n^2 + 2 vertices; n = round(1.1071 r / spacing) = 6.
	assert_int_equal(count, 10 * 6 * 6 + 2);
	for (int i = 0; i < count; ++i) {
		plume_vec3 p, n;
		plume_coat_follicle(coat, i, &p, &n);
		assert_close(plume_v3_length(p), 0.04, 1e-15);
		assert_close(plume_v3_distance(plume_v3_scale(n, 0.04), p), 0.0, 1e-15);
	}
	assert_rooted(coat);
	// Drawing order: the feathers nearest the tail point are at the bottom.
	plume_vec3 tail = plume_v3(0, -0.08, 0), p, n;
	double previous = 0.0;
	for (int i = 0; i < count; ++i) {
		plume_coat_follicle(coat, i, &p, &n);
		double d = plume_v3_distance(p, tail);
		assert_true(d >= previous);
		previous = d;
	}
	plume_coat_destroy(coat);
}

static void test_mesh_surface(void **state)
{
	(void)state;
	// An octahedron of radius 3 cm, faces wound outwards.
	char obj[512];
	snprintf(obj, sizeof obj, "%s/octahedron.obj", scratch);
	test_write_file(obj, "v 0.03 0 0\nv -0.03 0 0\nv 0 0.03 0\nv 0 -0.03 0\nv 0 0 0.03\nv 0 0 -0.03\n"
	                     "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n");
	const char *path =
	    write_coat("mesh.json", "\"surface\": {\"type\": \"mesh\", \"obj\": \"octahedron.obj\"},"
	                            "\"follicles\": {\"layout\": \"poisson\", \"spacing\": 0.006},"
	                            "\"key_feathers\": [{\"at\": [0, 0, 0.03], \"feather\": \"@plume.json\"},"
	                            "{\"at\": [0.03, 0, 0], \"feather\": \"@contour.json\"}],"
	                            "\"direction\": {\"towards\": [0, -0.05, 0]},"
	                            "\"lod\": {\"barb_elevations\": 0}");
	plume_coat *coat = build(path, 2, false);
	int count = plume_coat_feather_count(coat);
	assert_true(count > 50);
	for (int i = 0; i < count; ++i) {
		plume_vec3 p, n;
		plume_coat_follicle(coat, i, &p, &n);
		// On the octahedron |x| + |y| + |z| = 0.03.
		assert_close(fabs(p.x) + fabs(p.y) + fabs(p.z), 0.03, 1e-15);
	}
	assert_rooted(coat);
	assert_int_equal(plume_coat_surface(coat)->face_count, 8);
	plume_coat_destroy(coat);
}

/// The coat surface of a cube written as quads follicle for follicle equals the same cube
/// written as the triangles a fan from each quad's first corner gives, (c0 c1 c2), (c0 c2 c3).
static void test_mesh_surface_of_quads(void **state)
{
	(void)state;
	// A cube of half-side 3 cm, faces wound outwards.
	const char *vertices = "v -0.03 -0.03 -0.03\nv 0.03 -0.03 -0.03\nv 0.03 0.03 -0.03\nv -0.03 0.03 -0.03\n"
	                       "v -0.03 -0.03 0.03\nv 0.03 -0.03 0.03\nv 0.03 0.03 0.03\nv -0.03 0.03 0.03\n";
	const int quads[6][4] = {{1, 4, 3, 2}, {5, 6, 7, 8}, {1, 2, 6, 5}, {3, 4, 8, 7}, {1, 5, 8, 4}, {2, 3, 7, 6}};
	char quad_text[1024], triangle_text[1024];
	size_t q = (size_t)snprintf(quad_text, sizeof quad_text, "%s", vertices);
	size_t t = (size_t)snprintf(triangle_text, sizeof triangle_text, "%s", vertices);
	for (int f = 0; f < 6; ++f) {
		const int *c = quads[f];
		q += (size_t)snprintf(quad_text + q, sizeof quad_text - q, "f %d %d %d %d\n", c[0], c[1], c[2], c[3]);
		t += (size_t)snprintf(triangle_text + t, sizeof triangle_text - t, "f %d %d %d\nf %d %d %d\n", c[0], c[1], c[2],
		                      c[0], c[2], c[3]);
	}
	char obj[512];
	snprintf(obj, sizeof obj, "%s/cube-quads.obj", scratch);
	test_write_file(obj, quad_text);
	snprintf(obj, sizeof obj, "%s/cube-triangles.obj", scratch);
	test_write_file(obj, triangle_text);
	const char *rest = "\"follicles\": {\"layout\": \"poisson\", \"spacing\": 0.012},"
	                   "\"key_feathers\": [{\"at\": [0, 0, 0.03], \"feather\": \"@plume.json\"},"
	                   "{\"at\": [0.03, 0, 0], \"feather\": \"@contour.json\"}],"
	                   "\"direction\": {\"towards\": [0, -0.05, 0]}, \"lod\": {\"barb_elevations\": 0}";
	char body[1024];
	snprintf(body, sizeof body, "\"surface\": {\"type\": \"mesh\", \"obj\": \"cube-quads.obj\"}, %s", rest);
	plume_coat *from_quads = build(write_coat("quads.json", body), 2, false);
	snprintf(body, sizeof body, "\"surface\": {\"type\": \"mesh\", \"obj\": \"cube-triangles.obj\"}, %s", rest);
	plume_coat *from_triangles = build(write_coat("triangles.json", body), 2, false);
	assert_int_equal(plume_coat_surface(from_quads)->face_count, 12);
	assert_memory_equal(plume_coat_surface(from_quads)->faces, plume_coat_surface(from_triangles)->faces,
	                    36 * sizeof(int));
	int count = plume_coat_feather_count(from_quads);
	assert_true(count > 50);
	assert_int_equal(plume_coat_feather_count(from_triangles), count);
	for (int i = 0; i < count; ++i) {
		plume_vec3 p[2], n[2];
		plume_coat_follicle(from_quads, i, &p[0], &n[0]);
		plume_coat_follicle(from_triangles, i, &p[1], &n[1]);
		assert_memory_equal(&p[0], &p[1], sizeof p[0]);
		assert_memory_equal(&n[0], &n[1], sizeof n[0]);
	}
	assert_rooted(from_quads);
	plume_coat_destroy(from_triangles);
	plume_coat_destroy(from_quads);
}

static void test_exports_and_strip_rendering(void **state)
{
	(void)state;
	plume_coat *coat = build(figure15, 0, false);
	char obj[512], usda[512], lines[512], strips[512], strips2[512];
	snprintf(obj, sizeof obj, "%s/coat.obj", scratch);
	snprintf(usda, sizeof usda, "%s/coat.usda", scratch);
	snprintf(lines, sizeof lines, "%s/lines.png", scratch);
	snprintf(strips, sizeof strips, "%s/strips.png", scratch);
	snprintf(strips2, sizeof strips2, "%s/strips2.png", scratch);
	plume_error err;
	assert_int_equal(plume_coat_write_obj(coat, obj, &err), PLUME_OK);
	assert_int_equal(plume_coat_write_usda(coat, usda, &err), PLUME_OK);
	size_t size;
	unsigned char *text = test_read_file(obj, &size);
	int objects = 0;
	for (size_t i = 0; i + 1 < size; ++i)
		objects += text[i] == '\n' && text[i + 1] == 'o';
	assert_int_equal(objects, 64);
	free(text);
	text = test_read_file(usda, &size);
	assert_non_null(strstr((char *)text, "def BasisCurves \"feather_00063\""));
	assert_non_null(strstr((char *)text, "def Mesh \"surface\""));
	free(text);
	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 300;
	assert_int_equal(plume_coat_render2d(coat, &def, PLUME_IMAGE_PNG, lines, &err), PLUME_OK);
	def.style = PLUME_STYLE_STRIPS;
	assert_int_equal(plume_coat_render2d(coat, &def, PLUME_IMAGE_PNG, strips, &err), PLUME_OK);
	assert_int_equal(plume_coat_render2d(coat, &def, PLUME_IMAGE_PNG, strips2, &err), PLUME_OK);
	assert_true(test_hash_file(lines) != test_hash_file(strips));
	assert_true(test_hash_file(strips) == test_hash_file(strips2));
	def.strip_alpha = 0.0;
	assert_int_equal(plume_coat_render2d(coat, &def, PLUME_IMAGE_PNG, strips, &err), PLUME_ERROR_SPEC);
	plume_coat_destroy(coat);
}

static void expect_coat_error(const char *body, plume_status status, const char *fragment)
{
	const char *path = write_coat("bad.json", body);
	plume_coat *coat = NULL;
	plume_error err = {0};
	plume_spec_options options = {0};
	assert_int_equal(plume_coat_spec_generate(path, &options, &coat, &err), status);
	assert_null(coat);
	if (strstr(err.message, fragment) == NULL)
		fail_msg("message '%s' lacks '%s'", err.message, fragment);
}

static void test_bad_coats(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	const char *keys = "\"key_feathers\": [{\"at\": [0, 0], \"feather\": \"@plume.json\"}]";
	char body[2048];
	snprintf(body, sizeof body, "\"follicles\": {\"spacing\": 0.01}, %s", keys);
	expect_coat_error(body, PLUME_ERROR_SPEC, "$.surface: missing");
	snprintf(body, sizeof body, "\"surface\": {\"type\": \"cube\"}, \"follicles\": {\"spacing\": 0.01}, %s", keys);
	expect_coat_error(body, PLUME_ERROR_SPEC, "$.surface.type: unknown surface \"cube\"");
	snprintf(body, sizeof body,
	         "\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0]}, \"follicles\": {\"spacing\": 0.01}, %s", keys);
	expect_coat_error(body, PLUME_ERROR_SPEC, "$.surface.size[1]: is 0, must be a positive length");
	snprintf(body, sizeof body,
	         "\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0.05]}, \"follicles\": {\"spacing\": -1}, %s", keys);
	expect_coat_error(body, PLUME_ERROR_SPEC, "$.follicles.spacing: is -1");
	snprintf(body, sizeof body,
	         "\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0.05]}, \"follicles\": {\"spacing\": 0.01}, %s, "
	         "\"interpolation\": \"bilinear\"",
	         keys);
	expect_coat_error(body, PLUME_ERROR_SPEC, "bilinear interpolation needs 4 key feathers");
	snprintf(body, sizeof body,
	         "\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0.05]}, \"follicles\": {\"spacing\": 0.01}, %s, "
	         "\"lift_deg\": 0",
	         keys);
	expect_coat_error(body, PLUME_ERROR_SPEC, "$.lift_deg: is 0, allowed (0, 90]");
	expect_coat_error("\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0.05]}, \"follicles\": {\"spacing\": 0.01},"
	                  "\"key_feathers\": [{\"at\": [0, 0], \"feather\": {\"model\": \"franco-walter\"}}]",
	                  PLUME_ERROR_SPEC, "coat key feathers are streit-heidrich feathers");
	expect_coat_error("\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0.05]}, \"follicles\": {\"spacing\": 0.01},"
	                  "\"key_feathers\": [{\"at\": [0, 0], \"feather\": {\"rachis_length\": -1}}]",
	                  PLUME_ERROR_SPEC, "bad.json: $.key_feathers[0].feather.rachis_length is -1");
	// An inline key feather is part of the coat's file: its keys are named from the coat's root.
	expect_coat_error("\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0.05]}, \"follicles\": {\"spacing\": 0.01},"
	                  "\"key_feathers\": [{\"at\": [0, 0], \"feather\": \"@plume.json\"}, {\"at\": [0.02, 0], "
	                  "\"feather\": {\"rachis_lenght\": 0.1}}]",
	                  PLUME_ERROR_SPEC, "bad.json: $.key_feathers[1].feather.rachis_lenght: unknown key");
	expect_coat_error("\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0.05]}, \"follicles\": {\"spacing\": 0.01},"
	                  "\"key_feathers\": [{\"at\": [0, 0], \"feather\": {\"blend\": {\"feathers\": [{}, "
	                  "{\"spacing_tip\": -1}], \"t\": 0.5}}}]",
	                  PLUME_ERROR_SPEC, "bad.json: $.key_feathers[0].feather.blend.feathers[1].spacing_tip is -1");
	expect_coat_error("\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0.05]}, \"follicles\": {\"spacing\": 0.01},"
	                  "\"key_feathers\": [{\"at\": [0, 0], \"feather\": \"@plume.json\"},"
	                  "{\"at\": [0.001, 0], \"feather\": \"@plume.json\"}]",
	                  PLUME_ERROR_SPEC, "already holds key feather 0");
	// A Poisson layout's grid indexes cells by coordinate / spacing as longs: 1e12 m / 1e-7 m (1e19) was
	// cast past a long. A spacing under 1e-15 of how far the surface reaches is refused before the layout.
	expect_coat_error(
	    "\"surface\": {\"type\": \"sphere\", \"centre\": [1e12, 0, 0], \"radius\": 2e-6},"
	    "\"follicles\": {\"layout\": \"poisson\", \"spacing\": 1e-7},"
	    "\"key_feathers\": [{\"at\": [1e12, 0, 0], \"feather\": \"@plume.json\"}]",
	    PLUME_ERROR_SPEC,
	    "$.follicles.spacing: 1e-07 m (1e-07 m the smallest, with the gradient) is too fine for a Poisson "
	    "layout on a surface reaching 1e+12 m from the origin; allowed a smallest spacing >= 0.001 m");
	// An OBJ with a face of two corners.
	char obj[512];
	snprintf(obj, sizeof obj, "%s/short.obj", scratch);
	test_write_file(obj, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2\n");
	snprintf(body, sizeof body,
	         "\"surface\": {\"type\": \"mesh\", \"obj\": \"short.obj\"}, \"follicles\": {\"layout\": \"poisson\", "
	         "\"spacing\": 0.1}, %s",
	         keys);
	const char *path = write_coat("bad.json", body);
	plume_coat *coat = NULL;
	plume_error err = {0};
	plume_spec_options options = {0};
	assert_true(plume_coat_spec_generate(path, &options, &coat, &err) != PLUME_OK);
	assert_null(coat);
	assert_non_null(strstr(err.message, "short.obj:6: face 2 has 2 corners; a face needs at least 3"));
	assert_non_null(strstr(err.message, "$.surface.obj"));
	snprintf(body, sizeof body,
	         "\"surface\": {\"type\": \"mesh\", \"obj\": \"octahedron.obj\"}, \"follicles\": {\"spacing\": 0.1}, %s",
	         keys);
	expect_coat_error(body, PLUME_ERROR_SPEC, "a hexagonal layout needs a plane or a sphere");
	assert_int_equal(plume_bytes_in_use(), before);
}

// Progress calls as a plume_progress_fn records them.
typedef struct progress_log {
	int calls;
	int last_done;
	int last_total;
	bool monotone;
} progress_log;

static void record_progress(void *user, int done, int total)
{
	progress_log *log = user;
	log->monotone = log->monotone && done == log->last_done + 1 && done <= total;
	log->calls += 1;
	log->last_done = done;
	log->last_total = total;
}

static void test_progress(void **state)
{
	(void)state;
	// One call a feather, counting up to the feather count, from whichever thread built it; the
	// coat is the same with or without the callback.
	progress_log log = {.monotone = true};
	plume_spec_options options = {.progress = record_progress, .progress_user = &log};
	plume_coat *coat = NULL, *plain = build(figure15, 0, false);
	plume_error err = {0};
	if (plume_coat_spec_generate(figure15, &options, &coat, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	assert_int_equal(log.calls, 64);
	assert_int_equal(log.last_done, 64);
	assert_int_equal(log.last_total, 64);
	assert_true(log.monotone);
	for (int i = 0; i < 64; ++i)
		assert_true(plume_feather_equal(plume_coat_feather(coat, i), plume_coat_feather(plain, i)));
	plume_coat_destroy(coat);
	plume_coat_destroy(plain);
}

// ---------------------------------------------------------------------------
// Memory: the estimate coat_build checks bounds what the build allocates

static _Atomic int64_t peak_bytes;

/// plume_alloc's hook: the high-water mark of plume_bytes_in_use, the block being allocated included.
static void *peak_alloc(size_t size)
{
	int64_t now = plume_bytes_in_use() + (int64_t)size, seen = atomic_load(&peak_bytes);
	while (now > seen && !atomic_compare_exchange_weak(&peak_bytes, &seen, now)) {
	}
	return malloc(size);
}

/// The most bytes building the coat at path had allocated at once, beyond what was in use before.
static int64_t build_peak(const char *path)
{
	int64_t before = plume_bytes_in_use();
	atomic_store(&peak_bytes, before);
	plume_set_allocator(peak_alloc, NULL);
	plume_coat *coat = build(path, 0, false);
	plume_set_allocator(NULL, NULL);
	plume_coat_destroy(coat);
	return atomic_load(&peak_bytes) - before;
}

static plume_status build_within(const char *path, uint64_t max_memory, plume_error *err)
{
	plume_spec_options options = {.max_memory = max_memory};
	plume_coat *coat = NULL;
	plume_status status = plume_coat_spec_generate(path, &options, &coat, err);
	plume_coat_destroy(coat);
	return status;
}

static void test_estimate_bounds_the_build(void **state)
{
	(void)state;
	// The examples, and key feathers of three types (one with an afterfeather) blended by inverse
	// distance: a blend's rachis, curvatures and spacing between the keys'.
	char mixed[512];
	snprintf(mixed, sizeof mixed, "%s",
	         write_coat("mixed.json", "\"surface\": {\"type\": \"plane\", \"size\": [0.05, 0.04]},"
	                                  "\"follicles\": {\"layout\": \"poisson\", \"spacing\": 0.005},"
	                                  "\"key_feathers\": [{\"at\": [0, 0], \"feather\": \"@contour.json\"},"
	                                  "{\"at\": [0.05, 0], \"feather\": \"@plume.json\"},"
	                                  "{\"at\": [0.025, 0.04], \"feather\": \"" PLUME_SOURCE_DIR
	                                  "/examples/streit-heidrich/semiplume.json\"}],"
	                                  "\"interpolation\": \"inverse-distance\""));
	const char *const paths[] = {figure15, PLUME_SOURCE_DIR "/examples/coats/figure16-poisson.json",
	                             PLUME_SOURCE_DIR "/examples/coats/sphere.json",
	                             PLUME_SOURCE_DIR "/examples/coats/back-cap.json", mixed};
	int threads = 1;
#ifdef _OPENMP
	threads = omp_get_max_threads();
#endif
	for (size_t i = 0; i < sizeof paths / sizeof paths[0]; ++i) {
		int64_t peak = build_peak(paths[i]);
		assert_true(peak > 0);
		// Refused just below what the build really took: its estimate is at least that ...
		plume_error err = {0};
		assert_int_equal(build_within(paths[i], (uint64_t)peak - 1, &err), PLUME_ERROR_LIMIT);
		if (strstr(err.message, "$.follicles.spacing") == NULL || strstr(err.message, "KB") == NULL)
			fail_msg("%s: %s", paths[i], err.message);
		// ... and not far above it: built with three times that and each thread's scratch.
		uint64_t roomy = 3 * (uint64_t)peak + (uint64_t)threads * (2u << 20);
		if (build_within(paths[i], roomy, &err) != PLUME_OK)
			fail_msg("%s within %llu bytes (peak %lld): %s", paths[i], (unsigned long long)roomy, (long long)peak,
			         err.message);
	}
}

/// A surface seen from behind: no follicle faces +z, and the picture is the background alone.
static void test_picture_of_a_surface_seen_from_behind(void **state)
{
	(void)state;
	char obj[512];
	snprintf(obj, sizeof obj, "%s/flipped.obj", scratch);
	test_write_file(obj, "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nf 1 3 2\n");
	const char *path =
	    write_coat("flipped.json", "\"surface\": {\"type\": \"mesh\", \"obj\": \"flipped.obj\"},"
	                               "\"follicles\": {\"layout\": \"poisson\", \"spacing\": 0.01},"
	                               "\"key_feathers\": [{\"at\": [0, 0, 0], \"feather\": \"@contour.json\"}]");
	plume_coat *coat = build(path, 0, false);
	int count = plume_coat_feather_count(coat);
	assert_true(count > 1);
	for (int i = 0; i < count; ++i) {
		plume_vec3 root, normal;
		plume_coat_follicle(coat, i, &root, &normal);
		assert_close(normal.z, -1.0, 1e-12);
	}
	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 64;
	const plume_image_format formats[3] = {PLUME_IMAGE_PNG, PLUME_IMAGE_SVG, PLUME_IMAGE_PDF};
	const char *const names[3] = {"behind.png", "behind.svg", "behind.pdf"};
	for (int k = 0; k < 3; ++k) {
		char out[512];
		snprintf(out, sizeof out, "%s/%s", scratch, names[k]);
		plume_error err = {0};
		if (plume_coat_render2d(coat, &def, formats[k], out, &err) != PLUME_OK)
			fail_msg("%s: %s", names[k], err.message);
		assert_true(test_file_exists(out));
	}
	// The PNG is the white background, every pixel.
	char png[512];
	snprintf(png, sizeof png, "%s/behind.png", scratch);
	plume_texture *picture = NULL;
	plume_error err = {0};
	assert_int_equal(plume_texture_load(png, &picture, &err), PLUME_OK);
	for (int k = 0; k < 5; ++k) {
		plume_color c = plume_texture_sample_vane(picture, PLUME_SIDE_LEFT, 0.1 + 0.2 * k, 0.1 + 0.2 * k);
		assert_close(c.r + c.g + c.b + c.a, 4.0, 1e-9);
	}
	plume_texture_destroy(picture);
	// Without a view to frame it, no feather is still an error.
	const plume_feather *none = NULL;
	assert_int_equal(plume_render2d_feathers(&none, 0, &def, PLUME_IMAGE_PNG, png, &err), PLUME_ERROR_SPEC);
	plume_coat_destroy(coat);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_hexagonal_patch),
	    cmocka_unit_test(test_key_feathers_are_placed_as_designed),
	    cmocka_unit_test(test_bilinear_interpolation_inside_the_quad),
	    cmocka_unit_test(test_poisson_keeps_its_distance),
	    cmocka_unit_test(test_sphere_coat),
	    cmocka_unit_test(test_mesh_surface),
	    cmocka_unit_test(test_mesh_surface_of_quads),
	    cmocka_unit_test(test_exports_and_strip_rendering),
	    cmocka_unit_test(test_bad_coats),
	    cmocka_unit_test(test_progress),
	    cmocka_unit_test(test_estimate_bounds_the_build),
	    cmocka_unit_test(test_picture_of_a_surface_seen_from_behind),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}

// 2D rendering and textures: image size, fit and margin, colours read back
// from the PNG, the paper's texture mapping, determinism, errors that leave
// no file behind.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cairo.h>

#include "model/feather_internal.h"
#include "support.h"

// ---------------------------------------------------------------------------
// Fixtures

/// A synthetic feather with known geometry: a straight shaft from (0, 0) to
/// (0, 1) tapering from 0.1 to 0.04 m, one straight barb per vane from
/// (0, 0.5) to (-+0.4, 0.7), 0.03 m wide, and optionally a barbule on the
/// left barb and an afterfeather (a single shaft from (0, 0.1) to (0.3, 0.3)).
typedef struct fixture_options {
	double barb_width;
	bool barbule;
	bool afterfeather;
} fixture_options;

static void add_straight_barb(plume_feather *f, plume_side side, plume_vec3 from, plume_vec3 to, double width, double t)
{
	const int count = 9;
	int first = plume_feather_add_points(f, count);
	assert_true(first >= 0);
	for (int i = 0; i < count; ++i) {
		double u = (double)i / (count - 1);
		f->points[first + i] = plume_v3_lerp(from, to, u);
		f->normals[first + i] = plume_v3(0, 0, 1);
		f->widths[first + i] = width;
		f->uv[first + i].y = t;
	}
	plume_curve_range range = {first, count};
	plume_feather_measure_curve(f, range);
	plume_barb_record barb = {.curve = range, .side = side, .rachis_t = t, .segment = 0};
	assert_true(plume_feather_add_barb(f, &barb) >= 0);
}

static void add_straight_shaft(plume_feather *f, plume_vec3 from, plume_vec3 to, double width_base, double width_tip)
{
	const int count = 11;
	plume_shaft_sample *shaft = plume_feather_add_shaft(f, count);
	assert_non_null(shaft);
	plume_vec3 tangent = plume_v3_normalize(plume_v3_sub(to, from));
	for (int i = 0; i < count; ++i) {
		double u = (double)i / (count - 1);
		shaft[i] = (plume_shaft_sample){
		    .position = plume_v3_lerp(from, to, u),
		    .tangent = tangent,
		    .normal = plume_v3(0, 0, 1),
		    .binormal = plume_v3_cross(plume_v3(0, 0, 1), tangent),
		    .width = width_base + u * (width_tip - width_base),
		    .t = u,
		};
	}
}

static plume_feather *make_fixture(fixture_options options)
{
	plume_feather *f = plume_feather_create_empty();
	assert_non_null(f);
	add_straight_shaft(f, plume_v3(0, 0, 0), plume_v3(0, 1, 0), 0.1, 0.04);
	f->calamus_count = 2;
	add_straight_barb(f, PLUME_SIDE_LEFT, plume_v3(0, 0.5, 0), plume_v3(-0.4, 0.7, 0), options.barb_width, 0.5);
	add_straight_barb(f, PLUME_SIDE_RIGHT, plume_v3(0, 0.5, 0), plume_v3(0.4, 0.7, 0), options.barb_width, 0.5);
	if (options.barbule) {
		// From the left barb's middle (-0.2, 0.6) straight down to (-0.2, 0.4).
		int first = plume_feather_add_points(f, 2);
		assert_true(first >= 0);
		f->points[first] = plume_v3(-0.2, 0.6, 0);
		f->points[first + 1] = plume_v3(-0.2, 0.4, 0);
		f->widths[first] = f->widths[first + 1] = 0.02;
		plume_curve_range range = {first, 2};
		plume_feather_measure_curve(f, range);
		plume_barbule_record barbule = {.curve = range, .barb = 0, .barb_s = 0.5, .kind = PLUME_BARBULE_PROXIMAL};
		assert_int_equal(plume_feather_add_barbule(f, &barbule), 0);
		f->barbs[0].barbule_first = 0;
		f->barbs[0].barbule_count = 1;
	}
	if (options.afterfeather) {
		f->afterfeather = plume_feather_create_empty();
		assert_non_null(f->afterfeather);
		add_straight_shaft(f->afterfeather, plume_v3(0, 0.1, 0), plume_v3(0.3, 0.3, 0), 0.03, 0.03);
		f->afterfeather_t = 0.1;
	}
	return f;
}

static plume_feather *make_default_fixture(void) { return make_fixture((fixture_options){.barb_width = 0.03}); }

/// A small Franco–Walter feather, so that the tests stay quick under the sanitizers.
static plume_feather *make_small_fw_feather(void)
{
	plume_fw_def def = plume_fw_default_def();
	def.segments[0].barb_count = 20;
	def.segments[1].barb_count = 150;
	plume_feather *feather = NULL;
	plume_error err;
	assert_int_equal(plume_fw_generate(&def, 7, &feather, &err), PLUME_OK);
	return feather;
}

/// Per-test scratch folder and the allocator's count at the start.
typedef struct render_state {
	char dir[256];
	int64_t bytes_before;
} render_state;

static int setup(void **state)
{
	render_state *s = calloc(1, sizeof *s);
	test_make_temp_dir(s->dir, sizeof s->dir);
	s->bytes_before = plume_bytes_in_use();
	*state = s;
	return 0;
}

static int teardown(void **state)
{
	render_state *s = *state;
	// Every texture, feather and scratch buffer of the test has been freed.
	assert_int_equal(plume_bytes_in_use(), s->bytes_before);
	test_remove_tree(s->dir);
	free(s);
	return 0;
}

static void path_in(const render_state *s, const char *name, char *out, size_t size)
{
	snprintf(out, size, "%s/%s", s->dir, name);
}

// ---------------------------------------------------------------------------
// Reading images back

typedef struct image {
	cairo_surface_t *surface;
	int width, height, stride;
	const unsigned char *data;
} image;

static image read_png(const char *path)
{
	image im;
	im.surface = cairo_image_surface_create_from_png(path);
	assert_int_equal(cairo_surface_status(im.surface), CAIRO_STATUS_SUCCESS);
	im.width = cairo_image_surface_get_width(im.surface);
	im.height = cairo_image_surface_get_height(im.surface);
	im.stride = cairo_image_surface_get_stride(im.surface);
	im.data = cairo_image_surface_get_data(im.surface);
	assert_non_null(im.data);
	return im;
}

static void image_free(image *im) { cairo_surface_destroy(im->surface); }

/// Straight-alpha colour of a pixel, from Cairo's premultiplied ARGB32 (or RGB24).
static plume_color pixel(const image *im, int x, int y)
{
	assert_true(x >= 0 && x < im->width && y >= 0 && y < im->height);
	uint32_t word;
	memcpy(&word, im->data + (size_t)y * im->stride + (size_t)x * 4, 4);
	bool has_alpha = cairo_image_surface_get_format(im->surface) == CAIRO_FORMAT_ARGB32;
	double a = has_alpha ? (word >> 24 & 0xff) / 255.0 : 1.0;
	if (a == 0.0)
		return (plume_color){0, 0, 0, 0};
	return (plume_color){(word >> 16 & 0xff) / 255.0 / a, (word >> 8 & 0xff) / 255.0 / a, (word & 0xff) / 255.0 / a, a};
}

static bool color_near(plume_color a, plume_color b, double tolerance)
{
	return fabs(a.r - b.r) <= tolerance && fabs(a.g - b.g) <= tolerance && fabs(a.b - b.b) <= tolerance &&
	       fabs(a.a - b.a) <= tolerance;
}

#define assert_color_near(actual, expected, tolerance)                                                                 \
	do {                                                                                                               \
		plume_color assert_a = (actual), assert_e = (expected);                                                        \
		if (!color_near(assert_a, assert_e, (tolerance)))                                                              \
			fail_msg("colour (%.3f %.3f %.3f %.3f), expected (%.3f %.3f %.3f %.3f) within %g", assert_a.r, assert_a.g, \
			         assert_a.b, assert_a.a, assert_e.r, assert_e.g, assert_e.b, assert_e.a, (double)(tolerance));     \
	} while (0)

/// The fit the renderer promises: the feather's xy bounds scaled uniformly into
/// the image less the margin, centred, y up.
typedef struct expected_view {
	double scale, offset_x, offset_y, margin_px;
} expected_view;

static expected_view expect_view(const plume_feather *feather, const plume_render2d_def *def)
{
	plume_feather_info info = plume_feather_get_info(feather);
	double margin_px = def->margin * fmin(def->width, def->height);
	double sx = (def->width - 2 * margin_px) / (info.bounds_max.x - info.bounds_min.x);
	double sy = (def->height - 2 * margin_px) / (info.bounds_max.y - info.bounds_min.y);
	double scale = fmin(sx, sy);
	return (expected_view){
	    .scale = scale,
	    .offset_x = def->width / 2.0 - scale * (info.bounds_min.x + info.bounds_max.x) / 2.0,
	    .offset_y = def->height / 2.0 + scale * (info.bounds_min.y + info.bounds_max.y) / 2.0,
	    .margin_px = margin_px,
	};
}

/// Pixel covering the feather point (x, y).
static plume_color pixel_at(const image *im, const expected_view *v, double x, double y)
{
	return pixel(im, (int)floor(v->offset_x + v->scale * x), (int)floor(v->offset_y - v->scale * y));
}

static plume_status render(const plume_feather *f, const plume_render2d_def *def, plume_image_format format,
                           const char *path)
{
	plume_error err;
	memset(&err, 0, sizeof err);
	plume_status status = plume_render2d(f, def, format, path, &err);
	if (status != PLUME_OK)
		print_message("plume_render2d: %s\n", err.message);
	return status;
}

// ---------------------------------------------------------------------------
// Line style

static void test_default_def(void **state)
{
	(void)state;
	plume_render2d_def def = plume_render2d_default_def();
	assert_int_equal(def.width, 1024);
	assert_int_equal(def.height, 1024);
	assert_close(def.margin, 0.05, 0.0);
	assert_color_near(def.background, ((plume_color){1, 1, 1, 1}), 0.0);
	assert_color_near(def.barb_color, ((plume_color){0.18, 0.15, 0.13, 1}), 0.0);
	assert_color_near(def.shaft_color, ((plume_color){0.10, 0.08, 0.07, 1}), 0.0);
	assert_close(def.min_stroke_px, 0.35, 0.0);
	assert_true(def.draw_barbules);
	assert_null(def.texture);
}

static void test_png_size_background_and_ink(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_default_fixture();
	plume_render2d_def def = plume_render2d_default_def();
	def.width = 300;
	def.height = 400;
	def.background = (plume_color){0.2, 0.4, 0.6, 1.0};
	def.barb_color = (plume_color){1.0, 0.0, 0.0, 1.0};
	def.shaft_color = (plume_color){0.0, 1.0, 0.0, 1.0};
	char path[512];
	path_in(s, "line.png", path, sizeof path);
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, path), PLUME_OK);

	image im = read_png(path);
	assert_int_equal(im.width, 300);
	assert_int_equal(im.height, 400);
	const double tol = 1.5 / 255.0;
	assert_color_near(pixel(&im, 0, 0), def.background, tol);
	assert_color_near(pixel(&im, 299, 0), def.background, tol);
	assert_color_near(pixel(&im, 0, 399), def.background, tol);
	assert_color_near(pixel(&im, 299, 399), def.background, tol);

	expected_view v = expect_view(f, &def);
	// The shaft along x = 0: its colour over its whole length (tip at the top).
	for (double y = 0.05; y <= 0.95; y += 0.1)
		assert_color_near(pixel_at(&im, &v, 0.0, y), def.shaft_color, tol);
	// The barbs: the left one on the image's left, both rising to the outside.
	assert_color_near(pixel_at(&im, &v, -0.3, 0.65), def.barb_color, tol);
	assert_color_near(pixel_at(&im, &v, 0.3, 0.65), def.barb_color, tol);
	// Their mirror images across y = 0.6 are empty: y points up.
	assert_color_near(pixel_at(&im, &v, -0.3, 0.55), def.background, tol);
	assert_color_near(pixel_at(&im, &v, 0.3, 0.55), def.background, tol);
	// The shaft's tip is at the top of the image, the wide base at the bottom.
	int tip_row = (int)floor(v.offset_y - v.scale * 0.99), base_row = (int)floor(v.offset_y - v.scale * 0.01);
	assert_true(tip_row < base_row);
	int tip_ink = 0, base_ink = 0;
	for (int x = 0; x < im.width; ++x) {
		tip_ink += color_near(pixel(&im, x, tip_row), def.shaft_color, 0.1);
		base_ink += color_near(pixel(&im, x, base_row), def.shaft_color, 0.1);
	}
	assert_close(tip_ink, 0.04 * v.scale, 2.0);
	assert_close(base_ink, 0.1 * v.scale, 2.0);
	image_free(&im);
	plume_feather_destroy(f);
}

static void test_feather_fills_the_image_inside_the_margin(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_small_fw_feather();
	plume_render2d_def def = plume_render2d_default_def();
	def.width = 256;
	def.height = 320;
	def.margin = 0.1;
	char path[512];
	path_in(s, "fit.png", path, sizeof path);
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, path), PLUME_OK);
	image im = read_png(path);
	expected_view v = expect_view(f, &def);
	assert_close(v.margin_px, 25.6, 1e-12);
	// Nothing in the margin band (one pixel of antialiasing allowed inside it).
	int band = (int)floor(v.margin_px) - 1;
	int ink_rows_min = im.height, ink_rows_max = -1, ink_cols_min = im.width, ink_cols_max = -1;
	for (int y = 0; y < im.height; ++y)
		for (int x = 0; x < im.width; ++x) {
			bool ink = !color_near(pixel(&im, x, y), def.background, 1.5 / 255.0);
			if (!ink)
				continue;
			if (x < band || x >= im.width - band || y < band || y >= im.height - band)
				fail_msg("ink at (%d, %d), inside the %.1f px margin", x, y, v.margin_px);
			ink_rows_min = y < ink_rows_min ? y : ink_rows_min;
			ink_rows_max = y > ink_rows_max ? y : ink_rows_max;
			ink_cols_min = x < ink_cols_min ? x : ink_cols_min;
			ink_cols_max = x > ink_cols_max ? x : ink_cols_max;
		}
	// A tall feather: its height spans the image less the margins, and it is centred across.
	// (The bounds reach half the shaft's width below its base, where the
	// ribbon ends flat: 1.5 mm, about 2 px here.)
	assert_close(ink_rows_min, v.margin_px, 2.0);
	assert_close(ink_rows_max, im.height - v.margin_px, 3.5);
	assert_close(0.5 * (ink_cols_min + ink_cols_max), 0.5 * im.width, 3.0);
	image_free(&im);
	plume_feather_destroy(f);
}

static void test_min_stroke_keeps_hairlines_visible(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_fixture((fixture_options){.barb_width = 1e-9});
	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 200;
	char path[512];
	path_in(s, "thin.png", path, sizeof path);
	expected_view v = expect_view(f, &def);
	// Midpoint of the left barb, at a pixel centre: (-0.2, 0.6).
	def.min_stroke_px = 0.0;
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, path), PLUME_OK);
	image im = read_png(path);
	assert_color_near(pixel_at(&im, &v, -0.2, 0.6), def.background, 2.0 / 255.0);
	image_free(&im);

	def.min_stroke_px = 4.0;
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, path), PLUME_OK);
	im = read_png(path);
	assert_color_near(pixel_at(&im, &v, -0.2, 0.6), def.barb_color, 2.0 / 255.0);
	image_free(&im);
	plume_feather_destroy(f);
}

static void test_barbules_and_afterfeather(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_fixture((fixture_options){.barb_width = 0.03, .barbule = true, .afterfeather = true});
	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 256;
	char path[512];
	path_in(s, "parts.png", path, sizeof path);
	expected_view v = expect_view(f, &def);
	const double tol = 2.0 / 255.0;
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, path), PLUME_OK);
	image im = read_png(path);
	assert_color_near(pixel_at(&im, &v, -0.2, 0.45), def.barb_color, tol); // the barbule
	assert_color_near(pixel_at(&im, &v, 0.15, 0.2), def.shaft_color, tol); // the afterfeather's shaft
	image_free(&im);

	def.draw_barbules = false;
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, path), PLUME_OK);
	im = read_png(path);
	assert_color_near(pixel_at(&im, &v, -0.2, 0.45), def.background, tol);
	assert_color_near(pixel_at(&im, &v, 0.15, 0.2), def.shaft_color, tol);
	image_free(&im);
	plume_feather_destroy(f);
}

/// Length of the run of pixels near colour through (x, y), along a row (dx = 1) or a column (dy = 1).
static int run_length(const image *im, int x, int y, int dx, int dy, plume_color color)
{
	int length = 0;
	for (int k = -1; k <= 1; k += 2)
		for (int i = k > 0 ? 0 : 1;; ++i) {
			int px = x + k * i * dx, py = y + k * i * dy;
			if (px < 0 || py < 0 || px >= im->width || py >= im->height || !color_near(pixel(im, px, py), color, 0.25))
				break;
			length++;
		}
	return length;
}

static void test_ribbon_keeps_its_width_through_a_bend(void **state)
{
	render_state *s = *state;
	// A shaft and one barb bent at a right angle: 0.3 m to the left, then 0.3 m up.
	plume_feather *f = plume_feather_create_empty();
	add_straight_shaft(f, plume_v3(0, 0, 0), plume_v3(0, 1, 0), 0.02, 0.02);
	const plume_vec3 corner[] = {{0, 0.4, 0},    {-0.1, 0.4, 0}, {-0.2, 0.4, 0}, {-0.3, 0.4, 0},
	                             {-0.3, 0.5, 0}, {-0.3, 0.6, 0}, {-0.3, 0.7, 0}};
	const int count = (int)(sizeof corner / sizeof corner[0]);
	int first = plume_feather_add_points(f, count);
	for (int i = 0; i < count; ++i) {
		f->points[first + i] = corner[i];
		f->widths[first + i] = 0.04;
		f->uv[first + i].y = 0.4;
	}
	plume_feather_measure_curve(f, (plume_curve_range){first, count});
	plume_barb_record barb = {.curve = {first, count}, .side = PLUME_SIDE_LEFT, .rachis_t = 0.4};
	assert_true(plume_feather_add_barb(f, &barb) >= 0);

	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 400;
	char path[512];
	path_in(s, "bend.png", path, sizeof path);
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, path), PLUME_OK);
	image im = read_png(path);
	expected_view v = expect_view(f, &def);
	double width_px = 0.04 * v.scale;
	// Across each leg, away from the corner and just outside the other leg: the full width.
	const double along_horizontal[] = {-0.05, -0.15, -0.25, -0.275};
	for (int i = 0; i < 4; ++i) {
		int x = (int)floor(v.offset_x + v.scale * along_horizontal[i]), y = (int)floor(v.offset_y - v.scale * 0.4);
		assert_close(run_length(&im, x, y, 0, 1, def.barb_color), width_px, 1.5);
	}
	const double along_vertical[] = {0.425, 0.45, 0.55, 0.65};
	for (int i = 0; i < 4; ++i) {
		int x = (int)floor(v.offset_x - v.scale * 0.3), y = (int)floor(v.offset_y - v.scale * along_vertical[i]);
		assert_close(run_length(&im, x, y, 1, 0, def.barb_color), width_px, 1.5);
	}
	// The outer corner is square (a miter), not cut off.
	assert_color_near(pixel_at(&im, &v, -0.3 - 0.017, 0.4 - 0.017), def.barb_color, 2.0 / 255.0);
	image_free(&im);
	plume_feather_destroy(f);
}

static bool starts_with(const char *path, const char *magic)
{
	size_t size;
	unsigned char *data = test_read_file(path, &size);
	bool result = data != NULL && size >= strlen(magic) && memcmp(data, magic, strlen(magic)) == 0;
	free(data);
	return result;
}

static void test_formats_have_their_magic(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_small_fw_feather();
	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 128;
	char png[512], svg[512], pdf[512];
	path_in(s, "f.png", png, sizeof png);
	path_in(s, "f.svg", svg, sizeof svg);
	path_in(s, "f.pdf", pdf, sizeof pdf);
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, png), PLUME_OK);
	assert_int_equal(render(f, &def, PLUME_IMAGE_SVG, svg), PLUME_OK);
	assert_int_equal(render(f, &def, PLUME_IMAGE_PDF, pdf), PLUME_OK);
	assert_true(starts_with(png, "\x89PNG\r\n\x1a\n"));
	assert_true(starts_with(svg, "<?xml") || starts_with(svg, "<svg"));
	assert_true(starts_with(pdf, "%PDF-"));
	size_t size;
	char *text = (char *)test_read_file(svg, &size);
	assert_non_null(strstr(text, "<svg"));
	assert_non_null(strstr(text, "width=\"128"));
	assert_non_null(strstr(text, "</svg>"));
	free(text);
	// A PDF holds binary streams: search its bytes, not a C string.
	unsigned char *bytes = test_read_file(pdf, &size);
	bool has_eof = false;
	for (size_t i = 0; i + 5 <= size && !has_eof; ++i)
		has_eof = memcmp(bytes + i, "%%EOF", 5) == 0;
	assert_true(has_eof);
	free(bytes);
	// Only the three results: no temporary file left beside them.
	assert_int_equal(test_count_entries(s->dir), 3);
	plume_feather_destroy(f);
}

static void test_same_feather_same_bytes(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_small_fw_feather();
	uint8_t rgba[4 * 8 * 4];
	for (int i = 0; i < 4 * 8; ++i) {
		rgba[4 * i + 0] = (uint8_t)(37 * i);
		rgba[4 * i + 1] = (uint8_t)(255 - 11 * i);
		rgba[4 * i + 2] = (uint8_t)(90 + i);
		rgba[4 * i + 3] = 255;
	}
	plume_texture *texture = plume_texture_create(4, 8, rgba);
	assert_non_null(texture);
	const plume_image_format formats[3] = {PLUME_IMAGE_PNG, PLUME_IMAGE_SVG, PLUME_IMAGE_PDF};
	const char *const names[3] = {"png", "svg", "pdf"};
	for (int textured = 0; textured < 2; ++textured)
		for (int k = 0; k < 3; ++k) {
			plume_render2d_def def = plume_render2d_default_def();
			def.width = def.height = 160;
			def.texture = textured ? texture : NULL;
			char a[512], b[512], name[32];
			snprintf(name, sizeof name, "a%d.%s", textured, names[k]);
			path_in(s, name, a, sizeof a);
			snprintf(name, sizeof name, "b%d.%s", textured, names[k]);
			path_in(s, name, b, sizeof b);
			assert_int_equal(render(f, &def, formats[k], a), PLUME_OK);
			// Another feather object with the same content, rendered later in the same process.
			plume_feather *copy = plume_feather_clone(f);
			assert_non_null(copy);
			assert_int_equal(render(copy, &def, formats[k], b), PLUME_OK);
			plume_feather_destroy(copy);
			size_t size_a, size_b;
			unsigned char *bytes_a = test_read_file(a, &size_a), *bytes_b = test_read_file(b, &size_b);
			assert_non_null(bytes_a);
			assert_non_null(bytes_b);
			if (size_a != size_b || memcmp(bytes_a, bytes_b, size_a) != 0)
				fail_msg("%s (textured %d): two renders differ", names[k], textured);
			free(bytes_a);
			free(bytes_b);
		}
	plume_texture_destroy(texture);
	plume_feather_destroy(f);
}

// ---------------------------------------------------------------------------
// Textures

/// A 4 x 2 image, every pixel a different colour: red = 10 * row + column
/// (rows top first), green = 100 + column, blue = 200 + row, alpha = 255 - column.
static plume_texture *make_4x2(void)
{
	uint8_t rgba[2 * 4 * 4];
	for (int row = 0; row < 2; ++row)
		for (int column = 0; column < 4; ++column) {
			uint8_t *p = rgba + (row * 4 + column) * 4;
			p[0] = (uint8_t)(10 * row + column);
			p[1] = (uint8_t)(100 + column);
			p[2] = (uint8_t)(200 + row);
			p[3] = (uint8_t)(255 - column);
		}
	plume_texture *texture = plume_texture_create(4, 2, rgba);
	assert_non_null(texture);
	return texture;
}

/// The (row, column) that a sample came from, decoded from make_4x2's colours.
static void decode(plume_color c, int *row, int *column)
{
	*column = (int)lround(c.g * 255.0) - 100;
	*row = (int)lround(c.b * 255.0) - 200;
	assert_close(c.r * 255.0, 10 * *row + *column, 1e-9);
	assert_close(c.a * 255.0, 255 - *column, 1e-9);
}

static void test_texture_create_and_size(void **state)
{
	(void)state;
	plume_texture *texture = make_4x2();
	assert_int_equal(plume_texture_width(texture), 4);
	assert_int_equal(plume_texture_height(texture), 2);
	plume_texture_destroy(texture);
	plume_texture_destroy(NULL);
}

static void test_texture_paper_mapping(void **state)
{
	(void)state;
	plume_texture *texture = make_4x2();
	// m = 4, n = 2. i_n = floor(t n) counts rows from the bottom (row 1 when
	// stored top first); i_ml = floor((1 - s) m / 2); i_mr = floor(s m / 2 + m / 2).
	const struct {
		plume_side side;
		double s, t;
		int row, column;
	} cases[] = {
	    // t: 0 and just below 1/2 are the bottom row; 1/2 and 1 (clamped from n) the top.
	    {PLUME_SIDE_LEFT, 0.75, 0.0, 1, 0},
	    {PLUME_SIDE_LEFT, 0.75, 0.49, 1, 0},
	    {PLUME_SIDE_LEFT, 0.75, 0.5, 0, 0},
	    {PLUME_SIDE_LEFT, 0.75, 1.0, 0, 0},
	    {PLUME_SIDE_LEFT, 0.75, -3.0, 1, 0},
	    {PLUME_SIDE_LEFT, 0.75, 7.0, 0, 0},
	    // Left vane: s = 0 gives floor(m/2) = 2 (the middle column), s = 1 column 0.
	    {PLUME_SIDE_LEFT, 0.0, 0.0, 1, 2},
	    {PLUME_SIDE_LEFT, 0.01, 0.0, 1, 1},
	    {PLUME_SIDE_LEFT, 0.25, 0.0, 1, 1},
	    {PLUME_SIDE_LEFT, 0.5, 0.0, 1, 1},
	    {PLUME_SIDE_LEFT, 0.51, 0.0, 1, 0},
	    {PLUME_SIDE_LEFT, 1.0, 1.0, 0, 0},
	    {PLUME_SIDE_LEFT, 2.0, 1.0, 0, 0},  // clamped at column 0
	    {PLUME_SIDE_LEFT, -1.0, 1.0, 0, 3}, // (1 + 1) 2 = 4, clamped to 3
	    // Right vane: s = 0 gives 2, s = 1/2 gives 3, s = 1 gives m = 4, clamped to 3.
	    {PLUME_SIDE_RIGHT, 0.0, 0.0, 1, 2},
	    {PLUME_SIDE_RIGHT, 0.49, 0.0, 1, 2},
	    {PLUME_SIDE_RIGHT, 0.5, 0.0, 1, 3},
	    {PLUME_SIDE_RIGHT, 1.0, 1.0, 0, 3},
	    {PLUME_SIDE_RIGHT, 1e9, 1e9, 0, 3},
	    {PLUME_SIDE_RIGHT, -0.5, 0.25, 1, 1},
	    {PLUME_SIDE_RIGHT, -1e9, -1e9, 1, 0},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
		int row, column;
		decode(plume_texture_sample_vane(texture, cases[i].side, cases[i].s, cases[i].t), &row, &column);
		if (row != cases[i].row || column != cases[i].column)
			fail_msg("case %zu (side %d, s %g, t %g): pixel (%d, %d), expected (%d, %d)", i, (int)cases[i].side,
			         cases[i].s, cases[i].t, row, column, cases[i].row, cases[i].column);
	}
	plume_texture_destroy(texture);
}

static void test_texture_png_round_trip(void **state)
{
	render_state *s = *state;
	// Opaque and fully transparent pixels survive Cairo's premultiplication
	// exactly (a transparent pixel's colour is lost: it becomes 0).
	uint8_t rgba[3 * 2 * 4] = {
	    255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 12, 34, 56, 255, 200, 100, 50, 255, 9, 9, 9, 0,
	};
	plume_texture *texture = plume_texture_create(3, 2, rgba);
	char path[512];
	path_in(s, "t.png", path, sizeof path);
	plume_error err;
	assert_int_equal(plume_texture_write_png(texture, path, &err), PLUME_OK);
	plume_texture *loaded = NULL;
	assert_int_equal(plume_texture_load(path, &loaded, &err), PLUME_OK);
	assert_int_equal(plume_texture_width(loaded), 3);
	assert_int_equal(plume_texture_height(loaded), 2);
	// Column 2 of the bottom row is the right vane's edge; column 0 of the top row the left vane's edge.
	plume_color c = plume_texture_sample_vane(loaded, PLUME_SIDE_LEFT, 1.0, 1.0);
	assert_color_near(c, ((plume_color){1, 0, 0, 1}), 0.0);
	c = plume_texture_sample_vane(loaded, PLUME_SIDE_RIGHT, 0.0, 1.0); // floor(1.5) = column 1
	assert_color_near(c, ((plume_color){0, 1, 0, 1}), 0.0);
	c = plume_texture_sample_vane(loaded, PLUME_SIDE_LEFT, 1.0, 0.0);
	assert_color_near(c, ((plume_color){12 / 255.0, 34 / 255.0, 56 / 255.0, 1}), 0.0);
	c = plume_texture_sample_vane(loaded, PLUME_SIDE_RIGHT, 1.0, 0.0);
	assert_close(c.a, 0.0, 0.0);
	plume_texture_destroy(loaded);
	plume_texture_destroy(texture);
	assert_int_equal(test_count_entries(s->dir), 1);
}

static void test_texture_load_errors(void **state)
{
	render_state *s = *state;
	plume_texture *texture = (plume_texture *)&texture; // must be reset to NULL
	plume_error err;
	char path[512];
	path_in(s, "missing.png", path, sizeof path);
	assert_int_equal(plume_texture_load(path, &texture, &err), PLUME_ERROR_IO);
	assert_null(texture);
	assert_int_equal(err.status, PLUME_ERROR_IO);
	assert_non_null(strstr(err.message, path));
	assert_non_null(strstr(err.message, "cannot read"));

	path_in(s, "garbage.png", path, sizeof path);
	test_write_file(path, "this is not an image at all\n");
	assert_int_equal(plume_texture_load(path, &texture, &err), PLUME_ERROR_SYNTAX);
	assert_null(texture);
	assert_non_null(strstr(err.message, path));
	assert_non_null(strstr(err.message, "not an image stb can read ("));

	path_in(s, "empty.png", path, sizeof path);
	test_write_file(path, "");
	assert_int_equal(plume_texture_load(path, &texture, &err), PLUME_ERROR_SYNTAX);

	// A folder opens but cannot be read.
	assert_int_equal(plume_texture_load(s->dir, &texture, &err), PLUME_ERROR_IO);
	assert_null(texture);
}

static void test_texture_write_errors_leave_nothing(void **state)
{
	render_state *s = *state;
	plume_texture *texture = make_4x2();
	plume_error err;
	assert_int_equal(plume_texture_write_png(texture, "/nonexistent-plume-dir/t.png", &err), PLUME_ERROR_IO);
	assert_non_null(strstr(err.message, "/nonexistent-plume-dir/t.png"));
	// A folder that is a regular file.
	char file[512], path[600];
	path_in(s, "plain", file, sizeof file);
	test_write_file(file, "x");
	snprintf(path, sizeof path, "%s/t.png", file);
	assert_int_equal(plume_texture_write_png(texture, path, &err), PLUME_ERROR_IO);
	assert_int_equal(test_count_entries(s->dir), 1);
	plume_texture_destroy(texture);
}

static plume_texture *make_solid(uint8_t r, uint8_t g, uint8_t b, uint8_t a)
{
	uint8_t rgba[8 * 8 * 4];
	for (int i = 0; i < 8 * 8; ++i) {
		rgba[4 * i] = r;
		rgba[4 * i + 1] = g;
		rgba[4 * i + 2] = b;
		rgba[4 * i + 3] = a;
	}
	plume_texture *texture = plume_texture_create(8, 8, rgba);
	assert_non_null(texture);
	return texture;
}

static void test_textured_render_takes_texture_colours(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_fixture((fixture_options){.barb_width = 0.03, .barbule = true});
	plume_texture *red = make_solid(255, 0, 0, 255);
	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 256;
	def.texture = red;
	char path[512];
	path_in(s, "red.png", path, sizeof path);
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, path), PLUME_OK);
	image im = read_png(path);
	expected_view v = expect_view(f, &def);
	const double tol = 2.0 / 255.0;
	assert_color_near(pixel_at(&im, &v, -0.3, 0.65), ((plume_color){1, 0, 0, 1}), tol);
	assert_color_near(pixel_at(&im, &v, 0.3, 0.65), ((plume_color){1, 0, 0, 1}), tol);
	assert_color_near(pixel_at(&im, &v, -0.2, 0.45), ((plume_color){1, 0, 0, 1}), tol); // barbule too
	assert_color_near(pixel_at(&im, &v, 0.0, 0.3), def.shaft_color, tol);
	assert_color_near(pixel(&im, 0, 0), def.background, tol);
	image_free(&im);
	plume_texture_destroy(red);

	// Two colours, one per vane half of the image: each vane takes its half.
	uint8_t rgba[2 * 1 * 4] = {0, 0, 255, 255, 0, 255, 0, 255};
	plume_texture *halves = plume_texture_create(2, 1, rgba);
	def.texture = halves;
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, path), PLUME_OK);
	im = read_png(path);
	assert_color_near(pixel_at(&im, &v, -0.3, 0.65), ((plume_color){0, 0, 1, 1}), tol);
	assert_color_near(pixel_at(&im, &v, 0.3, 0.65), ((plume_color){0, 1, 0, 1}), tol);
	image_free(&im);
	plume_texture_destroy(halves);
	plume_feather_destroy(f);
}

static void test_transparent_texture_leaves_only_the_shaft(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_fixture((fixture_options){.barb_width = 0.03, .barbule = true});
	plume_texture *clear = make_solid(255, 0, 0, 0);
	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 200;
	def.texture = clear;
	char textured[512], bare[512];
	path_in(s, "clear.png", textured, sizeof textured);
	path_in(s, "bare.png", bare, sizeof bare);
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, textured), PLUME_OK);
	// The same without a texture and with invisible barbs: the same pixels.
	def.texture = NULL;
	def.barb_color.a = 0.0;
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, bare), PLUME_OK);
	assert_int_equal(test_hash_file(textured), test_hash_file(bare));
	image im = read_png(textured);
	expected_view v = expect_view(f, &def);
	assert_color_near(pixel_at(&im, &v, -0.3, 0.65), def.background, 1.5 / 255.0);
	assert_color_near(pixel_at(&im, &v, 0.0, 0.65), def.shaft_color, 1.5 / 255.0);
	image_free(&im);
	plume_texture_destroy(clear);
	plume_feather_destroy(f);
}

static void test_committed_bands_texture(void **state)
{
	render_state *s = *state;
	const char *committed = PLUME_SOURCE_DIR "/examples/textures/bands.png";
	plume_texture *bands = NULL;
	plume_error err;
	assert_int_equal(plume_texture_load(committed, &bands, &err), PLUME_OK);
	assert_int_equal(plume_texture_width(bands), 512);
	assert_int_equal(plume_texture_height(bands), 1024);
	// Opaque everywhere along the vane, banded, the two vanes mirror images.
	// s = 127.5 / 256 is the centre of column 128 on the left vane and of
	// column 383 on the right, the same distance from the rachis.
	const double mid = 127.5 / 256.0;
	double darkest = 1.0, lightest = 0.0;
	for (int i = 0; i <= 100; ++i) {
		double t = i / 100.0;
		plume_color left = plume_texture_sample_vane(bands, PLUME_SIDE_LEFT, mid, t);
		plume_color right = plume_texture_sample_vane(bands, PLUME_SIDE_RIGHT, mid, t);
		assert_close(left.a, 1.0, 0.0);
		assert_color_near(left, right, 0.0);
		darkest = fmin(darkest, left.g);
		lightest = fmax(lightest, left.g);
	}
	assert_true(lightest - darkest > 0.3);
	plume_texture_destroy(bands);

	// The committed file holds exactly the library's pattern, which is what
	// plume-make-texture writes (pixels, not bytes: those depend on zlib).
	plume_texture *made = plume_texture_create_banded(512, 1024);
	assert_non_null(made);
	char path[512];
	path_in(s, "bands.png", path, sizeof path);
	assert_int_equal(plume_texture_write_png(made, path, &err), PLUME_OK);
	plume_texture_destroy(made);
	image a = read_png(committed), b = read_png(path);
	assert_int_equal(cairo_image_surface_get_format(a.surface), cairo_image_surface_get_format(b.surface));
	assert_int_equal(a.width, b.width);
	assert_int_equal(a.height, b.height);
	for (int y = 0; y < a.height; ++y)
		for (int x = 0; x < a.width; ++x) {
			plume_color pa = pixel(&a, x, y), pb = pixel(&b, x, y);
			if (!color_near(pa, pb, 0.0))
				fail_msg("examples/textures/bands.png differs from plume_texture_create_banded at (%d, %d); "
				         "remake it with plume-make-texture",
				         x, y);
		}
	image_free(&a);
	image_free(&b);
}

// ---------------------------------------------------------------------------
// Errors

static void test_bad_defs_are_spec_errors_and_write_nothing(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_default_fixture();
	char path[512];
	path_in(s, "bad.png", path, sizeof path);
	// An older result at the destination must survive a failed render.
	test_write_file(path, "old");
	const char *const fields[] = {"width",         "width",         "height",       "margin",
	                              "margin",        "margin",        "background.r", "barb_color.a",
	                              "shaft_color.g", "min_stroke_px", "min_stroke_px"};
	for (int k = 0; k < (int)(sizeof fields / sizeof fields[0]); ++k) {
		plume_render2d_def def = plume_render2d_default_def();
		switch (k) {
		case 0: def.width = 15; break;
		case 1: def.width = 16385; break;
		case 2: def.height = 0; break;
		case 3: def.margin = -0.01; break;
		case 4: def.margin = 0.45; break;
		case 5: def.margin = NAN; break;
		case 6: def.background.r = 1.5; break;
		case 7: def.barb_color.a = -0.1; break;
		case 8: def.shaft_color.g = NAN; break;
		case 9: def.min_stroke_px = -1.0; break;
		case 10: def.min_stroke_px = INFINITY; break;
		}
		for (int format = 0; format < 3; ++format) {
			plume_error err;
			memset(&err, 0, sizeof err);
			assert_int_equal(plume_render2d(f, &def, (plume_image_format)format, path, &err), PLUME_ERROR_SPEC);
			if (strstr(err.message, fields[k]) == NULL)
				fail_msg("case %d: message \"%s\" does not name %s", k, err.message, fields[k]);
		}
	}
	// The edges of the ranges are allowed.
	plume_render2d_def def = plume_render2d_default_def();
	def.width = 16;
	def.height = 17;
	def.margin = 0.0;
	def.min_stroke_px = 0.0;
	def.background = (plume_color){0, 0, 0, 0};
	def.barb_color = (plume_color){1, 1, 1, 1};
	char ok[512];
	path_in(s, "edge.png", ok, sizeof ok);
	assert_int_equal(render(f, &def, PLUME_IMAGE_PNG, ok), PLUME_OK);

	size_t size;
	char *text = (char *)test_read_file(path, &size);
	assert_string_equal(text, "old");
	free(text);
	assert_int_equal(test_count_entries(s->dir), 2);
	plume_feather_destroy(f);
}

static void test_empty_feather_is_an_error(void **state)
{
	render_state *s = *state;
	plume_feather *f = plume_feather_create_empty();
	plume_render2d_def def = plume_render2d_default_def();
	char path[512];
	path_in(s, "empty.png", path, sizeof path);
	plume_error err;
	assert_int_equal(plume_render2d(f, &def, PLUME_IMAGE_PNG, path, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "empty"));
	assert_int_equal(test_count_entries(s->dir), 0);
	plume_feather_destroy(f);
}

static void test_unwritable_path_is_an_io_error(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_default_fixture();
	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 64;
	char file[512], path[600];
	path_in(s, "plain", file, sizeof file);
	test_write_file(file, "x");
	snprintf(path, sizeof path, "%s/x.png", file);
	const char *const names[3] = {"/nonexistent-plume-dir/x.png", "/nonexistent-plume-dir/x.svg", path};
	for (int format = 0; format < 3; ++format)
		for (int k = 0; k < 3; ++k) {
			plume_error err;
			memset(&err, 0, sizeof err);
			assert_int_equal(plume_render2d(f, &def, (plume_image_format)format, names[k], &err), PLUME_ERROR_IO);
			assert_int_equal(err.status, PLUME_ERROR_IO);
			assert_non_null(strstr(err.message, names[k]));
		}
	assert_false(test_file_exists("/nonexistent-plume-dir"));
	assert_int_equal(test_count_entries(s->dir), 1);
	plume_feather_destroy(f);
}

static void test_render_replaces_an_existing_file(void **state)
{
	render_state *s = *state;
	plume_feather *f = make_default_fixture();
	plume_render2d_def def = plume_render2d_default_def();
	def.width = def.height = 64;
	char path[512];
	path_in(s, "out.svg", path, sizeof path);
	test_write_file(path, "old");
	assert_int_equal(render(f, &def, PLUME_IMAGE_SVG, path), PLUME_OK);
	assert_true(starts_with(path, "<?xml") || starts_with(path, "<svg"));
	assert_int_equal(test_count_entries(s->dir), 1);
	plume_feather_destroy(f);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_default_def, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_png_size_background_and_ink, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_feather_fills_the_image_inside_the_margin, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_min_stroke_keeps_hairlines_visible, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_barbules_and_afterfeather, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_ribbon_keeps_its_width_through_a_bend, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_formats_have_their_magic, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_same_feather_same_bytes, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_texture_create_and_size, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_texture_paper_mapping, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_texture_png_round_trip, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_texture_load_errors, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_texture_write_errors_leave_nothing, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_textured_render_takes_texture_colours, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_transparent_texture_leaves_only_the_shaft, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_committed_bands_texture, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_bad_defs_are_spec_errors_and_write_nothing, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_empty_feather_is_an_error, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_unwritable_path_is_an_io_error, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_render_replaces_an_existing_file, setup, teardown),
	};
	return cmocka_run_group_tests_name("render", tests, NULL, NULL);
}

// Ray tracing: coverage against the Cairo renderer, a barb's projected width,
// cut-out textures, determinism across seeds and thread counts, fiber
// shading closed forms, camera framing and turntable, and bad inputs.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cairo.h>

#include "model/feather_internal.h"
#include "plume/raytrace.h"
#include "render/raytrace_internal.h"
#include "support.h"

#define PI 3.14159265358979323846

// ---------------------------------------------------------------------------
// Fixtures

/// A Franco–Walter feather with few, wide barbs, so that every barb spans pixels at test sizes.
static plume_feather *sparse_feather(void)
{
	plume_fw_def def = plume_fw_default_def();
	def.segments[0].barb_count = 6;
	def.segments[1].barb_count = 30;
	def.barb_width_base = 3.0e-3;
	def.barb_width_tip = 1.5e-3;
	plume_feather *feather = NULL;
	plume_error err = {0};
	assert_int_equal(plume_fw_generate(&def, 7, &feather, &err), PLUME_OK);
	return feather;
}

/// One straight barb from (0, 0, 0) to (1, 0, 0) of constant width, facing +z, and no shaft.
static plume_feather *single_barb(double width)
{
	plume_feather *f = plume_feather_create_empty();
	assert_non_null(f);
	const int count = 11;
	int first = plume_feather_add_points(f, count);
	assert_true(first >= 0);
	for (int i = 0; i < count; ++i) {
		f->points[first + i] = plume_v3((double)i / (count - 1), 0.0, 0.0);
		f->normals[first + i] = plume_v3(0, 0, 1);
		f->widths[first + i] = width;
		f->uv[first + i].y = 0.5;
	}
	plume_curve_range range = {first, count};
	plume_feather_measure_curve(f, range);
	plume_barb_record barb = {.curve = range, .side = PLUME_SIDE_RIGHT, .rachis_t = 0.5};
	assert_true(plume_feather_add_barb(f, &barb) >= 0);
	return f;
}

/// Settings for silhouette tests: transparent background, no ground.
static plume_raytrace_def mask_def(int size, int spp)
{
	plume_raytrace_def def = plume_raytrace_default_def();
	def.camera.width = def.camera.height = size;
	def.camera.orthographic = true;
	def.spp = spp;
	def.background = (plume_color){1, 1, 1, 0};
	def.ground = false;
	def.ao_samples = 0;
	def.barbules = PLUME_BARBULES_OFF;
	def.shadows = false;
	return def;
}

static uint8_t *render(const plume_feather *feather, const plume_raytrace_def *def)
{
	const plume_feather *list[1] = {feather};
	plume_raytrace_scene scene = {1, list, NULL, NULL};
	uint8_t *rgba = malloc(4 * (size_t)def->camera.width * (size_t)def->camera.height);
	assert_non_null(rgba);
	plume_error err = {0};
	plume_status status = plume_raytrace_render(&scene, def, rgba, NULL, &err);
	if (status != PLUME_OK)
		fail_msg("render failed: %s", err.message);
	return rgba;
}

// ---------------------------------------------------------------------------
// Coverage

/// The test: a frontal flat feather rendered orthographically covers the same pixels as the Cairo
/// line rendering of the same feather, within 2% of the mask area.
static void test_mask_matches_cairo(void **state)
{
	(void)state;
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/cairo.png", dir);
	plume_feather *feather = sparse_feather();
	const int size = 200;
	plume_render2d_def cairo_def = plume_render2d_default_def();
	cairo_def.width = cairo_def.height = size;
	cairo_def.background = (plume_color){1, 1, 1, 0};
	cairo_def.min_stroke_px = 0.0;
	cairo_def.draw_barbules = false;
	plume_error err = {0};
	assert_int_equal(plume_render2d(feather, &cairo_def, PLUME_IMAGE_PNG, path, &err), PLUME_OK);
	cairo_surface_t *surface = cairo_image_surface_create_from_png(path);
	assert_int_equal(cairo_surface_status(surface), CAIRO_STATUS_SUCCESS);
	assert_int_equal(cairo_image_surface_get_width(surface), size);
	const unsigned char *data = cairo_image_surface_get_data(surface);
	int stride = cairo_image_surface_get_stride(surface);

	plume_raytrace_def def = mask_def(size, 64); // same margin (0.05) and fit as the Cairo view
	uint8_t *rgba = render(feather, &def);
	int cairo_area = 0, traced_area = 0, differ = 0;
	for (int y = 0; y < size; ++y)
		for (int x = 0; x < size; ++x) {
			uint32_t word = *(const uint32_t *)(const void *)(data + (size_t)y * stride + 4 * (size_t)x);
			bool a = (word >> 24) >= 128, b = rgba[4 * ((size_t)y * size + x) + 3] >= 128;
			cairo_area += a;
			traced_area += b;
			differ += a != b;
		}
	if (getenv("RT_DEBUG_DIR") != NULL) {
		uint8_t *diff = calloc(4 * (size_t)size * size * 16, 1);
		for (int y = 0; y < 4 * size; ++y)
			for (int x = 0; x < 4 * size; ++x) {
				uint32_t word =
				    *(const uint32_t *)(const void *)(data + (size_t)(y / 4) * stride + 4 * (size_t)(x / 4));
				bool a = (word >> 24) >= 128, b = rgba[4 * ((size_t)(y / 4) * size + x / 4) + 3] >= 128;
				uint8_t *p = diff + 4 * ((size_t)y * size * 4 + x);
				p[0] = a && !b ? 255 : 0;
				p[2] = b && !a ? 255 : 0;
				p[1] = a && b ? 128 : 0;
				p[3] = 255;
			}
		char out[512];
		snprintf(out, sizeof out, "%s/diff.png", getenv("RT_DEBUG_DIR"));
		plume_write_rgba_png(4 * size, 4 * size, diff, out, &err);
		free(diff);
	}
	print_message("mask: cairo %d px, traced %d px, differing %d px (%.2f%%)\n", cairo_area, traced_area, differ,
	              100.0 * differ / cairo_area);
	assert_true(cairo_area > 2000);
	assert_true(fabs((double)traced_area - cairo_area) <= 0.02 * cairo_area);
	assert_true(differ <= 0.02 * cairo_area);
	free(rgba);
	cairo_surface_destroy(surface);
	plume_feather_destroy(feather);
	test_remove_tree(dir);
}

/// A single barb's projected width matches its width within half a pixel: summing the coverage (alpha)
/// down a column crossing the barb measures the width in pixels.
static void test_single_barb_width(void **state)
{
	(void)state;
	const double widths_px[3] = {1.3, 4.0, 7.6};
	for (int k = 0; k < 3; ++k) {
		const int size = 64;
		const double pixel = 1.2 / size; // ortho_height 1.2 m over 64 px
		plume_feather *feather = single_barb(widths_px[k] * pixel);
		plume_raytrace_def def = mask_def(size, 64);
		def.camera.automatic = false;
		def.camera.target = plume_v3(0.5, 0.0, 0.0);
		def.camera.eye = plume_v3(0.5, 0.0, 1.0);
		def.camera.ortho_height = 1.2;
		uint8_t *rgba = render(feather, &def);
		for (int x = 16; x <= 48; x += 16) {
			double coverage = 0.0;
			for (int y = 0; y < size; ++y)
				coverage += rgba[4 * ((size_t)y * size + x) + 3] / 255.0;
			assert_close(coverage, widths_px[k], 0.5);
		}
		free(rgba);
		plume_feather_destroy(feather);
	}
}

/// A texture whose alpha is zero everywhere leaves nothing but the background.
static void test_transparent_texture_renders_background(void **state)
{
	(void)state;
	uint8_t pixels[8 * 8 * 4];
	for (int i = 0; i < 8 * 8; ++i) {
		pixels[4 * i + 0] = 200;
		pixels[4 * i + 1] = 100;
		pixels[4 * i + 2] = 50;
		pixels[4 * i + 3] = 0;
	}
	plume_texture *texture = plume_texture_create(8, 8, pixels);
	plume_feather *feather = sparse_feather();
	plume_raytrace_def def = mask_def(48, 4);
	def.background = (plume_color){0.2, 0.4, 0.6, 1.0};
	def.texture = texture;
	def.camera.orthographic = false;
	uint8_t *rgba = render(feather, &def);
	for (int i = 0; i < 48 * 48; ++i) {
		assert_int_equal(rgba[4 * i + 0], rt_linear_to_srgb_byte(rt_srgb_to_linear(0.2)));
		assert_int_equal(rgba[4 * i + 1], rt_linear_to_srgb_byte(rt_srgb_to_linear(0.4)));
		assert_int_equal(rgba[4 * i + 2], rt_linear_to_srgb_byte(rt_srgb_to_linear(0.6)));
		assert_int_equal(rgba[4 * i + 3], 255);
	}
	// The same texture opaque covers pixels: the test above is not vacuous.
	for (int i = 0; i < 8 * 8; ++i)
		pixels[4 * i + 3] = 255;
	plume_texture *opaque = plume_texture_create(8, 8, pixels);
	def.texture = opaque;
	uint8_t *covered = render(feather, &def);
	assert_true(memcmp(rgba, covered, 4 * 48 * 48) != 0);
	free(covered);
	free(rgba);
	plume_texture_destroy(opaque);
	plume_texture_destroy(texture);
	plume_feather_destroy(feather);
}

/// Barbs take their colour from the texture by the vane mapping (Franco & Walter 4.4): the image's left
/// half colours the left vane (-x, on the image's left from the front), its right half the right vane.
static void test_texture_colours_the_vanes(void **state)
{
	(void)state;
	uint8_t pixels[16 * 4 * 4];
	for (int y = 0; y < 4; ++y)
		for (int x = 0; x < 16; ++x) {
			uint8_t *p = pixels + 4 * (y * 16 + x);
			p[0] = x < 8 ? 220 : 20;
			p[1] = 20;
			p[2] = x < 8 ? 20 : 220;
			p[3] = 255;
		}
	plume_texture *texture = plume_texture_create(16, 4, pixels);
	plume_feather *feather = sparse_feather();
	const int size = 96;
	plume_raytrace_def def = mask_def(size, 4);
	def.texture = texture;
	def.specular = 0.0; // white highlights would wash out the hues this test reads
	uint8_t *rgba = render(feather, &def);
	// Shaft column: where the shaft's centre line crosses the image's middle row, roughly the image centre.
	int red_left = 0, blue_left = 0, red_right = 0, blue_right = 0;
	for (int y = size / 4; y < 3 * size / 4; ++y)
		for (int x = 0; x < size; ++x) {
			const uint8_t *p = rgba + 4 * ((size_t)y * size + x);
			if (p[3] < 128 || abs(x - size / 2) < 4)
				continue; // background, edges and the shaft
			bool red = p[0] > 2 * p[2], blue = p[2] > 2 * p[0];
			if (x < size / 2) {
				red_left += red;
				blue_left += blue;
			} else {
				red_right += red;
				blue_right += blue;
			}
		}
	print_message("texture: left vane %d red, %d blue; right vane %d red, %d blue\n", red_left, blue_left, red_right,
	              blue_right);
	assert_true(red_left > 100 && blue_left == 0);
	assert_true(blue_right > 100 && red_right == 0);
	free(rgba);
	plume_feather_destroy(feather);
	plume_texture_destroy(texture);
}

// ---------------------------------------------------------------------------
// Determinism

static void test_same_seed_same_bytes(void **state)
{
	(void)state;
	int64_t bytes_before = plume_bytes_in_use();
	plume_feather *feather = sparse_feather();
	plume_raytrace_def def = plume_raytrace_default_def();
	def.camera.width = 80;
	def.camera.height = 60;
	def.spp = 4;
	def.threads = 1;
	uint8_t *a = render(feather, &def);
	def.threads = 2;
	uint8_t *b = render(feather, &def);
	assert_memory_equal(a, b, 4 * 80 * 60);
	def.seed = 2;
	uint8_t *c = render(feather, &def);
	assert_true(memcmp(a, c, 4 * 80 * 60) != 0); // the seed drives the jitter, shadows and occlusion
	free(a);
	free(b);
	free(c);
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), bytes_before);
}

static void test_png_same_bytes(void **state)
{
	(void)state;
	char dir[256], a[512], b[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(a, sizeof a, "%s/a.png", dir);
	snprintf(b, sizeof b, "%s/b.png", dir);
	plume_feather *feather = sparse_feather();
	const plume_feather *list[1] = {feather};
	plume_raytrace_scene scene = {1, list, NULL, NULL};
	plume_raytrace_def def = plume_raytrace_default_def();
	def.camera.width = def.camera.height = 64;
	def.spp = 4;
	plume_error err = {0};
	plume_raytrace_stats stats;
	assert_int_equal(plume_raytrace_render_png(&scene, &def, a, &stats, &err), PLUME_OK);
	assert_int_equal(plume_raytrace_render_png(&scene, &def, b, NULL, &err), PLUME_OK);
	assert_true(test_hash_file(a) != 0);
	assert_true(test_hash_file(a) == test_hash_file(b));
	assert_true(stats.curve_segments > 0);
	plume_feather_destroy(feather);
	test_remove_tree(dir);
}

/// Barbules are drawn on request, never when off, and in auto mode only when a barb spans enough pixels.
static void test_barbule_modes(void **state)
{
	(void)state;
	plume_feather *feather = single_barb(4.0 * 1.2 / 64);
	// One barbule of 5 points across the barb's middle.
	int first = plume_feather_add_points(feather, 5);
	assert_true(first >= 0);
	for (int i = 0; i < 5; ++i) {
		feather->points[first + i] = plume_v3(0.5, -0.2 + 0.1 * i, 0.0);
		feather->normals[first + i] = plume_v3(0, 0, 1);
		feather->widths[first + i] = 0.03;
	}
	plume_curve_range range = {first, 5};
	plume_feather_measure_curve(feather, range);
	plume_barbule_record barbule = {.curve = range, .barb = 0, .barb_s = 0.5};
	assert_true(plume_feather_add_barbule(feather, &barbule) >= 0);
	feather->barbs[0].barbule_first = 0;
	feather->barbs[0].barbule_count = 1;

	const plume_feather *list[1] = {feather};
	plume_raytrace_scene scene = {1, list, NULL, NULL};
	plume_raytrace_def def = mask_def(64, 1);
	def.camera.automatic = false;
	def.camera.target = plume_v3(0.5, 0.0, 0.0);
	def.camera.eye = plume_v3(0.5, 0.0, 1.0);
	def.camera.ortho_height = 1.2; // the barb is 4 px wide
	uint8_t rgba[4 * 64 * 64];
	plume_raytrace_stats stats;
	plume_error err = {0};
	const struct {
		plume_barbule_mode mode;
		double min_px;
		bool drawn;
	} cases[] = {
	    {PLUME_BARBULES_OFF, 4.0, false},
	    {PLUME_BARBULES_ON, 4.0, true},
	    {PLUME_BARBULES_AUTO, 3.9, true},
	    {PLUME_BARBULES_AUTO, 4.1, false},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
		def.barbules = cases[i].mode;
		def.barbule_min_px = cases[i].min_px;
		assert_int_equal(plume_raytrace_render(&scene, &def, rgba, &stats, &err), PLUME_OK);
		assert_int_equal(stats.barbules, cases[i].drawn);
		assert_int_equal(stats.curve_segments, 10 + (cases[i].drawn ? 4 : 0));
		// The barbule crosses rows the barb does not reach (y = +-0.2 m, about 10 px off the barb).
		int column_coverage = 0;
		for (int y = 0; y < 64; ++y)
			column_coverage += rgba[4 * (y * 64 + 32) + 3] > 0;
		assert_true(cases[i].drawn ? column_coverage > 10 : column_coverage <= 6);
	}
	plume_feather_destroy(feather);
}

// ---------------------------------------------------------------------------
// Camera

/// A half turn of the turntable about the up axis shows the flat feather from behind: the mirror image.
static void test_turntable_half_turn_mirrors(void **state)
{
	(void)state;
	plume_feather *feather = sparse_feather();
	const int size = 160;
	plume_raytrace_def def = mask_def(size, 64);
	uint8_t *front = render(feather, &def);
	def.camera.turntable = PI;
	uint8_t *back = render(feather, &def);
	int area = 0, differ = 0;
	for (int y = 0; y < size; ++y)
		for (int x = 0; x < size; ++x) {
			bool f = front[4 * ((size_t)y * size + x) + 3] >= 128;
			bool b = back[4 * ((size_t)y * size + (size - 1 - x)) + 3] >= 128;
			area += f;
			differ += f != b;
		}
	print_message("turntable: area %d px, differing %d px\n", area, differ);
	// Embree intersects ribbons through a view-dependent tessellation, so silhouettes seen from the two
	// sides differ by a fraction of a pixel along thin barbs: a few boundary pixels flip.
	assert_true(area > 1000);
	assert_true(differ <= 0.03 * area);
	free(front);
	free(back);
	plume_feather_destroy(feather);
}

/// Automatic framing leaves the eye outside the bounds and every bound corner inside the image.
static void test_automatic_framing_fits(void **state)
{
	(void)state;
	plume_camera camera = plume_camera_default();
	camera.width = 300;
	camera.height = 200;
	camera.view_direction = plume_v3(0.3, 0.5, 1.0);
	plume_vec3 lo = {-0.03, 0.0, -0.01}, hi = {0.04, 0.2, 0.02};
	plume_camera framed = plume_camera_frame_bounds(&camera, lo, hi);
	assert_false(framed.automatic);
	rt_camera view = rt_camera_make(&framed);
	for (int i = 0; i < 8; ++i) {
		plume_vec3 corner = {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
		plume_vec3 d = plume_v3_sub(corner, view.eye);
		double depth = plume_v3_dot(d, view.forward);
		assert_true(depth > 0.0);
		double x = plume_v3_dot(d, view.right) / depth / view.half_width; // -1 .. 1 across the image
		double y = plume_v3_dot(d, view.up) / depth / view.half_height;
		assert_true(fabs(x) <= 1.0 - 2.0 * 0.05 * 200 / 300 + 1e-9);
		assert_true(fabs(y) <= 1.0 - 2.0 * 0.05 + 1e-9);
	}
}

// ---------------------------------------------------------------------------
// Shading closed forms

static void test_kajiya_kay_closed_form(void **state)
{
	(void)state;
	plume_raytrace_def def = plume_raytrace_default_def();
	def.shading = PLUME_SHADING_KAJIYA_KAY;
	rt_fiber fiber = rt_fiber_from_def(&def);
	plume_vec3 t = {1, 0, 0}, n = {0, 0, 1}, white = {1, 1, 1};
	// Light and eye both along the normal: sin(T,L) = sin(T,V) = 1, cos = 0, so the highlight cone term is 1.
	plume_vec3 c = rt_fiber_shade(&fiber, t, n, n, n, white);
	assert_close(c.x, def.diffuse * 1.0 + def.specular, 1e-12);
	// Light at 60 degrees from the fiber, eye on the mirror cone (T.V = -T.L): the highlight is at its peak.
	plume_vec3 l = {cos(PI / 3), 0, sin(PI / 3)}, v = {-cos(PI / 3), 0, sin(PI / 3)};
	c = rt_fiber_shade(&fiber, t, n, v, l, white);
	double diffuse = def.diffuse * fmin(sin(PI / 3), 0.25 + 0.75 * sin(PI / 3));
	assert_close(c.x, diffuse + def.specular, 1e-12);
	// The light behind the ribbon: only the tinted transmitted fraction, by the cosine.
	plume_vec3 albedo = {0.5, 0.25, 0.1};
	plume_vec3 behind = {0, 0.6, -0.8};
	c = rt_fiber_shade(&fiber, t, n, n, behind, albedo);
	assert_close(c.x, 0.5 * def.transmission * 0.8, 1e-12);
	assert_close(c.z, 0.1 * def.transmission * 0.8, 1e-12);
}

/// The Marschner R lobe peaks where theta_h equals the shift alpha (Marschner et al. 2003, section 4.2).
static void test_marschner_lobe_peak(void **state)
{
	(void)state;
	plume_raytrace_def def = plume_raytrace_default_def();
	def.trt_weight = 0.0;
	def.diffuse = 0.0;
	rt_fiber fiber = rt_fiber_from_def(&def);
	plume_vec3 t = {0, 1, 0}, n = {0, 0, 1}, black = {0, 0, 0};
	double theta_i = 0.3, best = -1.0, best_theta_r = 0.0;
	plume_vec3 l = {0, sin(theta_i), cos(theta_i)};
	for (int k = -2000; k <= 2000; ++k) {
		double theta_r = k * 1e-4 * 8.0; // [-0.8, 0.8]
		plume_vec3 v = {0, sin(theta_r), cos(theta_r)};
		double value = rt_fiber_shade(&fiber, t, n, v, l, black).x;
		// Compare the lobe itself: divide out 1/cos^2(theta_d), which shifts the maximum.
		double cos_d = cos(0.5 * (theta_i - theta_r));
		value *= cos_d * cos_d;
		if (value > best) {
			best = value;
			best_theta_r = theta_r;
		}
	}
	assert_close(0.5 * (theta_i + best_theta_r), def.lobe_shift, 2e-3);
}

static void test_srgb_round_trip(void **state)
{
	(void)state;
	for (int i = 0; i < 256; ++i)
		assert_int_equal(rt_linear_to_srgb_byte(rt_srgb_to_linear(i / 255.0)), i);
}

// ---------------------------------------------------------------------------
// Bad inputs

static void test_camera_inside_is_an_error(void **state)
{
	(void)state;
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/inside.png", dir);
	plume_feather *feather = sparse_feather();
	const plume_feather *list[1] = {feather};
	plume_raytrace_scene scene = {1, list, NULL, NULL};
	plume_raytrace_def def = plume_raytrace_default_def();
	def.camera.width = def.camera.height = 32;
	def.camera.automatic = false;
	plume_feather_info info = plume_feather_get_info(feather);
	def.camera.eye = plume_v3_scale(plume_v3_add(info.bounds_min, info.bounds_max), 0.5);
	def.camera.target = plume_v3_add(def.camera.eye, plume_v3(0, 0, -1));
	plume_error err = {0};
	assert_int_equal(plume_raytrace_render_png(&scene, &def, path, NULL, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "inside the scene's bounds"));
	assert_non_null(strstr(err.message, "inside.png"));
	assert_false(test_file_exists(path));

	// Looking away from the feather.
	def.camera.eye = plume_v3(0.0, 0.1, 0.5);
	def.camera.target = plume_v3(0.0, 0.1, 1.0);
	assert_int_equal(plume_raytrace_render_png(&scene, &def, path, NULL, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "sees none of the scene"));
	assert_false(test_file_exists(path));

	// A bad setting names itself.
	def = plume_raytrace_default_def();
	def.spp = 0;
	assert_int_equal(plume_raytrace_render_png(&scene, &def, path, NULL, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "spp is 0"));
	assert_int_equal(test_count_entries(dir), 0);
	plume_feather_destroy(feather);
	test_remove_tree(dir);
}

static void test_camera_json(void **state)
{
	(void)state;
	char dir[256], path[512];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/camera.json", dir);
	test_write_file(path, "{\"camera\": {\"eye\": [0, 0.1, 0.5], \"target\": [0, 0.1, 0], \"fov_deg\": 40,"
	                      " \"size\": [320, 240], \"turntable_deg\": 90},"
	                      " \"lights\": [{\"direction\": [0, 1, 1], \"intensity\": 2, \"angle_deg\": 2}],"
	                      " \"spp\": 9, \"shading\": \"kajiya-kay\", \"ground\": false}");
	plume_raytrace_def def = plume_raytrace_default_def();
	plume_error err = {0};
	assert_int_equal(plume_raytrace_def_read(path, &def, &err), PLUME_OK);
	assert_false(def.camera.automatic);
	assert_close(def.camera.eye.z, 0.5, 0.0);
	assert_close(def.camera.fov, 40.0 * PI / 180.0, 1e-15);
	assert_int_equal(def.camera.width, 320);
	assert_int_equal(def.camera.height, 240);
	assert_close(def.camera.turntable, PI / 2, 1e-15);
	assert_int_equal(def.light_count, 1);
	assert_close(def.lights[0].intensity, 2.0, 0.0);
	assert_int_equal(def.spp, 9);
	assert_int_equal(def.shading, PLUME_SHADING_KAJIYA_KAY);
	assert_false(def.ground);

	struct {
		const char *text;
		const char *message;
	} bad[] = {
	    {"{\"camera\": {\"fov\": 40}}", "$.camera.fov: unknown key"},
	    {"{\"camera\": {\"fov_deg\": 190}}", "$.camera.fov_deg"},
	    {"{\"camera\": {\"size\": [10, 10]}}", "$.camera.size"},
	    // Too large for an int: refused without converting it (UBSan found the cast).
	    {"{\"camera\": {\"size\": [8e11, 16]}}", "$.camera.size: is [8e+11, 16], allowed whole pixels"},
	    {"{\"lights\": [{\"direction\": [0, 0]}]}", "$.lights[0].direction"},
	    {"{\"shading\": \"phong\"}", "$.shading"},
	    {"{\"spp\": 0}", "$.spp"},
	    {"{\"background\": [1, 2, 0]}", "$.background"},
	    {"{\"camera\": {\"eye\": [0, 0, 1], \"target\": [0, 0, 1]}}", "$.camera.target"},
	    // What the ray tracer needs of a camera, refused by the reader (naming the file and the key).
	    {"{\"camera\": {\"margin\": 0.45}}", "$.camera.margin: is 0.45, allowed [0, 0.45)"},
	    {"{\"camera\": {\"eye\": [0, 0, 1], \"target\": [0, 0, 0], \"up\": [0, 0, 2]}}",
	     "$.camera.up: (0, 0, 2) is parallel to the view direction"},
	    {"{\"camera\": {\"eye\": [0, 0, 1], \"target\": [0, 0, 0], \"orthographic\": true}}",
	     "$.camera.ortho_height: missing"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
		test_write_file(path, bad[i].text);
		def = plume_raytrace_default_def();
		assert_int_equal(plume_raytrace_def_read(path, &def, &err), PLUME_ERROR_SPEC);
		if (strstr(err.message, bad[i].message) == NULL || strstr(err.message, "camera.json") == NULL)
			fail_msg("'%s' gave '%s', expected '%s'", bad[i].text, err.message, bad[i].message);
	}
	test_write_file(path, "{\"spp\": 4,}");
	assert_int_equal(plume_raytrace_def_read(path, &def, &err), PLUME_ERROR_SYNTAX);
	test_remove_tree(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_mask_matches_cairo),
	    cmocka_unit_test(test_single_barb_width),
	    cmocka_unit_test(test_transparent_texture_renders_background),
	    cmocka_unit_test(test_texture_colours_the_vanes),
	    cmocka_unit_test(test_barbule_modes),
	    cmocka_unit_test(test_same_seed_same_bytes),
	    cmocka_unit_test(test_png_same_bytes),
	    cmocka_unit_test(test_turntable_half_turn_mirrors),
	    cmocka_unit_test(test_automatic_framing_fits),
	    cmocka_unit_test(test_kajiya_kay_closed_form),
	    cmocka_unit_test(test_marschner_lobe_peak),
	    cmocka_unit_test(test_srgb_round_trip),
	    cmocka_unit_test(test_camera_inside_is_an_error),
	    cmocka_unit_test(test_camera_json),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

// Camera and light settings for the ray tracer, from JSON (docs/rendering.md).
#include <math.h>
#include <string.h>

#include "../core/asserts.h"
#include "io/spec.h"
#include "plume/raytrace.h"

#define DEG (3.14159265358979323846 / 180.0)

/// An array of count numbers (count_alt also accepted when > 0); returns how many were read, 0 when absent.
static int read_numbers(plume_spec_reader *reader, const json_t *object, const char *path, const char *key, double *out,
                        int count, int count_alt)
{
	const json_t *array = plume_spec_array(reader, object, path, key);
	if (array == NULL || reader->status != PLUME_OK)
		return 0;
	char child[256];
	plume_spec_path(child, sizeof child, path, key);
	int n = (int)json_array_size(array);
	if (n != count && n != count_alt) {
		if (count_alt > 0)
			plume_spec_fail(reader, child, "expected %d or %d numbers, got %d", count, count_alt, n);
		else
			plume_spec_fail(reader, child, "expected %d numbers, got %d", count, n);
		return 0;
	}
	for (int i = 0; i < n; ++i) {
		const json_t *value = json_array_get(array, (size_t)i);
		if (!json_is_number(value) || !isfinite(json_number_value(value))) {
			char item[280];
			plume_spec_index_path(item, sizeof item, child, (size_t)i);
			plume_spec_fail(reader, item, "expected a number");
			return 0;
		}
		out[i] = json_number_value(value);
	}
	return n;
}

/// The shortest direction vector a camera or light file may hold: a shorter one (1e-300)
/// passed "non-zero" but its squared length underflowed to 0, and normalising it gave NaN.
#define MIN_DIRECTION_LENGTH 1e-9

/// [x, y, z]; a direction (nonzero) must be at least MIN_DIRECTION_LENGTH long.
static bool read_vec3(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                      plume_vec3 *out, bool nonzero)
{
	double v[3];
	if (read_numbers(reader, object, path, key, v, 3, 0) != 3)
		return false;
	double length = plume_v3_length(plume_v3(v[0], v[1], v[2]));
	if (nonzero && !(length >= MIN_DIRECTION_LENGTH)) {
		char child[256];
		plume_spec_path(child, sizeof child, path, key);
		plume_spec_fail(reader, child, "has length %g, allowed >= %g (a non-zero direction)", length,
		                MIN_DIRECTION_LENGTH);
		return false;
	}
	*out = plume_v3(v[0], v[1], v[2]);
	return true;
}

/// [r, g, b] or [r, g, b, a], sRGB in [0, 1].
static void read_color(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       plume_color *out)
{
	double v[4] = {0, 0, 0, 1};
	int n = read_numbers(reader, object, path, key, v, 3, 4);
	if (n == 0)
		return;
	for (int i = 0; i < n; ++i)
		if (!(v[i] >= 0.0 && v[i] <= 1.0)) {
			char child[256];
			plume_spec_path(child, sizeof child, path, key);
			plume_spec_fail(reader, child, "channel %d is %g, allowed [0, 1]", i, v[i]);
			return;
		}
	*out = (plume_color){v[0], v[1], v[2], v[3]};
}

static void check_range(plume_spec_reader *reader, const char *path, const char *key, double value, double lo,
                        double hi, bool open)
{
	bool ok = open ? (value > lo && value < hi) : (value >= lo && value <= hi);
	if (!ok) {
		char child[256];
		plume_spec_path(child, sizeof child, path, key);
		plume_spec_fail(reader, child, "is %g, allowed %c%g, %g%c", value, open ? '(' : '[', lo, hi, open ? ')' : ']');
	}
}

static void read_angle(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       double *radians, double lo_deg, double hi_deg, bool open)
{
	double degrees = *radians / DEG;
	if (plume_spec_number(reader, object, path, key, &degrees)) {
		check_range(reader, path, key, degrees, lo_deg, hi_deg, open);
		*radians = degrees * DEG;
	}
}

static void read_camera(plume_spec_reader *reader, const json_t *object, plume_camera *camera)
{
	static const char *const keys[] = {"eye",          "target", "up",     "view_direction", "fov_deg", "orthographic",
	                                   "ortho_height", "size",   "margin", "turntable_deg",  NULL};
	const char *path = "$.camera";
	plume_spec_check_keys(reader, object, path, keys);
	bool eye = read_vec3(reader, object, path, "eye", &camera->eye, false);
	bool target = read_vec3(reader, object, path, "target", &camera->target, false);
	if (eye || target) {
		camera->automatic = false;
		double distance = plume_v3_distance(camera->eye, camera->target);
		if (reader->status == PLUME_OK && !(distance >= MIN_DIRECTION_LENGTH))
			plume_spec_fail(reader, "$.camera.target",
			                "is %g m from the eye, allowed >= %g m (it must differ from the eye)", distance,
			                MIN_DIRECTION_LENGTH);
	}
	read_vec3(reader, object, path, "up", &camera->up, true);
	read_vec3(reader, object, path, "view_direction", &camera->view_direction, true);
	read_angle(reader, object, path, "fov_deg", &camera->fov, 0.0, 180.0, true);
	plume_spec_bool(reader, object, path, "orthographic", &camera->orthographic);
	if (plume_spec_number(reader, object, path, "ortho_height", &camera->ortho_height))
		check_range(reader, path, "ortho_height", camera->ortho_height, 0.0, INFINITY, true);
	double size[2];
	if (read_numbers(reader, object, path, "size", size, 2, 0) == 2) {
		if (!(size[0] >= 16 && size[0] <= 16384 && size[1] >= 16 && size[1] <= 16384 && size[0] == floor(size[0]) &&
		      size[1] == floor(size[1])))
			plume_spec_fail(reader, "$.camera.size", "is [%g, %g], allowed whole pixels in [16, 16384]", size[0],
			                size[1]);
		else { // only a size in range converts to int without overflow
			camera->width = (int)size[0];
			camera->height = (int)size[1];
		}
	}
	// The framing leaves margin on each side of the image: at 0.45 nothing is left between.
	if (plume_spec_number(reader, object, path, "margin", &camera->margin) &&
	    !(camera->margin >= 0.0 && camera->margin < 0.45))
		plume_spec_fail(reader, "$.camera.margin", "is %g, allowed [0, 0.45)", camera->margin);
	double turntable = camera->turntable / DEG;
	if (plume_spec_number(reader, object, path, "turntable_deg", &turntable)) {
		check_range(reader, path, "turntable_deg", turntable, -360.0, 360.0, false);
		camera->turntable = turntable * DEG;
	}
	if (reader->status != PLUME_OK || camera->automatic)
		return; // automatic framing chooses eye, target and up, and fits ortho_height
	// What the ray tracer needs of a camera placed by eye and target (src/render/camera.c),
	// refused here so that the message names the file and the key.
	plume_vec3 forward = plume_v3_sub(camera->target, camera->eye);
	if (!(plume_v3_length(plume_v3_cross(forward, camera->up)) >
	      1e-12 * plume_v3_length(forward) * plume_v3_length(camera->up)))
		plume_spec_fail(reader, "$.camera.up",
		                "(%g, %g, %g) is parallel to the view direction (from eye to target); give an up across it",
		                camera->up.x, camera->up.y, camera->up.z);
	else if (camera->orthographic && !(camera->ortho_height > 0.0 && isfinite(camera->ortho_height)))
		plume_spec_fail(reader, "$.camera.ortho_height",
		                "missing; an orthographic camera placed by eye and target needs its visible height in m "
		                "(> 0); automatic framing fits it");
}

static void read_lights(plume_spec_reader *reader, const json_t *array, plume_raytrace_def *def)
{
	static const char *const keys[] = {"direction", "color", "intensity", "angle_deg", NULL};
	size_t count = json_array_size(array);
	if (count > PLUME_RAYTRACE_MAX_LIGHTS) {
		plume_spec_fail(reader, "$.lights", "has %zu lights, at most %d allowed", count, PLUME_RAYTRACE_MAX_LIGHTS);
		return;
	}
	def->light_count = (int)count;
	for (size_t i = 0; i < count; ++i) {
		char path[64];
		plume_spec_index_path(path, sizeof path, "$.lights", i);
		const json_t *light = json_array_get(array, i);
		if (!json_is_object(light)) {
			plume_spec_fail(reader, path, "expected an object");
			return;
		}
		plume_light *l = def->lights + i;
		*l = (plume_light){{0.0, 1.0, 1.0}, {1.0, 1.0, 1.0, 1.0}, 1.0, 0.05};
		plume_spec_check_keys(reader, light, path, keys);
		if (json_object_get(light, "direction") == NULL)
			plume_spec_fail(reader, path, "missing \"direction\" (towards the light)");
		read_vec3(reader, light, path, "direction", &l->direction, true);
		read_color(reader, light, path, "color", &l->color);
		if (plume_spec_number(reader, light, path, "intensity", &l->intensity))
			check_range(reader, path, "intensity", l->intensity, 0.0, 1e6, false);
		read_angle(reader, light, path, "angle_deg", &l->angle, 0.0, 28.0, false);
	}
}

static void read_choice(plume_spec_reader *reader, const json_t *root, const char *key, const char *const *names,
                        int *value)
{
	const char *text = NULL;
	if (!plume_spec_string(reader, root, "$", key, &text))
		return;
	for (int i = 0; names[i] != NULL; ++i)
		if (strcmp(text, names[i]) == 0) {
			*value = i;
			return;
		}
	char path[64];
	plume_spec_path(path, sizeof path, "$", key);
	plume_spec_fail(reader, path, "unknown value \"%s\"; allowed: \"%s\", \"%s\"%s%s%s", text, names[0], names[1],
	                names[2] != NULL ? ", \"" : "", names[2] != NULL ? names[2] : "", names[2] != NULL ? "\"" : "");
}

plume_status plume_raytrace_def_read(const char *path, plume_raytrace_def *def, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	static const char *const keys[] = {
	    "camera",      "lights",        "spp",        "seed",         "background",  "sky_color",      "sky_intensity",
	    "ground",      "ground_normal", "ground_gap", "ground_color", "shading",     "barbules",       "barb_color",
	    "shaft_color", "shell_color",   "diffuse",    "specular",     "kk_exponent", "lobe_shift_deg", "lobe_width_deg",
	    "trt_weight",  "transmission",  "ao_samples", "ao_distance",  "shadows",     "description",    NULL};
	json_t *root = plume_spec_load(path, err);
	if (root == NULL)
		return err != NULL ? err->status : PLUME_ERROR_IO;
	plume_raytrace_def out = *def;
	plume_spec_reader reader = plume_spec_reader_begin(path, err);
	if (!json_is_object(root))
		plume_spec_fail(&reader, "$", "expected an object");
	plume_spec_check_keys(&reader, root, "$", keys);
	const json_t *camera = plume_spec_object(&reader, root, "$", "camera");
	if (camera != NULL)
		read_camera(&reader, camera, &out.camera);
	const json_t *lights = plume_spec_array(&reader, root, "$", "lights");
	if (lights != NULL && reader.status == PLUME_OK)
		read_lights(&reader, lights, &out);
	if (plume_spec_int(&reader, root, "$", "spp", &out.spp))
		check_range(&reader, "$", "spp", out.spp, 1, 4096, false);
	plume_spec_uint64(&reader, root, "$", "seed", &out.seed);
	read_color(&reader, root, "$", "background", &out.background);
	read_color(&reader, root, "$", "sky_color", &out.sky_color);
	if (plume_spec_number(&reader, root, "$", "sky_intensity", &out.sky_intensity))
		check_range(&reader, "$", "sky_intensity", out.sky_intensity, 0.0, 1e6, false);
	plume_spec_bool(&reader, root, "$", "ground", &out.ground);
	read_vec3(&reader, root, "$", "ground_normal", &out.ground_normal, true);
	if (plume_spec_number(&reader, root, "$", "ground_gap", &out.ground_gap))
		check_range(&reader, "$", "ground_gap", out.ground_gap, 0.0, 1e6, false);
	read_color(&reader, root, "$", "ground_color", &out.ground_color);
	static const char *const shadings[] = {"kajiya-kay", "marschner", NULL};
	int shading = (int)out.shading;
	read_choice(&reader, root, "shading", shadings, &shading);
	out.shading = (plume_shading_model)shading;
	static const char *const barbules[] = {"off", "on", "auto", NULL};
	int barbule_mode = (int)out.barbules;
	read_choice(&reader, root, "barbules", barbules, &barbule_mode);
	out.barbules = (plume_barbule_mode)barbule_mode;
	read_color(&reader, root, "$", "barb_color", &out.barb_color);
	read_color(&reader, root, "$", "shaft_color", &out.shaft_color);
	read_color(&reader, root, "$", "shell_color", &out.shell_color);
	if (plume_spec_number(&reader, root, "$", "diffuse", &out.diffuse))
		check_range(&reader, "$", "diffuse", out.diffuse, 0.0, 1.0, false);
	if (plume_spec_number(&reader, root, "$", "specular", &out.specular))
		check_range(&reader, "$", "specular", out.specular, 0.0, 1e3, false);
	if (plume_spec_number(&reader, root, "$", "kk_exponent", &out.kk_exponent))
		check_range(&reader, "$", "kk_exponent", out.kk_exponent, 1e-3, 1e6, false);
	read_angle(&reader, root, "$", "lobe_shift_deg", &out.lobe_shift, -28.0, 28.0, false);
	read_angle(&reader, root, "$", "lobe_width_deg", &out.lobe_width, 0.1, 57.0, false);
	if (plume_spec_number(&reader, root, "$", "trt_weight", &out.trt_weight))
		check_range(&reader, "$", "trt_weight", out.trt_weight, 0.0, 1e3, false);
	if (plume_spec_number(&reader, root, "$", "transmission", &out.transmission))
		check_range(&reader, "$", "transmission", out.transmission, 0.0, 1.0, false);
	if (plume_spec_int(&reader, root, "$", "ao_samples", &out.ao_samples))
		check_range(&reader, "$", "ao_samples", out.ao_samples, 0, 64, false);
	if (plume_spec_number(&reader, root, "$", "ao_distance", &out.ao_distance))
		check_range(&reader, "$", "ao_distance", out.ao_distance, 0.0, 1e3, true);
	plume_spec_bool(&reader, root, "$", "shadows", &out.shadows);
	json_decref(root);
	if (reader.status != PLUME_OK)
		return reader.status;
	*def = out;
	return PLUME_OK;
}

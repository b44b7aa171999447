// Streit–Heidrich specs: JSON keys are Table 1's parameters (docs/spec-streit-heidrich.md).
#include "spec_streit_heidrich.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/alloc.h"
#include "spec.h"
#include "spec_models.h"

#define PI 3.14159265358979323846
/// Blends may name feathers that blend others; this deep and no deeper (a file that names itself stops here).
#define MAX_DEPTH 8
/// Room for a JSON path: inline specs nest (a coat's key feather blending inline feathers).
#define PATH_SIZE 600

/// Keys of one feather's parameters: the spec's top level and its "afterfeather" object.
#define PARAM_KEYS                                                                                                     \
	"calamus_length", "calamus_width_ratio", "rachis_length", "rachis_width", "rachis_side_curvature",                 \
	    "rachis_front_curvature", "barb_length", "barb_length_right", "barb_length_scan", "base_angle_deg",            \
	    "tip_angle_deg", "left_base_angle_deg", "left_tip_angle_deg", "right_base_angle_deg", "right_tip_angle_deg",   \
	    "spacing_base", "spacing_tip", "key_barbs"

static const char *const top_keys[] = {
    "model",          "seed",         "description", PARAM_KEYS, "afterfeather", "barb_width_base",
    "barb_width_tip", "texture_mode", "lod",         "blend",    NULL,
};
static const char *const afterfeather_keys[] = {PARAM_KEYS, NULL};
static const char *const key_barb_keys[] = {"position", "cvs", "plumulaceous", NULL};
static const char *const scan_keys[] = {"image", "base_px", "tip_px", "threshold", "samples", NULL};
static const char *const lod_keys[] = {"barb_elevations", "rachis_elevations", "calamus_samples", NULL};
static const char *const blend_keys[] = {"feathers", "t", "weights", NULL};

void plume_spec_relative_path(char *out, size_t size, const char *file, const char *name)
{
	const char *slash = strrchr(file, '/');
	if (name[0] == '/' || slash == NULL)
		snprintf(out, size, "%s", name);
	else
		snprintf(out, size, "%.*s/%s", (int)(slash - file), file, name);
}

// ---------------------------------------------------------------------------
// Pieces

/// A point [x, y, z] (or [x, y], z = 0).
static bool read_point3(plume_spec_reader *reader, const json_t *value, const char *path, plume_vec3 *out)
{
	size_t n = json_is_array(value) ? json_array_size(value) : 0;
	if (n != 2 && n != 3) {
		plume_spec_fail(reader, path, "expected a control vertex [x, y, z] in units of barb length");
		return false;
	}
	double c[3] = {0.0, 0.0, 0.0};
	for (size_t i = 0; i < n; ++i) {
		const json_t *item = json_array_get(value, i);
		if (!json_is_number(item)) {
			char child[600];
			plume_spec_index_path(child, sizeof child, path, i);
			plume_spec_fail(reader, child, "expected a number");
			return false;
		}
		c[i] = json_number_value(item);
	}
	*out = plume_v3(c[0], c[1], c[2]);
	return true;
}

static void read_key_barb(plume_spec_reader *reader, const json_t *object, const char *path, plume_sh_key_barb *key)
{
	if (!json_is_object(object)) {
		plume_spec_fail(reader, path, "expected a key barb {\"position\": rp, \"cvs\": [[x, y, z], ...]}");
		return;
	}
	plume_spec_check_keys(reader, object, path, key_barb_keys);
	memset(key, 0, sizeof *key);
	key->position = NAN;
	if (!plume_spec_number(reader, object, path, "position", &key->position) && reader->status == PLUME_OK) {
		char child[600];
		plume_spec_path(child, sizeof child, path, "position");
		plume_spec_fail(reader, child, "missing; a key barb needs its position along the rachis, in [0, 1]");
	}
	plume_spec_number(reader, object, path, "plumulaceous", &key->plumulaceous);
	const json_t *cvs = plume_spec_array(reader, object, path, "cvs");
	char child[600];
	plume_spec_path(child, sizeof child, path, "cvs");
	if (reader->status != PLUME_OK)
		return;
	if (cvs == NULL || json_array_size(cvs) < 2 || json_array_size(cvs) > PLUME_SH_MAX_CVS) {
		plume_spec_fail(reader, child, "a key barb needs 2 to %d control vertices [x, y, z], got %zu", PLUME_SH_MAX_CVS,
		                cvs != NULL ? json_array_size(cvs) : (size_t)0);
		return;
	}
	key->cv_count = (int)json_array_size(cvs);
	for (int i = 0; i < key->cv_count; ++i) {
		char item[640];
		plume_spec_index_path(item, sizeof item, child, (size_t)i);
		if (!read_point3(reader, json_array_get(cvs, (size_t)i), item, &key->cvs[i]))
			return;
	}
}

/// "barb_length": a number (constant, m) or silhouette points [[rp, length_m], ...].
static void read_profile(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                         plume_sh_length_profile *profile)
{
	const json_t *value = reader->status == PLUME_OK ? json_object_get(object, key) : NULL;
	if (value == NULL)
		return;
	char child[600];
	plume_spec_path(child, sizeof child, path, key);
	memset(profile, 0, sizeof *profile);
	if (json_is_number(value)) {
		profile->count = 1;
		profile->length[0] = json_number_value(value);
		return;
	}
	size_t n = json_is_array(value) ? json_array_size(value) : 0;
	if (n < 1 || n > PLUME_SH_MAX_PROFILE) {
		plume_spec_fail(reader, child,
		                "expected a length in metres or 1 to %d silhouette points [rachis_position, length_m]",
		                PLUME_SH_MAX_PROFILE);
		return;
	}
	profile->count = (int)n;
	for (size_t i = 0; i < n; ++i) {
		const json_t *point = json_array_get(value, i);
		char item[640];
		plume_spec_index_path(item, sizeof item, child, i);
		if (!json_is_array(point) || json_array_size(point) != 2 || !json_is_number(json_array_get(point, 0)) ||
		    !json_is_number(json_array_get(point, 1))) {
			plume_spec_fail(reader, item, "expected a silhouette point [rachis_position, length_m]");
			return;
		}
		profile->position[i] = json_number_value(json_array_get(point, 0));
		profile->length[i] = json_number_value(json_array_get(point, 1));
	}
}

static bool read_pixel(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       double out[2])
{
	const json_t *value = reader->status == PLUME_OK ? json_object_get(object, key) : NULL;
	if (reader->status != PLUME_OK)
		return false;
	char child[600];
	plume_spec_path(child, sizeof child, path, key);
	if (value == NULL) {
		plume_spec_fail(reader, child, "missing; the scan needs the rachis base and tip in pixels [x, y]");
		return false;
	}
	if (!json_is_array(value) || json_array_size(value) != 2 || !json_is_number(json_array_get(value, 0)) ||
	    !json_is_number(json_array_get(value, 1))) {
		plume_spec_fail(reader, child, "expected a pixel position [x, y]");
		return false;
	}
	out[0] = json_number_value(json_array_get(value, 0));
	out[1] = json_number_value(json_array_get(value, 1));
	return true;
}

/// "barb_length_scan": {"image", "base_px", "tip_px", "threshold", "samples"} (4.2.2).
static plume_status read_scan(plume_spec_reader *reader, const char *file, const json_t *object, const char *path,
                              plume_sh_params *params, plume_error *err)
{
	const json_t *scan = plume_spec_object(reader, object, path, "barb_length_scan");
	if (scan == NULL || reader->status != PLUME_OK)
		return reader->status;
	char child[600];
	plume_spec_path(child, sizeof child, path, "barb_length_scan");
	plume_spec_check_keys(reader, scan, child, scan_keys);
	plume_sh_scan_def def = plume_sh_default_scan_def();
	const char *image = NULL;
	if (!plume_spec_string(reader, scan, child, "image", &image) && reader->status == PLUME_OK) {
		char image_path[640];
		plume_spec_path(image_path, sizeof image_path, child, "image");
		plume_spec_fail(reader, image_path, "missing; the scan's image file (PNG), relative to the spec");
	}
	read_pixel(reader, scan, child, "base_px", def.base_px);
	read_pixel(reader, scan, child, "tip_px", def.tip_px);
	plume_spec_number(reader, scan, child, "threshold", &def.threshold);
	plume_spec_int(reader, scan, child, "samples", &def.samples);
	if (reader->status != PLUME_OK)
		return reader->status;
	char image_path[4096];
	plume_spec_relative_path(image_path, sizeof image_path, file, image);
	plume_status status = plume_sh_scan_barb_lengths(image_path, &def, params, err);
	if (status != PLUME_OK) {
		char prefix[1200];
		snprintf(prefix, sizeof prefix, "%s: %s", file, child);
		plume_error_prefix(err, prefix);
		reader->status = status;
	}
	return status;
}

static void read_angle(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       double *radians)
{
	double degrees = *radians * 180.0 / PI;
	if (plume_spec_number(reader, object, path, key, &degrees))
		*radians = degrees * PI / 180.0;
}

/// One feather's parameters (Table 1) from object, over the values params already holds.
static plume_status read_params(plume_spec_reader *reader, const char *file, const json_t *object, const char *path,
                                plume_sh_params *params, plume_error *err)
{
	plume_sh_params *p = params;
	plume_spec_number(reader, object, path, "calamus_length", &p->calamus_length);
	plume_spec_number(reader, object, path, "calamus_width_ratio", &p->calamus_width_ratio);
	plume_spec_number(reader, object, path, "rachis_length", &p->rachis_length);
	plume_spec_number(reader, object, path, "rachis_width", &p->rachis_width);
	plume_spec_number(reader, object, path, "rachis_side_curvature", &p->rachis_side_curvature);
	plume_spec_number(reader, object, path, "rachis_front_curvature", &p->rachis_front_curvature);
	plume_spec_number(reader, object, path, "spacing_base", &p->spacing_base);
	plume_spec_number(reader, object, path, "spacing_tip", &p->spacing_tip);
	// Angles: both vanes at once, then either vane on its own. The validation names the
	// per-vane keys (left_base_angle_deg), which the spec need not have: the shared keys are
	// checked here, under the names they were given.
	static const char *const shared_angles[2] = {"base_angle_deg", "tip_angle_deg"};
	for (int end = 0; end < 2; ++end) {
		double degrees = NAN;
		if (!plume_spec_number(reader, object, path, shared_angles[end], &degrees))
			continue;
		if (!(degrees > 0.0 && degrees <= 180.0)) {
			// The shortest text that reads back as the value: what the spec says (180.0001, not "%g"'s 180).
			char child[PATH_SIZE], text[32];
			for (int digits = 6; digits <= 17; ++digits) {
				snprintf(text, sizeof text, "%.*g", digits, degrees);
				if (strtod(text, NULL) == degrees)
					break;
			}
			plume_spec_path(child, sizeof child, path, shared_angles[end]);
			// Worded as the validation words the per-vane keys.
			if (reader->status == PLUME_OK)
				reader->status = plume_error_set(reader->err, PLUME_ERROR_SPEC, "%s: %s is %s, allowed (0, 180]",
				                                 reader->file, child, text);
		}
		for (int side = 0; side < 2; ++side)
			p->barb_angle[side][end] = degrees * PI / 180.0;
	}
	read_angle(reader, object, path, "left_base_angle_deg", &p->barb_angle[0][0]);
	read_angle(reader, object, path, "left_tip_angle_deg", &p->barb_angle[0][1]);
	read_angle(reader, object, path, "right_base_angle_deg", &p->barb_angle[1][0]);
	read_angle(reader, object, path, "right_tip_angle_deg", &p->barb_angle[1][1]);
	if (reader->status == PLUME_OK && json_object_get(object, "barb_length") != NULL) {
		read_profile(reader, object, path, "barb_length", &p->barb_length[0]);
		p->barb_length[1] = p->barb_length[0];
	}
	read_profile(reader, object, path, "barb_length_right", &p->barb_length[1]);
	if (reader->status == PLUME_OK && json_object_get(object, "barb_length_scan") != NULL &&
	    json_object_get(object, "barb_length") != NULL) {
		char child[600];
		plume_spec_path(child, sizeof child, path, "barb_length_scan");
		plume_spec_fail(reader, child, "give barb_length or barb_length_scan, not both");
	}
	// No "key_barbs" means none: Bdf1 everywhere, a plumulaceous vane (4.2.1), not the library's defaults.
	p->key_barb_count = 0;
	const json_t *keys = plume_spec_array(reader, object, path, "key_barbs");
	if (keys != NULL && reader->status == PLUME_OK) {
		char child[600];
		plume_spec_path(child, sizeof child, path, "key_barbs");
		size_t n = json_array_size(keys);
		if (n > PLUME_SH_MAX_KEY_BARBS - 2) {
			plume_spec_fail(reader, child, "%zu key barbs, at most %d", n, PLUME_SH_MAX_KEY_BARBS - 2);
		} else {
			p->key_barb_count = (int)n;
			for (size_t j = 0; j < n && reader->status == PLUME_OK; ++j) {
				char item[640];
				plume_spec_index_path(item, sizeof item, child, j);
				read_key_barb(reader, json_array_get(keys, j), item, &p->key_barbs[j]);
			}
		}
	}
	if (reader->status != PLUME_OK)
		return reader->status;
	// The scan measures along the barb directions, so it comes after the angles.
	return read_scan(reader, file, object, path, p, err);
}

// ---------------------------------------------------------------------------
// Blends (4.2.3)

/// One feather of a blend: a file path (relative to the spec) or an inline spec.
static plume_status read_blend_feather(plume_spec_reader *reader, const char *file, const json_t *value,
                                       const char *path, int depth, plume_sh_def *out, plume_error *err)
{
	uint64_t seed;
	if (json_is_string(value)) {
		char other[4096];
		plume_spec_relative_path(other, sizeof other, file, json_string_value(value));
		json_t *root = plume_spec_load(other, err);
		if (root == NULL) {
			reader->status = err != NULL ? err->status : PLUME_ERROR_IO;
			return reader->status;
		}
		plume_status status;
		if (!json_is_object(root)) {
			status = plume_error_set(err, PLUME_ERROR_SPEC, "%s: $: expected a streit-heidrich spec object", other);
		} else {
			const char *model = NULL;
			plume_spec_reader inner = plume_spec_reader_begin(other, err);
			if (plume_spec_string(&inner, root, "$", "model", &model) && strcmp(model, "streit-heidrich") != 0)
				plume_spec_fail(&inner, "$.model",
				                "\"%s\" cannot be blended; feather types blend streit-heidrich feathers", model);
			status = inner.status;
			if (status == PLUME_OK)
				status = plume_sh_def_from_json(other, root, "$", out, &seed, NULL, depth + 1, err);
		}
		json_decref(root);
		reader->status = status;
		return status;
	}
	if (!json_is_object(value)) {
		plume_spec_fail(reader, path, "expected a spec file name or an inline streit-heidrich spec");
		return reader->status;
	}
	const char *model = NULL;
	if (plume_spec_string(reader, value, path, "model", &model) && strcmp(model, "streit-heidrich") != 0) {
		char model_path[PATH_SIZE];
		plume_spec_path(model_path, sizeof model_path, path, "model");
		plume_spec_fail(reader, model_path, "\"%s\" cannot be blended; feather types blend streit-heidrich feathers",
		                model);
		return reader->status;
	}
	if (reader->status != PLUME_OK)
		return reader->status;
	// An inline spec is part of this file: its messages name where it sits in it.
	reader->status = plume_sh_def_from_json(file, value, path, out, &seed, NULL, depth + 1, err);
	return reader->status;
}

static plume_status read_blend(plume_spec_reader *reader, const char *file, const json_t *blend, const char *base,
                               int depth, plume_sh_def *def, plume_error *err)
{
	char path[PATH_SIZE], feathers_path[PATH_SIZE], t_path[PATH_SIZE], weights_path[PATH_SIZE];
	plume_spec_path(path, sizeof path, base, "blend");
	plume_spec_path(feathers_path, sizeof feathers_path, path, "feathers");
	plume_spec_path(t_path, sizeof t_path, path, "t");
	plume_spec_path(weights_path, sizeof weights_path, path, "weights");
	plume_spec_check_keys(reader, blend, path, blend_keys);
	const json_t *feathers = plume_spec_array(reader, blend, path, "feathers");
	if (reader->status != PLUME_OK)
		return reader->status;
	size_t n = feathers != NULL ? json_array_size(feathers) : 0;
	if (n < 2 || n > 16) {
		plume_spec_fail(reader, feathers_path, "expected 2 to 16 feathers to blend, got %zu", n);
		return reader->status;
	}
	double weights[16] = {0};
	double t = 0.0;
	bool has_t = plume_spec_number(reader, blend, path, "t", &t);
	const json_t *weight_array = plume_spec_array(reader, blend, path, "weights");
	if (reader->status != PLUME_OK)
		return reader->status;
	if (has_t == (weight_array != NULL)) {
		plume_spec_fail(reader, path, "give either \"t\" (a position in [0, 1] along the feathers) or \"weights\"");
		return reader->status;
	}
	if (has_t) {
		if (!(t >= 0.0 && t <= 1.0)) {
			plume_spec_fail(reader, t_path, "is %g, allowed [0, 1]", t);
			return reader->status;
		}
		// A continuum through the feathers in order: t = 0 the first, t = 1 the last.
		double x = t * (double)(n - 1);
		size_t i = (size_t)floor(x);
		if (i >= n - 1)
			i = n - 2;
		double f = x - (double)i;
		weights[i] = 1.0 - f;
		weights[i + 1] = f;
	} else {
		if (json_array_size(weight_array) != n) {
			plume_spec_fail(reader, weights_path, "expected %zu weights, one per feather", n);
			return reader->status;
		}
		double total = 0.0;
		for (size_t i = 0; i < n; ++i) {
			const json_t *w = json_array_get(weight_array, i);
			char item[PATH_SIZE];
			plume_spec_index_path(item, sizeof item, weights_path, i);
			if (!json_is_number(w) || json_number_value(w) < 0.0) {
				plume_spec_fail(reader, item, "expected a weight >= 0");
				return reader->status;
			}
			weights[i] = json_number_value(w);
			total += weights[i];
		}
		if (!(total > 0.0)) {
			plume_spec_fail(reader, weights_path, "the weights sum to 0");
			return reader->status;
		}
	}
	plume_sh_def *defs = plume_alloc(n * sizeof *defs);
	if (defs == NULL)
		return reader->status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	const plume_sh_def *pointers[16];
	for (size_t i = 0; i < n && reader->status == PLUME_OK; ++i) {
		char item[PATH_SIZE];
		plume_spec_index_path(item, sizeof item, feathers_path, i);
		read_blend_feather(reader, file, json_array_get(feathers, i), item, depth, &defs[i], err);
		pointers[i] = &defs[i];
	}
	if (reader->status == PLUME_OK)
		reader->status = plume_sh_def_blend(pointers, weights, (int)n, def, err);
	plume_free(defs);
	return reader->status;
}

// ---------------------------------------------------------------------------
// The spec

static void read_lod(plume_spec_reader *reader, const json_t *root, const char *base, plume_sh_lod *lod)
{
	const json_t *object = plume_spec_object(reader, root, base, "lod");
	if (object == NULL || lod == NULL)
		return;
	char path[PATH_SIZE];
	plume_spec_path(path, sizeof path, base, "lod");
	plume_spec_check_keys(reader, object, path, lod_keys);
	plume_spec_int(reader, object, path, "barb_elevations", &lod->barb_elevations);
	plume_spec_int(reader, object, path, "rachis_elevations", &lod->rachis_elevations);
	plume_spec_int(reader, object, path, "calamus_samples", &lod->calamus_samples);
}

static void read_texture_mode(plume_spec_reader *reader, const json_t *root, const char *base, plume_sh_def *def)
{
	const char *mode = NULL;
	if (!plume_spec_string(reader, root, base, "texture_mode", &mode))
		return;
	static const char *const names[] = {"barb", "vane", "growth", NULL};
	for (int i = 0; names[i] != NULL; ++i)
		if (strcmp(mode, names[i]) == 0) {
			def->texture_mode = (plume_sh_texture_mode)i;
			return;
		}
	char path[PATH_SIZE];
	plume_spec_path(path, sizeof path, base, "texture_mode");
	plume_spec_fail(reader, path, "unknown mode \"%s\"; did you mean \"%s\"? (allowed: barb, vane, growth)", mode,
	                plume_spec_nearest(mode, names));
}

/// Keys of the whole feather (texture_mode, model, ...) put in the afterfeather: named as such,
/// where "did you mean" would guess a parameter that has nothing to do with them.
static void check_afterfeather_keys(plume_spec_reader *reader, const json_t *after, const char *base,
                                    const char *after_path)
{
	const char *key;
	json_t *value;
	json_object_foreach ((json_t *)after, key, value) {
		bool feather_key = false, after_key = false;
		for (const char *const *k = top_keys; *k != NULL; ++k)
			feather_key = feather_key || strcmp(key, *k) == 0;
		for (const char *const *k = afterfeather_keys; *k != NULL; ++k)
			after_key = after_key || strcmp(key, *k) == 0;
		if (feather_key && !after_key) {
			char child[PATH_SIZE], top[PATH_SIZE];
			plume_spec_path(child, sizeof child, after_path, key);
			plume_spec_path(top, sizeof top, base, key);
			plume_spec_fail(reader, child,
			                "is a key of the whole feather, not of its afterfeather: give it at the spec's top level "
			                "(%s)",
			                top);
			return;
		}
	}
}

/// plume_sh_def_validate names the keys from the root of a spec ("$.rachis_length ..."): an inline
/// spec at base ("$.blend.feathers[0]") gets base in its place, then the file in front.
static void name_from_base(plume_error *err, const char *file, const char *base)
{
	if (err != NULL && strcmp(base, "$") != 0 && err->message[0] == '$') {
		char message[sizeof err->message];
		snprintf(message, sizeof message, "%s%s", base, err->message + 1);
		memcpy(err->message, message, sizeof message);
	}
	plume_error_prefix(err, file);
}

plume_status plume_sh_def_from_json(const char *file, const json_t *root, const char *base, plume_sh_def *def,
                                    uint64_t *seed, plume_sh_lod *lod, int depth, plume_error *err)
{
	*def = plume_sh_default_def();
	*seed = 1;
	if (lod != NULL)
		*lod = plume_sh_default_lod();
	plume_spec_reader reader = plume_spec_reader_begin(file, err);
	char blend_path[PATH_SIZE], after_path[PATH_SIZE];
	plume_spec_path(blend_path, sizeof blend_path, base, "blend");
	plume_spec_path(after_path, sizeof after_path, base, "afterfeather");
	if (depth > MAX_DEPTH) {
		plume_spec_fail(&reader, blend_path, "blends nest more than %d deep (does a feather blend itself?)", MAX_DEPTH);
		return reader.status;
	}
	plume_spec_check_keys(&reader, root, base, top_keys);
	plume_spec_uint64(&reader, root, base, "seed", seed);
	const char *description;
	plume_spec_string(&reader, root, base, "description", &description);
	read_lod(&reader, root, base, lod);
	const json_t *blend = plume_spec_object(&reader, root, base, "blend");
	if (blend != NULL && reader.status == PLUME_OK) {
		// A blend is a feather of its own: parameters beside it would be ambiguous.
		const char *key;
		json_t *value;
		json_object_foreach ((json_t *)root, key, value) {
			if (strcmp(key, "model") != 0 && strcmp(key, "seed") != 0 && strcmp(key, "description") != 0 &&
			    strcmp(key, "lod") != 0 && strcmp(key, "blend") != 0 && strcmp(key, "texture_mode") != 0) {
				char child[PATH_SIZE];
				plume_spec_path(child, sizeof child, base, key);
				plume_spec_fail(&reader, child, "a blended feather takes its parameters from %s.feathers", blend_path);
				break;
			}
		}
		if (reader.status == PLUME_OK)
			read_blend(&reader, file, blend, base, depth, def, err);
		read_texture_mode(&reader, root, base, def);
		if (reader.status != PLUME_OK)
			return reader.status;
	} else {
		if (read_params(&reader, file, root, base, &def->main, err) != PLUME_OK)
			return reader.status;
		def->afterfeather = plume_sh_default_afterfeather(&def->main);
		plume_spec_number(&reader, root, base, "barb_width_base", &def->barb_width_base);
		plume_spec_number(&reader, root, base, "barb_width_tip", &def->barb_width_tip);
		read_texture_mode(&reader, root, base, def);
		const json_t *after = json_object_get(root, "afterfeather");
		if (after != NULL && reader.status == PLUME_OK) {
			if (json_is_boolean(after)) {
				def->has_afterfeather = json_is_true(after);
			} else if (json_is_object(after)) {
				def->has_afterfeather = true;
				check_afterfeather_keys(&reader, after, base, after_path);
				plume_spec_check_keys(&reader, after, after_path, afterfeather_keys);
				read_params(&reader, file, after, after_path, &def->afterfeather, err);
			} else {
				plume_spec_fail(&reader, after_path,
				                "expected true, false or an object with the afterfeather's parameters");
			}
		}
		if (reader.status != PLUME_OK)
			return reader.status;
	}
	// Ranges are the library's own check; its messages name the JSON path from the spec's root.
	plume_status status = plume_sh_def_validate(def, err);
	if (status != PLUME_OK)
		name_from_base(err, file, base);
	return status;
}

plume_status plume_sh_def_read(const char *path, plume_sh_def *def, uint64_t *seed, plume_sh_lod *lod, plume_error *err)
{
	plume_status status;
	json_t *root = plume_spec_load_model(path, &status, err);
	if (root == NULL)
		return status;
	status = plume_sh_def_from_json(path, root, "$", def, seed, lod, 0, err);
	json_decref(root);
	return status;
}

plume_status plume_sh_spec_generate(const char *file, const json_t *root, const plume_spec_options *options,
                                    plume_feather **out, plume_error *err)
{
	*out = NULL;
	double stage = 1.0;
	if (options != NULL && options->stage_kind == PLUME_STAGE_UNFURL)
		return plume_error_set(err, PLUME_ERROR_UNSUPPORTED,
		                       "%s: the streit-heidrich model has growth stages but no unfurling (zhang-kanai has); "
		                       "drop --unfurl",
		                       file);
	if (options != NULL && options->stage_kind == PLUME_STAGE_GROWTH) {
		if (!(options->stage >= 0.0 && options->stage <= 1.0))
			return plume_error_set(err, PLUME_ERROR_SPEC, "%s: growth stage %g is outside [0, 1]", file,
			                       options->stage);
		stage = options->stage;
	}
	plume_sh_def *def = plume_alloc(sizeof *def);
	if (def == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	uint64_t seed;
	plume_sh_lod lod;
	plume_status status = plume_sh_def_from_json(file, root, "$", def, &seed, &lod, 0, err);
	if (status == PLUME_OK) {
		if (options != NULL && options->seed_given)
			seed = options->seed;
		status = plume_spec_check_feather_bytes(
		    file, plume_sh_estimate_bytes(def, &lod), options, err,
		    "$.rachis_length / $.spacing_base, $.spacing_tip (at most %d barbs a vane%s) x $.key_barbs[*].cvs and "
		    "$.lod.barb_elevations (%d)",
		    PLUME_SH_MAX_BARBS, def->has_afterfeather ? ", and $.afterfeather's" : "", lod.barb_elevations);
		if (status == PLUME_OK && (status = plume_sh_generate_lod(def, seed, stage, &lod, out, err)) != PLUME_OK)
			plume_error_prefix(err, file);
	}
	plume_free(def);
	return status;
}

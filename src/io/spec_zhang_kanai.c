// Zhang–Kanai specs: JSON keys are the fields of plume_zk_def
// (docs/spec-zhang-kanai.md). Angles are given in degrees (keys ending in _deg).
#include <math.h>
#include <string.h>

#include "plume/zhang_kanai.h"
#include "spec.h"
#include "spec_models.h"

static const double deg = 3.14159265358979323846 / 180.0;

static const char *const top_keys[] = {
    "model",
    "seed",
    "description",
    "collar",
    "anterior",
    "posterior",
    "ridge_width",
    "ridge_width_variation",
    "emitter_speed",
    "barb_speed",
    "growth_speed",
    "step",
    "barb_count",
    "downsample",
    "growth_stage",
    "unfurl_weight",
    "sheath",
    "expansion",
    "theta_distal_deg",
    "theta_proximal_deg",
    "azimuth_deg",
    "ridge_height",
    "splits",
    "keep_barbules",
    "calamus_length",
    "rachis_taper",
    "shaft_samples",
    "barb_width_base",
    "barb_width_tip",
    "barbule_width",
    NULL,
};

static const char *const collar_keys[] = {"radius", "points", NULL};
static const char *const sheath_keys[] = {"height", "ramp", NULL};
static const char *const split_keys[] = {"side", "barb", "at", "angle_deg", NULL};

/// A number, or null-free finite check left to validation.
static bool read_number_at(plume_spec_reader *reader, const json_t *value, const char *path, double *out)
{
	if (!json_is_number(value)) {
		plume_spec_fail(reader, path, "expected a number");
		return false;
	}
	*out = json_number_value(value);
	return true;
}

/// A pair [a, b] of numbers.
static void read_pair(plume_spec_reader *reader, const json_t *value, const char *path, double *a, double *b)
{
	if (reader->status != PLUME_OK)
		return;
	if (!json_is_array(value) || json_array_size(value) != 2) {
		plume_spec_fail(reader, path, "expected a pair [a, b] of numbers");
		return;
	}
	char item[128];
	plume_spec_index_path(item, sizeof item, path, 0);
	if (read_number_at(reader, json_array_get(value, 0), item, a)) {
		plume_spec_index_path(item, sizeof item, path, 1);
		read_number_at(reader, json_array_get(value, 1), item, b);
	}
}

/// A distribution on the collar: a number (constant) or [[s, value], ...].
static void read_curve(plume_spec_reader *reader, const json_t *root, const char *key, plume_zk_curve *curve)
{
	const json_t *value = json_object_get(root, key);
	if (value == NULL || reader->status != PLUME_OK)
		return;
	char path[96];
	plume_spec_path(path, sizeof path, "$", key);
	if (json_is_number(value)) {
		*curve = plume_zk_constant(json_number_value(value));
		return;
	}
	size_t count = json_is_array(value) ? json_array_size(value) : 0;
	if (count < 1 || count > PLUME_ZK_MAX_CURVE_POINTS) {
		plume_spec_fail(reader, path,
		                "expected a number or 1 to %d control points [[s, value], ...] with s in [0, 1] increasing",
		                PLUME_ZK_MAX_CURVE_POINTS);
		return;
	}
	curve->count = (int)count;
	for (size_t k = 0; k < count; ++k) {
		char item[128];
		plume_spec_index_path(item, sizeof item, path, k);
		read_pair(reader, json_array_get(value, k), item, curve->s + k, curve->value + k);
	}
}

static void read_interval(plume_spec_reader *reader, const json_t *root, const char *key, double out[2])
{
	const json_t *value = json_object_get(root, key);
	if (value == NULL)
		return;
	char path[64];
	plume_spec_path(path, sizeof path, "$", key);
	read_pair(reader, value, path, out, out + 1);
}

static void read_collar(plume_spec_reader *reader, const json_t *root, plume_zk_def *def)
{
	const json_t *collar = plume_spec_object(reader, root, "$", "collar");
	if (collar == NULL || reader->status != PLUME_OK)
		return;
	plume_spec_check_keys(reader, collar, "$.collar", collar_keys);
	const json_t *points = json_object_get(collar, "points");
	bool has_radius = plume_spec_number(reader, collar, "$.collar", "radius", &def->collar_radius);
	if (points == NULL || reader->status != PLUME_OK)
		return;
	if (has_radius) {
		plume_spec_fail(reader, "$.collar",
		                "give either \"radius\" (a circle, eq. 1) or \"points\" (a Bézier), not both");
		return;
	}
	size_t count = json_is_array(points) ? json_array_size(points) : 0;
	if (!json_is_array(points)) {
		plume_spec_fail(reader, "$.collar.points", "expected an array of points [x, z]");
		return;
	}
	if (count < 4 || count > PLUME_ZK_MAX_COLLAR_POINTS) {
		plume_spec_fail(reader, "$.collar.points",
		                "has %zu control points; a closed composite cubic Bézier collar needs 4 to %d", count,
		                PLUME_ZK_MAX_COLLAR_POINTS);
		return;
	}
	def->collar_kind = PLUME_ZK_COLLAR_BEZIER;
	def->collar_point_count = (int)count;
	for (size_t k = 0; k < count; ++k) {
		char item[64];
		plume_spec_index_path(item, sizeof item, "$.collar.points", k);
		read_pair(reader, json_array_get(points, k), item, &def->collar_points[k].x, &def->collar_points[k].y);
	}
}

static void read_angle(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       double *radians)
{
	double degrees = *radians / deg;
	if (plume_spec_number(reader, object, path, key, &degrees))
		*radians = degrees * deg;
}

static void read_splits(plume_spec_reader *reader, const json_t *root, plume_zk_def *def)
{
	const json_t *splits = plume_spec_array(reader, root, "$", "splits");
	if (splits == NULL || reader->status != PLUME_OK)
		return;
	if (json_array_size(splits) > PLUME_ZK_MAX_SPLITS) {
		plume_spec_fail(reader, "$.splits", "has %zu entries, allowed at most %d", json_array_size(splits),
		                PLUME_ZK_MAX_SPLITS);
		return;
	}
	def->split_count = (int)json_array_size(splits);
	for (int k = 0; k < def->split_count && reader->status == PLUME_OK; ++k) {
		char path[64];
		plume_spec_index_path(path, sizeof path, "$.splits", (size_t)k);
		const json_t *item = json_array_get(splits, (size_t)k);
		if (!json_is_object(item)) {
			plume_spec_fail(reader, path, "expected an object {\"side\", \"barb\", \"at\", \"angle_deg\"}");
			return;
		}
		plume_spec_check_keys(reader, item, path, split_keys);
		plume_zk_split *split = def->splits + k;
		*split = (plume_zk_split){.side = PLUME_SIDE_LEFT, .barb = 0, .at = 0.5, .angle = 20.0 * deg};
		const char *side = "left";
		plume_spec_string(reader, item, path, "side", &side);
		if (reader->status == PLUME_OK && strcmp(side, "left") != 0 && strcmp(side, "right") != 0) {
			char side_path[80];
			plume_spec_path(side_path, sizeof side_path, path, "side");
			plume_spec_fail(reader, side_path, "is \"%s\"; allowed \"left\" or \"right\"", side);
		}
		split->side = strcmp(side, "right") == 0 ? PLUME_SIDE_RIGHT : PLUME_SIDE_LEFT;
		// The barb has no default: one left out bent barb 0, the vane's tip.
		if (!plume_spec_int(reader, item, path, "barb", &split->barb) && reader->status == PLUME_OK) {
			char barb_path[80];
			plume_spec_path(barb_path, sizeof barb_path, path, "barb");
			plume_spec_fail(reader, barb_path,
			                "missing; a split names its barb: the index in emission order on its vane, 0 the most "
			                "distal");
		}
		plume_spec_number(reader, item, path, "at", &split->at);
		read_angle(reader, item, path, "angle_deg", &split->angle);
	}
}

static plume_status def_from_json(const char *file, const json_t *root, plume_zk_def *def, uint64_t *seed,
                                  plume_error *err)
{
	*def = plume_zk_default_def();
	*seed = 1;
	plume_spec_reader reader = plume_spec_reader_begin(file, err);
	plume_spec_check_keys(&reader, root, "$", top_keys);
	plume_spec_uint64(&reader, root, "$", "seed", seed);
	const char *description;
	plume_spec_string(&reader, root, "$", "description", &description);
	read_collar(&reader, root, def);
	read_interval(&reader, root, "anterior", def->anterior);
	read_interval(&reader, root, "posterior", def->posterior);
	plume_spec_number(&reader, root, "$", "ridge_width", &def->ridge_width);
	plume_spec_number(&reader, root, "$", "ridge_width_variation", &def->ridge_width_variation);
	read_curve(&reader, root, "emitter_speed", &def->emitter_speed);
	read_curve(&reader, root, "barb_speed", &def->barb_speed);
	plume_spec_number(&reader, root, "$", "growth_speed", &def->growth_speed);
	plume_spec_number(&reader, root, "$", "step", &def->step);
	plume_spec_int(&reader, root, "$", "barb_count", &def->barb_count);
	plume_spec_int(&reader, root, "$", "downsample", &def->downsample);
	plume_spec_number(&reader, root, "$", "growth_stage", &def->growth_stage);
	plume_spec_number(&reader, root, "$", "unfurl_weight", &def->unfurl_weight);
	const json_t *sheath = plume_spec_object(&reader, root, "$", "sheath");
	if (sheath != NULL && reader.status == PLUME_OK) {
		def->sheath = true;
		plume_spec_check_keys(&reader, sheath, "$.sheath", sheath_keys);
		plume_spec_number(&reader, sheath, "$.sheath", "height", &def->sheath_height);
		plume_spec_number(&reader, sheath, "$.sheath", "ramp", &def->sheath_ramp);
	}
	plume_spec_bool(&reader, root, "$", "expansion", &def->expansion);
	read_angle(&reader, root, "$", "theta_distal_deg", &def->theta_distal);
	read_angle(&reader, root, "$", "theta_proximal_deg", &def->theta_proximal);
	read_angle(&reader, root, "$", "azimuth_deg", &def->azimuth);
	read_curve(&reader, root, "ridge_height", &def->ridge_height);
	read_splits(&reader, root, def);
	plume_spec_bool(&reader, root, "$", "keep_barbules", &def->keep_barbules);
	plume_spec_number(&reader, root, "$", "calamus_length", &def->calamus_length);
	plume_spec_number(&reader, root, "$", "rachis_taper", &def->rachis_taper);
	plume_spec_int(&reader, root, "$", "shaft_samples", &def->shaft_samples);
	plume_spec_number(&reader, root, "$", "barb_width_base", &def->barb_width_base);
	plume_spec_number(&reader, root, "$", "barb_width_tip", &def->barb_width_tip);
	plume_spec_number(&reader, root, "$", "barbule_width", &def->barbule_width);
	if (reader.status != PLUME_OK)
		return reader.status;
	plume_status status = plume_zk_def_validate(def, err);
	if (status != PLUME_OK)
		plume_error_prefix(err, file);
	return status;
}

plume_status plume_zk_def_read(const char *path, plume_zk_def *def, uint64_t *seed, plume_error *err)
{
	plume_status status;
	json_t *root = plume_spec_load_model(path, &status, err);
	if (root == NULL)
		return status;
	status = def_from_json(path, root, def, seed, err);
	json_decref(root);
	return status;
}

plume_status plume_zk_spec_generate(const char *file, const json_t *root, const plume_spec_options *options,
                                    plume_feather **out, plume_error *err)
{
	*out = NULL;
	plume_zk_def def;
	uint64_t seed;
	plume_status status = def_from_json(file, root, &def, &seed, err);
	if (status != PLUME_OK)
		return status;
	if (options != NULL) {
		if (options->seed_given)
			seed = options->seed;
		if (options->stage_kind != PLUME_STAGE_FULL && !(options->stage >= 0.0 && options->stage <= 1.0))
			return plume_error_set(err, PLUME_ERROR_SPEC, "%s: stage %g is outside [0, 1]", file, options->stage);
		// Growth: t_curr as a fraction of the growth period; unfurling: the global w.
		if (options->stage_kind == PLUME_STAGE_GROWTH)
			def.growth_stage = options->stage;
		else if (options->stage_kind == PLUME_STAGE_UNFURL)
			def.unfurl_weight = options->stage;
	}
	status = plume_spec_check_feather_bytes(
	    file, plume_zk_estimate_bytes(&def), options, err,
	    "$.barb_count (%d) and the barbs still growing ($.collar.radius or $.collar.points, $.barb_speed, "
	    "$.emitter_speed, $.ridge_width) x their points ($.step %g, $.downsample %d%s)",
	    def.barb_count, def.step, def.downsample, def.expansion && def.keep_barbules ? ", barbules kept" : "");
	if (status != PLUME_OK)
		return status;
	status = plume_zk_generate(&def, seed, out, NULL, err);
	if (status != PLUME_OK && status != PLUME_ERROR_MEMORY)
		plume_error_prefix(err, file);
	return status;
}

// Coat specs ("model": "coat", docs/coats.md): a surface, a follicle layout,
// key feathers (streit-heidrich specs, inline or files) and their placement.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/alloc.h"
#include "../model/coat_internal.h"
#include "plume/mesh.h"
#include "spec.h"
#include "spec_streit_heidrich.h"

#define PI 3.14159265358979323846

static const char *const top_keys[] = {"model", "seed",      "description", "surface", "follicles",     "key_feathers",
                                       "power", "direction", "lift_deg",    "lod",     "interpolation", NULL};
static const char *const surface_keys[] = {"type", "size", "centre", "radius", "obj", NULL};
static const char *const follicle_keys[] = {"layout", "spacing", "spacing_gradient", NULL};
static const char *const gradient_keys[] = {"from", "to", "factor", NULL};
static const char *const key_keys[] = {"at", "feather", NULL};
static const char *const direction_keys[] = {"along", "towards", NULL};
static const char *const lod_keys[] = {"barb_elevations", "rachis_elevations", "calamus_samples", NULL};

/// A point [x, y, z] or [x, y] (z = 0), m. False when absent.
static bool read_point(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       plume_vec3 *out)
{
	const json_t *value = reader->status == PLUME_OK ? json_object_get(object, key) : NULL;
	if (value == NULL)
		return false;
	char child[512];
	plume_spec_path(child, sizeof child, path, key);
	size_t n = json_is_array(value) ? json_array_size(value) : 0;
	double c[3] = {0, 0, 0};
	bool ok = n == 2 || n == 3;
	for (size_t i = 0; i < n && ok; ++i) {
		ok = json_is_number(json_array_get(value, i));
		if (ok)
			c[i] = json_number_value(json_array_get(value, i));
	}
	if (!ok) {
		plume_spec_fail(reader, child, "expected a point [x, y, z] in metres");
		return false;
	}
	*out = plume_v3(c[0], c[1], c[2]);
	return true;
}

static void require(plume_spec_reader *reader, bool present, const char *path, const char *key, const char *what)
{
	if (!present && reader->status == PLUME_OK) {
		char child[512];
		plume_spec_path(child, sizeof child, path, key);
		plume_spec_fail(reader, child, "missing; %s", what);
	}
}

static void positive(plume_spec_reader *reader, double value, const char *path)
{
	if (reader->status == PLUME_OK && !(value > 0.0 && isfinite(value)))
		plume_spec_fail(reader, path, "is %g, must be a positive length in metres", value);
}

static plume_status read_surface(plume_spec_reader *reader, const char *file, const json_t *root, coat_def *def,
                                 plume_error *err)
{
	const char *path = "$.surface";
	const json_t *surface = plume_spec_object(reader, root, "$", "surface");
	require(reader, surface != NULL, "$", "surface", "a coat needs a surface: plane, sphere or mesh");
	if (reader->status != PLUME_OK)
		return reader->status;
	plume_spec_check_keys(reader, surface, path, surface_keys);
	const char *type = NULL;
	require(reader, plume_spec_string(reader, surface, path, "type", &type), path, "type",
	        "one of plane, sphere, mesh");
	if (reader->status != PLUME_OK)
		return reader->status;
	if (strcmp(type, "plane") == 0) {
		def->surface = COAT_SURFACE_PLANE;
		plume_vec3 size = {0, 0, 0};
		require(reader, read_point(reader, surface, path, "size", &size), path, "size",
		        "the plane's size [width, height] in metres");
		def->plane_size[0] = size.x;
		def->plane_size[1] = size.y;
		positive(reader, size.x, "$.surface.size[0]");
		positive(reader, size.y, "$.surface.size[1]");
	} else if (strcmp(type, "sphere") == 0) {
		def->surface = COAT_SURFACE_SPHERE;
		def->sphere_centre = plume_v3(0, 0, 0);
		read_point(reader, surface, path, "centre", &def->sphere_centre);
		require(reader, plume_spec_number(reader, surface, path, "radius", &def->sphere_radius), path, "radius",
		        "the sphere's radius in metres");
		positive(reader, def->sphere_radius, "$.surface.radius");
	} else if (strcmp(type, "mesh") == 0) {
		def->surface = COAT_SURFACE_MESH;
		const char *obj = NULL;
		require(reader, plume_spec_string(reader, surface, path, "obj", &obj), path, "obj",
		        "the triangle mesh's OBJ file, relative to the coat spec");
		if (reader->status != PLUME_OK)
			return reader->status;
		char mesh_path[4096];
		plume_spec_relative_path(mesh_path, sizeof mesh_path, file, obj);
		plume_status status = plume_mesh_read_obj(mesh_path, &def->mesh, err);
		if (status != PLUME_OK) {
			char prefix[600];
			snprintf(prefix, sizeof prefix, "%s: $.surface.obj", file);
			plume_error_prefix(err, prefix);
			return reader->status = status;
		}
	} else {
		static const char *const types[] = {"plane", "sphere", "mesh", NULL};
		plume_spec_fail(reader, "$.surface.type", "unknown surface \"%s\"; did you mean \"%s\"? (plane, sphere, mesh)",
		                type, plume_spec_nearest(type, types));
	}
	return reader->status;
}

static void read_follicles(plume_spec_reader *reader, const json_t *root, coat_def *def)
{
	const char *path = "$.follicles";
	const json_t *object = plume_spec_object(reader, root, "$", "follicles");
	require(reader, object != NULL, "$", "follicles", "{\"layout\": \"hexagonal\" or \"poisson\", \"spacing\": m}");
	if (reader->status != PLUME_OK)
		return;
	plume_spec_check_keys(reader, object, path, follicle_keys);
	const char *layout = "hexagonal";
	plume_spec_string(reader, object, path, "layout", &layout);
	if (reader->status == PLUME_OK) {
		if (strcmp(layout, "hexagonal") == 0)
			def->layout = COAT_LAYOUT_HEXAGONAL;
		else if (strcmp(layout, "poisson") == 0)
			def->layout = COAT_LAYOUT_POISSON;
		else
			plume_spec_fail(reader, "$.follicles.layout", "unknown layout \"%s\" (allowed: hexagonal, poisson)",
			                layout);
	}
	require(reader, plume_spec_number(reader, object, path, "spacing", &def->spacing), path, "spacing",
	        "the distance between follicles in metres");
	positive(reader, def->spacing, "$.follicles.spacing");
	def->spacing_factor = 1.0;
	const json_t *gradient = plume_spec_object(reader, object, path, "spacing_gradient");
	if (gradient != NULL && reader->status == PLUME_OK) {
		const char *gpath = "$.follicles.spacing_gradient";
		plume_spec_check_keys(reader, gradient, gpath, gradient_keys);
		require(reader, read_point(reader, gradient, gpath, "from", &def->spacing_from), gpath, "from", "a point");
		require(reader, read_point(reader, gradient, gpath, "to", &def->spacing_to), gpath, "to", "a point");
		require(reader, plume_spec_number(reader, gradient, gpath, "factor", &def->spacing_factor), gpath, "factor",
		        "the spacing at \"to\" over the spacing at \"from\"");
		if (reader->status == PLUME_OK && !(def->spacing_factor >= 0.1 && def->spacing_factor <= 10.0))
			plume_spec_fail(reader, "$.follicles.spacing_gradient.factor", "is %g, allowed [0.1, 10]",
			                def->spacing_factor);
		if (reader->status == PLUME_OK && def->layout != COAT_LAYOUT_POISSON)
			plume_spec_fail(reader, gpath, "a varying density needs \"layout\": \"poisson\"");
	}
	if (reader->status == PLUME_OK && def->layout == COAT_LAYOUT_HEXAGONAL && def->surface == COAT_SURFACE_MESH)
		plume_spec_fail(reader, "$.follicles.layout",
		                "a hexagonal layout needs a plane or a sphere; use \"poisson\" on a mesh");
}

static plume_status read_key_feather(plume_spec_reader *reader, const char *file, const json_t *value, const char *path,
                                     plume_sh_def *def, uint64_t *seed, plume_error *err)
{
	char child[512];
	plume_spec_path(child, sizeof child, path, "feather");
	if (json_is_string(value)) {
		char other[4096];
		plume_spec_relative_path(other, sizeof other, file, json_string_value(value));
		json_t *root = plume_spec_load(other, err);
		if (root == NULL)
			return reader->status = err != NULL ? err->status : PLUME_ERROR_IO;
		plume_spec_reader inner = plume_spec_reader_begin(other, err);
		const char *model = NULL;
		if (!json_is_object(root))
			plume_spec_fail(&inner, "$", "expected a streit-heidrich spec object");
		else if (plume_spec_string(&inner, root, "$", "model", &model) && strcmp(model, "streit-heidrich") != 0)
			plume_spec_fail(&inner, "$.model",
			                "\"%s\": coat key feathers are streit-heidrich feathers (their parameters interpolate)",
			                model);
		plume_status status = inner.status;
		if (status == PLUME_OK)
			status = plume_sh_def_from_json(other, root, "$", def, seed, NULL, 0, err);
		json_decref(root);
		return reader->status = status;
	}
	if (!json_is_object(value)) {
		plume_spec_fail(reader, child, "expected a streit-heidrich spec file name or an inline spec object");
		return reader->status;
	}
	const char *model = NULL;
	if (plume_spec_string(reader, value, child, "model", &model) && strcmp(model, "streit-heidrich") != 0) {
		char model_path[600];
		plume_spec_path(model_path, sizeof model_path, child, "model");
		plume_spec_fail(reader, model_path, "\"%s\": coat key feathers are streit-heidrich feathers", model);
		return reader->status;
	}
	// An inline spec is part of the coat's file: its messages name where it sits in it.
	return reader->status = plume_sh_def_from_json(file, value, child, def, seed, NULL, 0, err);
}

static void read_keys(plume_spec_reader *reader, const char *file, const json_t *root, coat_def *def, plume_error *err)
{
	const json_t *keys = plume_spec_array(reader, root, "$", "key_feathers");
	require(reader, keys != NULL, "$", "key_feathers", "a coat interpolates from 1 to 16 key feathers");
	if (reader->status != PLUME_OK)
		return;
	size_t n = json_array_size(keys);
	if (n < 1 || n > COAT_MAX_KEYS) {
		plume_spec_fail(reader, "$.key_feathers", "%zu key feathers, allowed [1, %d]", n, COAT_MAX_KEYS);
		return;
	}
	def->key_defs = plume_alloc(n * sizeof *def->key_defs);
	if (def->key_defs == NULL) {
		reader->status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
		return;
	}
	def->key_count = (int)n;
	for (size_t k = 0; k < n && reader->status == PLUME_OK; ++k) {
		char path[64];
		plume_spec_index_path(path, sizeof path, "$.key_feathers", k);
		const json_t *item = json_array_get(keys, k);
		if (!json_is_object(item)) {
			plume_spec_fail(reader, path, "expected {\"at\": [x, y, z], \"feather\": spec}");
			return;
		}
		plume_spec_check_keys(reader, item, path, key_keys);
		require(reader, read_point(reader, item, path, "at", &def->key_at[k]), path, "at",
		        "where the key feather grows, [x, y, z] in metres (the nearest follicle takes it)");
		const json_t *feather = reader->status == PLUME_OK ? json_object_get(item, "feather") : NULL;
		require(reader, feather != NULL, path, "feather", "a streit-heidrich spec file or an inline spec");
		if (reader->status == PLUME_OK)
			read_key_feather(reader, file, feather, path, &def->key_defs[k], &def->key_seeds[k], err);
	}
}

static void read_placement(plume_spec_reader *reader, const json_t *root, coat_def *def)
{
	def->direction_towards = false;
	def->direction_vector = plume_v3(0.0, 1.0, 0.0);
	const json_t *direction = plume_spec_object(reader, root, "$", "direction");
	if (direction != NULL && reader->status == PLUME_OK) {
		plume_spec_check_keys(reader, direction, "$.direction", direction_keys);
		bool along = read_point(reader, direction, "$.direction", "along", &def->direction_vector);
		bool towards = read_point(reader, direction, "$.direction", "towards", &def->direction_point);
		if (reader->status == PLUME_OK && along == towards)
			plume_spec_fail(reader, "$.direction",
			                "give \"along\": [x, y, z] or \"towards\": [x, y, z] (a tail point)");
		def->direction_towards = towards;
		if (along && !(plume_v3_length(def->direction_vector) > 0.0))
			plume_spec_fail(reader, "$.direction.along", "must not be the zero vector");
	}
	double lift_deg = 15.0;
	plume_spec_number(reader, root, "$", "lift_deg", &lift_deg);
	if (reader->status == PLUME_OK && !(lift_deg > 0.0 && lift_deg <= 90.0))
		plume_spec_fail(reader, "$.lift_deg", "is %g, allowed (0, 90]: feathers leave the surface on its outer side",
		                lift_deg);
	def->lift = lift_deg * PI / 180.0;
	const char *interpolation = NULL;
	def->weighting = COAT_WEIGHTS_AUTO;
	if (plume_spec_string(reader, root, "$", "interpolation", &interpolation)) {
		static const char *const names[] = {"auto", "bilinear", "barycentric", "inverse-distance", NULL};
		int found = -1;
		for (int i = 0; names[i] != NULL; ++i)
			if (strcmp(interpolation, names[i]) == 0)
				found = i;
		if (found < 0)
			plume_spec_fail(reader, "$.interpolation", "unknown \"%s\"; did you mean \"%s\"? (%s)", interpolation,
			                plume_spec_nearest(interpolation, names), "auto, bilinear, barycentric, inverse-distance");
		else
			def->weighting = (coat_weighting)found;
	}
	def->power = 2.0;
	plume_spec_number(reader, root, "$", "power", &def->power);
	if (reader->status == PLUME_OK && !(def->power > 0.0 && def->power <= 16.0))
		plume_spec_fail(reader, "$.power", "is %g, allowed (0, 16]", def->power);
	if (reader->status != PLUME_OK)
		return;
	if (def->weighting == COAT_WEIGHTS_BILINEAR && def->key_count != 4)
		plume_spec_fail(reader, "$.interpolation",
		                "bilinear interpolation needs 4 key feathers (a quadrilateral, 4.4), got %d", def->key_count);
	if (def->weighting == COAT_WEIGHTS_BARYCENTRIC && def->key_count != 3)
		plume_spec_fail(reader, "$.interpolation", "barycentric interpolation needs 3 key feathers, got %d",
		                def->key_count);
}

static void read_lod(plume_spec_reader *reader, const json_t *root, plume_sh_lod *lod)
{
	*lod = plume_sh_default_lod();
	const json_t *object = plume_spec_object(reader, root, "$", "lod");
	if (object == NULL)
		return;
	plume_spec_check_keys(reader, object, "$.lod", lod_keys);
	plume_spec_int(reader, object, "$.lod", "barb_elevations", &lod->barb_elevations);
	plume_spec_int(reader, object, "$.lod", "rachis_elevations", &lod->rachis_elevations);
	plume_spec_int(reader, object, "$.lod", "calamus_samples", &lod->calamus_samples);
}

plume_status plume_coat_spec_generate(const char *path, const plume_spec_options *options, plume_coat **out,
                                      plume_error *err)
{
	*out = NULL;
	json_t *root = plume_spec_load(path, err);
	if (root == NULL)
		return err != NULL ? err->status : PLUME_ERROR_IO;
	coat_def def;
	memset(&def, 0, sizeof def);
	def.seed = 1;
	def.stage = 1.0;
	plume_spec_reader reader = plume_spec_reader_begin(path, err);
	const char *model = NULL;
	if (!json_is_object(root))
		plume_spec_fail(&reader, "$", "expected an object with \"model\": \"coat\"");
	else if (!plume_spec_string(&reader, root, "$", "model", &model) && reader.status == PLUME_OK)
		plume_spec_fail(&reader, "$.model", "missing; a coat spec has \"model\": \"coat\"");
	else if (model != NULL && strcmp(model, "coat") != 0)
		plume_spec_fail(&reader, "$.model", "\"%s\" is a feather model; plume coat reads \"model\": \"coat\"", model);
	if (options != NULL && options->stage_kind == PLUME_STAGE_UNFURL && reader.status == PLUME_OK)
		reader.status = plume_error_set(err, PLUME_ERROR_UNSUPPORTED, "%s: coats grow but do not unfurl", path);
	if (options != NULL && options->stage_kind == PLUME_STAGE_GROWTH)
		def.stage = options->stage;
	plume_spec_check_keys(&reader, root, "$", top_keys);
	plume_spec_uint64(&reader, root, "$", "seed", &def.seed);
	const char *description;
	plume_spec_string(&reader, root, "$", "description", &description);
	if (reader.status == PLUME_OK)
		read_surface(&reader, path, root, &def, err);
	read_follicles(&reader, root, &def);
	read_keys(&reader, path, root, &def, err);
	read_placement(&reader, root, &def);
	read_lod(&reader, root, &def.lod);
	if (options != NULL && options->seed_given)
		def.seed = options->seed;
	def.max_memory = options != NULL && options->max_memory > 0 ? options->max_memory : PLUME_DEFAULT_MAX_MEMORY;
	if (options != NULL) {
		def.progress = options->progress;
		def.progress_user = options->progress_user;
	}
	plume_status status = reader.status;
	if (status == PLUME_OK) {
		status = coat_build(&def, out, err);
		if (status != PLUME_OK && err != NULL && strncmp(err->message, path, strlen(path)) != 0)
			plume_error_prefix(err, path);
	}
	plume_mesh_destroy(def.mesh);
	plume_free(def.key_defs);
	json_decref(root);
	return status;
}

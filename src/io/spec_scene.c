// Scene specs (docs/scene.md): the feather, its mesh, materials, handles,
// forces and time stepping of a simulation.
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "plume/io.h"
#include "plume/scene.h"
#include "spec.h"
#include "spec_mesh.h"
#include "spec_models.h"

static const char *const top_keys[] = {
    "description", "feather", "guides",       "seed",     "mesh",        "materials", "handles", "forces", "gravity",
    "drag",        "bending", "time_step",    "duration", "frame_every", "quasi_static", "solver", "integrator", "air", "contact", NULL,
};
static const char *const material_keys[] = {
    "model",
    "E_vv",
    "E_ww",
    "E_vw",
    "youngs_modulus",
    "poisson_ratio",
    "thickness",
    "surface_density",
    "barb_constraint",
    "bending_along",
    "bending_across",
    "compression_coefficient",
    NULL,
};
static const char *const handle_keys[] = {"group", "near", "radius", "pivot", "interpolation", "keyframes", NULL};
static const char *const keyframe_keys[] = {"time", "translation", "rotation_axis", "rotation_deg", NULL};
static const char *const force_keys[] = {"group", "force", NULL};
static const char *const solver_keys[] = {"tolerance", "max_iterations", "max_substep_halvings", NULL};
static const char *const material_models[] = {"orthotropic", "isotropic", NULL};
static const char *const interpolations[] = {"linear", "smooth", NULL};
static const char *const integrators[] = {"implicit-euler", "bdf2", NULL};
static const char *const air_keys[] = {"density", "normal_drag", "tangential_drag", "centre_of_pressure", "wind",
                                       "gusts", "seed", NULL};
static const char *const gust_keys[] = {"speed", "length", "time", NULL};
/// Indexed by plume_bending_model.
static const char *const bending_models[] = {"fundamental-form", "paper-hinge", NULL};

/// An array of exactly n numbers.
static bool read_numbers(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                         double *out, int n)
{
	const json_t *array = plume_spec_array(reader, object, path, key);
	if (array == NULL)
		return false;
	char child[256];
	plume_spec_path(child, sizeof child, path, key);
	if ((int)json_array_size(array) != n) {
		plume_spec_fail(reader, child, "expected %d numbers, got %zu values", n, json_array_size(array));
		return false;
	}
	for (int i = 0; i < n; ++i) {
		const json_t *value = json_array_get(array, (size_t)i);
		if (!json_is_number(value)) {
			plume_spec_fail(reader, child, "element %d is not a number", i);
			return false;
		}
		out[i] = json_number_value(value);
		if (!isfinite(out[i])) {
			plume_spec_fail(reader, child, "element %d is not finite", i);
			return false;
		}
	}
	return true;
}

static bool read_vec3(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                      plume_vec3 *out)
{
	double v[3];
	if (!read_numbers(reader, object, path, key, v, 3))
		return false;
	*out = plume_v3(v[0], v[1], v[2]);
	return true;
}

static int word_index(plume_spec_reader *reader, const char *path, const char *word, const char *const *allowed)
{
	for (int i = 0; allowed[i] != NULL; ++i)
		if (strcmp(word, allowed[i]) == 0)
			return i;
	char list[256] = "";
	for (int i = 0; allowed[i] != NULL; ++i) {
		size_t used = strlen(list);
		snprintf(list + used, sizeof list - used, "%s%s", i > 0 ? ", " : "", allowed[i]);
	}
	plume_spec_fail(reader, path, "unknown value \"%s\"; did you mean \"%s\"? (allowed: %s)", word,
	                plume_spec_nearest(word, allowed), list);
	return -1;
}

static void read_material(plume_spec_reader *reader, const json_t *object, const char *path, plume_material *m)
{
	plume_spec_check_keys(reader, object, path, material_keys);
	const char *model = NULL;
	if (plume_spec_string(reader, object, path, "model", &model)) {
		char child[128];
		plume_spec_path(child, sizeof child, path, "model");
		int kind = word_index(reader, child, model, material_models);
		if (kind >= 0)
			m->kind = kind == 0 ? PLUME_MATERIAL_ORTHOTROPIC : PLUME_MATERIAL_ISOTROPIC;
	}
	plume_spec_number(reader, object, path, "E_vv", &m->E_vv);
	plume_spec_number(reader, object, path, "E_ww", &m->E_ww);
	plume_spec_number(reader, object, path, "E_vw", &m->E_vw);
	plume_spec_number(reader, object, path, "youngs_modulus", &m->youngs_modulus);
	plume_spec_number(reader, object, path, "poisson_ratio", &m->poisson_ratio);
	plume_spec_number(reader, object, path, "thickness", &m->thickness);
	plume_spec_number(reader, object, path, "surface_density", &m->surface_density);
	plume_spec_bool(reader, object, path, "barb_constraint", &m->barb_constraint);
	plume_spec_number(reader, object, path, "bending_along", &m->bending_along);
	plume_spec_number(reader, object, path, "bending_across", &m->bending_across);
	plume_spec_number(reader, object, path, "compression_coefficient", &m->compression_coefficient);
}

static void read_materials(plume_spec_reader *reader, const json_t *root, plume_sim_def *def)
{
	const json_t *materials = plume_spec_object(reader, root, "$", "materials");
	if (materials == NULL)
		return;
	static const char *const names[] = {"vane", "rachis", NULL};
	plume_spec_check_keys(reader, materials, "$.materials", names);
	for (int i = 0; i < 2; ++i) {
		const json_t *material = plume_spec_object(reader, materials, "$.materials", names[i]);
		char path[64];
		plume_spec_path(path, sizeof path, "$.materials", names[i]);
		if (material != NULL)
			read_material(reader, material, path, def->materials + i);
	}
}

static void read_solver(plume_spec_reader *reader, const json_t *root, plume_sim_def *def)
{
	const json_t *solver = plume_spec_object(reader, root, "$", "solver");
	if (solver == NULL)
		return;
	plume_spec_check_keys(reader, solver, "$.solver", solver_keys);
	plume_spec_number(reader, solver, "$.solver", "tolerance", &def->solver.tolerance);
	plume_spec_int(reader, solver, "$.solver", "max_iterations", &def->solver.max_iterations);
	plume_spec_int(reader, solver, "$.solver", "max_substep_halvings", &def->solver.max_substep_halvings);
}

/// The optional "contact" object (docs/scene.md, docs/contact.md): a scene that has one gets
/// contact unless it says "enabled": false; plume_sim_def_validate checks the ranges and names
/// $.contact.key in its message.
static void read_contact(plume_spec_reader *reader, const json_t *root, plume_sim_def *def)
{
	static const char *const keys[] = {"enabled",        "distance", "stiffness", "self_contact",
	                                   "ccd_separation", "friction", NULL};
	const json_t *contact = plume_spec_object(reader, root, "$", "contact");
	if (contact == NULL)
		return;
	plume_spec_check_keys(reader, contact, "$.contact", keys);
	def->contact.enabled = true;
	plume_spec_bool(reader, contact, "$.contact", "enabled", &def->contact.enabled);
	plume_spec_number(reader, contact, "$.contact", "distance", &def->contact.distance);
	plume_spec_number(reader, contact, "$.contact", "stiffness", &def->contact.stiffness);
	plume_spec_bool(reader, contact, "$.contact", "self_contact", &def->contact.self_contact);
	plume_spec_number(reader, contact, "$.contact", "ccd_separation", &def->contact.ccd_separation);
	plume_spec_number(reader, contact, "$.contact", "friction", &def->contact.friction);
}

/// "integrator" (a word) and "air" (docs/scene.md); plume_sim_def_validate checks the numbers.
static void read_dynamics(plume_spec_reader *reader, const json_t *root, plume_sim_def *def)
{
	const char *integrator = NULL;
	if (plume_spec_string(reader, root, "$", "integrator", &integrator)) {
		int which = word_index(reader, "$.integrator", integrator, integrators);
		if (which >= 0)
			def->integrator = (plume_integrator)which;
	}
	const json_t *air = plume_spec_object(reader, root, "$", "air");
	if (air == NULL)
		return;
	plume_spec_check_keys(reader, air, "$.air", air_keys);
	def->air.density = 1.2; // a scene that asks for air gets air at sea level unless it says otherwise
	plume_spec_number(reader, air, "$.air", "density", &def->air.density);
	plume_spec_number(reader, air, "$.air", "normal_drag", &def->air.normal_drag);
	plume_spec_number(reader, air, "$.air", "tangential_drag", &def->air.tangential_drag);
	plume_spec_bool(reader, air, "$.air", "centre_of_pressure", &def->air.centre_of_pressure);
	read_vec3(reader, air, "$.air", "wind", &def->air.wind);
	plume_spec_uint64(reader, air, "$.air", "seed", &def->air.seed);
	const json_t *gusts = plume_spec_object(reader, air, "$.air", "gusts");
	if (gusts == NULL)
		return;
	plume_spec_check_keys(reader, gusts, "$.air.gusts", gust_keys);
	plume_spec_number(reader, gusts, "$.air.gusts", "speed", &def->air.gust_speed);
	plume_spec_number(reader, gusts, "$.air.gusts", "length", &def->air.gust_length);
	plume_spec_number(reader, gusts, "$.air.gusts", "time", &def->air.gust_time);
}

static void read_keyframes(plume_spec_reader *reader, const json_t *array, const char *path, plume_scene_handle *handle)
{
	size_t count = json_array_size(array);
	handle->keyframes = plume_calloc(count > 0 ? count : 1, sizeof(plume_keyframe));
	if (handle->keyframes == NULL) {
		plume_spec_fail(reader, path, "out of memory");
		return;
	}
	for (size_t k = 0; k < count && reader->status == PLUME_OK; ++k) {
		char key_path[128];
		plume_spec_index_path(key_path, sizeof key_path, path, k);
		const json_t *object = json_array_get(array, k);
		if (!json_is_object(object)) {
			plume_spec_fail(reader, key_path, "expected an object {\"time\", \"translation\", ...}");
			return;
		}
		plume_keyframe *key = handle->keyframes + k;
		key->axis = plume_v3(0, 0, 1);
		plume_spec_check_keys(reader, object, key_path, keyframe_keys);
		char time_path[160];
		plume_spec_path(time_path, sizeof time_path, key_path, "time");
		if (!plume_spec_number(reader, object, key_path, "time", &key->time) && reader->status == PLUME_OK)
			plume_spec_fail(reader, time_path, "missing; every keyframe has a time in seconds");
		else if (reader->status == PLUME_OK && (key->time < 0 || (k > 0 && key->time <= key[-1].time)))
			plume_spec_fail(reader, time_path, "is %g; keyframe times must be >= 0 and increasing", key->time);
		read_vec3(reader, object, key_path, "translation", &key->translation);
		read_vec3(reader, object, key_path, "rotation_axis", &key->axis);
		double degrees = 0;
		plume_spec_number(reader, object, key_path, "rotation_deg", &degrees);
		key->angle = degrees * acos(-1.0) / 180;
		if (reader->status == PLUME_OK && key->angle != 0 && plume_v3_length(key->axis) == 0) {
			char axis_path[160];
			plume_spec_path(axis_path, sizeof axis_path, key_path, "rotation_axis");
			plume_spec_fail(reader, axis_path, "is the zero vector; a rotation needs an axis");
		}
		handle->keyframe_count = (int)k + 1;
	}
}

static bool group_exists(const plume_mesh *mesh, const char *name) { return plume_mesh_find_group(mesh, name) != NULL; }

static void unknown_group(plume_spec_reader *reader, const char *path, const char *name, const plume_mesh *mesh)
{
	char list[512] = "";
	const char *names[64];
	int count = mesh->group_count < 63 ? mesh->group_count : 63;
	for (int g = 0; g < count; ++g) {
		names[g] = mesh->groups[g].name;
		size_t used = strlen(list);
		snprintf(list + used, sizeof list - used, "%s%s", g > 0 ? ", " : "", names[g]);
	}
	names[count] = NULL;
	plume_spec_fail(reader, path, "unknown vertex group \"%s\"; did you mean \"%s\"? (the mesh has: %s)", name,
	                count > 0 ? plume_spec_nearest(name, names) : "", list);
}

/// Adds the group of the vertices of the handle's group within radius of near, named "handle N".
static void add_near_group(plume_spec_reader *reader, const char *path, plume_mesh *mesh, plume_scene_handle *handle,
                           int index)
{
	char name[32];
	snprintf(name, sizeof name, "handle %d", index);
	plume_error local = {0};
	if (plume_mesh_add_group_near(mesh, name, handle->group, handle->near, handle->radius, &local) != PLUME_OK) {
		plume_spec_fail(reader, path, "%s", local.message);
		return;
	}
	snprintf(handle->source_group, sizeof handle->source_group, "%s", handle->group);
	snprintf(handle->group, sizeof handle->group, "%s", name);
}

static void read_handles(plume_spec_reader *reader, const json_t *root, plume_scene *scene)
{
	const json_t *array = plume_spec_array(reader, root, "$", "handles");
	if (array == NULL)
		return;
	size_t count = json_array_size(array);
	scene->handles = plume_calloc(count > 0 ? count : 1, sizeof(plume_scene_handle));
	if (scene->handles == NULL) {
		plume_spec_fail(reader, "$.handles", "out of memory");
		return;
	}
	for (size_t h = 0; h < count && reader->status == PLUME_OK; ++h) {
		char path[64];
		plume_spec_index_path(path, sizeof path, "$.handles", h);
		const json_t *object = json_array_get(array, h);
		if (!json_is_object(object)) {
			plume_spec_fail(reader, path, "expected an object {\"group\": ..., \"keyframes\": [...]}");
			return;
		}
		plume_scene_handle *handle = scene->handles + h;
		scene->handle_count = (int)h + 1;
		plume_spec_check_keys(reader, object, path, handle_keys);
		const char *group = NULL;
		char group_path[96];
		plume_spec_path(group_path, sizeof group_path, path, "group");
		if (!plume_spec_string(reader, object, path, "group", &group)) {
			if (reader->status == PLUME_OK)
				plume_spec_fail(reader, group_path, "missing; a handle holds a vertex group");
			return;
		}
		if (!group_exists(scene->mesh, group)) {
			unknown_group(reader, group_path, group, scene->mesh);
			return;
		}
		snprintf(handle->group, sizeof handle->group, "%s", group);
		double near[2];
		handle->radius = 0;
		if (read_numbers(reader, object, path, "near", near, 2)) {
			handle->near_given = true;
			handle->near = (plume_vec2){near[0], near[1]};
			char radius_path[96];
			plume_spec_path(radius_path, sizeof radius_path, path, "radius");
			if (!plume_spec_number(reader, object, path, "radius", &handle->radius) && reader->status == PLUME_OK)
				plume_spec_fail(reader, radius_path, "missing; \"near\" selects vertices within a radius (m)");
			else if (reader->status == PLUME_OK && !(handle->radius > 0))
				plume_spec_fail(reader, radius_path, "is %g, allowed > 0", handle->radius);
			if (reader->status == PLUME_OK)
				add_near_group(reader, path, scene->mesh, handle, (int)h);
		}
		read_vec3(reader, object, path, "pivot", &handle->pivot);
		const char *interpolation = NULL;
		if (plume_spec_string(reader, object, path, "interpolation", &interpolation)) {
			char child[96];
			plume_spec_path(child, sizeof child, path, "interpolation");
			int which = word_index(reader, child, interpolation, interpolations);
			handle->interpolation = which == 1 ? PLUME_INTERPOLATION_SMOOTH : PLUME_INTERPOLATION_LINEAR;
		}
		const json_t *keyframes = plume_spec_array(reader, object, path, "keyframes");
		if (keyframes != NULL) {
			char key_path[96];
			plume_spec_path(key_path, sizeof key_path, path, "keyframes");
			read_keyframes(reader, keyframes, key_path, handle);
		}
	}
}

static void read_forces(plume_spec_reader *reader, const json_t *root, plume_scene *scene)
{
	const json_t *array = plume_spec_array(reader, root, "$", "forces");
	if (array == NULL)
		return;
	size_t count = json_array_size(array);
	scene->forces = plume_calloc(count > 0 ? count : 1, sizeof(plume_scene_force));
	if (scene->forces == NULL) {
		plume_spec_fail(reader, "$.forces", "out of memory");
		return;
	}
	for (size_t i = 0; i < count && reader->status == PLUME_OK; ++i) {
		char path[64], group_path[96];
		plume_spec_index_path(path, sizeof path, "$.forces", i);
		plume_spec_path(group_path, sizeof group_path, path, "group");
		const json_t *object = json_array_get(array, i);
		if (!json_is_object(object)) {
			plume_spec_fail(reader, path, "expected an object {\"group\": ..., \"force\": [x, y, z]}");
			return;
		}
		plume_spec_check_keys(reader, object, path, force_keys);
		const char *group = NULL;
		if (!plume_spec_string(reader, object, path, "group", &group)) {
			if (reader->status == PLUME_OK)
				plume_spec_fail(reader, group_path, "missing");
			return;
		}
		if (!group_exists(scene->mesh, group)) {
			unknown_group(reader, group_path, group, scene->mesh);
			return;
		}
		snprintf(scene->forces[i].group, sizeof scene->forces[i].group, "%s", group);
		read_vec3(reader, object, path, "force", &scene->forces[i].force);
		scene->force_count = (int)i + 1;
	}
}

/// Generates (or reads) the feather named by "feather": a generator spec inline or by path
/// (relative to the scene), or a feather written by `plume generate --format json`.
static plume_status load_feather(const char *file, const json_t *root, const plume_spec_options *options,
                                 plume_feather **out, plume_error *err)
{
	const json_t *value = json_object_get(root, "feather");
	if (json_is_object(value))
		return plume_spec_generate_json(file, value, options, out, err);
	if (!json_is_string(value))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s: $.feather: expected a feather spec (an object) or the path of one", file);
	const char *name = json_string_value(value);
	char path[4096];
	if (name[0] == '/') {
		snprintf(path, sizeof path, "%s", name);
	} else {
		char copy[4096];
		snprintf(copy, sizeof copy, "%s", file);
		snprintf(path, sizeof path, "%s/%s", dirname(copy), name);
	}
	json_t *spec = plume_spec_load(path, err);
	if (spec == NULL) {
		plume_error_prefix(err, file);
		return err != NULL ? err->status : PLUME_ERROR_IO;
	}
	plume_status status = json_object_get(spec, "model") != NULL
	                          ? plume_spec_generate_json(path, spec, options, out, err)
	                          : plume_read_json(path, out, err);
	json_decref(spec);
	return status;
}

static plume_status build_mesh(const char *file, const json_t *root, const plume_spec_options *options,
                               plume_scene *scene, plume_error *err)
{
	plume_spec_reader reader = plume_spec_reader_begin(file, err);
	plume_mesh_def mesh_def = plume_mesh_default_def();
	mesh_def.max_memory = options != NULL ? options->max_memory : 0;
	const json_t *mesh = plume_spec_object(&reader, root, "$", "mesh");
	if (mesh != NULL)
		plume_spec_mesh_def(&reader, mesh, "$.mesh", &mesh_def);
	const json_t *feather = json_object_get(root, "feather"), *guides = plume_spec_object(&reader, root, "$", "guides");
	if (reader.status != PLUME_OK)
		return reader.status;
	if ((feather == NULL) == (guides == NULL))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s: $: a scene needs exactly one of \"feather\" (a feather spec) or \"guides\"", file);
	plume_status status;
	if (feather != NULL) {
		status = load_feather(file, root, options, &scene->feather, err);
		if (status == PLUME_OK)
			status = plume_mesh_from_feather(scene->feather, &mesh_def, &scene->mesh, &scene->mesh_report, err);
	} else {
		plume_mesh_guides_storage storage;
		status = plume_spec_mesh_guides(&reader, guides, "$.guides", &storage);
		if (status == PLUME_OK) {
			status = plume_mesh_from_guides(&storage.guides, &mesh_def, &scene->mesh, &scene->mesh_report, err);
			plume_mesh_guides_storage_free(&storage);
		}
	}
	if (status != PLUME_OK && err != NULL && strncmp(err->message, file, strlen(file)) != 0)
		plume_error_prefix(err, file);
	return status;
}

static plume_status scene_from_json(const char *path, json_t *root, const plume_spec_options *options,
                                    plume_scene **out, plume_error *err);

plume_status plume_scene_load(const char *path, const plume_spec_options *options, plume_scene **out, plume_error *err)
{
	*out = NULL;
	json_t *root = plume_spec_load(path, err);
	if (root == NULL)
		return err != NULL ? err->status : PLUME_ERROR_IO;
	return scene_from_json(path, root, options, out, err);
}

plume_status plume_scene_parse(const char *text, const char *name, const plume_spec_options *options, plume_scene **out,
                               plume_error *err)
{
	*out = NULL;
	json_error_t error;
	json_t *root = json_loads(text, JSON_REJECT_DUPLICATES, &error);
	if (root == NULL)
		return plume_error_set(err, PLUME_ERROR_SYNTAX, "%s:%d:%d: %s", name, error.line, error.column, error.text);
	plume_status status = plume_spec_check_numbers(name, root, err);
	if (status != PLUME_OK) {
		json_decref(root);
		return status;
	}
	return scene_from_json(name, root, options, out, err);
}

/// "bending": true or false (on or off), or the model's name (on, that model).
static void read_bending(plume_spec_reader *reader, const json_t *root, plume_sim_def *def)
{
	const json_t *value = json_object_get(root, "bending");
	if (value == NULL || json_is_boolean(value)) {
		plume_spec_bool(reader, root, "$", "bending", &def->bending);
		return;
	}
	const char *name;
	if (!plume_spec_string(reader, root, "$", "bending", &name))
		return;
	int model = word_index(reader, "$.bending", name, bending_models);
	if (model >= 0)
		def->bending_model = (plume_bending_model)model;
}

/// Reads the scene and releases root.
static plume_status scene_from_json(const char *path, json_t *root, const plume_spec_options *options,
                                    plume_scene **out, plume_error *err)
{
	plume_scene *scene = plume_calloc(1, sizeof *scene);
	if (scene == NULL) {
		json_decref(root);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory reading %s", path);
	}
	scene->sim = plume_sim_default_def();
	scene->duration = 1;
	scene->frame_every = 1;

	plume_spec_reader reader = plume_spec_reader_begin(path, err);
	plume_spec_options feather_options = options != NULL ? *options : (plume_spec_options){0};
	if (!json_is_object(root))
		plume_spec_fail(&reader, "$", "expected an object (a scene)");
	plume_spec_check_keys(&reader, root, "$", top_keys);
	if (!feather_options.seed_given && plume_spec_uint64(&reader, root, "$", "seed", &feather_options.seed))
		feather_options.seed_given = true;
	read_materials(&reader, root, &scene->sim);
	read_vec3(&reader, root, "$", "gravity", &scene->sim.gravity);
	plume_spec_number(&reader, root, "$", "drag", &scene->sim.drag);
	read_bending(&reader, root, &scene->sim);
	plume_spec_number(&reader, root, "$", "time_step", &scene->sim.time_step);
	plume_spec_number(&reader, root, "$", "duration", &scene->duration);
	plume_spec_int(&reader, root, "$", "frame_every", &scene->frame_every);
	plume_spec_bool(&reader, root, "$", "quasi_static", &scene->quasi_static);
	read_solver(&reader, root, &scene->sim);
	read_dynamics(&reader, root, &scene->sim);
	read_contact(&reader, root, &scene->sim);
	if (reader.status == PLUME_OK && !(scene->duration > 0 && isfinite(scene->duration)))
		plume_spec_fail(&reader, "$.duration", "is %g, allowed > 0 (seconds)", scene->duration);
	if (reader.status == PLUME_OK && scene->frame_every < 1)
		plume_spec_fail(&reader, "$.frame_every", "is %d, allowed >= 1", scene->frame_every);
	plume_status status = reader.status;
	if (status == PLUME_OK) {
		status = plume_sim_def_validate(&scene->sim, 0, err);
		if (status != PLUME_OK)
			plume_error_prefix(err, path);
	}
	// The step count is an int in the run loop and in summary.json: a tiny step over a long
	// duration overflowed it (1e9 s in steps of 1e-9 s ran 0 steps and reported success).
	if (status == PLUME_OK && !(scene->duration / scene->sim.time_step <= PLUME_SCENE_MAX_STEPS)) {
		plume_spec_fail(&reader, "$.duration",
		                "%g s in steps of %g s ($.time_step) is %.3g steps; allowed at most %.0e", scene->duration,
		                scene->sim.time_step, scene->duration / scene->sim.time_step, (double)PLUME_SCENE_MAX_STEPS);
		status = reader.status;
	}
	if (status == PLUME_OK)
		status = build_mesh(path, root, &feather_options, scene, err);
	if (status == PLUME_OK) {
		read_handles(&reader, root, scene);
		read_forces(&reader, root, scene);
		status = reader.status;
	}
	json_decref(root);
	if (status != PLUME_OK) {
		plume_scene_destroy(scene);
		return status;
	}
	*out = scene;
	return PLUME_OK;
}

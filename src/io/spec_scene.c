// Scene specs (docs/scene.md): the feather, its mesh, materials, handles,
// forces and time stepping of a simulation.
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../model/feather_internal.h"
#include "core/alloc.h"
#include "plume/body.h"
#include "plume/coat.h"
#include "plume/intersect.h"
#include "plume/io.h"
#include "plume/scene.h"
#include "sim/scene_contact.h"
#include "spec.h"
#include "spec_body.h"
#include "spec_mesh.h"
#include "spec_models.h"

static const char *const top_keys[] = {
    "description", "feather",    "feathers", "guides",       "seed",      "mesh",     "materials",   "handles",
    "forces",      "gravity",    "drag",     "bending",      "time_step", "duration", "frame_every", "quasi_static",
    "solver",      "integrator", "air",      "cycle_period", "body",      "contact",  NULL,
};
static const char *const feather_entry_keys[] = {
    "shaft", "front", "name", "feather", "coat", "mesh", "position", "rotation_axis", "rotation_deg", "follicle", NULL};
static const char *const follicle_keys[] = {"bone", "nearest_bone", NULL};
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
static const char *const air_keys[] = {
    "density", "normal_drag", "tangential_drag", "centre_of_pressure", "wind", "gusts", "seed", NULL};
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
	// A modulus of the other model was ignored, unchecked (an orthotropic vane took "poisson_ratio":
	// -0.5 and ran on its E_ww, E_vw): the model was likely left out.
	static const char *const orthotropic_only[] = {"E_vv", "E_ww", "E_vw", NULL};
	static const char *const isotropic_only[] = {"youngs_modulus", "poisson_ratio", NULL};
	bool orthotropic = m->kind == PLUME_MATERIAL_ORTHOTROPIC;
	const char *const *unused = orthotropic ? isotropic_only : orthotropic_only;
	for (int k = 0; unused[k] != NULL && reader->status == PLUME_OK; ++k)
		if (json_object_get(object, unused[k]) != NULL) {
			char child[128];
			plume_spec_path(child, sizeof child, path, unused[k]);
			plume_spec_fail(reader, child,
			                "belongs to the %s model, and this material is %s; set \"model\": \"%s\", or leave "
			                "the key out",
			                orthotropic ? "isotropic" : "orthotropic", orthotropic ? "orthotropic" : "isotropic",
			                orthotropic ? "isotropic" : "orthotropic");
		}
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
	// A stiffness given is an explicit override of the adaptive one (docs/contact.md).
	if (plume_spec_number(reader, contact, "$.contact", "stiffness", &def->contact.stiffness))
		def->contact.adaptive_stiffness = false;
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
		} else if (reader->status == PLUME_OK && json_object_get(object, "radius") != NULL) {
			// Alone it selected nothing: the whole group was held.
			char radius_path[96];
			plume_spec_path(radius_path, sizeof radius_path, path, "radius");
			plume_spec_fail(reader, radius_path,
			                "given without \"near\"; a radius selects the group's vertices within it of a point "
			                "[x, y] of the reference plane (give both, or neither to hold the whole group)");
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

/// The group a handle was given as in the scene (a "near" selection's source group).
static const char *handle_given_group(const plume_scene_handle *handle)
{
	return handle->source_group[0] != '\0' ? handle->source_group : handle->group;
}

/// A vertex follows one handle: two handles that share a vertex were resolved by the later one
/// (its target overwrote the earlier's, and both reported its reaction).
static void check_handle_overlap(plume_spec_reader *reader, const plume_scene *scene)
{
	if (reader->status != PLUME_OK || scene->handle_count < 2)
		return;
	int *owner = plume_alloc(sizeof(int) * (size_t)scene->mesh->vertex_count);
	if (owner == NULL) {
		plume_spec_fail(reader, "$.handles", "out of memory");
		return;
	}
	for (int v = 0; v < scene->mesh->vertex_count; ++v)
		owner[v] = -1;
	for (int h = 0; h < scene->handle_count && reader->status == PLUME_OK; ++h) {
		const plume_vertex_group *group = plume_mesh_find_group(scene->mesh, scene->handles[h].group);
		for (int i = 0; group != NULL && i < group->count && reader->status == PLUME_OK; ++i) {
			int v = group->vertices[i], other = owner[v];
			if (other >= 0 && other != h) {
				char path[64];
				snprintf(path, sizeof path, "$.handles[%d].group", h);
				plume_spec_fail(reader, path,
				                "\"%s\" holds vertex %d, which $.handles[%d] (\"%s\") holds too; a vertex follows "
				                "one handle (hold groups that share no vertex, or one of the two)",
				                handle_given_group(scene->handles + h), v, other,
				                handle_given_group(scene->handles + other));
			}
			owner[v] = h;
		}
	}
	plume_free(owner);
}

/// A vertex may be in one handle: the scene's handles must leave alone the calamus of every
/// feather its follicle moves with the body.
static void check_follicle_handles(plume_spec_reader *reader, const plume_scene *scene)
{
	for (int i = 0; i < scene->feather_count && reader->status == PLUME_OK; ++i) {
		if (!scene->feathers[i].follicle)
			continue;
		char name[64];
		snprintf(name, sizeof name, "%s/rachis_clamp", scene->feathers[i].name);
		const plume_vertex_group *clamp = plume_mesh_find_group(scene->mesh, name);
		for (int h = 0; h < scene->handle_count && reader->status == PLUME_OK; ++h) {
			const plume_vertex_group *group = plume_mesh_find_group(scene->mesh, scene->handles[h].group);
			for (int a = 0; clamp != NULL && group != NULL && a < group->count; ++a) {
				bool shared = false;
				for (int b = 0; b < clamp->count && !shared; ++b)
					shared = group->vertices[a] == clamp->vertices[b];
				if (shared) {
					char path[64];
					snprintf(path, sizeof path, "$.handles[%d].group", h);
					plume_spec_fail(reader, path,
					                "\"%s\" holds feather \"%s\"'s calamus, which its follicle moves with the body; "
					                "hold another group, or one feather's (\"f1/left_edge\")",
					                scene->handles[h].source_group[0] ? scene->handles[h].source_group
					                                                  : scene->handles[h].group,
					                scene->feathers[i].name);
					break;
				}
			}
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
		if (!read_vec3(reader, object, path, "force", &scene->forces[i].force) && reader->status == PLUME_OK) {
			char force_path[96];
			plume_spec_path(force_path, sizeof force_path, path, "force");
			plume_spec_fail(reader, force_path, "missing; a force is [x, y, z] in N, shared by the group's vertices");
		}
		scene->force_count = (int)i + 1;
	}
}

/// The path of a file named in the scene: absolute, or relative to the scene's folder.
static void scene_relative(const char *file, const char *name, char *out, size_t size)
{
	if (name[0] == '/') {
		snprintf(out, size, "%s", name);
	} else {
		char copy[4096];
		snprintf(copy, sizeof copy, "%s", file);
		snprintf(out, size, "%s/%s", dirname(copy), name);
	}
}

/// An inline feather spec's error, "file: $.key: ...", at the scene's path of the spec:
/// "file: $.feathers[2].feather.key: ..." ("$.key" names no key of the scene).
static void inline_error_path(plume_error *err, const char *file, const char *where)
{
	if (err == NULL)
		return;
	size_t length = strlen(file);
	if (strncmp(err->message, file, length) != 0 || strncmp(err->message + length, ": $", 3) != 0)
		return;
	char message[sizeof err->message];
	snprintf(message, sizeof message, "%s: %s%s", file, where, err->message + length + 3);
	memcpy(err->message, message, sizeof message);
}

/// Generates (or reads) the feather of value (at JSON path `where`): a generator spec inline or
/// by path (relative to the scene), or a feather written by `plume generate --format json`.
/// Errors name the scene and `where`.
static plume_status load_feather(const char *file, const json_t *value, const char *where,
                                 const plume_spec_options *options, plume_feather **out, plume_error *err)
{
	if (json_is_object(value)) {
		plume_status status = plume_spec_generate_json(file, value, options, out, err);
		if (status != PLUME_OK)
			inline_error_path(err, file, where);
		return status;
	}
	if (!json_is_string(value))
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: %s: expected a feather spec (an object) or the path of one",
		                       file, where);
	char path[4096];
	scene_relative(file, json_string_value(value), path, sizeof path);
	json_t *spec = plume_spec_load(path, err);
	plume_status status = spec == NULL ? (err != NULL ? err->status : PLUME_ERROR_IO)
	                      : json_object_get(spec, "model") != NULL
	                          ? plume_spec_generate_json(path, spec, options, out, err)
	                          : plume_read_json(path, out, err);
	json_decref(spec);
	if (status != PLUME_OK) {
		char prefix[4200];
		snprintf(prefix, sizeof prefix, "%s: %s", file, where);
		plume_error_prefix(err, prefix);
	}
	return status;
}

// ---------------------------------------------------------------------------
// Many feathers (docs/scene.md "Many feathers")

/// A feather of "feathers" while the scene is read: in its own frame until it is meshed.
typedef struct pending_feather {
	plume_feather *feather;
	plume_mesh *mesh;
	plume_mesh_def mesh_def;
	plume_mat3 rotation;
	plume_vec3 translation;
	plume_mesh_report report;
	/// The entry's "feather" value: entries with equal values (the same spec file or the same
	/// inline spec) get copies of one generated feather, and of one mesh (`shared_mesh`, owned
	/// by the first) when their mesh settings are equal too. Generating and meshing are
	/// deterministic, so this only saves the time (a wing of one spec).
	const json_t *source;
	bool shared_mesh;
	char name[16];
	bool named;
	bool follicle;
	bool nearest_bone;
	char bone[32];
	char where[48]; ///< its entry's JSON path, for messages ("$.feathers[2]"; a coat's feathers share it)
} pending_feather;

typedef struct pending_list {
	pending_feather *items;
	int count, capacity;
} pending_list;

static pending_feather *pending_add(pending_list *list)
{
	if (list->count == list->capacity) {
		int capacity = list->capacity > 0 ? 2 * list->capacity : 8;
		pending_feather *items = plume_realloc(list->items, sizeof *items * (size_t)capacity);
		if (items == NULL)
			return NULL;
		list->items = items;
		list->capacity = capacity;
	}
	pending_feather *item = list->items + list->count++;
	memset(item, 0, sizeof *item);
	return item;
}

static void pending_free(pending_list *list)
{
	for (int i = 0; i < list->count; ++i) {
		plume_feather_destroy(list->items[i].feather);
		if (!list->items[i].shared_mesh)
			plume_mesh_destroy(list->items[i].mesh);
	}
	plume_free(list->items);
}

/// Letters, digits, '-' and '_', 1 to 15 bytes: a group prefix and a file name.
static bool valid_name(const char *name)
{
	size_t length = strlen(name);
	if (length == 0 || length > 15)
		return false;
	for (size_t i = 0; i < length; ++i) {
		char c = name[i];
		if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_'))
			return false;
	}
	return true;
}

/// "shaft" and "front": the directions the feather's own +y (its shaft) and +z (its front) take,
/// instead of an axis and an angle. front is made perpendicular to shaft (Gram-Schmidt).
static void read_frame(plume_spec_reader *reader, const json_t *object, const char *path, pending_feather *item)
{
	bool has_shaft = json_object_get(object, "shaft") != NULL, has_front = json_object_get(object, "front") != NULL;
	if (!has_shaft && !has_front)
		return;
	if (has_shaft != has_front || json_object_get(object, "rotation_deg") != NULL ||
	    json_object_get(object, "rotation_axis") != NULL) {
		plume_spec_fail(reader, path,
		                "a feather is turned by \"shaft\" and \"front\" together, or by \"rotation_axis\" and "
		                "\"rotation_deg\", not both");
		return;
	}
	plume_vec3 shaft, front;
	if (!read_vec3(reader, object, path, "shaft", &shaft) || !read_vec3(reader, object, path, "front", &front))
		return;
	char child[96];
	if (!(plume_v3_length(shaft) > 0)) {
		plume_spec_path(child, sizeof child, path, "shaft");
		plume_spec_fail(reader, child, "is the zero vector; it gives the direction of the feather's shaft");
		return;
	}
	shaft = plume_v3_normalize(shaft);
	double length = plume_v3_length(front);
	front = plume_v3_mad(front, -plume_v3_dot(front, shaft), shaft);
	// Within a thousandth of a radian of the shaft, the front has no direction of its own.
	if (!(plume_v3_length(front) > 1e-3 * length)) {
		plume_spec_path(child, sizeof child, path, "front");
		plume_spec_fail(reader, child, "is along the shaft (or zero); give a direction across it");
		return;
	}
	front = plume_v3_normalize(front);
	plume_vec3 x = plume_v3_cross(shaft, front); // the own frame is right-handed: x = y cross z
	item->rotation = (plume_mat3){{{x.x, shaft.x, front.x}, {x.y, shaft.y, front.y}, {x.z, shaft.z, front.z}}};
}

/// The attachment of an entry: name, mesh settings, placement and follicle, into item.
static void read_attachment(plume_spec_reader *reader, const json_t *object, const char *path,
                            const plume_mesh_def *scene_mesh, pending_feather *item)
{
	item->mesh_def = *scene_mesh;
	const json_t *mesh = plume_spec_object(reader, object, path, "mesh");
	if (mesh != NULL) {
		char mesh_path[96];
		plume_spec_path(mesh_path, sizeof mesh_path, path, "mesh");
		plume_spec_mesh_def(reader, mesh, mesh_path, &item->mesh_def);
	}
	plume_vec3 axis = plume_v3(0, 0, 1);
	double degrees = 0;
	read_vec3(reader, object, path, "position", &item->translation);
	read_vec3(reader, object, path, "rotation_axis", &axis);
	plume_spec_number(reader, object, path, "rotation_deg", &degrees);
	if (reader->status == PLUME_OK && json_object_get(object, "rotation_axis") != NULL &&
	    json_object_get(object, "rotation_deg") == NULL) { // an axis alone turned nothing
		char axis_path[96];
		plume_spec_path(axis_path, sizeof axis_path, path, "rotation_axis");
		plume_spec_fail(reader, axis_path,
		                "given without \"rotation_deg\"; an axis alone turns nothing (give the "
		                "angle in degrees too)");
		return;
	}
	item->rotation = plume_m3_identity();
	if (reader->status == PLUME_OK && degrees != 0) {
		if (plume_v3_length(axis) == 0) {
			char axis_path[96];
			plume_spec_path(axis_path, sizeof axis_path, path, "rotation_axis");
			plume_spec_fail(reader, axis_path, "is the zero vector; a rotation needs an axis");
			return;
		}
		item->rotation = plume_m3_rotation(plume_v3_normalize(axis), degrees * acos(-1.0) / 180);
	}
	read_frame(reader, object, path, item);
	const char *name = NULL;
	if (plume_spec_string(reader, object, path, "name", &name)) {
		char name_path[96];
		plume_spec_path(name_path, sizeof name_path, path, "name");
		if (!valid_name(name)) {
			plume_spec_fail(reader, name_path,
			                "\"%s\" is not a feather name; allowed 1 to 15 letters, digits, '-' or '_'", name);
			return;
		}
		snprintf(item->name, sizeof item->name, "%s", name);
		item->named = true;
	}
	const json_t *follicle = plume_spec_object(reader, object, path, "follicle");
	if (follicle != NULL) {
		char follicle_path[96];
		plume_spec_path(follicle_path, sizeof follicle_path, path, "follicle");
		plume_spec_check_keys(reader, follicle, follicle_path, follicle_keys);
		const char *bone = NULL;
		if (plume_spec_string(reader, follicle, follicle_path, "bone", &bone)) {
			size_t length = strlen(bone);
			if (length == 0 || length >= sizeof item->bone) { // "" followed the body as a whole
				char bone_path[128];
				plume_spec_path(bone_path, sizeof bone_path, follicle_path, "bone");
				plume_spec_fail(reader, bone_path,
				                "\"%.64s\" is not a bone's name; allowed 1 to %d bytes (leave \"bone\" out to "
				                "follow the body as a whole)",
				                bone, (int)sizeof item->bone - 1);
				return;
			}
			memcpy(item->bone, bone, length + 1);
		}
		plume_spec_bool(reader, follicle, follicle_path, "nearest_bone", &item->nearest_bone);
		if (reader->status == PLUME_OK && bone != NULL && item->nearest_bone)
			plume_spec_fail(reader, follicle_path, "names a bone and asks for the nearest one; give one of the two");
		item->follicle = true;
	}
}

/// Every feather of a coat spec becomes an entry: taken back to its own frame (for the
/// mesher) and placed by the coat's frame at its follicle, then by the entry's placement.
static plume_status expand_coat(const char *file, const char *name, const char *where, const pending_feather *entry,
                                const plume_spec_options *options, pending_list *list, plume_error *err)
{
	char path[4096];
	scene_relative(file, name, path, sizeof path);
	plume_coat *coat = NULL;
	plume_status status = plume_coat_spec_generate(path, options, &coat, err);
	if (status != PLUME_OK) {
		char prefix[4200];
		snprintf(prefix, sizeof prefix, "%s: %s.coat", file, where);
		plume_error_prefix(err, prefix);
		return status;
	}
	int count = plume_coat_feather_count(coat);
	for (int k = 0; k < count && status == PLUME_OK; ++k) {
		pending_feather *item = pending_add(list);
		plume_feather *feather = plume_feather_clone(plume_coat_feather(coat, k));
		if (item == NULL || feather == NULL) {
			plume_feather_destroy(feather);
			status = plume_error_set(err, PLUME_ERROR_MEMORY, "%s: %s: out of memory", file, where);
			break;
		}
		*item = *entry;
		item->feather = feather;
		plume_mat3 rotation;
		plume_vec3 origin;
		plume_coat_feather_frame(coat, k, &rotation, &origin);
		plume_mat3 inverse = plume_m3_transpose(rotation);
		plume_feather_move(feather, inverse, plume_v3_scale(plume_m3_apply(inverse, origin), -1));
		item->rotation = plume_m3_mul(entry->rotation, rotation);
		item->translation = plume_v3_add(plume_m3_apply(entry->rotation, origin), entry->translation);
		if (entry->named) {
			char composed[64];
			snprintf(composed, sizeof composed, "%s-%d", entry->name, k);
			if (!valid_name(composed)) {
				status = plume_error_set(err, PLUME_ERROR_SPEC,
				                         "%s: %s.name: \"%s\" with the coat feather's number (\"%s\") passes 15 bytes",
				                         file, where, entry->name, composed);
				break;
			}
			memcpy(item->name, composed, strlen(composed) + 1); // valid: at most 15 bytes
		}
	}
	plume_coat_destroy(coat);
	return status;
}

/// Reads the entries of "feathers" into list (own-frame feathers, placements, names).
static plume_status read_feather_entries(const char *file, const json_t *array, const plume_mesh_def *scene_mesh,
                                         const plume_spec_options *options, pending_list *list, plume_error *err)
{
	plume_spec_reader reader = plume_spec_reader_begin(file, err);
	size_t count = json_array_size(array);
	if (count == 0)
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: $.feathers: is empty; list at least one feather", file);
	double bytes = 0; // of the feathers read so far, list->items[0, counted)
	int counted = 0;
	for (size_t i = 0; i < count; ++i) {
		char path[48];
		plume_spec_index_path(path, sizeof path, "$.feathers", i);
		const json_t *object = json_array_get(array, i);
		if (!json_is_object(object))
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "%s: %s: expected an object {\"feather\": ..., \"position\": [x, y, z], ...}", file,
			                       path);
		plume_spec_check_keys(&reader, object, path, feather_entry_keys);
		pending_feather entry;
		memset(&entry, 0, sizeof entry);
		read_attachment(&reader, object, path, scene_mesh, &entry);
		if (reader.status != PLUME_OK)
			return reader.status;
		snprintf(entry.where, sizeof entry.where, "%s", path);
		const json_t *feather = json_object_get(object, "feather"), *coat = json_object_get(object, "coat");
		if ((feather == NULL) == (coat == NULL))
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "%s: %s: an entry needs exactly one of \"feather\" (a feather spec or dump) or "
			                       "\"coat\" (the path of a coat spec)",
			                       file, path);
		plume_status status;
		if (coat != NULL) {
			if (!json_is_string(coat))
				return plume_error_set(err, PLUME_ERROR_SPEC, "%s: %s.coat: expected the path of a coat spec", file,
				                       path);
			status = expand_coat(file, json_string_value(coat), path, &entry, options, list, err);
		} else {
			char where[64];
			plume_spec_path(where, sizeof where, path, "feather");
			pending_feather *item = pending_add(list);
			if (item == NULL)
				return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: %s: out of memory", file, path);
			*item = entry;
			item->source = feather;
			const pending_feather *same = NULL;
			for (int k = 0; k + 1 < list->count && same == NULL; ++k)
				if (list->items[k].source != NULL && json_equal(list->items[k].source, feather))
					same = list->items + k;
			if (same != NULL) {
				item->feather = plume_feather_clone(same->feather);
				status = item->feather != NULL
				             ? PLUME_OK
				             : plume_error_set(err, PLUME_ERROR_MEMORY, "%s: %s: out of memory", file, path);
			} else {
				status = load_feather(file, feather, where, options, &item->feather, err);
			}
		}
		if (status != PLUME_OK)
			return status;
		// Each feather is held to the limit when it is made; together they are too (a list may
		// repeat one spec many times).
		for (; counted < list->count; ++counted)
			bytes += plume_feather_bytes(list->items[counted].feather);
		if (bytes > plume_spec_memory_limit(options))
			return plume_error_set(err, PLUME_ERROR_LIMIT,
			                       "%s: %s: the feathers up to here take about %.3g GB; the limit is %.3g GB (raise it "
			                       "with --max-memory, or list fewer feathers)",
			                       file, path, bytes / 1e9, plume_spec_memory_limit(options) / 1e9);
	}
	return PLUME_OK;
}

static bool same_mesh_def(const plume_mesh_def *a, const plume_mesh_def *b)
{
	return a->edge_length == b->edge_length && a->rachis_width_base == b->rachis_width_base &&
	       a->rachis_width_tip == b->rachis_width_tip && a->include_calamus == b->include_calamus &&
	       a->max_memory == b->max_memory;
}

/// Default names, then no two alike.
static plume_status name_feathers(const char *file, pending_list *list, plume_error *err)
{
	for (int i = 0; i < list->count; ++i)
		if (!list->items[i].named)
			snprintf(list->items[i].name, sizeof list->items[i].name, "f%d", i);
	for (int i = 0; i < list->count; ++i)
		for (int j = 0; j < i; ++j)
			if (strcmp(list->items[i].name, list->items[j].name) == 0)
				return plume_error_set(err, PLUME_ERROR_SPEC,
				                       "%s: %s: the feather name \"%s\" is also the name of %s; names must differ "
				                       "(unnamed feathers are f0, f1, ... by their place in the list)",
				                       file, list->items[i].where, list->items[i].name, list->items[j].where);
	return PLUME_OK;
}

/// Ties a feather with a "follicle" to the body: its bone (named; the one the follicle rides on,
/// for "nearest_bone"; else the body's motion as a whole), and the follicle within PLUME_SCENE_FOLLICLE_TOLERANCE of
/// the rest surface.
static plume_status attach_follicle(const char *file, const plume_scene *scene, const pending_feather *item,
                                    plume_scene_feather *feather, plume_error *err)
{
	if (scene->body == NULL)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s: %s.follicle: the scene has no \"body\" to carry feather \"%s\"", file, item->where,
		                       item->name);
	const plume_body *body = scene->body;
	if (item->bone[0] != '\0') {
		feather->bone = plume_body_find_bone(body, item->bone);
		if (feather->bone < 0) {
			int count = plume_body_bone_count(body);
			const char *names[PLUME_BODY_MAX_BONES + 1];
			char list[512] = "";
			for (int b = 0; b < count; ++b) {
				names[b] = plume_body_bone_name(body, b);
				size_t used = strlen(list);
				snprintf(list + used, sizeof list - used, "%s%s", b > 0 ? ", " : "", names[b]);
			}
			names[count] = NULL;
			if (count == 0)
				return plume_error_set(err, PLUME_ERROR_SPEC,
				                       "%s: %s.follicle.bone: unknown bone \"%s\": the body has no bones (leave "
				                       "\"bone\" out to follow the body as a whole)",
				                       file, item->where, item->bone);
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "%s: %s.follicle.bone: unknown bone \"%s\"; did you mean \"%s\"? (the body has: %s)",
			                       file, item->where, item->bone, plume_spec_nearest(item->bone, names), list);
		}
	} else if (item->nearest_bone) {
		feather->bone = plume_body_nearest_bone(body, feather->follicle_point);
	} else {
		feather->bone = -1; // the body's motion as a whole
	}
	double distance = plume_body_rest_distance(body, feather->follicle_point, NULL);
	if (!(distance <= PLUME_SCENE_FOLLICLE_TOLERANCE)) {
		plume_vec3 p = feather->follicle_point;
		return plume_error_set(
		    err, PLUME_ERROR_SPEC,
		    "%s: %s.follicle: feather \"%s\"'s follicle (%.6g, %.6g, %.6g) is %.3g m from the body's "
		    "rest surface; allowed at most %g m (place the feather's calamus on the body)",
		    file, item->where, item->name, p.x, p.y, p.z, distance, PLUME_SCENE_FOLLICLE_TOLERANCE);
	}
	return PLUME_OK;
}

/// The feather a face of the joined mesh belongs to (feathers' faces are consecutive).
static int feather_of_face(const plume_scene *scene, int face)
{
	int lo = 0, hi = scene->feather_count - 1;
	while (lo < hi) {
		int mid = (lo + hi + 1) / 2;
		if (scene->feathers[mid].face_offset <= face)
			lo = mid;
		else
			hi = mid - 1;
	}
	return lo;
}

static plume_vec3 face_centroid(const plume_mesh *mesh, int face)
{
	const int *v = mesh->faces + 3 * face;
	plume_vec3 sum = plume_v3_add(plume_v3_add(mesh->rest[v[0]], mesh->rest[v[1]]), mesh->rest[v[2]]);
	return plume_v3_scale(sum, 1.0 / 3.0);
}

/// Every pair of intersecting triangles of the soup (plume_find_intersections, exact): into
/// *pairs (plume_free), their count into *count.
static plume_status all_intersections(const plume_vec3 *positions, int vertex_count, const int *triangles,
                                      int triangle_count, int **pairs, int *count, plume_error *err)
{
	int capacity = 1024;
	*pairs = NULL;
	for (;;) {
		plume_free(*pairs);
		*pairs = plume_alloc(sizeof(int) * 2 * (size_t)capacity);
		if (*pairs == NULL)
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
		plume_status status =
		    plume_find_intersections(positions, vertex_count, triangles, triangle_count, capacity, *pairs, count, err);
		if (status != PLUME_OK || *count <= capacity)
			return status;
		capacity = *count; // again, with room for every pair: none between two feathers is left out
	}
}

/// Feathers that intersect each other or the body at rest (exactly, plume_find_intersections)
/// are an error naming the first pair, the faces and where: a simulation cannot start from
/// surfaces that already pass through each other. A feather's own faces are the mesher's; a
/// carried feather's calamus faces sit on the body at its follicle and are not checked against it.
static plume_status check_rest_intersections(const char *file, const char *where, const plume_scene *scene,
                                             plume_error *err)
{
	const plume_mesh *mesh = scene->mesh;
	int body_vertices = scene->body != NULL ? plume_body_vertex_count(scene->body) : 0;
	int body_triangles = scene->body != NULL ? plume_body_triangle_count(scene->body) : 0;
	if (scene->feather_count < 2 && scene->body == NULL)
		return PLUME_OK;
	// The soup: the feathers' rest mesh, then the body's rest mesh.
	int vertex_count = mesh->vertex_count + body_vertices, triangle_count = mesh->face_count + body_triangles;
	plume_vec3 *positions = plume_alloc(sizeof(plume_vec3) * (size_t)vertex_count);
	int *triangles = plume_alloc(sizeof(int) * 3 * (size_t)triangle_count);
	bool *follicle_face = plume_alloc(sizeof(bool) * (size_t)(mesh->face_count + 1));
	if (positions == NULL || triangles == NULL || follicle_face == NULL) {
		plume_free(positions);
		plume_free(triangles);
		plume_free(follicle_face);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory checking the feathers at rest", file);
	}
	memcpy(positions, mesh->rest, sizeof(plume_vec3) * (size_t)mesh->vertex_count);
	memcpy(triangles, mesh->faces, sizeof(int) * 3 * (size_t)mesh->face_count);
	if (scene->body != NULL) {
		memcpy(positions + mesh->vertex_count, plume_body_rest_positions(scene->body),
		       sizeof(plume_vec3) * (size_t)body_vertices);
		const int *body = plume_body_triangles(scene->body);
		for (int k = 0; k < 3 * body_triangles; ++k)
			triangles[3 * mesh->face_count + k] = body[k] + mesh->vertex_count;
	}
	plume_scene_follicle_faces(scene, follicle_face);
	int *pairs = NULL, count = 0;
	plume_status status = all_intersections(positions, vertex_count, triangles, triangle_count, &pairs, &count, err);
	if (status != PLUME_OK) {
		char prefix[4200];
		snprintf(prefix, sizeof prefix, "%s: %s: checking the feathers at rest", file, where);
		plume_error_prefix(err, prefix);
	}
	int first = -1, reported = 0;
	for (int k = 0; status == PLUME_OK && k < count; ++k) {
		int a = pairs[2 * k], b = pairs[2 * k + 1]; // a < b: a body triangle comes second
		bool counts = b >= mesh->face_count ? a < mesh->face_count && !follicle_face[a]
		                                    : feather_of_face(scene, a) != feather_of_face(scene, b);
		if (counts && first < 0)
			first = k;
		reported += counts;
	}
	if (first >= 0) {
		int a = pairs[2 * first], b = pairs[2 * first + 1];
		const plume_scene_feather *fa = scene->feathers + feather_of_face(scene, a);
		const int *t = triangles + 3 * b;
		plume_vec3 other =
		    plume_v3_scale(plume_v3_add(plume_v3_add(positions[t[0]], positions[t[1]]), positions[t[2]]), 1.0 / 3.0);
		plume_vec3 at = plume_v3_scale(plume_v3_add(face_centroid(mesh, a), other), 0.5);
		if (b >= mesh->face_count) {
			status = plume_error_set(err, PLUME_ERROR_SPEC,
			                         "%s: %s: feather \"%s\" passes through the body at rest: its face %d meets "
			                         "body triangle %d near (%.6g, %.6g, %.6g) m (%d pairs of faces in all); place it "
			                         "outside the body",
			                         file, where, fa->name, a - fa->face_offset, b - mesh->face_count, at.x, at.y, at.z,
			                         reported);
		} else {
			const plume_scene_feather *fb = scene->feathers + feather_of_face(scene, b);
			status = plume_error_set(err, PLUME_ERROR_SPEC,
			                         "%s: %s: feathers \"%s\" and \"%s\" intersect at rest: face %d of \"%s\" "
			                         "meets face %d of \"%s\" near (%.6g, %.6g, %.6g) m (%d pairs of faces in all); "
			                         "place them apart",
			                         file, where, fa->name, fb->name, a - fa->face_offset, fa->name,
			                         b - fb->face_offset, fb->name, at.x, at.y, at.z, reported);
		}
	}
	plume_free(pairs);
	plume_free(positions);
	plume_free(triangles);
	plume_free(follicle_face);
	return status;
}

/// "feathers": every feather meshed in its own frame, placed, and the meshes joined.
static plume_status build_many(const char *file, const json_t *array, const plume_mesh_def *scene_mesh,
                               const plume_spec_options *options, plume_scene *scene, plume_error *err)
{
	pending_list list = {0};
	// options->progress counts the feathers meshed; a coat's own count would restart it.
	plume_spec_options quiet = options != NULL ? *options : (plume_spec_options){0};
	quiet.progress = NULL;
	plume_status status = read_feather_entries(file, array, scene_mesh, &quiet, &list, err);
	if (status == PLUME_OK)
		status = name_feathers(file, &list, err);
	for (int i = 0; i < list.count && status == PLUME_OK; ++i) {
		pending_feather *item = list.items + i;
		const pending_feather *same = NULL;
		for (int k = 0; k < i && same == NULL && item->source != NULL; ++k)
			if (list.items[k].source != NULL && !list.items[k].shared_mesh &&
			    json_equal(list.items[k].source, item->source) &&
			    same_mesh_def(&list.items[k].mesh_def, &item->mesh_def))
				same = list.items + k;
		if (same != NULL) {
			item->mesh = same->mesh;
			item->report = same->report;
			item->shared_mesh = true;
		} else {
			status = plume_mesh_from_feather(item->feather, &item->mesh_def, &item->mesh, &item->report, err);
		}
		if (status != PLUME_OK) {
			char prefix[4200];
			snprintf(prefix, sizeof prefix, "%s: %s (feather \"%s\"): meshing", file, item->where, item->name);
			plume_error_prefix(err, prefix);
			break;
		}
		plume_feather_move(item->feather, item->rotation, item->translation);
		if (options != NULL && options->progress != NULL)
			options->progress(options->progress_user, i + 1, list.count);
		plume_mesh_report report = item->report;
		if (i == 0) {
			scene->mesh_report = report;
		} else {
			scene->mesh_report.min_angle = fmin(scene->mesh_report.min_angle, report.min_angle);
			scene->mesh_report.aligned_fraction = fmin(scene->mesh_report.aligned_fraction, report.aligned_fraction);
			scene->mesh_report.guides_dropped += report.guides_dropped;
			scene->mesh_report.barbs_averaged += report.barbs_averaged;
			scene->mesh_report.vertices_trimmed += report.vertices_trimmed;
		}
	}
	if (status == PLUME_OK) {
		scene->feathers = plume_calloc((size_t)list.count, sizeof *scene->feathers);
		plume_mesh_part *parts = plume_calloc((size_t)list.count, sizeof *parts);
		if (scene->feathers == NULL || parts == NULL)
			status =
			    plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory joining %d feathers", file, list.count);
		int vertex_offset = 0, face_offset = 0;
		for (int i = 0; i < list.count && status == PLUME_OK; ++i) {
			pending_feather *item = list.items + i;
			plume_scene_feather *f = scene->feathers + i;
			parts[i] = (plume_mesh_part){item->mesh, item->rotation, item->translation, item->name};
			snprintf(f->name, sizeof f->name, "%s", item->name);
			f->rotation = item->rotation;
			f->translation = item->translation;
			f->follicle_point = item->translation;
			f->vertex_offset = vertex_offset;
			f->vertex_count = item->mesh->vertex_count;
			f->face_offset = face_offset;
			f->face_count = item->mesh->face_count;
			f->mesh_report = item->report;
			snprintf(f->bone_name, sizeof f->bone_name, "%s", item->bone);
			f->follicle = item->follicle;
			f->bone = -1;
			vertex_offset += f->vertex_count;
			face_offset += f->face_count;
			scene->feather_count = i + 1;
		}
		if (status == PLUME_OK) {
			status = plume_mesh_concatenate(parts, list.count, &scene->mesh, err);
			if (status != PLUME_OK)
				plume_error_prefix(err, file);
		}
		// The feathers move to the scene (placed at rest, like their meshes).
		for (int i = 0; i < scene->feather_count; ++i) {
			scene->feathers[i].feather = list.items[i].feather;
			list.items[i].feather = NULL;
		}
		plume_free(parts);
	}
	for (int i = 0; i < list.count && status == PLUME_OK; ++i)
		if (list.items[i].follicle)
			status = attach_follicle(file, scene, list.items + i, scene->feathers + i, err);
	if (status == PLUME_OK)
		status = check_rest_intersections(file, "$.feathers", scene, err);
	pending_free(&list);
	return status;
}

/// A scene written with "feather" or "guides" is one feather, its mesh as the mesher made it.
static plume_status one_feather(const char *file, plume_scene *scene, plume_error *err)
{
	scene->feathers = plume_calloc(1, sizeof *scene->feathers);
	if (scene->feathers == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", file);
	plume_scene_feather *f = scene->feathers;
	scene->feather_count = 1;
	snprintf(f->name, sizeof f->name, "f0");
	f->feather = scene->feather;
	f->rotation = plume_m3_identity();
	f->vertex_count = scene->mesh->vertex_count;
	f->face_count = scene->mesh->face_count;
	f->mesh_report = scene->mesh_report;
	f->bone = -1;
	return PLUME_OK;
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
	const json_t *feathers = plume_spec_array(&reader, root, "$", "feathers");
	if (reader.status != PLUME_OK)
		return reader.status;
	if ((feather != NULL) + (guides != NULL) + (feathers != NULL) != 1)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s: $: a scene needs exactly one of \"feather\" (a feather spec), \"feathers\" (a "
		                       "list of them) or \"guides\"",
		                       file);
	if (feathers != NULL)
		return build_many(file, feathers, &mesh_def, options, scene, err);
	plume_status status;
	if (feather != NULL) {
		status = load_feather(file, feather, "$.feather", options, &scene->feather, err);
		if (status == PLUME_OK) {
			status = plume_mesh_from_feather(scene->feather, &mesh_def, &scene->mesh, &scene->mesh_report, err);
			if (status != PLUME_OK) // as a list's entry says it ("$.feathers[2] (feather \"f2\"): meshing: ...")
				plume_error_prefix(err, "$.feather: meshing");
		}
	} else {
		plume_mesh_guides_storage storage;
		status = plume_spec_mesh_guides(&reader, guides, "$.guides", mesh_def.max_memory, &storage);
		if (status == PLUME_OK) {
			status = plume_mesh_from_guides(&storage.guides, &mesh_def, &scene->mesh, &scene->mesh_report, err);
			if (status != PLUME_OK)
				plume_error_prefix(err, "$.guides: meshing");
			plume_mesh_guides_storage_free(&storage);
		}
	}
	if (status != PLUME_OK && err != NULL && strncmp(err->message, file, strlen(file)) != 0)
		plume_error_prefix(err, file);
	if (status == PLUME_OK)
		status = one_feather(file, scene, err);
	if (status == PLUME_OK)
		status = check_rest_intersections(file, feather != NULL ? "$.feather" : "$.guides", scene, err);
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
	if (!json_is_string(value)) { // "expected a string" left out the booleans
		plume_spec_fail(reader, "$.bending", "expected true, false or a model's name (%s, %s), got %s",
		                bending_models[0], bending_models[1],
		                json_is_number(value)   ? "a number"
		                : json_is_array(value)  ? "an array"
		                : json_is_object(value) ? "an object"
		                                        : "null");
		return;
	}
	const char *name = json_string_value(value);
	int model = word_index(reader, "$.bending", name, bending_models);
	if (model >= 0)
		def->bending_model = (plume_bending_model)model;
}

/// "body": an object (docs/scene.md "Bodies") or the path of a body file, relative to the scene.
static plume_status read_body(const char *file, const json_t *root, plume_scene *scene, plume_error *err)
{
	const json_t *body = json_object_get(root, "body");
	if (body == NULL)
		return PLUME_OK;
	char copy[4096];
	snprintf(copy, sizeof copy, "%s", file);
	const char *folder = dirname(copy);
	if (json_is_object(body))
		return plume_spec_body(file, body, "$.body", folder, &scene->body, err);
	if (!json_is_string(body))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s: $.body: expected a body (an object) or the path of a body file", file);
	char path[4096];
	scene_relative(file, json_string_value(body), path, sizeof path);
	plume_status status = plume_body_load(path, &scene->body, err);
	if (status != PLUME_OK) {
		char prefix[4200];
		snprintf(prefix, sizeof prefix, "%s: $.body", file);
		plume_error_prefix(err, prefix);
	}
	return status;
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
	if (plume_spec_number(&reader, root, "$", "cycle_period", &scene->cycle_period) && !(scene->cycle_period > 0))
		plume_spec_fail(&reader, "$.cycle_period", "is %g, allowed > 0 (seconds)", scene->cycle_period);
	plume_spec_bool(&reader, root, "$", "quasi_static", &scene->quasi_static);
	read_solver(&reader, root, &scene->sim);
	read_dynamics(&reader, root, &scene->sim);
	read_contact(&reader, root, &scene->sim);
	if (reader.status == PLUME_OK && !(scene->duration > 0 && isfinite(scene->duration)))
		plume_spec_fail(&reader, "$.duration", "is %g, allowed > 0 (seconds)", scene->duration);
	if (reader.status == PLUME_OK && scene->frame_every < 1)
		plume_spec_fail(&reader, "$.frame_every", "is %d, allowed >= 1", scene->frame_every);
	// Air acts on the velocity relative to the wind, and a static solve has no velocity: it
	// leaves the air out (src/sim/potential.c), so a wind or gusts there blew on nothing.
	const plume_air_def *air = &scene->sim.air;
	if (reader.status == PLUME_OK && scene->quasi_static && air->density > 0 &&
	    (air->wind.x != 0 || air->wind.y != 0 || air->wind.z != 0 || air->gust_speed > 0))
		plume_spec_fail(&reader, "$.air",
		                "a quasi-static scene leaves the air out of its static solve, so its wind (%g, %g, %g) m/s "
		                "and gusts (%g m/s) would move nothing; drop \"quasi_static\" to feel them, or the wind",
		                air->wind.x, air->wind.y, air->wind.z, air->gust_speed);
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
		status = read_body(path, root, scene, err);
	if (status == PLUME_OK)
		status = build_mesh(path, root, &feather_options, scene, err);
	if (status == PLUME_OK) {
		read_handles(&reader, root, scene);
		check_handle_overlap(&reader, scene);
		check_follicle_handles(&reader, scene);
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

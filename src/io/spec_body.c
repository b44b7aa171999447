// Body specs (docs/body.md): a rest mesh (an OBJ file, a built-in shape or inline
// arrays), the body's rigid keyframes, a skeleton of keyframed bones and how it skins
// the mesh. The checks on the assembled definition are plume_body_create's; this file
// adds the JSON paths (and the OBJ's file and line) to its messages.
#define _POSIX_C_SOURCE 200809L
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/alloc.h"
#include "../sim/body_internal.h"
#include "obj_reader.h"
#include "spec.h"
#include "spec_body.h"

// ---------------------------------------------------------------------------
// OBJ (read by obj_reader.c; a body adds its zero-area check, with the file's line)

/// Fails on the first triangle of zero area, naming its face and line.
static plume_status check_obj_areas(const plume_obj *obj, const char *path, plume_error *err)
{
	const plume_vec3 *p = obj->vertices;
	for (int t = 0; t < obj->triangle_count; ++t) {
		const int *v = obj->triangles + 3 * t;
		if (plume_body_triangle_degenerate(p[v[0]], p[v[1]], p[v[2]])) {
			int face = obj->triangle_face[t];
			return plume_error_set(err, PLUME_ERROR_SYNTAX,
			                       "%s:%ld: face %d: degenerate (zero-area) triangle of vertices %d %d %d (1-based, "
			                       "as in the file); remove the face or move its vertices apart",
			                       path, obj->face_line[face], face + 1, v[0] + 1, v[1] + 1, v[2] + 1);
		}
	}
	return PLUME_OK;
}

plume_status plume_body_read_obj(const char *path, plume_body_mesh *mesh, plume_error *err)
{
	*mesh = (plume_body_mesh){0};
	plume_obj obj;
	plume_status status = plume_obj_read(path, PLUME_OBJ_POSITIONS, &obj, err);
	if (status == PLUME_OK)
		status = check_obj_areas(&obj, path, err);
	if (status == PLUME_OK) {
		// The body takes the reader's arrays as they are.
		*mesh = (plume_body_mesh){.vertex_count = obj.vertex_count,
		                          .vertices = obj.vertices,
		                          .triangle_count = obj.triangle_count,
		                          .triangles = obj.triangles};
		obj.vertices = NULL;
		obj.triangles = NULL;
	}
	plume_obj_free(&obj);
	return status;
}

// ---------------------------------------------------------------------------
// JSON

static const char *const body_keys[] = {"description", "mesh",  "pivot",    "interpolation",
                                        "keyframes",   "bones", "skinning", NULL};
static const char *const ellipsoid_keys[] = {"shape", "center", "radii", "segments", NULL};
static const char *const capsule_keys[] = {"shape", "a", "b", "radius", "segments", NULL};
static const char *const inline_keys[] = {"vertices", "triangles", NULL};
static const char *const bone_keys[] = {"name", "parent", "head", "tail", "interpolation", "keyframes", NULL};
static const char *const keyframe_keys[] = {"time", "translation", "rotation_axis", "rotation_deg", NULL};
static const char *const shapes[] = {"ellipsoid", "capsule", NULL};
static const char *const interpolations[] = {"linear", "smooth", NULL};
static const char *const skinnings[] = {"auto", "nearest", NULL};

/// Everything the definition points to, owned here until plume_body_create copies it.
typedef struct body_storage {
	plume_body_mesh mesh;
	plume_keyframe *keyframes;
	plume_body_bone_def *bones;
	plume_keyframe **bone_keys;
	int bone_count;
} body_storage;

static void storage_free(body_storage *storage)
{
	plume_body_mesh_free(&storage->mesh);
	plume_free(storage->keyframes);
	for (int b = 0; b < storage->bone_count; ++b)
		plume_free(storage->bone_keys[b]);
	plume_free(storage->bone_keys);
	plume_free(storage->bones);
}

/// An array of n finite numbers at value (path names it).
static bool numbers_at(plume_spec_reader *reader, const json_t *value, const char *path, double *out, int n)
{
	if (reader->status != PLUME_OK)
		return false;
	if (!json_is_array(value) || (int)json_array_size(value) != n) {
		plume_spec_fail(reader, path, "expected an array of %d numbers", n);
		return false;
	}
	for (int i = 0; i < n; ++i) {
		const json_t *x = json_array_get(value, (size_t)i);
		if (!json_is_number(x) || !isfinite(json_number_value(x))) {
			plume_spec_fail(reader, path, "element %d is not a finite number", i);
			return false;
		}
		out[i] = json_number_value(x);
	}
	return true;
}

/// An optional [x, y, z] member; absent keeps *out.
static bool vec3_member(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                        plume_vec3 *out)
{
	const json_t *value = json_object_get(object, key);
	if (value == NULL || reader->status != PLUME_OK)
		return false;
	char child[256];
	plume_spec_path(child, sizeof child, path, key);
	double x[3];
	if (!numbers_at(reader, value, child, x, 3))
		return false;
	*out = plume_v3(x[0], x[1], x[2]);
	return true;
}

static void require_vec3(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                         plume_vec3 *out, const char *why)
{
	if (!vec3_member(reader, object, path, key, out) && reader->status == PLUME_OK) {
		char child[256];
		plume_spec_path(child, sizeof child, path, key);
		plume_spec_fail(reader, child, "missing; %s", why);
	}
}

static int word_member(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       const char *const *allowed, int fallback)
{
	const char *word;
	if (!plume_spec_string(reader, object, path, key, &word))
		return fallback;
	for (int i = 0; allowed[i] != NULL; ++i)
		if (strcmp(word, allowed[i]) == 0)
			return i;
	char child[256], list[128] = "";
	plume_spec_path(child, sizeof child, path, key);
	for (int i = 0; allowed[i] != NULL; ++i) {
		size_t used = strlen(list);
		snprintf(list + used, sizeof list - used, "%s%s", i > 0 ? ", " : "", allowed[i]);
	}
	plume_spec_fail(reader, child, "unknown value \"%s\"; did you mean \"%s\"? (allowed: %s)", word,
	                plume_spec_nearest(word, allowed), list);
	return fallback;
}

/// "keyframes": [{"time", "translation", "rotation_axis", "rotation_deg"}]; the order of
/// the times and the axes are checked by plume_body_create.
static void read_keyframes(plume_spec_reader *reader, const json_t *object, const char *path, plume_keyframe **out,
                           int *count)
{
	const json_t *array = plume_spec_array(reader, object, path, "keyframes");
	if (array == NULL)
		return;
	char array_path[192];
	plume_spec_path(array_path, sizeof array_path, path, "keyframes");
	size_t n = json_array_size(array);
	*out = plume_calloc(n > 0 ? n : 1, sizeof **out);
	if (*out == NULL) {
		plume_spec_fail(reader, array_path, "out of memory");
		return;
	}
	for (size_t k = 0; k < n && reader->status == PLUME_OK; ++k) {
		char key_path[224];
		plume_spec_index_path(key_path, sizeof key_path, array_path, k);
		const json_t *key = json_array_get(array, k);
		if (!json_is_object(key)) {
			plume_spec_fail(reader, key_path,
			                "expected an object {\"time\", \"rotation_axis\", \"rotation_deg\", ...}");
			return;
		}
		plume_spec_check_keys(reader, key, key_path, keyframe_keys);
		plume_keyframe *frame = *out + k;
		frame->axis = plume_v3(0, 0, 1);
		if (!plume_spec_number(reader, key, key_path, "time", &frame->time) && reader->status == PLUME_OK) {
			char time_path[256];
			plume_spec_path(time_path, sizeof time_path, key_path, "time");
			plume_spec_fail(reader, time_path, "missing; every keyframe has a time in seconds");
		}
		vec3_member(reader, key, key_path, "translation", &frame->translation);
		vec3_member(reader, key, key_path, "rotation_axis", &frame->axis);
		double degrees = 0;
		plume_spec_number(reader, key, key_path, "rotation_deg", &degrees);
		frame->angle = degrees * (acos(-1.0) / 180);
		*count = (int)k + 1;
	}
}

static void read_inline_mesh(plume_spec_reader *reader, const json_t *mesh, const char *path, plume_body_mesh *out)
{
	plume_spec_check_keys(reader, mesh, path, inline_keys);
	const json_t *vertices = plume_spec_array(reader, mesh, path, "vertices");
	const json_t *triangles = plume_spec_array(reader, mesh, path, "triangles");
	if (reader->status != PLUME_OK)
		return;
	if (vertices == NULL || triangles == NULL) {
		char child[256];
		plume_spec_path(child, sizeof child, path, vertices == NULL ? "vertices" : "triangles");
		plume_spec_fail(reader, child,
		                "missing; an inline mesh has \"vertices\" [[x, y, z], ...] (m) and "
		                "\"triangles\" [[i, j, k], ...] (0-based)");
		return;
	}
	size_t nv = json_array_size(vertices), nt = json_array_size(triangles);
	if (nv > 100000000 || nt > 100000000) {
		plume_spec_fail(reader, path, "too many vertices or triangles (at most 1e8)");
		return;
	}
	out->vertices = plume_calloc(nv > 0 ? nv : 1, sizeof *out->vertices);
	out->triangles = plume_calloc(nt > 0 ? 3 * nt : 1, sizeof *out->triangles);
	if (out->vertices == NULL || out->triangles == NULL) {
		plume_spec_fail(reader, path, "out of memory");
		return;
	}
	out->vertex_count = (int)nv;
	out->triangle_count = (int)nt;
	char base[256], child[288];
	plume_spec_path(base, sizeof base, path, "vertices");
	for (size_t v = 0; v < nv && reader->status == PLUME_OK; ++v) {
		plume_spec_index_path(child, sizeof child, base, v);
		double x[3];
		if (numbers_at(reader, json_array_get(vertices, v), child, x, 3))
			out->vertices[v] = plume_v3(x[0], x[1], x[2]);
	}
	plume_spec_path(base, sizeof base, path, "triangles");
	for (size_t f = 0; f < nt && reader->status == PLUME_OK; ++f) {
		plume_spec_index_path(child, sizeof child, base, f);
		const json_t *t = json_array_get(triangles, f);
		if (!json_is_array(t) || json_array_size(t) != 3) {
			plume_spec_fail(reader, child, "expected three vertex indices [i, j, k]");
			return;
		}
		for (size_t k = 0; k < 3; ++k) {
			const json_t *index = json_array_get(t, k);
			json_int_t value = json_is_integer(index) ? json_integer_value(index) : -1;
			if (value < 0 || value >= (json_int_t)nv) {
				plume_spec_fail(reader, child, "element %zu is not a vertex index 0 to %zu", k, nv - 1);
				return;
			}
			out->triangles[3 * f + k] = (int)value;
		}
	}
}

static void read_shape(plume_spec_reader *reader, const json_t *mesh, const char *path, plume_body_mesh *out)
{
	int shape = word_member(reader, mesh, path, "shape", shapes, -1);
	if (reader->status != PLUME_OK)
		return;
	plume_spec_check_keys(reader, mesh, path, shape == 0 ? ellipsoid_keys : capsule_keys);
	int segments = shape == 0 ? 32 : 16;
	plume_spec_int(reader, mesh, path, "segments", &segments);
	plume_error local = {0};
	plume_status status = PLUME_OK;
	if (shape == 0) {
		plume_vec3 center = {0, 0, 0}, radii;
		vec3_member(reader, mesh, path, "center", &center);
		require_vec3(reader, mesh, path, "radii", &radii, "an ellipsoid has three radii [r_x, r_y, r_z] (m)");
		if (reader->status == PLUME_OK)
			status = plume_body_ellipsoid(center, radii, segments, out, &local);
	} else {
		plume_vec3 a, b;
		double radius = 0;
		require_vec3(reader, mesh, path, "a", &a, "a capsule runs from \"a\" to \"b\" (m)");
		require_vec3(reader, mesh, path, "b", &b, "a capsule runs from \"a\" to \"b\" (m)");
		if (!plume_spec_number(reader, mesh, path, "radius", &radius) && reader->status == PLUME_OK) {
			char child[256];
			plume_spec_path(child, sizeof child, path, "radius");
			plume_spec_fail(reader, child, "missing; a capsule has a radius (m)");
		}
		if (reader->status == PLUME_OK)
			status = plume_body_capsule(a, b, radius, segments, out, &local);
	}
	// The shape's messages start with the key at fault ("radii: ...").
	if (status != PLUME_OK) {
		reader->status = status;
		if (reader->err != NULL)
			plume_error_set(reader->err, status, "%s: %s.%s", reader->file, path, local.message);
	}
}

/// "mesh": an OBJ path, a shape object or an inline mesh.
static void read_mesh(plume_spec_reader *reader, const json_t *body, const char *path, const char *folder,
                      plume_body_mesh *out)
{
	char mesh_path[192];
	plume_spec_path(mesh_path, sizeof mesh_path, path, "mesh");
	const json_t *mesh = json_object_get(body, "mesh");
	if (mesh == NULL) {
		plume_spec_fail(reader, mesh_path,
		                "missing; a body needs a mesh: an OBJ file's path, {\"shape\": \"ellipsoid\", ...} or "
		                "{\"vertices\": ..., \"triangles\": ...}");
	} else if (json_is_string(mesh)) {
		const char *name = json_string_value(mesh);
		char file[4096];
		if (name[0] == '/' || folder == NULL)
			snprintf(file, sizeof file, "%s", name);
		else
			snprintf(file, sizeof file, "%s/%s", folder, name);
		plume_status status = plume_body_read_obj(file, out, reader->err);
		if (status != PLUME_OK) {
			reader->status = status;
			if (status == PLUME_ERROR_IO && reader->err != NULL) {
				char message[sizeof reader->err->message];
				snprintf(message, sizeof message, "%s", reader->err->message);
				plume_error_set(reader->err, status, "%s: %s: %s", reader->file, mesh_path, message);
			}
		}
	} else if (json_is_object(mesh)) {
		if (json_object_get(mesh, "shape") != NULL)
			read_shape(reader, mesh, mesh_path, out);
		else
			read_inline_mesh(reader, mesh, mesh_path, out);
	} else {
		plume_spec_fail(reader, mesh_path, "expected an OBJ file's path or an object (a shape or an inline mesh)");
	}
}

/// Tail default: the mean of the children's heads, or the head itself for a leaf.
static void default_tails(plume_body_bone_def *bones, int count, const bool *tail_given)
{
	for (int b = 0; b < count; ++b) {
		if (tail_given[b])
			continue;
		plume_vec3 sum = {0, 0, 0};
		int children = 0;
		for (int c = 0; c < count; ++c)
			if (bones[c].parent == b) {
				sum = plume_v3_add(sum, bones[c].head);
				++children;
			}
		bones[b].tail = children > 0 ? plume_v3_scale(sum, 1.0 / children) : bones[b].head;
	}
}

static void read_bones(plume_spec_reader *reader, const json_t *body, const char *path,
                       plume_interpolation interpolation, body_storage *storage)
{
	const json_t *array = plume_spec_array(reader, body, path, "bones");
	if (array == NULL)
		return;
	char bones_path[192];
	plume_spec_path(bones_path, sizeof bones_path, path, "bones");
	size_t n = json_array_size(array);
	if (n > PLUME_BODY_MAX_BONES) {
		plume_spec_fail(reader, bones_path, "%zu bones; allowed at most %d", n, PLUME_BODY_MAX_BONES);
		return;
	}
	storage->bones = plume_calloc(n > 0 ? n : 1, sizeof *storage->bones);
	storage->bone_keys = plume_calloc(n > 0 ? n : 1, sizeof *storage->bone_keys);
	if (storage->bones == NULL || storage->bone_keys == NULL) {
		plume_spec_fail(reader, bones_path, "out of memory");
		return;
	}
	storage->bone_count = (int)n;
	const char *parents[PLUME_BODY_MAX_BONES] = {NULL};
	bool tail_given[PLUME_BODY_MAX_BONES] = {false};
	for (size_t b = 0; b < n && reader->status == PLUME_OK; ++b) {
		char bone_path[224], child[256];
		plume_spec_index_path(bone_path, sizeof bone_path, bones_path, b);
		const json_t *object = json_array_get(array, b);
		if (!json_is_object(object)) {
			plume_spec_fail(reader, bone_path, "expected an object {\"name\", \"parent\", \"head\", \"keyframes\"}");
			return;
		}
		plume_spec_check_keys(reader, object, bone_path, bone_keys);
		plume_body_bone_def *bone = storage->bones + b;
		bone->parent = -1;
		const char *name = NULL;
		plume_spec_path(child, sizeof child, bone_path, "name");
		if (!plume_spec_string(reader, object, bone_path, "name", &name) && reader->status == PLUME_OK)
			plume_spec_fail(reader, child, "missing; every bone has a name");
		else if (name != NULL && (name[0] == '\0' || strlen(name) >= PLUME_BODY_NAME_SIZE))
			plume_spec_fail(reader, child, "\"%s\": a bone's name has 1 to %d bytes", name, PLUME_BODY_NAME_SIZE - 1);
		else if (name != NULL)
			snprintf(bone->name, sizeof bone->name, "%s", name);
		const json_t *parent = json_object_get(object, "parent");
		if (parent != NULL && !json_is_null(parent))
			plume_spec_string(reader, object, bone_path, "parent", &parents[b]);
		require_vec3(reader, object, bone_path, "head", &bone->head, "the joint the bone turns about, [x, y, z] (m)");
		tail_given[b] = vec3_member(reader, object, bone_path, "tail", &bone->tail);
		bone->interpolation =
		    (plume_interpolation)word_member(reader, object, bone_path, "interpolation", interpolations, interpolation);
		read_keyframes(reader, object, bone_path, &storage->bone_keys[b], &bone->keyframe_count);
		bone->keyframes = storage->bone_keys[b];
	}
	// Parents by name, once every bone is known.
	for (size_t b = 0; b < n && reader->status == PLUME_OK; ++b) {
		if (parents[b] == NULL)
			continue;
		const char *names[PLUME_BODY_MAX_BONES + 1];
		char list[512] = "";
		for (size_t c = 0; c < n; ++c) {
			names[c] = storage->bones[c].name;
			if (strcmp(names[c], parents[b]) == 0)
				storage->bones[b].parent = (int)c;
			size_t used = strlen(list);
			snprintf(list + used, sizeof list - used, "%s%s", c > 0 ? ", " : "", names[c]);
		}
		names[n] = NULL;
		char bone_path[224], child[256];
		plume_spec_index_path(bone_path, sizeof bone_path, bones_path, b);
		plume_spec_path(child, sizeof child, bone_path, "parent");
		if (storage->bones[b].parent < 0)
			plume_spec_fail(reader, child, "unknown bone \"%s\"; did you mean \"%s\"? (bones: %s; null for a root)",
			                parents[b], plume_spec_nearest(parents[b], names), list);
		else if (storage->bones[b].parent == (int)b)
			plume_spec_fail(reader, child,
			                "\"%s\" is the bone itself; a bone's parent is another bone, or null for a root",
			                parents[b]);
	}
	default_tails(storage->bones, (int)n, tail_given);
}

plume_status plume_spec_body(const char *file, const json_t *object, const char *path, const char *folder,
                             plume_body **out, plume_error *err)
{
	*out = NULL;
	plume_spec_reader reader = plume_spec_reader_begin(file, err);
	if (!json_is_object(object)) {
		plume_spec_fail(&reader, path, "expected an object (a body: \"mesh\", \"keyframes\", \"bones\", ...)");
		return reader.status;
	}
	plume_spec_check_keys(&reader, object, path, body_keys);
	body_storage storage = {0};
	plume_body_def def = plume_body_default_def();
	def.interpolation = (plume_interpolation)word_member(&reader, object, path, "interpolation", interpolations,
	                                                     PLUME_INTERPOLATION_LINEAR);
	vec3_member(&reader, object, path, "pivot", &def.pivot);
	read_keyframes(&reader, object, path, &storage.keyframes, &def.keyframe_count);
	def.keyframes = storage.keyframes;
	read_bones(&reader, object, path, def.interpolation, &storage);
	def.bones = storage.bones;
	def.bone_count = storage.bone_count;
	def.skinning = word_member(&reader, object, path, "skinning", skinnings, 0) == 1 ? PLUME_BODY_SKIN_NEAREST
	                                                                                 : PLUME_BODY_SKIN_BLEND;
	if (reader.status == PLUME_OK)
		read_mesh(&reader, object, path, folder, &storage.mesh);
	def.vertex_count = storage.mesh.vertex_count;
	def.vertices = storage.mesh.vertices;
	def.triangle_count = storage.mesh.triangle_count;
	def.triangles = storage.mesh.triangles;
	plume_status status = reader.status;
	if (status == PLUME_OK) {
		status = plume_body_create(&def, out, err);
		// plume_body_create names the field in the spec's terms ("bones[2].parent: ..."):
		// prefix the file and the JSON path of the body (of its mesh for the mesh's arrays).
		if (status != PLUME_OK && err != NULL) {
			char message[sizeof err->message];
			snprintf(message, sizeof message, "%s", err->message);
			bool mesh = strncmp(message, "vertices", 8) == 0 || strncmp(message, "triangles", 9) == 0;
			plume_error_set(err, status, "%s: %s%s.%s", file, path, mesh ? ".mesh" : "", message);
		}
	}
	storage_free(&storage);
	return status;
}

plume_status plume_body_load(const char *path, plume_body **out, plume_error *err)
{
	*out = NULL;
	json_t *root = plume_spec_load(path, err);
	if (root == NULL)
		return err != NULL ? err->status : PLUME_ERROR_IO;
	char copy[4096];
	snprintf(copy, sizeof copy, "%s", path);
	plume_status status = plume_spec_body(path, root, "$", dirname(copy), out, err);
	json_decref(root);
	return status;
}

plume_status plume_body_parse(const char *text, const char *name, plume_body **out, plume_error *err)
{
	*out = NULL;
	json_error_t error;
	json_t *root = json_loads(text, JSON_REJECT_DUPLICATES, &error);
	if (root == NULL)
		return plume_error_set(err, PLUME_ERROR_SYNTAX, "%s:%d:%d: %s", name, error.line, error.column, error.text);
	plume_status status = plume_spec_check_numbers(name, root, err);
	if (status == PLUME_OK)
		status = plume_spec_body(name, root, "$", NULL, out, err);
	json_decref(root);
	return status;
}

// glTF export of shells: a static shell, and a simulation as one animated file.
//
// The animation is morph-target animation (glTF 2.0, 3.7.2.2 "Morph Targets"
// and 3.11 "Animations"): the mesh's base positions are the first frame, target
// k holds frame k minus the first frame, and the animation's weights sampler
// has one key per frame whose weights are 1 for that frame's target and 0 for
// the others, LINEAR between keys. Those frames x frames weights are one sparse
// accessor (3.6.2.3) with no bufferView: zeros but for the frames ones, stored
// as their indices and values, 8 bytes a frame, so that the file grows with the
// frames and not with their square (clients still expand the weights: 4 bytes
// per frame squared in their memory). At a key time the displayed positions are
// exactly base + target k, that is frame k (to float rounding: each of base
// and displacement rounds once, a few 1e-8 m on a 0.2 m feather); between keys
// they blend two neighbouring frames linearly. Both Blender's importer (shape
// keys driven by an action) and three.js (morphTargetInfluences through an
// AnimationMixer) play this. The animated mesh has no NORMAL attribute, so
// clients compute normals from the moving triangles (glTF requires flat normals
// then; Blender recomputes smooth ones).
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/asserts.h"
#include "../core/alloc.h"
#include "animation.h"
#include "export.h"
#include "glb.h"
#include "plume/gltf.h"

/// The most frames an animation's sim.glb holds: its sparse weights' largest index,
/// frames^2 - 1, is 32-bit (plume simulate refuses longer runs before they start).
#define MAX_FRAMES 65536

/// Area-weighted vertex normals of the triangles (unit; +z where a vertex has no area).
static void vertex_normals(const plume_mesh *mesh, const plume_vec3 *x, double *normals)
{
	memset(normals, 0, 3 * (size_t)mesh->vertex_count * sizeof(double));
	for (int f = 0; f < mesh->face_count; ++f) {
		const int *v = mesh->faces + 3 * f;
		plume_vec3 n = plume_v3_cross(plume_v3_sub(x[v[1]], x[v[0]]), plume_v3_sub(x[v[2]], x[v[0]]));
		for (int k = 0; k < 3; ++k) {
			normals[3 * v[k]] += n.x;
			normals[3 * v[k] + 1] += n.y;
			normals[3 * v[k] + 2] += n.z;
		}
	}
	for (int i = 0; i < mesh->vertex_count; ++i) {
		double *n = normals + 3 * i;
		double length = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
		if (length > 0) {
			n[0] /= length;
			n[1] /= length;
			n[2] /= length;
		} else {
			n[0] = n[1] = 0;
			n[2] = 1;
		}
	}
}

/// Materials of the faces present, in increasing order; returns how many (at most 256).
static int face_materials(const plume_mesh *mesh, int present[256])
{
	bool seen[256] = {false};
	for (int f = 0; f < mesh->face_count; ++f)
		seen[mesh->material != NULL ? mesh->material[f] : 0] = true;
	int count = 0;
	for (int m = 0; m < 256; ++m)
		if (seen[m])
			present[count++] = m;
	return count;
}

/// One primitive per material present, sharing the attributes; the material's colour from def.
static json_t *shell_primitives(plume_glb *glb, const plume_mesh *mesh, json_t *attributes, const plume_gltf_def *def,
                                json_t *targets, bool *ok)
{
	int present[256];
	int count = face_materials(mesh, present);
	json_t *primitives = json_array();
	uint32_t *indices = plume_alloc(3 * (size_t)(mesh->face_count > 0 ? mesh->face_count : 1) * sizeof(uint32_t));
	if (indices == NULL || primitives == NULL) {
		*ok = false;
		plume_free(indices);
		json_decref(primitives);
		return NULL;
	}
	for (int k = 0; k < count; ++k) {
		int64_t n = 0;
		for (int f = 0; f < mesh->face_count; ++f)
			if ((mesh->material != NULL ? mesh->material[f] : 0) == present[k])
				for (int c = 0; c < 3; ++c)
					indices[n++] = (uint32_t)mesh->faces[3 * f + c];
		plume_color srgb = present[k] == PLUME_MATERIAL_RACHIS ? def->rachis_color : def->vane_color;
		double factor[4] = {plume_glb_linear(srgb.r), plume_glb_linear(srgb.g), plume_glb_linear(srgb.b), srgb.a};
		char name[32];
		if (present[k] == PLUME_MATERIAL_VANE || present[k] == PLUME_MATERIAL_RACHIS)
			snprintf(name, sizeof name, "%s", present[k] == PLUME_MATERIAL_VANE ? "vane" : "rachis");
		else
			snprintf(name, sizeof name, "material_%d", present[k]);
		int material = plume_glb_material(glb, name, factor);
		json_t *primitive = json_pack("{s:O, s:i, s:i, s:i}", "attributes", attributes, "indices",
		                              plume_glb_indices(glb, indices, n), "mode", 4, "material", material);
		if (primitive != NULL && targets != NULL)
			json_object_set(primitive, "targets", targets);
		plume_glb_append(glb, primitives, primitive);
	}
	plume_free(indices);
	return primitives;
}

int plume_glb_shell_node(plume_glb *glb, const plume_mesh *mesh, const plume_vec3 *positions, const plume_gltf_def *def,
                         const char *name)
{
	const plume_vec3 *x = positions != NULL ? positions : mesh->rest;
	size_t n = (size_t)mesh->vertex_count;
	double *position = plume_alloc(3 * (n > 0 ? n : 1) * sizeof(double));
	double *normal = plume_alloc(3 * (n > 0 ? n : 1) * sizeof(double));
	double *uv = plume_alloc(2 * (n > 0 ? n : 1) * sizeof(double));
	bool ok = position != NULL && normal != NULL && uv != NULL;
	json_t *primitives = NULL;
	if (ok) {
		for (size_t i = 0; i < n; ++i) {
			position[3 * i] = x[i].x;
			position[3 * i + 1] = x[i].y;
			position[3 * i + 2] = x[i].z;
			uv[2 * i] = mesh->uv != NULL ? mesh->uv[i].x : 0.0;
			uv[2 * i + 1] = mesh->uv != NULL ? mesh->uv[i].y : 0.0;
		}
		vertex_normals(mesh, x, normal);
		json_t *attributes =
		    json_pack("{s:i, s:i, s:i}", "POSITION", plume_glb_floats(glb, position, (int)n, 3, GLB_ARRAY_BUFFER, true),
		              "NORMAL", plume_glb_floats(glb, normal, (int)n, 3, GLB_ARRAY_BUFFER, false), "TEXCOORD_0",
		              plume_glb_floats(glb, uv, (int)n, 2, GLB_ARRAY_BUFFER, false));
		primitives = shell_primitives(glb, mesh, attributes, def, NULL, &ok);
		json_decref(attributes);
	}
	plume_free(position);
	plume_free(normal);
	plume_free(uv);
	if (!ok) {
		glb->failed = true;
		return 0;
	}
	int index = plume_glb_append(glb, glb->meshes, json_pack("{s:s, s:o}", "name", name, "primitives", primitives));
	return plume_glb_append(glb, glb->nodes, json_pack("{s:s, s:i}", "name", name, "mesh", index));
}

plume_status plume_mesh_write_glb(const plume_mesh *mesh, const plume_vec3 *positions, const plume_gltf_def *def,
                                  const char *path, plume_error *err)
{
	PLUME_ASSERT(mesh != NULL && path != NULL);
	PLUME_ASSERT_DEF_OR_NULL(def);
	int bad = plume_mesh_find_non_finite(mesh, positions, true);
	if (bad >= 0)
		return plume_error_set(err, PLUME_ERROR_NUMERIC,
		                       "%s: vertex %d has a NaN or infinite number (or one past single precision, 3.4e38), "
		                       "which glTF's float accessors cannot hold",
		                       path, bad + 1);
	plume_gltf_def defaults = plume_gltf_default_def();
	if (def == NULL)
		def = &defaults;
	plume_glb glb;
	plume_glb_init(&glb, "plume " PLUME_VERSION_STRING);
	plume_glb_scene_root(&glb, plume_glb_shell_node(&glb, mesh, positions, def, "shell"));
	plume_status status = plume_glb_write(&glb, path, err);
	plume_glb_free(&glb);
	return status;
}

// ---------------------------------------------------------------------------
// Animation

plume_status plume_mesh_animation_create(const plume_mesh *mesh, const plume_gltf_def *def, plume_mesh_animation **out,
                                         plume_error *err)
{
	PLUME_ASSERT(mesh != NULL && out != NULL);
	PLUME_ASSERT_DEF_OR_NULL(def);
	*out = NULL;
	plume_mesh_animation *a = plume_calloc(1, sizeof *a);
	if (a == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "animation: out of memory");
	a->mesh = mesh;
	a->def = def != NULL ? *def : plume_gltf_default_def();
	a->def.texture = NULL; // not kept: the caller's texture may not outlive the animation
	a->first = plume_alloc(3 * (size_t)(mesh->vertex_count > 0 ? mesh->vertex_count : 1) * sizeof(double));
	if (a->first == NULL) {
		plume_free(a);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "animation: out of memory");
	}
	*out = a;
	return PLUME_OK;
}

plume_status plume_mesh_animation_add_frame(plume_mesh_animation *a, double time, const plume_vec3 *positions,
                                            plume_error *err)
{
	if (!isfinite(time) || (a->frame_count > 0 && !(time > a->times[a->frame_count - 1])))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "animation: frame time %g must be finite and after the previous frame's", time);
	size_t n = 3 * (size_t)a->mesh->vertex_count;
	if (a->frame_count == a->frame_capacity) {
		int capacity = a->frame_capacity > 0 ? 2 * a->frame_capacity : 16;
		double *times = plume_realloc(a->times, (size_t)capacity * sizeof(double));
		if (times != NULL)
			a->times = times;
		float *displacements = plume_realloc(a->displacements, (size_t)capacity * (n > 0 ? n : 1) * sizeof(float));
		if (displacements != NULL)
			a->displacements = displacements;
		if (times == NULL || displacements == NULL)
			return plume_error_set(err, PLUME_ERROR_MEMORY, "animation: out of memory at frame %d", a->frame_count);
		a->frame_capacity = capacity;
	}
	if (a->frame_count == 0)
		for (int i = 0; i < a->mesh->vertex_count; ++i) {
			a->first[3 * i] = positions[i].x;
			a->first[3 * i + 1] = positions[i].y;
			a->first[3 * i + 2] = positions[i].z;
		}
	float *d = a->displacements + (size_t)a->frame_count * n;
	for (int i = 0; i < a->mesh->vertex_count; ++i) {
		d[3 * i] = (float)(positions[i].x - a->first[3 * i]);
		d[3 * i + 1] = (float)(positions[i].y - a->first[3 * i + 1]);
		d[3 * i + 2] = (float)(positions[i].z - a->first[3 * i + 2]);
	}
	a->times[a->frame_count++] = time;
	return PLUME_OK;
}

int plume_mesh_animation_frame_count(const plume_mesh_animation *a) { return a->frame_count; }

void plume_mesh_animation_set_feather(plume_mesh_animation *a, const struct plume_barb_embedding *embedding)
{
	a->feather_count = 0;
	if (embedding == NULL)
		return;
	plume_error err;
	if (plume_mesh_animation_add_feather(a, embedding, "", &err) != PLUME_OK)
		a->feather_count = 0; // out of memory: no feather, as before the call (the shell is still written)
}

plume_status plume_mesh_animation_add_feather(plume_mesh_animation *a, const struct plume_barb_embedding *embedding,
                                              const char *name, plume_error *err)
{
	PLUME_ASSERT(a != NULL && embedding != NULL && name != NULL);
	const struct plume_barb_embedding **embeddings =
	    plume_realloc(a->embeddings, (size_t)(a->feather_count + 1) * sizeof *embeddings);
	if (embeddings != NULL)
		a->embeddings = embeddings;
	char(*names)[32] = plume_realloc(a->names, (size_t)(a->feather_count + 1) * sizeof *names);
	if (names != NULL)
		a->names = names;
	if (embeddings == NULL || names == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "animation: out of memory");
	a->embeddings[a->feather_count] = embedding;
	// "feather" for the one feather of plume_mesh_animation_set_feather, "feather_NAME" otherwise.
	snprintf(a->names[a->feather_count], sizeof a->names[0], "feather%s%.23s", name[0] != '\0' ? "_" : "", name);
	a->feather_count++;
	return PLUME_OK;
}

void plume_mesh_animation_set_body(plume_mesh_animation *a, const plume_mesh_animation *body) { a->body = body; }

/// The animation's frames in double (base + displacement), frame k at list[k]; NULL when memory runs out.
static plume_vec3 *frame_positions(const plume_mesh_animation *a, const plume_vec3 ***list)
{
	int n = a->mesh->vertex_count, frames = a->frame_count;
	plume_vec3 *positions = plume_alloc((size_t)frames * (size_t)(n > 0 ? n : 1) * sizeof(plume_vec3));
	*list = plume_alloc((size_t)frames * sizeof **list);
	if (positions == NULL || *list == NULL) {
		plume_free(positions);
		plume_free(*list);
		*list = NULL;
		return NULL;
	}
	for (int k = 0; k < frames; ++k) {
		plume_vec3 *x = positions + (size_t)k * (size_t)n;
		const float *d = a->displacements + (size_t)k * 3 * (size_t)n;
		for (int i = 0; i < n; ++i)
			x[i] = plume_v3(a->first[3 * i] + d[3 * i], a->first[3 * i + 1] + d[3 * i + 1],
			                a->first[3 * i + 2] + d[3 * i + 2]);
		(*list)[k] = x;
	}
	return positions;
}

/// A bufferView of `words` 4-byte values (no target, as sparse storage requires). glb.c makes
/// views only with an accessor of floats, which only copies the bytes here: that accessor is
/// made and dropped again, the view kept.
static int raw_view(plume_glb *glb, const void *data, int words)
{
	if (glb->failed)
		return 0;
	int accessor = plume_glb_floats_f(glb, (const float *)data, words, 1, GLB_NO_TARGET, false);
	json_t *object = json_array_get(glb->accessors, (size_t)accessor);
	json_t *view = json_object_get(object, "bufferView");
	int index = (int)json_integer_value(view);
	if (glb->failed || view == NULL || json_array_remove(glb->accessors, (size_t)accessor) != 0) {
		glb->failed = true;
		return 0;
	}
	return index;
}

/// The weights output of the animation's sampler: key k weighs target k by 1 and the others
/// by 0, frames x frames floats stored sparsely (3.6.2.3): no bufferView, so zeros, but for
/// the frames indices k (frames + 1) whose values are 1. Indices are 32-bit, so frames is at
/// most MAX_FRAMES. Returns the accessor.
static int one_hot_weights(plume_glb *glb, int frames)
{
	PLUME_ASSERT(frames >= 1 && frames <= MAX_FRAMES);
	uint32_t *indices = plume_alloc((size_t)frames * sizeof *indices);
	float *ones = plume_alloc((size_t)frames * sizeof *ones);
	int accessor = 0;
	if (indices != NULL && ones != NULL) {
		for (int k = 0; k < frames; ++k) {
			indices[k] = (uint32_t)((uint64_t)k * (uint64_t)frames + (uint64_t)k); // < 2^32, asserted above
			ones[k] = 1.0f;
		}
		int index_view = raw_view(glb, indices, frames);
		int value_view = raw_view(glb, ones, frames);
		json_t *object =
		    json_pack("{s:i, s:I, s:s, s:{s:i, s:{s:i, s:i}, s:{s:i}}}", "componentType", GLB_FLOAT, "count",
		              (json_int_t)frames * (json_int_t)frames, "type", "SCALAR", "sparse", "count", frames, "indices",
		              "bufferView", index_view, "componentType", GLB_UNSIGNED_INT, "values", "bufferView", value_view);
		accessor = plume_glb_append(glb, glb->accessors, object);
	} else {
		glb->failed = true;
	}
	plume_free(indices);
	plume_free(ones);
	return accessor;
}

/// The animation's mesh as node `name`: base positions the first frame, one morph target per frame.
static int morph_node(plume_glb *glb, const plume_mesh_animation *a, const char *name, bool *ok)
{
	const plume_mesh *mesh = a->mesh;
	int n = mesh->vertex_count, frames = a->frame_count;
	double *uv = plume_alloc(2 * (size_t)(n > 0 ? n : 1) * sizeof(double));
	if (uv == NULL) {
		*ok = false;
		return 0;
	}
	for (int i = 0; i < n; ++i) {
		uv[2 * i] = mesh->uv != NULL ? mesh->uv[i].x : 0.0;
		uv[2 * i + 1] = mesh->uv != NULL ? mesh->uv[i].y : 0.0;
	}
	json_t *attributes =
	    json_pack("{s:i, s:i}", "POSITION", plume_glb_floats(glb, a->first, n, 3, GLB_ARRAY_BUFFER, true), "TEXCOORD_0",
	              plume_glb_floats(glb, uv, n, 2, GLB_ARRAY_BUFFER, false));
	plume_free(uv);
	json_t *targets = json_array(), *names = json_array(), *initial = json_array();
	for (int k = 0; k < frames; ++k) {
		// Morph target POSITION accessors must have min and max (spec 3.7.2.2).
		int accessor =
		    plume_glb_floats_f(glb, a->displacements + (size_t)k * 3 * (size_t)n, n, 3, GLB_ARRAY_BUFFER, true);
		json_array_append_new(targets, json_pack("{s:i}", "POSITION", accessor));
		char target[32];
		snprintf(target, sizeof target, "frame_%04d", k);
		json_array_append_new(names, json_string(target));
		json_array_append_new(initial, json_real(k == 0 ? 1.0 : 0.0));
	}
	json_t *primitives = shell_primitives(glb, mesh, attributes, &a->def, targets, ok);
	json_decref(attributes);
	json_decref(targets);
	// targetNames in extras: Blender names the shape keys after them, three.js the morph targets.
	int mesh_index = plume_glb_append(glb, glb->meshes,
	                                  json_pack("{s:s, s:o, s:o, s:{s:o}}", "name", name, "primitives", primitives,
	                                            "weights", initial, "extras", "targetNames", names));
	return plume_glb_append(glb, glb->nodes, json_pack("{s:s, s:i}", "name", name, "mesh", mesh_index));
}

plume_status plume_mesh_animation_write_glb(const plume_mesh_animation *a, const char *path, plume_error *err)
{
	if (a->frame_count == 0)
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: an animation needs at least one frame", path);
	const int frames = a->frame_count;
	if (a->body != NULL) {
		bool same = a->body->frame_count == frames;
		for (int k = 0; same && k < frames; ++k)
			same = a->body->times[k] == a->times[k];
		if (!same)
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "%s: the body has %d frames, the shell %d (or at other times); they must match",
			                       path, a->body->frame_count, frames);
	}
	if (frames > MAX_FRAMES)
		return plume_error_set(err, PLUME_ERROR_LIMIT,
		                       "%s: %d frames; a glTF morph animation of one target per frame holds at most %d (its "
		                       "sparse weights are indexed in 32 bits)",
		                       path, frames, MAX_FRAMES);
	plume_glb glb;
	plume_glb_init(&glb, "plume " PLUME_VERSION_STRING);
	// Every node whose weights the animation keys: the shell, each carried feather (as many
	// targets, one per frame), the body.
	int *animated = plume_alloc((size_t)(a->feather_count + 2) * sizeof *animated);
	int animated_count = 0;
	bool ok = animated != NULL;
	if (ok) {
		animated[animated_count] = morph_node(&glb, a, "shell", &ok);
		plume_glb_scene_root(&glb, animated[animated_count++]);
		if (ok && a->feather_count > 0) {
			const plume_vec3 **list = NULL;
			plume_vec3 *positions = frame_positions(a, &list);
			ok = positions != NULL;
			for (int f = 0; ok && f < a->feather_count; ++f) {
				int node = plume_glb_carried_feather(&glb, a->embeddings[f], list, frames, a->names[f], &a->def, &ok);
				if (ok) {
					plume_glb_scene_root(&glb, node);
					animated[animated_count++] = node;
				}
			}
			plume_free(positions);
			plume_free(list);
		}
		if (ok && a->body != NULL) {
			animated[animated_count] = morph_node(&glb, a->body, "body", &ok);
			plume_glb_scene_root(&glb, animated[animated_count++]);
		}
		float *times = plume_alloc((size_t)frames * sizeof(float));
		ok = ok && times != NULL;
		if (ok) {
			for (int k = 0; k < frames; ++k)
				times[k] = (float)a->times[k];
			// Sampler input must have min and max (spec 3.11).
			int input = plume_glb_floats_f(&glb, times, frames, 1, GLB_NO_TARGET, true);
			int output = one_hot_weights(&glb, frames);
			json_t *channels = json_array();
			for (int k = 0; k < animated_count; ++k)
				json_array_append_new(channels, json_pack("{s:i, s:{s:i, s:s}}", "sampler", 0, "target", "node",
				                                          animated[k], "path", "weights"));
			json_t *animation = json_pack("{s:s, s:[{s:i, s:s, s:i}], s:o}", "name", "simulation", "samplers", "input",
			                              input, "interpolation", "LINEAR", "output", output, "channels", channels);
			json_t *animations = json_array();
			plume_glb_append(&glb, animations, animation);
			if (json_object_set_new(glb.root, "animations", animations) != 0)
				glb.failed = true;
		}
		plume_free(times);
	}
	plume_free(animated);
	plume_status status =
	    ok ? plume_glb_write(&glb, path, err) : plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	plume_glb_free(&glb);
	return status;
}

void plume_mesh_animation_destroy(plume_mesh_animation *a)
{
	if (a == NULL)
		return;
	plume_free(a->times);
	plume_free(a->first);
	plume_free(a->displacements);
	plume_free(a->embeddings);
	plume_free(a->names);
	plume_free(a);
}

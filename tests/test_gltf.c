// glTF 2.0 binary export read back: the container's layout (spec 4.4), the
// JSON document, and every array compared with what was written: ribbons
// centred on the curves with their widths, normals, texture coordinates and
// colours; the shell's positions and faces; an animation whose frames are
// base + morph target to 1e-6 m at their key times; a coat's instances.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sys/stat.h>

#include <jansson.h>

#include "support.h"

static char scratch[256];

static int setup(void **state)
{
	(void)state;
	test_make_temp_dir(scratch, sizeof scratch);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	test_remove_tree(scratch);
	return 0;
}

// ---------------------------------------------------------------------------
// A small GLB reader (independent of the writer's code)

typedef struct glb_file {
	unsigned char *bytes;
	size_t size;
	json_t *doc;
	const unsigned char *bin;
	size_t bin_size;
} glb_file;

static uint32_t u32(const unsigned char *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static glb_file glb_read(const char *path)
{
	glb_file g = {0};
	g.bytes = test_read_file(path, &g.size);
	assert_non_null(g.bytes);
	assert_true(g.size >= 20);
	assert_memory_equal(g.bytes, "glTF", 4);
	assert_int_equal(u32(g.bytes + 4), 2);
	assert_int_equal(u32(g.bytes + 8), g.size);
	uint32_t json_length = u32(g.bytes + 12);
	assert_int_equal(json_length % 4, 0);
	assert_memory_equal(g.bytes + 16, "JSON", 4);
	json_error_t error;
	g.doc = json_loadb((const char *)g.bytes + 20, json_length, JSON_REJECT_DUPLICATES, &error);
	if (g.doc == NULL)
		fail_msg("%s: JSON chunk: %s", path, error.text);
	size_t at = 20 + json_length;
	if (at < g.size) {
		uint32_t bin_length = u32(g.bytes + at);
		assert_int_equal(bin_length % 4, 0);
		assert_memory_equal(g.bytes + at + 4, "BIN\0", 4);
		assert_int_equal(at + 8 + bin_length, g.size);
		g.bin = g.bytes + at + 8;
		g.bin_size = bin_length;
		json_int_t declared =
		    json_integer_value(json_object_get(json_array_get(json_object_get(g.doc, "buffers"), 0), "byteLength"));
		assert_true(declared <= (json_int_t)bin_length && declared + 3 >= (json_int_t)bin_length);
	}
	assert_string_equal(json_string_value(json_object_get(json_object_get(g.doc, "asset"), "version")), "2.0");
	return g;
}

static void glb_free(glb_file *g)
{
	json_decref(g->doc);
	free(g->bytes);
}

static int components_of(const char *type)
{
	return strcmp(type, "SCALAR") == 0 ? 1 : strcmp(type, "VEC2") == 0 ? 2 : strcmp(type, "VEC3") == 0 ? 3 : 4;
}

/// Accessor index's data: a pointer into the buffer, its count and component count; checks the type.
static const void *accessor(const glb_file *g, int index, int component_type, int *count, int *components)
{
	json_t *a = json_array_get(json_object_get(g->doc, "accessors"), (size_t)index);
	assert_non_null(a);
	assert_int_equal(json_integer_value(json_object_get(a, "componentType")), component_type);
	*count = (int)json_integer_value(json_object_get(a, "count"));
	*components = components_of(json_string_value(json_object_get(a, "type")));
	json_t *view = json_array_get(json_object_get(g->doc, "bufferViews"),
	                              (size_t)json_integer_value(json_object_get(a, "bufferView")));
	assert_non_null(view);
	assert_null(json_object_get(view, "byteStride"));
	size_t offset = (size_t)json_integer_value(json_object_get(view, "byteOffset")) +
	                (size_t)json_integer_value(json_object_get(a, "byteOffset"));
	size_t length = (size_t)json_integer_value(json_object_get(view, "byteLength"));
	assert_int_equal(offset % 4, 0);
	assert_true(length >= (size_t)*count * (size_t)*components * 4);
	assert_true(offset + length <= g->bin_size);
	return g->bin + offset;
}

static const float *floats(const glb_file *g, int index, int *count, int components)
{
	int c;
	const float *data = accessor(g, index, 5126, count, &c);
	assert_int_equal(c, components);
	return data;
}

/// A sparse accessor of floats with no bufferView (zeros, but for the sparse entries),
/// expanded: a malloc'd array of count * components floats. Checks the storage rules of
/// glTF 2.0 3.6.2.3: indices strictly increasing, views without a target.
static float *sparse_floats(const glb_file *g, int index, int *count, int components)
{
	json_t *a = json_array_get(json_object_get(g->doc, "accessors"), (size_t)index);
	assert_non_null(a);
	assert_null(json_object_get(a, "bufferView"));
	assert_int_equal(json_integer_value(json_object_get(a, "componentType")), 5126);
	assert_int_equal(components_of(json_string_value(json_object_get(a, "type"))), components);
	json_int_t total = json_integer_value(json_object_get(a, "count"));
	*count = (int)total;
	float *values = calloc((size_t)total * (size_t)components, sizeof *values);
	assert_non_null(values);
	json_t *sparse = json_object_get(a, "sparse");
	int n = (int)json_integer_value(json_object_get(sparse, "count"));
	json_t *indices = json_object_get(sparse, "indices"), *stored = json_object_get(sparse, "values");
	assert_int_equal(json_integer_value(json_object_get(indices, "componentType")), 5125);
	json_t *views = json_object_get(g->doc, "bufferViews");
	json_t *index_view = json_array_get(views, (size_t)json_integer_value(json_object_get(indices, "bufferView")));
	json_t *value_view = json_array_get(views, (size_t)json_integer_value(json_object_get(stored, "bufferView")));
	assert_non_null(index_view);
	assert_non_null(value_view);
	assert_null(json_object_get(index_view, "target"));
	assert_null(json_object_get(value_view, "target"));
	assert_true(json_integer_value(json_object_get(index_view, "byteLength")) >= 4 * (json_int_t)n);
	assert_true(json_integer_value(json_object_get(value_view, "byteLength")) >= 4 * (json_int_t)n * components);
	const uint32_t *at = (const uint32_t *)(g->bin + json_integer_value(json_object_get(index_view, "byteOffset")));
	const float *v = (const float *)(g->bin + json_integer_value(json_object_get(value_view, "byteOffset")));
	for (int i = 0; i < n; ++i) {
		assert_true(at[i] < (uint64_t)total);
		if (i > 0)
			assert_true(at[i] > at[i - 1]);
		for (int c = 0; c < components; ++c)
			values[(size_t)at[i] * (size_t)components + (size_t)c] = v[(size_t)i * (size_t)components + (size_t)c];
	}
	return values;
}

/// The named node's mesh's primitive p.
static json_t *primitive_of(const glb_file *g, const char *node_name, int p)
{
	json_t *nodes = json_object_get(g->doc, "nodes");
	for (size_t i = 0; i < json_array_size(nodes); ++i) {
		json_t *node = json_array_get(nodes, i);
		if (strcmp(json_string_value(json_object_get(node, "name")), node_name) == 0) {
			json_t *mesh = json_array_get(json_object_get(g->doc, "meshes"),
			                              (size_t)json_integer_value(json_object_get(node, "mesh")));
			return json_array_get(json_object_get(mesh, "primitives"), (size_t)p);
		}
	}
	fail_msg("no node %s", node_name);
	return NULL;
}

static int attribute(json_t *primitive, const char *name)
{
	json_t *a = json_object_get(json_object_get(primitive, "attributes"), name);
	assert_non_null(a);
	return (int)json_integer_value(a);
}

static double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

// ---------------------------------------------------------------------------

static plume_feather *blue(void)
{
	plume_spec_options options = {0};
	plume_feather *feather = NULL;
	plume_error err;
	if (plume_spec_generate(PLUME_SOURCE_DIR "/examples/franco-walter/blue.json", &options, &feather, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	return feather;
}

static void test_feather_ribbons_read_back(void **state)
{
	(void)state;
	plume_feather *feather = blue();
	char path[512];
	snprintf(path, sizeof path, "%s/feather.glb", scratch);
	plume_error err;
	assert_int_equal(plume_write_glb(feather, NULL, path, &err), PLUME_OK);
	glb_file g = glb_read(path);
	plume_gltf_def def = plume_gltf_default_def();
	plume_feather_info info = plume_feather_get_info(feather);
	const char *names[2] = {"left_vane", "right_vane"};
	for (int side = 0; side < 2; ++side) {
		json_t *primitive = primitive_of(&g, names[side], 0);
		assert_int_equal(json_integer_value(json_object_get(primitive, "mode")), 4);
		int n, nn, nt, nc, ni, ci;
		const float *x = floats(&g, attribute(primitive, "POSITION"), &n, 3);
		const float *normal = floats(&g, attribute(primitive, "NORMAL"), &nn, 3);
		const float *uv = floats(&g, attribute(primitive, "TEXCOORD_0"), &nt, 2);
		const float *color = floats(&g, attribute(primitive, "COLOR_0"), &nc, 4);
		const uint32_t *index =
		    accessor(&g, (int)json_integer_value(json_object_get(primitive, "indices")), 5125, &ni, &ci);
		assert_int_equal(nn, n);
		assert_int_equal(nt, n);
		assert_int_equal(nc, n);
		int v = 0, t = 0;
		for (int b = 0; b < info.barb_count; ++b) {
			plume_barb barb = plume_feather_barb(feather, b);
			if ((int)barb.side != side || barb.curve.count < 2)
				continue;
			for (int j = 0; j < barb.curve.count; ++j, v += 2) {
				assert_true(v + 1 < n);
				const float *a = x + 3 * v, *c = x + 3 * v + 3;
				plume_vec3 p = barb.curve.points[j];
				// The ribbon's two edges are centred on the point, a width apart, across the normal.
				assert_close(0.5 * (a[0] + c[0]), p.x, 1e-6);
				assert_close(0.5 * (a[1] + c[1]), p.y, 1e-6);
				assert_close(0.5 * (a[2] + c[2]), p.z, 1e-6);
				double dx = c[0] - a[0], dy = c[1] - a[1], dz = c[2] - a[2];
				assert_close(sqrt(dx * dx + dy * dy + dz * dz), barb.curve.widths[j], 1e-6);
				plume_vec3 nj = barb.curve.normals[j];
				assert_close(dx * nj.x + dy * nj.y + dz * nj.z, 0.0, 1e-6);
				for (int e = 0; e < 2; ++e) {
					assert_close(normal[3 * (v + e)], nj.x, 1e-6);
					assert_close(normal[3 * (v + e) + 2], nj.z, 1e-6);
					assert_close(uv[2 * (v + e)], barb.curve.uv[j].x, 1e-6);
					assert_close(uv[2 * (v + e) + 1], barb.curve.uv[j].y, 1e-6);
					assert_close(color[4 * (v + e)], srgb_to_linear(def.barb_color.r), 1e-6);
					assert_close(color[4 * (v + e) + 3], 1.0, 0);
				}
			}
			t += 6 * (barb.curve.count - 1);
		}
		assert_int_equal(v, n);
		assert_int_equal(t, ni);
		for (int i = 0; i < ni; ++i)
			assert_true(index[i] < (uint32_t)n);
		// Every triangle faces the curve's normal (counter-clockwise seen from it).
		for (int i = 0; i < ni; i += 3) {
			const float *p0 = x + 3 * index[i], *p1 = x + 3 * index[i + 1], *p2 = x + 3 * index[i + 2];
			plume_vec3 e1 = plume_v3(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
			plume_vec3 e2 = plume_v3(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]);
			plume_vec3 face = plume_v3_cross(e1, e2);
			const float *nv = normal + 3 * index[i];
			assert_true(face.x * nv[0] + face.y * nv[1] + face.z * nv[2] >= 0.0);
		}
	}
	// The shaft: one ribbon of every sample; POSITION has min and max.
	json_t *shaft = primitive_of(&g, "shaft", 0);
	json_t *position = json_array_get(json_object_get(g.doc, "accessors"), (size_t)attribute(shaft, "POSITION"));
	assert_int_equal(json_integer_value(json_object_get(position, "count")), 2 * info.shaft_sample_count);
	assert_int_equal(json_array_size(json_object_get(position, "min")), 3);
	assert_int_equal(json_array_size(json_object_get(position, "max")), 3);
	glb_free(&g);

	// Lines: one vertex per point and two indices per segment.
	def.curves = PLUME_GLTF_LINES;
	assert_int_equal(plume_write_glb(feather, &def, path, &err), PLUME_OK);
	g = glb_read(path);
	json_t *left = primitive_of(&g, "left_vane", 0);
	assert_int_equal(json_integer_value(json_object_get(left, "mode")), 1);
	int n, ni, ci, points = 0, segments = 0;
	floats(&g, attribute(left, "POSITION"), &n, 3);
	accessor(&g, (int)json_integer_value(json_object_get(left, "indices")), 5125, &ni, &ci);
	for (int b = 0; b < info.barb_count; ++b) {
		plume_barb barb = plume_feather_barb(feather, b);
		if (barb.side == PLUME_SIDE_LEFT && barb.curve.count >= 2) {
			points += barb.curve.count;
			segments += barb.curve.count - 1;
		}
	}
	assert_int_equal(n, points);
	assert_int_equal(ni, 2 * segments);
	glb_free(&g);

	// Same feather, same bytes.
	char again[512];
	snprintf(again, sizeof again, "%s/again.glb", scratch);
	assert_int_equal(plume_write_glb(feather, &def, again, &err), PLUME_OK);
	assert_true(test_hash_file(again) == test_hash_file(path));
	plume_feather_destroy(feather);
}

static plume_mesh *blue_mesh(plume_feather *feather)
{
	plume_mesh_def def = plume_mesh_default_def();
	def.edge_length = 0.01;
	plume_mesh *mesh = NULL;
	plume_error err;
	if (plume_mesh_from_feather(feather, &def, &mesh, NULL, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	return mesh;
}

/// The USD file's points time samples: one per frame at time code 24 t, each the frame's points.
static void check_usda_frames(const char *path, const plume_mesh *mesh, const double times[3])
{
	char *text = (char *)test_read_file(path, NULL);
	assert_non_null(text);
	assert_non_null(strstr(text, "timeCodesPerSecond = 24\n"));
	char *at = strstr(text, "point3f[] points.timeSamples = {\n");
	assert_non_null(at);
	at = strchr(at, '\n') + 1;
	for (int k = 0; k < 3; ++k) {
		char *end;
		double code = strtod(at, &end);
		assert_close(code, 24 * times[k], 1e-9);
		assert_true(strncmp(end, ": [", 3) == 0);
		at = end + 3;
		for (int i = 0; i < mesh->vertex_count; ++i) {
			double p[3];
			int used = 0;
			if (i > 0) {
				assert_true(strncmp(at, ", ", 2) == 0);
				at += 2;
			}
			assert_int_equal(sscanf(at, "(%lf, %lf, %lf)%n", &p[0], &p[1], &p[2], &used), 3);
			at += used;
			plume_vec3 want =
			    plume_v3_add(mesh->rest[i], plume_v3(0.01 * k * mesh->rest[i].y, 0.003 * k, -0.02 * k * k));
			assert_close(p[0], want.x, 1e-6);
			assert_close(p[1], want.y, 1e-6);
			assert_close(p[2], want.z, 1e-6);
		}
		assert_true(strncmp(at, "],\n", 3) == 0);
		at += 3;
	}
	assert_true(strncmp(at, "    }", 5) == 0);
	assert_non_null(strstr(text, "color3f[] primvars:displayColor = ["));
	free(text);
}

static void test_shell_and_animation_read_back(void **state)
{
	(void)state;
	plume_feather *feather = blue();
	plume_mesh *mesh = blue_mesh(feather);
	char path[512];
	snprintf(path, sizeof path, "%s/shell.glb", scratch);
	plume_error err;
	assert_int_equal(plume_mesh_write_glb(mesh, NULL, NULL, path, &err), PLUME_OK);
	glb_file g = glb_read(path);
	int faces = 0;
	for (int p = 0; p < 2; ++p) {
		json_t *primitive = primitive_of(&g, "shell", p);
		assert_non_null(primitive);
		int n, ni, ci;
		const float *x = floats(&g, attribute(primitive, "POSITION"), &n, 3);
		assert_int_equal(n, mesh->vertex_count);
		for (int i = 0; i < n; ++i)
			assert_close(x[3 * i + 1], mesh->rest[i].y, 1e-6);
		const uint32_t *index =
		    accessor(&g, (int)json_integer_value(json_object_get(primitive, "indices")), 5125, &ni, &ci);
		// Faces of primitive p are the mesh's faces of material p, in order.
		int k = 0;
		for (int f = 0; f < mesh->face_count; ++f) {
			if (mesh->material[f] != p)
				continue;
			for (int c = 0; c < 3; ++c)
				assert_int_equal(index[k + c], mesh->faces[3 * f + c]);
			k += 3;
		}
		assert_int_equal(k, ni);
		faces += ni / 3;
	}
	assert_int_equal(faces, mesh->face_count);
	glb_free(&g);

	// An animation of three frames: rest, rest + d, rest + 2d (d grows along y).
	plume_mesh_animation *animation = NULL;
	assert_int_equal(plume_mesh_animation_create(mesh, NULL, &animation, &err), PLUME_OK);
	plume_vec3 *x = malloc((size_t)mesh->vertex_count * sizeof *x);
	double times[3] = {0.0, 0.1, 0.35};
	for (int k = 0; k < 3; ++k) {
		for (int i = 0; i < mesh->vertex_count; ++i)
			x[i] = plume_v3_add(mesh->rest[i], plume_v3(0.01 * k * mesh->rest[i].y, 0.003 * k, -0.02 * k * k));
		assert_int_equal(plume_mesh_animation_add_frame(animation, times[k], x, &err), PLUME_OK);
	}
	assert_int_equal(plume_mesh_animation_add_frame(animation, 0.35, x, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "after the previous frame"));
	assert_int_equal(plume_mesh_animation_frame_count(animation), 3);
	snprintf(path, sizeof path, "%s/sim.glb", scratch);
	assert_int_equal(plume_mesh_animation_write_glb(animation, path, &err), PLUME_OK);
	char usda[512];
	snprintf(usda, sizeof usda, "%s/sim.usda", scratch);
	assert_int_equal(plume_mesh_animation_write_usda(animation, usda, &err), PLUME_OK);
	plume_mesh_animation_destroy(animation);
	check_usda_frames(usda, mesh, times);
	g = glb_read(path);
	json_t *primitive = primitive_of(&g, "shell", 0);
	json_t *targets = json_object_get(primitive, "targets");
	assert_int_equal(json_array_size(targets), 3);
	int n;
	const float *base = floats(&g, attribute(primitive, "POSITION"), &n, 3);
	for (int k = 0; k < 3; ++k) {
		int nt;
		const float *d = floats(
		    &g, (int)json_integer_value(json_object_get(json_array_get(targets, (size_t)k), "POSITION")), &nt, 3);
		assert_int_equal(nt, n);
		for (int i = 0; i < n; ++i) {
			plume_vec3 want =
			    plume_v3_add(mesh->rest[i], plume_v3(0.01 * k * mesh->rest[i].y, 0.003 * k, -0.02 * k * k));
			assert_close((double)base[3 * i] + d[3 * i], want.x, 1e-6);
			assert_close((double)base[3 * i + 1] + d[3 * i + 1], want.y, 1e-6);
			assert_close((double)base[3 * i + 2] + d[3 * i + 2], want.z, 1e-6);
		}
	}
	json_t *anim = json_array_get(json_object_get(g.doc, "animations"), 0);
	json_t *sampler = json_array_get(json_object_get(anim, "samplers"), 0);
	json_t *channel = json_array_get(json_object_get(anim, "channels"), 0);
	assert_string_equal(json_string_value(json_object_get(json_object_get(channel, "target"), "path")), "weights");
	int nk, nw;
	const float *t = floats(&g, (int)json_integer_value(json_object_get(sampler, "input")), &nk, 1);
	float *w = sparse_floats(&g, (int)json_integer_value(json_object_get(sampler, "output")), &nw, 1);
	assert_int_equal(nk, 3);
	assert_int_equal(nw, 9);
	for (int k = 0; k < 3; ++k) {
		assert_close(t[k], times[k], 1e-7);
		for (int j = 0; j < 3; ++j)
			assert_close(w[3 * k + j], j == k ? 1.0 : 0.0, 0);
	}
	free(w);
	glb_free(&g);
	free(x);

	// Many frames: the file grows with the frames, not their square. The one-hot weights of
	// 600 keys (600 x 600 floats, 1.44 MB stored densely) take 8 bytes a key.
	plume_mesh *tiny = plume_mesh_create(3, 1);
	tiny->rest[1] = plume_v3(1, 0, 0);
	tiny->rest[2] = plume_v3(0, 1, 0);
	tiny->faces[0] = 0, tiny->faces[1] = 1, tiny->faces[2] = 2;
	assert_int_equal(plume_mesh_animation_create(tiny, NULL, &animation, &err), PLUME_OK);
	const int many = 600;
	for (int k = 0; k < many; ++k) {
		plume_vec3 moved[3] = {plume_v3(0, 0, 1e-3 * k), plume_v3(1, 0, 0), plume_v3(0, 1, 0)};
		assert_int_equal(plume_mesh_animation_add_frame(animation, 0.01 * k, moved, &err), PLUME_OK);
	}
	assert_int_equal(plume_mesh_animation_write_glb(animation, path, &err), PLUME_OK);
	plume_mesh_animation_destroy(animation);
	plume_mesh_destroy(tiny);
	g = glb_read(path);
	// Per frame: a target of 3 vertices (36 bytes), a time (4) and a sparse weight (8).
	assert_true(g.bin_size <= (size_t)many * (36 + 4 + 8) + 1024);
	anim = json_array_get(json_object_get(g.doc, "animations"), 0);
	sampler = json_array_get(json_object_get(anim, "samplers"), 0);
	w = sparse_floats(&g, (int)json_integer_value(json_object_get(sampler, "output")), &nw, 1);
	assert_int_equal(nw, many * many);
	for (int k = 0; k < many; ++k)
		for (int j = 0; j < many; ++j)
			assert_true(w[(size_t)k * many + (size_t)j] == (j == k ? 1.0f : 0.0f));
	free(w);
	glb_free(&g);

	// A folder that does not exist: an error naming the path, nothing written.
	assert_int_equal(plume_mesh_write_glb(mesh, NULL, NULL, "/nonexistent-plume/shell.glb", &err), PLUME_ERROR_IO);
	assert_non_null(strstr(err.message, "/nonexistent-plume/shell.glb"));
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
}

/// Points of a feather in the order the carried-feather lines hold them: shaft, left
/// barbs, right barbs, barbules (curves of two points or more).
static int feather_points(const plume_feather *feather, plume_vec3 *out)
{
	plume_feather_info info = plume_feather_get_info(feather);
	int n = 0;
	if (info.shaft_sample_count >= 2)
		for (int i = 0; i < info.shaft_sample_count; ++i)
			out[n++] = plume_feather_shaft(feather)[i].position;
	for (int side = 0; side < 2; ++side)
		for (int b = 0; b < info.barb_count; ++b) {
			plume_barb barb = plume_feather_barb(feather, b);
			if ((int)barb.side == side && barb.curve.count >= 2)
				for (int j = 0; j < barb.curve.count; ++j)
					out[n++] = barb.curve.points[j];
		}
	for (int b = 0; b < info.barbule_count; ++b) {
		plume_barbule barbule = plume_feather_barbule(feather, b);
		if (barbule.curve.count >= 2)
			for (int j = 0; j < barbule.curve.count; ++j)
				out[n++] = barbule.curve.points[j];
	}
	return n;
}

static void test_carried_feather(void **state)
{
	(void)state;
	plume_feather *feather = blue();
	plume_mesh *mesh = blue_mesh(feather);
	plume_error err;
	plume_barb_embedding *embedding = NULL;
	assert_int_equal(plume_embedding_create(feather, mesh, &embedding, &err), PLUME_OK);
	plume_mesh_animation *animation = NULL;
	assert_int_equal(plume_mesh_animation_create(mesh, NULL, &animation, &err), PLUME_OK);
	plume_mesh_animation_set_feather(animation, embedding);
	plume_vec3 *x[2];
	for (int k = 0; k < 2; ++k) {
		x[k] = malloc((size_t)mesh->vertex_count * sizeof(plume_vec3));
		for (int i = 0; i < mesh->vertex_count; ++i) // frame 1: the shell bends out of its plane
			x[k][i] = plume_v3_add(mesh->rest[i], plume_v3(0, 0, 0.3 * k * mesh->rest[i].y * mesh->rest[i].y));
		assert_int_equal(plume_mesh_animation_add_frame(animation, 0.1 * k, x[k], &err), PLUME_OK);
	}
	char path[512];
	snprintf(path, sizeof path, "%s/carried.glb", scratch);
	assert_int_equal(plume_mesh_animation_write_glb(animation, path, &err), PLUME_OK);
	glb_file g = glb_read(path);
	json_t *primitive = primitive_of(&g, "feather", 0);
	assert_int_equal(json_integer_value(json_object_get(primitive, "mode")), 1);
	int n;
	const float *base = floats(&g, attribute(primitive, "POSITION"), &n, 3);
	plume_feather_info info = plume_feather_get_info(feather);
	plume_vec3 *want = malloc((size_t)(info.point_count + info.shaft_sample_count) * sizeof(plume_vec3));
	for (int k = 0; k < 2; ++k) {
		plume_feather *moved = NULL;
		assert_int_equal(plume_embedding_apply(embedding, x[k], &moved, &err), PLUME_OK);
		assert_int_equal(feather_points(moved, want), n);
		int nt;
		json_t *target = json_array_get(json_object_get(primitive, "targets"), (size_t)k);
		const float *d = floats(&g, (int)json_integer_value(json_object_get(target, "POSITION")), &nt, 3);
		assert_int_equal(nt, n);
		for (int i = 0; i < n; ++i) {
			assert_close((double)base[3 * i] + d[3 * i], want[i].x, 1e-6);
			assert_close((double)base[3 * i + 2] + d[3 * i + 2], want[i].z, 1e-6);
		}
		plume_feather_destroy(moved);
	}
	// The animation drives both nodes.
	json_t *channels = json_object_get(json_array_get(json_object_get(g.doc, "animations"), 0), "channels");
	assert_int_equal(json_array_size(channels), 2);
	glb_free(&g);
	free(want);
	free(x[0]);
	free(x[1]);
	plume_mesh_animation_destroy(animation);
	plume_embedding_destroy(embedding);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
}

static void test_coat_instances(void **state)
{
	(void)state;
	plume_spec_options options = {0};
	plume_coat *coat = NULL;
	plume_error err;
	if (plume_coat_spec_generate(PLUME_SOURCE_DIR "/examples/coats/figure15-hexagonal.json", &options, &coat, &err) !=
	    PLUME_OK)
		fail_msg("%s", err.message);
	char path[512];
	snprintf(path, sizeof path, "%s/coat.glb", scratch);
	plume_coat_glb_report report;
	assert_int_equal(plume_coat_write_glb_report(coat, NULL, path, &report, &err), PLUME_OK);
	int count = plume_coat_feather_count(coat);
	assert_int_equal(report.instances, count);
	assert_true(report.meshes >= 1 && report.meshes <= count);
	glb_file g = glb_read(path);
	json_t *nodes = json_object_get(g.doc, "nodes");
	int instances = 0;
	for (size_t i = 0; i < json_array_size(nodes); ++i) {
		json_t *node = json_array_get(nodes, i);
		const char *name = json_string_value(json_object_get(node, "name"));
		if (strncmp(name, "feather_", 8) != 0)
			continue;
		int index = atoi(name + 8);
		plume_vec3 follicle, normal;
		plume_coat_follicle(coat, index, &follicle, &normal);
		json_t *translation = json_object_get(node, "translation");
		assert_close(json_real_value(json_array_get(translation, 0)), follicle.x, 1e-6);
		assert_close(json_real_value(json_array_get(translation, 1)), follicle.y, 1e-6);
		assert_close(json_real_value(json_array_get(translation, 2)), follicle.z, 1e-6);
		// The mesh plus the translation puts the shaft's first sample where the feather's is.
		json_t *mesh =
		    json_array_get(json_object_get(g.doc, "meshes"), (size_t)json_integer_value(json_object_get(node, "mesh")));
		json_t *shaft = json_array_get(json_object_get(mesh, "primitives"), 0);
		int n;
		const float *x = floats(&g, attribute(shaft, "POSITION"), &n, 3);
		plume_vec3 root = plume_feather_shaft(plume_coat_feather(coat, index))[0].position;
		assert_close(0.5 * (x[0] + x[3]) + follicle.x, root.x, 1e-6);
		assert_close(0.5 * (x[1] + x[4]) + follicle.y, root.y, 1e-6);
		++instances;
	}
	assert_int_equal(instances, count);
	// The surface mesh has the coat surface's faces.
	json_t *surface = primitive_of(&g, "surface", 0);
	int ni, ci;
	accessor(&g, (int)json_integer_value(json_object_get(surface, "indices")), 5125, &ni, &ci);
	assert_int_equal(ni, 3 * plume_coat_surface(coat)->face_count);
	glb_free(&g);

	// USD: a PointInstancer with one prototype per feather, instance i at follicle i.
	snprintf(path, sizeof path, "%s/coat.usda", scratch);
	assert_int_equal(plume_coat_write_usda(coat, path, &err), PLUME_OK);
	char *text = (char *)test_read_file(path, NULL);
	assert_non_null(text);
	char *instancer = strstr(text, "def PointInstancer \"feathers\"");
	assert_non_null(instancer);
	char *positions = strstr(instancer, "point3f[] positions = [");
	assert_non_null(positions);
	positions += strlen("point3f[] positions = [");
	for (int i = 0; i < count; ++i) {
		double p[3];
		int used = 0;
		assert_int_equal(sscanf(positions, "%*[, ](%lf, %lf, %lf)%n", &p[0], &p[1], &p[2], &used) == 3 ||
		                     sscanf(positions, "(%lf, %lf, %lf)%n", &p[0], &p[1], &p[2], &used) == 3,
		                 1);
		positions += used;
		plume_vec3 follicle, normal;
		plume_coat_follicle(coat, i, &follicle, &normal);
		assert_close(p[0], follicle.x, 1e-6);
		assert_close(p[2], follicle.z, 1e-6);
		char name[64];
		snprintf(name, sizeof name, "</coat/feathers/prototypes/feather_%05d>", i);
		assert_non_null(strstr(instancer, name));
		snprintf(name, sizeof name, "def BasisCurves \"feather_%05d\"", i);
		assert_non_null(strstr(instancer, name));
	}
	assert_true(strncmp(positions, "]\n", 2) == 0);
	free(text);
	plume_coat_destroy(coat);
}

// ---------------------------------------------------------------------------
// Memory: the writers stream the binary chunk to the file and hold one part's arrays (coats: two
// feathers') at a time. Peaks count plume's allocations and jansson's (the JSON document).

static _Atomic int64_t peak_bytes, json_bytes;

static void note_peak(int64_t now)
{
	int64_t seen = atomic_load(&peak_bytes);
	while (now > seen && !atomic_compare_exchange_weak(&peak_bytes, &seen, now)) {
	}
}

static void *peak_alloc(size_t size)
{
	note_peak(plume_bytes_in_use() + (int64_t)size + atomic_load(&json_bytes));
	return malloc(size);
}

static void *peak_json_malloc(size_t size)
{
	unsigned char *block = malloc(size + 16);
	if (block == NULL)
		return NULL;
	memcpy(block, &size, sizeof size);
	note_peak(plume_bytes_in_use() + atomic_fetch_add(&json_bytes, (int64_t)size) + (int64_t)size);
	return block + 16;
}

static void peak_json_free(void *memory)
{
	if (memory == NULL)
		return;
	unsigned char *block = (unsigned char *)memory - 16;
	size_t size;
	memcpy(&size, block, sizeof size);
	atomic_fetch_sub(&json_bytes, (int64_t)size);
	free(block);
}

static void peak_begin(void)
{
	atomic_store(&json_bytes, 0);
	atomic_store(&peak_bytes, plume_bytes_in_use());
	plume_set_allocator(peak_alloc, NULL);
	json_set_alloc_funcs(peak_json_malloc, peak_json_free);
}

/// The most bytes allocated at once since peak_begin, beyond before.
static int64_t peak_end(int64_t before)
{
	plume_set_allocator(NULL, NULL);
	json_set_alloc_funcs(malloc, free);
	return atomic_load(&peak_bytes) - before;
}

static void test_writers_stream(void **state)
{
	(void)state;
	// 2000 barbs of 100 points: 400,000 ribbon vertices, 9.6 MB in the file.
	const char *spec = "{\"model\": \"franco-walter\", \"barb_samples\": 100, \"segments\": [{\"barb_count\": 500}, "
	                   "{\"barb_count\": 500}]}";
	plume_spec_options options = {0};
	plume_feather *feather = NULL;
	plume_error err = {0};
	if (plume_spec_parse(spec, "dense", &options, &feather, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	char folder[512], path[600];
	snprintf(folder, sizeof folder, "%s/stream", scratch);
	assert_int_equal(mkdir(folder, 0777), 0);
	snprintf(path, sizeof path, "%s/dense.glb", folder);
	int64_t before = plume_bytes_in_use();
	peak_begin();
	plume_status status = plume_write_glb(feather, NULL, path, &err);
	int64_t peak = peak_end(before);
	if (status != PLUME_OK)
		fail_msg("%s", err.message);
	size_t size = 0;
	free(test_read_file(path, &size));
	assert_true(size > 9000000);
	// Two blocks of 256 KiB, the longest curve's scratch and the JSON: nothing grows with the feather.
	if (peak > (2 << 20))
		fail_msg("plume_write_glb of a %zu-byte file took %lld bytes", size, (long long)peak);
	assert_int_equal(test_count_entries(folder), 1); // the spooled chunk is gone
	plume_feather_destroy(feather);

	// A coat: one feather's parts (and one earlier feather's, to compare) at a time and the document.
	plume_coat *coat = NULL;
	if (plume_coat_spec_generate(PLUME_SOURCE_DIR "/examples/coats/figure15-hexagonal.json", &options, &coat, &err) !=
	    PLUME_OK)
		fail_msg("%s", err.message);
	snprintf(path, sizeof path, "%s/coat.glb", scratch);
	before = plume_bytes_in_use();
	peak_begin();
	status = plume_coat_write_glb(coat, NULL, path, &err);
	peak = peak_end(before);
	if (status != PLUME_OK)
		fail_msg("%s", err.message);
	free(test_read_file(path, &size));
	int count = plume_coat_feather_count(coat);
	if (peak > (int64_t)count * (64 << 10) + (1 << 20))
		fail_msg("plume_coat_write_glb of %d feathers (%zu bytes) took %lld bytes", count, size, (long long)peak);
	plume_coat_destroy(coat);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_feather_ribbons_read_back),
	    cmocka_unit_test(test_shell_and_animation_read_back),
	    cmocka_unit_test(test_carried_feather),
	    cmocka_unit_test(test_coat_instances),
	    cmocka_unit_test(test_writers_stream),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}

// glTF 2.0 binary container (spec 4.4): a 12-byte header ("glTF", version 2,
// total length), a JSON chunk padded with spaces to 4 bytes, then a BIN chunk
// padded with zeros to 4 bytes. Accessor offsets are multiples of 4 because
// every view starts on a 4-byte boundary and every component is 4 bytes.
//
// Floats are written in the machine's byte order; glTF requires little endian,
// which every platform plume builds on is (checked at compile time below).
#include "glb.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/alloc.h"
#include "../core/atomic_file.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the glTF writer assumes a little-endian machine"
#endif

static json_t *set_array(plume_glb *glb, const char *key)
{
	json_t *array = json_array();
	if (array == NULL || json_object_set_new(glb->root, key, array) != 0) {
		glb->failed = true;
		return NULL;
	}
	return array;
}

void plume_glb_init(plume_glb *glb, const char *generator)
{
	memset(glb, 0, sizeof *glb);
	glb->root = json_object();
	if (glb->root == NULL) {
		glb->failed = true;
		return;
	}
	json_t *asset = json_pack("{s:s, s:s}", "version", "2.0", "generator", generator);
	if (asset == NULL || json_object_set_new(glb->root, "asset", asset) != 0)
		glb->failed = true;
	json_t *scenes = json_pack("[{s:[]}]", "nodes");
	if (scenes == NULL || json_object_set_new(glb->root, "scenes", scenes) != 0)
		glb->failed = true;
	if (json_object_set_new(glb->root, "scene", json_integer(0)) != 0)
		glb->failed = true;
	glb->buffer_views = set_array(glb, "bufferViews");
	glb->accessors = set_array(glb, "accessors");
	glb->meshes = set_array(glb, "meshes");
	glb->nodes = set_array(glb, "nodes");
	glb->materials = set_array(glb, "materials");
	glb->animations = NULL; // only documents with animations have the key
}

plume_status plume_glb_init_spooled(plume_glb *glb, const char *generator, const char *path, plume_error *err)
{
	plume_glb_init(glb, generator);
	plume_status status = plume_atomic_open(&glb->spool, path, err);
	if (status != PLUME_OK) {
		json_decref(glb->root);
		memset(glb, 0, sizeof *glb);
		return status;
	}
	glb->spooled = true;
	return PLUME_OK;
}

void plume_glb_free(plume_glb *glb)
{
	json_decref(glb->root);
	plume_free(glb->bytes);
	if (glb->spooled)
		plume_atomic_abort(&glb->spool);
	memset(glb, 0, sizeof *glb);
}

int plume_glb_append(plume_glb *glb, json_t *array, json_t *obj)
{
	if (array == NULL || obj == NULL || json_array_append_new(array, obj) != 0) {
		glb->failed = true;
		return 0;
	}
	return (int)json_array_size(array) - 1;
}

/// The GLB's length field is 32 bits: a binary chunk is refused (too_large) before it passes this.
#define GLB_MAX_BINARY ((size_t)UINT32_MAX - ((size_t)1 << 24))

/// Appends size bytes to the binary chunk: to the spool, or to the buffer in memory.
static void append_bytes(plume_glb *glb, const void *data, size_t size)
{
	if (glb->failed || glb->write_error != 0 || glb->too_large || size == 0)
		return;
	if (size > GLB_MAX_BINARY - glb->size) {
		glb->too_large = true;
		return;
	}
	if (glb->spooled) {
		if (fwrite(data, 1, size, glb->spool.stream) != size)
			glb->write_error = errno != 0 ? errno : EIO;
		else
			glb->size += size;
		return;
	}
	if (glb->size + size > glb->capacity) {
		size_t capacity = glb->capacity > 0 ? glb->capacity : 1 << 16;
		while (capacity < glb->size + size)
			capacity *= 2;
		uint8_t *bytes = plume_realloc(glb->bytes, capacity);
		if (bytes == NULL) {
			glb->failed = true;
			return;
		}
		glb->bytes = bytes;
		glb->capacity = capacity;
	}
	memcpy(glb->bytes + glb->size, data, size);
	glb->size += size;
}

void plume_glb_view_begin(plume_glb *glb)
{
	static const uint8_t zeros[4] = {0, 0, 0, 0};
	append_bytes(glb, zeros, ((glb->size + 3) & ~(size_t)3) - glb->size); // every view starts on 4 bytes
	glb->view_start = glb->size;
}

void plume_glb_view_append(plume_glb *glb, const void *data, size_t size) { append_bytes(glb, data, size); }

int plume_glb_view_end(plume_glb *glb, int target)
{
	json_t *view = json_pack("{s:i, s:I, s:I}", "buffer", 0, "byteOffset", (json_int_t)glb->view_start, "byteLength",
	                         (json_int_t)(glb->size - glb->view_start));
	if (view != NULL && target != GLB_NO_TARGET)
		json_object_set_new(view, "target", json_integer(target));
	return plume_glb_append(glb, glb->buffer_views, view);
}

/// Copies size bytes into the binary chunk as a new view; returns its index.
static int add_view(plume_glb *glb, const void *data, size_t size, int target)
{
	plume_glb_view_begin(glb);
	append_bytes(glb, data, size);
	return plume_glb_view_end(glb, target);
}

static const char *type_name(int components)
{
	switch (components) {
	case 1: return "SCALAR";
	case 2: return "VEC2";
	case 3: return "VEC3";
	default: return "VEC4";
	}
}

int plume_glb_float_accessor(plume_glb *glb, int view, int64_t count, int components, const float *min,
                             const float *max)
{
	json_t *accessor = json_pack("{s:i, s:i, s:I, s:s}", "bufferView", view, "componentType", GLB_FLOAT, "count",
	                             (json_int_t)count, "type", type_name(components));
	if (accessor != NULL && min != NULL && max != NULL) {
		json_t *lo = json_array(), *hi = json_array();
		for (int c = 0; c < components; ++c) {
			json_array_append_new(lo, json_real(min[c]));
			json_array_append_new(hi, json_real(max[c]));
		}
		json_object_set_new(accessor, "min", lo);
		json_object_set_new(accessor, "max", hi);
	}
	return plume_glb_append(glb, glb->accessors, accessor);
}

int plume_glb_floats_f(plume_glb *glb, const float *values, int count, int components, int target, bool bounds)
{
	int view = add_view(glb, values, (size_t)count * (size_t)components * sizeof(float), target);
	float lo[4], hi[4];
	bounds = bounds && count > 0;
	for (int c = 0; bounds && c < components; ++c) {
		float a = values[c], b = values[c];
		for (int i = 1; i < count; ++i) {
			float v = values[(size_t)i * (size_t)components + (size_t)c];
			a = v < a ? v : a;
			b = v > b ? v : b;
		}
		lo[c] = a;
		hi[c] = b;
	}
	return plume_glb_float_accessor(glb, view, count, components, bounds ? lo : NULL, bounds ? hi : NULL);
}

int plume_glb_floats(plume_glb *glb, const double *values, int count, int components, int target, bool bounds)
{
	size_t n = (size_t)count * (size_t)components;
	float *rounded = plume_alloc(n > 0 ? n * sizeof(float) : 1);
	if (rounded == NULL) {
		glb->failed = true;
		return 0;
	}
	for (size_t i = 0; i < n; ++i)
		rounded[i] = (float)values[i];
	int index = plume_glb_floats_f(glb, rounded, count, components, target, bounds);
	plume_free(rounded);
	return index;
}

int plume_glb_index_accessor(plume_glb *glb, int view, int64_t count)
{
	json_t *accessor = json_pack("{s:i, s:i, s:I, s:s}", "bufferView", view, "componentType", GLB_UNSIGNED_INT, "count",
	                             (json_int_t)count, "type", "SCALAR");
	return plume_glb_append(glb, glb->accessors, accessor);
}

int plume_glb_indices(plume_glb *glb, const uint32_t *values, int64_t count)
{
	int view = add_view(glb, values, (size_t)count * sizeof(uint32_t), GLB_ELEMENT_ARRAY_BUFFER);
	return plume_glb_index_accessor(glb, view, count);
}

void plume_glb_scene_root(plume_glb *glb, int node)
{
	json_t *scene = json_array_get(json_object_get(glb->root, "scenes"), 0);
	json_t *nodes = json_object_get(scene, "nodes");
	if (nodes == NULL || json_array_append_new(nodes, json_integer(node)) != 0)
		glb->failed = true;
}

int plume_glb_material(plume_glb *glb, const char *name, const double factor[4])
{
	json_t *material = json_pack("{s:s, s:b, s:{s:[f,f,f,f], s:f, s:f}}", "name", name, "doubleSided", 1,
	                             "pbrMetallicRoughness", "baseColorFactor", factor[0], factor[1], factor[2], factor[3],
	                             "metallicFactor", 0.0, "roughnessFactor", 0.8);
	return plume_glb_append(glb, glb->materials, material);
}

int plume_glb_png_texture(plume_glb *glb, const unsigned char *png, size_t size)
{
	int view = add_view(glb, png, size, GLB_NO_TARGET);
	json_t *images = json_object_get(glb->root, "images"), *samplers = json_object_get(glb->root, "samplers");
	json_t *textures = json_object_get(glb->root, "textures");
	images = images != NULL ? images : set_array(glb, "images");
	samplers = samplers != NULL ? samplers : set_array(glb, "samplers");
	textures = textures != NULL ? textures : set_array(glb, "textures");
	int image = plume_glb_append(glb, images, json_pack("{s:i, s:s}", "bufferView", view, "mimeType", "image/png"));
	// Linear filtering; clamped at the borders as plume_texture_sample_vane clamps its indices.
	int sampler = plume_glb_append(
	    glb, samplers,
	    json_pack("{s:i, s:i, s:i, s:i}", "magFilter", 9729, "minFilter", 9729, "wrapS", 33071, "wrapT", 33071));
	return plume_glb_append(glb, textures, json_pack("{s:i, s:i}", "sampler", sampler, "source", image));
}

void plume_glb_material_texture(plume_glb *glb, int material, int texture, int texcoord)
{
	json_t *pbr = json_object_get(json_array_get(glb->materials, (size_t)material), "pbrMetallicRoughness");
	json_t *info = json_pack("{s:i, s:i}", "index", texture, "texCoord", texcoord);
	if (pbr == NULL || info == NULL || json_object_set_new(pbr, "baseColorTexture", info) != 0)
		glb->failed = true;
}

double plume_glb_linear(double srgb)
{
	// IEC 61966-2-1.
	return srgb <= 0.04045 ? srgb / 12.92 : pow((srgb + 0.055) / 1.055, 2.4);
}

/// Frees json_dumps's text with jansson's own free (json_set_alloc_funcs may have changed it).
static void free_text(char *text)
{
	json_free_t free_fn = NULL;
	json_get_alloc_funcs(NULL, &free_fn);
	if (free_fn != NULL)
		free_fn(text);
	else
		free(text);
}

static void put_u32(uint8_t *at, uint32_t value)
{
	for (int i = 0; i < 4; ++i)
		at[i] = (uint8_t)(value >> (8 * i));
}

/// Copies the spooled binary chunk (glb->size bytes) to out. False when a read or a write fails.
static bool copy_spool(plume_glb *glb, FILE *out)
{
	if (fflush(glb->spool.stream) != 0 || ferror(glb->spool.stream))
		return false;
	enum { BLOCK = 1 << 18 };
	unsigned char *block = plume_alloc(BLOCK);
	FILE *in = block != NULL ? fopen(glb->spool.tmp_path, "rb") : NULL;
	size_t left = glb->size;
	bool ok = in != NULL;
	while (ok && left > 0) {
		size_t n = left < BLOCK ? left : BLOCK;
		ok = fread(block, 1, n, in) == n && fwrite(block, 1, n, out) == n;
		left -= n;
	}
	if (in != NULL)
		fclose(in);
	plume_free(block);
	return ok;
}

plume_status plume_glb_write(plume_glb *glb, const char *path, plume_error *err)
{
	if (glb->failed)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	if (glb->too_large)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: the binary chunk passes the GLB limit of 4 GiB", path);
	if (glb->write_error != 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write its binary chunk beside it: %s", path,
		                       strerror(glb->write_error));
	// The one buffer: its byteLength is the chunk's unpadded length (spec 4.4.3.3 allows padding after it).
	json_t *buffers = json_pack("[{s:I}]", "byteLength", (json_int_t)glb->size);
	if (buffers == NULL || json_object_set_new(glb->root, "buffers", buffers) != 0)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	// Empty top-level arrays are not allowed (spec: "minItems": 1).
	static const char *const keys[] = {"bufferViews", "accessors", "meshes", "nodes", "materials", "animations"};
	for (size_t k = 0; k < sizeof keys / sizeof keys[0]; ++k) {
		json_t *array = json_object_get(glb->root, keys[k]);
		if (array != NULL && json_array_size(array) == 0)
			json_object_del(glb->root, keys[k]);
	}
	char *text = json_dumps(glb->root, JSON_COMPACT | JSON_REAL_PRECISION(9));
	if (text == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	size_t json_length = strlen(text), json_padded = (json_length + 3) & ~(size_t)3;
	size_t bin_padded = (glb->size + 3) & ~(size_t)3;
	size_t total = 12 + 8 + json_padded + (glb->size > 0 ? 8 + bin_padded : 0);
	if (total > UINT32_MAX) {
		free_text(text);
		return plume_error_set(err, PLUME_ERROR_IO, "%s: %zu bytes is over the GLB limit of 4 GiB", path, total);
	}
	uint8_t header[20];
	memcpy(header, "glTF", 4);
	put_u32(header + 4, 2);
	put_u32(header + 8, (uint32_t)total);
	put_u32(header + 12, (uint32_t)json_padded);
	memcpy(header + 16, "JSON", 4);

	plume_atomic_file file;
	plume_status status = plume_atomic_open(&file, path, err);
	if (status != PLUME_OK) {
		free_text(text);
		return status;
	}
	static const char spaces[4] = {' ', ' ', ' ', ' '};
	static const uint8_t zeros[4] = {0, 0, 0, 0};
	bool ok = fwrite(header, 1, sizeof header, file.stream) == sizeof header &&
	          fwrite(text, 1, json_length, file.stream) == json_length &&
	          fwrite(spaces, 1, json_padded - json_length, file.stream) == json_padded - json_length;
	free_text(text);
	if (ok && glb->size > 0) {
		uint8_t chunk[8];
		put_u32(chunk, (uint32_t)bin_padded);
		memcpy(chunk + 4, "BIN\0", 4);
		ok = fwrite(chunk, 1, 8, file.stream) == 8 &&
		     (glb->spooled ? copy_spool(glb, file.stream)
		                   : fwrite(glb->bytes, 1, glb->size, file.stream) == glb->size) &&
		     fwrite(zeros, 1, bin_padded - glb->size, file.stream) == bin_padded - glb->size;
	}
	if (!ok) {
		plume_atomic_abort(&file);
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	}
	return plume_atomic_commit(&file, err);
}

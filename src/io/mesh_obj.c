// Wavefront OBJ for plume meshes: triangles with texture coordinates, one
// "g" group per run of faces with the same material. The reader takes any
// polygons (fanned into triangles by obj_reader.c) and maps the groups back.
//
// The writer prints "%.17g", which round-trips every double exactly, and keeps
// the face order, so write then read gives back the same positions, faces,
// UVs and materials. Both directions use the "C" numeric locale whatever the
// process's locale (see ../io/export.h).
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <locale.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/alloc.h"
#include "export.h"
#include "obj_reader.h"
#include "plume/mesh.h"

/// Group names the writer gives each material; the reader maps them back.
static void material_name(int material, char *out, size_t size)
{
	if (material == PLUME_MATERIAL_VANE)
		snprintf(out, size, "vane");
	else if (material == PLUME_MATERIAL_RACHIS)
		snprintf(out, size, "rachis");
	else
		snprintf(out, size, "material_%d", material);
}

static int material_from_name(const char *name)
{
	if (strcmp(name, "rachis") == 0)
		return PLUME_MATERIAL_RACHIS;
	if (strncmp(name, "material_", 9) == 0) {
		char *end;
		long value = strtol(name + 9, &end, 10);
		if (*end == '\0' && end != name + 9 && value >= 0 && value <= 255)
			return (int)value;
	}
	return PLUME_MATERIAL_VANE;
}

/// The lines after the positions: texture coordinates, groups and faces, which
/// do not change from frame to frame.
static void write_tail(FILE *stream, const plume_mesh *mesh)
{
	for (int i = 0; i < mesh->vertex_count; ++i)
		fprintf(stream, "vt %.17g %.17g\n", mesh->uv[i].x, mesh->uv[i].y);
	int current = -1;
	char name[32];
	for (int f = 0; f < mesh->face_count; ++f) {
		if (mesh->material[f] != current) {
			current = mesh->material[f];
			material_name(current, name, sizeof name);
			fprintf(stream, "g %s\n", name);
		}
		const int *v = mesh->faces + 3 * f;
		fprintf(stream, "f %d/%d %d/%d %d/%d\n", v[0] + 1, v[0] + 1, v[1] + 1, v[1] + 1, v[2] + 1, v[2] + 1);
	}
}

/// The whole file; tail, when not NULL, is write_tail's text for this mesh.
static plume_status write_obj(const plume_mesh *mesh, const plume_vec3 *positions, const char *tail, size_t tail_length,
                              const char *path, plume_error *err)
{
	if (positions == NULL)
		positions = mesh->rest;
	int bad = plume_mesh_find_non_finite(mesh, positions, false);
	if (bad >= 0)
		return plume_error_set(err, PLUME_ERROR_NUMERIC,
		                       "%s: vertex %d has a NaN or infinite number, which OBJ cannot hold", path, bad + 1);
	plume_text_file text;
	plume_status status = plume_text_open(&text, path, err);
	if (status != PLUME_OK)
		return status;
	FILE *stream = text.stream;
	fprintf(stream, "# plume mesh: %d vertices, %d triangles\n", mesh->vertex_count, mesh->face_count);
	for (int i = 0; i < mesh->vertex_count; ++i)
		fprintf(stream, "v %.17g %.17g %.17g\n", positions[i].x, positions[i].y, positions[i].z);
	if (tail != NULL)
		fwrite(tail, 1, tail_length, stream);
	else
		write_tail(stream, mesh);
	if (ferror(stream))
		status = plume_error_set(err, PLUME_ERROR_IO, "%s: write failed: %s", path, strerror(errno));
	return plume_text_close(&text, status, err);
}

plume_status plume_mesh_write_obj(const plume_mesh *mesh, const plume_vec3 *positions, const char *path,
                                  plume_error *err)
{
	return write_obj(mesh, positions, NULL, 0, path, err);
}

struct plume_mesh_obj_writer {
	const plume_mesh *mesh;
	char *tail; ///< write_tail's text, formatted once
	size_t tail_length;
};

plume_status plume_mesh_obj_writer_create(const plume_mesh *mesh, plume_mesh_obj_writer **out, plume_error *err)
{
	*out = NULL;
	plume_mesh_obj_writer *writer = plume_calloc(1, sizeof *writer);
	if (writer == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "OBJ writer: out of memory");
	writer->mesh = mesh;
	// Formatted in the "C" numeric locale, as plume_text_open does for files.
	locale_t c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
	char *text = NULL;
	size_t length = 0;
	FILE *stream = c_locale != (locale_t)0 ? open_memstream(&text, &length) : NULL;
	if (stream != NULL) {
		locale_t saved = uselocale(c_locale);
		write_tail(stream, mesh);
		bool failed = ferror(stream) != 0;
		uselocale(saved);
		if (fclose(stream) != 0 || failed) {
			free(text);
			text = NULL;
		}
	}
	if (c_locale != (locale_t)0)
		freelocale(c_locale);
	// open_memstream's buffer comes from malloc: copied, so that the writer's memory is counted.
	if (text != NULL && (writer->tail = plume_alloc(length + 1)) != NULL) {
		memcpy(writer->tail, text, length + 1);
		writer->tail_length = length;
	}
	free(text);
	if (writer->tail == NULL) {
		plume_free(writer);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "OBJ writer: out of memory");
	}
	*out = writer;
	return PLUME_OK;
}

plume_status plume_mesh_obj_writer_write(const plume_mesh_obj_writer *writer, const plume_vec3 *positions,
                                         const char *path, plume_error *err)
{
	return write_obj(writer->mesh, positions, writer->tail, writer->tail_length, path, err);
}

void plume_mesh_obj_writer_destroy(plume_mesh_obj_writer *writer)
{
	if (writer == NULL)
		return;
	plume_free(writer->tail);
	plume_free(writer);
}

// ---------------------------------------------------------------------------
// Reader (the parsing is obj_reader.c's, shared with the body meshes of scenes)

/// The plume_mesh of an OBJ's triangles: rest the positions, reference their (x, y),
/// uv the texture coordinates when every corner has one, material from the group names.
static plume_status mesh_from_obj(const plume_obj *obj, const char *path, plume_mesh **out, plume_error *err)
{
	plume_mesh *mesh = plume_mesh_create(obj->vertex_count, obj->triangle_count);
	bool *seen = plume_calloc((size_t)obj->vertex_count + 1, sizeof *seen);
	if (mesh == NULL || seen == NULL) {
		plume_mesh_destroy(mesh);
		plume_free(seen);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	}
	for (int i = 0; i < obj->vertex_count; ++i) {
		mesh->rest[i] = obj->vertices[i];
		mesh->reference[i] = (plume_vec2){obj->vertices[i].x, obj->vertices[i].y};
	}
	bool all_uv = true;
	for (int i = 0; i < 3 * obj->triangle_count; ++i)
		all_uv = all_uv && obj->triangle_uvs[i] >= 0;
	for (int i = 0; i < 3 * obj->triangle_count; ++i) {
		int v = obj->triangles[i];
		mesh->faces[i] = v;
		// A vertex with several texture coordinates (a seam) keeps its first.
		if (all_uv && !seen[v]) {
			mesh->uv[v] = obj->uvs[obj->triangle_uvs[i]];
			seen[v] = true;
		}
	}
	for (int f = 0; f < obj->triangle_count; ++f) {
		int group = obj->face_group[obj->triangle_face[f]];
		mesh->material[f] = (unsigned char)(group < 0 ? PLUME_MATERIAL_VANE : material_from_name(obj->groups[group]));
	}
	plume_free(seen);
	*out = mesh;
	return PLUME_OK;
}

plume_status plume_mesh_read_obj(const char *path, plume_mesh **out, plume_error *err)
{
	*out = NULL;
	plume_obj obj;
	plume_status status = plume_obj_read(path, PLUME_OBJ_POSITIONS_AND_UVS, &obj, err);
	if (status == PLUME_OK)
		status = mesh_from_obj(&obj, path, out, err);
	plume_obj_free(&obj);
	return status;
}

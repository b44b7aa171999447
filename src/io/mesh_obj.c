// Wavefront OBJ for plume meshes: triangles with texture coordinates, one
// "g" group per run of faces with the same material.
//
// The writer prints "%.17g", which round-trips every double exactly, and keeps
// the face order, so write then read gives back the same positions, faces,
// UVs and materials. Both directions use the "C" numeric locale whatever the
// process's locale (see ../io/export.h).
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <math.h>
#include <errno.h>
#include <locale.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/alloc.h"
#include "export.h"
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
// Reader

typedef struct obj_reader {
	const char *path;
	long line;
	plume_error *err;
	plume_vec3 *v;
	int v_count, v_capacity;
	plume_vec2 *vt;
	int vt_count, vt_capacity;
	int *faces; ///< per face corner: vertex index, texture index (-1 when none)
	int face_count, face_capacity;
	unsigned char *material;
	int material_capacity;
	int current_material;
} obj_reader;

static plume_status obj_fail(obj_reader *reader, plume_status status, const char *what)
{
	return plume_error_set(reader->err, status, "%s:%ld: %s", reader->path, reader->line, what);
}

/// The largest coordinate an OBJ may hold, m: the bound every JSON number has
/// (PLUME_SPEC_MAX_MAGNITUDE), so "nan", "inf" and 1e308 stop here instead of
/// reaching a layout loop (a nan vertex made the coat's follicle search endless).
#define OBJ_MAX_MAGNITUDE 1e12

/// Reads up to max numbers after the keyword; returns how many, -1 on garbage,
/// -2 on a value that is not finite or past OBJ_MAX_MAGNITUDE.
static int read_numbers(const char *text, double *out, int max)
{
	int n = 0;
	for (;;) {
		while (isspace((unsigned char)*text))
			++text;
		if (*text == '\0')
			return n;
		if (n == max)
			return n; // extra values (a w coordinate) are allowed
		char *end;
		out[n] = strtod(text, &end);
		if (end == text || !(isspace((unsigned char)*end) || *end == '\0'))
			return -1;
		if (!(fabs(out[n]) <= OBJ_MAX_MAGNITUDE))
			return -2;
		++n;
		text = end;
	}
}

/// Resolves a 1-based or negative OBJ index against count; -1 when out of range.
static int resolve_index(long index, int count)
{
	long resolved = index > 0 ? index - 1 : count + index;
	return index != 0 && resolved >= 0 && resolved < count ? (int)resolved : -1;
}

static plume_status read_face(obj_reader *reader, char *text)
{
	int corners[4][2];
	int n = 0;
	char *save = NULL;
	for (char *token = strtok_r(text, " \t\r\n", &save); token != NULL; token = strtok_r(NULL, " \t\r\n", &save)) {
		if (n == 3)
			return obj_fail(reader, PLUME_ERROR_SYNTAX, "face with more than 3 vertices; only triangles are allowed");
		char *end;
		long v = strtol(token, &end, 10);
		if (end == token)
			return obj_fail(reader, PLUME_ERROR_SYNTAX, "face vertex is not an index");
		long t = 0;
		if (*end == '/') {
			char *start = end + 1;
			if (*start != '/') {
				t = strtol(start, &end, 10);
				if (end == start)
					return obj_fail(reader, PLUME_ERROR_SYNTAX, "face texture coordinate is not an index");
			} else {
				end = start;
			}
			if (*end == '/') { // normal index: checked for syntax, not used
				char *normal = end + 1;
				(void)strtol(normal, &end, 10);
				if (end == normal)
					return obj_fail(reader, PLUME_ERROR_SYNTAX, "face normal is not an index");
			}
		}
		if (*end != '\0')
			return obj_fail(reader, PLUME_ERROR_SYNTAX, "malformed face vertex");
		corners[n][0] = resolve_index(v, reader->v_count);
		if (corners[n][0] < 0) {
			char message[128];
			snprintf(message, sizeof message, "vertex index %ld out of range (%d vertices so far)", v, reader->v_count);
			return obj_fail(reader, PLUME_ERROR_SYNTAX, message);
		}
		corners[n][1] = -1;
		if (t != 0) {
			corners[n][1] = resolve_index(t, reader->vt_count);
			if (corners[n][1] < 0) {
				char message[128];
				snprintf(message, sizeof message, "texture index %ld out of range (%d texture coordinates so far)", t,
				         reader->vt_count);
				return obj_fail(reader, PLUME_ERROR_SYNTAX, message);
			}
		}
		++n;
	}
	if (n < 3)
		return obj_fail(reader, PLUME_ERROR_SYNTAX, "face with fewer than 3 vertices");
	if (PLUME_GROW(reader->faces, reader->face_capacity, 6 * (reader->face_count + 1)) != 0 ||
	    PLUME_GROW(reader->material, reader->material_capacity, reader->face_count + 1) != 0)
		return obj_fail(reader, PLUME_ERROR_MEMORY, "out of memory");
	for (int k = 0; k < 3; ++k) {
		reader->faces[6 * reader->face_count + 2 * k] = corners[k][0];
		reader->faces[6 * reader->face_count + 2 * k + 1] = corners[k][1];
	}
	reader->material[reader->face_count++] = (unsigned char)reader->current_material;
	return PLUME_OK;
}

static plume_status read_line(obj_reader *reader, char *line)
{
	while (isspace((unsigned char)*line))
		++line;
	double values[3];
	if (line[0] == 'v' && isspace((unsigned char)line[1])) {
		int n = read_numbers(line + 2, values, 3);
		if (n == -2)
			return obj_fail(reader, PLUME_ERROR_SYNTAX, "\"v\": a coordinate is not finite or is beyond 1e12 m");
		if (n != 3)
			return obj_fail(reader, PLUME_ERROR_SYNTAX, "\"v\" needs three numbers");
		if (PLUME_GROW(reader->v, reader->v_capacity, reader->v_count + 1) != 0)
			return obj_fail(reader, PLUME_ERROR_MEMORY, "out of memory");
		reader->v[reader->v_count++] = plume_v3(values[0], values[1], values[2]);
	} else if (line[0] == 'v' && line[1] == 't' && isspace((unsigned char)line[2])) {
		int n = read_numbers(line + 3, values, 2);
		if (n == -2)
			return obj_fail(reader, PLUME_ERROR_SYNTAX, "\"vt\": a coordinate is not finite or is beyond 1e12");
		if (n < 1)
			return obj_fail(reader, PLUME_ERROR_SYNTAX, "\"vt\" needs one or two numbers");
		if (PLUME_GROW(reader->vt, reader->vt_capacity, reader->vt_count + 1) != 0)
			return obj_fail(reader, PLUME_ERROR_MEMORY, "out of memory");
		reader->vt[reader->vt_count++] = (plume_vec2){values[0], n > 1 ? values[1] : 0.0};
	} else if (line[0] == 'f' && isspace((unsigned char)line[1])) {
		return read_face(reader, line + 2);
	} else if (line[0] == 'g' && isspace((unsigned char)line[1])) {
		char name[64] = "";
		sscanf(line + 2, "%63s", name);
		reader->current_material = material_from_name(name);
	}
	return PLUME_OK; // comments, normals, objects, materials: ignored
}

static plume_status build_mesh(obj_reader *reader, plume_mesh **out)
{
	plume_mesh *mesh = plume_mesh_create(reader->v_count, reader->face_count);
	if (mesh == NULL)
		return plume_error_set(reader->err, PLUME_ERROR_MEMORY, "%s: out of memory", reader->path);
	bool all_uv = true;
	for (int i = 0; i < 3 * reader->face_count; ++i)
		all_uv = all_uv && reader->faces[2 * i + 1] >= 0;
	bool *seen = plume_calloc((size_t)reader->v_count + 1, sizeof *seen);
	if (seen == NULL) {
		plume_mesh_destroy(mesh);
		return plume_error_set(reader->err, PLUME_ERROR_MEMORY, "%s: out of memory", reader->path);
	}
	for (int i = 0; i < reader->v_count; ++i) {
		mesh->rest[i] = reader->v[i];
		mesh->reference[i] = (plume_vec2){reader->v[i].x, reader->v[i].y};
	}
	for (int i = 0; i < 3 * reader->face_count; ++i) {
		int v = reader->faces[2 * i], t = reader->faces[2 * i + 1];
		mesh->faces[i] = v;
		// A vertex with several texture coordinates (a seam) keeps its first.
		if (all_uv && !seen[v]) {
			mesh->uv[v] = reader->vt[t];
			seen[v] = true;
		}
	}
	for (int f = 0; f < reader->face_count; ++f)
		mesh->material[f] = reader->material[f];
	plume_free(seen);
	*out = mesh;
	return PLUME_OK;
}

plume_status plume_mesh_read_obj(const char *path, plume_mesh **out, plume_error *err)
{
	*out = NULL;
	FILE *stream = fopen(path, "r");
	if (stream == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
	locale_t c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
	if (c_locale == (locale_t)0) {
		fclose(stream);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	}
	locale_t saved_locale = uselocale(c_locale);
	obj_reader reader = {.path = path, .err = err};
	plume_status status = PLUME_OK;
	char *line = NULL;
	size_t capacity = 0;
	while (status == PLUME_OK && getline(&line, &capacity, stream) >= 0) {
		++reader.line;
		status = read_line(&reader, line);
	}
	if (status == PLUME_OK && ferror(stream))
		status = plume_error_set(err, PLUME_ERROR_IO, "%s: read failed: %s", path, strerror(errno));
	if (status == PLUME_OK && reader.face_count == 0)
		status =
		    obj_fail(&reader, PLUME_ERROR_SYNTAX, "end of file without faces (\"f\" lines): a mesh needs triangles");
	free(line); // allocated by getline with malloc
	fclose(stream);
	uselocale(saved_locale);
	freelocale(c_locale);
	if (status == PLUME_OK)
		status = build_mesh(&reader, out);
	plume_free(reader.v);
	plume_free(reader.vt);
	plume_free(reader.faces);
	plume_free(reader.material);
	return status;
}

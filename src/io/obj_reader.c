// The Wavefront OBJ reader of plume's polygon meshes (obj_reader.h): one pass over
// the lines, each a keyword and whitespace-separated tokens, polygons fanned into
// triangles from their first corner as they are read.
#define _POSIX_C_SOURCE 200809L
#include "obj_reader.h"

#include <errno.h>
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/alloc.h"
#include "spec.h"

/// What separates tokens: whitespace, '\r' of CRLF line ends included.
#define SEPARATORS " \t\r\n\v\f"

/// Whether c is one of SEPARATORS (inline: it runs on every byte of a "v" line).
static bool is_separator(char c) { return c == ' ' || (c >= '\t' && c <= '\r'); }

/// The first character at or after text that is not a separator.
static char *skip_separators(char *text)
{
	while (is_separator(*text))
		++text;
	return text;
}

/// The first separator or the end of the string at or after text.
static char *skip_token(char *text)
{
	while (*text != '\0' && !is_separator(*text))
		++text;
	return text;
}

typedef struct obj_parser {
	const char *path;
	long line;
	plume_error *err;
	plume_obj_content content;
	plume_obj obj;
	int vertex_capacity, uv_capacity;
	int triangle_capacity, triangle_uv_capacity, triangle_face_capacity;
	int face_line_capacity, face_group_capacity, group_capacity;
} obj_parser;

static plume_status parse_fail(obj_parser *parser, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static plume_status parse_fail(obj_parser *parser, const char *format, ...)
{
	char message[512];
	va_list args;
	va_start(args, format);
	vsnprintf(message, sizeof message, format, args);
	va_end(args);
	return plume_error_set(parser->err, PLUME_ERROR_SYNTAX, "%s:%ld: %s", parser->path, parser->line, message);
}

static plume_status out_of_memory(obj_parser *parser)
{
	return plume_error_set(parser->err, PLUME_ERROR_MEMORY, "%s:%ld: out of memory", parser->path, parser->line);
}

// ---------------------------------------------------------------------------
// "v" and "vt"

/// What a line of numbers holds and how its messages name it.
typedef struct number_line {
	const char *keyword; ///< "v"
	const char *element; ///< "vertex": messages read "vertex 7: ..."
	int needed;          ///< numbers the line must have
	int used;            ///< numbers kept (needed <= used <= 3); further ones are checked to be numbers only
	const char *needs;   ///< "three numbers (x y z)"
	const char *unit;    ///< appended to the bound: " m"
} number_line;

static const number_line vertex_line = {"v", "vertex", 3, 3, "three numbers (x y z)", " m"};
static const number_line uv_line = {"vt", "texture coordinate", 1, 2, "one or two numbers (u [v])", ""};

/// The numbers of text (the rest of the line) into out; element is the 1-based count of
/// the kind's lines, for the messages. strtod reads in place, with no tokens cut first:
/// these lines carry most of a mesh file's bytes.
static plume_status read_numbers(obj_parser *parser, const number_line *kind, int element, char *text, double out[3])
{
	int count = 0;
	for (;; ++count) {
		text = skip_separators(text);
		if (*text == '\0')
			break;
		char *end;
		double value = strtod(text, &end);
		if (end == text || !(*end == '\0' || is_separator(*end))) {
			int length = (int)(skip_token(text) - text);
			return parse_fail(parser, "%s %d: \"%.*s\" is not a number", kind->element, element,
			                  length < 40 ? length : 40, text);
		}
		text = end;
		if (count >= kind->used)
			continue;
		// The bound of every number plume reads (PLUME_SPEC_MAX_MAGNITUDE); nan and inf fail here.
		if (!(fabs(value) <= PLUME_SPEC_MAX_MAGNITUDE))
			return parse_fail(parser, "%s %d: coordinate %d is %g; allowed finite, within 1e12%s", kind->element,
			                  element, count + 1, value, kind->unit);
		out[count] = value;
	}
	if (count < kind->needed)
		return parse_fail(parser, "\"%s\" needs %s; found %d", kind->keyword, kind->needs, count);
	return PLUME_OK;
}

/// A "v" or "vt" line (kind: vertex_line or uv_line), appended to its array.
static plume_status read_point(obj_parser *parser, const number_line *kind, char *text)
{
	plume_obj *obj = &parser->obj;
	bool vertex = kind == &vertex_line;
	int count = vertex ? obj->vertex_count : obj->uv_count;
	double x[3] = {0, 0, 0};
	plume_status status = read_numbers(parser, kind, count + 1, text, x);
	if (status != PLUME_OK)
		return status;
	int failed = vertex ? PLUME_GROW(obj->vertices, parser->vertex_capacity, count + 1)
	                    : PLUME_GROW(obj->uvs, parser->uv_capacity, count + 1);
	if (failed != 0)
		return out_of_memory(parser);
	if (vertex)
		obj->vertices[obj->vertex_count++] = plume_v3(x[0], x[1], x[2]);
	else
		obj->uvs[obj->uv_count++] = (plume_vec2){x[0], x[1]};
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// "f"

/// A corner's indices as written: vertex, texture, normal (given: present).
typedef struct corner_text {
	long index[3];
	bool given[3];
} corner_text;

/// Splits v, v/vt, v//vn or v/vt/vn into its integer indices; false on anything else.
static bool parse_corner(const char *token, corner_text *corner)
{
	*corner = (corner_text){{0}, {false}};
	const char *text = token;
	for (int part = 0; part < 3; ++part) {
		if (part > 0) {
			if (*text != '/')
				break;
			++text;
			if (part == 1 && *text == '/')
				continue; // v//vn: no texture index
		}
		char *end;
		errno = 0;
		corner->index[part] = strtol(text, &end, 10);
		if (end == text || errno != 0)
			return false;
		corner->given[part] = true;
		text = end;
	}
	return *text == '\0';
}

/// A 1-based or negative (counted back from the last item so far) index into count
/// items, 0-based; -1 when out of range.
static int resolve_index(long index, int count)
{
	long resolved = index > 0 ? index - 1 : count + index;
	return index != 0 && resolved >= 0 && resolved < count ? (int)resolved : -1;
}

/// A corner resolved against what has been read so far.
typedef struct corner {
	int vertex, uv; ///< uv -1: none
} corner;

static plume_status resolve_corner(obj_parser *parser, const char *token, int face, corner *out)
{
	const plume_obj *obj = &parser->obj;
	*out = (corner){-1, -1};
	corner_text text;
	if (!parse_corner(token, &text))
		return parse_fail(parser, "face %d: corner \"%.40s\" is not a vertex index (v, v/vt, v//vn or v/vt/vn)",
		                  face + 1, token);
	out->vertex = resolve_index(text.index[0], obj->vertex_count);
	if (out->vertex < 0)
		return parse_fail(parser, "face %d: vertex index %ld out of range (%d vertices so far)", face + 1,
		                  text.index[0], obj->vertex_count);
	if (parser->content == PLUME_OBJ_POSITIONS_AND_UVS && text.given[1] &&
	    (out->uv = resolve_index(text.index[1], obj->uv_count)) < 0)
		return parse_fail(parser, "face %d: texture index %ld out of range (%d texture coordinates so far)", face + 1,
		                  text.index[1], obj->uv_count);
	return PLUME_OK;
}

static plume_status add_triangle(obj_parser *parser, int face, const corner *a, const corner *b, const corner *c)
{
	plume_obj *obj = &parser->obj;
	int needed = 3 * (obj->triangle_count + 1);
	if (PLUME_GROW(obj->triangles, parser->triangle_capacity, needed) != 0 ||
	    PLUME_GROW(obj->triangle_uvs, parser->triangle_uv_capacity, needed) != 0 ||
	    PLUME_GROW(obj->triangle_face, parser->triangle_face_capacity, obj->triangle_count + 1) != 0)
		return out_of_memory(parser);
	const corner *corners[3] = {a, b, c};
	for (int k = 0; k < 3; ++k) {
		obj->triangles[3 * obj->triangle_count + k] = corners[k]->vertex;
		obj->triangle_uvs[3 * obj->triangle_count + k] = corners[k]->uv;
	}
	obj->triangle_face[obj->triangle_count++] = face;
	return PLUME_OK;
}

/// One polygon (c0, c1, ..., c_n-1), fanned into the triangles (c0, c_i, c_i+1).
static plume_status read_face(obj_parser *parser, char *text)
{
	plume_obj *obj = &parser->obj;
	int face = obj->face_count, corners = 0;
	corner first = {0, 0}, previous = {0, 0};
	char *save = NULL;
	for (char *token = strtok_r(text, SEPARATORS, &save); token != NULL; token = strtok_r(NULL, SEPARATORS, &save)) {
		corner current;
		plume_status status = resolve_corner(parser, token, face, &current);
		if (status == PLUME_OK && corners >= 2)
			status = add_triangle(parser, face, &first, &previous, &current);
		if (status != PLUME_OK)
			return status;
		if (corners == 0)
			first = current;
		previous = current;
		++corners;
	}
	if (corners < 3)
		return parse_fail(parser, "face %d has %d corners; a face needs at least 3", face + 1, corners);
	if (PLUME_GROW(obj->face_line, parser->face_line_capacity, face + 1) != 0 ||
	    PLUME_GROW(obj->face_group, parser->face_group_capacity, face + 1) != 0)
		return out_of_memory(parser);
	obj->face_line[face] = parser->line;
	obj->face_group[face] = obj->group_count - 1;
	obj->face_count = face + 1;
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// Lines

static plume_status read_group(obj_parser *parser, char *text)
{
	plume_obj *obj = &parser->obj;
	if (PLUME_GROW(obj->groups, parser->group_capacity, obj->group_count + 1) != 0)
		return out_of_memory(parser);
	char *name = skip_separators(text);
	int length = (int)(skip_token(name) - name);
	snprintf(obj->groups[obj->group_count++], PLUME_OBJ_GROUP_SIZE, "%.*s", length, name);
	return PLUME_OK;
}

/// Whether the length bytes at word are keyword.
static bool is_keyword(const char *word, size_t length, const char *keyword)
{
	return length == strlen(keyword) && memcmp(word, keyword, length) == 0;
}

static plume_status read_line(obj_parser *parser, char *line)
{
	char *comment = strchr(line, '#');
	if (comment != NULL)
		*comment = '\0';
	char *keyword = skip_separators(line);
	char *rest = skip_token(keyword);
	size_t length = (size_t)(rest - keyword); // 0 on a blank line: no keyword
	if (is_keyword(keyword, length, "v"))
		return read_point(parser, &vertex_line, rest);
	if (is_keyword(keyword, length, "vt") && parser->content == PLUME_OBJ_POSITIONS_AND_UVS)
		return read_point(parser, &uv_line, rest);
	if (is_keyword(keyword, length, "f"))
		return read_face(parser, rest);
	if (is_keyword(keyword, length, "g"))
		return read_group(parser, rest);
	return PLUME_OK; // normals, objects, materials, smoothing groups (and texture coordinates not asked for)
}

plume_status plume_obj_read(const char *path, plume_obj_content content, plume_obj *obj, plume_error *err)
{
	*obj = (plume_obj){0};
	FILE *stream = fopen(path, "r");
	if (stream == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
	// Numbers in the "C" locale whatever the process's (see export.h).
	locale_t c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
	if (c_locale == (locale_t)0) {
		fclose(stream);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	}
	locale_t saved_locale = uselocale(c_locale);
	obj_parser parser = {.path = path, .err = err, .content = content};
	plume_status status = PLUME_OK;
	char *line = NULL;
	size_t capacity = 0;
	while (status == PLUME_OK && getline(&line, &capacity, stream) >= 0) {
		++parser.line;
		status = read_line(&parser, line);
	}
	if (status == PLUME_OK && ferror(stream))
		status = plume_error_set(err, PLUME_ERROR_IO, "%s: read failed: %s", path, strerror(errno));
	if (status == PLUME_OK && parser.obj.face_count == 0)
		status = parse_fail(&parser, "end of file without faces (\"f\" lines); a mesh needs at least one");
	free(line); // getline allocates with malloc
	fclose(stream);
	uselocale(saved_locale);
	freelocale(c_locale);
	if (status != PLUME_OK) {
		plume_obj_free(&parser.obj);
		return status;
	}
	*obj = parser.obj;
	return PLUME_OK;
}

void plume_obj_free(plume_obj *obj)
{
	plume_free(obj->vertices);
	plume_free(obj->uvs);
	plume_free(obj->triangles);
	plume_free(obj->triangle_uvs);
	plume_free(obj->triangle_face);
	plume_free(obj->face_line);
	plume_free(obj->face_group);
	plume_free(obj->groups);
	*obj = (plume_obj){0};
}

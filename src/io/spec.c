// JSON spec reading with paths in every message (see spec.h).
#define _POSIX_C_SOURCE 200809L
#include "../core/asserts.h"
#include "spec.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

json_t *plume_spec_load(const char *path, plume_error *err)
{
	// jansson reports a missing file as a parse error at line -1; say it plainly.
	FILE *file = fopen(path, "rb");
	if (file == NULL) {
		plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read: %s", path, strerror(errno));
		return NULL;
	}
	// A folder opens for reading; its first read fails, which jansson took for an empty text
	// ("'[' or '{' expected", a syntax error at 1:0).
	struct stat info;
	if (fstat(fileno(file), &info) == 0 && S_ISDIR(info.st_mode)) {
		fclose(file);
		plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read: %s (a spec is a JSON file)", path, strerror(EISDIR));
		return NULL;
	}
	json_error_t error;
	json_t *root = json_loadf(file, JSON_REJECT_DUPLICATES, &error);
	fclose(file);
	if (root == NULL) {
		plume_error_set(err, PLUME_ERROR_SYNTAX, "%s:%d:%d: %s", path, error.line, error.column, error.text);
		return NULL;
	}
	if (plume_spec_check_numbers(path, root, err) != PLUME_OK) {
		json_decref(root);
		return NULL;
	}
	return root;
}

/// Depth-first over the tree; path holds the JSON path of value (truncated
/// when longer than the buffer). jansson's parser bounds the depth (2048).
static bool numbers_in_range(plume_spec_reader *reader, const json_t *value, char *path, size_t size)
{
	size_t length = strlen(path);
	if (json_is_number(value)) {
		double x = json_number_value(value);
		if (!(fabs(x) <= PLUME_SPEC_MAX_MAGNITUDE)) {
			plume_spec_fail(reader, path, "%g is outside the range of any value plume reads, [-1e12, 1e12]", x);
			return false;
		}
	} else if (json_is_object(value)) {
		const char *key;
		json_t *child;
		json_object_foreach ((json_t *)value, key, child) {
			snprintf(path + length, size - length, ".%s", key);
			bool ok = numbers_in_range(reader, child, path, size);
			path[length] = '\0';
			if (!ok)
				return false;
		}
	} else if (json_is_array(value)) {
		for (size_t i = 0; i < json_array_size(value); ++i) {
			snprintf(path + length, size - length, "[%zu]", i);
			bool ok = numbers_in_range(reader, json_array_get(value, i), path, size);
			path[length] = '\0';
			if (!ok)
				return false;
		}
	}
	return true;
}

plume_status plume_spec_check_numbers(const char *file, const json_t *root, plume_error *err)
{
	plume_spec_reader reader = plume_spec_reader_begin(file, err);
	char path[512] = "$";
	numbers_in_range(&reader, root, path, sizeof path);
	return reader.status;
}

json_t *plume_spec_load_model(const char *path, plume_status *status, plume_error *err)
{
	plume_error local = {0};
	json_t *root = plume_spec_load(path, err != NULL ? err : &local);
	if (root == NULL) {
		*status = err != NULL ? err->status : local.status;
		return NULL;
	}
	if (!json_is_object(root)) {
		json_decref(root);
		*status = plume_error_set(err, PLUME_ERROR_SPEC, "%s: $: expected an object with a \"model\" key", path);
		return NULL;
	}
	*status = PLUME_OK;
	return root;
}

plume_spec_reader plume_spec_reader_begin(const char *file, plume_error *err)
{
	return (plume_spec_reader){.file = file, .err = err, .status = PLUME_OK};
}

void plume_spec_fail(plume_spec_reader *reader, const char *path, const char *format, ...)
{
	if (reader->status != PLUME_OK)
		return;
	reader->status = PLUME_ERROR_SPEC;
	if (reader->err == NULL)
		return;
	char message[768];
	va_list args;
	va_start(args, format);
	vsnprintf(message, sizeof message, format, args);
	va_end(args);
	plume_error_set(reader->err, PLUME_ERROR_SPEC, "%.200s: %.200s: %s", reader->file, path, message);
}

void plume_spec_path(char *out, size_t size, const char *parent, const char *key)
{
	snprintf(out, size, "%s.%s", parent, key);
}

void plume_spec_index_path(char *out, size_t size, const char *parent, size_t index)
{
	snprintf(out, size, "%s[%zu]", parent, index);
}

bool plume_spec_is_near(const char *word, const char *candidate)
{
	// A third of the word's letters, and at least two (a swap, "lenght", is two edits): typos
	// and plurals, not other words.
	size_t length = strlen(word), limit = length / 3 > 2 ? length / 3 : 2;
	return plume_edit_distance(word, candidate) <= limit;
}

const char *plume_spec_suggest(const char *word, const char *const *allowed)
{
	const char *nearest = plume_spec_nearest(word, allowed);
	if (plume_spec_is_near(word, nearest))
		return nearest;
	// A key cut short: "fov" for "fov_deg" (whose nearest by edits was "eye").
	size_t length = strlen(word);
	for (const char *const *candidate = allowed; length >= 3 && *candidate != NULL; ++candidate)
		if (strncmp(*candidate, word, length) == 0)
			return *candidate;
	return NULL;
}

const char *plume_spec_nearest(const char *word, const char *const *allowed)
{
	const char *nearest = allowed[0];
	size_t best = (size_t)-1;
	for (const char *const *candidate = allowed; *candidate != NULL; ++candidate) {
		size_t distance = plume_edit_distance(word, *candidate);
		if (distance < best) {
			best = distance;
			nearest = *candidate;
		}
	}
	return nearest;
}

void plume_spec_check_keys(plume_spec_reader *reader, const json_t *object, const char *path,
                           const char *const *allowed)
{
	if (reader->status != PLUME_OK)
		return;
	const char *key;
	json_t *value;
	json_object_foreach ((json_t *)object, key, value) {
		bool known = false;
		for (const char *const *candidate = allowed; *candidate != NULL && !known; ++candidate)
			known = strcmp(key, *candidate) == 0;
		if (!known) {
			char child[512];
			plume_spec_path(child, sizeof child, path, key);
			const char *nearest = plume_spec_suggest(key, allowed);
			if (nearest != NULL) {
				plume_spec_fail(reader, child, "unknown key; did you mean \"%s\"?", nearest);
				return;
			}
			// Nothing close: a guess would mislead ("texture_mode" is no "tip_angle_deg"); list what is allowed.
			char list[600] = "";
			size_t used = 0;
			for (const char *const *candidate = allowed; *candidate != NULL && used < sizeof list; ++candidate) {
				int n = snprintf(list + used, sizeof list - used, "%s%s", used > 0 ? ", " : "", *candidate);
				used += n > 0 ? (size_t)n : 0;
			}
			plume_spec_fail(reader, child, "unknown key; the keys here are: %s", list);
			return;
		}
	}
}

static const char *type_name(const json_t *value)
{
	switch (json_typeof(value)) {
	case JSON_OBJECT: return "an object";
	case JSON_ARRAY: return "an array";
	case JSON_STRING: return "a string";
	case JSON_INTEGER: return "an integer";
	case JSON_REAL: return "a number";
	case JSON_TRUE:
	case JSON_FALSE: return "a boolean";
	case JSON_NULL: return "null";
	}
	return "a value";
}

/// The member, or NULL when absent or after an earlier failure.
static const json_t *member(plume_spec_reader *reader, const json_t *object, const char *key)
{
	return reader->status == PLUME_OK ? json_object_get(object, key) : NULL;
}

static bool read_number(plume_spec_reader *reader, const json_t *value, const char *path, double *out)
{
	if (!json_is_number(value)) {
		plume_spec_fail(reader, path, "expected a number, got %s", type_name(value));
		return false;
	}
	*out = json_number_value(value);
	return true;
}

bool plume_spec_number(plume_spec_reader *reader, const json_t *object, const char *path, const char *key, double *out)
{
	const json_t *value = member(reader, object, key);
	if (value == NULL)
		return false;
	char child[512];
	plume_spec_path(child, sizeof child, path, key);
	return read_number(reader, value, child, out);
}

bool plume_spec_int(plume_spec_reader *reader, const json_t *object, const char *path, const char *key, int *out)
{
	const json_t *value = member(reader, object, key);
	if (value == NULL)
		return false;
	char child[512];
	plume_spec_path(child, sizeof child, path, key);
	if (!json_is_integer(value)) {
		plume_spec_fail(reader, child, "expected an integer, got %s", type_name(value));
		return false;
	}
	json_int_t number = json_integer_value(value);
	if (number < -2147483647 || number > 2147483647) {
		plume_spec_fail(reader, child, "%lld is too large", (long long)number);
		return false;
	}
	*out = (int)number;
	return true;
}

bool plume_spec_uint64(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       uint64_t *out)
{
	const json_t *value = member(reader, object, key);
	if (value == NULL)
		return false;
	char child[512];
	plume_spec_path(child, sizeof child, path, key);
	if (!json_is_integer(value) || json_integer_value(value) < 0) {
		plume_spec_fail(reader, child, "expected a non-negative integer, got %s", type_name(value));
		return false;
	}
	*out = (uint64_t)json_integer_value(value);
	return true;
}

bool plume_spec_bool(plume_spec_reader *reader, const json_t *object, const char *path, const char *key, bool *out)
{
	const json_t *value = member(reader, object, key);
	if (value == NULL)
		return false;
	if (!json_is_boolean(value)) {
		char child[512];
		plume_spec_path(child, sizeof child, path, key);
		plume_spec_fail(reader, child, "expected true or false, got %s", type_name(value));
		return false;
	}
	*out = json_is_true(value);
	return true;
}

bool plume_spec_string(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       const char **out)
{
	const json_t *value = member(reader, object, key);
	if (value == NULL)
		return false;
	if (!json_is_string(value)) {
		char child[512];
		plume_spec_path(child, sizeof child, path, key);
		plume_spec_fail(reader, child, "expected a string, got %s", type_name(value));
		return false;
	}
	*out = json_string_value(value);
	return true;
}

bool plume_spec_points2(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                        plume_vec2 *out, int count)
{
	const json_t *value = member(reader, object, key);
	if (value == NULL)
		return false;
	char child[512];
	plume_spec_path(child, sizeof child, path, key);
	if (!json_is_array(value) || json_array_size(value) != (size_t)count) {
		plume_spec_fail(reader, child, "expected an array of %d points [x, y] in metres", count);
		return false;
	}
	plume_vec2 points[64];
	PLUME_ASSERT(count >= 0 && count <= 64 && "plume_spec_points2 reads at most 64 points");
	for (int i = 0; i < count; ++i) {
		const json_t *point = json_array_get(value, (size_t)i);
		char item[540];
		plume_spec_index_path(item, sizeof item, child, (size_t)i);
		if (!json_is_array(point) || json_array_size(point) != 2) {
			plume_spec_fail(reader, item, "expected a point [x, y] in metres, got %s", type_name(point));
			return false;
		}
		char coordinate[560];
		plume_spec_index_path(coordinate, sizeof coordinate, item, 0);
		if (!read_number(reader, json_array_get(point, 0), coordinate, &points[i].x))
			return false;
		plume_spec_index_path(coordinate, sizeof coordinate, item, 1);
		if (!read_number(reader, json_array_get(point, 1), coordinate, &points[i].y))
			return false;
	}
	memcpy(out, points, (size_t)count * sizeof *out);
	return true;
}

static const json_t *typed_member(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                                  json_type type, const char *expected)
{
	const json_t *value = member(reader, object, key);
	if (value == NULL)
		return NULL;
	if (json_typeof(value) != type) {
		char child[512];
		plume_spec_path(child, sizeof child, path, key);
		plume_spec_fail(reader, child, "expected %s, got %s", expected, type_name(value));
		return NULL;
	}
	return value;
}

const json_t *plume_spec_object(plume_spec_reader *reader, const json_t *object, const char *path, const char *key)
{
	return typed_member(reader, object, path, key, JSON_OBJECT, "an object");
}

const json_t *plume_spec_array(plume_spec_reader *reader, const json_t *object, const char *path, const char *key)
{
	return typed_member(reader, object, path, key, JSON_ARRAY, "an array");
}

// JSON dump of a whole feather and its reader (schema: docs/feather-json.md).
//
// The writer prints the document as it goes, one barb per line (readable, and
// friendly to diff), so that a 132 000-point feather never sits in memory twice.
// Until 2026-11-28 it built each barb as a jansson value (13 small objects) and
// encoded that: on Figure 1's 4400-barb hawk the version 2 dump took 0.46 G
// instructions, 5 % of `plume simulate`'s run, and takes 0.15 G printed directly,
// with the same bytes. Doubles are printed with 17 significant digits as jansson's
// JSON_REAL_PRECISION(17) prints them (put_real), enough for strtod to give back the
// same double, bit for bit.
//
// The reader loads the document with jansson (JSON_REJECT_DUPLICATES, line and
// column on syntax errors) and rebuilds the feather with the builders of
// feather_internal.h, checking every key and array length on the way, so that
// bad input gives a message with its JSON path and never a crash.
#define _POSIX_C_SOURCE 200809L
#include "export.h"
#include "spec.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "../core/alloc.h"
#include "../model/feather_internal.h"
#include "plume/io.h"

// The number arrays are read and written through double pointers with a stride.
_Static_assert(sizeof(plume_vec3) == 3 * sizeof(double), "plume_vec3 must be three packed doubles");
_Static_assert(sizeof(plume_vec2) == 2 * sizeof(double), "plume_vec2 must be two packed doubles");

#define FORMAT_NAME "plume-feather"
#define FORMAT_VERSION 1        // every number inline, printed with 17 digits
#define FORMAT_VERSION_BINARY 2 // number arrays may be views into a float64 sidecar

static const char *const side_names[] = {"left", "right"};      // plume_side
static const char *const kind_names[] = {"distal", "proximal"}; // plume_barbule_kind

// ---------------------------------------------------------------------------
// Writing
//
// The writer reads the feather's counts from its fields (feather_internal.h), not
// through plume_feather_get_info, which also measures the bounds over every point
// (14 M instructions a call on the hawk).

/// What the writer carries through a document: the text stream, the sidecar of version 2
/// (NULL for version 1: every number inline) and whether a number was not finite, which
/// JSON cannot hold; the caller turns that into an error naming the piece.
typedef struct emitter {
	FILE *stream;
	struct sidecar *bin;
	bool non_finite;
} emitter;

/// Version 2's sidecar: the number arrays, little-endian IEEE 754 binary64, in
/// the order the JSON names them. Formatting a double with "%.17g" costs about a
/// microsecond; copying its 8 bytes costs nothing, and the file is half the size.
typedef struct sidecar {
	FILE *stream;
	unsigned long long length; ///< bytes written so far
	unsigned char chunk[8192];
	size_t used;
} sidecar;

static void sidecar_flush(sidecar *bin)
{
	fwrite(bin->chunk, 1, bin->used, bin->stream);
	bin->used = 0;
}

/// Appends one double, least significant byte first whatever the host's order.
static void sidecar_put(sidecar *bin, double value)
{
	if (bin->used + 8 > sizeof bin->chunk)
		sidecar_flush(bin);
	uint64_t bits;
	memcpy(&bits, &value, sizeof bits);
	for (int k = 0; k < 8; ++k)
		bin->chunk[bin->used++] = (unsigned char)(bits >> (8 * k));
	bin->length += 8;
}

/// A finite double as JSON: "%.17g" (enough for strtod to give back the same double, bit
/// for bit; plume_text_open holds the "C" numeric locale), with ".0" appended where the
/// digits alone would read back as an integer, and the exponent without its '+' and
/// leading zeros ("1e-05" -> "1e-5"). This is the text jansson's JSON_REAL_PRECISION(17)
/// gives, so files written before the writer printed its own numbers compare byte for byte.
static void put_real(emitter *out, double value)
{
	out->non_finite |= !isfinite(value);
	char text[40];
	int length = snprintf(text, sizeof text, "%.17g", value);
	char *exponent = strchr(text, 'e');
	if (exponent == NULL) {
		if (strchr(text, '.') == NULL)
			memcpy(text + length, ".0", 3);
	} else {
		// exponent[1] is its sign: '+' is overwritten, '-' kept; then the leading zeros go.
		char *sign = exponent + 1, *first = sign + (*sign == '-' ? 1 : 0), *from = sign + 1;
		while (*from == '0' && from[1] != '\0')
			++from;
		memmove(first, from, strlen(from) + 1);
	}
	fputs(text, out->stream);
}

/// "key": then count items of components doubles each, item i at base + i * stride:
/// inline (version 1) or the view {"offset": bytes, "count": numbers} into the sidecar.
static void put_numbers(emitter *out, const char *key, const void *base, size_t stride, int components, int count)
{
	fprintf(out->stream, ",\"%s\":", key);
	if (out->bin != NULL)
		fprintf(out->stream, "{\"offset\":%llu,\"count\":%lld}", out->bin->length,
		        (long long)count * (long long)components);
	else
		fputc('[', out->stream);
	for (int i = 0; i < count; ++i) {
		const double *item = (const double *)((const char *)base + (size_t)i * stride);
		for (int c = 0; c < components; ++c) {
			if (out->bin != NULL) {
				out->non_finite |= !isfinite(item[c]);
				sidecar_put(out->bin, item[c]);
			} else {
				if (i > 0 || c > 0)
					fputc(',', out->stream);
				put_real(out, item[c]);
			}
		}
	}
	if (out->bin == NULL)
		fputc(']', out->stream);
}

/// The per-point arrays every curve has (after a first member: each starts with a comma).
static void put_polyline(emitter *out, plume_polyline curve)
{
	put_numbers(out, "position", curve.points, sizeof *curve.points, 3, curve.count);
	put_numbers(out, "normal", curve.normals, sizeof *curve.normals, 3, curve.count);
	put_numbers(out, "arc_length", curve.arc_length, sizeof *curve.arc_length, 1, curve.count);
	put_numbers(out, "width", curve.widths, sizeof *curve.widths, 1, curve.count);
	put_numbers(out, "uv", curve.uv, sizeof *curve.uv, 2, curve.count);
}

static void put_shaft(emitter *out, const plume_feather *feather)
{
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	int count = feather->shaft_count;
	size_t stride = sizeof *shaft;
	fprintf(out->stream, "{\"calamus_samples\":%d", feather->calamus_count);
	// With no samples the base pointers are never read.
	put_numbers(out, "position", count > 0 ? &shaft->position : NULL, stride, 3, count);
	put_numbers(out, "tangent", count > 0 ? &shaft->tangent : NULL, stride, 3, count);
	put_numbers(out, "normal", count > 0 ? &shaft->normal : NULL, stride, 3, count);
	put_numbers(out, "binormal", count > 0 ? &shaft->binormal : NULL, stride, 3, count);
	put_numbers(out, "width", count > 0 ? &shaft->width : NULL, stride, 1, count);
	put_numbers(out, "t", count > 0 ? &shaft->t : NULL, stride, 1, count);
	fputc('}', out->stream);
}

static void put_barb(emitter *out, const plume_feather *feather, int index)
{
	plume_barb barb = plume_feather_barb(feather, index);
	fprintf(out->stream, "{\"side\":\"%s\",\"rachis_t\":", side_names[barb.side]);
	put_real(out, barb.rachis_t);
	fprintf(out->stream, ",\"segment\":%d", barb.segment);
	put_polyline(out, barb.curve);
	fputs(",\"barbules\":[", out->stream);
	for (int j = 0; j < barb.barbule_count; ++j) {
		plume_barbule barbule = plume_feather_barbule(feather, barb.barbule_first + j);
		fputs(j > 0 ? ",{\"barb_s\":" : "{\"barb_s\":", out->stream);
		put_real(out, barbule.barb_s);
		fprintf(out->stream, ",\"kind\":\"%s\"", kind_names[barbule.kind]);
		put_polyline(out, barbule.curve);
		fputc('}', out->stream);
	}
	fputs("]}", out->stream);
}

static void pad(FILE *stream, int level)
{
	for (int i = 0; i < level; ++i)
		fputs("  ", stream);
}

/// The error for a piece that had a NaN or infinite number (out->non_finite).
static plume_status non_finite(const char *path, const char *what, plume_error *err)
{
	return plume_error_set(err, PLUME_ERROR_NUMERIC, "%s: %s has a NaN or infinite number, which JSON cannot hold",
	                       path, what);
}

/// The members every feather object has ("shaft", "barbs", "afterfeather"),
/// indented by level; the caller writes the braces. One barb a line.
static plume_status write_members(emitter *out, const plume_feather *feather, int level, const char *path,
                                  plume_error *err)
{
	FILE *stream = out->stream;
	pad(stream, level);
	fputs("\"shaft\": ", stream);
	put_shaft(out, feather);
	if (out->non_finite)
		return non_finite(path, "the shaft", err);
	fputs(",\n", stream);
	pad(stream, level);
	fputs("\"barbs\": [", stream);
	int barb_count = feather->barb_count;
	for (int i = 0; i < barb_count; ++i) {
		fputs(i > 0 ? ",\n" : "\n", stream);
		pad(stream, level + 1);
		put_barb(out, feather, i);
		if (out->non_finite) {
			char what[64];
			snprintf(what, sizeof what, "barb %d", i);
			return non_finite(path, what, err);
		}
	}
	if (barb_count > 0) {
		fputc('\n', stream);
		pad(stream, level);
	}
	fputs("],\n", stream);
	pad(stream, level);
	fputs("\"afterfeather\": ", stream);
	const plume_feather *after = plume_feather_afterfeather(feather);
	if (after == NULL) {
		fputs("null\n", stream);
		return PLUME_OK;
	}
	fputs("{\n", stream);
	pad(stream, level + 1);
	fputs("\"t\": ", stream);
	put_real(out, plume_feather_afterfeather_t(feather));
	if (out->non_finite)
		return non_finite(path, "the afterfeather's t", err);
	fputs(",\n", stream);
	pad(stream, level + 1);
	fputs("\"feather\": {\n", stream);
	plume_status status = write_members(out, after, level + 2, path, err);
	pad(stream, level + 1);
	fputs("}\n", stream);
	pad(stream, level);
	fputs("}\n", stream);
	return status;
}

/// The file nests each barb's barbules under it, so a feather can be written
/// only when its barbules are grouped by barb, in order (feather.h promises
/// this); anything else would not read back as the same feather.
static bool barbules_grouped(const plume_feather *feather, int *bad_barb)
{
	int next = 0;
	for (int i = 0; i < feather->barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		if (barb.barbule_count == 0)
			continue;
		bool ok = barb.barbule_first == next && barb.barbule_count > 0 &&
		          barb.barbule_count <= feather->barbule_count - barb.barbule_first;
		for (int j = 0; ok && j < barb.barbule_count; ++j)
			ok = plume_feather_barbule(feather, next + j).barb == i;
		if (!ok) {
			*bad_barb = i;
			return false;
		}
		next += barb.barbule_count;
	}
	if (next != feather->barbule_count) {
		*bad_barb = -1;
		return false;
	}
	const plume_feather *after = plume_feather_afterfeather(feather);
	return after == NULL || barbules_grouped(after, bad_barb);
}

/// The sidecar's path and its name as the JSON gives it: path's file name with
/// ".json" replaced by ".bin" (or ".bin" appended).
static bool sidecar_path(const char *path, char *out, size_t size, const char **name)
{
	size_t length = strlen(path);
	if (length >= 5 && strcmp(path + length - 5, ".json") == 0)
		length -= 5;
	if (length + 5 > size)
		return false;
	memcpy(out, path, length);
	memcpy(out + length, ".bin", 5);
	const char *slash = strrchr(out, '/');
	*name = slash != NULL ? slash + 1 : out;
	return true;
}

static plume_status write_document(const plume_feather *feather, const char *path, bool binary, plume_error *err)
{
	int bad_barb;
	if (!barbules_grouped(feather, &bad_barb))
		return plume_error_set(err, PLUME_ERROR_UNSUPPORTED,
		                       "%s: cannot write: the feather's barbules are not grouped by barb in order "
		                       "(first mismatch at barb %d)",
		                       path, bad_barb);
	char bin_path[4096];
	const char *bin_name = NULL;
	if (binary && !sidecar_path(path, bin_path, sizeof bin_path, &bin_name))
		return plume_error_set(err, PLUME_ERROR_IO, "%s: path too long", path);
	plume_text_file text, bin_text;
	sidecar *bin = NULL;
	plume_status status = plume_text_open(&text, path, err);
	if (status != PLUME_OK)
		return status;
	if (binary) {
		if ((bin = plume_alloc(sizeof *bin)) == NULL)
			return plume_text_close(&text, plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path), err);
		if ((status = plume_text_open(&bin_text, bin_path, err)) != PLUME_OK) {
			plume_free(bin);
			return plume_text_close(&text, status, err);
		}
		*bin = (sidecar){.stream = bin_text.stream};
	}
	fprintf(text.stream, "{\n  \"format\": \"%s\",\n  \"version\": %d,\n", FORMAT_NAME,
	        binary ? FORMAT_VERSION_BINARY : FORMAT_VERSION);
	if (binary) {
		// The name goes into JSON as is: sidecar_path keeps it to the caller's file name.
		json_t *name = json_string(bin_name);
		fputs("  \"buffer\": {\"uri\": ", text.stream);
		if (name == NULL || json_dumpf(name, text.stream, JSON_ENCODE_ANY) != 0)
			status = plume_error_set(err, PLUME_ERROR_SPEC, "%s: the sidecar's name is not UTF-8", bin_path);
		json_decref(name);
		fputs("},\n", text.stream);
	}
	emitter out = {.stream = text.stream, .bin = bin};
	if (status == PLUME_OK)
		status = write_members(&out, feather, 1, path, err);
	fputs("}\n", text.stream);
	if (binary) {
		sidecar_flush(bin);
		// The sidecar is committed first: a JSON file never names a missing sidecar.
		status = plume_text_close(&bin_text, status, err);
		plume_free(bin);
	}
	return plume_text_close(&text, status, err);
}

plume_status plume_write_json(const plume_feather *feather, const char *path, plume_error *err)
{
	return write_document(feather, path, false, err);
}

plume_status plume_write_json_binary(const plume_feather *feather, const char *path, plume_error *err)
{
	return write_document(feather, path, true, err);
}

// ---------------------------------------------------------------------------
// Reading

/// Where the reader is in the document, for messages: "$.barbs[3].position".
typedef struct reader {
	const char *file;
	plume_error *err;
	const unsigned char *buffer; ///< version 2's sidecar, whole; NULL in version 1
	size_t buffer_length;
	char path[512];
	size_t length;
} reader;

/// Appends to the path; returns the length to restore with leave.
static size_t enter(reader *r, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static size_t enter(reader *r, const char *format, ...)
{
	size_t mark = r->length;
	va_list args;
	va_start(args, format);
	int written = vsnprintf(r->path + r->length, sizeof r->path - r->length, format, args);
	va_end(args);
	if (written > 0)
		r->length += (size_t)written < sizeof r->path - r->length ? (size_t)written : sizeof r->path - 1 - r->length;
	return mark;
}

static void leave(reader *r, size_t mark)
{
	r->length = mark;
	r->path[mark] = '\0';
}

static plume_status fail(reader *r, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/// A schema error at the current path: "file: $.barbs[3].position: message".
static plume_status fail(reader *r, const char *format, ...)
{
	char message[512];
	va_list args;
	va_start(args, format);
	vsnprintf(message, sizeof message, format, args);
	va_end(args);
	return plume_error_set(r->err, PLUME_ERROR_SPEC, "%s: %s: %s", r->file, r->path, message);
}

/// A schema error at member key of the current path.
static plume_status fail_at(reader *r, const char *key, const char *message)
{
	enter(r, ".%s", key);
	return fail(r, "%s", message);
}

static plume_status out_of_memory(reader *r)
{
	return plume_error_set(r->err, PLUME_ERROR_MEMORY, "%s: out of memory", r->file);
}

static bool in_list(const char *key, const char *const *keys, size_t count)
{
	for (size_t i = 0; i < count; ++i)
		if (strcmp(key, keys[i]) == 0)
			return true;
	return false;
}

/// value must be an object with exactly these keys (the format has no optional
/// ones, so a misspelt key is reported rather than ignored).
static plume_status check_object(reader *r, json_t *value, const char *what, const char *const *keys, size_t count)
{
	if (!json_is_object(value))
		return fail(r, "expected an object (%s)", what);
	const char *key;
	json_t *member;
	json_object_foreach (value, key, member) {
		if (!in_list(key, keys, count)) {
			char list[256] = "";
			for (size_t i = 0; i < count; ++i)
				snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i > 0 ? ", " : "", keys[i]);
			return fail(r, "unknown key \"%.100s\"; the keys here are: %s", key, list);
		}
	}
	for (size_t i = 0; i < count; ++i)
		if (json_object_get(value, keys[i]) == NULL)
			return fail(r, "missing key \"%s\"", keys[i]);
	return PLUME_OK;
}

static plume_status read_number(reader *r, json_t *object, const char *key, double *out)
{
	json_t *value = json_object_get(object, key);
	if (!json_is_number(value))
		return fail_at(r, key, "expected a number");
	*out = json_number_value(value);
	return PLUME_OK;
}

/// A fraction in [0, 1]: where a barb sits on the shaft (rachis_t), a barbule on its barb
/// (barb_s), the afterfeather on the shaft (t). The generators write nothing else.
static plume_status read_fraction(reader *r, json_t *object, const char *key, double *out)
{
	plume_status status = read_number(r, object, key, out);
	if (status == PLUME_OK && !(*out >= 0.0 && *out <= 1.0)) {
		enter(r, ".%s", key);
		return fail(r, "is %g, allowed [0, 1]", *out);
	}
	return status;
}

static plume_status read_int(reader *r, json_t *object, const char *key, json_int_t lo, json_int_t hi, int *out)
{
	json_t *value = json_object_get(object, key);
	if (!json_is_integer(value))
		return fail_at(r, key, "expected an integer");
	json_int_t number = json_integer_value(value);
	if (number < lo || number > hi) {
		enter(r, ".%s", key);
		return fail(r, "%" JSON_INTEGER_FORMAT " is out of range [%" JSON_INTEGER_FORMAT ", %" JSON_INTEGER_FORMAT "]",
		            number, lo, hi);
	}
	*out = (int)number;
	return PLUME_OK;
}

/// One of two names; *out is 0 for the first, 1 for the second.
static plume_status read_name(reader *r, json_t *object, const char *key, const char *const names[2], int *out)
{
	const char *text = json_string_value(json_object_get(object, key));
	for (int i = 0; text != NULL && i < 2; ++i) {
		if (strcmp(text, names[i]) == 0) {
			*out = i;
			return PLUME_OK;
		}
	}
	enter(r, ".%s", key);
	return fail(r, "expected \"%s\" or \"%s\"", names[0], names[1]);
}

/// A version 2 view {"offset": bytes, "count": numbers} into the sidecar; false
/// (and no message) when value is not one.
static bool is_view(const reader *r, json_t *value)
{
	return r->buffer != NULL && json_is_object(value) && json_object_size(value) == 2 &&
	       json_is_integer(json_object_get(value, "offset")) && json_is_integer(json_object_get(value, "count"));
}

/// The number of items in object[key], an array of components numbers per item
/// (or, in version 2, a view of as many numbers).
static plume_status read_count(reader *r, json_t *object, const char *key, int components, int *count)
{
	json_t *array = json_object_get(object, key);
	bool view = is_view(r, array);
	json_int_t numbers = view ? json_integer_value(json_object_get(array, "count")) : 0;
	size_t size = json_is_array(array) ? json_array_size(array) : numbers >= 0 ? (size_t)numbers : 1;
	if ((!json_is_array(array) && !view) || size % (size_t)components != 0 || size / (size_t)components > INT_MAX) {
		enter(r, ".%s", key);
		if (components == 1)
			return fail(r, "expected an array of numbers");
		return fail(r, "expected an array of %dn numbers", components);
	}
	*count = (int)(size / (size_t)components);
	return PLUME_OK;
}

/// Copies a view's numbers from the sidecar (little-endian binary64).
static plume_status read_view(reader *r, json_t *view, int components, size_t expected, void *base, size_t stride)
{
	json_int_t offset = json_integer_value(json_object_get(view, "offset"));
	json_int_t numbers = json_integer_value(json_object_get(view, "count"));
	if (numbers < 0 || (size_t)numbers != expected)
		return fail(r, "expected a view of %zu numbers, found \"count\": %" JSON_INTEGER_FORMAT, expected, numbers);
	if (offset < 0 || (size_t)offset > r->buffer_length || expected > (r->buffer_length - (size_t)offset) / 8)
		return fail(r, "the view (\"offset\": %" JSON_INTEGER_FORMAT ", %zu numbers) runs past the sidecar's %zu bytes",
		            offset, expected, r->buffer_length);
	const unsigned char *bytes = r->buffer + offset;
	for (size_t k = 0; k < expected; ++k, bytes += 8) {
		uint64_t bits = 0;
		for (int j = 7; j >= 0; --j)
			bits = bits << 8 | bytes[j];
		double x;
		memcpy(&x, &bits, sizeof x);
		// The sidecar's numbers pass the same bound as the JSON's (plume_spec_check_numbers):
		// nothing non-finite or absurd reaches the embedding or a renderer.
		if (!(fabs(x) <= PLUME_SPEC_MAX_MAGNITUDE))
			return fail(r,
			            "number %zu of the view in the sidecar is %g, outside the range of any value plume reads, "
			            "[-1e12, 1e12]",
			            k, x);
		size_t item = k / (size_t)components, component = k % (size_t)components;
		((double *)((char *)base + item * stride))[component] = x;
	}
	return PLUME_OK;
}

/// Reads object[key], count items of components numbers each, into the doubles
/// at base + i * stride (base is not touched when count is 0).
static plume_status read_numbers(reader *r, json_t *object, const char *key, int components, int count, void *base,
                                 size_t stride)
{
	json_t *array = json_object_get(object, key);
	size_t expected = (size_t)count * (size_t)components;
	size_t mark = enter(r, ".%s", key);
	if (is_view(r, array)) {
		plume_status status = read_view(r, array, components, expected, base, stride);
		leave(r, mark);
		return status;
	}
	if (!json_is_array(array))
		return fail(r, "expected an array of %zu numbers (%d per point)", expected, components);
	if (json_array_size(array) != expected)
		return fail(r, "expected %zu numbers (%d per point, %d points), found %zu", expected, components, count,
		            json_array_size(array));
	for (size_t k = 0; k < expected; ++k) {
		json_t *value = json_array_get(array, k);
		if (!json_is_number(value)) {
			enter(r, "[%zu]", k);
			return fail(r, "expected a number");
		}
		size_t item = k / (size_t)components, component = k % (size_t)components;
		double *target = (double *)((char *)base + item * stride) + component;
		*target = json_number_value(value);
	}
	leave(r, mark);
	return PLUME_OK;
}

/// The per-point arrays of a barb or barbule, appended to the point pool.
static plume_status read_polyline(reader *r, json_t *object, plume_feather *feather, plume_curve_range *range)
{
	int count = 0;
	plume_status status = read_count(r, object, "position", 3, &count);
	if (status != PLUME_OK)
		return status;
	if (count > INT_MAX / 2 - feather->point_count)
		return fail_at(r, "position", "too many points");
	int first = feather->point_count;
	if (count > 0 && (first = plume_feather_add_points(feather, count)) < 0)
		return out_of_memory(r);
	*range = (plume_curve_range){first, count};
	bool any = count > 0; // no pointer arithmetic on a pool that may still be NULL
	if ((status = read_numbers(r, object, "position", 3, count, any ? (void *)(feather->points + first) : NULL,
	                           sizeof(plume_vec3))) != PLUME_OK ||
	    (status = read_numbers(r, object, "normal", 3, count, any ? (void *)(feather->normals + first) : NULL,
	                           sizeof(plume_vec3))) != PLUME_OK ||
	    (status = read_numbers(r, object, "arc_length", 1, count, any ? (void *)(feather->arc_length + first) : NULL,
	                           sizeof(double))) != PLUME_OK ||
	    (status = read_numbers(r, object, "width", 1, count, any ? (void *)(feather->widths + first) : NULL,
	                           sizeof(double))) != PLUME_OK ||
	    (status = read_numbers(r, object, "uv", 2, count, any ? (void *)(feather->uv + first) : NULL,
	                           sizeof(plume_vec2))) != PLUME_OK)
		return status;
	return PLUME_OK;
}

static plume_status read_shaft(reader *r, json_t *object, plume_feather *feather)
{
	static const char *const keys[] = {"calamus_samples", "position", "tangent", "normal", "binormal", "width", "t"};
	plume_status status = check_object(r, object, "the shaft", keys, sizeof keys / sizeof keys[0]);
	int count = 0;
	if (status != PLUME_OK || (status = read_count(r, object, "position", 3, &count)) != PLUME_OK)
		return status;
	plume_shaft_sample *shaft = NULL;
	if (count > 0 && (shaft = plume_feather_add_shaft(feather, count)) == NULL)
		return out_of_memory(r);
	size_t stride = sizeof(plume_shaft_sample);
	if ((status = read_numbers(r, object, "position", 3, count, shaft ? &shaft->position : NULL, stride)) != PLUME_OK ||
	    (status = read_numbers(r, object, "tangent", 3, count, shaft ? &shaft->tangent : NULL, stride)) != PLUME_OK ||
	    (status = read_numbers(r, object, "normal", 3, count, shaft ? &shaft->normal : NULL, stride)) != PLUME_OK ||
	    (status = read_numbers(r, object, "binormal", 3, count, shaft ? &shaft->binormal : NULL, stride)) != PLUME_OK ||
	    (status = read_numbers(r, object, "width", 1, count, shaft ? &shaft->width : NULL, stride)) != PLUME_OK ||
	    (status = read_numbers(r, object, "t", 1, count, shaft ? &shaft->t : NULL, stride)) != PLUME_OK)
		return status;
	return read_int(r, object, "calamus_samples", 0, count, &feather->calamus_count);
}

static plume_status read_barbule(reader *r, json_t *object, plume_feather *feather, int barb)
{
	static const char *const keys[] = {"barb_s", "kind", "position", "normal", "arc_length", "width", "uv"};
	plume_barbule_record record = {.barb = barb};
	int kind = 0;
	plume_status status = check_object(r, object, "a barbule", keys, sizeof keys / sizeof keys[0]);
	if (status != PLUME_OK || (status = read_fraction(r, object, "barb_s", &record.barb_s)) != PLUME_OK ||
	    (status = read_name(r, object, "kind", kind_names, &kind)) != PLUME_OK ||
	    (status = read_polyline(r, object, feather, &record.curve)) != PLUME_OK)
		return status;
	record.kind = (plume_barbule_kind)kind;
	return plume_feather_add_barbule(feather, &record) < 0 ? out_of_memory(r) : PLUME_OK;
}

static plume_status read_barb(reader *r, json_t *object, plume_feather *feather)
{
	static const char *const keys[] = {"side",       "rachis_t", "segment", "position", "normal",
	                                   "arc_length", "width",    "uv",      "barbules"};
	plume_barb_record record = {0};
	int side = 0;
	plume_status status = check_object(r, object, "a barb", keys, sizeof keys / sizeof keys[0]);
	if (status != PLUME_OK || (status = read_name(r, object, "side", side_names, &side)) != PLUME_OK ||
	    (status = read_fraction(r, object, "rachis_t", &record.rachis_t)) != PLUME_OK ||
	    (status = read_int(r, object, "segment", INT_MIN, INT_MAX, &record.segment)) != PLUME_OK ||
	    (status = read_polyline(r, object, feather, &record.curve)) != PLUME_OK)
		return status;
	record.side = (plume_side)side;

	// Barbules are stored grouped by barb: this barb's start where the pool's end is now.
	json_t *barbules = json_object_get(object, "barbules");
	if (!json_is_array(barbules))
		return fail_at(r, "barbules", "expected an array");
	int index = feather->barb_count; // the barb's index once added below
	record.barbule_first = feather->barbule_count;
	size_t i;
	json_t *item;
	json_array_foreach (barbules, i, item) {
		size_t mark = enter(r, ".barbules[%zu]", i);
		if ((status = read_barbule(r, item, feather, index)) != PLUME_OK)
			return status;
		leave(r, mark);
	}
	record.barbule_count = feather->barbule_count - record.barbule_first;
	return plume_feather_add_barb(feather, &record) < 0 ? out_of_memory(r) : PLUME_OK;
}

/// Loads version 2's sidecar, named by $.buffer.uri: a file name in the JSON
/// file's folder (no folders, so a document cannot point elsewhere).
static plume_status load_sidecar(reader *r, json_t *buffer)
{
	static const char *const keys[] = {"uri"};
	size_t mark = enter(r, ".buffer");
	plume_status status = check_object(r, buffer, "the sidecar {\"uri\": NAME}", keys, 1);
	if (status != PLUME_OK)
		return status;
	const char *uri = json_string_value(json_object_get(buffer, "uri"));
	if (uri == NULL || uri[0] == '\0' || strchr(uri, '/') != NULL || strchr(uri, '\\') != NULL ||
	    strcmp(uri, "..") == 0 || strcmp(uri, ".") == 0)
		return fail_at(r, "uri", "expected a file name in the JSON file's folder");
	const char *slash = strrchr(r->file, '/');
	size_t folder = slash != NULL ? (size_t)(slash - r->file) + 1 : 0;
	char path[4096];
	if (folder + strlen(uri) + 1 > sizeof path)
		return fail_at(r, "uri", "path too long");
	memcpy(path, r->file, folder);
	strcpy(path + folder, uri);
	FILE *file = fopen(path, "rb");
	if (file == NULL)
		return plume_error_set(r->err, PLUME_ERROR_IO, "%s: cannot read the sidecar %s ($.buffer.uri): %s", r->file,
		                       path, strerror(errno));
	long length = -1;
	if (fseek(file, 0, SEEK_END) == 0)
		length = ftell(file);
	unsigned char *bytes = length >= 0 ? plume_alloc(length > 0 ? (size_t)length : 1) : NULL;
	bool ok = bytes != NULL && fseek(file, 0, SEEK_SET) == 0 && fread(bytes, 1, (size_t)length, file) == (size_t)length;
	int error = errno;
	fclose(file);
	if (!ok) {
		plume_free(bytes);
		if (length >= 0 && bytes == NULL)
			return out_of_memory(r);
		return plume_error_set(r->err, PLUME_ERROR_IO, "%s: cannot read the sidecar %s: %s", r->file, path,
		                       strerror(error));
	}
	r->buffer = bytes;
	r->buffer_length = (size_t)length;
	leave(r, mark);
	return PLUME_OK;
}

static plume_status read_feather(reader *r, json_t *object, plume_feather *feather, bool top)
{
	static const char *const top_keys[] = {"format", "version", "shaft", "barbs", "afterfeather", "buffer"};
	// A nested feather has the same keys less the two that name the format; version 2 adds "buffer".
	json_t *version = json_object_get(object, "version");
	bool binary = top && json_is_integer(version) && json_integer_value(version) == FORMAT_VERSION_BINARY;
	const char *const *keys = top ? top_keys : top_keys + 2;
	size_t key_count = top ? (binary ? 6 : 5) : 3;
	plume_status status = check_object(r, object, "a feather", keys, key_count);
	if (status != PLUME_OK)
		return status;
	if (top) {
		const char *format = json_string_value(json_object_get(object, "format"));
		if (format == NULL || strcmp(format, FORMAT_NAME) != 0)
			return fail_at(r, "format", "expected \"" FORMAT_NAME "\"");
		if (!json_is_integer(version) || (json_integer_value(version) != FORMAT_VERSION && !binary)) {
			enter(r, ".version");
			return fail(r, "unsupported version (this plume reads versions %d and %d)", FORMAT_VERSION,
			            FORMAT_VERSION_BINARY);
		}
		if (binary && (status = load_sidecar(r, json_object_get(object, "buffer"))) != PLUME_OK)
			return status;
	}

	size_t mark = enter(r, ".shaft");
	if ((status = read_shaft(r, json_object_get(object, "shaft"), feather)) != PLUME_OK)
		return status;
	leave(r, mark);

	json_t *barbs = json_object_get(object, "barbs");
	if (!json_is_array(barbs))
		return fail_at(r, "barbs", "expected an array");
	size_t i;
	json_t *item;
	json_array_foreach (barbs, i, item) {
		mark = enter(r, ".barbs[%zu]", i);
		if ((status = read_barb(r, item, feather)) != PLUME_OK)
			return status;
		leave(r, mark);
	}

	json_t *after = json_object_get(object, "afterfeather");
	if (json_is_null(after))
		return PLUME_OK;
	static const char *const after_keys[] = {"t", "feather"};
	mark = enter(r, ".afterfeather");
	if ((status = check_object(r, after, "the afterfeather, or null", after_keys, 2)) != PLUME_OK ||
	    (status = read_fraction(r, after, "t", &feather->afterfeather_t)) != PLUME_OK)
		return status;
	// Attached before it is filled, so that destroying the parent frees it on any error.
	if ((feather->afterfeather = plume_feather_create_empty()) == NULL)
		return out_of_memory(r);
	enter(r, ".feather");
	if ((status = read_feather(r, json_object_get(after, "feather"), feather->afterfeather, false)) != PLUME_OK)
		return status;
	leave(r, mark);
	return PLUME_OK;
}

plume_status plume_read_json(const char *path, plume_feather **out, plume_error *err)
{
	*out = NULL;
	FILE *file = fopen(path, "rb");
	if (file == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read: %s", path, strerror(errno));
	json_error_t error;
	json_t *root = json_loadf(file, JSON_REJECT_DUPLICATES, &error);
	int read_error = ferror(file) ? errno : 0; // e.g. EISDIR: fopen opens a folder, reading it fails
	fclose(file);
	if (root == NULL) {
		if (read_error != 0)
			return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read: %s", path, strerror(read_error));
		if (json_error_code(&error) == json_error_out_of_memory)
			return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
		return plume_error_set(err, PLUME_ERROR_SYNTAX, "%s:%d:%d: %s", path, error.line, error.column, error.text);
	}

	plume_status checked = plume_spec_check_numbers(path, root, err);
	if (checked != PLUME_OK) {
		json_decref(root);
		return checked;
	}
	reader r = {.file = path, .err = err, .path = "$", .length = 1};
	plume_feather *feather = plume_feather_create_empty();
	plume_status status = feather != NULL ? read_feather(&r, root, feather, true) : out_of_memory(&r);
	json_decref(root);
	plume_free((void *)r.buffer);
	if (status != PLUME_OK) {
		plume_feather_destroy(feather);
		return status;
	}
	*out = feather;
	return PLUME_OK;
}

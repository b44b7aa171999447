// Private: reading JSON specs with messages a user can act on.
//
// A reader carries the file name and the first error; every getter after a
// failure does nothing, so callers read a whole spec and check once:
//
//     plume_spec_reader reader = plume_spec_reader_begin(path, err);
//     plume_spec_check_keys(&reader, root, "$", allowed_keys);
//     plume_spec_number(&reader, root, "$", "margin", &def.margin);
//     if (reader.status != PLUME_OK) ...
//
// Value messages read "file: $.path.key: what is wrong"; syntax errors
// "file:line:column: what was expected" (from jansson).
#ifndef PLUME_SPEC_H
#define PLUME_SPEC_H

#include <jansson.h>

#include "plume/core.h"

typedef struct plume_spec_reader {
	const char *file;
	plume_error *err;
	plume_status status;
} plume_spec_reader;

/// Parses path with duplicate keys rejected. Returns NULL and fills err on
/// a missing file (PLUME_ERROR_IO) or bad JSON (PLUME_ERROR_SYNTAX).
json_t *plume_spec_load(const char *path, plume_error *err);

/// plume_spec_load for a model spec: also fails (PLUME_ERROR_SPEC) when the top level
/// is not an object. *status receives the outcome; NULL on failure.
json_t *plume_spec_load_model(const char *path, plume_status *status, plume_error *err);

/// The largest magnitude of any number plume reads from JSON (specs, scenes,
/// lab files, cameras, feather dumps). Every key has its own, narrower range;
/// this one holds before any reader runs, so no value near DBL_MAX can reach
/// a product, a loop bound or an output file (1e12 leaves moduli in Pa and
/// any length in metres far inside it, and its square far from overflow).
#define PLUME_SPEC_MAX_MAGNITUDE 1e12

/// Fails (PLUME_ERROR_SPEC, "file: $.path: ...") on the first number of the
/// tree whose magnitude exceeds PLUME_SPEC_MAX_MAGNITUDE. plume_spec_load
/// already calls it; readers of JSON from elsewhere call it themselves.
plume_status plume_spec_check_numbers(const char *file, const json_t *root, plume_error *err);

plume_spec_reader plume_spec_reader_begin(const char *file, plume_error *err);

/// Records an error at path ("file: path: message").
void plume_spec_fail(plume_spec_reader *reader, const char *path, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/// Fails on the first key of object not in allowed (NULL-terminated), naming
/// the allowed key it suggests (plume_spec_suggest), else listing them.
void plume_spec_check_keys(plume_spec_reader *reader, const json_t *object, const char *path,
                           const char *const *allowed);

/// Writes "parent.key" into out (the JSON path of a child).
void plume_spec_path(char *out, size_t size, const char *parent, const char *key);

/// Writes "parent[index]" into out.
void plume_spec_index_path(char *out, size_t size, const char *parent, size_t index);

// Typed getters: when key is absent, *out keeps its value (the default) and
// the getter returns false; a present value of the wrong type fails.

bool plume_spec_number(plume_spec_reader *reader, const json_t *object, const char *path, const char *key, double *out);
bool plume_spec_int(plume_spec_reader *reader, const json_t *object, const char *path, const char *key, int *out);
bool plume_spec_uint64(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       uint64_t *out);
bool plume_spec_bool(plume_spec_reader *reader, const json_t *object, const char *path, const char *key, bool *out);
/// A string; *out points into the JSON tree.
bool plume_spec_string(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                       const char **out);
/// An array of exactly count points [x, y].
bool plume_spec_points2(plume_spec_reader *reader, const json_t *object, const char *path, const char *key,
                        plume_vec2 *out, int count);
/// An object member (NULL when absent); fails when present but not an object.
const json_t *plume_spec_object(plume_spec_reader *reader, const json_t *object, const char *path, const char *key);
/// An array member (NULL when absent); fails when present but not an array.
const json_t *plume_spec_array(plume_spec_reader *reader, const json_t *object, const char *path, const char *key);

/// The allowed word nearest to word by edit distance (for "did you mean").
const char *plume_spec_nearest(const char *word, const char *const *allowed);

/// Whether candidate is near enough to word to be offered as "did you mean": at most a third of
/// word's letters (and at least 2) edits away.
bool plume_spec_is_near(const char *word, const char *candidate);

/// What "did you mean" offers for word: the nearest allowed word when it is near, else one that
/// begins with word (3 letters or more); NULL when none is (a guess would mislead).
const char *plume_spec_suggest(const char *word, const char *const *allowed);

#endif

// Private: what the geometry exporters (OBJ, USD, JSON) share: an output
// text file and the selection of curves that one exported object holds.
//
// Files that include this header define _POSIX_C_SOURCE 200809L first
// (locale_t and uselocale are POSIX 2008).
#ifndef PLUME_IO_EXPORT_H
#define PLUME_IO_EXPORT_H

#include <locale.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "../core/atomic_file.h"
#include "plume/feather.h"
#include "plume/mesh.h"

/// A text output: an atomic file (temporary file renamed on success) with a
/// large stdio buffer, written while the calling thread uses the "C" numeric
/// locale. printf formats "%g" with LC_NUMERIC's decimal point, so a program
/// that called setlocale(LC_ALL, "") in, say, de_DE would otherwise write
/// "0,5". uselocale changes the calling thread only and is undone by
/// plume_text_close, so there is no global state and other threads are not
/// affected.
typedef struct plume_text_file {
	plume_atomic_file file;
	FILE *stream; ///< write here
	char *buffer;
	locale_t c_locale;
	locale_t saved_locale;
} plume_text_file;

/// Opens path's temporary file for writing. On failure nothing is left to close.
plume_status plume_text_open(plume_text_file *text, const char *path, plume_error *err);

/// Finishes a file opened by plume_text_open: when status is PLUME_OK, commits
/// it (renames it over path); otherwise removes the temporary file and leaves
/// path as it was. Restores the thread's locale. Returns the final status
/// (a failed commit turns PLUME_OK into PLUME_ERROR_IO).
plume_status plume_text_close(plume_text_file *text, plume_status status, plume_error *err);

/// A polyline of count vertices whose first vertex has the 1-based OBJ index
/// first, as count - 1 two-vertex line elements "l a b". Blender 3.4's default
/// OBJ importer keeps only the first segment of a longer "l" element, and
/// misreads "l a/ta b/tb" (it drops and reconnects vertices), so the elements
/// carry no texture index: the file has one "vt" per "v", in the same order
/// (vt i belongs to v i). Checked with Blender's default and legacy importers
/// and ParaView (docs/formats.md).
void plume_obj_polyline(FILE *stream, long long first, int count);

/// Which curves of a feather one exported object holds.
typedef enum plume_curve_set {
	PLUME_CURVES_LEFT,     ///< barbs of the left vane
	PLUME_CURVES_RIGHT,    ///< barbs of the right vane
	PLUME_CURVES_BARBS,    ///< all barbs
	PLUME_CURVES_BARBULES, ///< all barbules
} plume_curve_set;

/// The loop bound for plume_curve_set_get: the feather's barb or barbule count.
int plume_curve_set_range(const plume_feather *feather, plume_curve_set set);

/// Barb or barbule i (0 <= i < plume_curve_set_range) as a polyline when it is
/// in the set; false when it is on the other side or has fewer than two
/// points (a polyline needs two; OBJ "l" and USD linear curves reject fewer).
bool plume_curve_set_get(const plume_feather *feather, plume_curve_set set, int i, plume_polyline *curve);

/// Curves and points that plume_curve_set_get yields for the set.
void plume_curve_set_count(const plume_feather *feather, plume_curve_set set, int *curves, int64_t *points);

/// The first piece of the feather (or of its afterfeathers) holding a number no exporter can
/// write, described in what ("barb 12 (point 3)", "afterfeather's shaft sample 0"); false when
/// there is none. A number is NaN or infinite, or, for files of single precision (USD's float
/// attributes, glTF's accessors), past FLT_MAX, where the float rounds to infinity. "%.9g"
/// would print "nan" and "inf", which no OBJ or USD reader takes for a number, and glTF's
/// bounds would be infinite. Checked before a file is opened: nothing is written.
bool plume_feather_find_non_finite(const plume_feather *feather, bool single_precision, char *what, size_t size);

/// The same for a mesh's vertices: the first vertex whose position (positions[i], or the
/// mesh's rest shape when positions is NULL) or texture coordinate no exporter can write,
/// -1 when there is none.
int plume_mesh_find_non_finite(const plume_mesh *mesh, const plume_vec3 *positions, bool single_precision);

#endif

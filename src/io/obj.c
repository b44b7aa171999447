// Wavefront OBJ export: every curve is a run of two-vertex line elements
// "l a b" over its consecutive vertices (plume_obj_polyline: Blender 3.4's
// default importer reads only the first segment of a longer "l" and misreads
// "l a/ta b/tb"), grouped into one object per part (shaft, left vane, right
// vane, barbules), so that Blender and ParaView import each part whole, as
// connected edges. Texture coordinates are one "vt" per "v", in the same order.
//
// Numbers are printed with "%.9g": nine significant digits keep a relative
// error below 5e-10 (a fraction of a nanometre on a 0.2 m feather) and
// reproduce any float32 exactly, which is what Blender and Houdini store, at
// about half the size of "%.17g". The exact, bit-for-bit format is the JSON
// dump (feather_json.c). The output is written in the "C" numeric locale
// whatever the process's locale (see export.h), so it is the same bytes on
// every run and machine.
#define _POSIX_C_SOURCE 200809L
#include "export.h"

#include <math.h>

#include "plume/io.h"

/// Object names grow by this prefix at each afterfeather level.
#define AFTERFEATHER_PREFIX "afterfeather_"

static void write_shaft(FILE *stream, const plume_feather *feather, const char *prefix, long long *next)
{
	plume_feather_info info = plume_feather_get_info(feather);
	int count = info.shaft_sample_count;
	if (count < 2)
		return; // no polyline: see plume_curve_set_get
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	fprintf(stream, "o %sshaft\n", prefix);
	for (int i = 0; i < count; ++i)
		fprintf(stream, "v %.9g %.9g %.9g\n", shaft[i].position.x, shaft[i].position.y, shaft[i].position.z);
	for (int i = 0; i < count; ++i)
		fprintf(stream, "vt 0 %.9g\n", shaft[i].t);
	plume_obj_polyline(stream, *next, count);
	*next += count;
}

/// One object holding every curve of the set: all its "v", then all its "vt",
/// then one "l" per curve. Every vertex has exactly one texture coordinate, so
/// the v and vt indices are the same number.
static void write_curves(FILE *stream, const plume_feather *feather, plume_curve_set set, const char *prefix,
                         const char *name, long long *next)
{
	int curves;
	int64_t points;
	plume_curve_set_count(feather, set, &curves, &points);
	if (curves == 0)
		return;
	int range = plume_curve_set_range(feather, set);
	plume_polyline curve;
	fprintf(stream, "o %s%s\n", prefix, name);
	for (int i = 0; i < range; ++i)
		if (plume_curve_set_get(feather, set, i, &curve))
			for (int j = 0; j < curve.count; ++j)
				fprintf(stream, "v %.9g %.9g %.9g\n", curve.points[j].x, curve.points[j].y, curve.points[j].z);
	for (int i = 0; i < range; ++i)
		if (plume_curve_set_get(feather, set, i, &curve))
			for (int j = 0; j < curve.count; ++j)
				fprintf(stream, "vt %.9g %.9g\n", curve.uv[j].x, curve.uv[j].y);
	for (int i = 0; i < range; ++i) {
		if (!plume_curve_set_get(feather, set, i, &curve))
			continue;
		plume_obj_polyline(stream, *next, curve.count);
		*next += curve.count;
	}
}

/// The feather's objects, then its afterfeather's (recursively) under a longer prefix.
static void write_feather(FILE *stream, const plume_feather *feather, const char *prefix, long long *next)
{
	write_shaft(stream, feather, prefix, next);
	write_curves(stream, feather, PLUME_CURVES_LEFT, prefix, "left_vane", next);
	write_curves(stream, feather, PLUME_CURVES_RIGHT, prefix, "right_vane", next);
	write_curves(stream, feather, PLUME_CURVES_BARBULES, prefix, "barbules", next);
	const plume_feather *after = plume_feather_afterfeather(feather);
	if (after != NULL) {
		// Object names only; a prefix that does not fit is cut (the names stay unique
		// by position in the file, and nesting that deep does not occur in practice).
		char longer[256];
		snprintf(longer, sizeof longer, "%s%s", prefix, AFTERFEATHER_PREFIX);
		write_feather(stream, after, longer, next);
	}
}

plume_status plume_write_obj(const plume_feather *feather, const char *path, plume_error *err)
{
	// Checked before the file is opened: nothing is written, and path keeps what it held.
	char what[320];
	if (plume_feather_find_non_finite(feather, false, what, sizeof what))
		return plume_error_set(err, PLUME_ERROR_NUMERIC, "%s: %s has a NaN or infinite number, which OBJ cannot hold",
		                       path, what);
	plume_text_file text;
	plume_status status = plume_text_open(&text, path, err);
	if (status != PLUME_OK)
		return status;
	plume_feather_info info = plume_feather_get_info(feather);
	fprintf(text.stream,
	        "# plume %s: a feather as polylines, each as consecutive segments (l a b)\n"
	        "# units: metres; the shaft runs along +y, the vanes lie near z = 0, +z is the front\n"
	        "# texture coordinates: one vt per v, in the same order (vt i belongs to v i);"
	        " barbs s = arc-length fraction from the rachis, t = shaft fraction of the root;"
	        " shaft s = 0, t = shaft fraction\n"
	        "# %d shaft samples, %d barbs (%d left, %d right), %d barbules, %d barb and barbule points, "
	        "afterfeather: %s\n",
	        PLUME_VERSION_STRING, info.shaft_sample_count, info.barb_count, info.barb_count_left, info.barb_count_right,
	        info.barbule_count, info.point_count, info.has_afterfeather ? "yes" : "no");
	long long next = 1; // OBJ indices are 1-based and count across objects
	write_feather(text.stream, feather, "", &next);
	return plume_text_close(&text, PLUME_OK, err);
}

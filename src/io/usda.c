// USD text export (.usda): the shaft, the barbs and the barbules as
// UsdGeomBasisCurves prims under one Xform, the afterfeather as a nested Xform.
//
// Schema notes (UsdGeom, BasisCurves and Curves):
// - "type" defaults to "cubic", so "linear" is authored; "basis" is ignored by
//   linear curves and left out; "wrap" is authored as "nonperiodic".
// - "widths" are diameters (plume's widths are diameters too). With "normals"
//   authored, a curve is imaged as a flat ribbon facing the normals (the
//   barbs); without, as a tube (the shaft).
// - For linear curves "vertex" and "varying" data both hold one value per
//   point; "vertex" is used throughout, which every importer handles.
// - Per-curve data ("primvars:side", ...) is "uniform": one value per curve.
// - primvars:displayColor (linear RGB, constant per prim) gives every prim the
//   ray tracer's default colours, so viewers without materials show a feather.
// Points, normals and widths are single precision in USD (point3f, normal3f,
// float): each value is rounded to float and printed with "%.9g", which
// reproduces that float exactly. The text is written in the "C" numeric
// locale (see export.h), so the same feather gives the same bytes everywhere.
#define _POSIX_C_SOURCE 200809L
#include "export.h"

#include <math.h>

#include "plume/io.h"

/// Four spaces per nesting level, as usdcat writes.
static void indent(FILE *stream, int depth)
{
	for (int i = 0; i < depth; ++i)
		fputs("    ", stream);
}

static void print_vec3(FILE *stream, plume_vec3 v)
{
	fprintf(stream, "(%.9g, %.9g, %.9g)", (float)v.x, (float)v.y, (float)v.z);
}

/// Closes an attribute's value array and gives its interpolation metadata.
static void end_array(FILE *stream, int depth, const char *interpolation)
{
	fputs("] (\n", stream);
	indent(stream, depth + 1);
	fprintf(stream, "interpolation = \"%s\"\n", interpolation);
	indent(stream, depth);
	fputs(")\n", stream);
}

/// The extent of a set of points and widths: bounds of the points grown by
/// half the widest width, as UsdGeomCurves::ComputeExtent defines it.
typedef struct extent {
	plume_vec3 lo, hi;
	double max_width;
} extent;

static void extent_add(extent *box, plume_vec3 p, double width)
{
	box->lo = plume_v3(fmin(box->lo.x, p.x), fmin(box->lo.y, p.y), fmin(box->lo.z, p.z));
	box->hi = plume_v3(fmax(box->hi.x, p.x), fmax(box->hi.y, p.y), fmax(box->hi.z, p.z));
	box->max_width = fmax(box->max_width, width);
}

static void write_extent(FILE *stream, int depth, const extent *box)
{
	double r = 0.5 * box->max_width;
	indent(stream, depth);
	fputs("float3[] extent = [", stream);
	print_vec3(stream, plume_v3_sub(box->lo, plume_v3(r, r, r)));
	fputs(", ", stream);
	print_vec3(stream, plume_v3_add(box->hi, plume_v3(r, r, r)));
	fputs("]\n", stream);
}

static const extent empty_extent = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, 0.0};

/// primvars:displayColor, constant over a prim: sRGB colour converted to linear
/// (USD's colours are linear), the ray tracer's default shaft and barb colours.
static void write_display_color(FILE *stream, int depth, double r, double g, double b)
{
	double c[3] = {r, g, b};
	for (int k = 0; k < 3; ++k)
		c[k] = c[k] <= 0.04045 ? c[k] / 12.92 : pow((c[k] + 0.055) / 1.055, 2.4);
	indent(stream, depth);
	fprintf(stream, "color3f[] primvars:displayColor = [(%.9g, %.9g, %.9g)] (\n", (float)c[0], (float)c[1],
	        (float)c[2]);
	indent(stream, depth + 1);
	fputs("interpolation = \"constant\"\n", stream);
	indent(stream, depth);
	fputs(")\n", stream);
}

/// The curve type attributes every prim here shares.
static void write_curve_type(FILE *stream, int depth)
{
	indent(stream, depth);
	fputs("uniform token type = \"linear\"\n", stream);
	indent(stream, depth);
	fputs("uniform token wrap = \"nonperiodic\"\n", stream);
}

/// The shaft as one unoriented (tube) curve; texture coordinates (0, t) as in the OBJ export.
static void write_shaft(FILE *stream, const plume_feather *feather, int depth)
{
	int count = plume_feather_get_info(feather).shaft_sample_count;
	if (count < 2)
		return; // not a curve: see plume_curve_set_get
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	extent box = empty_extent;
	for (int i = 0; i < count; ++i)
		extent_add(&box, shaft[i].position, shaft[i].width);

	indent(stream, depth);
	fputs("def BasisCurves \"shaft\"\n", stream);
	indent(stream, depth);
	fputs("{\n", stream);
	int inner = depth + 1;
	write_curve_type(stream, inner);
	indent(stream, inner);
	fprintf(stream, "int[] curveVertexCounts = [%d]\n", count);
	write_extent(stream, inner, &box);
	indent(stream, inner);
	fputs("point3f[] points = [", stream);
	for (int i = 0; i < count; ++i) {
		fputs(i > 0 ? ", " : "", stream);
		print_vec3(stream, shaft[i].position);
	}
	fputs("]\n", stream);
	indent(stream, inner);
	fputs("float[] widths = [", stream);
	for (int i = 0; i < count; ++i)
		fprintf(stream, "%s%.9g", i > 0 ? ", " : "", (float)shaft[i].width);
	end_array(stream, inner, "vertex");
	indent(stream, inner);
	fputs("texCoord2f[] primvars:st = [", stream);
	for (int i = 0; i < count; ++i)
		fprintf(stream, "%s(0, %.9g)", i > 0 ? ", " : "", (float)shaft[i].t);
	end_array(stream, inner, "vertex");
	write_display_color(stream, inner, 0.78, 0.72, 0.62);
	indent(stream, depth);
	fputs("}\n", stream);
}

/// Which per-point array write_point_data prints.
typedef enum point_data { POINT_POSITION, POINT_NORMAL, POINT_WIDTH, POINT_UV } point_data;

/// One per-point array of every curve in the set, a curve per line (USD text
/// allows line breaks inside arrays; one line per curve keeps files readable).
static void write_point_data(FILE *stream, const plume_feather *feather, plume_curve_set set, int depth,
                             point_data data)
{
	int range = plume_curve_set_range(feather, set);
	bool first = true;
	plume_polyline curve;
	for (int i = 0; i < range; ++i) {
		if (!plume_curve_set_get(feather, set, i, &curve))
			continue;
		fputs(first ? "\n" : ",\n", stream);
		first = false;
		indent(stream, depth + 1);
		for (int j = 0; j < curve.count; ++j) {
			fputs(j > 0 ? ", " : "", stream);
			switch (data) {
			case POINT_POSITION: print_vec3(stream, curve.points[j]); break;
			case POINT_NORMAL: print_vec3(stream, curve.normals[j]); break;
			case POINT_WIDTH: fprintf(stream, "%.9g", (float)curve.widths[j]); break;
			case POINT_UV: fprintf(stream, "(%.9g, %.9g)", (float)curve.uv[j].x, (float)curve.uv[j].y); break;
			}
		}
	}
	fputc('\n', stream);
	indent(stream, depth);
}

/// Which per-curve (uniform) value write_curve_data prints.
typedef enum curve_data { CURVE_VERTEX_COUNT, CURVE_SIDE, CURVE_SEGMENT, CURVE_KIND, CURVE_BARB } curve_data;

static void write_curve_data(FILE *stream, const plume_feather *feather, plume_curve_set set, curve_data data)
{
	int range = plume_curve_set_range(feather, set);
	bool first = true;
	plume_polyline curve;
	for (int i = 0; i < range; ++i) {
		if (!plume_curve_set_get(feather, set, i, &curve))
			continue;
		int value = curve.count;
		if (data == CURVE_SIDE || data == CURVE_SEGMENT) {
			plume_barb barb = plume_feather_barb(feather, i);
			value = data == CURVE_SIDE ? (int)barb.side : barb.segment;
		} else if (data == CURVE_KIND || data == CURVE_BARB) {
			plume_barbule barbule = plume_feather_barbule(feather, i);
			value = data == CURVE_KIND ? (int)barbule.kind : barbule.barb;
		}
		fprintf(stream, first ? "%d" : ", %d", value);
		first = false;
	}
}

/// One BasisCurves prim with every curve of the set, as oriented ribbons.
static void write_curves(FILE *stream, const plume_feather *feather, plume_curve_set set, const char *name, int depth)
{
	int curves;
	int64_t points;
	plume_curve_set_count(feather, set, &curves, &points);
	if (curves == 0)
		return;
	extent box = empty_extent;
	int range = plume_curve_set_range(feather, set);
	plume_polyline curve;
	for (int i = 0; i < range; ++i)
		if (plume_curve_set_get(feather, set, i, &curve))
			for (int j = 0; j < curve.count; ++j)
				extent_add(&box, curve.points[j], curve.widths[j]);

	indent(stream, depth);
	fprintf(stream, "def BasisCurves \"%s\"\n", name);
	indent(stream, depth);
	fputs("{\n", stream);
	int inner = depth + 1;
	write_curve_type(stream, inner);
	indent(stream, inner);
	fputs("int[] curveVertexCounts = [", stream);
	write_curve_data(stream, feather, set, CURVE_VERTEX_COUNT);
	fputs("]\n", stream);
	write_extent(stream, inner, &box);
	indent(stream, inner);
	fputs("point3f[] points = [", stream);
	write_point_data(stream, feather, set, inner, POINT_POSITION);
	fputs("]\n", stream);
	indent(stream, inner);
	fputs("normal3f[] normals = [", stream);
	write_point_data(stream, feather, set, inner, POINT_NORMAL);
	end_array(stream, inner, "vertex");
	indent(stream, inner);
	fputs("float[] widths = [", stream);
	write_point_data(stream, feather, set, inner, POINT_WIDTH);
	end_array(stream, inner, "vertex");
	indent(stream, inner);
	fputs("texCoord2f[] primvars:st = [", stream);
	write_point_data(stream, feather, set, inner, POINT_UV);
	end_array(stream, inner, "vertex");
	write_display_color(stream, inner, 0.45, 0.33, 0.22);

	// Per-curve integers, named as in plume's structure (0 = left / distal, 1 = right / proximal).
	static const struct {
		curve_data data;
		const char *name;
		bool barbs; // a barb attribute (else a barbule one)
	} uniform_data[] = {
	    {CURVE_SIDE, "side", true},
	    {CURVE_SEGMENT, "segment", true},
	    {CURVE_KIND, "kind", false},
	    {CURVE_BARB, "barb", false},
	};
	for (size_t k = 0; k < sizeof uniform_data / sizeof uniform_data[0]; ++k) {
		if (uniform_data[k].barbs != (set != PLUME_CURVES_BARBULES))
			continue;
		indent(stream, inner);
		fprintf(stream, "int[] primvars:%s = [", uniform_data[k].name);
		write_curve_data(stream, feather, set, uniform_data[k].data);
		end_array(stream, inner, "uniform");
	}
	indent(stream, depth);
	fputs("}\n", stream);
}

/// An Xform holding the feather's prims and, nested, its afterfeather's. The
/// root is the asset (a component model); an afterfeather records where it
/// attaches in a custom attribute, plume:attach_t (shaft fraction of its parent).
static void write_feather(FILE *stream, const plume_feather *feather, const char *name, bool root, double attach_t,
                          int depth)
{
	indent(stream, depth);
	fprintf(stream, "def Xform \"%s\"", name);
	if (root) {
		fputs(" (\n", stream);
		indent(stream, depth + 1);
		fputs("kind = \"component\"\n", stream);
		indent(stream, depth);
		fputc(')', stream);
	}
	fputc('\n', stream);
	indent(stream, depth);
	fputs("{\n", stream);
	if (!root) {
		indent(stream, depth + 1);
		fprintf(stream, "custom double plume:attach_t = %.17g\n", attach_t);
	}
	write_shaft(stream, feather, depth + 1);
	write_curves(stream, feather, PLUME_CURVES_BARBS, "barbs", depth + 1);
	write_curves(stream, feather, PLUME_CURVES_BARBULES, "barbules", depth + 1);
	const plume_feather *after = plume_feather_afterfeather(feather);
	if (after != NULL) // its geometry is already in this feather's frame: no transform
		write_feather(stream, after, "afterfeather", false, plume_feather_afterfeather_t(feather), depth + 1);
	indent(stream, depth);
	fputs("}\n", stream);
}

plume_status plume_write_usda(const plume_feather *feather, const char *path, plume_error *err)
{
	// Checked before the file is opened: nothing is written, and path keeps what it held.
	char what[320];
	if (plume_feather_find_non_finite(feather, true, what, sizeof what))
		return plume_error_set(err, PLUME_ERROR_NUMERIC,
		                       "%s: %s has a NaN or infinite number (or one past single precision, 3.4e38), which "
		                       "USD's float attributes cannot hold",
		                       path, what);
	plume_text_file text;
	plume_status status = plume_text_open(&text, path, err);
	if (status != PLUME_OK)
		return status;
	plume_feather_info info = plume_feather_get_info(feather);
	fprintf(text.stream,
	        "#usda 1.0\n"
	        "(\n"
	        "    defaultPrim = \"feather\"\n"
	        "    doc = \"\"\"plume %s: a feather as curves. %d shaft samples, %d barbs (%d left, %d right), "
	        "%d barbules, %d barb and barbule points, afterfeather: %s.\"\"\"\n"
	        "    metersPerUnit = 1\n"
	        "    upAxis = \"Y\"\n"
	        ")\n\n",
	        PLUME_VERSION_STRING, info.shaft_sample_count, info.barb_count, info.barb_count_left, info.barb_count_right,
	        info.barbule_count, info.point_count, info.has_afterfeather ? "yes" : "no");
	write_feather(text.stream, feather, "feather", true, 0.0, 0);
	return plume_text_close(&text, PLUME_OK, err);
}

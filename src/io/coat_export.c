// A coat's geometry out: OBJ polylines and USD BasisCurves, one object per
// feather in drawing order (the picture is render/coat_draw.c).
#define _POSIX_C_SOURCE 200809L
#include "export.h"

#include <math.h>
#include <stdlib.h>

#include "../core/alloc.h"
#include "plume/coat.h"

/// Calls visit for the feather's shaft, each barb and barbule, then its afterfeather's, as polylines with
/// widths and uv (the shaft's uv is (0, t)).
typedef void curve_visitor(void *context, int count, const plume_vec3 *points, const double *widths,
                           const plume_vec2 *uv);

static void visit_curves(const plume_feather *feather, curve_visitor *visit, void *context, plume_vec3 *shaft_points,
                         double *shaft_widths, plume_vec2 *shaft_uv)
{
	plume_feather_info info = plume_feather_get_info(feather);
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	if (info.shaft_sample_count >= 2) {
		for (int i = 0; i < info.shaft_sample_count; ++i) {
			shaft_points[i] = shaft[i].position;
			shaft_widths[i] = shaft[i].width;
			shaft_uv[i] = (plume_vec2){0.0, shaft[i].t};
		}
		visit(context, info.shaft_sample_count, shaft_points, shaft_widths, shaft_uv);
	}
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		if (barb.curve.count >= 2)
			visit(context, barb.curve.count, barb.curve.points, barb.curve.widths, barb.curve.uv);
	}
	for (int i = 0; i < info.barbule_count; ++i) {
		plume_barbule barbule = plume_feather_barbule(feather, i);
		if (barbule.curve.count >= 2)
			visit(context, barbule.curve.count, barbule.curve.points, barbule.curve.widths, barbule.curve.uv);
	}
	const plume_feather *after = plume_feather_afterfeather(feather);
	if (after != NULL)
		visit_curves(after, visit, context, shaft_points, shaft_widths, shaft_uv);
}

/// Scratch for shafts: the longest shaft of the coat (afterfeathers included).
typedef struct shaft_scratch {
	plume_vec3 *points;
	double *widths;
	plume_vec2 *uv;
} shaft_scratch;

static int longest_shaft(const plume_feather *feather)
{
	int n = plume_feather_get_info(feather).shaft_sample_count;
	const plume_feather *after = plume_feather_afterfeather(feather);
	if (after != NULL) {
		int m = longest_shaft(after);
		n = m > n ? m : n;
	}
	return n;
}

static bool scratch_init(shaft_scratch *s, const plume_coat *coat)
{
	int n = 1;
	for (int i = 0; i < plume_coat_feather_count(coat); ++i) {
		int m = longest_shaft(plume_coat_feather(coat, i));
		n = m > n ? m : n;
	}
	s->points = plume_alloc((size_t)n * sizeof *s->points);
	s->widths = plume_alloc((size_t)n * sizeof *s->widths);
	s->uv = plume_alloc((size_t)n * sizeof *s->uv);
	return s->points != NULL && s->widths != NULL && s->uv != NULL;
}

static void scratch_free(shaft_scratch *s)
{
	plume_free(s->points);
	plume_free(s->widths);
	plume_free(s->uv);
}

/// Scratch for the coat's shafts and the output text file; on failure neither is left to free.
static plume_status open_output(const plume_coat *coat, const char *path, shaft_scratch *scratch, plume_text_file *text,
                                plume_error *err)
{
	if (!scratch_init(scratch, coat)) {
		scratch_free(scratch);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	}
	plume_status status = plume_text_open(text, path, err);
	if (status != PLUME_OK)
		scratch_free(scratch);
	return status;
}

// ---------------------------------------------------------------------------
// OBJ

typedef struct obj_pass {
	FILE *stream;
	int what; ///< 0: v lines, 1: vt lines, 2: l elements
	long long next;
} obj_pass;

static void obj_visit(void *context, int count, const plume_vec3 *points, const double *widths, const plume_vec2 *uv)
{
	(void)widths;
	obj_pass *pass = context;
	if (pass->what == 0)
		for (int i = 0; i < count; ++i)
			fprintf(pass->stream, "v %.9g %.9g %.9g\n", points[i].x, points[i].y, points[i].z);
	else if (pass->what == 1)
		for (int i = 0; i < count; ++i)
			fprintf(pass->stream, "vt %.9g %.9g\n", uv[i].x, uv[i].y);
	else {
		plume_obj_polyline(pass->stream, pass->next, count);
		pass->next += count;
	}
}

plume_status plume_coat_write_obj(const plume_coat *coat, const char *path, plume_error *err)
{
	shaft_scratch scratch;
	plume_text_file text;
	plume_status status = open_output(coat, path, &scratch, &text, err);
	if (status != PLUME_OK)
		return status;
	int count = plume_coat_feather_count(coat);
	fprintf(text.stream,
	        "# plume %s: a feather coat, %d feathers as polylines (consecutive segments l a b; one vt per v, same "
	        "order), one object each in "
	        "drawing order\n"
	        "# (bottom to top), shaft first, then barbs and afterfeather; metres, world coordinates\n",
	        PLUME_VERSION_STRING, count);
	obj_pass pass = {.stream = text.stream, .next = 1};
	for (int f = 0; f < count; ++f) {
		fprintf(text.stream, "o feather_%05d\n", f);
		for (pass.what = 0; pass.what < 3; ++pass.what)
			visit_curves(plume_coat_feather(coat, f), obj_visit, &pass, scratch.points, scratch.widths, scratch.uv);
	}
	scratch_free(&scratch);
	return plume_text_close(&text, PLUME_OK, err);
}

// ---------------------------------------------------------------------------
// USD

typedef struct usd_pass {
	FILE *stream;
	int what; ///< 0: counts, 1: points, 2: widths, 3: uv
	bool first;
	plume_vec3 origin; ///< subtracted from points: prototypes are relative to their follicle
} usd_pass;

static void usd_visit(void *context, int count, const plume_vec3 *points, const double *widths, const plume_vec2 *uv)
{
	usd_pass *pass = context;
	FILE *s = pass->stream;
	if (pass->what == 0) {
		fprintf(s, pass->first ? "%d" : ", %d", count);
		pass->first = false;
		return;
	}
	for (int i = 0; i < count; ++i) {
		if (!pass->first)
			fputs(", ", s);
		pass->first = false;
		if (pass->what == 1)
			fprintf(s, "(%.9g, %.9g, %.9g)", (float)(points[i].x - pass->origin.x),
			        (float)(points[i].y - pass->origin.y), (float)(points[i].z - pass->origin.z));
		else if (pass->what == 2)
			fprintf(s, "%.9g", (float)widths[i]);
		else
			fprintf(s, "(%.9g, %.9g)", (float)uv[i].x, (float)uv[i].y);
	}
}

/// sRGB to linear (USD's displayColor is linear), IEC 61966-2-1.
static double linear(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

/// A constant primvars:displayColor from an sRGB colour, at the given indentation.
static void usd_display_color(FILE *s, const char *indent, double r, double g, double b)
{
	fprintf(s, "%scolor3f[] primvars:displayColor = [(%.9g, %.9g, %.9g)] (\n%s    interpolation = \"constant\"\n%s)\n",
	        indent, (float)linear(r), (float)linear(g), (float)linear(b), indent, indent);
}

static void usd_surface(FILE *s, const plume_mesh *mesh)
{
	fputs("    def Mesh \"surface\"\n    {\n        int[] faceVertexCounts = [", s);
	for (int f = 0; f < mesh->face_count; ++f)
		fputs(f > 0 ? ", 3" : "3", s);
	fputs("]\n        int[] faceVertexIndices = [", s);
	for (int k = 0; k < 3 * mesh->face_count; ++k)
		fprintf(s, k > 0 ? ", %d" : "%d", mesh->faces[k]);
	fputs("]\n        point3f[] points = [", s);
	for (int v = 0; v < mesh->vertex_count; ++v)
		fprintf(s, "%s(%.9g, %.9g, %.9g)", v > 0 ? ", " : "", (float)mesh->rest[v].x, (float)mesh->rest[v].y,
		        (float)mesh->rest[v].z);
	fputs("]\n        uniform token subdivisionScheme = \"none\"\n", s);
	usd_display_color(s, "        ", 0.70, 0.62, 0.50); // the ray tracer's shell colour
	fputs("    }\n", s);
}

plume_status plume_coat_write_usda(const plume_coat *coat, const char *path, plume_error *err)
{
	shaft_scratch scratch;
	plume_text_file text;
	plume_status status = open_output(coat, path, &scratch, &text, err);
	if (status != PLUME_OK)
		return status;
	FILE *s = text.stream;
	int count = plume_coat_feather_count(coat);
	fprintf(s,
	        "#usda 1.0\n(\n    defaultPrim = \"coat\"\n    doc = \"\"\"plume %s: a feather coat, %d feathers as linear "
	        "curves in drawing order (bottom to top), placed by a PointInstancer at their follicles, and its "
	        "surface.\"\"\"\n    metersPerUnit = 1\n"
	        "    upAxis = \"Y\"\n)\n\ndef Xform \"coat\"\n{\n",
	        PLUME_VERSION_STRING, count);
	usd_surface(s, plume_coat_surface(coat));
	// UsdGeomPointInstancer: instance i is prototype i (every interpolated feather is its own shape)
	// translated to its follicle; the prototypes sit under the instancer, relative to the follicle.
	fputs("    def PointInstancer \"feathers\"\n    {\n        rel prototypes = [", s);
	for (int f = 0; f < count; ++f)
		fprintf(s, "%s</coat/feathers/prototypes/feather_%05d>", f > 0 ? ", " : "", f);
	fputs("]\n        int[] protoIndices = [", s);
	for (int f = 0; f < count; ++f)
		fprintf(s, f > 0 ? ", %d" : "%d", f);
	fputs("]\n        point3f[] positions = [", s);
	for (int f = 0; f < count; ++f) {
		plume_vec3 follicle, normal;
		plume_coat_follicle(coat, f, &follicle, &normal);
		fprintf(s, "%s(%.9g, %.9g, %.9g)", f > 0 ? ", " : "", (float)follicle.x, (float)follicle.y, (float)follicle.z);
	}
	fputs("]\n\n        def Scope \"prototypes\"\n        {\n", s);
	static const char *const heads[4] = {"        int[] curveVertexCounts = [", "        point3f[] points = [",
	                                     "        float[] widths = [", "        texCoord2f[] primvars:st = ["};
	for (int f = 0; f < count; ++f) {
		fprintf(s,
		        "            def BasisCurves \"feather_%05d\"\n            {\n                uniform token type = "
		        "\"linear\"\n"
		        "                uniform token wrap = \"nonperiodic\"\n",
		        f);
		usd_pass pass = {.stream = s};
		plume_vec3 normal;
		plume_coat_follicle(coat, f, &pass.origin, &normal);
		for (pass.what = 0; pass.what < 4; ++pass.what) {
			fprintf(s, "        %s", heads[pass.what]);
			pass.first = true;
			visit_curves(plume_coat_feather(coat, f), usd_visit, &pass, scratch.points, scratch.widths, scratch.uv);
			fputs(pass.what >= 2 ? "] (\n                    interpolation = \"vertex\"\n                )\n" : "]\n",
			      s);
		}
		usd_display_color(s, "                ", 0.45, 0.33, 0.22); // the ray tracer's barb colour
		fputs("            }\n", s);
	}
	fputs("        }\n    }\n}\n", s);
	scratch_free(&scratch);
	return plume_text_close(&text, PLUME_OK, err);
}

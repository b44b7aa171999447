// USD text (.usda) of an animated shell: one Mesh prim whose points are time
// samples, one per frame (UsdGeomPointBased "points", point3f[]), with the
// extent sampled alongside, texture coordinates as primvars:st, and
// primvars:displayColor per face (uniform) from the face's material. Time codes
// are seconds x 24 with timeCodesPerSecond = 24, so a player shows the frames at
// their simulated times. Points are frame k = first frame + displacement k in
// float, the same values the glTF file holds, printed with "%.9g" (exact for a
// float). A simulation with a body (plume_mesh_animation_set_body) has a second
// Mesh prim, "body", sampled the same way, as sim.glb has node "body". Written in
// the "C" numeric locale (export.h).
#define _POSIX_C_SOURCE 200809L
#include "export.h"

#include <math.h>

#include "animation.h"
#include "glb.h"

/// Time codes per second: USD's default, what Blender and usdview expect.
#define TIME_CODES_PER_SECOND 24.0

/// One Mesh prim `name` of the animation a: faces, points and extent sampled per frame,
/// texture coordinates and per-face colours and materials.
static void write_mesh_prim(FILE *s, const plume_mesh_animation *a, const char *name)
{
	const plume_mesh *mesh = a->mesh;
	int n = mesh->vertex_count;
	fprintf(s,
	        "def Mesh \"%s\"\n"
	        "{\n"
	        "    uniform bool doubleSided = 1\n"
	        "    uniform token subdivisionScheme = \"none\"\n",
	        name);
	fputs("    int[] faceVertexCounts = [", s);
	for (int f = 0; f < mesh->face_count; ++f)
		fputs(f > 0 ? ", 3" : "3", s);
	fputs("]\n", s);
	fputs("    int[] faceVertexIndices = [", s);
	for (int64_t i = 0; i < 3 * (int64_t)mesh->face_count; ++i)
		fprintf(s, "%s%d", i > 0 ? ", " : "", mesh->faces[i]);
	fputs("]\n", s);
	// Points and extent, one sample per frame.
	static const char *const attributes[2] = {"float3[] extent", "point3f[] points"};
	for (int which = 0; which < 2; ++which) {
		fprintf(s, "    %s.timeSamples = {\n", attributes[which]);
		for (int k = 0; k < a->frame_count; ++k) {
			const float *d = a->displacements + (size_t)k * 3 * (size_t)n;
			fprintf(s, "        %.9g: [", a->times[k] * TIME_CODES_PER_SECOND);
			float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
			for (int i = 0; i < n; ++i) {
				float p[3];
				for (int c = 0; c < 3; ++c) {
					p[c] = (float)a->first[3 * i + c] + d[3 * i + c];
					lo[c] = fminf(lo[c], p[c]);
					hi[c] = fmaxf(hi[c], p[c]);
				}
				if (which == 1)
					fprintf(s, "%s(%.9g, %.9g, %.9g)", i > 0 ? ", " : "", p[0], p[1], p[2]);
			}
			if (which == 0)
				fprintf(s, "(%.9g, %.9g, %.9g), (%.9g, %.9g, %.9g)", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
			fputs("],\n", s);
		}
		fputs("    }\n", s);
	}
	fputs("    texCoord2f[] primvars:st = [", s);
	for (int i = 0; i < n; ++i)
		fprintf(s, "%s(%.9g, %.9g)", i > 0 ? ", " : "", mesh->uv != NULL ? (float)mesh->uv[i].x : 0.0f,
		        mesh->uv != NULL ? (float)mesh->uv[i].y : 0.0f);
	fputs("] (\n        interpolation = \"vertex\"\n    )\n", s);
	// displayColor is linear in USD (like glTF's colours).
	fputs("    color3f[] primvars:displayColor = [", s);
	for (int f = 0; f < mesh->face_count; ++f) {
		int m = mesh->material != NULL ? mesh->material[f] : 0;
		plume_color c = m == PLUME_MATERIAL_RACHIS ? a->def.rachis_color : a->def.vane_color;
		fprintf(s, "%s(%.9g, %.9g, %.9g)", f > 0 ? ", " : "", (float)plume_glb_linear(c.r),
		        (float)plume_glb_linear(c.g), (float)plume_glb_linear(c.b));
	}
	fputs("] (\n        interpolation = \"uniform\"\n    )\n", s);
	fputs("    int[] primvars:material = [", s);
	for (int f = 0; f < mesh->face_count; ++f)
		fprintf(s, "%s%d", f > 0 ? ", " : "", mesh->material != NULL ? mesh->material[f] : 0);
	fputs("] (\n        interpolation = \"uniform\"\n    )\n", s);
	fputs("}\n", s);
}

plume_status plume_mesh_animation_write_usda(const plume_mesh_animation *a, const char *path, plume_error *err)
{
	if (a->frame_count == 0)
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: an animation needs at least one frame", path);
	if (a->body != NULL && a->body->frame_count == 0)
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: the body has no frame", path);
	const plume_mesh *mesh = a->mesh;
	plume_text_file text;
	plume_status status = plume_text_open(&text, path, err);
	if (status != PLUME_OK)
		return status;
	FILE *s = text.stream;
	double t0 = a->times[0] * TIME_CODES_PER_SECOND, t1 = a->times[a->frame_count - 1] * TIME_CODES_PER_SECOND;
	fprintf(s,
	        "#usda 1.0\n"
	        "(\n"
	        "    defaultPrim = \"shell\"\n"
	        "    doc = \"\"\"plume %s: a simulated shell, %d frames of %d vertices and %d triangles%s.\"\"\"\n"
	        "    metersPerUnit = 1\n"
	        "    upAxis = \"Y\"\n"
	        "    startTimeCode = %.9g\n"
	        "    endTimeCode = %.9g\n"
	        "    timeCodesPerSecond = %g\n"
	        "    framesPerSecond = %g\n"
	        ")\n\n",
	        PLUME_VERSION_STRING, a->frame_count, mesh->vertex_count, mesh->face_count,
	        a->body != NULL ? ", and the body it hangs on (prim \"body\")" : "", t0, t1, TIME_CODES_PER_SECOND,
	        TIME_CODES_PER_SECOND);
	write_mesh_prim(s, a, "shell");
	if (a->body != NULL) { // the same frames as the shell's, as sim.glb's node "body"
		fputs("\n", s);
		write_mesh_prim(s, a->body, "body");
	}
	return plume_text_close(&text, PLUME_OK, err);
}

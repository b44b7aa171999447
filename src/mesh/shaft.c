// Streit & Heidrich 4.3.1-4.3.2: the shaft as a generalized cylinder, a ring of
// vertices around every shaft sample, its cross-section tessellated as coarsely
// as a triangle (Figure 8, left) or as finely as the view needs.
#include <math.h>

#include "plume/mesh.h"
#include "plume/streit_heidrich.h"

#define TWO_PI 6.283185307179586

plume_status plume_sh_shaft_mesh(const plume_feather *feather, int sides, plume_mesh **out, plume_error *err)
{
	*out = NULL;
	if (sides < 3 || sides > 256)
		return plume_error_set(err, PLUME_ERROR_SPEC, "shaft mesh: %d sides, allowed [3, 256]", sides);
	plume_feather_info info = plume_feather_get_info(feather);
	int rings = info.shaft_sample_count;
	if (rings < 2)
		return plume_error_set(err, PLUME_ERROR_SPEC, "shaft mesh: the feather has no shaft");
	plume_mesh *mesh = plume_mesh_create(rings * sides, 2 * (rings - 1) * sides);
	if (mesh == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "shaft mesh: out of memory");
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	for (int r = 0; r < rings; ++r) {
		// The ring lies in the plane of the sample's normal and binormal, its radius half the width: the
		// calamus's last ring and the rachis's first are the same sample, so the two meet without a step.
		double radius = 0.5 * shaft[r].width;
		for (int k = 0; k < sides; ++k) {
			double angle = TWO_PI * k / sides;
			plume_vec3 offset = plume_v3_add(plume_v3_scale(shaft[r].normal, radius * cos(angle)),
			                                 plume_v3_scale(shaft[r].binormal, radius * sin(angle)));
			int v = r * sides + k;
			mesh->rest[v] = plume_v3_add(shaft[r].position, offset);
			mesh->reference[v] = (plume_vec2){mesh->rest[v].x, mesh->rest[v].y};
			mesh->uv[v] = (plume_vec2){(double)k / sides, shaft[r].t};
		}
	}
	int f = 0;
	for (int r = 0; r + 1 < rings; ++r)
		for (int k = 0; k < sides; ++k) {
			int a = r * sides + k, b = r * sides + (k + 1) % sides;
			int c = a + sides, d = b + sides;
			int *t = mesh->faces + 3 * f;
			t[0] = a, t[1] = b, t[2] = d;
			t[3] = a, t[4] = d, t[5] = c;
			mesh->material[f] = mesh->material[f + 1] = PLUME_MATERIAL_RACHIS;
			f += 2;
		}
	*out = mesh;
	return PLUME_OK;
}

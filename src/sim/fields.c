// Per-face fields for output (plume_sim_face_fields): the same kinematics and
// material tensors the energies use (membrane.c), evaluated once at the current
// positions, and the bending energy of each hinge shared half and half by its
// two faces (of each fundamental-form element: its face's).
#include <stdlib.h>
#include <string.h>

#include "../core/alloc.h"
#include "../core/asserts.h"
#include "sim/sim_internal.h"

/// A face found by its sorted vertex triple.
typedef struct face_key {
	int v[3];
	int face;
} face_key;

static int compare_key(const void *a, const void *b)
{
	const face_key *x = a, *y = b;
	for (int k = 0; k < 3; ++k)
		if (x->v[k] != y->v[k])
			return x->v[k] < y->v[k] ? -1 : 1;
	return 0;
}

static void sort3(int v[3])
{
	for (int i = 0; i < 2; ++i)
		for (int j = 0; j < 2 - i; ++j)
			if (v[j] > v[j + 1]) {
				int t = v[j];
				v[j] = v[j + 1];
				v[j + 1] = t;
			}
}

static int find_face(const face_key *keys, int count, int a, int b, int c)
{
	face_key key = {{a, b, c}, -1};
	sort3(key.v);
	const face_key *found = bsearch(&key, keys, (size_t)count, sizeof *keys, compare_key);
	return found != NULL ? found->face : -1;
}

plume_status plume_sim_face_fields(const plume_sim *sim, plume_sim_face_field *out, plume_error *err)
{
	PLUME_ASSERT_HANDLE(sim);
	PLUME_ASSERT(out != NULL);
	int faces = sim->face_count;
	for (int f = 0; f < faces; ++f) {
		const plume_membrane_element *element = sim->membranes + f;
		plume_vec3 local[3] = {sim->x[element->vertices[0]], sim->x[element->vertices[1]],
		                       sim->x[element->vertices[2]]};
		plume_green_strain strain;
		plume_green_strain_eval(element, local, &strain);
		const plume_material *material = sim->def.materials + sim->face_material[f];
		// element->stiffness is thickness * C in Voigt form acting on (E_xx, E_yy, 2 E_xy).
		double S[3] = {0, 0, 0};
		for (int i = 0; i < 3; ++i)
			for (int j = 0; j < 3; ++j)
				S[i] += element->stiffness[3 * i + j] * strain.strain[j] / material->thickness;
		plume_sim_face_field *o = out + f;
		o->strain[0] = strain.strain[0];
		o->strain[1] = strain.strain[1];
		o->strain[2] = 0.5 * strain.strain[2];
		memcpy(o->stress, S, sizeof S);
		o->membrane_energy_density = plume_membrane_energy(element, local, NULL, NULL) / element->area;
		o->compression_energy_density =
		    element->compression > 0 ? plume_compression_energy(element, local, NULL, NULL) / element->area : 0.0;
		o->bending_energy_density = 0.0;
	}
	if (!sim->def.bending || plume_sim_bending_count(sim) == 0)
		return PLUME_OK;
	face_key *keys = plume_alloc((size_t)(faces > 0 ? faces : 1) * sizeof *keys);
	if (keys == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "face fields: out of memory");
	for (int f = 0; f < faces; ++f) {
		memcpy(keys[f].v, sim->faces + 3 * f, sizeof keys[f].v);
		sort3(keys[f].v);
		keys[f].face = f;
	}
	qsort(keys, (size_t)faces, sizeof *keys, compare_key);
	// A hinge's energy goes half and half to its faces; a fundamental-form element's to its face.
	bool hinges = sim->def.bending_model == PLUME_BENDING_PAPER_HINGE;
	for (int e = 0; e < plume_sim_bending_count(sim); ++e) {
		double energy = plume_sim_bending_energy(sim, sim->x, e);
		const int *v = plume_sim_bending_vertices(sim, e);
		int sides[2] = {find_face(keys, faces, v[0], v[1], v[2]),
		                hinges ? find_face(keys, faces, v[0], v[1], v[3]) : -1};
		for (int k = 0; k < 2; ++k)
			if (sides[k] >= 0)
				out[sides[k]].bending_energy_density += (hinges ? 0.5 : 1.0) * energy / sim->membranes[sides[k]].area;
	}
	plume_free(keys);
	return PLUME_OK;
}

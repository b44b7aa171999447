// plume_sim_face_fields against closed forms: a flat isotropic sheet whose
// start shape is its reference stretched by (lx, ly), sheared for the off-
// diagonal term, has F, hence the Green strain, the St-Venant-Kirchhoff stress
// and the energy density, known exactly; a flat sheet bends nothing.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <string.h>

#include "support.h"

/// Two triangles over the unit square (reference), start shape x = A X.
static plume_mesh *square(const double A[4])
{
	plume_mesh *mesh = plume_mesh_create(4, 2);
	assert_non_null(mesh);
	static const plume_vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
	static const int faces[6] = {0, 1, 2, 0, 2, 3};
	for (int i = 0; i < 4; ++i) {
		plume_vec2 X = corners[i];
		mesh->reference[i] = X;
		mesh->rest[i] = plume_v3(A[0] * X.x + A[1] * X.y, A[2] * X.x + A[3] * X.y, 0.0);
	}
	memcpy(mesh->faces, faces, sizeof faces);
	for (int f = 0; f < 2; ++f) {
		mesh->material[f] = 0;
		mesh->barb_angle[f] = 0.0;
		mesh->barb_edge[f] = -1;
	}
	return mesh;
}

static void test_stretched_sheet(void **state)
{
	(void)state;
	const double A[4] = {1.1, 0.05, 0.0, 0.95}; // x = A X: stretch and shear
	plume_mesh *mesh = square(A);
	plume_sim_def def = plume_sim_default_def();
	def.materials[0] = plume_material_rachis(); // isotropic: E, nu
	def.material_count = 1;
	def.gravity = plume_v3(0, 0, 0);
	plume_sim *sim = NULL;
	plume_error err;
	if (plume_sim_create(mesh, &def, &sim, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	plume_sim_face_field fields[2];
	assert_int_equal(plume_sim_face_fields(sim, fields, &err), PLUME_OK);
	// E = (A^T A - I) / 2.
	double Exx = 0.5 * (A[0] * A[0] + A[2] * A[2] - 1), Eyy = 0.5 * (A[1] * A[1] + A[3] * A[3] - 1);
	double Exy = 0.5 * (A[0] * A[1] + A[2] * A[3]);
	double E = def.materials[0].youngs_modulus, nu = def.materials[0].poisson_ratio, t = def.materials[0].thickness;
	double k = E / (1 - nu * nu);
	double Sxx = k * (Exx + nu * Eyy), Syy = k * (Eyy + nu * Exx), Sxy = k * (1 - nu) * Exy;
	for (int f = 0; f < 2; ++f) {
		assert_close(fields[f].strain[0], Exx, 1e-14);
		assert_close(fields[f].strain[1], Eyy, 1e-14);
		assert_close(fields[f].strain[2], Exy, 1e-14);
		assert_close(fields[f].stress[0], Sxx, 1e-9 * k);
		assert_close(fields[f].stress[1], Syy, 1e-9 * k);
		assert_close(fields[f].stress[2], Sxy, 1e-9 * k);
		// psi per reference area = t (E : S) / 2.
		assert_close(fields[f].membrane_energy_density, 0.5 * t * (Exx * Sxx + Eyy * Syy + 2 * Exy * Sxy),
		             1e-9 * k * t);
		assert_close(fields[f].bending_energy_density, 0.0, 0.0);
	}
	// The densities times the areas add up to the simulator's energy.
	plume_sim_energies energies = plume_sim_energy(sim);
	assert_close(0.5 * (fields[0].membrane_energy_density + fields[1].membrane_energy_density), energies.membrane,
	             1e-12 * fabs(energies.membrane));
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_stretched_sheet),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

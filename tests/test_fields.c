// plume_sim_face_fields against closed forms: a flat isotropic sheet whose
// start shape is its reference stretched by (lx, ly), sheared for the off-
// diagonal term, has F, hence the Green strain, the St-Venant-Kirchhoff stress
// and the energy density, known exactly; a flat sheet bends nothing.
// plume_sim_vane_shape_measure: a sheet stretched by (1.1, 0.9), or simply sheared
// by s (smallest stretch sqrt(1 + s^2/4) - s/2), then rotated in space, has those
// principal stretches; a rigidly moved sheet leaves its plane by nothing, and one
// vertex lifted by d off the moved plane by exactly d.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <string.h>

#include "sim/sim_internal.h"
#include "support.h"

/// Two triangles over the unit square, flat at rest.
static plume_mesh *square(void)
{
	plume_mesh *mesh = plume_mesh_create(4, 2);
	assert_non_null(mesh);
	static const plume_vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
	static const int faces[6] = {0, 1, 2, 0, 2, 3};
	for (int i = 0; i < 4; ++i) {
		plume_vec2 X = corners[i];
		mesh->reference[i] = X;
		mesh->rest[i] = plume_v3(X.x, X.y, 0.0);
	}
	memcpy(mesh->faces, faces, sizeof faces);
	for (int f = 0; f < 2; ++f) {
		mesh->material[f] = 0;
		mesh->barb_angle[f] = 0.0;
		mesh->barb_edge[f] = -1;
	}
	return mesh;
}

/// Moves the square's simulation to its start shape x = Q (A X, 0).
static void start_shape(plume_sim *sim, const plume_mesh *mesh, const double A[4], plume_mat3 Q)
{
	for (int i = 0; i < 4; ++i) {
		plume_vec2 X = mesh->reference[i];
		sim->x[i] = plume_m3_apply(Q, plume_v3(A[0] * X.x + A[1] * X.y, A[2] * X.x + A[3] * X.y, 0.0));
	}
}

static void test_stretched_sheet(void **state)
{
	(void)state;
	const double A[4] = {1.1, 0.05, 0.0, 0.95}; // x = A X: stretch and shear
	plume_mesh *mesh = square();
	plume_sim_def def = plume_sim_default_def();
	def.materials[0] = plume_material_rachis(); // isotropic: E, nu
	def.material_count = 1;
	def.gravity = plume_v3(0, 0, 0);
	plume_sim *sim = NULL;
	plume_error err;
	if (plume_sim_create(mesh, &def, &sim, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	start_shape(sim, mesh, A, plume_m3_identity());
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

/// x = Q (A X, 0) for the square's reference X, Q a rotation about a skew axis.
static plume_sim *rotated_square(const double A[4], plume_mesh **mesh)
{
	*mesh = square();
	static const int base[3] = {0, 1, 3};
	plume_error err;
	assert_int_equal(plume_mesh_add_group(*mesh, "base", base, 3, &err), PLUME_OK);
	assert_int_equal(plume_mesh_add_group(*mesh, "edge", base, 2, &err), PLUME_OK);
	plume_sim_def def = plume_sim_default_def();
	def.gravity = plume_v3(0, 0, 0);
	plume_sim *sim = NULL;
	if (plume_sim_create(*mesh, &def, &sim, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	start_shape(sim, *mesh, A, plume_m3_rotation(plume_v3_normalize(plume_v3(1, 2, 3)), 0.7));
	return sim;
}

static void test_principal_stretch(void **state)
{
	(void)state;
	const double stretched[4] = {1.1, 0, 0, 0.9}, s = 0.3, sheared[4] = {1, s, 0, 1};
	const double *shapes[2] = {stretched, sheared};
	const double expected[2] = {0.9, sqrt(1 + s * s / 4) - s / 2};
	for (int k = 0; k < 2; ++k) {
		plume_mesh *mesh;
		plume_sim *sim = rotated_square(shapes[k], &mesh);
		plume_sim_vane_shape shape = plume_sim_vane_shape_measure(sim, "base");
		assert_close(shape.min_principal_stretch, expected[k], 1e-14);
		// The start shape is planar: nothing has left the plane.
		assert_close(shape.max_out_of_plane, 0.0, 1e-15);
		plume_sim_destroy(sim);
		plume_mesh_destroy(mesh);
	}
}

static void test_out_of_plane(void **state)
{
	(void)state;
	const double identity[4] = {1, 0, 0, 1};
	plume_mesh *mesh;
	plume_sim *sim = rotated_square(identity, &mesh);
	// A rigid motion of the whole sheet.
	plume_mat3 R = plume_m3_rotation(plume_v3_normalize(plume_v3(-2, 1, 0.5)), 1.9);
	plume_vec3 t = plume_v3(0.3, -0.2, 0.1);
	for (int i = 0; i < 4; ++i)
		sim->x[i] = plume_v3_add(plume_m3_apply(R, mesh->rest[i]), t);
	plume_sim_vane_shape shape = plume_sim_vane_shape_measure(sim, "base");
	assert_close(shape.min_principal_stretch, 1.0, 1e-14);
	assert_close(shape.max_out_of_plane, 0.0, 1e-14);
	// Vertex 2 (not in the base) lifted by d along the moved normal.
	plume_vec3 normal =
	    plume_v3_normalize(plume_v3_cross(plume_v3_sub(sim->x[1], sim->x[0]), plume_v3_sub(sim->x[3], sim->x[0])));
	const double d = 0.01;
	sim->x[2] = plume_v3_add(sim->x[2], plume_v3_scale(normal, d));
	shape = plume_sim_vane_shape_measure(sim, "base");
	assert_close(shape.max_out_of_plane, d, 1e-14);
	// A lift adds grad(w) grad(w)^T to C = I: the smallest stretch stays 1.
	assert_close(shape.min_principal_stretch, 1.0, 1e-14);
	// No frame: an unknown group, or two points.
	assert_true(isnan(plume_sim_vane_shape_measure(sim, "nowhere").max_out_of_plane));
	assert_true(isnan(plume_sim_vane_shape_measure(sim, "edge").max_out_of_plane));
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_stretched_sheet),
	    cmocka_unit_test(test_principal_stretch),
	    cmocka_unit_test(test_out_of_plane),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

// Bending on any triangulation (issue 13): cantilever strips against Euler-Bernoulli and
// rolled strips against (1/2) D A / R^2 on four triangulation families (plume_lab_strip_mesh),
// for the fundamental-form model; the paper's hinge is measured against the same strips
// to show what the new model fixes.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "plume/lab.h"
#include "sim/sim_internal.h"
#include "support.h"

static const double PI = 3.14159265358979323846;

enum { LEVELS = 3 };
static const int levels[LEVELS] = {2, 4, 8};

/// delta / delta_EB on one family at the three levels.
static void cantilever_levels(plume_strip_family family, plume_bending_model model, double along, double across,
                              double barb_angle, double ratio[LEVELS])
{
	for (int l = 0; l < LEVELS; ++l) {
		plume_cantilever_def def = plume_cantilever_default_def();
		def.family = family;
		def.model = model;
		def.across = levels[l];
		def.bending_along = along;
		def.bending_across = across;
		def.barb_angle = barb_angle;
		plume_error err;
		assert_int_equal(plume_lab_cantilever(&def, ratio + l, &err), PLUME_OK);
	}
}

// Measured (isotropic, delta/delta_EB - 1 at 4, 8, 16 cells across a 10:1 strip):
// right-isosceles +1.3e-3, +3.1e-4, +7.8e-5 and elongated +2.0e-2, +5.0e-3, +1.3e-3 (rate 2);
// equilateral -1.6e-2, -8.6e-3, -4.4e-3 and slanted -1.4e-2, -9.0e-3, -5.4e-3 (rate 1: the
// clamp line cuts their shifted rows, whose nearest vertex is moved onto it).
static void assert_converges(const char *what, const double ratio[LEVELS], double finest, double rate)
{
	double e[LEVELS];
	for (int l = 0; l < LEVELS; ++l)
		e[l] = fabs(ratio[l] - 1);
	print_message("%-40s delta/delta_EB %.5f %.5f %.5f  rates %.2f %.2f\n", what, ratio[0], ratio[1], ratio[2],
	              log2(e[0] / e[1]), log2(e[1] / e[2]));
	assert_true(e[LEVELS - 1] < finest);
	for (int l = 0; l + 1 < LEVELS; ++l)
		assert_true(log2(e[l] / e[l + 1]) > rate);
}

static void test_cantilever_isotropic(void **state)
{
	(void)state;
	// Asserted rates: the measured ones less a margin.
	const double rates[PLUME_STRIP_FAMILY_COUNT] = {1.8, 0.8, 1.8, 0.6};
	for (int family = 0; family < PLUME_STRIP_FAMILY_COUNT; ++family) {
		double ratio[LEVELS];
		cantilever_levels((plume_strip_family)family, PLUME_BENDING_FUNDAMENTAL_FORM, 1e-3, 1e-3, 0, ratio);
		char what[64];
		snprintf(what, sizeof what, "isotropic, %s", plume_strip_family_name((plume_strip_family)family));
		assert_converges(what, ratio, 0.03, rates[family]);
	}
}

static void test_cantilever_anisotropic(void **state)
{
	(void)state;
	// The vane's moduli (thesis Table 6.1): barbs along the strip bend with D_across, barbs
	// across it fold with D_along, 2500 times softer. Along: every family as isotropic.
	// Across, on meshes with edges along the barbs (right-isosceles, elongated): as
	// isotropic. Across on meshes without (equilateral, slanted) the stiff modulus sees the
	// discretisation error of the cross curvature 2500-fold: measured 0.52, 0.73, 0.86 on
	// equilateral at 4, 8, 16 across, converging at rate ~0.9 (docs/physics-energies.md).
	const double rates[PLUME_STRIP_FAMILY_COUNT] = {1.8, 0.8, 1.8, 0.6};
	for (int family = 0; family < PLUME_STRIP_FAMILY_COUNT; ++family)
		for (int barbs = 0; barbs < 2; ++barbs) {
			bool aligned = family == PLUME_STRIP_RIGHT || family == PLUME_STRIP_ELONGATED;
			double ratio[LEVELS];
			cantilever_levels((plume_strip_family)family, PLUME_BENDING_FUNDAMENTAL_FORM, 1e-7, 2.5e-4,
			                  barbs == 0 ? 0 : PI / 2, ratio);
			char what[64];
			snprintf(what, sizeof what, "barbs %s, %s", barbs == 0 ? "along" : "across",
			         plume_strip_family_name((plume_strip_family)family));
			if (barbs == 0 || aligned)
				assert_converges(what, ratio, 0.03, rates[family]);
			else
				assert_converges(what, ratio, 0.6, 0.3);
		}
}

static void test_cantilever_paper_hinge_is_mesh_dependent(void **state)
{
	(void)state;
	// What the new model fixes: the hinge is 25 % too soft on right-isosceles triangles and
	// does not converge (issue 13 measured 1.309 ... 1.249 on its strips).
	double ratio[LEVELS];
	cantilever_levels(PLUME_STRIP_RIGHT, PLUME_BENDING_PAPER_HINGE, 1e-3, 1e-3, 0, ratio);
	print_message("paper hinge, right-isosceles: %.5f %.5f %.5f\n", ratio[0], ratio[1], ratio[2]);
	assert_true(ratio[2] > 1.2);
}

/// Bending energy of a strip rolled into a cylinder of radius R about the y axis (axis 0)
/// or the x axis (axis 1), over (1/2) D A / R^2: of the whole strip, and of its interior
/// faces (no edge on the boundary; fundamental-form model only).
static double rolled_ratio(plume_strip_family family, int across, int axis, plume_bending_model model, double *interior)
{
	const double length = 0.06, width = 0.03, R = 0.05, D = 2.5e-4;
	plume_mesh *mesh;
	plume_error err;
	assert_int_equal(plume_lab_strip_mesh(family, length, width, 1, across, 0, &mesh, &err), PLUME_OK);
	plume_sim_def def = plume_sim_default_def();
	def.materials[0] = plume_material_rachis();
	def.materials[0].bending_along = def.materials[0].bending_across = D;
	def.material_count = 1;
	def.bending_model = model;
	plume_sim *sim;
	assert_int_equal(plume_sim_create(mesh, &def, &sim, &err), PLUME_OK);
	for (int i = 0; i < mesh->vertex_count; ++i) {
		double u = axis == 0 ? mesh->reference[i].x : mesh->reference[i].y;
		double v = axis == 0 ? mesh->reference[i].y : mesh->reference[i].x;
		plume_vec3 p = plume_v3(R * sin(u / R), v, R * (1 - cos(u / R)));
		sim->x[i] = axis == 0 ? p : plume_v3(p.y, p.x, p.z);
	}
	double area = 0, inner_area = 0, inner_energy = 0;
	for (int f = 0; f < mesh->face_count; ++f)
		area += sim->membranes[f].area;
	if (interior != NULL) {
		assert_int_equal(sim->ff_count, mesh->face_count);
		for (int f = 0; f < sim->ff_count; ++f) {
			const int *v = sim->ff_faces[f].vertices;
			if (v[3] < 0 || v[4] < 0 || v[5] < 0)
				continue;
			inner_area += sim->membranes[f].area;
			inner_energy += plume_sim_bending_energy(sim, sim->x, f);
		}
		*interior = inner_energy / (0.5 * D * inner_area / (R * R));
	}
	double ratio = plume_sim_energy(sim).bending / (0.5 * D * area / (R * R));
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
	return ratio;
}

static void test_rolled_cylinder(void **state)
{
	(void)state;
	// Interior faces store (1/2) D A / R^2 on every family (measured within 1e-3). The faces
	// with an edge on the free boundary across the curvature have no angle there (the edge's
	// normal is free, as with a director): the whole strip's deficit is that row, O(h), as
	// for the paper's hinge (measured: the same 0.889, 0.941 on right-isosceles).
	for (int family = 0; family < PLUME_STRIP_FAMILY_COUNT; ++family)
		for (int axis = 0; axis < 2; ++axis) {
			double inner_coarse, inner_fine;
			double coarse =
			    rolled_ratio((plume_strip_family)family, 8, axis, PLUME_BENDING_FUNDAMENTAL_FORM, &inner_coarse);
			double fine =
			    rolled_ratio((plume_strip_family)family, 16, axis, PLUME_BENDING_FUNDAMENTAL_FORM, &inner_fine);
			double hinge = rolled_ratio((plume_strip_family)family, 16, axis, PLUME_BENDING_PAPER_HINGE, NULL);
			print_message("cylinder, %-16s axis %d: energy / ((1/2) D A / R^2): interior faces %.5f, %.5f; "
			              "whole strip %.5f, %.5f (8, 16 across); paper hinge %.5f\n",
			              plume_strip_family_name((plume_strip_family)family), axis, inner_coarse, inner_fine, coarse,
			              fine, hinge);
			assert_true(fabs(inner_fine - 1) < 0.02);
			assert_true(fine > coarse && fine <= 1 + 1e-9);
		}
}

/// A strip too long for its cells is refused before its counts are cast to int (a 1e12 m strip
/// of 1 mm cells was undefined behaviour); NaN sizes and barb angles are refused too.
static void test_strip_bounds(void **state)
{
	(void)state;
	plume_mesh *mesh = NULL;
	plume_error err;
	assert_int_equal(plume_lab_strip_mesh(PLUME_STRIP_RIGHT, 1e12, 0.01, 1, 10, 0, &mesh, &err), PLUME_ERROR_SPEC);
	assert_null(mesh);
	assert_non_null(strstr(err.message, "allowed at most 1e+08"));
	assert_int_equal(plume_lab_strip_mesh(PLUME_STRIP_RIGHT, NAN, 0.01, 1, 10, 0, &mesh, &err), PLUME_ERROR_SPEC);
	assert_int_equal(plume_lab_strip_mesh(PLUME_STRIP_RIGHT, 0.1, 0.01, 1, 10, NAN, &mesh, &err), PLUME_ERROR_SPEC);
	assert_int_equal(plume_lab_strip_mesh(PLUME_STRIP_RIGHT, 0.1, 0.01, 1, 10, 0, &mesh, &err), PLUME_OK);
	plume_mesh_destroy(mesh);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_cantilever_isotropic),
	    cmocka_unit_test(test_cantilever_anisotropic),
	    cmocka_unit_test(test_cantilever_paper_hinge_is_mesh_dependent),
	    cmocka_unit_test(test_rolled_cylinder),
	    cmocka_unit_test(test_strip_bounds),
	};
	int64_t before = plume_bytes_in_use();
	int failed = cmocka_run_group_tests(tests, NULL, NULL);
	if (plume_bytes_in_use() != before) {
		fprintf(stderr, "test_bending: %lld bytes leaked\n", (long long)(plume_bytes_in_use() - before));
		return 1;
	}
	return failed;
}

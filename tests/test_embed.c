// Barb embedding: the rest shell rebuilds the rest feather (round trip to 1e-9 m), a rigidly moved shell
// moves every barb rigidly, a bent shell carries barbs with it, and bad shells are refused.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/feather_internal.h"
#include "plume/embed.h"
#include "plume/raytrace.h"
#include "support.h"

static plume_feather *small_feather(void)
{
	plume_fw_def def = plume_fw_default_def();
	def.segments[0].barb_count = 10;
	def.segments[1].barb_count = 60;
	plume_feather *feather = NULL;
	plume_error err = {0};
	assert_int_equal(plume_fw_generate(&def, 3, &feather, &err), PLUME_OK);
	return feather;
}

static plume_mesh *mesh_of(const plume_feather *feather)
{
	plume_mesh_def def = plume_mesh_default_def();
	plume_mesh *mesh = NULL;
	plume_error err = {0};
	if (plume_mesh_from_feather(feather, &def, &mesh, NULL, &err) != PLUME_OK)
		fail_msg("mesher: %s", err.message);
	return mesh;
}

/// Largest distance between corresponding points (shaft and pool) of two feathers with the same layout,
/// and largest difference of their normals.
static void compare(const plume_feather *a, const plume_feather *b, double *point_error, double *normal_error)
{
	*point_error = *normal_error = 0.0;
	assert_int_equal(a->shaft_count, b->shaft_count);
	assert_int_equal(a->point_count, b->point_count);
	for (int i = 0; i < a->shaft_count; ++i) {
		*point_error = fmax(*point_error, plume_v3_distance(a->shaft[i].position, b->shaft[i].position));
		*normal_error = fmax(*normal_error, plume_v3_distance(a->shaft[i].tangent, b->shaft[i].tangent));
		*normal_error = fmax(*normal_error, plume_v3_distance(a->shaft[i].normal, b->shaft[i].normal));
		*normal_error = fmax(*normal_error, plume_v3_distance(a->shaft[i].binormal, b->shaft[i].binormal));
	}
	for (int i = 0; i < a->point_count; ++i) {
		*point_error = fmax(*point_error, plume_v3_distance(a->points[i], b->points[i]));
		*normal_error = fmax(*normal_error, plume_v3_distance(a->normals[i], b->normals[i]));
	}
}

static void test_round_trip(void **state)
{
	(void)state;
	int64_t bytes_before = plume_bytes_in_use();
	plume_feather *feather = small_feather();
	plume_mesh *mesh = mesh_of(feather);
	plume_barb_embedding *embedding = NULL;
	plume_error err = {0};
	assert_int_equal(plume_embedding_create(feather, mesh, &embedding, &err), PLUME_OK);
	plume_feather_info info = plume_feather_get_info(feather);
	assert_int_equal(plume_embedding_point_count(embedding), info.shaft_sample_count + info.point_count);
	plume_feather *rebuilt = NULL;
	assert_int_equal(plume_embedding_apply(embedding, mesh->rest, &rebuilt, &err), PLUME_OK);
	double point_error, normal_error;
	compare(feather, rebuilt, &point_error, &normal_error);
	print_message("round trip: points %.3g m, directions %.3g; max offset from the shell %.3g m\n", point_error,
	              normal_error, plume_embedding_max_offset(embedding));
	assert_true(point_error <= 1e-9);
	assert_true(normal_error <= 1e-9);
	// Widths and texture coordinates are the feather's own; arc lengths are measured again.
	for (int i = 0; i < info.point_count; ++i) {
		assert_true(rebuilt->widths[i] == feather->widths[i]);
		assert_true(rebuilt->uv[i].x == feather->uv[i].x && rebuilt->uv[i].y == feather->uv[i].y);
		assert_close(rebuilt->arc_length[i], feather->arc_length[i], 1e-9);
	}
	plume_feather_destroy(rebuilt);
	plume_embedding_destroy(embedding);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), bytes_before);
}

static void test_rigid_motion(void **state)
{
	(void)state;
	plume_feather *feather = small_feather();
	plume_mesh *mesh = mesh_of(feather);
	plume_barb_embedding *embedding = NULL;
	plume_error err = {0};
	assert_int_equal(plume_embedding_create(feather, mesh, &embedding, &err), PLUME_OK);
	plume_mat3 rotation = plume_m3_rotation(plume_v3_normalize(plume_v3(0.3, -1.0, 0.5)), 1.1);
	plume_vec3 shift = {0.5, -0.25, 2.0};
	plume_vec3 *positions = malloc((size_t)mesh->vertex_count * sizeof *positions);
	for (int i = 0; i < mesh->vertex_count; ++i)
		positions[i] = plume_v3_add(plume_m3_apply(rotation, mesh->rest[i]), shift);
	plume_feather *moved = NULL;
	assert_int_equal(plume_embedding_apply(embedding, positions, &moved, &err), PLUME_OK);
	// The expected feather: every point and direction moved by the same rigid motion.
	plume_feather *expected = plume_feather_clone(feather);
	for (int i = 0; i < expected->shaft_count; ++i) {
		plume_shaft_sample *s = expected->shaft + i;
		s->position = plume_v3_add(plume_m3_apply(rotation, s->position), shift);
		s->tangent = plume_m3_apply(rotation, s->tangent);
		s->normal = plume_m3_apply(rotation, s->normal);
		s->binormal = plume_m3_apply(rotation, s->binormal);
	}
	for (int i = 0; i < expected->point_count; ++i) {
		expected->points[i] = plume_v3_add(plume_m3_apply(rotation, expected->points[i]), shift);
		expected->normals[i] = plume_m3_apply(rotation, expected->normals[i]);
	}
	double point_error, normal_error;
	compare(expected, moved, &point_error, &normal_error);
	print_message("rigid motion: points %.3g m, directions %.3g\n", point_error, normal_error);
	assert_true(point_error <= 1e-9);
	assert_true(normal_error <= 1e-9);
	// Lengths are invariant under a rigid motion.
	for (int i = 0; i < moved->point_count; ++i)
		assert_close(moved->arc_length[i], feather->arc_length[i], 1e-9);
	plume_feather_destroy(expected);
	plume_feather_destroy(moved);
	free(positions);
	plume_embedding_destroy(embedding);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
}

/// A shell bent about the x axis (z = -k y^2 / 2 for a flat one): the barbs follow it, each point staying
/// within the piecewise-linear shell's own error of the bent surface.
static void test_bent_shell_carries_barbs(void **state)
{
	(void)state;
	plume_feather *feather = small_feather();
	plume_mesh *mesh = mesh_of(feather);
	plume_barb_embedding *embedding = NULL;
	plume_error err = {0};
	assert_int_equal(plume_embedding_create(feather, mesh, &embedding, &err), PLUME_OK);
	const double k = 5.0; // 1/m
	plume_vec3 *positions = malloc((size_t)mesh->vertex_count * sizeof *positions);
	for (int i = 0; i < mesh->vertex_count; ++i) {
		plume_vec3 r = mesh->rest[i];
		positions[i] = plume_v3(r.x, r.y, r.z - 0.5 * k * r.y * r.y);
	}
	plume_feather *moved = NULL;
	assert_int_equal(plume_embedding_apply(embedding, positions, &moved, &err), PLUME_OK);
	double worst = 0.0;
	for (int i = 0; i < moved->point_count; ++i) {
		plume_vec3 rest = feather->points[i], p = moved->points[i];
		double expected_z = rest.z - 0.5 * k * rest.y * rest.y;
		worst = fmax(worst, fabs(p.z - expected_z));
	}
	// A point interpolated (or, beyond the shell's border, extrapolated) linearly over a triangle of the
	// parabola z = -k y^2 / 2 misses it by at most k (E + O)^2 / 2, E the longest edge and O the
	// farthest a point sits from its triangle.
	double longest = 0.0;
	for (int f = 0; f < mesh->face_count; ++f)
		for (int e = 0; e < 3; ++e)
			longest = fmax(longest, plume_v3_distance(mesh->rest[mesh->faces[3 * f + e]],
			                                          mesh->rest[mesh->faces[3 * f + (e + 1) % 3]]));
	double reach = longest + plume_embedding_max_offset(embedding);
	double bound = 0.5 * k * reach * reach;
	print_message("bent shell: largest deviation from the bent surface %.3g m (bound %.3g m)\n", worst, bound);
	assert_true(worst <= bound);
	assert_true(worst > 0.0);
	plume_feather_destroy(moved);
	free(positions);
	plume_embedding_destroy(embedding);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
}

static void test_bad_shells(void **state)
{
	(void)state;
	int64_t bytes_before = plume_bytes_in_use();
	plume_feather *feather = small_feather();
	plume_mesh *empty = plume_mesh_create(3, 0);
	plume_barb_embedding *embedding = NULL;
	plume_error err = {0};
	assert_int_equal(plume_embedding_create(feather, empty, &embedding, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "no faces"));
	assert_null(embedding);
	plume_mesh_destroy(empty);

	plume_mesh *flat = plume_mesh_create(3, 1); // all three vertices at the origin
	flat->faces[0] = 0, flat->faces[1] = 1, flat->faces[2] = 2;
	assert_int_equal(plume_embedding_create(feather, flat, &embedding, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "degenerate"));
	plume_mesh_destroy(flat);

	plume_mesh *mesh = mesh_of(feather);
	assert_int_equal(plume_embedding_create(feather, mesh, &embedding, &err), PLUME_OK);
	plume_vec3 *positions = malloc((size_t)mesh->vertex_count * sizeof *positions);
	memcpy(positions, mesh->rest, (size_t)mesh->vertex_count * sizeof *positions);
	positions[mesh->vertex_count / 2].y = NAN;
	plume_feather *moved = NULL;
	assert_int_equal(plume_embedding_apply(embedding, positions, &moved, &err), PLUME_ERROR_NUMERIC);
	assert_null(moved);
	free(positions);
	plume_embedding_destroy(embedding);
	embedding = NULL;

	// Issue 17: a barb point Embree's float query cannot place (NaN, or a
	// feather.json coordinate of 1e308) is on no face; it read frames[-1].
	feather->points[feather->point_count / 2].x = NAN;
	assert_int_equal(plume_embedding_create(feather, mesh, &embedding, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "lies on no face of the shell"));
	assert_null(embedding);
	feather->points[feather->point_count / 2].x = 1e308;
	assert_int_equal(plume_embedding_create(feather, mesh, &embedding, &err), PLUME_ERROR_SPEC);
	assert_null(embedding);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), bytes_before);
}

/// The carried feather renders, and with the shell: the scene takes both.
static void test_render_with_shell(void **state)
{
	(void)state;
	plume_feather *feather = small_feather();
	plume_mesh *mesh = mesh_of(feather);
	const plume_feather *list[1] = {feather};
	plume_raytrace_scene scene = {1, list, mesh, NULL};
	plume_raytrace_def def = plume_raytrace_default_def();
	def.camera.width = def.camera.height = 48;
	def.spp = 1;
	def.ground = false;
	def.background = (plume_color){0, 0, 0, 0};
	uint8_t *rgba = malloc(4 * 48 * 48);
	plume_raytrace_stats stats;
	plume_error err = {0};
	assert_int_equal(plume_raytrace_render(&scene, &def, rgba, &stats, &err), PLUME_OK);
	assert_int_equal(stats.triangles, mesh->face_count);
	int covered = 0;
	for (int i = 0; i < 48 * 48; ++i)
		covered += rgba[4 * i + 3] > 0;
	assert_true(covered > 100);
	free(rgba);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
}

/// Two copies of one shell in the same place, joined (as a scene joins its feathers): a feather
/// embedded in the second copy's faces follows that copy alone. Embedded in all the faces, it
/// hangs on the first copy (ties go to the lower face), so the face range is what makes it follow.
static void test_face_range(void **state)
{
	(void)state;
	int64_t bytes_before = plume_bytes_in_use();
	plume_feather *feather = small_feather();
	plume_mesh *mesh = mesh_of(feather), *joined = NULL;
	plume_error err = {0};
	plume_mesh_part parts[2] = {{mesh, plume_m3_identity(), {0, 0, 0}, "a"},
	                            {mesh, plume_m3_identity(), {0, 0, 0}, "b"}};
	assert_int_equal(plume_mesh_concatenate(parts, 2, &joined, &err), PLUME_OK);
	plume_barb_embedding *own = NULL, *all = NULL;
	assert_int_equal(plume_embedding_create_faces(feather, joined, mesh->face_count, mesh->face_count, &own, &err),
	                 PLUME_OK);
	assert_int_equal(plume_embedding_create(feather, joined, &all, &err), PLUME_OK);
	// The first copy stays, the second turns and moves.
	plume_mat3 rotation = plume_m3_rotation(plume_v3_normalize(plume_v3(1, 2, -0.5)), 0.7);
	plume_vec3 shift = {0.1, 0.2, -0.3};
	plume_vec3 *positions = malloc((size_t)joined->vertex_count * sizeof *positions);
	for (int i = 0; i < joined->vertex_count; ++i)
		positions[i] =
		    i < mesh->vertex_count ? joined->rest[i] : plume_v3_add(plume_m3_apply(rotation, joined->rest[i]), shift);
	plume_feather *moved = NULL, *stayed = NULL;
	assert_int_equal(plume_embedding_apply(own, positions, &moved, &err), PLUME_OK);
	assert_int_equal(plume_embedding_apply(all, positions, &stayed, &err), PLUME_OK);
	// Expected: the rest feather moved by the rigid motion, point by point (compare) and by plume_feather_move.
	plume_feather *expected = plume_feather_clone(feather);
	plume_feather_move(expected, rotation, shift);
	double point_error, normal_error;
	compare(expected, moved, &point_error, &normal_error);
	print_message("face range: points %.3g m, directions %.3g\n", point_error, normal_error);
	assert_true(point_error <= 1e-9 && normal_error <= 1e-9);
	assert_true(plume_feather_distance(expected, moved) <= 1e-9);
	compare(feather, stayed, &point_error, &normal_error);
	assert_true(point_error <= 1e-9);
	// plume_feather_distance: a translated copy is |shift| away; another feather has another structure.
	plume_feather *shifted = plume_feather_clone(feather);
	plume_feather_move(shifted, plume_m3_identity(), plume_v3(0, 0.003, 0.004));
	assert_close(plume_feather_distance(feather, shifted), 0.005, 1e-15);
	plume_fw_def def = plume_fw_default_def();
	plume_feather *other = NULL;
	assert_int_equal(plume_fw_generate(&def, 4, &other, &err), PLUME_OK);
	assert_true(isinf(plume_feather_distance(feather, other)));
	plume_feather_destroy(other);
	plume_feather_destroy(shifted);
	plume_feather_destroy(expected);
	plume_feather_destroy(moved);
	plume_feather_destroy(stayed);
	free(positions);
	plume_embedding_destroy(own);
	plume_embedding_destroy(all);
	plume_mesh_destroy(joined);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), bytes_before);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_round_trip),
	    cmocka_unit_test(test_rigid_motion),
	    cmocka_unit_test(test_bent_shell_carries_barbs),
	    cmocka_unit_test(test_bad_shells),
	    cmocka_unit_test(test_render_with_shell),
	    cmocka_unit_test(test_face_range),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

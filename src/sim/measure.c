// Shape measures of the vane for a run's statistics (plume_sim_vane_shape_measure):
// how far the vane is compressed in its plane and how far it has left that plane.
#include <math.h>

#include "../core/asserts.h"
#include "sim/sim_internal.h"

/// The vane: the faces of material 0 (plume_sim_def.materials: [vane, rachis] by default).
enum { VANE_MATERIAL = 0 };

/// Smallest principal stretch of one face: the square root of the smallest eigenvalue
/// of the right Cauchy-Green tensor C = F^T F = I + 2 E (E the Green strain).
static double face_min_stretch(const plume_sim *sim, int f)
{
	const plume_membrane_element *element = sim->membranes + f;
	plume_vec3 local[3] = {sim->x[element->vertices[0]], sim->x[element->vertices[1]], sim->x[element->vertices[2]]};
	plume_green_strain strain;
	plume_green_strain_eval(element, local, &strain);
	// strain.strain is Voigt (E_xx, E_yy, 2 E_xy).
	double cxx = 1 + 2 * strain.strain[0], cyy = 1 + 2 * strain.strain[1], cxy = strain.strain[2];
	double mean = 0.5 * (cxx + cyy), half = 0.5 * (cxx - cyy);
	double smallest = mean - sqrt(half * half + cxy * cxy);
	return sqrt(fmax(smallest, 0.0));
}

/// An orthonormal frame (columns e1, e2, e3) spanned by two points a, b seen from origin c:
/// e1 along a - c, e3 normal to both. False when they are (nearly) collinear.
static bool frame_from_points(plume_vec3 c, plume_vec3 a, plume_vec3 b, plume_mat3 *frame)
{
	plume_vec3 u = plume_v3_sub(a, c), w = plume_v3_cross(u, plume_v3_sub(b, c));
	double lu = plume_v3_length(u), lw = plume_v3_length(w);
	if (!(lu > 0) || !(lw > 1e-9 * lu * lu))
		return false;
	plume_vec3 e1 = plume_v3_scale(u, 1 / lu), e3 = plume_v3_scale(w, 1 / lw), e2 = plume_v3_cross(e3, e1);
	plume_vec3 columns[3] = {e1, e2, e3};
	for (int j = 0; j < 3; ++j) {
		frame->m[0][j] = columns[j].x;
		frame->m[1][j] = columns[j].y;
		frame->m[2][j] = columns[j].z;
	}
	return true;
}

static plume_vec3 group_centroid(const plume_vertex_group *group, const plume_vec3 *x)
{
	plume_vec3 sum = plume_v3(0, 0, 0);
	for (int i = 0; i < group->count; ++i)
		sum = plume_v3_add(sum, x[group->vertices[i]]);
	return plume_v3_scale(sum, 1.0 / group->count);
}

/// The rigid motion of the base group from the rest shape to now: y -> moved + R (y - rest).
/// The frame is built from the group's centroid, its vertex farthest from the centroid at
/// rest and the vertex farthest off that line, picked at rest and followed to now, so a
/// rigidly moved group gives its motion exactly. False for fewer than three non-collinear vertices.
static bool base_motion(const plume_sim *sim, const plume_vertex_group *group, plume_mat3 *R, plume_vec3 *rest,
                        plume_vec3 *moved)
{
	if (group->count < 3)
		return false;
	*rest = group_centroid(group, sim->rest);
	*moved = group_centroid(group, sim->x);
	int far = group->vertices[0], off = group->vertices[0];
	double far_distance = -1, off_distance = -1;
	for (int i = 0; i < group->count; ++i) {
		double d = plume_v3_length(plume_v3_sub(sim->rest[group->vertices[i]], *rest));
		if (d > far_distance) {
			far_distance = d;
			far = group->vertices[i];
		}
	}
	plume_vec3 axis = plume_v3_sub(sim->rest[far], *rest);
	for (int i = 0; i < group->count; ++i) {
		double d = plume_v3_length(plume_v3_cross(axis, plume_v3_sub(sim->rest[group->vertices[i]], *rest)));
		if (d > off_distance) {
			off_distance = d;
			off = group->vertices[i];
		}
	}
	plume_mat3 at_rest, now;
	if (!frame_from_points(*rest, sim->rest[far], sim->rest[off], &at_rest) ||
	    !frame_from_points(*moved, sim->x[far], sim->x[off], &now))
		return false;
	*R = plume_m3_mul(now, plume_m3_transpose(at_rest));
	return true;
}

/// The largest distance of a vane vertex from the rest vane's plane moved with the base group.
/// The rest vane's plane passes through its area-weighted centroid, normal to the sum of its
/// faces' area vectors (the plane itself for a flat vane, the mean plane of a curved one).
static double max_out_of_plane(const plume_sim *sim, const plume_vertex_group *group)
{
	plume_mat3 R;
	plume_vec3 base_rest, base_moved;
	if (group == NULL || !base_motion(sim, group, &R, &base_rest, &base_moved))
		return NAN;
	plume_vec3 normal = plume_v3(0, 0, 0), centroid = plume_v3(0, 0, 0);
	double area = 0;
	for (int f = 0; f < sim->face_count; ++f) {
		if (sim->face_material[f] != VANE_MATERIAL)
			continue;
		const int *v = sim->faces + 3 * f;
		plume_vec3 a = sim->rest[v[0]], b = sim->rest[v[1]], c = sim->rest[v[2]];
		plume_vec3 twice = plume_v3_cross(plume_v3_sub(b, a), plume_v3_sub(c, a));
		double face_area = 0.5 * plume_v3_length(twice);
		normal = plume_v3_add(normal, twice);
		centroid = plume_v3_add(centroid, plume_v3_scale(plume_v3_add(plume_v3_add(a, b), c), face_area / 3));
		area += face_area;
	}
	if (!(area > 0) || !(plume_v3_length(normal) > 0))
		return NAN;
	centroid = plume_v3_scale(centroid, 1 / area);
	plume_vec3 moved_normal = plume_m3_apply(R, plume_v3_normalize(normal));
	plume_vec3 moved_point = plume_v3_add(base_moved, plume_m3_apply(R, plume_v3_sub(centroid, base_rest)));
	double largest = 0;
	for (int f = 0; f < sim->face_count; ++f) {
		if (sim->face_material[f] != VANE_MATERIAL)
			continue;
		for (int k = 0; k < 3; ++k) {
			plume_vec3 x = sim->x[sim->faces[3 * f + k]];
			largest = fmax(largest, fabs(plume_v3_dot(plume_v3_sub(x, moved_point), moved_normal)));
		}
	}
	return largest;
}

plume_sim_vane_shape plume_sim_vane_shape_measure(const plume_sim *sim, const char *base_group)
{
	PLUME_ASSERT_HANDLE(sim);
	PLUME_ASSERT(base_group != NULL);
	plume_sim_vane_shape shape = {NAN, NAN};
	for (int f = 0; f < sim->face_count; ++f)
		if (sim->face_material[f] == VANE_MATERIAL)
			shape.min_principal_stretch = isnan(shape.min_principal_stretch)
			                                  ? face_min_stretch(sim, f)
			                                  : fmin(shape.min_principal_stretch, face_min_stretch(sim, f));
	if (!isnan(shape.min_principal_stretch))
		shape.max_out_of_plane = max_out_of_plane(sim, plume_sim_find_group(sim, base_group));
	return shape;
}

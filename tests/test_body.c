// Bodies: rigid keyframes against closed-form rotations, a shoulder-elbow-wrist chain
// against hand-composed transforms, skinning invariants, the built-in meshes (closed,
// outward, volume and distance between the inscribed and circumscribed bounds that
// each mesh's own faces give), the OBJ reader, and every error of a bad body.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/spec_body.h"
#include "plume/body.h"
#include "support.h"

static const double pi = 3.14159265358979323846;

// ---------------------------------------------------------------------------
// Independent helpers: rotations written out, not plume's Rodrigues.

static plume_vec3 rotate_z(plume_vec3 p, double angle)
{
	double c = cos(angle), s = sin(angle);
	return plume_v3(c * p.x - s * p.y, s * p.x + c * p.y, p.z);
}

/// Rodrigues' formula applied to a vector: v cos + (k x v) sin + k (k . v)(1 - cos).
static plume_vec3 rotate(plume_vec3 v, plume_vec3 axis, double angle)
{
	double n = sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
	plume_vec3 k = plume_v3(axis.x / n, axis.y / n, axis.z / n);
	double c = cos(angle), s = sin(angle), d = k.x * v.x + k.y * v.y + k.z * v.z;
	plume_vec3 kv = plume_v3(k.y * v.z - k.z * v.y, k.z * v.x - k.x * v.z, k.x * v.y - k.y * v.x);
	return plume_v3(v.x * c + kv.x * s + k.x * d * (1 - c), v.y * c + kv.y * s + k.y * d * (1 - c),
	                v.z * c + kv.z * s + k.z * d * (1 - c));
}

/// p turned by angle about axis through centre.
static plume_vec3 rotate_about(plume_vec3 p, plume_vec3 axis, double angle, plume_vec3 centre)
{
	return plume_v3_add(rotate(plume_v3_sub(p, centre), axis, angle), centre);
}

static void assert_vec_close(plume_vec3 a, plume_vec3 b, double tolerance)
{
	if (!(plume_v3_distance(a, b) <= tolerance))
		fail_msg("(%.17g, %.17g, %.17g) and (%.17g, %.17g, %.17g) differ by %.3g > %.3g", a.x, a.y, a.z, b.x, b.y, b.z,
		         plume_v3_distance(a, b), tolerance);
}

static plume_vec3 apply(plume_mat3 r, plume_vec3 t, plume_vec3 p)
{
	return plume_v3(r.m[0][0] * p.x + r.m[0][1] * p.y + r.m[0][2] * p.z + t.x,
	                r.m[1][0] * p.x + r.m[1][1] * p.y + r.m[1][2] * p.z + t.y,
	                r.m[2][0] * p.x + r.m[2][1] * p.y + r.m[2][2] * p.z + t.z);
}

static plume_body *create(const plume_body_def *def)
{
	plume_body *body = NULL;
	plume_error err = {0};
	if (plume_body_create(def, &body, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	return body;
}

/// The default def with an ellipsoid mesh (the mesh is kept in *mesh).
static plume_body_def ellipsoid_def(plume_body_mesh *mesh, plume_vec3 center, plume_vec3 radii, int segments)
{
	plume_error err = {0};
	if (plume_body_ellipsoid(center, radii, segments, mesh, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	plume_body_def def = plume_body_default_def();
	def.vertex_count = mesh->vertex_count;
	def.vertices = mesh->vertices;
	def.triangle_count = mesh->triangle_count;
	def.triangles = mesh->triangles;
	return def;
}

// ---------------------------------------------------------------------------
// Rigid keyframes

static void test_rigid_keyframes(void **state)
{
	(void)state;
	plume_body_mesh mesh;
	plume_body_def def = ellipsoid_def(&mesh, plume_v3(0.3, -0.2, 0.1), plume_v3(0.5, 0.3, 0.2), 8);
	plume_keyframe keys[] = {
	    {.time = 1, .translation = {0, 0, 0}, .axis = {0, 0, 1}, .angle = 0},
	    {.time = 3, .translation = {1, 2, 0}, .axis = {0, 0, 2}, .angle = pi / 2},
	};
	def.keyframes = keys;
	def.keyframe_count = 2;
	def.pivot = plume_v3(0.5, 0, 0);
	plume_body *body = create(&def);
	int n = plume_body_vertex_count(body);
	plume_vec3 *posed = malloc(sizeof *posed * (size_t)n);
	const plume_vec3 *rest = plume_body_rest_positions(body);
	// Linear: at t = 1.5 a quarter of the way, t = 2 half, and the end keys held outside.
	const double times[] = {-1, 1, 1.5, 2, 3, 7};
	const double fractions[] = {0, 0, 0.25, 0.5, 1, 1};
	for (int i = 0; i < 6; ++i) {
		plume_body_pose(body, times[i], posed);
		double s = fractions[i];
		for (int v = 0; v < n; ++v) {
			plume_vec3 expected = plume_v3_add(rotate_z(plume_v3_sub(rest[v], def.pivot), s * pi / 2), def.pivot);
			expected = plume_v3_add(expected, plume_v3(s, 2 * s, 0));
			assert_vec_close(posed[v], expected, 1e-14);
		}
		plume_mat3 r;
		plume_vec3 t;
		plume_body_bone_transform(body, -1, times[i], &r, &t);
		assert_vec_close(apply(r, t, rest[3]), posed[3], 1e-14);
	}
	plume_body_destroy(body);

	// Smooth: smoothstep of the key fraction; at t = 1.5 it is 3/16 - 2/64 = 5/32.
	def.interpolation = PLUME_INTERPOLATION_SMOOTH;
	body = create(&def);
	rest = plume_body_rest_positions(body);
	plume_body_pose(body, 1.5, posed);
	double s = 5.0 / 32;
	for (int v = 0; v < n; ++v) {
		plume_vec3 expected = plume_v3_add(rotate_z(plume_v3_sub(rest[v], def.pivot), s * pi / 2), def.pivot);
		assert_vec_close(posed[v], plume_v3_add(expected, plume_v3(s, 2 * s, 0)), 1e-14);
	}
	plume_body_destroy(body);

	// One axis: the angle is interpolated, so a full turn in one interval is a quarter turn a
	// quarter of the way (a slerp between the keys would not move at all).
	plume_keyframe turn[] = {{.time = 0, .axis = {0, 0, 1}}, {.time = 1, .axis = {0, 0, 1}, .angle = 2 * pi}};
	def.interpolation = PLUME_INTERPOLATION_LINEAR;
	def.keyframes = turn;
	def.pivot = plume_v3(0, 0, 0);
	body = create(&def);
	rest = plume_body_rest_positions(body);
	plume_body_pose(body, 0.25, posed);
	for (int v = 0; v < n; ++v)
		assert_vec_close(posed[v], rotate_z(rest[v], pi / 2), 1e-14);
	plume_body_destroy(body);

	// Opposite axes are one axis with the angle's sign changed: from 10 degrees about z to
	// 270 about -z (-270 about z) passes -130 degrees half-way (the shorter arc would not).
	plume_keyframe opposite[] = {{.time = 0, .axis = {0, 0, 1}, .angle = pi / 18},
	                             {.time = 1, .axis = {0, 0, -3}, .angle = 1.5 * pi}};
	def.keyframes = opposite;
	body = create(&def);
	rest = plume_body_rest_positions(body);
	plume_body_pose(body, 0.5, posed);
	for (int v = 0; v < n; ++v)
		assert_vec_close(posed[v], rotate_z(rest[v], -13 * pi / 18), 1e-14);
	plume_body_destroy(body);

	// Two axes: the slerp half-way between 90 degrees about x and 90 degrees about y is the
	// normalised sum of the quaternions, (sqrt2, sqrt2/2, sqrt2/2, 0) / sqrt3: the angle
	// 2 acos(sqrt(2/3)) about (1, 1, 0).
	plume_keyframe cross[] = {{.time = 0, .axis = {1, 0, 0}, .angle = pi / 2},
	                          {.time = 1, .axis = {0, 1, 0}, .angle = pi / 2}};
	def.keyframes = cross;
	body = create(&def);
	rest = plume_body_rest_positions(body);
	plume_body_pose(body, 0.5, posed);
	for (int v = 0; v < n; ++v)
		assert_vec_close(posed[v], rotate(rest[v], plume_v3(1, 1, 0), 2 * acos(sqrt(2.0 / 3))), 1e-14);
	plume_body_pose(body, 1, posed);
	for (int v = 0; v < n; ++v)
		assert_vec_close(posed[v], rotate(rest[v], plume_v3(0, 1, 0), pi / 2), 1e-14);
	plume_body_destroy(body);
	free(posed);
	plume_body_mesh_free(&mesh);
}

// ---------------------------------------------------------------------------
// Skeletons

/// Shoulder at the origin, elbow at (1, 0, 0), wrist at (2, 0, 0), hand to (2.5, 0, 0);
/// at t = 1 the shoulder and the elbow have turned 90 degrees about z and the wrist
/// 90 degrees about y, and the body has moved by (0, 0, 5).
static const plume_keyframe shoulder_keys[] = {{.time = 0, .axis = {0, 0, 1}},
                                               {.time = 1, .axis = {0, 0, 1}, .angle = pi / 2}};
static const plume_keyframe wrist_keys[] = {{.time = 0, .axis = {0, 1, 0}},
                                            {.time = 1, .axis = {0, 1, 0}, .angle = pi / 2}};
static const plume_keyframe body_keys[] = {{.time = 0, .axis = {0, 0, 1}},
                                           {.time = 1, .translation = {0, 0, 5}, .axis = {0, 0, 1}}};

static plume_body_def arm_def(plume_body_mesh *mesh, plume_body_bone_def bones[3])
{
	plume_error err = {0};
	if (plume_body_capsule(plume_v3(0, 0, 0), plume_v3(2.5, 0, 0), 0.2, 16, mesh, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	plume_body_def def = plume_body_default_def();
	def.vertex_count = mesh->vertex_count;
	def.vertices = mesh->vertices;
	def.triangle_count = mesh->triangle_count;
	def.triangles = mesh->triangles;
	def.keyframes = body_keys;
	def.keyframe_count = 2;
	// Listed children first: the order of the array is not the order of the tree.
	bones[0] = (plume_body_bone_def){.name = "wrist", .parent = 2, .head = {2, 0, 0}, .tail = {2.5, 0, 0}};
	bones[1] = (plume_body_bone_def){.name = "shoulder", .parent = -1, .head = {0, 0, 0}, .tail = {1, 0, 0}};
	bones[2] = (plume_body_bone_def){.name = "elbow", .parent = 1, .head = {1, 0, 0}, .tail = {2, 0, 0}};
	bones[0].keyframes = wrist_keys;
	bones[1].keyframes = bones[2].keyframes = shoulder_keys;
	for (int b = 0; b < 3; ++b)
		bones[b].keyframe_count = 2;
	def.bones = bones;
	def.bone_count = 3;
	return def;
}

static void test_bone_chain(void **state)
{
	(void)state;
	plume_body_mesh mesh;
	plume_body_bone_def bones[3];
	plume_body_def def = arm_def(&mesh, bones);
	plume_body *body = create(&def);
	assert_int_equal(plume_body_bone_count(body), 3);
	assert_int_equal(plume_body_find_bone(body, "elbow"), 2);
	assert_int_equal(plume_body_find_bone(body, "knee"), -1);
	assert_string_equal(plume_body_bone_name(body, 0), "wrist");

	// By hand at t = 1: Rz(90) Rz(90) Ry(90) = diag(-1, -1, 1) [[0,0,1],[0,1,0],[-1,0,0]]
	// = [[0,0,-1],[0,-1,0],[-1,0,0]]; the wrist goes to (-1, 1, 0) + (0, 0, 5), so
	// t = (-1, 1, 5) - R (2, 0, 0) = (-1, 1, 7), and the hand's tip to (-1, 1, 4.5).
	plume_mat3 r;
	plume_vec3 t;
	plume_body_bone_transform(body, 0, 1, &r, &t);
	const double expected[3][3] = {{0, 0, -1}, {0, -1, 0}, {-1, 0, 0}};
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			assert_close(r.m[i][j], expected[i][j], 1e-15);
	assert_vec_close(t, plume_v3(-1, 1, 7), 1e-15);
	assert_vec_close(apply(r, t, plume_v3(2.5, 0, 0)), plume_v3(-1, 1, 4.5), 1e-15);
	// The elbow: Rz(180), its head (1, 0, 0) at (0, 1, 5).
	plume_body_bone_transform(body, 2, 1, &r, &t);
	assert_vec_close(apply(r, t, plume_v3(1, 0, 0)), plume_v3(0, 1, 5), 1e-15);
	assert_vec_close(apply(r, t, plume_v3(2, 0, 0)), plume_v3(-1, 1, 5), 1e-15);

	// Half-way, any point: the hand's local turn, then the elbow's, then the shoulder's,
	// applied one after the other to the point (not composed as matrices).
	const plume_vec3 points[] = {{2.5, 0, 0}, {2.2, 0.1, -0.3}, {0.4, 0.2, 0.1}};
	for (int i = 0; i < 3; ++i) {
		plume_vec3 p = points[i];
		p = rotate_about(p, plume_v3(0, 1, 0), pi / 4, plume_v3(2, 0, 0));
		p = rotate_about(p, plume_v3(0, 0, 1), pi / 4, plume_v3(1, 0, 0));
		p = rotate_about(p, plume_v3(0, 0, 1), pi / 4, plume_v3(0, 0, 0));
		p = plume_v3_add(p, plume_v3(0, 0, 2.5));
		plume_body_bone_transform(body, 0, 0.5, &r, &t);
		assert_vec_close(apply(r, t, points[i]), p, 1e-14);
	}
	plume_body_destroy(body);
	plume_body_mesh_free(&mesh);
}

static void test_skinning(void **state)
{
	(void)state;
	plume_body_mesh mesh;
	plume_body_bone_def bones[3];
	plume_body_def def = arm_def(&mesh, bones);
	int n = mesh.vertex_count;
	// Given weights: vertex v on bone v % 3 alone (the second slot unused or weight 0).
	int *skin_bones = malloc(sizeof(int) * 2 * (size_t)n);
	double *skin_weights = malloc(sizeof(double) * 2 * (size_t)n);
	for (int v = 0; v < n; ++v) {
		skin_bones[2 * v] = v % 3;
		skin_weights[2 * v] = 2.5; // normalised to 1
		skin_bones[2 * v + 1] = v % 2 ? -1 : (v + 1) % 3;
		skin_weights[2 * v + 1] = 0;
	}
	def.skin_influences = 2;
	def.skin_bones = skin_bones;
	def.skin_weights = skin_weights;
	plume_body *body = create(&def);
	plume_vec3 *posed = malloc(sizeof *posed * (size_t)n);
	const plume_vec3 *rest = plume_body_rest_positions(body);
	for (double time = 0; time <= 1; time += 0.25) {
		plume_body_pose(body, time, posed);
		for (int v = 0; v < n; ++v) {
			plume_mat3 r;
			plume_vec3 t;
			plume_body_bone_transform(body, v % 3, time, &r, &t);
			assert_vec_close(posed[v], apply(r, t, rest[v]), 0);
		}
	}
	plume_body_destroy(body);

	// Automatic weights. At rest time the pose is the rest mesh, and with the bones still,
	// a rigid motion of the whole body keeps every distance.
	def.skin_bones = NULL;
	def.skin_weights = NULL;
	body = create(&def);
	rest = plume_body_rest_positions(body);
	plume_body_pose(body, 0, posed);
	for (int v = 0; v < n; ++v)
		assert_vec_close(posed[v], rest[v], 1e-15);
	plume_body_pose(body, -3, posed);
	for (int v = 0; v < n; ++v)
		assert_vec_close(posed[v], rest[v], 1e-15);
	plume_body_destroy(body);
	plume_keyframe tumble[] = {{.time = 0, .axis = {0, 0, 1}},
	                           {.time = 1, .translation = {0.3, -2, 1}, .axis = {1, 2, 3}, .angle = 2.5}};
	def.keyframes = tumble;
	def.pivot = plume_v3(1, 1, 0);
	for (int b = 0; b < 3; ++b)
		bones[b].keyframe_count = 0;
	body = create(&def);
	rest = plume_body_rest_positions(body);
	plume_body_pose(body, 0.7, posed);
	double worst = 0;
	for (int i = 0; i < n; ++i)
		for (int j = i + 1; j < n; ++j)
			worst = fmax(worst, fabs(plume_v3_distance(posed[i], posed[j]) - plume_v3_distance(rest[i], rest[j])));
	assert_true(worst < 1e-14);
	// The follicle bones: the middle of the upper arm rides on the shoulder, the hand on the wrist.
	assert_int_equal(plume_body_nearest_bone(body, plume_v3(0.5, 0.2, 0)), 1);
	assert_int_equal(plume_body_nearest_bone(body, plume_v3(1.5, 0, -0.2)), 2);
	assert_int_equal(plume_body_nearest_bone(body, plume_v3(2.6, 0, 0)), 0);
	plume_body_destroy(body);
	plume_body_mesh_free(&mesh);
	free(posed);
	free(skin_bones);
	free(skin_weights);
}

/// Automatic weights: a vertex at the elbow joint is shared half and half, one halfway along
/// the upper arm takes d^-4 weights; NEAREST gives the nearest bone alone.
static void test_automatic_weights(void **state)
{
	(void)state;
	const plume_vec3 vertices[] = {{1, 0.2, 0}, {0.5, 0.2, 0}, {1.5, 0, 0.3}, {1, -0.2, -0.1}};
	const int triangles[] = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};
	plume_body_bone_def bones[2] = {
	    {.name = "upper", .parent = -1, .head = {0, 0, 0}, .tail = {1, 0, 0}},
	    {.name = "fore", .parent = 0, .head = {1, 0, 0}, .tail = {2, 0, 0}},
	};
	plume_keyframe bend[] = {{.time = 0, .axis = {0, 0, 1}}, {.time = 1, .axis = {0, 0, 1}, .angle = pi / 2}};
	bones[1].keyframes = bend;
	bones[1].keyframe_count = 2;
	plume_body_def def = plume_body_default_def();
	def.vertex_count = 4;
	def.vertices = vertices;
	def.triangle_count = 4;
	def.triangles = triangles;
	def.bone_count = 2;
	def.bones = bones;
	plume_body *body = create(&def);
	plume_vec3 posed[4];
	plume_body_pose(body, 1, posed);
	// The upper arm does not move; the forearm turns 90 degrees about z through (1, 0, 0).
	plume_vec3 turned0 = rotate_about(vertices[0], plume_v3(0, 0, 1), pi / 2, plume_v3(1, 0, 0));
	assert_vec_close(posed[0], plume_v3_lerp(vertices[0], turned0, 0.5), 1e-15);
	double d0 = 0.2, d1 = sqrt(0.5 * 0.5 + 0.2 * 0.2);
	double w1 = pow(d1, -4) / (pow(d0, -4) + pow(d1, -4));
	plume_vec3 turned1 = rotate_about(vertices[1], plume_v3(0, 0, 1), pi / 2, plume_v3(1, 0, 0));
	assert_vec_close(posed[1], plume_v3_lerp(vertices[1], turned1, w1), 1e-15);
	assert_true(w1 < 0.04);
	plume_body_destroy(body);
	def.skinning = PLUME_BODY_SKIN_NEAREST;
	body = create(&def);
	plume_body_pose(body, 1, posed);
	assert_vec_close(posed[1], vertices[1], 0);
	assert_vec_close(posed[2], rotate_about(vertices[2], plume_v3(0, 0, 1), pi / 2, plume_v3(1, 0, 0)), 1e-15);
	plume_body_destroy(body);
}

// ---------------------------------------------------------------------------
// Built-in meshes

/// Every directed edge once and its reverse once: closed, consistently oriented.
static void assert_closed(const plume_body_mesh *mesh)
{
	int n = mesh->vertex_count;
	unsigned char *count = calloc((size_t)n * (size_t)n, 1);
	for (int f = 0; f < mesh->triangle_count; ++f)
		for (int k = 0; k < 3; ++k) {
			int a = mesh->triangles[3 * f + k], b = mesh->triangles[3 * f + (k + 1) % 3];
			assert_true(a != b);
			++count[(size_t)a * (size_t)n + (size_t)b];
		}
	int edges = 0;
	for (int a = 0; a < n; ++a)
		for (int b = 0; b < n; ++b) {
			assert_true(count[(size_t)a * (size_t)n + (size_t)b] <= 1);
			assert_int_equal(count[(size_t)a * (size_t)n + (size_t)b], count[(size_t)b * (size_t)n + (size_t)a]);
			edges += count[(size_t)a * (size_t)n + (size_t)b];
		}
	// Euler: V - E + F = 2 for a sphere.
	assert_int_equal(n - edges / 2 + mesh->triangle_count, 2);
	free(count);
}

static double signed_volume(const plume_body_mesh *mesh)
{
	double volume = 0;
	for (int f = 0; f < mesh->triangle_count; ++f) {
		const int *t = mesh->triangles + 3 * f;
		plume_vec3 a = mesh->vertices[t[0]], b = mesh->vertices[t[1]], c = mesh->vertices[t[2]];
		volume += plume_v3_dot(a, plume_v3_cross(b, c)) / 6;
	}
	return volume;
}

/// Signed distance of p to the plane of face f (positive outside), and the check that the
/// mesh is convex: no vertex outside any face plane.
static double plane_distance(const plume_body_mesh *mesh, int f, plume_vec3 p)
{
	const int *t = mesh->triangles + 3 * f;
	plume_vec3 a = mesh->vertices[t[0]];
	plume_vec3 normal = plume_v3_normalize(
	    plume_v3_cross(plume_v3_sub(mesh->vertices[t[1]], a), plume_v3_sub(mesh->vertices[t[2]], a)));
	return plume_v3_dot(normal, plume_v3_sub(p, a));
}

static void assert_convex(const plume_body_mesh *mesh, double tolerance)
{
	for (int f = 0; f < mesh->triangle_count; ++f)
		for (int v = 0; v < mesh->vertex_count; ++v)
			assert_true(plane_distance(mesh, f, mesh->vertices[v]) <= tolerance);
}

static void test_ellipsoid(void **state)
{
	(void)state;
	plume_error err = {0};
	const int segments[] = {3, 8, 32, 64};
	double previous_error = INFINITY;
	for (int i = 0; i < 4; ++i) {
		// The unit sphere's mesh: its faces' distance to the centre r_in bounds the volume of
		// the ellipsoid's (an affine image): 4/3 pi abc r_in^3 <= V <= 4/3 pi abc.
		plume_body_mesh unit, mesh;
		assert_int_equal(plume_body_ellipsoid(plume_v3(0, 0, 0), plume_v3(1, 1, 1), segments[i], &unit, &err),
		                 PLUME_OK);
		assert_closed(&unit);
		assert_convex(&unit, 1e-14);
		double r_in = INFINITY;
		for (int f = 0; f < unit.triangle_count; ++f)
			r_in = fmin(r_in, -plane_distance(&unit, f, plume_v3(0, 0, 0)));
		for (int v = 0; v < unit.vertex_count; ++v)
			assert_close(plume_v3_length(unit.vertices[v]), 1, 1e-15);
		plume_vec3 radii = plume_v3(0.3, 0.2, 0.5), center = plume_v3(1, -2, 0.5);
		assert_int_equal(plume_body_ellipsoid(center, radii, segments[i], &mesh, &err), PLUME_OK);
		int bands = segments[i] / 2 > 2 ? segments[i] / 2 : 2;
		assert_int_equal(mesh.vertex_count, 2 + (bands - 1) * segments[i]);
		assert_closed(&mesh);
		for (int v = 0; v < mesh.vertex_count; ++v) {
			plume_vec3 p = plume_v3_sub(mesh.vertices[v], center);
			assert_close(pow(p.x / radii.x, 2) + pow(p.y / radii.y, 2) + pow(p.z / radii.z, 2), 1, 1e-14);
		}
		double exact = 4.0 / 3 * pi * radii.x * radii.y * radii.z;
		double volume = signed_volume(&mesh);
		assert_true(volume <= exact * (1 + 1e-14));
		assert_true(volume >= exact * pow(r_in, 3) * (1 - 1e-14));
		// Second order: 8 times finer in angle... the error falls at least 3x per doubling.
		double error = exact - volume;
		if (i >= 2)
			assert_true(error < previous_error / 3);
		previous_error = error;
		plume_body_mesh_free(&unit);
		plume_body_mesh_free(&mesh);
	}
	assert_int_equal(plume_body_ellipsoid(plume_v3(0, 0, 0), plume_v3(1, 0, 1), 8, &(plume_body_mesh){0}, &err),
	                 PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "radii: (1, 0, 1); allowed finite and > 0"));
	assert_int_equal(plume_body_ellipsoid(plume_v3(0, 0, 0), plume_v3(1, 1, 1), 2, &(plume_body_mesh){0}, &err),
	                 PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "segments: is 2; allowed 3 to 4096"));
}

static void test_capsule(void **state)
{
	(void)state;
	plume_error err = {0};
	plume_vec3 a = plume_v3(0.1, 0.2, -0.3), b = plume_v3(-0.4, 0.5, 0.6);
	double radius = 0.15, length = plume_v3_distance(a, b);
	const int segments[] = {3, 12, 48};
	for (int i = 0; i < 3; ++i) {
		plume_body_mesh mesh;
		assert_int_equal(plume_body_capsule(a, b, radius, segments[i], &mesh, &err), PLUME_OK);
		assert_closed(&mesh);
		assert_convex(&mesh, 1e-14);
		// Every vertex on the surface: at distance radius from the segment.
		plume_vec3 d = plume_v3_scale(plume_v3_sub(b, a), 1 / length);
		for (int v = 0; v < mesh.vertex_count; ++v) {
			plume_vec3 p = mesh.vertices[v];
			double s = fmin(fmax(plume_v3_dot(plume_v3_sub(p, a), d), 0), length);
			assert_close(plume_v3_distance(p, plume_v3_mad(a, s, d)), radius, 1e-15);
		}
		// The capsule of radius rho, the least distance from a or b to a face plane, is inside
		// the (convex) mesh, and the mesh inside the capsule of the given radius.
		double rho = INFINITY;
		for (int f = 0; f < mesh.triangle_count; ++f)
			rho = fmin(rho, fmin(-plane_distance(&mesh, f, a), -plane_distance(&mesh, f, b)));
		double volume = signed_volume(&mesh);
		assert_true(volume <= (pi * radius * radius * length + 4.0 / 3 * pi * pow(radius, 3)) * (1 + 1e-14));
		assert_true(volume >= (pi * rho * rho * length + 4.0 / 3 * pi * pow(rho, 3)) * (1 - 1e-14));
		assert_true(rho > 0);
		plume_body_mesh_free(&mesh);
	}
	assert_int_equal(plume_body_capsule(a, a, radius, 8, &(plume_body_mesh){0}, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "b: equals a"));
}

static void test_rest_distance(void **state)
{
	(void)state;
	plume_body_mesh mesh;
	double r = 0.7;
	plume_body_def def = ellipsoid_def(&mesh, plume_v3(0, 0, 0), plume_v3(r, r, r), 96);
	double r_in = INFINITY;
	for (int f = 0; f < mesh.triangle_count; ++f)
		r_in = fmin(r_in, -plane_distance(&mesh, f, plume_v3(0, 0, 0)));
	assert_true(r_in > r * 0.998);
	plume_body *body = create(&def);
	plume_rng rng = plume_rng_seed(14);
	for (int i = 0; i < 40; ++i) {
		// A direction uniform enough, a radius inside or outside.
		plume_vec3 direction = plume_v3_normalize(
		    plume_v3(plume_rng_range(&rng, -1, 1), plume_rng_range(&rng, -1, 1), plume_rng_range(&rng, -1, 1)));
		double rho = (i % 2 ? 1.5 : 0.4) * r;
		plume_vec3 p = plume_v3_scale(direction, rho);
		int triangle = -1;
		double d = plume_body_rest_distance(body, p, &triangle);
		// The sphere's distance |rho - r|, within the band [r_in, r] the mesh lies in.
		double low = rho > r ? rho - r : r_in - rho, high = rho > r ? rho - r_in : r - rho;
		assert_true(d >= low - 1e-15 && d <= high + 1e-15);
		assert_true(triangle >= 0 && triangle < mesh.triangle_count);
		// The triangle it names is at that distance: its plane is no farther.
		assert_true(fabs(plane_distance(&mesh, triangle, p)) <= d + 1e-15);
	}
	assert_close(plume_body_rest_distance(body, mesh.vertices[17], NULL), 0, 0);
	plume_body_destroy(body);
	plume_body_mesh_free(&mesh);
}

// ---------------------------------------------------------------------------
// OBJ and JSON

static char folder[512];

static void write_fixture(const char *name, const char *text, char *path, size_t size)
{
	snprintf(path, size, "%s/%s", folder, name);
	test_write_file(path, text);
}

static void test_obj(void **state)
{
	(void)state;
	plume_body_mesh mesh, back;
	plume_error err = {0};
	assert_int_equal(plume_body_ellipsoid(plume_v3(0, 0, 1), plume_v3(0.3, 0.2, 0.1), 12, &mesh, &err), PLUME_OK);
	char path[600];
	snprintf(path, sizeof path, "%s/body.obj", folder);
	FILE *file = fopen(path, "w");
	fprintf(file, "# an ellipsoid\no body\n");
	for (int v = 0; v < mesh.vertex_count; ++v)
		fprintf(file, "v %.17g %.17g %.17g\nvn 0 0 1\n", mesh.vertices[v].x, mesh.vertices[v].y, mesh.vertices[v].z);
	// Corners in every syntax: plain, v/vt/vn, v//vn, and counted back from the end.
	for (int f = 0; f < mesh.triangle_count; ++f) {
		const int *t = mesh.triangles + 3 * f;
		if (f % 3 == 0)
			fprintf(file, "f %d %d/1/1 %d//1\n", t[0] + 1, t[1] + 1, t[2] + 1);
		else
			fprintf(file, "f %d %d %d\n", t[0] - mesh.vertex_count, t[1] - mesh.vertex_count, t[2] - mesh.vertex_count);
	}
	fclose(file);
	assert_int_equal(plume_body_read_obj(path, &back, &err), PLUME_OK);
	assert_int_equal(back.vertex_count, mesh.vertex_count);
	assert_int_equal(back.triangle_count, mesh.triangle_count);
	assert_memory_equal(back.vertices, mesh.vertices, sizeof(plume_vec3) * (size_t)mesh.vertex_count);
	assert_memory_equal(back.triangles, mesh.triangles, sizeof(int) * 3 * (size_t)mesh.triangle_count);
	plume_body_mesh_free(&back);
	plume_body_mesh_free(&mesh);

	// A body file naming the OBJ relative to itself.
	char json[600];
	write_fixture("body.json",
	              "{\"mesh\": \"body.obj\", \"keyframes\": [{\"time\": 0}, {\"time\": 1, "
	              "\"translation\": [0, 0, 2]}]}",
	              json, sizeof json);
	plume_body *body = NULL;
	if (plume_body_load(json, &body, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	plume_vec3 posed[200];
	assert_true(plume_body_vertex_count(body) <= 200);
	plume_body_pose(body, 0.5, posed);
	assert_close(posed[0].z, plume_body_rest_positions(body)[0].z + 1, 1e-15);
	plume_body_destroy(body);

	// A quad and a pentagon, fanned from their first corner.
	write_fixture("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\nf 1 2 3 4\nf 1 2 3 5 4\n", path,
	              sizeof path);
	assert_int_equal(plume_body_read_obj(path, &back, &err), PLUME_OK);
	const int fan[] = {0, 1, 2, 0, 2, 3, 0, 1, 2, 0, 2, 4, 0, 4, 3};
	assert_int_equal(back.triangle_count, 5);
	assert_memory_equal(back.triangles, fan, sizeof fan);
	plume_body_mesh_free(&back);

	// CRLF line ends, comments, blank lines; a body reads no texture coordinates, so a
	// "vt" that is not finite and texture indices past the "vt" lines pass (the shell's
	// reader, plume_mesh_read_obj, refuses both: test_mesh.c).
	write_fixture("crlf.obj",
	              "# exported on Windows\r\n\r\nv 0 0 0\r\nv 1 0 0 # origin's neighbour\r\nv 1 1 0\r\n"
	              "v 0 1 0\r\nvt nan 0\r\n\tf 1/9/1 2/9/1 -2/9/1 -1/9/1\r\n",
	              path, sizeof path);
	assert_int_equal(plume_body_read_obj(path, &back, &err), PLUME_OK);
	const int quad[] = {0, 1, 2, 0, 2, 3};
	assert_int_equal(back.vertex_count, 4);
	assert_int_equal(back.triangle_count, 2);
	assert_memory_equal(back.triangles, quad, sizeof quad);
	assert_true(back.vertices[1].x == 1.0 && back.vertices[3].y == 1.0);
	plume_body_mesh_free(&back);

	// Errors, with file and line.
	const struct {
		const char *text, *message;
	} bad[] = {
	    {"v 0 0 0\nv nan 0 0\n", ":2: vertex 2: coordinate 1 is nan; allowed finite"},
	    {"v 0 0 0\nv 1 0\n", ":2: \"v\" needs three numbers"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", ":4: face 1: vertex index 4 out of range (3 vertices so far)"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", ":4: face 1: vertex index -4 out of range"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", ":4: face 1: vertex index 0 out of range"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\n\nf 1 2 4\n",
	     ":7: face 2: degenerate (zero-area) triangle of vertices 1 2 4"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n", ":4: face 1: degenerate (zero-area) triangle of vertices 1 2 2"},
	    {"v 0 0 0\nv 1 0 0\nf 1 2\n", ":3: face 1 has 2 corners; a face needs at least 3"},
	    {"v 0 0 0\nv 1 0 0\nf 1 x 2\n", ":3: face 1: corner \"x\" is not a vertex index"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/x\n", ":4: face 1: corner \"3/x\" is not a vertex index"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\nf 1 2 3 4 5\n",
	     ":6: face 2: vertex index 5 out of range (4 vertices so far)"},
	    {"v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\n# a triangle\r\nf 1 2 3 -4\r\n", ":5: face 1: vertex index -4 out of range"},
	    {"v 0 0 0\nv 1 0x 0\n", ":2: vertex 2: \"0x\" is not a number"},
	    {"v 0 0 0\nv 1 0 -inf\n", ":2: vertex 2: coordinate 3 is -inf; allowed finite, within 1e12 m"},
	    {"v 0 0 0\n# nothing else\n", ":2: end of file without faces"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
		write_fixture("bad.obj", bad[i].text, path, sizeof path);
		assert_int_equal(plume_body_read_obj(path, &back, &err), PLUME_ERROR_SYNTAX);
		if (strstr(err.message, bad[i].message) == NULL || strstr(err.message, "bad.obj:") == NULL)
			fail_msg("case %zu: \"%s\" lacks \"%s\"", i, err.message, bad[i].message);
		assert_null(back.vertices);
		assert_null(back.triangles);
		assert_int_equal(back.vertex_count + back.triangle_count, 0);
	}
	// The error comes through a body file as is, naming the OBJ and its line.
	write_fixture("bad.json", "{\"mesh\": \"bad.obj\"}", json, sizeof json);
	assert_int_equal(plume_body_load(json, &body, &err), PLUME_ERROR_SYNTAX);
	assert_non_null(strstr(err.message, "bad.obj:2: end of file without faces"));
	assert_null(body);
	write_fixture("missing.json", "{\"mesh\": \"nowhere.obj\"}", json, sizeof json);
	assert_int_equal(plume_body_load(json, &body, &err), PLUME_ERROR_IO);
	assert_non_null(strstr(err.message, "missing.json: $.mesh: "));
	assert_non_null(strstr(err.message, "nowhere.obj: cannot open"));
}

/// A JSON body with the arm's skeleton; `extra` is spliced into the top-level object.
static const char *arm_json =
    "{\"mesh\": {\"shape\": \"capsule\", \"a\": [0, 0, 0], \"b\": [2.5, 0, 0], \"radius\": 0.2},"
    " \"interpolation\": \"linear\","
    " \"keyframes\": [{\"time\": 0}, {\"time\": 1, \"translation\": [0, 0, 5]}],"
    " \"bones\": ["
    "  {\"name\": \"wrist\", \"parent\": \"elbow\", \"head\": [2, 0, 0], \"tail\": [2.5, 0, 0],"
    "   \"keyframes\": [{\"time\": 0}, {\"time\": 1, \"rotation_axis\": [0, 1, 0], "
    "\"rotation_deg\": 90}]},"
    "  {\"name\": \"shoulder\", \"head\": [0, 0, 0],"
    "   \"keyframes\": [{\"time\": 0}, {\"time\": 1, \"rotation_deg\": 90}]},"
    "  {\"name\": \"elbow\", \"parent\": \"shoulder\", \"head\": [1, 0, 0],"
    "   \"keyframes\": [{\"time\": 0}, {\"time\": 1, \"rotation_deg\": 90}]}"
    " ], \"skinning\": \"auto\"}";

static void test_json(void **state)
{
	(void)state;
	plume_body *body = NULL;
	plume_error err = {0};
	if (plume_body_parse(arm_json, "arm.json", &body, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	// The same as the C definition of the arm, and the elbow's tail defaults to the wrist's head.
	plume_body_mesh mesh;
	plume_body_bone_def bones[3];
	plume_body_def def = arm_def(&mesh, bones);
	plume_body *expected = create(&def);
	int n = plume_body_vertex_count(body);
	assert_int_equal(n, plume_body_vertex_count(expected));
	plume_vec3 *a = malloc(sizeof *a * (size_t)n), *b = malloc(sizeof *b * (size_t)n);
	for (double t = 0; t <= 1; t += 0.125) {
		plume_body_pose(body, t, a);
		plume_body_pose(expected, t, b);
		for (int v = 0; v < n; ++v)
			assert_vec_close(a[v], b[v], 1e-15);
	}
	free(a);
	free(b);
	plume_body_destroy(expected);
	plume_body_destroy(body);

	// "nearest" is PLUME_BODY_SKIN_NEAREST: every vertex moves rigidly with one bone.
	char text[2048];
	snprintf(text, sizeof text, "%.*s\"nearest\"}", (int)(strstr(arm_json, "\"auto\"") - arm_json), arm_json);
	if (plume_body_parse(text, "arm.json", &body, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	def.skinning = PLUME_BODY_SKIN_NEAREST;
	expected = create(&def);
	a = malloc(sizeof *a * (size_t)n), b = malloc(sizeof *b * (size_t)n);
	plume_body_pose(body, 0.6, a);
	plume_body_pose(expected, 0.6, b);
	for (int v = 0; v < n; ++v)
		assert_vec_close(a[v], b[v], 1e-15);
	free(a);
	free(b);
	plume_body_destroy(expected);
	plume_body_destroy(body);
	plume_body_mesh_free(&mesh);

	// Inline meshes; a scene's "body" member names its path.
	json_t *root = json_loads("{\"body\": {\"mesh\": {\"vertices\": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],"
	                          " \"triangles\": [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]}}}",
	                          0, NULL);
	assert_int_equal(plume_spec_body("scene.json", json_object_get(root, "body"), "$.body", NULL, &body, &err),
	                 PLUME_OK);
	assert_int_equal(plume_body_triangle_count(body), 4);
	assert_int_equal(plume_body_bone_count(body), 0);
	assert_int_equal(plume_body_nearest_bone(body, plume_v3(0.2, 0.2, 0.2)), -1);
	assert_close(plume_body_rest_distance(body, plume_v3(1, 1, 1), NULL), sqrt(3) - 1 / sqrt(3), 1e-15);
	plume_body_destroy(body);
	json_decref(root);
	root = json_loads("{\"body\": {\"mesh\": {\"shape\": \"ellipsoid\", \"radii\": [1, 1, 1]}, \"bones\": [{\"name\": "
	                  "\"a\", \"parent\": \"b\", \"head\": [0, 0, 0]}, {\"name\": \"b\", \"parent\": \"a\", "
	                  "\"head\": [0, 0, 1]}]}}",
	                  0, NULL);
	assert_int_equal(plume_spec_body("scene.json", json_object_get(root, "body"), "$.body", NULL, &body, &err),
	                 PLUME_ERROR_SPEC);
	assert_string_equal(err.message, "scene.json: $.body.bones[0].parent: the parents form a cycle (\"a\" -> \"b\" -> "
	                                 "\"a\"); a skeleton is a tree");
	json_decref(root);
}

static void test_json_errors(void **state)
{
	(void)state;
	const char *sphere = "\"mesh\": {\"shape\": \"ellipsoid\", \"radii\": [1, 1, 1], \"segments\": 8}";
#define TETRA "\"mesh\": {\"vertices\": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]], \"triangles\": "
	const struct {
		const char *prefix, *body, *message;
	} bad[] = {
	    {"", "\"keyframes\": []", "b.json: $.mesh: missing; a body needs a mesh"},
	    {TETRA "[[0, 1, 2], [0, 1, 3]]}", "",
	     "b.json: $.mesh.triangles[1]: degenerate (zero area): vertices 0 (0, 0, 0), 1 (1, 0, 0), 3 (2, 0, 0)"},
	    {TETRA "[[0, 1, 4]]}", "", "b.json: $.mesh.triangles[0]: element 2 is not a vertex index 0 to 3"},
	    {TETRA "[[0, 1]]}", "", "b.json: $.mesh.triangles[0]: expected three vertex indices"},
	    {"\"mesh\": {\"vertices\": [[0, 0, 0], [1, 0]], \"triangles\": [[0, 1, 1]]}", "",
	     "b.json: $.mesh.vertices[1]: expected an array of 3 numbers"},
	    {"\"mesh\": {\"shape\": \"ellipse\", \"radii\": [1, 1, 1]}", "",
	     "b.json: $.mesh.shape: unknown value \"ellipse\"; did you mean \"ellipsoid\"?"},
	    {"\"mesh\": {\"shape\": \"ellipsoid\", \"radii\": [1, -1, 1]}", "",
	     "b.json: $.mesh.radii: (1, -1, 1); allowed finite and > 0 (m)"},
	    {"\"mesh\": {\"shape\": \"ellipsoid\", \"radius\": 1}", "",
	     "b.json: $.mesh.radius: unknown key; did you mean \"radii\"?"},
	    {"\"mesh\": {\"shape\": \"capsule\", \"a\": [0, 0, 0], \"b\": [1, 0, 0]}", "",
	     "b.json: $.mesh.radius: missing; a capsule has a radius (m)"},
	    {sphere, "\"keyframes\": [{\"time\": 1}, {\"time\": 0.5}]",
	     "b.json: $.keyframes[1].time: is 0.5 after the previous key's; keyframe times must be finite, >= 0 and "
	     "increasing"},
	    {sphere, "\"keyframes\": [{\"translation\": [0, 0, 1]}]", "b.json: $.keyframes[0].time: missing"},
	    {sphere, "\"keyframes\": [{\"time\": 0, \"rotation_axis\": [0, 0, 0], \"rotation_deg\": 10}]",
	     "b.json: $.keyframes[0].rotation_axis: is the zero vector; a rotation needs a finite, non-zero axis"},
	    {sphere, "\"bones\": [{\"name\": \"a\", \"head\": [0, 0, 0], \"keyframes\": [{\"time\": 0}, {\"time\": 0}]}]",
	     "b.json: $.bones[0].keyframes[1].time: is 0 after the previous key's"},
	    {sphere, "\"bones\": [{\"name\": \"a\", \"head\": [0, 0, 0]}, {\"name\": \"a\", \"head\": [0, 0, 1]}]",
	     "b.json: $.bones[1].name: \"a\" is also the name of bones[0]; names must be unique"},
	    {sphere,
	     "\"bones\": [{\"name\": \"arm\", \"head\": [0, 0, 0]}, {\"name\": \"b\", \"parent\": \"amr\", "
	     "\"head\": [0, 0, 1]}]",
	     "b.json: $.bones[1].parent: unknown bone \"amr\"; did you mean \"arm\"? (bones: arm, b; null for a root)"},
	    {sphere, "\"bones\": [{\"name\": \"a\", \"parent\": \"a\", \"head\": [0, 0, 0]}]",
	     "b.json: $.bones[0].parent: \"a\" is the bone itself; a bone's parent is another bone, or null for a root"},
	    {sphere, "\"bones\": [{\"name\": \"a\"}]", "b.json: $.bones[0].head: missing"},
	    {sphere, "\"bones\": [{\"head\": [0, 0, 0]}]", "b.json: $.bones[0].name: missing; every bone has a name"},
	    {sphere, "\"bones\": [{\"name\": \"a\", \"head\": [0, 0, 0], \"length\": 1}]",
	     "b.json: $.bones[0].length: unknown key"},
	    {sphere, "\"skinning\": \"automatic\"",
	     "b.json: $.skinning: unknown value \"automatic\"; did you mean \"auto\"?"},
	    {sphere, "\"pivot\": [0, 0]", "b.json: $.pivot: expected an array of 3 numbers"},
	    {sphere, "\"interpolation\": \"cubic\"", "b.json: $.interpolation: unknown value \"cubic\""},
	    {sphere, "\"keyframe\": []", "b.json: $.keyframe: unknown key; did you mean \"keyframes\"?"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
		char text[1024];
		snprintf(text, sizeof text, "{%s%s%s}", bad[i].prefix, bad[i].prefix[0] && bad[i].body[0] ? ", " : "",
		         bad[i].body);
		plume_body *body = (plume_body *)&text; // must be reset to NULL
		plume_error err = {0};
		plume_status status = plume_body_parse(text, "b.json", &body, &err);
		if (status != PLUME_ERROR_SPEC)
			fail_msg("case %zu: %s", i, err.message);
		assert_null(body);
		if (strncmp(err.message, bad[i].message, strlen(bad[i].message)) != 0)
			fail_msg("case %zu: \"%s\"\n  expected to start with \"%s\"", i, err.message, bad[i].message);
	}
	plume_body *body = NULL;
	plume_error err = {0};
	assert_int_equal(plume_body_parse("{\"mesh\": ", "b.json", &body, &err), PLUME_ERROR_SYNTAX);
	assert_non_null(strstr(err.message, "b.json:1:"));
}

/// The definition's own errors (what JSON cannot express: non-finite numbers, given weights).
static void test_def_errors(void **state)
{
	(void)state;
	plume_vec3 vertices[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
	int triangles[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
	plume_body_bone_def bones[2] = {{.name = "a", .parent = -1}, {.name = "b", .parent = 0, .head = {0, 0, 1}}};
	plume_keyframe keys[2] = {{.time = 0, .axis = {0, 0, 1}}, {.time = 1, .axis = {0, 0, 1}}};
	int skin_bones[4] = {0, 1, 1, 0};
	double skin_weights[4] = {1, 1, 1, 1};
	struct {
		int field;
		const char *message;
	} cases[] = {
	    {0, "vertices[2]: (0, nan, 0) is not finite"},
	    {1, "triangles[3]: vertex index 4 out of range; allowed 0 to 3 (4 vertices)"},
	    {2, "triangles[1]: degenerate (zero area)"},
	    {3, "vertices: 2 given; a body mesh needs at least 3"},
	    {4, "keyframes[1].translation: is not finite"},
	    {5, "bones[1].head: is not finite"},
	    {6, "skin_bones[1]: bone 2 out of range; allowed -1 to 1"},
	    {7, "skin_weights[0]: -1; weights are finite and >= 0"},
	    {8, "skin_weights[1]: the vertex's weights sum to 0"},
	    {9, "bones[1].parent: is 2; allowed -1 (a root) or another bone, 0 to 1"},
	    {10, "bones[0].name: empty"},
	    {11, "keyframes[0].rotation_deg: is not finite"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
		plume_vec3 v[4];
		int t[12];
		memcpy(v, vertices, sizeof v);
		memcpy(t, triangles, sizeof t);
		plume_body_bone_def b[2];
		memcpy(b, bones, sizeof b);
		plume_keyframe k[2];
		memcpy(k, keys, sizeof k);
		int sb[4];
		double sw[4];
		memcpy(sb, skin_bones, sizeof sb);
		memcpy(sw, skin_weights, sizeof sw);
		plume_body_def def = plume_body_default_def();
		def.vertex_count = 4;
		def.vertices = v;
		def.triangle_count = 4;
		def.triangles = t;
		def.keyframe_count = 2;
		def.keyframes = k;
		def.bone_count = 2;
		def.bones = b;
		def.skin_influences = 1;
		def.skin_bones = sb;
		def.skin_weights = sw;
		switch (cases[i].field) {
		case 0: v[2].y = NAN; break;
		case 1: t[11] = 4; break;
		case 2: v[3] = plume_v3(0.5, 0, 0); break;
		case 3: def.vertex_count = 2; break;
		case 4: k[1].translation.x = INFINITY; break;
		case 5: b[1].head.z = NAN; break;
		case 6: sb[1] = 2; break;
		case 7: sw[0] = -1; break;
		case 8: sb[1] = -1; break;
		case 9: b[1].parent = 2; break;
		case 10: b[0].name[0] = '\0'; break;
		case 11: k[0].angle = NAN; break;
		}
		plume_body *body = NULL;
		plume_error err = {0};
		assert_int_equal(plume_body_create(&def, &body, &err), PLUME_ERROR_SPEC);
		assert_null(body);
		if (strncmp(err.message, cases[i].message, strlen(cases[i].message)) != 0)
			fail_msg("case %zu: \"%s\"\n  expected to start with \"%s\"", i, err.message, cases[i].message);
	}
}

static int setup(void **state)
{
	(void)state;
	test_make_temp_dir(folder, sizeof folder);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	test_remove_tree(folder);
	return 0;
}

int main(void)
{
	int64_t before = plume_bytes_in_use();
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_rigid_keyframes),   cmocka_unit_test(test_bone_chain), cmocka_unit_test(test_skinning),
	    cmocka_unit_test(test_automatic_weights), cmocka_unit_test(test_ellipsoid),  cmocka_unit_test(test_capsule),
	    cmocka_unit_test(test_rest_distance),     cmocka_unit_test(test_obj),        cmocka_unit_test(test_json),
	    cmocka_unit_test(test_json_errors),       cmocka_unit_test(test_def_errors),
	};
	int failures = cmocka_run_group_tests(tests, setup, teardown);
	if (plume_bytes_in_use() != before) {
		fprintf(stderr, "test_body: %lld bytes leaked\n", (long long)(plume_bytes_in_use() - before));
		return 1;
	}
	return failures;
}

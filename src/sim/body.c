// Bodies (include/plume/body.h, docs/body.md): a rest triangle mesh moved by keyframes,
// rigidly or through a skeleton of bones with linear blend skinning.
//
// Every transform here maps rest coordinates to posed ones as x -> R x + t, so a bone's
// world transform is its parent's composed with its own local one:
//   local  L_b(x) = R_b (x - h_b) + h_b + T_b           (turn about the head, then shift)
//   world  M_b = M_parent o L_b:  R = R_p R_b,  t = R_p (h_b + T_b - R_b h_b) + t_p
// with the body's rigid motion M_{-1}(x) = R (x - pivot) + pivot + T as the roots' parent.
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "../core/alloc.h"
#include "../core/asserts.h"
#include "body_internal.h"
#include "contact_distance.h"
#include "plume/body.h"

typedef struct body_bone {
	char name[PLUME_BODY_NAME_SIZE];
	int parent;
	plume_vec3 head, tail;
	plume_interpolation interpolation;
	int keyframe_count;
	plume_keyframe *keyframes;
} body_bone;

struct plume_body {
	uint32_t magic;
	int vertex_count, triangle_count;
	plume_vec3 *rest;
	int *triangles;
	plume_vec3 pivot;
	plume_interpolation interpolation;
	int keyframe_count;
	plume_keyframe *keyframes;
	int bone_count;
	body_bone *bones;
	/// Bones with every parent before its children.
	int *order;
	/// PLUME_BODY_MAX_INFLUENCES bones (-1: unused) and weights per vertex.
	int *skin_bones;
	double *skin_weights;
};

plume_body_def plume_body_default_def(void)
{
	return (plume_body_def){
	    .pivot = {0, 0, 0},
	    .interpolation = PLUME_INTERPOLATION_LINEAR,
	    .skinning = PLUME_BODY_SKIN_BLEND,
	    .cookie = PLUME_DEF_COOKIE,
	};
}

// ---------------------------------------------------------------------------
// Checks

bool plume_body_triangle_degenerate(plume_vec3 a, plume_vec3 b, plume_vec3 c)
{
	plume_vec3 ab = plume_v3_sub(b, a), bc = plume_v3_sub(c, b), ca = plume_v3_sub(a, c);
	double longest = fmax(plume_v3_dot(ab, ab), fmax(plume_v3_dot(bc, bc), plume_v3_dot(ca, ca)));
	double twice_area = plume_v3_length(plume_v3_cross(ab, plume_v3_sub(c, a)));
	// Written so that a NaN anywhere makes the triangle degenerate.
	return !(twice_area > 1e-12 * longest && isfinite(longest));
}

static bool finite3(plume_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

static plume_status check_keyframes(const plume_keyframe *keys, int count, const char *path, plume_error *err)
{
	if (count < 0 || (count > 0 && keys == NULL))
		return plume_error_set(err, PLUME_ERROR_SPEC, "%skeyframes: %d keys without an array", path, count);
	for (int k = 0; k < count; ++k) {
		const plume_keyframe *key = keys + k;
		if (!(isfinite(key->time) && key->time >= 0 && (k == 0 || key->time > key[-1].time)))
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "%skeyframes[%d].time: is %g%s; keyframe times must be finite, >= 0 and increasing",
			                       path, k, key->time, k > 0 ? " after the previous key's" : "");
		if (!finite3(key->translation))
			return plume_error_set(err, PLUME_ERROR_SPEC, "%skeyframes[%d].translation: is not finite", path, k);
		if (!isfinite(key->angle))
			return plume_error_set(err, PLUME_ERROR_SPEC, "%skeyframes[%d].rotation_deg: is not finite", path, k);
		if (!finite3(key->axis) || (key->angle != 0 && plume_v3_length(key->axis) == 0))
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "%skeyframes[%d].rotation_axis: is %s; a rotation needs a finite, non-zero axis",
			                       path, k, finite3(key->axis) ? "the zero vector" : "not finite");
	}
	return PLUME_OK;
}

static plume_status check_mesh(const plume_body_def *def, plume_error *err)
{
	if (def->vertex_count < 3 || def->vertices == NULL)
		return plume_error_set(err, PLUME_ERROR_SPEC, "vertices: %d given; a body mesh needs at least 3",
		                       def->vertices == NULL ? 0 : def->vertex_count);
	if (def->triangle_count < 1 || def->triangles == NULL)
		return plume_error_set(err, PLUME_ERROR_SPEC, "triangles: none given; a body mesh needs at least one");
	for (int v = 0; v < def->vertex_count; ++v)
		if (!finite3(def->vertices[v]))
			return plume_error_set(err, PLUME_ERROR_SPEC, "vertices[%d]: (%g, %g, %g) is not finite", v,
			                       def->vertices[v].x, def->vertices[v].y, def->vertices[v].z);
	for (int f = 0; f < def->triangle_count; ++f) {
		const int *t = def->triangles + 3 * f;
		for (int k = 0; k < 3; ++k)
			if (t[k] < 0 || t[k] >= def->vertex_count)
				return plume_error_set(err, PLUME_ERROR_SPEC,
				                       "triangles[%d]: vertex index %d out of range; allowed 0 to %d (%d vertices)", f,
				                       t[k], def->vertex_count - 1, def->vertex_count);
		plume_vec3 a = def->vertices[t[0]], b = def->vertices[t[1]], c = def->vertices[t[2]];
		if (plume_body_triangle_degenerate(a, b, c))
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "triangles[%d]: degenerate (zero area): vertices %d (%g, %g, %g), %d (%g, %g, %g), "
			                       "%d (%g, %g, %g); remove the face or move its vertices apart",
			                       f, t[0], a.x, a.y, a.z, t[1], b.x, b.y, b.z, t[2], c.x, c.y, c.z);
	}
	return PLUME_OK;
}

/// Fills order with the bones, parents first; fails on a cycle, naming it.
static plume_status check_bones(const plume_body_def *def, int *order, plume_error *err)
{
	int n = def->bone_count;
	if (n < 0 || n > PLUME_BODY_MAX_BONES || (n > 0 && def->bones == NULL))
		return plume_error_set(err, PLUME_ERROR_SPEC, "bones: %d given; allowed 0 to %d", n, PLUME_BODY_MAX_BONES);
	for (int b = 0; b < n; ++b) {
		const plume_body_bone_def *bone = def->bones + b;
		const char *zero = memchr(bone->name, '\0', PLUME_BODY_NAME_SIZE);
		size_t length = zero != NULL ? (size_t)(zero - bone->name) : PLUME_BODY_NAME_SIZE;
		if (length == 0 || length == PLUME_BODY_NAME_SIZE)
			return plume_error_set(err, PLUME_ERROR_SPEC, "bones[%d].name: %s; a bone has a name of 1 to %d bytes", b,
			                       length == 0 ? "empty" : "too long", PLUME_BODY_NAME_SIZE - 1);
		for (int other = 0; other < b; ++other)
			if (strcmp(def->bones[other].name, bone->name) == 0)
				return plume_error_set(err, PLUME_ERROR_SPEC,
				                       "bones[%d].name: \"%s\" is also the name of bones[%d]; names must be unique", b,
				                       bone->name, other);
		if (bone->parent < -1 || bone->parent >= n || bone->parent == b)
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "bones[%d].parent: is %d; allowed -1 (a root) or another bone, 0 to %d", b,
			                       bone->parent, n - 1);
		if (!finite3(bone->head) || !finite3(bone->tail))
			return plume_error_set(err, PLUME_ERROR_SPEC, "bones[%d].%s: is not finite", b,
			                       finite3(bone->head) ? "tail" : "head");
		char path[64];
		snprintf(path, sizeof path, "bones[%d].", b);
		plume_status status = check_keyframes(bone->keyframes, bone->keyframe_count, path, err);
		if (status != PLUME_OK)
			return status;
	}
	// Parents first: repeatedly take the bones whose parent is placed (n passes at most);
	// what is left then hangs on a cycle.
	bool placed[PLUME_BODY_MAX_BONES] = {false};
	int count = 0;
	for (bool progress = true; progress && count < n;) {
		progress = false;
		for (int b = 0; b < n; ++b)
			if (!placed[b] && (def->bones[b].parent < 0 || placed[def->bones[b].parent])) {
				placed[b] = true;
				order[count++] = b;
				progress = true;
			}
	}
	if (count == n)
		return PLUME_OK;
	// Walk up from the first unplaced bone until a bone repeats: that bone is on the cycle.
	int b = 0;
	while (placed[b])
		++b;
	for (int step = 0; step < n; ++step)
		b = def->bones[b].parent;
	char cycle[512] = "";
	int start = b;
	do {
		size_t used = strlen(cycle);
		snprintf(cycle + used, sizeof cycle - used, "%s\"%s\"", used > 0 ? " -> " : "", def->bones[b].name);
		b = def->bones[b].parent;
	} while (b != start);
	return plume_error_set(err, PLUME_ERROR_SPEC,
	                       "bones[%d].parent: the parents form a cycle (%s -> \"%s\"); a skeleton is a tree", start,
	                       cycle, def->bones[start].name);
}

static plume_status check_given_skin(const plume_body_def *def, plume_error *err)
{
	int k = def->skin_influences;
	if (k < 1 || k > PLUME_BODY_MAX_INFLUENCES || def->skin_weights == NULL)
		return plume_error_set(err, PLUME_ERROR_SPEC, "skin_influences: is %d with %s; allowed 1 to %d with weights", k,
		                       def->skin_weights == NULL ? "no weights" : "weights", PLUME_BODY_MAX_INFLUENCES);
	if (def->bone_count == 0)
		return plume_error_set(err, PLUME_ERROR_SPEC, "skin_bones: given for a body without bones");
	for (int v = 0; v < def->vertex_count; ++v) {
		double sum = 0;
		for (int i = 0; i < k; ++i) {
			int bone = def->skin_bones[k * v + i];
			double weight = def->skin_weights[k * v + i];
			if (bone < -1 || bone >= def->bone_count)
				return plume_error_set(err, PLUME_ERROR_SPEC, "skin_bones[%d]: bone %d out of range; allowed -1 to %d",
				                       v, bone, def->bone_count - 1);
			if (!(isfinite(weight) && weight >= 0))
				return plume_error_set(err, PLUME_ERROR_SPEC, "skin_weights[%d]: %g; weights are finite and >= 0", v,
				                       weight);
			if (bone >= 0)
				sum += weight;
		}
		if (!(sum > 0))
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "skin_weights[%d]: the vertex's weights sum to 0; every vertex needs a bone", v);
	}
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// Skinning weights

static double segment_distance(plume_vec3 p, plume_vec3 a, plume_vec3 b)
{
	plume_vec3 ab = plume_v3_sub(b, a);
	double length2 = plume_v3_dot(ab, ab);
	double s = length2 > 0 ? plume_v3_dot(plume_v3_sub(p, a), ab) / length2 : 0;
	s = s < 0 ? 0 : s > 1 ? 1 : s;
	return plume_v3_distance(p, plume_v3_mad(a, s, ab));
}

/// The two nearest bones (BLEND, weights d^-4 normalised) or the nearest (NEAREST).
static void auto_skin(plume_body *body, plume_body_skinning skinning)
{
	for (int v = 0; v < body->vertex_count; ++v) {
		int *bones = body->skin_bones + PLUME_BODY_MAX_INFLUENCES * v;
		double *weights = body->skin_weights + PLUME_BODY_MAX_INFLUENCES * v;
		int best[2] = {-1, -1};
		double distance[2] = {INFINITY, INFINITY};
		for (int b = 0; b < body->bone_count; ++b) {
			double d = segment_distance(body->rest[v], body->bones[b].head, body->bones[b].tail);
			if (d < distance[0]) {
				best[1] = best[0], distance[1] = distance[0];
				best[0] = b, distance[0] = d;
			} else if (d < distance[1]) {
				best[1] = b, distance[1] = d;
			}
		}
		bones[0] = best[0];
		weights[0] = 1;
		if (skinning == PLUME_BODY_SKIN_BLEND && best[1] >= 0 && distance[0] > 0) {
			// w_i = d_i^-4 / (d_0^-4 + d_1^-4), written with the ratio r = d_0 / d_1 <= 1.
			double r = distance[0] / distance[1], r4 = r * r * r * r;
			bones[1] = best[1];
			weights[0] = 1 / (1 + r4);
			weights[1] = r4 / (1 + r4);
		}
	}
}

static void given_skin(plume_body *body, const plume_body_def *def)
{
	int k = def->skin_influences;
	for (int v = 0; v < body->vertex_count; ++v) {
		double sum = 0;
		for (int i = 0; i < k; ++i)
			if (def->skin_bones[k * v + i] >= 0)
				sum += def->skin_weights[k * v + i];
		int used = 0;
		for (int i = 0; i < k; ++i)
			if (def->skin_bones[k * v + i] >= 0 && def->skin_weights[k * v + i] > 0) {
				body->skin_bones[PLUME_BODY_MAX_INFLUENCES * v + used] = def->skin_bones[k * v + i];
				body->skin_weights[PLUME_BODY_MAX_INFLUENCES * v + used] = def->skin_weights[k * v + i] / sum;
				++used;
			}
	}
}

// ---------------------------------------------------------------------------
// Creation

static void *copy_array(const void *source, int count, size_t size)
{
	void *copy = plume_calloc(count > 0 ? (size_t)count : 1u, size);
	if (copy != NULL && count > 0)
		memcpy(copy, source, (size_t)count * size);
	return copy;
}

plume_status plume_body_create(const plume_body_def *def, plume_body **out, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	PLUME_ASSERT(out != NULL);
	*out = NULL;
	int order[PLUME_BODY_MAX_BONES];
	plume_status status = check_mesh(def, err);
	if (status == PLUME_OK)
		status = check_keyframes(def->keyframes, def->keyframe_count, "", err);
	if (status == PLUME_OK && !finite3(def->pivot))
		status = plume_error_set(err, PLUME_ERROR_SPEC, "pivot: is not finite");
	if (status == PLUME_OK)
		status = check_bones(def, order, err);
	if (status == PLUME_OK && def->skin_bones != NULL)
		status = check_given_skin(def, err);
	if (status == PLUME_OK && def->skin_bones == NULL && def->skinning != PLUME_BODY_SKIN_BLEND &&
	    def->skinning != PLUME_BODY_SKIN_NEAREST)
		status = plume_error_set(err, PLUME_ERROR_SPEC, "skinning: unknown method %d", (int)def->skinning);
	if (status != PLUME_OK)
		return status;

	plume_body *body = plume_calloc(1, sizeof *body);
	if (body == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating a body");
	body->magic = PLUME_HANDLE_MAGIC;
	body->vertex_count = def->vertex_count;
	body->triangle_count = def->triangle_count;
	body->pivot = def->pivot;
	body->interpolation = def->interpolation;
	body->keyframe_count = def->keyframe_count;
	body->bone_count = def->bone_count;
	body->rest = copy_array(def->vertices, def->vertex_count, sizeof *body->rest);
	body->triangles = copy_array(def->triangles, 3 * def->triangle_count, sizeof *body->triangles);
	body->keyframes = copy_array(def->keyframes, def->keyframe_count, sizeof *body->keyframes);
	body->bones = plume_calloc((size_t)def->bone_count + 1, sizeof *body->bones);
	body->order = copy_array(order, def->bone_count, sizeof *body->order);
	size_t slots = (size_t)PLUME_BODY_MAX_INFLUENCES * (size_t)def->vertex_count;
	body->skin_bones = plume_alloc(slots * sizeof *body->skin_bones);
	body->skin_weights = plume_calloc(slots, sizeof *body->skin_weights);
	bool ok = body->rest != NULL && body->triangles != NULL && body->keyframes != NULL && body->bones != NULL &&
	          body->order != NULL && body->skin_bones != NULL && body->skin_weights != NULL;
	for (int b = 0; ok && b < def->bone_count; ++b) {
		const plume_body_bone_def *source = def->bones + b;
		body_bone *bone = body->bones + b;
		memcpy(bone->name, source->name, sizeof bone->name);
		bone->parent = source->parent;
		bone->head = source->head;
		bone->tail = source->tail;
		bone->interpolation = source->interpolation;
		bone->keyframe_count = source->keyframe_count;
		bone->keyframes = copy_array(source->keyframes, source->keyframe_count, sizeof *bone->keyframes);
		ok = bone->keyframes != NULL;
	}
	if (!ok) {
		plume_body_destroy(body);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating a body");
	}
	for (size_t i = 0; i < slots; ++i)
		body->skin_bones[i] = -1;
	if (def->bone_count > 0) {
		if (def->skin_bones != NULL)
			given_skin(body, def);
		else
			auto_skin(body, def->skinning);
	}
	*out = body;
	return PLUME_OK;
}

void plume_body_destroy(plume_body *body)
{
	if (body == NULL)
		return;
	PLUME_ASSERT_HANDLE(body);
	body->magic = 0;
	for (int b = 0; body->bones != NULL && b < body->bone_count; ++b)
		plume_free(body->bones[b].keyframes);
	plume_free(body->bones);
	plume_free(body->order);
	plume_free(body->rest);
	plume_free(body->triangles);
	plume_free(body->keyframes);
	plume_free(body->skin_bones);
	plume_free(body->skin_weights);
	plume_free(body);
}

// ---------------------------------------------------------------------------
// Accessors

int plume_body_vertex_count(const plume_body *body)
{
	PLUME_ASSERT_HANDLE(body);
	return body->vertex_count;
}

int plume_body_triangle_count(const plume_body *body)
{
	PLUME_ASSERT_HANDLE(body);
	return body->triangle_count;
}

const int *plume_body_triangles(const plume_body *body)
{
	PLUME_ASSERT_HANDLE(body);
	return body->triangles;
}

const plume_vec3 *plume_body_rest_positions(const plume_body *body)
{
	PLUME_ASSERT_HANDLE(body);
	return body->rest;
}

int plume_body_bone_count(const plume_body *body)
{
	PLUME_ASSERT_HANDLE(body);
	return body->bone_count;
}

int plume_body_find_bone(const plume_body *body, const char *name)
{
	PLUME_ASSERT_HANDLE(body);
	for (int b = 0; name != NULL && b < body->bone_count; ++b)
		if (strcmp(body->bones[b].name, name) == 0)
			return b;
	return -1;
}

const char *plume_body_bone_name(const plume_body *body, int bone)
{
	PLUME_ASSERT_HANDLE(body);
	PLUME_ASSERT_INDEX(bone, body->bone_count);
	return body->bones[bone].name;
}

// ---------------------------------------------------------------------------
// Keyframes

/// A rigid transform x -> rotation x + translation.
typedef struct rigid {
	plume_mat3 rotation;
	plume_vec3 translation;
} rigid;

static double ease(plume_interpolation interpolation, double s)
{
	return interpolation == PLUME_INTERPOLATION_SMOOTH ? s * s * (3 - 2 * s) : s;
}

typedef struct quaternion {
	double w, x, y, z;
} quaternion;

static quaternion axis_angle_quaternion(plume_vec3 unit_axis, double angle)
{
	double s = sin(angle / 2);
	return (quaternion){cos(angle / 2), s * unit_axis.x, s * unit_axis.y, s * unit_axis.z};
}

static plume_mat3 quaternion_matrix(quaternion q)
{
	double w = q.w, x = q.x, y = q.y, z = q.z;
	return (plume_mat3){{
	    {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
	    {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
	    {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
	}};
}

/// Shoemake's slerp along the shorter arc, s in [0, 1].
static quaternion slerp(quaternion a, quaternion b, double s)
{
	double dot = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
	if (dot < 0) {
		b = (quaternion){-b.w, -b.x, -b.y, -b.z};
		dot = -dot;
	}
	double wa = 1 - s, wb = s;
	if (dot < 1 - 1e-12) {
		double theta = acos(dot), sine = sin(theta);
		wa = sin((1 - s) * theta) / sine;
		wb = sin(s * theta) / sine;
	}
	quaternion q = {wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z};
	double norm = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
	return (quaternion){q.w / norm, q.x / norm, q.y / norm, q.z / norm};
}

void plume_keyframes_pose(const plume_keyframe *keys, int count, plume_interpolation interpolation, double t,
                          plume_vec3 *translation, plume_mat3 *rotation)
{
	*translation = plume_v3(0, 0, 0);
	*rotation = plume_m3_identity();
	if (count == 0)
		return;
	int k = 0;
	while (k + 1 < count && t >= keys[k + 1].time)
		++k;
	if (k + 1 == count || t <= keys[0].time) {
		// Before the first key or from the last one on: that key's pose.
		const plume_keyframe *key = t <= keys[0].time ? keys : keys + k;
		*translation = key->translation;
		if (key->angle != 0)
			*rotation = plume_m3_rotation(plume_v3_normalize(key->axis), key->angle);
		return;
	}
	const plume_keyframe *a = keys + k, *b = keys + k + 1;
	double s = ease(interpolation, (t - a->time) / (b->time - a->time));
	*translation = plume_v3_lerp(a->translation, b->translation, s);
	plume_vec3 axis_a = plume_v3_normalize(a->axis), axis_b = plume_v3_normalize(b->axis);
	double angle_a = a->angle, angle_b = b->angle;
	// A key without rotation takes the other key's axis; opposite axes are one axis with
	// the angle's sign changed. Then a shared axis interpolates the angle.
	if (angle_a == 0)
		axis_a = axis_b;
	if (angle_b == 0)
		axis_b = axis_a;
	double cosine = plume_v3_dot(axis_a, axis_b);
	if (cosine < -1 + 1e-12) {
		angle_b = -angle_b;
		axis_b = axis_a;
		cosine = 1;
	}
	if (cosine > 1 - 1e-12) {
		double angle = angle_a + s * (angle_b - angle_a);
		if (angle != 0)
			*rotation = plume_m3_rotation(axis_a, angle);
		return;
	}
	*rotation =
	    quaternion_matrix(slerp(axis_angle_quaternion(axis_a, angle_a), axis_angle_quaternion(axis_b, angle_b), s));
}

/// x -> R (x - centre) + centre + T as R x + t.
static rigid about(plume_mat3 rotation, plume_vec3 centre, plume_vec3 shift)
{
	plume_vec3 t = plume_v3_add(plume_v3_sub(centre, plume_m3_apply(rotation, centre)), shift);
	return (rigid){rotation, t};
}

/// parent o local.
static rigid compose(rigid parent, rigid local)
{
	return (rigid){plume_m3_mul(parent.rotation, local.rotation),
	               plume_v3_add(plume_m3_apply(parent.rotation, local.translation), parent.translation)};
}

static rigid body_motion(const plume_body *body, double t)
{
	plume_vec3 shift;
	plume_mat3 rotation;
	plume_keyframes_pose(body->keyframes, body->keyframe_count, body->interpolation, t, &shift, &rotation);
	return about(rotation, body->pivot, shift);
}

static rigid bone_local(const body_bone *bone, double t)
{
	plume_vec3 shift;
	plume_mat3 rotation;
	plume_keyframes_pose(bone->keyframes, bone->keyframe_count, bone->interpolation, t, &shift, &rotation);
	return about(rotation, bone->head, shift);
}

/// World transforms of every bone at t, parents first.
static void bone_worlds(const plume_body *body, double t, rigid *world)
{
	rigid root = body_motion(body, t);
	for (int i = 0; i < body->bone_count; ++i) {
		int b = body->order[i];
		int parent = body->bones[b].parent;
		world[b] = compose(parent < 0 ? root : world[parent], bone_local(body->bones + b, t));
	}
}

void plume_body_bone_transform(const plume_body *body, int bone, double t, plume_mat3 *rotation,
                               plume_vec3 *translation)
{
	PLUME_ASSERT_HANDLE(body);
	PLUME_ASSERT(bone >= -1 && bone < body->bone_count);
	PLUME_ASSERT(isfinite(t));
	// The chain from the bone up to its root, then composed from the root down.
	int chain[PLUME_BODY_MAX_BONES], depth = 0;
	for (int b = bone; b >= 0; b = body->bones[b].parent)
		chain[depth++] = b;
	rigid world = body_motion(body, t);
	while (depth > 0) {
		int b = chain[--depth];
		world = compose(world, bone_local(body->bones + b, t));
	}
	*rotation = world.rotation;
	*translation = world.translation;
}

void plume_body_pose(const plume_body *body, double t, plume_vec3 *out)
{
	PLUME_ASSERT_HANDLE(body);
	PLUME_ASSERT(out != NULL && isfinite(t));
	if (body->bone_count == 0) {
		rigid motion = body_motion(body, t);
		for (int v = 0; v < body->vertex_count; ++v)
			out[v] = plume_v3_add(plume_m3_apply(motion.rotation, body->rest[v]), motion.translation);
		return;
	}
	rigid world[PLUME_BODY_MAX_BONES];
	bone_worlds(body, t, world);
	// Linear blend skinning: x = sum_i w_i (R_i x_rest + t_i).
	for (int v = 0; v < body->vertex_count; ++v) {
		const int *bones = body->skin_bones + PLUME_BODY_MAX_INFLUENCES * v;
		const double *weights = body->skin_weights + PLUME_BODY_MAX_INFLUENCES * v;
		plume_vec3 sum = {0, 0, 0};
		for (int i = 0; i < PLUME_BODY_MAX_INFLUENCES && bones[i] >= 0; ++i) {
			const rigid *m = world + bones[i];
			sum =
			    plume_v3_mad(sum, weights[i], plume_v3_add(plume_m3_apply(m->rotation, body->rest[v]), m->translation));
		}
		out[v] = sum;
	}
}

// ---------------------------------------------------------------------------
// Queries on the rest surface

double plume_body_rest_distance(const plume_body *body, plume_vec3 point, int *triangle)
{
	PLUME_ASSERT_HANDLE(body);
	double best = INFINITY;
	int nearest = 0;
	for (int f = 0; f < body->triangle_count; ++f) {
		const int *t = body->triangles + 3 * f;
		double d2 = plume_point_triangle_distance2(point, body->rest[t[0]], body->rest[t[1]], body->rest[t[2]], NULL);
		if (d2 < best) {
			best = d2;
			nearest = f;
		}
	}
	if (triangle != NULL)
		*triangle = nearest;
	return sqrt(best);
}

int plume_body_nearest_bone(const plume_body *body, plume_vec3 point)
{
	PLUME_ASSERT_HANDLE(body);
	if (body->bone_count == 0)
		return -1;
	int triangle;
	plume_body_rest_distance(body, point, &triangle);
	double sum[PLUME_BODY_MAX_BONES] = {0};
	for (int k = 0; k < 3; ++k) {
		int v = body->triangles[3 * triangle + k];
		for (int i = 0; i < PLUME_BODY_MAX_INFLUENCES; ++i) {
			int b = body->skin_bones[PLUME_BODY_MAX_INFLUENCES * v + i];
			if (b >= 0)
				sum[b] += body->skin_weights[PLUME_BODY_MAX_INFLUENCES * v + i];
		}
	}
	int best = 0;
	for (int b = 1; b < body->bone_count; ++b)
		if (sum[b] > sum[best])
			best = b;
	return best;
}

// ---------------------------------------------------------------------------
// Built-in shapes

/// A surface of revolution about the axis `d` through `origin` (frame u, v, d right-handed):
/// a pole at height z_south, rings k = 0 .. ring_count - 1 at heights z[k] with radii rho[k],
/// and a pole at z_north, `segments` vertices per ring. Triangles counter-clockwise seen
/// from outside (the normal of (ring k, j), (ring k, j + 1), (ring k + 1, j + 1) points away
/// from the axis for rings of equal radius, and along -d at the south cap).
static plume_status lathe(plume_vec3 origin, plume_vec3 u, plume_vec3 v, plume_vec3 d, double z_south, double z_north,
                          int ring_count, const double *z, const double *rho, int segments, plume_body_mesh *out,
                          plume_error *err)
{
	int vertex_count = 2 + ring_count * segments;
	int triangle_count = 2 * segments * ring_count;
	out->vertices = plume_calloc((size_t)vertex_count, sizeof *out->vertices);
	out->triangles = plume_calloc((size_t)triangle_count * 3, sizeof *out->triangles);
	if (out->vertices == NULL || out->triangles == NULL) {
		plume_body_mesh_free(out);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory meshing a body shape");
	}
	out->vertex_count = vertex_count;
	out->triangle_count = triangle_count;
	const double two_pi = 2 * acos(-1.0);
	int south = 0, north = vertex_count - 1;
	out->vertices[south] = plume_v3_mad(origin, z_south, d);
	out->vertices[north] = plume_v3_mad(origin, z_north, d);
	for (int k = 0; k < ring_count; ++k)
		for (int j = 0; j < segments; ++j) {
			double phi = two_pi * j / segments;
			plume_vec3 radial = plume_v3_add(plume_v3_scale(u, cos(phi)), plume_v3_scale(v, sin(phi)));
			out->vertices[1 + k * segments + j] = plume_v3_mad(plume_v3_mad(origin, z[k], d), rho[k], radial);
		}
	int *t = out->triangles;
	for (int j = 0; j < segments; ++j) {
		int j1 = (j + 1) % segments;
		*t++ = south, *t++ = 1 + j1, *t++ = 1 + j;
	}
	for (int k = 0; k + 1 < ring_count; ++k)
		for (int j = 0; j < segments; ++j) {
			int j1 = (j + 1) % segments;
			int a = 1 + k * segments + j, b = 1 + k * segments + j1;
			int c = b + segments, e = a + segments;
			*t++ = a, *t++ = b, *t++ = c;
			*t++ = a, *t++ = c, *t++ = e;
		}
	int last = 1 + (ring_count - 1) * segments;
	for (int j = 0; j < segments; ++j) {
		int j1 = (j + 1) % segments;
		*t++ = last + j, *t++ = last + j1, *t++ = north;
	}
	return PLUME_OK;
}

void plume_body_mesh_free(plume_body_mesh *mesh)
{
	if (mesh == NULL)
		return;
	plume_free(mesh->vertices);
	plume_free(mesh->triangles);
	*mesh = (plume_body_mesh){0};
}

static bool positive_length(double x) { return isfinite(x) && x > 0 && x <= 1e12; }

plume_status plume_body_ellipsoid(plume_vec3 center, plume_vec3 radii, int segments, plume_body_mesh *out,
                                  plume_error *err)
{
	PLUME_ASSERT(out != NULL);
	*out = (plume_body_mesh){0};
	if (!(positive_length(radii.x) && positive_length(radii.y) && positive_length(radii.z)))
		return plume_error_set(err, PLUME_ERROR_SPEC, "radii: (%g, %g, %g); allowed finite and > 0 (m)", radii.x,
		                       radii.y, radii.z);
	if (!finite3(center))
		return plume_error_set(err, PLUME_ERROR_SPEC, "center: is not finite");
	if (segments < 3 || segments > 4096)
		return plume_error_set(err, PLUME_ERROR_SPEC, "segments: is %d; allowed 3 to 4096", segments);
	int bands = segments / 2 > 2 ? segments / 2 : 2;
	double z[2048], rho[2048];
	const double pi = acos(-1.0);
	for (int k = 0; k + 1 < bands; ++k) {
		double theta = pi * (k + 1) / bands; // polar angle from the -z pole
		z[k] = -cos(theta);
		rho[k] = sin(theta);
	}
	// The unit sphere, then scaled per axis (a positive scaling keeps the orientation).
	plume_status status = lathe(plume_v3(0, 0, 0), plume_v3(1, 0, 0), plume_v3(0, 1, 0), plume_v3(0, 0, 1), -1, 1,
	                            bands - 1, z, rho, segments, out, err);
	for (int i = 0; status == PLUME_OK && i < out->vertex_count; ++i) {
		plume_vec3 p = out->vertices[i];
		out->vertices[i] = plume_v3(center.x + radii.x * p.x, center.y + radii.y * p.y, center.z + radii.z * p.z);
	}
	return status;
}

plume_status plume_body_capsule(plume_vec3 a, plume_vec3 b, double radius, int segments, plume_body_mesh *out,
                                plume_error *err)
{
	PLUME_ASSERT(out != NULL);
	*out = (plume_body_mesh){0};
	if (!positive_length(radius))
		return plume_error_set(err, PLUME_ERROR_SPEC, "radius: is %g; allowed finite and > 0 (m)", radius);
	if (!finite3(a) || !finite3(b))
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: is not finite", finite3(a) ? "b" : "a");
	double length = plume_v3_distance(a, b);
	if (!(length > 0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "b: equals a; a capsule needs an axis of non-zero length");
	if (segments < 3 || segments > 4096)
		return plume_error_set(err, PLUME_ERROR_SPEC, "segments: is %d; allowed 3 to 4096", segments);
	plume_vec3 d = plume_v3_scale(plume_v3_sub(b, a), 1 / length);
	// u: perpendicular to d, from the coordinate axis least aligned with it; v = d x u.
	plume_vec3 e = fabs(d.x) <= fabs(d.y) && fabs(d.x) <= fabs(d.z) ? plume_v3(1, 0, 0)
	               : fabs(d.y) <= fabs(d.z)                         ? plume_v3(0, 1, 0)
	                                                                : plume_v3(0, 0, 1);
	plume_vec3 u = plume_v3_normalize(plume_v3_cross(d, e));
	plume_vec3 v = plume_v3_cross(d, u);
	int cap = segments / 4 > 1 ? segments / 4 : 1;
	// Bands along the cylinder no longer than the edges around it (2 pi r / segments), so
	// that a capsule skinned to a chain of bones bends between rings.
	double along = ceil(length * segments / (2 * acos(-1.0) * radius));
	int cylinder = along < 1 ? 1 : along > 4096 ? 4096 : (int)along;
	double *z = plume_alloc(sizeof(double) * (size_t)(2 * cap + cylinder));
	double *rho = plume_alloc(sizeof(double) * (size_t)(2 * cap + cylinder));
	if (z == NULL || rho == NULL) {
		plume_free(z);
		plume_free(rho);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory meshing a capsule");
	}
	const double half_pi = acos(-1.0) / 2;
	int rings = 0;
	for (int k = 1; k <= cap; ++k) { // the cap at a, up to its equator
		double theta = half_pi * k / cap;
		z[rings] = k == cap ? 0 : -radius * cos(theta);
		rho[rings++] = k == cap ? radius : radius * sin(theta);
	}
	for (int k = 1; k < cylinder; ++k) { // the cylinder's inner rings
		z[rings] = length * k / cylinder;
		rho[rings++] = radius;
	}
	for (int k = 0; k < cap; ++k) { // the cap at b, from its equator
		double theta = half_pi * k / cap;
		z[rings] = length + radius * sin(theta);
		rho[rings++] = radius * cos(theta);
	}
	plume_status status = lathe(a, u, v, d, -radius, length + radius, rings, z, rho, segments, out, err);
	plume_free(z);
	plume_free(rho);
	return status;
}

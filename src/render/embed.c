// Barb-level feathers carried by a shell: embedding and reconstruction (see include/plume/embed.h).
//
// The nearest triangle of each point is found with an Embree point query
// (the BVH prunes by the current best distance; distances are computed in
// double precision, ties go to the lower face index, so the result does not
// depend on the traversal order or the thread count). The point is then
// written in that triangle's affine frame: barycentric coordinates of its
// projection on the plane (which may lie outside the triangle, near the
// shell's border) and the height above the plane. The reconstruction
// evaluates the same affine map on the deformed triangle, so the rest shell
// returns every point to rounding.
#include <math.h>
#include <string.h>

#include <embree3/rtcore.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "model/feather_internal.h"
#include "plume/embed.h"

typedef struct anchor {
	int face;
	double b1, b2; ///< barycentric coordinates of the projection for vertices 1 and 2 (b0 = 1 - b1 - b2)
	double h;      ///< height above the triangle's plane along its unit normal, m
} anchor;

/// A direction in a triangle's orthonormal frame (e1 along edge 0-1, e2 in the plane, n the normal).
typedef struct frame_coords {
	double c[3];
} frame_coords;

struct plume_barb_embedding {
	uint32_t magic;         ///< PLUME_HANDLE_MAGIC while alive (core/asserts.h)
	plume_feather *feather; ///< a copy of the rest feather: the template of every rebuilt one
	const plume_mesh *mesh;
	int first_face, face_count; ///< the faces the points are embedded in: [first_face, first_face + face_count)
	int point_count;
	anchor *anchors; ///< shaft samples then pool points, feather then afterfeather
	/// Per shaft sample: tangent, normal; per pool point: normal (same order as anchors).
	frame_coords *directions;
	int direction_count;
	double max_offset;
};

typedef struct triangle_frame {
	plume_vec3 origin, e1, e2, n;
	bool valid;
} triangle_frame;

static triangle_frame make_frame(const plume_vec3 *x, const int *face)
{
	plume_vec3 a = x[face[0]], b = x[face[1]], c = x[face[2]];
	plume_vec3 n = plume_v3_cross(plume_v3_sub(b, a), plume_v3_sub(c, a));
	triangle_frame f = {.origin = a};
	double area2 = plume_v3_length(n), edge = plume_v3_length(plume_v3_sub(b, a));
	f.valid = area2 > 0.0 && edge > 0.0 && isfinite(area2);
	if (!f.valid)
		return f;
	f.n = plume_v3_scale(n, 1.0 / area2);
	f.e1 = plume_v3_scale(plume_v3_sub(b, a), 1.0 / edge);
	f.e2 = plume_v3_cross(f.n, f.e1);
	return f;
}

/// Squared distance from p to the triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
static double triangle_distance2(plume_vec3 p, plume_vec3 a, plume_vec3 b, plume_vec3 c)
{
	plume_vec3 ab = plume_v3_sub(b, a), ac = plume_v3_sub(c, a), ap = plume_v3_sub(p, a);
	double d1 = plume_v3_dot(ab, ap), d2 = plume_v3_dot(ac, ap);
	plume_vec3 q;
	if (d1 <= 0.0 && d2 <= 0.0) {
		q = a;
	} else {
		plume_vec3 bp = plume_v3_sub(p, b);
		double d3 = plume_v3_dot(ab, bp), d4 = plume_v3_dot(ac, bp);
		plume_vec3 cp = plume_v3_sub(p, c);
		double d5 = plume_v3_dot(ab, cp), d6 = plume_v3_dot(ac, cp);
		double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
		if (d3 >= 0.0 && d4 <= d3)
			q = b;
		else if (d6 >= 0.0 && d5 <= d6)
			q = c;
		else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
			q = plume_v3_mad(a, d1 / (d1 - d3), ab);
		else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
			q = plume_v3_mad(a, d2 / (d2 - d6), ac);
		else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
			q = plume_v3_mad(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), plume_v3_sub(c, b));
		else {
			double denom = 1.0 / (va + vb + vc);
			q = plume_v3_add(a, plume_v3_add(plume_v3_scale(ab, vb * denom), plume_v3_scale(ac, vc * denom)));
		}
	}
	plume_vec3 d = plume_v3_sub(p, q);
	return plume_v3_dot(d, d);
}

typedef struct nearest_query {
	const plume_mesh *mesh;
	int first_face;               ///< Embree's primID k is face first_face + k
	const triangle_frame *frames; ///< per face of the range (index primID)
	plume_vec3 p;
	double best2;
	int best_face;
} nearest_query;

static bool visit_triangle(struct RTCPointQueryFunctionArguments *args)
{
	nearest_query *q = args->userPtr;
	int face = q->first_face + (int)args->primID;
	if (!q->frames[args->primID].valid)
		return false;
	const int *f = q->mesh->faces + 3 * face;
	double d2 = triangle_distance2(q->p, q->mesh->rest[f[0]], q->mesh->rest[f[1]], q->mesh->rest[f[2]]);
	if (d2 < q->best2 || (d2 == q->best2 && face < q->best_face)) {
		q->best2 = d2;
		q->best_face = face;
		// Shrink the search (a float radius slightly above the double distance never excludes a tie).
		float radius = (float)(sqrt(d2) * (1.0 + 1e-6) + 1e-12);
		if (radius < args->query->radius) {
			args->query->radius = radius;
			return true;
		}
	}
	return false;
}

static anchor embed_point(RTCScene scene, const plume_mesh *mesh, int first_face, const triangle_frame *frames,
                          plume_vec3 p)
{
	nearest_query q = {mesh, first_face, frames, p, INFINITY, -1};
	struct RTCPointQuery query = {.x = (float)p.x, .y = (float)p.y, .z = (float)p.z, .time = 0.0f, .radius = INFINITY};
	struct RTCPointQueryContext context;
	rtcInitPointQueryContext(&context);
	rtcPointQuery(scene, &query, &context, visit_triangle, &q);
	anchor a = {q.best_face, 0.0, 0.0, 0.0};
	if (q.best_face < 0)
		return a;
	const int *f = mesh->faces + 3 * q.best_face;
	plume_vec3 x0 = mesh->rest[f[0]];
	plume_vec3 v0 = plume_v3_sub(mesh->rest[f[1]], x0), v1 = plume_v3_sub(mesh->rest[f[2]], x0);
	const plume_vec3 n = frames[q.best_face - first_face].n;
	a.h = plume_v3_dot(plume_v3_sub(p, x0), n);
	plume_vec3 w = plume_v3_mad(plume_v3_sub(p, x0), -a.h, n);
	double d00 = plume_v3_dot(v0, v0), d01 = plume_v3_dot(v0, v1), d11 = plume_v3_dot(v1, v1);
	double d20 = plume_v3_dot(w, v0), d21 = plume_v3_dot(w, v1);
	double denom = d00 * d11 - d01 * d01;
	a.b1 = (d11 * d20 - d01 * d21) / denom;
	a.b2 = (d00 * d21 - d01 * d20) / denom;
	return a;
}

static frame_coords to_frame(const triangle_frame *f, plume_vec3 d)
{
	return (frame_coords){{plume_v3_dot(d, f->e1), plume_v3_dot(d, f->e2), plume_v3_dot(d, f->n)}};
}

static plume_vec3 from_frame(const triangle_frame *f, frame_coords c)
{
	return plume_v3_mad(plume_v3_mad(plume_v3_scale(f->e1, c.c[0]), c.c[1], f->e2), c.c[2], f->n);
}

/// Counts the points and directions of a feather and its afterfeathers.
static void count_points(const plume_feather *f, int *points, int *directions)
{
	for (; f != NULL; f = f->afterfeather) {
		*points += f->shaft_count + f->point_count;
		*directions += 2 * f->shaft_count + f->point_count;
	}
}

int plume_embedding_point_count(const plume_barb_embedding *embedding)
{
	PLUME_ASSERT_HANDLE(embedding);
	return embedding->point_count;
}

double plume_embedding_max_offset(const plume_barb_embedding *embedding)
{
	PLUME_ASSERT_HANDLE(embedding);
	return embedding->max_offset;
}

void plume_embedding_destroy(plume_barb_embedding *embedding)
{
	if (embedding == NULL)
		return;
	PLUME_ASSERT_HANDLE(embedding);
	embedding->magic = 0;
	plume_feather_destroy(embedding->feather);
	plume_free(embedding->anchors);
	plume_free(embedding->directions);
	plume_free(embedding);
}

/// Rest frames of the faces [first, first + count) (index: face - first); PLUME_ERROR_SPEC when none is usable.
static plume_status rest_frames(const plume_mesh *mesh, int first, int count, triangle_frame **out, plume_error *err)
{
	if (count <= 0)
		return plume_error_set(err, PLUME_ERROR_SPEC, "embedding: the shell has no faces");
	triangle_frame *frames = plume_alloc((size_t)count * sizeof *frames);
	if (frames == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "embedding: out of memory");
	int valid = 0;
	for (int i = 0; i < count; ++i) {
		const int *face = mesh->faces + 3 * (first + i);
		for (int k = 0; k < 3; ++k)
			PLUME_ASSERT(face[k] >= 0 && face[k] < mesh->vertex_count);
		frames[i] = make_frame(mesh->rest, face);
		valid += frames[i].valid;
	}
	if (valid == 0) {
		plume_free(frames);
		return plume_error_set(err, PLUME_ERROR_SPEC, "embedding: every face of the shell is degenerate");
	}
	*out = frames;
	return PLUME_OK;
}

/// A BVH of the faces [first, first + count) over all of the mesh's vertices (primID k: face first + k).
static RTCScene build_scene(RTCDevice device, const plume_mesh *mesh, int first, int count)
{
	RTCScene scene = rtcNewScene(device);
	RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
	float *vertices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
	                                          (size_t)mesh->vertex_count);
	unsigned *indices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
	                                            3 * sizeof(unsigned), (size_t)count);
	if (vertices == NULL || indices == NULL) {
		rtcReleaseGeometry(geometry);
		rtcReleaseScene(scene);
		return NULL;
	}
	for (int i = 0; i < mesh->vertex_count; ++i) {
		vertices[3 * i + 0] = (float)mesh->rest[i].x;
		vertices[3 * i + 1] = (float)mesh->rest[i].y;
		vertices[3 * i + 2] = (float)mesh->rest[i].z;
	}
	for (int i = 0; i < 3 * count; ++i)
		indices[i] = (unsigned)mesh->faces[3 * first + i];
	rtcCommitGeometry(geometry);
	rtcAttachGeometry(scene, geometry);
	rtcReleaseGeometry(geometry);
	rtcCommitScene(scene);
	return scene;
}

plume_status plume_embedding_create(const plume_feather *feather, const plume_mesh *mesh, plume_barb_embedding **out,
                                    plume_error *err)
{
	PLUME_ASSERT(mesh != NULL);
	return plume_embedding_create_faces(feather, mesh, 0, mesh->face_count, out, err);
}

plume_status plume_embedding_create_faces(const plume_feather *feather, const plume_mesh *mesh, int first_face,
                                          int face_count, plume_barb_embedding **out, plume_error *err)
{
	PLUME_ASSERT_HANDLE(feather);
	PLUME_ASSERT(mesh != NULL && out != NULL);
	PLUME_ASSERT(first_face >= 0 && face_count >= 0 && first_face + face_count <= mesh->face_count);
	*out = NULL;
	triangle_frame *frames = NULL;
	plume_status status = rest_frames(mesh, first_face, face_count, &frames, err);
	if (status != PLUME_OK)
		return status;
	plume_barb_embedding *e = plume_calloc(1, sizeof *e);
	int points = 0, directions = 0;
	count_points(feather, &points, &directions);
	if (e != NULL) {
		e->magic = PLUME_HANDLE_MAGIC;
		e->mesh = mesh;
		e->first_face = first_face;
		e->face_count = face_count;
		e->point_count = points;
		e->direction_count = directions;
		e->feather = plume_feather_clone(feather);
		e->anchors = plume_alloc((size_t)(points > 0 ? points : 1) * sizeof *e->anchors);
		e->directions = plume_alloc((size_t)(directions > 0 ? directions : 1) * sizeof *e->directions);
	}
	RTCDevice device = rtcNewDevice(NULL);
	RTCScene scene = device != NULL ? build_scene(device, mesh, first_face, face_count) : NULL;
	if (e == NULL || e->feather == NULL || e->anchors == NULL || e->directions == NULL || scene == NULL) {
		if (scene != NULL)
			rtcReleaseScene(scene);
		if (device != NULL)
			rtcReleaseDevice(device);
		plume_free(frames);
		plume_embedding_destroy(e);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "embedding: out of memory");
	}
	// Flat lists of the points and directions to embed, in a fixed order.
	int point = 0, direction = 0;
	for (const plume_feather *f = feather; f != NULL; f = f->afterfeather) {
		int first_point = point;
		for (int i = 0; i < f->shaft_count; ++i)
			e->anchors[point++] = embed_point(scene, mesh, first_face, frames, f->shaft[i].position);
#pragma omp parallel for schedule(static)
		for (int i = 0; i < f->point_count; ++i)
			e->anchors[point + i] = embed_point(scene, mesh, first_face, frames, f->points[i]);
		point += f->point_count;
		// A point with no nearest face (a coordinate Embree's float query cannot
		// hold, or NaN) has no frame to carry it: refuse rather than index frames[-1].
		for (int i = first_point; i < point; ++i) {
			if (e->anchors[i].face < 0) {
				rtcReleaseScene(scene);
				rtcReleaseDevice(device);
				plume_free(frames);
				plume_embedding_destroy(e);
				return plume_error_set(err, PLUME_ERROR_SPEC,
				                       "embedding: point %d of the feather lies on no face of the shell "
				                       "(a coordinate not finite in single precision)",
				                       i);
			}
		}
		for (int i = 0; i < f->shaft_count; ++i) {
			const triangle_frame *fr = frames + e->anchors[first_point + i].face - first_face;
			e->directions[direction++] = to_frame(fr, f->shaft[i].tangent);
			e->directions[direction++] = to_frame(fr, f->shaft[i].normal);
		}
		for (int i = 0; i < f->point_count; ++i) {
			const triangle_frame *fr = frames + e->anchors[first_point + f->shaft_count + i].face - first_face;
			e->directions[direction++] = to_frame(fr, f->normals[i]);
		}
	}
	for (int i = 0; i < points; ++i) {
		const anchor *a = e->anchors + i;
		const int *face = mesh->faces + 3 * a->face;
		// Distance to the triangle itself, not just to its plane.
		plume_vec3 p = plume_v3_add(plume_v3_add(plume_v3_scale(mesh->rest[face[0]], 1.0 - a->b1 - a->b2),
		                                         plume_v3_add(plume_v3_scale(mesh->rest[face[1]], a->b1),
		                                                      plume_v3_scale(mesh->rest[face[2]], a->b2))),
		                            plume_v3_scale(frames[a->face - first_face].n, a->h));
		double d = sqrt(triangle_distance2(p, mesh->rest[face[0]], mesh->rest[face[1]], mesh->rest[face[2]]));
		e->max_offset = fmax(e->max_offset, d);
	}
	rtcReleaseScene(scene);
	rtcReleaseDevice(device);
	plume_free(frames);
	*out = e;
	return PLUME_OK;
}

/// The embedded point on the shell at x.
static plume_vec3 place(const plume_mesh *mesh, const plume_vec3 *x, const triangle_frame *frame, anchor a)
{
	const int *f = mesh->faces + 3 * a.face;
	plume_vec3 p = plume_v3_scale(x[f[0]], 1.0 - a.b1 - a.b2);
	p = plume_v3_mad(p, a.b1, x[f[1]]);
	p = plume_v3_mad(p, a.b2, x[f[2]]);
	return plume_v3_mad(p, a.h, frame->n);
}

static void measure(plume_feather *f, plume_curve_range range)
{
	double *arc = f->arc_length + range.first;
	const plume_vec3 *p = f->points + range.first;
	arc[0] = 0.0;
	for (int i = 1; i < range.count; ++i)
		arc[i] = arc[i - 1] + plume_v3_distance(p[i - 1], p[i]);
}

plume_status plume_embedding_apply(const plume_barb_embedding *embedding, const plume_vec3 *positions,
                                   plume_feather **out, plume_error *err)
{
	PLUME_ASSERT_HANDLE(embedding);
	PLUME_ASSERT(positions != NULL && out != NULL);
	*out = NULL;
	const plume_mesh *mesh = embedding->mesh;
	for (int i = 0; i < mesh->vertex_count; ++i)
		if (!isfinite(positions[i].x) || !isfinite(positions[i].y) || !isfinite(positions[i].z))
			return plume_error_set(err, PLUME_ERROR_NUMERIC, "embedding: shell vertex %d is not finite", i);
	const int first = embedding->first_face;
	triangle_frame *frames =
	    plume_alloc((size_t)(embedding->face_count > 0 ? embedding->face_count : 1) * sizeof *frames);
	plume_feather *moved = plume_feather_clone(embedding->feather);
	if (frames == NULL || moved == NULL) {
		plume_free(frames);
		plume_feather_destroy(moved);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "embedding: out of memory");
	}
	for (int i = 0; i < embedding->face_count; ++i)
		frames[i] = make_frame(positions, mesh->faces + 3 * (first + i));
	int point = 0, direction = 0;
	for (plume_feather *f = moved; f != NULL; f = f->afterfeather) {
		for (int i = 0; i < f->shaft_count; ++i, ++point) {
			anchor a = embedding->anchors[point];
			const triangle_frame *fr = frames + a.face - first;
			plume_shaft_sample *s = f->shaft + i;
			s->position = place(mesh, positions, fr, a);
			plume_vec3 t = plume_v3_normalize(from_frame(fr, embedding->directions[direction++]));
			plume_vec3 n = from_frame(fr, embedding->directions[direction++]);
			n = plume_v3_normalize(plume_v3_mad(n, -plume_v3_dot(n, t), t));
			s->tangent = t;
			s->normal = n;
			s->binormal = plume_v3_cross(n, t);
		}
		for (int i = 0; i < f->point_count; ++i, ++point) {
			anchor a = embedding->anchors[point];
			const triangle_frame *fr = frames + a.face - first;
			f->points[i] = place(mesh, positions, fr, a);
			f->normals[i] = plume_v3_normalize(from_frame(fr, embedding->directions[direction++]));
		}
		for (int i = 0; i < f->barb_count; ++i)
			measure(f, f->barbs[i].curve);
		for (int i = 0; i < f->barbule_count; ++i)
			measure(f, f->barbules[i].curve);
	}
	plume_free(frames);
	*out = moved;
	return PLUME_OK;
}

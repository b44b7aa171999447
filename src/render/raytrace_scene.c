// The Embree scene of a render: feathers as curves, the shell as triangles.
//
// Barbs are normal-oriented Catmull-Rom ribbons: the curve passes through
// every barb point, its width is the barb's width there, and it faces the
// barb's normal (the vane normal), so a vane seen from the front shows the
// barbs' full widths and seen edge-on almost nothing. The shaft is a chain of
// round cones whose radius follows the shaft's width; barbules are thin
// ray-facing strips. Textured barbs lose the segments whose texel is a hole.
#include <assert.h>
#include <math.h>
#include <string.h>

#include "core/alloc.h"
#include "render/raytrace_internal.h"

static plume_status embree_error(RTCDevice device, const char *what, plume_error *err)
{
	enum RTCError code = rtcGetDeviceError(device);
	return plume_error_set(err, code == RTC_ERROR_OUT_OF_MEMORY ? PLUME_ERROR_MEMORY : PLUME_ERROR_UNSUPPORTED,
	                       "raytrace: Embree could not %s (error %d)", what, (int)code);
}

/// Appends a geometry record; its index is its Embree geometry ID.
static rt_geometry *add_geometry(rt_scene *s, rt_kind kind, const plume_feather *feather, int segment_count,
                                 plume_error *err)
{
	if (PLUME_GROW(s->geometries, s->geometry_capacity, s->geometry_count + 1) != 0) {
		plume_error_set(err, PLUME_ERROR_MEMORY, "raytrace: out of memory");
		return NULL;
	}
	rt_geometry *g = s->geometries + s->geometry_count;
	memset(g, 0, sizeof *g);
	g->kind = kind;
	g->feather = feather;
	if (segment_count > 0) {
		g->segments = plume_alloc((size_t)segment_count * sizeof *g->segments);
		if (g->segments == NULL) {
			plume_error_set(err, PLUME_ERROR_MEMORY, "raytrace: out of memory");
			return NULL;
		}
	}
	s->geometry_count++;
	return g;
}

/// Commits g's Embree geometry and attaches it under its record index.
static plume_status attach(rt_scene *s, rt_geometry *g, plume_error *err)
{
	rtcCommitGeometry(g->handle);
	unsigned id = (unsigned)(g - s->geometries);
	rtcAttachGeometryByID(s->scene, g->handle, id);
	if (rtcGetDeviceError(s->device) != RTC_ERROR_NONE)
		return embree_error(s->device, "attach a geometry", err);
	return PLUME_OK;
}

/// Whether the barb segment [j, j + 1] is kept: with a texture, its midpoint texel must not be a hole
/// (the same per-segment rule as the Cairo renderer's textured barbs).
static bool segment_visible(const plume_texture *texture, const plume_barb *barb, int j)
{
	if (texture == NULL)
		return true;
	const plume_vec2 *uv = barb->curve.uv;
	plume_color c =
	    plume_texture_sample_vane(texture, barb->side, 0.5 * (uv[j].x + uv[j + 1].x), 0.5 * (uv[j].y + uv[j + 1].y));
	return c.a >= 0.5;
}

static plume_status add_barbs(rt_scene *s, const plume_feather *feather, plume_error *err)
{
	plume_feather_info info = plume_feather_get_info(feather);
	int vertex_count = 0, segment_count = 0;
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		if (barb.curve.count < 2)
			continue;
		vertex_count += barb.curve.count + 2;
		for (int j = 0; j + 1 < barb.curve.count; ++j)
			segment_count += segment_visible(s->texture, &barb, j);
	}
	if (segment_count == 0)
		return PLUME_OK;
	rt_geometry *g = add_geometry(s, RT_BARBS, feather, segment_count, err);
	if (g == NULL)
		return PLUME_ERROR_MEMORY;
	g->handle = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_CATMULL_ROM_CURVE);
	float *vertices = rtcSetNewGeometryBuffer(g->handle, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
	                                          4 * sizeof(float), (size_t)vertex_count);
	float *normals = rtcSetNewGeometryBuffer(g->handle, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
	                                         (size_t)vertex_count);
	unsigned *indices = rtcSetNewGeometryBuffer(g->handle, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned),
	                                            (size_t)segment_count);
	if (vertices == NULL || normals == NULL || indices == NULL)
		return embree_error(s->device, "allocate barb buffers", err);
	int vertex = 0, segment = 0;
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		int n = barb.curve.count;
		if (n < 2)
			continue;
		// Control points p0, p0, p1, ..., p(n-1), p(n-1): the Catmull-Rom curve passes through every point
		// and segment j (from p_j to p_j+1) starts at control point j.
		for (int k = -1; k <= n; ++k) {
			int p = k < 0 ? 0 : (k >= n ? n - 1 : k);
			float *v = vertices + 4 * (size_t)(vertex + k + 1);
			v[0] = (float)barb.curve.points[p].x;
			v[1] = (float)barb.curve.points[p].y;
			v[2] = (float)barb.curve.points[p].z;
			v[3] = (float)(0.5 * barb.curve.widths[p]);
			float *nn = normals + 3 * (size_t)(vertex + k + 1);
			nn[0] = (float)barb.curve.normals[p].x;
			nn[1] = (float)barb.curve.normals[p].y;
			nn[2] = (float)barb.curve.normals[p].z;
		}
		for (int j = 0; j + 1 < n; ++j) {
			if (!segment_visible(s->texture, &barb, j))
				continue;
			indices[segment] = (unsigned)(vertex + j);
			g->segments[segment] = (rt_segment){i, j};
			segment++;
		}
		vertex += n + 2;
	}
	g->segment_count = segment_count;
	s->curve_segments += segment_count;
	return attach(s, g, err);
}

static plume_status add_shaft(rt_scene *s, const plume_feather *feather, plume_error *err)
{
	plume_feather_info info = plume_feather_get_info(feather);
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	int n = info.shaft_sample_count;
	if (n < 2)
		return PLUME_OK;
	// With a texture the shaft takes the colour at the rachis; a hole there removes the segment.
	int segment_count = 0;
	for (int j = 0; j + 1 < n; ++j) {
		double t = 0.5 * (shaft[j].t + shaft[j + 1].t);
		segment_count += s->texture == NULL || plume_texture_sample_vane(s->texture, PLUME_SIDE_RIGHT, 0.0, t).a >= 0.5;
	}
	if (segment_count == 0)
		return PLUME_OK;
	rt_geometry *g = add_geometry(s, RT_SHAFT, feather, segment_count, err);
	if (g == NULL)
		return PLUME_ERROR_MEMORY;
	g->handle = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
	float *vertices =
	    rtcSetNewGeometryBuffer(g->handle, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), (size_t)n);
	unsigned *indices = rtcSetNewGeometryBuffer(g->handle, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned),
	                                            (size_t)segment_count);
	if (vertices == NULL || indices == NULL)
		return embree_error(s->device, "allocate shaft buffers", err);
	for (int k = 0; k < n; ++k) {
		vertices[4 * k + 0] = (float)shaft[k].position.x;
		vertices[4 * k + 1] = (float)shaft[k].position.y;
		vertices[4 * k + 2] = (float)shaft[k].position.z;
		vertices[4 * k + 3] = (float)(0.5 * shaft[k].width);
	}
	int segment = 0;
	for (int j = 0; j + 1 < n; ++j) {
		double t = 0.5 * (shaft[j].t + shaft[j + 1].t);
		if (s->texture != NULL && plume_texture_sample_vane(s->texture, PLUME_SIDE_RIGHT, 0.0, t).a < 0.5)
			continue;
		indices[segment] = (unsigned)j;
		g->segments[segment] = (rt_segment){0, j};
		segment++;
	}
	g->segment_count = segment_count;
	s->curve_segments += segment_count;
	return attach(s, g, err);
}

static plume_status add_barbules(rt_scene *s, const plume_feather *feather, plume_error *err)
{
	plume_feather_info info = plume_feather_get_info(feather);
	int vertex_count = 0, segment_count = 0;
	for (int i = 0; i < info.barbule_count; ++i) {
		plume_barbule b = plume_feather_barbule(feather, i);
		if (b.curve.count >= 2) {
			vertex_count += b.curve.count;
			segment_count += b.curve.count - 1;
		}
	}
	if (segment_count == 0)
		return PLUME_OK;
	rt_geometry *g = add_geometry(s, RT_BARBULES, feather, segment_count, err);
	if (g == NULL)
		return PLUME_ERROR_MEMORY;
	g->handle = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_FLAT_LINEAR_CURVE);
	float *vertices = rtcSetNewGeometryBuffer(g->handle, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
	                                          4 * sizeof(float), (size_t)vertex_count);
	unsigned *indices = rtcSetNewGeometryBuffer(g->handle, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned),
	                                            (size_t)segment_count);
	if (vertices == NULL || indices == NULL)
		return embree_error(s->device, "allocate barbule buffers", err);
	int vertex = 0, segment = 0;
	for (int i = 0; i < info.barbule_count; ++i) {
		plume_barbule b = plume_feather_barbule(feather, i);
		if (b.curve.count < 2)
			continue;
		for (int k = 0; k < b.curve.count; ++k) {
			float *v = vertices + 4 * (size_t)(vertex + k);
			v[0] = (float)b.curve.points[k].x;
			v[1] = (float)b.curve.points[k].y;
			v[2] = (float)b.curve.points[k].z;
			v[3] = (float)(0.5 * b.curve.widths[k]);
		}
		for (int j = 0; j + 1 < b.curve.count; ++j) {
			indices[segment] = (unsigned)(vertex + j);
			g->segments[segment] = (rt_segment){i, j};
			segment++;
		}
		vertex += b.curve.count;
	}
	g->segment_count = segment_count;
	s->curve_segments += segment_count;
	return attach(s, g, err);
}

static void grow(plume_vec3 *lo, plume_vec3 *hi, plume_vec3 p)
{
	lo->x = fmin(lo->x, p.x);
	lo->y = fmin(lo->y, p.y);
	lo->z = fmin(lo->z, p.z);
	hi->x = fmax(hi->x, p.x);
	hi->y = fmax(hi->y, p.y);
	hi->z = fmax(hi->z, p.z);
}

static plume_status add_feather(rt_scene *s, const plume_feather *feather, bool barbules, plume_error *err)
{
	plume_status status;
	if ((status = add_barbs(s, feather, err)) != PLUME_OK || (status = add_shaft(s, feather, err)) != PLUME_OK)
		return status;
	if (barbules && (status = add_barbules(s, feather, err)) != PLUME_OK)
		return status;
	const plume_feather *after = plume_feather_afterfeather(feather);
	return after != NULL ? add_feather(s, after, barbules, err) : PLUME_OK;
}

static plume_status add_shell(rt_scene *s, const plume_mesh *mesh, const plume_vec3 *positions, plume_error *err)
{
	if (mesh->face_count <= 0)
		return PLUME_OK;
	rt_geometry *g = add_geometry(s, RT_SHELL, NULL, 0, err);
	if (g == NULL)
		return PLUME_ERROR_MEMORY;
	g->handle = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE);
	float *vertices = rtcSetNewGeometryBuffer(g->handle, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
	                                          3 * sizeof(float), (size_t)mesh->vertex_count);
	unsigned *indices = rtcSetNewGeometryBuffer(g->handle, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
	                                            3 * sizeof(unsigned), (size_t)mesh->face_count);
	if (vertices == NULL || indices == NULL)
		return embree_error(s->device, "allocate shell buffers", err);
	for (int i = 0; i < mesh->vertex_count; ++i) {
		vertices[3 * i + 0] = (float)positions[i].x;
		vertices[3 * i + 1] = (float)positions[i].y;
		vertices[3 * i + 2] = (float)positions[i].z;
	}
	for (int i = 0; i < 3 * mesh->face_count; ++i)
		indices[i] = (unsigned)mesh->faces[i];
	s->triangles += mesh->face_count;
	return attach(s, g, err);
}

void plume_raytrace_scene_bounds(const plume_raytrace_scene *scene, plume_vec3 *lo, plume_vec3 *hi)
{
	*lo = plume_v3(INFINITY, INFINITY, INFINITY);
	*hi = plume_v3(-INFINITY, -INFINITY, -INFINITY);
	for (int i = 0; i < scene->feather_count; ++i) {
		plume_feather_info info = plume_feather_get_info(scene->feathers[i]);
		if (info.shaft_sample_count + info.point_count == 0)
			continue;
		grow(lo, hi, info.bounds_min);
		grow(lo, hi, info.bounds_max);
	}
	if (scene->shell != NULL) {
		const plume_vec3 *positions = scene->shell_positions != NULL ? scene->shell_positions : scene->shell->rest;
		for (int i = 0; i < scene->shell->vertex_count; ++i)
			grow(lo, hi, positions[i]);
	}
	if (lo->x > hi->x)
		*lo = *hi = plume_v3(0.0, 0.0, 0.0);
}

static void on_embree_error(void *user, enum RTCError code, const char *message)
{
	(void)user;
	(void)code;
	(void)message; // reported through rtcGetDeviceError; the library never prints
}

plume_status rt_scene_build(rt_scene *out, const plume_raytrace_scene *scene, const plume_texture *texture,
                            bool barbules, plume_error *err)
{
	memset(out, 0, sizeof *out);
	out->texture = texture;
	out->barbules = barbules;
	out->device = rtcNewDevice(NULL);
	if (out->device == NULL)
		return plume_error_set(err, PLUME_ERROR_UNSUPPORTED, "raytrace: Embree could not start (error %d)",
		                       (int)rtcGetDeviceError(NULL));
	rtcSetDeviceErrorFunction(out->device, on_embree_error, NULL);
	out->scene = rtcNewScene(out->device);
	if (out->scene == NULL)
		return embree_error(out->device, "create a scene", err);
	rtcSetSceneBuildQuality(out->scene, RTC_BUILD_QUALITY_MEDIUM);
	plume_status status = PLUME_OK;
	for (int i = 0; i < scene->feather_count && status == PLUME_OK; ++i)
		status = add_feather(out, scene->feathers[i], barbules, err);
	if (status == PLUME_OK && scene->shell != NULL)
		status = add_shell(out, scene->shell,
		                   scene->shell_positions != NULL ? scene->shell_positions : scene->shell->rest, err);
	if (status != PLUME_OK)
		return status;
	rtcCommitScene(out->scene);
	if (rtcGetDeviceError(out->device) != RTC_ERROR_NONE)
		return embree_error(out->device, "build the scene", err);
	plume_raytrace_scene_bounds(scene, &out->lo, &out->hi);
	return PLUME_OK;
}

void rt_scene_destroy(rt_scene *s)
{
	for (int i = 0; i < s->geometry_count; ++i) {
		if (s->geometries[i].handle != NULL)
			rtcReleaseGeometry(s->geometries[i].handle);
		plume_free(s->geometries[i].segments);
	}
	plume_free(s->geometries);
	if (s->scene != NULL)
		rtcReleaseScene(s->scene);
	if (s->device != NULL)
		rtcReleaseDevice(s->device);
	memset(s, 0, sizeof *s);
}

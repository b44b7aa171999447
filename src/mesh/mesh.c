// plume_mesh: allocation, vertex groups, barb-edge collection and quality
// measures. The builders (aligned.c, sample.c, obj.c) fill the arrays.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/asserts.h"
#include "../core/alloc.h"
#include "aligned_internal.h"
#include "plume/mesh.h"

static const double pi = 3.14159265358979323846;

plume_mesh_def plume_mesh_default_def(void)
{
	return (plume_mesh_def){
	    .cookie = PLUME_DEF_COOKIE,
	    .edge_length = 5e-3,
	    .rachis_width_base = 0.0,
	    .rachis_width_tip = 0.0,
	    .include_calamus = true,
	};
}

/// calloc of at least one element, so that an empty array is still a valid pointer.
static void *zeroed(int count, size_t size) { return plume_calloc(count > 0 ? (size_t)count : 1u, size); }

plume_mesh *plume_mesh_create(int vertex_count, int face_count)
{
	PLUME_ASSERT(vertex_count >= 0 && face_count >= 0);
	plume_mesh *mesh = plume_calloc(1, sizeof *mesh);
	if (mesh == NULL)
		return NULL;
	mesh->vertex_count = vertex_count;
	mesh->face_count = face_count;
	mesh->reference = zeroed(vertex_count, sizeof *mesh->reference);
	mesh->rest = zeroed(vertex_count, sizeof *mesh->rest);
	mesh->uv = zeroed(vertex_count, sizeof *mesh->uv);
	mesh->faces = zeroed(3 * face_count, sizeof *mesh->faces);
	mesh->material = zeroed(face_count, sizeof *mesh->material);
	mesh->barb_angle = zeroed(face_count, sizeof *mesh->barb_angle);
	mesh->barb_edge = zeroed(face_count, sizeof *mesh->barb_edge);
	mesh->barb_edges = zeroed(0, sizeof *mesh->barb_edges);
	if (mesh->reference == NULL || mesh->rest == NULL || mesh->uv == NULL || mesh->faces == NULL ||
	    mesh->material == NULL || mesh->barb_angle == NULL || mesh->barb_edge == NULL || mesh->barb_edges == NULL) {
		plume_mesh_destroy(mesh);
		return NULL;
	}
	for (int f = 0; f < face_count; ++f)
		mesh->barb_edge[f] = -1;
	return mesh;
}

void plume_mesh_destroy(plume_mesh *mesh)
{
	if (mesh == NULL)
		return;
	for (int g = 0; g < mesh->group_count; ++g)
		plume_free(mesh->groups[g].vertices);
	plume_free(mesh->groups);
	plume_free(mesh->reference);
	plume_free(mesh->rest);
	plume_free(mesh->uv);
	plume_free(mesh->faces);
	plume_free(mesh->material);
	plume_free(mesh->barb_angle);
	plume_free(mesh->barb_edge);
	plume_free(mesh->barb_edges);
	plume_free(mesh);
}

plume_status plume_mesh_add_group(plume_mesh *mesh, const char *name, const int *vertices, int count, plume_error *err)
{
	PLUME_ASSERT(mesh != NULL && name != NULL);
	PLUME_ASSERT(count >= 0 && (count == 0 || vertices != NULL));
	size_t length = strlen(name);
	if (length == 0 || length >= sizeof mesh->groups[0].name)
		return plume_error_set(err, PLUME_ERROR_SPEC, "vertex group name \"%s\" must have 1 to %zu bytes", name,
		                       sizeof mesh->groups[0].name - 1);
	if (plume_mesh_find_group(mesh, name) != NULL)
		return plume_error_set(err, PLUME_ERROR_SPEC, "the mesh already has a vertex group \"%s\"", name);
	for (int i = 0; i < count; ++i)
		if (vertices[i] < 0 || vertices[i] >= mesh->vertex_count)
			return plume_error_set(err, PLUME_ERROR_SPEC, "vertex group \"%s\": vertex %d out of range [0, %d)", name,
			                       vertices[i], mesh->vertex_count);
	int *copy = zeroed(count, sizeof *copy);
	plume_vertex_group *groups = plume_realloc(mesh->groups, (size_t)(mesh->group_count + 1) * sizeof *groups);
	if (copy == NULL || groups == NULL) {
		plume_free(copy);
		if (groups != NULL)
			mesh->groups = groups;
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory adding vertex group \"%s\"", name);
	}
	if (count > 0)
		memcpy(copy, vertices, (size_t)count * sizeof *copy);
	mesh->groups = groups;
	plume_vertex_group *group = groups + mesh->group_count++;
	memset(group->name, 0, sizeof group->name);
	memcpy(group->name, name, length);
	group->count = count;
	group->vertices = copy;
	return PLUME_OK;
}

const plume_vertex_group *plume_mesh_find_group(const plume_mesh *mesh, const char *name)
{
	for (int g = 0; g < mesh->group_count; ++g)
		if (strcmp(mesh->groups[g].name, name) == 0)
			return mesh->groups + g;
	return NULL;
}

static int compare_edges(const void *a, const void *b)
{
	const int *x = a, *y = b;
	if (x[0] != y[0])
		return x[0] < y[0] ? -1 : 1;
	return (x[1] > y[1]) - (x[1] < y[1]);
}

plume_status plume_mesh_collect_barb_edges(plume_mesh *mesh, plume_error *err)
{
	int count = 0;
	for (int f = 0; f < mesh->face_count; ++f)
		count += mesh->barb_edge[f] >= 0;
	int *edges = zeroed(2 * count, sizeof *edges);
	if (edges == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory collecting barb edges");
	int n = 0;
	for (int f = 0; f < mesh->face_count; ++f) {
		int k = mesh->barb_edge[f];
		if (k < 0)
			continue;
		PLUME_ASSERT(k < 3);
		int a = mesh->faces[3 * f + k], b = mesh->faces[3 * f + (k + 1) % 3];
		edges[2 * n] = a < b ? a : b;
		edges[2 * n + 1] = a < b ? b : a;
		++n;
	}
	qsort(edges, (size_t)n, 2 * sizeof *edges, compare_edges);
	int unique = 0;
	for (int i = 0; i < n; ++i) {
		if (unique > 0 && edges[2 * i] == edges[2 * (unique - 1)] && edges[2 * i + 1] == edges[2 * (unique - 1) + 1])
			continue;
		edges[2 * unique] = edges[2 * i];
		edges[2 * unique + 1] = edges[2 * i + 1];
		++unique;
	}
	plume_free(mesh->barb_edges);
	mesh->barb_edges = edges;
	mesh->barb_edge_count = unique;
	return PLUME_OK;
}

static int compare_keys(const void *a, const void *b)
{
	long long x = *(const long long *)a, y = *(const long long *)b;
	return (x > y) - (x < y);
}

static long long edge_key(const plume_mesh *mesh, int a, int b)
{
	return a < b ? (long long)a * mesh->vertex_count + b : (long long)b * mesh->vertex_count + a;
}

/// True when edge (a, b) belongs to exactly one vane face: it lies on the vane's
/// border, against the rachis band or on the outline. keys: the vane faces' edges, sorted.
static bool on_vane_border(const plume_mesh *mesh, const long long *keys, int count, int a, int b)
{
	long long key = edge_key(mesh, a, b);
	int lo = 0, hi = count; // first index with keys[i] >= key
	while (lo < hi) {
		int mid = lo + (hi - lo) / 2;
		if (keys[mid] < key)
			lo = mid + 1;
		else
			hi = mid;
	}
	return lo < count && keys[lo] == key && (lo + 1 == count || keys[lo + 1] != key);
}

unsigned char *mesh_junction_corners(const plume_mesh *mesh)
{
	// The vane faces' edges, to tell the vane's border edges (used by one vane face).
	long long *keys = plume_alloc(3 * (size_t)(mesh->face_count > 0 ? mesh->face_count : 1) * sizeof *keys);
	unsigned char *corners = plume_calloc((size_t)(mesh->face_count > 0 ? mesh->face_count : 1), 1);
	if (keys == NULL || corners == NULL) {
		plume_free(keys);
		plume_free(corners);
		return NULL;
	}
	int key_count = 0;
	for (int f = 0; f < mesh->face_count; ++f)
		if (mesh->material[f] == PLUME_MATERIAL_VANE)
			for (int k = 0; k < 3; ++k)
				keys[key_count++] = edge_key(mesh, mesh->faces[3 * f + k], mesh->faces[3 * f + (k + 1) % 3]);
	qsort(keys, (size_t)key_count, sizeof *keys, compare_keys);
	for (int f = 0; f < mesh->face_count; ++f) {
		const int *v = mesh->faces + 3 * f;
		int barb = mesh->barb_edge[f];
		if (mesh->material[f] != PLUME_MATERIAL_VANE || barb < 0)
			continue;
		// Corner k lies between local edges k (v[k], v[k + 1]) and k + 2: the one that is not the barb edge.
		for (int k = 0; k < 3; ++k) {
			int other = barb == k ? (k + 2) % 3 : barb == (k + 2) % 3 ? k : -1;
			if (other >= 0 && on_vane_border(mesh, keys, key_count, v[other], v[(other + 1) % 3]))
				corners[f] |= (unsigned char)(1u << k);
		}
	}
	plume_free(keys);
	return corners;
}

bool mesh_measure(const plume_mesh *mesh, plume_mesh_report *out)
{
	plume_mesh_report report = {
	    .min_angle = mesh->face_count > 0 ? pi : 0.0, .aligned_fraction = 1.0, .vane_min_angle = pi};
	const double quality = PLUME_MESH_QUALITY_ANGLE_DEG * pi / 180.0;
	int vane_faces = 0, aligned = 0;
	unsigned char *corners = mesh_junction_corners(mesh);
	if (corners == NULL)
		return false;
	// The rachis tip edge: the band's top row, where the two vanes' last guides are rooted.
	const plume_vertex_group *tip = plume_mesh_find_group(mesh, "rachis_tip");
	int tip_a = tip != NULL && tip->count == 2 ? tip->vertices[0] : -1;
	int tip_b = tip != NULL && tip->count == 2 ? tip->vertices[1] : -1;
	for (int f = 0; f < mesh->face_count; ++f) {
		const int *v = mesh->faces + 3 * f;
		double angles[3];
		for (int k = 0; k < 3; ++k) {
			plume_vec2 p = mesh->reference[v[k]], a = mesh->reference[v[(k + 1) % 3]],
			           b = mesh->reference[v[(k + 2) % 3]];
			double ax = a.x - p.x, ay = a.y - p.y, bx = b.x - p.x, by = b.y - p.y;
			// atan2(|a x b|, a . b) is accurate for small and near-pi angles alike.
			angles[k] = atan2(fabs(ax * by - ay * bx), ax * bx + ay * by);
			if (angles[k] < report.min_angle)
				report.min_angle = angles[k];
		}
		if (mesh->material[f] != PLUME_MATERIAL_VANE)
			continue;
		++vane_faces;
		int barb = mesh->barb_edge[f];
		aligned += barb >= 0;
		// A junction face: each angle under the quality bound lies at a vertex where the
		// face's barb edge (local edge k or k + 2 at vertex k) meets a border edge, the
		// other edge at that vertex: the angle between a guide and the rachis or the
		// outline; or it faces the rachis tip edge (group rachis_tip), where the two
		// vanes' last guides meet the rachis: the angle the band's width at its tip
		// subtends, as thin as the band's own top faces (docs/meshing.md).
		int small = 0, junction = 0;
		for (int k = 0; k < 3; ++k) {
			if (!(angles[k] < quality))
				continue;
			++small;
			int a = v[(k + 1) % 3], b = v[(k + 2) % 3];
			if (barb < 0)
				continue;
			if (corners[f] & (1u << k))
				++junction;
			else if (tip_a >= 0 && ((a == tip_a && b == tip_b) || (a == tip_b && b == tip_a)))
				++junction;
		}
		if (small > 0 && junction == small) {
			++report.excepted_count;
			continue;
		}
		for (int k = 0; k < 3; ++k)
			report.vane_min_angle = fmin(report.vane_min_angle, angles[k]);
	}
	plume_free(corners);
	report.aligned_fraction = vane_faces > 0 ? (double)aligned / vane_faces : 1.0;
	*out = report;
	return true;
}

plume_mesh_report plume_mesh_measure(const plume_mesh *mesh)
{
	plume_mesh_report report;
	if (!mesh_measure(mesh, &report)) { // out of memory: no face is told a junction face
		plume_mesh_report plain = {.min_angle = mesh->face_count > 0 ? pi : 0.0, .vane_min_angle = pi};
		report = plain;
		int vane_faces = 0, aligned = 0;
		for (int f = 0; f < mesh->face_count; ++f) {
			for (int k = 0; k < 3; ++k) {
				plume_vec2 p = mesh->reference[mesh->faces[3 * f + k]],
				           a = mesh->reference[mesh->faces[3 * f + (k + 1) % 3]],
				           b = mesh->reference[mesh->faces[3 * f + (k + 2) % 3]];
				double ax = a.x - p.x, ay = a.y - p.y, bx = b.x - p.x, by = b.y - p.y;
				double angle = atan2(fabs(ax * by - ay * bx), ax * bx + ay * by);
				report.min_angle = fmin(report.min_angle, angle);
				if (mesh->material[f] == PLUME_MATERIAL_VANE)
					report.vane_min_angle = fmin(report.vane_min_angle, angle);
			}
			if (mesh->material[f] == PLUME_MATERIAL_VANE) {
				++vane_faces;
				aligned += mesh->barb_edge[f] >= 0;
			}
		}
		report.aligned_fraction = vane_faces > 0 ? (double)aligned / vane_faces : 1.0;
	}
	return report;
}

plume_status plume_mesh_add_group_near(plume_mesh *mesh, const char *name, const char *source, plume_vec2 near,
                                       double radius, plume_error *err)
{
	const plume_vertex_group *group = plume_mesh_find_group(mesh, source);
	if (group == NULL)
		return plume_error_set(err, PLUME_ERROR_SPEC, "unknown vertex group \"%s\"", source);
	int *picked = plume_alloc(sizeof(int) * (size_t)(group->count > 0 ? group->count : 1));
	if (picked == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory selecting vertices");
	int count = 0;
	for (int i = 0; i < group->count; ++i) {
		plume_vec2 p = mesh->reference[group->vertices[i]];
		if (hypot(p.x - near.x, p.y - near.y) <= radius)
			picked[count++] = group->vertices[i];
	}
	plume_status status = count == 0 ? plume_error_set(err, PLUME_ERROR_SPEC,
	                                                   "no vertex of group \"%s\" lies within radius %g m of (%g, %g)",
	                                                   source, radius, near.x, near.y)
	                                 : plume_mesh_add_group(mesh, name, picked, count, err);
	plume_free(picked);
	return status;
}

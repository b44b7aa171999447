// plume_mesh_concatenate: many feathers' meshes as one (a scene with many feathers is
// one simulation, docs/scene.md "Many feathers"). Each part keeps its own material plane
// (reference, uv) and is placed rigidly in 3D; its vertex groups are kept under a prefix,
// and each group name without a prefix gathers that group of every part.
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "../core/alloc.h"
#include "../core/asserts.h"
#include "plume/mesh.h"

/// The name's first group among parts [0, part) with that name, for the union groups.
static bool seen_before(const plume_mesh_part *parts, int part, const char *name)
{
	for (int p = 0; p < part; ++p)
		if (plume_mesh_find_group(parts[p].mesh, name) != NULL)
			return true;
	return false;
}

/// The union over every part of group `name`, offset into the concatenated numbering.
static plume_status add_union_group(plume_mesh *out, const plume_mesh_part *parts, int count, const int *offsets,
                                    const char *name, plume_error *err)
{
	int64_t total = 0;
	for (int p = 0; p < count; ++p) {
		const plume_vertex_group *group = plume_mesh_find_group(parts[p].mesh, name);
		total += group != NULL ? group->count : 0;
	}
	int *vertices = plume_alloc(sizeof(int) * (size_t)(total > 0 ? total : 1));
	if (vertices == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory joining vertex group \"%s\"", name);
	int n = 0;
	for (int p = 0; p < count; ++p) {
		const plume_vertex_group *group = plume_mesh_find_group(parts[p].mesh, name);
		for (int i = 0; group != NULL && i < group->count; ++i)
			vertices[n++] = group->vertices[i] + offsets[p];
	}
	plume_status status = plume_mesh_add_group(out, name, vertices, n, err);
	plume_free(vertices);
	return status;
}

static plume_status add_prefixed_group(plume_mesh *out, const char *prefix, const plume_vertex_group *group, int offset,
                                       plume_error *err)
{
	char name[sizeof group->name];
	int length = snprintf(name, sizeof name, "%s/%s", prefix, group->name);
	if (length < 0 || (size_t)length >= sizeof name)
		return plume_error_set(err, PLUME_ERROR_SPEC, "vertex group \"%s/%s\" is longer than %zu bytes", prefix,
		                       group->name, sizeof name - 1);
	int *vertices = plume_alloc(sizeof(int) * (size_t)(group->count > 0 ? group->count : 1));
	if (vertices == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory adding vertex group \"%s\"", name);
	for (int i = 0; i < group->count; ++i)
		vertices[i] = group->vertices[i] + offset;
	plume_status status = plume_mesh_add_group(out, name, vertices, group->count, err);
	plume_free(vertices);
	return status;
}

/// Copies part p's arrays into out at the given offsets, rest positions placed.
static void copy_part(plume_mesh *out, const plume_mesh_part *part, int vertex_offset, int face_offset, int barb_offset)
{
	const plume_mesh *mesh = part->mesh;
	for (int v = 0; v < mesh->vertex_count; ++v) {
		out->reference[vertex_offset + v] = mesh->reference[v];
		out->uv[vertex_offset + v] = mesh->uv[v];
		out->rest[vertex_offset + v] = plume_v3_add(plume_m3_apply(part->rotation, mesh->rest[v]), part->translation);
	}
	for (int f = 0; f < mesh->face_count; ++f) {
		for (int k = 0; k < 3; ++k)
			out->faces[3 * (face_offset + f) + k] = mesh->faces[3 * f + k] + vertex_offset;
		out->material[face_offset + f] = mesh->material[f];
		out->barb_angle[face_offset + f] = mesh->barb_angle[f];
		out->barb_edge[face_offset + f] = mesh->barb_edge[f];
	}
	for (int e = 0; e < 2 * mesh->barb_edge_count; ++e)
		out->barb_edges[2 * barb_offset + e] = mesh->barb_edges[e] + vertex_offset;
}

plume_status plume_mesh_concatenate(const plume_mesh_part *parts, int count, plume_mesh **out, plume_error *err)
{
	PLUME_ASSERT(out != NULL && count >= 1 && parts != NULL);
	*out = NULL;
	int64_t vertices = 0, faces = 0, barb_edges = 0;
	for (int p = 0; p < count; ++p) {
		PLUME_ASSERT(parts[p].mesh != NULL && parts[p].prefix != NULL);
		for (int q = 0; q < p; ++q)
			if (strcmp(parts[p].prefix, parts[q].prefix) == 0)
				return plume_error_set(err, PLUME_ERROR_SPEC, "parts %d and %d share the group prefix \"%s\"", q, p,
				                       parts[p].prefix);
		vertices += parts[p].mesh->vertex_count;
		faces += parts[p].mesh->face_count;
		barb_edges += parts[p].mesh->barb_edge_count;
	}
	// Three indices a face and two a barb edge are ints too.
	if (vertices > INT32_MAX || 3 * faces > INT32_MAX || 2 * barb_edges > INT32_MAX)
		return plume_error_set(err, PLUME_ERROR_LIMIT,
		                       "%lld vertices and %lld faces in one mesh: allowed at most %d indices",
		                       (long long)vertices, (long long)faces, INT32_MAX);
	int *offsets = plume_alloc(sizeof(int) * (size_t)count);
	plume_mesh *mesh = plume_mesh_create((int)vertices, (int)faces);
	if (mesh != NULL) {
		plume_free(mesh->barb_edges);
		mesh->barb_edges = plume_alloc(sizeof(int) * (size_t)(2 * barb_edges > 0 ? 2 * barb_edges : 1));
	}
	if (offsets == NULL || mesh == NULL || mesh->barb_edges == NULL) {
		plume_free(offsets);
		plume_mesh_destroy(mesh);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory joining %d meshes", count);
	}
	mesh->barb_edge_count = (int)barb_edges;
	int vertex_offset = 0, face_offset = 0, barb_offset = 0;
	for (int p = 0; p < count; ++p) {
		offsets[p] = vertex_offset;
		copy_part(mesh, parts + p, vertex_offset, face_offset, barb_offset);
		vertex_offset += parts[p].mesh->vertex_count;
		face_offset += parts[p].mesh->face_count;
		barb_offset += parts[p].mesh->barb_edge_count;
	}
	plume_status status = PLUME_OK;
	for (int p = 0; p < count && status == PLUME_OK; ++p)
		for (int g = 0; g < parts[p].mesh->group_count && status == PLUME_OK; ++g) {
			const char *name = parts[p].mesh->groups[g].name;
			if (!seen_before(parts, p, name))
				status = add_union_group(mesh, parts, count, offsets, name, err);
		}
	for (int p = 0; p < count && status == PLUME_OK; ++p)
		for (int g = 0; g < parts[p].mesh->group_count && status == PLUME_OK; ++g)
			status = add_prefixed_group(mesh, parts[p].prefix, parts[p].mesh->groups + g, offsets[p], err);
	plume_free(offsets);
	if (status != PLUME_OK) {
		plume_mesh_destroy(mesh);
		return status;
	}
	*out = mesh;
	return PLUME_OK;
}

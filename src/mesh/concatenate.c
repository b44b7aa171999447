// plume_mesh_concatenate: many feathers' meshes as one (a scene with many feathers is
// one simulation, docs/scene.md "Many feathers"). Each part keeps its own material plane
// (reference, uv) and is placed rigidly in 3D; its vertex groups are kept under a prefix,
// and each group name without a prefix gathers that group of every part.
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/alloc.h"
#include "../core/asserts.h"
#include "plume/mesh.h"

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

/// A group of the result, before its vertices are copied: its name and where they come from
/// (one part's group, or every part's group of that name when part is -1).
typedef struct group_plan {
	char name[sizeof(((plume_vertex_group *)0)->name)];
	int part;
	int group;
	int count;
} group_plan;

static int compare_names(const void *a, const void *b)
{
	return strcmp(((const group_plan *)a)->name, ((const group_plan *)b)->name);
}

static int compare_prefixes(const void *a, const void *b)
{
	return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/// The groups of the result in order: one per distinct name (first appearance), then each
/// part's own, prefixed. PLUME_ERROR_SPEC for a prefixed name too long or two names alike.
static plume_status plan_groups(const plume_mesh_part *parts, int count, group_plan **out, int *out_count,
                                plume_error *err)
{
	int64_t total = 0;
	for (int p = 0; p < count; ++p)
		total += parts[p].mesh->group_count;
	group_plan *plan = plume_calloc((size_t)(2 * total + 1), sizeof *plan);
	if (plan == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory joining %d meshes", count);
	int n = 0, distinct = 0;
	// Distinct names are few (a feather's mesh has seven groups): a linear search is enough.
	for (int p = 0; p < count; ++p)
		for (int g = 0; g < parts[p].mesh->group_count; ++g) {
			const plume_vertex_group *group = parts[p].mesh->groups + g;
			int u = 0;
			while (u < distinct && strcmp(plan[u].name, group->name) != 0)
				++u;
			if (u == distinct) {
				memcpy(plan[u].name, group->name, sizeof plan[u].name);
				plan[u].part = -1;
				distinct++;
			}
			plan[u].count += group->count;
		}
	n = distinct;
	plume_status status = PLUME_OK;
	for (int p = 0; p < count && status == PLUME_OK; ++p)
		for (int g = 0; g < parts[p].mesh->group_count; ++g) {
			const plume_vertex_group *group = parts[p].mesh->groups + g;
			int length = snprintf(plan[n].name, sizeof plan[n].name, "%s/%s", parts[p].prefix, group->name);
			if (length < 0 || (size_t)length >= sizeof plan[n].name) {
				status = plume_error_set(err, PLUME_ERROR_SPEC, "vertex group \"%s/%s\" is longer than %zu bytes",
				                         parts[p].prefix, group->name, sizeof plan[n].name - 1);
				break;
			}
			plan[n].part = p;
			plan[n].group = g;
			plan[n].count = group->count;
			n++;
		}
	// Names must stay unique (a part's own group "a/b" under prefix "x" is "x/a/b", as is group
	// "b" under prefix "x/a"): sorted copies side by side.
	if (status == PLUME_OK) {
		group_plan *sorted = plume_alloc(sizeof *sorted * (size_t)(n > 0 ? n : 1));
		if (sorted == NULL) {
			status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory joining %d meshes", count);
		} else {
			memcpy(sorted, plan, sizeof *sorted * (size_t)n);
			qsort(sorted, (size_t)n, sizeof *sorted, compare_names);
			for (int k = 1; k < n && status == PLUME_OK; ++k)
				if (strcmp(sorted[k - 1].name, sorted[k].name) == 0)
					status = plume_error_set(err, PLUME_ERROR_SPEC, "two vertex groups would be named \"%s\"",
					                         sorted[k].name);
			plume_free(sorted);
		}
	}
	if (status != PLUME_OK) {
		plume_free(plan);
		return status;
	}
	*out = plan;
	*out_count = n;
	return PLUME_OK;
}

/// Fills out's groups from the plan: vertex indices offset into the joined numbering.
static plume_status make_groups(plume_mesh *out, const plume_mesh_part *parts, int count, const int *offsets,
                                const group_plan *plan, int n, plume_error *err)
{
	out->groups = plume_calloc((size_t)(n > 0 ? n : 1), sizeof *out->groups);
	if (out->groups == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory joining %d meshes", count);
	for (int k = 0; k < n; ++k) {
		plume_vertex_group *group = out->groups + k;
		memcpy(group->name, plan[k].name, sizeof group->name);
		group->vertices = plume_alloc(sizeof(int) * (size_t)(plan[k].count > 0 ? plan[k].count : 1));
		if (group->vertices == NULL)
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory joining %d meshes", count);
		out->group_count = k + 1;
		for (int p = plan[k].part < 0 ? 0 : plan[k].part; p < (plan[k].part < 0 ? count : plan[k].part + 1); ++p) {
			const plume_vertex_group *source = plan[k].part < 0 ? plume_mesh_find_group(parts[p].mesh, plan[k].name)
			                                                    : parts[p].mesh->groups + plan[k].group;
			for (int i = 0; source != NULL && i < source->count; ++i)
				group->vertices[group->count++] = source->vertices[i] + offsets[p];
		}
	}
	return PLUME_OK;
}

plume_status plume_mesh_concatenate(const plume_mesh_part *parts, int count, plume_mesh **out, plume_error *err)
{
	PLUME_ASSERT(out != NULL && count >= 1 && parts != NULL);
	*out = NULL;
	int64_t vertices = 0, faces = 0, barb_edges = 0;
	for (int p = 0; p < count; ++p) {
		PLUME_ASSERT(parts[p].mesh != NULL && parts[p].prefix != NULL);
		vertices += parts[p].mesh->vertex_count;
		faces += parts[p].mesh->face_count;
		barb_edges += parts[p].mesh->barb_edge_count;
	}
	// Three indices a face and two a barb edge are ints too.
	if (vertices > INT32_MAX || 3 * faces > INT32_MAX || 2 * barb_edges > INT32_MAX)
		return plume_error_set(err, PLUME_ERROR_LIMIT,
		                       "%lld vertices and %lld faces in one mesh: allowed at most %d indices",
		                       (long long)vertices, (long long)faces, INT32_MAX);
	// Prefixes alike would merge two parts' groups: sorted, neighbours differ.
	const char **prefixes = plume_alloc(sizeof *prefixes * (size_t)count);
	if (prefixes == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory joining %d meshes", count);
	for (int p = 0; p < count; ++p)
		prefixes[p] = parts[p].prefix;
	qsort(prefixes, (size_t)count, sizeof *prefixes, compare_prefixes);
	for (int p = 1; p < count; ++p)
		if (strcmp(prefixes[p - 1], prefixes[p]) == 0) {
			plume_status status =
			    plume_error_set(err, PLUME_ERROR_SPEC, "two parts share the group prefix \"%s\"", prefixes[p]);
			plume_free(prefixes);
			return status;
		}
	plume_free(prefixes);
	group_plan *plan = NULL;
	int group_count = 0;
	plume_status status = plan_groups(parts, count, &plan, &group_count, err);
	if (status != PLUME_OK)
		return status;
	int *offsets = plume_alloc(sizeof(int) * (size_t)count);
	plume_mesh *mesh = plume_mesh_create((int)vertices, (int)faces);
	if (mesh != NULL) {
		plume_free(mesh->barb_edges);
		mesh->barb_edges = plume_alloc(sizeof(int) * (size_t)(2 * barb_edges > 0 ? 2 * barb_edges : 1));
	}
	if (offsets == NULL || mesh == NULL || mesh->barb_edges == NULL) {
		plume_free(plan);
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
	status = make_groups(mesh, parts, count, offsets, plan, group_count, err);
	plume_free(plan);
	plume_free(offsets);
	if (status != PLUME_OK) {
		plume_mesh_destroy(mesh);
		return status;
	}
	*out = mesh;
	return PLUME_OK;
}

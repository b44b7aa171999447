// A scene's body as a contact obstacle, and the independent intersection check of its
// frames (docs/contact.md, "Contact in scenes").
//
// A carried feather's calamus enters the skin at its follicle: its faces touch or cross
// the body by construction, and a barrier between them would be infinite from the first
// step. The obstacle therefore leaves out the body triangles that come within reach of a
// follicle face — every body triangle closer than the contact distance plus the face's
// longest edge to one of the face's corners, which covers every point of the face — and the
// intersection check leaves out exactly the pairs (follicle face, body triangle), and the body
// against itself. Everything else counts: feather against feather, a feather against itself,
// a feather against the body.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "plume/body.h"
#include "plume/intersect.h"
#include "sim/contact_distance.h"
#include "sim/scene_contact.h"

struct plume_scene_surfaces {
	const plume_scene *scene;
	int shell_vertex_count;
	int shell_face_count;
	int body_vertex_count;
	/// The soup of the check: shell positions then body positions; shell faces then body triangles.
	plume_vec3 *positions;
	int *triangles;
	int triangle_count;
	bool *follicle_face;
	/// The obstacle's index in the simulation (-1: none), the body vertices it holds (those of
	/// its kept triangles, in body order) and room for their positions.
	int obstacle;
	int *obstacle_vertices;
	int obstacle_vertex_count;
	plume_vec3 *obstacle_positions;
	/// Room for the pairs of one check.
	int *pairs;
	int pair_capacity;
};

void plume_scene_follicle_faces(const plume_scene *scene, bool *follicle_face)
{
	const plume_mesh *mesh = scene->mesh;
	memset(follicle_face, 0, sizeof(bool) * (size_t)mesh->face_count);
	for (int i = 0; i < scene->feather_count; ++i) {
		const plume_scene_feather *feather = scene->feathers + i;
		if (!feather->follicle)
			continue;
		char name[64];
		snprintf(name, sizeof name, "%s/rachis_clamp", feather->name);
		const plume_vertex_group *clamp = plume_mesh_find_group(mesh, name);
		if (clamp == NULL)
			continue;
		// The group's vertices lie in the feather's own range; so do its faces.
		for (int f = feather->face_offset; f < feather->face_offset + feather->face_count; ++f) {
			const int *v = mesh->faces + 3 * f;
			for (int k = 0; k < clamp->count && !follicle_face[f]; ++k)
				follicle_face[f] =
				    clamp->vertices[k] == v[0] || clamp->vertices[k] == v[1] || clamp->vertices[k] == v[2];
		}
	}
}

/// Whether body triangle t (at body) is within reach of a follicle face: closer than the
/// contact distance plus the face's longest edge to one of its corners.
static bool near_follicle(const plume_scene_surfaces *s, const plume_vec3 *body, const int *t, double reach)
{
	const plume_mesh *mesh = s->scene->mesh;
	for (int f = 0; f < s->shell_face_count; ++f) {
		if (!s->follicle_face[f])
			continue;
		const int *v = mesh->faces + 3 * f;
		double longest = 0;
		for (int k = 0; k < 3; ++k)
			longest = fmax(longest, plume_v3_length(plume_v3_sub(mesh->rest[v[k]], mesh->rest[v[(k + 1) % 3]])));
		double limit = reach + longest;
		for (int k = 0; k < 3; ++k)
			if (plume_point_triangle_distance2(mesh->rest[v[k]], body[t[0]], body[t[1]], body[t[2]], NULL) <
			    limit * limit)
				return true;
	}
	return false;
}

/// The body, less its triangles at the follicles and the vertices only they use, as an
/// obstacle of sim (an obstacle's vertices are contact points too).
static plume_status add_body_obstacle(plume_scene_surfaces *s, plume_sim *sim, const plume_vec3 *body, plume_error *err)
{
	const plume_body *b = s->scene->body;
	int count = plume_body_triangle_count(b), vertex_count = plume_body_vertex_count(b);
	const int *triangles = plume_body_triangles(b);
	int *kept = plume_alloc(sizeof(int) * 3 * (size_t)(count > 0 ? count : 1));
	int *renumber = plume_alloc(sizeof(int) * (size_t)(vertex_count > 0 ? vertex_count : 1));
	s->obstacle_vertices = plume_alloc(sizeof(int) * (size_t)(vertex_count > 0 ? vertex_count : 1));
	s->obstacle_positions = plume_alloc(sizeof(plume_vec3) * (size_t)(vertex_count > 0 ? vertex_count : 1));
	if (kept == NULL || renumber == NULL || s->obstacle_vertices == NULL || s->obstacle_positions == NULL) {
		plume_free(kept);
		plume_free(renumber);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory preparing the body for contact");
	}
	for (int v = 0; v < vertex_count; ++v)
		renumber[v] = -1;
	int kept_count = 0;
	for (int t = 0; t < count; ++t) {
		if (near_follicle(s, body, triangles + 3 * t, s->scene->sim.contact.distance))
			continue;
		for (int k = 0; k < 3; ++k)
			renumber[triangles[3 * t + k]] = 0;
		memcpy(kept + 3 * kept_count++, triangles + 3 * t, sizeof(int) * 3);
	}
	s->obstacle_vertex_count = 0;
	for (int v = 0; v < vertex_count; ++v) {
		if (renumber[v] < 0)
			continue;
		renumber[v] = s->obstacle_vertex_count;
		s->obstacle_vertices[s->obstacle_vertex_count] = v;
		s->obstacle_positions[s->obstacle_vertex_count++] = body[v];
	}
	for (int k = 0; k < 3 * kept_count; ++k)
		kept[k] = renumber[kept[k]];
	plume_status status = plume_sim_add_obstacle(sim, s->obstacle_positions, s->obstacle_vertex_count, kept, kept_count,
	                                             &s->obstacle, err);
	if (status != PLUME_OK)
		plume_error_prefix(err, "the body as a contact obstacle");
	plume_free(kept);
	plume_free(renumber);
	return status;
}

plume_status plume_scene_surfaces_create(const plume_scene *scene, plume_sim *sim, const plume_vec3 *body_rest_pose,
                                         plume_scene_surfaces **out, plume_error *err)
{
	PLUME_ASSERT(scene != NULL && sim != NULL && out != NULL);
	*out = NULL;
	const plume_mesh *mesh = scene->mesh;
	plume_scene_surfaces *s = plume_calloc(1, sizeof *s);
	if (s == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory preparing the intersection check");
	s->scene = scene;
	s->obstacle = -1;
	s->shell_vertex_count = mesh->vertex_count;
	s->shell_face_count = mesh->face_count;
	s->body_vertex_count = scene->body != NULL ? plume_body_vertex_count(scene->body) : 0;
	int body_triangles = scene->body != NULL ? plume_body_triangle_count(scene->body) : 0;
	s->triangle_count = mesh->face_count + body_triangles;
	s->positions = plume_alloc(sizeof(plume_vec3) * (size_t)(s->shell_vertex_count + s->body_vertex_count + 1));
	s->triangles = plume_alloc(sizeof(int) * 3 * (size_t)(s->triangle_count + 1));
	s->follicle_face = plume_alloc(sizeof(bool) * (size_t)(mesh->face_count + 1));
	s->pair_capacity = 64;
	s->pairs = plume_alloc(sizeof(int) * 2 * (size_t)s->pair_capacity);
	if (s->positions == NULL || s->triangles == NULL || s->follicle_face == NULL || s->pairs == NULL) {
		plume_scene_surfaces_destroy(s);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory preparing the intersection check");
	}
	memcpy(s->triangles, mesh->faces, sizeof(int) * 3 * (size_t)mesh->face_count);
	if (scene->body != NULL) {
		const int *body = plume_body_triangles(scene->body);
		for (int k = 0; k < 3 * body_triangles; ++k)
			s->triangles[3 * mesh->face_count + k] = body[k] + mesh->vertex_count;
	}
	plume_scene_follicle_faces(scene, s->follicle_face);
	plume_status status = PLUME_OK;
	if (scene->body != NULL && scene->sim.contact.enabled)
		status = add_body_obstacle(s, sim, body_rest_pose, err);
	if (status != PLUME_OK) {
		plume_scene_surfaces_destroy(s);
		return status;
	}
	*out = s;
	return PLUME_OK;
}

void plume_scene_surfaces_destroy(plume_scene_surfaces *surfaces)
{
	if (surfaces == NULL)
		return;
	plume_free(surfaces->positions);
	plume_free(surfaces->triangles);
	plume_free(surfaces->follicle_face);
	plume_free(surfaces->pairs);
	plume_free(surfaces->obstacle_vertices);
	plume_free(surfaces->obstacle_positions);
	plume_free(surfaces);
}

void plume_scene_surfaces_move_body(plume_scene_surfaces *surfaces, plume_sim *sim, const plume_vec3 *body_pose)
{
	if (surfaces->obstacle < 0)
		return;
	for (int k = 0; k < surfaces->obstacle_vertex_count; ++k)
		surfaces->obstacle_positions[k] = body_pose[surfaces->obstacle_vertices[k]];
	plume_sim_set_obstacle_positions(sim, surfaces->obstacle, surfaces->obstacle_positions);
}

plume_status plume_scene_surfaces_intersections(plume_scene_surfaces *s, const plume_vec3 *shell_positions,
                                                const plume_vec3 *body_pose, int *count, int first_pair[2],
                                                plume_error *err)
{
	PLUME_ASSERT(body_pose != NULL || s->body_vertex_count == 0);
	memcpy(s->positions, shell_positions, sizeof(plume_vec3) * (size_t)s->shell_vertex_count);
	if (s->body_vertex_count > 0)
		memcpy(s->positions + s->shell_vertex_count, body_pose, sizeof(plume_vec3) * (size_t)s->body_vertex_count);
	int total = 0;
	for (;;) {
		plume_status status =
		    plume_find_intersections(s->positions, s->shell_vertex_count + s->body_vertex_count, s->triangles,
		                             s->triangle_count, s->pair_capacity, s->pairs, &total, err);
		if (status != PLUME_OK)
			return status;
		if (total <= s->pair_capacity)
			break;
		// Again with room for every pair, so the follicle pairs can be told from the rest.
		int *grown = plume_realloc(s->pairs, sizeof(int) * 2 * (size_t)total);
		if (grown == NULL)
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory in the intersection check");
		s->pairs = grown;
		s->pair_capacity = total;
	}
	*count = 0;
	for (int k = 0; k < total; ++k) {
		int a = s->pairs[2 * k], b = s->pairs[2 * k + 1]; // a < b: a body triangle comes second
		// The body against itself is its author's (a bird's limbs may be overlapping closed
		// shells) and a follicle face against the body sits in its skin: neither counts.
		if (b >= s->shell_face_count && (a >= s->shell_face_count || s->follicle_face[a]))
			continue;
		if (*count == 0 && first_pair != NULL) {
			first_pair[0] = a;
			first_pair[1] = b;
		}
		++*count;
	}
	return PLUME_OK;
}

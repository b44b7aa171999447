// Many feathers carried by a joined shell, and a body, for the ray tracer (cli.h, cli_carried):
// shared by `plume simulate --render` and `plume render` of a simulation folder.
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static void release_moved(cli_carried *c)
{
	for (int i = 0; i < c->count && c->moved != NULL; ++i) {
		plume_feather_destroy(c->moved[i]);
		c->moved[i] = NULL;
	}
}

plume_status cli_carried_begin(cli_carried *c, const plume_mesh *shell, int count, const plume_feather *const *feathers,
                               const int *faces, bool draw_shell, const plume_mesh *body, plume_error *err)
{
	memset(c, 0, sizeof *c);
	c->count = count;
	c->embeddings = calloc((size_t)(count > 0 ? count : 1), sizeof *c->embeddings);
	c->moved = calloc((size_t)(count > 0 ? count : 1), sizeof *c->moved);
	c->list = calloc((size_t)(count > 0 ? count : 1), sizeof *c->list);
	if (c->embeddings == NULL || c->moved == NULL || c->list == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	for (int i = 0; i < count; ++i) {
		if (feathers[i] == NULL)
			continue;
		plume_status status =
		    plume_embedding_create_faces(feathers[i], shell, faces[2 * i], faces[2 * i + 1], &c->embeddings[i], err);
		if (status != PLUME_OK)
			return status;
	}
	// The surface drawn plain: the simulated shell (when asked) and the body, one mesh.
	int vertices = 0, triangles = 0;
	if (draw_shell) {
		c->shell_vertices = shell->vertex_count;
		vertices += shell->vertex_count;
		triangles += shell->face_count;
	}
	if (body != NULL) {
		vertices += body->vertex_count;
		triangles += body->face_count;
	}
	if (vertices == 0)
		return PLUME_OK;
	c->surface = plume_mesh_create(vertices, triangles);
	c->surface_positions = malloc(sizeof(plume_vec3) * (size_t)vertices);
	if (c->surface == NULL || c->surface_positions == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	int v = 0, f = 0;
	const plume_mesh *parts[2] = {draw_shell ? shell : NULL, body};
	for (int p = 0; p < 2; ++p) {
		if (parts[p] == NULL)
			continue;
		memcpy(c->surface->rest + v, parts[p]->rest, sizeof(plume_vec3) * (size_t)parts[p]->vertex_count);
		for (int k = 0; k < 3 * parts[p]->face_count; ++k)
			c->surface->faces[3 * f + k] = parts[p]->faces[k] + v;
		v += parts[p]->vertex_count;
		f += parts[p]->face_count;
	}
	memcpy(c->surface_positions, c->surface->rest, sizeof(plume_vec3) * (size_t)vertices);
	return PLUME_OK;
}

plume_status cli_carried_pose(cli_carried *c, const plume_vec3 *positions, const plume_vec3 *body_positions,
                              plume_raytrace_scene *scene, plume_error *err)
{
	release_moved(c);
	int drawn = 0;
	for (int i = 0; i < c->count; ++i) {
		if (c->embeddings[i] == NULL)
			continue;
		plume_status status = plume_embedding_apply(c->embeddings[i], positions, &c->moved[i], err);
		if (status != PLUME_OK)
			return status;
		c->list[drawn++] = c->moved[i];
	}
	if (c->surface != NULL) {
		memcpy(c->surface_positions, positions, sizeof(plume_vec3) * (size_t)c->shell_vertices);
		int body_vertices = c->surface->vertex_count - c->shell_vertices;
		const plume_vec3 *body = body_positions != NULL ? body_positions : c->surface->rest + c->shell_vertices;
		memcpy(c->surface_positions + c->shell_vertices, body, sizeof(plume_vec3) * (size_t)body_vertices);
	}
	*scene = (plume_raytrace_scene){drawn, c->list, c->surface, c->surface != NULL ? c->surface_positions : NULL};
	return PLUME_OK;
}

void cli_carried_end(cli_carried *c)
{
	release_moved(c);
	for (int i = 0; i < c->count && c->embeddings != NULL; ++i)
		plume_embedding_destroy(c->embeddings[i]);
	free(c->embeddings);
	free(c->moved);
	free(c->list);
	plume_mesh_destroy(c->surface);
	free(c->surface_positions);
	memset(c, 0, sizeof *c);
}

// Benchmark: the paper's Figure 1 scenario (examples/scenes/figure1-anisotropic.json)
// at the paper's resolution (e = 5 mm) and on a mesh four times finer (e = 2.5 mm),
// with the isotropic comparison. Prints wall time, steps, Newton iterations per step,
// the split between assembly, factorisation and solve, and the largest barb strain.
// No files are written: this measures the simulator alone.
#include <stdio.h>
#include <stdlib.h>

#include "plume/plume.h"

static int run(const char *name, double edge_length)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/examples/scenes/%s.json", PLUME_SOURCE_DIR, name);
	plume_scene *scene = NULL;
	plume_error err = {0};
	if (plume_scene_load(path, NULL, &scene, &err) != PLUME_OK) {
		fprintf(stderr, "%s\n", err.message);
		return 1;
	}
	if (edge_length != 0.005) {
		// Re-mesh the same feather finer.
		plume_mesh_def def = plume_mesh_default_def();
		def.edge_length = edge_length;
		def.rachis_width_base = 0.008;
		def.rachis_width_tip = 0.004;
		plume_mesh *mesh = NULL;
		if (plume_mesh_from_feather(scene->feather, &def, &mesh, &scene->mesh_report, &err) != PLUME_OK) {
			fprintf(stderr, "%s\n", err.message);
			plume_scene_destroy(scene);
			return 1;
		}
		// Handles that select vertices near a point are selected again on the new mesh.
		for (int h = 0; h < scene->handle_count; ++h) {
			plume_scene_handle *handle = scene->handles + h;
			if (handle->near_given && plume_mesh_add_group_near(mesh, handle->group, handle->source_group, handle->near,
			                                                    handle->radius, &err) != PLUME_OK) {
				fprintf(stderr, "%s\n", err.message);
				plume_mesh_destroy(mesh);
				plume_scene_destroy(scene);
				return 1;
			}
		}
		plume_mesh_destroy(scene->mesh);
		scene->mesh = mesh;
	}
	plume_scene_summary summary;
	plume_status status = plume_scene_run(scene, NULL, NULL, &summary, &err);
	printf("%-22s e = %.4f m: %5d vertices %5d faces %4d barb constraints | %s %3d steps, %5d Newton iterations "
	       "(%.2f a step), %.2f s wall (assembly %.2f s, factorisation %.2f s, solve %.2f s), largest barb strain "
	       "%.2e, rachis tip deflection %.4f m\n",
	       name, edge_length, summary.vertex_count, summary.face_count, summary.constraint_count,
	       status == PLUME_OK ? "ok    " : "FAILED", summary.steps, summary.newton_iterations,
	       summary.steps > 0 ? (double)summary.newton_iterations / summary.steps : 0.0, summary.wall_seconds,
	       summary.seconds_assembly, summary.seconds_factor, summary.seconds_solve, summary.max_barb_strain,
	       summary.rachis_tip_deflection);
	if (status != PLUME_OK)
		printf("  %s\n", err.message);
	plume_scene_destroy(scene);
	return status == PLUME_OK ? 0 : 1;
}

int main(int argc, char **argv)
{
	bool quick = argc > 1 && argv[1][0] == 'q';
	int failures = run("figure1-anisotropic", 0.005);
	failures += run("figure1-isotropic", 0.005);
	if (!quick)
		failures += run("figure1-anisotropic", 0.0025);
	return failures == 0 ? 0 : 1;
}

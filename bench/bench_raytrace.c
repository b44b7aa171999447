#define _POSIX_C_SOURCE 200809L // clock_gettime (bench_support.h)
// Benchmark: ray tracing the hawk preset (2 vanes x 2200 barbs x 30 samples) at 1920 x 1080 with 16
// samples per pixel (issue 7's target: under 10 s on 2 cores), and the time per frame of a barb-level
// sequence: the feather embedded in its shell, carried by a rigidly turning shell, re-rendered.
//
// Usage: bench_raytrace [SPEC.json] [OUTPUT_DIR] [THREADS]   (defaults: the hawk preset, /tmp, 2)
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <omp.h>

#include "plume/embed.h"
#include "plume/plume.h"
#include "plume/raytrace.h"
#include "bench_support.h"

int main(int argc, char **argv)
{
	const char *spec = argc > 1 ? argv[1] : PLUME_SOURCE_DIR "/examples/franco-walter/hawk.json";
	const char *dir = argc > 2 ? argv[2] : "/tmp";
	int threads = argc > 3 ? atoi(argv[3]) : 2;
	plume_error err = {0};
	plume_feather *feather = NULL;
	plume_spec_options options = {0};
	bench_check("bench_raytrace", plume_spec_generate(spec, &options, &feather, &err), &err);
	plume_feather_info info = plume_feather_get_info(feather);

	const plume_feather *list[1] = {feather};
	plume_raytrace_scene scene = {1, list, NULL, NULL};
	plume_raytrace_def def = plume_raytrace_default_def();
	def.camera.width = 1920;
	def.camera.height = 1080;
	def.spp = 16;
	def.threads = threads;
	char path[1024];
	snprintf(path, sizeof path, "%s/bench_raytrace.png", dir);
	plume_raytrace_stats stats;
	double start = omp_get_wtime();
	clock_t cpu_start = clock();
	bench_check("bench_raytrace", plume_raytrace_render_png(&scene, &def, path, &stats, &err), &err);
	double total = omp_get_wtime() - start;
	double cpu = (double)(clock() - cpu_start) / CLOCKS_PER_SEC;
	printf("hawk: %d barbs, %d points, %d curve segments\n", info.barb_count, info.point_count, stats.curve_segments);
	printf("render 1920x1080, 16 spp, %d threads: build %.3f s, trace %.3f s, total with PNG %.3f s wall, %.3f s "
	       "CPU\n",
	       threads, stats.build_seconds, stats.render_seconds, total, cpu);

	// A sequence: mesh the feather, embed its barbs, turn the shell rigidly, rebuild and render each frame.
	plume_mesh *mesh = NULL;
	plume_mesh_def mesh_def = plume_mesh_default_def();
	bench_check("bench_raytrace", plume_mesh_from_feather(feather, &mesh_def, &mesh, NULL, &err), &err);
	plume_barb_embedding *embedding = NULL;
	start = omp_get_wtime();
	bench_check("bench_raytrace", plume_embedding_create(feather, mesh, &embedding, &err), &err);
	double embed_seconds = omp_get_wtime() - start;
	plume_vec3 *positions = malloc((size_t)mesh->vertex_count * sizeof *positions);
	const int frames = 4;
	def.camera.width = 960;
	def.camera.height = 540;
	def.camera.view_direction = plume_v3(0.6, 0.3, 1.0);
	double apply_seconds = 0.0, render_seconds = 0.0;
	for (int f = 0; f < frames; ++f) {
		plume_mat3 rotation = plume_m3_rotation(plume_v3(0.0, 1.0, 0.0), 0.2 * f);
		for (int i = 0; i < mesh->vertex_count; ++i)
			positions[i] = plume_m3_apply(rotation, mesh->rest[i]);
		plume_feather *moved = NULL;
		start = omp_get_wtime();
		bench_check("bench_raytrace", plume_embedding_apply(embedding, positions, &moved, &err), &err);
		apply_seconds += omp_get_wtime() - start;
		const plume_feather *frame_list[1] = {moved};
		plume_raytrace_scene frame = {1, frame_list, NULL, NULL};
		snprintf(path, sizeof path, "%s/bench_raytrace_frame%d.png", dir, f);
		start = omp_get_wtime();
		bench_check("bench_raytrace", plume_raytrace_render_png(&frame, &def, path, NULL, &err), &err);
		render_seconds += omp_get_wtime() - start;
		plume_feather_destroy(moved);
	}
	printf("sequence: shell %d vertices, %d faces; embedding %.3f s; per frame: carry barbs %.3f s, render "
	       "960x540 16 spp %.3f s\n",
	       mesh->vertex_count, mesh->face_count, embed_seconds, apply_seconds / frames, render_seconds / frames);
	free(positions);
	plume_embedding_destroy(embedding);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
	return 0;
}

#define _POSIX_C_SOURCE 200809L // clock_gettime (bench_support.h)
// Benchmark: barb-aligned mesh quality of every example feather (Franco-Walter,
// Streit-Heidrich, Zhang-Kanai) at e = 5 mm and 2.5 mm: vane faces, the smallest
// vane angle, the faces under 20 degrees and where they lie (touching the rachis,
// touching the outline, between guides), the junction faces the report excepts,
// the fraction of vane faces with a barb edge, and the meshing time.
//
// Usage: bench_mesh [SPEC.json ...]   (default: every example feather)
#define _GNU_SOURCE
#include <glob.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plume/plume.h"
#include "bench_support.h"

static const double pi = 3.14159265358979323846;

static double face_min_angle(const plume_mesh *mesh, int f)
{
	const int *v = mesh->faces + 3 * f;
	double best = pi;
	for (int k = 0; k < 3; ++k) {
		plume_vec2 p = mesh->reference[v[k]], a = mesh->reference[v[(k + 1) % 3]], b = mesh->reference[v[(k + 2) % 3]];
		double ax = a.x - p.x, ay = a.y - p.y, bx = b.x - p.x, by = b.y - p.y;
		best = fmin(best, atan2(fabs(ax * by - ay * bx), ax * bx + ay * by));
	}
	return best;
}

static void mark_group(const plume_mesh *mesh, const char *name, unsigned char *mark, unsigned char bit)
{
	const plume_vertex_group *group = plume_mesh_find_group(mesh, name);
	for (int i = 0; group != NULL && i < group->count; ++i)
		mark[group->vertices[i]] |= bit;
}

static void measure(const char *spec, double e)
{
	plume_mesh_spec_options options = plume_mesh_spec_default_options();
	options.edge_length = e;
	plume_mesh *mesh = NULL;
	plume_mesh_report report;
	plume_error err = {0};
	double start = bench_now();
	plume_status status = plume_mesh_spec_read(spec, &options, &mesh, &report, &err);
	double time = bench_now() - start;
	const char *name = strstr(spec, "examples/");
	name = name != NULL ? name + 9 : spec;
	if (status != PLUME_OK) {
		printf("%-44s %5.1f  FAILED: %s\n", name, 1e3 * e, err.message);
		return;
	}
	unsigned char *mark = calloc((size_t)mesh->vertex_count, 1);
	mark_group(mesh, "rachis", mark, 1);
	mark_group(mesh, "left_edge", mark, 2);
	mark_group(mesh, "right_edge", mark, 2);
	int vane = 0, aligned = 0, small = 0, at_rachis = 0, at_outline = 0, between = 0;
	double min_angle = pi;
	for (int f = 0; f < mesh->face_count; ++f) {
		if (mesh->material[f] != PLUME_MATERIAL_VANE)
			continue;
		++vane;
		aligned += mesh->barb_edge[f] >= 0;
		double angle = face_min_angle(mesh, f);
		min_angle = fmin(min_angle, angle);
		if (angle >= 20.0 * pi / 180.0)
			continue;
		++small;
		const int *v = mesh->faces + 3 * f;
		if (getenv("BENCH_MESH_VERBOSE") != NULL) {
			printf("  face %d barb %d:", f, mesh->barb_edge[f]);
			for (int k = 0; k < 3; ++k) {
				plume_vec2 p = mesh->reference[v[k]], a = mesh->reference[v[(k + 1) % 3]],
				           b = mesh->reference[v[(k + 2) % 3]];
				double ax = a.x - p.x, ay = a.y - p.y, bx = b.x - p.x, by = b.y - p.y;
				printf(" v%d%s (%.4f %.4f) %.1fdeg", v[k],
				       mark[v[k]] & 1   ? "R"
				       : mark[v[k]] & 2 ? "E"
				                        : "",
				       p.x, p.y, atan2(fabs(ax * by - ay * bx), ax * bx + ay * by) * 180 / pi);
			}
			printf("\n");
		}
		unsigned char m = mark[v[0]] | mark[v[1]] | mark[v[2]];
		if (m & 1)
			++at_rachis;
		else if (m & 2)
			++at_outline;
		else
			++between;
	}
	printf("%-44s %5.1f %6d %7.2f %6d %6d %6d %6d %7.2f %6d %7.2f %8.4f %7.1f\n", name, 1e3 * e, vane,
	       min_angle * 180.0 / pi, small, at_rachis, at_outline, between, report.vane_min_angle * 180.0 / pi,
	       report.excepted_count, 100.0 * report.excepted_count / (vane > 0 ? vane : 1), (double)aligned / vane,
	       1e3 * time);
	free(mark);
	plume_mesh_destroy(mesh);
}

int main(int argc, char **argv)
{
	printf("%-44s %5s %6s %7s %6s %6s %6s %6s %7s %6s %7s %8s %7s\n", "feather", "e_mm", "vane", "min_deg", "<20",
	       "rachis", "edge", "inside", "rep_min", "except", "exc_%", "aligned", "ms");
	if (argc > 1) {
		for (int i = 1; i < argc; ++i)
			for (int j = 0; j < 2; ++j)
				measure(argv[i], j == 0 ? 5e-3 : 2.5e-3);
		return 0;
	}
	static const char *const dirs[] = {"franco-walter", "streit-heidrich", "zhang-kanai"};
	for (int d = 0; d < 3; ++d) {
		char pattern[4096];
		snprintf(pattern, sizeof pattern, "%s/examples/%s/*.json", PLUME_SOURCE_DIR, dirs[d]);
		glob_t found;
		if (glob(pattern, 0, NULL, &found) != 0)
			continue;
		for (size_t i = 0; i < found.gl_pathc; ++i)
			for (int j = 0; j < 2; ++j)
				measure(found.gl_pathv[i], j == 0 ? 5e-3 : 2.5e-3);
		globfree(&found);
	}
	return 0;
}

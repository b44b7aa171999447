// The barb-aligned mesher and plume_mesh: every vane face has a barb edge on
// every example feather and on explicit guides, the meshes are valid (positive
// areas, consistently oriented manifold, no overlapping faces), groups are
// sane, OBJ round trips are exact, reader errors name file and line, output is
// deterministic and nothing leaks.
#define _POSIX_C_SOURCE 200809L
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/spec.h"
#include "io/spec_mesh.h"
#include "model/feather_internal.h"
#include "support.h"

static const double pi = 3.14159265358979323846;

/// Smallest interior angle this suite accepts, radians. Measured on the
/// examples at e = 5 mm: peacock 0.33 deg (random loose barbs at the vane base),
/// hawk 1.8 deg, the others above 0.45 deg; examples/meshes/guides.json 0.16 deg (slivers
/// where the boundary clips the lowest guides).
static const double min_angle_bound = 0.1 * 3.14159265358979323846 / 180.0;

static const char *const examples[] = {"blue", "figure6a", "figure6b", "filoplume", "hawk", "peacock"};

static plume_feather *example(const char *name)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/examples/franco-walter/%s.json", PLUME_SOURCE_DIR, name);
	plume_fw_def def;
	uint64_t seed;
	plume_error err;
	if (plume_fw_def_read(path, &def, &seed, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	plume_feather *feather = NULL;
	if (plume_fw_generate(&def, seed, &feather, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	return feather;
}

static double signed_area2(const plume_mesh *mesh, int f)
{
	plume_vec2 a = mesh->reference[mesh->faces[3 * f]], b = mesh->reference[mesh->faces[3 * f + 1]],
	           c = mesh->reference[mesh->faces[3 * f + 2]];
	return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

static int compare_ints3(const void *a, const void *b) { return memcmp(a, b, 3 * sizeof(int)); }

static double orient(plume_vec2 a, plume_vec2 b, plume_vec2 c)
{
	return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

static bool segments_cross(plume_vec2 p, plume_vec2 q, plume_vec2 r, plume_vec2 s)
{
	double o1 = orient(p, q, r), o2 = orient(p, q, s), o3 = orient(r, s, p), o4 = orient(r, s, q);
	return ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
}

/// Strictly inside a counter-clockwise triangle.
static bool inside(plume_vec2 p, plume_vec2 a, plume_vec2 b, plume_vec2 c)
{
	return orient(a, b, p) > 1e-18 && orient(b, c, p) > 1e-18 && orient(c, a, p) > 1e-18;
}

/// The mesh is a valid planar triangulation: positive areas, every directed
/// edge used once (a consistently oriented manifold), and no two faces overlap
/// (no edges cross, no vertex inside another face).
static void assert_valid_mesh(const plume_mesh *mesh)
{
	for (int f = 0; f < mesh->face_count; ++f) {
		assert_true(signed_area2(mesh, f) > 0.0);
		for (int k = 0; k < 3; ++k)
			assert_true(mesh->faces[3 * f + k] >= 0 && mesh->faces[3 * f + k] < mesh->vertex_count);
	}
	for (int v = 0; v < mesh->vertex_count; ++v) {
		assert_true(isfinite(mesh->rest[v].x) && isfinite(mesh->rest[v].y) && isfinite(mesh->rest[v].z));
		assert_true(isfinite(mesh->uv[v].x) && isfinite(mesh->uv[v].y));
	}
	// Every vertex belongs to a face: a vertex outside them would have no mass in the simulator.
	bool *used = calloc((size_t)mesh->vertex_count, sizeof *used);
	for (int i = 0; i < 3 * mesh->face_count; ++i)
		used[mesh->faces[i]] = true;
	for (int v = 0; v < mesh->vertex_count; ++v)
		if (!used[v])
			fail_msg("vertex %d at (%g, %g) belongs to no face", v, mesh->reference[v].x, mesh->reference[v].y);
	free(used);
	int n = 3 * mesh->face_count;
	int(*edges)[3] = malloc((size_t)n * sizeof *edges);
	for (int f = 0; f < mesh->face_count; ++f)
		for (int k = 0; k < 3; ++k) {
			edges[3 * f + k][0] = mesh->faces[3 * f + k];
			edges[3 * f + k][1] = mesh->faces[3 * f + (k + 1) % 3];
			edges[3 * f + k][2] = 0;
		}
	qsort(edges, (size_t)n, sizeof *edges, compare_ints3);
	for (int i = 1; i < n; ++i)
		assert_false(edges[i][0] == edges[i - 1][0] && edges[i][1] == edges[i - 1][1]);
	free(edges);
	// Overlaps: every pair of faces with overlapping boxes.
	for (int f = 0; f < mesh->face_count; ++f) {
		const int *a = mesh->faces + 3 * f;
		plume_vec2 pa[3] = {mesh->reference[a[0]], mesh->reference[a[1]], mesh->reference[a[2]]};
		double ax0 = fmin(pa[0].x, fmin(pa[1].x, pa[2].x)), ax1 = fmax(pa[0].x, fmax(pa[1].x, pa[2].x));
		double ay0 = fmin(pa[0].y, fmin(pa[1].y, pa[2].y)), ay1 = fmax(pa[0].y, fmax(pa[1].y, pa[2].y));
		for (int g = f + 1; g < mesh->face_count; ++g) {
			const int *b = mesh->faces + 3 * g;
			plume_vec2 pb[3] = {mesh->reference[b[0]], mesh->reference[b[1]], mesh->reference[b[2]]};
			if (fmax(pb[0].x, fmax(pb[1].x, pb[2].x)) < ax0 || fmin(pb[0].x, fmin(pb[1].x, pb[2].x)) > ax1 ||
			    fmax(pb[0].y, fmax(pb[1].y, pb[2].y)) < ay0 || fmin(pb[0].y, fmin(pb[1].y, pb[2].y)) > ay1)
				continue;
			for (int i = 0; i < 3; ++i)
				for (int j = 0; j < 3; ++j) {
					bool shared_a = a[i] == b[0] || a[i] == b[1] || a[i] == b[2];
					bool shared_b = b[j] == a[0] || b[j] == a[1] || b[j] == a[2];
					if (segments_cross(pa[i], pa[(i + 1) % 3], pb[j], pb[(j + 1) % 3]))
						fail_msg("faces %d (material %d) and %d (material %d) cross near (%g, %g)", f,
						         mesh->material[f], g, mesh->material[g], pa[i].x, pa[i].y);
					if (!shared_b && inside(pb[j], pa[0], pa[1], pa[2]))
						fail_msg("vertex %d of face %d lies inside face %d", b[j], g, f);
					if (!shared_a && inside(pa[i], pb[0], pb[1], pb[2]))
						fail_msg("vertex %d of face %d lies inside face %d", a[i], f, g);
				}
		}
	}
}

static bool has_edge(const plume_mesh *mesh, int f, int u, int v)
{
	for (int k = 0; k < 3; ++k) {
		int a = mesh->faces[3 * f + k], b = mesh->faces[3 * f + (k + 1) % 3];
		if ((a == u && b == v) || (a == v && b == u))
			return true;
	}
	return false;
}

static bool in_group(const plume_vertex_group *group, int v)
{
	for (int i = 0; i < group->count; ++i)
		if (group->vertices[i] == v)
			return true;
	return false;
}

/// Everything the simulator relies on in a barb-aligned mesh.
static void assert_aligned_mesh(const plume_mesh *mesh, const plume_mesh_report *report, double e)
{
	assert_valid_mesh(mesh);
	assert_true(report->aligned_fraction == 1.0);
	assert_true(report->min_angle >= min_angle_bound);
	plume_mesh_report measured = plume_mesh_measure(mesh);
	assert_true(measured.min_angle == report->min_angle);
	int vane = 0;
	for (int f = 0; f < mesh->face_count; ++f) {
		int k = mesh->barb_edge[f];
		if (mesh->material[f] == PLUME_MATERIAL_RACHIS) {
			assert_int_equal(k, -1);
			continue;
		}
		assert_int_equal(mesh->material[f], PLUME_MATERIAL_VANE);
		++vane;
		assert_true(k >= 0 && k < 3); // every vane face has its barb edge
		plume_vec2 p = mesh->reference[mesh->faces[3 * f + k]], q = mesh->reference[mesh->faces[3 * f + (k + 1) % 3]];
		double angle = mesh->barb_angle[f];
		assert_true(angle >= 0.0 && angle < pi);
		// The barb angle is the barb edge's direction, modulo pi.
		double length = hypot(q.x - p.x, q.y - p.y);
		assert_close(fabs((q.x - p.x) * sin(angle) - (q.y - p.y) * cos(angle)) / length, 0.0, 1e-12);
	}
	assert_true(vane > 0);
	// barb_edges: unique, sorted, each an edge of a vane face that marks it.
	for (int i = 0; i < mesh->barb_edge_count; ++i) {
		int u = mesh->barb_edges[2 * i], v = mesh->barb_edges[2 * i + 1];
		assert_true(u < v);
		if (i > 0)
			assert_true(mesh->barb_edges[2 * i - 2] < u ||
			            (mesh->barb_edges[2 * i - 2] == u && mesh->barb_edges[2 * i - 1] < v));
		bool found = false;
		for (int f = 0; f < mesh->face_count && !found; ++f)
			found = mesh->material[f] == PLUME_MATERIAL_VANE && has_edge(mesh, f, u, v);
		assert_true(found);
		double length = hypot(mesh->reference[v].x - mesh->reference[u].x, mesh->reference[v].y - mesh->reference[u].y);
		assert_true(length > 0.0 && length < 2.0 * e);
	}
	// Groups.
	const char *names[] = {"rachis", "rachis_base", "rachis_tip", "vane_tip", "left_edge", "right_edge"};
	for (int i = 0; i < 6; ++i)
		assert_non_null(plume_mesh_find_group(mesh, names[i]));
	const plume_vertex_group *rachis = plume_mesh_find_group(mesh, "rachis");
	const plume_vertex_group *base = plume_mesh_find_group(mesh, "rachis_base");
	const plume_vertex_group *tip = plume_mesh_find_group(mesh, "rachis_tip");
	const plume_vertex_group *vane_tip = plume_mesh_find_group(mesh, "vane_tip");
	assert_int_equal(base->count, 2);
	assert_int_equal(tip->count, 2);
	assert_true(vane_tip->count >= 1);
	for (int i = 0; i < base->count; ++i)
		assert_true(in_group(rachis, base->vertices[i]) && in_group(rachis, tip->vertices[i]));
	for (int i = 0; i < vane_tip->count; ++i)
		assert_false(in_group(rachis, vane_tip->vertices[i]));
	// rachis_base is the lowest row: no rachis vertex lies below it along the band.
	plume_vec2 b0 = mesh->reference[base->vertices[0]], b1 = mesh->reference[base->vertices[1]];
	plume_vec2 t0 = mesh->reference[tip->vertices[0]];
	plume_vec2 axis = {t0.x - b0.x, t0.y - b0.y};
	double width = hypot(b1.x - b0.x, b1.y - b0.y), length = hypot(axis.x, axis.y);
	for (int i = 0; i < rachis->count; ++i) {
		plume_vec2 p = mesh->reference[rachis->vertices[i]];
		assert_true(((p.x - b0.x) * axis.x + (p.y - b0.y) * axis.y) / length >= -width);
	}
	// Faces of the rachis use rachis vertices only.
	for (int f = 0; f < mesh->face_count; ++f)
		if (mesh->material[f] == PLUME_MATERIAL_RACHIS)
			for (int k = 0; k < 3; ++k)
				assert_true(in_group(rachis, mesh->faces[3 * f + k]));
	for (int side = 0; side < 2; ++side) {
		const plume_vertex_group *edge = plume_mesh_find_group(mesh, side == 0 ? "left_edge" : "right_edge");
		for (int i = 0; i < edge->count; ++i)
			assert_false(in_group(rachis, edge->vertices[i]));
	}
}

static void test_examples_are_aligned(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	for (size_t i = 0; i < sizeof examples / sizeof examples[0]; ++i) {
		plume_feather *feather = example(examples[i]);
		plume_mesh_def def = plume_mesh_default_def();
		plume_mesh *mesh = NULL;
		plume_mesh_report report;
		plume_error err;
		if (plume_mesh_from_feather(feather, &def, &mesh, &report, &err) != PLUME_OK)
			fail_msg("%s: %s", examples[i], err.message);
		print_message("%-10s %5d vertices %5d faces  min angle %.2f deg  dropped %d  averaged %d  trimmed %d\n",
		              examples[i], mesh->vertex_count, mesh->face_count, report.min_angle * 180.0 / pi,
		              report.guides_dropped, report.barbs_averaged, report.vertices_trimmed);
		assert_aligned_mesh(mesh, &report, def.edge_length);
		assert_true(report.guide_count[0] > 0 && report.guide_count[1] > 0);
		// Franco-Walter feathers are flat: the rest shape is the reference at z = 0.
		for (int v = 0; v < mesh->vertex_count; ++v) {
			assert_true(mesh->rest[v].x == mesh->reference[v].x && mesh->rest[v].y == mesh->reference[v].y);
			assert_true(mesh->rest[v].z == 0.0);
			assert_true(mesh->uv[v].x >= -1e-12 && mesh->uv[v].x <= 1.0 + 1e-12);
			assert_true(mesh->uv[v].y >= -1e-12 && mesh->uv[v].y <= 1.0 + 1e-12);
		}
		plume_mesh_destroy(mesh);
		plume_feather_destroy(feather);
	}
	assert_int_equal(plume_bytes_in_use(), before);
}

/// Issue 13: the vane's quality on every example feather of the three generators
/// at e = 5 mm and 2.5 mm. Outside junction faces (a shallow angle between a
/// guide and the rachis or the outline, or the face over a pointed rachis tip:
/// plume_mesh_report.excepted_count) the
/// smallest vane angle must reach 20 degrees; the rows below 20 are the measured
/// floor, pinned so that a change that makes them worse fails (docs/meshing.md
/// lists what still makes them: fans at guides cut short that no neighbour
/// vertex within e takes, the narrow strips of Streit-Heidrich barbs at a few
/// degrees to the rachis). Junction faces stay at most 4 % of the vane where it
/// has 100 faces or more.
typedef struct quality_row {
	const char *spec;
	double edge_length;
	double min_angle_deg; ///< vane_min_angle must reach it
	int excepted;         ///< excepted_count, at most
} quality_row;

static const quality_row quality_rows[] = {
    {"franco-walter/blue.json", 5e-3, 20.0, 0},
    {"franco-walter/blue.json", 2.5e-3, 20.0, 0},
    {"franco-walter/figure6a.json", 5e-3, 20.0, 2},
    {"franco-walter/figure6a.json", 2.5e-3, 20.0, 8},
    {"franco-walter/figure6b.json", 5e-3, 20.0, 1},
    {"franco-walter/figure6b.json", 2.5e-3, 20.0, 0},
    {"franco-walter/filoplume.json", 5e-3, 20.0, 1},
    {"franco-walter/filoplume.json", 2.5e-3, 20.0, 1},
    {"franco-walter/hawk.json", 5e-3, 20.0, 0},
    {"franco-walter/hawk.json", 2.5e-3, 20.0, 1},
    {"franco-walter/peacock.json", 5e-3, 20.0, 1},
    {"franco-walter/peacock.json", 2.5e-3, 5.92, 11},
    {"franco-walter/pigeon-primary.json", 5e-3, 20.0, 3},
    {"franco-walter/pigeon-primary.json", 2.5e-3, 20.0, 5},
    {"franco-walter/pigeon-secondary.json", 5e-3, 20.0, 0},
    {"franco-walter/pigeon-secondary.json", 2.5e-3, 20.0, 3},
    {"streit-heidrich/bristle.json", 5e-3, 20.0, 0},
    {"streit-heidrich/bristle.json", 2.5e-3, 20.0, 0},
    {"streit-heidrich/continuum.json", 5e-3, 20.0, 0},
    {"streit-heidrich/continuum.json", 2.5e-3, 20.0, 3},
    {"streit-heidrich/contour.json", 5e-3, 20.0, 0},
    {"streit-heidrich/contour.json", 2.5e-3, 20.0, 0},
    {"streit-heidrich/down.json", 5e-3, 20.0, 1},
    {"streit-heidrich/down.json", 2.5e-3, 20.0, 1},
    {"streit-heidrich/filoplume.json", 5e-3, 20.0, 5},
    {"streit-heidrich/filoplume.json", 2.5e-3, 6.90, 6},
    {"streit-heidrich/flight.json", 5e-3, 20.0, 29},
    {"streit-heidrich/flight.json", 2.5e-3, 20.0, 68},
    {"streit-heidrich/peacock.json", 5e-3, 5.93, 53},
    {"streit-heidrich/peacock.json", 2.5e-3, 0.31, 103},
    {"streit-heidrich/semiplume.json", 5e-3, 20.0, 4},
    {"streit-heidrich/semiplume.json", 2.5e-3, 20.0, 11},
    {"zhang-kanai/figure10-asymmetry-020.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure10-asymmetry-020.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure10-asymmetry-040.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure10-asymmetry-040.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure10-asymmetry-050.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure10-asymmetry-050.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure11-expansion.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure11-expansion.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure11-split.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure11-split.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure11-without-expansion.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure11-without-expansion.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure13-crest.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure13-crest.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure8-contour.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure8-contour.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure9-tip-angular.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure9-tip-angular.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure9-tip-pointed.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure9-tip-pointed.json", 2.5e-3, 20.0, 0},
    {"zhang-kanai/figure9-tip-rounded.json", 5e-3, 20.0, 0},
    {"zhang-kanai/figure9-tip-rounded.json", 2.5e-3, 20.0, 0},
};

/// Meshes examples/SPEC (a feather or guides spec) at edge length e, as `plume mesh` does.
static plume_mesh *example_mesh(const char *spec, double e, plume_mesh_report *report)
{
	char path[640];
	snprintf(path, sizeof path, "%s/examples/%s", PLUME_SOURCE_DIR, spec);
	plume_mesh_spec_options options = plume_mesh_spec_default_options();
	options.edge_length = e;
	plume_mesh *mesh = NULL;
	plume_error err;
	if (plume_mesh_spec_read(path, &options, &mesh, report, &err) != PLUME_OK)
		fail_msg("%s: %s", spec, err.message);
	return mesh;
}

static void test_example_quality(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	int meeting = 0;
	for (size_t i = 0; i < sizeof quality_rows / sizeof quality_rows[0]; ++i) {
		const quality_row *row = quality_rows + i;
		plume_mesh_report report;
		plume_mesh *mesh = example_mesh(row->spec, row->edge_length, &report);
		assert_valid_mesh(mesh);
		assert_true(report.aligned_fraction == 1.0);
		int vane = 0;
		for (int f = 0; f < mesh->face_count; ++f)
			if (mesh->material[f] == PLUME_MATERIAL_VANE) {
				++vane;
				assert_true(mesh->barb_edge[f] >= 0 && mesh->barb_edge[f] < 3);
			}
		plume_mesh_report measured = plume_mesh_measure(mesh);
		assert_true(measured.vane_min_angle == report.vane_min_angle);
		assert_int_equal(measured.excepted_count, report.excepted_count);
		double angle = report.vane_min_angle * 180.0 / pi;
		if (angle < row->min_angle_deg || report.excepted_count > row->excepted)
			fail_msg("%s at e = %g: vane min angle %.3f deg (bound %.2f), %d junction faces (at most %d)", row->spec,
			         row->edge_length, angle, row->min_angle_deg, report.excepted_count, row->excepted);
		if (vane >= 100)
			assert_true(report.excepted_count <= 0.04 * vane);
		meeting += angle >= PLUME_MESH_QUALITY_ANGLE_DEG;
		plume_mesh_destroy(mesh);
	}
	print_message("%d of %d example meshes reach %.0f degrees outside junction faces\n", meeting,
	              (int)(sizeof quality_rows / sizeof quality_rows[0]), PLUME_MESH_QUALITY_ANGLE_DEG);
	// 48 built by GCC, 49 by Clang since the thinned tries (47 by both before sliding left the
	// rachis tip's corner out, 45 before the bristle's lone stub was cut back, 39 by GCC before
	// the root-phased tries): the Streit-Heidrich generator's growth turns last-bit differences
	// between the two compilers into different feathers (different face counts), so the two
	// builds do not reach the same count. The rows above hold the lower floor of the two builds
	// and the higher junction count.
	assert_true(meeting >= 48);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// The junction test of plume_mesh_measure against a closed form: a vane face
/// (0,0) (1,0) (1,0.2) has atan(0.2) = 11.3 degrees at its first vertex, between
/// its barb edge (local 0) and edge 2. Alone, edge 2 is on the vane's border: a
/// junction face. With a second vane face across edge 2 it is an ordinary sliver.
static void test_junction_faces(void **state)
{
	(void)state;
	plume_mesh *mesh = plume_mesh_create(4, 2);
	assert_non_null(mesh);
	mesh->reference[0] = (plume_vec2){0.0, 0.0};
	mesh->reference[1] = (plume_vec2){1.0, 0.0};
	mesh->reference[2] = (plume_vec2){1.0, 0.2};
	mesh->reference[3] = (plume_vec2){0.0, 1.0};
	int faces[6] = {0, 1, 2, 0, 2, 3};
	memcpy(mesh->faces, faces, sizeof faces);
	mesh->barb_edge[0] = 0;
	mesh->barb_edge[1] = 1;
	mesh->material[0] = PLUME_MATERIAL_VANE;
	mesh->material[1] = PLUME_MATERIAL_RACHIS; // not part of the vane: edge 2 of face 0 is on the border
	plume_mesh_report report = plume_mesh_measure(mesh);
	assert_int_equal(report.excepted_count, 1);
	assert_true(report.vane_min_angle == pi); // no other vane face
	assert_close(report.min_angle, atan(0.2), 1e-15);
	mesh->material[1] = PLUME_MATERIAL_VANE; // now edge 2 is inside the vane
	report = plume_mesh_measure(mesh);
	assert_int_equal(report.excepted_count, 0);
	assert_close(report.vane_min_angle, atan(0.2), 1e-15);
	mesh->barb_edge[0] = 1; // barb edge not at the small angle: never a junction
	mesh->material[1] = PLUME_MATERIAL_RACHIS;
	report = plume_mesh_measure(mesh);
	assert_int_equal(report.excepted_count, 0);
	assert_close(report.vane_min_angle, atan(0.2), 1e-15);
	plume_mesh_destroy(mesh);
}

/// The rachis tip junction against a closed form: vane face (-0.05,0) (0.05,0)
/// (-0.05,1) over the rachis tip edge (the first two vertices, 0.1 wide) has
/// atan(0.1) = 5.7 degrees at its third vertex, facing that edge; its barb edge
/// (third to first vertex) meets a vane edge that a second vane face shares, so
/// it is no guide-to-border junction. It is a junction face when the first two
/// vertices are the group rachis_tip, an ordinary sliver otherwise.
static void test_rachis_tip_junction(void **state)
{
	(void)state;
	plume_mesh *mesh = plume_mesh_create(5, 3);
	assert_non_null(mesh);
	plume_vec2 p[5] = {{-0.05, 0.0}, {0.05, 0.0}, {-0.05, 1.0}, {0.0, -1.0}, {0.5, 1.0}};
	memcpy(mesh->reference, p, sizeof p);
	int faces[9] = {0, 1, 2, 1, 4, 2, 0, 3, 1};
	memcpy(mesh->faces, faces, sizeof faces);
	mesh->material[0] = mesh->material[1] = PLUME_MATERIAL_VANE;
	mesh->material[2] = PLUME_MATERIAL_RACHIS;
	mesh->barb_edge[0] = 2; // (-0.05,1) to (-0.05,0): the left vane's last guide
	mesh->barb_edge[1] = 0; // (0.05,0) to (0.5,1): the right vane's
	mesh->barb_edge[2] = -1;
	plume_mesh_report report = plume_mesh_measure(mesh);
	assert_int_equal(report.excepted_count, 0);
	assert_close(report.vane_min_angle, atan(0.1), 1e-15);
	plume_error err;
	int tip[2] = {0, 1};
	assert_int_equal(plume_mesh_add_group(mesh, "rachis_tip", tip, 2, &err), PLUME_OK);
	report = plume_mesh_measure(mesh);
	assert_int_equal(report.excepted_count, 1);
	// Left: the other vane face (0.05,0) (0.5,1) (-0.05,1), whose angles at its last
	// two vertices are atan2(1, 0.1) and atan2(1, 0.45): 29.9 degrees at the first.
	assert_close(report.vane_min_angle, pi - atan2(1.0, 0.1) - atan2(1.0, 0.45), 1e-14);
	int wrong[2] = {1, 2}; // a group that is not the edge the small angle faces: no junction
	plume_mesh_destroy(mesh);
	mesh = plume_mesh_create(5, 3);
	assert_non_null(mesh);
	memcpy(mesh->reference, p, sizeof p);
	memcpy(mesh->faces, faces, sizeof faces);
	mesh->material[0] = mesh->material[1] = PLUME_MATERIAL_VANE;
	mesh->material[2] = PLUME_MATERIAL_RACHIS;
	mesh->barb_edge[0] = 2;
	mesh->barb_edge[1] = 0;
	mesh->barb_edge[2] = -1;
	assert_int_equal(plume_mesh_add_group(mesh, "rachis_tip", wrong, 2, &err), PLUME_OK);
	report = plume_mesh_measure(mesh);
	assert_int_equal(report.excepted_count, 0);
	plume_mesh_destroy(mesh);
}

/// The default hawk with many seeds (random barb shapes that cross) and two
/// edge lengths: always a valid, fully aligned mesh.
static void test_random_seeds_and_edge_lengths(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_fw_def fw = plume_fw_default_def();
	double lengths[] = {5e-3, 2.5e-3, 1e-2};
	for (uint64_t seed = 1; seed <= 12; ++seed) {
		plume_feather *feather = NULL;
		assert_int_equal(plume_fw_generate(&fw, seed, &feather, NULL), PLUME_OK);
		for (int l = 0; l < 3; ++l) {
			plume_mesh_def def = plume_mesh_default_def();
			def.edge_length = lengths[l];
			plume_mesh *mesh = NULL;
			plume_mesh_report report;
			plume_error err;
			if (plume_mesh_from_feather(feather, &def, &mesh, &report, &err) != PLUME_OK)
				fail_msg("seed %d: %s", (int)seed, err.message);
			if (seed <= 3 || l == 0)
				assert_aligned_mesh(mesh, &report, def.edge_length);
			else
				assert_true(report.aligned_fraction == 1.0);
			if (seed == 1 && l == 0) {
				// 0.2 m feather at e = 5 mm: the simulator's resolution (thesis Table 6.1).
				print_message("hawk seed 1, e = 5 mm: %d vertices, %d faces\n", mesh->vertex_count, mesh->face_count);
				assert_in_range(mesh->vertex_count, 300, 3000);
			}
			plume_mesh_destroy(mesh);
		}
		plume_feather_destroy(feather);
	}
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_deterministic(void **state)
{
	(void)state;
	plume_feather *feather = example("hawk");
	plume_mesh_def def = plume_mesh_default_def();
	plume_mesh *a = NULL, *b = NULL;
	assert_int_equal(plume_mesh_from_feather(feather, &def, &a, NULL, NULL), PLUME_OK);
	assert_int_equal(plume_mesh_from_feather(feather, &def, &b, NULL, NULL), PLUME_OK);
	assert_int_equal(a->vertex_count, b->vertex_count);
	assert_int_equal(a->face_count, b->face_count);
	assert_memory_equal(a->reference, b->reference, (size_t)a->vertex_count * sizeof *a->reference);
	assert_memory_equal(a->rest, b->rest, (size_t)a->vertex_count * sizeof *a->rest);
	assert_memory_equal(a->uv, b->uv, (size_t)a->vertex_count * sizeof *a->uv);
	assert_memory_equal(a->faces, b->faces, (size_t)a->face_count * 3 * sizeof *a->faces);
	assert_memory_equal(a->barb_angle, b->barb_angle, (size_t)a->face_count * sizeof *a->barb_angle);
	assert_memory_equal(a->barb_edges, b->barb_edges, (size_t)a->barb_edge_count * 2 * sizeof *a->barb_edges);
	plume_mesh_destroy(a);
	plume_mesh_destroy(b);
	plume_feather_destroy(feather);
}

// ---------------------------------------------------------------------------
// Hand-built feathers: one-sided, zero-length barbs, short vanes, no barbs

/// A straight 0.1 m shaft along +y (optionally lifted into a parabola in z)
/// with barb_count straight barbs per listed side, each barb_length long at
/// 45 degrees tipwards, the vane on [0.3, 0.9] of the shaft.
static plume_feather *hand_feather(int barb_count, bool left, bool right, double barb_length, double bow)
{
	plume_feather *feather = plume_feather_create_empty();
	int samples = 21;
	plume_shaft_sample *shaft = plume_feather_add_shaft(feather, samples);
	for (int i = 0; i < samples; ++i) {
		double t = (double)i / (samples - 1);
		shaft[i] = (plume_shaft_sample){.position = plume_v3(0.0, 0.1 * t, bow * t * t),
		                                .tangent = plume_v3(0.0, 1.0, 0.0),
		                                .normal = plume_v3(0.0, 0.0, 1.0),
		                                .binormal = plume_v3(-1.0, 0.0, 0.0),
		                                .width = 2e-3 - 1.5e-3 * t,
		                                .t = t};
	}
	feather->calamus_count = 6;
	for (int side = 0; side < 2; ++side) {
		if ((side == 0 && !left) || (side == 1 && !right))
			continue;
		for (int b = 0; b < barb_count; ++b) {
			double t = 0.3 + 0.6 * (barb_count > 1 ? (double)b / (barb_count - 1) : 0.5);
			int first = plume_feather_add_points(feather, 5);
			for (int k = 0; k < 5; ++k) {
				double s = k / 4.0 * barb_length / sqrt(2.0);
				double x = side == 0 ? -s : s, y = 0.1 * t + s;
				feather->points[first + k] = plume_v3(x, y, bow * (y / 0.1) * (y / 0.1));
				feather->uv[first + k].y = t;
			}
			plume_curve_range range = {first, 5};
			plume_feather_measure_curve(feather, range);
			plume_barb_record record = {.curve = range, .side = (plume_side)side, .rachis_t = t};
			plume_feather_add_barb(feather, &record);
		}
	}
	return feather;
}

static void test_one_sided_feather(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_feather *feather = hand_feather(7, false, true, 0.03, 0.0);
	plume_mesh_def def = plume_mesh_default_def();
	plume_mesh *mesh = NULL;
	plume_mesh_report report;
	plume_error err;
	if (plume_mesh_from_feather(feather, &def, &mesh, &report, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	assert_aligned_mesh(mesh, &report, def.edge_length);
	assert_int_equal(report.guide_count[PLUME_SIDE_LEFT], 0);
	assert_true(report.guide_count[PLUME_SIDE_RIGHT] > 0);
	assert_int_equal(plume_mesh_find_group(mesh, "left_edge")->count, 0);
	// Vane vertices all lie on the right (+x) of the straight shaft.
	const plume_vertex_group *rachis = plume_mesh_find_group(mesh, "rachis");
	for (int v = rachis->count; v < mesh->vertex_count; ++v)
		assert_true(mesh->reference[v].x > 0.0);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_curved_rest_shape_and_zero_length_barbs(void **state)
{
	(void)state;
	// A bowed feather: rest z follows the shaft's and the barbs' height.
	plume_feather *feather = hand_feather(9, true, true, 0.025, 0.01);
	// Two zero-length barbs (all points equal) on the left.
	for (int b = 0; b < 2; ++b) {
		int first = plume_feather_add_points(feather, 3);
		for (int k = 0; k < 3; ++k)
			feather->points[first + k] = plume_v3(0.0, 0.05, 0.0025);
		plume_barb_record record = {.curve = {first, 3}, .side = PLUME_SIDE_LEFT, .rachis_t = 0.5};
		plume_feather_add_barb(feather, &record);
	}
	plume_mesh_def def = plume_mesh_default_def();
	plume_mesh *mesh = NULL;
	plume_mesh_report report;
	plume_error err;
	if (plume_mesh_from_feather(feather, &def, &mesh, &report, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	assert_aligned_mesh(mesh, &report, def.edge_length);
	assert_int_equal(report.guides_dropped, 2);
	for (int v = 0; v < mesh->vertex_count; ++v) {
		double y = mesh->reference[v].y;
		// Everything (shaft and barbs) lies on z = 0.01 (y / 0.1)^2; the band's
		// vertices and blended guides follow it to the interpolation's accuracy.
		assert_close(mesh->rest[v].z, 0.01 * (y / 0.1) * (y / 0.1), 2e-4);
	}
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
}

static void test_short_vanes_and_no_barbs(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	// Barbs 1 mm long at e = 5 mm: one step per guide.
	plume_feather *feather = hand_feather(5, true, true, 1e-3, 0.0);
	plume_mesh_def def = plume_mesh_default_def();
	plume_mesh *mesh = NULL;
	plume_mesh_report report;
	plume_error err;
	if (plume_mesh_from_feather(feather, &def, &mesh, &report, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	assert_valid_mesh(mesh);
	assert_true(report.aligned_fraction == 1.0);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);

	// No barbs at all: a clear error, no mesh.
	feather = hand_feather(0, true, true, 0.03, 0.0);
	mesh = (plume_mesh *)&report; // must be reset to NULL
	assert_int_equal(plume_mesh_from_feather(feather, &def, &mesh, &report, &err), PLUME_ERROR_SPEC);
	assert_null(mesh);
	assert_non_null(strstr(err.message, "no vane to mesh"));
	plume_feather_destroy(feather);

	// A bad edge length.
	feather = hand_feather(5, true, true, 0.03, 0.0);
	def.edge_length = -1.0;
	assert_int_equal(plume_mesh_from_feather(feather, &def, &mesh, &report, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "edge_length"));
	def.edge_length = 1e-9;
	assert_int_equal(plume_mesh_from_feather(feather, &def, &mesh, &report, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "too small"));
	plume_feather_destroy(feather);
	assert_int_equal(plume_bytes_in_use(), before);
}

// ---------------------------------------------------------------------------
// Explicit guides

static void test_explicit_guides(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	// A 0.1 m lens-shaped feather with a straight rachis and three guides per side.
	plume_vec2 boundary[8] = {{0.0, -0.001}, {0.02, 0.02},   {0.025, 0.06},  {0.01, 0.095},
	                          {0.0, 0.1},    {-0.01, 0.095}, {-0.025, 0.06}, {-0.02, 0.02}};
	plume_vec2 rachis[2] = {{0.0, 0.0}, {0.0, 0.1}};
	plume_vec2 points[12] = {{0.0, 0.01}, {-0.02, 0.03}, {0.0, 0.05}, {-0.03, 0.08}, {0.0, 0.09}, {-0.02, 0.11},
	                         {0.0, 0.01}, {0.02, 0.03},  {0.0, 0.05}, {0.03, 0.08},  {0.0, 0.09}, {0.02, 0.11}};
	int offsets[7] = {0, 2, 4, 6, 8, 10, 12};
	plume_mesh_guides guides = {.boundary_count = 8,
	                            .boundary = boundary,
	                            .rachis_count = 2,
	                            .rachis = rachis,
	                            .guide_count = 6,
	                            .guide_offsets = offsets,
	                            .guide_points = points};
	plume_mesh_def def = plume_mesh_default_def();
	def.rachis_width_base = 2e-3;
	def.rachis_width_tip = 1e-3;
	plume_mesh *mesh = NULL;
	plume_mesh_report report;
	plume_error err;
	if (plume_mesh_from_guides(&guides, &def, &mesh, &report, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	assert_aligned_mesh(mesh, &report, def.edge_length);
	assert_int_equal(report.guides_dropped, 0);
	assert_true(report.guide_count[0] >= 15 && report.guide_count[1] >= 15);
	// Guide tips lie on the boundary: inside its bounding box, and some on the outline.
	for (int v = 0; v < mesh->vertex_count; ++v) {
		assert_true(fabs(mesh->reference[v].x) <= 0.025 + 1e-9);
		assert_true(mesh->reference[v].y >= -1e-3 - 1e-9 && mesh->reference[v].y <= 0.1 + 1e-9);
		assert_true(mesh->rest[v].z == 0.0);
	}
	// The estimate counts the rows and the guide vertices before any is placed: at least
	// the mesh's vertices (trimming only removes some), at most the pool of placed ones.
	plume_mesh_estimate estimate;
	assert_int_equal(plume_mesh_estimate_guides(&guides, &def, &estimate, &err), PLUME_OK);
	print_message("estimate %.0f vertices, %.0f faces, %.0f bytes; mesh %d vertices, %d faces\n", estimate.vertices,
	              estimate.faces, estimate.bytes, mesh->vertex_count, mesh->face_count);
	assert_true(estimate.vertices >= mesh->vertex_count && estimate.vertices <= 1.2 * mesh->vertex_count + 100);
	assert_true(estimate.faces >= mesh->face_count);
	assert_true(estimate.rachis_length > 0.099 && estimate.rachis_length < 0.101);
	assert_true(estimate.longest_guide > 0.02 && estimate.longest_guide < 0.05);
	assert_true(estimate.bytes >= PLUME_MESH_BYTES_PER_VERTEX * estimate.vertices);
	plume_mesh_destroy(mesh);
	// Past def.max_memory: PLUME_ERROR_LIMIT before the work, nothing built.
	def.max_memory = (uint64_t)(0.5 * estimate.bytes);
	assert_int_equal(plume_mesh_from_guides(&guides, &def, &mesh, &report, &err), PLUME_ERROR_LIMIT);
	assert_null(mesh);
	assert_non_null(strstr(err.message, "raise it with --max-memory"));
	def.max_memory = (uint64_t)(2.0 * estimate.bytes);
	assert_int_equal(plume_mesh_from_guides(&guides, &def, &mesh, &report, &err), PLUME_OK);
	plume_mesh_destroy(mesh);
	def.max_memory = 0;

	// Widths are required for explicit guides.
	def.rachis_width_base = 0.0;
	assert_int_equal(plume_mesh_from_guides(&guides, &def, &mesh, &report, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "rachis_width_base"));
	assert_int_equal(plume_bytes_in_use(), before);
}

/// Distance from p to segment ab.
static double segment_distance(plume_vec2 p, plume_vec2 a, plume_vec2 b)
{
	double dx = b.x - a.x, dy = b.y - a.y;
	double t = ((p.x - a.x) * dx + (p.y - a.y) * dy) / (dx * dx + dy * dy);
	t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
	return hypot(a.x + t * dx - p.x, a.y + t * dy - p.y);
}

/// The edge length of mesh_two_guides.
static const double TWO_GUIDES_EDGE = 0.004;

/// Meshes two straight guides (points: root and tip of each) rooted on a straight
/// rachis from (0, 0) to (0, 0.1) inside boundary, at e = TWO_GUIDES_EDGE with a 2 to
/// 1 mm band.
static plume_mesh *mesh_two_guides(plume_vec2 *boundary, int boundary_count, plume_vec2 points[4],
                                   plume_mesh_report *report)
{
	plume_vec2 rachis[2] = {{0.0, 0.0}, {0.0, 0.1}};
	int offsets[3] = {0, 2, 4};
	plume_mesh_guides guides = {.boundary_count = boundary_count,
	                            .boundary = boundary,
	                            .rachis_count = 2,
	                            .rachis = rachis,
	                            .guide_count = 2,
	                            .guide_offsets = offsets,
	                            .guide_points = points};
	plume_mesh_def def = plume_mesh_default_def();
	def.edge_length = TWO_GUIDES_EDGE;
	def.rachis_width_base = 0.002;
	def.rachis_width_tip = 0.001;
	plume_mesh *mesh = NULL;
	plume_error err;
	if (plume_mesh_from_guides(&guides, &def, &mesh, report, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	return mesh;
}

/// Barbs at a shallow angle to the rachis (docs/meshing.md, "Root-phased
/// steps"): straight barbs at 15 degrees to a straight rachis, rows 4 mm
/// apart, so each guide lies h = 4 sin 15 = 1.04 mm from the next and the
/// next guide's root lies c = 4 cos 15 = 3.86 mm along it; the outline cuts
/// the guides square. Steps of about e leave neighbouring guides' vertices
/// nearly side by side at the rachis: 16.4 degrees there (measured before the
/// root-phased try). Steps of 2 c / 3 put every vertex midway between two of
/// the next guide's from the root on: zigzag faces of base angles
/// atan(3 tan 15) = 38.8 degrees, and 38.8 - 15 = 23.8 degrees at the next
/// root in the face on the rachis edge (its 15 degrees at the root is a
/// junction angle), so the vane reaches 20 degrees.
static void test_shallow_barbs_phased(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	const double theta = 15.0 * pi / 180.0, reach = 0.06;
	plume_vec2 u = {sin(theta), cos(theta)}, n = {u.y, -u.x};
	double t = (-0.001 - reach * u.x) / n.x; // where the square cut meets x = -1 mm
	plume_vec2 boundary[3] = {{-0.001, -0.002},
	                          {reach * u.x + 0.05 * n.x, reach * u.y + 0.05 * n.y},
	                          {reach * u.x + t * n.x, reach * u.y + t * n.y}};
	plume_vec2 points[4] = {{0.0, 0.0}, {0.2 * u.x, 0.2 * u.y}, {0.0, 0.1}, {0.2 * u.x, 0.1 + 0.2 * u.y}};
	plume_mesh_report report;
	plume_mesh *mesh = mesh_two_guides(boundary, 3, points, &report);
	assert_aligned_mesh(mesh, &report, TWO_GUIDES_EDGE);
	print_message("vane min angle %.3f deg, %d junction faces\n", report.vane_min_angle * 180.0 / pi,
	              report.excepted_count);
	assert_true(report.vane_min_angle * 180.0 / pi >= PLUME_MESH_QUALITY_ANGLE_DEG);
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// The vane faces' area, m^2.
static double vane_area(const plume_mesh *mesh)
{
	double area = 0.0;
	for (int f = 0; f < mesh->face_count; ++f)
		if (mesh->material[f] == PLUME_MATERIAL_VANE)
			area += 0.5 * signed_area2(mesh, f);
	return area;
}

/// True when p lies inside the polygon (even-odd rule).
static bool in_polygon(const plume_vec2 *polygon, int count, plume_vec2 p)
{
	bool in = false;
	for (int i = 0, j = count - 1; i < count; j = i++) {
		plume_vec2 a = polygon[i], b = polygon[j];
		if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y))
			in = !in;
	}
	return in;
}

/// A feather of straight barbs at theta to the straight rachis of mesh_two_guides,
/// its outline at x = foot, stepping out to x = top along the guide rooted at y =
/// 50 mm, gap outside it (on the side of the guide below). *region: the area the
/// vane should cover, by a 0.1 mm grid: inside the outline, outside the band (2 to
/// 1 mm wide), between the first guide (rooted at y = 0) and the last (y = 0.1).
static plume_mesh *stepped_outline_mesh(double theta, double foot, double top, double gap, plume_mesh_report *report,
                                        double *region)
{
	const double root = 0.05, cell = 1e-4;
	plume_vec2 u = {sin(theta), cos(theta)}, n = {u.y, -u.x};
	plume_vec2 low = {foot + gap * n.x, root + foot / u.x * u.y + gap * n.y};
	plume_vec2 high = {top + gap * n.x, root + top / u.x * u.y + gap * n.y};
	plume_vec2 outline[7] = {{-0.001, -0.002}, {foot, -0.002}, {foot, low.y}, low, high, {top, 0.13}, {-0.001, 0.13}};
	plume_vec2 points[4] = {{0.0, 0.0}, {0.2 * u.x, 0.2 * u.y}, {0.0, 0.1}, {0.2 * u.x, 0.1 + 0.2 * u.y}};
	*region = 0.0;
	for (double x = 0.5 * cell; x < 0.012; x += cell)
		for (double y = -0.002 + 0.5 * cell; y < 0.135; y += cell) {
			double half_width = 0.001 - 0.0005 * fmin(fmax(y / 0.1, 0.0), 1.0);
			bool vane = x >= half_width && y >= (x - 0.001) * u.y / u.x && y <= 0.1 + (x - 0.0005) * u.y / u.x;
			if (vane && in_polygon(outline, 7, (plume_vec2){x, y}))
				*region += cell * cell;
		}
	return mesh_two_guides(outline, 7, points, report);
}

/// A guide that runs along the outline past its neighbour's tip (docs/meshing.md,
/// step 11): the outline of stepped_outline_mesh at x = 8 mm stepping out to 9.5
/// mm, 0.4 mm outside the guide, barbs at 19 degrees. The guide below ends at the
/// step's foot, and its strip closes with a fan from that tip over the guide's last
/// vertices: 7.7 degrees in every try that keeps the tail (measured). Cut back one
/// vertex, the vane reaches 20 degrees and keeps 99.4 % of the area it should
/// cover. With the step 0.2 mm outside the guide, from 8 to 10 mm at 20 degrees,
/// cutting tails reaches 20 degrees only by leaving out 6.5 % of the vane: that try
/// is not kept (MESH_VARIANT_AREA), and the vane stays whole.
static void test_outline_tail_cut(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_mesh_report report;
	double region;
	plume_mesh *mesh = stepped_outline_mesh(19.0 * pi / 180.0, 0.008, 0.0095, 4e-4, &report, &region);
	assert_aligned_mesh(mesh, &report, TWO_GUIDES_EDGE);
	print_message("vane min angle %.3f deg, %d vertices cut, vane %.4g m^2 of %.4g\n",
	              report.vane_min_angle * 180.0 / pi, report.vertices_trimmed, vane_area(mesh), region);
	assert_true(report.vane_min_angle * 180.0 / pi >= PLUME_MESH_QUALITY_ANGLE_DEG);
	assert_true(report.vertices_trimmed >= 1);
	assert_true(vane_area(mesh) >= 0.95 * region && vane_area(mesh) <= 1.05 * region);
	plume_mesh_destroy(mesh);

	mesh = stepped_outline_mesh(20.0 * pi / 180.0, 0.008, 0.010, 2e-4, &report, &region);
	assert_aligned_mesh(mesh, &report, TWO_GUIDES_EDGE);
	print_message("vane min angle %.3f deg, %d vertices cut, vane %.4g m^2 of %.4g\n",
	              report.vane_min_angle * 180.0 / pi, report.vertices_trimmed, vane_area(mesh), region);
	assert_true(vane_area(mesh) >= 0.95 * region && vane_area(mesh) <= 1.05 * region);
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// A guide that ends well before its neighbours (docs/meshing.md, "Joining
/// short guides"): straight barbs at 30 degrees to a straight rachis, rows 4 mm
/// apart (guides 2 mm apart), and a slot 0.6 mm wide cut into the outline
/// along the guide rooted at y = 48 mm, ending 13.5 mm along it, so that guide
/// alone ends there. Without the join the strips beside it end in fans from its
/// tip: 1.24 degrees (measured); joined, the tip moves onto a neighbour's
/// vertex, no vertex stays on the slot, and the vane's smallest angle is that
/// of the same feather without the slot.
static void test_short_guide_joined(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	const double along = 0.0135, half_width = 3e-4;
	plume_vec2 u = {0.5, sqrt(3.0) / 2.0}, n = {-u.y, u.x}, root = {0.00076, 0.048}; // the row's rachis vertex
	plume_vec2 cap = {root.x + along * u.x, root.y + along * u.y};
	plume_vec2 low = {cap.x - half_width * n.x, cap.y - half_width * n.y};
	plume_vec2 high = {cap.x + half_width * n.x, cap.y + half_width * n.y};
	plume_vec2 low_out = {0.02, low.y + (0.02 - low.x) * u.y / u.x},
	           high_out = {0.02, high.y + (0.02 - high.x) * u.y / u.x};
	plume_vec2 plain[4] = {{-0.001, -0.002}, {0.02, -0.002}, {0.02, 0.13}, {-0.001, 0.13}};
	plume_vec2 slotted[8] = {{-0.001, -0.002}, {0.02, -0.002}, low_out,       low, high,
	                         high_out,         {0.02, 0.13},   {-0.001, 0.13}};
	plume_vec2 points[4] = {{0.0, 0.01}, {0.06 * u.x, 0.01 + 0.06 * u.y}, {0.0, 0.08}, {0.06 * u.x, 0.08 + 0.06 * u.y}};
	plume_mesh_report plain_report, report;
	plume_mesh_destroy(mesh_two_guides(plain, 4, points, &plain_report));
	plume_mesh *mesh = mesh_two_guides(slotted, 8, points, &report);
	assert_aligned_mesh(mesh, &report, TWO_GUIDES_EDGE);
	print_message("vane min angle %.3f deg, %.3f deg without the slot\n", report.vane_min_angle * 180.0 / pi,
	              plain_report.vane_min_angle * 180.0 / pi);
	assert_true(report.vane_min_angle >= plain_report.vane_min_angle);
	for (int v = 0; v < mesh->vertex_count; ++v) {
		plume_vec2 p = mesh->reference[v];
		double gap = fmin(segment_distance(p, low_out, low),
		                  fmin(segment_distance(p, low, high), segment_distance(p, high, high_out)));
		if (gap < 1e-9)
			fail_msg("vertex %d at (%g, %g) lies on the slot", v, p.x, p.y);
	}
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// A vane of two guides whose end guide is a stub (docs/meshing.md, step 5):
/// the Streit-Heidrich bristle at 5 mm has one guide on its left (a vane of
/// one barb, no area) and on its right a 3.5 mm guide and, one row up, a
/// 0.38 mm one. Walked, their strip was a sliver of 4.3 degrees from the
/// 3.5 mm guide's tip, and the left guide's tip a vertex of no face. Now the
/// stub is cut back to its root and the vane is the one triangle between the
/// long guide and the two rachis vertices (its angles 43, 56 and 81
/// degrees built by GCC; Clang's feather differs, 46.6 at its smallest), and
/// the lone left guide is left out. At 2.5 mm the same stub's
/// strip rises from 15.3 to 23.5 degrees.
static void test_lone_stub_cut_back(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	const double edges[2] = {5e-3, 2.5e-3};
	for (int i = 0; i < 2; ++i) {
		plume_mesh_report report;
		plume_mesh *mesh = example_mesh("streit-heidrich/bristle.json", edges[i], &report);
		assert_valid_mesh(mesh);
		print_message("e = %g: vane min angle %.2f deg, guides %d + %d\n", edges[i], report.vane_min_angle * 180.0 / pi,
		              report.guide_count[0], report.guide_count[1]);
		assert_true(report.vane_min_angle * 180.0 / pi >= PLUME_MESH_QUALITY_ANGLE_DEG);
		if (i == 0) {
			assert_int_equal(report.guide_count[PLUME_SIDE_LEFT], 0);
			assert_int_equal(plume_mesh_find_group(mesh, "left_edge")->count, 0);
			int vane = -1, count = 0;
			for (int f = 0; f < mesh->face_count; ++f)
				if (mesh->material[f] == PLUME_MATERIAL_VANE) {
					vane = f;
					++count;
				}
			assert_int_equal(count, 1);
			// Two right rachis vertices (2 r + 1) one row apart, and the long guide's tip.
			const int *v = mesh->faces + 3 * vane;
			const plume_vertex_group *right = plume_mesh_find_group(mesh, "right_edge");
			int rachis_count = plume_mesh_find_group(mesh, "rachis")->count, low = INT_MAX, high = -1, tip = -1;
			for (int k = 0; k < 3; ++k)
				if (v[k] < rachis_count) {
					assert_int_equal(v[k] % 2, 1);
					low = v[k] < low ? v[k] : low;
					high = v[k] > high ? v[k] : high;
				} else
					tip = v[k];
			assert_int_equal(high - low, 2);
			assert_int_equal(right->count, 1);
			assert_int_equal(right->vertices[0], tip);
		}
		plume_mesh_destroy(mesh);
	}
	assert_int_equal(plume_bytes_in_use(), before);
}

static void test_guides_spec_errors(void **state)
{
	(void)state;
	char dir[512], path[640];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/guides.json", dir);
	struct {
		const char *text, *expected;
	} cases[] = {
	    {"{\"guides\": [[[0,0],[1,1]]], \"rachis\": [[0,0],[0,1]]}", "needs \"boundary\""},
	    {"{\"guides\": [[[0,0],[1,1]]], \"rachis\": [[0,0],[0,1]], \"boundary\": [[0,0],[1,0]]}",
	     "$.boundary: expected an array of at least 3 points"},
	    {"{\"guides\": [{\"type\": \"spline\", \"points\": [[0,0],[1,1]]}], \"rachis\": [[0,0],[0,1]], "
	     "\"boundary\": [[0,0],[1,0],[1,1]]}",
	     "$.guides[0].type: unknown spline type \"spline\""},
	    {"{\"guides\": [[[0,0],[1,\"a\"]]], \"rachis\": [[0,0],[0,1]], \"boundary\": [[0,0],[1,0],[1,1]]}",
	     "$.guides[0][1]: expected a point"},
	    {"{\"guides\": [[[0,0],[1,1]]], \"rachis\": [[0,0],[0,1]], \"boundary\": [[0,0],[1,0],[1,1]], "
	     "\"mesh\": {\"edge_lenght\": 1}}",
	     "$.mesh"},
	    {"{\"guides\": [[[0,0],[1,1]]], \"rachis\": [[0,0],[0,1]], \"boundary\": [[0,0],[1,0],[1,1]], "
	     "\"mesh\": {\"edge_length\": -1}}",
	     "$.mesh.edge_length: is -1"},
	};
	int64_t before = plume_bytes_in_use();
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
		test_write_file(path, cases[i].text);
		plume_mesh_spec_options options = plume_mesh_spec_default_options();
		plume_mesh *mesh = NULL;
		plume_mesh_report report;
		plume_error err = {0};
		plume_status status = plume_mesh_spec_read(path, &options, &mesh, &report, &err);
		assert_int_equal(status, PLUME_ERROR_SPEC);
		assert_null(mesh);
		if (strstr(err.message, cases[i].expected) == NULL || strstr(err.message, "guides.json") == NULL)
			fail_msg("case %d: \"%s\" lacks \"%s\"", (int)i, err.message, cases[i].expected);
	}
	assert_int_equal(plume_bytes_in_use(), before);
	test_remove_tree(dir);
}

static void test_guides_spec_splines(void **state)
{
	(void)state;
	char dir[512], path[640];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/guides.json", dir);
	snprintf(path, sizeof path, "%s/examples/meshes/guides.json", PLUME_SOURCE_DIR);
	plume_mesh_spec_options options = plume_mesh_spec_default_options();
	plume_mesh *mesh = NULL;
	plume_mesh_report report;
	plume_error err;
	if (plume_mesh_spec_read(path, &options, &mesh, &report, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	assert_aligned_mesh(mesh, &report, report.edge_length);
	plume_mesh_destroy(mesh);
	test_remove_tree(dir);
}

/// tests/data/NAME meshed with the default options; fails the test with the error's message.
static plume_mesh *mesh_test_data(const char *name, plume_mesh_report *report)
{
	char path[640];
	snprintf(path, sizeof path, "%s/tests/data/%s", PLUME_SOURCE_DIR, name);
	plume_mesh_spec_options options = plume_mesh_spec_default_options();
	plume_mesh *mesh = NULL;
	plume_error err;
	if (plume_mesh_spec_read(path, &options, &mesh, report, &err) != PLUME_OK)
		fail_msg("%s: %s", name, err.message);
	return mesh;
}

/// A feather five times the example's size: the strip walk's spatial index
/// (src/mesh/aligned.c) gives the scan's mesh. The counts are those the
/// mesher gives with every query scanned (MESH_SCAN_MAX raised past the pool;
/// re-measured so for the staggered guide vertices, the joined short guides
/// and the tries that thin guides at 0.4 e or cut tails along the outline, of
/// issue 13). The index took the time from 5x down here, 150x at 20x the
/// size.
static void test_tall_guides(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_mesh_report report;
	plume_mesh *mesh = mesh_test_data("tall-guides.json", &report);
	assert_int_equal(mesh->vertex_count, 10039);
	assert_int_equal(mesh->face_count, 19771);
	assert_int_equal(mesh->barb_edge_count, 9747);
	assert_int_equal(report.vertices_trimmed, 115);
	assert_int_equal(report.guide_count[0], 148);
	assert_int_equal(report.guide_count[1], 149);
	assert_true(report.aligned_fraction == 1.0);
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// Every vertex belongs to a face (one outside them is massless in the simulator). Two short
/// guides joined from both sides to the same vertex of the guide between them closed both of
/// its strips there, and its tip belonged to no face (tests/data/orphan-tip.json, random
/// guides); a build with such a vertex fails, so the unjoined mesh stands.
static void test_every_vertex_in_a_face(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_mesh_report report;
	plume_mesh *mesh = mesh_test_data("orphan-tip.json", &report);
	bool *used = calloc((size_t)mesh->vertex_count, sizeof *used);
	for (int i = 0; i < 3 * mesh->face_count; ++i)
		used[mesh->faces[i]] = true;
	for (int v = 0; v < mesh->vertex_count; ++v)
		if (!used[v])
			fail_msg("vertex %d of %d is in no face", v, mesh->vertex_count);
	free(used);
	assert_true(report.aligned_fraction == 1.0);
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// The try that cuts tails along the outline (trim_outline_tails) checks the closing edges of
/// a guide's strips; a strip whose other guide was left out as a stub before it
/// (drop_short_end_guides: no vertices) had its closing edge read at vertex -1, before the
/// point pool (AddressSanitizer, heap-buffer-overflow; garbage in other builds). Such strips are
/// skipped, as walk_line_strips skips them.
static void test_tails_past_dropped_guide(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_mesh_report report;
	plume_mesh *mesh = mesh_test_data("tails-dropped-guide.json", &report);
	assert_int_equal(mesh->vertex_count, 20);
	assert_int_equal(mesh->face_count, 22);
	assert_true(report.aligned_fraction == 1.0);
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), before);
}

/// The last safety net finds overlapping faces through a grid (src/mesh/aligned.c,
/// find_overlap) and names a face, when every try folds (tests/data/folding-guides.json).
/// A first try that folds is passed over: the Franco-Walter peacock at seed 4 and e = 1 mm,
/// which this test held to the error before, is meshed by a thinned try.
static void test_overlap_reported(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	char path[640];
	snprintf(path, sizeof path, "%s/tests/data/folding-guides.json", PLUME_SOURCE_DIR);
	plume_mesh_spec_options options = plume_mesh_spec_default_options();
	plume_mesh *mesh = NULL;
	plume_error err;
	assert_int_equal(plume_mesh_spec_read(path, &options, &mesh, NULL, &err), PLUME_ERROR_NUMERIC);
	assert_null(mesh);
	if (strstr(err.message, "fold over one another near (0.0036397, 0.0439616) m") == NULL)
		fail_msg("%s", err.message);
	assert_int_equal(plume_bytes_in_use(), before);

	snprintf(path, sizeof path, "%s/examples/franco-walter/peacock.json", PLUME_SOURCE_DIR);
	options.edge_length = 0.001;
	options.seed = 4;
	options.seed_given = true;
	plume_mesh_report report;
	if (plume_mesh_spec_read(path, &options, &mesh, &report, &err) != PLUME_OK)
		fail_msg("%s", err.message);
	assert_true(report.aligned_fraction == 1.0);
	assert_true(mesh->face_count > 40000);
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), before);
}

// ---------------------------------------------------------------------------
// OBJ

/// A mesh with a NaN, an infinite number or one past single precision (3.4e38, glTF's floats)
/// is refused by the OBJ and glTF writers, naming the vertex, and no file is written: the OBJ
/// writer printed "nan" (which no reader, plume's included, takes for a number) and the glTF
/// writer NaN positions, bounds without them, and a max of two numbers for 1e300 (JSON has no
/// infinity), exit 0.
static void test_mesh_writers_refuse_non_finite(void **state)
{
	(void)state;
	char dir[512], obj[640], glb[640];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(obj, sizeof obj, "%s/mesh.obj", dir);
	snprintf(glb, sizeof glb, "%s/mesh.glb", dir);
	plume_feather *feather = example("figure6a");
	plume_mesh_def def = plume_mesh_default_def();
	plume_mesh *mesh = NULL;
	assert_int_equal(plume_mesh_from_feather(feather, &def, &mesh, NULL, NULL), PLUME_OK);
	plume_error err;
	mesh->rest[3].y = NAN;
	assert_int_equal(plume_mesh_write_obj(mesh, NULL, obj, &err), PLUME_ERROR_NUMERIC);
	assert_non_null(strstr(err.message, "mesh.obj: vertex 4 has a NaN or infinite number"));
	assert_int_equal(plume_mesh_write_glb(mesh, NULL, NULL, glb, &err), PLUME_ERROR_NUMERIC);
	assert_non_null(strstr(err.message, "mesh.glb: vertex 4 has a NaN or infinite number"));
	mesh->rest[3].y = 1e300; // a double, written by OBJ; past glTF's floats
	assert_int_equal(plume_mesh_write_glb(mesh, NULL, NULL, glb, &err), PLUME_ERROR_NUMERIC);
	assert_int_equal(access(glb, F_OK), -1);
	mesh->rest[3].y = 0.0;
	mesh->uv[5].x = INFINITY;
	assert_int_equal(plume_mesh_write_obj(mesh, NULL, obj, &err), PLUME_ERROR_NUMERIC);
	assert_non_null(strstr(err.message, "vertex 6"));
	assert_int_equal(access(obj, F_OK), -1);
	mesh->uv[5].x = 0.0;
	// Positions other than rest, through the frame writer too.
	plume_vec3 *moved = malloc((size_t)mesh->vertex_count * sizeof *moved);
	memcpy(moved, mesh->rest, (size_t)mesh->vertex_count * sizeof *moved);
	moved[7].z = -INFINITY;
	assert_int_equal(plume_mesh_write_obj(mesh, moved, obj, &err), PLUME_ERROR_NUMERIC);
	plume_mesh_obj_writer *writer = NULL;
	assert_int_equal(plume_mesh_obj_writer_create(mesh, &writer, &err), PLUME_OK);
	assert_int_equal(plume_mesh_obj_writer_write(writer, moved, obj, &err), PLUME_ERROR_NUMERIC);
	assert_non_null(strstr(err.message, "vertex 8"));
	assert_int_equal(access(obj, F_OK), -1);
	assert_int_equal(plume_mesh_obj_writer_write(writer, NULL, obj, &err), PLUME_OK);
	assert_int_equal(plume_mesh_write_glb(mesh, NULL, NULL, glb, &err), PLUME_OK);
	plume_mesh_obj_writer_destroy(writer);
	free(moved);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
	test_remove_tree(dir);
}

static void test_obj_round_trip(void **state)
{
	(void)state;
	char dir[512], path[640];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/mesh.obj", dir);
	plume_feather *feather = example("figure6a");
	plume_mesh_def def = plume_mesh_default_def();
	plume_mesh *mesh = NULL, *back = NULL;
	assert_int_equal(plume_mesh_from_feather(feather, &def, &mesh, NULL, NULL), PLUME_OK);
	// Awkward values: thirds, a huge and a tiny magnitude, -0.
	mesh->rest[0] = plume_v3(1.0 / 3.0, -0.0, 1e-300);
	mesh->rest[1].z = 12345.678901234567;
	plume_error err;
	assert_int_equal(plume_mesh_write_obj(mesh, NULL, path, &err), PLUME_OK);
	assert_int_equal(plume_mesh_read_obj(path, &back, &err), PLUME_OK);
	assert_int_equal(back->vertex_count, mesh->vertex_count);
	assert_int_equal(back->face_count, mesh->face_count);
	for (int v = 0; v < mesh->vertex_count; ++v) {
		assert_close(back->rest[v].x, mesh->rest[v].x, 1e-12);
		assert_close(back->rest[v].y, mesh->rest[v].y, 1e-12);
		assert_close(back->rest[v].z, mesh->rest[v].z, 1e-12);
		assert_true(back->rest[v].x == mesh->rest[v].x && back->rest[v].z == mesh->rest[v].z); // %.17g is exact
		assert_true(back->uv[v].x == mesh->uv[v].x && back->uv[v].y == mesh->uv[v].y);
		assert_true(back->reference[v].x == mesh->rest[v].x && back->reference[v].y == mesh->rest[v].y);
	}
	assert_memory_equal(back->faces, mesh->faces, (size_t)mesh->face_count * 3 * sizeof *mesh->faces);
	assert_memory_equal(back->material, mesh->material, (size_t)mesh->face_count);
	for (int f = 0; f < back->face_count; ++f)
		assert_int_equal(back->barb_edge[f], -1);
	// Written positions other than rest.
	plume_vec3 *moved = malloc((size_t)mesh->vertex_count * sizeof *moved);
	for (int v = 0; v < mesh->vertex_count; ++v)
		moved[v] = plume_v3(mesh->rest[v].x, mesh->rest[v].y, 0.5);
	plume_mesh_destroy(back);
	assert_int_equal(plume_mesh_write_obj(mesh, moved, path, &err), PLUME_OK);
	assert_int_equal(plume_mesh_read_obj(path, &back, &err), PLUME_OK);
	assert_true(back->rest[7].z == 0.5);
	// The frame writer (the invariant lines formatted once) writes the same bytes, frame after
	// frame, and a different file for different positions.
	char framed[640];
	snprintf(framed, sizeof framed, "%s/frame.obj", dir);
	plume_mesh_obj_writer *writer = NULL;
	assert_int_equal(plume_mesh_obj_writer_create(mesh, &writer, &err), PLUME_OK);
	assert_int_equal(plume_mesh_obj_writer_write(writer, moved, framed, &err), PLUME_OK);
	assert_true(test_hash_file(framed) == test_hash_file(path));
	assert_int_equal(plume_mesh_obj_writer_write(writer, NULL, framed, &err), PLUME_OK);
	assert_true(test_hash_file(framed) != test_hash_file(path));
	assert_int_equal(plume_mesh_write_obj(mesh, NULL, path, &err), PLUME_OK);
	assert_true(test_hash_file(framed) == test_hash_file(path));
	plume_mesh_obj_writer_destroy(writer);
	free(moved);
	plume_mesh_destroy(back);
	plume_mesh_destroy(mesh);
	plume_feather_destroy(feather);
	test_remove_tree(dir);
}

static void test_obj_reader(void **state)
{
	(void)state;
	char dir[512], path[640];
	test_make_temp_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/in.obj", dir);
	// Every face vertex syntax, negative indices, comments, normals.
	test_write_file(path, "# comment\nv 0 0 0\nv 1 0 0\nv 0 1 0.5\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
	                      "vn 0 0 1\no thing\nf 1 2 3\nf 2/2 4/4 3/3\nf -3//1 -1//1 -2//1\nf 1/1/1 2/2/1 3/3/1\n");
	plume_mesh *mesh = NULL;
	plume_error err;
	assert_int_equal(plume_mesh_read_obj(path, &mesh, &err), PLUME_OK);
	assert_int_equal(mesh->vertex_count, 4);
	assert_int_equal(mesh->face_count, 4);
	int expected[12] = {0, 1, 2, 1, 3, 2, 1, 3, 2, 0, 1, 2};
	assert_memory_equal(mesh->faces, expected, sizeof expected);
	assert_true(mesh->rest[2].z == 0.5 && mesh->reference[2].y == 1.0);
	assert_true(mesh->uv[0].x == 0.0 && mesh->uv[1].x == 0.0); // not every face vertex has a vt: zero
	plume_mesh_destroy(mesh);

	// A quad and a pentagon, fanned from their first corner: (c0, c_i, c_i+1), each
	// triangle with its corners' texture coordinates and its polygon's group; CRLF line
	// ends, a comment after the data, blank and indented lines.
	test_write_file(path, "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\nv 0.5 1.5 0 # apex\r\n\r\n"
	                      "vt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvt 0 1\r\nvt 0.5 1.5\r\n"
	                      "  f 1/1 2/2 3/3 4/4\r\ng rachis\r\nf -5/-5 -4/-4 -3/-3 -1/-1 -2/-2\r\n");
	assert_int_equal(plume_mesh_read_obj(path, &mesh, &err), PLUME_OK);
	assert_int_equal(mesh->vertex_count, 5);
	assert_int_equal(mesh->face_count, 5);
	const int fan[15] = {0, 1, 2, 0, 2, 3, 0, 1, 2, 0, 2, 4, 0, 4, 3};
	assert_memory_equal(mesh->faces, fan, sizeof fan);
	const unsigned char materials[5] = {PLUME_MATERIAL_VANE, PLUME_MATERIAL_VANE, PLUME_MATERIAL_RACHIS,
	                                    PLUME_MATERIAL_RACHIS, PLUME_MATERIAL_RACHIS};
	assert_memory_equal(mesh->material, materials, sizeof materials);
	assert_true(mesh->uv[4].x == 0.5 && mesh->uv[4].y == 1.5 && mesh->uv[2].x == 1.0);
	assert_true(mesh->rest[4].y == 1.5);
	plume_mesh_destroy(mesh);

	// Errors name the file, the line and what is wrong, and return no mesh.
	struct {
		const char *text, *expected;
	} cases[] = {
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n", "in.obj:5: face 1: vertex index 7 out of range (3 vertices so far)"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 -4\n", "in.obj:5: face 2: vertex index -4 out of range"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "in.obj:4: face 1: vertex index 0 out of range"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n",
	     "in.obj:5: face 1: texture index 2 out of range (1 texture coordinates so far)"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 5\n", "in.obj:5: face 1: vertex index 5 out of range"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "in.obj:3: end of file without faces"},
	    {"v 0 0\n", "in.obj:1: \"v\" needs three numbers (x y z); found 2"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "in.obj:4: face 1 has 2 corners; a face needs at least 3"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n", "in.obj:4: face 1: corner \"x\" is not a vertex index"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2/ 3\n", "in.obj:4: face 1: corner \"2/\" is not a vertex index"},
	    {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3//x\n", "in.obj:4: face 1: corner \"3//x\" is not a vertex index"},
	    {"v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3 4\r\n", "in.obj:4: face 1: vertex index 4 out of range"},
	    {"v 0 0 0\nv 1 0,5 0\n", "in.obj:2: vertex 2: \"0,5\" is not a number"},
	    {"v 0 0 0\nv 1 0 0 one\n", "in.obj:2: vertex 2: \"one\" is not a number"},
	    {"v 0 0 0\nv 0 inf 0\n", "in.obj:2: vertex 2: coordinate 2 is inf; allowed finite, within 1e12 m"},
	    {"v 0 0 0\nvt 0 x\n", "in.obj:2: texture coordinate 1: \"x\" is not a number"},
	    {"vt\n", "in.obj:1: \"vt\" needs one or two numbers (u [v]); found 0"},
	};
	int64_t before = plume_bytes_in_use();
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
		test_write_file(path, cases[i].text);
		mesh = NULL;
		assert_int_equal(plume_mesh_read_obj(path, &mesh, &err), PLUME_ERROR_SYNTAX);
		assert_null(mesh);
		if (strstr(err.message, cases[i].expected) == NULL)
			fail_msg("case %d: \"%s\" lacks \"%s\"", (int)i, err.message, cases[i].expected);
	}
	assert_int_equal(plume_bytes_in_use(), before);
	snprintf(path, sizeof path, "%s/missing.obj", dir);
	assert_int_equal(plume_mesh_read_obj(path, &mesh, &err), PLUME_ERROR_IO);
	assert_non_null(strstr(err.message, "missing.obj"));
	test_remove_tree(dir);
}

// ---------------------------------------------------------------------------
// Plain mesh functions

static void test_groups_and_barb_edges(void **state)
{
	(void)state;
	int64_t before = plume_bytes_in_use();
	plume_mesh *mesh = plume_mesh_create(4, 2);
	assert_non_null(mesh);
	int faces[6] = {0, 1, 2, 1, 3, 2};
	memcpy(mesh->faces, faces, sizeof faces);
	mesh->reference[1] = (plume_vec2){1, 0};
	mesh->reference[2] = (plume_vec2){0, 1};
	mesh->reference[3] = (plume_vec2){1, 1};
	mesh->barb_edge[0] = 1; // edge 1-2
	mesh->barb_edge[1] = 2; // edge 2-1: the same edge
	assert_int_equal(plume_mesh_collect_barb_edges(mesh, NULL), PLUME_OK);
	assert_int_equal(mesh->barb_edge_count, 1);
	assert_int_equal(mesh->barb_edges[0], 1);
	assert_int_equal(mesh->barb_edges[1], 2);
	plume_mesh_report report = plume_mesh_measure(mesh);
	assert_close(report.min_angle, pi / 4.0, 1e-15);
	assert_true(report.aligned_fraction == 1.0);
	mesh->barb_edge[1] = -1;
	assert_close(plume_mesh_measure(mesh).aligned_fraction, 0.5, 0.0);
	int members[2] = {3, 0};
	plume_error err;
	assert_int_equal(plume_mesh_add_group(mesh, "handle", members, 2, &err), PLUME_OK);
	assert_int_equal(plume_mesh_add_group(mesh, "handle", members, 2, &err), PLUME_ERROR_SPEC);
	members[0] = 4;
	assert_int_equal(plume_mesh_add_group(mesh, "bad", members, 2, &err), PLUME_ERROR_SPEC);
	assert_non_null(strstr(err.message, "out of range"));
	assert_int_equal(plume_mesh_add_group(mesh, "a-name-that-is-far-too-long-for-it", members, 1, &err),
	                 PLUME_ERROR_SPEC);
	const plume_vertex_group *group = plume_mesh_find_group(mesh, "handle");
	assert_non_null(group);
	assert_int_equal(group->vertices[0], 3);
	assert_null(plume_mesh_find_group(mesh, "missing"));
	plume_mesh_destroy(mesh);
	assert_int_equal(plume_bytes_in_use(), before);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_examples_are_aligned),
	    cmocka_unit_test(test_example_quality),
	    cmocka_unit_test(test_junction_faces),
	    cmocka_unit_test(test_rachis_tip_junction),
	    cmocka_unit_test(test_random_seeds_and_edge_lengths),
	    cmocka_unit_test(test_deterministic),
	    cmocka_unit_test(test_one_sided_feather),
	    cmocka_unit_test(test_curved_rest_shape_and_zero_length_barbs),
	    cmocka_unit_test(test_short_vanes_and_no_barbs),
	    cmocka_unit_test(test_explicit_guides),
	    cmocka_unit_test(test_short_guide_joined),
	    cmocka_unit_test(test_lone_stub_cut_back),
	    cmocka_unit_test(test_shallow_barbs_phased),
	    cmocka_unit_test(test_outline_tail_cut),
	    cmocka_unit_test(test_guides_spec_errors),
	    cmocka_unit_test(test_guides_spec_splines),
	    cmocka_unit_test(test_tall_guides),
	    cmocka_unit_test(test_every_vertex_in_a_face),
	    cmocka_unit_test(test_tails_past_dropped_guide),
	    cmocka_unit_test(test_overlap_reported),
	    cmocka_unit_test(test_obj_round_trip),
	    cmocka_unit_test(test_mesh_writers_refuse_non_finite),
	    cmocka_unit_test(test_obj_reader),
	    cmocka_unit_test(test_groups_and_barb_edges),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

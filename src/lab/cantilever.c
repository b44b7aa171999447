// Cantilever strips on four triangulation families (issue 13): the measure of whether a
// bending discretisation gives the continuum stiffness on any mesh. The strips are
// lattices (x, y) = ((i + j sigma) dx, j dy), rows along the strip, cut to a rectangle.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "plume/lab.h"

static const double PI = 3.14159265358979323846;

static const char *const family_names[PLUME_STRIP_FAMILY_COUNT] = {"right-isosceles", "equilateral", "elongated-4to1",
                                                                   "slanted-60"};

const char *plume_strip_family_name(plume_strip_family family)
{
	return (int)family >= 0 && (int)family < PLUME_STRIP_FAMILY_COUNT ? family_names[family] : "unknown";
}

/// Cell length dx and row shift sigma (in cells) of a family whose rows are dy apart.
static void family_lattice(plume_strip_family family, double dy, double *dx, double *sigma)
{
	switch (family) {
	case PLUME_STRIP_EQUILATERAL: *dx = 2 * dy / sqrt(3.0), *sigma = 0.5; return;
	case PLUME_STRIP_ELONGATED: *dx = 4 * dy, *sigma = 0; return;
	case PLUME_STRIP_SLANTED: *dx = dy, *sigma = 1 / tan(PI / 3); return;
	case PLUME_STRIP_RIGHT: break;
	}
	*dx = dy, *sigma = 0;
}

typedef struct strip_rows {
	int *first;  ///< lattice index i of each row's first vertex
	int *count;  ///< vertices in each row
	int *offset; ///< id of each row's first vertex
} strip_rows;

static int vertex_at(const strip_rows *rows, int i, int j)
{
	int k = i - rows->first[j];
	return k >= 0 && k < rows->count[j] ? rows->offset[j] + k : -1;
}

static plume_status add_groups(plume_mesh *mesh, const strip_rows *rows, int across, double length, plume_error *err)
{
	int *clamp = plume_alloc(sizeof(int) * (size_t)mesh->vertex_count);
	int *tip = plume_alloc(sizeof(int) * (size_t)(across + 1));
	if (clamp == NULL || tip == NULL) {
		plume_free(clamp);
		plume_free(tip);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building a strip");
	}
	int clamped = 0;
	for (int v = 0; v < mesh->vertex_count; ++v)
		if (mesh->reference[v].x <= 0)
			clamp[clamped++] = v;
	for (int j = 0; j <= across; ++j)
		tip[j] = rows->offset[j] + rows->count[j] - 1;
	int corners[2] = {tip[0], tip[across]};
	(void)length;
	plume_status status = plume_mesh_add_group(mesh, "clamp", clamp, clamped, err);
	if (status == PLUME_OK)
		status = plume_mesh_add_group(mesh, "tip", tip, across + 1, err);
	if (status == PLUME_OK)
		status = plume_mesh_add_group(mesh, "tip_corners", corners, 2, err);
	if (status == PLUME_OK && across > 1)
		status = plume_mesh_add_group(mesh, "tip_inner", tip + 1, across - 1, err);
	plume_free(clamp);
	plume_free(tip);
	return status;
}

/// The largest strip plume_lab_strip_mesh builds (the studies' finest is about 1e5 vertices).
#define STRIP_MAX_VERTICES 1e8

plume_status plume_lab_strip_mesh(plume_strip_family family, double length, double width, int clamp_cells, int across,
                                  double barb_angle, plume_mesh **out, plume_error *err)
{
	*out = NULL;
	if (across < 1 || clamp_cells < 1 || !(length > 0) || !(width > 0) || family < 0 ||
	    (int)family >= PLUME_STRIP_FAMILY_COUNT)
		return plume_error_set(err, PLUME_ERROR_SPEC, "strip: invalid family, size or refinement");
	double dy = width / across, dx, sigma;
	family_lattice(family, dy, &dx, &sigma);
	// The rows' vertex counts are ints (a larger one cast from a double is undefined) and no
	// study meshes a strip past STRIP_MAX_VERTICES.
	double estimate = (length / dx + clamp_cells + 2.0) * (across + 1.0);
	if (!(estimate <= STRIP_MAX_VERTICES) || !isfinite(barb_angle))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "strip: %g m long, %g m wide, %d rows of cells across and %d clamped make about %.3g "
		                       "vertices, allowed at most %g (and a finite barb angle)",
		                       length, width, across, clamp_cells, estimate, STRIP_MAX_VERTICES);
	double clamp = clamp_cells * dx;
	int rows_count = across + 1;
	strip_rows rows = {plume_alloc(sizeof(int) * (size_t)rows_count), plume_alloc(sizeof(int) * (size_t)rows_count),
	                   plume_alloc(sizeof(int) * (size_t)rows_count)};
	if (!rows.first || !rows.count || !rows.offset) {
		plume_free(rows.first), plume_free(rows.count), plume_free(rows.offset);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building a strip");
	}
	// Row j holds the lattice vertices with x in (-clamp - dx/2, length + dx/2].
	int vertices = 0;
	for (int j = 0; j < rows_count; ++j) {
		double shift = j * sigma;
		rows.first[j] = (int)floor(-clamp / dx - 0.5 - shift + 1e-9) + 1;
		int last = (int)floor(length / dx + 0.5 - shift + 1e-9);
		rows.count[j] = last - rows.first[j] + 1;
		rows.offset[j] = vertices;
		vertices += rows.count[j];
	}
	int faces = 0;
	for (int pass = 0; pass < 2; ++pass) {
		for (int j = 0; j < across; ++j) {
			int lo = rows.first[j] < rows.first[j + 1] ? rows.first[j] : rows.first[j + 1];
			int hi = rows.first[j] + rows.count[j] > rows.first[j + 1] + rows.count[j + 1]
			             ? rows.first[j] + rows.count[j]
			             : rows.first[j + 1] + rows.count[j + 1];
			for (int i = lo - 1; i <= hi; ++i) {
				int t[2][3] = {
				    {vertex_at(&rows, i, j), vertex_at(&rows, i + 1, j), vertex_at(&rows, i, j + 1)},
				    {vertex_at(&rows, i + 1, j), vertex_at(&rows, i + 1, j + 1), vertex_at(&rows, i, j + 1)}};
				for (int k = 0; k < 2; ++k) {
					if (t[k][0] < 0 || t[k][1] < 0 || t[k][2] < 0)
						continue;
					if (pass == 1)
						memcpy((*out)->faces + 3 * faces, t[k], sizeof t[k]);
					++faces;
				}
			}
		}
		if (pass == 0 && (*out = plume_mesh_create(vertices, faces)) == NULL) {
			plume_free(rows.first), plume_free(rows.count), plume_free(rows.offset);
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building a strip");
		}
		faces = 0;
	}
	plume_mesh *mesh = *out;
	for (int j = 0; j < rows_count; ++j)
		for (int k = 0; k < rows.count[j]; ++k) {
			double x = (rows.first[j] + k + j * sigma) * dx;
			// The nearest vertex to each of the three lines moves onto it.
			if (k == 0)
				x = -clamp;
			else if (k == rows.count[j] - 1)
				x = length;
			else if (x > -0.5 * dx - 1e-9 * dx && x <= 0.5 * dx - 1e-9 * dx)
				x = 0;
			int v = rows.offset[j] + k;
			mesh->reference[v] = (plume_vec2){x, j * dy};
			mesh->rest[v] = plume_v3(x, j * dy, 0);
			mesh->uv[v] = (plume_vec2){x / length, j * dy / width};
		}
	double angle = fmod(barb_angle, PI);
	if (angle < 0)
		angle += PI;
	for (int f = 0; f < mesh->face_count; ++f) {
		mesh->material[f] = 0;
		mesh->barb_angle[f] = angle;
		mesh->barb_edge[f] = -1;
	}
	plume_status status = add_groups(mesh, &rows, across, length, err);
	plume_free(rows.first), plume_free(rows.count), plume_free(rows.offset);
	if (status != PLUME_OK) {
		plume_mesh_destroy(mesh);
		*out = NULL;
	}
	return status;
}

plume_cantilever_def plume_cantilever_default_def(void)
{
	return (plume_cantilever_def){.family = PLUME_STRIP_RIGHT,
	                              .across = 8,
	                              .length = 0.1,
	                              .width = 0.01,
	                              .barb_angle = 0,
	                              .bending_along = 1e-3,
	                              .bending_across = 1e-3,
	                              .model = PLUME_BENDING_FUNDAMENTAL_FORM};
}

plume_status plume_lab_cantilever(const plume_cantilever_def *def, double *ratio, plume_error *err)
{
	*ratio = NAN;
	plume_mesh *mesh;
	plume_status status =
	    plume_lab_strip_mesh(def->family, def->length, def->width, 2, def->across, def->barb_angle, &mesh, err);
	if (status != PLUME_OK)
		return status;
	plume_sim_def sim_def = plume_sim_default_def();
	plume_material *m = sim_def.materials;
	*m = plume_material_rachis();
	// A membrane so stiff that it does not stretch: only bending deforms.
	m->youngs_modulus = 1e4 * fmax(def->bending_along, def->bending_across) / pow(def->width / def->across, 3);
	m->poisson_ratio = 0;
	m->thickness = 1e-3;
	m->surface_density = 0;
	m->bending_along = def->bending_along;
	m->bending_across = def->bending_across;
	sim_def.material_count = 1;
	sim_def.gravity = plume_v3(0, 0, 0);
	sim_def.bending_model = def->model;
	sim_def.solver.tolerance = 1e-10;
	// The strip's axis is a fold line at beta = pi/2 - barb_angle to the barbs (eq. 6.4).
	double beta = 0.5 * PI - def->barb_angle;
	double D = 0.5 * (def->bending_along - def->bending_across) * cos(2 * beta) +
	           0.5 * (def->bending_along + def->bending_across);
	double L = def->length, W = def->width;
	double deflection_eb = 1e-4 * L, P = 3 * deflection_eb * D * W / (L * L * L);
	plume_sim *sim = NULL;
	status = plume_sim_create(mesh, &sim_def, &sim, err);
	if (status == PLUME_OK && plume_sim_add_handle(sim, "clamp", err) < 0)
		status = PLUME_ERROR_SPEC;
	// A line load: each tip vertex carries its share of the width, half at the corners.
	int n = def->across;
	if (status == PLUME_OK)
		status = plume_sim_set_group_load(sim, "tip_corners", plume_v3(0, 0, P / n), err);
	if (status == PLUME_OK && n > 1)
		status = plume_sim_set_group_load(sim, "tip_inner", plume_v3(0, 0, P * (n - 1) / n), err);
	plume_solve_report report;
	if (status == PLUME_OK)
		status = plume_sim_solve_static(sim, &report, err);
	if (status == PLUME_OK) {
		const plume_vertex_group *tip = plume_mesh_find_group(mesh, "tip");
		const plume_vec3 *x = plume_sim_positions(sim);
		double sum = 0;
		for (int k = 0; k < tip->count; ++k)
			sum += (k == 0 || k == tip->count - 1 ? 0.5 : 1.0) * x[tip->vertices[k]].z;
		*ratio = sum / n / deflection_eb;
	}
	plume_sim_destroy(sim);
	plume_mesh_destroy(mesh);
	return status;
}

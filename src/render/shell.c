// A shaded view of a shell mesh: orthographic projection, flat Lambert shading
// of both sides, faces drawn back to front. Enough to watch a simulation;
// ray tracing is render/raytrace.
#include <math.h>
#include <stdlib.h>

#include <cairo.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "plume/mesh.h"
#include "plume/render.h"
#include "render/cairo_png.h"

plume_shell_view_def plume_shell_view_default_def(void)
{
	plume_shell_view_def def = {0};
	def.width = 800;
	def.height = 800;
	def.azimuth = 0.6;
	def.elevation = 0.35;
	def.bounds_min = plume_v3(1, 1, 1);
	def.bounds_max = plume_v3(-1, -1, -1);
	def.background = (plume_color){0.96, 0.96, 0.95, 1};
	def.vane_color = (plume_color){0.78, 0.70, 0.58, 1};
	def.rachis_color = (plume_color){0.35, 0.27, 0.20, 1};
	def.cookie = PLUME_DEF_COOKIE;
	return def;
}

typedef struct view_basis {
	plume_vec3 right, up, toward;
} view_basis;

static view_basis make_basis(double azimuth, double elevation)
{
	view_basis b;
	b.toward = plume_v3(sin(azimuth) * cos(elevation), sin(elevation), cos(azimuth) * cos(elevation));
	b.right = plume_v3_normalize(plume_v3_cross(plume_v3(0, 1, 0), b.toward));
	b.up = plume_v3_cross(b.toward, b.right);
	return b;
}

typedef struct depth_face {
	double depth;
	int face;
} depth_face;

static int compare_depth(const void *a, const void *b)
{
	const depth_face *p = a, *q = b;
	if (p->depth != q->depth)
		return p->depth < q->depth ? -1 : 1;
	return (p->face > q->face) - (p->face < q->face);
}

/// Projected extent of the box's eight corners.
static void box_extent(const view_basis *b, plume_vec3 lo, plume_vec3 hi, double extent[4])
{
	extent[0] = extent[2] = INFINITY;
	extent[1] = extent[3] = -INFINITY;
	for (int c = 0; c < 8; ++c) {
		plume_vec3 p = plume_v3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
		double u = plume_v3_dot(p, b->right), v = plume_v3_dot(p, b->up);
		extent[0] = fmin(extent[0], u), extent[1] = fmax(extent[1], u);
		extent[2] = fmin(extent[2], v), extent[3] = fmax(extent[3], v);
	}
}

plume_status plume_render_shell_png(const plume_mesh *mesh, const plume_vec3 *positions,
                                    const plume_shell_view_def *def, const char *path, plume_error *err)
{
	PLUME_ASSERT(mesh != NULL && path != NULL);
	PLUME_ASSERT_DEF(def);
	if (def->width < 1 || def->height < 1 || def->width > 16384 || def->height > 16384)
		return plume_error_set(err, PLUME_ERROR_SPEC, "image size %dx%d, allowed 1 to 16384 pixels a side", def->width,
		                       def->height);
	const plume_vec3 *x = positions != NULL ? positions : mesh->rest;
	view_basis basis = make_basis(def->azimuth, def->elevation);
	plume_vec3 lo = def->bounds_min, hi = def->bounds_max;
	if (lo.x > hi.x) {
		lo = hi = x[0];
		for (int i = 1; i < mesh->vertex_count; ++i) {
			lo = plume_v3(fmin(lo.x, x[i].x), fmin(lo.y, x[i].y), fmin(lo.z, x[i].z));
			hi = plume_v3(fmax(hi.x, x[i].x), fmax(hi.y, x[i].y), fmax(hi.z, x[i].z));
		}
	}
	double extent[4];
	box_extent(&basis, lo, hi, extent);
	double margin = 0.05 * fmin(def->width, def->height);
	double su = (def->width - 2 * margin) / fmax(extent[1] - extent[0], 1e-12);
	double sv = (def->height - 2 * margin) / fmax(extent[3] - extent[2], 1e-12);
	double scale = fmin(su, sv);
	double cu = 0.5 * (extent[0] + extent[1]), cv = 0.5 * (extent[2] + extent[3]);

	depth_face *order = plume_alloc(sizeof(depth_face) * (size_t)(mesh->face_count > 0 ? mesh->face_count : 1));
	if (order == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory drawing %s", path);
	for (int f = 0; f < mesh->face_count; ++f) {
		const int *v = mesh->faces + 3 * f;
		plume_vec3 centre = plume_v3_scale(plume_v3_add(plume_v3_add(x[v[0]], x[v[1]]), x[v[2]]), 1.0 / 3);
		order[f] = (depth_face){plume_v3_dot(centre, basis.toward), f};
	}
	qsort(order, (size_t)mesh->face_count, sizeof *order, compare_depth);

	cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, def->width, def->height);
	cairo_t *cr = cairo_create(surface);
	cairo_set_source_rgba(cr, def->background.r, def->background.g, def->background.b, def->background.a);
	cairo_paint(cr);
	cairo_set_line_width(cr, 0.6);
	cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
	plume_vec3 light = plume_v3_normalize(plume_v3_add(basis.toward, plume_v3_scale(basis.up, 0.8)));
	for (int k = 0; k < mesh->face_count; ++k) {
		int f = order[k].face;
		const int *v = mesh->faces + 3 * f;
		plume_vec3 normal =
		    plume_v3_normalize(plume_v3_cross(plume_v3_sub(x[v[1]], x[v[0]]), plume_v3_sub(x[v[2]], x[v[0]])));
		// Thin shells are lit from both sides.
		double lambert = fabs(plume_v3_dot(normal, light));
		double shade = 0.35 + 0.65 * lambert;
		plume_color c = mesh->material[f] == PLUME_MATERIAL_RACHIS ? def->rachis_color : def->vane_color;
		for (int i = 0; i < 3; ++i) {
			double u = plume_v3_dot(x[v[i]], basis.right), w = plume_v3_dot(x[v[i]], basis.up);
			double px = 0.5 * def->width + (u - cu) * scale, py = 0.5 * def->height - (w - cv) * scale;
			if (i == 0)
				cairo_move_to(cr, px, py);
			else
				cairo_line_to(cr, px, py);
		}
		cairo_close_path(cr);
		cairo_set_source_rgba(cr, c.r * shade, c.g * shade, c.b * shade, 1);
		cairo_fill_preserve(cr);
		cairo_set_source_rgba(cr, c.r * shade * 0.8, c.g * shade * 0.8, c.b * shade * 0.8, 1);
		cairo_stroke(cr);
	}
	plume_free(order);
	cairo_destroy(cr);
	plume_status status = plume_cairo_write_png(surface, path, err);
	cairo_surface_destroy(surface);
	return status;
}

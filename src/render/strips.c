// Streit & Heidrich 4.3.1: each barb drawn as two triangle strips, one each
// side of its polyline, of constant width in the vane plane, alpha-blended
// towards the barb's tip and away from its centre line (after Koh and Huang's
// hair strips). Proper blending needs an order: the vane nearer the camera is
// drawn after the other, its strips from the barb tip inwards, the far vane's
// from the rachis outwards. Each strip quad is a Cairo mesh-pattern patch whose
// corner alphas give the two fades.
#include "render/strips.h"

#include <math.h>

typedef struct strip_context {
	cairo_t *cr;
	const plume_render2d_def *def;
	double scale, offset_x, offset_y;
} strip_context;

static void image_point(const strip_context *c, plume_vec3 p, double *x, double *y)
{
	*x = c->offset_x + c->scale * p.x;
	*y = c->offset_y - c->scale * p.y;
}

/// The barb's colour at segment i: the texture's at the segment's middle, else the line colour.
static plume_color segment_color(const strip_context *c, const plume_polyline *curve, plume_side side, int i)
{
	if (c->def->texture == NULL)
		return c->def->barb_color;
	double s = 0.5 * (curve->uv[i].x + curve->uv[i + 1].x), t = 0.5 * (curve->uv[i].y + curve->uv[i + 1].y);
	return plume_texture_sample_vane(c->def->texture, side, s, t);
}

/// Adds the patch of one side (+1 or -1) of segment i.
static void add_patch(const strip_context *c, cairo_pattern_t *mesh, const plume_polyline *curve, plume_side side,
                      int i, double which)
{
	double x[2], y[2], ox[2], oy[2], alpha[2];
	for (int k = 0; k < 2; ++k) {
		int j = i + k;
		image_point(c, curve->points[j], &x[k], &y[k]);
		// In the vane plane, across the barb: normal x tangent, projected onto the image (foreshortened).
		int a = j > 0 ? j - 1 : j, b = j + 1 < curve->count ? j + 1 : j;
		plume_vec3 tangent = plume_v3_sub(curve->points[b], curve->points[a]);
		plume_vec3 across = plume_v3_normalize(plume_v3_cross(curve->normals[j], tangent));
		ox[k] = which * c->def->strip_width_px * across.x;
		oy[k] = -which * c->def->strip_width_px * across.y;
		// Towards the tip the strip fades out (s is the arc-length fraction).
		alpha[k] = c->def->strip_alpha * (1.0 - curve->uv[j].x);
	}
	plume_color color = segment_color(c, curve, side, i);
	cairo_mesh_pattern_begin_patch(mesh);
	cairo_mesh_pattern_move_to(mesh, x[0], y[0]);
	cairo_mesh_pattern_line_to(mesh, x[1], y[1]);
	cairo_mesh_pattern_line_to(mesh, x[1] + ox[1], y[1] + oy[1]);
	cairo_mesh_pattern_line_to(mesh, x[0] + ox[0], y[0] + oy[0]);
	// Centre line at the barb's alpha, outer edge transparent: the fade away from the centre.
	cairo_mesh_pattern_set_corner_color_rgba(mesh, 0, color.r, color.g, color.b, color.a * alpha[0]);
	cairo_mesh_pattern_set_corner_color_rgba(mesh, 1, color.r, color.g, color.b, color.a * alpha[1]);
	cairo_mesh_pattern_set_corner_color_rgba(mesh, 2, color.r, color.g, color.b, 0.0);
	cairo_mesh_pattern_set_corner_color_rgba(mesh, 3, color.r, color.g, color.b, 0.0);
	cairo_mesh_pattern_end_patch(mesh);
}

/// One barb's two strips; inwards: from the tip to the root.
static bool draw_barb(const strip_context *c, const plume_barb *barb, bool inwards)
{
	const plume_polyline *curve = &barb->curve;
	if (curve->count < 2)
		return true;
	cairo_pattern_t *mesh = cairo_pattern_create_mesh();
	if (cairo_pattern_status(mesh) != CAIRO_STATUS_SUCCESS) {
		cairo_pattern_destroy(mesh);
		return false;
	}
	int segments = curve->count - 1;
	for (int n = 0; n < segments; ++n) {
		int i = inwards ? segments - 1 - n : n;
		add_patch(c, mesh, curve, barb->side, i, 1.0);
		add_patch(c, mesh, curve, barb->side, i, -1.0);
	}
	cairo_set_source(c->cr, mesh);
	cairo_paint(c->cr);
	bool ok = cairo_pattern_status(mesh) == CAIRO_STATUS_SUCCESS;
	cairo_pattern_destroy(mesh);
	return ok;
}

bool plume_strips_draw_barbs(cairo_t *cr, const plume_feather *feather, const plume_render2d_def *def, double scale,
                             double offset_x, double offset_y)
{
	strip_context c = {.cr = cr, .def = def, .scale = scale, .offset_x = offset_x, .offset_y = offset_y};
	plume_feather_info info = plume_feather_get_info(feather);
	// The camera looks along -z: the vane with the larger mean z is the nearer one.
	double sum[2] = {0.0, 0.0};
	int points[2] = {0, 0};
	for (int i = 0; i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		for (int k = 0; k < barb.curve.count; ++k)
			sum[barb.side] += barb.curve.points[k].z;
		points[barb.side] += barb.curve.count;
	}
	double mean[2] = {points[0] > 0 ? sum[0] / points[0] : 0.0, points[1] > 0 ? sum[1] / points[1] : 0.0};
	plume_side near = mean[PLUME_SIDE_RIGHT] > mean[PLUME_SIDE_LEFT] ? PLUME_SIDE_RIGHT : PLUME_SIDE_LEFT;
	plume_side far = near == PLUME_SIDE_LEFT ? PLUME_SIDE_RIGHT : PLUME_SIDE_LEFT;
	const plume_side order[2] = {far, near};
	for (int pass = 0; pass < 2; ++pass)
		for (int i = 0; i < info.barb_count; ++i) {
			plume_barb barb = plume_feather_barb(feather, i);
			if (barb.side == order[pass] && !draw_barb(&c, &barb, order[pass] == near))
				return false;
		}
	return true;
}

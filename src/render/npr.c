// 2D rendering with Cairo (Franco & Walter 4.4): the feather seen from the
// front, orthographically, every curve a filled ribbon whose width follows
// the curve's widths; barbs in one colour (the paper's non-photorealistic
// style) or coloured from a texture by their (s, t).
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "core/atomic_file.h"
#include "plume/render.h"
#include "render/cairo_png.h"
#include "render/strips.h"

plume_render2d_def plume_render2d_default_def(void)
{
	return (plume_render2d_def){
	    .cookie = PLUME_DEF_COOKIE,
	    .width = 1024,
	    .height = 1024,
	    .margin = 0.05,
	    .background = {1.0, 1.0, 1.0, 1.0},
	    .barb_color = {0.18, 0.15, 0.13, 1.0},
	    .shaft_color = {0.10, 0.08, 0.07, 1.0},
	    .min_stroke_px = 0.35,
	    .draw_barbules = true,
	    .texture = NULL,
	    .style = PLUME_STYLE_LINES,
	    .strip_width_px = 2.0,
	    .strip_alpha = 0.6,
	    .view_min = {0.0, 0.0},
	    .view_max = {0.0, 0.0},
	};
}

// ---------------------------------------------------------------------------
// Validation

static plume_status check_size(const char *name, int value, plume_error *err)
{
	if (value < 16 || value > 16384)
		return plume_error_set(err, PLUME_ERROR_SPEC, "render2d: %s is %d, allowed [16, 16384]", name, value);
	return PLUME_OK;
}

static plume_status check_color(const char *name, plume_color color, plume_error *err)
{
	const double channels[4] = {color.r, color.g, color.b, color.a};
	const char *const channel_names[4] = {"r", "g", "b", "a"};
	for (int i = 0; i < 4; ++i)
		if (!(channels[i] >= 0.0 && channels[i] <= 1.0))
			return plume_error_set(err, PLUME_ERROR_SPEC, "render2d: %s.%s is %g, allowed [0, 1]", name,
			                       channel_names[i], channels[i]);
	return PLUME_OK;
}

static plume_status validate_def(const plume_render2d_def *def, plume_error *err)
{
	plume_status status;
	if ((status = check_size("width", def->width, err)) != PLUME_OK ||
	    (status = check_size("height", def->height, err)) != PLUME_OK)
		return status;
	if (!(def->margin >= 0.0 && def->margin < 0.45))
		return plume_error_set(err, PLUME_ERROR_SPEC, "render2d: margin is %g, allowed [0, 0.45)", def->margin);
	if ((status = check_color("background", def->background, err)) != PLUME_OK ||
	    (status = check_color("barb_color", def->barb_color, err)) != PLUME_OK ||
	    (status = check_color("shaft_color", def->shaft_color, err)) != PLUME_OK)
		return status;
	if (def->style != PLUME_STYLE_LINES && def->style != PLUME_STYLE_STRIPS)
		return plume_error_set(err, PLUME_ERROR_SPEC, "render2d: style is %d, allowed lines (0) or strips (1)",
		                       (int)def->style);
	if (def->style == PLUME_STYLE_STRIPS && (!(def->strip_width_px > 0.0 && isfinite(def->strip_width_px)) ||
	                                         !(def->strip_alpha > 0.0 && def->strip_alpha <= 1.0)))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "render2d: strip_width_px is %g and strip_alpha %g; allowed > 0 and (0, 1]",
		                       def->strip_width_px, def->strip_alpha);
	if (!(def->min_stroke_px >= 0.0 && isfinite(def->min_stroke_px)))
		return plume_error_set(err, PLUME_ERROR_SPEC, "render2d: min_stroke_px is %g, must be a finite number >= 0",
		                       def->min_stroke_px);
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// Ribbons

/// Feather frame (m) to image (px): x right, y up in the feather, y down in Cairo.
typedef struct view {
	double scale;     ///< px per m
	double offset_x;  ///< image x of feather x = 0
	double offset_y;  ///< image y of feather y = 0
	double min_width; ///< px
} view;

typedef struct pt2 {
	double x, y;
} pt2;

/// Scratch for one curve at a time, allocated once per render and grown to
/// the longest curve, so that the per-curve loop does not allocate.
typedef struct scratch {
	pt2 *left;  ///< centre + half width * offset direction
	pt2 *right; ///< centre - half width * offset direction
	int capacity;
} scratch;

typedef struct renderer {
	cairo_t *cr;
	const plume_render2d_def *def;
	view view;
	scratch scratch;
	bool out_of_memory;
} renderer;

static pt2 unit2(double x, double y)
{
	double length = sqrt(x * x + y * y);
	if (!(length > 0.0))
		return (pt2){0.0, 0.0};
	return (pt2){x / length, y / length};
}

/// The miter at a joint keeps the ribbon's width across a bend, but grows
/// without bound at a hairpin; beyond this factor it is cut back.
#define MITER_LIMIT 2.0

/// Fills scratch.left/right with the ribbon's two edges for count points
/// (positions and widths in the feather frame). Returns false when memory runs out.
static bool build_ribbon(renderer *r, int count, const plume_vec3 *points, const double *widths,
                         const plume_shaft_sample *shaft)
{
	if (count > r->scratch.capacity) {
		int left_capacity = r->scratch.capacity, right_capacity = r->scratch.capacity;
		if (PLUME_GROW(r->scratch.left, left_capacity, count) != 0 ||
		    PLUME_GROW(r->scratch.right, right_capacity, count) != 0) {
			r->out_of_memory = true;
			return false;
		}
		r->scratch.capacity = left_capacity < right_capacity ? left_capacity : right_capacity;
	}
	const view *v = &r->view;
	// Centre points in pixels, stored in left[] for now.
	pt2 *centre = r->scratch.left;
	for (int i = 0; i < count; ++i) {
		plume_vec3 p = shaft != NULL ? shaft[i].position : points[i];
		centre[i] = (pt2){v->offset_x + v->scale * p.x, v->offset_y - v->scale * p.y};
	}
	// A direction for joints whose neighbours coincide in the projection: the
	// first segment with a length, else "up" (the ribbon then has no area).
	pt2 last_direction = {0.0, -1.0};
	for (int i = 0; i + 1 < count; ++i) {
		pt2 d = unit2(centre[i + 1].x - centre[i].x, centre[i + 1].y - centre[i].y);
		if (d.x != 0.0 || d.y != 0.0) {
			last_direction = d;
			break;
		}
	}
	// left[i] is overwritten at step i, so the previous centre is kept aside.
	pt2 previous = centre[0];
	for (int i = 0; i < count; ++i) {
		pt2 c = centre[i];
		pt2 before = i > 0 ? unit2(c.x - previous.x, c.y - previous.y) : (pt2){0.0, 0.0};
		pt2 after = i + 1 < count ? unit2(centre[i + 1].x - c.x, centre[i + 1].y - c.y) : (pt2){0.0, 0.0};
		previous = c;
		pt2 tangent = unit2(before.x + after.x, before.y + after.y);
		if (tangent.x == 0.0 && tangent.y == 0.0)
			tangent = (after.x != 0.0 || after.y != 0.0)     ? after
			          : (before.x != 0.0 || before.y != 0.0) ? before
			                                                 : last_direction;
		last_direction = tangent;
		// Miter: the offset along the joint's normal that keeps the distance to
		// the adjacent segments at half the width, 1 / cos(half the bend).
		double miter = 1.0;
		pt2 segment = (after.x != 0.0 || after.y != 0.0) ? after : before;
		double cosine = tangent.x * segment.x + tangent.y * segment.y;
		if (cosine > 0.0)
			miter = fmin(1.0 / cosine, MITER_LIMIT);
		double width = widths != NULL ? widths[i] : shaft[i].width;
		double half = 0.5 * fmax(width * v->scale, v->min_width) * miter;
		// In-plane perpendicular (the tangent turned a quarter).
		pt2 normal = {-tangent.y, tangent.x};
		r->scratch.right[i] = (pt2){c.x - half * normal.x, c.y - half * normal.y};
		r->scratch.left[i] = (pt2){c.x + half * normal.x, c.y + half * normal.y};
	}
	return true;
}

/// Adds to the path the ribbon's piece between points first and last (a closed polygon).
static void ribbon_path(cairo_t *cr, const scratch *s, int first, int last)
{
	cairo_move_to(cr, s->left[first].x, s->left[first].y);
	for (int i = first + 1; i <= last; ++i)
		cairo_line_to(cr, s->left[i].x, s->left[i].y);
	for (int i = last; i >= first; --i)
		cairo_line_to(cr, s->right[i].x, s->right[i].y);
	cairo_close_path(cr);
}

#define TWO_PI 6.283185307179586

/// A lone point: a dot of its width.
static void dot_path(renderer *r, plume_vec3 p, double width)
{
	const view *v = &r->view;
	double radius = 0.5 * fmax(width * v->scale, v->min_width);
	cairo_new_sub_path(r->cr);
	cairo_arc(r->cr, v->offset_x + v->scale * p.x, v->offset_y - v->scale * p.y, radius, 0.0, TWO_PI);
	cairo_close_path(r->cr);
}

static void set_color(cairo_t *cr, plume_color c) { cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a); }

static bool same_color(plume_color a, plume_color b) { return a.r == b.r && a.g == b.g && a.b == b.b && a.a == b.a; }

/// One curve in one colour.
static void draw_curve_plain(renderer *r, const plume_polyline *curve, plume_color color)
{
	if (curve->count <= 0 || color.a <= 0.0)
		return;
	if (curve->count == 1) {
		dot_path(r, curve->points[0], curve->widths[0]);
	} else {
		if (!build_ribbon(r, curve->count, curve->points, curve->widths, NULL))
			return;
		ribbon_path(r->cr, &r->scratch, 0, curve->count - 1);
	}
	set_color(r->cr, color);
	cairo_fill(r->cr);
}

/// One barb coloured from the texture segment by segment, by the uv of each
/// segment's midpoint. Runs of segments with the same colour are filled as
/// one polygon: the picture is the same, the SVG and PDF much smaller.
static void draw_barb_textured(renderer *r, const plume_polyline *curve, plume_side side)
{
	const plume_texture *texture = r->def->texture;
	if (curve->count <= 0)
		return;
	if (curve->count == 1) {
		plume_color c = plume_texture_sample_vane(texture, side, curve->uv[0].x, curve->uv[0].y);
		if (c.a > 0.0) {
			dot_path(r, curve->points[0], curve->widths[0]);
			set_color(r->cr, c);
			cairo_fill(r->cr);
		}
		return;
	}
	if (!build_ribbon(r, curve->count, curve->points, curve->widths, NULL))
		return;
	int run_start = 0;
	plume_color run_color = {0, 0, 0, 0};
	for (int i = 0; i + 1 < curve->count; ++i) {
		double s = 0.5 * (curve->uv[i].x + curve->uv[i + 1].x);
		double t = 0.5 * (curve->uv[i].y + curve->uv[i + 1].y);
		plume_color c = plume_texture_sample_vane(texture, side, s, t);
		if (i == 0) {
			run_color = c;
		} else if (!same_color(c, run_color)) {
			if (run_color.a > 0.0) {
				ribbon_path(r->cr, &r->scratch, run_start, i);
				set_color(r->cr, run_color);
				cairo_fill(r->cr);
			}
			run_start = i;
			run_color = c;
		}
	}
	if (run_color.a > 0.0) {
		ribbon_path(r->cr, &r->scratch, run_start, curve->count - 1);
		set_color(r->cr, run_color);
		cairo_fill(r->cr);
	}
}

static void draw_shaft(renderer *r, const plume_shaft_sample *shaft, int count)
{
	if (count <= 0 || r->def->shaft_color.a <= 0.0)
		return;
	if (count == 1) {
		dot_path(r, shaft[0].position, shaft[0].width);
	} else {
		if (!build_ribbon(r, count, NULL, NULL, shaft))
			return;
		ribbon_path(r->cr, &r->scratch, 0, count - 1);
	}
	set_color(r->cr, r->def->shaft_color);
	cairo_fill(r->cr);
}

/// Back to front: the afterfeather (it grows from the underside), barbules,
/// barbs, then the shaft on top.
static void draw_feather(renderer *r, const plume_feather *feather)
{
	const plume_feather *after = plume_feather_afterfeather(feather);
	if (after != NULL)
		draw_feather(r, after);
	plume_feather_info info = plume_feather_get_info(feather);
	const plume_render2d_def *def = r->def;

	if (def->draw_barbules) {
		for (int i = 0; i < info.barbule_count && !r->out_of_memory; ++i) {
			plume_barbule barbule = plume_feather_barbule(feather, i);
			plume_barb barb = plume_feather_barb(feather, barbule.barb);
			plume_color color = def->barb_color;
			// A barbule takes the texture's colour where it joins its barb:
			// (barb_s, the barb's t) on the barb's vane.
			if (def->texture != NULL) {
				double t = barb.curve.count > 0 ? barb.curve.uv[0].y : barb.rachis_t;
				color = plume_texture_sample_vane(def->texture, barb.side, barbule.barb_s, t);
			}
			draw_curve_plain(r, &barbule.curve, color);
		}
	}
	if (def->style == PLUME_STYLE_STRIPS) {
		if (!plume_strips_draw_barbs(r->cr, feather, def, r->view.scale, r->view.offset_x, r->view.offset_y))
			r->out_of_memory = true;
	} else {
		for (int i = 0; i < info.barb_count && !r->out_of_memory; ++i) {
			plume_barb barb = plume_feather_barb(feather, i);
			if (def->texture != NULL)
				draw_barb_textured(r, &barb.curve, barb.side);
			else
				draw_curve_plain(r, &barb.curve, def->barb_color);
		}
	}
	if (!r->out_of_memory)
		draw_shaft(r, plume_feather_shaft(feather), info.shaft_sample_count);
}

/// Scale and offsets that fit the feather's xy bounds into the image less the
/// margin, centred, keeping the aspect ratio.
static view fit_view(const plume_render2d_def *def, plume_feather_info info)
{
	if (def->view_max.x > def->view_min.x && def->view_max.y > def->view_min.y) {
		info.bounds_min = plume_v3(def->view_min.x, def->view_min.y, 0.0);
		info.bounds_max = plume_v3(def->view_max.x, def->view_max.y, 0.0);
	}
	double margin_px = def->margin * (def->width < def->height ? def->width : def->height);
	double room_x = def->width - 2.0 * margin_px, room_y = def->height - 2.0 * margin_px;
	double extent_x = info.bounds_max.x - info.bounds_min.x, extent_y = info.bounds_max.y - info.bounds_min.y;
	double scale;
	if (extent_x > 0.0 && extent_y > 0.0)
		scale = fmin(room_x / extent_x, room_y / extent_y);
	else if (extent_x > 0.0)
		scale = room_x / extent_x;
	else if (extent_y > 0.0)
		scale = room_y / extent_y;
	else
		scale = 1.0; // a single point: any scale puts it in the middle
	double centre_x = 0.5 * (info.bounds_min.x + info.bounds_max.x);
	double centre_y = 0.5 * (info.bounds_min.y + info.bounds_max.y);
	return (view){
	    .scale = scale,
	    .offset_x = 0.5 * def->width - scale * centre_x,
	    .offset_y = 0.5 * def->height + scale * centre_y,
	    .min_width = def->min_stroke_px,
	};
}

// ---------------------------------------------------------------------------
// Output

/// Cairo names the SVG's top group after the surface's process-wide serial
/// number ("surface1" for a process's first surface, "surface57" later), so the
/// same drawing would not give the same bytes twice in one process. The names
/// are renumbered by first appearance as the text streams to the file (a name
/// split between two of Cairo's writes is held back until it ends), which keeps
/// references between them intact and holds none of the document in memory.
enum { SVG_MAX_NAMES = 64, SVG_MAX_DIGITS = 20 };

typedef struct svg_renamer {
	int matched;                 ///< characters of "surface" matched so far (7: now reading its digits)
	char digits[SVG_MAX_DIGITS]; ///< the digits read after "surface"
	int digit_count;
	long seen[SVG_MAX_NAMES]; ///< the numbers met, in order of first appearance
	int seen_count;
} svg_renamer;

/// Where Cairo's output goes: a file, through the renamer for SVG.
typedef struct stream_closure {
	FILE *stream;
	int error; ///< errno of the first failed write, 0 when none failed
	bool svg;  ///< renumber surface names (svg_renamer)
	svg_renamer names;
} stream_closure;

static const char svg_token[] = "surface";
enum { SVG_TOKEN_LENGTH = sizeof svg_token - 1 };

static bool put_bytes(stream_closure *target, const void *data, size_t length)
{
	if (length > 0 && fwrite(data, 1, length, target->stream) != length) {
		if (target->error == 0)
			target->error = errno != 0 ? errno : EIO;
		return false;
	}
	return true;
}

/// Writes the name held (matched, digits): renumbered when it has digits, else as it came.
static bool flush_name(stream_closure *target)
{
	svg_renamer *r = &target->names;
	bool ok = put_bytes(target, svg_token, (size_t)r->matched);
	if (r->digit_count > 0) {
		long number = 0;
		for (int i = 0; i < r->digit_count; ++i)
			number = number < 100000000L ? number * 10 + (r->digits[i] - '0') : number;
		int rank = -1;
		for (int k = 0; k < r->seen_count && rank < 0; ++k)
			if (r->seen[k] == number)
				rank = k;
		if (rank < 0 && r->seen_count < SVG_MAX_NAMES) {
			r->seen[r->seen_count] = number;
			rank = r->seen_count++;
		}
		if (rank >= 0) { // beyond SVG_MAX_NAMES distinct names the rest stay as Cairo wrote them
			char text[16];
			int n = snprintf(text, sizeof text, "%d", rank + 1);
			ok = ok && put_bytes(target, text, (size_t)n);
		} else {
			ok = ok && put_bytes(target, r->digits, (size_t)r->digit_count);
		}
	}
	r->matched = 0;
	r->digit_count = 0;
	return ok;
}

/// The SVG text through the renamer: plain runs go out as they are, names renumbered.
static bool write_svg_renamed(stream_closure *target, const unsigned char *data, size_t length)
{
	svg_renamer *r = &target->names;
	size_t run = 0; // data[run, i) passes through unchanged
	for (size_t i = 0; i < length; ++i) {
		char c = (char)data[i];
		if (r->matched == 0) {
			if (c != svg_token[0])
				continue;
			if (!put_bytes(target, data + run, i - run))
				return false;
			r->matched = 1;
			run = i + 1;
		} else if (r->matched < SVG_TOKEN_LENGTH) {
			if (c == svg_token[r->matched]) {
				r->matched++;
				run = i + 1;
			} else {
				// Not a name: the letters held go out, and c starts over ("surface" repeats no letter
				// of its own, so no match can begin inside the letters held).
				if (!flush_name(target))
					return false;
				run = i;
				--i;
			}
		} else if (isdigit((unsigned char)c) && r->digit_count < SVG_MAX_DIGITS) {
			r->digits[r->digit_count++] = c;
			run = i + 1;
		} else {
			if (!flush_name(target))
				return false;
			run = i;
			--i;
		}
	}
	return put_bytes(target, data + run, length - run);
}

static cairo_status_t write_to_stream(void *closure, const unsigned char *data, unsigned int length)
{
	stream_closure *target = closure;
	bool ok = target->svg ? write_svg_renamed(target, data, length) : put_bytes(target, data, length);
	return ok ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

static const char *format_name(plume_image_format format)
{
	switch (format) {
	case PLUME_IMAGE_PNG: return "PNG";
	case PLUME_IMAGE_SVG: return "SVG";
	case PLUME_IMAGE_PDF: return "PDF";
	}
	return "image";
}

static plume_status cairo_failure(const char *path, plume_image_format format, cairo_status_t status,
                                  const stream_closure *closure, plume_error *err)
{
	if (status == CAIRO_STATUS_NO_MEMORY)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory while rendering %s", path,
		                       format_name(format));
	return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write %s: %s", path, format_name(format),
	                       closure != NULL && closure->error != 0 ? strerror(closure->error)
	                                                              : cairo_status_to_string(status));
}

/// Paints the background and the feather onto surface.
/// The bounds of several feathers together.
static plume_feather_info union_info(const plume_feather *const *feathers, int count)
{
	plume_feather_info info = plume_feather_get_info(feathers[0]);
	for (int i = 1; i < count; ++i) {
		plume_feather_info other = plume_feather_get_info(feathers[i]);
		info.bounds_min.x = fmin(info.bounds_min.x, other.bounds_min.x);
		info.bounds_min.y = fmin(info.bounds_min.y, other.bounds_min.y);
		info.bounds_min.z = fmin(info.bounds_min.z, other.bounds_min.z);
		info.bounds_max.x = fmax(info.bounds_max.x, other.bounds_max.x);
		info.bounds_max.y = fmax(info.bounds_max.y, other.bounds_max.y);
		info.bounds_max.z = fmax(info.bounds_max.z, other.bounds_max.z);
	}
	return info;
}

static cairo_status_t paint(cairo_surface_t *surface, const plume_feather *const *feathers, int count,
                            const plume_render2d_def *def, bool *out_of_memory)
{
	cairo_t *cr = cairo_create(surface);
	// No feather (count 0): the def's view frames the empty picture.
	plume_feather_info info = {0};
	if (count > 0)
		info = union_info(feathers, count);
	renderer r = {.cr = cr, .def = def, .view = fit_view(def, info)};
	// SOURCE so that a translucent background replaces the surface's
	// transparent black instead of blending with it.
	cairo_set_operator(cr, CAIRO_OPERATOR_SOURCE);
	set_color(cr, def->background);
	cairo_paint(cr);
	cairo_set_operator(cr, CAIRO_OPERATOR_OVER);
	cairo_set_antialias(cr, CAIRO_ANTIALIAS_GOOD);
	// Ribbons fold over themselves at sharp bends; with the winding rule the
	// fold stays filled.
	cairo_set_fill_rule(cr, CAIRO_FILL_RULE_WINDING);
	for (int i = 0; i < count && !r.out_of_memory; ++i)
		draw_feather(&r, feathers[i]);
	plume_free(r.scratch.left);
	plume_free(r.scratch.right);
	*out_of_memory = r.out_of_memory;
	cairo_status_t status = cairo_status(cr);
	cairo_destroy(cr);
	return status;
}

static plume_status render_png(const plume_feather *const *feathers, int count, const plume_render2d_def *def,
                               const char *path, plume_error *err)
{
	cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, def->width, def->height);
	cairo_status_t status = cairo_surface_status(surface);
	bool out_of_memory = false;
	if (status == CAIRO_STATUS_SUCCESS)
		status = paint(surface, feathers, count, def, &out_of_memory);
	if (status == CAIRO_STATUS_SUCCESS && out_of_memory)
		status = CAIRO_STATUS_NO_MEMORY;
	if (status != CAIRO_STATUS_SUCCESS) {
		cairo_surface_destroy(surface);
		return cairo_failure(path, PLUME_IMAGE_PNG, status, NULL, err);
	}
	cairo_surface_flush(surface);
	plume_status result = plume_cairo_write_png(surface, path, err);
	cairo_surface_destroy(surface);
	return result;
}

/// A fixed date for the PDF's metadata: Cairo otherwise stamps the current
/// time, and the same feather must give the same bytes. This is the paper's year.
#define FIXED_PDF_DATE "2002-01-01T00:00:00Z"

static plume_status render_vector(const plume_feather *const *feathers, int count, const plume_render2d_def *def,
                                  plume_image_format format, const char *path, plume_error *err)
{
	plume_atomic_file file;
	plume_status result = plume_atomic_open(&file, path, err);
	if (result != PLUME_OK)
		return result;
	stream_closure closure = {.stream = file.stream, .svg = format == PLUME_IMAGE_SVG};
	cairo_surface_t *surface;
	if (format == PLUME_IMAGE_SVG) {
		surface = cairo_svg_surface_create_for_stream(write_to_stream, &closure, def->width, def->height);
	} else {
		surface = cairo_pdf_surface_create_for_stream(write_to_stream, &closure, def->width, def->height);
		cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATE_DATE, FIXED_PDF_DATE);
		cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_MOD_DATE, FIXED_PDF_DATE);
	}
	cairo_status_t status = cairo_surface_status(surface);
	bool out_of_memory = false;
	if (status == CAIRO_STATUS_SUCCESS)
		status = paint(surface, feathers, count, def, &out_of_memory);
	if (status == CAIRO_STATUS_SUCCESS && out_of_memory)
		status = CAIRO_STATUS_NO_MEMORY;
	// Finishing writes the document's tail; its status tells whether every write worked.
	cairo_surface_finish(surface);
	if (status == CAIRO_STATUS_SUCCESS)
		status = cairo_surface_status(surface);
	cairo_surface_destroy(surface);
	// A name at the very end of the document.
	if (status == CAIRO_STATUS_SUCCESS && closure.svg && closure.names.matched > 0 && !flush_name(&closure))
		status = CAIRO_STATUS_WRITE_ERROR;
	if (status != CAIRO_STATUS_SUCCESS || closure.error != 0) {
		plume_atomic_abort(&file);
		return cairo_failure(path, format, status != CAIRO_STATUS_SUCCESS ? status : CAIRO_STATUS_WRITE_ERROR, &closure,
		                     err);
	}
	return plume_atomic_commit(&file, err);
}

plume_status plume_render2d(const plume_feather *feather, const plume_render2d_def *def, plume_image_format format,
                            const char *path, plume_error *err)
{
	PLUME_ASSERT(feather != NULL);
	return plume_render2d_feathers(&feather, 1, def, format, path, err);
}

plume_status plume_render2d_feathers(const plume_feather *const *feathers, int count, const plume_render2d_def *def,
                                     plume_image_format format, const char *path, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	PLUME_ASSERT(count >= 0 && (count == 0 || feathers != NULL));
	PLUME_ASSERT(def != NULL && path != NULL);
	// No feather at all is a picture of the background, when the def says what it frames.
	bool framed = def->view_max.x > def->view_min.x && def->view_max.y > def->view_min.y;
	if (count < 1 && !framed)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "render2d: no feather to draw (and no view_min, view_max to frame "
		                       "an empty picture)");
	plume_status status = validate_def(def, err);
	if (status != PLUME_OK)
		return status;
	if (format != PLUME_IMAGE_PNG && format != PLUME_IMAGE_SVG && format != PLUME_IMAGE_PDF)
		return plume_error_set(err, PLUME_ERROR_UNSUPPORTED, "%s: unknown image format %d", path, (int)format);
	for (int i = 0; i < count; ++i)
		if (plume_feather_get_info(feathers[i]).shaft_sample_count <= 0)
			return plume_error_set(err, PLUME_ERROR_SPEC, "render2d: the feather is empty (it has no shaft)");
	plume_feather_info info = {0};
	if (count > 0)
		info = union_info(feathers, count);
	if (!(isfinite(info.bounds_min.x) && isfinite(info.bounds_min.y) && isfinite(info.bounds_max.x) &&
	      isfinite(info.bounds_max.y)))
		return plume_error_set(err, PLUME_ERROR_NUMERIC, "render2d: the feather's bounds are not finite");
	if (format == PLUME_IMAGE_PNG)
		return render_png(feathers, count, def, path, err);
	return render_vector(feathers, count, def, format, path, err);
}

// plume — rendering. 2D: Cairo (line style and texture mapping) to PNG, SVG, PDF.
#ifndef PLUME_RENDER_H
#define PLUME_RENDER_H

#include "plume/feather.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

typedef enum plume_image_format {
	PLUME_IMAGE_PNG = 0,
	PLUME_IMAGE_SVG = 1,
	PLUME_IMAGE_PDF = 2,
} plume_image_format;

/// Linear-free sRGB colour with straight alpha, components in [0, 1].
typedef struct plume_color {
	double r, g, b, a;
} plume_color;

// ---------------------------------------------------------------------------
// Textures (Franco & Walter 4.4): the image's left half maps onto the left
// vane, its right half onto the right vane, by the barb's (s, t); the image's
// bottom row is the feather's base.

typedef struct plume_texture plume_texture;

/// Loads a PNG, JPEG, BMP or TGA image (stb_image).
plume_status plume_texture_load(const char *path, plume_texture **out, plume_error *err);

/// Wraps a copy of width x height RGBA8 pixels, rows top first.
plume_texture *plume_texture_create(int width, int height, const uint8_t *rgba);

/// plume's own texture: a hawk-like pattern of dark chevron bars on a tan
/// ground with a dark subterminal band and a pale tip, mirrored between the
/// halves so both vanes match. Pure integer and polynomial arithmetic, so the
/// pixels are identical on every machine. NULL when memory runs out.
plume_texture *plume_texture_create_banded(int width, int height);

void plume_texture_destroy(plume_texture *texture);

int plume_texture_width(const plume_texture *texture);
int plume_texture_height(const plume_texture *texture);

/// Colour of a barb point on the given side at (s, t), with the paper's mapping:
/// i_n = floor(t n), i_m = floor((1 - s) m / 2) on the left vane and
/// floor(s m / 2 + m / 2) on the right, clamped to the image.
plume_color plume_texture_sample_vane(const plume_texture *texture, plume_side side, double s, double t);

/// Writes texture as PNG (atomically).
plume_status plume_texture_write_png(const plume_texture *texture, const char *path, plume_error *err);

// ---------------------------------------------------------------------------
// 2D rendering: an orthographic front view (the feather's xy plane) scaled to
// fit the image, strokes as filled ribbons whose width tapers as the curves'
// widths do.

/// How the 2D renderer draws barbs.
typedef enum plume_render_style {
	/// Filled ribbons as wide as the barbs (Franco & Walter's line style).
	PLUME_STYLE_LINES = 0,
	/// Two triangle strips each side of every barb, of constant width in the vane plane, fading in alpha
	/// towards the barb's tip and away from its centre line, the vane nearer the camera drawn from the barb
	/// tips inwards and the other outwards (Streit & Heidrich 4.3.1). Texture colours apply as in lines.
	PLUME_STYLE_STRIPS = 1,
} plume_render_style;

typedef struct plume_render2d_def {
	/// Image size in pixels (points for SVG and PDF), [16, 16384]. Default 1024 x 1024.
	int width;
	int height;
	/// Empty border around the feather, fraction of the smaller image side. Default 0.05.
	double margin;
	/// Default opaque white.
	plume_color background;
	/// Colour of barbs in the line style. Default dark brown-grey (0.18, 0.15, 0.13, 1).
	plume_color barb_color;
	/// Colour of the shaft. Default (0.10, 0.08, 0.07, 1).
	plume_color shaft_color;
	/// No stroke is drawn thinner than this, pixels, so fine barbs stay visible. Default 0.35.
	double min_stroke_px;
	/// Draw barbules when the feather has them. Default true.
	bool draw_barbules;
	/// When not NULL, barbs take their colour from this texture (the shaft keeps shaft_color).
	const plume_texture *texture;
	/// Barb drawing. Default PLUME_STYLE_LINES.
	plume_render_style style;
	/// PLUME_STYLE_STRIPS: width of each strip (one side of a barb), pixels, > 0. Default 2.
	double strip_width_px;
	/// PLUME_STYLE_STRIPS: alpha at a barb's root on its centre line, (0, 1]. Default 0.6.
	double strip_alpha;
	/// The region of the feather plane (x, y, m) fitted into the image, when view_max is above view_min in
	/// both coordinates; otherwise the feather's own bounds. Frames of a sequence share one framing this way.
	/// Default: empty (0, 0) to (0, 0).
	plume_vec2 view_min;
	plume_vec2 view_max;
	/// PLUME_DEF_COOKIE, set by plume_render2d_default_def; do not change.
	uint32_t cookie;
} plume_render2d_def;

plume_render2d_def plume_render2d_default_def(void);

/// Renders the feather (and its afterfeather) to path in the given format.
/// The file appears whole or not at all.
plume_status plume_render2d(const plume_feather *feather, const plume_render2d_def *def, plume_image_format format,
                            const char *path, plume_error *err);

/// Renders several feathers into one picture (a coat seen from +z, orthographically): one view fits them
/// all, and they are drawn whole, one after the other, in the order given (bottom to top).
plume_status plume_render2d_feathers(const plume_feather *const *feathers, int count, const plume_render2d_def *def,
                                     plume_image_format format, const char *path, plume_error *err);

// ---------------------------------------------------------------------------
// Shells: a quick shaded view of a simulated mesh (Cairo, flat shading, painter's order).

typedef struct plume_mesh plume_mesh;

typedef struct plume_shell_view_def {
	int width;  ///< pixels. Default 800.
	int height; ///< pixels. Default 800.
	/// Camera direction (from the scene towards the camera): azimuth about +y and elevation, radians.
	/// Defaults 0.6 and 0.35: a three-quarter view of a feather whose vane lies in the xy plane.
	double azimuth;
	double elevation;
	/// World box that must stay in view (so frames of a sequence share one framing); when
	/// min > max the box is taken from the positions. Default empty.
	plume_vec3 bounds_min;
	plume_vec3 bounds_max;
	plume_color background;   ///< Default (0.96, 0.96, 0.95, 1).
	plume_color vane_color;   ///< Default (0.78, 0.70, 0.58, 1).
	plume_color rachis_color; ///< Default (0.35, 0.27, 0.20, 1).
	/// PLUME_DEF_COOKIE, set by plume_shell_view_default_def; do not change.
	uint32_t cookie;
} plume_shell_view_def;

plume_shell_view_def plume_shell_view_default_def(void);

/// Draws the mesh at positions (mesh->rest when NULL) as a PNG, written whole or not at all.
plume_status plume_render_shell_png(const plume_mesh *mesh, const plume_vec3 *positions,
                                    const plume_shell_view_def *def, const char *path, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_RENDER_H

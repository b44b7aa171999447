// Private: Streit & Heidrich's triangle-strip barbs (4.3.1) for the 2D renderer.
#ifndef PLUME_RENDER_STRIPS_H
#define PLUME_RENDER_STRIPS_H

#include <stdbool.h>

#include <cairo.h>

#include "plume/render.h"

/// Draws the feather's barbs (not its afterfeather or shaft) as alpha-faded strips with Cairo, the feather
/// frame mapped to the image by image = (offset_x + scale x, offset_y - scale y). Returns false when
/// memory runs out.
bool plume_strips_draw_barbs(cairo_t *cr, const plume_feather *feather, const plume_render2d_def *def, double scale,
                             double offset_x, double offset_y);

#endif

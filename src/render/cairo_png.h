// Private: a Cairo image surface written as a PNG file that appears whole or not at all.
#ifndef PLUME_CAIRO_PNG_H
#define PLUME_CAIRO_PNG_H

#include <cairo.h>

#include "plume/core.h"

/// Writes surface to path through a temporary file. Errors: PLUME_ERROR_IO
/// "path: cannot write PNG: reason" (the path keeps whatever it had before),
/// PLUME_ERROR_MEMORY when Cairo runs out of memory.
plume_status plume_cairo_write_png(cairo_surface_t *surface, const char *path, plume_error *err);

#endif

// Private: a texture encoded as PNG in memory (for images embedded in .glb files).
#ifndef PLUME_TEXTURE_PNG_H
#define PLUME_TEXTURE_PNG_H

#include <stddef.h>

#include "plume/render.h"

/// The texture as PNG bytes (Cairo's encoder), *size of them; free with plume_free. NULL with
/// err set (PLUME_ERROR_MEMORY) on failure.
unsigned char *plume_texture_png_bytes(const plume_texture *texture, size_t *size, plume_error *err);

#endif

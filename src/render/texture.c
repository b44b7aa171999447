// Textures for the 2D renderer (Franco & Walter 4.4): RGBA8 images, loaded
// with stb_image, sampled with the paper's vane mapping, written with Cairo.
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <cairo.h>
#include <stb_image.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "plume/render.h"
#include "render/cairo_png.h"
#include "render/texture_png.h"

struct plume_texture {
	int width;
	int height;
	uint8_t *rgba; ///< width * height * 4 bytes, rows top first, straight alpha
};

/// Bytes of a width x height RGBA8 image, or 0 when that does not fit in size_t.
static size_t image_bytes(int width, int height)
{
	if (width <= 0 || height <= 0)
		return 0;
	size_t w = (size_t)width, h = (size_t)height;
	if (w > SIZE_MAX / 4 / h)
		return 0;
	return w * h * 4;
}

plume_texture *plume_texture_create(int width, int height, const uint8_t *rgba)
{
	PLUME_ASSERT(width > 0 && height > 0 && rgba != NULL);
	size_t bytes = image_bytes(width, height);
	if (bytes == 0)
		return NULL;
	plume_texture *texture = plume_alloc(sizeof *texture);
	if (texture == NULL)
		return NULL;
	texture->rgba = plume_alloc(bytes);
	if (texture->rgba == NULL) {
		plume_free(texture);
		return NULL;
	}
	memcpy(texture->rgba, rgba, bytes);
	texture->width = width;
	texture->height = height;
	return texture;
}

void plume_texture_destroy(plume_texture *texture)
{
	if (texture == NULL)
		return;
	plume_free(texture->rgba);
	plume_free(texture);
}

int plume_texture_width(const plume_texture *texture) { return texture->width; }

int plume_texture_height(const plume_texture *texture) { return texture->height; }

/// Reads a whole file into plume memory, so that a read error (a folder, an
/// unreadable device) is told apart from an image stb cannot decode.
static plume_status read_whole_file(const char *path, uint8_t **data_out, size_t *size_out, plume_error *err)
{
	FILE *file = fopen(path, "rb");
	if (file == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read: %s", path, strerror(errno));
	uint8_t *data = NULL;
	int capacity = 0;
	size_t size = 0;
	for (;;) {
		if (size + 65536 > (size_t)INT_MAX / 2) {
			// stb_image takes the length as an int (and the buffer doubles as it grows).
			fclose(file);
			plume_free(data);
			return plume_error_set(err, PLUME_ERROR_SYNTAX, "%s: not an image stb can read (file too large)", path);
		}
		if (PLUME_GROW(data, capacity, (int)size + 65536) != 0) {
			fclose(file);
			plume_free(data);
			return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory while reading", path);
		}
		size_t got = fread(data + size, 1, 65536, file);
		size += got;
		if (got < 65536)
			break;
	}
	if (ferror(file)) {
		int error = errno;
		fclose(file);
		plume_free(data);
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read: %s", path, strerror(error));
	}
	fclose(file);
	*data_out = data;
	*size_out = size;
	return PLUME_OK;
}

plume_status plume_texture_load(const char *path, plume_texture **out, plume_error *err)
{
	PLUME_ASSERT(path != NULL && out != NULL);
	*out = NULL;
	uint8_t *data = NULL;
	size_t size = 0;
	plume_status status = read_whole_file(path, &data, &size, err);
	if (status != PLUME_OK)
		return status;
	int width = 0, height = 0, channels = 0;
	// The header's size before the pixels: a crafted 60000 x 60000 PNG of a few
	// bytes would otherwise ask stb for 14 GB. 16384 is the CLI's largest --size.
	if (stbi_info_from_memory(data, (int)size, &width, &height, &channels) && (width > 16384 || height > 16384)) {
		plume_free(data);
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: a %d x %d image; textures are at most 16384 x 16384 pixels",
		                       path, width, height);
	}
	// stb's own allocations use malloc; the pixels are copied into plume memory
	// at once so that the texture is counted like every other libplume object.
	stbi_uc *pixels = stbi_load_from_memory(data, (int)size, &width, &height, &channels, 4);
	plume_free(data);
	if (pixels == NULL) {
		const char *reason = stbi_failure_reason();
		return plume_error_set(err, PLUME_ERROR_SYNTAX, "%s: not an image stb can read (%s)", path,
		                       reason != NULL ? reason : "unknown reason");
	}
	if (image_bytes(width, height) == 0) {
		stbi_image_free(pixels);
		return plume_error_set(err, PLUME_ERROR_SYNTAX, "%s: not an image stb can read (size %d x %d)", path, width,
		                       height);
	}
	plume_texture *texture = plume_texture_create(width, height, pixels);
	stbi_image_free(pixels);
	if (texture == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory for a %d x %d texture", path, width, height);
	*out = texture;
	return PLUME_OK;
}

/// floor(value) clamped to [0, size - 1], safe for values far outside the
/// range (a direct cast of a huge double to int would be undefined).
static int clamp_index(double value, int size)
{
	double index = floor(value);
	if (!(index > 0.0))
		return 0;
	if (index >= (double)(size - 1))
		return size - 1;
	return (int)index;
}

plume_color plume_texture_sample_vane(const plume_texture *texture, plume_side side, double s, double t)
{
	PLUME_ASSERT(texture != NULL && !isnan(s) && !isnan(t));
	int m = texture->width, n = texture->height;
	// Franco & Walter 4.4: i_n = floor(t n), i_ml = floor((1 - s) m / 2),
	// i_mr = floor(s m / 2 + m / 2). The rachis (s = 0) sits at the middle
	// column and each vane's edge (s = 1) at the image's left or right border.
	int i_n = clamp_index(t * n, n);
	int i_m = side == PLUME_SIDE_LEFT ? clamp_index((1.0 - s) * m / 2.0, m) : clamp_index(s * m / 2.0 + m / 2.0, m);
	// i_n counts from the image's bottom row (the feather's base); rows are stored top first.
	int row = n - 1 - i_n;
	const uint8_t *p = texture->rgba + ((size_t)row * (size_t)m + (size_t)i_m) * 4;
	return (plume_color){p[0] / 255.0, p[1] / 255.0, p[2] / 255.0, p[3] / 255.0};
}

/// Straight 8-bit channel times alpha, rounded: Cairo's ARGB32 is premultiplied.
static uint32_t premultiply(uint8_t channel, uint8_t alpha) { return ((uint32_t)channel * alpha + 127u) / 255u; }

// The texture as a Cairo ARGB32 surface (premultiplied) in *out.
static plume_status texture_surface(const plume_texture *texture, const char *path, cairo_surface_t **out,
                                    plume_error *err)
{
	*out = NULL;
	cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, texture->width, texture->height);
	cairo_status_t cairo_status = cairo_surface_status(surface);
	if (cairo_status != CAIRO_STATUS_SUCCESS) {
		cairo_surface_destroy(surface);
		return plume_error_set(err, cairo_status == CAIRO_STATUS_NO_MEMORY ? PLUME_ERROR_MEMORY : PLUME_ERROR_IO,
		                       "%s: cannot make a %d x %d image: %s", path, texture->width, texture->height,
		                       cairo_status_to_string(cairo_status));
	}
	cairo_surface_flush(surface);
	unsigned char *target = cairo_image_surface_get_data(surface);
	int stride = cairo_image_surface_get_stride(surface);
	for (int y = 0; y < texture->height; ++y) {
		const uint8_t *source = texture->rgba + (size_t)y * (size_t)texture->width * 4;
		// ARGB32 pixels are native-endian 32-bit words, alpha in the top byte.
		uint32_t *row = (uint32_t *)(void *)(target + (size_t)y * (size_t)stride);
		for (int x = 0; x < texture->width; ++x) {
			const uint8_t *p = source + (size_t)x * 4;
			uint8_t a = p[3];
			row[x] = (uint32_t)a << 24 | premultiply(p[0], a) << 16 | premultiply(p[1], a) << 8 | premultiply(p[2], a);
		}
	}
	cairo_surface_mark_dirty(surface);
	*out = surface;
	return PLUME_OK;
}

plume_status plume_texture_write_png(const plume_texture *texture, const char *path, plume_error *err)
{
	PLUME_ASSERT(texture != NULL && path != NULL);
	cairo_surface_t *surface = NULL;
	plume_status status = texture_surface(texture, path, &surface, err);
	if (status != PLUME_OK)
		return status;
	status = plume_cairo_write_png(surface, path, err);
	cairo_surface_destroy(surface);
	return status;
}

typedef struct png_bytes {
	unsigned char *data;
	size_t size, capacity;
} png_bytes;

static cairo_status_t append_png(void *closure, const unsigned char *data, unsigned int length)
{
	png_bytes *out = closure;
	if (out->size + length > out->capacity) {
		size_t capacity = out->capacity > 0 ? out->capacity : 1 << 16;
		while (capacity < out->size + length)
			capacity *= 2;
		unsigned char *grown = plume_realloc(out->data, capacity);
		if (grown == NULL)
			return CAIRO_STATUS_NO_MEMORY;
		out->data = grown;
		out->capacity = capacity;
	}
	memcpy(out->data + out->size, data, length);
	out->size += length;
	return CAIRO_STATUS_SUCCESS;
}

unsigned char *plume_texture_png_bytes(const plume_texture *texture, size_t *size, plume_error *err)
{
	*size = 0;
	cairo_surface_t *surface = NULL;
	if (texture_surface(texture, "texture", &surface, err) != PLUME_OK)
		return NULL;
	png_bytes out = {0};
	cairo_status_t status = cairo_surface_write_to_png_stream(surface, append_png, &out);
	cairo_surface_destroy(surface);
	if (status != CAIRO_STATUS_SUCCESS) {
		plume_free(out.data);
		plume_error_set(err, PLUME_ERROR_MEMORY, "texture: cannot encode PNG: %s", cairo_status_to_string(status));
		return NULL;
	}
	*size = out.size;
	return out.data;
}

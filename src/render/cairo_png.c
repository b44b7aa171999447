// PNG files from Cairo surfaces, for the renderer and the textures alike.
#include "cairo_png.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "core/atomic_file.h"

typedef struct png_target {
	FILE *stream;
	int error; ///< errno of the first failed write, 0 when none failed
} png_target;

static cairo_status_t write_to_stream(void *closure, const unsigned char *data, unsigned int length)
{
	png_target *target = closure;
	if (fwrite(data, 1, length, target->stream) != length) {
		if (target->error == 0)
			target->error = errno != 0 ? errno : EIO;
		return CAIRO_STATUS_WRITE_ERROR;
	}
	return CAIRO_STATUS_SUCCESS;
}

plume_status plume_cairo_write_png(cairo_surface_t *surface, const char *path, plume_error *err)
{
	plume_atomic_file file;
	plume_status status = plume_atomic_open(&file, path, err);
	if (status != PLUME_OK)
		return status;
	png_target target = {file.stream, 0};
	cairo_status_t cairo_status = cairo_surface_write_to_png_stream(surface, write_to_stream, &target);
	if (cairo_status != CAIRO_STATUS_SUCCESS) {
		plume_atomic_abort(&file);
		if (cairo_status == CAIRO_STATUS_NO_MEMORY)
			return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory while writing PNG", path);
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write PNG: %s", path,
		                       target.error != 0 ? strerror(target.error) : cairo_status_to_string(cairo_status));
	}
	return plume_atomic_commit(&file, err);
}

// Writes examples/textures/bands.png: plume's own banded hawk-like feather
// texture (plume_texture_create_banded), laid out for Franco & Walter's
// mapping (section 4.4): the image's left half is the left vane, its right
// half the right vane, the rachis (s = 0) runs down the middle column, each
// vane's edge (s = 1) is an image border, and the bottom row is the base.
//
// Usage: plume-make-texture OUTPUT.png
//
// The pattern lives in the library, so the committed file, the CLI's demo and
// the tests all see the same pixels.
#include <stdio.h>

#include "plume/plume.h"

enum { TEXTURE_WIDTH = 512, TEXTURE_HEIGHT = 1024 };

int main(int argc, char **argv)
{
	if (argc != 2) {
		fprintf(stderr,
		        "usage: %s OUTPUT.png\n"
		        "Writes plume's banded hawk-like feather texture (%d x %d), as in examples/textures/bands.png.\n",
		        argc > 0 ? argv[0] : "plume-make-texture", TEXTURE_WIDTH, TEXTURE_HEIGHT);
		return 2;
	}
	plume_texture *texture = plume_texture_create_banded(TEXTURE_WIDTH, TEXTURE_HEIGHT);
	if (texture == NULL) {
		fprintf(stderr, "plume-make-texture: out of memory\n");
		return 1;
	}
	plume_error err;
	plume_status status = plume_texture_write_png(texture, argv[1], &err);
	plume_texture_destroy(texture);
	if (status != PLUME_OK) {
		fprintf(stderr, "plume-make-texture: %s\n", err.message);
		return 1;
	}
	return 0;
}

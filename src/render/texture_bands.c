// plume's built-in banded feather texture (see plume_texture_create_banded).
//
// No sin or cos: the bars come from a triangle wave and a smoothstep, so the
// image does not depend on the C library's transcendental functions.
#include <math.h>
#include "../core/alloc.h"

#include "plume/render.h"

static double smoothstep(double edge0, double edge1, double x)
{
	double t = (x - edge0) / (edge1 - edge0);
	t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
	return t * t * (3.0 - 2.0 * t);
}

static double mix(double a, double b, double t) { return a + (b - a) * t; }

static unsigned char to_byte(double value)
{
	value = value < 0.0 ? 0.0 : (value > 1.0 ? 1.0 : value);
	return (unsigned char)(value * 255.0 + 0.5);
}

/// Colour at vane coordinates (s from the rachis to the edge, t from base to tip).
static void banded_color(double s, double t, double rgb[3])
{
	static const double ground[3] = {0.80, 0.64, 0.44}, bar[3] = {0.27, 0.18, 0.11}, tip[3] = {0.93, 0.90, 0.84};
	// Barbs slant tipwards, so a bar that rises with s lies straight across the
	// rendered vane, as the bars of a hawk's tail do.
	double phase = 7.0 * (t + 0.12 * s);
	double wave = fabs(phase - floor(phase) - 0.5) * 2.0; // triangle wave in [0, 1]
	double darkness = smoothstep(0.55, 0.75, wave);
	darkness = fmax(darkness, smoothstep(0.80, 0.84, t) * (1.0 - smoothstep(0.93, 0.95, t))); // subterminal band
	for (int c = 0; c < 3; ++c) {
		double value = mix(ground[c], bar[c], darkness);
		value = mix(value, tip[c], smoothstep(0.95, 0.97, t));
		value *= mix(1.08, 0.92, s); // paler along the rachis, darker at the edge
		rgb[c] = value;
	}
}

plume_texture *plume_texture_create_banded(int width, int height)
{
	if (width < 2 || height < 2)
		return NULL;
	unsigned char *pixels = plume_alloc((size_t)width * (size_t)height * 4);
	if (pixels == NULL)
		return NULL;
	double half = width / 2.0;
	for (int y = 0; y < height; ++y) {
		double t = 1.0 - (y + 0.5) / height; // row 0 is the tip
		for (int x = 0; x < width; ++x) {
			// Left half: s = 1 at the left border; right half: s = 1 at the right border.
			double s = x < width / 2 ? 1.0 - (x + 0.5) / half : (x + 0.5 - half) / half;
			double rgb[3];
			banded_color(s, t, rgb);
			unsigned char *pixel = pixels + 4 * ((size_t)y * (size_t)width + (size_t)x);
			pixel[0] = to_byte(rgb[0]);
			pixel[1] = to_byte(rgb[1]);
			pixel[2] = to_byte(rgb[2]);
			pixel[3] = 255;
		}
	}
	plume_texture *texture = plume_texture_create(width, height, pixels);
	plume_free(pixels);
	return texture;
}

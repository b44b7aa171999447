// Streit & Heidrich 4.2.2: barb lengths from a flatbed scan. The image is
// segmented into feather (dark) and light background; each barb's length is
// the distance from the rachis to the silhouette along the barb's direction.
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <stb_image.h>

#include "../core/alloc.h"
#include "streit_heidrich_internal.h"

plume_sh_scan_def plume_sh_default_scan_def(void)
{
	return (plume_sh_scan_def){.base_px = {0.0, 0.0}, .tip_px = {0.0, 0.0}, .threshold = 0.0, .samples = 101};
}

/// Otsu's threshold over a 256-bin luminance histogram: the level that best separates two classes.
/// Returns a luminance in [0, 1], or -1 when the image has a single level.
static double otsu(const unsigned char *levels, size_t count)
{
	double histogram[256] = {0};
	for (size_t i = 0; i < count; ++i)
		histogram[levels[i]] += 1.0;
	double total = (double)count, sum = 0.0;
	for (int k = 0; k < 256; ++k)
		sum += k * histogram[k];
	double weight_below = 0.0, sum_below = 0.0, best = -1.0;
	int best_level = -1;
	for (int k = 0; k < 255; ++k) {
		weight_below += histogram[k];
		sum_below += k * histogram[k];
		double weight_above = total - weight_below;
		if (weight_below == 0.0 || weight_above == 0.0)
			continue;
		double mean_below = sum_below / weight_below, mean_above = (sum - sum_below) / weight_above;
		double between = weight_below * weight_above * (mean_below - mean_above) * (mean_below - mean_above);
		if (between > best) {
			best = between;
			best_level = k;
		}
	}
	return best_level < 0 ? -1.0 : (best_level + 0.5) / 255.0;
}

typedef struct scan_image {
	int width, height;
	unsigned char *levels; ///< luminance 0..255 over white, rows top first
	double threshold;      ///< levels below threshold * 255 are feather
} scan_image;

static bool is_feather(const scan_image *image, double x, double y)
{
	int i = (int)floor(x), j = (int)floor(y);
	if (i < 0 || j < 0 || i >= image->width || j >= image->height)
		return false;
	return image->levels[(size_t)j * (size_t)image->width + (size_t)i] < image->threshold * 255.0;
}

/// Distance from origin along unit direction to the farthest feather pixel before a background run longer
/// than gap (pixels), or 0.
static double march(const scan_image *image, const double origin[2], const double direction[2], double gap)
{
	const double step = 0.25;
	double limit = hypot(image->width, image->height);
	double farthest = 0.0, last_hit = 0.0;
	for (double d = 0.0; d <= limit; d += step) {
		if (is_feather(image, origin[0] + d * direction[0], origin[1] + d * direction[1])) {
			farthest = d + 0.5 * step;
			last_hit = d;
		} else if (d - last_hit > gap) {
			break;
		}
	}
	return farthest;
}

plume_status plume_sh_scan_barb_lengths(const char *image_path, const plume_sh_scan_def *scan, plume_sh_params *params,
                                        plume_error *err)
{
	if (scan->samples < 2 || scan->samples > PLUME_SH_MAX_PROFILE)
		return plume_error_set(err, PLUME_ERROR_SPEC, "samples is %d, allowed [2, %d]", scan->samples,
		                       PLUME_SH_MAX_PROFILE);
	if (!(scan->threshold < 1.0) || !isfinite(scan->threshold))
		return plume_error_set(err, PLUME_ERROR_SPEC, "threshold is %g, allowed [0, 1) (0: Otsu's)", scan->threshold);
	double rachis[2] = {scan->tip_px[0] - scan->base_px[0], scan->tip_px[1] - scan->base_px[1]};
	double rachis_px = hypot(rachis[0], rachis[1]);
	if (!(rachis_px >= 2.0) || !isfinite(rachis_px))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "base_px and tip_px are %g pixels apart; the rachis must span at least 2 pixels",
		                       rachis_px);
	FILE *file = fopen(image_path, "rb");
	if (file == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read: %s", image_path, strerror(errno));
	int width = 0, height = 0, channels = 0;
	// The header's size first: scans are at most 16384 x 16384 pixels (a crafted header asks for gigabytes).
	if (stbi_info_from_file(file, &width, &height, &channels) && (width > 16384 || height > 16384)) {
		fclose(file);
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: a %d x %d image; scans are at most 16384 x 16384 pixels",
		                       image_path, width, height);
	}
	unsigned char *pixels = stbi_load_from_file(file, &width, &height, &channels, 4);
	fclose(file);
	if (pixels == NULL) {
		const char *reason = stbi_failure_reason();
		return plume_error_set(err, PLUME_ERROR_SYNTAX, "%s: not an image stb can read (%s)", image_path,
		                       reason != NULL ? reason : "unknown reason");
	}
	size_t count = (size_t)width * (size_t)height;
	scan_image image = {.width = width, .height = height, .levels = plume_alloc(count > 0 ? count : 1)};
	if (image.levels == NULL) {
		stbi_image_free(pixels);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", image_path);
	}
	for (size_t i = 0; i < count; ++i) {
		const unsigned char *p = pixels + 4 * i;
		// Rec. 709 luminance, composited over white (a transparent pixel is background).
		double luminance = (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
		double alpha = p[3] / 255.0;
		double over_white = alpha * luminance + (1.0 - alpha);
		image.levels[i] = (unsigned char)lround(over_white * 255.0);
	}
	stbi_image_free(pixels);
	image.threshold = scan->threshold > 0.0 ? scan->threshold : otsu(image.levels, count);
	size_t feather_pixels = 0;
	if (image.threshold > 0.0)
		for (size_t i = 0; i < count; ++i)
			feather_pixels += image.levels[i] < image.threshold * 255.0;
	if (feather_pixels == 0) {
		plume_free(image.levels);
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s: the scan is empty: no pixel is darker than the light background (threshold %g)",
		                       image_path, image.threshold > 0.0 ? image.threshold : 0.0);
	}

	// Image axes: x right, y down. The feather's +y runs from base to tip; its +x (the right vane) is that
	// direction turned a quarter clockwise on screen, as plume renders a feather seen from the front.
	double tangent[2] = {rachis[0] / rachis_px, rachis[1] / rachis_px};
	double right[2] = {-tangent[1], tangent[0]};
	double metres_per_px = params->rachis_length / rachis_px;
	double gap = fmax(3.0, 0.03 * rachis_px);
	for (int side = 0; side < 2; ++side) {
		plume_sh_length_profile *profile = &params->barb_length[side];
		memset(profile, 0, sizeof *profile);
		profile->count = scan->samples;
		double outward = side == PLUME_SIDE_LEFT ? -1.0 : 1.0;
		for (int j = 0; j < scan->samples; ++j) {
			double rp = (double)j / (scan->samples - 1);
			double angle = sh_barb_angle(params, (plume_side)side, rp);
			double origin[2] = {scan->base_px[0] + rp * rachis[0], scan->base_px[1] + rp * rachis[1]};
			double direction[2] = {-cos(angle) * tangent[0] + outward * sin(angle) * right[0],
			                       -cos(angle) * tangent[1] + outward * sin(angle) * right[1]};
			profile->position[j] = rp;
			profile->length[j] = march(&image, origin, direction, gap) * metres_per_px;
		}
	}
	plume_free(image.levels);
	return PLUME_OK;
}

// Plots of the lab's curves with PLplot (a real plotting library, as the issue asks):
// PNG through the "mem" raster driver (Debian's PLplot has no pngcairo driver) and
// Cairo's PNG writer, SVG through the "svg" driver. And CSV tables.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <plplot/plplot.h>

#include "core/alloc.h"
#include "core/asserts.h"
#include "core/atomic_file.h"
#include "core/number_text.h"
#include "plume/lab.h"
#include "render/cairo_png.h"

static bool has_driver(const char *name)
{
	const char **menus = NULL, **names = NULL;
	int count = 0;
	// plgDevs fills arrays of at most the count given; 64 is more than PLplot ships.
	const char *menu_storage[64], *name_storage[64];
	menus = menu_storage;
	names = name_storage;
	count = 64;
	plgDevs(&menus, &names, &count);
	for (int i = 0; i < count; ++i)
		if (strcmp(names[i], name) == 0)
			return true;
	return false;
}

// Data range of all series on one axis (log10 when the axis is logarithmic).
static void axis_range(const plume_plot *plot, bool y_axis, bool log_axis, double *lo, double *hi)
{
	*lo = INFINITY;
	*hi = -INFINITY;
	for (int s = 0; s < plot->series_count; ++s) {
		const plume_plot_series *series = plot->series + s;
		const double *v = y_axis ? series->y : series->x;
		for (int i = 0; i < series->count; ++i) {
			double value = log_axis ? (v[i] > 0.0 ? log10(v[i]) : NAN) : v[i];
			if (isfinite(value)) {
				*lo = fmin(*lo, value);
				*hi = fmax(*hi, value);
			}
		}
	}
	if (!isfinite(*lo)) {
		*lo = 0.0;
		*hi = 1.0;
	}
	double span = *hi - *lo;
	if (span <= 0.0)
		span = fabs(*hi) > 0.0 ? fabs(*hi) : 1.0;
	// A margin of 5%; linear axes that start at zero keep the origin.
	*lo = (!log_axis && *lo >= 0.0 && *lo <= 0.05 * span) ? 0.0 : *lo - 0.05 * span;
	*hi += 0.05 * span;
}

enum { PALETTE = 8 };
static const int palette[PALETTE][3] = {{31, 119, 180}, {214, 39, 40},  {44, 160, 44}, {148, 103, 189},
                                        {255, 127, 14}, {23, 190, 207}, {140, 86, 75}, {127, 127, 127}};

// Draws into the current stream (after plinit).
static plume_status draw(const plume_plot *plot, plume_error *err)
{
	plscol0(0, 255, 255, 255); // background
	plscol0(1, 0, 0, 0);       // axes and text
	for (int c = 0; c < PALETTE; ++c)
		plscol0(2 + c, palette[c][0], palette[c][1], palette[c][2]);
	pladv(0);
	plvsta();
	plschr(0.0, 0.9);
	double x0, x1, y0, y1;
	axis_range(plot, false, plot->log_x, &x0, &x1);
	axis_range(plot, true, plot->log_y, &y0, &y1);
	plvpor(0.12, 0.95, 0.12, 0.9);
	plwind(x0, x1, y0, y1);
	plcol0(1);
	plwidth(1.0);
	plbox(plot->log_x ? "bcnstl" : "bcnst", 0.0, 0, plot->log_y ? "bcnstvl" : "bcnstv", 0.0, 0);
	pllab(plot->x_label != NULL ? plot->x_label : "", plot->y_label != NULL ? plot->y_label : "",
	      plot->title != NULL ? plot->title : "");
	int n = plot->series_count;
	PLINT opts[16], text_colors[16], line_colors[16], line_styles[16], symbol_colors[16], symbol_numbers[16];
	PLFLT line_widths[16], symbol_scales[16];
	const char *texts[16], *symbols[16];
	if (n > 16)
		return plume_error_set(err, PLUME_ERROR_SPEC, "a plot holds at most 16 series, got %d", n);
	for (int s = 0; s < n; ++s) {
		const plume_plot_series *series = plot->series + s;
		double *x = plume_alloc(sizeof(double) * (size_t)(series->count + 1));
		double *y = plume_alloc(sizeof(double) * (size_t)(series->count + 1));
		if (x == NULL || y == NULL) {
			plume_free(x);
			plume_free(y);
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory plotting");
		}
		int count = 0;
		for (int i = 0; i < series->count; ++i) {
			double xv = plot->log_x ? log10(series->x[i]) : series->x[i];
			double yv = plot->log_y ? log10(series->y[i]) : series->y[i];
			if (isfinite(xv) && isfinite(yv)) {
				x[count] = xv;
				y[count] = yv;
				++count;
			}
		}
		int color = 2 + s % PALETTE;
		plcol0(color);
		pllsty(series->dashed ? 2 : 1);
		plwidth(2.0);
		if (series->points || count == 1)
			plpoin(count, x, y, 3); // a lone sample is drawn as a marker
		else if (count > 1)
			plline(count, x, y);
		plume_free(x);
		plume_free(y);
		opts[s] = series->points ? PL_LEGEND_SYMBOL : PL_LEGEND_LINE;
		text_colors[s] = 1;
		line_colors[s] = color;
		line_styles[s] = series->dashed ? 2 : 1;
		line_widths[s] = 2.0;
		symbol_colors[s] = color;
		symbol_scales[s] = 1.0;
		symbol_numbers[s] = 3;
		symbols[s] = "#(728)";
		texts[s] = series->label != NULL ? series->label : "";
	}
	pllsty(1);
	plwidth(1.0);
	if (n > 0) {
		PLFLT legend_width, legend_height;
		bool top = plot->legend == PLUME_LEGEND_TOP_LEFT || plot->legend == PLUME_LEGEND_TOP_RIGHT;
		bool left = plot->legend == PLUME_LEGEND_TOP_LEFT || plot->legend == PLUME_LEGEND_BOTTOM_LEFT;
		PLINT position = (top ? PL_POSITION_TOP : PL_POSITION_BOTTOM) | (left ? PL_POSITION_LEFT : PL_POSITION_RIGHT) |
		                 PL_POSITION_INSIDE;
		pllegend(&legend_width, &legend_height, PL_LEGEND_BOUNDING_BOX, position, 0.02, 0.02, 0.08, 0, 1, 1, 0, 0, n,
		         opts, 1.0, 0.8, 2.0, 0.0, text_colors, texts, NULL, NULL, NULL, NULL, line_colors, line_styles,
		         line_widths, symbol_colors, symbol_scales, symbol_numbers, symbols);
	}
	return PLUME_OK;
}

static plume_status plot_svg(const plume_plot *plot, const char *path, int width, int height, plume_error *err)
{
	if (!has_driver("svg"))
		return plume_error_set(err, PLUME_ERROR_UNSUPPORTED, "%s: this PLplot has no svg driver", path);
	plume_atomic_file file;
	plume_status status = plume_atomic_open(&file, path, err);
	if (status != PLUME_OK)
		return status;
	fclose(file.stream);
	file.stream = NULL;
	PLINT stream;
	plmkstrm(&stream);
	plsdev("svg");
	plsfnam(file.tmp_path);
	plspage(90.0, 90.0, width, height, 0, 0);
	plscolbg(255, 255, 255);
	plinit();
	status = draw(plot, err);
	plend1();
	if (status != PLUME_OK) {
		plume_atomic_abort(&file);
		return status;
	}
	return plume_atomic_commit(&file, err);
}

static plume_status plot_png(const plume_plot *plot, const char *path, int width, int height, plume_error *err)
{
	if (!has_driver("mem"))
		return plume_error_set(err, PLUME_ERROR_UNSUPPORTED, "%s: this PLplot has no mem driver for PNG", path);
	size_t stride = 3 * (size_t)width;
	unsigned char *rgb = plume_alloc(stride * (size_t)height);
	if (rgb == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory for a %d x %d plot", width, height);
	memset(rgb, 255, stride * (size_t)height);
	PLINT stream;
	plmkstrm(&stream);
	plsdev("mem");
	plsmem(width, height, rgb);
	plscolbg(255, 255, 255);
	plinit();
	plume_status status = draw(plot, err);
	plend1();
	if (status == PLUME_OK) {
		cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
		cairo_surface_flush(surface);
		unsigned char *data = cairo_image_surface_get_data(surface);
		int pitch = cairo_image_surface_get_stride(surface);
		if (data == NULL) {
			status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory for a %d x %d plot", width, height);
		} else {
			for (int j = 0; j < height; ++j) {
				uint32_t *row = (uint32_t *)(void *)(data + (size_t)j * (size_t)pitch);
				const unsigned char *source = rgb + (size_t)j * stride;
				for (int i = 0; i < width; ++i)
					row[i] = (uint32_t)source[3 * i] << 16 | (uint32_t)source[3 * i + 1] << 8 | source[3 * i + 2];
			}
			cairo_surface_mark_dirty(surface);
			status = plume_cairo_write_png(surface, path, err);
		}
		cairo_surface_destroy(surface);
	}
	plume_free(rgb);
	return status;
}

plume_status plume_lab_plot(const plume_plot *plot, const char *png_path, const char *svg_path, plume_error *err)
{
	int width = plot->width > 0 ? plot->width : 960;
	int height = plot->height > 0 ? plot->height : 720;
	plume_status status = PLUME_OK;
	if (png_path != NULL)
		status = plot_png(plot, png_path, width, height, err);
	if (status == PLUME_OK && svg_path != NULL)
		status = plot_svg(plot, svg_path, width, height, err);
	return status;
}

const char *plume_lab_format_number(char *text, size_t size, double value)
{
	PLUME_ASSERT(text != NULL && size >= PLUME_LAB_NUMBER_TEXT);
	return plume_number_shortest(text, size, value);
}

plume_status plume_lab_write_csv(const char *path, const char *header, const double *const *columns, int column_count,
                                 int row_count, plume_error *err)
{
	plume_atomic_file file;
	plume_status status = plume_atomic_open(&file, path, err);
	if (status != PLUME_OK)
		return status;
	fprintf(file.stream, "%s\n", header);
	char number[PLUME_LAB_NUMBER_TEXT];
	for (int r = 0; r < row_count; ++r)
		for (int c = 0; c < column_count; ++c)
			fprintf(file.stream, "%s%c", plume_lab_format_number(number, sizeof number, columns[c][r]),
			        c + 1 < column_count ? ',' : '\n');
	return plume_atomic_commit(&file, err);
}

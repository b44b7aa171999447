// Output sets: all files of one run appear together or not at all.
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

int cli_fail(const plume_error *err)
{
	fprintf(stderr, "plume: %s\n", err->message);
	switch (err->status) {
	case PLUME_OK: return CLI_EXIT_OK;
	case PLUME_ERROR_IO: return CLI_EXIT_IO;
	case PLUME_ERROR_SYNTAX:
	case PLUME_ERROR_SPEC: return CLI_EXIT_INPUT;
	default: return CLI_EXIT_FAILURE;
	}
}

bool cli_check_arguments(const char *command, int argc, char **argv, const char *input, const char *output_dir)
{
	if (optind >= argc)
		cli_usage_error(command, "missing %s", input);
	else if (optind + 1 < argc)
		cli_usage_error(command, "unexpected argument '%s'", argv[optind + 1]);
	else if (output_dir == NULL)
		cli_usage_error(command, "missing -o DIR");
	else
		return true;
	return false;
}

bool cli_parse_style(const char *command, const char *text, plume_render_style *style)
{
	if (strcmp(text, "lines") == 0)
		*style = PLUME_STYLE_LINES;
	else if (strcmp(text, "strips") == 0)
		*style = PLUME_STYLE_STRIPS;
	else {
		cli_usage_error(command, "--style '%s': allowed lines, strips", text);
		return false;
	}
	return true;
}

int cli_usage_error(const char *command, const char *format, ...)
{
	va_list args;
	va_start(args, format);
	fprintf(stderr, "plume: %s: ", command);
	vfprintf(stderr, format, args);
	fprintf(stderr, "\nTry 'plume help %s'.\n", command);
	va_end(args);
	return CLI_EXIT_USAGE;
}

static const struct {
	const char *name;
	unsigned bit;
} format_names[] = {
    {"png", CLI_FORMAT_PNG},   {"svg", CLI_FORMAT_SVG},   {"pdf", CLI_FORMAT_PDF}, {"obj", CLI_FORMAT_OBJ},
    {"usda", CLI_FORMAT_USDA}, {"json", CLI_FORMAT_JSON}, {"glb", CLI_FORMAT_GLB},
};

bool cli_parse_formats(const char *command, const char *list, unsigned *formats)
{
	*formats = 0;
	const char *cursor = list;
	while (*cursor != '\0') {
		size_t length = strcspn(cursor, ",");
		bool known = false;
		for (size_t i = 0; i < sizeof format_names / sizeof format_names[0]; ++i) {
			if (strlen(format_names[i].name) == length && strncmp(cursor, format_names[i].name, length) == 0) {
				*formats |= format_names[i].bit;
				known = true;
			}
		}
		if (!known) {
			cli_usage_error(command, "unknown format '%.*s' in --format; allowed: png, svg, pdf, obj, usda, json, glb",
			                (int)length, cursor);
			return false;
		}
		cursor += length;
		if (*cursor == ',')
			++cursor;
	}
	if (*formats == 0) {
		cli_usage_error(command, "--format needs at least one of png, svg, pdf, obj, usda, json, glb");
		return false;
	}
	return true;
}

bool cli_parse_size(const char *command, const char *text, int *width, int *height)
{
	char tail;
	if (sscanf(text, "%dx%d%c", width, height, &tail) != 2 || *width < 16 || *width > 16384 || *height < 16 ||
	    *height > 16384) {
		cli_usage_error(command, "--size '%s' must be WxH in pixels, each in [16, 16384]", text);
		return false;
	}
	return true;
}

bool cli_parse_seed(const char *command, const char *text, uint64_t *seed)
{
	char *end;
	errno = 0;
	unsigned long long value = strtoull(text, &end, 10);
	if (errno != 0 || end == text || *end != '\0' || text[0] == '-') {
		cli_usage_error(command, "--seed '%s' must be a non-negative integer below 2^64", text);
		return false;
	}
	*seed = value;
	return true;
}

// ---------------------------------------------------------------------------
// Staging

static void remove_tree(const char *path)
{
	DIR *dir = opendir(path);
	if (dir != NULL) {
		struct dirent *entry;
		while ((entry = readdir(dir)) != NULL) {
			if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0)
				continue;
			char child[4352];
			snprintf(child, sizeof child, "%s/%s", path, entry->d_name);
			remove_tree(child);
		}
		closedir(dir);
		rmdir(path);
	} else {
		unlink(path);
	}
}

plume_status cli_output_begin(cli_output *output, const char *dir, plume_error *err)
{
	memset(output, 0, sizeof *output);
	size_t length = strlen(dir);
	while (length > 1 && dir[length - 1] == '/')
		--length;
	if (length == 0 || length + 32 >= sizeof output->dir)
		return plume_error_set(err, PLUME_ERROR_IO, "'%s': not a usable output folder", dir);
	memcpy(output->dir, dir, length);
	output->dir[length] = '\0';

	struct stat info;
	if (stat(output->dir, &info) == 0) {
		if (!S_ISDIR(info.st_mode))
			return plume_error_set(err, PLUME_ERROR_IO, "%s: exists and is not a folder", output->dir);
		output->dir_existed = true;
		snprintf(output->stage, sizeof output->stage, "%s/.plume-staging-XXXXXX", output->dir);
	} else {
		// A new folder is staged beside it and renamed into place whole.
		const char *slash = strrchr(output->dir, '/');
		int parent = slash != NULL ? (int)(slash - output->dir + 1) : 0;
		snprintf(output->stage, sizeof output->stage, "%.*s.%s.plume-staging-XXXXXX", parent, output->dir,
		         output->dir + parent);
	}
	if (mkdtemp(output->stage) == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write the output folder: %s", output->dir,
		                       strerror(errno));
	return PLUME_OK;
}

const char *cli_output_path(cli_output *output, const char *name, char *buffer, size_t size)
{
	if (output->name_count < (int)(sizeof output->names / sizeof output->names[0])) {
		snprintf(output->names[output->name_count], sizeof output->names[0], "%s", name);
		output->name_count++;
	}
	snprintf(buffer, size, "%s/%s", output->stage, name);
	return buffer;
}

plume_status cli_output_commit(cli_output *output, plume_error *err)
{
	if (!output->dir_existed) {
		// mkdtemp made the folder 0700; a results folder is ordinary.
		mode_t mask = umask(0);
		umask(mask);
		chmod(output->stage, 0777 & ~mask);
		if (rename(output->stage, output->dir) != 0) {
			plume_error_set(err, PLUME_ERROR_IO, "%s: cannot create the output folder: %s", output->dir,
			                strerror(errno));
			cli_output_abort(output);
			return PLUME_ERROR_IO;
		}
		return PLUME_OK;
	}
	// Every entry of the staging folder replaces its namesake. A folder (frames/) that
	// exists is moved aside first and removed only once the new one is in place.
	DIR *stage = opendir(output->stage);
	if (stage == NULL) {
		plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read the staging folder: %s", output->stage, strerror(errno));
		cli_output_abort(output);
		return PLUME_ERROR_IO;
	}
	struct dirent *entry;
	plume_status status = PLUME_OK;
	while (status == PLUME_OK && (entry = readdir(stage)) != NULL) {
		if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0)
			continue;
		char from[4608], to[4608], aside[4608];
		snprintf(from, sizeof from, "%s/%s", output->stage, entry->d_name);
		snprintf(to, sizeof to, "%s/%s", output->dir, entry->d_name);
		struct stat info;
		bool replace_folder = stat(to, &info) == 0 && S_ISDIR(info.st_mode);
		if (replace_folder) {
			snprintf(aside, sizeof aside, "%s/.%s.plume-old", output->dir, entry->d_name);
			if (rename(to, aside) != 0)
				replace_folder = false;
		}
		if (rename(from, to) != 0) {
			status = plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", to, strerror(errno));
			if (replace_folder)
				rename(aside, to);
		} else if (replace_folder) {
			remove_tree(aside);
		}
	}
	closedir(stage);
	if (status != PLUME_OK) {
		cli_output_abort(output);
		return status;
	}
	rmdir(output->stage);
	return PLUME_OK;
}

void cli_output_abort(cli_output *output)
{
	if (output->stage[0] != '\0')
		remove_tree(output->stage);
}

// ---------------------------------------------------------------------------
// Writing a feather

static plume_render2d_def image_def(const plume_feather *feather, const cli_image_options *images)
{
	plume_render2d_def def = plume_render2d_default_def();
	def.texture = images->texture;
	if (images->width > 0) {
		def.width = images->width;
		def.height = images->height;
		return def;
	}
	// Automatic size: 1200 pixels tall, as wide as the feather needs.
	plume_feather_info info = plume_feather_get_info(feather);
	double w = info.bounds_max.x - info.bounds_min.x, h = info.bounds_max.y - info.bounds_min.y;
	def.height = 1200;
	double inner = def.height * (1.0 - 2.0 * def.margin);
	int width = h > 0.0 ? (int)(inner * w / h + 2.0 * def.margin * def.height + 0.5) : def.height;
	def.width = width < 256 ? 256 : (width > 4096 ? 4096 : width);
	return def;
}

plume_status cli_write_feather(cli_output *output, const plume_feather *feather, const char *stem, unsigned formats,
                               const cli_image_options *images, plume_error *err)
{
	static const struct {
		unsigned bit;
		const char *extension;
	} order[] = {
	    {CLI_FORMAT_PNG, "png"},   {CLI_FORMAT_SVG, "svg"},   {CLI_FORMAT_PDF, "pdf"}, {CLI_FORMAT_OBJ, "obj"},
	    {CLI_FORMAT_USDA, "usda"}, {CLI_FORMAT_JSON, "json"}, {CLI_FORMAT_GLB, "glb"},
	};
	plume_render2d_def def = image_def(feather, images);
	for (size_t i = 0; i < sizeof order / sizeof order[0]; ++i) {
		if ((formats & order[i].bit) == 0)
			continue;
		char name[64], path[4352];
		snprintf(name, sizeof name, "%s.%s", stem, order[i].extension);
		cli_output_path(output, name, path, sizeof path);
		plume_status status;
		switch (order[i].bit) {
		case CLI_FORMAT_PNG: status = plume_render2d(feather, &def, PLUME_IMAGE_PNG, path, err); break;
		case CLI_FORMAT_SVG: status = plume_render2d(feather, &def, PLUME_IMAGE_SVG, path, err); break;
		case CLI_FORMAT_PDF: status = plume_render2d(feather, &def, PLUME_IMAGE_PDF, path, err); break;
		case CLI_FORMAT_OBJ: status = plume_write_obj(feather, path, err); break;
		case CLI_FORMAT_USDA: status = plume_write_usda(feather, path, err); break;
		case CLI_FORMAT_GLB: {
			plume_gltf_def gltf = plume_gltf_default_def();
			gltf.texture = images->texture;
			status = plume_write_glb(feather, &gltf, path, err);
			break;
		}
		default: status = plume_write_json(feather, path, err); break;
		}
		if (status != PLUME_OK)
			return status;
	}
	return PLUME_OK;
}

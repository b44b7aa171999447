// plume demo [-o DIR]: the whole path on a built-in feather, no input needed.
#define _POSIX_C_SOURCE 200809L
#include <getopt.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"

void cli_help_demo(void)
{
	puts("Usage: plume demo [-o DIR]\n"
	     "\n"
	     "Generates plume's built-in feather (a 0.2 m hawk contour feather, Franco &\n"
	     "Walter's model with the paper's hawk parameters) and writes it to DIR\n"
	     "(default: plume-demo) as images in the line style (PNG, SVG, PDF), a\n"
	     "texture-mapped PNG coloured by plume's own banded texture, and geometry\n"
	     "(OBJ curves, USD curves, JSON).\n"
	     "\n"
	     "Options:\n"
	     "  -o, --output DIR   output folder (default: plume-demo)\n"
	     "  -h, --help         this help");
}

int cli_demo(int argc, char **argv)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'},
	    {"help", no_argument, NULL, 'h'},
	    {NULL, 0, NULL, 0},
	};
	const char *output_dir = "plume-demo";
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 'h': cli_help_demo(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("demo", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("demo", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (optind < argc)
		return cli_usage_error("demo", "unexpected argument '%s'", argv[optind]);

	plume_error err = {0};
	plume_fw_def def = plume_fw_default_def();
	plume_feather *feather = NULL;
	plume_texture *texture = plume_texture_create_banded(512, 1024);
	cli_output output;
	cli_image_options lines = {0, 0, NULL}, textured = {0, 0, texture};
	plume_status status = texture == NULL ? plume_error_set(&err, PLUME_ERROR_MEMORY, "out of memory")
	                                      : plume_fw_generate(&def, 1, &feather, &err);
	if (status == PLUME_OK && (status = cli_output_begin(&output, output_dir, &err)) == PLUME_OK) {
		status = cli_write_feather(&output, feather, "feather", CLI_FORMAT_ALL, &lines, &err);
		if (status == PLUME_OK)
			status = cli_write_feather(&output, feather, "feather-textured", CLI_FORMAT_PNG, &textured, &err);
		if (status == PLUME_OK)
			status = cli_output_commit(&output, &err);
		else
			cli_output_abort(&output);
	}
	if (status == PLUME_OK) {
		plume_feather_info info = plume_feather_get_info(feather);
		printf("plume demo: a %.3f m hawk feather, %d barbs of %d points (Franco & Walter, seed 1)\n",
		       info.shaft_length, info.barb_count, def.barb_samples);
		for (int i = 0; i < output.name_count; ++i)
			printf("  %s/%s\n", output.dir, output.names[i]);
	}
	plume_feather_destroy(feather);
	plume_texture_destroy(texture);
	return status == PLUME_OK ? CLI_EXIT_OK : cli_fail(&err);
}

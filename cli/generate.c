// plume generate SPEC.json -o DIR [--seed N] [--format LIST] [--size WxH] [--texture IMAGE]
#define _POSIX_C_SOURCE 200809L
#include <getopt.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"

/// Writes the generator's diagnostics (plume_feather_summary) to
/// <staging>/summary.json and prints them on stdout: a model that could not do
/// everything it was asked (Zhang–Kanai barbs that did not snap) says so.
static plume_status write_summary(cli_output *output, const plume_feather *feather, plume_error *err)
{
	const char *summary = plume_feather_summary(feather);
	if (summary == NULL)
		return PLUME_OK;
	char path[4352];
	cli_output_path(output, "summary.json", path, sizeof path);
	FILE *file = fopen(path, "wb");
	bool written = file != NULL && fprintf(file, "%s\n", summary) >= 0;
	if (file != NULL && fclose(file) != 0)
		written = false;
	if (!written)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write the summary", path);
	printf("summary: %s\n", summary);
	return PLUME_OK;
}

/// cli_parse_formats skips one comma after each name, so "png," passed where "png,,obj" did not:
/// an empty item is refused wherever it is.
static bool formats_without_empty_items(const char *command, const char *list)
{
	size_t length = strlen(list);
	if (length > 0 && (list[0] == ',' || list[length - 1] == ',' || strstr(list, ",,") != NULL)) {
		cli_usage_error(command, "--format '%s' has an empty item; allowed: png, svg, pdf, obj, usda, json, glb", list);
		return false;
	}
	return true;
}

void cli_help_generate(void)
{
	puts("Usage: plume generate SPEC.json -o DIR [options]\n"
	     "\n"
	     "Generates the feather that SPEC.json describes and writes DIR/feather.<ext>\n"
	     "for each format. All files appear together, or none when anything fails.\n"
	     "A generator that reports diagnostics (zhang-kanai: barbs that did not snap)\n"
	     "also writes DIR/summary.json and prints it.\n"
	     "\n"
	     "Options:\n"
	     "  -o, --output DIR       output folder (created if missing)\n"
	     "  -s, --seed N           random seed; overrides the spec's \"seed\" (default 1)\n"
	     "  -f, --format LIST      comma-separated: png,svg,pdf,obj,usda,json,glb\n"
	     "                         (default: all but glb)\n"
	     "      --size WxH         image size in pixels (default: 1200 tall, width to fit)\n"
	     "  -t, --texture IMAGE    colour the barbs from IMAGE (Franco & Walter 4.4) instead\n"
	     "                         of the line style; feather.glb embeds IMAGE\n"
	     "      --max-memory BYTES refuse a feather estimated past BYTES, before the work (K, M,\n"
	     "                         G suffixes; default 4G; docs/cli.md)\n"
	     "  -h, --help             this help\n"
	     "\n"
	     "Specs are described in docs/spec-franco-walter.md and docs/spec-zhang-kanai.md;\n"
	     "examples/ has ready ones.");
}

int cli_generate(int argc, char **argv)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'},
	    {"seed", required_argument, NULL, 's'},
	    {"format", required_argument, NULL, 'f'},
	    {"size", required_argument, NULL, 'S'},
	    {"texture", required_argument, NULL, 't'},
	    {"max-memory", required_argument, NULL, 'M'},
	    {"help", no_argument, NULL, 'h'},
	    {NULL, 0, NULL, 0},
	};
	const char *output_dir = NULL, *texture_path = NULL;
	unsigned formats = CLI_FORMAT_ALL;
	plume_spec_options spec_options = {.seed = 0, .seed_given = false};
	cli_image_options images = {0, 0, NULL};
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:s:f:t:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 's':
			if (!cli_parse_seed("generate", optarg, &spec_options.seed))
				return CLI_EXIT_USAGE;
			spec_options.seed_given = true;
			break;
		case 'f':
			if (!formats_without_empty_items("generate", optarg) || !cli_parse_formats("generate", optarg, &formats))
				return CLI_EXIT_USAGE;
			break;
		case 'S':
			if (!cli_parse_size("generate", optarg, &images.width, &images.height))
				return CLI_EXIT_USAGE;
			break;
		case 't': texture_path = optarg; break;
		case 'M':
			if (!cli_parse_memory("generate", optarg, &spec_options.max_memory))
				return CLI_EXIT_USAGE;
			break;
		case 'h': cli_help_generate(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("generate", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("generate", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (!cli_check_arguments("generate", argc, argv, "SPEC.json", output_dir))
		return CLI_EXIT_USAGE;

	plume_error err = {0};
	plume_texture *texture = NULL;
	if (texture_path != NULL && plume_texture_load(texture_path, &texture, &err) != PLUME_OK)
		return cli_fail(&err);
	images.texture = texture;

	plume_feather *feather = NULL;
	cli_output output;
	plume_status status = plume_spec_generate(argv[optind], &spec_options, &feather, &err);
	if (status == PLUME_OK && (status = cli_output_begin(&output, output_dir, &err)) == PLUME_OK) {
		status = cli_write_feather(&output, feather, "feather", formats, &images, &err);
		if (status == PLUME_OK)
			status = write_summary(&output, feather, &err);
		if (status == PLUME_OK)
			status = cli_output_commit(&output, &err);
		else
			cli_output_abort(&output, &err);
	}
	plume_feather_destroy(feather);
	plume_texture_destroy(texture);
	if (status != PLUME_OK)
		return cli_fail(&err);
	return CLI_EXIT_OK;
}

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

// ---------------------------------------------------------------------------
// What the outputs add (docs/cli.md, Limits): checked once the feather is built, before anything is
// written. Cairo's SVG and PDF surfaces hold every drawing operation until the page ends (a fill for
// each curve, or with --texture for each run of one colour along a barb, and the document's text);
// the others stream, but for their pixels (PNG), a block at a time (GLB) or the texture's PNG
// encoding (GLB with --texture). Each format's memory is freed before the next is written: the
// largest counts. The constants are peak RSS measured on Franco–Walter, Streit–Heidrich and
// Zhang–Kanai feathers of 2 to 1000 points a barb, with half again as margin.

/// SVG and PDF: bytes per fill and per curve point.
#define GENERATE_VECTOR_FILL_BYTES 1536.0
#define GENERATE_SVG_POINT_BYTES 96.0
#define GENERATE_PDF_POINT_BYTES 32.0
/// What a format holds besides: a text format its stream's buffer and scratch, a picture Cairo's
/// surface, the GLB its two blocks of 256 KiB and its JSON document.
#define GENERATE_TEXT_BYTES (64.0 * 1024)
#define GENERATE_PICTURE_BYTES (256.0 * 1024)
#define GENERATE_GLB_BYTES (1024.0 * 1024)

/// Bytes writing formats adds to the feather, at most: the largest format's.
static double output_bytes(const plume_feather *feather, unsigned formats, const cli_image_options *images)
{
	double points = 0.0, barb_points = 0.0, curves = 0.0, longest = 0.0;
	for (const plume_feather *f = feather; f != NULL; f = plume_feather_afterfeather(f)) {
		plume_feather_info info = plume_feather_get_info(f);
		points += info.shaft_sample_count + info.point_count;
		curves += 1.0 + info.barb_count + info.barbule_count;
		longest = info.shaft_sample_count > longest ? info.shaft_sample_count : longest;
		for (int b = 0; b < info.barb_count; ++b) {
			int count = plume_feather_barb(f, b).curve.count;
			barb_points += count;
			longest = count > longest ? count : longest;
		}
	}
	// With a texture a barb is filled once per run of one colour: at most once per segment.
	double fills = images->texture != NULL ? curves + barb_points : curves;
	// The picture: --size, else 1200 pixels tall and at most 4096 wide (cli_write_feather).
	double pixels = images->width > 0 ? (double)images->width * images->height : 4096.0 * 1200.0;
	double texture = images->texture != NULL
	                     ? 4.0 * plume_texture_width(images->texture) * (double)plume_texture_height(images->texture)
	                     : 0.0;
	double bytes[5] = {0};
	if ((formats & (CLI_FORMAT_OBJ | CLI_FORMAT_USDA | CLI_FORMAT_JSON)) != 0)
		bytes[0] = GENERATE_TEXT_BYTES;
	if ((formats & CLI_FORMAT_PNG) != 0)
		bytes[1] = GENERATE_PICTURE_BYTES + 4.0 * pixels;
	if ((formats & CLI_FORMAT_SVG) != 0)
		bytes[2] = GENERATE_PICTURE_BYTES + GENERATE_VECTOR_FILL_BYTES * fills + GENERATE_SVG_POINT_BYTES * points;
	if ((formats & CLI_FORMAT_PDF) != 0)
		bytes[3] = GENERATE_PICTURE_BYTES + GENERATE_VECTOR_FILL_BYTES * fills + GENERATE_PDF_POINT_BYTES * points;
	if ((formats & CLI_FORMAT_GLB) != 0) // and the texture's pixels and PNG encoding; a curve's colours
		bytes[4] = GENERATE_GLB_BYTES + 3.0 * texture + 64.0 * longest;
	double most = 0.0;
	for (int k = 0; k < 5; ++k)
		most = bytes[k] > most ? bytes[k] : most;
	return most;
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
	     "      --max-memory BYTES refuse a feather, or its outputs, estimated past BYTES,\n"
	     "                         before the work (K, M, G suffixes; default 4G; docs/cli.md)\n"
	     "  -h, --help             this help\n"
	     "\n"
	     "Specs are described in docs/spec-franco-walter.md and docs/spec-zhang-kanai.md;\n"
	     "examples/ has ready ones.");
}

int cli_generate(int argc, char **argv)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'},  {"seed", required_argument, NULL, 's'},
	    {"format", required_argument, NULL, 'f'},  {"size", required_argument, NULL, 'S'},
	    {"texture", required_argument, NULL, 't'}, {"max-memory", required_argument, NULL, 'M'},
	    {"help", no_argument, NULL, 'h'},          {NULL, 0, NULL, 0},
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
			if (!cli_parse_formats("generate", optarg, &formats))
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
	if (status == PLUME_OK)
		status = cli_check_output_memory(argv[optind], "feather", formats, images.texture != NULL ? ", --texture" : "",
		                                 output_bytes(feather, formats, &images), spec_options.max_memory, &err);
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

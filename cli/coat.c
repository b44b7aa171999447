// plume coat COAT.json -o DIR [--seed S] [--format LIST] [--size WxH] [--style lines|strips] [--stage G]
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "plume/coat.h"

void cli_help_coat(void)
{
	puts("Usage: plume coat COAT.json -o DIR [options]\n"
	     "\n"
	     "Covers a surface with feathers (Streit & Heidrich 4.4): follicles laid out on a\n"
	     "plane, a sphere or an OBJ triangle mesh, key feathers at chosen follicles, every\n"
	     "other feather interpolated from them. Writes DIR/coat.obj and DIR/coat.usda\n"
	     "(one curve object per feather, bottom to top) and DIR/coat.png (the coat seen\n"
	     "from +z). All files appear together, or none when anything fails.\n"
	     "\n"
	     "Options:\n"
	     "  -o, --output DIR       output folder (created if missing)\n"
	     "  -s, --seed N           random seed; overrides the coat's \"seed\" (default 1)\n"
	     "  -f, --format LIST      comma-separated: png,svg,pdf,obj,usda,glb (default: png,obj,usda)\n"
	     "      --size WxH         image size in pixels (default 1200x1200)\n"
	     "      --style STYLE      lines (default) or strips: barbs as alpha-faded triangle\n"
	     "                         strips (Streit & Heidrich 4.3.1)\n"
	     "      --stage G          grow every feather to stage G in [0, 1] (default 1)\n"
	     "      --max-memory SIZE  refuse a coat, or its outputs, estimated to need more\n"
	     "                         (default 4G; docs/cli.md)\n"
	     "  -h, --help             this help\n"
	     "\n"
	     "Coat specs are described in docs/coats.md; examples/coats/ has ready ones.");
}

static bool parse_stage(const char *text, double *stage)
{
	char *end;
	errno = 0;
	double value = strtod(text, &end);
	if (errno != 0 || end == text || *end != '\0' || !(value >= 0.0 && value <= 1.0)) {
		cli_usage_error("coat", "--stage '%s' must be a number in [0, 1]", text);
		return false;
	}
	*stage = value;
	return true;
}

// ---------------------------------------------------------------------------
// What the outputs add (docs/cli.md, Limits): checked once the coat is built, before anything is
// written. Per picture format, Cairo's vector surfaces hold every drawing operation until the page
// ends (a fill for each curve, its path, and the document's text); the GLB holds its JSON document
// (an object per view, accessor, primitive and node) and two feathers' ribbons at a time. Each
// format's memory is freed before the next is written: the largest counts. The constants are peak RSS
// measured on coats of 64 to 2929 feathers at 4 and 12 points a barb, with half again as margin.

/// SVG and PDF (lines): bytes per fill (one per curve) and per curve point.
#define COAT_VECTOR_FILL_BYTES 1536.0
#define COAT_SVG_POINT_BYTES 96.0
#define COAT_PDF_POINT_BYTES 32.0
/// SVG and PDF with --style strips: a mesh pattern of two patches per barb segment, per barb point.
#define COAT_SVG_STRIP_POINT_BYTES 2048.0
#define COAT_PDF_STRIP_POINT_BYTES 5120.0
/// GLB: the JSON document per feather (its node, and a mesh of up to four primitives, each with five
/// accessors and views), and per curve point of the two feathers held (two ribbon vertices of 14 floats
/// and six indices).
#define COAT_GLB_FEATHER_BYTES 4096.0
#define COAT_GLB_PRIMITIVE_BYTES 14336.0
#define COAT_GLB_POINT_BYTES 136.0
/// What a format holds besides: a text format its stream's buffer and scratch, a picture Cairo's surface,
/// the GLB its two blocks of 256 KiB.
#define COAT_TEXT_BYTES (64.0 * 1024)
#define COAT_PICTURE_BYTES (256.0 * 1024)
#define COAT_GLB_BYTES (1024.0 * 1024)

/// The coat's curves: counts over every feather and afterfeather.
typedef struct coat_counts {
	double points;      ///< shaft samples, barb and barbule points
	double barb_points; ///< barb points alone
	double curves;      ///< shafts, barbs and barbules: one fill each
	double barbs;
	double primitives;  ///< non-empty glTF parts (shaft, vanes, barbules) over the feathers
	double most_points; ///< the most points of one feather, afterfeather in
	int feathers;
} coat_counts;

static coat_counts count_curves(const plume_coat *coat)
{
	coat_counts c = {0};
	c.feathers = plume_coat_feather_count(coat);
	for (int i = 0; i < c.feathers; ++i) {
		double points = 0.0;
		bool parts[4] = {false, false, false, false};
		for (const plume_feather *f = plume_coat_feather(coat, i); f != NULL; f = plume_feather_afterfeather(f)) {
			plume_feather_info info = plume_feather_get_info(f);
			points += info.shaft_sample_count + info.point_count;
			c.curves += 1.0 + info.barb_count + info.barbule_count;
			c.barbs += info.barb_count;
			for (int b = 0; b < info.barb_count; ++b) {
				plume_barb barb = plume_feather_barb(f, b);
				c.barb_points += barb.curve.count;
				parts[barb.side == PLUME_SIDE_LEFT ? 1 : 2] = true;
			}
			parts[0] = parts[0] || info.shaft_sample_count > 0;
			parts[3] = parts[3] || info.barbule_count > 0;
		}
		for (int k = 0; k < 4; ++k)
			c.primitives += parts[k] ? 1.0 : 0.0;
		c.points += points;
		c.most_points = points > c.most_points ? points : c.most_points;
	}
	return c;
}

/// Bytes writing formats adds to the coat, at most: the largest format's.
static double output_bytes(const plume_coat *coat, unsigned formats, const plume_render2d_def *image)
{
	coat_counts c = count_curves(coat);
	bool strips = image->style == PLUME_STYLE_STRIPS;
	double fills = strips ? c.curves - c.barbs : c.curves; // strips draw barbs as mesh patterns, not fills
	double bytes[5] = {0};
	if ((formats & (CLI_FORMAT_OBJ | CLI_FORMAT_USDA)) != 0)
		bytes[0] = COAT_TEXT_BYTES;
	if ((formats & CLI_FORMAT_PNG) != 0)
		bytes[1] = COAT_PICTURE_BYTES + 4.0 * image->width * image->height;
	if ((formats & CLI_FORMAT_SVG) != 0)
		bytes[2] = COAT_PICTURE_BYTES + COAT_VECTOR_FILL_BYTES * fills + COAT_SVG_POINT_BYTES * c.points +
		           (strips ? COAT_SVG_STRIP_POINT_BYTES * c.barb_points : 0.0);
	if ((formats & CLI_FORMAT_PDF) != 0)
		bytes[3] = COAT_PICTURE_BYTES + COAT_VECTOR_FILL_BYTES * fills + COAT_PDF_POINT_BYTES * c.points +
		           (strips ? COAT_PDF_STRIP_POINT_BYTES * c.barb_points : 0.0);
	if ((formats & CLI_FORMAT_GLB) != 0) { // and the surface's mesh, in doubles and floats
		const plume_mesh *surface = plume_coat_surface(coat);
		bytes[4] = COAT_GLB_BYTES + COAT_GLB_FEATHER_BYTES * c.feathers + COAT_GLB_PRIMITIVE_BYTES * c.primitives +
		           2.0 * COAT_GLB_POINT_BYTES * c.most_points + 160.0 * surface->vertex_count +
		           48.0 * surface->face_count;
	}
	double most = 0.0;
	for (int k = 0; k < 5; ++k)
		most = bytes[k] > most ? bytes[k] : most;
	return most;
}

/// The picture shows the feathers whose follicle faces +z (plume_coat_render2d): says so when none does.
static void warn_hidden(const plume_coat *coat)
{
	int count = plume_coat_feather_count(coat);
	for (int i = 0; i < count; ++i) {
		plume_vec3 root, normal;
		plume_coat_follicle(coat, i, &root, &normal);
		if (normal.z > -0.05)
			return;
	}
	fprintf(stderr,
	        "plume: coat: warning: no follicle faces +z (the surface is seen from behind), so the picture shows "
	        "none of the %d feathers\n",
	        count);
}

static plume_status write_coat(cli_output *output, const plume_coat *coat, unsigned formats,
                               const plume_render2d_def *image, plume_error *err)
{
	static const struct {
		unsigned bit;
		const char *name;
		plume_image_format format;
	} images[] = {{CLI_FORMAT_PNG, "coat.png", PLUME_IMAGE_PNG},
	              {CLI_FORMAT_SVG, "coat.svg", PLUME_IMAGE_SVG},
	              {CLI_FORMAT_PDF, "coat.pdf", PLUME_IMAGE_PDF}};
	char path[4352];
	plume_status status = PLUME_OK;
	if ((formats & CLI_FORMAT_OBJ) != 0 &&
	    (status = plume_coat_write_obj(coat, cli_output_path(output, "coat.obj", path, sizeof path), err)) != PLUME_OK)
		return status;
	if ((formats & CLI_FORMAT_USDA) != 0 &&
	    (status = plume_coat_write_usda(coat, cli_output_path(output, "coat.usda", path, sizeof path), err)) !=
	        PLUME_OK)
		return status;
	if ((formats & CLI_FORMAT_GLB) != 0) {
		plume_coat_glb_report report;
		status = plume_coat_write_glb_report(coat, NULL, cli_output_path(output, "coat.glb", path, sizeof path),
		                                     &report, err);
		if (status != PLUME_OK)
			return status;
		printf("coat.glb: %d feather instances of %d meshes, and the surface\n", report.instances, report.meshes);
	}
	for (size_t i = 0; i < sizeof images / sizeof images[0]; ++i)
		if ((formats & images[i].bit) != 0 &&
		    (status = plume_coat_render2d(coat, image, images[i].format,
		                                  cli_output_path(output, images[i].name, path, sizeof path), err)) != PLUME_OK)
			return status;
	return PLUME_OK;
}

int cli_coat(int argc, char **argv)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'},
	    {"seed", required_argument, NULL, 's'},
	    {"format", required_argument, NULL, 'f'},
	    {"size", required_argument, NULL, 'S'},
	    {"style", required_argument, NULL, 'y'},
	    {"stage", required_argument, NULL, 'g'},
	    {"help", no_argument, NULL, 'h'},
	    {"max-memory", required_argument, NULL, 'M'},
	    {NULL, 0, NULL, 0},
	};
	const char *output_dir = NULL;
	unsigned formats = CLI_FORMAT_PNG | CLI_FORMAT_OBJ | CLI_FORMAT_USDA;
	plume_spec_options spec_options = {.seed = 0, .seed_given = false};
	plume_render2d_def image = plume_render2d_default_def();
	image.width = image.height = 1200;
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:s:f:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 's':
			if (!cli_parse_seed("coat", optarg, &spec_options.seed))
				return CLI_EXIT_USAGE;
			spec_options.seed_given = true;
			break;
		case 'f':
			if (!cli_parse_formats("coat", optarg, &formats))
				return CLI_EXIT_USAGE;
			if ((formats & CLI_FORMAT_JSON) != 0)
				return cli_usage_error("coat", "--format json is for single feathers; a coat writes png, svg, pdf, "
				                               "obj, usda, glb");
			break;
		case 'S':
			if (!cli_parse_size("coat", optarg, &image.width, &image.height))
				return CLI_EXIT_USAGE;
			break;
		case 'y':
			if (!cli_parse_style("coat", optarg, &image.style))
				return CLI_EXIT_USAGE;
			break;
		case 'g':
			if (!parse_stage(optarg, &spec_options.stage))
				return CLI_EXIT_USAGE;
			spec_options.stage_kind = PLUME_STAGE_GROWTH;
			break;
		case 'M':
			if (!cli_parse_memory("coat", optarg, &spec_options.max_memory))
				return CLI_EXIT_USAGE;
			break;
		case 'h': cli_help_coat(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("coat", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("coat", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (!cli_check_arguments("coat", argc, argv, "COAT.json", output_dir))
		return CLI_EXIT_USAGE;

	plume_error err = {0};
	plume_coat *coat = NULL;
	cli_output output;
	cli_progress progress;
	cli_progress_begin(&progress, "coat", 1);
	spec_options.progress = cli_progress_callback;
	spec_options.progress_user = &progress;
	plume_status status = plume_coat_spec_generate(argv[optind], &spec_options, &coat, &err);
	cli_progress_end(&progress);
	if (status == PLUME_OK) {
		char sizing[64];
		snprintf(sizing, sizeof sizing, ", --size %dx%d%s", image.width, image.height,
		         image.style == PLUME_STYLE_STRIPS ? ", --style strips" : "");
		status = cli_check_output_memory(argv[optind], "coat", formats, sizing, output_bytes(coat, formats, &image),
		                                 spec_options.max_memory, &err);
	}
	if (status == PLUME_OK && (formats & (CLI_FORMAT_PNG | CLI_FORMAT_SVG | CLI_FORMAT_PDF)) != 0)
		warn_hidden(coat);
	if (status == PLUME_OK && (status = cli_output_begin(&output, output_dir, &err)) == PLUME_OK) {
		status = write_coat(&output, coat, formats, &image, &err);
		if (status == PLUME_OK)
			status = cli_output_commit(&output, &err);
		else
			cli_output_abort(&output, &err);
	}
	plume_coat_destroy(coat);
	if (status != PLUME_OK)
		return cli_fail(&err);
	return CLI_EXIT_OK;
}

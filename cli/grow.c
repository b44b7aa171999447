// plume grow SPEC.json -o DIR --frames N [--unfurl] [--seed S] [--format LIST] [--size WxH]
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

/// More frames than this is a typing mistake rather than an animation.
#define MAX_FRAMES 10000

void cli_help_grow(void)
{
	puts("Usage: plume grow SPEC.json -o DIR --frames N [options]\n"
	     "\n"
	     "Writes N stages of a feather's development: DIR/frame-0000.<ext> is the start\n"
	     "and DIR/frame-<N-1>.<ext> the finished feather (stage i / (N - 1); one frame is\n"
	     "the finished feather). Growth follows the model's own schedule: streit-heidrich\n"
	     "4.2.4 (shaft, then barbs, then the sheath opening from the tip), zhang-kanai's\n"
	     "growth period. All files appear together, or none when anything fails.\n"
	     "\n"
	     "Options:\n"
	     "  -o, --output DIR       output folder (created if missing)\n"
	     "  -n, --frames N         number of frames, [1, 10000]\n"
	     "  -u, --unfurl           unfurling stages instead of growth (zhang-kanai)\n"
	     "  -s, --seed N           random seed; overrides the spec's \"seed\" (default 1)\n"
	     "  -f, --format LIST      comma-separated: png,svg,pdf,obj,usda,json,glb (default:\n"
	     "                         png,obj,usda); every frame is frame-NNNN.<ext>\n"
	     "      --size WxH         image size in pixels (default: 1200 tall, width to fit);\n"
	     "                         every frame shares one framing, so the feather grows in it\n"
	     "      --style STYLE      lines (default) or strips (alpha-faded triangle strips)\n"
	     "  -h, --help             this help\n"
	     "\n"
	     "Example: plume grow examples/streit-heidrich/contour.json -o growth --frames 5");
}

static bool parse_frames(const char *text, int *frames)
{
	char *end;
	errno = 0;
	long value = strtol(text, &end, 10);
	if (errno != 0 || end == text || *end != '\0' || value < 1 || value > MAX_FRAMES) {
		cli_usage_error("grow", "--frames '%s' must be an integer in [1, %d]", text, MAX_FRAMES);
		return false;
	}
	*frames = (int)value;
	return true;
}

static double frame_stage(int i, int frames) { return frames > 1 ? (double)i / (frames - 1) : 1.0; }

/// One frame's feather. A model without the stages asked for (franco-walter has none,
/// streit-heidrich no unfurling) fails with PLUME_ERROR_UNSUPPORTED, which the command
/// once reported as a failed computation (exit 1): *wrong_stages tells cli_grow it is the
/// command line's mistake.
static plume_status generate_frame(const char *spec, const plume_spec_options *options, plume_feather **out,
                                   bool *wrong_stages, plume_error *err)
{
	plume_status status = plume_spec_generate(spec, options, out, err);
	if (status == PLUME_ERROR_UNSUPPORTED)
		*wrong_stages = true;
	return status;
}

/// The union of every frame's bounds in the feather plane, so that all frames share one framing and the
/// feather is seen to grow.
static plume_status frame_bounds(const char *spec, plume_spec_options options, int frames, plume_vec2 *lo,
                                 plume_vec2 *hi, bool *wrong_stages, plume_error *err)
{
	*lo = (plume_vec2){1e300, 1e300};
	*hi = (plume_vec2){-1e300, -1e300};
	for (int i = 0; i < frames; ++i) {
		options.stage = frame_stage(i, frames);
		plume_feather *feather = NULL;
		plume_status status = generate_frame(spec, &options, &feather, wrong_stages, err);
		if (status != PLUME_OK)
			return status;
		plume_feather_info info = plume_feather_get_info(feather);
		lo->x = info.bounds_min.x < lo->x ? info.bounds_min.x : lo->x;
		lo->y = info.bounds_min.y < lo->y ? info.bounds_min.y : lo->y;
		hi->x = info.bounds_max.x > hi->x ? info.bounds_max.x : hi->x;
		hi->y = info.bounds_max.y > hi->y ? info.bounds_max.y : hi->y;
		plume_feather_destroy(feather);
	}
	return PLUME_OK;
}

/// One frame's files, written by the background writer (cli/writer.c) while the next frame
/// grows: writing (the OBJ's and USD's printed numbers, PNG compression) costs several times
/// the generation. The job owns the feather.
typedef struct frame_job {
	plume_feather *feather;
	plume_render2d_def image; ///< the framing every frame shares
	cli_feather_file files[CLI_FEATHER_FORMATS];
	int file_count;
} frame_job;

static plume_status run_frame_job(void *data, plume_error *err)
{
	const frame_job *job = data;
	plume_status status = PLUME_OK;
	for (int i = 0; i < job->file_count && status == PLUME_OK; ++i)
		status = cli_write_feather_file(job->feather, job->files + i, &job->image, NULL, err);
	return status;
}

static void release_frame_job(void *data)
{
	frame_job *job = data;
	plume_feather_destroy(job->feather);
	free(job);
}

/// Generates every frame and hands it to the writer: images with one shared view, geometry
/// as cli_write_feather writes it. The first failure, here or in the writer, is the one
/// returned.
static plume_status write_frames(cli_output *output, const char *spec, plume_spec_options options, int frames,
                                 unsigned formats, plume_render2d_def image, bool *wrong_stages, plume_error *err)
{
	plume_status status = PLUME_OK;
	if ((formats & (CLI_FORMAT_PNG | CLI_FORMAT_SVG | CLI_FORMAT_PDF)) != 0) {
		if ((status = frame_bounds(spec, options, frames, &image.view_min, &image.view_max, wrong_stages, err)) !=
		    PLUME_OK)
			return status;
		if (image.width == 0) { // 1200 tall, as wide as the framing needs
			double w = image.view_max.x - image.view_min.x, h = image.view_max.y - image.view_min.y;
			image.height = 1200;
			image.width = cli_image_width(w, h, image.height, image.margin);
		}
	}
	cli_writer *writer = NULL;
	if ((status = cli_writer_start(&writer, err)) != PLUME_OK)
		return status;
	for (int i = 0; i < frames && status == PLUME_OK && cli_writer_status(writer, NULL) == PLUME_OK; ++i) {
		options.stage = frame_stage(i, frames);
		frame_job *job = malloc(sizeof *job);
		if (job == NULL) {
			status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
			break;
		}
		*job = (frame_job){.image = image};
		if ((status = generate_frame(spec, &options, &job->feather, wrong_stages, err)) != PLUME_OK) {
			free(job);
			break;
		}
		char stem[32];
		snprintf(stem, sizeof stem, "frame-%04d", i);
		job->file_count = cli_feather_file_paths(output, stem, formats, job->files);
		cli_writer_submit(writer, run_frame_job, release_frame_job, job);
	}
	plume_error write_error;
	plume_status write_status = cli_writer_finish(writer, &write_error);
	if (status == PLUME_OK && write_status != PLUME_OK) {
		*err = write_error;
		status = write_status;
	}
	return status;
}

int cli_grow(int argc, char **argv)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'},
	    {"frames", required_argument, NULL, 'n'},
	    {"unfurl", no_argument, NULL, 'u'},
	    {"seed", required_argument, NULL, 's'},
	    {"format", required_argument, NULL, 'f'},
	    {"size", required_argument, NULL, 'S'},
	    {"style", required_argument, NULL, 'y'},
	    {"help", no_argument, NULL, 'h'},
	    {NULL, 0, NULL, 0},
	};
	const char *output_dir = NULL;
	int frames = 0;
	unsigned formats = CLI_FORMAT_PNG | CLI_FORMAT_OBJ | CLI_FORMAT_USDA;
	plume_spec_options spec_options = {.seed = 0, .seed_given = false, .stage_kind = PLUME_STAGE_GROWTH};
	plume_render2d_def image = plume_render2d_default_def();
	image.width = image.height = 0;
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:n:us:f:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 'n':
			if (!parse_frames(optarg, &frames))
				return CLI_EXIT_USAGE;
			break;
		case 'u': spec_options.stage_kind = PLUME_STAGE_UNFURL; break;
		case 's':
			if (!cli_parse_seed("grow", optarg, &spec_options.seed))
				return CLI_EXIT_USAGE;
			spec_options.seed_given = true;
			break;
		case 'f':
			if (!cli_parse_formats("grow", optarg, &formats))
				return CLI_EXIT_USAGE;
			break;
		case 'S':
			if (!cli_parse_size("grow", optarg, &image.width, &image.height))
				return CLI_EXIT_USAGE;
			break;
		case 'y':
			if (!cli_parse_style("grow", optarg, &image.style))
				return CLI_EXIT_USAGE;
			break;
		case 'h': cli_help_grow(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("grow", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("grow", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (!cli_check_arguments("grow", argc, argv, "SPEC.json", output_dir))
		return CLI_EXIT_USAGE;
	if (frames == 0)
		return cli_usage_error("grow", "missing --frames N");
	cli_output output;
	plume_error err = {0};
	bool wrong_stages = false;
	plume_status status = cli_output_begin(&output, output_dir, &err);
	if (status == PLUME_OK) {
		status = write_frames(&output, argv[optind], spec_options, frames, formats, image, &wrong_stages, &err);
		if (status == PLUME_OK)
			status = cli_output_commit(&output, &err);
		else
			cli_output_abort(&output, &err);
	}
	if (status != PLUME_OK && wrong_stages)
		return cli_usage_error("grow", "%s", err.message);
	if (status != PLUME_OK)
		return cli_fail(&err);
	return CLI_EXIT_OK;
}

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
	     "(OBJ curves, USD curves, JSON, glTF ribbons). Then it meshes the feather into a\n"
	     "barb-aligned shell, simulates the paper's Figure 1 scenario for half a second\n"
	     "(rachis base held, vane tip pulled down in the vane's plane, inextensible\n"
	     "barbs) and ray-traces three frames at barb level: figure1-NNNN.png.\n"
	     "\n"
	     "Options:\n"
	     "  -o, --output DIR   output folder (default: plume-demo)\n"
	     "  -h, --help         this help");
}

/// Jouve et al. 2024, Figure 1, on the built-in feather: a short version of
/// examples/scenes/figure1-anisotropic.json.
static const char demo_scene[] =
    "{\"feather\": {\"model\": \"franco-walter\", \"seed\": 1},"
    " \"mesh\": {\"edge_length\": 0.005, \"rachis_width_base\": 0.008, \"rachis_width_tip\": 0.004},"
    " \"handles\": [{\"group\": \"rachis_clamp\"},"
    "  {\"group\": \"vane_tip\", \"interpolation\": \"smooth\","
    "   \"keyframes\": [{\"time\": 0, \"translation\": [0, 0, 0]}, {\"time\": 0.55, \"translation\": [-0.02, 0, 0]}]}],"
    " \"gravity\": [-9.661, 0, -1.703], \"duration\": 0.55}";

enum { DEMO_FRAMES = 3 };

typedef struct demo_run {
	cli_output *output;
	plume_raytrace_def render_def;
	cli_carried carried;
	int steps;
} demo_run;

static plume_status demo_step(void *user, int step, double time, const plume_sim *sim, const plume_solve_report *report,
                              double wall_seconds, plume_error *err)
{
	(void)time, (void)report, (void)wall_seconds;
	demo_run *run = user;
	if (step % (run->steps / (DEMO_FRAMES - 1)) != 0)
		return PLUME_OK;
	char name[64], path[4352];
	snprintf(name, sizeof name, "figure1-%04d.png", step);
	plume_raytrace_scene picture;
	plume_status status = cli_carried_pose(&run->carried, plume_sim_positions(sim), NULL, &picture, err);
	if (status == PLUME_OK)
		status = plume_raytrace_render_png(&picture, &run->render_def,
		                                   cli_output_path(run->output, name, path, sizeof path), NULL, err);
	return status;
}

/// Meshes, simulates and ray-traces the demo scene into the staging folder.
static plume_status simulate_demo(cli_output *output, plume_scene_summary *summary, plume_error *err)
{
	plume_scene *scene = NULL;
	plume_status status = plume_scene_parse(demo_scene, "demo scene", NULL, &scene, err);
	if (status != PLUME_OK)
		return status;
	plume_vec3 lo, hi;
	cli_scene_bounds(scene, &lo, &hi);
	demo_run run = {
	    output, cli_sequence_render_def(lo, hi, 400, 640, 4), {0}, (int)(scene->duration / scene->sim.time_step + 0.5)};
	status = cli_carry_scene(scene, &run.carried, err);
	if (status == PLUME_OK)
		status = plume_scene_run(scene, demo_step, &run, summary, err);
	cli_carried_end(&run.carried);
	plume_scene_destroy(scene);
	return status;
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
	plume_scene_summary summary = {0};
	plume_status status = texture == NULL ? plume_error_set(&err, PLUME_ERROR_MEMORY, "out of memory")
	                                      : plume_fw_generate(&def, 1, &feather, &err);
	if (status == PLUME_OK && (status = cli_output_begin(&output, output_dir, &err)) == PLUME_OK) {
		status = cli_write_feather(&output, feather, "feather", CLI_FORMAT_ALL | CLI_FORMAT_GLB, &lines, &err);
		if (status == PLUME_OK)
			status = cli_write_feather(&output, feather, "feather-textured", CLI_FORMAT_PNG, &textured, &err);
		if (status == PLUME_OK)
			status = simulate_demo(&output, &summary, &err);
		if (status == PLUME_OK)
			status = cli_output_commit(&output, &err);
		else
			cli_output_abort(&output, &err);
	}
	if (status == PLUME_OK) {
		plume_feather_info info = plume_feather_get_info(feather);
		printf("plume demo: a %.3f m hawk feather, %d barbs of %d points (Franco & Walter, seed 1)\n",
		       info.shaft_length, info.barb_count, def.barb_samples);
		printf("plume demo: Figure 1 on a %d-vertex barb-aligned shell: %d steps, %.1f Newton iterations a step, "
		       "largest barb strain %.2g, rachis tip deflection %.1f mm\n",
		       summary.vertex_count, summary.steps,
		       (double)summary.newton_iterations / (summary.steps > 0 ? summary.steps : 1), summary.max_barb_strain,
		       1e3 * summary.rachis_tip_deflection);
		for (int i = 0; i < output.name_count; ++i)
			printf("  %s/%s\n", output.dir, output.names[i]);
	}
	plume_feather_destroy(feather);
	plume_texture_destroy(texture);
	return status == PLUME_OK ? CLI_EXIT_OK : cli_fail(&err);
}

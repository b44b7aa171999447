// plume mesh SPEC.json -o DIR [--edge-length E] [--seed S]
//
// Meshes a feather spec (any model) or a guides spec (docs/meshing.md) with the
// barb-aligned mesher and writes DIR/mesh.obj, DIR/mesh.png (the reference
// mesh: rachis and vane faces in two colours, barb-aligned edges in dark blue)
// and DIR/report.json (counts and quality).
#define _POSIX_C_SOURCE 200809L
#include <cairo.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "plume/lab.h"

// Also declared in cli.h beside the other commands.
int cli_mesh(int argc, char **argv);
void cli_help_mesh(void);

void cli_help_mesh(void)
{
	puts("Usage: plume mesh SPEC.json -o DIR [options]\n"
	     "\n"
	     "Builds the barb-aligned triangle mesh that the simulator deforms (Jouve 2024,\n"
	     "thesis 6.2) from a feather spec (its rachis and barbs are the guides) or from\n"
	     "a guides spec (boundary polygon, rachis spline, barb guide splines), and writes\n"
	     "  DIR/mesh.obj    the rest shape with UVs, one group per material\n"
	     "  DIR/mesh.png    the reference mesh: rachis and vane faces, barb-aligned edges\n"
	     "  DIR/report.json vertex and face counts, minimum angle, aligned fraction,\n"
	     "                  guides dropped\n"
	     "  DIR/mesh.glb    the rest shell as glTF 2.0, with --format glb\n"
	     "All files appear together, or none when anything fails.\n"
	     "\n"
	     "Options:\n"
	     "  -o, --output DIR        output folder (created if missing)\n"
	     "  -e, --edge-length E     target edge length in metres (default: the spec's\n"
	     "                          \"mesh\".\"edge_length\", else 0.005, thesis Table 6.1)\n"
	     "  -s, --seed N            random seed of a feather spec; overrides its \"seed\"\n"
	     "      --size WxH          image size in pixels (default: 1200 tall)\n"
	     "  -f, --format LIST       comma-separated: obj,png,glb (default: obj,png)\n"
	     "      --max-memory BYTES  refuse a mesh, or its outputs, estimated past BYTES (K, M,\n"
	     "                          G suffixes; default 4G): about 320 bytes a vertex, 4 a\n"
	     "                          pixel of mesh.png (docs/cli.md)\n"
	     "  -h, --help              this help\n"
	     "\n"
	     "The guides spec is described in docs/meshing.md.");
}

static bool parse_length(const char *text, double *out)
{
	char *end;
	errno = 0;
	double value = strtod(text, &end);
	if (end == text || *end != '\0' || errno != 0 || !(value > 0.0) || !isfinite(value))
		return false;
	*out = value;
	return true;
}

/// Parses --format: a comma-separated list of obj, png and glb (the formats a mesh is
/// written in; cli_parse_formats knows a feather's too). False after the usage message.
static bool parse_mesh_formats(const char *list, unsigned *formats)
{
	static const struct {
		const char *name;
		unsigned bit;
	} names[] = {{"obj", CLI_FORMAT_OBJ}, {"png", CLI_FORMAT_PNG}, {"glb", CLI_FORMAT_GLB}};
	*formats = 0;
	// An empty item ("obj,", ",obj", "obj,,png") is a typo, refused as cli_parse_formats does.
	size_t size = strlen(list);
	if (size > 0 && (list[0] == ',' || list[size - 1] == ',' || strstr(list, ",,") != NULL)) {
		cli_usage_error("mesh", "--format '%s' has an empty item; a mesh writes obj, png, glb", list);
		return false;
	}
	for (const char *cursor = list; *cursor != '\0';) {
		size_t length = strcspn(cursor, ",");
		size_t i = 0;
		while (i < sizeof names / sizeof names[0] &&
		       !(strlen(names[i].name) == length && strncmp(cursor, names[i].name, length) == 0))
			++i;
		if (i == sizeof names / sizeof names[0]) {
			cli_usage_error("mesh", "unknown format '%.*s' in --format: a mesh writes obj, png, glb", (int)length,
			                cursor);
			return false;
		}
		*formats |= names[i].bit;
		cursor += length;
		if (*cursor == ',')
			++cursor;
	}
	if (*formats == 0) {
		cli_usage_error("mesh", "--format needs at least one of obj, png, glb");
		return false;
	}
	return true;
}

// ---------------------------------------------------------------------------
// Picture of the reference mesh

typedef struct view {
	double scale, x0, y1, margin;
} view;

static void to_pixels(const view *v, plume_vec2 p, double *x, double *y)
{
	*x = v->margin + (p.x - v->x0) * v->scale;
	*y = v->margin + (v->y1 - p.y) * v->scale;
}

/// The reference mesh's bounds in the feather plane.
static void mesh_bounds(const plume_mesh *mesh, double *x0, double *y0, double *x1, double *y1)
{
	*x0 = *y0 = INFINITY;
	*x1 = *y1 = -INFINITY;
	for (int i = 0; i < mesh->vertex_count; ++i) {
		*x0 = fmin(*x0, mesh->reference[i].x);
		*x1 = fmax(*x1, mesh->reference[i].x);
		*y0 = fmin(*y0, mesh->reference[i].y);
		*y1 = fmax(*y1, mesh->reference[i].y);
	}
}

/// mesh.png's size: --size's (width, height > 0), else 1200 tall and as wide as the mesh needs.
static void picture_size(const plume_mesh *mesh, int *width, int *height)
{
	double x0, y0, x1, y1;
	mesh_bounds(mesh, &x0, &y0, &x1, &y1);
	double span_x = fmax(x1 - x0, 1e-9), span_y = fmax(y1 - y0, 1e-9);
	double margin = 20.0;
	if (*height <= 0)
		*height = 1200;
	if (*width <= 0) {
		// As wide as the mesh needs, up to what --size allows; clamped as a double: a flat mesh's
		// span_x / span_y (a 0.1 m row of guides 1e-8 m apart) is past an int.
		double wide = ceil(2.0 * margin + (*height - 2.0 * margin) * span_x / span_y);
		*width = !(wide <= 16384.0) ? 16384 : (int)wide;
	}
	if (*width < 16)
		*width = 16;
}

/// Bytes writing the formats adds to the mesh, at most: the largest format's (each frees its
/// memory before the next). png: Cairo's surface, 4 B a pixel, and 256 KiB; glb: the attributes
/// as doubles (64 B a vertex), the indices (12 B a face) and 1 MiB; obj and the report: 64 KiB.
static double output_bytes(const plume_mesh *mesh, unsigned formats, int width, int height)
{
	double most = 64.0 * 1024;
	if ((formats & CLI_FORMAT_PNG) != 0) {
		picture_size(mesh, &width, &height);
		most = fmax(most, 256.0 * 1024 + 4.0 * width * (double)height);
	}
	if ((formats & CLI_FORMAT_GLB) != 0)
		most = fmax(most, 1024.0 * 1024 + 64.0 * mesh->vertex_count + 12.0 * mesh->face_count);
	return most;
}

static plume_status draw_mesh(const plume_mesh *mesh, int width, int height, const char *path, plume_error *err)
{
	double x0, y0, x1, y1;
	mesh_bounds(mesh, &x0, &y0, &x1, &y1);
	double span_x = fmax(x1 - x0, 1e-9), span_y = fmax(y1 - y0, 1e-9);
	picture_size(mesh, &width, &height);
	// 20 pixels, at most a quarter of the picture: a --size under 40 made the scale negative,
	// the mesh drawn turned half a turn (and the wrong side's scale picked).
	double margin = fmin(20.0, 0.25 * fmin(width, height));
	view v = {fmin((width - 2.0 * margin) / span_x, (height - 2.0 * margin) / span_y), x0, y1, margin};
	cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
	cairo_t *cr = cairo_create(surface);
	cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
	cairo_paint(cr);
	cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
	for (int f = 0; f < mesh->face_count; ++f) {
		for (int k = 0; k < 3; ++k) {
			double x, y;
			to_pixels(&v, mesh->reference[mesh->faces[3 * f + k]], &x, &y);
			if (k == 0)
				cairo_move_to(cr, x, y);
			else
				cairo_line_to(cr, x, y);
		}
		cairo_close_path(cr);
		if (mesh->material[f] == PLUME_MATERIAL_RACHIS)
			cairo_set_source_rgb(cr, 0.96, 0.62, 0.25); // orange, as in the paper's Figure 7
		else
			cairo_set_source_rgb(cr, 0.72, 0.86, 0.96); // light blue
		cairo_fill_preserve(cr);
		cairo_set_source_rgb(cr, 0.45, 0.45, 0.5);
		cairo_set_line_width(cr, 0.6);
		cairo_stroke(cr);
	}
	cairo_set_source_rgb(cr, 0.05, 0.2, 0.6);
	cairo_set_line_width(cr, 1.8);
	cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
	for (int e = 0; e < mesh->barb_edge_count; ++e) {
		double x, y;
		to_pixels(&v, mesh->reference[mesh->barb_edges[2 * e]], &x, &y);
		cairo_move_to(cr, x, y);
		to_pixels(&v, mesh->reference[mesh->barb_edges[2 * e + 1]], &x, &y);
		cairo_line_to(cr, x, y);
	}
	cairo_stroke(cr);
	cairo_destroy(cr);
	cairo_surface_flush(surface);
	cairo_status_t written = cairo_surface_write_to_png(surface, path);
	cairo_surface_destroy(surface);
	if (written != CAIRO_STATUS_SUCCESS)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write PNG: %s", path, cairo_status_to_string(written));
	return PLUME_OK;
}

static plume_status write_report(const plume_mesh *mesh, const plume_mesh_report *report, const char *path,
                                 plume_error *err)
{
	FILE *stream = fopen(path, "w");
	if (stream == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
	int rachis_faces = 0;
	for (int f = 0; f < mesh->face_count; ++f)
		rachis_faces += mesh->material[f] == PLUME_MATERIAL_RACHIS;
	// null when every vane face is a junction face (or there is none): no angle to report,
	// where plume_mesh_report holds pi.
	int measured_faces = mesh->face_count - rachis_faces - report->excepted_count;
	char vane_min_angle[32] = "null";
	if (measured_faces > 0)
		snprintf(vane_min_angle, sizeof vane_min_angle, "%.6f",
		         report->vane_min_angle * 180.0 / 3.14159265358979323846);
	char edge_length[PLUME_LAB_NUMBER_TEXT]; // 0.004, not %.17g's 0.0040000000000000001
	plume_lab_format_number(edge_length, sizeof edge_length, report->edge_length);
	fprintf(stream,
	        "{\n"
	        "  \"edge_length\": %s,\n"
	        "  \"vertex_count\": %d,\n"
	        "  \"face_count\": %d,\n"
	        "  \"rachis_face_count\": %d,\n"
	        "  \"vane_face_count\": %d,\n"
	        "  \"barb_edge_count\": %d,\n"
	        "  \"min_angle_deg\": %.6f,\n"
	        "  \"vane_min_angle_deg\": %s,\n"
	        "  \"excepted_count\": %d,\n"
	        "  \"aligned_fraction\": %.17g,\n"
	        "  \"guides_dropped\": %d,\n"
	        "  \"barbs_averaged\": %d,\n"
	        "  \"vertices_trimmed\": %d,\n"
	        "  \"guide_count\": [%d, %d],\n"
	        "  \"groups\": {",
	        edge_length, mesh->vertex_count, mesh->face_count, rachis_faces, mesh->face_count - rachis_faces,
	        mesh->barb_edge_count, report->min_angle * 180.0 / 3.14159265358979323846, vane_min_angle,
	        report->excepted_count, report->aligned_fraction, report->guides_dropped, report->barbs_averaged,
	        report->vertices_trimmed, report->guide_count[0], report->guide_count[1]);
	for (int g = 0; g < mesh->group_count; ++g)
		fprintf(stream, "%s\"%s\": %d", g > 0 ? ", " : "", mesh->groups[g].name, mesh->groups[g].count);
	fprintf(stream, "}\n}\n");
	bool failed = ferror(stream) != 0;
	if (fclose(stream) != 0 || failed)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: write failed", path);
	return PLUME_OK;
}

int cli_mesh(int argc, char **argv)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'},
	    {"edge-length", required_argument, NULL, 'e'},
	    {"seed", required_argument, NULL, 's'},
	    {"size", required_argument, NULL, 'S'},
	    {"help", no_argument, NULL, 'h'},
	    {"format", required_argument, NULL, 'f'},
	    {"max-memory", required_argument, NULL, 'M'},
	    {NULL, 0, NULL, 0},
	};
	const char *output_dir = NULL;
	plume_mesh_spec_options spec_options = plume_mesh_spec_default_options();
	int width = 0, height = 0;
	unsigned formats = CLI_FORMAT_OBJ | CLI_FORMAT_PNG;
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:e:s:f:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 'e':
			if (!parse_length(optarg, &spec_options.edge_length))
				return cli_usage_error("mesh", "--edge-length '%s' is not a positive length in metres", optarg);
			break;
		case 's':
			if (!cli_parse_seed("mesh", optarg, &spec_options.seed))
				return CLI_EXIT_USAGE;
			spec_options.seed_given = true;
			break;
		case 'S':
			if (!cli_parse_size("mesh", optarg, &width, &height))
				return CLI_EXIT_USAGE;
			break;
		case 'f':
			if (!parse_mesh_formats(optarg, &formats))
				return CLI_EXIT_USAGE;
			break;
		case 'M':
			if (!cli_parse_memory("mesh", optarg, &spec_options.max_memory))
				return CLI_EXIT_USAGE;
			break;
		case 'h': cli_help_mesh(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("mesh", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("mesh", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (!cli_check_arguments("mesh", argc, argv, "SPEC.json", output_dir))
		return CLI_EXIT_USAGE;

	plume_error err = {0};
	plume_mesh *mesh = NULL;
	plume_mesh_report report;
	plume_status status = plume_mesh_spec_read(argv[optind], &spec_options, &mesh, &report, &err);
	if (status == PLUME_OK) {
		// The outputs are held to --max-memory as well, before any is written (a --size of
		// 16384x16384 is a 1 GiB picture), with the mesh the library holds.
		status =
		    cli_check_output_memory(argv[optind], "mesh", formats, (formats & CLI_FORMAT_PNG) != 0 ? ", --size" : "",
		                            output_bytes(mesh, formats, width, height), spec_options.max_memory, &err);
	}
	cli_output output;
	if (status == PLUME_OK && (status = cli_output_begin(&output, output_dir, &err)) == PLUME_OK) {
		char path[4400];
		status = PLUME_OK;
		if ((formats & CLI_FORMAT_OBJ) != 0)
			status = plume_mesh_write_obj(mesh, NULL, cli_output_path(&output, "mesh.obj", path, sizeof path), &err);
		if (status == PLUME_OK && (formats & CLI_FORMAT_GLB) != 0)
			status =
			    plume_mesh_write_glb(mesh, NULL, NULL, cli_output_path(&output, "mesh.glb", path, sizeof path), &err);
		if (status == PLUME_OK && (formats & CLI_FORMAT_PNG) != 0)
			status = draw_mesh(mesh, width, height, cli_output_path(&output, "mesh.png", path, sizeof path), &err);
		if (status == PLUME_OK)
			status = write_report(mesh, &report, cli_output_path(&output, "report.json", path, sizeof path), &err);
		if (status == PLUME_OK)
			status = cli_output_commit(&output, &err);
		else
			cli_output_abort(&output, &err);
	}
	plume_mesh_destroy(mesh);
	if (status != PLUME_OK)
		return cli_fail(&err);
	return CLI_EXIT_OK;
}

// plume render INPUT -o DIR [--camera FILE] [--spp N] [--size WxH] [--seed N] [--texture IMAGE]
//                          [--turntable N] [--threads N] [--shell] [--format LIST]
//
// INPUT is a feather or coat spec (ray-traced to DIR/feather.png, or a turntable in DIR/turntable/) or a simulation
// output folder (docs/rendering.md): the generated feather's barbs (every feather's, each in its own
// piece of the joined shell, for a many-feather run) are embedded in the rest shell and carried to
// every frame, with the body of the frame, written as DIR/frames/NNNN.png, .obj and .usda.
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "cli.h"
#include "plume/coat.h"
#include "plume/embed.h"
#include "plume/raytrace.h"

void cli_help_render(void)
{
	puts("Usage: plume render INPUT -o DIR [options]\n"
	     "\n"
	     "Ray-traces INPUT with Embree: barbs as ribbons facing the vane normal, the shaft as a\n"
	     "tube, fiber shading, shadows, ambient occlusion, jittered supersampling.\n"
	     "  INPUT a feather spec (.json): writes DIR/feather.png (or DIR/turntable/NNNN.png).\n"
	     "  INPUT a coat spec (\"model\": \"coat\"): every feather of the coat over its surface,\n"
	     "        written the same way.\n"
	     "  INPUT a simulation folder (from plume simulate): embeds the barbs of feather.json in\n"
	     "        mesh.obj, carries them to every frames/NNNN.obj and writes DIR/frames/NNNN.png,\n"
	     "        NNNN.obj and NNNN.usda (barb-level curves). A run of many feathers\n"
	     "        (feathers.json): every feather in its own piece of the shell, the curves in\n"
	     "        NNNN-NAME.obj and .usda, and the body (frames/body-NNNN.obj) as a surface.\n"
	     "        The frames are taken by number (0000 ... 9999, 10000, ...), all of them\n"
	     "        (a missing one is an error); DIR may not be the simulation folder itself.\n"
	     "All files appear together, or none when anything fails; a render into a folder\n"
	     "it wrote before replaces that run (the files you added are kept).\n"
	     "\n"
	     "Options:\n"
	     "  -o, --output DIR       output folder (created if missing)\n"
	     "  -c, --camera FILE      camera, lights and render settings (docs/rendering.md);\n"
	     "                         default: automatic framing of the feather from the front\n"
	     "      --spp N            samples per pixel, [1, 4096] (default 16)\n"
	     "      --max-memory BYTES refuse images estimated past BYTES (K, M, G suffixes; default\n"
	     "                         4G): 8 B a pixel while rendering, 4 B a pixel per image\n"
	     "                         written and per image held (--strip) (docs/cli.md)\n"
	     "      --size WxH         image size in pixels (default 800x800)\n"
	     "  -s, --seed N           seed of the sampling (spec renders also use it for the feather)\n"
	     "  -t, --texture IMAGE    colour the barbs from IMAGE (Franco & Walter 4.4)\n"
	     "      --turntable N      N images turning the camera once around the feather\n"
	     "      --threads N        OpenMP threads (default: all); the image does not depend on it\n"
	     "      --shell            also draw the simulated shell (simulation folders)\n"
	     "      --strip N          simulation folders: also DIR/strip.png, N frames evenly spaced\n"
	     "                         from the first to the last, side by side\n"
	     "  -f, --format LIST      simulation folders only: png,obj,usda (default: all three)\n"
	     "      --frames A:B[:S]   simulation folders: only frames A, A+S, ... up to B (frame\n"
	     "                         numbers NNNN); the camera still frames the whole sequence,\n"
	     "                         so ranges rendered apart (plume sweep) match, and the\n"
	     "                         frames join DIR/frames/ when it exists\n"
	     "  -h, --help             this help");
}

typedef struct render_options {
	const char *input, *output_dir, *camera_path, *texture_path;
	int spp, width, height, turntable, threads, strip;
	bool seed_given, shell;
	uint64_t seed;
	unsigned formats;
	bool formats_given; ///< -f/--format (simulation folders only)
	bool frames_given;  ///< --frames: render frame numbers first, first + step, ... <= last
	int frame_first, frame_last, frame_step;
	uint64_t max_memory; ///< --max-memory (0: PLUME_DEFAULT_MAX_MEMORY)
} render_options;

static bool parse_count(const char *text, int lo, int hi, int *out)
{
	char *end;
	errno = 0;
	long value = strtol(text, &end, 10);
	if (errno != 0 || end == text || *end != '\0' || value < lo || value > hi)
		return false;
	*out = (int)value;
	return true;
}

static int parse_options(int argc, char **argv, render_options *o)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'},
	    {"camera", required_argument, NULL, 'c'},
	    {"spp", required_argument, NULL, 'p'},
	    {"size", required_argument, NULL, 'S'},
	    {"seed", required_argument, NULL, 's'},
	    {"texture", required_argument, NULL, 't'},
	    {"turntable", required_argument, NULL, 'T'},
	    {"threads", required_argument, NULL, 'j'},
	    {"strip", required_argument, NULL, 'P'},
	    {"shell", no_argument, NULL, 'm'},
	    {"format", required_argument, NULL, 'f'},
	    {"frames", required_argument, NULL, 'F'},
	    {"max-memory", required_argument, NULL, 'M'},
	    {"help", no_argument, NULL, 'h'},
	    {NULL, 0, NULL, 0},
	};
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:c:s:t:f:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': o->output_dir = optarg; break;
		case 'c': o->camera_path = optarg; break;
		case 'p':
			if (!parse_count(optarg, 1, 4096, &o->spp))
				return cli_usage_error("render", "--spp '%s' must be an integer in [1, 4096]", optarg);
			break;
		case 'S':
			if (!cli_parse_size("render", optarg, &o->width, &o->height))
				return CLI_EXIT_USAGE;
			break;
		case 's':
			if (!cli_parse_seed("render", optarg, &o->seed))
				return CLI_EXIT_USAGE;
			o->seed_given = true;
			break;
		case 't': o->texture_path = optarg; break;
		case 'T':
			if (!parse_count(optarg, 1, 3600, &o->turntable))
				return cli_usage_error("render", "--turntable '%s' must be an integer in [1, 3600]", optarg);
			break;
		case 'j':
			if (!parse_count(optarg, 1, 1024, &o->threads))
				return cli_usage_error("render", "--threads '%s' must be an integer in [1, 1024]", optarg);
			break;
		case 'm': o->shell = true; break;
		case 'P':
			if (!parse_count(optarg, 1, 64, &o->strip))
				return cli_usage_error("render", "--strip '%s' must be an integer in [1, 64]", optarg);
			break;
		case 'f': {
			o->formats = 0;
			o->formats_given = true;
			char list[256];
			snprintf(list, sizeof list, "%s", optarg);
			for (char *name = strtok(list, ","); name != NULL; name = strtok(NULL, ",")) {
				if (strcmp(name, "png") == 0)
					o->formats |= CLI_FORMAT_PNG;
				else if (strcmp(name, "obj") == 0)
					o->formats |= CLI_FORMAT_OBJ;
				else if (strcmp(name, "usda") == 0)
					o->formats |= CLI_FORMAT_USDA;
				else
					return cli_usage_error("render", "unknown format '%s' in --format; allowed: png, obj, usda", name);
			}
			if (o->formats == 0)
				return cli_usage_error("render", "--format needs at least one of png, obj, usda");
			break;
		}
		case 'F': {
			char text[64], *second = NULL, *third = NULL;
			snprintf(text, sizeof text, "%s", optarg);
			second = strchr(text, ':');
			if (second != NULL) {
				*second++ = '\0';
				third = strchr(second, ':');
				if (third != NULL)
					*third++ = '\0';
			}
			o->frame_step = 1;
			if (second == NULL || !parse_count(text, 0, 99999999, &o->frame_first) ||
			    !parse_count(second, 0, 99999999, &o->frame_last) ||
			    (third != NULL && !parse_count(third, 1, 99999999, &o->frame_step)) || o->frame_last < o->frame_first)
				return cli_usage_error("render", "--frames '%s': expected A:B or A:B:S with 0 <= A <= B and S >= 1",
				                       optarg);
			o->frames_given = true;
			break;
		}
		case 'M':
			if (!cli_parse_memory("render", optarg, &o->max_memory))
				return CLI_EXIT_USAGE;
			break;
		case 'h': cli_help_render(); return -1;
		case ':': return cli_usage_error("render", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("render", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (!cli_check_arguments("render", argc, argv, "INPUT (a feather spec or a simulation folder)", o->output_dir))
		return CLI_EXIT_USAGE;
	o->input = argv[optind];
	return CLI_EXIT_OK;
}

/// Refuses (PLUME_ERROR_LIMIT) images whose estimate (plume_raytrace_estimate_bytes) passes --max-memory.
static plume_status check_images(const render_options *o, const plume_raytrace_def *def, int images, int held,
                                 const char *count_keys, plume_error *err)
{
	double bytes = plume_raytrace_estimate_bytes(def, images, held);
	double limit = (double)(o->max_memory > 0 ? o->max_memory : PLUME_DEFAULT_MAX_MEMORY);
	if (bytes <= limit)
		return PLUME_OK;
	return plume_error_set(err, PLUME_ERROR_LIMIT,
	                       "%s: %d image(s) of %dx%d pixels (--size or the camera's $.camera.size; %s), %d held at "
	                       "once, take about %.3g GB; the limit is %.3g GB (raise it with --max-memory, or render "
	                       "fewer or smaller images)",
	                       o->input, images, def->camera.width, def->camera.height, count_keys, held, bytes / 1e9,
	                       limit / 1e9);
}

/// The render settings: defaults, then the camera file, then the command line.
static plume_status make_def(const render_options *o, const plume_texture *texture, plume_raytrace_def *def,
                             plume_error *err)
{
	*def = plume_raytrace_default_def();
	if (o->camera_path != NULL) {
		plume_status status = plume_raytrace_def_read(o->camera_path, def, err);
		if (status != PLUME_OK)
			return status;
	}
	if (o->spp > 0)
		def->spp = o->spp;
	if (o->width > 0) {
		def->camera.width = o->width;
		def->camera.height = o->height;
	}
	if (o->seed_given)
		def->seed = o->seed;
	def->threads = o->threads;
	def->texture = texture;
	return PLUME_OK;
}

/// Ray-traces one image into image and writes it to path as PNG. A camera that the
/// scene shows to be wrong (its eye inside the scene, or seeing none of it) is named
/// by its file and key; other errors name the image.
static plume_status render_image(const render_options *o, const plume_raytrace_scene *scene,
                                 const plume_raytrace_def *def, uint8_t *image, const char *path, plume_error *err)
{
	plume_status status = plume_raytrace_render(scene, def, image, NULL, err);
	if (status == PLUME_OK)
		return plume_write_rgba_png(def->camera.width, def->camera.height, image, path, err);
	static const char view[] = "raytrace: the camera at";
	const char *at = strstr(err->message, view);
	if (status == PLUME_ERROR_SPEC && at != NULL) {
		char message[sizeof err->message];
		snprintf(message, sizeof message, "%s", at + strlen("raytrace: "));
		if (o->camera_path != NULL)
			plume_error_set(err, status, "%s: $.camera.%s: %s", o->camera_path,
			                strstr(message, "is inside") != NULL ? "eye" : "target", message);
		else
			plume_error_set(err, status, "%s: %s", o->input, message);
	} else {
		plume_error_prefix(err, path);
	}
	return status;
}

/// A subfolder of the staging folder, registered as one output name. An earlier run's
/// folder of that name in DIR is replaced at the commit, the user's files in it kept
/// (cli/output.c).
static plume_status stage_folder(cli_output *output, const char *name, char *path, size_t size, plume_error *err)
{
	cli_output_path(output, name, path, size);
	if (mkdir(path, 0777) != 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot create: %s", path, strerror(errno));
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// A feather spec

/// True when the spec file says "model": "coat" (anything unreadable is left to the feather reader's errors).
static bool is_coat_spec(const char *path)
{
	json_t *root = json_load_file(path, 0, NULL);
	const char *model = json_string_value(json_object_get(root, "model"));
	bool coat = model != NULL && strcmp(model, "coat") == 0;
	json_decref(root);
	return coat;
}

static plume_status render_spec(const render_options *o, const plume_raytrace_def *def, cli_output *output,
                                plume_error *err)
{
	plume_spec_options spec_options = {.seed = o->seed, .seed_given = o->seed_given, .max_memory = o->max_memory};
	plume_feather *feather = NULL;
	plume_coat *coat = NULL;
	const plume_feather **list = NULL;
	plume_raytrace_scene scene = {0};
	plume_status status;
	if (is_coat_spec(o->input)) {
		// A coat: every feather (already in world coordinates) over the coat's surface.
		if ((status = plume_coat_spec_generate(o->input, &spec_options, &coat, err)) != PLUME_OK)
			return status;
		scene.feather_count = plume_coat_feather_count(coat);
		list = malloc((size_t)(scene.feather_count > 0 ? scene.feather_count : 1) * sizeof *list);
		if (list == NULL) {
			plume_coat_destroy(coat);
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
		}
		for (int i = 0; i < scene.feather_count; ++i)
			list[i] = plume_coat_feather(coat, i);
		scene.shell = plume_coat_surface(coat);
	} else {
		if ((status = plume_spec_generate(o->input, &spec_options, &feather, err)) != PLUME_OK)
			return status;
		list = malloc(sizeof *list);
		if (list == NULL) {
			plume_feather_destroy(feather);
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
		}
		list[0] = feather;
		scene.feather_count = 1;
	}
	scene.feathers = list;
	char path[4608];
	status = check_images(o, def, o->turntable > 0 ? o->turntable : 1, 0, "--turntable", err);
	uint8_t *image = malloc(4 * (size_t)def->camera.width * (size_t)def->camera.height);
	if (status == PLUME_OK && image == NULL)
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory for the image");
	if (status == PLUME_OK && o->turntable == 0) {
		cli_output_path(output, "feather.png", path, sizeof path);
		status = render_image(o, &scene, def, image, path, err);
	} else if (status == PLUME_OK) {
		char folder[4352];
		status = stage_folder(output, "turntable", folder, sizeof folder, err);
		plume_raytrace_def frame = *def;
		// One framing for every angle: the camera turns, the feather stays.
		plume_vec3 lo, hi;
		plume_raytrace_scene_bounds(&scene, &lo, &hi);
		frame.camera = plume_camera_frame_bounds(&def->camera, lo, hi);
		cli_progress progress;
		cli_progress_begin(&progress, "render", o->turntable);
		for (int i = 0; i < o->turntable && status == PLUME_OK; ++i) {
			frame.camera.turntable = 2.0 * 3.14159265358979323846 * i / o->turntable;
			snprintf(path, sizeof path, "%s/%04d.png", folder, i);
			status = render_image(o, &scene, &frame, image, path, err);
			if (status == PLUME_OK)
				cli_progress_update(&progress, i + 1);
		}
	}
	free(image);
	free(list);
	plume_feather_destroy(feather);
	plume_coat_destroy(coat);
	return status;
}

// ---------------------------------------------------------------------------
// A simulation folder

typedef struct sim_input {
	/// The feathers at rest, world coordinates: feather.json, or every feather of a
	/// many-feather run (feathers.json). A NULL feather (guides) is not drawn.
	int feather_count;
	plume_feather **feathers;
	char (*names)[64]; ///< "" for feather.json; else each feather's name
	int *faces;        ///< per feather: first face and face count in the rest shell
	plume_mesh *rest;
	plume_mesh *body; ///< body.obj at rest, or NULL
	int frame_count;
	char (*frame_names)[64];     ///< "NNNN.obj", in the order of their numbers
	int *frame_numbers;          ///< NNNN of each: 0, 1, ... frame_count - 1 (read_sim checks)
	plume_vec3 **positions;      ///< per frame, rest vertex order
	plume_vec3 **body_positions; ///< per frame (frames/body-NNNN.obj), when there is a body
} sim_input;

static void sim_input_free(sim_input *in)
{
	for (int i = 0; i < in->feather_count && in->feathers != NULL; ++i)
		plume_feather_destroy(in->feathers[i]);
	free(in->feathers);
	free(in->names);
	free(in->faces);
	plume_mesh_destroy(in->rest);
	plume_mesh_destroy(in->body);
	for (int i = 0; i < in->frame_count; ++i) {
		free(in->positions != NULL ? in->positions[i] : NULL);
		free(in->body_positions != NULL ? in->body_positions[i] : NULL);
	}
	free(in->positions);
	free(in->body_positions);
	free(in->frame_names);
	free(in->frame_numbers);
}

static plume_status sim_input_reserve(sim_input *in, int count, plume_error *err)
{
	in->feather_count = count;
	in->feathers = calloc((size_t)(count > 0 ? count : 1), sizeof *in->feathers);
	in->names = calloc((size_t)(count > 0 ? count : 1), sizeof *in->names);
	in->faces = calloc(2 * (size_t)(count > 0 ? count : 1), sizeof *in->faces);
	if (in->feathers == NULL || in->names == NULL || in->faces == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	return PLUME_OK;
}

/// The feathers of a many-feather run (DIR/feathers.json, written by plume simulate): each
/// read from its dump (shared by the copies of one feather) and placed by its rotation and
/// translation. The face ranges are checked against the rest shell by the caller.
static plume_status read_feathers(const char *dir, const char *index_path, sim_input *in, plume_error *err)
{
	json_error_t error;
	json_t *root = json_load_file(index_path, 0, &error);
	if (root == NULL)
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: line %d: %s", index_path, error.line, error.text);
	json_t *list = json_object_get(root, "feathers");
	plume_status status = json_is_array(list) && json_array_size(list) > 0
	                          ? sim_input_reserve(in, (int)json_array_size(list), err)
	                          : plume_error_set(err, PLUME_ERROR_SPEC,
	                                            "%s: $.feathers: expected a non-empty array of feathers", index_path);
	char path[4608];
	for (int i = 0; i < in->feather_count && status == PLUME_OK; ++i) {
		json_t *entry = json_array_get(list, (size_t)i), *rotation = json_object_get(entry, "rotation"),
		       *translation = json_object_get(entry, "translation");
		const char *name = json_string_value(json_object_get(entry, "name"));
		const char *dump = json_string_value(json_object_get(entry, "dump"));
		json_t *first = json_object_get(entry, "face_offset"), *count = json_object_get(entry, "face_count");
		if (name == NULL || !json_is_integer(first) || !json_is_integer(count)) {
			status = plume_error_set(err, PLUME_ERROR_SPEC,
			                         "%s: $.feathers[%d]: needs \"name\", \"face_offset\" and \"face_count\"",
			                         index_path, i);
			break;
		}
		snprintf(in->names[i], sizeof in->names[i], "%s", name);
		in->faces[2 * i] = (int)json_integer_value(first);
		in->faces[2 * i + 1] = (int)json_integer_value(count);
		if (dump == NULL) // guides: nothing to draw
			continue;
		if (strchr(dump, '/') != NULL || json_array_size(rotation) != 9 || json_array_size(translation) != 3) {
			status = plume_error_set(err, PLUME_ERROR_SPEC,
			                         "%s: $.feathers[%d]: \"dump\" must be a file name in feathers/, \"rotation\" 9 "
			                         "numbers and \"translation\" 3",
			                         index_path, i);
			break;
		}
		snprintf(path, sizeof path, "%s/feathers/%s", dir, dump);
		if (access(path, F_OK) != 0) {
			status = plume_error_set(err, PLUME_ERROR_IO,
			                         "%s: missing; feather \"%s\" of %s needs it (plume simulate writes one dump per "
			                         "distinct feather)",
			                         path, name, index_path);
			break;
		}
		if ((status = plume_read_json(path, &in->feathers[i], err)) != PLUME_OK)
			break;
		plume_mat3 r;
		for (int k = 0; k < 9; ++k)
			r.m[k / 3][k % 3] = json_number_value(json_array_get(rotation, (size_t)k));
		plume_vec3 t = plume_v3(json_number_value(json_array_get(translation, 0)),
		                        json_number_value(json_array_get(translation, 1)),
		                        json_number_value(json_array_get(translation, 2)));
		plume_feather_move(in->feathers[i], r, t);
	}
	json_decref(root);
	return status;
}

/// A frame file's number: the digits of "NNNN.obj" (simulate writes %04d, so 10000.obj follows 9999.obj).
static int frame_number(const char *name) { return (int)strtol(name, NULL, 10); }

static int compare_frames(const void *a, const void *b)
{
	int x = frame_number(a), y = frame_number(b);
	return x < y ? -1 : x > y ? 1 : strcmp(a, b);
}

/// Names "NNNN.obj" in dir, in the order of their numbers.
static plume_status list_frames(const char *dir, sim_input *in, plume_error *err)
{
	DIR *folder = opendir(dir);
	if (folder == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read the frames folder: %s", dir, strerror(errno));
	struct dirent *entry;
	int capacity = 0;
	plume_status status = PLUME_OK;
	while ((entry = readdir(folder)) != NULL) {
		size_t length = strlen(entry->d_name);
		// At most 9 digits: every number fits an int.
		if (length < 5 || length > 13 || strcmp(entry->d_name + length - 4, ".obj") != 0 ||
		    strspn(entry->d_name, "0123456789") != length - 4)
			continue;
		if (in->frame_count == capacity) {
			capacity = capacity > 0 ? 2 * capacity : 64;
			void *grown = realloc(in->frame_names, (size_t)capacity * sizeof *in->frame_names);
			if (grown == NULL) {
				status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
				break;
			}
			in->frame_names = grown;
		}
		memcpy(in->frame_names[in->frame_count++], entry->d_name, length + 1); // length < 64, checked above
	}
	closedir(folder);
	if (status == PLUME_OK && in->frame_count == 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: no frames (NNNN.obj) in the frames folder", dir);
	if (status != PLUME_OK)
		return status;
	qsort(in->frame_names, (size_t)in->frame_count, sizeof *in->frame_names, compare_frames);
	in->frame_numbers = malloc((size_t)in->frame_count * sizeof *in->frame_numbers);
	if (in->frame_numbers == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	for (int i = 0; i < in->frame_count; ++i)
		in->frame_numbers[i] = frame_number(in->frame_names[i]);
	return PLUME_OK;
}

/// The frames of a simulation are numbered 0, 1, ... without a gap, as many as its
/// summary.json says (when it has one): a missing or extra frame is named.
static plume_status check_frames(const char *dir, const char *frames_dir, const sim_input *in, plume_error *err)
{
	for (int i = 0; i < in->frame_count; ++i) {
		int n = in->frame_numbers[i];
		if (n == i)
			continue;
		if (n < i) // the same number twice, as in 5.obj and 0005.obj
			return plume_error_set(err, PLUME_ERROR_SPEC, "%s/%s and %s: both are frame %d", frames_dir,
			                       in->frame_names[i - 1], in->frame_names[i], n);
		return plume_error_set(err, PLUME_ERROR_IO,
		                       "%s/%04d.obj: missing; a simulation's frames run from 0000 without a gap (this folder "
		                       "has %d frame files, %s to %s)",
		                       frames_dir, i, in->frame_count, in->frame_names[0],
		                       in->frame_names[in->frame_count - 1]);
	}
	char path[4608];
	snprintf(path, sizeof path, "%s/summary.json", dir);
	json_t *summary = json_load_file(path, 0, NULL);
	json_t *frames = json_object_get(summary, "frames");
	plume_status status = PLUME_OK;
	if (json_is_integer(frames) && json_integer_value(frames) > in->frame_count)
		status = plume_error_set(err, PLUME_ERROR_IO, "%s/%04d.obj: missing; %s says the run wrote %lld frames",
		                         frames_dir, in->frame_count, path, (long long)json_integer_value(frames));
	else if (json_is_integer(frames) && json_integer_value(frames) < in->frame_count)
		status = plume_error_set(err, PLUME_ERROR_SPEC,
		                         "%s/%s: not of this run; %s says the run wrote %lld frames (0000 to %04lld)",
		                         frames_dir, in->frame_names[json_integer_value(frames)], path,
		                         (long long)json_integer_value(frames), (long long)json_integer_value(frames) - 1);
	json_decref(summary);
	return status;
}

/// Frame i's body, frames/body-NNNN.obj, which must keep body.obj's vertices and faces.
static plume_status read_body_frame(const char *frames_dir, sim_input *in, int i, plume_error *err)
{
	char path[4608];
	snprintf(path, sizeof path, "%s/body-%s", frames_dir, in->frame_names[i]);
	plume_mesh *frame = NULL;
	plume_status status = plume_mesh_read_obj(path, &frame, err);
	if (status != PLUME_OK) {
		if (access(path, F_OK) != 0)
			return plume_error_set(err, PLUME_ERROR_IO, "%s: missing; the run has a body (body.obj) in every frame",
			                       path);
		return status;
	}
	if (frame->vertex_count != in->body->vertex_count || frame->face_count != in->body->face_count ||
	    memcmp(frame->faces, in->body->faces, 3 * sizeof(int) * (size_t)frame->face_count) != 0) {
		plume_error_set(err, PLUME_ERROR_SPEC,
		                "%s: has %d vertices and %d faces, but body.obj has %d and %d (or other faces)", path,
		                frame->vertex_count, frame->face_count, in->body->vertex_count, in->body->face_count);
		plume_mesh_destroy(frame);
		return PLUME_ERROR_SPEC;
	}
	in->body_positions[i] = malloc((size_t)frame->vertex_count * sizeof(plume_vec3));
	if (in->body_positions[i] != NULL)
		memcpy(in->body_positions[i], frame->rest, (size_t)frame->vertex_count * sizeof(plume_vec3));
	plume_mesh_destroy(frame);
	return in->body_positions[i] != NULL ? PLUME_OK : plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
}

/// Reads feather.json (or feathers.json and the dumps), mesh.obj, body.obj and every frame, checking that the frames
/// match the rest shell.
static plume_status read_sim(const char *dir, sim_input *in, plume_error *err)
{
	char path[4608], index[4608];
	snprintf(path, sizeof path, "%s/feather.json", dir);
	snprintf(index, sizeof index, "%s/feathers.json", dir);
	plume_status status;
	if (access(path, F_OK) != 0 && access(index, F_OK) == 0) {
		if ((status = read_feathers(dir, index, in, err)) != PLUME_OK)
			return status;
	} else {
		if ((status = sim_input_reserve(in, 1, err)) != PLUME_OK)
			return status;
		if ((status = plume_read_json(path, &in->feathers[0], err)) != PLUME_OK) {
			if (access(path, F_OK) != 0)
				return plume_error_set(err, PLUME_ERROR_IO,
				                       "%s: missing; plume render needs the generated feather of a simulation to "
				                       "carry its barbs (or feathers.json, for a run of many feathers)",
				                       path);
			return status;
		}
	}
	snprintf(path, sizeof path, "%s/mesh.obj", dir);
	if ((status = plume_mesh_read_obj(path, &in->rest, err)) != PLUME_OK)
		return status;
	if (in->names[0][0] == '\0') {
		in->faces[1] = in->rest->face_count;
	}
	for (int i = 0; i < in->feather_count; ++i)
		if (in->faces[2 * i] < 0 || in->faces[2 * i + 1] < 0 ||
		    in->faces[2 * i] + (int64_t)in->faces[2 * i + 1] > in->rest->face_count)
			return plume_error_set(
			    err, PLUME_ERROR_SPEC, "%s: feather \"%s\": faces %d to %d are not all in mesh.obj (%d faces)", index,
			    in->names[i], in->faces[2 * i], in->faces[2 * i] + in->faces[2 * i + 1] - 1, in->rest->face_count);
	snprintf(path, sizeof path, "%s/body.obj", dir);
	if (access(path, F_OK) == 0 && (status = plume_mesh_read_obj(path, &in->body, err)) != PLUME_OK)
		return status;
	char frames_dir[4352];
	snprintf(frames_dir, sizeof frames_dir, "%s/frames", dir);
	int names = 0;
	in->frame_count = 0;
	if ((status = list_frames(frames_dir, in, err)) != PLUME_OK ||
	    (status = check_frames(dir, frames_dir, in, err)) != PLUME_OK)
		return status;
	names = in->frame_count;
	in->positions = calloc((size_t)names, sizeof *in->positions);
	in->body_positions = calloc((size_t)names, sizeof *in->body_positions);
	if (in->positions == NULL || in->body_positions == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	for (int i = 0; i < names; ++i) {
		snprintf(path, sizeof path, "%s/%s", frames_dir, in->frame_names[i]);
		plume_mesh *frame = NULL;
		if ((status = plume_mesh_read_obj(path, &frame, err)) != PLUME_OK)
			return status;
		bool same = frame->vertex_count == in->rest->vertex_count && frame->face_count == in->rest->face_count &&
		            memcmp(frame->faces, in->rest->faces, 3 * sizeof(int) * (size_t)frame->face_count) == 0;
		if (!same) {
			plume_error_set(err, PLUME_ERROR_SPEC,
			                "%s: has %d vertices and %d faces, but the rest shell mesh.obj has %d and %d (or other "
			                "faces); frames must keep the shell's vertices and faces",
			                path, frame->vertex_count, frame->face_count, in->rest->vertex_count, in->rest->face_count);
			plume_mesh_destroy(frame);
			return PLUME_ERROR_SPEC;
		}
		in->positions[i] = malloc((size_t)frame->vertex_count * sizeof(plume_vec3));
		if (in->positions[i] == NULL) {
			plume_mesh_destroy(frame);
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
		}
		memcpy(in->positions[i], frame->rest, (size_t)frame->vertex_count * sizeof(plume_vec3));
		plume_mesh_destroy(frame);
		if (in->body != NULL && (status = read_body_frame(frames_dir, in, i, err)) != PLUME_OK)
			return status;
	}
	return PLUME_OK;
}

static void grow_bounds(plume_vec3 *lo, plume_vec3 *hi, plume_vec3 a, plume_vec3 b)
{
	lo->x = fmin(lo->x, a.x), lo->y = fmin(lo->y, a.y), lo->z = fmin(lo->z, a.z);
	hi->x = fmax(hi->x, b.x), hi->y = fmax(hi->y, b.y), hi->z = fmax(hi->z, b.z);
}

/// Which strip slot frame number n fills, of frames first .. last: the frames
/// first + round(k (last - first) / (slots - 1)) for k = 0 .. slots - 1; -1 for none.
static int strip_slot(int slots, int first, int last, int n)
{
	if (slots <= 0)
		return -1;
	if (slots == 1)
		return n == last ? 0 : -1;
	for (int k = 0; k < slots; ++k)
		if (first + (int)((double)k * (last - first) / (slots - 1) + 0.5) == n)
			return k;
	return -1;
}

/// Whether --frames selects frame number n.
static bool frame_selected(const render_options *o, int n)
{
	if (!o->frames_given)
		return true;
	return n >= o->frame_first && n <= o->frame_last && (n - o->frame_first) % o->frame_step == 0;
}

/// --frames, once every selected frame is rendered into the staging folder: DIR and
/// DIR/frames are made if missing (ranges rendered by other processes may share them),
/// the staged frames join DIR/frames file by file (each rename atomic) and DIR's run
/// manifest, and the staged folder goes. Nothing is made outside the staging folder
/// before this, so bad input leaves no folder behind.
static plume_status merge_frames(cli_output *output, const char *staged, plume_error *err)
{
	char final[4352];
	snprintf(final, sizeof final, "%s/frames", output->dir);
	bool made_dir = mkdir(output->dir, 0777) == 0;
	if (!made_dir && errno != EEXIST)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot create: %s", output->dir, strerror(errno));
	struct stat info;
	if (mkdir(final, 0777) != 0 && (errno != EEXIST || stat(final, &info) != 0 || !S_ISDIR(info.st_mode))) {
		plume_error_set(err, PLUME_ERROR_IO, "%s: cannot create the frames folder: %s", final,
		                errno == EEXIST ? "a file has that name" : strerror(errno));
		if (made_dir)
			rmdir(output->dir);
		return PLUME_ERROR_IO;
	}
	DIR *folder = opendir(staged);
	if (folder == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read: %s", staged, strerror(errno));
	struct dirent *entry;
	plume_status status = PLUME_OK;
	char(*names)[256] = NULL;
	const char **list = NULL;
	int count = 0, capacity = 0;
	while (status == PLUME_OK && (entry = readdir(folder)) != NULL) {
		if (entry->d_name[0] == '.')
			continue;
		char from[4608], to[4608];
		snprintf(from, sizeof from, "%s/%s", staged, entry->d_name);
		snprintf(to, sizeof to, "%s/%s", final, entry->d_name);
		if (count == capacity) {
			capacity = capacity > 0 ? 2 * capacity : 64;
			void *grown = realloc(names, (size_t)capacity * sizeof *names);
			if (grown == NULL) {
				status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
				break;
			}
			names = grown;
		}
		if (rename(from, to) != 0)
			status = plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", to, strerror(errno));
		else
			snprintf(names[count++], sizeof names[0], "%s", entry->d_name);
	}
	closedir(folder);
	list = count > 0 ? malloc((size_t)count * sizeof *list) : NULL;
	for (int i = 0; i < count && list != NULL; ++i)
		list[i] = names[i];
	plume_error note;
	if (count > 0 && (list == NULL || cli_output_manifest_add(output->dir, "frames", list, count, &note) != PLUME_OK))
		fprintf(stderr,
		        "plume: %s: the frames are written, but the folder's run manifest could not list them: a "
		        "later run into it keeps them as files of yours\n",
		        output->dir);
	free(list);
	free(names);
	if (status == PLUME_OK && rmdir(staged) != 0)
		status = plume_error_set(err, PLUME_ERROR_IO, "%s: cannot remove: %s", staged, strerror(errno));
	return status;
}

static plume_status render_sim(const render_options *o, const plume_raytrace_def *def, cli_output *output,
                               plume_error *err)
{
	sim_input in = {0};
	cli_carried carried = {0};
	plume_status status = read_sim(o->input, &in, err);
	if (status == PLUME_OK)
		status = cli_carried_begin(&carried, in.rest, in.feather_count, (const plume_feather *const *)in.feathers,
		                           in.faces, o->shell, in.body, err);
	// One camera for the whole sequence, framing the carried feathers (and the body) over every frame.
	plume_raytrace_def frame_def = *def;
	plume_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
	for (int i = 0; i < in.frame_count && status == PLUME_OK; ++i) {
		plume_raytrace_scene scene;
		if ((status = cli_carried_pose(&carried, in.positions[i], in.body_positions[i], &scene, err)) != PLUME_OK)
			break;
		plume_vec3 a, b;
		plume_raytrace_scene_bounds(&scene, &a, &b);
		grow_bounds(&lo, &hi, a, b);
	}
	if (status == PLUME_OK)
		frame_def.camera = plume_camera_frame_bounds(&def->camera, lo, hi);
	char folder[4352];
	int selected = 0;
	for (int i = 0; i < in.frame_count; ++i)
		selected += frame_selected(o, in.frame_numbers[i]);
	if (status == PLUME_OK && selected == 0)
		status = plume_error_set(
		    err, PLUME_ERROR_SPEC, "%s: no frame in --frames %d:%d:%d (the frames are %.*s to %.*s)", o->input,
		    o->frame_first, o->frame_last, o->frame_step, (int)strlen(in.frame_names[0]) - 4, in.frame_names[0],
		    (int)strlen(in.frame_names[in.frame_count - 1]) - 4, in.frame_names[in.frame_count - 1]);
	const int slots = o->strip < in.frame_count ? o->strip : in.frame_count;
	if (status == PLUME_OK)
		status = check_images(o, &frame_def, selected + (slots > 0), slots, "the frames, --frames, --strip", err);
	if (status == PLUME_OK)
		status = stage_folder(output, "frames", folder, sizeof folder, err);
	const int w = frame_def.camera.width, h = frame_def.camera.height;
	uint8_t *image = malloc(4 * (size_t)w * (size_t)h);
	// A strip of more frames than there are shows each frame once (slots).
	uint8_t *strip = slots > 0 ? calloc(4 * (size_t)w * (size_t)h, (size_t)slots) : NULL;
	if (status == PLUME_OK && (image == NULL || (slots > 0 && strip == NULL)))
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory for the images");
	cli_progress progress;
	cli_progress_begin(&progress, "render frames", in.frame_count);
	for (int i = 0; i < in.frame_count && status == PLUME_OK; ++i) {
		if (!frame_selected(o, in.frame_numbers[i]))
			continue;
		plume_raytrace_scene scene;
		if ((status = cli_carried_pose(&carried, in.positions[i], in.body_positions[i], &scene, err)) != PLUME_OK)
			break;
		char stem[64], path[4608];
		snprintf(stem, sizeof stem, "%.*s", (int)(strlen(in.frame_names[i]) - 4), in.frame_names[i]);
		if (status == PLUME_OK && (o->formats & CLI_FORMAT_PNG)) {
			snprintf(path, sizeof path, "%s/%s.png", folder, stem);
			status = render_image(o, &scene, &frame_def, image, path, err);
		}
		int slot = strip_slot(slots, in.frame_numbers[0], in.frame_numbers[in.frame_count - 1], in.frame_numbers[i]);
		if (status == PLUME_OK && slot >= 0 && strip != NULL) {
			for (int y = 0; y < h; ++y)
				memcpy(strip + 4 * ((size_t)y * (size_t)(w * slots) + (size_t)(slot * w)),
				       image + 4 * (size_t)y * (size_t)w, 4 * (size_t)w);
		}
		// Curves: NNNN.obj for one feather, NNNN-NAME.obj per feather of a many-feather run.
		for (int f = 0; f < in.feather_count && status == PLUME_OK; ++f) {
			const plume_feather *moved = carried.moved[f];
			if (moved == NULL)
				continue;
			char file[128];
			snprintf(file, sizeof file, "%s%s%s", stem, in.names[f][0] != '\0' ? "-" : "", in.names[f]);
			if (o->formats & CLI_FORMAT_OBJ) {
				snprintf(path, sizeof path, "%s/%s.obj", folder, file);
				status = plume_write_obj(moved, path, err);
			}
			if (status == PLUME_OK && (o->formats & CLI_FORMAT_USDA)) {
				snprintf(path, sizeof path, "%s/%s.usda", folder, file);
				status = plume_write_usda(moved, path, err);
			}
		}
		if (status == PLUME_OK)
			cli_progress_update(&progress, i + 1);
	}
	if (status == PLUME_OK && strip != NULL) {
		char path[4608];
		cli_output_path(output, "strip.png", path, sizeof path);
		status = plume_write_rgba_png(w * slots, h, strip, path, err);
	}
	if (status == PLUME_OK && o->frames_given)
		status = merge_frames(output, folder, err);
	free(image);
	free(strip);
	cli_carried_end(&carried);
	sim_input_free(&in);
	return status;
}

/// Whether the paths a and b name the same existing file or folder (device and inode, so
/// that "sim", "./sim/" and a link to it are one).
static bool same_file(const char *a, const char *b)
{
	struct stat x, y;
	return stat(a, &x) == 0 && stat(b, &y) == 0 && x.st_dev == y.st_dev && x.st_ino == y.st_ino;
}

/// A spec without "model": a scene (for plume simulate), or a spec that names no generator.
static plume_status check_spec_kind(const char *path, plume_error *err)
{
	json_t *root = json_load_file(path, 0, NULL);
	plume_status status = PLUME_OK;
	if (json_is_object(root) && json_object_get(root, "model") == NULL) { // anything else: the spec reader says
		if (json_object_get(root, "feather") != NULL || json_object_get(root, "feathers") != NULL)
			status = plume_error_set(err, PLUME_ERROR_SPEC,
			                         "%s: a scene (docs/scene.md), which plume render does not take: simulate it "
			                         "(plume simulate %s -o DIR) and render the simulation folder DIR",
			                         path, path);
		else
			status = plume_error_set(err, PLUME_ERROR_SPEC,
			                         "%s: $.model: missing; plume render takes a feather spec (\"model\": one of "
			                         "franco-walter, streit-heidrich, zhang-kanai), a coat spec (\"model\": \"coat\") "
			                         "or a simulation folder (written by plume simulate)",
			                         path);
	}
	json_decref(root);
	return status;
}

int cli_render(int argc, char **argv)
{
	render_options o = {.formats = CLI_FORMAT_PNG | CLI_FORMAT_OBJ | CLI_FORMAT_USDA};
	int code = parse_options(argc, argv, &o);
	if (code != CLI_EXIT_OK)
		return code < 0 ? CLI_EXIT_OK : code;
	plume_error err = {0};
	struct stat info;
	if (stat(o.input, &info) != 0) {
		plume_error_set(&err, PLUME_ERROR_IO, "%s: cannot read: %s", o.input, strerror(errno));
		return cli_fail(&err);
	}
	bool sim = S_ISDIR(info.st_mode);
	if (!sim && o.shell)
		return cli_usage_error("render", "--shell needs a simulation folder as INPUT");
	if (!sim && o.formats_given)
		return cli_usage_error("render", "--format needs a simulation folder as INPUT (a spec renders feather.png, "
		                                 "or turntable/NNNN.png)");
	if (sim && o.turntable > 0)
		return cli_usage_error("render", "--turntable needs a feather spec as INPUT");
	if (o.strip > 0 && (!sim || !(o.formats & CLI_FORMAT_PNG)))
		return cli_usage_error("render", "--strip needs a simulation folder as INPUT and png among the formats");
	if (o.frames_given && (!sim || o.strip > 0))
		return cli_usage_error("render", "--frames needs a simulation folder as INPUT, and no --strip");
	// The rendered frames/NNNN.obj would replace the simulation's own shell frames.
	char input_frames[4352], output_frames[4352];
	snprintf(input_frames, sizeof input_frames, "%s/frames", o.input);
	snprintf(output_frames, sizeof output_frames, "%s/frames", o.output_dir);
	if (sim && (same_file(o.input, o.output_dir) || same_file(input_frames, output_frames)))
		return cli_usage_error("render",
		                       "-o %s is the simulation folder %s itself: the rendered frames/NNNN.obj would replace "
		                       "its shell frames; choose another output folder (such as %s/rt)",
		                       o.output_dir, o.input, o.input);
	// Another simulation's folder: the same (a render's own output has no mesh.obj).
	char output_mesh[4352], output_frame[4352];
	snprintf(output_mesh, sizeof output_mesh, "%s/mesh.obj", o.output_dir);
	snprintf(output_frame, sizeof output_frame, "%s/frames/0000.obj", o.output_dir);
	if (sim && access(output_mesh, F_OK) == 0 && access(output_frame, F_OK) == 0)
		return cli_usage_error("render",
		                       "-o %s holds a simulation (mesh.obj, frames/0000.obj ...): the rendered "
		                       "frames/NNNN.obj would replace its shell frames; choose another output folder",
		                       o.output_dir);
	if (o.camera_path != NULL && stat(o.camera_path, &info) == 0 && S_ISDIR(info.st_mode)) {
		plume_error_set(&err, PLUME_ERROR_IO, "%s: is a folder; --camera takes a camera file (docs/rendering.md)",
		                o.camera_path);
		return cli_fail(&err);
	}
	if (o.texture_path != NULL && stat(o.texture_path, &info) == 0 && S_ISDIR(info.st_mode)) {
		plume_error_set(&err, PLUME_ERROR_IO, "%s: is a folder; --texture takes an image file", o.texture_path);
		return cli_fail(&err);
	}

	plume_texture *texture = NULL;
	if (o.texture_path != NULL && plume_texture_load(o.texture_path, &texture, &err) != PLUME_OK)
		return cli_fail(&err);
	plume_raytrace_def def;
	plume_status status = make_def(&o, texture, &def, &err);
	if (status == PLUME_OK && !sim)
		status = check_spec_kind(o.input, &err);
	// Nothing is made outside the staging folder until the run has succeeded: --frames
	// makes DIR/frames (shared with ranges rendered by other processes) only then.
	cli_output output;
	if (status == PLUME_OK && (status = cli_output_begin(&output, o.output_dir, &err)) == PLUME_OK) {
		status = sim ? render_sim(&o, &def, &output, &err) : render_spec(&o, &def, &output, &err);
		if (status == PLUME_OK)
			status = cli_output_commit(&output, &err);
		else
			cli_output_abort(&output, &err);
	}
	plume_texture_destroy(texture);
	if (status != PLUME_OK)
		return cli_fail(&err);
	return CLI_EXIT_OK;
}

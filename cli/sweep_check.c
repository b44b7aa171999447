// plume sweep: checks before any run: the extra arguments must be ones the command
// takes and the sweep does not set; each value a run will see must pass the command's
// own spec reader (which names the JSON path and the allowed range); an output naming a
// mesh group, a handle or a feather must name one the first run has.
#define _GNU_SOURCE
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "sweep.h"

// ---------------------------------------------------------------------------
// $.arguments

/// An option the sweep sets on every run's command line, or one that overrides a key
/// of the spec when that key is swept: given in $.arguments it would send every run to
/// one folder, or silently replace the swept values.
typedef struct set_option {
	int probe;        ///< the probe_kind of the command it belongs to; -1: every command
	char letter;      ///< its short form, 0 for none
	const char *name; ///< its long form
	const char *path; ///< refused only when a parameter sweeps this path; NULL: always
	const char *why;
} set_option;

static const set_option set_options[] = {
    {-1, 'o', "output", NULL, "the sweep gives each run its own output folder"},
    {-1, 'h', "help", NULL, "every run would print the help instead of running"},
    {PROBE_RENDER, 'f', "format", NULL, "set $.spec.format instead"},
    {PROBE_RENDER, 0, "frames", NULL, "the sweep sets each run's range from $.first, $.count and $.step"},
    {PROBE_RENDER, 0, "spp", NULL, "set $.spec.spp instead"},
    {PROBE_RENDER, 0, "size", NULL, "set $.spec.size instead"},
    {PROBE_CALIBRATION, 0, "phi", NULL, "set $.spec.phi instead"},
    {PROBE_CALIBRATION, 0, "Eb", NULL, "set $.spec.Eb instead"},
    {PROBE_CALIBRATION, 0, "EB", NULL, "set $.spec.EB instead"},
    {PROBE_CALIBRATION, 0, "aspect", NULL, "set $.spec.aspect instead"},
    {PROBE_CALIBRATION, 0, "period", NULL, "set $.spec.period instead"},
    {PROBE_CALIBRATION, 0, "width", NULL, "set $.spec.width instead"},
    {PROBE_CALIBRATION, 0, "elements", NULL, "set $.spec.elements instead"},
    {PROBE_CALIBRATION, 0, "macro-elements", NULL, "set $.spec.macro_elements instead"},
    {PROBE_CALIBRATION, 0, "phases", NULL, "set $.spec.phases instead"},
    {PROBE_CALIBRATION, 0, "compression", NULL, "set $.spec.compression instead"},
    {PROBE_CALIBRATION, 0, "tilted-strain", NULL, "set $.spec.tilted_strain instead"},
    {PROBE_CALIBRATION, 0, "unconstrained", NULL, "set $.spec.unconstrained instead"},
    {PROBE_FEATHER, 's', "seed", "$.seed", "it would override the swept $.seed"},
    {PROBE_MESH, 's', "seed", "$.seed", "it would override the swept $.seed"},
    {PROBE_COAT, 's', "seed", "$.seed", "it would override the swept $.seed"},
    {PROBE_MESH, 'e', "edge-length", "$.mesh.edge_length", "it would override the swept $.mesh.edge_length"},
    {PROBE_SCENE, 0, "duration", "$.duration", "it would override the swept $.duration"},
    {PROBE_SCENE, 0, "frames-every", "$.frame_every", "it would override the swept $.frame_every"},
};

/// Whether arg names the option as getopt_long reads it: "-o", "-oDIR", "--output",
/// "--output=DIR" or an abbreviation such as "--out".
static bool names_option(const char *arg, char letter, const char *name)
{
	if (letter != 0 && arg[0] == '-' && arg[1] == letter)
		return true;
	if (strncmp(arg, "--", 2) != 0)
		return false;
	size_t length = strcspn(arg + 2, "=");
	return length > 0 && strncmp(arg + 2, name, length) == 0;
}

static bool sweeps_path(const sweep *s, const char *path)
{
	for (int p = 0; p < s->param_count; ++p)
		if (strcmp(s->params[p].path, path) == 0)
			return true;
	return false;
}

/// The last line of stream that is not empty or the "Try 'plume help'" hint, without
/// "plume: " and the command's own "NAME: ".
static void last_message(FILE *stream, const sweep_command *command, char *out, size_t size)
{
	char line[1024];
	out[0] = '\0';
	rewind(stream);
	while (fgets(line, sizeof line, stream) != NULL) {
		line[strcspn(line, "\r\n")] = '\0';
		if (line[0] == '\0' || strncmp(line, "Try 'plume", 10) == 0)
			continue;
		const char *text = strncmp(line, "plume: ", 7) == 0 ? line + 7 : line;
		size_t word = strlen(command->words[0]);
		if (strncmp(text, command->words[0], word) == 0 && strncmp(text + word, ": ", 2) == 0)
			text += word + 2;
		snprintf(out, size, "%s", text);
	}
}

/// Runs "plume COMMAND WORDS... --help", stdout and stderr kept. A command reads all its
/// options before it prints its help, so the help comes (exit 0) only when every option
/// is one the command takes and every value parses; otherwise message gets its error.
static bool command_takes(const sweep *s, const char *const *words, size_t count, char *message, size_t size)
{
	const char *args[48];
	size_t n = 0;
	args[n++] = "plume";
	for (int i = 0; i < 2 && s->command->words[i] != NULL; ++i)
		args[n++] = s->command->words[i];
	for (size_t i = 0; i < count && n + 2 < sizeof args / sizeof args[0]; ++i)
		args[n++] = words[i];
	args[n++] = "--help";
	args[n] = NULL;
	FILE *out = tmpfile(), *err = tmpfile();
	pid_t pid = out != NULL && err != NULL ? fork() : -1;
	if (pid == 0) {
		dup2(fileno(out), 1);
		dup2(fileno(err), 2);
		execv("/proc/self/exe", (char **)args);
		_exit(127);
	}
	int status = 0;
	while (pid > 0 && waitpid(pid, &status, 0) < 0 && errno == EINTR) {
	}
	char usage[8] = "";
	if (pid > 0) {
		rewind(out);
		if (fgets(usage, sizeof usage, out) == NULL)
			usage[0] = '\0';
		last_message(err, s->command, message, size);
	} else
		snprintf(message, size, "cannot start plume to check them: %s", strerror(errno));
	if (out != NULL)
		fclose(out);
	if (err != NULL)
		fclose(err);
	return pid > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0 && strncmp(usage, "Usage:", 6) == 0;
}

/// $.arguments: not an option the sweep sets, every option one the command takes with a
/// value it accepts, and no word that would be a second spec.
static bool check_arguments(const sweep *s)
{
	size_t count = json_array_size(s->arguments);
	if (count == 0)
		return true;
	if (count > 32)
		return sweep_error(s, "$.arguments holds %zu words; at most 32", count);
	const char *words[32];
	for (size_t i = 0; i < count; ++i)
		words[i] = json_string_value(json_array_get(s->arguments, i));
	for (size_t i = 0; i < count; ++i) {
		if (strcmp(words[i], "--") == 0)
			return sweep_error(s, "$.arguments[%zu]: '--' would make the words after it second specs", i);
		for (size_t k = 0; k < sizeof set_options / sizeof set_options[0]; ++k) {
			const set_option *o = set_options + k;
			if ((o->probe == -1 || o->probe == (int)s->command->probe) && names_option(words[i], o->letter, o->name) &&
			    (o->path == NULL || sweeps_path(s, o->path)))
				return sweep_error(s, "$.arguments[%zu]: '%s' (--%s) is refused in a sweep: %s", i, words[i], o->name,
				                   o->why);
		}
	}
	char message[1024];
	if (!command_takes(s, words, count, message, sizeof message)) {
		// The check's own --help read as the value of the last option: that one lacks its value.
		if (strstr(message, "'--help'") != NULL || strncmp(message, "missing", 7) == 0)
			return sweep_error(s, "$.arguments[%zu]: '%s' needs a value after it", count - 1, words[count - 1]);
		return sweep_error(s, "$.arguments: plume %s refuses them: %s", s->command->name, message);
	}
	// A word that is neither an option nor the value of the option before it would be
	// a second spec: an option takes the next word as its value exactly when, followed
	// by --help alone, it does not print the help.
	for (size_t i = 0; i < count; ++i) {
		if (words[i][0] == '-' && words[i][1] != '\0')
			continue;
		bool value = i > 0 && words[i - 1][0] == '-' && !command_takes(s, words + i - 1, 1, message, sizeof message);
		if (!value)
			return sweep_error(s,
			                   "$.arguments[%zu]: '%s' is neither an option of plume %s nor an option's value; "
			                   "the sweep gives each run its spec",
			                   i, words[i], s->command->name);
	}
	return true;
}

// ---------------------------------------------------------------------------
// The command's spec reader

/// What the first run's probe saw that an output's placeholder may name.
typedef struct probe_shape {
	json_t *groups; ///< mesh: the groups' names
	int handles;    ///< scene
	int feathers;   ///< scene
	bool summary;   ///< generate: the feather has a summary (Zhang-Kanai feathers)
} probe_shape;

/// Refuses a render whose output folder is the simulation's or its frames/: the
/// render's frames/ would replace the simulation's frames.
static bool render_folders_differ(const json_t *spec, const struct stat *simulation, char *message, size_t size)
{
	const char *output = json_string_value(json_object_get(spec, "output"));
	if (output == NULL) {
		snprintf(message, size, "$.output must be a folder name");
		return false;
	}
	const char *sim = json_string_value(json_object_get(spec, "simulation"));
	char frames[PATH_MAX + 16];
	snprintf(frames, sizeof frames, "%s/frames", sim);
	struct stat out, sim_frames;
	if (stat(output, &out) != 0)
		return true; // a new folder
	bool same = out.st_dev == simulation->st_dev && out.st_ino == simulation->st_ino;
	bool into_frames =
	    stat(frames, &sim_frames) == 0 && out.st_dev == sim_frames.st_dev && out.st_ino == sim_frames.st_ino;
	if (same || into_frames) {
		snprintf(message, size,
		         "$.output (%s) is %s $.simulation (%s): the rendered frames would replace the simulation's "
		         "frames; choose another output folder",
		         output, same ? "the same folder as" : "the frames folder of", sim);
		return false;
	}
	return true;
}

/// Whether the command's reader takes spec (message: why not); shape, when not NULL,
/// gets what the spec builds.
static bool probe_spec(const sweep *s, json_t *spec, char *message, size_t size, probe_shape *shape)
{
	plume_error err = {0};
	plume_status status = PLUME_OK;
	if (s->command->probe == PROBE_CALIBRATION) {
		const char *name;
		json_t *value;
		json_object_foreach (spec, name, value) {
			size_t best = strcmp(name, "unconstrained") == 0 || strcmp(name, "description") == 0 ? 0 : SIZE_MAX;
			const char *nearest = "phi";
			for (int i = 0; i < CLI_CALIBRATE_OPTION_COUNT && best != 0; ++i) {
				size_t d = plume_edit_distance(cli_calibrate_options[i].key, name);
				if (d < best) {
					best = d;
					nearest = cli_calibrate_options[i].key;
				}
			}
			if (best != 0) {
				snprintf(message, size, "$.%s: not a calibration option; did you mean \"%s\"?", name, nearest);
				return false;
			}
		}
		for (int i = 0; i < CLI_CALIBRATE_OPTION_COUNT; ++i) {
			const cli_calibrate_option *k = &cli_calibrate_options[i];
			json_t *v = json_object_get(spec, k->key);
			if (v == NULL)
				continue;
			double x = json_number_value(v);
			if (!json_is_number(v) || !cli_calibrate_option_allows(k, x)) {
				char range[64];
				cli_calibrate_option_range(k, range, sizeof range);
				snprintf(message, size, "$.%s is %.10g, allowed %s in %s", k->key, x,
				         k->integer ? "a whole number" : "a number", range);
				return false;
			}
		}
		static const char *const needed[] = {"phi", "Eb", "EB"};
		for (int i = 0; i < 3; ++i)
			if (json_object_get(spec, needed[i]) == NULL) {
				snprintf(message, size, "the calibration needs $.%s", needed[i]);
				return false;
			}
		return true;
	}
	if (s->command->probe == PROBE_RENDER) {
		const char *name;
		json_t *value;
		json_object_foreach (spec, name, value) {
			bool known = false;
			for (int i = 0; sweep_render_keys[i] != NULL; ++i)
				known = known || strcmp(sweep_render_keys[i], name) == 0;
			if (!known) {
				snprintf(message, size,
				         "$.%s: not a render frames key (simulation, output, first, count, step, spp, size, format)",
				         name);
				return false;
			}
		}
		static const char *const counts[] = {"first", "count", "step", "spp"};
		for (int i = 0; i < 4; ++i) {
			json_t *v = json_object_get(spec, counts[i]);
			double lo = i == 0 ? 0 : 1;
			if ((v != NULL || i < 2) && !(json_is_integer(v) && json_integer_value(v) >= lo)) {
				snprintf(message, size, "$.%s must be a whole number >= %g", counts[i], lo);
				return false;
			}
		}
		struct stat info;
		const char *sim = json_string_value(json_object_get(spec, "simulation"));
		if (sim == NULL || stat(sim, &info) != 0 || !S_ISDIR(info.st_mode)) {
			snprintf(message, size, "$.simulation: %s is not a simulation folder", sim ? sim : "(none)");
			return false;
		}
		return render_folders_differ(spec, &info, message, size);
	}
	char path[] = "/tmp/plume-sweep-probe-XXXXXX.json";
	int fd = mkstemps(path, 5);
	if (fd < 0) {
		snprintf(message, size, "cannot write a temporary file: %s", strerror(errno));
		return false;
	}
	close(fd);
	if (json_dump_file(spec, path, JSON_INDENT(1) | JSON_REAL_PRECISION(17)) != 0) {
		unlink(path);
		snprintf(message, size, "cannot write a temporary file");
		return false;
	}
	plume_spec_options options = {0};
	switch (s->command->probe) {
	case PROBE_FEATHER: {
		plume_feather *feather = NULL;
		status = plume_spec_generate(path, &options, &feather, &err);
		if (shape != NULL && feather != NULL)
			shape->summary = plume_feather_summary(feather) != NULL;
		plume_feather_destroy(feather);
		break;
	}
	case PROBE_MESH: {
		plume_mesh *mesh = NULL;
		plume_mesh_report report;
		plume_mesh_spec_options mesh_options = plume_mesh_spec_default_options();
		status = plume_mesh_spec_read(path, &mesh_options, &mesh, &report, &err);
		for (int g = 0; shape != NULL && mesh != NULL && g < mesh->group_count; ++g)
			json_array_append_new(shape->groups, json_string(mesh->groups[g].name));
		plume_mesh_destroy(mesh);
		break;
	}
	case PROBE_COAT: {
		plume_coat *coat = NULL;
		status = plume_coat_spec_generate(path, &options, &coat, &err);
		plume_coat_destroy(coat);
		break;
	}
	case PROBE_SCENE: {
		plume_scene *scene = NULL;
		status = plume_scene_load(path, &options, &scene, &err);
		if (shape != NULL && scene != NULL) {
			shape->handles = scene->handle_count;
			shape->feathers = scene->feather_count;
		}
		plume_scene_destroy(scene);
		break;
	}
	case PROBE_LAB: {
		plume_lab_spec lab;
		status = plume_lab_spec_load(path, &lab, &err);
		break;
	}
	default: break;
	}
	unlink(path);
	if (status == PLUME_OK)
		return true;
	// "/tmp/plume-sweep-probe-XXXX.json: $.x: ..." -> "$.x: ..."
	const char *text = err.message;
	if (strncmp(text, path, strlen(path)) == 0) {
		text += strlen(path);
		while (*text == ':' || *text == ' ')
			++text;
	}
	snprintf(message, size, "%s", text);
	return false;
}

/// An output's placeholder must name a group, handle or feather of the first run; a
/// generate sweep's outputs need a feather that writes a summary.
static bool check_outputs(const sweep *s, const probe_shape *shape)
{
	for (int i = 0; i < s->output_count; ++i) {
		char hole[128];
		const sweep_output *o = sweep_output_find(s->command, s->outputs[i], hole, sizeof hole);
		if (s->command->probe == PROBE_FEATHER && !shape->summary)
			return sweep_error(s,
			                   "$.outputs[%d]: generate writes its outputs (summary.json) for Zhang-Kanai feathers "
			                   "only, and the first run's feather is not one",
			                   i);
		if (strstr(o->key, "<group>") != NULL) {
			bool found = false;
			for (size_t g = 0; g < json_array_size(shape->groups); ++g)
				found = found || strcmp(json_string_value(json_array_get(shape->groups, g)), hole) == 0;
			if (!found) {
				fprintf(stderr,
				        "plume: %s: $.outputs[%d]: the first run's mesh has no group \"%s\"; its groups:", s->file, i,
				        hole);
				for (size_t g = 0; g < json_array_size(shape->groups); ++g)
					fprintf(stderr, "%s %s", g ? "," : "", json_string_value(json_array_get(shape->groups, g)));
				fputc('\n', stderr);
				return false;
			}
		}
		bool handle = strstr(o->key, "<handle>") != NULL;
		if (handle || strstr(o->key, "<feather>") != NULL) {
			int count = handle ? shape->handles : shape->feathers;
			if (atol(hole) >= count)
				return sweep_error(s, "$.outputs[%d]: %s: the first run's scene has %d %s (indices from 0)", i,
				                   s->outputs[i], count, handle ? "handles" : "feathers");
		}
	}
	return true;
}

/// The arguments; every grid/list value, and the ends of every distribution's range,
/// through the reader; the outputs against the first run.
bool sweep_check(const sweep *s)
{
	if (!check_arguments(s))
		return false;
	char message[1024];
	json_t *first = sweep_run_spec(s, 0);
	probe_shape shape = {.groups = json_array()};
	bool ok = probe_spec(s, first, message, sizeof message, &shape);
	json_decref(first);
	if (!ok) {
		json_decref(shape.groups);
		return sweep_error(s, "the first run's spec is refused: %s", message);
	}
	ok = check_outputs(s, &shape);
	json_decref(shape.groups);
	if (!ok)
		return false;
	for (int p = 0; p < s->param_count; ++p) {
		const sweep_param *param = s->params + p;
		json_t *probes = json_array();
		const json_t *item = json_array_get(json_object_get(s->root, "parameters"), (size_t)p);
		size_t count = param->values != NULL ? json_array_size(param->values) : 0;
		if (json_object_get(item, "grid") != NULL) {
			// A grid is an interval: its ends, and one inside value (which may be a
			// fraction where the ends are whole), stand for all; a scene's reader
			// generates and meshes the feather, so each check costs.
			json_array_append(probes, json_array_get(param->values, 0));
			if (count > 2)
				json_array_append(probes, json_array_get(param->values, 1));
			if (count > 1)
				json_array_append(probes, json_array_get(param->values, count - 1));
		} else if (param->values != NULL) {
			for (size_t k = 0; k < count; ++k)
				json_array_append(probes, json_array_get(param->values, k));
		} else {
			// The ends of the range the samples can reach; an unbounded side of a
			// normal is checked 10 standard deviations out (probability 8e-24).
			double lo = param->lo, hi = param->hi;
			if (param->dist == DIST_NORMAL) {
				lo = fmax(lo, param->a - 10 * param->b);
				hi = fmin(hi, param->a + 10 * param->b);
			} else if (param->dist == DIST_LOGNORMAL) {
				lo = fmax(lo, exp(param->a - 10 * param->b));
				hi = fmin(hi, exp(param->a + 10 * param->b));
			}
			if (sweep_param_mass(param) < 1e-3)
				return sweep_error(s,
				                   "$.parameters[%d]: [min, max] holds %.2g of the distribution's probability; "
				                   "at least 1e-3 is needed",
				                   p, sweep_param_mass(param));
			json_array_append_new(probes, param->integer ? json_integer((json_int_t)ceil(lo)) : json_real(lo));
			json_array_append_new(probes, param->integer ? json_integer((json_int_t)floor(hi)) : json_real(hi));
		}
		for (size_t k = 0; k < json_array_size(probes); ++k) {
			json_t *spec = sweep_run_spec(s, 0);
			json_t *value = json_array_get(probes, k);
			sweep_path_set(spec, param->path, json_incref(value));
			ok = probe_spec(s, spec, message, sizeof message, NULL);
			json_decref(spec);
			if (!ok) {
				char text[128];
				sweep_csv_value(text, sizeof text, value);
				if (param->values != NULL)
					sweep_error(s, "$.parameters[%d] (%s): the value %s is refused: %s", p, param->path, text, message);
				else
					sweep_error(s,
					            "$.parameters[%d] (%s): the distribution reaches %s, which is refused: %s; "
					            "bound it with \"min\"/\"max\"%s",
					            p, param->path, text, message,
					            param->dist == DIST_NORMAL ? " or use \"lognormal\" for a positive value" : "");
				json_decref(probes);
				return false;
			}
		}
		json_decref(probes);
	}
	return true;
}

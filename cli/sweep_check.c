// plume sweep: checks before any run: each value a run will see must pass the command's
// own spec reader (which names the JSON path and the allowed range).
#define _GNU_SOURCE
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sweep.h"

static bool probe_spec(const sweep *s, json_t *spec, char *message, size_t size)
{
	plume_error err = {0};
	plume_status status = PLUME_OK;
	if (s->command->probe == PROBE_CALIBRATION) {
		const char *name;
		json_t *value;
		json_object_foreach (spec, name, value) {
			size_t best = strcmp(name, "unconstrained") == 0 || strcmp(name, "description") == 0 ? 0 : SIZE_MAX;
			const char *nearest = "phi";
			for (int i = 0; i < SWEEP_CALIBRATION_KEY_COUNT && best != 0; ++i) {
				size_t d = plume_edit_distance(sweep_calibration_keys[i].key, name);
				if (d < best) {
					best = d;
					nearest = sweep_calibration_keys[i].key;
				}
			}
			if (best != 0) {
				snprintf(message, size, "$.%s: not a calibration option; did you mean \"%s\"?", name, nearest);
				return false;
			}
		}
		for (int i = 0; i < SWEEP_CALIBRATION_KEY_COUNT; ++i) {
			const calibration_key *k = sweep_calibration_keys + i;
			json_t *v = json_object_get(spec, k->key);
			if (v == NULL)
				continue;
			double x = json_number_value(v);
			bool ok = json_is_number(v) &&
			          (k->integer ? (x == floor(x) && x >= k->lo && x <= k->hi) : (x > k->lo && x < k->hi));
			if (!ok) {
				if (k->integer)
					snprintf(message, size, "$.%s is %.10g, allowed a whole number >= %g", k->key, x, k->lo);
				else if (isinf(k->hi))
					snprintf(message, size, "$.%s is %.10g, allowed > %g", k->key, x, k->lo);
				else
					snprintf(message, size, "$.%s is %.10g, allowed in (%g, %g)", k->key, x, k->lo, k->hi);
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
		return true;
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
		plume_feather_destroy(feather);
		break;
	}
	case PROBE_MESH: {
		plume_mesh *mesh = NULL;
		plume_mesh_report report;
		plume_mesh_spec_options mesh_options = plume_mesh_spec_default_options();
		status = plume_mesh_spec_read(path, &mesh_options, &mesh, &report, &err);
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

/// Every grid/list value, and the ends of every distribution's range, through the reader.
bool sweep_check(const sweep *s)
{
	char message[1024];
	json_t *first = sweep_run_spec(s, 0);
	bool ok = probe_spec(s, first, message, sizeof message);
	json_decref(first);
	if (!ok)
		return sweep_error(s, "the first run's spec is refused: %s", message);
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
			ok = probe_spec(s, spec, message, sizeof message);
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

// plume sweep: one run is a child plume process (/proc/self/exe) in DIR/runs/NNNNNN, on
// its own copy of the spec; its exit, signal, message and outputs make one CSV row.
// The local scheduler keeps up to -j runs going at once.
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "sweep.h"

static void run_dir(const char *dir, int index, char *out, size_t size)
{
	snprintf(out, size, "%s/runs/%06d", dir, index);
}

/// Writes the run's spec and starts plume on it; the pid, or -1 (message in row).
pid_t sweep_run_start(const sweep *s, const char *dir, int index, char *failure, size_t size)
{
	char folder[PATH_MAX], path[PATH_MAX + 32];
	run_dir(dir, index, folder, sizeof folder);
	cli_remove_tree(folder); // what a killed attempt left
	snprintf(path, sizeof path, "%s/runs", dir);
	mkdir(path, 0777);
	if (mkdir(folder, 0777) != 0) {
		snprintf(failure, size, "cannot create %s: %s", folder, strerror(errno));
		return -1;
	}
	json_t *spec = sweep_run_spec(s, index);
	snprintf(path, sizeof path, "%s/spec.json", folder);
	int failed = json_dump_file(spec, path, JSON_INDENT(2) | JSON_REAL_PRECISION(17));
	json_decref(spec);
	if (failed != 0) {
		snprintf(failure, size, "cannot write %s", path);
		return -1;
	}
	// The command line; relative names, so that messages do not depend on DIR.
	char *args[64];
	static char values[SWEEP_CALIBRATION_KEY_COUNT][64];
	int n = 0;
	args[n++] = "plume";
	for (int i = 0; i < 2 && s->command->words[i] != NULL; ++i)
		args[n++] = (char *)s->command->words[i];
	if (s->command->probe == PROBE_CALIBRATION) {
		json_t *run = sweep_run_spec(s, index);
		for (int i = 0; i < SWEEP_CALIBRATION_KEY_COUNT; ++i) {
			json_t *v = json_object_get(run, sweep_calibration_keys[i].key);
			if (v == NULL)
				continue;
			snprintf(values[i], sizeof values[i], "%.17g", json_number_value(v));
			args[n++] = (char *)sweep_calibration_keys[i].option;
			args[n++] = values[i];
		}
		if (json_is_true(json_object_get(run, "unconstrained")))
			args[n++] = "--unconstrained";
		json_decref(run);
	} else if (s->command->probe == PROBE_RENDER) {
		json_t *run = sweep_run_spec(s, index);
		static char render_args[5][PATH_MAX + 64];
		long long first = json_integer_value(json_object_get(run, "first"));
		long long count = json_integer_value(json_object_get(run, "count"));
		json_t *step_value = json_object_get(run, "step");
		long long step = step_value != NULL ? json_integer_value(step_value) : 1;
		snprintf(render_args[0], sizeof render_args[0], "%s", json_string_value(json_object_get(run, "simulation")));
		snprintf(render_args[1], sizeof render_args[1], "%s", json_string_value(json_object_get(run, "output")));
		snprintf(render_args[2], sizeof render_args[2], "%lld:%lld:%lld", first, first + (count - 1) * step, step);
		args[n++] = render_args[0];
		args[n++] = "-o";
		args[n++] = render_args[1];
		args[n++] = "--frames";
		args[n++] = render_args[2];
		if (json_object_get(run, "spp") != NULL) {
			snprintf(render_args[3], sizeof render_args[3], "%lld",
			         (long long)json_integer_value(json_object_get(run, "spp")));
			args[n++] = "--spp";
			args[n++] = render_args[3];
		}
		if (json_is_string(json_object_get(run, "size"))) {
			snprintf(render_args[4], sizeof render_args[4], "%s", json_string_value(json_object_get(run, "size")));
			args[n++] = "--size";
			args[n++] = render_args[4];
		}
		if (json_is_string(json_object_get(run, "format"))) {
			static char format[64];
			snprintf(format, sizeof format, "%s", json_string_value(json_object_get(run, "format")));
			args[n++] = "-f";
			args[n++] = format;
		}
		json_decref(run);
	} else {
		args[n++] = "spec.json";
		args[n++] = "-o";
		args[n++] = "out";
	}
	for (size_t i = 0; s->arguments != NULL && i < json_array_size(s->arguments) && n < 62; ++i)
		args[n++] = (char *)json_string_value(json_array_get(s->arguments, i));
	args[n] = NULL;
	fflush(NULL);
	pid_t pid = fork();
	if (pid < 0) {
		snprintf(failure, size, "cannot start a run: %s", strerror(errno));
		return -1;
	}
	if (pid == 0) {
		// The run dies with the sweep: a killed sweep leaves no run writing behind it.
		prctl(PR_SET_PDEATHSIG, SIGKILL);
		if (chdir(folder) != 0)
			_exit(127);
		int out = open("stdout.txt", O_WRONLY | O_CREAT | O_TRUNC, 0666);
		int errfd = open("stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0666);
		int null = open("/dev/null", O_RDONLY);
		if (out < 0 || errfd < 0 || null < 0)
			_exit(127);
		dup2(null, 0);
		dup2(out, 1);
		dup2(errfd, 2);
		// One thread a run: parallelism comes from the runs, and results do not
		// depend on the thread count anyway.
		setenv("OMP_NUM_THREADS", "1", 0);
		execv("/proc/self/exe", args);
		_exit(127);
	}
	return pid;
}

/// The output at a dotted key in root, as CSV text (empty when absent).
static void output_value(const json_t *root, const char *key, char *out, size_t size)
{
	char copy[128];
	snprintf(copy, sizeof copy, "%s", key);
	const json_t *node = root;
	for (char *part = strtok(copy, "."); part != NULL && node != NULL; part = strtok(NULL, "."))
		node = json_is_object(node) ? json_object_get(node, part) : NULL;
	sweep_csv_value(out, size, node);
}

/// The last non-empty line of a file, without "plume: ".
static void last_line(const char *path, char *out, size_t size)
{
	out[0] = '\0';
	FILE *file = fopen(path, "r");
	if (file == NULL)
		return;
	char line[2048];
	while (fgets(line, sizeof line, file) != NULL) {
		line[strcspn(line, "\r\n")] = '\0';
		if (line[0] != '\0' && strncmp(line, "Try 'plume", 10) != 0)
			snprintf(out, size, "%s", strncmp(line, "plume: ", 7) == 0 ? line + 7 : line);
	}
	fclose(file);
}

typedef enum row_status { ROW_OK, ROW_FAILED, ROW_SIGNAL } row_status;
static const char *const row_status_names[] = {"ok", "failed", "signal"};

/// The CSV row of a finished run (wait_status from waitpid; pid < 0: it never started).
char *sweep_run_finish(const sweep *s, const char *dir, int index, pid_t pid, int wait_status, const char *failure)
{
	char folder[PATH_MAX], path[PATH_MAX + 64], message[1024] = "";
	run_dir(dir, index, folder, sizeof folder);
	row_status status = ROW_OK;
	if (pid < 0) {
		status = ROW_FAILED;
		snprintf(message, sizeof message, "%s", failure);
	} else if (WIFSIGNALED(wait_status)) {
		status = ROW_SIGNAL;
		snprintf(message, sizeof message, "killed by signal %d (%s)", WTERMSIG(wait_status),
		         strsignal(WTERMSIG(wait_status)));
	} else if (!WIFEXITED(wait_status) || WEXITSTATUS(wait_status) != 0) {
		status = ROW_FAILED;
		snprintf(path, sizeof path, "%s/stderr.txt", folder);
		char line[1000];
		last_line(path, line, sizeof line);
		snprintf(message, sizeof message, "exit %d: %s", WEXITSTATUS(wait_status), line);
	}
	// The outputs (a failed simulation still writes its summary up to the failure).
	json_t *result = NULL;
	if (pid >= 0 && s->command->result != NULL) {
		if (strcmp(s->command->result, "stdout") == 0)
			snprintf(path, sizeof path, "%s/stdout.txt", folder);
		else
			snprintf(path, sizeof path, "%s/out/%s", folder, s->command->result);
		result = json_load_file(path, 0, NULL);
	}
	size_t capacity = 4096 + (size_t)(s->param_count + s->output_count) * 160;
	char *row = malloc(capacity);
	if (row == NULL) {
		json_decref(result);
		return NULL;
	}
	size_t n = (size_t)snprintf(row, capacity, "%d", index);
	char text[256];
	for (int p = 0; p < s->param_count; ++p) {
		json_t *value = sweep_run_value(s, p, index);
		sweep_csv_value(text, sizeof text, value);
		json_decref(value);
		n += (size_t)snprintf(row + n, capacity - n, ",%s", text);
	}
	for (int o = 0; o < s->output_count; ++o) {
		output_value(result, s->outputs[o], text, sizeof text);
		n += (size_t)snprintf(row + n, capacity - n, ",%s", text);
	}
	json_t *message_json = json_string(message);
	char quoted[1100];
	sweep_csv_value(quoted, sizeof quoted, message_json);
	json_decref(message_json);
	snprintf(row + n, capacity - n, ",%s,%s\n", row_status_names[status], quoted);
	json_decref(result);
	if (!s->keep_runs && pid >= 0)
		cli_remove_tree(folder);
	return row;
}

/// Runs every missing run with up to jobs children at once.
bool sweep_run_local(sweep_state *state, int jobs)
{
	const sweep *s = state->s;
	typedef struct slot {
		pid_t pid;
		int index;
		double start;
	} slot;
	slot *slots = calloc((size_t)jobs, sizeof *slots);
	if (slots == NULL)
		return false;
	int next = 0, running = 0;
	bool ok = true;
	for (;;) {
		while (running < jobs && ok) {
			while (next < s->run_count && state->rows[next] != NULL)
				++next;
			if (next >= s->run_count)
				break;
			char failure[512] = "";
			double start = cli_now_seconds();
			pid_t pid = sweep_run_start(s, state->dir, next, failure, sizeof failure);
			if (pid < 0) {
				ok = sweep_record_row(state, next, sweep_run_finish(s, state->dir, next, -1, 0, failure));
				++next;
				continue;
			}
			int k = 0;
			while (slots[k].pid != 0)
				++k;
			slots[k] = (slot){pid, next, start};
			++running;
			++next;
		}
		if (running == 0)
			break;
		int wait_status = 0;
		pid_t pid = waitpid(-1, &wait_status, 0);
		if (pid < 0) {
			if (errno == EINTR)
				continue;
			break;
		}
		for (int k = 0; k < jobs; ++k)
			if (slots[k].pid == pid) {
				sweep_record_timing(state, slots[k].index, cli_now_seconds() - slots[k].start, k);
				ok = sweep_record_row(state, slots[k].index,
				                      sweep_run_finish(s, state->dir, slots[k].index, pid, wait_status, "")) &&
				     ok;
				slots[k].pid = 0;
				--running;
			}
	}
	free(slots);
	return ok;
}

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
#include <dirent.h>
#include <sys/wait.h>
#include <unistd.h>

#include "sweep.h"

// ---------------------------------------------------------------------------
// Run folders. DIR/runs may hold the user's own files, and a DIR/runs/NNNNNN the
// user made is not the sweep's: the sweep marks the folders it makes and removes
// only marked ones, and in them only what a run writes (a file the user put there
// keeps its folder).

/// What a run writes in its folder, besides the marker.
static const char *const run_files[] = {"spec.json", "stdout.txt", "stderr.txt", NULL};
/// The command's output folder in the run's folder, and the prefix of the staging
/// folders a killed command leaves beside it (cli/output.c).
#define RUN_OUTPUT "out"
#define RUN_OUTPUT_STAGING ".out.plume-staging-"
/// DIR/runs holds this when the sweep made it.
#define RUNS_MARKER ".plume-sweep-runs"

void sweep_run_folder(const char *dir, int index, char *out, size_t size)
{
	snprintf(out, size, "%s/runs/%06d", dir, index);
}

static bool holds_file(const char *folder, const char *name)
{
	char path[PATH_MAX + 64];
	snprintf(path, sizeof path, "%s/%s", folder, name);
	struct stat info;
	return lstat(path, &info) == 0 && S_ISREG(info.st_mode);
}

bool sweep_run_folder_ours(const char *folder) { return holds_file(folder, SWEEP_RUN_MARKER); }

/// Whether folder holds nothing but its marker.
static bool only_marker(const char *folder, const char *marker)
{
	DIR *d = opendir(folder);
	if (d == NULL)
		return false;
	bool only = true;
	for (struct dirent *e; only && (e = readdir(d)) != NULL;)
		only = strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0 || strcmp(e->d_name, marker) == 0;
	closedir(d);
	return only;
}

/// Removes folder's marker and folder when nothing else is in it.
static void remove_if_only_marker(const char *folder, const char *marker)
{
	char path[PATH_MAX + 64];
	snprintf(path, sizeof path, "%s/%s", folder, marker);
	if (only_marker(folder, marker) && unlink(path) == 0)
		rmdir(folder);
}

void sweep_run_folder_remove(const char *folder)
{
	if (!sweep_run_folder_ours(folder))
		return;
	char path[PATH_MAX + 64];
	for (int i = 0; run_files[i] != NULL; ++i) {
		snprintf(path, sizeof path, "%s/%s", folder, run_files[i]);
		unlink(path);
	}
	// The command's output, and its staging folders where a killed command left them.
	snprintf(path, sizeof path, "%s/" RUN_OUTPUT, folder);
	cli_remove_tree(path);
	DIR *d = opendir(folder);
	for (struct dirent *e; d != NULL && (e = readdir(d)) != NULL;)
		if (strncmp(e->d_name, RUN_OUTPUT_STAGING, strlen(RUN_OUTPUT_STAGING)) == 0) {
			snprintf(path, sizeof path, "%s/%s", folder, e->d_name);
			if (holds_file(path, ".plume-staging-marker"))
				cli_remove_tree(path);
		}
	if (d != NULL)
		closedir(d);
	remove_if_only_marker(folder, SWEEP_RUN_MARKER);
}

void sweep_runs_remove(const char *dir)
{
	char runs[PATH_MAX + 16], folder[PATH_MAX + 300];
	snprintf(runs, sizeof runs, "%s/runs", dir);
	DIR *d = opendir(runs);
	if (d == NULL)
		return;
	for (struct dirent *e; (e = readdir(d)) != NULL;)
		if (strlen(e->d_name) == 6 && strspn(e->d_name, "0123456789") == 6) {
			snprintf(folder, sizeof folder, "%s/%s", runs, e->d_name);
			sweep_run_folder_remove(folder);
		}
	closedir(d);
	remove_if_only_marker(runs, RUNS_MARKER);
}

/// Creates a folder with the sweep's marker, or takes the existing one: any folder when
/// !ours_only (DIR/runs may be the user's), else only one with the marker (a run's
/// folder); false (message in failure) otherwise.
static bool make_own_folder(const char *path, const char *marker, bool ours_only, char *failure, size_t size)
{
	char marker_path[PATH_MAX + 64];
	snprintf(marker_path, sizeof marker_path, "%s/%s", path, marker);
	if (mkdir(path, 0777) != 0) {
		struct stat info;
		if (errno != EEXIST || stat(path, &info) != 0 || !S_ISDIR(info.st_mode)) {
			snprintf(failure, size, "cannot create %s: %s", path, strerror(errno == EEXIST ? ENOTDIR : errno));
			return false;
		}
		if (ours_only && !holds_file(path, marker)) {
			snprintf(failure, size, "%s is not this sweep's (it lacks %s): left as it is", path, marker);
			return false;
		}
		return true;
	}
	int fd = open(marker_path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
	if (fd < 0) {
		snprintf(failure, size, "cannot create %s: %s", marker_path, strerror(errno));
		return false;
	}
	close(fd);
	return true;
}

/// Writes the run's spec and starts plume on it; the pid, or -1 (message in row).
pid_t sweep_run_start(const sweep *s, const char *dir, int index, char *failure, size_t size)
{
	char folder[PATH_MAX], path[PATH_MAX + 32];
	sweep_run_folder(dir, index, folder, sizeof folder);
	sweep_run_folder_remove(folder); // what a killed attempt left
	snprintf(path, sizeof path, "%s/runs", dir);
	// DIR/runs may be the user's own (no marker): the sweep then only adds its folders.
	// (Under MPI the first runs of several ranks may create it at once.)
	if (!make_own_folder(path, RUNS_MARKER, false, failure, size) ||
	    !make_own_folder(folder, SWEEP_RUN_MARKER, true, failure, size))
		return -1;
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
	static char values[CLI_CALIBRATE_OPTION_COUNT][64];
	int n = 0;
	args[n++] = "plume";
	for (int i = 0; i < 2 && s->command->words[i] != NULL; ++i)
		args[n++] = (char *)s->command->words[i];
	if (s->command->probe == PROBE_CALIBRATION) {
		json_t *run = sweep_run_spec(s, index);
		for (int i = 0; i < CLI_CALIBRATE_OPTION_COUNT; ++i) {
			json_t *v = json_object_get(run, cli_calibrate_options[i].key);
			if (v == NULL)
				continue;
			snprintf(values[i], sizeof values[i], "%.17g", json_number_value(v));
			args[n++] = (char *)cli_calibrate_options[i].option;
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

/// The output at key in root ("a.b", "a[1]", "a[0].b"), as CSV text (empty when absent).
static void output_value(const json_t *root, const char *key, char *out, size_t size)
{
	char name[128];
	const json_t *node = root;
	for (const char *k = key; *k != '\0' && node != NULL;) {
		if (*k == '.')
			++k;
		if (*k == '[') {
			char *end = NULL;
			long i = strtol(k + 1, &end, 10);
			node = json_is_array(node) && *end == ']' && i >= 0 ? json_array_get(node, (size_t)i) : NULL;
			k = *end == ']' ? end + 1 : end;
			continue;
		}
		size_t length = strcspn(k, ".[");
		snprintf(name, sizeof name, "%.*s", (int)length, k);
		node = json_is_object(node) ? json_object_get(node, name) : NULL;
		k += length;
	}
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
	sweep_run_folder(dir, index, folder, sizeof folder);
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
		sweep_run_folder_remove(folder);
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

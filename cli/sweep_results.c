// plume sweep: DIR: sweep.json, results.csv (rewritten whole, atomically, as rows
// arrive, in index order), timings.csv; and resuming a sweep in the DIR it left.
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "sweep.h"

bool sweep_write_atomic(const char *path, const char *const *parts, int count)
{
	char temp[PATH_MAX + 16];
	snprintf(temp, sizeof temp, "%s.tmp", path);
	FILE *file = fopen(temp, "wb");
	if (file == NULL)
		return false;
	bool ok = true;
	for (int i = 0; i < count; ++i)
		if (parts[i] != NULL && fputs(parts[i], file) < 0)
			ok = false;
	ok = fflush(file) == 0 && ok;
	ok = fsync(fileno(file)) == 0 && ok;
	ok = fclose(file) == 0 && ok;
	if (ok && rename(temp, path) != 0)
		ok = false;
	if (!ok)
		unlink(temp);
	return ok;
}

static bool write_results(sweep_state *state)
{
	char path[PATH_MAX + 32];
	snprintf(path, sizeof path, "%s/results.csv", state->dir);
	const sweep *s = state->s;
	const char **parts = malloc(sizeof *parts * ((size_t)s->run_count + 1));
	if (parts == NULL)
		return false;
	parts[0] = state->header;
	for (int i = 0; i < s->run_count; ++i)
		parts[i + 1] = state->rows[i];
	bool ok = sweep_write_atomic(path, parts, s->run_count + 1);
	free(parts);
	if (!ok)
		fprintf(stderr, "plume: %s: cannot write: %s\n", path, strerror(errno));
	return ok;
}

void sweep_record_timing(const sweep_state *state, int index, double seconds, int worker)
{
	char path[PATH_MAX + 32], line[128];
	snprintf(path, sizeof path, "%s/timings.csv", state->dir);
	int fd = open(path, O_WRONLY | O_CREAT | O_APPEND, 0666);
	if (fd < 0)
		return;
	int n = snprintf(line, sizeof line, "%d,%.3f,%d\n", index, seconds, worker);
	if (write(fd, line, (size_t)n) != n) {
		// timings are informative; a failed write loses one line only
	}
	close(fd);
}

bool sweep_record_row(sweep_state *state, int index, char *row)
{
	if (row == NULL)
		return false;
	free(state->rows[index]);
	state->rows[index] = row;
	state->done++;
	return write_results(state);
}

/// The sweep document written to DIR/sweep.json: what ran, with which plume.
static char *sweep_document(const sweep *s)
{
	json_t *doc = json_object();
	json_object_set_new(doc, "plume_version", json_string(PLUME_VERSION_STRING));
	json_object_set(doc, "sweep", s->root);
	json_object_set(doc, "base_spec", s->spec);
	json_object_set_new(doc, "seed", json_integer((json_int_t)s->seed));
	json_object_set_new(doc, "runs", json_integer(s->run_count));
	char *text = json_dumps(doc, JSON_INDENT(2) | JSON_SORT_KEYS | JSON_REAL_PRECISION(17));
	json_decref(doc);
	return text;
}

/// Splits a CSV line into its first field (the index) and its status field.
bool sweep_parse_row(const char *line, int field_count, int *index, char *status, size_t size)
{
	char *end = NULL;
	long i = strtol(line, &end, 10);
	if (end == line || *end != ',')
		return false;
	*index = (int)i;
	const char *start;
	size_t length;
	if (!sweep_row_field(line, field_count - 2, &start, &length) || length >= size)
		return false;
	memcpy(status, start, length);
	status[length] = '\0';
	// Exactly field_count fields.
	return sweep_row_field(line, field_count - 1, &start, &length) &&
	       !sweep_row_field(line, field_count, &start, &length);
}

bool sweep_row_field(const char *row, int k, const char **start, size_t *length)
{
	int field = 0;
	bool quoted = false;
	const char *begin = row;
	for (const char *c = row;; ++c) {
		if (*c == '"')
			quoted = !quoted;
		else if ((*c == ',' && !quoted) || *c == '\n' || *c == '\0') {
			if (field == k) {
				*start = begin;
				*length = (size_t)(c - begin);
				return true;
			}
			++field;
			begin = c + 1;
			if (*c != ',')
				return false;
		}
	}
}

/// One sweep at a time in DIR: the lock goes with the process, however it ends.
/// False after a message naming the lock file or the folder.
static bool lock_folder(const char *dir)
{
	char path[PATH_MAX + 32];
	struct stat info;
	if (stat(dir, &info) != 0 || !S_ISDIR(info.st_mode)) {
		fprintf(stderr, "plume: %s: not a folder; -o names the folder the sweep writes\n", dir);
		return false;
	}
	snprintf(path, sizeof path, "%s/.sweep.lock", dir);
	int lock = open(path, O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
	if (lock < 0) {
		fprintf(stderr, "plume: %s: cannot create the sweep's lock: %s\n", path, strerror(errno));
		return false;
	}
	if (flock(lock, LOCK_EX | LOCK_NB) != 0) {
		if (errno == EWOULDBLOCK)
			fprintf(stderr, "plume: %s: another plume sweep is running in this folder\n", dir);
		else
			fprintf(stderr, "plume: %s: cannot lock: %s\n", path, strerror(errno));
		close(lock);
		return false;
	}
	return true; // held until the process ends
}

/// A new sweep writes these in DIR: files of the user's by these names are not replaced.
static bool holds_no_results(const char *dir)
{
	static const char *const names[] = {"results.csv", "timings.csv", "stats.json", "plots", NULL};
	char path[PATH_MAX + 32];
	for (int i = 0; names[i] != NULL; ++i) {
		snprintf(path, sizeof path, "%s/%s", dir, names[i]);
		struct stat info;
		if (lstat(path, &info) == 0) {
			fprintf(stderr,
			        "plume: %s exists, but %s holds no sweep.json: it is not a sweep's, and a sweep would replace "
			        "it; move it away or choose another folder\n",
			        path, dir);
			return false;
		}
	}
	return true;
}

/// DIR/runs/NNNNNN of a run still to do must be absent or the sweep's own (its marker):
/// a folder the user made there is refused rather than written into or removed.
static bool runs_folder_free(const sweep_state *state)
{
	char runs[PATH_MAX + 16], folder[PATH_MAX + 300];
	snprintf(runs, sizeof runs, "%s/runs", state->dir);
	struct stat info;
	if (lstat(runs, &info) != 0)
		return true;
	if (stat(runs, &info) != 0 || !S_ISDIR(info.st_mode)) { // a link to a folder will do
		fprintf(stderr, "plume: %s: not a folder; the sweep keeps its runs' folders there\n", runs);
		return false;
	}
	DIR *d = opendir(runs);
	if (d == NULL) {
		fprintf(stderr, "plume: %s: cannot read: %s\n", runs, strerror(errno));
		return false;
	}
	bool ok = true;
	for (struct dirent *e; ok && (e = readdir(d)) != NULL;) {
		if (strlen(e->d_name) != 6 || strspn(e->d_name, "0123456789") != 6)
			continue;
		long index = strtol(e->d_name, NULL, 10);
		if (index >= state->s->run_count || state->rows[index] != NULL)
			continue;
		snprintf(folder, sizeof folder, "%s/%s", runs, e->d_name);
		if (!sweep_run_folder_ours(folder)) {
			fprintf(stderr,
			        "plume: %s: not a run folder of this sweep (it lacks %s), and run %ld would write there: "
			        "move it away or choose another folder\n",
			        folder, SWEEP_RUN_MARKER, index);
			ok = false;
		}
	}
	closedir(d);
	return ok;
}

/// Creates DIR or, when it holds this same sweep, reads the rows already done.
/// False after a message; *code says why (CLI_EXIT_INPUT: DIR holds another sweep;
/// CLI_EXIT_IO: DIR cannot be written, or writing it would replace files not the sweep's).
bool sweep_state_begin(int *code, sweep_state *state, const sweep *s, const char *dir)
{
	memset(state, 0, sizeof *state);
	*code = CLI_EXIT_IO;
	state->s = s;
	state->dir = dir;
	state->rows = calloc((size_t)s->run_count, sizeof *state->rows);
	if (state->rows == NULL)
		return false;
	size_t n = (size_t)snprintf(state->header, sizeof state->header, "index");
	for (int p = 0; p < s->param_count; ++p)
		n += (size_t)snprintf(state->header + n, sizeof state->header - n, ",%s", s->params[p].name);
	for (int o = 0; o < s->output_count; ++o)
		n += (size_t)snprintf(state->header + n, sizeof state->header - n, ",%s", s->outputs[o]);
	snprintf(state->header + n, sizeof state->header - n, ",status,message\n");
	int field_count = 1 + s->param_count + s->output_count + 2;

	char path[PATH_MAX + 32];
	char *document = sweep_document(s);
	int made, failure = cli_make_parents(dir, &made);
	if (failure != 0) {
		fprintf(stderr, "plume: %.*s: cannot create: %s\n", made, dir, strerror(failure));
		free(document);
		return false;
	}
	if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
		fprintf(stderr, "plume: %s: cannot create: %s\n", dir, strerror(errno));
		free(document);
		return false;
	}
	if (!lock_folder(dir)) {
		free(document);
		return false;
	}
	snprintf(path, sizeof path, "%s/sweep.json", dir);
	FILE *file = fopen(path, "rb");
	if (file != NULL) {
		// A resumed sweep: it must be the same sweep.
		char *existing = malloc(strlen(document) + 2);
		size_t got = existing ? fread(existing, 1, strlen(document) + 1, file) : 0;
		fclose(file);
		bool same = existing != NULL && got == strlen(document) + 1 && existing[got - 1] == '\n' &&
		            memcmp(existing, document, got - 1) == 0;
		free(existing);
		if (!same) {
			fprintf(stderr,
			        "plume: %s holds another sweep (its sweep.json differs): resume only with the same sweep, "
			        "spec and plume version, or choose another folder\n",
			        dir);
			free(document);
			*code = CLI_EXIT_INPUT;
			return false;
		}
		snprintf(path, sizeof path, "%s/results.csv", dir);
		file = fopen(path, "rb");
		if (file != NULL) {
			char *line = NULL;
			size_t capacity = 0;
			ssize_t length = getline(&line, &capacity, file);
			if (length < 0 || strcmp(line, state->header) != 0) {
				fprintf(stderr, "plume: %s: the header is not this sweep's\n", path);
				free(line);
				fclose(file);
				free(document);
				return false;
			}
			while ((length = getline(&line, &capacity, file)) > 0) {
				int index;
				char status[16];
				// A run killed by a signal may have been killed from outside: run it again.
				if (sweep_parse_row(line, field_count, &index, status, sizeof status) && index >= 0 &&
				    index < s->run_count && state->rows[index] == NULL && strcmp(status, "signal") != 0) {
					state->rows[index] = strdup(line);
					state->done++;
				}
			}
			free(line);
			fclose(file);
		}
		if (!runs_folder_free(state)) {
			free(document);
			return false;
		}
	} else {
		const char *parts[2] = {document, "\n"};
		if (!holds_no_results(dir) || !runs_folder_free(state)) {
			free(document);
			return false;
		}
		if (!sweep_write_atomic(path, parts, 2)) {
			fprintf(stderr, "plume: %s: cannot write: %s\n", path, strerror(errno));
			free(document);
			return false;
		}
	}
	free(document);
	return write_results(state);
}

void sweep_state_end(sweep_state *state)
{
	for (int i = 0; state->rows != NULL && i < state->s->run_count; ++i)
		free(state->rows[i]);
	free(state->rows);
}

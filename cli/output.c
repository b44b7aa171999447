// Output sets: all files of one run appear together or not at all.
#define _GNU_SOURCE // renameat2
#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

int cli_fail(const plume_error *err)
{
	fprintf(stderr, "plume: %s\n", err->message);
	switch (err->status) {
	case PLUME_OK: return CLI_EXIT_OK;
	case PLUME_ERROR_IO: return CLI_EXIT_IO;
	case PLUME_ERROR_SYNTAX:
	case PLUME_ERROR_SPEC: return CLI_EXIT_INPUT;
	case PLUME_ERROR_LIMIT: return CLI_EXIT_LIMIT;
	default: return CLI_EXIT_FAILURE;
	}
}

bool cli_check_arguments(const char *command, int argc, char **argv, const char *input, const char *output_dir)
{
	if (optind >= argc)
		cli_usage_error(command, "missing %s", input);
	else if (optind + 1 < argc)
		cli_usage_error(command, "unexpected argument '%s'", argv[optind + 1]);
	else if (output_dir == NULL)
		cli_usage_error(command, "missing -o DIR");
	else
		return true;
	return false;
}

bool cli_parse_style(const char *command, const char *text, plume_render_style *style)
{
	if (strcmp(text, "lines") == 0)
		*style = PLUME_STYLE_LINES;
	else if (strcmp(text, "strips") == 0)
		*style = PLUME_STYLE_STRIPS;
	else {
		cli_usage_error(command, "--style '%s': allowed lines, strips", text);
		return false;
	}
	return true;
}

int cli_usage_error(const char *command, const char *format, ...)
{
	va_list args;
	va_start(args, format);
	fprintf(stderr, "plume: %s: ", command);
	vfprintf(stderr, format, args);
	fprintf(stderr, "\nTry 'plume help %s'.\n", command);
	va_end(args);
	return CLI_EXIT_USAGE;
}

static const struct {
	const char *name;
	unsigned bit;
} format_names[] = {
    {"png", CLI_FORMAT_PNG},   {"svg", CLI_FORMAT_SVG},   {"pdf", CLI_FORMAT_PDF}, {"obj", CLI_FORMAT_OBJ},
    {"usda", CLI_FORMAT_USDA}, {"json", CLI_FORMAT_JSON}, {"glb", CLI_FORMAT_GLB},
};

void cli_format_list(unsigned formats, char *text, size_t size)
{
	if (size > 0)
		text[0] = '\0';
	for (size_t i = 0; i < sizeof format_names / sizeof format_names[0]; ++i)
		if ((formats & format_names[i].bit) != 0)
			snprintf(text + strlen(text), size - strlen(text), "%s%s", text[0] != '\0' ? ", " : "",
			         format_names[i].name);
}

bool cli_parse_formats(const char *command, const char *list, unsigned *formats)
{
	*formats = 0;
	// An empty item ("png,", ",png", "png,,obj") is a typo, not a format: refused wherever it is.
	size_t size = strlen(list);
	if (size > 0 && (list[0] == ',' || list[size - 1] == ',' || strstr(list, ",,") != NULL)) {
		cli_usage_error(command, "--format '%s' has an empty item; allowed: png, svg, pdf, obj, usda, json, glb", list);
		return false;
	}
	const char *cursor = list;
	while (*cursor != '\0') {
		size_t length = strcspn(cursor, ",");
		bool known = false;
		for (size_t i = 0; i < sizeof format_names / sizeof format_names[0]; ++i) {
			if (strlen(format_names[i].name) == length && strncmp(cursor, format_names[i].name, length) == 0) {
				*formats |= format_names[i].bit;
				known = true;
			}
		}
		if (!known) {
			cli_usage_error(command, "unknown format '%.*s' in --format; allowed: png, svg, pdf, obj, usda, json, glb",
			                (int)length, cursor);
			return false;
		}
		cursor += length;
		if (*cursor == ',')
			++cursor;
	}
	if (*formats == 0) {
		cli_usage_error(command, "--format needs at least one of png, svg, pdf, obj, usda, json, glb");
		return false;
	}
	return true;
}

bool cli_parse_size(const char *command, const char *text, int *width, int *height)
{
	char tail;
	if (sscanf(text, "%dx%d%c", width, height, &tail) != 2 || *width < 16 || *width > 16384 || *height < 16 ||
	    *height > 16384) {
		cli_usage_error(command, "--size '%s' must be WxH in pixels, each in [16, 16384]", text);
		return false;
	}
	return true;
}

int cli_image_width(double w, double h, int height, double margin)
{
	if (!(h > 0.0))
		return height;
	// Clamped as a double: a flat feather's w / h (a 200 m span over a 1e-6 m rachis) is past an int.
	double width = height * (1.0 - 2.0 * margin) * w / h + 2.0 * margin * height + 0.5;
	return !(width >= 256.0) ? 256 : (width > 4096.0 ? 4096 : (int)width);
}

bool cli_parse_seed(const char *command, const char *text, uint64_t *seed)
{
	char *end;
	errno = 0;
	unsigned long long value = strtoull(text, &end, 10);
	if (errno != 0 || end == text || *end != '\0' || text[0] == '-') {
		cli_usage_error(command, "--seed '%s' must be a non-negative integer below 2^64", text);
		return false;
	}
	*seed = value;
	return true;
}

bool cli_parse_memory(const char *command, const char *text, uint64_t *bytes)
{
	char *end;
	errno = 0;
	double value = strtod(text, &end);
	double unit = 1.0;
	switch (*end) {
	case 'K':
	case 'k':
		unit = 1024.0;
		++end;
		break;
	case 'M':
	case 'm':
		unit = 1048576.0;
		++end;
		break;
	case 'G':
	case 'g':
		unit = 1073741824.0;
		++end;
		break;
	case 'T':
	case 't':
		unit = 1099511627776.0;
		++end;
		break;
	default: break;
	}
	if (*end == 'B' || *end == 'b')
		++end;
	double total = value * unit;
	if (errno != 0 || end == text || *end != '\0' || !(total >= 1048576.0 && total <= 1e18)) {
		cli_usage_error(command, "--max-memory '%s' must be a size such as 512M, 8G or 1T, at least 1M", text);
		return false;
	}
	*bytes = (uint64_t)total;
	return true;
}

// ---------------------------------------------------------------------------
// Staging
//
// A run writes into a staging folder beside DIR, ".NAME.plume-staging-PID-XXXXXX"
// (same parent, so the same file system). When every file is written:
//  - a new DIR: the staging folder is renamed to DIR;
//  - an existing DIR: every entry of DIR the run does not write, and the earlier
//    run did not write either (its manifest, RUN_MANIFEST, below), is hard-linked
//    into the staging folder (a folder the run writes too, such as frames/, is
//    merged: the user's files in it are linked, the earlier run's are not), then
//    renameat2(RENAME_EXCHANGE) swaps the two folders in one step and
//    the earlier run, now under the staging name, is removed. The user's files
//    live on through their second link; nothing plume did not write is lost,
//    and a reader sees the whole earlier run or the whole new one, never a mix.
// Without RENAME_EXCHANGE (a kernel or file system without it) DIR is renamed
// aside and the staging folder renamed into place: two renames with a moment
// in between where DIR is absent, but never mixed. Without hard links (vfat),
// or for another user's file the kernel will not let plume link
// (fs.protected_hardlinks), the run fails and DIR keeps the earlier run. When
// the parent folder is not writable, the staging folder goes inside DIR and
// entries move one by one (the user's files in the run's folders linked in
// first), and then the earlier run's other files are removed.
//
// Interrupted runs. Each staging folder holds a marker file, STAGING_MARKER, that
// says "plume staging", the PID and that process's start time. SIGINT and SIGTERM
// during a run remove the run's staging folders (cli_output_begin installs the
// handler) and then end plume by the same signal, so DIR keeps the earlier run
// and nothing is left beside it. What no handler sees (SIGKILL, a crash, a power
// cut) is cleaned by the next run into the same DIR: it removes a folder beside
// DIR (or inside it, where a run staged there) only when its name has the staging
// pattern, its marker is plume's and names this name's PID, and that process is
// gone (or the PID now belongs to a process that started at another time). A
// folder without a valid marker is never touched, whatever its name.

void cli_remove_tree(const char *path)
{
	struct stat link_info;
	if (lstat(path, &link_info) == 0 && S_ISLNK(link_info.st_mode)) {
		unlink(path); // never into what a link points at
		return;
	}
	DIR *dir = opendir(path);
	if (dir != NULL) {
		struct dirent *entry;
		while ((entry = readdir(dir)) != NULL) {
			if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0)
				continue;
			char child[4352];
			snprintf(child, sizeof child, "%s/%s", path, entry->d_name);
			struct stat info;
			if (lstat(child, &info) == 0 && S_ISDIR(info.st_mode))
				cli_remove_tree(child);
			else
				unlink(child);
		}
		closedir(dir);
		rmdir(path);
	} else {
		unlink(path);
	}
}

// The marker file in every staging folder; its name starts like the staging
// folders' so that a marker left in DIR by a run killed mid-commit is never
// carried into the next run (carry_over skips the pattern).
#define STAGING_MARKER ".plume-staging-marker"
#define STAGING_MARKER_HEADER "plume staging folder"

/// When process pid started, in clock ticks after boot (/proc/PID/stat, field 22), or 0
/// when it cannot be read (no /proc, or no such process).
static unsigned long long process_start(long pid)
{
	char path[64], text[1024];
	snprintf(path, sizeof path, "/proc/%ld/stat", pid);
	FILE *file = fopen(path, "r");
	if (file == NULL)
		return 0;
	size_t n = fread(text, 1, sizeof text - 1, file);
	fclose(file);
	text[n] = '\0';
	// The command name (field 2) is in parentheses and may hold spaces: count from the last ')'.
	const char *at = strrchr(text, ')');
	if (at == NULL)
		return 0;
	unsigned long long start = 0;
	for (int field = 2; field < 22 && at != NULL; ++field)
		at = strchr(at + 1, ' ');
	if (at == NULL || sscanf(at + 1, "%llu", &start) != 1)
		return 0;
	return start;
}

/// Writes the marker of a new staging folder. 0 or an errno.
static int write_marker(const char *stage)
{
	char path[4352];
	snprintf(path, sizeof path, "%s/" STAGING_MARKER, stage);
	FILE *file = fopen(path, "w");
	if (file == NULL)
		return errno;
	long pid = (long)getpid();
	fprintf(file, STAGING_MARKER_HEADER "\npid %ld\nstart %llu\n", pid, process_start(pid));
	return fclose(file) == 0 ? 0 : errno;
}

/// Whether the staging folder path, named with pid, holds a valid marker of that
/// pid and that run is over (the process is gone, or the PID was reused since).
static bool marker_says_dead(const char *path, long pid)
{
	char marker[4672], text[256];
	snprintf(marker, sizeof marker, "%s/" STAGING_MARKER, path);
	struct stat info;
	if (lstat(marker, &info) != 0 || !S_ISREG(info.st_mode) || info.st_size >= (off_t)sizeof text)
		return false;
	FILE *file = fopen(marker, "r");
	if (file == NULL)
		return false;
	size_t n = fread(text, 1, sizeof text - 1, file);
	fclose(file);
	text[n] = '\0';
	long marker_pid = 0;
	unsigned long long start = 0;
	int used = 0;
	if (sscanf(text, STAGING_MARKER_HEADER "\npid %ld\nstart %llu\n%n", &marker_pid, &start, &used) != 2 ||
	    (size_t)used != n || marker_pid != pid)
		return false;
	if (kill((pid_t)pid, 0) != 0)
		return errno == ESRCH;
	// A live process with that PID: the run is over when it started at another time.
	unsigned long long now = process_start(pid);
	return start != 0 && now != 0 && now != start;
}

/// True for a folder "PREFIX<pid>-XXXXXX" of ours whose run is over (marker_says_dead).
static bool stale_staging(const char *parent, const char *name, const char *prefix)
{
	size_t length = strlen(prefix);
	if (strncmp(name, prefix, length) != 0)
		return false;
	char *end;
	errno = 0;
	long pid = strtol(name + length, &end, 10);
	if (errno != 0 || end == name + length || pid <= 0 || *end != '-' || strlen(end + 1) != 6 || pid == (long)getpid())
		return false;
	char path[4608];
	snprintf(path, sizeof path, "%s/%s", parent, name);
	struct stat info;
	return lstat(path, &info) == 0 && S_ISDIR(info.st_mode) && info.st_uid == geteuid() && marker_says_dead(path, pid);
}

/// Removes staging folders an earlier, dead plume left beside DIR (and, where a
/// run staged inside DIR, those in it).
static void remove_stale_staging(const char *parent, const char *prefix)
{
	DIR *dir = opendir(parent);
	if (dir == NULL)
		return;
	struct dirent *entry;
	while ((entry = readdir(dir)) != NULL) {
		if (!stale_staging(parent, entry->d_name, prefix))
			continue;
		char path[4608];
		snprintf(path, sizeof path, "%s/%s", parent, entry->d_name);
		cli_remove_tree(path);
	}
	closedir(dir);
}

// ---------------------------------------------------------------------------
// Interruption: SIGINT and SIGTERM remove the staging folders of the runs under
// way. The handler may run on any thread at any moment, so it uses only
// async-signal-safe calls (openat, getdents64, unlinkat, close, signal, raise) on
// paths copied into static storage before the handler could need them, and while
// a commit is swapping folders it only notes the signal: the commit finishes (DIR
// then holds one whole run) and re-raises it.

enum { MAX_ACTIVE_STAGES = 4 };
static char active_stage[MAX_ACTIVE_STAGES][sizeof((cli_output *)0)->stage];
static _Atomic int active_used[MAX_ACTIVE_STAGES];
static _Atomic int committing;
static _Atomic int pending_signal;

/// Removes name (a file or a folder tree) in the folder at_fd. Async-signal-safe.
static void remove_at(int at_fd, const char *name, int depth)
{
	if (unlinkat(at_fd, name, 0) == 0 || (errno != EISDIR && errno != EPERM) || depth > 16)
		return;
	int fd = openat(at_fd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
	if (fd < 0)
		return;
	char buffer[4096];
	// Read from the start again after each batch: entries are removed as they are read.
	for (;;) {
		lseek(fd, 0, SEEK_SET);
		ssize_t n = getdents64(fd, buffer, sizeof buffer);
		bool removed = false;
		for (ssize_t at = 0; at < n;) {
			struct dirent64 *entry = (struct dirent64 *)(buffer + at);
			at += entry->d_reclen;
			if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0)
				continue;
			remove_at(fd, entry->d_name, depth + 1);
			removed = true;
		}
		if (!removed)
			break;
	}
	close(fd);
	unlinkat(at_fd, name, AT_REMOVEDIR);
}

/// Another thread may still be writing a file into the folder while the handler empties it
/// (the signal can land on any thread): a few passes, until the folder itself is gone.
static void remove_active_stages(void)
{
	for (int i = 0; i < MAX_ACTIVE_STAGES; ++i) {
		struct stat info;
		for (int pass = 0;
		     pass < 8 && active_used[i] && fstatat(AT_FDCWD, active_stage[i], &info, AT_SYMLINK_NOFOLLOW) == 0; ++pass)
			remove_at(AT_FDCWD, active_stage[i], 0);
	}
}

static void on_interrupt(int signal_number)
{
	int saved = errno;
	if (committing) {
		pending_signal = signal_number;
		errno = saved;
		return;
	}
	remove_active_stages();
	signal(signal_number, SIG_DFL);
	raise(signal_number); // delivered when the handler returns: plume ends by the signal
	errno = saved;
}

/// Installs on_interrupt for SIGINT and SIGTERM, except where they are ignored
/// (nohup, a background job of a shell without job control): that choice stands.
static void install_interrupt_handler(void)
{
	static bool installed;
	if (installed)
		return;
	installed = true;
	int signals[] = {SIGINT, SIGTERM};
	for (size_t i = 0; i < sizeof signals / sizeof signals[0]; ++i) {
		struct sigaction old;
		if (sigaction(signals[i], NULL, &old) != 0 || old.sa_handler == SIG_IGN)
			continue;
		struct sigaction action;
		memset(&action, 0, sizeof action);
		action.sa_handler = on_interrupt;
		sigemptyset(&action.sa_mask);
		action.sa_flags = SA_RESTART;
		sigaction(signals[i], &action, NULL);
	}
}

/// Remembers output's staging folder for on_interrupt (with more than
/// MAX_ACTIVE_STAGES at once, the others are left to the next run's clean-up).
static void track_stage(cli_output *output)
{
	for (int i = 0; i < MAX_ACTIVE_STAGES; ++i)
		if (!active_used[i]) {
			memcpy(active_stage[i], output->stage, sizeof active_stage[i]);
			active_used[i] = 1;
			output->stage_slot = i + 1;
			return;
		}
}

static void untrack_stage(cli_output *output)
{
	if (output->stage_slot > 0)
		active_used[output->stage_slot - 1] = 0;
	output->stage_slot = 0;
}

/// Brackets the part of a commit that swaps folders: a signal in it waits for its end.
static void begin_critical(void) { committing = 1; }

static void end_critical(void)
{
	committing = 0;
	int signal_number = pending_signal;
	if (signal_number != 0) {
		remove_active_stages();
		signal(signal_number, SIG_DFL);
		raise(signal_number);
	}
}

/// mkdtemp of output->stage, then its tracking and marker, with a signal held back
/// until all three are done (so no folder is left unmarked). On failure the folder,
/// if made (*made), is removed again.
static plume_status make_stage(cli_output *output, bool *made, plume_error *err)
{
	install_interrupt_handler();
	begin_critical();
	int failure = 0;
	*made = mkdtemp(output->stage) != NULL;
	if (!*made) {
		failure = errno;
	} else {
		track_stage(output);
		failure = write_marker(output->stage);
	}
	end_critical();
	if (failure == 0)
		return PLUME_OK;
	if (*made)
		cli_output_abort(output, NULL);
	return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write the output folder: %s", output->dir,
	                       strerror(failure));
}

/// Stages inside DIR itself (mkdtemp fills in the XXXXXX), for a DIR that cannot be
/// swapped whole: the run's files are then moved in entry by entry.
static plume_status stage_inside_dir(cli_output *output, plume_error *err)
{
	output->stage_inside = true;
	snprintf(output->stage, sizeof output->stage, "%s/.plume-staging-%ld-XXXXXX", output->dir, (long)getpid());
	bool made;
	return make_stage(output, &made, err);
}

void cli_remove_parents(const char *path, int made)
{
	if (made == 0)
		return;
	char folder[PATH_MAX];
	snprintf(folder, sizeof folder, "%s", path);
	for (char *slash = strrchr(folder, '/'); slash != NULL; slash = strrchr(folder, '/')) {
		*slash = '\0';
		if ((int)strlen(folder) < made || rmdir(folder) != 0)
			break;
	}
}

plume_status cli_check_output_memory(const char *spec, const char *held_name, unsigned formats, const char *options,
                                     double outputs, uint64_t max_memory, plume_error *err)
{
	double limit = (double)(max_memory > 0 ? max_memory : PLUME_DEFAULT_MAX_MEMORY);
	double held = (double)plume_bytes_in_use();
	if (held + outputs <= limit)
		return PLUME_OK;
	char list[64];
	cli_format_list(formats, list, sizeof list);
	return plume_error_set(err, PLUME_ERROR_LIMIT,
	                       "%s: writing %s (--format%s) takes up to %.3g GB besides the %s's %.3g GB: %.3g GB in all; "
	                       "the limit is %.3g GB (raise it with --max-memory, or write fewer or smaller formats)",
	                       spec, list, options, outputs / 1e9, held_name, held / 1e9, (held + outputs) / 1e9,
	                       limit / 1e9);
}

int cli_make_parents(const char *path, int *made)
{
	*made = 0;
	char folder[PATH_MAX];
	if (snprintf(folder, sizeof folder, "%s", path) >= (int)sizeof folder)
		return ENAMETOOLONG;
	for (char *slash = strchr(folder + 1, '/'); slash != NULL; slash = strchr(slash + 1, '/')) {
		*slash = '\0';
		int failure = mkdir(folder, 0777) == 0 ? 0 : errno;
		if (failure == 0 && *made == 0)
			*made = (int)strlen(folder);
		if (failure != 0 && failure != EEXIST) {
			cli_remove_parents(path, *made);
			*made = (int)(slash - folder); // the folder that could not be made, for the message
			return failure;
		}
		*slash = '/';
	}
	return 0;
}

plume_status cli_output_begin(cli_output *output, const char *dir, plume_error *err)
{
	memset(output, 0, sizeof *output);
	size_t length = strlen(dir);
	while (length > 1 && dir[length - 1] == '/')
		--length;
	if (length == 0 || length + 64 >= sizeof output->dir)
		return plume_error_set(err, PLUME_ERROR_IO, "'%s': not a usable output folder", dir);
	memcpy(output->dir, dir, length);
	output->dir[length] = '\0';

	struct stat info;
	if (stat(output->dir, &info) == 0) {
		if (!S_ISDIR(info.st_mode))
			return plume_error_set(err, PLUME_ERROR_IO, "%s: exists and is not a folder", output->dir);
		output->dir_existed = true;
	} else {
		// "Created if missing": a nested new DIR with its missing parents (mkdir -p).
		int failure = cli_make_parents(output->dir, &output->parents_made);
		if (failure != 0)
			return plume_error_set(err, PLUME_ERROR_IO, "%.*s: cannot make the folder: %s", output->parents_made,
			                       output->dir, strerror(failure));
	}
	// DIR named "." or ".." (or ending in "/." or "/.."): its last component is no name in its
	// parent, so the staging folder "beside" it went inside it (or below it), and linking DIR's
	// files into the staging folder recursed into itself. The folder's own path instead.
	const char *last = strrchr(output->dir, '/');
	last = last != NULL ? last + 1 : output->dir;
	if (output->dir_existed && (strcmp(last, ".") == 0 || strcmp(last, "..") == 0)) {
		char resolved[PATH_MAX];
		if (realpath(output->dir, resolved) == NULL || strlen(resolved) + 64 >= sizeof output->dir)
			return plume_error_set(err, PLUME_ERROR_IO, "'%s': not a usable output folder", dir);
		memcpy(output->dir, resolved, strlen(resolved) + 1); // fits: checked above
	}
	const char *slash = strrchr(output->dir, '/');
	int parent = slash != NULL ? (int)(slash - output->dir + 1) : 0;
	char prefix[2200], parent_dir[2100];
	snprintf(prefix, sizeof prefix, ".%s.plume-staging-", output->dir + parent);
	snprintf(parent_dir, sizeof parent_dir, "%.*s", parent > 0 ? parent : 1, parent > 0 ? output->dir : ".");
	remove_stale_staging(parent_dir, prefix);
	if (output->dir_existed)
		remove_stale_staging(output->dir, ".plume-staging-");
	// DIR a symbolic link to a folder: swapping would replace the link, not the
	// folder; stage inside the folder it names and move entry by entry instead.
	struct stat link_info;
	if (output->dir_existed && lstat(output->dir, &link_info) == 0 && S_ISLNK(link_info.st_mode)) {
		return stage_inside_dir(output, err);
	}
	snprintf(output->stage, sizeof output->stage, "%.*s%s%ld-XXXXXX", parent, output->dir, prefix, (long)getpid());
	bool made;
	plume_status status = make_stage(output, &made, err);
	if (status != PLUME_OK && !output->dir_existed)
		cli_remove_parents(output->dir, output->parents_made);
	if (status == PLUME_OK || made || !output->dir_existed)
		return status;
	// An existing DIR in a parent we may not write: stage inside DIR, move entry by entry.
	return stage_inside_dir(output, err);
}

const char *cli_output_path(cli_output *output, const char *name, char *buffer, size_t size)
{
	if (output->name_count < (int)(sizeof output->names / sizeof output->names[0])) {
		snprintf(output->names[output->name_count], sizeof output->names[0], "%s", name);
		output->name_count++;
	}
	snprintf(buffer, size, "%s/%s", output->stage, name);
	return buffer;
}

// ---------------------------------------------------------------------------
// The run manifest: RUN_MANIFEST in DIR lists every file and folder the last run
// wrote (paths relative to DIR, folders with a trailing '/', one a line, sorted),
// so that the next run into DIR replaces exactly those and keeps everything else,
// whatever its name. A DIR without one (written by a plume that wrote none, or only
// by `plume render --frames`) falls back to the old rule: in a folder of the run, a
// file whose name starts with a digit is an earlier run's frame.

#define RUN_MANIFEST ".plume-run"
#define RUN_MANIFEST_HEADER "plume run manifest 1"

typedef struct manifest {
	bool present;     ///< DIR had a manifest (otherwise the old rule applies)
	bool keep_all;    ///< its run was another command's: nothing in it is replaced but by name
	char command[32]; ///< the command that wrote it ("simulate", "render", ...), or ""
	char **paths;     ///< sorted
	size_t count, capacity;
} manifest;

/// This run's command, argv[1] ("generate", "render", ...), from /proc/self/cmdline; ""
/// where that cannot be read (then every earlier run counts as this command's).
static const char *run_command(void)
{
	static char command[32];
	static bool known;
	if (known)
		return command;
	known = true;
	char text[512];
	FILE *file = fopen("/proc/self/cmdline", "rb");
	size_t n = file != NULL ? fread(text, 1, sizeof text - 1, file) : 0;
	if (file != NULL)
		fclose(file);
	text[n] = '\0';
	size_t first = strlen(text); // argv[0], then its NUL
	if (first + 1 < n)
		snprintf(command, sizeof command, "%s", text + first + 1);
	if (strspn(command, "abcdefghijklmnopqrstuvwxyz-") != strlen(command))
		command[0] = '\0';
	return command;
}

static void manifest_free(manifest *m)
{
	for (size_t i = 0; i < m->count; ++i)
		free(m->paths[i]);
	free(m->paths);
	memset(m, 0, sizeof *m);
}

/// Adds a copy of path. 0 or ENOMEM.
static int manifest_add(manifest *m, const char *path)
{
	if (m->count == m->capacity) {
		size_t capacity = m->capacity > 0 ? 2 * m->capacity : 64;
		char **grown = realloc(m->paths, capacity * sizeof *grown);
		if (grown == NULL)
			return ENOMEM;
		m->paths = grown;
		m->capacity = capacity;
	}
	if ((m->paths[m->count] = strdup(path)) == NULL)
		return ENOMEM;
	m->count++;
	return 0;
}

static int compare_paths(const void *a, const void *b)
{
	return strcmp(*(const char *const *)a, *(const char *const *)b);
}

static bool manifest_has(const manifest *m, const char *path)
{
	return m->count > 0 && bsearch(&path, m->paths, m->count, sizeof *m->paths, compare_paths) != NULL;
}

/// Reads DIR's manifest; a DIR without one (or with one plume cannot read) leaves m
/// not present. 0 or ENOMEM.
static int manifest_read(const char *dir, manifest *m)
{
	memset(m, 0, sizeof *m);
	char path[4352], line[4352];
	snprintf(path, sizeof path, "%s/" RUN_MANIFEST, dir);
	struct stat info;
	if (lstat(path, &info) != 0 || !S_ISREG(info.st_mode))
		return 0;
	FILE *file = fopen(path, "r");
	if (file == NULL)
		return 0;
	// "plume run manifest 1 COMMAND" (COMMAND absent: unknown).
	size_t prefix = strlen(RUN_MANIFEST_HEADER);
	bool header = fgets(line, sizeof line, file) != NULL && strncmp(line, RUN_MANIFEST_HEADER, prefix) == 0 &&
	              (line[prefix] == '\n' || line[prefix] == ' ');
	if (header && line[prefix] == ' ')
		snprintf(m->command, sizeof m->command, "%.*s", (int)strcspn(line + prefix + 1, "\n"), line + prefix + 1);
	int failure = 0;
	while (header && failure == 0 && fgets(line, sizeof line, file) != NULL) {
		size_t length = strlen(line);
		if (length > 0 && line[length - 1] != '\n' && !feof(file)) { // an overlong line names nothing of ours
			while (fgets(line, sizeof line, file) != NULL && line[strlen(line) - 1] != '\n')
				;
			continue;
		}
		if (length < 2 || line[length - 1] != '\n')
			continue; // an empty line, or the last one cut short
		line[length - 1] = '\0';
		failure = manifest_add(m, line);
	}
	fclose(file);
	m->present = header && failure == 0;
	if (m->present)
		qsort(m->paths, m->count, sizeof *m->paths, compare_paths);
	else
		manifest_free(m);
	return failure;
}

/// Lists the tree at dir into m (relative to the run's folder, after prefix), leaving
/// out the staging marker and the manifest. 0 or an errno.
static int manifest_list(const char *dir, const char *prefix, manifest *m)
{
	DIR *folder = opendir(dir);
	if (folder == NULL)
		return errno;
	int failure = 0;
	struct dirent *entry;
	while (failure == 0 && (entry = readdir(folder)) != NULL) {
		const char *name = entry->d_name;
		if (strcmp(name, ".") == 0 || strcmp(name, "..") == 0 || strchr(name, '\n') != NULL ||
		    (prefix[0] == '\0' && (strcmp(name, STAGING_MARKER) == 0 || strcmp(name, RUN_MANIFEST) == 0)))
			continue;
		char path[4608], relative[4352];
		snprintf(path, sizeof path, "%s/%s", dir, name);
		struct stat info;
		if (lstat(path, &info) != 0)
			continue;
		bool folder_entry = S_ISDIR(info.st_mode);
		snprintf(relative, sizeof relative, "%s%s%s", prefix, name, folder_entry ? "/" : "");
		failure = manifest_add(m, relative);
		if (failure == 0 && folder_entry)
			failure = manifest_list(path, relative, m);
	}
	closedir(folder);
	return failure;
}

/// Writes the manifest of what the staging folder holds into it. 0 or an errno.
static int write_manifest(const char *stage)
{
	manifest m = {0};
	int failure = manifest_list(stage, "", &m);
	if (failure == 0) {
		qsort(m.paths, m.count, sizeof *m.paths, compare_paths);
		char path[4352];
		snprintf(path, sizeof path, "%s/" RUN_MANIFEST, stage);
		FILE *file = fopen(path, "w");
		if (file == NULL) {
			failure = errno;
		} else {
			fprintf(file, RUN_MANIFEST_HEADER "%s%s\n", run_command()[0] != '\0' ? " " : "", run_command());
			for (size_t i = 0; i < m.count; ++i)
				fprintf(file, "%s\n", m.paths[i]);
			if (fclose(file) != 0)
				failure = errno;
		}
	}
	manifest_free(&m);
	return failure;
}

plume_status cli_output_manifest_add(const char *dir, const char *folder, const char *const *names, int count,
                                     plume_error *err)
{
	char path[4352];
	snprintf(path, sizeof path, "%s/" RUN_MANIFEST, dir);
	// Only a manifest of this command's run: another command's keeps to its own files
	// (other_command), and these stay files it does not replace.
	manifest earlier;
	if (manifest_read(dir, &earlier) != 0)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	bool ours = earlier.present && strcmp(earlier.command, run_command()) == 0;
	manifest_free(&earlier);
	if (!ours)
		return PLUME_OK;
	int fd = open(path, O_WRONLY | O_APPEND | O_NOFOLLOW | O_CLOEXEC);
	if (fd < 0)
		return errno == ENOENT ? PLUME_OK
		                       : plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
	// One write for all the lines: runs appending at once (ranges rendered in parallel) do not interleave.
	// The folder too (listed again when the earlier run had it: the reader takes either).
	size_t size = 0, capacity = (size_t)count * 80 + strlen(folder) + 80;
	char *text = malloc(capacity);
	plume_status status = text != NULL ? PLUME_OK : plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	if (status == PLUME_OK)
		size = (size_t)sprintf(text, "%s/\n", folder);
	for (int i = 0; i < count && status == PLUME_OK; ++i) {
		size_t need = strlen(folder) + strlen(names[i]) + 3;
		if (size + need > capacity) {
			capacity = 2 * capacity + need;
			char *grown = realloc(text, capacity);
			if (grown == NULL) {
				status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
				break;
			}
			text = grown;
		}
		size += (size_t)sprintf(text + size, "%s/%s\n", folder, names[i]);
	}
	if (status == PLUME_OK && write(fd, text, size) != (ssize_t)size)
		status = plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
	free(text);
	close(fd);
	return status;
}

// ---------------------------------------------------------------------------
// Commit

/// The old rule, for a DIR without a manifest: a file plume writes inside a folder of a
/// run (frames/0012.obj, 0012-rt.png, ...) has a digit first.
static bool plume_frame_name(const char *name) { return name[0] >= '0' && name[0] <= '9'; }

/// Whether the entry relative (in a folder `depth` deep in DIR; folders with a trailing
/// '/') is the earlier run's: listed in DIR's manifest, or without one by the old rule.
static bool earlier_run(const manifest *earlier, const char *relative, const char *name, int depth, bool folder)
{
	if (earlier->keep_all)
		return false;
	if (earlier->present)
		return manifest_has(earlier, relative);
	return depth > 0 && !folder && plume_frame_name(name);
}

/// Hard-links the tree at from to to (folders recreated with their mode). 0 or an errno;
/// the path that failed in failed.
static int link_tree(const char *from, const char *to, char *failed, size_t failed_size)
{
	struct stat info;
	if (lstat(from, &info) != 0)
		return errno;
	if (!S_ISDIR(info.st_mode)) {
		if (linkat(AT_FDCWD, from, AT_FDCWD, to, 0) == 0)
			return 0;
		int failure = errno;
		snprintf(failed, failed_size, "%s", from);
		return failure;
	}
	if (mkdir(to, info.st_mode & 07777) != 0)
		return errno;
	DIR *dir = opendir(from);
	if (dir == NULL)
		return errno;
	int failure = 0;
	struct dirent *entry;
	while (failure == 0 && (entry = readdir(dir)) != NULL) {
		if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0)
			continue;
		char a[4608], b[4608];
		snprintf(a, sizeof a, "%s/%s", from, entry->d_name);
		snprintf(b, sizeof b, "%s/%s", to, entry->d_name);
		failure = link_tree(a, b, failed, failed_size);
	}
	closedir(dir);
	return failure;
}

/// Carries every entry of old (DIR, or the folder `prefix` in it, `depth` deep) that the
/// run did not write and the earlier run did not write either into stage, by hard links.
/// 0, an errno (the path in `failed`), or -1 when a folder of DIR has the name of a file
/// of the run (or the reverse), named in `failed`: plume will not delete it.
static int carry_over(const char *old, const char *stage, const char *prefix, int depth, const manifest *earlier,
                      char *failed, size_t failed_size)
{
	DIR *dir = opendir(old);
	if (dir == NULL)
		return errno;
	int failure = 0;
	struct dirent *entry;
	while (failure == 0 && (entry = readdir(dir)) != NULL) {
		const char *name = entry->d_name;
		if (strcmp(name, ".") == 0 || strcmp(name, "..") == 0 || strncmp(name, ".plume-staging-", 15) == 0 ||
		    (depth == 0 && strcmp(name, RUN_MANIFEST) == 0))
			continue;
		char a[4608], b[4608], relative[4352];
		snprintf(a, sizeof a, "%s/%s", old, name);
		snprintf(b, sizeof b, "%s/%s", stage, name);
		struct stat old_info, new_info;
		if (lstat(a, &old_info) != 0)
			continue;
		bool folder = S_ISDIR(old_info.st_mode);
		snprintf(relative, sizeof relative, "%s%s%s", prefix, name, folder ? "/" : "");
		if (lstat(b, &new_info) == 0) {
			if (folder && S_ISDIR(new_info.st_mode)) {
				failure = carry_over(a, b, relative, depth + 1, earlier, failed, failed_size);
			} else if (folder != S_ISDIR(new_info.st_mode)) {
				snprintf(failed, failed_size, "%s", a);
				failure = -1;
			}
			continue; // the run's file replaces the earlier one
		}
		if (folder && earlier->present) {
			// A folder the run does not write: what in it is not the earlier run's stays.
			if (mkdir(b, old_info.st_mode & 07777) != 0) {
				failure = errno;
				continue;
			}
			failure = carry_over(a, b, relative, depth + 1, earlier, failed, failed_size);
			if (failure == 0 && !earlier->keep_all && manifest_has(earlier, relative))
				rmdir(b); // the earlier run's folder goes when nothing of the user's is in it
			continue;
		}
		if (earlier_run(earlier, relative, name, depth, folder))
			continue; // the earlier run's file: the new run replaces it
		failure = link_tree(a, b, failed, failed_size);
	}
	closedir(dir);
	return failure;
}

/// Removes from the folder dir (`prefix` in DIR) the earlier run's entries that the run
/// did not write (written: the new run's manifest), keeping what is not the earlier
/// run's; for the per-entry commit, which has nothing to carry over.
static void drop_earlier(const char *dir, const char *prefix, const manifest *earlier, const manifest *written)
{
	DIR *folder = opendir(dir);
	if (folder == NULL)
		return;
	struct dirent *entry;
	while ((entry = readdir(folder)) != NULL) {
		const char *name = entry->d_name;
		if (strcmp(name, ".") == 0 || strcmp(name, "..") == 0 || strncmp(name, ".plume-staging-", 15) == 0 ||
		    (prefix[0] == '\0' && strcmp(name, RUN_MANIFEST) == 0))
			continue;
		char path[4608], relative[4352];
		snprintf(path, sizeof path, "%s/%s", dir, name);
		struct stat info;
		if (lstat(path, &info) != 0)
			continue;
		bool is_folder = S_ISDIR(info.st_mode);
		snprintf(relative, sizeof relative, "%s%s%s", prefix, name, is_folder ? "/" : "");
		if (is_folder) {
			drop_earlier(path, relative, earlier, written);
			if (manifest_has(earlier, relative) && !manifest_has(written, relative))
				rmdir(path); // only when empty
		} else if (manifest_has(earlier, relative) && !manifest_has(written, relative)) {
			unlink(path);
		}
	}
	closedir(folder);
}

/// Whether the staging folder holds nothing but its marker.
static bool stage_empty(const char *stage)
{
	DIR *dir = opendir(stage);
	if (dir == NULL)
		return false;
	bool empty = true;
	struct dirent *entry;
	while (empty && (entry = readdir(dir)) != NULL)
		empty = strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0 ||
		        strcmp(entry->d_name, STAGING_MARKER) == 0;
	closedir(dir);
	return empty;
}

/// Removes the staging folder of a run that left nothing in it to commit.
static void drop_stage(cli_output *output)
{
	char marker[4672];
	snprintf(marker, sizeof marker, "%s/" STAGING_MARKER, output->stage);
	begin_critical();
	unlink(marker);
	rmdir(output->stage);
	untrack_stage(output);
	end_critical();
}

/// err set for a failed carry_over (failure, the path in failed): why the earlier
/// folder's other files could not be kept in the new run.
static plume_status carry_failed(const cli_output *output, int failure, const char *failed, plume_error *err)
{
	if (failure == -1)
		return plume_error_set(err, PLUME_ERROR_IO,
		                       "%s: the run writes a file or folder of that name; move it away first", failed);
	struct stat info;
	if (failure == EPERM && failed[0] != '\0' && lstat(failed, &info) == 0 && info.st_uid != geteuid()) {
		// fs.protected_hardlinks (Linux's default): only a file's owner, or one who may read
		// and write it, may hard-link it.
		return plume_error_set(err, PLUME_ERROR_IO,
		                       "%s: owned by another user (uid %ld), and this system lets no one else hard-link it "
		                       "(fs.protected_hardlinks), which plume needs to keep it beside the new run; nothing was "
		                       "changed: write to another folder, or have its owner move it",
		                       failed, (long)info.st_uid);
	}
	if (failure == EPERM || failure == ENOTSUP || failure == EXDEV || failure == EMLINK)
		// No hard links here (vfat, some network file systems): keeping the earlier
		// run intact matters more than this run; say how to get it.
		return plume_error_set(
		    err, PLUME_ERROR_IO,
		    "%s: this file system cannot hard-link the folder's other files into the new run (%s: %s); "
		    "write to a new folder instead",
		    output->dir, failed[0] != '\0' ? failed : output->dir, strerror(failure));
	return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", failed[0] != '\0' ? failed : output->dir,
	                       strerror(failure));
}

/// An earlier run of another command (plume render into a folder of plume simulate's,
/// generate into one of render's) is not this run's to replace: its files are kept as
/// the user's (earlier->keep_all), and a run that would overwrite one of them fails
/// instead (PLUME_ERROR_IO, naming it). 0 when the earlier run is this command's.
static plume_status other_command(const cli_output *output, manifest *earlier, const char *stage, plume_error *err)
{
	const char *command = run_command();
	if (!earlier->present || earlier->command[0] == '\0' || command[0] == '\0' ||
	    strcmp(earlier->command, command) == 0)
		return PLUME_OK;
	earlier->keep_all = true;
	manifest written;
	if (manifest_read(stage, &written) != 0)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	plume_status status = PLUME_OK;
	for (size_t i = 0; i < written.count && status == PLUME_OK; ++i) {
		const char *path = written.paths[i];
		if (path[strlen(path) - 1] != '/' && manifest_has(earlier, path))
			status = plume_error_set(err, PLUME_ERROR_IO,
			                         "%s/%s: written by plume %s, which this plume %s would replace; nothing was "
			                         "changed: write to another folder, or move it away first",
			                         output->dir, path, earlier->command, command);
	}
	manifest_free(&written);
	return status;
}

/// The per-entry commit, for an existing DIR whose parent plume may not write (so
/// nothing can be staged beside it): each staged entry replaces its namesake (a
/// folder of the run keeps the user's files in it), then the earlier run's other
/// entries go.
static plume_status commit_by_moves(cli_output *output, plume_error *err)
{
	manifest earlier = {0}, written = {0};
	int failure = write_manifest(output->stage);
	if (failure == 0)
		failure = manifest_read(output->dir, &earlier);
	if (failure == 0)
		failure = manifest_read(output->stage, &written);
	plume_status other = failure == 0 ? other_command(output, &earlier, output->stage, err) : PLUME_OK;
	if (other != PLUME_OK) {
		cli_output_abort(output, NULL);
		manifest_free(&earlier);
		manifest_free(&written);
		return other;
	}
	DIR *stage = failure == 0 ? opendir(output->stage) : NULL;
	if (stage == NULL) {
		plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read the staging folder: %s", output->stage,
		                strerror(failure != 0 ? failure : errno));
		cli_output_abort(output, NULL);
		manifest_free(&earlier);
		manifest_free(&written);
		return PLUME_ERROR_IO;
	}
	struct dirent *entry;
	plume_status status = PLUME_OK;
	begin_critical();
	while (status == PLUME_OK && (entry = readdir(stage)) != NULL) {
		if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0 ||
		    strcmp(entry->d_name, STAGING_MARKER) == 0)
			continue;
		char from[4608], to[4608], aside[4608], failed[4608] = "", relative[4352];
		snprintf(from, sizeof from, "%s/%s", output->stage, entry->d_name);
		snprintf(to, sizeof to, "%s/%s", output->dir, entry->d_name);
		snprintf(relative, sizeof relative, "%s/", entry->d_name);
		struct stat info, staged;
		bool replace_folder = lstat(to, &info) == 0 && S_ISDIR(info.st_mode);
		bool staged_folder = lstat(from, &staged) == 0 && S_ISDIR(staged.st_mode);
		if (replace_folder != staged_folder && lstat(to, &info) == 0) {
			status = carry_failed(output, -1, to, err); // a folder for a file, or the reverse: never deleted
			break;
		}
		if (replace_folder) {
			failure = carry_over(to, from, relative, 1, &earlier, failed, sizeof failed);
			if (failure != 0) {
				status = carry_failed(output, failure, failed, err);
				break;
			}
		}
		if (replace_folder) {
			snprintf(aside, sizeof aside, "%s/.%s.plume-old", output->dir, entry->d_name);
			if (rename(to, aside) != 0)
				replace_folder = false;
		}
		if (rename(from, to) != 0) {
			status = plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", to, strerror(errno));
			if (replace_folder)
				rename(aside, to);
		} else if (replace_folder) {
			cli_remove_tree(aside);
		}
	}
	closedir(stage);
	if (status != PLUME_OK) {
		cli_output_abort(output, NULL);
		end_critical();
		manifest_free(&earlier);
		manifest_free(&written);
		return status;
	}
	if (earlier.present && !earlier.keep_all)
		drop_earlier(output->dir, "", &earlier, &written);
	manifest_free(&earlier);
	manifest_free(&written);
	char marker[4672];
	snprintf(marker, sizeof marker, "%s/" STAGING_MARKER, output->stage);
	unlink(marker);
	rmdir(output->stage);
	untrack_stage(output);
	end_critical();
	return PLUME_OK;
}

/// Swaps stage and dir in one step; falls back to two renames. 0 or an errno.
static int exchange(const char *stage, const char *dir)
{
#ifdef RENAME_EXCHANGE
	if (renameat2(AT_FDCWD, stage, AT_FDCWD, dir, RENAME_EXCHANGE) == 0)
		return 0;
	if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP)
		return errno;
#endif
	char aside[4200];
	snprintf(aside, sizeof aside, "%s-old", stage); // still the staging pattern's prefix: removed if we die here
	if (rename(dir, aside) != 0)
		return errno;
	if (rename(stage, dir) != 0) {
		int failure = errno;
		rename(aside, dir);
		return failure;
	}
	return rename(aside, stage) == 0 ? 0 : errno;
}

plume_status cli_output_commit(cli_output *output, plume_error *err)
{
	struct stat info;
	bool dir_exists = stat(output->dir, &info) == 0;
	if (dir_exists && stage_empty(output->stage)) {
		// Nothing to commit (render --frames moved its frames into DIR itself): DIR stays as it is.
		drop_stage(output);
		return PLUME_OK;
	}
	int failure = write_manifest(output->stage);
	if (failure != 0) {
		plume_error_set(err, PLUME_ERROR_IO, "%s/" RUN_MANIFEST ": cannot write: %s", output->dir, strerror(failure));
		cli_output_abort(output, NULL);
		return PLUME_ERROR_IO;
	}
	if (output->stage_inside)
		return commit_by_moves(output, err);
	if (!output->dir_existed || !dir_exists) {
		// mkdtemp made the folder 0700; a results folder is ordinary.
		mode_t mask = umask(0);
		umask(mask);
		chmod(output->stage, 0777 & ~mask);
		begin_critical();
		if (rename(output->stage, output->dir) != 0) {
			plume_error_set(err, PLUME_ERROR_IO, "%s: cannot create the output folder: %s", output->dir,
			                strerror(errno));
			cli_output_abort(output, NULL);
			end_critical();
			return PLUME_ERROR_IO;
		}
		untrack_stage(output);
		end_critical();
		char marker[4352];
		snprintf(marker, sizeof marker, "%s/" STAGING_MARKER, output->dir);
		unlink(marker); // killed before this, DIR keeps a marker that the next run drops
		return PLUME_OK;
	}
	manifest earlier;
	char failed[4608] = "";
	failure = manifest_read(output->dir, &earlier);
	plume_status other = failure == 0 ? other_command(output, &earlier, output->stage, err) : PLUME_OK;
	if (other != PLUME_OK) {
		manifest_free(&earlier);
		cli_output_abort(output, NULL);
		return other;
	}
	if (failure == 0)
		failure = carry_over(output->dir, output->stage, "", 0, &earlier, failed, sizeof failed);
	manifest_free(&earlier);
	if (failure != 0) {
		carry_failed(output, failure, failed, err);
		cli_output_abort(output, NULL);
		return PLUME_ERROR_IO;
	}
	begin_critical();
	chmod(output->stage, info.st_mode & 07777);
	failure = exchange(output->stage, output->dir);
	if (failure != 0) {
		plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", output->dir, strerror(failure));
		cli_output_abort(output, NULL);
		end_critical();
		return PLUME_ERROR_IO;
	}
	// The earlier run now has the staging name: the marker goes with it, so that a run
	// killed before the removal below leaves a folder the next run recognises.
	char marker_from[4352], marker_to[4352];
	snprintf(marker_from, sizeof marker_from, "%s/" STAGING_MARKER, output->dir);
	snprintf(marker_to, sizeof marker_to, "%s/" STAGING_MARKER, output->stage);
	rename(marker_from, marker_to);
	end_critical();                 // a signal held back until now removes the earlier run too, then ends plume
	cli_remove_tree(output->stage); // the earlier run; the user's files live on in DIR
	untrack_stage(output);
	return PLUME_OK;
}

/// err's message with every mention of the staging folder replaced by DIR: a file the
/// run could not write is named where the user asked for it, not in a folder that is
/// removed before they read the message.
static void name_output_in_error(const cli_output *output, plume_error *err)
{
	size_t stage_length = strlen(output->stage);
	if (stage_length == 0)
		return;
	char named[sizeof err->message];
	size_t used = 0;
	for (const char *at = err->message; *at != '\0' && used + 1 < sizeof named;) {
		if (strncmp(at, output->stage, stage_length) == 0) {
			used += (size_t)snprintf(named + used, sizeof named - used, "%s", output->dir);
			used = used < sizeof named ? used : sizeof named - 1;
			at += stage_length;
		} else {
			named[used++] = *at++;
		}
	}
	named[used] = '\0';
	memcpy(err->message, named, used + 1);
}

void cli_output_abort(cli_output *output, plume_error *err)
{
	if (err != NULL)
		name_output_in_error(output, err);
	if (output->stage[0] != '\0')
		cli_remove_tree(output->stage);
	untrack_stage(output);
	cli_remove_parents(output->dir, output->parents_made);
}

// ---------------------------------------------------------------------------
// Writing a feather

static plume_render2d_def image_def(const plume_feather *feather, const cli_image_options *images)
{
	plume_render2d_def def = plume_render2d_default_def();
	def.texture = images->texture;
	if (images->width > 0) {
		def.width = images->width;
		def.height = images->height;
		return def;
	}
	// Automatic size: 1200 pixels tall, as wide as the feather needs.
	plume_feather_info info = plume_feather_get_info(feather);
	double w = info.bounds_max.x - info.bounds_min.x, h = info.bounds_max.y - info.bounds_min.y;
	def.height = 1200;
	def.width = cli_image_width(w, h, def.height, def.margin);
	return def;
}

/// The formats of a feather's files, in the order cli_write_feather writes them.
static const struct {
	unsigned bit;
	const char *extension;
} feather_formats[] = {
    {CLI_FORMAT_PNG, "png"},   {CLI_FORMAT_SVG, "svg"},   {CLI_FORMAT_PDF, "pdf"}, {CLI_FORMAT_OBJ, "obj"},
    {CLI_FORMAT_USDA, "usda"}, {CLI_FORMAT_JSON, "json"}, {CLI_FORMAT_GLB, "glb"},
};

int cli_feather_file_paths(cli_output *output, const char *stem, unsigned formats, cli_feather_file files[])
{
	int count = 0;
	for (size_t i = 0; i < sizeof feather_formats / sizeof feather_formats[0]; ++i) {
		if ((formats & feather_formats[i].bit) == 0)
			continue;
		char name[64];
		snprintf(name, sizeof name, "%s.%s", stem, feather_formats[i].extension);
		files[count].format = feather_formats[i].bit;
		cli_output_path(output, name, files[count].path, sizeof files[count].path);
		++count;
	}
	return count;
}

plume_status cli_write_feather_file(const plume_feather *feather, const cli_feather_file *file,
                                    const plume_render2d_def *image, const plume_texture *texture, plume_error *err)
{
	switch (file->format) {
	case CLI_FORMAT_PNG: return plume_render2d(feather, image, PLUME_IMAGE_PNG, file->path, err);
	case CLI_FORMAT_SVG: return plume_render2d(feather, image, PLUME_IMAGE_SVG, file->path, err);
	case CLI_FORMAT_PDF: return plume_render2d(feather, image, PLUME_IMAGE_PDF, file->path, err);
	case CLI_FORMAT_OBJ: return plume_write_obj(feather, file->path, err);
	case CLI_FORMAT_USDA: return plume_write_usda(feather, file->path, err);
	case CLI_FORMAT_GLB: {
		plume_gltf_def gltf = plume_gltf_default_def();
		gltf.texture = texture;
		return plume_write_glb(feather, &gltf, file->path, err);
	}
	default: return plume_write_json(feather, file->path, err);
	}
}

plume_status cli_write_feather(cli_output *output, const plume_feather *feather, const char *stem, unsigned formats,
                               const cli_image_options *images, plume_error *err)
{
	cli_feather_file files[CLI_FEATHER_FORMATS];
	int count = cli_feather_file_paths(output, stem, formats, files);
	plume_render2d_def def = image_def(feather, images);
	for (int i = 0; i < count; ++i) {
		plume_status status = cli_write_feather_file(feather, files + i, &def, images->texture, err);
		if (status != PLUME_OK)
			return status;
	}
	return PLUME_OK;
}

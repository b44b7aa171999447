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

bool cli_parse_formats(const char *command, const char *list, unsigned *formats)
{
	*formats = 0;
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
//  - an existing DIR: every entry of DIR the run does not write is hard-linked
//    into the staging folder (a folder the run writes too, such as frames/, is
//    merged: the user's files in it are linked, the earlier run's frames are
//    not), then renameat2(RENAME_EXCHANGE) swaps the two folders in one step and
//    the earlier run, now under the staging name, is removed. The user's files
//    live on through their second link; nothing plume did not write is lost,
//    and a reader sees the whole earlier run or the whole new one, never a mix.
// Without RENAME_EXCHANGE (a kernel or file system without it) DIR is renamed
// aside and the staging folder renamed into place: two renames with a moment
// in between where DIR is absent, but never mixed. Without hard links (vfat)
// the run fails and DIR keeps the earlier run. When the parent folder is not
// writable, the staging folder goes inside DIR and entries move one by one.
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

/// Whether name is one plume writes inside a folder of a run (frames/0012.obj,
/// 0012-rt.png, ...): a digit first. An earlier run's files of that kind are
/// replaced by the new run's folder; anything else in it is the user's.
static bool plume_frame_name(const char *name) { return name[0] >= '0' && name[0] <= '9'; }

/// Hard-links the tree at from to to (folders recreated with their mode). 0 or an errno.
static int link_tree(const char *from, const char *to)
{
	struct stat info;
	if (lstat(from, &info) != 0)
		return errno;
	if (!S_ISDIR(info.st_mode))
		return linkat(AT_FDCWD, from, AT_FDCWD, to, 0) == 0 ? 0 : errno;
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
		failure = link_tree(a, b);
	}
	closedir(dir);
	return failure;
}

/// Carries every entry of old (DIR or a folder in it) that the run did not
/// write into stage, by hard links. 0, an errno, or -1 when a folder of DIR
/// has the name of a file of the run (or the reverse): plume will not delete it.
static int carry_over(const char *old, const char *stage, int depth, char *conflict, size_t conflict_size)
{
	DIR *dir = opendir(old);
	if (dir == NULL)
		return errno;
	int failure = 0;
	struct dirent *entry;
	while (failure == 0 && (entry = readdir(dir)) != NULL) {
		const char *name = entry->d_name;
		if (strcmp(name, ".") == 0 || strcmp(name, "..") == 0 || strncmp(name, ".plume-staging-", 15) == 0)
			continue;
		char a[4608], b[4608];
		snprintf(a, sizeof a, "%s/%s", old, name);
		snprintf(b, sizeof b, "%s/%s", stage, name);
		struct stat old_info, new_info;
		if (lstat(a, &old_info) != 0)
			continue;
		if (lstat(b, &new_info) == 0) {
			if (S_ISDIR(old_info.st_mode) && S_ISDIR(new_info.st_mode)) {
				failure = carry_over(a, b, depth + 1, conflict, conflict_size);
			} else if (S_ISDIR(old_info.st_mode) != S_ISDIR(new_info.st_mode)) {
				snprintf(conflict, conflict_size, "%s", a);
				failure = -1;
			}
			continue; // the run's file replaces the earlier one
		}
		if (depth > 0 && plume_frame_name(name) && !S_ISDIR(old_info.st_mode))
			continue; // an earlier run's frame: the new frames/ replaces it
		failure = link_tree(a, b);
	}
	closedir(dir);
	return failure;
}

/// The per-entry commit, for an existing DIR whose parent plume may not write (so
/// nothing can be staged beside it): each staged entry replaces its namesake.
static plume_status commit_by_moves(cli_output *output, plume_error *err)
{
	DIR *stage = opendir(output->stage);
	if (stage == NULL) {
		plume_error_set(err, PLUME_ERROR_IO, "%s: cannot read the staging folder: %s", output->stage, strerror(errno));
		cli_output_abort(output, NULL);
		return PLUME_ERROR_IO;
	}
	struct dirent *entry;
	plume_status status = PLUME_OK;
	begin_critical();
	while (status == PLUME_OK && (entry = readdir(stage)) != NULL) {
		if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0 ||
		    strcmp(entry->d_name, STAGING_MARKER) == 0)
			continue;
		char from[4608], to[4608], aside[4608];
		snprintf(from, sizeof from, "%s/%s", output->stage, entry->d_name);
		snprintf(to, sizeof to, "%s/%s", output->dir, entry->d_name);
		struct stat info;
		bool replace_folder = stat(to, &info) == 0 && S_ISDIR(info.st_mode);
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
		return status;
	}
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
	if (output->stage_inside)
		return commit_by_moves(output, err);
	struct stat info;
	if (!output->dir_existed || stat(output->dir, &info) != 0) {
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
	char conflict[4608] = "";
	int failure = carry_over(output->dir, output->stage, 0, conflict, sizeof conflict);
	if (failure == EPERM || failure == ENOTSUP || failure == EXDEV || failure == EMLINK) {
		// No hard links here (vfat, some network file systems): keeping the earlier
		// run intact matters more than this run; say how to get it.
		plume_error_set(err, PLUME_ERROR_IO,
		                "%s: this file system cannot hard-link the folder's other files into the new run (%s); "
		                "write to a new folder instead",
		                output->dir, strerror(failure));
		cli_output_abort(output, NULL);
		return PLUME_ERROR_IO;
	}
	if (failure == -1) {
		plume_error_set(err, PLUME_ERROR_IO, "%s: the run writes a file or folder of that name; move it away first",
		                conflict);
		cli_output_abort(output, NULL);
		return PLUME_ERROR_IO;
	}
	begin_critical();
	if (failure == 0) {
		chmod(output->stage, info.st_mode & 07777);
		failure = exchange(output->stage, output->dir);
	}
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
	double inner = def.height * (1.0 - 2.0 * def.margin);
	int width = h > 0.0 ? (int)(inner * w / h + 2.0 * def.margin * def.height + 0.5) : def.height;
	def.width = width < 256 ? 256 : (width > 4096 ? 4096 : width);
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

// Progress lines on stderr for long commands: "plume WHAT: 3/100 (3%), 2 s elapsed,
// about 1 min 5 s left", rewritten in place, only when stderr is a terminal (a log
// file or a pipe gets nothing). The estimate assumes the remaining items take as
// long as the finished ones did on average.
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"

double cli_now_seconds(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void print_duration(double seconds)
{
	long s = (long)(seconds + 0.5);
	if (s >= 3600)
		fprintf(stderr, "%ld h %02ld min", s / 3600, s / 60 % 60);
	else if (s >= 60)
		fprintf(stderr, "%ld min %02ld s", s / 60, s % 60);
	else
		fprintf(stderr, "%ld s", s);
}

void cli_progress_begin(cli_progress *progress, const char *what, int total)
{
	progress->what = what;
	progress->total = total;
	progress->start = cli_now_seconds();
	progress->shown = isatty(STDERR_FILENO) != 0 && total > 0;
	progress->open = false;
	progress->printed = -1.0;
}

void cli_progress_update(cli_progress *progress, int done) { cli_progress_update_note(progress, done, NULL); }

void cli_progress_update_note(cli_progress *progress, int done, const char *note)
{
	if (!progress->shown)
		return;
	// At most ten lines a second (a coat builds thousands of feathers a second); the last always.
	double t = cli_now_seconds(), elapsed = t - progress->start;
	if (done < progress->total && progress->printed >= 0.0 && t - progress->printed < 0.1)
		return;
	progress->printed = t;
	fprintf(stderr, "\r\033[Kplume %s: %d/%d (%d%%), ", progress->what, done, progress->total,
	        (int)(100.0 * done / progress->total));
	print_duration(elapsed);
	fputs(" elapsed", stderr);
	if (done > 0 && done < progress->total) {
		fputs(", about ", stderr);
		print_duration(elapsed / done * (progress->total - done));
		fputs(" left", stderr);
	}
	if (note != NULL)
		fprintf(stderr, ", %s", note);
	progress->open = done < progress->total;
	if (done >= progress->total)
		fputc('\n', stderr);
	fflush(stderr);
}

void cli_progress_callback(void *user, int done, int total)
{
	cli_progress *progress = user;
	progress->total = total;
	cli_progress_update(progress, done);
}

void cli_progress_end(cli_progress *progress)
{
	if (progress->shown && progress->open) {
		fputc('\n', stderr);
		fflush(stderr);
	}
	progress->open = false;
}

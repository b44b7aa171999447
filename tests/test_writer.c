// plume simulate's background writer (cli/writer.c): every job handed over runs once and
// is released once; the first failure is the one reported, and the jobs handed over after
// it are released without running; a full queue is emptied by the handing thread instead
// of waited on.
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "support.h"

typedef struct counters {
	atomic_int ran, released, ran_here; // ran_here: on the thread that handed the job over
	pthread_t handing;
	atomic_int waiting_for;    // a blocking job waits until this many others have run
	atomic_int blocked_writer; // a blocking job has started on the writer's thread
} counters;

typedef struct job {
	counters *c;
	int index;
	int fail; // fail with PLUME_ERROR_IO when not 0
	bool block;
} job;

static job jobs[64];

static void sleep_ms(int ms)
{
	struct timespec t = {0, ms * 1000000L};
	nanosleep(&t, NULL);
}

static plume_status run_job(void *data, plume_error *err)
{
	job *j = data;
	if (pthread_equal(pthread_self(), j->c->handing))
		atomic_fetch_add(&j->c->ran_here, 1);
	else if (j->block)
		atomic_store(&j->c->blocked_writer, 1);
	if (j->block) // until the others have run, 10 s at most: never, if the handing thread only waited
		for (int k = 0; k < 10000 && atomic_load(&j->c->ran) < atomic_load(&j->c->waiting_for); ++k)
			sleep_ms(1);
	atomic_fetch_add(&j->c->ran, 1);
	if (j->fail)
		return plume_error_set(err, PLUME_ERROR_IO, "job %d failed", j->index);
	return PLUME_OK;
}

static void release_job(void *data)
{
	job *j = data;
	atomic_fetch_add(&j->c->released, 1);
}

static void test_every_job_runs_once(void **state)
{
	(void)state;
	counters c = {.handing = pthread_self()};
	cli_writer *writer = NULL;
	plume_error err = {0};
	assert_int_equal(cli_writer_start(&writer, &err), PLUME_OK);
	for (int k = 0; k < 64; ++k) {
		jobs[k] = (job){&c, k, 0, false};
		cli_writer_submit(writer, run_job, release_job, jobs + k);
	}
	assert_int_equal(cli_writer_finish(writer, &err), PLUME_OK);
	assert_int_equal(atomic_load(&c.ran), 64);
	assert_int_equal(atomic_load(&c.released), 64);
	assert_int_equal(cli_writer_finish(NULL, &err), PLUME_OK);
}

static void test_first_failure_stops_the_rest(void **state)
{
	(void)state;
	counters c = {.handing = pthread_self()};
	cli_writer *writer = NULL;
	plume_error err = {0};
	assert_int_equal(cli_writer_start(&writer, &err), PLUME_OK);
	jobs[0] = (job){&c, 0, 1, false};
	cli_writer_submit(writer, run_job, release_job, jobs);
	// The status says so once the job has run (without waiting for the writer to end).
	plume_status seen = PLUME_OK;
	for (int k = 0; k < 10000 && seen == PLUME_OK; ++k, sleep_ms(1))
		seen = cli_writer_status(writer, &err);
	assert_int_equal(seen, PLUME_ERROR_IO);
	assert_string_equal(err.message, "job 0 failed");
	// Jobs handed over after it are released, not run, and fail nothing more.
	for (int k = 1; k < 20; ++k) {
		jobs[k] = (job){&c, k, k == 5, false};
		cli_writer_submit(writer, run_job, release_job, jobs + k);
	}
	memset(&err, 0, sizeof err);
	assert_int_equal(cli_writer_finish(writer, &err), PLUME_ERROR_IO);
	assert_string_equal(err.message, "job 0 failed");
	assert_int_equal(atomic_load(&c.ran), 1);
	assert_int_equal(atomic_load(&c.released), 20);
}

static void test_full_queue_is_emptied_by_the_handing_thread(void **state)
{
	(void)state;
	// The first job holds the writer's thread until the 20 others have run: only the handing
	// thread can run them, which it does when the queue (8) is full and at the end. A handing
	// thread that waited instead would wait 10 s, and the writer's thread would run them all.
	counters c = {.handing = pthread_self(), .waiting_for = 20};
	cli_writer *writer = NULL;
	plume_error err = {0};
	assert_int_equal(cli_writer_start(&writer, &err), PLUME_OK);
	jobs[0] = (job){&c, 0, 0, true};
	cli_writer_submit(writer, run_job, release_job, jobs);
	for (int k = 0; k < 10000 && !atomic_load(&c.blocked_writer); ++k)
		sleep_ms(1);
	assert_true(atomic_load(&c.blocked_writer));
	for (int k = 1; k <= 20; ++k) {
		jobs[k] = (job){&c, k, 0, false};
		cli_writer_submit(writer, run_job, release_job, jobs + k);
	}
	assert_int_equal(cli_writer_finish(writer, &err), PLUME_OK);
	assert_int_equal(atomic_load(&c.ran), 21);
	assert_int_equal(atomic_load(&c.released), 21);
	assert_int_equal(atomic_load(&c.ran_here), 20);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_every_job_runs_once),
	    cmocka_unit_test(test_first_failure_stops_the_rest),
	    cmocka_unit_test(test_full_queue_is_emptied_by_the_handing_thread),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}

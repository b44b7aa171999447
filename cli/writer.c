// A background writer: one thread that runs the file-writing jobs a command hands it, so
// that formatting numbers into text files (printf per number: a frame's OBJ, the
// barb-level feather's JSON) and drawing preview pictures run beside the computation
// instead of between its steps (issue 15, "I/O off the critical path"). Each job writes
// its own files whole: the bytes are the same as when the jobs run inline, and only when
// they are written changes.
//
// The queue is bounded. A job handed over while CLI_WRITER_QUEUE jobs wait is not queued
// behind them: the handing thread first runs the oldest waiting job itself, so a writer
// slower than the computation (a PNG per frame costs more than a step) costs memory for
// that many jobs at most, and both threads write until it has caught up. cli_writer_finish
// likewise runs what is left on the calling thread beside the writer's. The first job that
// fails stops the writer: later jobs are dropped (their data released), and the failure is
// reported by cli_writer_status and cli_writer_finish.
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdlib.h>

#include "cli.h"

#define CLI_WRITER_QUEUE 8

typedef struct writer_job {
	cli_writer_job_fn *run;
	void (*release)(void *data);
	void *data;
} writer_job;

struct cli_writer {
	pthread_t thread;
	bool threaded; // false when no thread could be started: every job runs where it is handed over
	pthread_mutex_t lock;
	pthread_cond_t changed; // a job queued, or the writer closing
	writer_job queue[CLI_WRITER_QUEUE];
	int head, count;
	bool closing;
	plume_status status; // the first failure, PLUME_OK until then
	plume_error error;
};

static void release_job(writer_job *job)
{
	if (job->release != NULL)
		job->release(job->data);
}

/// Takes the oldest waiting job and runs it (or, after a failure, only releases it), with
/// the lock released meanwhile. Called with the lock held and a job waiting; returns with
/// the lock held.
static void run_oldest(cli_writer *writer)
{
	writer_job job = writer->queue[writer->head];
	writer->head = (writer->head + 1) % CLI_WRITER_QUEUE;
	--writer->count;
	bool failed = writer->status != PLUME_OK;
	pthread_mutex_unlock(&writer->lock);

	plume_error error = {0};
	plume_status status = failed ? PLUME_OK : job.run(job.data, &error);
	release_job(&job);

	pthread_mutex_lock(&writer->lock);
	if (status != PLUME_OK && writer->status == PLUME_OK) {
		writer->status = status;
		writer->error = error;
	}
}

static void *writer_main(void *argument)
{
	cli_writer *writer = argument;
	pthread_mutex_lock(&writer->lock);
	for (;;) {
		while (writer->count == 0 && !writer->closing)
			pthread_cond_wait(&writer->changed, &writer->lock);
		if (writer->count == 0)
			break; // closing, nothing left
		run_oldest(writer);
	}
	pthread_mutex_unlock(&writer->lock);
	return NULL;
}

plume_status cli_writer_start(cli_writer **out, plume_error *err)
{
	*out = NULL;
	cli_writer *writer = calloc(1, sizeof *writer);
	if (writer == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory starting the writer");
	pthread_mutex_init(&writer->lock, NULL);
	pthread_cond_init(&writer->changed, NULL);
	// Without a thread (a process limit, say) the jobs run inline, as they did before the
	// writer: slower, never wrong.
	writer->threaded = pthread_create(&writer->thread, NULL, writer_main, writer) == 0;
	*out = writer;
	return PLUME_OK;
}

void cli_writer_submit(cli_writer *writer, cli_writer_job_fn *run, void (*release)(void *data), void *data)
{
	writer_job job = {run, release, data};
	pthread_mutex_lock(&writer->lock);
	while (writer->count == CLI_WRITER_QUEUE && writer->status == PLUME_OK)
		run_oldest(writer);           // help rather than wait
	if (writer->status != PLUME_OK) { // failed already: the job would be dropped anyway
		pthread_mutex_unlock(&writer->lock);
		release_job(&job);
		return;
	}
	writer->queue[(writer->head + writer->count) % CLI_WRITER_QUEUE] = job;
	++writer->count;
	if (!writer->threaded)
		run_oldest(writer); // no thread to hand it to
	pthread_cond_signal(&writer->changed);
	pthread_mutex_unlock(&writer->lock);
}

plume_status cli_writer_status(cli_writer *writer, plume_error *err)
{
	pthread_mutex_lock(&writer->lock);
	plume_status status = writer->status;
	if (status != PLUME_OK && err != NULL)
		*err = writer->error;
	pthread_mutex_unlock(&writer->lock);
	return status;
}

plume_status cli_writer_finish(cli_writer *writer, plume_error *err)
{
	if (writer == NULL)
		return PLUME_OK;
	pthread_mutex_lock(&writer->lock);
	writer->closing = true;
	pthread_cond_signal(&writer->changed);
	while (writer->count > 0)
		run_oldest(writer); // beside the writer's thread
	pthread_mutex_unlock(&writer->lock);
	if (writer->threaded)
		pthread_join(writer->thread, NULL);
	plume_status status = writer->status;
	if (status != PLUME_OK && err != NULL)
		*err = writer->error;
	pthread_cond_destroy(&writer->changed);
	pthread_mutex_destroy(&writer->lock);
	free(writer);
	return status;
}

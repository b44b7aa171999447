// plume sweep under mpirun or srun (plume built with MPI): rank 0 hands the missing
// runs out one at a time as ranks become free and gathers the rows; the others run.
#define _GNU_SOURCE
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>

#include "sweep.h"

#ifdef PLUME_WITH_MPI
#include <mpi.h>
#endif

#ifdef PLUME_WITH_MPI
enum { TAG_READY = 1, TAG_ROW = 2, TAG_WORK = 3 };

/// Whether this process was started by an MPI launcher (mpirun, srun): only then is
/// MPI initialised, so plain `plume sweep` works without a launcher.
bool sweep_mpi_launched(void)
{
	return getenv("OMPI_COMM_WORLD_SIZE") != NULL || getenv("PMI_SIZE") != NULL || getenv("PMIX_RANK") != NULL;
}

/// The rank the launcher gave this process, read before MPI starts (so that a usage error
/// prints once, not once a rank); 0 when no launcher says.
int sweep_mpi_launcher_rank(void)
{
	static const char *const names[] = {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID"};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
		const char *value = getenv(names[i]);
		if (value != NULL)
			return atoi(value);
	}
	return 0;
}

/// Rank 0: hands the missing runs out one at a time as ranks become free, gathers the rows.
bool sweep_mpi_schedule(sweep_state *state, int size)
{
	const sweep *s = state->s;
	int next = 0, active = size - 1;
	bool ok = true;
	double *started = calloc((size_t)size, sizeof *started);
	int *assigned = calloc((size_t)size, sizeof *assigned);
	while (active > 0) {
		// Poll with sleeps: a blocking probe spins a core that the runs need.
		MPI_Status status;
		int arrived = 0;
		for (;;) {
			MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &arrived, &status);
			if (arrived)
				break;
			nanosleep(&(struct timespec){0, 2000000}, NULL);
		}
		int length = 0;
		MPI_Get_count(&status, MPI_CHAR, &length);
		char *message = malloc((size_t)length + 1);
		MPI_Recv(message, length, MPI_CHAR, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		message[length] = '\0';
		int source = status.MPI_SOURCE;
		if (status.MPI_TAG == TAG_ROW) {
			sweep_record_timing(state, assigned[source], cli_now_seconds() - started[source], source);
			ok = sweep_record_row(state, assigned[source], strdup(message)) && ok;
		}
		free(message);
		while (next < s->run_count && state->rows[next] != NULL)
			++next;
		int work = next < s->run_count && ok ? next++ : -1;
		if (work >= 0) {
			assigned[source] = work;
			started[source] = cli_now_seconds();
		} else
			--active;
		MPI_Send(&work, 1, MPI_INT, source, TAG_WORK, MPI_COMM_WORLD);
	}
	free(started);
	free(assigned);
	return ok;
}

void sweep_mpi_work(const sweep *s, const char *dir)
{
	char ready = 0;
	MPI_Send(&ready, 0, MPI_CHAR, 0, TAG_READY, MPI_COMM_WORLD);
	for (;;) {
		int index = -1;
		MPI_Recv(&index, 1, MPI_INT, 0, TAG_WORK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		if (index < 0)
			break;
		char failure[512] = "";
		int wait_status = 0;
		pid_t pid = sweep_run_start(s, dir, index, failure, sizeof failure);
		while (pid >= 0 && waitpid(pid, &wait_status, 0) < 0 && errno == EINTR) {
		}
		char *row = sweep_run_finish(s, dir, index, pid, wait_status, failure);
		const char *text = row != NULL ? row : "";
		MPI_Send(text, (int)strlen(text), MPI_CHAR, 0, TAG_ROW, MPI_COMM_WORLD);
		free(row);
	}
}
#endif

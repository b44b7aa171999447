// plume sweep SWEEP.json -o DIR [-j N]: many runs of one command over parameters.
//
// The sweep is process-level orchestration, so it lives in the CLI, not in libplume:
// each run is the plume binary itself (/proc/self/exe) started on a modified copy of
// the base spec, in its own folder, so that a crash, an abort or a non-converging run
// is isolated and recorded as a row instead of stopping the sweep. The library never
// forks, prints or exits; the CLI may. With MPI (PLUME_WITH_MPI) the same runs are
// handed to ranks: rank 0 schedules, the others run (docs/sweeps.md).
//
// Determinism: the rows of DIR/results.csv depend only on the sweep (values, seeds,
// outputs), never on the worker count, the rank count or the order runs finish in:
// rows are kept in index order and the per-run timings go to DIR/timings.csv instead.
//
// The command's files each own one step (cli/sweep.h lists them); this one reads the
// command line and runs the steps in order.
#define _GNU_SOURCE
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef PLUME_WITH_MPI
#include <mpi.h>
#endif

#include "sweep.h"

void cli_help_sweep(void)
{
	puts("Usage: plume sweep SWEEP.json -o DIR [-j N] [--dry-run] [--max-runs N]\n"
	     "       mpirun -n N plume sweep SWEEP.json -o DIR\n"
	     "\n"
	     "Runs one plume command (generate, mesh, coat, simulate, lab traction, lab\n"
	     "calibrate, render frames) many times over values of its spec named by JSON\n"
	     "path: grids, lists, seeded random samples (uniform, normal, log-normal,\n"
	     "truncated) or the rows of another sweep's results.csv.\n"
	     "Each run is a separate plume process: a failing run is recorded with its\n"
	     "message and the sweep goes on (it exits 1 when every run failed).\n"
	     "docs/sweeps.md describes the sweep file.\n"
	     "\n"
	     "Writes DIR/results.csv (index, parameters, outputs, status, message; in index\n"
	     "order and the same bytes for any -j or rank count), DIR/timings.csv (seconds per\n"
	     "run), DIR/sweep.json (the sweep, plume's version, the seed), DIR/stats.json\n"
	     "(mean, std, 5/50/95 percentiles of each output) and DIR/plots/*.png (each\n"
	     "output against each parameter; histograms of random sweeps). Started again\n"
	     "on the same DIR, a sweep runs only the runs results.csv lacks.\n"
	     "\n"
	     "  -o, --output DIR       output folder (required)\n"
	     "  -j, --jobs N           runs at once on this machine (default 1)\n"
	     "      --dry-run          check the sweep and print each run's parameter values\n"
	     "                         (CSV) without running anything or writing DIR\n"
	     "      --max-runs N       refuse a sweep of more than N runs before any starts\n"
	     "                         (default 100000, at most 1000000; docs/cli.md)\n"
	     "  -h, --help             this help\n"
	     "\n"
	     "Under mpirun or srun (plume built with MPI) rank 0 schedules and every other\n"
	     "rank runs one run at a time."
#ifdef PLUME_WITH_MPI
	     " This plume was built with MPI."
#else
	     " This plume was built without MPI."
#endif
	);
}

/// --dry-run: the parameter values of every run, as the first columns of results.csv.
static void print_plan(const sweep *s)
{
	printf("index");
	for (int p = 0; p < s->param_count; ++p)
		printf(",%s", s->params[p].name);
	printf("\n");
	char text[256];
	for (int i = 0; i < s->run_count; ++i) {
		printf("%d", i);
		for (int p = 0; p < s->param_count; ++p) {
			json_t *value = sweep_run_value(s, p, i);
			sweep_csv_value(text, sizeof text, value);
			json_decref(value);
			printf(",%s", text);
		}
		printf("\n");
	}
}

int cli_sweep(int argc, char **argv)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'}, {"jobs", required_argument, NULL, 'j'},
	    {"dry-run", no_argument, NULL, 'n'},      {"max-runs", required_argument, NULL, 'R'},
	    {"help", no_argument, NULL, 'h'},         {NULL, 0, NULL, 0}};
	const char *output_dir = NULL;
	int jobs = 1;
	bool dry_run = false;
	long max_runs = SWEEP_DEFAULT_MAX_RUNS;
	// Under a launcher only rank 0 speaks, from the first usage error on: every other rank
	// writes its messages to /dev/null (each reads the same command line and sweep, so
	// rank 0 says what they would).
	bool quiet = false;
#ifdef PLUME_WITH_MPI
	quiet = sweep_mpi_launched() && sweep_mpi_launcher_rank() != 0;
#endif
	if (quiet && freopen("/dev/null", "w", stderr) == NULL)
		return CLI_EXIT_IO;
	int option;
	optind = 1;
	opterr = 0;
	while ((option = getopt_long(argc, argv, ":o:j:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 'j': {
			char *end = NULL;
			long value = strtol(optarg, &end, 10);
			if (end == optarg || *end != '\0' || value < 1 || value > 1024)
				return cli_usage_error("sweep", "-j expects a whole number in [1, 1024], got '%s'", optarg);
			jobs = (int)value;
			break;
		}
		case 'n': dry_run = true; break;
		case 'R': {
			char *end = NULL;
			max_runs = strtol(optarg, &end, 10);
			if (end == optarg || *end != '\0' || max_runs < 1 || max_runs > 1000000)
				return cli_usage_error("sweep", "--max-runs expects a whole number in [1, 1000000], got '%s'", optarg);
			break;
		}
		case 'h':
			if (!quiet)
				cli_help_sweep();
			return CLI_EXIT_OK;
		case ':': return cli_usage_error("sweep", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("sweep", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (!cli_check_arguments("sweep", argc, argv, "SWEEP.json", output_dir))
		return CLI_EXIT_USAGE;

	int rank = 0, size = 1;
	(void)size; // read by the MPI build only
#ifdef PLUME_WITH_MPI
	// Before anything prints, --dry-run too: under a launcher only rank 0 speaks.
	bool mpi = sweep_mpi_launched();
	if (mpi) {
		MPI_Init(NULL, NULL);
		MPI_Comm_rank(MPI_COMM_WORLD, &rank);
		MPI_Comm_size(MPI_COMM_WORLD, &size);
	}
#endif
	// Every rank reads the sweep (it is small; the workers start runs from it); only
	// rank 0 checks it, speaks (above) and writes DIR.
	sweep s;
	int code = CLI_EXIT_OK;
	if (!sweep_load(&s, argv[optind]))
		code = s.failure_code;
	else if (rank == 0 && !dry_run && s.run_count > max_runs) {
		// Before any run starts or DIR is touched: each run is a plume process.
		sweep_error(&s,
		            "$.samples (%d) x the grids' and lists' values (%d) make %d runs; the limit is %ld (raise it "
		            "with --max-runs, up to 1000000)",
		            s.samples, s.grid_count, s.run_count, max_runs);
		code = CLI_EXIT_LIMIT;
	} else if (rank == 0 && !sweep_check(&s))
		code = CLI_EXIT_INPUT;
	else if (rank == 0 && dry_run)
		print_plan(&s);
	sweep_state state;
	memset(&state, 0, sizeof state);
	if (code == CLI_EXIT_OK && rank == 0 && !dry_run) {
		int begin_code = CLI_EXIT_IO;
		if (!sweep_state_begin(&begin_code, &state, &s, output_dir))
			code = begin_code;
	}
#ifdef PLUME_WITH_MPI
	if (mpi) {
		MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
		if (code == CLI_EXIT_OK && !dry_run) {
			if (size == 1)
				code = sweep_run_local(&state, jobs) ? CLI_EXIT_OK : CLI_EXIT_IO;
			else if (rank == 0)
				code = sweep_mpi_schedule(&state, size) ? CLI_EXIT_OK : CLI_EXIT_IO;
			else
				sweep_mpi_work(&s, output_dir);
		}
	} else
#endif
	    if (code == CLI_EXIT_OK && !dry_run)
		code = sweep_run_local(&state, jobs) ? CLI_EXIT_OK : CLI_EXIT_IO;
	bool finished = rank == 0 && code == CLI_EXIT_OK && !dry_run;
	if (finished)
		code = sweep_write_summary(&state) ? CLI_EXIT_OK : CLI_EXIT_IO;
	if (finished && code == CLI_EXIT_OK && !s.keep_runs)
		sweep_runs_remove(output_dir); // and what killed attempts left of runs since done
	if (finished && code == CLI_EXIT_OK && sweep_ok_count(&state) == 0) {
		// Every row is kept, with its message; but a sweep that measured nothing failed.
		sweep_error(&s, "every run failed (%d of %d); results.csv in %s has their messages", s.run_count, s.run_count,
		            output_dir);
		code = CLI_EXIT_FAILURE;
	}
	sweep_state_end(&state);
	sweep_free(&s);
#ifdef PLUME_WITH_MPI
	if (mpi)
		MPI_Finalize();
#endif
	return code;
}

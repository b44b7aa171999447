// plume sweep (cli/sweep*.c): what the files of the sweep command share. Private to
// the CLI; the library knows nothing of sweeps (docs/sweeps.md, DESIGN.md).
//   sweep.c          the command line, --dry-run, and the order of the steps
//   sweep_commands.c the commands a sweep can run and the outputs they write
//   sweep_spec.c     reading SWEEP.json; sweep_paths.c its JSON paths
//   sweep_check.c    before any run: $.arguments, every value through the command's own
//                    spec reader, the outputs against the first run
//   sweep_values.c   each run's values: grids, lists, seeded samples; CSV text
//   sweep_run.c      a run as a child plume process in a folder the sweep marks as its
//                    own; the local scheduler (-j)
//   sweep_mpi.c      the MPI scheduler (rank 0) and workers
//   sweep_results.c  DIR/sweep.json, results.csv, timings.csv, resuming
//   sweep_stats.c    DIR/stats.json and DIR/plots
#ifndef PLUME_CLI_SWEEP_H
#define PLUME_CLI_SWEEP_H

#include <jansson.h>
#include <limits.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>
#ifndef PATH_MAX
#include <linux/limits.h> // PATH_MAX without _GNU_SOURCE; the sweep is Linux-only (prctl, /proc/self/exe)
#endif

#include "cli.h"
#include "plume/lab.h"

// Paths and messages are cut at their buffers' sizes (PATH_MAX-long folder names
// would make every buffer several pages); a cut message is still a message.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wformat-truncation"
#endif

// ---------------------------------------------------------------------------
// Commands a sweep can run (sweep_commands.c)

typedef enum probe_kind {
	PROBE_FEATHER,
	PROBE_MESH,
	PROBE_COAT,
	PROBE_SCENE,
	PROBE_LAB,
	PROBE_CALIBRATION,
	PROBE_RENDER
} probe_kind;

/// A value a command writes to its result file: a key into its JSON ("slope_pa",
/// "slopes.longitudinal", "guide_count[1]"). A key may hold one placeholder, <group>
/// (a mesh group's name), <handle> or <feather> (an index), which the first run's
/// probe checks (sweep_check.c).
typedef struct sweep_output {
	const char *key;
	const char *when; ///< the runs that write it ("with contact"); NULL: every run
} sweep_output;

typedef struct sweep_command {
	const char *name;
	const char *words[2]; ///< the command line words before the spec
	probe_kind probe;
	/// File (in the run's output folder) whose JSON holds the outputs; "stdout" for
	/// a command that prints its result; NULL for none.
	const char *result;
	/// Every number and boolean that file has; {NULL} ends the list.
	const sweep_output *outputs;
} sweep_command;

enum { SWEEP_COMMAND_COUNT = 7 };
extern const sweep_command sweep_commands[SWEEP_COMMAND_COUNT];
/// The output of command that key names, or NULL. hole receives the text standing for
/// the output's placeholder (a group name, an index); empty when it has none.
const sweep_output *sweep_output_find(const sweep_command *command, const char *key, char *hole, size_t size);
/// The keys of a render frames spec; NULL-terminated.
extern const char *const sweep_render_keys[];

// The calibration has no spec file: its spec is an object of the command's options, the
// keys of cli_calibrate_options (cli.h).

// ---------------------------------------------------------------------------
// The sweep (sweep_spec.c)

typedef enum dist_kind { DIST_NONE, DIST_UNIFORM, DIST_NORMAL, DIST_LOGNORMAL } dist_kind;

/// An integer parameter's values lie in [-2^53, 2^53], where a double holds every integer: they
/// become JSON integers exactly (json_int_t), and a rounding or a cast of a larger one is not defined.
#define SWEEP_MAX_INTEGER 9007199254740992.0

typedef struct sweep_param {
	char path[256]; ///< "$.material.barb_fraction"
	char name[256]; ///< "material.barb_fraction", the CSV column
	json_t *values; ///< grid or list: an array of values
	dist_kind dist;
	double a, b;   ///< uniform: [a, b]; normal: mean, std; log-normal: mean and std of ln x
	double lo, hi; ///< truncation (or -inf, inf)
	bool integer;  ///< random values rounded to integers
	int zip_lead;  ///< columns of one CSV go together: the first such parameter; -1 for others
} sweep_param;

typedef struct sweep {
	const char *file;
	/// Why sweep_load failed: CLI_EXIT_INPUT (a bad sweep), CLI_EXIT_IO (a file it reads
	/// cannot be read) or CLI_EXIT_LIMIT (more runs than a sweep may have).
	int failure_code;
	char base_dir[PATH_MAX];
	const sweep_command *command;
	json_t *root; ///< the sweep file
	json_t *spec; ///< the base spec, paths made absolute
	json_t *arguments;
	sweep_param params[32];
	int param_count;
	int random_count;
	int samples;
	uint64_t seed;
	char outputs[32][128];
	int output_count;
	bool keep_runs;
	int grid_count; ///< product of the grid/list lengths
	int run_count;
} sweep;

/// The runs a sweep may have unless --max-runs raises it (docs/cli.md, Limits); $.samples and the
/// grids allow up to 1000000.
#define SWEEP_DEFAULT_MAX_RUNS 100000L

/// Prints "plume: FILE: message" on stderr; returns false.
bool sweep_error(const sweep *s, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/// Reads and checks the sweep file (false after a message); sweep_free in either case.
bool sweep_load(sweep *s, const char *file);
void sweep_free(sweep *s);
/// Whether parameter i is a dimension of the grid (zipped columns share their first's).
bool sweep_owns_dimension(const sweep_param *p, int i);

// JSON paths (sweep_paths.c): "$" followed by ".key" and "[index]" parts.
/// The value at path in root and its parent (for replacement); NULL when absent.
/// *settable: the path names a key the parent object lacks (a key left to its default).
json_t *sweep_path_lookup(json_t *root, const char *path, json_t **parent, char *key, size_t key_size, size_t *index,
                          bool *settable);
/// Sets the value at path (taking the reference); false when the path is not there.
bool sweep_path_set(json_t *root, const char *path, json_t *value);
/// The scalar path in root nearest to path (for "did you mean"); best holds 512 bytes.
void sweep_nearest_path(const json_t *node, const char *prefix, const char *path, char *best, size_t *best_distance);

/// $.arguments (refused when the sweep sets them or the command does not take them),
/// every grid/list value and the ends of every distribution's range through the
/// command's spec reader, and the outputs the first run's probe resolves (sweep_check.c);
/// false after a message.
bool sweep_check(const sweep *s);

// Values of a run (sweep_values.c)
/// Probability mass of [lo, hi] under the parameter's distribution (before truncation).
double sweep_param_mass(const sweep_param *p);
/// Value of parameter param in run index (new reference).
json_t *sweep_run_value(const sweep *s, int param, int index);
/// CSV text of a scalar: numbers to 17 digits (they round-trip), strings quoted when needed.
void sweep_csv_value(char *out, size_t size, const json_t *value);
/// The spec of run index (new reference).
json_t *sweep_run_spec(const sweep *s, int index);

// ---------------------------------------------------------------------------
// DIR (sweep_results.c)

typedef struct sweep_state {
	const sweep *s;
	const char *dir;
	char **rows; ///< per index, NULL until done
	int done;
	char header[8192];
} sweep_state;

/// Creates DIR or, when it holds this same sweep, reads the rows already done.
/// False after a message; *code says why (CLI_EXIT_INPUT: DIR holds another sweep;
/// CLI_EXIT_IO: DIR cannot be written, or writing it would replace files not the sweep's).
bool sweep_state_begin(int *code, sweep_state *state, const sweep *s, const char *dir);
void sweep_state_end(sweep_state *state);
/// Writes the parts to path.tmp, syncs it and renames it over path.
bool sweep_write_atomic(const char *path, const char *const *parts, int count);
/// Keeps row (malloc'd; NULL: out of memory) as run index's and rewrites results.csv.
bool sweep_record_row(sweep_state *state, int index, char *row);
/// Appends "index,seconds,worker" to DIR/timings.csv.
void sweep_record_timing(const sweep_state *state, int index, double seconds, int worker);
/// Splits a CSV line into its first field (the index) and its status field.
bool sweep_parse_row(const char *line, int field_count, int *index, char *status, size_t size);
/// Field k of a row sweep wrote (its quotes kept): start and length; false when the
/// row has fewer fields. (Another sweep's results.csv, which may have been edited,
/// is read by sweep_spec.c's csv_field, which also unquotes.)
bool sweep_row_field(const char *row, int k, const char **start, size_t *length);

// Runs (sweep_run.c, sweep_mpi.c)
/// Writes the run's spec and starts plume on it; the pid, or -1 (message in failure).
pid_t sweep_run_start(const sweep *s, const char *dir, int index, char *failure, size_t size);
/// The CSV row of a finished run (wait_status from waitpid; pid < 0: it never started).
char *sweep_run_finish(const sweep *s, const char *dir, int index, pid_t pid, int wait_status, const char *failure);
/// Runs every missing run with up to jobs children at once.
bool sweep_run_local(sweep_state *state, int jobs);

// Run folders DIR/runs/NNNNNN are the sweep's only when they hold this marker; the sweep
// removes only its own folders and in them only what a run writes (sweep_run.c).
#define SWEEP_RUN_MARKER ".plume-sweep-run"
/// DIR/runs/NNNNNN of run index.
void sweep_run_folder(const char *dir, int index, char *out, size_t size);
/// Whether folder holds the sweep's marker.
bool sweep_run_folder_ours(const char *folder);
/// Removes what the sweep and its run wrote in folder, and folder when that empties it.
void sweep_run_folder_remove(const char *folder);
/// Removes the sweep's run folders in DIR/runs, and DIR/runs when the sweep made it and
/// nothing else is left in it.
void sweep_runs_remove(const char *dir);
#ifdef PLUME_WITH_MPI
/// Whether this process was started by an MPI launcher (mpirun, srun).
bool sweep_mpi_launched(void);
/// The rank the launcher gave this process, before MPI starts; 0 when none.
int sweep_mpi_launcher_rank(void);
/// Rank 0: hands the missing runs out one at a time as ranks become free, gathers the rows.
bool sweep_mpi_schedule(sweep_state *state, int size);
/// Ranks other than 0: runs what rank 0 hands out until it says stop.
void sweep_mpi_work(const sweep *s, const char *dir);
#endif

/// DIR/stats.json, DIR/plots/*.png and the summary line (sweep_stats.c).
bool sweep_write_summary(const sweep_state *state);
/// The rows with status ok.
int sweep_ok_count(const sweep_state *state);

#endif

// Benchmark: the paper's Figure 1 scenario (examples/scenes/figure1-anisotropic.json, the
// vane tip pulled 3 cm) in full, anisotropic and isotropic, at the paper's resolution
// (e = 5 mm) and at 2.5 mm: wall and CPU time, steps, Newton iterations a step, steps
// retried in substeps and the largest barb strain (issue 13). Then the scaling series on
// finer meshes (e = 2.5, 1.75, 1.25 mm) and the solver's floor: per mesh size, the CPU
// of one Newton iteration against the CPU of one numeric factorisation (run to the end)
// of the same KKT matrix in the same run, their ratio, factorisations and solves per iteration,
// CHOLMOD's GFlop/s, where the rest of an iteration goes (assembly, factoring, solves, the line
// search), and the exponent k of time ~ V^k fitted over the sizes. Last,
// the `plume simulate` command on the 5 mm scene (all its files) against the
// library's load and run of the same scene (issue 15's target: within 20 %).
//
// The factorisations and solves are counted and timed by wrapping CHOLMOD's entry
// points at link time (bench/CMakeLists.txt: --wrap=cholmod_factorize,
// --wrap=cholmod_solve2), so the library carries no benchmark code. Times are CPU
// times (the machine may be shared: CPU seconds are steadier than wall seconds).
// The scaling series runs every mesh size over the scene's first SCALING_DURATION
// seconds, before the vane buckles, and fits CPU per step against vertex count. (The
// buckling steps take many more Newton iterations and would measure the bifurcation, not
// the solver's growth; the whole runs at 1.75 and 1.25 mm take minutes and are in
// docs/simulation.md, Speed.) `bench_simulate quick` runs the 5 mm runs only,
// `bench_simulate all` adds e = 1.25 mm (5,000 vertices) to the series, and
// `bench_simulate buckling` runs the whole 1.1 s at every size, anisotropic and isotropic.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cholmod.h>

#include "plume/plume.h"

#include "bench_support.h"

// ---------------------------------------------------------------------------
// CHOLMOD, counted

typedef struct counters {
	long factorizations; ///< every call, the ones that stop at a pivot that is not positive too
	long solves;
	double factor_cpu; ///< seconds, this thread, every call
	/// The factorisations that ran to the end (L->minor == n): the floor an iteration is
	/// measured against. One that finds the matrix not positive definite stops at that
	/// pivot, after a fraction of the work (Newton's shift ladder, kkt.h), so it is no
	/// measure of one factorisation.
	long complete;
	double complete_cpu;
	double complete_cpu_min; ///< the fastest complete factorisation
	double flops;            ///< CHOLMOD's count (Common->fl) summed over the complete ones
	double solve_cpu;
} counters;

static counters counted;

static double thread_cpu(void)
{
	struct timespec t;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double wall_clock(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double process_cpu(void)
{
	struct timespec t;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int __real_cholmod_factorize(cholmod_sparse *A, cholmod_factor *L, cholmod_common *Common);
int __wrap_cholmod_factorize(cholmod_sparse *A, cholmod_factor *L, cholmod_common *Common);
int __real_cholmod_solve2(int sys, cholmod_factor *L, cholmod_dense *B, cholmod_sparse *Bset, cholmod_dense **X_Handle,
                          cholmod_sparse **Xset_Handle, cholmod_dense **Y_Handle, cholmod_dense **E_Handle,
                          cholmod_common *Common);
int __wrap_cholmod_solve2(int sys, cholmod_factor *L, cholmod_dense *B, cholmod_sparse *Bset, cholmod_dense **X_Handle,
                          cholmod_sparse **Xset_Handle, cholmod_dense **Y_Handle, cholmod_dense **E_Handle,
                          cholmod_common *Common);

int __wrap_cholmod_factorize(cholmod_sparse *A, cholmod_factor *L, cholmod_common *Common)
{
	double start = thread_cpu();
	int result = __real_cholmod_factorize(A, L, Common);
	double seconds = thread_cpu() - start;
	counted.factorizations += 1;
	counted.factor_cpu += seconds;
	if (L->minor == L->n) {
		counted.complete += 1;
		counted.complete_cpu += seconds;
		if (counted.complete == 1 || seconds < counted.complete_cpu_min)
			counted.complete_cpu_min = seconds;
		// fl: the flop count of the whole factorisation, set by cholmod_analyze for this pattern.
		counted.flops += Common->fl;
	}
	return result;
}

int __wrap_cholmod_solve2(int sys, cholmod_factor *L, cholmod_dense *B, cholmod_sparse *Bset, cholmod_dense **X_Handle,
                          cholmod_sparse **Xset_Handle, cholmod_dense **Y_Handle, cholmod_dense **E_Handle,
                          cholmod_common *Common)
{
	double start = thread_cpu();
	int result = __real_cholmod_solve2(sys, L, B, Bset, X_Handle, Xset_Handle, Y_Handle, E_Handle, Common);
	counted.solve_cpu += thread_cpu() - start;
	counted.solves += 1;
	return result;
}

// ---------------------------------------------------------------------------
// Runs

/// Simulated seconds of the scaling series: 15 steps of 11 ms, converged on every size.
static const double SCALING_DURATION = 0.165;

typedef struct result {
	int vertices;
	int steps;
	double cpu;     ///< load, mesh and run
	double run_cpu; ///< plume_scene_run alone
	double wall;    ///< load, mesh and run, wall seconds
	int iterations;
	double rachis_tip; ///< the rachis tip's deflection at the end (m)
	counters c;
} result;

static int load(const char *name, double edge_length, plume_scene **out)
{
	char path[1024];
	snprintf(path, sizeof path, "%s/examples/scenes/%s.json", PLUME_SOURCE_DIR, name);
	plume_scene *scene = NULL;
	plume_error err = {0};
	if (plume_scene_load(path, NULL, &scene, &err) != PLUME_OK) {
		fprintf(stderr, "%s\n", err.message);
		return 1;
	}
	*out = scene;
	if (edge_length == 0.005)
		return 0;
	// Re-mesh the same feather finer.
	plume_mesh_def def = plume_mesh_default_def();
	def.edge_length = edge_length;
	def.rachis_width_base = 0.008;
	def.rachis_width_tip = 0.004;
	plume_mesh *mesh = NULL;
	if (plume_mesh_from_feather(scene->feather, &def, &mesh, &scene->mesh_report, &err) != PLUME_OK) {
		fprintf(stderr, "%s\n", err.message);
		return 1;
	}
	// Handles that select vertices near a point are selected again on the new mesh.
	for (int h = 0; h < scene->handle_count; ++h) {
		plume_scene_handle *handle = scene->handles + h;
		if (handle->near_given && plume_mesh_add_group_near(mesh, handle->group, handle->source_group, handle->near,
		                                                    handle->radius, &err) != PLUME_OK) {
			fprintf(stderr, "%s\n", err.message);
			plume_mesh_destroy(mesh);
			return 1;
		}
	}
	plume_mesh_destroy(scene->mesh);
	scene->mesh = mesh;
	return 0;
}

/// Runs the scene on a mesh of this edge length, for duration seconds (0: the scene's).
static int run(const char *name, double edge_length, double duration, result *out)
{
	double start = process_cpu(), load_wall = wall_clock();
	plume_scene *scene = NULL;
	if (load(name, edge_length, &scene) != 0) {
		plume_scene_destroy(scene);
		return 1;
	}
	if (duration > 0)
		scene->duration = duration;
	counted = (counters){0};
	plume_scene_summary summary;
	plume_error err = {0};
	double run_start = process_cpu(), wall_start = wall_clock();
	plume_status status = plume_scene_run(scene, NULL, NULL, &summary, &err);
	double end = process_cpu(), wall = wall_clock() - wall_start;
	*out = (result){.vertices = summary.vertex_count,
	                .steps = summary.steps,
	                .cpu = end - start,
	                .run_cpu = end - run_start,
	                .wall = wall_clock() - load_wall,
	                .iterations = summary.newton_iterations,
	                .rachis_tip = summary.rachis_tip_deflection,
	                .c = counted};
	const counters *c = &out->c;
	double iterations = summary.newton_iterations > 0 ? summary.newton_iterations : 1;
	double per_iteration = out->run_cpu / iterations;
	double per_factor = c->complete > 0 ? c->complete_cpu / (double)c->complete : 0;
	printf("%-20s e = %4.2f mm %5d vertices %5d faces %4d constraints | %s %3d steps (%d retried) %5d iterations "
	       "(%.2f a step) %6.2f s CPU (%.1f ms a step), %6.2f s wall, strain %.1e, rachis tip %.4f cm\n",
	       name, 1000 * edge_length, summary.vertex_count, summary.face_count, summary.constraint_count,
	       status == PLUME_OK ? "ok    " : "FAILED", summary.steps, summary.retried_steps, summary.newton_iterations,
	       summary.steps > 0 ? (double)summary.newton_iterations / summary.steps : 0.0, out->run_cpu,
	       summary.steps > 0 ? 1e3 * out->run_cpu / summary.steps : 0.0, wall, summary.max_barb_strain,
	       100 * summary.rachis_tip_deflection);
	printf("%-20s   per iteration %7.2f ms CPU; one factorisation %6.2f ms (fastest %6.2f ms); ratio %5.2f; "
	       "%.2f factorisations (%.2f complete) and %.2f solves an iteration; factorisation %4.1f %% of the run, "
	       "%.2f GFlop/s; solves %4.1f %%\n",
	       "", 1e3 * per_iteration, 1e3 * per_factor, 1e3 * c->complete_cpu_min,
	       per_factor > 0 ? per_iteration / per_factor : 0.0, (double)c->factorizations / iterations,
	       (double)c->complete / iterations, (double)c->solves / iterations, 100 * c->factor_cpu / out->run_cpu,
	       c->complete_cpu > 0 ? 1e-9 * c->flops / c->complete_cpu : 0.0, 100 * c->solve_cpu / out->run_cpu);
	// Where the rest of an iteration goes, by the library's own wall clocks (plume_scene_summary):
	// what a ratio above 1 is made of. And the ratio by wall time: the factorisation runs on one
	// thread (OpenBLAS held to one, CHOLMOD's OpenMP regions off: sim/sparse.c), so its CPU is
	// its wall time, while an iteration's CPU also counts the OpenMP threads of the assembly,
	// which from 4096 faces on (e = 1.75 mm) spin through the serial factorisation under
	// libgomp's default wait policy: measured there, 2.42 by CPU, 1.77 with
	// OMP_WAIT_POLICY=passive, about 1.6 by wall time. Below 4096 faces both ratios agree.
	double rest =
	    wall - summary.seconds_assembly - summary.seconds_factor - summary.seconds_solve - summary.seconds_contact;
	printf("%-20s   an iteration's wall time: assembly %.2f ms, factoring %.2f ms (loading the reduced matrix and "
	       "failed shifts included), solves %.2f ms, contact %.2f ms, the rest %.2f ms (line search, checks); "
	       "%.2f factorisations by wall time\n",
	       "", 1e3 * summary.seconds_assembly / iterations, 1e3 * summary.seconds_factor / iterations,
	       1e3 * summary.seconds_solve / iterations, 1e3 * summary.seconds_contact / iterations,
	       1e3 * rest / iterations, per_factor > 0 ? wall / iterations / per_factor : 0.0);
	if (status != PLUME_OK)
		printf("  %s\n", err.message);
	plume_scene_destroy(scene);
	return status == PLUME_OK ? 0 : 1;
}

/// Least-squares slope of log y against log x: y the CPU a step, or one factorisation's.
static double exponent(const result *r, int count, bool factor)
{
	double sx = 0, sy = 0, sxx = 0, sxy = 0;
	for (int i = 0; i < count; ++i) {
		double per_factor = r[i].c.complete_cpu / (double)(r[i].c.complete > 0 ? r[i].c.complete : 1);
		double x = log(r[i].vertices), y = log(factor ? per_factor : r[i].run_cpu / (r[i].steps > 0 ? r[i].steps : 1));
		sx += x, sy += y, sxx += x * x, sxy += x * y;
	}
	return (count * sxy - sx * sy) / (count * sxx - sx * sx);
}

/// `plume simulate` of Figure 1 with all its files: CPU seconds (returned; -1 when it
/// fails) and wall seconds (*wall). Its feather dump and OBJ frames are written by a
/// second thread beside the run (cli/writer.c), so on two cores its wall time is the
/// nearer to the library's.
static double command_cpu(double *wall)
{
	char dir[] = "/tmp/plume-bench-XXXXXX";
	if (mkdtemp(dir) == NULL)
		return -1;
	char command[2048];
	snprintf(command, sizeof command,
	         "'%s' simulate '%s/examples/scenes/figure1-anisotropic.json' -o '%s/out' >/dev/null 2>&1", PLUME_BINARY,
	         PLUME_SOURCE_DIR, dir);
	struct rusage before, after;
	getrusage(RUSAGE_CHILDREN, &before);
	double start = wall_clock();
	int status = system(command);
	*wall = wall_clock() - start;
	getrusage(RUSAGE_CHILDREN, &after);
	snprintf(command, sizeof command, "rm -rf '%s'", dir);
	if (system(command) != 0 || status != 0)
		return -1;
	double seconds = (double)(after.ru_utime.tv_sec - before.ru_utime.tv_sec) +
	                 (double)(after.ru_stime.tv_sec - before.ru_stime.tv_sec) +
	                 1e-6 * (double)(after.ru_utime.tv_usec - before.ru_utime.tv_usec) +
	                 1e-6 * (double)(after.ru_stime.tv_usec - before.ru_stime.tv_usec);
	return seconds;
}

/// The library's load and run of the 5 mm scene, as the command does them, printing nothing:
/// CPU seconds (returned; -1 when it fails) and wall seconds (*wall).
static double library_cpu(double *wall)
{
	double start = process_cpu(), start_wall = wall_clock();
	plume_scene *scene = NULL;
	plume_scene_summary summary;
	plume_error err = {0};
	bool ok = load("figure1-anisotropic", 0.005, &scene) == 0 &&
	          plume_scene_run(scene, NULL, NULL, &summary, &err) == PLUME_OK;
	plume_scene_destroy(scene);
	*wall = wall_clock() - start_wall;
	return ok ? process_cpu() - start : -1;
}

/// `bench_simulate buckling`: the whole run, through the vane's buckling, anisotropic and
/// isotropic, at every size, and the ratio of their rachis tips (docs/simulation.md, Speed;
/// about 10 minutes on one core).
static int buckling(const double *sizes, int count)
{
	int failures = 0;
	for (int i = 0; i < count; ++i) {
		result anisotropic, isotropic;
		failures += run("figure1-anisotropic", sizes[i], 0, &anisotropic);
		failures += run("figure1-isotropic", sizes[i], 0, &isotropic);
		printf("e = %.2f mm: rachis tip %.4f cm, isotropic %.4f cm, ratio %.3f\n", 1000 * sizes[i],
		       100 * anisotropic.rachis_tip, 100 * isotropic.rachis_tip, anisotropic.rachis_tip / isotropic.rachis_tip);
	}
	return failures == 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
	bool quick = argc > 1 && argv[1][0] == 'q', all = argc > 1 && argv[1][0] == 'a';
	static const double sizes[] = {0.005, 0.0025, 0.00175, 0.00125};
	if (argc > 1 && argv[1][0] == 'b')
		return buckling(sizes, 4);
	int size_count = quick ? 1 : all ? 4 : 3;
	result paper, results[4], isotropic;
	int failures = run("figure1-anisotropic", 0.005, 0, &paper);
	failures += run("figure1-isotropic", 0.005, 0, &isotropic);
	if (!quick) {
		result fine;
		failures += run("figure1-anisotropic", 0.0025, 0, &fine);
		failures += run("figure1-isotropic", 0.0025, 0, &fine);
	}
	if (size_count > 1) {
		printf("scaling series: every size over the first %.2f s\n", SCALING_DURATION);
		for (int i = 0; i < size_count; ++i)
			failures += run("figure1-anisotropic", sizes[i], SCALING_DURATION, results + i);
		printf("fitted exponent, time ~ V^k over %d sizes: CPU a step k = %.2f, one factorisation k = %.2f\n",
		       size_count, exponent(results, size_count, false), exponent(results, size_count, true));
	}
	// The command against the library, in turns, COMMAND_RUNS times each: one run of each
	// varied by 1.14-1.38 in CPU on an idle machine (2026-11-29), the medians by less.
	enum { COMMAND_RUNS = 5 };
	double command[COMMAND_RUNS], command_wall[COMMAND_RUNS], library[COMMAND_RUNS], library_wall[COMMAND_RUNS];
	for (int i = 0; i < COMMAND_RUNS; ++i) {
		library[i] = library_cpu(library_wall + i);
		command[i] = command_cpu(command_wall + i);
		if (library[i] < 0 || command[i] < 0) {
			printf("plume simulate or the library's run failed (%s)\n", PLUME_BINARY);
			return 1;
		}
	}
	double c = bench_median(command, COMMAND_RUNS), cw = bench_median(command_wall, COMMAND_RUNS);
	double l = bench_median(library, COMMAND_RUNS), lw = bench_median(library_wall, COMMAND_RUNS);
	printf("plume simulate figure1-anisotropic (all files): %.2f s CPU, %.2f s wall; library load + run %.2f s CPU, "
	       "%.2f s wall (medians of %d in turns); command / library = %.2f CPU, %.2f wall (target <= 1.20)\n",
	       c, cw, l, lw, COMMAND_RUNS, c / l, cw / lw);
	return failures == 0 ? 0 : 1;
}

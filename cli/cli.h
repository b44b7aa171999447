// The plume command: shared pieces of the subcommands.
#ifndef PLUME_CLI_H
#define PLUME_CLI_H

#include <stdbool.h>

#include "plume/plume.h"

/// Exit codes (docs/cli.md).
enum {
	CLI_EXIT_OK = 0,
	CLI_EXIT_FAILURE = 1, ///< a computation failed
	CLI_EXIT_USAGE = 2,   ///< bad command line
	CLI_EXIT_INPUT = 3,   ///< a spec or input file is malformed or has a bad value
	CLI_EXIT_IO = 4,      ///< a file could not be read or written
	CLI_EXIT_LIMIT = 5,   ///< refused before the work: past a resource limit (--max-memory)
};

/// Output formats, as a bit set.
enum {
	CLI_FORMAT_PNG = 1u << 0,
	CLI_FORMAT_SVG = 1u << 1,
	CLI_FORMAT_PDF = 1u << 2,
	CLI_FORMAT_OBJ = 1u << 3,
	CLI_FORMAT_USDA = 1u << 4,
	CLI_FORMAT_JSON = 1u << 5,
	CLI_FORMAT_ALL = (1u << 6) - 1, ///< generate's default set (glb is asked for by name)
	CLI_FORMAT_GLB = 1u << 6,       ///< glTF 2.0 binary (plume/gltf.h)
};

/// Prints "plume: message" on stderr and returns the exit code for the status.
int cli_fail(const plume_error *err);

/// Prints "plume: <command>: message" and a hint to the command's help; returns CLI_EXIT_USAGE.
int cli_usage_error(const char *command, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/// Parses "png,svg,obj"; false (and a usage message) on an unknown name.
bool cli_parse_formats(const char *command, const char *list, unsigned *formats);
/// The formats' names, comma-separated ("png, svg"), into text.
void cli_format_list(unsigned formats, char *text, size_t size);

/// Parses "WxH" with both in [16, 16384].
bool cli_parse_size(const char *command, const char *text, int *width, int *height);
/// Without --size: the width of a picture height pixels tall that frames a w x h view (margin: a
/// fraction of the height on each side), in [256, 4096]; height when h is not > 0.
int cli_image_width(double w, double h, int height, double margin);

/// One numeric option of `plume lab calibrate` and the values it allows alone (the ranges
/// between options, such as the band period against the sample's size, are the command's own
/// check, cli/lab.c). `plume sweep` takes the same options as keys of a calibration's spec and
/// checks them against the same table before any run.
typedef struct cli_calibrate_option {
	const char *key;    ///< the sweep's key: "phi", "macro_elements"
	const char *option; ///< the command's option: "--phi", "--macro-elements"
	const char *unit;   ///< printed after a value in messages: " Pa", " m" or ""
	const char *what;   ///< said of the option in messages, or NULL
	bool integer;       ///< an int field (a whole number), else a double
	double lo, hi;      ///< the allowed range, closed at an end where the flag says so
	bool lo_closed, hi_closed;
	size_t offset; ///< of the value in plume_calibration_def
} cli_calibrate_option;
enum { CLI_CALIBRATE_OPTION_COUNT = 11 };
extern const cli_calibrate_option cli_calibrate_options[CLI_CALIBRATE_OPTION_COUNT];
/// Whether value is in the option's range (and whole, for an integer option).
bool cli_calibrate_option_allows(const cli_calibrate_option *option, double value);
/// "value, allowed in (lo, hi]" style text of the option's range: "(0, 1e12]", "[2, 4000000]".
void cli_calibrate_option_range(const cli_calibrate_option *option, char *text, size_t size);

/// After the options: exactly one positional argument (named input in the message,
/// "SPEC.json") and an output folder. False after printing the usage error.
bool cli_check_arguments(const char *command, int argc, char **argv, const char *input, const char *output_dir);

/// Parses --style: lines or strips.
bool cli_parse_style(const char *command, const char *text, plume_render_style *style);

/// Parses a decimal seed.
bool cli_parse_seed(const char *command, const char *text, uint64_t *seed);
/// Parses --max-memory: bytes with an optional K, M, G or T suffix (powers of 1024), at least 1M.
bool cli_parse_memory(const char *command, const char *text, uint64_t *bytes);

/// How a feather's images are drawn.
typedef struct cli_image_options {
	int width, height;            ///< 0: height 1200 and the width from the feather's aspect
	const plume_texture *texture; ///< NULL: the line style
} cli_image_options;

/// PLUME_ERROR_LIMIT when what the library holds now (the input, named held_name: "feather")
/// and the largest output's bytes pass max_memory (0: the default), checked before any file is
/// written: "SPEC: writing FORMATS (--format OPTIONS) takes up to ...". options: the other flags
/// that size the outputs, each after ", " (", --size 800x600"), or "".
plume_status cli_check_output_memory(const char *spec, const char *held_name, unsigned formats, const char *options,
                                     double outputs, uint64_t max_memory, plume_error *err);

/// Makes the missing parent folders of path (mkdir -p of its parent): 0, or the errno of the
/// folder that could not be made (*made then its path's length, and none left made). *made:
/// the length of the path of the topmost folder made, 0 when every one existed.
int cli_make_parents(const char *path, int *made);
/// Removes the folders cli_make_parents made for path (made: its *made), deepest first, each
/// only if empty.
void cli_remove_parents(const char *path, int made);

// A set of output files written all together or not at all: files go to a
// staging folder beside the destination, which replaces it in one rename only
// when every one of them was written (cli/output.c says how).
typedef struct cli_output {
	char dir[2048];
	char stage[4160];
	bool dir_existed;
	/// The length of the path of the topmost of DIR's parent folders this run made (they are
	/// removed again when it aborts, if empty); 0 when every one existed.
	int parents_made;
	bool stage_inside; ///< staged inside DIR (its parent is not writable): committed entry by entry
	int stage_slot;    ///< 1 + its slot in output.c's list for the signal handler, 0 when none
	char names[32][80];
	int name_count;
} cli_output;

plume_status cli_output_begin(cli_output *output, const char *dir, plume_error *err);
/// Path of a new file in the staging folder; remembers the name for commit.
const char *cli_output_path(cli_output *output, const char *name, char *buffer, size_t size);
plume_status cli_output_commit(cli_output *output, plume_error *err);
/// Removes the staging folder; with err, first names DIR instead of it in err's message.
void cli_output_abort(cli_output *output, plume_error *err);
/// Records in DIR's run manifest (cli/output.c) the files folder/names[i] that a run moved
/// into DIR itself (plume render --frames joining DIR/frames/), so that the next run into
/// DIR replaces them as plume's; nothing to do when DIR has no manifest.
plume_status cli_output_manifest_add(const char *dir, const char *folder, const char *const *names, int count,
                                     plume_error *err);
/// Removes a file or a folder and everything in it (links removed, not followed).
void cli_remove_tree(const char *path);

/// Writes <stem>.<ext> for every format in the set into the staging folder.
plume_status cli_write_feather(cli_output *output, const plume_feather *feather, const char *stem, unsigned formats,
                               const cli_image_options *images, plume_error *err);
/// One file of a feather: its format (one CLI_FORMAT_ bit) and its path in the staging folder.
enum { CLI_FEATHER_FORMATS = 7 };
typedef struct cli_feather_file {
	unsigned format;
	char path[4352];
} cli_feather_file;
/// cli_write_feather in two halves, so that the files can be written on another thread
/// (cli/grow.c's writer): the paths of <stem>.<ext> for every format in the set, in the
/// order cli_write_feather writes them (files holds CLI_FEATHER_FORMATS; returns how many),
/// registered with output; then one file, touching no cli_output. Images are drawn with
/// image; a glTF file takes texture.
int cli_feather_file_paths(cli_output *output, const char *stem, unsigned formats, cli_feather_file files[]);
plume_status cli_write_feather_file(const plume_feather *feather, const cli_feather_file *file,
                                    const plume_render2d_def *image, const plume_texture *texture, plume_error *err);

/// Many feathers carried by one joined shell, and a body, drawn together (cli/carry.c): the
/// one path of `plume simulate --render` and `plume render` of a many-feather run folder.
/// Each feather's barbs are embedded in its own face range of the shell
/// (plume_embedding_create_faces); the body (and, when asked, the simulated shell) is one
/// plain surface.
typedef struct cli_carried {
	int count;                         ///< feathers (NULL embeddings are not drawn: guides)
	plume_barb_embedding **embeddings; ///< per feather
	plume_feather **moved;             ///< per feather, after cli_carried_pose (NULL: not drawn)
	int shell_vertices;                ///< vertices of the drawn shell taken from the feathers' shell (0: none)
	plume_mesh *surface;               ///< the shell (--shell) then the body, or NULL
	plume_vec3 *surface_positions;
	const plume_feather **list; ///< the drawn feathers, for the ray tracer
} cli_carried;

/// feathers[i] (NULL: not drawn) is embedded in the faces [faces[2 i], faces[2 i] + faces[2 i + 1])
/// of shell. draw_shell: the shell itself is drawn too. body may be NULL. shell and body are
/// copied where needed; shell must outlive c.
plume_status cli_carried_begin(cli_carried *c, const plume_mesh *shell, int count, const plume_feather *const *feathers,
                               const int *faces, bool draw_shell, const plume_mesh *body, plume_error *err);
/// Carries every feather to the shell's positions and places the body at body_positions (its
/// rest when NULL): *scene then draws them until the next call or cli_carried_end.
plume_status cli_carried_pose(cli_carried *c, const plume_vec3 *positions, const plume_vec3 *body_positions,
                              plume_raytrace_scene *scene, plume_error *err);
void cli_carried_end(cli_carried *c);

/// The box a scene's sequence stays in: the rest shell grown by the largest handle
/// translation (at least a tenth of its size), so every frame shares one framing.
void cli_scene_bounds(const plume_scene *scene, plume_vec3 *lo, plume_vec3 *hi);

/// Ray-traced frames of a simulation at barb level: the render settings with a camera that
/// frames the box [lo, hi] (the whole sequence's reach) in a width x height image.
plume_raytrace_def cli_sequence_render_def(plume_vec3 lo, plume_vec3 hi, int width, int height, int spp);
/// The scene's feathers, each embedded in its own faces of the scene's shell, and its body
/// (cli_carried_begin): what cli_carried_pose then carries to every frame.
plume_status cli_carry_scene(const plume_scene *scene, cli_carried *carried, plume_error *err);

/// A progress line with a time estimate on stderr, when it is a terminal (cli/progress.c).
typedef struct cli_progress {
	const char *what;
	int total;
	double start;
	bool shown;
	bool open;      ///< a line is shown and not finished
	double printed; ///< when the last line was printed, < 0 before the first
} cli_progress;
void cli_progress_begin(cli_progress *progress, const char *what, int total);
/// done items of total finished; prints a newline when done reaches total.
void cli_progress_update(cli_progress *progress, int done);
/// Seconds on the monotonic clock (for durations).
double cli_now_seconds(void);
/// The same with ", note" after the estimate (e.g. the simulated time).
void cli_progress_update_note(cli_progress *progress, int done, const char *note);
/// A plume_progress_fn for the library's loops (coats, calibrations, studies); user is a
/// cli_progress begun with any total > 0, which each call replaces.
void cli_progress_callback(void *user, int done, int total);
/// Ends an unfinished line (a failed run) so that the error message starts on its own line.
void cli_progress_end(cli_progress *progress);

/// simulate --fields (cli/fields.c): DIR/fields/NNNN.vtu for the simulator's current state.
plume_status cli_fields_write_frame(cli_output *output, const plume_scene *scene, const plume_sim *sim, int frame,
                                    plume_error *err);
/// DIR/fields.pvd listing fields/0000.vtu ... with their times.
plume_status cli_fields_write_pvd(cli_output *output, const double *times, int frames, plume_error *err);

/// A background writer (cli/writer.c): one thread running file-writing jobs, oldest first,
/// beside the computation (the handing thread helps when its queue is full). A job returns
/// a status and fills err on failure; the first failure drops the jobs after it.
typedef plume_status cli_writer_job_fn(void *data, plume_error *err);
typedef struct cli_writer cli_writer;
/// Fails only when out of memory; where no thread can be started, jobs run where they are
/// handed over.
plume_status cli_writer_start(cli_writer **out, plume_error *err);
/// Queues run(data) and then release(data) (release may be NULL); while the queue is full,
/// runs its oldest job on the calling thread first. After a failure the job is not run,
/// only released.
void cli_writer_submit(cli_writer *writer, cli_writer_job_fn *run, void (*release)(void *data), void *data);
/// The first failure so far (err: its error, when not NULL), or PLUME_OK. Does not wait.
plume_status cli_writer_status(cli_writer *writer, plume_error *err);
/// Runs what is queued (on the calling thread too), stops the thread and frees the writer
/// (NULL: nothing to do); returns the first failure's status and error, or PLUME_OK.
plume_status cli_writer_finish(cli_writer *writer, plume_error *err);

int cli_generate(int argc, char **argv);
int cli_grow(int argc, char **argv);
int cli_mesh(int argc, char **argv);
int cli_coat(int argc, char **argv);
int cli_simulate(int argc, char **argv);
int cli_render(int argc, char **argv);
int cli_lab(int argc, char **argv);
int cli_demo(int argc, char **argv);
int cli_sweep(int argc, char **argv);
int cli_view(int argc, char **argv);

void cli_help_generate(void);
void cli_help_grow(void);
void cli_help_mesh(void);
void cli_help_coat(void);
void cli_help_simulate(void);
void cli_help_render(void);
void cli_help_lab(void);
void cli_help_demo(void);
void cli_help_sweep(void);
void cli_help_view(void);

#endif

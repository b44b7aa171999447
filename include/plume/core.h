// plume — core: status codes, errors, memory, vectors, Bézier curves, random numbers.
//
// Everything here is plain data and pure functions. Nothing keeps global state
// except the optional allocator hook (set once, before any object exists).
#ifndef PLUME_CORE_H
#define PLUME_CORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

// Exported from the shared library: the declarations between PLUME_API_BEGIN and
// PLUME_API_END in these headers. libplume is compiled with hidden visibility
// (CMakeLists.txt), so its internal functions stay internal.
#if defined(__GNUC__)
#define PLUME_API_BEGIN _Pragma("GCC visibility push(default)")
#define PLUME_API_END _Pragma("GCC visibility pop")
#else
#define PLUME_API_BEGIN
#define PLUME_API_END
#endif

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

#define PLUME_VERSION_MAJOR 0
#define PLUME_VERSION_MINOR 1
#define PLUME_VERSION_PATCH 0
#define PLUME_VERSION_STRING "0.1.0"

// ---------------------------------------------------------------------------
// Status and errors

/// Stable status codes returned by every fallible libplume call.
/// The numeric values never change; new codes are appended.
typedef enum plume_status {
	PLUME_OK = 0,
	PLUME_ERROR_IO = 1,          ///< a file could not be read or written
	PLUME_ERROR_SYNTAX = 2,      ///< malformed input text (JSON syntax, OBJ, image)
	PLUME_ERROR_SPEC = 3,        ///< a well-formed spec with a wrong key, type or value
	PLUME_ERROR_MEMORY = 4,      ///< an allocation failed
	PLUME_ERROR_NUMERIC = 5,     ///< a computation did not converge or produced NaN
	PLUME_ERROR_UNSUPPORTED = 6, ///< a format or feature that this build does not have
	PLUME_ERROR_LIMIT = 7,       ///< the work would pass a resource limit (see plume_spec_options.max_memory)
} plume_status;

/// Human-readable message for a failed call. Filled by the callee, never
/// printed by the library. Pass NULL where the message is not wanted.
typedef struct plume_error {
	plume_status status;
	char message[1024];
} plume_error;

/// Set by the *_default_def() functions in a definition's `cookie` field, and
/// asserted by the functions that take the definition: a definition struct that
/// was declared but never initialised from its default is a programmer error, and
/// the call aborts with the file and line (Box2D's b2_secret_cookie). Programmer-error
/// asserts (an index out of range, a NULL or destroyed handle, such a definition) are
/// on in every build type unless libplume is configured with -DPLUME_DISABLE_ASSERTS=ON.
#define PLUME_DEF_COOKIE 0x706c756du

/// The default of every max_memory (plume_spec_options, plume_mesh_def) and of the CLI's
/// --max-memory: 4 GiB (docs/cli.md, "Limits").
#define PLUME_DEFAULT_MAX_MEMORY (4ull << 30)

/// Short stable name of a status ("io", "syntax", "spec", ...).
const char *plume_status_name(plume_status status);

/// Fills err (when not NULL) with status and a printf-style message; returns status.
plume_status plume_error_set(plume_error *err, plume_status status, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/// Prepends "prefix: " to an already filled message (used to add a file name).
void plume_error_prefix(plume_error *err, const char *prefix);

/// Levenshtein distance between two strings (insertions, deletions, substitutions), for
/// the "did you mean" of an error message. Strings longer than 255 bytes count their
/// first 255 only.
size_t plume_edit_distance(const char *a, const char *b);

// ---------------------------------------------------------------------------
// Progress of long loops

/// Called by a long library loop (a coat's feathers, a calibration's traction tests, a study's
/// runs) after each item: done of total finished so far. total is an estimate where the
/// loop's length is not known in advance (a calibration's search) and may grow between calls;
/// done never exceeds it. Calls come one at a time, from any thread (parallel loops serialise
/// them). The library never prints: the caller (the CLI) shows the progress.
typedef void plume_progress_fn(void *user, int done, int total);

// ---------------------------------------------------------------------------
// Memory

typedef void *plume_alloc_fn(size_t size);
typedef void plume_free_fn(void *memory);

/// Routes every libplume allocation through alloc_fn/free_fn (NULL restores
/// malloc/free). Call before creating any plume object; not thread-safe.
void plume_set_allocator(plume_alloc_fn *alloc_fn, plume_free_fn *free_fn);

/// Bytes currently allocated by libplume (all threads). Tests assert that it
/// returns to its starting value after every destroy.
int64_t plume_bytes_in_use(void);

// ---------------------------------------------------------------------------
// Vectors (plain structs, passed by value)

typedef struct plume_vec2 {
	double x, y;
} plume_vec2;

typedef struct plume_vec3 {
	double x, y, z;
} plume_vec3;

static inline plume_vec3 plume_v3(double x, double y, double z) { return (plume_vec3){x, y, z}; }
static inline plume_vec3 plume_v3_add(plume_vec3 a, plume_vec3 b)
{
	return (plume_vec3){a.x + b.x, a.y + b.y, a.z + b.z};
}
static inline plume_vec3 plume_v3_sub(plume_vec3 a, plume_vec3 b)
{
	return (plume_vec3){a.x - b.x, a.y - b.y, a.z - b.z};
}
static inline plume_vec3 plume_v3_scale(plume_vec3 a, double s) { return (plume_vec3){a.x * s, a.y * s, a.z * s}; }
/// a + s b
static inline plume_vec3 plume_v3_mad(plume_vec3 a, double s, plume_vec3 b)
{
	return (plume_vec3){a.x + s * b.x, a.y + s * b.y, a.z + s * b.z};
}
/// (1 - t) a + t b
static inline plume_vec3 plume_v3_lerp(plume_vec3 a, plume_vec3 b, double t)
{
	return (plume_vec3){a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)};
}
static inline double plume_v3_dot(plume_vec3 a, plume_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline plume_vec3 plume_v3_cross(plume_vec3 a, plume_vec3 b)
{
	return (plume_vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double plume_v3_length(plume_vec3 a);
double plume_v3_distance(plume_vec3 a, plume_vec3 b);
/// a / |a|; the zero vector stays zero.
plume_vec3 plume_v3_normalize(plume_vec3 a);

/// 3x3 matrix, row-major: m[row][column].
typedef struct plume_mat3 {
	double m[3][3];
} plume_mat3;

plume_mat3 plume_m3_identity(void);
plume_mat3 plume_m3_mul(plume_mat3 a, plume_mat3 b);
plume_mat3 plume_m3_transpose(plume_mat3 a);
plume_vec3 plume_m3_apply(plume_mat3 a, plume_vec3 v);
double plume_m3_det(plume_mat3 a);
/// Rotation by angle (radians) about a unit axis (Rodrigues).
plume_mat3 plume_m3_rotation(plume_vec3 axis, double angle);

// ---------------------------------------------------------------------------
// Bézier curves of any degree up to PLUME_BEZIER_MAX_POINTS - 1.
//
// A curve is an array of count = degree + 1 control points; t runs over [0, 1].
// Functions that need scratch memory use a stack buffer of this size, so the
// hot paths never allocate. Degrees above 63 are numerically useless anyway.

#define PLUME_BEZIER_MAX_POINTS 64

/// Point at t by de Casteljau's algorithm.
plume_vec3 plume_bezier_eval(const plume_vec3 *points, int count, double t);

/// order-th derivative at t (order 0 is the point itself); zero when order > degree.
plume_vec3 plume_bezier_derivative(const plume_vec3 *points, int count, int order, double t);

/// Control points of the derivative curve (the hodograph): count - 1 points
/// d_i = degree (p_{i+1} - p_i) written to out.
void plume_bezier_hodograph(const plume_vec3 *points, int count, plume_vec3 *out);

/// Degree elevation by one: writes count + 1 points to out, same curve.
void plume_bezier_elevate(const plume_vec3 *points, int count, plume_vec3 *out);

/// Splits the curve at t into left [0, t] and right [t, 1], each count points.
void plume_bezier_split(const plume_vec3 *points, int count, double t, plume_vec3 *left, plume_vec3 *right);

/// Arc length of the curve between parameters t0 <= t1 (adaptive Gauss–Legendre,
/// relative accuracy about 1e-12).
double plume_bezier_length(const plume_vec3 *points, int count, double t0, double t1);

/// Parameter at which the arc length from t = 0 equals fraction of the whole length.
double plume_bezier_param_at_length(const plume_vec3 *points, int count, double fraction);

/// sample_count parameters equally spaced in arc length, first 0 and last 1
/// (sample_count >= 2). Arc-length error below 1e-9 of the curve's length.
void plume_bezier_sample_by_length(const plume_vec3 *points, int count, int sample_count, double *params_out);

/// Parameter of the curve point nearest to p: the best of a uniform search,
/// polished by Newton's method on (B(t) - p) . B'(t) = 0.
double plume_bezier_closest_param(const plume_vec3 *points, int count, plume_vec3 p);

/// A curve's cumulative arc length over a fixed partition of [0, 1], for
/// callers that look up many lengths on one curve. Plain data on the stack;
/// fill with plume_bezier_arc_init, read the fields, do not change them.
#define PLUME_BEZIER_ARC_INTERVALS 256

typedef struct plume_bezier_arc {
	plume_vec3 hodograph[PLUME_BEZIER_MAX_POINTS];
	int hodograph_count;
	double cumulative[PLUME_BEZIER_ARC_INTERVALS + 1]; ///< length from 0 to t = j / intervals
	double speed[PLUME_BEZIER_ARC_INTERVALS + 1];      ///< |B'(t)| at t = j / intervals
	double length;                                     ///< the whole curve's length
} plume_bezier_arc;

void plume_bezier_arc_init(plume_bezier_arc *arc, const plume_vec3 *points, int count);
/// Parameter where the length from t = 0 is fraction * arc->length, to about 1e-15 in t.
double plume_bezier_arc_param(const plume_bezier_arc *arc, double fraction);

// ---------------------------------------------------------------------------
// Random numbers: xoshiro256** seeded by splitmix64. The state is explicit and
// passed down; the same seed gives the same sequence on every machine.

typedef struct plume_rng {
	uint64_t s[4];
} plume_rng;

plume_rng plume_rng_seed(uint64_t seed);
uint64_t plume_rng_next(plume_rng *rng);
/// Uniform double in [0, 1) with 53 random bits.
double plume_rng_uniform(plume_rng *rng);
/// Uniform double in [lo, hi].
double plume_rng_range(plume_rng *rng, double lo, double hi);
/// An independent stream: the generator seeded from this one's next output.
plume_rng plume_rng_split(plume_rng *rng);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_CORE_H

// plume — the shared feather structure.
//
// Every generator produces a plume_feather and every consumer (renderers,
// exporters, the mesher) reads one; none of them knows which generator made it.
// The object is opaque and owned by whoever created it; readers get plain
// const views into its arrays, valid until the feather is destroyed.
//
// Geometry is in metres. A feather is built in its own frame: the shaft starts
// near the origin and runs towards +y, the vanes lie near the z = 0 plane with
// the left vane on the -x side, and +z is the front (dorsal) side.
#ifndef PLUME_FEATHER_H
#define PLUME_FEATHER_H

#include "plume/core.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

typedef struct plume_feather plume_feather;

/// Which vane a barb belongs to.
typedef enum plume_side {
	PLUME_SIDE_LEFT = 0,
	PLUME_SIDE_RIGHT = 1,
} plume_side;

/// Which kind a barbule is (Zhang & Kanai IV-C): distal barbules point to the
/// feather tip and hook into the next barb, proximal ones point to the base.
typedef enum plume_barbule_kind {
	PLUME_BARBULE_DISTAL = 0,
	PLUME_BARBULE_PROXIMAL = 1,
} plume_barbule_kind;

/// One sample of the shaft centre line (calamus then rachis).
typedef struct plume_shaft_sample {
	plume_vec3 position;
	plume_vec3 tangent;  ///< unit, towards the tip
	plume_vec3 normal;   ///< unit, out of the vane plane (front side)
	plume_vec3 binormal; ///< unit, normal x tangent: towards the left vane
	double width;        ///< diameter of the shaft here, m
	double t;            ///< arc-length fraction of the shaft: 0 at the base, 1 at the tip
} plume_shaft_sample;

/// A sampled curve: count points, each with a per-point parameter array.
/// Arrays are owned by the feather.
typedef struct plume_polyline {
	int count;
	const plume_vec3 *points;
	const plume_vec3 *normals; ///< unit; the ribbon's facing direction at each point
	const double *arc_length;  ///< m, along the curve from its first point
	const double *widths;      ///< m, the curve's width at each point
	const plume_vec2 *uv;      ///< texture coordinates (s, t)
} plume_polyline;

/// One barb: a polyline from its root on the rachis to its tip.
/// uv.s goes from 0 at the rachis to 1 at the tip (arc-length fraction);
/// uv.t is the shaft parameter of the root, 0 at the base, 1 at the tip
/// (Franco & Walter 4.4), the same for every point of the barb.
typedef struct plume_barb {
	plume_polyline curve;
	plume_side side;
	double rachis_t;   ///< attachment: shaft arc-length fraction of the root
	int segment;       ///< generator-specific group (Franco–Walter: 0 below I_s, 1 above)
	int barbule_first; ///< index of its first barbule (see plume_feather_barbule)
	int barbule_count;
} plume_barb;

/// One barbule: a small polyline attached to a barb.
typedef struct plume_barbule {
	plume_polyline curve;
	int barb;      ///< index of the barb it grows from
	double barb_s; ///< arc-length fraction along that barb where it attaches
	plume_barbule_kind kind;
} plume_barbule;

/// Summary counts.
typedef struct plume_feather_info {
	int shaft_sample_count;
	int calamus_sample_count; ///< the first calamus_sample_count shaft samples are the calamus
	int barb_count;           ///< both vanes
	int barb_count_left;
	int barb_count_right;
	int barbule_count;
	int point_count; ///< all barb and barbule points
	bool has_afterfeather;
	double shaft_length;   ///< m
	plume_vec3 bounds_min; ///< axis-aligned bounds of everything, afterfeather included
	plume_vec3 bounds_max;
} plume_feather_info;

void plume_feather_destroy(plume_feather *feather);

plume_feather_info plume_feather_get_info(const plume_feather *feather);

/// The shaft samples, base first; count from plume_feather_get_info.
const plume_shaft_sample *plume_feather_shaft(const plume_feather *feather);

/// Barb i, 0 <= i < barb_count. Barbs are ordered by side (left first), then
/// from the base to the tip.
plume_barb plume_feather_barb(const plume_feather *feather, int i);

/// Barbule i, 0 <= i < barbule_count, grouped by barb.
plume_barbule plume_feather_barbule(const plume_feather *feather, int i);

/// The afterfeather (a secondary feather attached where calamus meets rachis),
/// or NULL. Owned by this feather.
const plume_feather *plume_feather_afterfeather(const plume_feather *feather);

/// Where the afterfeather attaches: shaft arc-length fraction.
double plume_feather_afterfeather_t(const plume_feather *feather);

/// Deep equality of two feathers (every array bit for bit). For tests and round trips.
bool plume_feather_equal(const plume_feather *a, const plume_feather *b);

/// Moves the feather (and its afterfeather) rigidly: every point p goes to rotation p + translation,
/// directions (shaft frames, normals) turn with rotation. rotation must be a rotation matrix.
void plume_feather_move(plume_feather *feather, plume_mat3 rotation, plume_vec3 translation);

/// The largest distance, m, between corresponding points (shaft samples and barb and barbule
/// points, afterfeathers included) of two feathers of the same structure (the same counts,
/// curves, widths and texture coordinates, bit for bit); INFINITY when the structure differs.
/// Tells apart copies of one feather that went through rigid motions (rounding only) from
/// different feathers.
double plume_feather_distance(const plume_feather *a, const plume_feather *b);

/// A deep copy, or NULL when memory runs out.
plume_feather *plume_feather_clone(const plume_feather *feather);

/// The generator's diagnostics as a JSON object text (for example the
/// Zhang–Kanai barbs that could not snap), or NULL when it left none. Owned by
/// the feather. Diagnostics describe how the feather was made, not its shape:
/// plume_feather_equal ignores them, plume_feather_clone copies them, and the
/// feather JSON format does not carry them. `plume generate` writes them to
/// DIR/summary.json and prints them.
const char *plume_feather_summary(const plume_feather *feather);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_FEATHER_H

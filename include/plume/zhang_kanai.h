// plume — the Zhang–Kanai morphogenesis generator.
//
// Zhang & Kanai, "Biological Modeling of Feathers by Morphogenesis
// Simulation", section IV: barb ridges are emitted on a ring-shaped collar,
// grow helically in the follicle (IV-A), unfurl when the sheath breaks (IV-B)
// and are pulled together by their barbules (IV-C, optional). plume adds what
// the paper leaves to other software: a rachis built from the barb roots at
// the anterior polarity, so the result is a complete plume_feather.
//
// Units: metres, seconds, radians. Loci s are arc-length fractions of the
// collar in [0, 1]; speeds are metres per second along the collar, so a
// locus moves at ds/dt = V(s) / L with L the collar's perimeter (the paper's
// unit collar makes V a fraction per second; eq. 3 and 4 then read the same).
//
// Coordinates (paper IV-A): the collar lies in the xz-plane, its axis along
// +y, C(0) on the -z axis and s increasing from -z towards +x (eq. 1). The
// feather is translated so that the middle of the anterior interval's chord
// is on the y axis; after unfurling the vanes lie near the z = 0 plane, the
// left vane on -x, and +z (the side that faced the follicle's axis) is the front.
#ifndef PLUME_ZHANG_KANAI_H
#define PLUME_ZHANG_KANAI_H

#include "plume/feather.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

#define PLUME_ZK_MAX_CURVE_POINTS 16
#define PLUME_ZK_MAX_COLLAR_POINTS 64
#define PLUME_ZK_MAX_SPLITS 8
#define PLUME_ZK_MAX_BARBS 5000

/// A positive scalar distribution over the collar (paper V: "for any scalar
/// distribution on C(s), we use curve editor"): control points (s_k, value_k)
/// with s_k strictly increasing in [0, 1], joined by a monotone piecewise cubic
/// (Fritsch–Carlson). Between two control points the curve never leaves the
/// range of their values, so positive control values give a positive curve
/// everywhere; outside [s_0, s_last] it is constant. One point: a constant.
typedef struct plume_zk_curve {
	int count; ///< [1, PLUME_ZK_MAX_CURVE_POINTS]
	double s[PLUME_ZK_MAX_CURVE_POINTS];
	double value[PLUME_ZK_MAX_CURVE_POINTS];
} plume_zk_curve;

/// A curve with one value everywhere.
plume_zk_curve plume_zk_constant(double value);

/// The curve's value at locus s.
double plume_zk_curve_eval(const plume_zk_curve *curve, double s);

typedef enum plume_zk_collar_kind {
	/// x = R sin(2 pi s), z = -R cos(2 pi s): the paper's eq. 1 scaled by R.
	PLUME_ZK_COLLAR_CIRCLE = 0,
	/// A closed composite cubic Bézier through the control points (IV-A):
	/// between points k and k + 1 the segment has the inner control points
	/// P_k + (P_{k+1} - P_{k-1}) / 6 and P_{k+1} - (P_{k+2} - P_k) / 6
	/// (Catmull–Rom tangents, C1), indices modulo the count. C(0) is the first point.
	PLUME_ZK_COLLAR_BEZIER = 1,
} plume_zk_collar_kind;

/// A manual split (IV-C, Figure 11 bottom): before snapping, the barb is bent
/// at one of its vertices in the vane plane, towards the feather's base; the
/// barb is not snapped to the one above it, and the barbs below snap to it.
typedef struct plume_zk_split {
	plume_side side;
	/// Barb in emission order on its vane, 0 the most distal (the first emitted).
	int barb;
	/// Where it bends: fraction of the barb's vertices from the root, [0, 1].
	double at;
	/// Bending angle, radians, (-pi, pi); positive bends the distal part towards the base.
	double angle;
} plume_zk_split;

typedef struct plume_zk_def {
	// --- Collar (IV-A)
	/// Circle (eq. 1) or Bézier. Default circle.
	plume_zk_collar_kind collar_kind;
	/// R for the circle, m, > 0. Default 0.01 (a vane up to about pi R = 31 mm wide).
	double collar_radius;
	/// Points (x, z) the Bézier collar passes through, m, counter-clockwise seen
	/// from +y like eq. 1 (from -z towards +x); at least 4. Unused for the circle.
	plume_vec2 collar_points[PLUME_ZK_MAX_COLLAR_POINTS];
	int collar_point_count;
	/// I_A = <left, right>: the anterior polarity (rachidial ridge), containing s = 0,
	/// i.e. [left, 1] + [0, right]. Default <0.98, 0.02>.
	double anterior[2];
	/// I_P = <left, right>: the posterior polarity (barb generative zone).
	/// Must satisfy I_A.right < I_P.right <= I_P.left < I_A.left. Default <0.51, 0.49> (Figure 10 left).
	double posterior[2];

	// --- Helical growth (IV-A)
	/// d: barb ridge width, the distance an emitter moves between emissions, m, > 0. Default 8e-4.
	double ridge_width;
	/// Each emission distance is d (1 + r), r uniform in [-v, v] from the seed (the paper's
	/// section VI notes that real ridges differ); [0, 0.9]. Default 0 (the paper's equal widths).
	double ridge_width_variation;
	/// V_e(s): emitter speed, m/s, > 0 everywhere. Default 0.012 at the anterior polarity
	/// slowing to 0.004 at s = 0.5, convex downward there (Figure 9 left's rounded tip).
	plume_zk_curve emitter_speed;
	/// V_b(s): barb elongation speed, m/s, > 0 everywhere. Default 0.008 constant.
	plume_zk_curve barb_speed;
	/// v_grow: longitudinal growth speed of the follicle (eq. 5), m/s, > 0. Default 0.005.
	double growth_speed;
	/// Runge–Kutta step of the pathline integration (eq. 2-4), s, > 0. Default 0.02.
	double step;
	/// N: growth stops when N barbs of either vane are mature, [1, 5000]. Default 100.
	int barb_count;
	/// f: keep every f-th pathline point (both ends always), [1, 1000]. Default 4.
	int downsample;
	/// Growth stage: t_curr as a fraction of the growth period [0, t_end], [0, 1].
	/// Below 1 the developing barbs are kept (the growth sequence of Figure 8); at 1 they
	/// are discarded (IV-A, Termination). Default 1.
	double growth_stage;

	// --- Unfurling (IV-B)
	/// w: global unfurling weight, 0 the helix in the follicle, 1 flat, [0, 1]. Default 1.
	double unfurl_weight;
	/// Per-barb weights from a sheath: when true, barb i unfurls by
	/// w clamp((y_root - sheath_height) / sheath_ramp, 0, 1), so barbs still in the follicle
	/// stay helical during growth. Default false (every barb unfurls by w, as in the paper).
	bool sheath;
	/// Height of the sheath's broken edge above the collar, m, >= 0. Default 0.
	double sheath_height;
	/// Rise over which a barb goes from helical to unfurled by w, m, > 0. Default 0.01.
	double sheath_ramp;

	// --- Expansion (IV-C)
	/// Construct barbules and snap the barbs. Default false (the paper's optional third stage).
	bool expansion;
	/// theta_d: zenith angle from the ramus to the distal barbule (eq. 12), radians,
	/// (0, pi). Default 30 degrees (chosen so that the default vane snaps fully:
	/// the paper gives no values and notes that the valid range is limited, section V).
	double theta_distal;
	/// theta_p: the same for the proximal barbule, (0, pi). Default 150 degrees.
	double theta_proximal;
	/// phi: azimuth by which the barbules flatten about the ramus, radians, [0, pi];
	/// the distal one to the tip's side, the proximal one to the base's. Default 90 degrees (Figure 6).
	double azimuth;
	/// l_ridge(s): barb ridge height, m, > 0 everywhere. Default 3.5e-4 at the anterior
	/// polarity falling to 3e-4 at s = 0.5 (smaller ridges posteriorly, section V).
	plume_zk_curve ridge_height;
	/// Manual splits, applied before snapping. Default none.
	plume_zk_split splits[PLUME_ZK_MAX_SPLITS];
	int split_count;
	/// Keep the barbules in the feather (two per barb vertex, distal then proximal). Default true.
	bool keep_barbules;

	// --- Rachis and widths (plume's own; the paper leaves the rachis to other software)
	/// Bare calamus below the collar level, m, > 0. Default 0.015.
	double calamus_length;
	/// Rachis width at the tip over its width at the base (the anterior interval's chord), (0, 1]. Default 0.25.
	double rachis_taper;
	/// Shaft samples, [2, 100000]. Default 100.
	int shaft_samples;
	/// Barb width at the root and at the tip, m, > 0. Defaults 1.5e-4 and 3e-5.
	double barb_width_base;
	double barb_width_tip;
	/// Barbule width, m, > 0. Default 1e-5.
	double barbule_width;
	/// PLUME_DEF_COOKIE, set by plume_zk_default_def; do not change.
	uint32_t cookie;
} plume_zk_def;

/// A contour feather about 0.12 m long, 100 barbs per vane, unfurled, no expansion.
plume_zk_def plume_zk_default_def(void);

/// Checks every field. Messages name the spec's JSON path
/// ("$.posterior overlaps $.anterior: ...", "$.emitter_speed[2][1] is -1, ...").
plume_status plume_zk_def_validate(const plume_zk_def *def, plume_error *err);

/// Bytes the feather of def takes, counted before the growth and never below the built feather's.
/// A vane keeps at most its first N = barb_count barbs (barbs mature in emission order; below
/// growth_stage 1 also those still developing). Barb i grows back to I_A from where it left the ridge,
/// at most d (i + 1) (1 + ridge_width_variation) or the vane's path from I_A to I_P (the collar's
/// perimeter, or the Bezier collar's control polygon, which no Bezier arc outruns, times the interval);
/// every RK4 step moves at least step x the smallest control value of V_b (the curves never leave their
/// control values' range), every downsample-th step is kept (growth refuses more than two million).
/// Developing barbs are emitted at least d (1 - ridge_width_variation) / max V_e apart and are younger
/// than the longest pathline. Barbules (expansion with keep_barbules) add four points a vertex.
/// Past any limit for a def that does not validate.
double plume_zk_estimate_bytes(const plume_zk_def *def);

/// How snapping went for one barb (IV-C).
typedef enum plume_zk_snap {
	PLUME_ZK_SNAP_OFF = 0, ///< expansion is off
	PLUME_ZK_SNAP_TOP,     ///< the most distal barb of its vane: nothing above to snap to
	PLUME_ZK_SNAP_FULL,    ///< every vertex snapped
	PLUME_ZK_SNAP_PARTIAL, ///< snapped from the root up to a vertex that could not reach the boundary
	PLUME_ZK_SNAP_SKIPPED, ///< the root could not reach the boundary (Figure 12's flaw): kept as grown
	PLUME_ZK_SNAP_SPLIT,   ///< bent by a manual split and not snapped to the barb above
} plume_zk_snap;

typedef struct plume_zk_barb_report {
	plume_side side;
	int index;            ///< emission order on its vane, 0 the most distal
	int feather_barb;     ///< its index in the plume_feather
	double emit_time;     ///< P_0.t, s
	double emit_locus;    ///< P_0.locus
	double mature_time;   ///< when its root reached I_A, s; INFINITY while developing
	bool mature;          ///< mature at t_curr
	int vertex_count;     ///< after downsampling
	double unfurl_weight; ///< its own w
	plume_zk_snap snap;
	int snapped_vertices; ///< vertices from the root whose distal barbule touches the barb above
} plume_zk_barb_report;

/// What a generation did. Owned arrays: free with plume_zk_report_free.
typedef struct plume_zk_report {
	double t_end;         ///< termination time: N barbs of one vane mature, s
	double t_curr;        ///< the stage built: growth_stage t_end, s
	double unfurl_weight; ///< the global w
	int barb_count;       ///< barbs in the feather, both vanes
	int barb_count_side[2];
	int developing_count;        ///< barbs still developing at t_curr (kept below stage 1, else discarded)
	double clamp_time[2];        ///< when each emitter reached I_P, s; INFINITY if it did not by t_end
	int snapped_count;           ///< FULL
	int partial_count;           ///< PARTIAL
	int unsnapped_count;         ///< SKIPPED
	int *unsnapped;              ///< unsnapped_count indices into barbs[]
	plume_zk_barb_report *barbs; ///< barb_count entries, in the feather's barb order
} plume_zk_report;

void plume_zk_report_free(plume_zk_report *report);

/// Runs the three stages and builds the feather. report may be NULL. The
/// feather's summary (plume_feather_summary) carries the same counts as JSON.
/// Same def and seed, same bytes.
plume_status plume_zk_generate(const plume_zk_def *def, uint64_t seed, plume_feather **out, plume_zk_report *report,
                               plume_error *err);

/// Reads a zhang-kanai spec (docs/spec-zhang-kanai.md) into def and its seed (1 when absent).
plume_status plume_zk_def_read(const char *path, plume_zk_def *def, uint64_t *seed, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_ZHANG_KANAI_H

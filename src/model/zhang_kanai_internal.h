// Private: the stages of the Zhang–Kanai generator, shared by its files.
//
//   zhang_kanai_curve.c   monotone cubic distributions on the collar
//   zhang_kanai_collar.c  C(s) and its unit tangent, by arc-length fraction
//   zhang_kanai_growth.c  emitters, RK4 pathlines, termination, downsampling (IV-A)
//   zhang_kanai_unfurl.c  positions, discrete frames, forward kinematics (IV-B)
//   zhang_kanai_expand.c  barbules, splits and snapping (IV-C)
//   zhang_kanai.c         defaults, validation, the rachis and the feather
#ifndef PLUME_ZHANG_KANAI_INTERNAL_H
#define PLUME_ZHANG_KANAI_INTERNAL_H

#include "plume/zhang_kanai.h"

/// A plume_zk_curve with its Hermite tangents (Fritsch–Carlson).
typedef struct zk_curve {
	plume_zk_curve points;
	double tangent[PLUME_ZK_MAX_CURVE_POINTS];
} zk_curve;

void zk_curve_init(zk_curve *curve, const plume_zk_curve *points);
double zk_curve_eval(const zk_curve *curve, double s);

/// The collar, parameterized by arc-length fraction.
typedef struct zk_collar {
	plume_zk_collar_kind kind;
	double radius;
	int segment_count;
	plume_vec3 (*segments)[4]; ///< Bézier segments (x, 0, z)
	plume_bezier_arc *arcs;    ///< one per segment
	double *start;             ///< arc length at each segment's start, segment_count + 1 entries
	double length;             ///< L, m
} zk_collar;

plume_status zk_collar_init(zk_collar *collar, const plume_zk_def *def);
void zk_collar_free(zk_collar *collar);
/// C(s), s taken modulo 1.
plume_vec3 zk_collar_point(const zk_collar *collar, double s);
/// C(s) and dC/ds / |dC/ds|, the unit direction of increasing s (one lookup for both).
void zk_collar_frame(const zk_collar *collar, double s, plume_vec3 *point, plume_vec3 *tangent);

/// One barb after the helical growth stage: its downsampled pathline, tip
/// (emission point) first, as loci and times.
typedef struct zk_barb {
	plume_side side;
	int index; ///< emission order on its vane
	double emit_time, emit_locus;
	double mature_time; ///< INFINITY when it never reaches I_A before the growth ends
	bool mature;        ///< at t_curr
	int first;          ///< its range in the growth's vertex arrays
	int count;
} zk_barb;

typedef struct zk_growth {
	double t_end, t_curr;
	double clamp_time[2];
	int developing_count;
	zk_barb *barbs; ///< left vane then right, each in emission order (distal first)
	int barb_count;
	int side_count[2];
	double *locus; ///< per vertex, each barb's range tip first
	double *time;
	int vertex_count;
} zk_growth;

/// Runs IV-A: emits, integrates and terminates; keeps the barbs present at
/// t_curr = growth_stage t_end (mature ones, and developing ones below stage 1).
plume_status zk_grow(const plume_zk_def *def, const zk_collar *collar, uint64_t seed, zk_growth *growth,
                     plume_error *err);
void zk_growth_free(zk_growth *growth);

/// A vertex's discrete frame as the columns of a rotation: t, n, b (eq. 6-8).
typedef struct zk_frame {
	plume_vec3 t, n, b;
} zk_frame;

/// Positions and frames of every growth vertex, each barb's range reordered
/// root first (the forward-kinematics order of IV-B).
typedef struct zk_shape {
	plume_vec3 *p;
	zk_frame *frame;
	double *locus;     ///< root first, as p
	double *weight;    ///< per barb: its unfurling weight
	plume_vec3 origin; ///< what was subtracted from C(s): the middle of I_A's chord
} zk_shape;

/// Eq. 5-10: helix positions at t_curr, then unfurled by each barb's weight.
plume_status zk_unfurl(const plume_zk_def *def, const zk_collar *collar, const zk_growth *growth, zk_shape *shape);
void zk_shape_free(zk_shape *shape);

/// Unfurls one chain of count vertices (root first) in place by weight w:
/// frames have b = +y; each segment's horizontal part is turned towards its
/// parent's tangent by w of the angle between them, and each tangent keeps
/// (1 - w) of its turn relative to its parent. Segment lengths are kept.
void zk_unfurl_chain(plume_vec3 *p, zk_frame *frame, int count, double w);

/// Barbule vectors of one vertex (eq. 11-12), world space.
typedef struct zk_barbules {
	plume_vec3 *distal; ///< per vertex, as shape->p
	plume_vec3 *proximal;
	plume_zk_snap *snap; ///< per barb
	int *snapped;        ///< per barb
} zk_barbules;

/// IV-C: builds the barbules, applies the splits and snaps each vane from its
/// most distal barb proximally. Changes shape's positions and frames.
plume_status zk_expand(const plume_zk_def *def, const zk_growth *growth, zk_shape *shape, zk_barbules *barbules);
void zk_barbules_free(zk_barbules *barbules);

/// The most distal point where the sphere (centre, radius) meets the
/// polyline, as a parameter segment + u; returns false when they do not meet.
bool zk_sphere_polyline(plume_vec3 centre, double radius, const plume_vec3 *line, int count, plume_vec3 *hit);

/// The angle a in (-pi, pi], in at most 33 steps whatever a is (NaN for a non-finite a).
double zk_wrap_angle(double a);

#endif

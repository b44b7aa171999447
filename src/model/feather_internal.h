// Private: the layout of plume_feather, for the library's generators and readers.
//
// All barb and barbule points live in one pool of parallel arrays; a curve is
// a range [first, first + count) in the pool. Builders append with the
// plume_feather_add_* functions and fill the returned ranges directly.
#ifndef PLUME_FEATHER_INTERNAL_H
#define PLUME_FEATHER_INTERNAL_H

#include "plume/feather.h"

#include "../core/vec_inline.h"

typedef struct plume_curve_range {
	int first;
	int count;
} plume_curve_range;

typedef struct plume_barb_record {
	plume_curve_range curve;
	plume_side side;
	double rachis_t;
	int segment;
	int barbule_first;
	int barbule_count;
} plume_barb_record;

typedef struct plume_barbule_record {
	plume_curve_range curve;
	int barb;
	double barb_s;
	plume_barbule_kind kind;
} plume_barbule_record;

struct plume_feather {
	uint32_t magic; ///< PLUME_HANDLE_MAGIC while alive (core/asserts.h)
	plume_shaft_sample *shaft;
	int shaft_count, shaft_capacity;
	int calamus_count;

	// point pool
	plume_vec3 *points;
	plume_vec3 *normals;
	double *arc_length;
	double *widths;
	plume_vec2 *uv;
	int point_count, point_capacity;

	plume_barb_record *barbs;
	int barb_count, barb_capacity;

	plume_barbule_record *barbules;
	int barbule_count, barbule_capacity;

	plume_feather *afterfeather;
	double afterfeather_t;

	char *summary; ///< generator diagnostics (JSON text) or NULL; see plume_feather_summary
};

/// Bytes of a feather holding `points` pool points (five per-point arrays), `barbs` barb and
/// `barbules` barbule records and `shaft` shaft samples: what the generators' estimates before
/// the work count (doubles, so that absurd counts do not overflow).
double plume_feather_layout_bytes(double points, double barbs, double barbules, double shaft);

/// plume_feather_layout_bytes of a built feather's counts, its afterfeather's included.
double plume_feather_bytes(const plume_feather *feather);

/// An empty feather, or NULL when memory runs out.
plume_feather *plume_feather_create_empty(void);

/// Appends count shaft samples (uninitialized); returns the first one or NULL.
plume_shaft_sample *plume_feather_add_shaft(plume_feather *feather, int count);

/// Makes room for capacity pool points in all, so that later appends do not
/// move the pool. Returns 0, or -1 when memory runs out.
int plume_feather_reserve_points(plume_feather *feather, int capacity);

/// Appends count pool points (zeroed); returns the index of the first, or -1.
int plume_feather_add_points(plume_feather *feather, int count);

/// plume_feather_add_points without the zeroing, for a builder that writes every field of every point
/// (position, normal, width, uv, and arc length through plume_feather_measure_curve).
int plume_feather_append_points(plume_feather *feather, int count);

/// Appends a barb record; returns its index or -1.
int plume_feather_add_barb(plume_feather *feather, const plume_barb_record *barb);

/// Appends a barbule record; returns its index or -1.
int plume_feather_add_barbule(plume_feather *feather, const plume_barbule_record *barbule);

/// Replaces the feather's summary by a copy of json (NULL clears it).
/// Returns 0, or -1 when memory runs out (the old summary is then kept).
int plume_feather_set_summary(plume_feather *feather, const char *json);

/// Fills arc_length for a range of the pool from its points, and uv.s as the
/// arc-length fraction (0 at the first point, 1 at the last). Inline: the
/// generators measure every barb and barbule, most of a few points.
static inline void plume_feather_measure_curve(plume_feather *feather, plume_curve_range range)
{
	const plume_vec3 *points = feather->points + range.first;
	double *arc = feather->arc_length + range.first;
	arc[0] = 0.0;
	for (int i = 1; i < range.count; ++i)
		arc[i] = arc[i - 1] + core_v3_distance(points[i - 1], points[i]);
	double total = arc[range.count - 1];
	plume_vec2 *uv = feather->uv + range.first;
	for (int i = 0; i < range.count; ++i)
		uv[i].x = total > 0.0 ? arc[i] / total : (range.count > 1 ? (double)i / (range.count - 1) : 0.0);
}

#endif

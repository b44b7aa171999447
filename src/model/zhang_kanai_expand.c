// Expansion (Zhang & Kanai IV-C): barbules and snapping.
//
// Ramus (eq. 11):  r = v_grow b + V_e(s) t.
// Barbule (eq. 12): v = R(r, phi') (l_ridge / tan(theta) r/|r| + dir l_ridge n).
// Eq. 12 prints one R(r, phi) "for two barbules", which would put the distal
// and the proximal barbule on the same side of the barb; the text says both
// flatten by the same angle from the ridge, so plume turns them to opposite
// sides: the distal barbule by phi' = dir phi, towards the feather's tip (the
// barb above), the proximal one by -dir phi, towards the base. (dir: -1 left,
// +1 right, as in eq. 6.) Eq. 11 uses the emitter speed V_e, as printed.
//
// Snapping, from the most distal barb proximally, one cycle per pair (A above,
// B below; Figure 7):
//   1-2) the tips of A's proximal barbules form a boundary; its first segment
//        is extended over the gap at the rachis to D, the projection of B's root;
//   3-4) from B's root outwards, each vertex's frame is rotated (with every
//        vertex after it) so that the tip of its distal barbule lies on the
//        boundary, at the most distal point where the sphere of the barbule's
//        length meets it. The first vertex that cannot reach stops the barb.
// A barb whose root cannot reach is kept as grown (Figure 12) and reported.
#include <math.h>
#include <string.h>

#include "../core/alloc.h"
#include "../core/vec_inline.h"
#include "zhang_kanai_internal.h"

static plume_vec3 frame_apply(const zk_frame *f, plume_vec3 local)
{
	return plume_v3_add(plume_v3_add(plume_v3_scale(f->t, local.x), plume_v3_scale(f->n, local.y)),
	                    plume_v3_scale(f->b, local.z));
}

/// The angles of one barbule of eq. 12 on one vane: tan theta and the cosine and sine of its turn phi'
/// about the ramus, taken once for every vertex of the vane.
typedef struct barbule_angles {
	double tan_theta, cos_azimuth, sin_azimuth;
	double dir;
} barbule_angles;

static barbule_angles make_angles(double theta, double azimuth, double dir)
{
	return (barbule_angles){
	    .tan_theta = tan(theta), .cos_azimuth = cos(azimuth), .sin_azimuth = sin(azimuth), .dir = dir};
}

/// Eq. 12 about the unit ramus axis r/|r| of eq. 11, in the vertex's own frame
/// (t, n, b): the same vector for any rotation of the frame, so snapping can
/// rotate frames and keep barbules.
static plume_vec3 barbule_local(plume_vec3 axis, double ridge, const barbule_angles *angles)
{
	plume_vec3 v =
	    plume_v3_add(plume_v3_scale(axis, ridge / angles->tan_theta), plume_v3(0.0, angles->dir * ridge, 0.0));
	plume_mat3 turn = core_m3_rotation_cs(axis, angles->cos_azimuth, angles->sin_azimuth);
	return core_m3_apply(&turn, v);
}

/// The most distal point where the sphere meets segment i of the line, if any.
static bool sphere_segment(plume_vec3 centre, double radius, const plume_vec3 *line, int i, plume_vec3 *hit)
{
	plume_vec3 d = plume_v3_sub(line[i + 1], line[i]), f = plume_v3_sub(line[i], centre);
	double a = plume_v3_dot(d, d);
	if (!(a > 0.0))
		return false;
	double b = 2.0 * plume_v3_dot(f, d), c = plume_v3_dot(f, f) - radius * radius;
	double disc = b * b - 4.0 * a * c;
	if (disc < 0.0)
		return false;
	double root = sqrt(disc);
	double u = (-b + root) / (2.0 * a); // the larger root first: the more distal point
	if (!(u >= 0.0 && u <= 1.0))
		u = (-b - root) / (2.0 * a);
	if (u >= 0.0 && u <= 1.0) {
		*hit = plume_v3_mad(line[i], u, d);
		return true;
	}
	return false;
}

bool zk_sphere_polyline(plume_vec3 centre, double radius, const plume_vec3 *line, int count, plume_vec3 *hit)
{
	for (int i = count - 2; i >= 0; --i)
		if (sphere_segment(centre, radius, line, i, hit))
			return true;
	return false;
}

/// Segments per bounding ball of a snapping boundary.
enum { BLOCK = 8 };

/// A ball around the points of each block of BLOCK segments of the line (count points): blocks[k] holds
/// segments [k BLOCK, (k + 1) BLOCK).
typedef struct ball {
	plume_vec3 centre;
	double radius;
} ball;

static void bound_blocks(const plume_vec3 *line, int count, ball *blocks)
{
	for (int first = 0, k = 0; first + 1 < count; first += BLOCK, ++k) {
		int last = first + BLOCK < count - 1 ? first + BLOCK : count - 1; // its last point
		plume_vec3 lo = line[first], hi = line[first];
		for (int i = first + 1; i <= last; ++i) {
			lo = plume_v3(fmin(lo.x, line[i].x), fmin(lo.y, line[i].y), fmin(lo.z, line[i].z));
			hi = plume_v3(fmax(hi.x, line[i].x), fmax(hi.y, line[i].y), fmax(hi.z, line[i].z));
		}
		blocks[k].centre = plume_v3_scale(plume_v3_add(lo, hi), 0.5);
		blocks[k].radius = 0.0;
		for (int i = first; i <= last; ++i)
			blocks[k].radius = fmax(blocks[k].radius, core_v3_distance(line[i], blocks[k].centre));
	}
}

/// zk_sphere_polyline's answer, bit for bit, without testing the segments of a block whose ball lies
/// wholly outside or wholly inside the sphere (none of them can meet its surface). The margin, a
/// millionth of the sizes, is far above the rounding of the segment test, so no block that test would
/// find a point in is skipped.
static bool sphere_polyline_blocks(plume_vec3 centre, double radius, const plume_vec3 *line, int count,
                                   const ball *blocks, plume_vec3 *hit)
{
	for (int k = (count - 2) / BLOCK; k >= 0 && count >= 2; --k) {
		double distance = core_v3_distance(centre, blocks[k].centre), r = blocks[k].radius;
		double margin = 1e-6 * (radius + r);
		if (distance > radius + r + margin || distance + r < radius - margin)
			continue;
		int first = k * BLOCK, last = first + BLOCK < count - 1 ? first + BLOCK - 1 : count - 2; // segments
		for (int i = last; i >= first; --i)
			if (sphere_segment(centre, radius, line, i, hit))
				return true;
	}
	return false;
}

/// The rotation that turns unit a onto unit b about a x b.
static plume_mat3 rotation_between(plume_vec3 a, plume_vec3 b)
{
	plume_vec3 axis = plume_v3_cross(a, b);
	double s = core_v3_length(axis), c = plume_v3_dot(a, b);
	if (s < 1e-300) {
		if (c > 0.0)
			return plume_m3_identity();
		plume_vec3 other = fabs(a.x) < 0.9 ? plume_v3(1.0, 0.0, 0.0) : plume_v3(0.0, 1.0, 0.0);
		return plume_m3_rotation(core_v3_normalize(plume_v3_cross(a, other)), 3.14159265358979323846);
	}
	double angle = atan2(s, c);
	return core_m3_rotation_cs(plume_v3_scale(axis, 1.0 / s), cos(angle), sin(angle));
}

/// Rotates vertex j's frame by q about its position, carrying every vertex after it.
static void rotate_from(plume_vec3 *p, zk_frame *frame, int count, int j, const plume_mat3 *q)
{
	plume_vec3 pivot = p[j];
	for (int k = j; k < count; ++k) {
		if (k > j)
			p[k] = plume_v3_add(pivot, core_m3_apply(q, plume_v3_sub(p[k], pivot)));
		frame[k].t = core_m3_apply(q, frame[k].t);
		frame[k].n = core_m3_apply(q, frame[k].n);
		frame[k].b = core_m3_apply(q, frame[k].b);
	}
}

void zk_barbules_free(zk_barbules *barbules)
{
	plume_free(barbules->distal);
	plume_free(barbules->proximal);
	plume_free(barbules->snap);
	plume_free(barbules->snapped);
	memset(barbules, 0, sizeof *barbules);
}

typedef struct expand_ctx {
	const plume_zk_def *def;
	const zk_growth *growth;
	zk_shape *shape;
	plume_vec3 *local_distal, *local_proximal; ///< per vertex, in its frame
	plume_vec3 *boundary;                      ///< scratch, max vertices + 1
	ball *blocks;                              ///< scratch: the boundary's blocks
} expand_ctx;

static plume_vec3 world_barbule(const expand_ctx *ctx, const plume_vec3 *local, int vertex)
{
	return frame_apply(ctx->shape->frame + vertex, local[vertex]);
}

/// One cycle: snaps barb b below to barb a above. Returns the vertices snapped.
static int snap_pair(const expand_ctx *ctx, const zk_barb *a, const zk_barb *b)
{
	zk_shape *shape = ctx->shape;
	int n = 0;
	// 1-2) the boundary of A's proximal barbule tips, extended to D below its first point.
	for (int j = 0; j < a->count; ++j)
		ctx->boundary[1 + j] =
		    plume_v3_add(shape->p[a->first + j], world_barbule(ctx, ctx->local_proximal, a->first + j));
	plume_vec3 root = shape->p[b->first];
	int start = 1;
	if (a->count >= 2) {
		plume_vec3 first = ctx->boundary[1], d = plume_v3_sub(ctx->boundary[2], first);
		double dd = plume_v3_dot(d, d);
		double u = dd > 0.0 ? plume_v3_dot(plume_v3_sub(root, first), d) / dd : 0.0;
		if (u < 0.0) { // the gap at the rachis: AB extended to D
			ctx->boundary[0] = plume_v3_mad(first, u, d);
			start = 0;
		}
	}
	const plume_vec3 *line = ctx->boundary + start;
	int line_count = a->count + 1 - start;
	bound_blocks(line, line_count, ctx->blocks);
	// 3-4) each vertex of B from the root: turn its distal barbule onto the boundary.
	for (int j = 0; j < b->count; ++j) {
		int v = b->first + j;
		plume_vec3 barbule = world_barbule(ctx, ctx->local_distal, v);
		double radius = core_v3_length(barbule);
		plume_vec3 hit;
		if (!(radius > 0.0) || !sphere_polyline_blocks(shape->p[v], radius, line, line_count, ctx->blocks, &hit))
			break;
		plume_vec3 to = plume_v3_scale(plume_v3_sub(hit, shape->p[v]), 1.0 / radius);
		plume_mat3 q = rotation_between(plume_v3_scale(barbule, 1.0 / radius), core_v3_normalize(to));
		rotate_from(shape->p + b->first, shape->frame + b->first, b->count, j, &q);
		++n;
	}
	return n;
}

/// Bends a barb at a vertex about its normal, towards the feather's base.
static void apply_split(zk_shape *shape, const zk_barb *barb, const plume_zk_split *split)
{
	int j = (int)lround(split->at * (barb->count - 1));
	// A positive angle about n turns t towards -b: n x t = -b (the frame is right-handed).
	plume_mat3 q = plume_m3_rotation(shape->frame[barb->first + j].n, split->angle);
	rotate_from(shape->p + barb->first, shape->frame + barb->first, barb->count, j, &q);
}

plume_status zk_expand(const plume_zk_def *def, const zk_growth *growth, zk_shape *shape, zk_barbules *barbules)
{
	memset(barbules, 0, sizeof *barbules);
	size_t n = (size_t)(growth->vertex_count > 0 ? growth->vertex_count : 1);
	size_t nb = (size_t)(growth->barb_count > 0 ? growth->barb_count : 1);
	int longest = 1;
	for (int i = 0; i < growth->barb_count; ++i)
		if (growth->barbs[i].count > longest)
			longest = growth->barbs[i].count;
	expand_ctx ctx = {.def = def, .growth = growth, .shape = shape};
	ctx.local_distal = plume_alloc(n * sizeof *ctx.local_distal);
	ctx.local_proximal = plume_alloc(n * sizeof *ctx.local_proximal);
	ctx.boundary = plume_alloc((size_t)(longest + 1) * sizeof *ctx.boundary);
	ctx.blocks = plume_alloc((size_t)(longest / BLOCK + 1) * sizeof *ctx.blocks);
	barbules->snap = plume_calloc(nb, sizeof *barbules->snap);
	barbules->snapped = plume_calloc(nb, sizeof *barbules->snapped);
	if (def->expansion) {
		barbules->distal = plume_alloc(n * sizeof *barbules->distal);
		barbules->proximal = plume_alloc(n * sizeof *barbules->proximal);
	}
	plume_status status = PLUME_OK;
	if (ctx.local_distal == NULL || ctx.local_proximal == NULL || ctx.boundary == NULL || ctx.blocks == NULL ||
	    barbules->snap == NULL || barbules->snapped == NULL ||
	    (def->expansion && (barbules->distal == NULL || barbules->proximal == NULL))) {
		status = PLUME_ERROR_MEMORY;
		goto done;
	}
	if (!def->expansion)
		goto done; // every barb PLUME_ZK_SNAP_OFF (zero)

	zk_curve ve, ridge;
	zk_curve_init(&ve, &def->emitter_speed);
	zk_curve_init(&ridge, &def->ridge_height);
	barbule_angles angles[2][2]; // [side][distal, proximal]
	for (int side = 0; side < 2; ++side) {
		double dir = side == PLUME_SIDE_LEFT ? -1.0 : 1.0;
		angles[side][0] = make_angles(def->theta_distal, dir * def->azimuth, dir);
		angles[side][1] = make_angles(def->theta_proximal, -dir * def->azimuth, dir);
	}
	for (int i = 0; i < growth->barb_count; ++i) {
		const zk_barb *barb = growth->barbs + i;
		const barbule_angles *side = angles[barb->side];
		for (int j = 0; j < barb->count; ++j) {
			int v = barb->first + j;
			double s = shape->locus[v], vs = zk_curve_eval(&ve, s), l = zk_curve_eval(&ridge, s);
			plume_vec3 axis = core_v3_normalize(plume_v3(vs, 0.0, def->growth_speed)); // eq. 11 in (t, n, b)
			ctx.local_distal[v] = barbule_local(axis, l, side + 0);
			ctx.local_proximal[v] = barbule_local(axis, l, side + 1);
		}
	}
	// Splits first ("bend a chosen barb before snapping").
	for (int k = 0; k < def->split_count; ++k) {
		const plume_zk_split *split = def->splits + k;
		for (int i = 0; i < growth->barb_count; ++i) {
			const zk_barb *barb = growth->barbs + i;
			if (barb->side == split->side && barb->index == split->barb && barb->count > 0) {
				apply_split(shape, barb, split);
				barbules->snap[i] = PLUME_ZK_SNAP_SPLIT;
			}
		}
	}
	// Each vane from its most distal barb proximally: growth order is emission order.
	for (int i = 0; i < growth->barb_count; ++i) {
		const zk_barb *barb = growth->barbs + i;
		bool top = i == 0 || growth->barbs[i - 1].side != barb->side;
		if (barbules->snap[i] == PLUME_ZK_SNAP_SPLIT)
			continue;
		if (top) {
			barbules->snap[i] = PLUME_ZK_SNAP_TOP;
			continue;
		}
		int snapped = snap_pair(&ctx, growth->barbs + i - 1, barb);
		barbules->snapped[i] = snapped;
		barbules->snap[i] = snapped == 0 ? PLUME_ZK_SNAP_SKIPPED
		                                 : (snapped == barb->count ? PLUME_ZK_SNAP_FULL : PLUME_ZK_SNAP_PARTIAL);
	}
	for (int v = 0; v < growth->vertex_count; ++v) {
		barbules->distal[v] = world_barbule(&ctx, ctx.local_distal, v);
		barbules->proximal[v] = world_barbule(&ctx, ctx.local_proximal, v);
	}
done:
	plume_free(ctx.local_distal);
	plume_free(ctx.local_proximal);
	plume_free(ctx.boundary);
	plume_free(ctx.blocks);
	if (status != PLUME_OK)
		zk_barbules_free(barbules);
	return status;
}

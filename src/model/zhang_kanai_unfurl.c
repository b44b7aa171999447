// Unfurling (Zhang & Kanai IV-B) and the helix it starts from.
//
// Helix: a vertex at locus s recorded at time t sits at C(s) + y u_y with
// y = v_grow (t_curr - t) (eq. 5). Its discrete frame (eq. 6-8) is
//   t = dir dC/ds,  b = u_y,  n = b x t,   dir = -1 left, +1 right.
// Every frame shares b = u_y, so the hierarchy of eq. 9-10 reduces to one
// heading angle per vertex: in the parent's frame the child's offset has a
// horizontal part at angle alpha from the parent's tangent, and the child's
// tangent is turned by delta from the parent's. Unfurling by w rotates the
// offset by -w alpha and the tangent by -w delta about b ("align each line
// segment, and each tangent, to the tangent of the parent frame"), so
// the chain keeps every segment length; w = 0 is the helix and w = 1 lays the
// barb in the plane of its root's tangent and u_y.
#include <math.h>
#include <string.h>

#include "../core/alloc.h"
#include "zhang_kanai_internal.h"

static const double pi = 3.14159265358979323846264338327950288;

static zk_frame frame_from_heading(double psi)
{
	// t = (cos psi, 0, sin psi), b = u_y, n = b x t = (sin psi, 0, -cos psi).
	double c = cos(psi), s = sin(psi);
	return (zk_frame){.t = {c, 0.0, s}, .n = {s, 0.0, -c}, .b = {0.0, 1.0, 0.0}};
}

double zk_wrap_angle(double a)
{
	// A difference of two angles needs a turn or two. Past 64 pi (a runaway or
	// non-finite angle) remainder() reduces it at once: turn by turn never ended
	// (1e20 - 2 pi is 1e20, inf - 2 pi is inf); NaN (also from inf) skips the loops.
	if (!(fabs(a) <= 64.0 * pi))
		a = remainder(a, 2.0 * pi);
	while (a > pi)
		a -= 2.0 * pi;
	while (a <= -pi)
		a += 2.0 * pi;
	return a;
}

/// w = 1 without trigonometry: every segment's horizontal part along the
/// root's tangent, every frame the root's (the same result as the general path).
static void lay_flat(plume_vec3 *p, zk_frame *frame, int count)
{
	plume_vec3 parent = p[0];
	for (int j = 0; j + 1 < count; ++j) {
		plume_vec3 offset = plume_v3_sub(p[j + 1], parent);
		parent = p[j + 1];
		double horizontal = hypot(plume_v3_dot(offset, frame[j].t), plume_v3_dot(offset, frame[j].n));
		p[j + 1] = plume_v3(p[j].x + horizontal * frame[0].t.x, p[j].y + offset.y, p[j].z + horizontal * frame[0].t.z);
		frame[j] = frame[0];
	}
	frame[count - 1] = frame[0];
}

void zk_unfurl_chain(plume_vec3 *p, zk_frame *frame, int count, double w)
{
	if (count < 1)
		return;
	if (w == 1.0) {
		lay_flat(p, frame, count);
		return;
	}
	double psi = atan2(frame[0].t.z, frame[0].t.x);
	double heading = psi;                      // the root's frame does not move (eq. 9: P^_0 = P_0)
	plume_vec3 position = p[0], parent = p[0]; // parent: p[j] before it was moved
	for (int j = 0; j + 1 < count; ++j) {
		plume_vec3 offset = plume_v3_sub(p[j + 1], parent);
		parent = p[j + 1];
		double along = plume_v3_dot(offset, frame[j].t), across = plume_v3_dot(offset, frame[j].n);
		double alpha = atan2(across, along); // offset's angle from the tangent, in the parent's frame
		double horizontal = hypot(along, across);
		double child_psi = atan2(frame[j + 1].t.z, frame[j + 1].t.x);
		double delta = zk_wrap_angle(child_psi - psi);
		psi = child_psi;
		// A vector at angle beta from t towards n has the world heading psi - beta.
		double segment_heading = heading - (1.0 - w) * alpha;
		position = plume_v3(position.x + horizontal * cos(segment_heading), position.y + offset.y,
		                    position.z + horizontal * sin(segment_heading));
		p[j + 1] = position;
		// The parent's frame is final already: write it only now, the loop read it above.
		frame[j] = frame_from_heading(heading);
		heading += (1.0 - w) * delta;
	}
	frame[count - 1] = frame_from_heading(heading);
}

void zk_shape_free(zk_shape *shape)
{
	plume_free(shape->p);
	plume_free(shape->frame);
	plume_free(shape->locus);
	plume_free(shape->weight);
	memset(shape, 0, sizeof *shape);
}

/// Per-barb weight: the global w, or w scaled by how far the root has risen
/// past the sheath's broken edge.
static double barb_weight(const plume_zk_def *def, double root_y)
{
	if (!def->sheath)
		return def->unfurl_weight;
	double u = (root_y - def->sheath_height) / def->sheath_ramp;
	return def->unfurl_weight * (u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u));
}

plume_status zk_unfurl(const plume_zk_def *def, const zk_collar *collar, const zk_growth *growth, zk_shape *shape)
{
	memset(shape, 0, sizeof *shape);
	size_t n = (size_t)(growth->vertex_count > 0 ? growth->vertex_count : 1);
	shape->p = plume_alloc(n * sizeof *shape->p);
	shape->frame = plume_alloc(n * sizeof *shape->frame);
	shape->locus = plume_alloc(n * sizeof *shape->locus);
	shape->weight = plume_alloc((size_t)(growth->barb_count > 0 ? growth->barb_count : 1) * sizeof *shape->weight);
	if (shape->p == NULL || shape->frame == NULL || shape->locus == NULL || shape->weight == NULL) {
		zk_shape_free(shape);
		return PLUME_ERROR_MEMORY;
	}
	// The rachis will stand on the middle of I_A's chord: make that the y axis.
	plume_vec3 a = zk_collar_point(collar, def->anterior[0]), b = zk_collar_point(collar, def->anterior[1]);
	shape->origin = plume_v3_scale(plume_v3_add(a, b), 0.5);
	for (int i = 0; i < growth->barb_count; ++i) {
		const zk_barb *barb = growth->barbs + i;
		double dir = barb->side == PLUME_SIDE_LEFT ? -1.0 : 1.0;
		for (int j = 0; j < barb->count; ++j) {
			// Growth stored the tip first; forward kinematics wants the root first.
			int from = barb->first + barb->count - 1 - j, to = barb->first + j;
			double s = growth->locus[from];
			plume_vec3 on_collar, tangent;
			zk_collar_frame(collar, s, &on_collar, &tangent);
			plume_vec3 c = plume_v3_sub(on_collar, shape->origin);
			c.y = def->growth_speed * (growth->t_curr - growth->time[from]); // eq. 5
			shape->p[to] = c;
			shape->locus[to] = s;
			plume_vec3 t = plume_v3_scale(tangent, dir);                                        // eq. 6
			shape->frame[to] = (zk_frame){.t = t, .n = {t.z, 0.0, -t.x}, .b = {0.0, 1.0, 0.0}}; // eq. 7-8
		}
		double w = barb_weight(def, shape->p[barb->first].y);
		shape->weight[i] = w;
		zk_unfurl_chain(shape->p + barb->first, shape->frame + barb->first, barb->count, w);
	}
	return PLUME_OK;
}

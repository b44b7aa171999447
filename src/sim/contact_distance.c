// Distances between contact primitives (sim/contact_distance.h).
//
// Both functions return the squared distance between two actual points of the
// primitives, chosen region by region, so a rounding error can only make the answer
// larger than the exact one by rounding, never report a pair closer than it is.
#include "sim/contact_distance.h"

/// Squared distance from p to the segment ab and the parameter of its closest point.
static double point_segment_distance2(plume_vec3 p, plume_vec3 a, plume_vec3 b, double *parameter)
{
	plume_vec3 ab = plume_v3_sub(b, a);
	double length2 = plume_v3_dot(ab, ab);
	double t = length2 > 0 ? plume_v3_dot(plume_v3_sub(p, a), ab) / length2 : 0;
	t = t < 0 ? 0 : t > 1 ? 1 : t;
	*parameter = t;
	plume_vec3 d = plume_v3_sub(p, plume_v3_mad(a, t, ab));
	return plume_v3_dot(d, d);
}

/// The kind for a point against segment (from, to): its endpoints or its interior.
static plume_distance_kind segment_kind(double t, plume_distance_kind at_from, plume_distance_kind at_to,
                                        plume_distance_kind interior)
{
	return t <= 0 ? at_from : t >= 1 ? at_to : interior;
}

double plume_point_triangle_distance2(plume_vec3 p, plume_vec3 a, plume_vec3 b, plume_vec3 c, plume_distance_kind *kind)
{
	plume_vec3 ab = plume_v3_sub(b, a), ac = plume_v3_sub(c, a);
	plume_vec3 n = plume_v3_cross(ab, ac);
	double n2 = plume_v3_dot(n, n);
	plume_distance_kind found = PLUME_PT_PLANE;
	double best = 0;
	// Interior: the projection of p lies inside the triangle when its barycentric
	// coordinates (signed sub-areas over the area) are all positive.
	if (n2 > 0) {
		plume_vec3 ap = plume_v3_sub(p, a), bp = plume_v3_sub(p, b), cp = plume_v3_sub(p, c);
		double u = plume_v3_dot(plume_v3_cross(plume_v3_sub(c, b), bp), n);
		double v = plume_v3_dot(plume_v3_cross(ac, cp), n) * -1;
		double w = plume_v3_dot(plume_v3_cross(ab, ap), n);
		if (u > 0 && v > 0 && w > 0) {
			double h = plume_v3_dot(ap, n);
			plume_vec3 projected = plume_v3_mad(p, -h / n2, n);
			plume_vec3 d = plume_v3_sub(p, projected);
			best = plume_v3_dot(d, d);
			if (kind != NULL)
				*kind = found;
			return best;
		}
	}
	// Otherwise (or degenerate) the closest point is on the boundary.
	double t;
	best = point_segment_distance2(p, a, b, &t);
	found = segment_kind(t, PLUME_PT_A, PLUME_PT_B, PLUME_PT_AB);
	double d2 = point_segment_distance2(p, b, c, &t);
	if (d2 < best) {
		best = d2;
		found = segment_kind(t, PLUME_PT_B, PLUME_PT_C, PLUME_PT_BC);
	}
	d2 = point_segment_distance2(p, c, a, &t);
	if (d2 < best) {
		best = d2;
		found = segment_kind(t, PLUME_PT_C, PLUME_PT_A, PLUME_PT_CA);
	}
	if (kind != NULL)
		*kind = found;
	return best;
}

double plume_edge_edge_distance2(plume_vec3 a0, plume_vec3 a1, plume_vec3 b0, plume_vec3 b1, plume_distance_kind *kind)
{
	// The closest pair has an endpoint in it unless both closest points are interior,
	// which needs the lines not to be parallel: try the lines, then the four endpoints.
	plume_vec3 da = plume_v3_sub(a1, a0), db = plume_v3_sub(b1, b0), r = plume_v3_sub(a0, b0);
	double aa = plume_v3_dot(da, da), bb = plume_v3_dot(db, db), ab = plume_v3_dot(da, db);
	double ar = plume_v3_dot(da, r), br = plume_v3_dot(db, r);
	double denominator = aa * bb - ab * ab;
	double best = -1;
	plume_distance_kind found = PLUME_EE_LINES;
	if (denominator > 1e-14 * aa * bb) {
		// s from the 2x2 normal equations; t by projecting a(s) on the line b rather
		// than from the same equations. Near parallel lines s and t are both wrong
		// by about eps / sin² (the system is that ill-conditioned), and independent
		// errors move the pair across the valley of the distance: measured, d² 6%
		// too large at sin² = 2e-11. Projecting keeps the pair across from each
		// other, so the error in s only slides it along the valley (a change of
		// d² of order sin² δs²).
		double s = (ab * br - bb * ar) / denominator;
		plume_vec3 on_a = plume_v3_mad(a0, s, da);
		double t = plume_v3_dot(plume_v3_sub(on_a, b0), db) / bb;
		if (s > 0 && s < 1 && t > 0 && t < 1) {
			plume_vec3 d = plume_v3_sub(on_a, plume_v3_mad(b0, t, db));
			best = plume_v3_dot(d, d);
		}
	}
	double t;
	double d2 = point_segment_distance2(a0, b0, b1, &t);
	if (best < 0 || d2 < best) {
		best = d2;
		found = segment_kind(t, PLUME_EE_A0_B0, PLUME_EE_A0_B1, PLUME_EE_A0_B);
	}
	d2 = point_segment_distance2(a1, b0, b1, &t);
	if (d2 < best) {
		best = d2;
		found = segment_kind(t, PLUME_EE_A1_B0, PLUME_EE_A1_B1, PLUME_EE_A1_B);
	}
	d2 = point_segment_distance2(b0, a0, a1, &t);
	if (d2 < best) {
		best = d2;
		found = segment_kind(t, PLUME_EE_A0_B0, PLUME_EE_A1_B0, PLUME_EE_A_B0);
	}
	d2 = point_segment_distance2(b1, a0, a1, &t);
	if (d2 < best) {
		best = d2;
		found = segment_kind(t, PLUME_EE_A0_B1, PLUME_EE_A1_B1, PLUME_EE_A_B1);
	}
	if (kind != NULL)
		*kind = found;
	return best;
}

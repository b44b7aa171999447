// The barb-aligned mesher's input: the rachis centre line and the barb guides,
// read from a feather or from explicit guides (Jouve thesis 6.2, "Meshing").
//
// A generated feather has far more barbs than a simulation mesh has rows
// (2200 per vane against about 40 rows at e = 5 mm), and barbs drawn with
// random shapes (Franco & Walter 4.3) cross their neighbours. The guides are
// therefore derived, not copied: barbs rooted within one edge length of each
// other along the rachis are averaged point by point (at equal arc-length
// fractions) into one smoothed guide, which removes the random part of their
// shapes, and a guide that still crosses the previous kept guide is left out
// and counted. Sparse input (explicit guides, a few barbs) passes unchanged.
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/alloc.h"
#include "aligned_internal.h"

/// One input barb before averaging.
typedef struct raw_barb {
	double sigma;
	int index; ///< input order, to sort ties deterministically
	const plume_vec3 *points;
	const plume_vec2 *uv; ///< NULL: uv = (arc fraction, rachis parameter)
	int count;
	double t; ///< rachis parameter of the root, for the texture's v when uv is NULL
} raw_barb;

void mesh_input_free(mesh_input *input)
{
	plume_free(input->rachis.p);
	plume_free(input->rachis.tangent);
	plume_free(input->rachis.sigma);
	plume_free(input->rachis.width);
	plume_free(input->rachis.t);
	plume_free(input->rachis.lift);
	for (int side = 0; side < 2; ++side)
		plume_free(input->guides[side]);
	memset(input, 0, sizeof *input);
}

static bool centre_alloc(mesh_centre *centre, int count)
{
	size_t n = (size_t)(count > 0 ? count : 1);
	centre->p = plume_calloc(n, sizeof *centre->p);
	centre->tangent = plume_calloc(n, sizeof *centre->tangent);
	centre->sigma = plume_calloc(n, sizeof *centre->sigma);
	centre->width = plume_calloc(n, sizeof *centre->width);
	centre->t = plume_calloc(n, sizeof *centre->t);
	centre->lift = plume_calloc(n, sizeof *centre->lift);
	return centre->p != NULL && centre->tangent != NULL && centre->sigma != NULL && centre->width != NULL &&
	       centre->t != NULL && centre->lift != NULL;
}

static double plane_distance(plume_vec3 a, plume_vec3 b) { return hypot(b.x - a.x, b.y - a.y); }

static bool finite3(plume_vec3 p) { return isfinite(p.x) && isfinite(p.y) && isfinite(p.z); }

/// Index i with sigma[i] <= s < sigma[i + 1], clamped to [0, count - 2].
static int find_segment(const double *values, int count, double s)
{
	int lo = 0, hi = count - 1;
	while (hi - lo > 1) {
		int mid = (lo + hi) / 2;
		if (values[mid] <= s)
			lo = mid;
		else
			hi = mid;
	}
	return lo;
}

void mesh_centre_eval(const mesh_centre *centre, double sigma, plume_vec3 *p, plume_vec2 *tangent, double *width,
                      double *t, double *lift)
{
	int i = find_segment(centre->sigma, centre->count, sigma);
	double span = centre->sigma[i + 1] - centre->sigma[i];
	double a = (sigma - centre->sigma[i]) / span;
	a = a < 0.0 ? 0.0 : a > 1.0 ? 1.0 : a;
	*p = plume_v3_lerp(centre->p[i], centre->p[i + 1], a);
	plume_vec2 t0 = centre->tangent[i], t1 = centre->tangent[i + 1];
	plume_vec2 d = {t0.x + a * (t1.x - t0.x), t0.y + a * (t1.y - t0.y)};
	double length = hypot(d.x, d.y);
	if (length > 0.0)
		*tangent = (plume_vec2){d.x / length, d.y / length};
	else // opposite tangents at the segment's ends: use the chord
		*tangent =
		    (plume_vec2){(centre->p[i + 1].x - centre->p[i].x) / span, (centre->p[i + 1].y - centre->p[i].y) / span};
	*width = centre->width[i] + a * (centre->width[i + 1] - centre->width[i]);
	*t = centre->t[i] + a * (centre->t[i + 1] - centre->t[i]);
	*lift = centre->lift[i] + a * (centre->lift[i + 1] - centre->lift[i]);
}

/// Fills the tangents of samples whose tangent is unknown (zero) by finite differences.
static void finish_tangents(mesh_centre *centre)
{
	for (int i = 0; i < centre->count; ++i) {
		plume_vec2 *tangent = centre->tangent + i;
		double length = hypot(tangent->x, tangent->y);
		if (length > 0.0 && isfinite(length)) {
			*tangent = (plume_vec2){tangent->x / length, tangent->y / length};
			continue;
		}
		int a = i > 0 ? i - 1 : i, b = i + 1 < centre->count ? i + 1 : i;
		double span = centre->sigma[b] - centre->sigma[a];
		*tangent = (plume_vec2){(centre->p[b].x - centre->p[a].x) / span, (centre->p[b].y - centre->p[a].y) / span};
	}
}

// ---------------------------------------------------------------------------
// Segment crossing

static double orient(plume_vec3 a, plume_vec3 b, plume_vec3 c)
{
	return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// Proper crossing of segments pq and rs (touching at an end does not count).
static bool segments_cross(plume_vec3 p, plume_vec3 q, plume_vec3 r, plume_vec3 s)
{
	double o1 = orient(p, q, r), o2 = orient(p, q, s), o3 = orient(r, s, p), o4 = orient(r, s, q);
	return ((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)) && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0));
}

typedef struct box2 {
	double x0, y0, x1, y1;
} box2;

static box2 segment_box(plume_vec3 a, plume_vec3 b)
{
	return (box2){fmin(a.x, b.x), fmin(a.y, b.y), fmax(a.x, b.x), fmax(a.y, b.y)};
}

static bool boxes_overlap(box2 a, box2 b) { return a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1; }

bool mesh_polylines_cross(const plume_vec3 *a, int a_count, const plume_vec3 *b, int b_count)
{
	for (int i = 0; i + 1 < a_count; ++i) {
		box2 box = segment_box(a[i], a[i + 1]);
		for (int j = 0; j + 1 < b_count; ++j)
			if (boxes_overlap(box, segment_box(b[j], b[j + 1])) && segments_cross(a[i], a[i + 1], b[j], b[j + 1]))
				return true;
	}
	return false;
}

// ---------------------------------------------------------------------------
// Guides

/// Resamples a polyline at MESH_GUIDE_SAMPLES points equally spaced in plane arc
/// length. False when it has no plane length or a non-finite point.
static bool resample(const raw_barb *raw, mesh_guide *out)
{
	if (raw->count < 2)
		return false;
	double total = 0.0;
	for (int i = 0; i < raw->count; ++i)
		if (!finite3(raw->points[i]))
			return false;
	for (int i = 0; i + 1 < raw->count; ++i)
		total += plane_distance(raw->points[i], raw->points[i + 1]);
	if (!(total > 0.0) || !isfinite(total))
		return false;
	int segment = 0;
	double start = 0.0; // arc length at points[segment]
	for (int k = 0; k < MESH_GUIDE_SAMPLES; ++k) {
		double s = (double)k / (MESH_GUIDE_SAMPLES - 1);
		double target = s * total;
		double length = plane_distance(raw->points[segment], raw->points[segment + 1]);
		while (segment + 2 < raw->count && start + length < target) {
			start += length;
			++segment;
			length = plane_distance(raw->points[segment], raw->points[segment + 1]);
		}
		double a = length > 0.0 ? (target - start) / length : 0.0;
		a = a < 0.0 ? 0.0 : a > 1.0 ? 1.0 : a;
		if (k == MESH_GUIDE_SAMPLES - 1) {
			segment = raw->count - 2;
			a = 1.0;
		}
		out->p[k] = plume_v3_lerp(raw->points[segment], raw->points[segment + 1], a);
		if (raw->uv != NULL) {
			plume_vec2 u0 = raw->uv[segment], u1 = raw->uv[segment + 1];
			out->uv[k] = (plume_vec2){u0.x + a * (u1.x - u0.x), u0.y + a * (u1.y - u0.y)};
		} else {
			out->uv[k] = (plume_vec2){s, raw->t};
		}
	}
	return true;
}

static int compare_raw(const void *a, const void *b)
{
	const raw_barb *x = a, *y = b;
	if (x->sigma != y->sigma)
		return x->sigma < y->sigma ? -1 : 1;
	return (x->index > y->index) - (x->index < y->index);
}

/// Appends a finished bin to the side's guides unless it crosses the last kept one.
static void keep_bin(mesh_input *input, int side, mesh_guide *bin)
{
	double w = 1.0 / bin->weight;
	bin->sigma *= w;
	for (int k = 0; k < MESH_GUIDE_SAMPLES; ++k) {
		bin->p[k] = plume_v3_scale(bin->p[k], w);
		bin->uv[k] = (plume_vec2){bin->uv[k].x * w, bin->uv[k].y * w};
	}
	int n = input->guide_count[side];
	if (n > 0 && mesh_polylines_cross(input->guides[side][n - 1].p, MESH_GUIDE_SAMPLES, bin->p, MESH_GUIDE_SAMPLES)) {
		input->guides_dropped += bin->weight;
		return;
	}
	if (bin->weight > 1)
		input->barbs_averaged += bin->weight;
	input->guides[side][input->guide_count[side]++] = *bin;
}

/// Sorts one side's barbs along the rachis, averages those within edge_length
/// of the first barb of their bin, and keeps the non-crossing averages.
static plume_status build_side_guides(mesh_input *input, int side, raw_barb *raws, int count, double edge_length,
                                      plume_error *err)
{
	input->guides[side] = plume_calloc((size_t)(count > 0 ? count : 1), sizeof(mesh_guide));
	if (input->guides[side] == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building barb guides");
	input->sigma_first[side] = INFINITY;
	input->sigma_last[side] = -INFINITY;
	qsort(raws, (size_t)count, sizeof *raws, compare_raw);
	mesh_guide bin, sample;
	memset(&bin, 0, sizeof bin);
	double bin_start = 0.0;
	// The first and the last barb stay guides of their own, so that the vane
	// starts and ends exactly where the barbs do (at the tip, both vanes' last
	// barbs usually meet in one point).
	int first_valid = -1, last_valid = -1;
	for (int i = 0; i < count && first_valid < 0; ++i)
		if (isfinite(raws[i].sigma) && resample(raws + i, &sample))
			first_valid = i;
	for (int i = count - 1; i > first_valid && last_valid < 0; --i)
		if (isfinite(raws[i].sigma) && resample(raws + i, &sample))
			last_valid = i;
	for (int i = 0; i < count; ++i) {
		if (!isfinite(raws[i].sigma) || !resample(raws + i, &sample)) {
			++input->guides_dropped;
			continue;
		}
		bool alone = i == first_valid || i == last_valid;
		bool after_first =
		    bin.weight > 0 && bin_start == raws[first_valid].sigma && bin.weight == 1 && i == first_valid + 1;
		if (bin.weight > 0 && (alone || after_first || raws[i].sigma >= bin_start + edge_length)) {
			keep_bin(input, side, &bin);
			memset(&bin, 0, sizeof bin);
		}
		if (bin.weight == 0)
			bin_start = raws[i].sigma;
		bin.weight++;
		bin.sigma += raws[i].sigma;
		for (int k = 0; k < MESH_GUIDE_SAMPLES; ++k) {
			bin.p[k] = plume_v3_add(bin.p[k], sample.p[k]);
			bin.uv[k] = (plume_vec2){bin.uv[k].x + sample.uv[k].x, bin.uv[k].y + sample.uv[k].y};
		}
		input->sigma_first[side] = fmin(input->sigma_first[side], raws[i].sigma);
		input->sigma_last[side] = fmax(input->sigma_last[side], raws[i].sigma);
	}
	if (bin.weight > 0)
		keep_bin(input, side, &bin);
	return PLUME_OK;
}

/// Plane arc length of the centre line where its shaft parameter is t.
static double sigma_at_t(const mesh_centre *centre, double t)
{
	int i = find_segment(centre->t, centre->count, t);
	double span = centre->t[i + 1] - centre->t[i];
	double a = span > 0.0 ? (t - centre->t[i]) / span : 0.0;
	a = a < 0.0 ? 0.0 : a > 1.0 ? 1.0 : a;
	return centre->sigma[i] + a * (centre->sigma[i + 1] - centre->sigma[i]);
}

static plume_status check_def(const plume_mesh_def *def, plume_error *err)
{
	if (!(def->edge_length > 0.0) || !isfinite(def->edge_length))
		return plume_error_set(err, PLUME_ERROR_SPEC, "mesh edge_length is %g, must be a positive length in metres",
		                       def->edge_length);
	if (!isfinite(def->rachis_width_base) || !isfinite(def->rachis_width_tip))
		return plume_error_set(err, PLUME_ERROR_SPEC, "mesh rachis widths must be finite (<= 0: from the feather)");
	return PLUME_OK;
}

static plume_status finish_widths(mesh_input *input, const plume_mesh_def *def, plume_error *err)
{
	double start = fmin(input->sigma_first[0], input->sigma_first[1]);
	if (!isfinite(start))
		start = 0.0;
	plume_vec3 p;
	plume_vec2 tangent;
	double width, t, lift;
	mesh_centre_eval(&input->rachis, start, &p, &tangent, &width, &t, &lift);
	input->width_base = def->rachis_width_base > 0.0 ? def->rachis_width_base : width;
	input->width_tip =
	    def->rachis_width_tip > 0.0 ? def->rachis_width_tip : input->rachis.width[input->rachis.count - 1];
	if (!(def->rachis_width_tip > 0.0) && !(input->width_tip > 0.0)) {
		// A shaft that ends in a point (Streit & Heidrich's taper to zero): the band
		// takes the shaft's width one edge length below the tip, at the last row.
		double end = input->rachis.sigma[input->rachis.count - 1];
		mesh_centre_eval(&input->rachis, fmax(0.0, end - def->edge_length), &p, &tangent, &input->width_tip, &t, &lift);
	}
	if (!(input->width_base > 0.0) || !(input->width_tip > 0.0) || !isfinite(input->width_base) ||
	    !isfinite(input->width_tip))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "the rachis band needs a positive width (base %g m, tip %g m): set the mesh's "
		                       "rachis_width_base and rachis_width_tip",
		                       input->width_base, input->width_tip);
	return PLUME_OK;
}

plume_status mesh_input_from_feather(const plume_feather *feather, const plume_mesh_def *def, mesh_input *input,
                                     plume_error *err)
{
	memset(input, 0, sizeof *input);
	plume_status status = check_def(def, err);
	if (status != PLUME_OK)
		return status;
	plume_feather_info info = plume_feather_get_info(feather);
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	mesh_centre *centre = &input->rachis;
	if (!centre_alloc(centre, info.shaft_sample_count)) {
		mesh_input_free(input);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory reading the feather's shaft");
	}
	// Shaft samples that do not advance in the plane (duplicates) are skipped,
	// so that sigma increases strictly.
	for (int i = 0; i < info.shaft_sample_count; ++i) {
		const plume_shaft_sample *sample = shaft + i;
		if (!finite3(sample->position) || !isfinite(sample->width) || !isfinite(sample->t))
			continue;
		int n = centre->count;
		double step = n > 0 ? plane_distance(centre->p[n - 1], sample->position) : 0.0;
		if (n > 0 && !(step > 0.0))
			continue;
		centre->p[n] = sample->position;
		centre->sigma[n] = n > 0 ? centre->sigma[n - 1] + step : 0.0;
		centre->tangent[n] =
		    finite3(sample->tangent) ? (plume_vec2){sample->tangent.x, sample->tangent.y} : (plume_vec2){0.0, 0.0};
		centre->width[n] = sample->width;
		centre->t[n] = n > 0 && sample->t < centre->t[n - 1] ? centre->t[n - 1] : sample->t;
		double planar = hypot(sample->binormal.x, sample->binormal.y);
		centre->lift[n] = planar > 0.0 && finite3(sample->binormal) ? sample->binormal.z / planar : 0.0;
		centre->count = n + 1;
	}
	if (centre->count < 2) {
		mesh_input_free(input);
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "cannot mesh a feather whose shaft has no length in the feather plane "
		                       "(%d distinct samples)",
		                       centre->count);
	}
	finish_tangents(centre);

	raw_barb *raws = plume_calloc((size_t)(info.barb_count > 0 ? info.barb_count : 1), sizeof *raws);
	if (raws == NULL) {
		mesh_input_free(input);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory reading the feather's barbs");
	}
	for (int side = 0; side < 2 && status == PLUME_OK; ++side) {
		int count = 0;
		for (int i = 0; i < info.barb_count; ++i) {
			plume_barb barb = plume_feather_barb(feather, i);
			if ((int)barb.side != side)
				continue;
			raws[count++] = (raw_barb){
			    .sigma = isfinite(barb.rachis_t) ? sigma_at_t(centre, barb.rachis_t) : NAN,
			    .index = i,
			    .points = barb.curve.points,
			    .uv = barb.curve.uv,
			    .count = barb.curve.count,
			    .t = barb.rachis_t,
			};
		}
		status = build_side_guides(input, side, raws, count, def->edge_length, err);
	}
	plume_free(raws);
	if (status == PLUME_OK)
		status = finish_widths(input, def, err);
	if (status != PLUME_OK)
		mesh_input_free(input);
	return status;
}

/// Plane arc length of the point of the centre line nearest to p.
static double project_on_centre(const mesh_centre *centre, plume_vec3 p)
{
	double best = INFINITY, sigma = 0.0;
	for (int i = 0; i + 1 < centre->count; ++i) {
		plume_vec3 a = centre->p[i], b = centre->p[i + 1];
		double dx = b.x - a.x, dy = b.y - a.y;
		double length2 = dx * dx + dy * dy;
		double u = ((p.x - a.x) * dx + (p.y - a.y) * dy) / length2;
		u = u < 0.0 ? 0.0 : u > 1.0 ? 1.0 : u;
		double ex = a.x + u * dx - p.x, ey = a.y + u * dy - p.y;
		double distance2 = ex * ex + ey * ey;
		if (distance2 < best) {
			best = distance2;
			sigma = centre->sigma[i] + u * (centre->sigma[i + 1] - centre->sigma[i]);
		}
	}
	return sigma;
}

plume_status mesh_input_from_guides(const plume_mesh_guides *guides, const plume_mesh_def *def, mesh_input *input,
                                    plume_error *err)
{
	memset(input, 0, sizeof *input);
	plume_status status = check_def(def, err);
	if (status != PLUME_OK)
		return status;
	if (!(def->rachis_width_base > 0.0) || !(def->rachis_width_tip > 0.0))
		return plume_error_set(
		    err, PLUME_ERROR_SPEC,
		    "explicit guides need positive rachis_width_base and rachis_width_tip (m), got %g and %g",
		    def->rachis_width_base, def->rachis_width_tip);
	if (guides->boundary_count < 3)
		return plume_error_set(err, PLUME_ERROR_SPEC, "the boundary polygon needs at least 3 points, got %d",
		                       guides->boundary_count);
	for (int i = 0; i < guides->boundary_count; ++i)
		if (!isfinite(guides->boundary[i].x) || !isfinite(guides->boundary[i].y))
			return plume_error_set(err, PLUME_ERROR_SPEC, "boundary point %d is not finite", i);
	mesh_centre *centre = &input->rachis;
	if (!centre_alloc(centre, guides->rachis_count)) {
		mesh_input_free(input);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory reading the rachis");
	}
	for (int i = 0; i < guides->rachis_count; ++i) {
		plume_vec3 p = {guides->rachis[i].x, guides->rachis[i].y, 0.0};
		if (!finite3(p)) {
			mesh_input_free(input);
			return plume_error_set(err, PLUME_ERROR_SPEC, "rachis point %d is not finite", i);
		}
		int n = centre->count;
		double step = n > 0 ? plane_distance(centre->p[n - 1], p) : 0.0;
		if (n > 0 && !(step > 0.0))
			continue;
		centre->p[n] = p;
		centre->sigma[n] = n > 0 ? centre->sigma[n - 1] + step : 0.0;
		centre->count = n + 1;
	}
	if (centre->count < 2) {
		mesh_input_free(input);
		return plume_error_set(err, PLUME_ERROR_SPEC, "the rachis needs at least 2 distinct points");
	}
	double length = centre->sigma[centre->count - 1];
	for (int i = 0; i < centre->count; ++i) {
		centre->t[i] = centre->sigma[i] / length;
		centre->width[i] = def->rachis_width_base + centre->t[i] * (def->rachis_width_tip - def->rachis_width_base);
	}
	finish_tangents(centre);
	input->boundary = guides->boundary;
	input->boundary_count = guides->boundary_count;

	// The guides' points lifted to z = 0, and each guide's side: left when it
	// leaves the rachis to the left of its direction (thesis Figure 6.2).
	int total = guides->guide_count > 0 ? guides->guide_offsets[guides->guide_count] : 0;
	plume_vec3 *points = plume_calloc((size_t)(total > 0 ? total : 1), sizeof *points);
	raw_barb *raws = plume_calloc((size_t)(guides->guide_count > 0 ? guides->guide_count : 1), sizeof *raws);
	int *sides = plume_calloc((size_t)(guides->guide_count > 0 ? guides->guide_count : 1), sizeof *sides);
	if (points == NULL || raws == NULL || sides == NULL)
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory reading the guides");
	for (int i = 0; i < total && status == PLUME_OK; ++i)
		points[i] = (plume_vec3){guides->guide_points[i].x, guides->guide_points[i].y, 0.0};
	for (int g = 0; g < guides->guide_count && status == PLUME_OK; ++g) {
		int first = guides->guide_offsets[g], count = guides->guide_offsets[g + 1] - first;
		double sigma = count > 0 ? project_on_centre(centre, points[first]) : NAN;
		sides[g] = PLUME_SIDE_LEFT;
		if (count >= 2) {
			plume_vec3 p;
			plume_vec2 tangent;
			double width, t, lift;
			mesh_centre_eval(centre, sigma, &p, &tangent, &width, &t, &lift);
			plume_vec3 d = plume_v3_sub(points[first + count - 1], points[first]);
			sides[g] = tangent.x * d.y - tangent.y * d.x >= 0.0 ? PLUME_SIDE_LEFT : PLUME_SIDE_RIGHT;
		}
		raws[g] = (raw_barb){.sigma = sigma,
		                     .index = g,
		                     .points = points + first,
		                     .uv = NULL,
		                     .count = count,
		                     .t = isfinite(sigma) ? sigma / length : 0.0};
	}
	raw_barb *mine = plume_calloc((size_t)(guides->guide_count > 0 ? guides->guide_count : 1), sizeof *mine);
	if (mine == NULL && status == PLUME_OK)
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory reading the guides");
	for (int side = 0; side < 2 && status == PLUME_OK; ++side) {
		int count = 0;
		for (int g = 0; g < guides->guide_count; ++g)
			if (sides[g] == side)
				mine[count++] = raws[g];
		status = build_side_guides(input, side, mine, count, def->edge_length, err);
	}
	plume_free(mine);
	// Explicit guides are extrapolated over the whole rachis (the thesis meshes
	// everything the boundary encloses), so the vane spans every row.
	for (int side = 0; side < 2; ++side)
		if (input->guide_count[side] > 0) {
			input->sigma_first[side] = -INFINITY;
			input->sigma_last[side] = INFINITY;
		}
	if (status == PLUME_OK)
		status = finish_widths(input, def, err);
	plume_free(points);
	plume_free(raws);
	plume_free(sides);
	if (status != PLUME_OK)
		mesh_input_free(input);
	return status;
}

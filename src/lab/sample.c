// The lab's rectangular samples (Jouve thesis 3.2 and 4.3): barb-aligned meshes
// made of strips between lines parallel to the barbs, Delaunay meshes of
// jittered random points (Qhull), and mesoscale band samples whose band
// boundaries are mesh lines.
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libqhull_r/qhull_ra.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "plume/lab.h"

static const double PI = 3.14159265358979323846;

plume_sample_def plume_sample_default_def(void)
{
	return (plume_sample_def){
	    .cookie = PLUME_DEF_COOKIE,
	    .width = 1.0e-2,
	    .height = 1.3e-2,
	    .thickness = 1.2e-4,
	    .barb_angle = 0.25 * PI,
	    .mesh = PLUME_SAMPLE_ALIGNED,
	    .element_count = 2000,
	    .seed = 1,
	};
}

plume_band_def plume_band_default_def(void)
{
	return (plume_band_def){.cookie = PLUME_DEF_COOKIE,
	                        .period = 4.0e-4,
	                        .barb_fraction = 0.14,
	                        .barb_divisions = 1,
	                        .barbule_divisions = 3};
}

// Growing arrays of points and triangles, filled by the two meshers.
typedef struct builder {
	plume_vec2 *points;
	int point_count, point_capacity;
	int *faces; // 3 per triangle
	signed char *barb_edge;
	unsigned char *material;
	int face_count, face_capacity, barb_edge_capacity, material_capacity;
} builder;

static void builder_free(builder *b)
{
	plume_free(b->points);
	plume_free(b->faces);
	plume_free(b->barb_edge);
	plume_free(b->material);
}

static int add_point(builder *b, plume_vec2 p)
{
	if (PLUME_GROW(b->points, b->point_capacity, b->point_count + 1) != 0)
		return -1;
	b->points[b->point_count] = p;
	return b->point_count++;
}

static double cross2(plume_vec2 a, plume_vec2 b, plume_vec2 c)
{
	return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Adds triangle (i, j, k), counter-clockwise; barb is the local index of the
// barb-aligned edge in the given order (-1: none), kept on the same edge if the
// triangle is flipped.
static int add_face(builder *b, int i, int j, int k, int barb, unsigned char material)
{
	if (PLUME_GROW(b->faces, b->face_capacity, 3 * (b->face_count + 1)) != 0 ||
	    PLUME_GROW(b->barb_edge, b->barb_edge_capacity, b->face_count + 1) != 0 ||
	    PLUME_GROW(b->material, b->material_capacity, b->face_count + 1) != 0)
		return -1;
	if (cross2(b->points[i], b->points[j], b->points[k]) < 0.0) {
		// (i, j, k) -> (i, k, j): edge 0 (i j) becomes 2 (j i), edge 1 (j k) stays 1, edge 2 (k i) becomes 0.
		int t = j;
		j = k;
		k = t;
		if (barb == 0)
			barb = 2;
		else if (barb == 2)
			barb = 0;
	}
	int *f = b->faces + 3 * b->face_count;
	f[0] = i;
	f[1] = j;
	f[2] = k;
	b->barb_edge[b->face_count] = (signed char)barb;
	b->material[b->face_count] = material;
	b->face_count++;
	return 0;
}

// ---------------------------------------------------------------------------
// Aligned meshes. With d the barb direction and n its normal, the lines
// n . p = w cut the rectangle in strips. The line offsets include the four
// corners, so every strip is bounded by two barb segments and two straight
// pieces of the rectangle's sides, and a zipper triangulation between the two
// segments gives triangles that each have an edge on a barb line.

typedef struct line_set {
	double *offsets;
	int count, capacity;
} line_set;

static int compare_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

static int push_offset(line_set *set, double w)
{
	if (PLUME_GROW(set->offsets, set->capacity, set->count + 1) != 0)
		return -1;
	set->offsets[set->count++] = w;
	return 0;
}

// Band of an offset: 1 inside a barb band, 0 inside a barbule band. Barb bands are
// centred at (k + 1/2 + phase) T from the lowest corner.
static int band_of(const plume_band_def *bands, double w_from_min)
{
	double s = fmod(w_from_min - bands->phase * bands->period + bands->period, bands->period) / bands->period;
	double half = 0.5 * bands->barb_fraction;
	return s > 0.5 - half && s < 0.5 + half;
}

// Clips the line n . p = w to the rectangle: the segment's parameter range along d.
static void clip_line(double W, double H, plume_vec2 d, plume_vec2 n, double w, double *t0, double *t1)
{
	double lo = -INFINITY, hi = INFINITY;
	// p = w n + t d; 0 <= p.x <= W, 0 <= p.y <= H.
	double base[2] = {w * n.x, w * n.y}, dir[2] = {d.x, d.y}, size[2] = {W, H};
	for (int a = 0; a < 2; ++a) {
		if (fabs(dir[a]) < 1e-14)
			continue;
		double ta = (0.0 - base[a]) / dir[a], tb = (size[a] - base[a]) / dir[a];
		if (ta > tb) {
			double t = ta;
			ta = tb;
			tb = t;
		}
		lo = fmax(lo, ta);
		hi = fmin(hi, tb);
	}
	if (hi < lo)
		hi = lo = 0.5 * (lo + hi); // a corner line: one point, up to rounding
	*t0 = lo;
	*t1 = hi;
}

static double snap(double value, double size, double tolerance)
{
	if (fabs(value) < tolerance)
		return 0.0;
	if (fabs(value - size) < tolerance)
		return size;
	return value;
}

static plume_status mesh_aligned(const plume_sample_def *sample, const plume_band_def *bands, builder *b,
                                 plume_error *err)
{
	double W = sample->width, H = sample->height;
	double phi = 0.5 * PI - sample->barb_angle; // barb direction from +x
	plume_vec2 d = {cos(phi), sin(phi)};
	plume_vec2 n = {-d.y, d.x};
	double tolerance = 1e-9 * fmax(W, H);
	double corners[4] = {0.0, W * n.x, H * n.y, W * n.x + H * n.y};
	qsort(corners, 4, sizeof *corners, compare_double);
	double w_min = corners[0], w_max = corners[3];
	double spacing = sqrt(2.0 * W * H / sample->element_count);

	// Break offsets: corners and band boundaries.
	line_set breaks = {0}, lines = {0};
	plume_status status = PLUME_OK;
	for (int i = 0; i < 4 && status == PLUME_OK; ++i)
		if (push_offset(&breaks, corners[i]) != 0)
			status = PLUME_ERROR_MEMORY;
	if (bands != NULL) {
		double T = bands->period, half = 0.5 * bands->barb_fraction * T;
		// The first centre at or below the lowest corner, so that a shifted pattern has
		// no gap there.
		for (double centre = w_min + (bands->phase - 0.5) * T; centre - half < w_max && status == PLUME_OK;
		     centre += T) {
			if (centre + half <= w_min)
				continue;
			if (push_offset(&breaks, centre - half) != 0 || push_offset(&breaks, centre + half) != 0)
				status = PLUME_ERROR_MEMORY;
		}
	}
	if (status != PLUME_OK)
		goto done;
	qsort(breaks.offsets, (size_t)breaks.count, sizeof *breaks.offsets, compare_double);
	// Subdivide each interval between breaks (inside [w_min, w_max]) into rows.
	double previous = w_min;
	if (push_offset(&lines, w_min) != 0) {
		status = PLUME_ERROR_MEMORY;
		goto done;
	}
	for (int i = 0; i < breaks.count; ++i) {
		double next = fmin(breaks.offsets[i], w_max);
		double gap = next - previous;
		if (gap <= tolerance)
			continue;
		int rows = (int)ceil(gap / spacing - 1e-9);
		if (bands != NULL) {
			int band = band_of(bands, 0.5 * (previous + next) - w_min);
			int divisions = band ? bands->barb_divisions : bands->barbule_divisions;
			double width = band ? bands->barb_fraction * bands->period : (1.0 - bands->barb_fraction) * bands->period;
			int band_rows = (int)ceil(divisions * gap / width - 1e-6);
			if (band_rows > rows)
				rows = band_rows;
		}
		if (rows < 1)
			rows = 1;
		for (int r = 1; r <= rows && status == PLUME_OK; ++r)
			if (push_offset(&lines, r == rows ? next : previous + gap * r / rows) != 0)
				status = PLUME_ERROR_MEMORY;
		previous = next;
	}
	if (status != PLUME_OK)
		goto done;

	// Spacing along the lines: triangles ~ 2 * total line length / spacing.
	double total_length = 0.0;
	for (int k = 0; k < lines.count; ++k) {
		double t0, t1;
		clip_line(W, H, d, n, lines.offsets[k], &t0, &t1);
		total_length += t1 - t0;
	}
	double along = 2.0 * total_length / sample->element_count;
	if (bands == NULL)
		along = fmin(along, spacing);
	if (!(along > 0.0))
		along = spacing;

	int *first = plume_alloc(sizeof(int) * (size_t)(lines.count + 1));
	if (first == NULL) {
		status = PLUME_ERROR_MEMORY;
		goto done;
	}
	for (int k = 0; k < lines.count && status == PLUME_OK; ++k) {
		double t0, t1;
		clip_line(W, H, d, n, lines.offsets[k], &t0, &t1);
		int segments = (int)lround((t1 - t0) / along);
		if (t1 - t0 <= tolerance)
			segments = 0;
		else if (segments < 1)
			segments = 1;
		first[k] = b->point_count;
		for (int j = 0; j <= segments; ++j) {
			double t = segments == 0 ? 0.5 * (t0 + t1) : t0 + (t1 - t0) * j / segments;
			plume_vec2 p = {lines.offsets[k] * n.x + t * d.x, lines.offsets[k] * n.y + t * d.y};
			p.x = snap(p.x, W, tolerance);
			p.y = snap(p.y, H, tolerance);
			if (add_point(b, p) < 0) {
				status = PLUME_ERROR_MEMORY;
				break;
			}
		}
	}
	if (status == PLUME_OK)
		first[lines.count] = b->point_count;
	// Zip consecutive lines: advance on the line whose next point comes first along d.
	for (int k = 0; k + 1 < lines.count && status == PLUME_OK; ++k) {
		unsigned char material = 0;
		if (bands != NULL)
			material = (unsigned char)(band_of(bands, 0.5 * (lines.offsets[k] + lines.offsets[k + 1]) - w_min)
			                               ? PLUME_BAND_BARB
			                               : PLUME_BAND_BARBULE);
		int a = first[k], a_end = first[k + 1] - 1;
		int c = first[k + 1], c_end = first[k + 2] - 1;
		while ((a < a_end || c < c_end) && status == PLUME_OK) {
			bool advance_a;
			if (a == a_end)
				advance_a = false;
			else if (c == c_end)
				advance_a = true;
			else {
				double ta = b->points[a + 1].x * d.x + b->points[a + 1].y * d.y;
				double tc = b->points[c + 1].x * d.x + b->points[c + 1].y * d.y;
				advance_a = ta <= tc;
			}
			int result = advance_a ? add_face(b, a, a + 1, c, 0, material) : add_face(b, c, c + 1, a, 0, material);
			if (result != 0)
				status = PLUME_ERROR_MEMORY;
			if (advance_a)
				++a;
			else
				++c;
		}
	}
	plume_free(first);
done:
	plume_free(breaks.offsets);
	plume_free(lines.offsets);
	if (status == PLUME_ERROR_MEMORY)
		plume_error_set(err, status, "out of memory building the aligned sample mesh");
	return status;
}

// ---------------------------------------------------------------------------
// Unaligned meshes: Qhull's Delaunay triangulation of points on the sides at
// the target spacing and of one random point per cell of a grid inside, each
// jittered within the middle 60% of its cell so that no two points come closer
// than a fifth of the spacing.

static plume_status mesh_unaligned(const plume_sample_def *sample, builder *b, plume_error *err)
{
	double W = sample->width, H = sample->height;
	double spacing = sqrt(2.0 * W * H / sample->element_count);
	int nx = (int)lround(W / spacing), ny = (int)lround(H / spacing);
	if (nx < 1)
		nx = 1;
	if (ny < 1)
		ny = 1;
	double hx = W / nx, hy = H / ny;
	plume_rng rng = plume_rng_seed(sample->seed);
	// Sides, counter-clockwise from the origin.
	for (int i = 0; i < nx; ++i)
		if (add_point(b, (plume_vec2){hx * i, 0.0}) < 0)
			goto memory;
	for (int j = 0; j < ny; ++j)
		if (add_point(b, (plume_vec2){W, hy * j}) < 0)
			goto memory;
	for (int i = nx; i > 0; --i)
		if (add_point(b, (plume_vec2){hx * i, H}) < 0)
			goto memory;
	for (int j = ny; j > 0; --j)
		if (add_point(b, (plume_vec2){0.0, hy * j}) < 0)
			goto memory;
	for (int j = 0; j < ny; ++j)
		for (int i = 0; i < nx; ++i) {
			double x = hx * (i + 0.5 + plume_rng_range(&rng, -0.3, 0.3));
			double y = hy * (j + 0.5 + plume_rng_range(&rng, -0.3, 0.3));
			if (add_point(b, (plume_vec2){x, y}) < 0)
				goto memory;
		}

	coordT *coords = plume_alloc(sizeof(coordT) * 2 * (size_t)b->point_count);
	if (coords == NULL)
		goto memory;
	for (int i = 0; i < b->point_count; ++i) {
		coords[2 * i] = b->points[i].x;
		coords[2 * i + 1] = b->points[i].y;
	}
	// Qhull's messages go to a memory stream so that the library prints nothing.
	char *messages = NULL;
	size_t message_size = 0;
	FILE *sink = open_memstream(&messages, &message_size);
	if (sink == NULL) {
		plume_free(coords);
		goto memory;
	}
	qhT qh_storage;
	qhT *qh = &qh_storage;
	qh_zero(qh, sink);
	char options[] = "qhull d Qt Qbb Qc Qz";
	int code = qh_new_qhull(qh, 2, b->point_count, coords, False, options, NULL, sink);
	plume_status status = PLUME_OK;
	if (code == 0) {
		facetT *facet;
		vertexT *vertex, **vertexp;
		double min_area = 1e-10 * hx * hy;
		FORALLfacets
		{
			if (facet->upperdelaunay)
				continue;
			int v[3], k = 0;
			FOREACHvertex_(facet->vertices)
			{
				if (k < 3)
					v[k] = qh_pointid(qh, vertex->point);
				++k;
			}
			if (k != 3 || fabs(cross2(b->points[v[0]], b->points[v[1]], b->points[v[2]])) < min_area)
				continue;
			if (add_face(b, v[0], v[1], v[2], -1, 0) != 0) {
				status = PLUME_ERROR_MEMORY;
				break;
			}
		}
	}
	qh_freeqhull(qh, !qh_ALL);
	int curlong, totlong;
	qh_memfreeshort(qh, &curlong, &totlong);
	fclose(sink);
	plume_free(coords);
	if (code != 0)
		status = plume_error_set(err, PLUME_ERROR_NUMERIC, "Qhull could not triangulate the sample (code %d): %.300s",
		                         code, messages != NULL ? messages : "");
	else if (status == PLUME_ERROR_MEMORY)
		plume_error_set(err, status, "out of memory building the unaligned sample mesh");
	free(messages);
	return status;
memory:
	return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory building the unaligned sample mesh");
}

// Faces are sorted so that the mesh does not depend on the order Qhull lists them in.
static int compare_face(const void *a, const void *b)
{
	const int *x = a, *y = b;
	for (int k = 0; k < 3; ++k)
		if (x[k] != y[k])
			return (x[k] > y[k]) - (x[k] < y[k]);
	return 0;
}

double plume_sample_estimate_bytes(double element_count)
{
	return PLUME_LAB_BYTES_FIXED + element_count * PLUME_LAB_BYTES_PER_ELEMENT;
}

plume_status plume_sample_validate(const plume_sample_def *sample, const plume_band_def *bands, plume_error *err)
{
	PLUME_ASSERT_DEF(sample);
	PLUME_ASSERT(bands == NULL || bands->cookie == PLUME_DEF_COOKIE);
	// Sizes with a floor and a ceiling, not just > 0: a 1e-300 m sample's triangle areas
	// underflow to 0 and its energies divide by them.
	if (!(sample->width >= 1e-6 && sample->width <= 10.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "sample.width is %g m, allowed [1e-06, 10]", sample->width);
	if (!(sample->height >= 1e-6 && sample->height <= 10.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "sample.height is %g m, allowed [1e-06, 10]", sample->height);
	if (!(sample->thickness >= 1e-9 && sample->thickness <= 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "sample.thickness is %g m, allowed [1e-09, 1]",
		                       sample->thickness);
	if (!(sample->barb_angle >= 0.0 && sample->barb_angle < PI))
		return plume_error_set(err, PLUME_ERROR_SPEC, "sample.barb_angle_deg is %g, allowed in [0, 180)",
		                       sample->barb_angle * 180.0 / PI);
	if (sample->element_count < 2 || sample->element_count > 4000000)
		return plume_error_set(err, PLUME_ERROR_SPEC, "sample.elements is %d, allowed in [2, 4000000]",
		                       sample->element_count);
	if (sample->mesh != PLUME_SAMPLE_ALIGNED && sample->mesh != PLUME_SAMPLE_UNALIGNED)
		return plume_error_set(err, PLUME_ERROR_SPEC, "sample.mesh is %d, allowed aligned or unaligned",
		                       (int)sample->mesh);
	if (bands == NULL)
		return PLUME_OK;
	if (sample->mesh != PLUME_SAMPLE_ALIGNED)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "sample.mesh is unaligned, but mesoscale bands need an aligned mesh that resolves them");
	if (!(bands->barb_fraction > 0.0 && bands->barb_fraction < 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "material.barb_fraction is %g, allowed in (0, 1)",
		                       bands->barb_fraction);
	if (!(bands->period > 0.0 && isfinite(bands->period)))
		return plume_error_set(err, PLUME_ERROR_SPEC, "material.band_period is %g m, allowed > 0", bands->period);
	if (!(bands->phase >= 0.0 && bands->phase < 1.0))
		return plume_error_set(err, PLUME_ERROR_SPEC, "material.band_phase is %g, allowed in [0, 1)", bands->phase);
	if (bands->barb_divisions < 1 || bands->barb_divisions > 64)
		return plume_error_set(err, PLUME_ERROR_SPEC, "material.barb_divisions is %d, allowed in [1, 64]",
		                       bands->barb_divisions);
	if (bands->barbule_divisions < 1 || bands->barbule_divisions > 64)
		return plume_error_set(err, PLUME_ERROR_SPEC, "material.barbule_divisions is %d, allowed in [1, 64]",
		                       bands->barbule_divisions);
	// More than 100000 bands across the sample would not fit in memory, and a band narrower
	// than a millionth of the sample cannot be meshed sensibly. A period that passes the first
	// is at least 1e-5 of the larger side, so only the barb fraction can fail the second.
	if ((sample->width + sample->height) / bands->period > 1e5)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "material.band_period is %g m, allowed >= %g m: at most 100000 periods across the "
		                       "%g x %g m sample (its width + height)",
		                       bands->period, (sample->width + sample->height) / 1e5, sample->width, sample->height);
	double size = fmax(sample->width, sample->height), least = 1e-6 * size / bands->period;
	bool barbs_narrower = bands->barb_fraction <= 0.5;
	double narrowest = bands->period * (barbs_narrower ? bands->barb_fraction : 1.0 - bands->barb_fraction);
	if (narrowest < 1e-6 * size) {
		char fraction[PLUME_LAB_NUMBER_TEXT]; // all its digits: 0.9999999999 is not 1
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "material.barb_fraction is %s, allowed in [%g, %g] at material.band_period %g m: its %s "
		                       "bands would be %g m wide, narrower than a millionth of the %g x %g m sample",
		                       plume_lab_format_number(fraction, sizeof fraction, bands->barb_fraction), least,
		                       1.0 - least, bands->period, barbs_narrower ? "barb" : "barbule", narrowest,
		                       sample->width, sample->height);
	}
	return PLUME_OK;
}

static plume_status add_clamp_group(plume_mesh *mesh, const char *name, double y, double tolerance, plume_error *err)
{
	int count = 0;
	int *vertices = plume_alloc(sizeof(int) * (size_t)mesh->vertex_count);
	if (vertices == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	for (int i = 0; i < mesh->vertex_count; ++i)
		if (fabs(mesh->reference[i].y - y) <= tolerance)
			vertices[count++] = i;
	plume_status status = plume_mesh_add_group(mesh, name, vertices, count, err);
	plume_free(vertices);
	return status;
}

plume_status plume_sample_mesh(const plume_sample_def *sample, const plume_band_def *bands, plume_mesh **out,
                               plume_error *err)
{
	PLUME_ASSERT(out != NULL);
	*out = NULL;
	plume_status status = plume_sample_validate(sample, bands, err);
	if (status != PLUME_OK)
		return status;
	builder b = {0};
	status =
	    sample->mesh == PLUME_SAMPLE_ALIGNED ? mesh_aligned(sample, bands, &b, err) : mesh_unaligned(sample, &b, err);
	if (status == PLUME_OK && sample->mesh == PLUME_SAMPLE_UNALIGNED) {
		// Sort faces (their barb marks and materials are all equal) for determinism.
		qsort(b.faces, (size_t)b.face_count, 3 * sizeof(int), compare_face);
	}
	if (status != PLUME_OK) {
		builder_free(&b);
		return status;
	}
	plume_mesh *mesh = plume_mesh_create(b.point_count, b.face_count);
	if (mesh == NULL) {
		builder_free(&b);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory creating the sample mesh");
	}
	double phi = fmod(0.5 * PI - sample->barb_angle + 2.0 * PI, PI);
	for (int i = 0; i < b.point_count; ++i) {
		mesh->reference[i] = b.points[i];
		mesh->rest[i] = plume_v3(b.points[i].x, b.points[i].y, 0.0);
		mesh->uv[i] = (plume_vec2){b.points[i].x / sample->width, b.points[i].y / sample->height};
	}
	memcpy(mesh->faces, b.faces, sizeof(int) * 3 * (size_t)b.face_count);
	for (int f = 0; f < b.face_count; ++f) {
		mesh->material[f] = b.material[f];
		mesh->barb_edge[f] = b.barb_edge[f];
		mesh->barb_angle[f] = phi;
	}
	builder_free(&b);
	double tolerance = 1e-9 * fmax(sample->width, sample->height);
	status = add_clamp_group(mesh, "bottom", 0.0, tolerance, err);
	if (status == PLUME_OK)
		status = add_clamp_group(mesh, "top", sample->height, tolerance, err);
	if (status == PLUME_OK && sample->mesh == PLUME_SAMPLE_ALIGNED)
		status = plume_mesh_collect_barb_edges(mesh, err);
	if (status != PLUME_OK) {
		plume_mesh_destroy(mesh);
		return status;
	}
	*out = mesh;
	return PLUME_OK;
}

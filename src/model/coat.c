// Feather coats (Streit & Heidrich 4.4): follicles on a surface, key feathers,
// interpolated feathers placed by normal, direction field and lift, in drawing
// order from the bottom feather to the top one.
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "../core/asserts.h"
#include "../core/alloc.h"
#include "coat_internal.h"
#include "feather_internal.h"

#define PI 3.14159265358979323846

struct plume_coat {
	uint32_t magic; ///< PLUME_HANDLE_MAGIC while alive (core/asserts.h)
	int count;
	plume_feather **feathers; ///< drawing order
	plume_vec3 *roots;
	plume_vec3 *normals;
	plume_mat3 *frames; ///< per feather: its own frame's axes as columns (x, shaft, front)
	bool *is_key;
	plume_mesh *surface;
};

int plume_coat_feather_count(const plume_coat *coat)
{
	PLUME_ASSERT_HANDLE(coat);
	return coat->count;
}

const plume_feather *plume_coat_feather(const plume_coat *coat, int index)
{
	PLUME_ASSERT_HANDLE(coat);
	PLUME_ASSERT_INDEX(index, coat->count);
	return coat->feathers[index];
}

void plume_coat_follicle(const plume_coat *coat, int index, plume_vec3 *position, plume_vec3 *normal)
{
	PLUME_ASSERT_HANDLE(coat);
	PLUME_ASSERT_INDEX(index, coat->count);
	PLUME_ASSERT(position != NULL && normal != NULL);
	*position = coat->roots[index];
	*normal = coat->normals[index];
}

void plume_coat_feather_frame(const plume_coat *coat, int index, plume_mat3 *rotation, plume_vec3 *origin)
{
	PLUME_ASSERT_HANDLE(coat);
	PLUME_ASSERT_INDEX(index, coat->count);
	PLUME_ASSERT(rotation != NULL && origin != NULL);
	*rotation = coat->frames[index];
	*origin = coat->roots[index];
}

bool plume_coat_is_key(const plume_coat *coat, int index)
{
	PLUME_ASSERT_HANDLE(coat);
	PLUME_ASSERT_INDEX(index, coat->count);
	return coat->is_key[index];
}

const plume_mesh *plume_coat_surface(const plume_coat *coat)
{
	PLUME_ASSERT_HANDLE(coat);
	return coat->surface;
}

void plume_coat_destroy(plume_coat *coat)
{
	if (coat == NULL)
		return;
	PLUME_ASSERT_HANDLE(coat);
	coat->magic = 0;
	for (int i = 0; i < coat->count; ++i)
		plume_feather_destroy(coat->feathers[i]);
	plume_free(coat->feathers);
	plume_free(coat->roots);
	plume_free(coat->normals);
	plume_free(coat->frames);
	plume_free(coat->is_key);
	plume_mesh_destroy(coat->surface);
	plume_free(coat);
}

// ---------------------------------------------------------------------------
// Surfaces as meshes

static plume_mesh *plane_mesh(const coat_def *def)
{
	plume_mesh *mesh = plume_mesh_create(4, 2);
	if (mesh == NULL)
		return NULL;
	double w = def->plane_size[0], h = def->plane_size[1];
	const plume_vec3 corners[4] = {{0, 0, 0}, {w, 0, 0}, {w, h, 0}, {0, h, 0}};
	for (int i = 0; i < 4; ++i) {
		mesh->rest[i] = corners[i];
		mesh->reference[i] = (plume_vec2){corners[i].x, corners[i].y};
		mesh->uv[i] = (plume_vec2){w > 0 ? corners[i].x / w : 0, h > 0 ? corners[i].y / h : 0};
	}
	const int faces[6] = {0, 1, 2, 0, 2, 3};
	memcpy(mesh->faces, faces, sizeof faces);
	for (int f = 0; f < 2; ++f)
		mesh->barb_edge[f] = -1;
	return mesh;
}

/// A latitude-longitude sphere: rings x segments quads, the pole rows as triangles.
static plume_mesh *sphere_mesh(const coat_def *def)
{
	enum { RINGS = 24, SEGMENTS = 48 };
	int vertex_count = (RINGS - 1) * SEGMENTS + 2;
	int face_count = 2 * SEGMENTS * (RINGS - 1);
	plume_mesh *mesh = plume_mesh_create(vertex_count, face_count);
	if (mesh == NULL)
		return NULL;
	double r = def->sphere_radius;
	plume_vec3 c = def->sphere_centre;
	int v = 0;
	mesh->rest[v++] = plume_v3(c.x, c.y, c.z + r);
	for (int i = 1; i < RINGS; ++i) {
		double theta = PI * i / RINGS;
		for (int j = 0; j < SEGMENTS; ++j) {
			double phi = 2.0 * PI * j / SEGMENTS;
			mesh->rest[v] =
			    plume_v3(c.x + r * sin(theta) * cos(phi), c.y + r * sin(theta) * sin(phi), c.z + r * cos(theta));
			mesh->uv[v] = (plume_vec2){(double)j / SEGMENTS, 1.0 - (double)i / RINGS};
			++v;
		}
	}
	mesh->rest[v++] = plume_v3(c.x, c.y, c.z - r);
	for (int i = 0; i < vertex_count; ++i)
		mesh->reference[i] = (plume_vec2){mesh->rest[i].x, mesh->rest[i].y};
	int f = 0;
	int south = vertex_count - 1;
	for (int j = 0; j < SEGMENTS; ++j) {
		int a = 1 + j, b = 1 + (j + 1) % SEGMENTS;
		int *t = mesh->faces + 3 * f++;
		t[0] = 0, t[1] = a, t[2] = b; // outward winding
		int last = 1 + (RINGS - 2) * SEGMENTS;
		t = mesh->faces + 3 * f++;
		t[0] = south, t[1] = last + (j + 1) % SEGMENTS, t[2] = last + j;
	}
	for (int i = 0; i + 1 < RINGS - 1; ++i)
		for (int j = 0; j < SEGMENTS; ++j) {
			int a = 1 + i * SEGMENTS + j, b = 1 + i * SEGMENTS + (j + 1) % SEGMENTS;
			int d = a + SEGMENTS, e = b + SEGMENTS;
			int *t = mesh->faces + 3 * f++;
			t[0] = a, t[1] = d, t[2] = e;
			t = mesh->faces + 3 * f++;
			t[0] = a, t[1] = e, t[2] = b;
		}
	for (int k = 0; k < face_count; ++k)
		mesh->barb_edge[k] = -1;
	return mesh;
}

// ---------------------------------------------------------------------------
// Follicle layouts

typedef struct follicles {
	plume_vec3 *positions;
	plume_vec3 *normals;
	int count, capacity;
	double most; ///< more follicles than this would not fit in the memory limit: the layout stops
} follicles;

/// FOLLICLES_PAST_LIMIT: the layout passed f->most and stops; -1: out of memory.
enum { FOLLICLES_PAST_LIMIT = -3 };

static int add_follicle(follicles *f, plume_vec3 position, plume_vec3 normal)
{
	if (f->count + 1 > f->most)
		return FOLLICLES_PAST_LIMIT;
	int capacity = f->capacity;
	if (PLUME_GROW(f->positions, capacity, f->count + 1) != 0)
		return -1;
	capacity = f->capacity;
	if (PLUME_GROW(f->normals, capacity, f->count + 1) != 0)
		return -1;
	f->capacity = capacity;
	f->positions[f->count] = position;
	f->normals[f->count] = normal;
	f->count++;
	return 0;
}

// Resource bounds (docs/cli.md, Limits). Before the layout, its own arrays (the follicle count
// estimated from the surface's area: an upper bound for hexagonal layouts, the densest packing for
// Poisson ones); after it, the coat, from the follicles laid out and a bound on any one feather
// (coat_feather_bound), before any feather is built.
#define COAT_MAX_FOLLICLES 1e8 // also keeps every count far inside an int
/// Bytes a follicle takes besides its feather: the coat's arrays (feather pointer, root, normal, frame, key
/// flag: 129 B) and, while it is built, the layout's (positions and normals grown by doubling: 96 B, the
/// Poisson grid's cells and links) and the build's (key index, drawing order, status).
#define COAT_FOLLICLE_BYTES 512.0
/// Scratch of one thread while it builds a feather: the blended definition (60 KiB), the blend's key lists
/// (27 KiB for each key feather, 16 at most), the builder's tables, and the barbs' roots (at most 4000).
#define COAT_THREAD_BYTES (2.0 * 1024 * 1024)

/// The Poisson layout's hash grid indexes a point's cell by its coordinates over the smallest spacing, as
/// longs: at most 1e15 cells from the origin keeps the index far inside a long (9.2e18; a cast past it is
/// undefined) and a coordinate's rounding under a quarter of a cell, so that neighbouring cells stay apart.
#define COAT_MAX_CELL_INDEX 1e15

/// The largest coordinate magnitude of a point of the surface, m.
static double surface_reach(const coat_def *def, const plume_mesh *surface)
{
	if (def->surface == COAT_SURFACE_PLANE)
		return fmax(def->plane_size[0], def->plane_size[1]);
	if (def->surface == COAT_SURFACE_SPHERE) {
		plume_vec3 c = def->sphere_centre;
		return fmax(fabs(c.x), fmax(fabs(c.y), fabs(c.z))) + def->sphere_radius;
	}
	double reach = 0.0; // a mesh's points are blends of its vertices
	for (int i = 0; i < surface->vertex_count; ++i) {
		plume_vec3 p = surface->rest[i];
		reach = fmax(reach, fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))));
	}
	return reach;
}

/// Upper estimate of the follicle count, from the layout's own geometry.
static double estimated_follicles(const coat_def *def, double area)
{
	double s = def->spacing;
	if (def->layout == COAT_LAYOUT_POISSON) {
		// Disks of diameter s packed no denser than the hexagonal lattice: area / (sqrt(3)/2 s^2).
		double smallest = s * fmin(1.0, def->spacing_factor);
		return area / (0.8660254037844386 * smallest * smallest) + 16.0;
	}
	if (def->surface == COAT_SURFACE_PLANE)
		return (def->plane_size[0] / s + 2.0) * (def->plane_size[1] / (0.8660254037844386 * s) + 2.0);
	double n = fmax(1.0, floor(1.1071487177940904 * def->sphere_radius / s + 0.5));
	return 10.0 * n * n + 2.0;
}

/// Regular hexagonal lattice on the plane: rows spacing sqrt(3)/2 apart, every other row shifted by half.
static int hexagonal_plane(const coat_def *def, follicles *f)
{
	double s = def->spacing, row_step = s * sqrt(3.0) / 2.0;
	int rows = (int)floor(def->plane_size[1] / row_step + 1e-9) + 1, status = 0;
	for (int r = 0; r < rows; ++r) {
		double y = r * row_step;
		for (double x = (r % 2) * 0.5 * s; x <= def->plane_size[0] + 1e-9 * s; x += s)
			if ((status = add_follicle(f, plume_v3(x, y, 0.0), plume_v3(0.0, 0.0, 1.0))) != 0)
				return status;
	}
	return 0;
}

/// Hexagonal on a sphere: the vertices of a geodesic icosphere of frequency n (10 n^2 + 2 follicles, all
/// with six neighbours but the twelve of the icosahedron), n chosen so that edges are near the spacing.
static int hexagonal_sphere(const coat_def *def, follicles *f)
{
	static const double g = 1.6180339887498949;
	static const double ico[12][3] = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
	                                  {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
	static const int faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
	                                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
	                                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
	                                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
	double edge_angle = 1.1071487177940904; // between neighbouring icosahedron vertices
	int n = (int)floor(edge_angle * def->sphere_radius / def->spacing + 0.5);
	if (n < 1)
		n = 1;
	plume_vec3 corner[12];
	for (int i = 0; i < 12; ++i)
		corner[i] = plume_v3_normalize(plume_v3(ico[i][0], ico[i][1], ico[i][2]));
#define PUT(p)                                                                                                         \
	do {                                                                                                               \
		plume_vec3 u = plume_v3_normalize(p);                                                                          \
		int added = add_follicle(f, plume_v3_mad(def->sphere_centre, def->sphere_radius, u), u);                       \
		if (added != 0)                                                                                                \
			return added;                                                                                              \
	} while (0)
	for (int i = 0; i < 12; ++i)
		PUT(corner[i]);
	// Each edge once (from the face where it runs from the smaller to the larger vertex index).
	for (int t = 0; t < 20; ++t)
		for (int e = 0; e < 3; ++e) {
			int a = faces[t][e], b = faces[t][(e + 1) % 3];
			if (a > b)
				continue;
			for (int k = 1; k < n; ++k)
				PUT(plume_v3_lerp(corner[a], corner[b], (double)k / n));
		}
	for (int t = 0; t < 20; ++t) {
		plume_vec3 a = corner[faces[t][0]], b = corner[faces[t][1]], c = corner[faces[t][2]];
		for (int i = 1; i < n; ++i)
			for (int j = 1; i + j < n; ++j)
				PUT(plume_v3_add(a, plume_v3_add(plume_v3_scale(plume_v3_sub(b, a), (double)i / n),
				                                 plume_v3_scale(plume_v3_sub(c, a), (double)j / n))));
	}
#undef PUT
	return 0;
}

/// Area-weighted vertex normals of a mesh (outward for counter-clockwise faces seen from outside).
static plume_vec3 *vertex_normals(const plume_mesh *mesh)
{
	plume_vec3 *normals = plume_calloc((size_t)mesh->vertex_count, sizeof *normals);
	if (normals == NULL)
		return NULL;
	for (int t = 0; t < mesh->face_count; ++t) {
		const int *v = mesh->faces + 3 * t;
		plume_vec3 n = plume_v3_cross(plume_v3_sub(mesh->rest[v[1]], mesh->rest[v[0]]),
		                              plume_v3_sub(mesh->rest[v[2]], mesh->rest[v[0]]));
		for (int k = 0; k < 3; ++k)
			normals[v[k]] = plume_v3_add(normals[v[k]], n);
	}
	for (int i = 0; i < mesh->vertex_count; ++i)
		normals[i] = plume_v3_normalize(normals[i]);
	return normals;
}

/// Spacing at p (Poisson layouts): linear in the projection of p on the gradient segment.
static double spacing_at(const coat_def *def, plume_vec3 p)
{
	if (def->spacing_factor == 1.0)
		return def->spacing;
	plume_vec3 axis = plume_v3_sub(def->spacing_to, def->spacing_from);
	double length2 = plume_v3_dot(axis, axis);
	double f = length2 > 0.0 ? plume_v3_dot(plume_v3_sub(p, def->spacing_from), axis) / length2 : 0.0;
	f = f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
	return def->spacing * (1.0 + f * (def->spacing_factor - 1.0));
}

/// A uniformly distributed surface point and its normal.
typedef struct surface_sampler {
	const coat_def *def;
	const plume_mesh *mesh;
	const plume_vec3 *vertex_normals;
	double *cumulative_area; ///< meshes: running sum of face areas
	double area;
} surface_sampler;

static void sample_surface(const surface_sampler *s, plume_rng *rng, plume_vec3 *p, plume_vec3 *n)
{
	const coat_def *def = s->def;
	switch (def->surface) {
	case COAT_SURFACE_PLANE:
		*p = plume_v3(plume_rng_uniform(rng) * def->plane_size[0], plume_rng_uniform(rng) * def->plane_size[1], 0.0);
		*n = plume_v3(0.0, 0.0, 1.0);
		return;
	case COAT_SURFACE_SPHERE: {
		double z = 2.0 * plume_rng_uniform(rng) - 1.0, phi = 2.0 * PI * plume_rng_uniform(rng);
		double r = sqrt(fmax(0.0, 1.0 - z * z));
		*n = plume_v3(r * cos(phi), r * sin(phi), z);
		*p = plume_v3_mad(def->sphere_centre, def->sphere_radius, *n);
		return;
	}
	case COAT_SURFACE_MESH: {
		double target = plume_rng_uniform(rng) * s->area;
		int lo = 0, hi = s->mesh->face_count - 1;
		while (lo < hi) {
			int mid = (lo + hi) / 2;
			if (s->cumulative_area[mid] < target)
				lo = mid + 1;
			else
				hi = mid;
		}
		const int *v = s->mesh->faces + 3 * lo;
		double a = plume_rng_uniform(rng), b = plume_rng_uniform(rng);
		if (a + b > 1.0) {
			a = 1.0 - a;
			b = 1.0 - b;
		}
		double c = 1.0 - a - b;
		*p = plume_v3_add(plume_v3_add(plume_v3_scale(s->mesh->rest[v[0]], c), plume_v3_scale(s->mesh->rest[v[1]], a)),
		                  plume_v3_scale(s->mesh->rest[v[2]], b));
		*n = plume_v3_normalize(plume_v3_add(
		    plume_v3_add(plume_v3_scale(s->vertex_normals[v[0]], c), plume_v3_scale(s->vertex_normals[v[1]], a)),
		    plume_v3_scale(s->vertex_normals[v[2]], b)));
		return;
	}
	}
}

/// Hash grid of accepted follicles, cell = the smallest spacing.
typedef struct grid {
	int *head;
	int *next;
	unsigned mask;
	double cell;
} grid;

static unsigned cell_hash(long x, long y, long z, unsigned mask)
{
	uint64_t h = (uint64_t)x * 73856093u ^ (uint64_t)y * 19349663u ^ (uint64_t)z * 83492791u;
	return (unsigned)(h ^ (h >> 29)) & mask;
}

/// Seeded dart throwing (Poisson-disk): candidates uniform over the surface, each kept when no kept follicle
/// is closer than the larger of the two spacings. Stops after many rejections in a row.
static int poisson(const coat_def *def, const surface_sampler *sampler, follicles *f)
{
	double smallest = def->spacing * fmin(1.0, def->spacing_factor),
	       largest = def->spacing * fmax(1.0, def->spacing_factor);
	double expected = sampler->area / (0.5 * smallest * smallest) + 16.0;
	if (expected > 4e7)
		return -2;
	unsigned size = 1024;
	while (size < 2.0 * expected)
		size *= 2;
	grid g = {.head = plume_alloc(size * sizeof(int)), .next = NULL, .mask = size - 1, .cell = smallest};
	int next_capacity = 0;
	if (g.head == NULL)
		return -1;
	for (unsigned i = 0; i < size; ++i)
		g.head[i] = -1;
	plume_rng rng = plume_rng_seed(def->seed ^ 0x9e3779b97f4a7c15ULL);
	int reach = (int)ceil(largest / smallest);
	int failures = 0, limit = 3000;
	int status = 0;
	while (failures < limit) {
		plume_vec3 p, n;
		sample_surface(sampler, &rng, &p, &n);
		double rp = spacing_at(def, p);
		long cx = (long)floor(p.x / g.cell), cy = (long)floor(p.y / g.cell), cz = (long)floor(p.z / g.cell);
		bool free = true;
		for (long dx = -reach; dx <= reach && free; ++dx)
			for (long dy = -reach; dy <= reach && free; ++dy)
				for (long dz = -reach; dz <= reach && free; ++dz)
					for (int q = g.head[cell_hash(cx + dx, cy + dy, cz + dz, g.mask)]; q >= 0 && free; q = g.next[q]) {
						double d = plume_v3_distance(p, f->positions[q]);
						if (d < fmax(rp, spacing_at(def, f->positions[q])))
							free = false;
					}
		if (!free) {
			++failures;
			continue;
		}
		failures = 0;
		if ((status = add_follicle(f, p, n)) != 0 || (status = PLUME_GROW(g.next, next_capacity, f->count)) != 0)
			break;
		unsigned h = cell_hash(cx, cy, cz, g.mask);
		g.next[f->count - 1] = g.head[h];
		g.head[h] = f->count - 1;
	}
	plume_free(g.head);
	plume_free(g.next);
	return status;
}

// ---------------------------------------------------------------------------
// The coat's bytes

/// Widens bound so that plume_sh_estimate_bytes of it is at least that of p: the longer rachis, the
/// larger curvatures (their sizes: a bend either way lengthens the rachis's control polygon), both
/// spacings the smallest of the four, and one key barb of the most control vertices.
static void widen_params(plume_sh_params *bound, const plume_sh_params *p)
{
	bound->rachis_length = fmax(bound->rachis_length, p->rachis_length);
	bound->rachis_side_curvature = fmax(fabs(bound->rachis_side_curvature), fabs(p->rachis_side_curvature));
	bound->rachis_front_curvature = fmax(fabs(bound->rachis_front_curvature), fabs(p->rachis_front_curvature));
	double spacing = fmin(fmin(bound->spacing_base, bound->spacing_tip), fmin(p->spacing_base, p->spacing_tip));
	bound->spacing_base = bound->spacing_tip = spacing;
	int cvs = bound->key_barb_count > 0 ? bound->key_barbs[0].cv_count : 0;
	for (int j = 0; j < p->key_barb_count && j < PLUME_SH_MAX_KEY_BARBS; ++j)
		cvs = p->key_barbs[j].cv_count > cvs ? p->key_barbs[j].cv_count : cvs;
	bound->key_barb_count = cvs > 0 ? 1 : 0;
	if (cvs > 0)
		bound->key_barbs[0].cv_count = cvs;
}

double coat_feather_bound(const coat_def *def)
{
	// Every feather is plume_sh_def_blend of the key feathers (a key feather: its own weight 1), and
	// a blend's parameters are weighted means: its rachis length, the sizes of its curvatures and its
	// smaller spacing lie within the key feathers' (afterfeathers: those of the key feathers that have
	// one), and its key barbs have no more control vertices than the key feathers' (Bdf1 and Bdf2
	// included, the 4 plume_sh_estimate_bytes counts at least). So the estimate of the widest
	// definition bounds every feather's, which bounds the feather built (streit_heidrich.h).
	plume_sh_def *bound = plume_alloc(sizeof *bound);
	if (bound == NULL)
		return INFINITY;
	*bound = def->key_defs[0];
	bound->has_afterfeather = false;
	bound->main.key_barb_count = 0;
	for (int k = 0; k < def->key_count; ++k) {
		const plume_sh_def *key = &def->key_defs[k];
		widen_params(&bound->main, &key->main);
		if (key->has_afterfeather) {
			if (!bound->has_afterfeather) {
				bound->afterfeather = key->afterfeather;
				bound->afterfeather.key_barb_count = 0;
			}
			bound->has_afterfeather = true;
			widen_params(&bound->afterfeather, &key->afterfeather);
		}
	}
	double estimate = plume_sh_estimate_bytes(bound, &def->lod);
	plume_free(bound);
	// What the estimate leaves out, per feather object (main, afterfeather): barb and shaft records
	// grow by doubling from 16 (a barb record, 40 B, is at most 1/9 of its barb's share of the
	// estimate: at least 4 points of 80 B), the shaft's samples are 112 B, and the feather's own
	// struct and its arrays' allocation headers take under 1 KiB.
	double shaft = def->lod.calamus_samples + 4.0 + def->lod.rachis_elevations;
	double objects = 1.0;
	for (int k = 0; k < def->key_count; ++k)
		if (def->key_defs[k].has_afterfeather)
			objects = 2.0;
	return estimate * 10.0 / 9.0 +
	       objects * (sizeof(plume_shaft_sample) * (shaft + 16.0) + sizeof(plume_barb_record) * 16.0 + 1024.0);
}

/// Threads that build feathers at once.
static int coat_threads(void)
{
#ifdef _OPENMP
	return omp_get_max_threads();
#else
	return 1;
#endif
}

/// The bytes of a coat besides its follicles: the threads' scratch, the surface (rest, reference, uv,
/// faces and per-face data) and the layout's vertex normals and areas.
static double coat_fixed_bytes(const plume_mesh *surface)
{
	double surface_bytes = surface != NULL ? 96.0 * surface->vertex_count + 48.0 * surface->face_count : 0.0;
	return coat_threads() * COAT_THREAD_BYTES + surface_bytes;
}

double coat_estimate_bytes(const coat_def *def, int follicle_count, const plume_mesh *surface)
{
	return follicle_count * (coat_feather_bound(def) + COAT_FOLLICLE_BYTES) + coat_fixed_bytes(surface);
}

/// PLUME_ERROR_LIMIT for a coat of follicle_count follicles past the limit, or (stopped) for a layout that
/// stopped at follicle_count, the most that fit.
static plume_status coat_limit_error(const coat_def *def, double follicle_count, bool stopped, double feather,
                                     double fixed, plume_error *err)
{
	double limit = (double)def->max_memory;
	if (stopped && follicle_count < 1.0)
		return plume_error_set(err, PLUME_ERROR_LIMIT,
		                       "$.follicles.spacing: the coat's scratch (%.3g GB for its threads and surface) leaves "
		                       "no room for a feather of up to %.3g KB (the key feathers' bound, at $.lod) in the "
		                       "limit of %.3g GB (raise it with --max-memory)",
		                       fixed / 1e9, feather / 1e3, limit / 1e9);
	if (stopped)
		return plume_error_set(err, PLUME_ERROR_LIMIT,
		                       "$.follicles.spacing: %g m on this surface makes more than %.0f follicles (the layout "
		                       "stopped there), and with feathers of at most %.3g KB each (the key feathers' longest "
		                       "rachis, largest curvatures, smallest barb spacing and most control vertices, at $.lod) "
		                       "no more fit in the limit of %.3g GB (raise it with --max-memory, or widen the spacing)",
		                       def->spacing, follicle_count, feather / 1e3, limit / 1e9);
	return plume_error_set(err, PLUME_ERROR_LIMIT,
	                       "$.follicles.spacing: %g m on this surface makes %.0f follicles; with feathers of at most "
	                       "%.3g KB each (the key feathers' longest rachis, largest curvatures, smallest barb spacing "
	                       "and most control vertices, at $.lod) the coat takes up to %.3g GB; the limit is %.3g GB "
	                       "(raise it with --max-memory, or widen the spacing)",
	                       def->spacing, follicle_count, feather / 1e3,
	                       (follicle_count * (feather + COAT_FOLLICLE_BYTES) + fixed) / 1e9, limit / 1e9);
}

plume_status coat_follicles(const coat_def *def, const plume_mesh *surface, plume_vec3 **positions,
                            plume_vec3 **normals, int *count, plume_error *err)
{
	follicles f = {0};
	surface_sampler sampler = {.def = def, .mesh = surface};
	int status = 0;
	if (def->surface == COAT_SURFACE_MESH) {
		sampler.vertex_normals = vertex_normals(surface);
		sampler.cumulative_area = plume_alloc((size_t)surface->face_count * sizeof(double));
		if (sampler.vertex_normals == NULL || sampler.cumulative_area == NULL)
			status = -1;
		for (int t = 0; t < surface->face_count && status == 0; ++t) {
			const int *v = surface->faces + 3 * t;
			sampler.area +=
			    0.5 * plume_v3_length(plume_v3_cross(plume_v3_sub(surface->rest[v[1]], surface->rest[v[0]]),
			                                         plume_v3_sub(surface->rest[v[2]], surface->rest[v[0]])));
			sampler.cumulative_area[t] = sampler.area;
		}
	} else if (def->surface == COAT_SURFACE_PLANE) {
		sampler.area = def->plane_size[0] * def->plane_size[1];
	} else {
		sampler.area = 4.0 * PI * def->sphere_radius * def->sphere_radius;
	}
	if (status == 0 && !(isfinite(sampler.area) && sampler.area > 0.0)) {
		plume_free((void *)sampler.vertex_normals);
		plume_free(sampler.cumulative_area);
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "$.surface: the surface's area is %g m^2; it needs a finite, "
		                       "positive area to hold follicles",
		                       sampler.area);
	}
	if (status == 0) {
		// Refuse before the layout grows: its arrays take COAT_FOLLICLE_BYTES a follicle (the feathers
		// are counted once the follicles are known, coat_build).
		double estimate = estimated_follicles(def, sampler.area);
		double bytes = estimate * COAT_FOLLICLE_BYTES;
		if (!(estimate <= COAT_MAX_FOLLICLES && bytes <= (double)def->max_memory)) {
			plume_free((void *)sampler.vertex_normals);
			plume_free(sampler.cumulative_area);
			return plume_error_set(err, PLUME_ERROR_LIMIT,
			                       "$.follicles.spacing: %g m on %.3g m^2 of surface makes about %.3g follicles (at "
			                       "most %.0e), whose layout alone takes %.3g GB; the limit is %.3g GB (raise it with "
			                       "--max-memory, or widen the spacing)",
			                       def->spacing, sampler.area, estimate, COAT_MAX_FOLLICLES, bytes / 1e9,
			                       (double)def->max_memory / 1e9);
		}
	}
	if (status == 0 && def->layout == COAT_LAYOUT_POISSON) {
		double cell = def->spacing * fmin(1.0, def->spacing_factor), reach = surface_reach(def, surface);
		if (!(reach / cell <= COAT_MAX_CELL_INDEX)) {
			plume_free((void *)sampler.vertex_normals);
			plume_free(sampler.cumulative_area);
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "$.follicles.spacing: %g m (%g m the smallest, with the gradient) is too fine for a "
			                       "Poisson layout on a surface reaching %g m from the origin; allowed a smallest "
			                       "spacing >= %g m (1e-15 of that reach)",
			                       def->spacing, cell, reach, reach / COAT_MAX_CELL_INDEX);
		}
	}
	// The coat is checked once its follicles are known, before any feather is built: every feather is
	// bounded (coat_feather_bound). A Poisson layout, the slow one, stops as soon as it has more
	// follicles than would fit; the others are counted whole (their arrays are bounded above).
	double feather = def->key_count > 0 ? coat_feather_bound(def) : 0.0;
	double fixed = coat_fixed_bytes(surface), most = INFINITY;
	if (def->key_count > 0)
		most = fmax(0.0, floor(((double)def->max_memory - fixed) / (feather + COAT_FOLLICLE_BYTES)));
	f.most = def->layout == COAT_LAYOUT_POISSON ? most : INFINITY;
	if (status == 0) {
		if (def->layout == COAT_LAYOUT_POISSON)
			status = poisson(def, &sampler, &f);
		else if (def->surface == COAT_SURFACE_PLANE)
			status = hexagonal_plane(def, &f);
		else
			status = hexagonal_sphere(def, &f);
	}
	plume_free((void *)sampler.vertex_normals);
	plume_free(sampler.cumulative_area);
	bool stopped = status == FOLLICLES_PAST_LIMIT; // more than f.most follicles, the rest not laid out
	if (status == 0 && f.count > most)
		status = FOLLICLES_PAST_LIMIT;
	if (status != 0) {
		plume_free(f.positions);
		plume_free(f.normals);
		if (status == FOLLICLES_PAST_LIMIT) {
			return coat_limit_error(def, stopped ? f.most : f.count, stopped, feather, fixed, err);
		}
		if (status == -2)
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "the follicle spacing %g m puts tens of millions of follicles on this surface; "
			                       "widen it",
			                       def->spacing);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory while laying out follicles");
	}
	*positions = f.positions;
	*normals = f.normals;
	*count = f.count;
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// Interpolation weights

/// The key feathers' plane: origin, two in-plane axes.
typedef struct key_plane {
	plume_vec3 origin, e1, e2;
} key_plane;

static key_plane make_key_plane(const plume_vec3 *keys, int count)
{
	key_plane plane = {.origin = keys[0]};
	plume_vec3 normal = count >= 4 ? plume_v3_cross(plume_v3_sub(keys[2], keys[0]), plume_v3_sub(keys[3], keys[1]))
	                               : plume_v3_cross(plume_v3_sub(keys[1], keys[0]), plume_v3_sub(keys[2], keys[0]));
	normal = plume_v3_normalize(normal);
	plane.e1 = plume_v3_sub(keys[1], keys[0]);
	plane.e1 = plume_v3_normalize(plume_v3_mad(plane.e1, -plume_v3_dot(plane.e1, normal), normal));
	plane.e2 = plume_v3_cross(normal, plane.e1);
	return plane;
}

static void to_plane(const key_plane *plane, plume_vec3 p, double out[2])
{
	plume_vec3 d = plume_v3_sub(p, plane->origin);
	out[0] = plume_v3_dot(d, plane->e1);
	out[1] = plume_v3_dot(d, plane->e2);
}

/// Bilinear weights in the quadrilateral k0 k1 k2 k3 (4.4): (u, v) from inverting
/// P(u, v) = (1-u)(1-v) k0 + u(1-v) k1 + u v k2 + (1-u) v k3 by Newton's method, clamped to the quad.
static void bilinear_weights(const double k[4][2], const double p[2], double w[4])
{
	double u = 0.5, v = 0.5;
	for (int iteration = 0; iteration < 30; ++iteration) {
		double x[2], du[2], dv[2];
		for (int c = 0; c < 2; ++c) {
			x[c] = (1 - u) * (1 - v) * k[0][c] + u * (1 - v) * k[1][c] + u * v * k[2][c] + (1 - u) * v * k[3][c] - p[c];
			du[c] = (1 - v) * (k[1][c] - k[0][c]) + v * (k[2][c] - k[3][c]);
			dv[c] = (1 - u) * (k[3][c] - k[0][c]) + u * (k[2][c] - k[1][c]);
		}
		double det = du[0] * dv[1] - du[1] * dv[0];
		if (fabs(det) < 1e-300)
			break;
		double step_u = (x[0] * dv[1] - x[1] * dv[0]) / det, step_v = (du[0] * x[1] - du[1] * x[0]) / det;
		u -= step_u;
		v -= step_v;
		if (fabs(step_u) + fabs(step_v) < 1e-14)
			break;
	}
	u = u < 0 ? 0 : (u > 1 ? 1 : u);
	v = v < 0 ? 0 : (v > 1 ? 1 : v);
	w[0] = (1 - u) * (1 - v);
	w[1] = u * (1 - v);
	w[2] = u * v;
	w[3] = (1 - u) * v;
}

static void barycentric_weights(const double k[3][2], const double p[2], double w[3])
{
	double d = (k[1][1] - k[2][1]) * (k[0][0] - k[2][0]) + (k[2][0] - k[1][0]) * (k[0][1] - k[2][1]);
	w[0] = ((k[1][1] - k[2][1]) * (p[0] - k[2][0]) + (k[2][0] - k[1][0]) * (p[1] - k[2][1])) / d;
	w[1] = ((k[2][1] - k[0][1]) * (p[0] - k[2][0]) + (k[0][0] - k[2][0]) * (p[1] - k[2][1])) / d;
	w[2] = 1.0 - w[0] - w[1];
	// Outside the triangle: the negative weights go, the rest renormalized.
	double total = 0.0;
	for (int i = 0; i < 3; ++i) {
		w[i] = fmax(w[i], 0.0);
		total += w[i];
	}
	for (int i = 0; i < 3; ++i)
		w[i] /= total;
}

static void inverse_distance_weights(const plume_vec3 *keys, int count, plume_vec3 p, double power, double *w)
{
	for (int i = 0; i < count; ++i) {
		double d = plume_v3_distance(keys[i], p);
		if (d == 0.0) {
			for (int j = 0; j < count; ++j)
				w[j] = i == j ? 1.0 : 0.0;
			return;
		}
		w[i] = 1.0 / pow(d, power);
	}
}

// ---------------------------------------------------------------------------
// Placement

/// The world frame of a feather at a follicle: x, y (the shaft) and z (the front).
static void feather_frame(const coat_def *def, plume_vec3 p, plume_vec3 n, plume_vec3 axes[3])
{
	plume_vec3 d = def->direction_towards ? plume_v3_sub(def->direction_point, p) : def->direction_vector;
	d = plume_v3_mad(d, -plume_v3_dot(d, n), n);
	if (plume_v3_length(d) < 1e-12) {
		// The direction is along the normal here (a pole): any tangent will do, chosen the same way every time.
		plume_vec3 helper = fabs(n.x) < 0.9 ? plume_v3(1, 0, 0) : plume_v3(0, 1, 0);
		d = plume_v3_cross(n, helper);
	}
	d = plume_v3_normalize(d);
	plume_vec3 shaft = plume_v3_add(plume_v3_scale(d, cos(def->lift)), plume_v3_scale(n, sin(def->lift)));
	plume_vec3 front = plume_v3_add(plume_v3_scale(d, -sin(def->lift)), plume_v3_scale(n, cos(def->lift)));
	axes[0] = plume_v3_cross(shaft, front);
	axes[1] = shaft;
	axes[2] = front;
}

static plume_vec3 rotate(const plume_vec3 axes[3], plume_vec3 v)
{
	return plume_v3_add(plume_v3_add(plume_v3_scale(axes[0], v.x), plume_v3_scale(axes[1], v.y)),
	                    plume_v3_scale(axes[2], v.z));
}

/// Moves a feather (and its afterfeather) from its own frame to the world.
static void place(plume_feather *feather, const plume_vec3 axes[3], plume_vec3 origin)
{
	for (int i = 0; i < feather->shaft_count; ++i) {
		plume_shaft_sample *s = feather->shaft + i;
		s->position = plume_v3_add(origin, rotate(axes, s->position));
		s->tangent = rotate(axes, s->tangent);
		s->normal = rotate(axes, s->normal);
		s->binormal = rotate(axes, s->binormal);
	}
	for (int i = 0; i < feather->point_count; ++i) {
		feather->points[i] = plume_v3_add(origin, rotate(axes, feather->points[i]));
		feather->normals[i] = rotate(axes, feather->normals[i]);
	}
	if (feather->afterfeather != NULL)
		place(feather->afterfeather, axes, origin);
}

typedef struct order_entry {
	double key;
	int index;
} order_entry;

static int compare_order(const void *a, const void *b)
{
	const order_entry *x = a, *y = b;
	if (x->key != y->key)
		return x->key < y->key ? -1 : 1;
	return (x->index > y->index) - (x->index < y->index);
}

/// Weights of every key feather at follicle p.
static void follicle_weights(const coat_def *def, coat_weighting weighting, const key_plane *plane,
                             const double planar_keys[][2], plume_vec3 p, double *w)
{
	double q[2];
	switch (weighting) {
	case COAT_WEIGHTS_BILINEAR:
		to_plane(plane, p, q);
		bilinear_weights(planar_keys, q, w);
		return;
	case COAT_WEIGHTS_BARYCENTRIC:
		to_plane(plane, p, q);
		barycentric_weights(planar_keys, q, w);
		return;
	default: inverse_distance_weights(def->key_at, def->key_count, p, def->power, w); return;
	}
}

plume_status coat_build(coat_def *def, plume_coat **out, plume_error *err)
{
	*out = NULL;
	plume_coat *coat = plume_calloc(1, sizeof *coat);
	if (coat == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
	coat->magic = PLUME_HANDLE_MAGIC;
	plume_status status = PLUME_OK;
	if (def->surface == COAT_SURFACE_MESH) {
		coat->surface = def->mesh;
		def->mesh = NULL;
	} else {
		coat->surface = def->surface == COAT_SURFACE_PLANE ? plane_mesh(def) : sphere_mesh(def);
	}
	plume_vec3 *positions = NULL, *normals = NULL;
	int count = 0;
	int *key_of = NULL;
	order_entry *order = NULL;
	if (coat->surface == NULL) {
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
		goto fail;
	}
	if ((status = coat_follicles(def, coat->surface, &positions, &normals, &count, err)) != PLUME_OK)
		goto fail;
	if (count == 0) {
		status = plume_error_set(err, PLUME_ERROR_SPEC, "$.follicles: the layout leaves no follicle on the surface");
		goto fail;
	}
	// Key feathers take the follicles nearest to where they are asked to be.
	key_of = plume_alloc((size_t)count * sizeof *key_of);
	order = plume_alloc((size_t)count * sizeof *order);
	coat->feathers = plume_calloc((size_t)count, sizeof *coat->feathers);
	coat->roots = plume_alloc((size_t)count * sizeof *coat->roots);
	coat->normals = plume_alloc((size_t)count * sizeof *coat->normals);
	coat->frames = plume_alloc((size_t)count * sizeof *coat->frames);
	coat->is_key = plume_calloc((size_t)count, sizeof *coat->is_key);
	if (key_of == NULL || order == NULL || coat->feathers == NULL || coat->roots == NULL || coat->normals == NULL ||
	    coat->frames == NULL || coat->is_key == NULL) {
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
		goto fail;
	}
	for (int i = 0; i < count; ++i)
		key_of[i] = -1;
	for (int k = 0; k < def->key_count; ++k) {
		int nearest = 0;
		for (int i = 1; i < count; ++i)
			if (plume_v3_distance(positions[i], def->key_at[k]) < plume_v3_distance(positions[nearest], def->key_at[k]))
				nearest = i;
		if (key_of[nearest] >= 0) {
			status = plume_error_set(err, PLUME_ERROR_SPEC,
			                         "$.key_feathers[%d].at: the nearest follicle already holds key feather %d; key "
			                         "feathers need follicles of their own",
			                         k, key_of[nearest]);
			goto fail;
		}
		key_of[nearest] = k;
		def->key_at[k] = positions[nearest];
	}
	coat->count = count;

	coat_weighting weighting = def->weighting;
	if (weighting == COAT_WEIGHTS_AUTO)
		weighting = def->key_count == 4   ? COAT_WEIGHTS_BILINEAR
		            : def->key_count == 3 ? COAT_WEIGHTS_BARYCENTRIC
		                                  : COAT_WEIGHTS_INVERSE_DISTANCE;
	key_plane plane = make_key_plane(def->key_at, def->key_count >= 3 ? def->key_count : 3);
	double planar_keys[COAT_MAX_KEYS][2];
	for (int k = 0; k < def->key_count; ++k)
		to_plane(&plane, def->key_at[k], planar_keys[k]);

	// Drawing order (4.4: "drawn from the bottom feather to the top"): feathers overlap like roof tiles
	// along the direction field, so the ones furthest downstream are the bottom ones.
	for (int i = 0; i < count; ++i) {
		double downstream = def->direction_towards ? plume_v3_distance(positions[i], def->direction_point)
		                                           : -plume_v3_dot(positions[i], def->direction_vector);
		order[i] = (order_entry){downstream, i};
	}
	qsort(order, (size_t)count, sizeof *order, compare_order);

	plume_status *statuses = plume_alloc((size_t)count * sizeof *statuses);
	plume_error *errors = plume_calloc(1, sizeof *errors);
	if (statuses == NULL || errors == NULL) {
		plume_free(statuses);
		plume_free(errors);
		status = plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory");
		goto fail;
	}
	const plume_sh_def *key_pointers[COAT_MAX_KEYS];
	for (int k = 0; k < def->key_count; ++k)
		key_pointers[k] = &def->key_defs[k];
	int failed = count; // the first failing follicle in drawing order
	int built = 0;      // feathers finished, for def->progress
#pragma omp parallel for schedule(dynamic, 4)
	for (int slot = 0; slot < count; ++slot) {
		int i = order[slot].index;
		plume_error local = {0};
		plume_status s = PLUME_OK;
		plume_feather *feather = NULL;
		if (key_of[i] >= 0) {
			int k = key_of[i];
			s = plume_sh_generate_lod(&def->key_defs[k], def->key_seeds[k], def->stage, &def->lod, &feather, &local);
		} else {
			double weights[COAT_MAX_KEYS];
			follicle_weights(def, weighting, &plane, (const double(*)[2])planar_keys, positions[i], weights);
			plume_sh_def *blended = plume_alloc(sizeof *blended);
			if (blended == NULL) {
				s = plume_error_set(&local, PLUME_ERROR_MEMORY, "out of memory");
			} else {
				s = plume_sh_def_blend(key_pointers, weights, def->key_count, blended, &local);
				plume_rng rng = plume_rng_seed(def->seed + 0x9e3779b97f4a7c15ULL * (uint64_t)(i + 1));
				if (s == PLUME_OK)
					s = plume_sh_generate_lod(blended, plume_rng_next(&rng), def->stage, &def->lod, &feather, &local);
				plume_free(blended);
			}
		}
		if (s == PLUME_OK) {
			plume_vec3 axes[3];
			feather_frame(def, positions[i], normals[i], axes);
			place(feather, axes, positions[i]);
			// The axes are the columns: rotate(axes, v) = axes[0] v.x + axes[1] v.y + axes[2] v.z.
			coat->frames[slot] = (plume_mat3){{{axes[0].x, axes[1].x, axes[2].x},
			                                   {axes[0].y, axes[1].y, axes[2].y},
			                                   {axes[0].z, axes[1].z, axes[2].z}}};
		}
		coat->feathers[slot] = feather;
		coat->roots[slot] = positions[i];
		coat->normals[slot] = normals[i];
		coat->is_key[slot] = key_of[i] >= 0;
		statuses[slot] = s;
		if (def->progress != NULL) {
			// One call at a time, with the count of feathers finished so far, whichever thread.
#pragma omp critical
			def->progress(def->progress_user, ++built, count);
		}
		if (s != PLUME_OK) {
			// Unnamed: a named section's lock is a global symbol libplume.so would export.
#pragma omp critical
			if (slot < failed) {
				failed = slot;
				*errors = local;
			}
		}
	}
	if (failed < count) {
		status = statuses[failed];
		if (err != NULL)
			*err = *errors;
	}
	plume_free(statuses);
	plume_free(errors);
	if (status != PLUME_OK)
		goto fail;
	plume_free(positions);
	plume_free(normals);
	plume_free(key_of);
	plume_free(order);
	*out = coat;
	return PLUME_OK;
fail:
	plume_free(positions);
	plume_free(normals);
	plume_free(key_of);
	plume_free(order);
	plume_coat_destroy(coat);
	return status;
}

// glTF export of feathers and coats: curves as ribbons or line segments.
//
// A ribbon follows a curve with two vertices per point, at p -/+ (w/2) s where
// w is the curve's width there and s = n x t is the unit direction across the
// curve in the plane facing the curve's normal n (t: the tangent, by central
// differences). The shaft uses its own frame (s = binormal). Both ribbon edges
// carry the point's normal, texture coordinates and colour, so a renderer
// shades the ribbon as the curve it stands for. Triangles wind counter-
// clockwise seen from n. Colours are converted from sRGB to linear, as glTF's
// COLOR_0 is linear.
#include <math.h>
#include <string.h>

#include "../core/asserts.h"
#include "../core/alloc.h"
#include "glb.h"
#include "render/texture_png.h"
#include "plume/embed.h"
#include "plume/gltf.h"

plume_gltf_def plume_gltf_default_def(void)
{
	return (plume_gltf_def){
	    .cookie = PLUME_DEF_COOKIE,
	    .curves = PLUME_GLTF_RIBBONS,
	    .barbules = true,
	    .texture = NULL,
	    .barb_color = {0.45, 0.33, 0.22, 1.0},
	    .shaft_color = {0.78, 0.72, 0.62, 1.0},
	    .vane_color = {0.70, 0.62, 0.50, 1.0},
	    .rachis_color = {0.78, 0.72, 0.62, 1.0},
	};
}

/// One primitive's arrays, grown as curves are added.
typedef struct part {
	double *position, *normal, *uv, *color; // 3, 3, 2, 4 per vertex
	double *image_uv;                       // 2 per vertex: where the texture's image is read (TEXCOORD_1)
	int vertices, vertex_capacity;
	uint32_t *indices;
	int64_t index_count, index_capacity;
	bool failed;
} part;

static void part_free(part *p)
{
	plume_free(p->position);
	plume_free(p->normal);
	plume_free(p->uv);
	plume_free(p->color);
	plume_free(p->image_uv);
	plume_free(p->indices);
	memset(p, 0, sizeof *p);
}

static bool part_reserve(part *p, int vertices, int64_t indices)
{
	if (p->failed)
		return false;
	if (p->vertices + vertices > p->vertex_capacity) {
		int capacity = p->vertex_capacity > 0 ? p->vertex_capacity : 1024;
		while (capacity < p->vertices + vertices)
			capacity *= 2;
		double *arrays[5] = {p->position, p->normal, p->uv, p->color, p->image_uv};
		static const int widths[5] = {3, 3, 2, 4, 2};
		for (int k = 0; k < 5; ++k) {
			double *grown = plume_realloc(arrays[k], (size_t)capacity * (size_t)widths[k] * sizeof(double));
			if (grown == NULL) {
				p->failed = true;
				return false;
			}
			arrays[k] = grown;
		}
		p->position = arrays[0];
		p->normal = arrays[1];
		p->uv = arrays[2];
		p->color = arrays[3];
		p->image_uv = arrays[4];
		p->vertex_capacity = capacity;
	}
	if (p->index_count + indices > p->index_capacity) {
		int64_t capacity = p->index_capacity > 0 ? p->index_capacity : 4096;
		while (capacity < p->index_count + indices)
			capacity *= 2;
		uint32_t *grown = plume_realloc(p->indices, (size_t)capacity * sizeof(uint32_t));
		if (grown == NULL) {
			p->failed = true;
			return false;
		}
		p->indices = grown;
		p->index_capacity = capacity;
	}
	return true;
}

static void part_vertex(part *p, plume_vec3 position, plume_vec3 normal, plume_vec2 uv, plume_color color,
                        plume_vec2 image_uv)
{
	int v = p->vertices++;
	p->image_uv[2 * v] = image_uv.x;
	p->image_uv[2 * v + 1] = image_uv.y;
	double *x = p->position + 3 * v, *n = p->normal + 3 * v, *t = p->uv + 2 * v, *c = p->color + 4 * v;
	x[0] = position.x;
	x[1] = position.y;
	x[2] = position.z;
	n[0] = normal.x;
	n[1] = normal.y;
	n[2] = normal.z;
	t[0] = uv.x;
	t[1] = uv.y;
	c[0] = color.r;
	c[1] = color.g;
	c[2] = color.b;
	c[3] = color.a;
}

static plume_color linear(plume_color c)
{
	return (plume_color){plume_glb_linear(c.r), plume_glb_linear(c.g), plume_glb_linear(c.b), c.a};
}

/// A unit vector perpendicular to a (for degenerate frames).
static plume_vec3 any_perpendicular(plume_vec3 a)
{
	plume_vec3 axis = fabs(a.x) < 0.9 ? plume_v3(1, 0, 0) : plume_v3(0, 1, 0);
	return plume_v3_normalize(plume_v3_cross(a, axis));
}

/// One curve: points, their normals, widths, uvs and colours; across[] given
/// (the shaft's binormals) or NULL to derive n x t.
typedef struct curve_in {
	int count;
	const plume_vec3 *points;
	const plume_vec3 *normals; ///< NULL: derived from across and the tangent
	const plume_vec3 *across;  ///< NULL: n x t
	const double *widths;
	const plume_vec2 *uv;
	plume_vec3 origin;          ///< subtracted from every point
	const plume_vec2 *image_uv; ///< per point, where the texture's image is read
} curve_in;

static void add_curve(part *p, const curve_in *c, plume_gltf_curves mode, const plume_color *colors)
{
	int n = c->count;
	if (n < 2)
		return;
	if (mode == PLUME_GLTF_LINES) {
		if (!part_reserve(p, n, 2 * (int64_t)(n - 1)))
			return;
		uint32_t base = (uint32_t)p->vertices;
		for (int j = 0; j < n; ++j) {
			plume_vec3 normal = c->normals != NULL ? c->normals[j] : plume_v3(0, 0, 1);
			part_vertex(p, plume_v3_sub(c->points[j], c->origin), normal, c->uv[j], colors[j], c->image_uv[j]);
		}
		for (int j = 0; j + 1 < n; ++j) {
			p->indices[p->index_count++] = base + (uint32_t)j;
			p->indices[p->index_count++] = base + (uint32_t)j + 1;
		}
		return;
	}
	if (!part_reserve(p, 2 * n, 6 * (int64_t)(n - 1)))
		return;
	uint32_t base = (uint32_t)p->vertices;
	for (int j = 0; j < n; ++j) {
		plume_vec3 tangent = plume_v3_sub(c->points[j + 1 < n ? j + 1 : j], c->points[j > 0 ? j - 1 : j]);
		tangent = plume_v3_normalize(tangent);
		plume_vec3 normal, side;
		if (c->across != NULL) {
			side = c->across[j];
			normal = c->normals != NULL ? c->normals[j] : plume_v3_normalize(plume_v3_cross(tangent, side));
		} else {
			normal = c->normals[j];
			side = plume_v3_cross(normal, tangent);
			double length = plume_v3_length(side);
			side = length > 1e-12 ? plume_v3_scale(side, 1.0 / length) : any_perpendicular(tangent);
		}
		double half = 0.5 * c->widths[j];
		plume_vec3 centre = plume_v3_sub(c->points[j], c->origin);
		part_vertex(p, plume_v3_mad(centre, -half, side), normal, c->uv[j], colors[j], c->image_uv[j]);
		part_vertex(p, plume_v3_mad(centre, half, side), normal, c->uv[j], colors[j], c->image_uv[j]);
	}
	for (int j = 0; j + 1 < n; ++j) {
		uint32_t a0 = base + 2 * (uint32_t)j, b0 = a0 + 1, a1 = a0 + 2, b1 = a0 + 3;
		uint32_t tri[6] = {a0, a1, b0, b0, a1, b1};
		memcpy(p->indices + p->index_count, tri, sizeof tri);
		p->index_count += 6;
	}
}

/// Where plume_texture_sample_vane reads the image for (s, t) on a side, as glTF texture
/// coordinates (origin at the image's top left): Franco & Walter 4.4's columns (the rachis in
/// the middle, each vane's edge at a border) and rows (t = 0 at the bottom).
static plume_vec2 image_uv(plume_side side, plume_vec2 uv)
{
	double u = side == PLUME_SIDE_LEFT ? 0.5 * (1.0 - uv.x) : 0.5 * (1.0 + uv.x);
	return (plume_vec2){u, 1.0 - uv.y};
}

/// Per-point colours of a curve: the texture's at (s, t) on the given side, or a constant;
/// and the points' image coordinates.
typedef struct curve_buffers {
	plume_color *colors;
	plume_vec2 *image_uv;
	int capacity;
} curve_buffers;

static bool curve_colors(curve_buffers *b, int count, const plume_gltf_def *def, const plume_vec2 *uv, plume_side side,
                         plume_color constant)
{
	if (count > b->capacity) {
		plume_color *grown = plume_realloc(b->colors, (size_t)count * sizeof(plume_color));
		if (grown != NULL)
			b->colors = grown;
		plume_vec2 *grown_uv = plume_realloc(b->image_uv, (size_t)count * sizeof(plume_vec2));
		if (grown_uv != NULL)
			b->image_uv = grown_uv;
		if (grown == NULL || grown_uv == NULL)
			return false;
		b->capacity = count;
	}
	for (int j = 0; j < count; ++j) {
		b->colors[j] =
		    linear(def->texture != NULL ? plume_texture_sample_vane(def->texture, side, uv[j].x, uv[j].y) : constant);
		b->image_uv[j] = image_uv(side, uv[j]);
	}
	return true;
}

/// The parts of one feather (not its afterfeather).
enum { PART_SHAFT, PART_LEFT, PART_RIGHT, PART_BARBULES, PART_COUNT };
static const char *const part_names[PART_COUNT] = {"shaft", "left_vane", "right_vane", "barbules"};

static bool build_parts(const plume_feather *feather, const plume_gltf_def *def, plume_vec3 origin,
                        part parts[PART_COUNT])
{
	curve_buffers buffers = {0};
	bool ok = true;
	plume_feather_info info = plume_feather_get_info(feather);
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	int n = info.shaft_sample_count;
	if (n >= 2) {
		plume_vec3 *points = plume_alloc((size_t)n * 3 * sizeof(plume_vec3));
		double *widths = plume_alloc((size_t)n * sizeof(double));
		plume_vec2 *uv = plume_alloc((size_t)n * sizeof(plume_vec2));
		ok = points != NULL && widths != NULL && uv != NULL;
		if (ok) {
			plume_vec3 *normals = points + n, *across = points + 2 * n;
			for (int i = 0; i < n; ++i) {
				points[i] = shaft[i].position;
				normals[i] = shaft[i].normal;
				across[i] = shaft[i].binormal;
				widths[i] = shaft[i].width;
				uv[i] = (plume_vec2){0.0, shaft[i].t};
			}
			// The shaft's colour is the texture's at the rachis (s = 0) of the left vane.
			ok = curve_colors(&buffers, n, def, uv, PLUME_SIDE_LEFT, def->shaft_color);
			curve_in c = {n, points, normals, across, widths, uv, origin, buffers.image_uv};
			if (ok)
				add_curve(&parts[PART_SHAFT], &c, def->curves, buffers.colors);
		}
		plume_free(points);
		plume_free(widths);
		plume_free(uv);
	}
	for (int i = 0; ok && i < info.barb_count; ++i) {
		plume_barb barb = plume_feather_barb(feather, i);
		if (barb.curve.count < 2)
			continue;
		ok = curve_colors(&buffers, barb.curve.count, def, barb.curve.uv, barb.side, def->barb_color);
		curve_in c = {barb.curve.count, barb.curve.points, barb.curve.normals, NULL, barb.curve.widths, barb.curve.uv,
		              origin,           buffers.image_uv};
		if (ok)
			add_curve(&parts[barb.side == PLUME_SIDE_LEFT ? PART_LEFT : PART_RIGHT], &c, def->curves, buffers.colors);
	}
	for (int i = 0; ok && def->barbules && i < info.barbule_count; ++i) {
		plume_barbule barbule = plume_feather_barbule(feather, i);
		if (barbule.curve.count < 2)
			continue;
		plume_side side = plume_feather_barb(feather, barbule.barb).side;
		// A barbule takes its barb's colour where it attaches (its own uv is along the barbule).
		plume_barb barb = plume_feather_barb(feather, barbule.barb);
		plume_vec2 at = {barbule.barb_s, barb.curve.count > 0 ? barb.curve.uv[0].y : 0.0};
		ok = curve_colors(&buffers, 1, def, &at, side, def->barb_color);
		if (!ok)
			break;
		plume_color one = buffers.colors[0];
		plume_vec2 one_uv = buffers.image_uv[0];
		ok = curve_colors(&buffers, barbule.curve.count, def, barbule.curve.uv, side, def->barb_color);
		for (int j = 0; ok && j < barbule.curve.count; ++j) {
			buffers.colors[j] = one;
			buffers.image_uv[j] = one_uv;
		}
		curve_in c = {barbule.curve.count,
		              barbule.curve.points,
		              barbule.curve.normals,
		              NULL,
		              barbule.curve.widths,
		              barbule.curve.uv,
		              origin,
		              buffers.image_uv};
		if (ok)
			add_curve(&parts[PART_BARBULES], &c, def->curves, buffers.colors);
	}
	plume_free(buffers.colors);
	plume_free(buffers.image_uv);
	for (int k = 0; k < PART_COUNT; ++k)
		ok = ok && !parts[k].failed;
	return ok;
}

/// A glTF primitive from a part: attributes, indices, mode, material.
/// textured: the texture's image is embedded, read through TEXCOORD_1; the colour is then the
/// texture's alone (glTF multiplies COLOR_0 into the base colour, so it is left out).
static json_t *part_primitive(plume_glb *glb, const part *p, plume_gltf_curves mode, int material, bool textured)
{
	int position = plume_glb_floats(glb, p->position, p->vertices, 3, GLB_ARRAY_BUFFER, true);
	int normal = plume_glb_floats(glb, p->normal, p->vertices, 3, GLB_ARRAY_BUFFER, false);
	int uv = plume_glb_floats(glb, p->uv, p->vertices, 2, GLB_ARRAY_BUFFER, false);
	json_t *primitive = json_pack("{s:{s:i, s:i, s:i}, s:i, s:i}", "attributes", "POSITION", position, "NORMAL", normal,
	                              "TEXCOORD_0", uv, "mode", mode == PLUME_GLTF_LINES ? 1 : 4, "material", material);
	json_t *attributes = json_object_get(primitive, "attributes");
	if (textured)
		json_object_set_new(attributes, "TEXCOORD_1",
		                    json_integer(plume_glb_floats(glb, p->image_uv, p->vertices, 2, GLB_ARRAY_BUFFER, false)));
	else
		json_object_set_new(attributes, "COLOR_0",
		                    json_integer(plume_glb_floats(glb, p->color, p->vertices, 4, GLB_ARRAY_BUFFER, false)));
	json_object_set_new(primitive, "indices", json_integer(plume_glb_indices(glb, p->indices, p->index_count)));
	return primitive;
}

/// The two materials every curve file shares (colours are in COLOR_0, or with a texture in
/// the embedded image, PNG-encoded).
static plume_status curve_materials(plume_glb *glb, const plume_gltf_def *def, int *shaft, int *vane, plume_error *err)
{
	static const double white[4] = {1, 1, 1, 1};
	*shaft = plume_glb_material(glb, "shaft", white);
	*vane = plume_glb_material(glb, "vane", white);
	if (def->texture == NULL)
		return PLUME_OK;
	size_t size = 0;
	plume_error local = {0};
	unsigned char *png = plume_texture_png_bytes(def->texture, &size, &local);
	if (png == NULL) {
		if (err != NULL)
			*err = local;
		return local.status;
	}
	int texture = plume_glb_png_texture(glb, png, size);
	plume_free(png);
	plume_glb_material_texture(glb, *shaft, texture, 1);
	plume_glb_material_texture(glb, *vane, texture, 1);
	return PLUME_OK;
}

/// Node "name" with one child node per non-empty part (and, nested, the afterfeather). Returns the node.
static int write_feather_nodes(plume_glb *glb, const plume_feather *feather, const plume_gltf_def *def,
                               const char *name, int materials[2], bool *ok)
{
	part parts[PART_COUNT];
	memset(parts, 0, sizeof parts);
	*ok = *ok && build_parts(feather, def, plume_v3(0, 0, 0), parts);
	json_t *children = json_array();
	for (int k = 0; *ok && k < PART_COUNT; ++k) {
		if (parts[k].vertices == 0)
			continue;
		json_t *primitive =
		    part_primitive(glb, &parts[k], def->curves, materials[k == PART_SHAFT ? 0 : 1], def->texture != NULL);
		int mesh = plume_glb_append(glb, glb->meshes,
		                            json_pack("{s:s, s:[o]}", "name", part_names[k], "primitives", primitive));
		int node = plume_glb_append(glb, glb->nodes, json_pack("{s:s, s:i}", "name", part_names[k], "mesh", mesh));
		json_array_append_new(children, json_integer(node));
	}
	for (int k = 0; k < PART_COUNT; ++k)
		part_free(&parts[k]);
	const plume_feather *after = plume_feather_afterfeather(feather);
	if (*ok && after != NULL) {
		int node = write_feather_nodes(glb, after, def, "afterfeather", materials, ok);
		json_array_append_new(children, json_integer(node));
	}
	return plume_glb_append(glb, glb->nodes, json_pack("{s:s, s:o}", "name", name, "children", children));
}

/// A new container with the two curve materials (and the texture, when def has one);
/// freed again on failure.
static plume_status begin_curves_glb(plume_glb *glb, const plume_gltf_def *def, int materials[2], plume_error *err)
{
	plume_glb_init(glb, "plume " PLUME_VERSION_STRING);
	plume_status status = curve_materials(glb, def, &materials[0], &materials[1], err);
	if (status != PLUME_OK)
		plume_glb_free(glb);
	return status;
}

plume_status plume_write_glb(const plume_feather *feather, const plume_gltf_def *def, const char *path,
                             plume_error *err)
{
	PLUME_ASSERT(feather != NULL && path != NULL);
	PLUME_ASSERT_DEF_OR_NULL(def);
	plume_gltf_def defaults = plume_gltf_default_def();
	if (def == NULL)
		def = &defaults;
	plume_glb glb;
	int materials[2];
	plume_status begun = begin_curves_glb(&glb, def, materials, err);
	if (begun != PLUME_OK)
		return begun;
	bool ok = true;
	int root = write_feather_nodes(&glb, feather, def, "feather", materials, &ok);
	plume_glb_scene_root(&glb, root);
	plume_status status =
	    ok ? plume_glb_write(&glb, path, err) : plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	plume_glb_free(&glb);
	return status;
}

// ---------------------------------------------------------------------------
// Coats

/// FNV-1a over the bytes of the part arrays: two feathers whose geometry
/// relative to their follicle is the same give the same hash, and share a mesh
/// (the arrays are then compared in full, so a collision cannot merge two).
static uint64_t hash_bytes(uint64_t h, const void *data, size_t size)
{
	const uint8_t *bytes = data;
	for (size_t i = 0; i < size; ++i) {
		h ^= bytes[i];
		h *= 1099511628211ull;
	}
	return h;
}

typedef struct coat_mesh {
	uint64_t hash;
	part parts[PART_COUNT];
	int mesh;
} coat_mesh;

static bool same_parts(const part a[PART_COUNT], const part b[PART_COUNT])
{
	for (int k = 0; k < PART_COUNT; ++k) {
		if (a[k].vertices != b[k].vertices || a[k].index_count != b[k].index_count)
			return false;
		size_t v = (size_t)a[k].vertices;
		if (memcmp(a[k].position, b[k].position, 3 * v * sizeof(double)) != 0 ||
		    memcmp(a[k].normal, b[k].normal, 3 * v * sizeof(double)) != 0 ||
		    memcmp(a[k].uv, b[k].uv, 2 * v * sizeof(double)) != 0 ||
		    memcmp(a[k].color, b[k].color, 4 * v * sizeof(double)) != 0 ||
		    memcmp(a[k].image_uv, b[k].image_uv, 2 * v * sizeof(double)) != 0 ||
		    memcmp(a[k].indices, b[k].indices, (size_t)a[k].index_count * sizeof(uint32_t)) != 0)
			return false;
	}
	return true;
}

/// All parts of a feather and its afterfeathers, merged per part (the afterfeather's
/// barbs join its parent's vanes), relative to origin.
static bool build_coat_parts(const plume_feather *feather, const plume_gltf_def *def, plume_vec3 origin,
                             part parts[PART_COUNT])
{
	bool ok = true;
	for (const plume_feather *f = feather; ok && f != NULL; f = plume_feather_afterfeather(f))
		ok = build_parts(f, def, origin, parts);
	return ok;
}

plume_status plume_coat_write_glb_report(const plume_coat *coat, const plume_gltf_def *def, const char *path,
                                         plume_coat_glb_report *report, plume_error *err)
{
	PLUME_ASSERT(coat != NULL);
	PLUME_ASSERT(path != NULL);
	PLUME_ASSERT_DEF_OR_NULL(def);
	plume_gltf_def defaults = plume_gltf_default_def();
	if (def == NULL)
		def = &defaults;
	plume_glb glb;
	int materials[2];
	plume_status begun = begin_curves_glb(&glb, def, materials, err);
	if (begun != PLUME_OK)
		return begun;
	int count = plume_coat_feather_count(coat);
	coat_mesh *meshes = plume_calloc(count > 0 ? (size_t)count : 1, sizeof(coat_mesh));
	json_t *children = json_array();
	int mesh_count = 0;
	bool ok = meshes != NULL && children != NULL;
	for (int i = 0; ok && i < count; ++i) {
		plume_vec3 follicle, normal;
		plume_coat_follicle(coat, i, &follicle, &normal);
		coat_mesh *candidate = &meshes[mesh_count];
		ok = build_coat_parts(plume_coat_feather(coat, i), def, follicle, candidate->parts);
		if (!ok)
			break;
		uint64_t h = 14695981039346656037ull;
		for (int k = 0; k < PART_COUNT; ++k) {
			h = hash_bytes(h, candidate->parts[k].position, 3 * (size_t)candidate->parts[k].vertices * sizeof(double));
			h = hash_bytes(h, candidate->parts[k].color, 4 * (size_t)candidate->parts[k].vertices * sizeof(double));
		}
		candidate->hash = h;
		int mesh = -1;
		for (int m = 0; m < mesh_count && mesh < 0; ++m)
			if (meshes[m].hash == h && same_parts(meshes[m].parts, candidate->parts))
				mesh = meshes[m].mesh;
		if (mesh < 0) {
			json_t *primitives = json_array();
			for (int k = 0; k < PART_COUNT; ++k)
				if (candidate->parts[k].vertices > 0)
					json_array_append_new(primitives,
					                      part_primitive(&glb, &candidate->parts[k], def->curves,
					                                     materials[k == PART_SHAFT ? 0 : 1], def->texture != NULL));
			char name[32];
			snprintf(name, sizeof name, "feather_%05d", i);
			mesh = plume_glb_append(&glb, glb.meshes, json_pack("{s:s, s:o}", "name", name, "primitives", primitives));
			candidate->mesh = mesh;
			++mesh_count;
		} else {
			for (int k = 0; k < PART_COUNT; ++k)
				part_free(&candidate->parts[k]);
		}
		char name[32];
		snprintf(name, sizeof name, "feather_%05d", i);
		int node = plume_glb_append(&glb, glb.nodes,
		                            json_pack("{s:s, s:i, s:[f,f,f]}", "name", name, "mesh", mesh, "translation",
		                                      follicle.x, follicle.y, follicle.z));
		json_array_append_new(children, json_integer(node));
	}
	if (ok) {
		int surface = plume_glb_shell_node(&glb, plume_coat_surface(coat), NULL, def, "surface");
		json_array_append_new(children, json_integer(surface));
		int root = plume_glb_append(&glb, glb.nodes, json_pack("{s:s, s:o}", "name", "coat", "children", children));
		plume_glb_scene_root(&glb, root);
		children = NULL;
	}
	json_decref(children);
	for (int m = 0; meshes != NULL && m <= mesh_count && m < count; ++m)
		for (int k = 0; k < PART_COUNT; ++k)
			part_free(&meshes[m].parts[k]);
	plume_free(meshes);
	if (report != NULL)
		*report = (plume_coat_glb_report){ok ? count : 0, ok ? mesh_count : 0};
	plume_status status =
	    ok ? plume_glb_write(&glb, path, err) : plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	plume_glb_free(&glb);
	return status;
}

plume_status plume_coat_write_glb(const plume_coat *coat, const plume_gltf_def *def, const char *path, plume_error *err)
{
	return plume_coat_write_glb_report(coat, def, path, NULL, err);
}

// ---------------------------------------------------------------------------
// A feather carried by an animated shell

/// Appends part b's vertices and indices to a (lines only: no ribbons across parts).
static bool part_append(part *a, const part *b)
{
	if (b->vertices == 0) // an empty part has no arrays (memcpy from NULL is undefined even for 0 bytes)
		return !a->failed;
	if (!part_reserve(a, b->vertices, b->index_count))
		return false;
	int v = a->vertices;
	memcpy(a->position + 3 * v, b->position, 3 * (size_t)b->vertices * sizeof(double));
	memcpy(a->normal + 3 * v, b->normal, 3 * (size_t)b->vertices * sizeof(double));
	memcpy(a->uv + 2 * v, b->uv, 2 * (size_t)b->vertices * sizeof(double));
	memcpy(a->color + 4 * v, b->color, 4 * (size_t)b->vertices * sizeof(double));
	for (int64_t i = 0; i < b->index_count; ++i)
		a->indices[a->index_count + i] = b->indices[i] + (uint32_t)v;
	a->vertices += b->vertices;
	a->index_count += b->index_count;
	return true;
}

/// The moved feather of one frame as a single part of line segments.
static bool carried_lines(const plume_barb_embedding *embedding, const plume_vec3 *positions, const plume_gltf_def *def,
                          part *out)
{
	plume_feather *moved = NULL;
	plume_error err;
	if (plume_embedding_apply(embedding, positions, &moved, &err) != PLUME_OK)
		return false;
	plume_gltf_def lines = *def;
	lines.curves = PLUME_GLTF_LINES;
	part parts[PART_COUNT];
	memset(parts, 0, sizeof parts);
	bool ok = build_parts(moved, &lines, plume_v3(0, 0, 0), parts);
	memset(out, 0, sizeof *out);
	for (int k = 0; ok && k < PART_COUNT; ++k)
		ok = part_append(out, &parts[k]);
	for (int k = 0; k < PART_COUNT; ++k)
		part_free(&parts[k]);
	plume_feather_destroy(moved);
	return ok;
}

int plume_glb_carried_feather(plume_glb *glb, const plume_barb_embedding *embedding, const plume_vec3 *const *frames,
                              int frame_count, const char *name, const plume_gltf_def *def, bool *ok)
{
	part base;
	if (!carried_lines(embedding, frames[0], def, &base)) {
		*ok = false;
		return 0;
	}
	json_t *targets = json_array();
	float *displacement = plume_alloc(3 * (size_t)(base.vertices > 0 ? base.vertices : 1) * sizeof(float));
	*ok = targets != NULL && displacement != NULL;
	for (int k = 0; *ok && k < frame_count; ++k) {
		part moved;
		*ok = carried_lines(embedding, frames[k], def, &moved) && moved.vertices == base.vertices;
		for (int i = 0; *ok && i < 3 * base.vertices; ++i)
			displacement[i] = (float)(moved.position[i] - base.position[i]);
		if (*ok)
			json_array_append_new(
			    targets, json_pack("{s:i}", "POSITION",
			                       plume_glb_floats_f(glb, displacement, base.vertices, 3, GLB_ARRAY_BUFFER, true)));
		part_free(&moved);
	}
	int node = 0;
	if (*ok) {
		int position = plume_glb_floats(glb, base.position, base.vertices, 3, GLB_ARRAY_BUFFER, true);
		int uv = plume_glb_floats(glb, base.uv, base.vertices, 2, GLB_ARRAY_BUFFER, false);
		int color = plume_glb_floats(glb, base.color, base.vertices, 4, GLB_ARRAY_BUFFER, false);
		int indices = plume_glb_indices(glb, base.indices, base.index_count);
		static const double white[4] = {1, 1, 1, 1};
		int material = plume_glb_material(glb, "barbs", white);
		json_t *weights = json_array();
		for (int k = 0; k < frame_count; ++k)
			json_array_append_new(weights, json_real(k == 0 ? 1.0 : 0.0));
		json_t *primitive =
		    json_pack("{s:{s:i, s:i, s:i}, s:i, s:i, s:i, s:o}", "attributes", "POSITION", position, "TEXCOORD_0", uv,
		              "COLOR_0", color, "indices", indices, "mode", 1, "material", material, "targets", targets);
		targets = NULL;
		int mesh =
		    plume_glb_append(glb, glb->meshes,
		                     json_pack("{s:s, s:[o], s:o}", "name", name, "primitives", primitive, "weights", weights));
		node = plume_glb_append(glb, glb->nodes, json_pack("{s:s, s:i}", "name", name, "mesh", mesh));
	}
	json_decref(targets);
	plume_free(displacement);
	part_free(&base);
	return node;
}

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
#define _POSIX_C_SOURCE 200809L // export.h: locale_t
#include <math.h>
#include <string.h>

#include "../core/asserts.h"
#include "../core/alloc.h"
#include "../model/feather_internal.h"
#include "export.h"
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

// ---------------------------------------------------------------------------
// Curves to vertices
//
// A part (shaft, left vane, right vane, barbules) is counted first (part_size), then
// its vertices and indices are produced curve by curve (emit_vertices, emit_indices)
// into a sink: the feather writer streams each attribute into the file's binary
// chunk; the coat and carried-feather writers fill arrays of the exact size.

/// One vertex of a part as computed (doubles); glTF stores each component as a float.
typedef struct gl_vertex {
	double position[3], normal[3], uv[2], color[4], image_uv[2];
} gl_vertex;

typedef void vertex_sink(void *context, const gl_vertex *vertex);
typedef void index_sink(void *context, const uint32_t *indices, int count);

/// The parts of one feather (not its afterfeather).
enum { PART_SHAFT, PART_LEFT, PART_RIGHT, PART_BARBULES, PART_COUNT };
static const char *const part_names[PART_COUNT] = {"shaft", "left_vane", "right_vane", "barbules"};

/// One curve of a part: its points, normals, widths and uv, or the shaft's samples; its colour's side.
typedef struct curve_ref {
	int count;
	const plume_vec3 *points;
	const plume_vec3 *normals;
	const double *widths;
	const plume_vec2 *uv;
	const plume_shaft_sample *shaft; ///< the shaft: points, normals, widths and across (binormals) from here
	plume_side side;
	bool one_color;       ///< a barbule: every point takes the colour at attach_uv
	plume_vec2 attach_uv; ///< where a barbule joins its barb: (barb_s, the barb's t)
} curve_ref;

/// The next curve of 2 or more points of a part, from *cursor on (0 first). False after the last.
static bool next_curve(const plume_feather *feather, int kind, const plume_gltf_def *def, int *cursor, curve_ref *c)
{
	memset(c, 0, sizeof *c);
	// The counts straight from the feather: plume_feather_get_info also measures its bounds.
	if (kind == PART_SHAFT) {
		if (*cursor > 0 || feather->shaft_count < 2)
			return false;
		*cursor = 1;
		c->count = feather->shaft_count;
		c->shaft = plume_feather_shaft(feather);
		c->side = PLUME_SIDE_LEFT; // the shaft's colour is the texture's at the rachis (s = 0) of the left vane
		return true;
	}
	if (kind == PART_LEFT || kind == PART_RIGHT) {
		plume_side side = kind == PART_LEFT ? PLUME_SIDE_LEFT : PLUME_SIDE_RIGHT;
		for (; *cursor < feather->barb_count; ++*cursor) {
			plume_barb barb = plume_feather_barb(feather, *cursor);
			if (barb.curve.count < 2 || barb.side != side)
				continue;
			*c = (curve_ref){.count = barb.curve.count,
			                 .points = barb.curve.points,
			                 .normals = barb.curve.normals,
			                 .widths = barb.curve.widths,
			                 .uv = barb.curve.uv,
			                 .side = barb.side};
			++*cursor;
			return true;
		}
		return false;
	}
	int count = def->barbules ? feather->barbule_count : 0;
	for (; *cursor < count; ++*cursor) {
		plume_barbule barbule = plume_feather_barbule(feather, *cursor);
		if (barbule.curve.count < 2)
			continue;
		// A barbule takes its barb's colour where it attaches (its own uv is along the barbule).
		plume_barb barb = plume_feather_barb(feather, barbule.barb);
		plume_vec2 at = {barbule.barb_s, barb.curve.count > 0 ? barb.curve.uv[0].y : 0.0};
		*c = (curve_ref){.count = barbule.curve.count,
		                 .points = barbule.curve.points,
		                 .normals = barbule.curve.normals,
		                 .widths = barbule.curve.widths,
		                 .uv = barbule.curve.uv,
		                 .side = barb.side,
		                 .one_color = true,
		                 .attach_uv = at};
		++*cursor;
		return true;
	}
	return false;
}

/// Vertices and indices a curve of count points makes.
static int64_t curve_vertices(int count, plume_gltf_curves mode)
{
	return mode == PLUME_GLTF_LINES ? count : 2 * (int64_t)count;
}

static int64_t curve_indices(int count, plume_gltf_curves mode)
{
	return (mode == PLUME_GLTF_LINES ? 2 : 6) * (int64_t)(count - 1);
}

/// Adds the vertices and indices of a part of feather (not its afterfeather) to *vertices and *indices,
/// and raises *longest to its longest curve.
static void part_size(const plume_feather *feather, int kind, const plume_gltf_def *def, int64_t *vertices,
                      int64_t *indices, int *longest)
{
	curve_ref c;
	for (int cursor = 0; next_curve(feather, kind, def, &cursor, &c);) {
		*vertices += curve_vertices(c.count, def->curves);
		*indices += curve_indices(c.count, def->curves);
		*longest = c.count > *longest ? c.count : *longest;
	}
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

/// Where plume_texture_sample_vane reads the image for (s, t) on a side, as glTF texture
/// coordinates (origin at the image's top left): Franco & Walter 4.4's columns (the rachis in
/// the middle, each vane's edge at a border) and rows (t = 0 at the bottom).
static plume_vec2 image_uv(plume_side side, plume_vec2 uv)
{
	double u = side == PLUME_SIDE_LEFT ? 0.5 * (1.0 - uv.x) : 0.5 * (1.0 + uv.x);
	return (plume_vec2){u, 1.0 - uv.y};
}

/// Scratch for one curve at a time, sized once for the longest curve: per point its colour
/// (the texture's at (s, t) on the curve's side, or a constant), image coordinates, and the
/// shaft's uv (0, t).
typedef struct curve_buffers {
	plume_color *colors;
	plume_vec2 *image_uv;
	plume_vec2 *uv;
	int capacity;
} curve_buffers;

static bool buffers_init(curve_buffers *b, int longest)
{
	size_t n = (size_t)(longest > 1 ? longest : 1);
	b->colors = plume_alloc(n * sizeof *b->colors);
	b->image_uv = plume_alloc(n * sizeof *b->image_uv);
	b->uv = plume_alloc(n * sizeof *b->uv);
	b->capacity = (int)n;
	return b->colors != NULL && b->image_uv != NULL && b->uv != NULL;
}

static void buffers_free(curve_buffers *b)
{
	plume_free(b->colors);
	plume_free(b->image_uv);
	plume_free(b->uv);
	memset(b, 0, sizeof *b);
}

/// One point's colour and image coordinates.
static void point_color(const plume_gltf_def *def, plume_side side, plume_vec2 uv, plume_color constant,
                        plume_color *color, plume_vec2 *image)
{
	*color = linear(def->texture != NULL ? plume_texture_sample_vane(def->texture, side, uv.x, uv.y) : constant);
	*image = image_uv(side, uv);
}

static void put_vertex(vertex_sink *sink, void *context, plume_vec3 position, plume_vec3 normal, plume_vec2 uv,
                       plume_color color, plume_vec2 image)
{
	const gl_vertex v = {{position.x, position.y, position.z},
	                     {normal.x, normal.y, normal.z},
	                     {uv.x, uv.y},
	                     {color.r, color.g, color.b, color.a},
	                     {image.x, image.y}};
	sink(context, &v);
}

/// The vertices of one curve, relative to origin: two per point across the curve (ribbons), or one.
static void curve_vertices_out(const curve_ref *c, const plume_gltf_def *def, plume_vec3 origin, curve_buffers *b,
                               vertex_sink *sink, void *context)
{
	int n = c->count;
	const plume_vec2 *uv = c->uv;
	if (c->shaft != NULL) {
		for (int j = 0; j < n; ++j)
			b->uv[j] = (plume_vec2){0.0, c->shaft[j].t};
		uv = b->uv;
	}
	plume_color constant = c->shaft != NULL ? def->shaft_color : def->barb_color;
	if (c->one_color) {
		plume_color one;
		plume_vec2 one_image;
		point_color(def, c->side, c->attach_uv, constant, &one, &one_image);
		for (int j = 0; j < n; ++j) {
			b->colors[j] = one;
			b->image_uv[j] = one_image;
		}
	} else {
		for (int j = 0; j < n; ++j)
			point_color(def, c->side, uv[j], constant, &b->colors[j], &b->image_uv[j]);
	}
#define POINT(j) (c->shaft != NULL ? c->shaft[j].position : c->points[j])
	for (int j = 0; j < n; ++j) {
		plume_vec3 centre = plume_v3_sub(POINT(j), origin);
		if (def->curves == PLUME_GLTF_LINES) {
			plume_vec3 normal = c->shaft != NULL     ? c->shaft[j].normal
			                    : c->normals != NULL ? c->normals[j]
			                                         : plume_v3(0, 0, 1);
			put_vertex(sink, context, centre, normal, uv[j], b->colors[j], b->image_uv[j]);
			continue;
		}
		plume_vec3 tangent = plume_v3_normalize(plume_v3_sub(POINT(j + 1 < n ? j + 1 : j), POINT(j > 0 ? j - 1 : j)));
		plume_vec3 normal, side;
		double width;
		if (c->shaft != NULL) { // the shaft's own frame: across is the binormal
			side = c->shaft[j].binormal;
			normal = c->shaft[j].normal;
			width = c->shaft[j].width;
		} else {
			normal = c->normals[j];
			side = plume_v3_cross(normal, tangent);
			double length = plume_v3_length(side);
			side = length > 1e-12 ? plume_v3_scale(side, 1.0 / length) : any_perpendicular(tangent);
			width = c->widths[j];
		}
		double half = 0.5 * width;
		put_vertex(sink, context, plume_v3_mad(centre, -half, side), normal, uv[j], b->colors[j], b->image_uv[j]);
		put_vertex(sink, context, plume_v3_mad(centre, half, side), normal, uv[j], b->colors[j], b->image_uv[j]);
	}
#undef POINT
}

/// The vertices of a part of feather (not its afterfeather), in order.
static void emit_vertices(const plume_feather *feather, int kind, const plume_gltf_def *def, plume_vec3 origin,
                          curve_buffers *buffers, vertex_sink *sink, void *context)
{
	curve_ref c;
	for (int cursor = 0; next_curve(feather, kind, def, &cursor, &c);)
		curve_vertices_out(&c, def, origin, buffers, sink, context);
}

/// The indices of a part of feather, its first vertex *base; *base moves past its vertices.
/// Ribbon triangles wind counter-clockwise seen from the normal.
static void emit_indices(const plume_feather *feather, int kind, const plume_gltf_def *def, uint32_t *base,
                         index_sink *sink, void *context)
{
	curve_ref c;
	for (int cursor = 0; next_curve(feather, kind, def, &cursor, &c);) {
		for (int j = 0; j + 1 < c.count; ++j) {
			if (def->curves == PLUME_GLTF_LINES) {
				const uint32_t segment[2] = {*base + (uint32_t)j, *base + (uint32_t)j + 1};
				sink(context, segment, 2);
			} else {
				uint32_t a0 = *base + 2 * (uint32_t)j, b0 = a0 + 1, a1 = a0 + 2, b1 = a0 + 3;
				const uint32_t tri[6] = {a0, a1, b0, b0, a1, b1};
				sink(context, tri, 6);
			}
		}
		*base += (uint32_t)curve_vertices(c.count, def->curves);
	}
}

/// Most vertices of one primitive: its indices are 32-bit and its counts ints.
#define PART_MAX_VERTICES INT32_MAX

// ---------------------------------------------------------------------------
// Parts in memory (coats, carried feathers): arrays of the exact size, floats as glTF stores them

typedef struct part {
	float *position, *normal, *uv, *color, *image_uv; // 3, 3, 2, 4, 2 per vertex
	double *exact;                                    // 3 per vertex: positions before rounding (carried feathers)
	int vertices;
	uint32_t *indices;
	int64_t index_count;
} part;

static void part_free(part *p)
{
	plume_free(p->position);
	plume_free(p->normal);
	plume_free(p->uv);
	plume_free(p->color);
	plume_free(p->image_uv);
	plume_free(p->exact);
	plume_free(p->indices);
	memset(p, 0, sizeof *p);
}

/// Allocates a part for vertices and indices; exact: keep the positions in doubles too.
static bool part_alloc(part *p, int64_t vertices, int64_t indices, bool exact)
{
	memset(p, 0, sizeof *p);
	if (vertices > PART_MAX_VERTICES)
		return false;
	size_t v = (size_t)(vertices > 0 ? vertices : 1);
	p->position = plume_alloc(3 * v * sizeof(float));
	p->normal = plume_alloc(3 * v * sizeof(float));
	p->uv = plume_alloc(2 * v * sizeof(float));
	p->color = plume_alloc(4 * v * sizeof(float));
	p->image_uv = plume_alloc(2 * v * sizeof(float));
	p->exact = exact ? plume_alloc(3 * v * sizeof(double)) : NULL;
	p->indices = plume_alloc((size_t)(indices > 0 ? indices : 1) * sizeof(uint32_t));
	bool ok = p->position != NULL && p->normal != NULL && p->uv != NULL && p->color != NULL && p->image_uv != NULL &&
	          (!exact || p->exact != NULL) && p->indices != NULL;
	if (!ok)
		part_free(p);
	return ok;
}

static void store_vertex(void *context, const gl_vertex *v)
{
	part *p = context;
	size_t i = (size_t)p->vertices++;
	for (int k = 0; k < 3; ++k) {
		p->position[3 * i + k] = (float)v->position[k];
		p->normal[3 * i + k] = (float)v->normal[k];
		if (p->exact != NULL)
			p->exact[3 * i + k] = v->position[k];
	}
	for (int k = 0; k < 2; ++k) {
		p->uv[2 * i + k] = (float)v->uv[k];
		p->image_uv[2 * i + k] = (float)v->image_uv[k];
	}
	for (int k = 0; k < 4; ++k)
		p->color[4 * i + k] = (float)v->color[k];
}

static void store_indices(void *context, const uint32_t *indices, int count)
{
	part *p = context;
	memcpy(p->indices + p->index_count, indices, (size_t)count * sizeof *indices);
	p->index_count += count;
}

/// One part from the parts kinds[0..kind_count) of feather and, with afterfeathers, of each of
/// its afterfeathers after it, relative to origin. False when memory runs out or it has too many
/// vertices.
static bool part_build(const plume_feather *feather, bool afterfeathers, const int *kinds, int kind_count,
                       const plume_gltf_def *def, plume_vec3 origin, bool exact, part *out)
{
	int64_t vertices = 0, indices = 0;
	int longest = 0;
	for (const plume_feather *f = feather; f != NULL; f = afterfeathers ? plume_feather_afterfeather(f) : NULL)
		for (int k = 0; k < kind_count; ++k)
			part_size(f, kinds[k], def, &vertices, &indices, &longest);
	curve_buffers buffers;
	bool ok = buffers_init(&buffers, longest);
	ok = part_alloc(out, vertices, indices, exact) && ok;
	uint32_t base = 0;
	for (const plume_feather *f = feather; ok && f != NULL; f = afterfeathers ? plume_feather_afterfeather(f) : NULL)
		for (int k = 0; k < kind_count; ++k) {
			emit_vertices(f, kinds[k], def, origin, &buffers, store_vertex, out);
			emit_indices(f, kinds[k], def, &base, store_indices, out);
		}
	buffers_free(&buffers);
	if (!ok)
		part_free(out);
	return ok;
}

/// A glTF primitive from a part: attributes, indices, mode, material.
/// textured: the texture's image is embedded, read through TEXCOORD_1; the colour is then the
/// texture's alone (glTF multiplies COLOR_0 into the base colour, so it is left out).
static json_t *part_primitive(plume_glb *glb, const part *p, plume_gltf_curves mode, int material, bool textured)
{
	int position = plume_glb_floats_f(glb, p->position, p->vertices, 3, GLB_ARRAY_BUFFER, true);
	int normal = plume_glb_floats_f(glb, p->normal, p->vertices, 3, GLB_ARRAY_BUFFER, false);
	int uv = plume_glb_floats_f(glb, p->uv, p->vertices, 2, GLB_ARRAY_BUFFER, false);
	json_t *primitive = json_pack("{s:{s:i, s:i, s:i}, s:i, s:i}", "attributes", "POSITION", position, "NORMAL", normal,
	                              "TEXCOORD_0", uv, "mode", mode == PLUME_GLTF_LINES ? 1 : 4, "material", material);
	json_t *attributes = json_object_get(primitive, "attributes");
	if (textured)
		json_object_set_new(
		    attributes, "TEXCOORD_1",
		    json_integer(plume_glb_floats_f(glb, p->image_uv, p->vertices, 2, GLB_ARRAY_BUFFER, false)));
	else
		json_object_set_new(attributes, "COLOR_0",
		                    json_integer(plume_glb_floats_f(glb, p->color, p->vertices, 4, GLB_ARRAY_BUFFER, false)));
	json_object_set_new(primitive, "indices", json_integer(plume_glb_indices(glb, p->indices, p->index_count)));
	return primitive;
}

// ---------------------------------------------------------------------------
// Parts streamed (one feather): each attribute written to the binary chunk as it is computed

enum { ATTRIBUTE_POSITION, ATTRIBUTE_NORMAL, ATTRIBUTE_UV, ATTRIBUTE_COLOR, ATTRIBUTE_IMAGE_UV };

/// Values on their way to one view, a block at a time.
typedef struct stream_view {
	plume_glb *glb;
	int attribute;
	int components;
	float *block; ///< STREAM_BLOCK floats
	int used;
	int64_t count; ///< elements so far
	float min[4], max[4];
} stream_view;

enum { STREAM_BLOCK = 1 << 16 };

static void stream_flush(stream_view *s)
{
	plume_glb_view_append(s->glb, s->block, (size_t)s->used * sizeof(float));
	s->used = 0;
}

static void stream_vertex(void *context, const gl_vertex *v)
{
	stream_view *s = context;
	const double *from = s->attribute == ATTRIBUTE_POSITION ? v->position
	                     : s->attribute == ATTRIBUTE_NORMAL ? v->normal
	                     : s->attribute == ATTRIBUTE_UV     ? v->uv
	                     : s->attribute == ATTRIBUTE_COLOR  ? v->color
	                                                        : v->image_uv;
	if (s->used + s->components > STREAM_BLOCK)
		stream_flush(s);
	for (int c = 0; c < s->components; ++c) {
		float value = (float)from[c];
		s->block[s->used++] = value;
		if (s->count == 0 || value < s->min[c])
			s->min[c] = value;
		if (s->count == 0 || value > s->max[c])
			s->max[c] = value;
	}
	s->count++;
}

static void stream_indices(void *context, const uint32_t *indices, int count)
{
	stream_view *s = context;
	if (s->used + count > STREAM_BLOCK)
		stream_flush(s);
	memcpy(s->block + s->used, indices, (size_t)count * sizeof *indices); // 4 bytes each, as the floats
	s->used += count;
	s->count += count;
}

/// One attribute of a part of feather as a view and accessor, streamed; returns the accessor.
static int stream_attribute(plume_glb *glb, const plume_feather *feather, int kind, const plume_gltf_def *def,
                            curve_buffers *buffers, float *block, int attribute)
{
	static const int components[5] = {3, 3, 2, 4, 2};
	stream_view s = {.glb = glb, .attribute = attribute, .components = components[attribute], .block = block};
	plume_glb_view_begin(glb);
	emit_vertices(feather, kind, def, plume_v3(0, 0, 0), buffers, stream_vertex, &s);
	stream_flush(&s);
	int view = plume_glb_view_end(glb, GLB_ARRAY_BUFFER);
	bool bounds = attribute == ATTRIBUTE_POSITION && s.count > 0;
	return plume_glb_float_accessor(glb, view, s.count, s.components, bounds ? s.min : NULL, bounds ? s.max : NULL);
}

/// The primitive of a part of feather, its arrays streamed into the binary chunk in
/// part_primitive's order (the same bytes).
static json_t *stream_primitive(plume_glb *glb, const plume_feather *feather, int kind, const plume_gltf_def *def,
                                curve_buffers *buffers, float *block, int material)
{
	int position = stream_attribute(glb, feather, kind, def, buffers, block, ATTRIBUTE_POSITION);
	int normal = stream_attribute(glb, feather, kind, def, buffers, block, ATTRIBUTE_NORMAL);
	int uv = stream_attribute(glb, feather, kind, def, buffers, block, ATTRIBUTE_UV);
	json_t *primitive =
	    json_pack("{s:{s:i, s:i, s:i}, s:i, s:i}", "attributes", "POSITION", position, "NORMAL", normal, "TEXCOORD_0",
	              uv, "mode", def->curves == PLUME_GLTF_LINES ? 1 : 4, "material", material);
	json_t *attributes = json_object_get(primitive, "attributes");
	bool textured = def->texture != NULL;
	json_object_set_new(attributes, textured ? "TEXCOORD_1" : "COLOR_0",
	                    json_integer(stream_attribute(glb, feather, kind, def, buffers, block,
	                                                  textured ? ATTRIBUTE_IMAGE_UV : ATTRIBUTE_COLOR)));
	stream_view s = {.glb = glb, .block = block};
	uint32_t base = 0;
	plume_glb_view_begin(glb);
	emit_indices(feather, kind, def, &base, stream_indices, &s);
	stream_flush(&s);
	int view = plume_glb_view_end(glb, GLB_ELEMENT_ARRAY_BUFFER);
	json_object_set_new(primitive, "indices", json_integer(plume_glb_index_accessor(glb, view, s.count)));
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

/// Node "name" with one child node per non-empty part (and, nested, the afterfeather), the parts
/// streamed. Returns the node.
static int write_feather_nodes(plume_glb *glb, const plume_feather *feather, const plume_gltf_def *def,
                               const char *name, int materials[2], bool *ok)
{
	int64_t vertices[PART_COUNT] = {0}, indices[PART_COUNT] = {0};
	int longest = 0;
	for (int k = 0; k < PART_COUNT; ++k) {
		part_size(feather, k, def, &vertices[k], &indices[k], &longest);
		*ok = *ok && vertices[k] <= PART_MAX_VERTICES;
	}
	curve_buffers buffers;
	bool ready = buffers_init(&buffers, longest);
	float *block = plume_alloc(STREAM_BLOCK * sizeof *block);
	*ok = *ok && ready && block != NULL;
	json_t *children = json_array();
	for (int k = 0; *ok && k < PART_COUNT; ++k) {
		if (vertices[k] == 0)
			continue;
		json_t *primitive = stream_primitive(glb, feather, k, def, &buffers, block, materials[k == PART_SHAFT ? 0 : 1]);
		int mesh = plume_glb_append(glb, glb->meshes,
		                            json_pack("{s:s, s:[o]}", "name", part_names[k], "primitives", primitive));
		int node = plume_glb_append(glb, glb->nodes, json_pack("{s:s, s:i}", "name", part_names[k], "mesh", mesh));
		json_array_append_new(children, json_integer(node));
	}
	buffers_free(&buffers);
	plume_free(block);
	const plume_feather *after = plume_feather_afterfeather(feather);
	if (*ok && after != NULL) {
		int node = write_feather_nodes(glb, after, def, "afterfeather", materials, ok);
		json_array_append_new(children, json_integer(node));
	}
	return plume_glb_append(glb, glb->nodes, json_pack("{s:s, s:o}", "name", name, "children", children));
}

/// A new container for path, its binary chunk spooled beside it, with the two curve materials
/// (and the texture, when def has one); freed again on failure.
static plume_status begin_curves_glb(plume_glb *glb, const plume_gltf_def *def, const char *path, int materials[2],
                                     plume_error *err)
{
	plume_status status = plume_glb_init_spooled(glb, "plume " PLUME_VERSION_STRING, path, err);
	if (status != PLUME_OK)
		return status;
	status = curve_materials(glb, def, &materials[0], &materials[1], err);
	if (status != PLUME_OK)
		plume_glb_free(glb);
	return status;
}

/// What failed, when a curve file's builder could not finish (ok false): too many vertices
/// for one primitive, else memory.
static plume_status build_failure(const char *path, bool too_many, plume_error *err)
{
	if (too_many)
		return plume_error_set(err, PLUME_ERROR_LIMIT,
		                       "%s: a part of the feather has more than %d vertices, the most one glTF primitive of "
		                       "plume's holds",
		                       path, PART_MAX_VERTICES);
	return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
}

/// True when a part of feather or of its afterfeathers has more vertices than a primitive holds.
static bool too_many_vertices(const plume_feather *feather, const plume_gltf_def *def, bool merged)
{
	int64_t total[PART_COUNT] = {0};
	for (const plume_feather *f = feather; f != NULL; f = plume_feather_afterfeather(f))
		for (int k = 0; k < PART_COUNT; ++k) {
			int64_t vertices = 0, indices = 0;
			int longest = 0;
			part_size(f, k, def, &vertices, &indices, &longest);
			total[k] = merged ? total[k] + vertices : vertices;
			if (total[k] > PART_MAX_VERTICES)
				return true;
		}
	return false;
}

plume_status plume_write_glb(const plume_feather *feather, const plume_gltf_def *def, const char *path,
                             plume_error *err)
{
	PLUME_ASSERT(feather != NULL && path != NULL);
	PLUME_ASSERT_DEF_OR_NULL(def);
	plume_gltf_def defaults = plume_gltf_default_def();
	if (def == NULL)
		def = &defaults;
	// Checked before the file is opened: nothing is written, and path keeps what it held.
	char what[320];
	if (plume_feather_find_non_finite(feather, true, what, sizeof what))
		return plume_error_set(err, PLUME_ERROR_NUMERIC,
		                       "%s: %s has a NaN or infinite number (or one past single precision, 3.4e38), which "
		                       "glTF's float accessors cannot hold",
		                       path, what);
	plume_glb glb;
	int materials[2];
	plume_status begun = begin_curves_glb(&glb, def, path, materials, err);
	if (begun != PLUME_OK)
		return begun;
	bool ok = true;
	int root = write_feather_nodes(&glb, feather, def, "feather", materials, &ok);
	plume_glb_scene_root(&glb, root);
	plume_status status =
	    ok ? plume_glb_write(&glb, path, err) : build_failure(path, too_many_vertices(feather, def, false), err);
	plume_glb_free(&glb);
	return status;
}

// ---------------------------------------------------------------------------
// Coats
//
// One feather's parts at a time in memory: a mesh is written as soon as it is built, and
// only its hash and feather are kept; a later feather with the same hash is compared with
// that feather's parts, built again.

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

static bool same_parts(const part a[PART_COUNT], const part b[PART_COUNT])
{
	for (int k = 0; k < PART_COUNT; ++k) {
		if (a[k].vertices != b[k].vertices || a[k].index_count != b[k].index_count)
			return false;
		size_t v = (size_t)a[k].vertices;
		if (v == 0)
			continue;
		if (memcmp(a[k].position, b[k].position, 3 * v * sizeof(float)) != 0 ||
		    memcmp(a[k].normal, b[k].normal, 3 * v * sizeof(float)) != 0 ||
		    memcmp(a[k].uv, b[k].uv, 2 * v * sizeof(float)) != 0 ||
		    memcmp(a[k].color, b[k].color, 4 * v * sizeof(float)) != 0 ||
		    memcmp(a[k].image_uv, b[k].image_uv, 2 * v * sizeof(float)) != 0 ||
		    memcmp(a[k].indices, b[k].indices, (size_t)a[k].index_count * sizeof(uint32_t)) != 0)
			return false;
	}
	return true;
}

/// All parts of a coat's feather and its afterfeathers, merged per part (the afterfeather's
/// barbs join its parent's vanes), relative to its follicle.
static bool build_coat_parts(const plume_coat *coat, int index, const plume_gltf_def *def, part parts[PART_COUNT])
{
	plume_vec3 follicle, normal;
	plume_coat_follicle(coat, index, &follicle, &normal);
	memset(parts, 0, PART_COUNT * sizeof *parts);
	bool ok = true;
	for (int k = 0; ok && k < PART_COUNT; ++k)
		ok = part_build(plume_coat_feather(coat, index), true, &k, 1, def, follicle, false, &parts[k]);
	return ok;
}

static void free_parts(part parts[PART_COUNT])
{
	for (int k = 0; k < PART_COUNT; ++k)
		part_free(&parts[k]);
}

static uint64_t hash_parts(const part parts[PART_COUNT])
{
	uint64_t h = 14695981039346656037ull;
	for (int k = 0; k < PART_COUNT; ++k) {
		h = hash_bytes(h, parts[k].position, 3 * (size_t)parts[k].vertices * sizeof(float));
		h = hash_bytes(h, parts[k].color, 4 * (size_t)parts[k].vertices * sizeof(float));
	}
	return h;
}

/// A mesh written: its hash, the feather it was built from, its index among the meshes.
typedef struct coat_mesh {
	uint64_t hash;
	int feather;
	int mesh;
} coat_mesh;

/// The meshes written so far, found by hash (open addressing; capacity a power of two over twice the feathers).
typedef struct mesh_table {
	coat_mesh *meshes;
	int count;
	int *slots; ///< -1 or an index into meshes
	size_t mask;
} mesh_table;

static bool table_init(mesh_table *t, int feathers)
{
	size_t capacity = 16;
	while (capacity < 2 * (size_t)feathers)
		capacity *= 2;
	t->meshes = plume_alloc((size_t)(feathers > 0 ? feathers : 1) * sizeof *t->meshes);
	t->slots = plume_alloc(capacity * sizeof *t->slots);
	t->count = 0;
	t->mask = capacity - 1;
	if (t->slots != NULL)
		for (size_t i = 0; i < capacity; ++i)
			t->slots[i] = -1;
	return t->meshes != NULL && t->slots != NULL;
}

static void table_free(mesh_table *t)
{
	plume_free(t->meshes);
	plume_free(t->slots);
}

/// The mesh whose parts equal candidate's (hash h), or -1 with *slot where to add it; *ok false
/// when memory runs out rebuilding a feather to compare.
static int table_find(const mesh_table *t, const plume_coat *coat, const plume_gltf_def *def, uint64_t h,
                      const part candidate[PART_COUNT], size_t *slot, bool *ok)
{
	size_t i = (size_t)(h ^ (h >> 32)) & t->mask;
	for (; t->slots[i] >= 0; i = (i + 1) & t->mask) {
		const coat_mesh *m = &t->meshes[t->slots[i]];
		if (m->hash != h)
			continue;
		part earlier[PART_COUNT];
		*ok = build_coat_parts(coat, m->feather, def, earlier);
		bool same = *ok && same_parts(earlier, candidate);
		free_parts(earlier);
		if (!*ok)
			return -1;
		if (same)
			return m->mesh;
	}
	*slot = i;
	return -1;
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
	if (report != NULL)
		*report = (plume_coat_glb_report){0, 0};
	int count = plume_coat_feather_count(coat);
	for (int i = 0; i < count; ++i)
		if (too_many_vertices(plume_coat_feather(coat, i), def, true))
			return build_failure(path, true, err);
	plume_glb glb;
	int materials[2];
	plume_status begun = begin_curves_glb(&glb, def, path, materials, err);
	if (begun != PLUME_OK)
		return begun;
	mesh_table table;
	bool ok = table_init(&table, count);
	json_t *children = json_array();
	ok = ok && children != NULL;
	for (int i = 0; ok && i < count; ++i) {
		part candidate[PART_COUNT];
		ok = build_coat_parts(coat, i, def, candidate);
		uint64_t h = ok ? hash_parts(candidate) : 0;
		size_t slot = 0;
		int mesh = ok ? table_find(&table, coat, def, h, candidate, &slot, &ok) : -1;
		char name[32];
		snprintf(name, sizeof name, "feather_%05d", i);
		if (ok && mesh < 0) {
			json_t *primitives = json_array();
			for (int k = 0; k < PART_COUNT; ++k)
				if (candidate[k].vertices > 0)
					json_array_append_new(primitives,
					                      part_primitive(&glb, &candidate[k], def->curves,
					                                     materials[k == PART_SHAFT ? 0 : 1], def->texture != NULL));
			mesh = plume_glb_append(&glb, glb.meshes, json_pack("{s:s, s:o}", "name", name, "primitives", primitives));
			table.meshes[table.count] = (coat_mesh){h, i, mesh};
			table.slots[slot] = table.count++;
		}
		free_parts(candidate);
		if (!ok)
			break;
		plume_vec3 follicle, normal;
		plume_coat_follicle(coat, i, &follicle, &normal);
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
	int mesh_count = table.count;
	table_free(&table);
	if (report != NULL && ok)
		*report = (plume_coat_glb_report){count, mesh_count};
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

/// The moved feather of one frame as a single part of line segments (all its parts in order),
/// its positions kept exact too.
static bool carried_lines(const plume_barb_embedding *embedding, const plume_vec3 *positions, const plume_gltf_def *def,
                          part *out)
{
	memset(out, 0, sizeof *out);
	plume_feather *moved = NULL;
	plume_error err;
	if (plume_embedding_apply(embedding, positions, &moved, &err) != PLUME_OK)
		return false;
	plume_gltf_def lines = *def;
	lines.curves = PLUME_GLTF_LINES;
	static const int kinds[PART_COUNT] = {PART_SHAFT, PART_LEFT, PART_RIGHT, PART_BARBULES};
	bool ok = part_build(moved, false, kinds, PART_COUNT, &lines, plume_v3(0, 0, 0), true, out);
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
			displacement[i] = (float)(moved.exact[i] - base.exact[i]);
		if (*ok)
			json_array_append_new(
			    targets, json_pack("{s:i}", "POSITION",
			                       plume_glb_floats_f(glb, displacement, base.vertices, 3, GLB_ARRAY_BUFFER, true)));
		part_free(&moved);
	}
	int node = 0;
	if (*ok) {
		int position = plume_glb_floats_f(glb, base.position, base.vertices, 3, GLB_ARRAY_BUFFER, true);
		int uv = plume_glb_floats_f(glb, base.uv, base.vertices, 2, GLB_ARRAY_BUFFER, false);
		int color = plume_glb_floats_f(glb, base.color, base.vertices, 4, GLB_ARRAY_BUFFER, false);
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

// Mesh specs: the mesher's definition and explicit barb guides in JSON
// (docs/meshing.md), and plume_mesh_spec_read for `plume mesh`.
//
// Splines are sampled here into polylines, which is what the mesher takes:
//   "polyline"     the points as they are;
//   "catmull-rom"  the uniform Catmull-Rom spline through the points (end
//                  tangents from mirrored end points), "samples" per span (16);
//   "bezier"       one Bézier curve of degree count - 1 with the points as its
//                  control points, "samples" points in all (64).
#define _POSIX_C_SOURCE 200809L
#include <limits.h>
#include <math.h>
#include <string.h>

#include "../core/alloc.h"
#include "plume/model.h"
#include "spec_mesh.h"

static const char *const def_keys[] = {"edge_length", "rachis_width_base", "rachis_width_tip", "include_calamus", NULL};

bool plume_spec_mesh_def(plume_spec_reader *reader, const json_t *object, const char *path, plume_mesh_def *def)
{
	if (!json_is_object(object)) {
		plume_spec_fail(reader, path, "expected an object with the mesh parameters");
		return false;
	}
	plume_spec_check_keys(reader, object, path, def_keys);
	char child[512];
	if (plume_spec_number(reader, object, path, "edge_length", &def->edge_length) &&
	    !(def->edge_length > 0.0 && isfinite(def->edge_length))) {
		plume_spec_path(child, sizeof child, path, "edge_length");
		plume_spec_fail(reader, child, "is %g, must be a positive length in metres (default 0.005)", def->edge_length);
	}
	static const char *const widths[] = {"rachis_width_base", "rachis_width_tip"};
	double *values[] = {&def->rachis_width_base, &def->rachis_width_tip};
	for (int i = 0; i < 2; ++i)
		if (plume_spec_number(reader, object, path, widths[i], values[i]) && !(*values[i] >= 0.0)) {
			plume_spec_path(child, sizeof child, path, widths[i]);
			plume_spec_fail(reader, child, "is %g, must be a width in metres >= 0 (0: the feather's shaft width)",
			                *values[i]);
		}
	plume_spec_bool(reader, object, path, "include_calamus", &def->include_calamus);
	return reader->status == PLUME_OK;
}

void plume_mesh_guides_storage_free(plume_mesh_guides_storage *storage)
{
	plume_free(storage->boundary);
	plume_free(storage->rachis);
	plume_free(storage->guide_offsets);
	plume_free(storage->guide_points);
	memset(storage, 0, sizeof *storage);
}

// ---------------------------------------------------------------------------
// Points and splines

/// A growing array of points.
typedef struct point_list {
	plume_vec2 *items;
	int count, capacity;
} point_list;

static bool push(point_list *list, plume_vec2 p)
{
	if (PLUME_GROW(list->items, list->capacity, list->count + 1) != 0)
		return false;
	list->items[list->count++] = p;
	return true;
}

/// Reads an array of at least min_count points [x, y] into a fresh list.
static bool read_points(plume_spec_reader *reader, const json_t *array, const char *path, int min_count,
                        point_list *out)
{
	memset(out, 0, sizeof *out);
	if (!json_is_array(array) || json_array_size(array) < (size_t)min_count) {
		plume_spec_fail(reader, path, "expected an array of at least %d points [x, y] in metres", min_count);
		return false;
	}
	for (size_t i = 0; i < json_array_size(array); ++i) {
		const json_t *point = json_array_get(array, i);
		char item[600];
		plume_spec_index_path(item, sizeof item, path, i);
		if (!json_is_array(point) || json_array_size(point) != 2 || !json_is_number(json_array_get(point, 0)) ||
		    !json_is_number(json_array_get(point, 1))) {
			plume_spec_fail(reader, item, "expected a point [x, y] of two numbers in metres");
			break;
		}
		plume_vec2 p = {json_number_value(json_array_get(point, 0)), json_number_value(json_array_get(point, 1))};
		if (!isfinite(p.x) || !isfinite(p.y)) {
			plume_spec_fail(reader, item, "coordinates must be finite");
			break;
		}
		if (!push(out, p)) {
			plume_spec_fail(reader, item, "out of memory");
			reader->status = reader->err != NULL ? (reader->err->status = PLUME_ERROR_MEMORY) : PLUME_ERROR_MEMORY;
			break;
		}
	}
	if (reader->status != PLUME_OK) {
		plume_free(out->items);
		memset(out, 0, sizeof *out);
		return false;
	}
	return true;
}

static plume_vec2 catmull_rom(plume_vec2 p0, plume_vec2 p1, plume_vec2 p2, plume_vec2 p3, double t)
{
	double t2 = t * t, t3 = t2 * t;
	double a = -0.5 * t3 + t2 - 0.5 * t, b = 1.5 * t3 - 2.5 * t2 + 1.0, c = -1.5 * t3 + 2.0 * t2 + 0.5 * t,
	       d = 0.5 * t3 - 0.5 * t2;
	return (plume_vec2){a * p0.x + b * p1.x + c * p2.x + d * p3.x, a * p0.y + b * p1.y + c * p2.y + d * p3.y};
}

static const char *const spline_keys[] = {"type", "points", "samples", NULL};

/// Reads a spline (array of points, or object with type/points/samples) and
/// appends its sampled polyline to out.
static bool read_spline(plume_spec_reader *reader, const json_t *value, const char *path, point_list *out)
{
	const char *type = "polyline";
	int samples = -1;
	const json_t *array = value;
	char points_path[600];
	snprintf(points_path, sizeof points_path, "%s", path);
	if (json_is_object(value)) {
		plume_spec_check_keys(reader, value, path, spline_keys);
		plume_spec_string(reader, value, path, "type", &type);
		plume_spec_int(reader, value, path, "samples", &samples);
		array = json_object_get(value, "points");
		plume_spec_path(points_path, sizeof points_path, path, "points");
		if (reader->status != PLUME_OK)
			return false;
		if (array == NULL) {
			plume_spec_fail(reader, path, "a spline needs \"points\"");
			return false;
		}
	} else if (!json_is_array(value)) {
		plume_spec_fail(reader, path,
		                "expected a spline: an array of points [x, y] or an object with \"type\" "
		                "and \"points\"");
		return false;
	}
	bool polyline = strcmp(type, "polyline") == 0, catmull = strcmp(type, "catmull-rom") == 0,
	     bezier = strcmp(type, "bezier") == 0;
	char child[620];
	if (!polyline && !catmull && !bezier) {
		plume_spec_path(child, sizeof child, path, "type");
		plume_spec_fail(reader, child, "unknown spline type \"%s\"; allowed: polyline, catmull-rom, bezier", type);
		return false;
	}
	if (samples != -1 && polyline) { // it would be ignored: the points are the polyline
		plume_spec_path(child, sizeof child, path, "samples");
		plume_spec_fail(reader, child,
		                "a polyline takes its points as they are; \"samples\" is for catmull-rom and bezier");
		return false;
	}
	if (samples != -1 && (samples < 2 || samples > 10000)) {
		plume_spec_path(child, sizeof child, path, "samples");
		plume_spec_fail(reader, child, "is %d, allowed [2, 10000]", samples);
		return false;
	}
	point_list control;
	if (!read_points(reader, array, points_path, 2, &control))
		return false;
	bool ok = true;
	if (polyline) {
		for (int i = 0; i < control.count && ok; ++i)
			ok = push(out, control.items[i]);
	} else if (catmull) {
		int per_span = samples > 0 ? samples : 16;
		int n = control.count;
		for (int s = 0; s + 1 < n && ok; ++s) {
			plume_vec2 p1 = control.items[s], p2 = control.items[s + 1];
			plume_vec2 p0 = s > 0 ? control.items[s - 1] : (plume_vec2){2.0 * p1.x - p2.x, 2.0 * p1.y - p2.y};
			plume_vec2 p3 = s + 2 < n ? control.items[s + 2] : (plume_vec2){2.0 * p2.x - p1.x, 2.0 * p2.y - p1.y};
			for (int k = 0; k < per_span && ok; ++k)
				ok = push(out, catmull_rom(p0, p1, p2, p3, (double)k / per_span));
		}
		if (ok)
			ok = push(out, control.items[n - 1]);
	} else {
		if (control.count > PLUME_BEZIER_MAX_POINTS) {
			plume_spec_fail(reader, points_path, "a Bézier spline takes at most %d control points, got %d",
			                PLUME_BEZIER_MAX_POINTS, control.count);
			plume_free(control.items);
			return false;
		}
		plume_vec3 points[PLUME_BEZIER_MAX_POINTS];
		for (int i = 0; i < control.count; ++i)
			points[i] = plume_v3(control.items[i].x, control.items[i].y, 0.0);
		int count = samples > 0 ? samples : 64;
		for (int k = 0; k < count && ok; ++k) {
			plume_vec3 p = plume_bezier_eval(points, control.count, (double)k / (count - 1));
			ok = push(out, (plume_vec2){p.x, p.y});
		}
	}
	plume_free(control.items);
	if (!ok)
		plume_spec_fail(reader, path, "out of memory");
	return ok;
}

/// The points read_spline samples value into (0 where it will refuse value: a wrong type,
/// too few points, samples outside [2, 10000]).
static double spline_sample_count(const json_t *value)
{
	if (json_is_array(value))
		return (double)json_array_size(value);
	const json_t *points = json_object_get(value, "points"), *type = json_object_get(value, "type"),
	             *samples = json_object_get(value, "samples");
	if (!json_is_object(value) || !json_is_array(points) || json_array_size(points) < 2)
		return 0.0;
	double n = (double)json_array_size(points), per = -1.0;
	if (samples != NULL) {
		if (!json_is_integer(samples) || json_integer_value(samples) < 2 || json_integer_value(samples) > 10000)
			return 0.0;
		per = (double)json_integer_value(samples);
	}
	const char *name = type == NULL ? "polyline" : json_is_string(type) ? json_string_value(type) : "";
	if (strcmp(name, "catmull-rom") == 0)
		return (n - 1.0) * (per > 0.0 ? per : 16.0) + 1.0;
	if (strcmp(name, "bezier") == 0)
		return per > 0.0 ? per : 64.0;
	return strcmp(name, "polyline") == 0 ? n : 0.0;
}

/// Refuses splines whose samples would pass max_memory (0: PLUME_DEFAULT_MAX_MEMORY) at
/// PLUME_MESH_BYTES_PER_GUIDE_POINT each, or an int's count, before any is sampled: a few
/// kilobytes of JSON ("samples": 10000 on long point lists) sampled into gigabytes. Names the
/// spline at which the running count passes the limit (PLUME_ERROR_LIMIT).
static bool check_sample_counts(plume_spec_reader *reader, const json_t *object, const char *path, uint64_t max_memory)
{
	double limit = (double)(max_memory > 0 ? max_memory : PLUME_DEFAULT_MAX_MEMORY), total = 0.0;
	const json_t *guides = json_object_get(object, "guides");
	size_t count = json_is_array(guides) ? json_array_size(guides) : 0;
	for (size_t i = 0; i <= count; ++i) {
		const json_t *spline = i == 0 ? json_object_get(object, "rachis") : json_array_get(guides, i - 1);
		total += spline_sample_count(spline);
		double bytes = total * PLUME_MESH_BYTES_PER_GUIDE_POINT;
		if (bytes <= limit && total <= INT_MAX / 2)
			continue;
		char list[520], child[560];
		plume_spec_path(list, sizeof list, path, i == 0 ? "rachis" : "guides");
		if (i > 0)
			plume_spec_index_path(child, sizeof child, list, i - 1);
		else
			snprintf(child, sizeof child, "%s", list);
		plume_spec_fail(reader, child,
		                "the splines up to here sample into %.0f points, about %.3g GB at %d B a point; the limit is "
		                "%.3g GB%s (fewer \"samples\" or points, or raise --max-memory)",
		                total, bytes / 1e9, PLUME_MESH_BYTES_PER_GUIDE_POINT, limit / 1e9,
		                total > INT_MAX / 2 ? " and 1073741823 points" : "");
		reader->status = PLUME_ERROR_LIMIT;
		if (reader->err != NULL)
			reader->err->status = PLUME_ERROR_LIMIT;
		return false;
	}
	return true;
}

plume_status plume_spec_mesh_guides(plume_spec_reader *reader, const json_t *object, const char *path,
                                    uint64_t max_memory, plume_mesh_guides_storage *storage)
{
	memset(storage, 0, sizeof *storage);
	char child[512];
	point_list boundary = {0}, rachis = {0}, guide_points = {0};
	int *offsets = NULL;
	static const char *const required[] = {"boundary", "rachis", "guides"};
	for (int i = 0; i < 3 && reader->status == PLUME_OK; ++i)
		if (json_object_get(object, required[i]) == NULL)
			plume_spec_fail(reader, path, "a guides spec needs \"%s\"", required[i]);
	if (reader->status == PLUME_OK)
		check_sample_counts(reader, object, path, max_memory);
	if (reader->status == PLUME_OK) {
		plume_spec_path(child, sizeof child, path, "boundary");
		read_points(reader, json_object_get(object, "boundary"), child, 3, &boundary);
	}
	if (reader->status == PLUME_OK) {
		plume_spec_path(child, sizeof child, path, "rachis");
		read_spline(reader, json_object_get(object, "rachis"), child, &rachis);
	}
	const json_t *guides = reader->status == PLUME_OK ? plume_spec_array(reader, object, path, "guides") : NULL;
	size_t guide_count = guides != NULL ? json_array_size(guides) : 0;
	if (reader->status == PLUME_OK && guide_count == 0)
		plume_spec_path(child, sizeof child, path, "guides"),
		    plume_spec_fail(reader, child, "needs at least one guide");
	if (reader->status == PLUME_OK) {
		offsets = plume_calloc(guide_count + 1, sizeof *offsets);
		if (offsets == NULL)
			plume_spec_fail(reader, path, "out of memory");
	}
	for (size_t g = 0; g < guide_count && reader->status == PLUME_OK; ++g) {
		plume_spec_path(child, sizeof child, path, "guides");
		char item[540];
		plume_spec_index_path(item, sizeof item, child, g);
		read_spline(reader, json_array_get(guides, g), item, &guide_points);
		offsets[g + 1] = guide_points.count;
	}
	if (reader->status != PLUME_OK) {
		plume_free(boundary.items);
		plume_free(rachis.items);
		plume_free(guide_points.items);
		plume_free(offsets);
		return reader->status;
	}
	storage->boundary = boundary.items;
	storage->rachis = rachis.items;
	storage->guide_points = guide_points.items;
	storage->guide_offsets = offsets;
	storage->guides = (plume_mesh_guides){
	    .boundary_count = boundary.count,
	    .boundary = boundary.items,
	    .rachis_count = rachis.count,
	    .rachis = rachis.items,
	    .guide_count = (int)guide_count,
	    .guide_offsets = offsets,
	    .guide_points = guide_points.items,
	};
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// plume_mesh_spec_read

plume_mesh_spec_options plume_mesh_spec_default_options(void)
{
	return (plume_mesh_spec_options){.edge_length = 0.0, .seed = 0, .seed_given = false};
}

static const char *const guides_spec_keys[] = {"description", "mesh", "boundary", "rachis", "guides", NULL};

plume_status plume_mesh_spec_read(const char *path, const plume_mesh_spec_options *options, plume_mesh **out,
                                  plume_mesh_report *report, plume_error *err)
{
	*out = NULL;
	json_t *root = plume_spec_load(path, err);
	if (root == NULL)
		return err != NULL ? err->status : PLUME_ERROR_IO;
	plume_mesh_def def = plume_mesh_default_def();
	def.max_memory = options->max_memory;
	plume_status status = PLUME_OK;
	if (json_is_object(root) && json_object_get(root, "guides") != NULL) {
		plume_spec_reader reader = plume_spec_reader_begin(path, err);
		plume_spec_check_keys(&reader, root, "$", guides_spec_keys);
		const char *description;
		plume_spec_string(&reader, root, "$", "description", &description);
		const json_t *mesh = plume_spec_object(&reader, root, "$", "mesh");
		if (mesh != NULL)
			plume_spec_mesh_def(&reader, mesh, "$.mesh", &def);
		plume_mesh_guides_storage storage = {0};
		if (reader.status == PLUME_OK)
			plume_spec_mesh_guides(&reader, root, "$", def.max_memory, &storage);
		status = reader.status;
		if (status == PLUME_OK) {
			if (options->edge_length > 0.0)
				def.edge_length = options->edge_length;
			status = plume_mesh_from_guides(&storage.guides, &def, out, report, err);
			if (status != PLUME_OK)
				plume_error_prefix(err, path);
		}
		plume_mesh_guides_storage_free(&storage);
	} else {
		plume_spec_options spec_options = {
		    .seed = options->seed, .seed_given = options->seed_given, .max_memory = options->max_memory};
		plume_feather *feather = NULL;
		status = plume_spec_generate(path, &spec_options, &feather, err);
		if (status == PLUME_OK) {
			if (options->edge_length > 0.0)
				def.edge_length = options->edge_length;
			status = plume_mesh_from_feather(feather, &def, out, report, err);
			if (status != PLUME_OK)
				plume_error_prefix(err, path);
		}
		plume_feather_destroy(feather);
	}
	json_decref(root);
	return status;
}

// What the geometry exporters share: buffered atomic text files in the "C"
// numeric locale, and the curves that make up one exported object.
#define _POSIX_C_SOURCE 200809L
#include "export.h"

#include <math.h>

#include "../core/alloc.h"
#include "../model/feather_internal.h"

// Big enough that stdio writes in large blocks (the default is 4 KiB), small
// enough not to matter next to the feather being written.
enum { TEXT_BUFFER_SIZE = 1 << 20 };

plume_status plume_text_open(plume_text_file *text, const char *path, plume_error *err)
{
	text->stream = NULL;
	text->buffer = NULL;
	text->c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
	if (text->c_locale == (locale_t)0)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory", path);
	plume_status status = plume_atomic_open(&text->file, path, err);
	if (status != PLUME_OK) {
		freelocale(text->c_locale);
		return status;
	}
	text->stream = text->file.stream;
	// Without the buffer stdio still works, only with smaller writes.
	text->buffer = plume_alloc(TEXT_BUFFER_SIZE);
	if (text->buffer != NULL)
		setvbuf(text->stream, text->buffer, _IOFBF, TEXT_BUFFER_SIZE);
	text->saved_locale = uselocale(text->c_locale);
	return PLUME_OK;
}

plume_status plume_text_close(plume_text_file *text, plume_status status, plume_error *err)
{
	uselocale(text->saved_locale);
	freelocale(text->c_locale);
	// The stream is closed (in commit or abort) before its buffer is freed.
	if (status == PLUME_OK)
		status = plume_atomic_commit(&text->file, err);
	else
		plume_atomic_abort(&text->file);
	plume_free(text->buffer);
	text->buffer = NULL;
	text->stream = NULL;
	return status;
}

void plume_obj_polyline(FILE *stream, long long first, int count)
{
	for (int j = 0; j + 1 < count; ++j)
		fprintf(stream, "l %lld %lld\n", first + j, first + j + 1);
}

int plume_curve_set_range(const plume_feather *feather, plume_curve_set set)
{
	return set == PLUME_CURVES_BARBULES ? feather->barbule_count : feather->barb_count;
}

bool plume_curve_set_get(const plume_feather *feather, plume_curve_set set, int i, plume_polyline *curve)
{
	if (set == PLUME_CURVES_BARBULES) {
		*curve = plume_feather_barbule(feather, i).curve;
	} else {
		plume_barb barb = plume_feather_barb(feather, i);
		if ((set == PLUME_CURVES_LEFT && barb.side != PLUME_SIDE_LEFT) ||
		    (set == PLUME_CURVES_RIGHT && barb.side != PLUME_SIDE_RIGHT))
			return false;
		*curve = barb.curve;
	}
	return curve->count >= 2;
}

void plume_curve_set_count(const plume_feather *feather, plume_curve_set set, int *curves, int64_t *points)
{
	*curves = 0;
	*points = 0;
	int range = plume_curve_set_range(feather, set);
	plume_polyline curve;
	for (int i = 0; i < range; ++i) {
		if (plume_curve_set_get(feather, set, i, &curve)) {
			++*curves;
			*points += curve.count;
		}
	}
}

static bool number_fits(double value, bool single) { return single ? isfinite((float)value) : isfinite(value); }

static bool vec_fits(plume_vec3 v, bool single)
{
	return number_fits(v.x, single) && number_fits(v.y, single) && number_fits(v.z, single);
}

static bool find_non_finite(const plume_feather *feather, bool single, const char *prefix, char *what, size_t size)
{
	int count = plume_feather_get_info(feather).shaft_sample_count;
	const plume_shaft_sample *shaft = plume_feather_shaft(feather);
	for (int i = 0; i < count; ++i)
		if (!vec_fits(shaft[i].position, single) || !vec_fits(shaft[i].tangent, single) ||
		    !vec_fits(shaft[i].normal, single) || !vec_fits(shaft[i].binormal, single) ||
		    !number_fits(shaft[i].width, single) || !number_fits(shaft[i].t, single)) {
			snprintf(what, size, "%sshaft sample %d", prefix, i);
			return true;
		}
	static const plume_curve_set sets[] = {PLUME_CURVES_BARBS, PLUME_CURVES_BARBULES};
	static const char *const names[] = {"barb", "barbule"};
	for (int k = 0; k < 2; ++k) {
		int range = plume_curve_set_range(feather, sets[k]);
		plume_polyline curve;
		for (int i = 0; i < range; ++i) {
			if (!plume_curve_set_get(feather, sets[k], i, &curve))
				continue;
			for (int j = 0; j < curve.count; ++j)
				if (!vec_fits(curve.points[j], single) || !vec_fits(curve.normals[j], single) ||
				    !number_fits(curve.widths[j], single) || !number_fits(curve.uv[j].x, single) ||
				    !number_fits(curve.uv[j].y, single)) {
					snprintf(what, size, "%s%s %d (point %d)", prefix, names[k], i, j);
					return true;
				}
		}
	}
	const plume_feather *after = plume_feather_afterfeather(feather);
	if (after == NULL)
		return false;
	if (!isfinite(plume_feather_afterfeather_t(feather))) {
		snprintf(what, size, "%safterfeather's attach_t", prefix);
		return true;
	}
	char longer[256];
	snprintf(longer, sizeof longer, "%safterfeather's ", prefix);
	return find_non_finite(after, single, longer, what, size);
}

bool plume_feather_find_non_finite(const plume_feather *feather, bool single_precision, char *what, size_t size)
{
	return find_non_finite(feather, single_precision, "", what, size);
}

int plume_mesh_find_non_finite(const plume_mesh *mesh, const plume_vec3 *positions, bool single_precision)
{
	const plume_vec3 *x = positions != NULL ? positions : mesh->rest;
	for (int i = 0; i < mesh->vertex_count; ++i)
		if (!vec_fits(x[i], single_precision) || (mesh->uv != NULL && !(number_fits(mesh->uv[i].x, single_precision) &&
		                                                                number_fits(mesh->uv[i].y, single_precision))))
			return i;
	return -1;
}

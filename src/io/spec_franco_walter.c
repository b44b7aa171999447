// Franco–Walter specs: JSON keys are the fields of plume_fw_def (docs/spec-franco-walter.md).
#include <string.h>

#include "spec.h"
#include "spec_models.h"

static const char *const top_keys[] = {
    "model",
    "seed",
    "shaft",
    "left_outline",
    "right_outline",
    "calamus_fraction",
    "segments",
    "second_segment_start",
    "shaft_samples",
    "barb_samples",
    "shaft_width_base",
    "shaft_width_tip",
    "barb_width_base",
    "barb_width_tip",
    "description",
    NULL,
};

static const char *const segment_keys[] = {
    "barb_count", "length_variation", "shape_variation", "symmetric_vanes", "uniform_shape", "uniform_length", NULL,
};

static void read_segment(plume_spec_reader *reader, const json_t *object, const char *path, plume_fw_segment *segment)
{
	if (!json_is_object(object)) {
		plume_spec_fail(reader, path, "expected an object with the segment's parameters");
		return;
	}
	plume_spec_check_keys(reader, object, path, segment_keys);
	plume_spec_int(reader, object, path, "barb_count", &segment->barb_count);
	plume_spec_number(reader, object, path, "length_variation", &segment->length_variation);
	plume_spec_number(reader, object, path, "shape_variation", &segment->shape_variation);
	plume_spec_bool(reader, object, path, "symmetric_vanes", &segment->symmetric_vanes);
	plume_spec_bool(reader, object, path, "uniform_shape", &segment->uniform_shape);
	plume_spec_bool(reader, object, path, "uniform_length", &segment->uniform_length);
}

plume_status plume_fw_def_from_json(const char *file, const json_t *root, plume_fw_def *def, uint64_t *seed,
                                    plume_error *err)
{
	*def = plume_fw_default_def();
	*seed = 1;
	plume_spec_reader reader = plume_spec_reader_begin(file, err);
	plume_spec_check_keys(&reader, root, "$", top_keys);
	plume_spec_uint64(&reader, root, "$", "seed", seed);
	plume_spec_points2(&reader, root, "$", "shaft", def->shaft, 4);
	bool left_given = plume_spec_points2(&reader, root, "$", "left_outline", def->left_outline, 5);
	bool right_given = plume_spec_points2(&reader, root, "$", "right_outline", def->right_outline, 5);
	// A spec that shapes only the left vane gets its mirror image on the right;
	// one that shapes neither keeps the default feather's two outlines.
	def->mirror_right_outline = left_given && !right_given;
	plume_spec_number(&reader, root, "$", "calamus_fraction", &def->calamus_fraction);
	plume_spec_number(&reader, root, "$", "second_segment_start", &def->second_segment_start);
	plume_spec_int(&reader, root, "$", "shaft_samples", &def->shaft_samples);
	plume_spec_int(&reader, root, "$", "barb_samples", &def->barb_samples);
	plume_spec_number(&reader, root, "$", "shaft_width_base", &def->shaft_width_base);
	plume_spec_number(&reader, root, "$", "shaft_width_tip", &def->shaft_width_tip);
	plume_spec_number(&reader, root, "$", "barb_width_base", &def->barb_width_base);
	plume_spec_number(&reader, root, "$", "barb_width_tip", &def->barb_width_tip);
	const char *description;
	plume_spec_string(&reader, root, "$", "description", &description);

	const json_t *segments = plume_spec_array(&reader, root, "$", "segments");
	if (segments != NULL) {
		if (json_array_size(segments) != 2) {
			plume_spec_fail(&reader, "$.segments",
			                "expected 2 segments (below and above second_segment_start), got %zu",
			                json_array_size(segments));
		}
		for (size_t i = 0; i < 2 && reader.status == PLUME_OK; ++i) {
			char path[64];
			plume_spec_index_path(path, sizeof path, "$.segments", i);
			read_segment(&reader, json_array_get(segments, i), path, def->segments + i);
		}
	}
	if (reader.status != PLUME_OK)
		return reader.status;
	// Ranges are the library's own check; its messages already name the JSON path.
	plume_status status = plume_fw_def_validate(def, err);
	if (status != PLUME_OK)
		plume_error_prefix(err, file);
	return status;
}

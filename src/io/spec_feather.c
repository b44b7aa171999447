// Feather specs: the "model" key picks the generator.
#include <string.h>

#include "spec.h"
#include "spec_models.h"

static const char *const model_names[] = {"franco-walter", NULL};

plume_status plume_fw_def_read(const char *path, plume_fw_def *def, uint64_t *seed, plume_error *err)
{
	json_t *root = plume_spec_load(path, err);
	if (root == NULL)
		return err != NULL ? err->status : PLUME_ERROR_IO;
	plume_status status;
	if (!json_is_object(root))
		status = plume_error_set(err, PLUME_ERROR_SPEC, "%s: $: expected an object with a \"model\" key", path);
	else
		status = plume_fw_def_from_json(path, root, def, seed, err);
	json_decref(root);
	return status;
}

plume_status plume_spec_generate(const char *path, const plume_spec_options *options, plume_feather **out,
                                 plume_error *err)
{
	*out = NULL;
	json_t *root = plume_spec_load(path, err);
	if (root == NULL)
		return err != NULL ? err->status : PLUME_ERROR_IO;
	plume_spec_reader reader = plume_spec_reader_begin(path, err);
	const char *model = NULL;
	if (!json_is_object(root))
		plume_spec_fail(&reader, "$", "expected an object with a \"model\" key");
	else if (!plume_spec_string(&reader, root, "$", "model", &model) && reader.status == PLUME_OK)
		plume_spec_fail(&reader, "$.model", "missing; a spec names its generator (one of: franco-walter)");

	plume_status status = reader.status;
	if (status == PLUME_OK && strcmp(model, "franco-walter") == 0) {
		plume_fw_def def;
		uint64_t seed;
		status = plume_fw_def_from_json(path, root, &def, &seed, err);
		if (status == PLUME_OK) {
			if (options != NULL && options->seed_given)
				seed = options->seed;
			status = plume_fw_generate(&def, seed, out, err);
		}
	} else if (status == PLUME_OK) {
		plume_spec_fail(&reader, "$.model", "unknown model \"%s\"; did you mean \"%s\"? (known: franco-walter)", model,
		                plume_spec_nearest(model, model_names));
		status = reader.status;
	}
	json_decref(root);
	return status;
}

// Feather specs: the "model" key picks the generator.
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "spec.h"
#include "spec_models.h"

typedef struct model_entry {
	const char *name;
	plume_spec_generate_fn generate;
} model_entry;

static const model_entry models[] = {
    {"franco-walter", plume_fw_spec_generate},
    {"streit-heidrich", plume_sh_spec_generate},
    {"zhang-kanai", plume_zk_spec_generate},
};
enum { MODEL_COUNT = sizeof models / sizeof models[0] };
static const char *const model_names[] = {"franco-walter", "streit-heidrich", "zhang-kanai", NULL};
#define MODEL_LIST "franco-walter, streit-heidrich, zhang-kanai"

plume_status plume_fw_def_read(const char *path, plume_fw_def *def, uint64_t *seed, plume_error *err)
{
	plume_status status;
	json_t *root = plume_spec_load_model(path, &status, err);
	if (root == NULL)
		return status;
	status = plume_fw_def_from_json(path, root, def, seed, err);
	json_decref(root);
	return status;
}

double plume_spec_memory_limit(const plume_spec_options *options)
{
	return (double)(options != NULL && options->max_memory > 0 ? options->max_memory : PLUME_DEFAULT_MAX_MEMORY);
}

plume_status plume_spec_check_feather_bytes(const char *file, double bytes, const plume_spec_options *options,
                                            plume_error *err, const char *keys, ...)
{
	double limit = plume_spec_memory_limit(options);
	if (bytes <= limit)
		return PLUME_OK;
	char what[512];
	va_list args;
	va_start(args, keys);
	vsnprintf(what, sizeof what, keys, args);
	va_end(args);
	return plume_error_set(err, PLUME_ERROR_LIMIT,
	                       "%s: %s make a feather of about %.3g GB; the limit is %.3g GB (raise it with --max-memory, "
	                       "or lower them)",
	                       file, what, bytes / 1e9, limit / 1e9);
}

plume_status plume_fw_spec_generate(const char *file, const json_t *root, const plume_spec_options *options,
                                    plume_feather **out, plume_error *err)
{
	if (options != NULL && options->stage_kind != PLUME_STAGE_FULL)
		return plume_error_set(err, PLUME_ERROR_UNSUPPORTED,
		                       "%s: the franco-walter model has no growth or unfurling stages "
		                       "(streit-heidrich and zhang-kanai do)",
		                       file);
	plume_fw_def def;
	uint64_t seed;
	plume_status status = plume_fw_def_from_json(file, root, &def, &seed, err);
	if (status != PLUME_OK)
		return status;
	if (options != NULL && options->seed_given)
		seed = options->seed;
	// A def out of its ranges gets its range message, not the limit's.
	double bytes = plume_fw_estimate_bytes(&def);
	if (!(bytes <= plume_spec_memory_limit(options)) && (status = plume_fw_def_validate(&def, err)) != PLUME_OK)
		return status;
	if ((status = plume_spec_check_feather_bytes(
	         file, bytes, options, err,
	         "$.segments[*].barb_count (%d and %d barbs a vane) x $.barb_samples (%d) and "
	         "$.shaft_samples (%d)",
	         def.segments[0].barb_count, def.segments[1].barb_count, def.barb_samples, def.shaft_samples)) != PLUME_OK)
		return status;
	return plume_fw_generate(&def, seed, out, err);
}

plume_status plume_spec_generate_json(const char *file, const json_t *root, const plume_spec_options *options,
                                      plume_feather **out, plume_error *err)
{
	*out = NULL;
	plume_spec_reader reader = plume_spec_reader_begin(file, err);
	const char *model = NULL;
	if (!json_is_object(root))
		plume_spec_fail(&reader, "$", "expected an object with a \"model\" key");
	else if (!plume_spec_string(&reader, root, "$", "model", &model) && reader.status == PLUME_OK)
		plume_spec_fail(&reader, "$.model", "missing; a spec names its generator (one of: " MODEL_LIST ")");
	if (reader.status != PLUME_OK)
		return reader.status;
	for (int i = 0; i < MODEL_COUNT; ++i)
		if (strcmp(model, models[i].name) == 0)
			return models[i].generate(file, root, options, out, err);
	if (strcmp(model, "coat") == 0) {
		plume_spec_fail(&reader, "$.model",
		                "\"coat\" is a coat spec, not a feather: use `plume coat %s -o DIR` (docs/coats.md)", file);
		return reader.status;
	}
	plume_spec_fail(&reader, "$.model", "unknown model \"%s\"; did you mean \"%s\"? (known: " MODEL_LIST ")", model,
	                plume_spec_nearest(model, model_names));
	return reader.status;
}

plume_status plume_spec_generate(const char *path, const plume_spec_options *options, plume_feather **out,
                                 plume_error *err)
{
	*out = NULL;
	json_t *root = plume_spec_load(path, err);
	if (root == NULL)
		return err != NULL ? err->status : PLUME_ERROR_IO;
	plume_status status = plume_spec_generate_json(path, root, options, out, err);
	json_decref(root);
	return status;
}

plume_status plume_spec_parse(const char *text, const char *name, const plume_spec_options *options,
                              plume_feather **out, plume_error *err)
{
	*out = NULL;
	json_error_t error;
	json_t *root = json_loads(text, JSON_REJECT_DUPLICATES, &error);
	if (root == NULL)
		return plume_error_set(err, PLUME_ERROR_SYNTAX, "%s:%d:%d: %s", name, error.line, error.column, error.text);
	plume_status status = plume_spec_generate_json(name, root, options, out, err);
	json_decref(root);
	return status;
}

// Private: each generator's spec reader, for the "model" dispatch in spec_feather.c.
#ifndef PLUME_SPEC_MODELS_H
#define PLUME_SPEC_MODELS_H

#include <jansson.h>

#include "plume/model.h"

/// Reads a parsed Franco–Walter spec into def (starting from the defaults) and
/// its seed (1 when absent); validates the ranges.
plume_status plume_fw_def_from_json(const char *file, const json_t *root, plume_fw_def *def, uint64_t *seed,
                                    plume_error *err);

/// Each generator's spec entry point: reads the parsed spec (root is an object
/// whose "model" names this generator), applies options (seed override,
/// development stage) and generates. file names the spec in error messages.
typedef plume_status (*plume_spec_generate_fn)(const char *file, const json_t *root, const plume_spec_options *options,
                                               plume_feather **out, plume_error *err);

/// Generates the feather of a parsed spec, dispatching on its "model" key.
plume_status plume_spec_generate_json(const char *file, const json_t *root, const plume_spec_options *options,
                                      plume_feather **out, plume_error *err);

/// --max-memory from options, PLUME_DEFAULT_MAX_MEMORY when unset, in bytes.
double plume_spec_memory_limit(const plume_spec_options *options);

/// PLUME_ERROR_LIMIT when a feather estimated at bytes before the work passes options' --max-memory
/// (PLUME_DEFAULT_MAX_MEMORY when unset): "file: KEYS make a feather of about X GB; the limit is Y GB
/// (raise it with --max-memory, or lower them)", keys formatted like printf.
plume_status plume_spec_check_feather_bytes(const char *file, double bytes, const plume_spec_options *options,
                                            plume_error *err, const char *keys, ...);

plume_status plume_fw_spec_generate(const char *file, const json_t *root, const plume_spec_options *options,
                                    plume_feather **out, plume_error *err);
plume_status plume_sh_spec_generate(const char *file, const json_t *root, const plume_spec_options *options,
                                    plume_feather **out, plume_error *err);
plume_status plume_zk_spec_generate(const char *file, const json_t *root, const plume_spec_options *options,
                                    plume_feather **out, plume_error *err);

#endif

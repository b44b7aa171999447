// Private: each generator's spec reader, for the "model" dispatch in spec_feather.c.
#ifndef PLUME_SPEC_MODELS_H
#define PLUME_SPEC_MODELS_H

#include <jansson.h>

#include "plume/model.h"

/// Reads a parsed Franco–Walter spec into def (starting from the defaults) and
/// its seed (1 when absent); validates the ranges.
plume_status plume_fw_def_from_json(const char *file, const json_t *root, plume_fw_def *def, uint64_t *seed,
                                    plume_error *err);

#endif

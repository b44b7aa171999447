// Private: reading streit-heidrich specs, for the feather dispatch and for coats.
#ifndef PLUME_SPEC_STREIT_HEIDRICH_H
#define PLUME_SPEC_STREIT_HEIDRICH_H

#include <jansson.h>

#include "plume/streit_heidrich.h"

/// Reads a parsed streit-heidrich spec (root an object) into def, seed (1 when absent) and lod (the
/// defaults when absent; may be NULL). file names the spec in messages and is the base of relative paths
/// (scans, blended feathers); base is root's JSON path in file, "$" for a spec of its own and, say,
/// "$.blend.feathers[0]" for an inline one, which messages start from. depth counts nested blends (0 at
/// the top).
plume_status plume_sh_def_from_json(const char *file, const json_t *root, const char *base, plume_sh_def *def,
                                    uint64_t *seed, plume_sh_lod *lod, int depth, plume_error *err);

/// Writes into out the path of name relative to the folder of file (name itself when absolute).
void plume_spec_relative_path(char *out, size_t size, const char *file, const char *name);

#endif

// Private: the pieces of the Streit–Heidrich generator shared by its files
// (key barbs and blending, generation, scans).
#ifndef PLUME_STREIT_HEIDRICH_INTERNAL_H
#define PLUME_STREIT_HEIDRICH_INTERNAL_H

#include "plume/streit_heidrich.h"

/// Entries in the precomputed table of Bdf1's random control vertices (4.3.1).
#define SH_BDF1_TABLE 64

/// The key barbs a feather actually interpolates between (4.2.1): its own key
/// barbs, clamped, with Bdf1 added at rp = 0 when none is below and Bdf2 at
/// rp = 1 when none is above (Bdf1 at both ends when there are none). Bdf1 is
/// stored as zero control vertices with plumulaceous weight 1: the barb's own
/// table entry is added at generation (sh_barb_cvs), which keeps every
/// interpolation linear. The list always starts at rp = 0 and ends at rp = 1.
typedef struct sh_key_list {
	int count;
	plume_sh_key_barb keys[PLUME_SH_MAX_KEY_BARBS + 2];
} sh_key_list;

/// Bdf1's table: SH_BDF1_TABLE cubic barbs drawn from the seed.
typedef struct sh_bdf1_table {
	plume_vec3 cvs[SH_BDF1_TABLE][4];
} sh_bdf1_table;

void sh_bdf1_table_init(sh_bdf1_table *table, uint64_t seed);

/// Builds the effective key list of params (see sh_key_list).
void sh_key_list_build(const plume_sh_params *params, sh_key_list *list);

/// Control vertices of the barb at rp in the barb frame (eq. 1 with degree
/// elevation and Bdf1's table entry for barb_index). Returns the count.
int sh_barb_cvs(const sh_key_list *list, const sh_bdf1_table *table, double rp, int barb_index, plume_vec3 *cvs);

/// Elevates a curve of count points to target points (target >= count,
/// target <= PLUME_BEZIER_MAX_POINTS) in place; cvs must hold target points.
void sh_elevate_to(plume_vec3 *cvs, int count, int target);

/// plume_sh_default_afterfeather written into after (a different object than main), without the copy of
/// returning it.
void sh_default_afterfeather(const plume_sh_params *main, plume_sh_params *after);

/// Barb length of a profile at rp, m.
double sh_profile_eval(const plume_sh_length_profile *profile, double rp);

/// A profile holding one constant length.
plume_sh_length_profile sh_profile_constant(double length);

/// Barb angle of params at rp on a side (linear from base to tip), radians.
double sh_barb_angle(const plume_sh_params *params, plume_side side, double rp);

/// Validates one feather's parameters; prefix is the JSON path of the object holding them ("$" or
/// "$.afterfeather").
plume_status sh_params_validate(const plume_sh_params *params, const char *prefix, plume_error *err);

#endif

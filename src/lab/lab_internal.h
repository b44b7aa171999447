// Internal to the lab: the mean traction curve over band phases, with progress counted.
#ifndef PLUME_LAB_INTERNAL_H
#define PLUME_LAB_INTERNAL_H

#include "plume/lab.h"

/// A running count of traction tests for a plume_progress_fn; total may be raised as a
/// search goes on.
typedef struct plume_lab_progress {
	plume_progress_fn *fn; ///< NULL: nothing is reported
	void *user;
	int done;
	int total;
} plume_lab_progress;

/// plume_lab_mean_slope, with each run's slope in phase_slopes (phase_count of them for the
/// mesoscale model, one for the macroscale; may be NULL), and when stress is not NULL the
/// curve (def->steps + 1 samples): strain (may be NULL) and the stress averaged over the
/// phases. progress (may be NULL) counts each run.
plume_status lab_mean_curve(const plume_lab_material *material, const plume_sample_def *sample,
                            const plume_traction_def *def, int phase_count, double *slope, double *phase_slopes,
                            int *solve_count, double *strain, double *stress, plume_lab_progress *progress,
                            plume_error *err);

#endif

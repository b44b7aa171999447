// plume — feather generators.
//
// Each generator takes a definition struct (start from its *_default_def()
// and change fields) and a seed, and creates a plume_feather.
#ifndef PLUME_MODEL_H
#define PLUME_MODEL_H

#include "plume/feather.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

// ---------------------------------------------------------------------------
// Franco & Walter 2002, "Modeling and Rendering of Individual Feathers", section 4.
//
// A cubic Bézier shaft, two vane outlines as quartic Béziers (five control
// points) and, on each vane, barbs as cubic Béziers from the rachis to the
// outline, perturbed by seven parameters (Table 1). The shaft is split at I_s
// into two segments with their own parameters.
//
// Correspondence (the paper leaves it open): barb k of a vane sits at the
// vane fraction q in [0, 1], evenly spaced in arc length over each segment.
// Its root P0 is the rachis point at arc-length fraction q of the vaned part of
// the shaft (above the calamus) and its unperturbed tip P3 the outline point at
// arc-length fraction q of the outline. Outlines therefore start near the
// vane's base and end at the tip; where they start sets the barbs' slant.

#define PLUME_FW_MAX_BARBS 5000

/// Parameters of one segment (one row of the paper's Table 2).
typedef struct plume_fw_segment {
	/// N_b: barbs on each vane in this segment, [0, 5000]. Default 100.
	int barb_count;
	/// F_pv: each barb's length is scaled by 1 + r, r uniform in [-F_pv, F_pv]; [0, 1]. Default 0.05.
	double length_variation;
	/// F_b: control points P1 and P2 move by up to F_b d (d = |P3 - P0|); [0, 1]. Default 0.3.
	double shape_variation;
	/// S_v: both vanes use the same random values, so the right vane mirrors the left. Default true.
	bool symmetric_vanes;
	/// U_f: the four shape values are drawn once per segment, so every barb has the same
	/// shape relative to its endpoints. Default true.
	bool uniform_shape;
	/// U_c: the length value is drawn once per segment. Default false.
	bool uniform_length;
} plume_fw_segment;

typedef struct plume_fw_def {
	/// Shaft (calamus + rachis) as a cubic Bézier in the feather plane, m, base first.
	/// Default: 0.2 m, from (0, 0) to (0.004, 0.2), gently curved towards +x.
	plume_vec2 shaft[4];
	/// Left vane outline (x < 0 side), quartic Bézier, m, from the vane's base to the tip.
	plume_vec2 left_outline[5];
	/// Right vane outline. Ignored when mirror_right_outline is true.
	plume_vec2 right_outline[5];
	/// Use the mirror image of left_outline across the shaft's chord (base to tip)
	/// as the right outline. Default true.
	bool mirror_right_outline;
	/// Fraction of the shaft's length, from the base, that is bare calamus; [0, 0.95]. Default 0.15.
	double calamus_fraction;
	/// Segment parameters: [0] below I_s, [1] above it. Defaults: Table 2's hawk rows,
	/// {200, 0.2, 0.3, F, F, F} and {2000, 0.03, 0.2, T, T, F}.
	plume_fw_segment segments[2];
	/// I_s: vane fraction where the second segment starts; [0, 1]. Default 0.2.
	double second_segment_start;
	/// Samples along the shaft, [2, 100000]. Default 100.
	int shaft_samples;
	/// Samples along each barb, [2, 1000]. Default 30 (paper, section 4.4).
	int barb_samples;
	/// Shaft diameter at the base and at the tip, m, > 0. Defaults 3e-3 and 4e-4.
	double shaft_width_base;
	double shaft_width_tip;
	/// Barb width at its root and at its tip, m, > 0. Defaults 1.5e-4 and 3e-5.
	double barb_width_base;
	double barb_width_tip;
	/// PLUME_DEF_COOKIE, set by plume_fw_default_def; do not change.
	uint32_t cookie;
} plume_fw_def;

/// A 0.2 m contour feather close to the paper's hawk feather (Table 2).
plume_fw_def plume_fw_default_def(void);

/// Checks every field against its range. Messages name the field as a JSON
/// path of the spec ("$.segments[1].barb_count is 6000, allowed [0, 5000]").
plume_status plume_fw_def_validate(const plume_fw_def *def, plume_error *err);

/// Bytes the feather of def takes, counted before the work: its points (the shaft's
/// shaft_samples and barb_samples for each barb of both vanes) times the feather's five
/// per-point arrays (position, normal, arc length, width, uv).
double plume_fw_estimate_bytes(const plume_fw_def *def);

/// Generates the feather. Same def and seed, same bytes, on every machine.
plume_status plume_fw_generate(const plume_fw_def *def, uint64_t seed, plume_feather **out, plume_error *err);

// ---------------------------------------------------------------------------
// Specs: JSON files with a "model" key naming the generator.

/// Which development stage plume_spec_generate builds.
typedef enum plume_stage_kind {
	/// The finished feather (default).
	PLUME_STAGE_FULL = 0,
	/// A growth stage: stage 0 is the start of growth, 1 the finished feather
	/// (Streit–Heidrich 4.2.4; Zhang–Kanai t_curr over the growth period).
	PLUME_STAGE_GROWTH,
	/// An unfurling stage (Zhang–Kanai IV-B): stage is the weight w, 0 the helix in the follicle.
	PLUME_STAGE_UNFURL,
} plume_stage_kind;

/// Options for plume_spec_generate. Zero-initialised options mean: the spec's
/// seed, the finished feather.
typedef struct plume_spec_options {
	/// Overrides the spec's "seed" key when seed_given is true.
	uint64_t seed;
	bool seed_given;
	/// Development stage to build; a model without that kind of stage fails with PLUME_ERROR_UNSUPPORTED.
	plume_stage_kind stage_kind;
	/// Stage in [0, 1] for PLUME_STAGE_GROWTH and PLUME_STAGE_UNFURL.
	double stage;
	/// Bytes the model may build (estimated before the work; PLUME_ERROR_LIMIT past it). 0 means
	/// PLUME_DEFAULT_MAX_MEMORY, so that a zero-initialised options struct keeps working.
	uint64_t max_memory;
	/// Coats (plume_coat_spec_generate): called after each feather is built. Default NULL (none).
	plume_progress_fn *progress;
	void *progress_user;
} plume_spec_options;


/// Reads a feather spec from path and generates it. Syntax errors read
/// "path:line:column: ..."; value errors "path: $.key.path: ...".
plume_status plume_spec_generate(const char *path, const plume_spec_options *options, plume_feather **out,
                                 plume_error *err);

/// The same from JSON text (a feather spec in memory, e.g. from a binding); name stands for
/// the file in messages ("name:line:column: ..." and "name: $.key.path: ...").
plume_status plume_spec_parse(const char *text, const char *name, const plume_spec_options *options,
                              plume_feather **out, plume_error *err);

/// Reads a Franco–Walter spec into def and its seed (1 when absent).
plume_status plume_fw_def_read(const char *path, plume_fw_def *def, uint64_t *seed, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_MODEL_H

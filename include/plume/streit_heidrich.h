// plume — Streit & Heidrich 2002, "A Biologically-Parameterized Feather Model".
//
// A feather is designed from a few parameters (Table 1) and a handful of key
// barbs; every other barb is interpolated between the key barbs above and
// below it (section 4.2.1, eq. 1). Feather types blend by interpolating all
// parameters and key barbs (4.2.3); growth stages follow the staggered
// schedule of Figure 6 (4.2.4); an afterfeather with its own parameters grows
// where the calamus meets the rachis.
//
// Frames. The paper builds the rachis along its z axis; plume's feather frame
// has the shaft along +y, the left vane on -x and the front (dorsal side) on +z
// (feather.h). The paper's rachis control vertex (a, b, c), a = rvdc rl
// (front-to-back), b = rlc rl (side-to-side), c along the rachis, is plume's
// (x, y, z) = (b, c, a).
//
// A key barb's control vertices are given in the barb's own frame, in units of
// the barb's length: +x from the rachis outwards along the barb, +y in the vane
// plane towards the feather's tip, +z to the front. The frame is mirrored
// between the vanes, so one key barb shapes both vanes alike.
//
// Barb angles are measured in the vane plane between the barb and the rachis
// below its root: 90 degrees is perpendicular to the rachis, 180 degrees lies
// along the rachis towards the tip (the closed barbs of a growing feather,
// Figure 6's "fixed (180 degrees)").
#ifndef PLUME_STREIT_HEIDRICH_H
#define PLUME_STREIT_HEIDRICH_H

#include "plume/feather.h"
#include "plume/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

/// Most control vertices of one key barb (degree 31).
#define PLUME_SH_MAX_CVS 32
/// Most key barbs of one feather (Table 1's m + 1). A spec may give 30: blending makes the default key
/// barbs Bdf1 and Bdf2 explicit and needs the two places left.
#define PLUME_SH_MAX_KEY_BARBS 32
/// Most points of a barb-length profile (silhouette points or scan samples).
#define PLUME_SH_MAX_PROFILE 160
/// Most barbs on one vane.
#define PLUME_SH_MAX_BARBS 4000

/// One key barb B_j (Table 1): control vertices and position on the rachis.
typedef struct plume_sh_key_barb {
	/// rp: position along the rachis, arc-length fraction, [0, 1]; key barbs are in non-decreasing order.
	double position;
	/// n + 1: number of control vertices, [2, PLUME_SH_MAX_CVS].
	int cv_count;
	/// cv_i in the barb frame, units of barb length. |cv_0 - cv_n| is clamped to [0, 1] (4.1):
	/// a larger distance is scaled back to 1 about cv_0.
	plume_vec3 cvs[PLUME_SH_MAX_CVS];
	/// Weight of the default key barb Bdf1's random control vertices added to cvs (0 for a key barb
	/// given by its control vertices). Blended feathers carry Bdf1's share here. [0, 1]. Default 0.
	double plumulaceous;
} plume_sh_key_barb;

/// Barb length along the rachis for one vane (4.1: "constant or defined by a
/// set of silhouette boundary points"): length[i] metres at rachis fraction
/// position[i], linear in between, constant beyond the ends.
typedef struct plume_sh_length_profile {
	/// Number of points, [1, PLUME_SH_MAX_PROFILE]; one point is a constant length.
	int count;
	double position[PLUME_SH_MAX_PROFILE]; ///< rp, strictly increasing in [0, 1]
	double length[PLUME_SH_MAX_PROFILE];   ///< m, >= 0
} plume_sh_length_profile;

/// The parameters of one feather (Table 1), shared by the main feather and its afterfeather.
typedef struct plume_sh_params {
	/// cl: calamus length, m, >= 0. Default 0.012.
	double calamus_length;
	/// cwr: calamus width at its base over its width where it meets the rachis (= rachis_width), > 0. Default 1.2.
	double calamus_width_ratio;
	/// rl: rachis length, m, > 0. Default 0.1.
	double rachis_length;
	/// rw: rachis width at its base, m, > 0. Default 2e-3. The rachis tapers to a point (4.1).
	double rachis_width;
	/// rlc: side-to-side rachis curvature, units of rl, [-1, 1]. Default 0.04.
	double rachis_side_curvature;
	/// rvdc: front-to-back rachis curvature, units of rl, [-1, 1]; negative bends towards the back. Default -0.03.
	double rachis_front_curvature;
	/// Barb length on the left and right vane (silhouette), m. Default: an ovate 0.035 m vane.
	plume_sh_length_profile barb_length[2];
	/// vlba, vlta, vrba, vrta: barb angles at the rachis base and tip of each vane ([side][0 base, 1 tip]),
	/// radians in (0, pi]. Defaults 2.4 (137.5 degrees) at the base and 2.75 (157.6 degrees) at the tip.
	double barb_angle[2][2];
	/// spb, spt: distance between neighbouring barbs along the rachis at its base and tip, m, > 0, the same on
	/// both vanes. Defaults 8e-4 and 5e-4.
	double spacing_base;
	double spacing_tip;
	/// m + 1 key barbs, [0, PLUME_SH_MAX_KEY_BARBS], in order of position; none gives an entirely plumulaceous (down)
	/// vane. Default: a slightly curved pennaceous barb at 0.3 and a straighter one at 0.9.
	int key_barb_count;
	plume_sh_key_barb key_barbs[PLUME_SH_MAX_KEY_BARBS];
} plume_sh_params;

/// Texture coordinate modes (4.3.3). (s, t) land in each barb point's uv.
typedef enum plume_sh_texture_mode {
	/// On the barb: s the arc-length fraction along the barb, t the root's shaft fraction. Follows the barb
	/// whatever its angle or curvature.
	PLUME_SH_TEXTURE_BARB = 0,
	/// On the vane: s the point's distance from the rachis over the feather's largest barb length, t its height
	/// along the rachis over the rachis length, both ignoring rachis curvature. The texture stays put while barbs
	/// change ("swims on top of the barbs").
	PLUME_SH_TEXTURE_VANE = 1,
	/// Relative to growth: s the position around the sheath's circular cross-section (0 at the rachis, 1 at the
	/// opposite side; the two vanes take the two halves), t the time at which the point left the collar, 0 at the
	/// tip (the oldest part) and 1 at the base.
	PLUME_SH_TEXTURE_GROWTH = 2,
} plume_sh_texture_mode;

typedef struct plume_sh_def {
	/// The main feather's parameters (Table 1).
	plume_sh_params main;
	/// Attach an afterfeather where the calamus meets the rachis (3.1). Default false.
	bool has_afterfeather;
	/// The afterfeather's parameters ("the same parameters as the main feather", 4.1). Default: a plumulaceous
	/// feather 0.4 times the main one's size, no calamus.
	plume_sh_params afterfeather;
	/// Barb width at the root and at the tip, m, > 0 (drawing; not in Table 1). Defaults 1e-4 and 2.5e-5.
	double barb_width_base;
	double barb_width_tip;
	/// Texture coordinate mode. Default PLUME_SH_TEXTURE_BARB.
	plume_sh_texture_mode texture_mode;
	/// PLUME_DEF_COOKIE, set by plume_sh_default_def; do not change.
	uint32_t cookie;
} plume_sh_def;

/// A 0.1 m contour feather: pennaceous above a plumulaceous base.
plume_sh_def plume_sh_default_def(void);

/// Default afterfeather parameters for a main feather: plumulaceous, 0.4 of its size.
plume_sh_params plume_sh_default_afterfeather(const plume_sh_params *main);

/// Checks every field; messages name the spec's JSON path ("$.key_barbs[2].position is 1.2, allowed [0, 1]").
plume_status plume_sh_def_validate(const plume_sh_def *def, plume_error *err);

/// Level of detail (4.3.2): tessellation by degree elevation of the rachis and barb curves. Chosen per call,
/// never stored in a definition.
typedef struct plume_sh_lod {
	/// Degree elevations of each barb curve; its polyline is the elevated control polygon. [0, 60]. Default 8
	/// (a cubic barb becomes 12 points). 0 draws the key barb's own control vertices (Figure 8, left).
	int barb_elevations;
	/// Degree elevations of the cubic rachis, [0, 60]. Default 36 (40 points).
	int rachis_elevations;
	/// Samples along the straight calamus, [2, 64]. Default 4.
	int calamus_samples;
} plume_sh_lod;

plume_sh_lod plume_sh_default_lod(void);

/// Generates the feather at a growth stage (4.2.4, Figure 6): stage in [0, 1], 1 the finished feather.
/// Same def, seed and stage, same bytes. The seed fixes the table of Bdf1's random control vertices.
plume_status plume_sh_generate(const plume_sh_def *def, uint64_t seed, double stage, plume_feather **out,
                               plume_error *err);

/// Bytes the feather of def takes at lod (NULL: plume_sh_default_lod()), counted before the work and
/// never below the built feather's: per feather (main, afterfeather) the barbs a vane can hold (the
/// rachis's control polygon, which no Bezier arc outruns, over the smaller spacing; at most
/// PLUME_SH_MAX_BARBS) times the points of a barb (the widest key barb, Bdf1/Bdf2's four control
/// vertices included, plus the elevations), and the shaft. Past any limit for a def that does not validate.
double plume_sh_estimate_bytes(const plume_sh_def *def, const plume_sh_lod *lod);

/// plume_sh_generate with an explicit level of detail (lod NULL: plume_sh_default_lod()).
plume_status plume_sh_generate_lod(const plume_sh_def *def, uint64_t seed, double stage, const plume_sh_lod *lod,
                                   plume_feather **out, plume_error *err);

/// The shaft of a generated feather as a generalized cylinder (4.3.1): a ring of sides vertices around each
/// shaft sample (radius half its width, in the plane of its normal and binormal), joined by triangles.
/// sides in [3, 256]; 3 is Figure 8's triangle cross-section. A level of detail chosen per call (4.3.2).
plume_status plume_sh_shaft_mesh(const plume_feather *feather, int sides, plume_mesh **out, plume_error *err);

/// Reads a streit-heidrich spec (docs/spec-streit-heidrich.md) into def, its seed (1 when absent) and its level
/// of detail (the defaults when absent); lod may be NULL.
plume_status plume_sh_def_read(const char *path, plume_sh_def *def, uint64_t *seed, plume_sh_lod *lod,
                               plume_error *err);

/// Feather types (4.2.3): out = sum_i weights[i] defs[i] over every parameter and key barb. Key barbs are
/// first completed with the default key barbs each feather uses (Bdf1 below, Bdf2 above), then the smaller
/// sets are inflated, by inserting key barbs that their own interpolation already gives, until all have as
/// many; key barb k of each feather blends with key barb k of the others. Weights must be >= 0 with a
/// positive sum (they are normalized). Non-numeric fields (texture mode) come from the heaviest feather.
plume_status plume_sh_def_blend(const plume_sh_def *const *defs, const double *weights, int count, plume_sh_def *out,
                                plume_error *err);

/// Two-feather case of plume_sh_def_blend: (1 - t) a + t b, t in [0, 1].
plume_status plume_sh_def_interpolate(const plume_sh_def *a, const plume_sh_def *b, double t, plume_sh_def *out,
                                      plume_error *err);

/// Where a scanned feather lies in its image (4.2.2).
typedef struct plume_sh_scan_def {
	/// Pixel coordinates (x right, y down, pixel centres at +0.5) of the rachis base and tip. Their distance is
	/// the rachis length rl in the image and sets the scale.
	double base_px[2];
	double tip_px[2];
	/// Luminance in [0, 1] below which a pixel is feather (the background is light). <= 0: Otsu's threshold.
	/// Default 0 (Otsu).
	double threshold;
	/// Rachis positions sampled along the rachis, [2, PLUME_SH_MAX_PROFILE]. Default 101.
	int samples;
} plume_sh_scan_def;

plume_sh_scan_def plume_sh_default_scan_def(void);

/// Barb lengths from a scan (4.2.2): segments the image (PNG, JPEG, ...) into feather and light
/// background, then for each sampled rachis position and each vane takes the distance from the rachis to
/// the farthest feather pixel along the barb's direction (the barb angles of params). Fills
/// params->barb_length[both vanes] in metres.
plume_status plume_sh_scan_barb_lengths(const char *image_path, const plume_sh_scan_def *scan, plume_sh_params *params,
                                        plume_error *err);

/// Generates the barb control vertices of barb at rachis fraction rp on the given side, in the barb's frame
/// (before scaling by length and rotation), as generation does: eq. 1 between the key barbs around rp,
/// with the defaults Bdf1/Bdf2 and degree elevation. barb_index picks Bdf1's random table entry. Writes up to
/// PLUME_SH_MAX_CVS points to cvs and returns their count. For tests and tools.
int plume_sh_barb_cvs(const plume_sh_params *params, uint64_t seed, double rp, int barb_index, plume_vec3 *cvs);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_STREIT_HEIDRICH_H

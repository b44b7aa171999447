// Private: what the barb-aligned mesher reads, whatever made it (a feather or
// explicit guides). guides.c builds it; aligned.c meshes it.
//
// Everything lives in the feather plane: a point's (x, y) is its reference
// (material) position and its z the height of the rest shape above it, so the
// rest shape is a height field over the reference (Jouve thesis 6.2).
#ifndef PLUME_MESH_ALIGNED_INTERNAL_H
#define PLUME_MESH_ALIGNED_INTERNAL_H

#include "plume/mesh.h"

/// Samples per guide, equally spaced in plane arc length from root to tip.
enum { MESH_GUIDE_SAMPLES = 33 };

/// One barb guide: a barb, or the average of the barbs rooted within one edge
/// length of each other along the rachis.
typedef struct mesh_guide {
	double sigma; ///< root position: plane arc length along the rachis centre line, m
	int weight;   ///< input barbs averaged into it
	plume_vec3 p[MESH_GUIDE_SAMPLES];
	plume_vec2 uv[MESH_GUIDE_SAMPLES];
} mesh_guide;

/// The rachis centre line, base first, with strictly increasing sigma.
typedef struct mesh_centre {
	int count;
	plume_vec3 *p;       ///< (x, y) reference, z rest height
	plume_vec2 *tangent; ///< unit, in the plane, towards the tip
	double *sigma;       ///< plane arc length from the base, m
	double *width;       ///< shaft diameter, m
	double *t;           ///< shaft parameter (texture v), 0 at the base, 1 at the tip
	double *lift;        ///< height change per unit of leftward offset (binormal z / |binormal xy|)
} mesh_centre;

typedef struct mesh_input {
	mesh_centre rachis;
	mesh_guide *guides[2]; ///< per side, sorted by sigma, consecutive ones not crossing
	int guide_count[2];
	/// Root range of the usable input barbs per side; the vane spans these rows.
	double sigma_first[2], sigma_last[2];
	double width_base, width_tip; ///< band width at the vane base and at the tip, m
	const plume_vec2 *boundary;   ///< closed polygon clipping the guides, or NULL
	int boundary_count;
	int guides_dropped; ///< input barbs left out (crossing, zero length, non-finite)
	int barbs_averaged; ///< input barbs averaged with a neighbour into one guide
} mesh_input;

void mesh_input_free(mesh_input *input);

/// Reads a feather's shaft and barbs. Fails when the shaft is shorter than two samples.
plume_status mesh_input_from_feather(const plume_feather *feather, const plume_mesh_def *def, mesh_input *input,
                                     plume_error *err);

/// Reads explicit guides (rachis polyline, barb guide polylines, boundary polygon).
plume_status mesh_input_from_guides(const plume_mesh_guides *guides, const plume_mesh_def *def, mesh_input *input,
                                    plume_error *err);

/// Point of the centre line at plane arc length sigma (clamped to its ends):
/// position, unit tangent, width, shaft parameter and lift.
void mesh_centre_eval(const mesh_centre *centre, double sigma, plume_vec3 *p, plume_vec2 *tangent, double *width,
                      double *t, double *lift);

/// True when the open polylines a and b (plane coordinates) properly cross.
bool mesh_polylines_cross(const plume_vec3 *a, int a_count, const plume_vec3 *b, int b_count);

/// Per face, the bit k set when corner k of a vane face lies between its barb
/// edge and an edge on the vane's border (an edge of one vane face: against the
/// rachis band, or on the outline): the angle between a guide and the rachis or
/// the outline, a junction angle (plume_mesh_measure). NULL out of memory;
/// plume_free it.
unsigned char *mesh_junction_corners(const plume_mesh *mesh);

/// plume_mesh_measure, or false when out of memory (the junction faces need the
/// vane's edges sorted): the mesher fails then rather than report less.
bool mesh_measure(const plume_mesh *mesh, plume_mesh_report *out);

#endif

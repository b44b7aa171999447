// Private: the pieces of the ray tracer (camera, shading, Embree scene).
#ifndef PLUME_RAYTRACE_INTERNAL_H
#define PLUME_RAYTRACE_INTERNAL_H

#include <embree3/rtcore.h>

#include "plume/raytrace.h"

// ---------------------------------------------------------------------------
// Camera (camera.c)

/// A resolved camera: an orthonormal basis and the image plane's half extents.
typedef struct rt_camera {
	plume_vec3 eye;
	plume_vec3 forward, right, up;  ///< unit; right x up = -forward
	double half_width, half_height; ///< perspective: tangents of the half angles; orthographic: m
	bool orthographic;
	int width, height;
} rt_camera;

/// Checks a resolved (non-automatic) camera; fills err naming the bad field.
plume_status rt_camera_check(const plume_camera *camera, plume_error *err);

rt_camera rt_camera_make(const plume_camera *camera);

/// The ray through image point (x, y) in pixels (0, 0 the top-left corner, y down).
void rt_camera_ray(const rt_camera *camera, double x, double y, plume_vec3 *origin, plume_vec3 *direction);

// ---------------------------------------------------------------------------
// Shading (shading.c). Colours are linear RGB in a plume_vec3 (x = r).

/// sRGB-encoded channel in [0, 1] to linear light (IEC 61966-2-1).
double rt_srgb_to_linear(double c);
/// Linear light in [0, 1] to an sRGB-encoded byte, rounded.
uint8_t rt_linear_to_srgb_byte(double c);
plume_vec3 rt_color_linear(plume_color c);

/// Fiber parameters taken from the render def.
typedef struct rt_fiber {
	plume_shading_model model;
	double diffuse, specular, kk_exponent;
	double lobe_shift, lobe_width, trt_weight;
	double transmission;
} rt_fiber;

rt_fiber rt_fiber_from_def(const plume_raytrace_def *def);

/// Light reflected (or transmitted) towards v by a fiber with unit tangent t and unit normal n (facing v),
/// lit from unit direction l with unit radiance, for albedo (linear). Includes the cosine factor.
plume_vec3 rt_fiber_shade(const rt_fiber *fiber, plume_vec3 t, plume_vec3 n, plume_vec3 v, plume_vec3 l,
                          plume_vec3 albedo);

// ---------------------------------------------------------------------------
// Scene (raytrace_scene.c)

typedef enum rt_kind {
	RT_BARBS = 0,
	RT_SHAFT = 1,
	RT_BARBULES = 2,
	RT_SHELL = 3,
} rt_kind;

/// Per primitive of a curve geometry: the curve (barb, barbule; 0 for the shaft) and its segment's first point.
typedef struct rt_segment {
	int curve;
	int point;
} rt_segment;

/// What one Embree geometry holds.
typedef struct rt_geometry {
	rt_kind kind;
	const plume_feather *feather;
	RTCGeometry handle;
	rt_segment *segments; ///< per primitive (curves), NULL for the shell
	int segment_count;
} rt_geometry;

typedef struct rt_scene {
	RTCDevice device;
	RTCScene scene;
	rt_geometry *geometries;
	int geometry_count, geometry_capacity;
	plume_vec3 lo, hi; ///< bounds of the feathers and the shell
	int curve_segments, triangles;
	bool barbules;
	const plume_texture *texture;
} rt_scene;

/// Builds the Embree scene. barbules: whether to add barbules.
plume_status rt_scene_build(rt_scene *out, const plume_raytrace_scene *scene, const plume_texture *texture,
                            bool barbules, plume_error *err);
void rt_scene_destroy(rt_scene *scene);

#endif

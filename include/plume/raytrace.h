// plume — ray-traced rendering with Embree (issue 7).
//
// A scene is a set of feathers (barbs as flat ribbons facing their normals,
// the shaft as a round tube, barbules as thin camera-facing strips) and an
// optional triangle shell, over an optional ground plane. Barbs and the shaft
// are shaded with a fiber model (Kajiya & Kay 1989, or two longitudinal lobes
// after Marschner et al. 2003) plus transmission through the vane, shadows
// and ambient occlusion; pixels are jittered supersamples, gamma-encoded to
// sRGB. Every pixel draws its random numbers from its own generator seeded
// by (seed, pixel index), so the bytes do not depend on the thread count.
//
// Colours given by the caller are sRGB with straight alpha (plume_color); the
// renderer converts them to linear light, shades, and encodes the result.
#ifndef PLUME_RAYTRACE_H
#define PLUME_RAYTRACE_H

#include "plume/feather.h"
#include "plume/mesh.h"
#include "plume/render.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

// ---------------------------------------------------------------------------
// Camera

typedef struct plume_camera {
	/// Place the camera automatically (eye, target, up, ortho_height ignored): looking at the centre of
	/// the scene's bounds from view_direction, far enough that the bounds fit with margin. Default true.
	bool automatic;
	/// Camera position, target point and up vector, m. Used when automatic is false.
	plume_vec3 eye;
	plume_vec3 target;
	plume_vec3 up; ///< default (0, 1, 0): the feather's shaft points up the image
	/// Automatic framing: direction from the target towards the eye. Default (0, 0, 1), the feather's front.
	plume_vec3 view_direction;
	/// Vertical field of view, radians, in (0, pi). Default 30 degrees.
	double fov;
	/// Orthographic projection (parallel rays along the view direction). Default false.
	bool orthographic;
	/// Orthographic: visible height at the target, m; <= 0 with automatic framing means "fit". Default 0.
	double ortho_height;
	/// Image size in pixels, each in [16, 16384]. Default 800 x 800.
	int width;
	int height;
	/// Automatic framing: empty border, fraction of the smaller image side, [0, 0.45). Default 0.05.
	double margin;
	/// Turntable: rotation of the eye about the up axis through the target, radians. Default 0.
	double turntable;
} plume_camera;

plume_camera plume_camera_default(void);

/// The camera with automatic framing resolved for the axis-aligned box [lo, hi]
/// (automatic becomes false, eye/target/up/ortho_height filled, the turntable
/// angle applied and reset to 0). A camera that is not automatic only gets its turntable applied.
plume_camera plume_camera_frame_bounds(const plume_camera *camera, plume_vec3 lo, plume_vec3 hi);

// ---------------------------------------------------------------------------
// Lights and render settings

#define PLUME_RAYTRACE_MAX_LIGHTS 8

/// A distant light (the sun, a studio softbox far away).
typedef struct plume_light {
	/// Direction from the scene towards the light (any length > 0).
	plume_vec3 direction;
	/// Colour (sRGB) and intensity (multiplies the colour; 1 lights a white surface facing it to white).
	plume_color color;
	double intensity;
	/// Angular radius of the light's disc, radians, [0, 0.5]: soft shadows. Default 0.05 (about 3 degrees).
	double angle;
} plume_light;

typedef enum plume_shading_model {
	/// Kajiya & Kay 1989: diffuse sin(T, L), specular (cos(T,L) cos(T,V) + sin(T,L) sin(T,V))^p.
	PLUME_SHADING_KAJIYA_KAY = 0,
	/// Two longitudinal Gaussian lobes after Marschner et al. 2003: R (white, shifted by alpha) and
	/// TRT (tinted, shifted by -3 alpha / 2, twice as wide), plus Kajiya–Kay diffuse.
	PLUME_SHADING_MARSCHNER = 1,
} plume_shading_model;

typedef enum plume_barbule_mode {
	PLUME_BARBULES_OFF = 0,
	PLUME_BARBULES_ON = 1,
	/// Barbules only at close range: when a barb at the target is at least barbule_min_px pixels wide.
	PLUME_BARBULES_AUTO = 2,
} plume_barbule_mode;

typedef struct plume_raytrace_def {
	plume_camera camera;
	/// Lights; default: a key light from the upper front left and a weaker fill from the back right.
	int light_count;
	plume_light lights[PLUME_RAYTRACE_MAX_LIGHTS];
	/// Sky colour for ambient light (sRGB) and its intensity. Default pale blue-grey, 0.35.
	plume_color sky_color;
	double sky_intensity;
	/// Samples per pixel (jittered, stratified when a square), [1, 4096]. Default 16.
	int spp;
	/// Seed of the per-pixel generators. Default 1.
	uint64_t seed;
	/// Background (sRGB, straight alpha; alpha 0 gives a transparent PNG). Default opaque white.
	plume_color background;
	/// Ground plane: a plane facing ground_normal just behind the scene's bounds, receiving shadows.
	/// Default true, normal (0, 0, 1) (the feather lies on a table and is seen from above).
	bool ground;
	plume_vec3 ground_normal;
	/// Gap between the scene's bounds and the ground, fraction of the bounds' diagonal, >= 0. Default 0.02.
	double ground_gap;
	plume_color ground_color; ///< default light grey (0.85, 0.85, 0.83)
	/// Fiber shading model for barbs and the shaft. Default PLUME_SHADING_MARSCHNER.
	plume_shading_model shading;
	/// Barb colour when there is no texture (sRGB). Default hawk brown (0.45, 0.33, 0.22).
	plume_color barb_color;
	/// Shaft colour when there is no texture. Default pale horn (0.78, 0.72, 0.62).
	plume_color shaft_color;
	/// Shell (triangle mesh) colour. Default (0.70, 0.62, 0.50).
	plume_color shell_color;
	/// When not NULL, barbs take their colour from it by their (s, t) (Franco & Walter 4.4), and the shaft
	/// takes the colour at the rachis (s = 0). Texels with alpha below 0.5 are holes (a cut-out).
	const plume_texture *texture;
	/// Barbules: off, on, or at close range. Default PLUME_BARBULES_AUTO with barbule_min_px 4.
	plume_barbule_mode barbules;
	double barbule_min_px;
	/// Diffuse weight of fibers, [0, 1]. Default 0.8.
	double diffuse;
	/// Specular weight of the R lobe (Kajiya–Kay: the specular term), >= 0. Default 0.25.
	double specular;
	/// Kajiya–Kay specular exponent, > 0. Default 40.
	double kk_exponent;
	/// Marschner: longitudinal shift alpha of the R lobe, radians (cuticle tilt; Marschner et al. 2003
	/// Table 1 gives -10 to -5 degrees for hair). Default -5 degrees.
	double lobe_shift;
	/// Marschner: longitudinal width beta of the R lobe, radians (5 to 10 degrees for hair). Default 8 degrees.
	double lobe_width;
	/// Marschner: weight of the tinted TRT lobe, >= 0. Default 0.35.
	double trt_weight;
	/// Fraction of light passing through a barb to its unlit side (the vane is translucent), [0, 1].
	/// Default 0.35.
	double transmission;
	/// Ambient occlusion rays per sample (0: none) and their length as a fraction of the bounds'
	/// diagonal. Default 1 and 0.05.
	int ao_samples;
	double ao_distance;
	/// Cast shadow rays towards the lights. Default true.
	bool shadows;
	/// OpenMP threads; 0 means OpenMP's default. The image does not depend on it. Default 0.
	int threads;
	/// PLUME_DEF_COOKIE, set by plume_raytrace_default_def; do not change.
	uint32_t cookie;
} plume_raytrace_def;

plume_raytrace_def plume_raytrace_default_def(void);

/// What to render: feathers (their afterfeathers included) and an optional shell.
typedef struct plume_raytrace_scene {
	int feather_count;
	const plume_feather *const *feathers;
	/// Optional triangle shell, drawn at shell_positions (its rest positions when NULL).
	const plume_mesh *shell;
	const plume_vec3 *shell_positions;
} plume_raytrace_scene;

/// Figures of one render.
typedef struct plume_raytrace_stats {
	int curve_segments;   ///< barb, shaft and barbule segments in the scene
	int triangles;        ///< shell and ground triangles
	bool barbules;        ///< whether barbules were drawn
	double build_seconds; ///< scene construction (Embree BVH build)
	double render_seconds;
} plume_raytrace_stats;

/// Axis-aligned bounds of the scene's feathers and shell (not the ground).
void plume_raytrace_scene_bounds(const plume_raytrace_scene *scene, plume_vec3 *lo, plume_vec3 *hi);

/// Renders into rgba: camera.width * camera.height pixels, 4 bytes each (sRGB, straight alpha), rows top
/// first. Errors (nothing written to rgba's caller-visible files; rgba contents unspecified):
/// PLUME_ERROR_SPEC for a bad def, a camera inside the scene's bounds or one that sees none of it;
/// PLUME_ERROR_MEMORY; PLUME_ERROR_UNSUPPORTED when Embree fails. stats may be NULL.
plume_status plume_raytrace_render(const plume_raytrace_scene *scene, const plume_raytrace_def *def, uint8_t *rgba,
                                   plume_raytrace_stats *stats, plume_error *err);

/// Bytes that rendering `images` images of def's camera size takes, about: 8 B a pixel while one
/// renders (its RGBA buffer and the PNG encoder's surface), 4 B a pixel for each image written (a
/// PNG is at most about its raw pixels) and 4 B a pixel for each of `held` images kept in memory
/// together (a strip of frames). Callers compare it with their limit before the work (docs/cli.md).
double plume_raytrace_estimate_bytes(const plume_raytrace_def *def, int images, int held);

/// Renders and writes a PNG atomically: the file appears whole or not at all.
plume_status plume_raytrace_render_png(const plume_raytrace_scene *scene, const plume_raytrace_def *def,
                                       const char *path, plume_raytrace_stats *stats, plume_error *err);

/// Writes width x height RGBA8 pixels (straight alpha, rows top first) as a PNG, atomically.
plume_status plume_write_rgba_png(int width, int height, const uint8_t *rgba, const char *path, plume_error *err);

/// Reads camera and light settings from a JSON file into def (keys absent keep def's values):
/// {"camera": {"eye", "target", "up", "view_direction", "fov_deg", "orthographic", "ortho_height",
/// "size": [w, h], "margin", "turntable_deg"}, "lights": [{"direction", "color", "intensity",
/// "angle_deg"}], "spp", "seed", "background", "sky_color", "sky_intensity", "ground", "ground_normal",
/// "ground_gap", "ground_color", "shading": "marschner" | "kajiya-kay", "barbules": "off" | "on" | "auto",
/// "barb_color", "shaft_color", "shell_color", "transmission", "ao_samples", "ao_distance", "shadows"}.
/// A camera with "eye" or "target" is not automatic. Errors read "file: $.json.path: what is allowed".
plume_status plume_raytrace_def_read(const char *path, plume_raytrace_def *def, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_RAYTRACE_H

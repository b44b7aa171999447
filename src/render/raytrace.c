// The ray tracer: settings, checks, the pixel loop and PNG output.
//
// Each pixel averages spp jittered samples (stratified on a grid when spp is
// a square). A sample's primary ray finds the nearest barb, shaft, barbule or
// shell triangle (Embree) or the ground plane (analytic, so rays that miss
// the feather never traverse a huge ground triangle), then gathers the lights
// through shadow rays and the sky through ambient-occlusion rays. Samples are
// accumulated premultiplied in linear light and encoded to sRGB at the end.
#include <math.h>
#include <omp.h>
#include <string.h>

#include <cairo.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "render/cairo_png.h"
#include "render/raytrace_internal.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

plume_raytrace_def plume_raytrace_default_def(void)
{
	plume_raytrace_def def = {
	    .cookie = PLUME_DEF_COOKIE,
	    .camera = plume_camera_default(),
	    .light_count = 2,
	    .sky_color = {0.78, 0.84, 0.92, 1.0},
	    .sky_intensity = 0.35,
	    .spp = 16,
	    .seed = 1,
	    .background = {1.0, 1.0, 1.0, 1.0},
	    .ground = true,
	    .ground_normal = {0.0, 0.0, 1.0},
	    .ground_gap = 0.02,
	    .ground_color = {0.85, 0.85, 0.83, 1.0},
	    .shading = PLUME_SHADING_MARSCHNER,
	    .barb_color = {0.45, 0.33, 0.22, 1.0},
	    .shaft_color = {0.78, 0.72, 0.62, 1.0},
	    .shell_color = {0.70, 0.62, 0.50, 1.0},
	    .texture = NULL,
	    .barbules = PLUME_BARBULES_AUTO,
	    .barbule_min_px = 4.0,
	    .diffuse = 0.8,
	    .specular = 0.25,
	    .kk_exponent = 40.0,
	    .lobe_shift = -5.0 * DEG,
	    .lobe_width = 8.0 * DEG,
	    .trt_weight = 0.35,
	    .transmission = 0.35,
	    .ao_samples = 1,
	    .ao_distance = 0.05,
	    .shadows = true,
	    .threads = 0,
	};
	// Key light from the upper front left, fill from the right and behind (it shines through the vane).
	def.lights[0] = (plume_light){{-0.45, 0.55, 1.0}, {1.0, 0.97, 0.92, 1.0}, 1.6, 0.05};
	def.lights[1] = (plume_light){{0.8, 0.3, -0.35}, {0.85, 0.9, 1.0, 1.0}, 0.6, 0.08};
	return def;
}

// ---------------------------------------------------------------------------
// Checks

static plume_status check_color(const char *name, plume_color c, plume_error *err)
{
	const double channels[4] = {c.r, c.g, c.b, c.a};
	for (int i = 0; i < 4; ++i)
		if (!(channels[i] >= 0.0 && channels[i] <= 1.0))
			return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: %s channel %d is %g, allowed [0, 1]", name, i,
			                       channels[i]);
	return PLUME_OK;
}

static bool finite_nonzero(plume_vec3 v)
{
	double length = plume_v3_length(v);
	return length > 0.0 && isfinite(length);
}

static plume_status check_range(const char *name, double value, double lo, double hi, plume_error *err)
{
	if (!(value >= lo && value <= hi))
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: %s is %g, allowed [%g, %g]", name, value, lo, hi);
	return PLUME_OK;
}

static plume_status validate_def(const plume_raytrace_def *def, plume_error *err)
{
	plume_status status;
	if ((status = rt_camera_check(&def->camera, err)) != PLUME_OK)
		return status;
	if (def->light_count < 0 || def->light_count > PLUME_RAYTRACE_MAX_LIGHTS)
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: light_count is %d, allowed [0, %d]", def->light_count,
		                       PLUME_RAYTRACE_MAX_LIGHTS);
	for (int i = 0; i < def->light_count; ++i) {
		const plume_light *l = def->lights + i;
		if (!finite_nonzero(l->direction))
			return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: light %d direction must be a non-zero vector", i);
		if ((status = check_color("light color", l->color, err)) != PLUME_OK ||
		    (status = check_range("light intensity", l->intensity, 0.0, 1e6, err)) != PLUME_OK ||
		    (status = check_range("light angle (radians)", l->angle, 0.0, 0.5, err)) != PLUME_OK)
			return status;
	}
	if ((status = check_color("sky_color", def->sky_color, err)) != PLUME_OK ||
	    (status = check_range("sky_intensity", def->sky_intensity, 0.0, 1e6, err)) != PLUME_OK ||
	    (status = check_color("background", def->background, err)) != PLUME_OK ||
	    (status = check_color("ground_color", def->ground_color, err)) != PLUME_OK ||
	    (status = check_color("barb_color", def->barb_color, err)) != PLUME_OK ||
	    (status = check_color("shaft_color", def->shaft_color, err)) != PLUME_OK ||
	    (status = check_color("shell_color", def->shell_color, err)) != PLUME_OK ||
	    (status = check_range("ground_gap", def->ground_gap, 0.0, 1e6, err)) != PLUME_OK ||
	    (status = check_range("diffuse", def->diffuse, 0.0, 1.0, err)) != PLUME_OK ||
	    (status = check_range("specular", def->specular, 0.0, 1e3, err)) != PLUME_OK ||
	    (status = check_range("kk_exponent", def->kk_exponent, 1e-3, 1e6, err)) != PLUME_OK ||
	    (status = check_range("lobe_shift (radians)", def->lobe_shift, -0.5, 0.5, err)) != PLUME_OK ||
	    (status = check_range("lobe_width (radians)", def->lobe_width, 1e-3, 1.0, err)) != PLUME_OK ||
	    (status = check_range("trt_weight", def->trt_weight, 0.0, 1e3, err)) != PLUME_OK ||
	    (status = check_range("transmission", def->transmission, 0.0, 1.0, err)) != PLUME_OK ||
	    (status = check_range("ao_distance", def->ao_distance, 1e-6, 1e3, err)) != PLUME_OK ||
	    (status = check_range("barbule_min_px", def->barbule_min_px, 0.0, 1e6, err)) != PLUME_OK)
		return status;
	if (def->ground && !finite_nonzero(def->ground_normal))
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: ground_normal must be a non-zero vector");
	if (def->spp < 1 || def->spp > 4096)
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: spp is %d, allowed [1, 4096]", def->spp);
	if (def->ao_samples < 0 || def->ao_samples > 64)
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: ao_samples is %d, allowed [0, 64]", def->ao_samples);
	if (def->threads < 0)
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: threads is %d, must be >= 0", def->threads);
	if (def->shading != PLUME_SHADING_KAJIYA_KAY && def->shading != PLUME_SHADING_MARSCHNER)
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: unknown shading model %d", (int)def->shading);
	if (def->barbules != PLUME_BARBULES_OFF && def->barbules != PLUME_BARBULES_ON &&
	    def->barbules != PLUME_BARBULES_AUTO)
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: unknown barbule mode %d", (int)def->barbules);
	return PLUME_OK;
}

/// Slab test of the ray against the box; true when it enters the box at some t in [0, t_max].
static bool ray_hits_box_before(plume_vec3 o, plume_vec3 d, plume_vec3 lo, plume_vec3 hi, double t_max)
{
	double t0 = 0.0, t1 = t_max;
	const double os[3] = {o.x, o.y, o.z}, ds[3] = {d.x, d.y, d.z}, los[3] = {lo.x, lo.y, lo.z},
	             his[3] = {hi.x, hi.y, hi.z};
	for (int a = 0; a < 3; ++a) {
		if (ds[a] == 0.0) {
			if (os[a] < los[a] || os[a] > his[a])
				return false;
			continue;
		}
		double ta = (los[a] - os[a]) / ds[a], tb = (his[a] - os[a]) / ds[a];
		if (ta > tb) {
			double swap = ta;
			ta = tb;
			tb = swap;
		}
		t0 = fmax(t0, ta);
		t1 = fmin(t1, tb);
		if (t0 > t1)
			return false;
	}
	return true;
}

static bool ray_hits_box(plume_vec3 o, plume_vec3 d, plume_vec3 lo, plume_vec3 hi)
{
	return ray_hits_box_before(o, d, lo, hi, INFINITY);
}

/// A camera inside the scene's bounds, or one whose pixels all miss them, is an input error.
static plume_status check_view(const rt_camera *camera, plume_vec3 lo, plume_vec3 hi, plume_error *err)
{
	plume_vec3 e = camera->eye;
	bool inside = e.x > lo.x && e.x < hi.x && e.y > lo.y && e.y < hi.y && e.z > lo.z && e.z < hi.z;
	if (inside && !camera->orthographic)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "raytrace: the camera at (%g, %g, %g) is inside the scene's bounds [%g, %g] x [%g, %g] "
		                       "x [%g, %g] m; move the eye out of the feather",
		                       e.x, e.y, e.z, lo.x, hi.x, lo.y, hi.y, lo.z, hi.z);
	// A box thinner than a pixel (a flat feather seen edge-on) can slip between the pixel centres: a corner
	// in front of the camera and inside the image also counts.
	for (int i = 0; i < 8; ++i) {
		plume_vec3 corner = {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
		plume_vec3 d = plume_v3_sub(corner, camera->eye);
		double depth = plume_v3_dot(d, camera->forward);
		double scale = camera->orthographic ? 1.0 : depth;
		if (depth > 0.0 && fabs(plume_v3_dot(d, camera->right)) <= camera->half_width * scale &&
		    fabs(plume_v3_dot(d, camera->up)) <= camera->half_height * scale)
			return PLUME_OK;
	}
	for (int y = 0; y < camera->height; ++y)
		for (int x = 0; x < camera->width; ++x) {
			plume_vec3 o, d;
			rt_camera_ray(camera, x + 0.5, y + 0.5, &o, &d);
			if (camera->orthographic && inside)
				o = plume_v3_mad(o, -2.0 * plume_v3_distance(lo, hi), d); // a parallel view can start anywhere
			if (ray_hits_box(o, d, lo, hi))
				return PLUME_OK;
		}
	return plume_error_set(err, PLUME_ERROR_SPEC,
	                       "raytrace: the camera at (%g, %g, %g) sees none of the scene (bounds [%g, %g] x [%g, %g] x "
	                       "[%g, %g] m); point it at the feather or use automatic framing",
	                       e.x, e.y, e.z, lo.x, hi.x, lo.y, hi.y, lo.z, hi.z);
}

// ---------------------------------------------------------------------------
// Sampling

/// Per-pixel generator: the image does not depend on which thread draws which pixel.
static plume_rng pixel_rng(uint64_t seed, uint64_t pixel)
{
	return plume_rng_seed(seed ^ (pixel * 0xD1B54A32D192ED03ull + 0x9E3779B97F4A7C15ull));
}

/// Orthonormal t1, t2 completing the unit vector n (Duff et al. 2017).
static void basis(plume_vec3 n, plume_vec3 *t1, plume_vec3 *t2)
{
	double sign = n.z >= 0.0 ? 1.0 : -1.0;
	double a = -1.0 / (sign + n.z), b = n.x * n.y * a;
	*t1 = plume_v3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
	*t2 = plume_v3(b, sign + n.y * n.y * a, -n.y);
}

static plume_vec3 cosine_direction(plume_vec3 n, plume_rng *rng)
{
	double u1 = plume_rng_uniform(rng), u2 = plume_rng_uniform(rng);
	double r = sqrt(u1), phi = 2.0 * PI * u2;
	plume_vec3 t1, t2;
	basis(n, &t1, &t2);
	return plume_v3_mad(plume_v3_mad(plume_v3_scale(n, sqrt(fmax(0.0, 1.0 - u1))), r * cos(phi), t1), r * sin(phi), t2);
}

/// A direction uniformly inside the cone of half-angle angle around the unit axis.
static plume_vec3 cone_direction(plume_vec3 axis, double angle, plume_rng *rng)
{
	double u1 = plume_rng_uniform(rng), u2 = plume_rng_uniform(rng);
	if (angle <= 0.0)
		return axis;
	double cos_max = cos(angle);
	double c = 1.0 - u1 * (1.0 - cos_max), s = sqrt(fmax(0.0, 1.0 - c * c)), phi = 2.0 * PI * u2;
	plume_vec3 t1, t2;
	basis(axis, &t1, &t2);
	return plume_v3_mad(plume_v3_mad(plume_v3_scale(axis, c), s * cos(phi), t1), s * sin(phi), t2);
}

// ---------------------------------------------------------------------------
// Tracing

typedef struct tracer {
	const plume_raytrace_def *def;
	const rt_scene *scene;
	rt_fiber fiber;
	plume_vec3 lights[PLUME_RAYTRACE_MAX_LIGHTS];   ///< unit directions
	plume_vec3 radiance[PLUME_RAYTRACE_MAX_LIGHTS]; ///< linear colour times intensity
	plume_vec3 sky;                                 ///< linear sky radiance
	plume_vec3 background;                          ///< linear
	plume_vec3 barb_albedo, shaft_albedo, shell_albedo, ground_albedo;
	bool ground;
	plume_vec3 ground_normal;
	double ground_offset;      ///< the plane is x . ground_normal = ground_offset
	double epsilon;            ///< ray offset, m
	double ao_distance;        ///< m
	plume_vec3 box_lo, box_hi; ///< the scene's bounds, slightly grown: rays that miss it skip Embree
} tracer;

static void init_ray(struct RTCRay *ray, plume_vec3 o, plume_vec3 d, double tnear, double tfar)
{
	ray->org_x = (float)o.x;
	ray->org_y = (float)o.y;
	ray->org_z = (float)o.z;
	ray->dir_x = (float)d.x;
	ray->dir_y = (float)d.y;
	ray->dir_z = (float)d.z;
	ray->tnear = (float)tnear;
	ray->tfar = (float)tfar;
	ray->time = 0.0f;
	ray->mask = 0xFFFFFFFFu;
	ray->id = 0;
	ray->flags = 0;
}

/// Distance along the ray to the ground, or infinity (the ground is seen from its normal's side only).
static double ground_distance(const tracer *tr, plume_vec3 o, plume_vec3 d)
{
	if (!tr->ground)
		return INFINITY;
	double dn = plume_v3_dot(d, tr->ground_normal), height = plume_v3_dot(o, tr->ground_normal) - tr->ground_offset;
	if (dn >= 0.0 || height <= 0.0)
		return INFINITY;
	return height / -dn;
}

/// Whether anything blocks o + t d for t in (epsilon, distance).
static bool occluded(const tracer *tr, plume_vec3 o, plume_vec3 d, double distance)
{
	if (ground_distance(tr, o, d) < distance)
		return true;
	if (!ray_hits_box_before(o, d, tr->box_lo, tr->box_hi, distance))
		return false; // most shadow and occlusion rays from the ground never come near the feather
	struct RTCIntersectContext context;
	rtcInitIntersectContext(&context);
	struct RTCRay ray;
	init_ray(&ray, o, d, tr->epsilon, isfinite(distance) ? distance : INFINITY);
	rtcOccluded1(tr->scene->scene, &context, &ray);
	return ray.tfar < 0.0f;
}

/// Fraction of the sky that the point sees around its normal, by ambient-occlusion rays.
static double sky_visibility(const tracer *tr, plume_vec3 p, plume_vec3 n, plume_rng *rng)
{
	int count = tr->def->ao_samples;
	if (count == 0)
		return 1.0;
	// Occlusion rays are ao_distance long: from farther away than that the scene cannot occlude anything.
	plume_vec3 gap = {fmax(0.0, fmax(tr->box_lo.x - p.x, p.x - tr->box_hi.x)),
	                  fmax(0.0, fmax(tr->box_lo.y - p.y, p.y - tr->box_hi.y)),
	                  fmax(0.0, fmax(tr->box_lo.z - p.z, p.z - tr->box_hi.z))};
	// Nor can the ground, for a point on it (its hemisphere faces away) or high above it.
	bool ground_clear = !tr->ground || plume_v3_dot(n, tr->ground_normal) >= 1.0 - 1e-12 ||
	                    plume_v3_dot(p, tr->ground_normal) - tr->ground_offset > tr->ao_distance;
	if (ground_clear && plume_v3_dot(gap, gap) > tr->ao_distance * tr->ao_distance)
		return 1.0;
	int open = 0;
	for (int i = 0; i < count; ++i)
		open += !occluded(tr, p, cosine_direction(n, rng), tr->ao_distance);
	return (double)open / count;
}

/// Light reaching a surface point through shadow rays, weighted by the surface's response.
typedef plume_vec3 response_fn(const tracer *tr, const void *surface, plume_vec3 l);

typedef struct fiber_surface {
	plume_vec3 t, n, v, albedo;
} fiber_surface;

static plume_vec3 fiber_response(const tracer *tr, const void *surface, plume_vec3 l)
{
	const fiber_surface *s = surface;
	return rt_fiber_shade(&tr->fiber, s->t, s->n, s->v, l, s->albedo);
}

typedef struct lambert_surface {
	plume_vec3 n, albedo;
} lambert_surface;

static plume_vec3 lambert_response(const tracer *tr, const void *surface, plume_vec3 l)
{
	(void)tr;
	const lambert_surface *s = surface;
	return plume_v3_scale(s->albedo, fmax(0.0, plume_v3_dot(s->n, l)));
}

static plume_vec3 gather_lights(const tracer *tr, plume_vec3 p, plume_vec3 n, response_fn *response,
                                const void *surface, plume_rng *rng)
{
	plume_vec3 sum = {0.0, 0.0, 0.0};
	for (int i = 0; i < tr->def->light_count; ++i) {
		plume_vec3 l = cone_direction(tr->lights[i], tr->def->lights[i].angle, rng);
		if (tr->ground && plume_v3_dot(l, tr->ground_normal) <= 0.0)
			continue; // the light is below the ground
		plume_vec3 f = response(tr, surface, l);
		if (f.x <= 0.0 && f.y <= 0.0 && f.z <= 0.0)
			continue;
		// Shadow rays leave from the side of the surface that faces the light.
		plume_vec3 origin = plume_v3_mad(p, plume_v3_dot(n, l) >= 0.0 ? tr->epsilon : -tr->epsilon, n);
		if (tr->def->shadows && occluded(tr, origin, l, INFINITY))
			continue;
		sum = plume_v3_add(sum, plume_v3(f.x * tr->radiance[i].x, f.y * tr->radiance[i].y, f.z * tr->radiance[i].z));
	}
	return sum;
}

static plume_vec3 lerp_uv_color(const plume_texture *texture, plume_side side, plume_vec2 a, plume_vec2 b, double u)
{
	double s = a.x + u * (b.x - a.x), t = a.y + u * (b.y - a.y);
	return rt_color_linear(plume_texture_sample_vane(texture, side, s, t));
}

/// Albedo (linear) of a curve hit.
static plume_vec3 curve_albedo(const tracer *tr, const rt_geometry *g, rt_segment seg, double u)
{
	const plume_texture *texture = tr->scene->texture;
	switch (g->kind) {
	case RT_BARBS: {
		if (texture == NULL)
			return tr->barb_albedo;
		plume_barb barb = plume_feather_barb(g->feather, seg.curve);
		return lerp_uv_color(texture, barb.side, barb.curve.uv[seg.point], barb.curve.uv[seg.point + 1], u);
	}
	case RT_SHAFT: {
		if (texture == NULL)
			return tr->shaft_albedo;
		const plume_shaft_sample *shaft = plume_feather_shaft(g->feather);
		double t = shaft[seg.point].t + u * (shaft[seg.point + 1].t - shaft[seg.point].t);
		return rt_color_linear(plume_texture_sample_vane(texture, PLUME_SIDE_RIGHT, 0.0, t));
	}
	default: {
		if (texture == NULL)
			return tr->barb_albedo;
		plume_barbule barbule = plume_feather_barbule(g->feather, seg.curve);
		plume_barb barb = plume_feather_barb(g->feather, barbule.barb);
		return rt_color_linear(plume_texture_sample_vane(texture, barb.side, barbule.barb_s, barb.curve.uv[0].y));
	}
	}
}

/// Linear radiance and coverage of one camera sample.
static void trace_sample(const tracer *tr, plume_vec3 o, plume_vec3 d, plume_rng *rng, plume_vec3 *color, double *alpha)
{
	struct RTCIntersectContext context;
	rtcInitIntersectContext(&context);
	struct RTCRayHit hit;
	init_ray(&hit.ray, o, d, 0.0, INFINITY);
	hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
	hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
	if (ray_hits_box(o, d, tr->box_lo, tr->box_hi))
		rtcIntersect1(tr->scene->scene, &context, &hit);
	double t_ground = ground_distance(tr, o, d);
	plume_vec3 v = plume_v3_scale(d, -1.0);
	if (hit.hit.geomID != RTC_INVALID_GEOMETRY_ID && hit.ray.tfar < t_ground) {
		const rt_geometry *g = tr->scene->geometries + hit.hit.geomID;
		plume_vec3 p = plume_v3_mad(o, hit.ray.tfar, d);
		plume_vec3 n = plume_v3_normalize(plume_v3(hit.hit.Ng_x, hit.hit.Ng_y, hit.hit.Ng_z));
		if (plume_v3_dot(n, v) < 0.0)
			n = plume_v3_scale(n, -1.0);
		plume_vec3 radiance;
		if (g->kind == RT_SHELL) {
			lambert_surface surface = {n, tr->shell_albedo};
			radiance = gather_lights(tr, p, n, lambert_response, &surface, rng);
			double sky = sky_visibility(tr, plume_v3_mad(p, tr->epsilon, n), n, rng);
			radiance = plume_v3_add(radiance,
			                        plume_v3_scale(plume_v3(tr->sky.x * surface.albedo.x, tr->sky.y * surface.albedo.y,
			                                                tr->sky.z * surface.albedo.z),
			                                       sky));
		} else {
			rt_segment seg = g->segments[hit.hit.primID];
			float position[4], derivative[4];
			rtcInterpolate1(g->handle, hit.hit.primID, hit.hit.u, hit.hit.v, RTC_BUFFER_TYPE_VERTEX, 0, position,
			                derivative, NULL, 4);
			plume_vec3 t = plume_v3_normalize(plume_v3(derivative[0], derivative[1], derivative[2]));
			// The normal is kept perpendicular to the fiber.
			plume_vec3 nn = plume_v3_normalize(plume_v3_mad(n, -plume_v3_dot(n, t), t));
			if (plume_v3_length(nn) > 0.0)
				n = nn;
			fiber_surface surface = {t, n, v, curve_albedo(tr, g, seg, hit.hit.u)};
			radiance = gather_lights(tr, p, n, fiber_response, &surface, rng);
			double sky = sky_visibility(tr, plume_v3_mad(p, tr->epsilon, n), n, rng) * tr->fiber.diffuse;
			radiance = plume_v3_add(radiance,
			                        plume_v3_scale(plume_v3(tr->sky.x * surface.albedo.x, tr->sky.y * surface.albedo.y,
			                                                tr->sky.z * surface.albedo.z),
			                                       sky));
		}
		*color = radiance;
		*alpha = 1.0;
		return;
	}
	if (isfinite(t_ground)) {
		plume_vec3 p = plume_v3_mad(o, t_ground, d);
		plume_vec3 n = tr->ground_normal;
		lambert_surface surface = {n, tr->ground_albedo};
		plume_vec3 lifted = plume_v3_mad(p, tr->epsilon, n);
		plume_vec3 radiance = gather_lights(tr, lifted, n, lambert_response, &surface, rng);
		double sky = sky_visibility(tr, lifted, n, rng);
		*color =
		    plume_v3_add(radiance, plume_v3_scale(plume_v3(tr->sky.x * surface.albedo.x, tr->sky.y * surface.albedo.y,
		                                                   tr->sky.z * surface.albedo.z),
		                                          sky));
		*alpha = 1.0;
		return;
	}
	*color = tr->background;
	*alpha = tr->def->background.a;
}

static tracer make_tracer(const plume_raytrace_def *def, const rt_scene *scene)
{
	tracer tr = {.def = def, .scene = scene, .fiber = rt_fiber_from_def(def)};
	for (int i = 0; i < def->light_count; ++i) {
		tr.lights[i] = plume_v3_normalize(def->lights[i].direction);
		tr.radiance[i] = plume_v3_scale(rt_color_linear(def->lights[i].color), def->lights[i].intensity);
	}
	tr.sky = plume_v3_scale(rt_color_linear(def->sky_color), def->sky_intensity);
	tr.background = rt_color_linear(def->background);
	tr.barb_albedo = rt_color_linear(def->barb_color);
	tr.shaft_albedo = rt_color_linear(def->shaft_color);
	tr.shell_albedo = rt_color_linear(def->shell_color);
	tr.ground_albedo = rt_color_linear(def->ground_color);
	double diagonal = plume_v3_distance(scene->lo, scene->hi);
	if (!(diagonal > 0.0))
		diagonal = 1.0;
	tr.epsilon = 2e-6 * diagonal;
	plume_vec3 slack = plume_v3(1e-5 * diagonal, 1e-5 * diagonal, 1e-5 * diagonal);
	tr.box_lo = plume_v3_sub(scene->lo, slack);
	tr.box_hi = plume_v3_add(scene->hi, slack);
	tr.ao_distance = def->ao_distance * diagonal;
	tr.ground = def->ground;
	if (def->ground) {
		tr.ground_normal = plume_v3_normalize(def->ground_normal);
		double lowest = INFINITY;
		for (int i = 0; i < 8; ++i) {
			plume_vec3 corner = {(i & 1) ? scene->hi.x : scene->lo.x, (i & 2) ? scene->hi.y : scene->lo.y,
			                     (i & 4) ? scene->hi.z : scene->lo.z};
			lowest = fmin(lowest, plume_v3_dot(corner, tr.ground_normal));
		}
		tr.ground_offset = lowest - def->ground_gap * diagonal;
	}
	return tr;
}

/// Whether barbules are drawn: always, never, or when the widest barb spans barbule_min_px at the target.
static bool want_barbules(const plume_raytrace_def *def, const plume_camera *camera, const plume_raytrace_scene *scene)
{
	if (def->barbules != PLUME_BARBULES_AUTO)
		return def->barbules == PLUME_BARBULES_ON;
	double widest = 0.0;
	bool any = false;
	for (int f = 0; f < scene->feather_count; ++f) {
		plume_feather_info info = plume_feather_get_info(scene->feathers[f]);
		any = any || info.barbule_count > 0;
		for (int i = 0; i < info.barb_count; ++i) {
			plume_barb barb = plume_feather_barb(scene->feathers[f], i);
			for (int k = 0; k < barb.curve.count; ++k)
				widest = fmax(widest, barb.curve.widths[k]);
		}
	}
	if (!any)
		return false;
	double view_height = camera->orthographic
	                         ? camera->ortho_height
	                         : 2.0 * tan(0.5 * camera->fov) * plume_v3_distance(camera->eye, camera->target);
	return widest * camera->height / view_height >= def->barbule_min_px;
}

plume_status plume_raytrace_render(const plume_raytrace_scene *scene, const plume_raytrace_def *def, uint8_t *rgba,
                                   plume_raytrace_stats *stats, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	PLUME_ASSERT(scene != NULL && def != NULL && rgba != NULL);
	plume_status status = validate_def(def, err);
	if (status != PLUME_OK)
		return status;
	plume_vec3 lo, hi;
	plume_raytrace_scene_bounds(scene, &lo, &hi);
	plume_camera camera = plume_camera_frame_bounds(&def->camera, lo, hi);
	if ((status = rt_camera_check(&camera, err)) != PLUME_OK)
		return status;
	rt_camera view = rt_camera_make(&camera);
	if ((status = check_view(&view, lo, hi, err)) != PLUME_OK)
		return status;

	double start = omp_get_wtime();
	rt_scene built;
	status = rt_scene_build(&built, scene, def->texture, want_barbules(def, &camera, scene), err);
	if (status != PLUME_OK) {
		rt_scene_destroy(&built);
		return status;
	}
	double built_at = omp_get_wtime();
	tracer tr = make_tracer(def, &built);

	const int width = camera.width, height = camera.height, spp = def->spp;
	int grid = (int)floor(sqrt((double)spp) + 0.5);
	bool stratified = grid * grid == spp;
	int threads = def->threads > 0 ? def->threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
	for (int y = 0; y < height; ++y) {
		for (int x = 0; x < width; ++x) {
			uint64_t pixel = (uint64_t)y * (uint64_t)width + (uint64_t)x;
			plume_rng rng = pixel_rng(def->seed, pixel);
			double r = 0.0, g = 0.0, b = 0.0, a = 0.0;
			for (int s = 0; s < spp; ++s) {
				double jx = plume_rng_uniform(&rng), jy = plume_rng_uniform(&rng);
				if (stratified) {
					jx = ((s % grid) + jx) / grid;
					jy = ((s / grid) + jy) / grid;
				}
				plume_vec3 o, d, color;
				double alpha;
				rt_camera_ray(&view, x + jx, y + jy, &o, &d);
				trace_sample(&tr, o, d, &rng, &color, &alpha);
				r += alpha * color.x;
				g += alpha * color.y;
				b += alpha * color.z;
				a += alpha;
			}
			uint8_t *out = rgba + 4 * pixel;
			if (a > 0.0) {
				out[0] = rt_linear_to_srgb_byte(r / a);
				out[1] = rt_linear_to_srgb_byte(g / a);
				out[2] = rt_linear_to_srgb_byte(b / a);
			} else {
				out[0] = out[1] = out[2] = 0;
			}
			out[3] = (uint8_t)floor(255.0 * a / spp + 0.5);
		}
	}
	double end = omp_get_wtime();
	if (stats != NULL) {
		*stats = (plume_raytrace_stats){
		    .curve_segments = built.curve_segments,
		    .triangles = built.triangles,
		    .barbules = built.barbules,
		    .build_seconds = built_at - start,
		    .render_seconds = end - built_at,
		};
	}
	rt_scene_destroy(&built);
	return PLUME_OK;
}

// ---------------------------------------------------------------------------
// PNG

plume_status plume_write_rgba_png(int width, int height, const uint8_t *rgba, const char *path, plume_error *err)
{
	cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height);
	if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS) {
		cairo_surface_destroy(surface);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory for a %dx%d image", path, width, height);
	}
	cairo_surface_flush(surface);
	unsigned char *data = cairo_image_surface_get_data(surface);
	int stride = cairo_image_surface_get_stride(surface);
	// Cairo's ARGB32 is premultiplied, one native-endian 32-bit word per pixel.
	for (int y = 0; y < height; ++y) {
		uint32_t *row = (uint32_t *)(void *)(data + (size_t)y * (size_t)stride);
		for (int x = 0; x < width; ++x) {
			const uint8_t *p = rgba + 4 * ((size_t)y * (size_t)width + (size_t)x);
			uint32_t alpha = p[3];
			uint32_t red = ((uint32_t)p[0] * alpha + 127u) / 255u, green = ((uint32_t)p[1] * alpha + 127u) / 255u,
			         blue = ((uint32_t)p[2] * alpha + 127u) / 255u;
			row[x] = (alpha << 24) | (red << 16) | (green << 8) | blue;
		}
	}
	cairo_surface_mark_dirty(surface);
	plume_status status = plume_cairo_write_png(surface, path, err);
	cairo_surface_destroy(surface);
	return status;
}

double plume_raytrace_estimate_bytes(const plume_raytrace_def *def, int images, int held)
{
	double pixels = (double)def->camera.width * (double)def->camera.height;
	return pixels * (8.0 + 4.0 * images + 4.0 * held);
}

plume_status plume_raytrace_render_png(const plume_raytrace_scene *scene, const plume_raytrace_def *def,
                                       const char *path, plume_raytrace_stats *stats, plume_error *err)
{
	PLUME_ASSERT_DEF(def);
	size_t size = 4 * (size_t)def->camera.width * (size_t)(def->camera.height > 0 ? def->camera.height : 0);
	if (def->camera.width < 16 || def->camera.width > 16384 || def->camera.height < 16 || def->camera.height > 16384)
		return rt_camera_check(&def->camera, err);
	uint8_t *rgba = plume_alloc(size);
	if (rgba == NULL)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "%s: out of memory for the image", path);
	plume_status status = plume_raytrace_render(scene, def, rgba, stats, err);
	if (status == PLUME_OK)
		status = plume_write_rgba_png(def->camera.width, def->camera.height, rgba, path, err);
	else
		plume_error_prefix(err, path);
	plume_free(rgba);
	return status;
}

// Cameras for the ray tracer: defaults, automatic framing, turntable, rays.
#include <math.h>

#include "render/raytrace_internal.h"

#define DEG (3.14159265358979323846 / 180.0)

plume_camera plume_camera_default(void)
{
	return (plume_camera){
	    .automatic = true,
	    .eye = {0.0, 0.0, 1.0},
	    .target = {0.0, 0.0, 0.0},
	    .up = {0.0, 1.0, 0.0},
	    .view_direction = {0.0, 0.0, 1.0},
	    .fov = 30.0 * DEG,
	    .orthographic = false,
	    .ortho_height = 0.0,
	    .width = 800,
	    .height = 800,
	    .margin = 0.05,
	    .turntable = 0.0,
	};
}

/// A unit vector perpendicular to forward, as close to up as possible; another axis when up is parallel.
static plume_vec3 orthogonal_up(plume_vec3 forward, plume_vec3 up)
{
	plume_vec3 u = plume_v3_mad(up, -plume_v3_dot(up, forward), forward);
	if (plume_v3_length(u) < 1e-9 * (plume_v3_length(up) + 1e-300)) {
		plume_vec3 axis = fabs(forward.x) < 0.9 ? plume_v3(1.0, 0.0, 0.0) : plume_v3(0.0, 1.0, 0.0);
		u = plume_v3_mad(axis, -plume_v3_dot(axis, forward), forward);
	}
	return plume_v3_normalize(u);
}

static plume_camera apply_turntable(plume_camera camera)
{
	if (camera.turntable != 0.0) {
		plume_mat3 rotation = plume_m3_rotation(plume_v3_normalize(camera.up), camera.turntable);
		camera.eye = plume_v3_add(camera.target, plume_m3_apply(rotation, plume_v3_sub(camera.eye, camera.target)));
		camera.turntable = 0.0;
	}
	return camera;
}

plume_camera plume_camera_frame_bounds(const plume_camera *camera, plume_vec3 lo, plume_vec3 hi)
{
	plume_camera out = *camera;
	if (!camera->automatic)
		return apply_turntable(out);
	plume_vec3 centre = plume_v3_scale(plume_v3_add(lo, hi), 0.5);
	plume_vec3 back = plume_v3_normalize(camera->view_direction); // target -> eye
	plume_vec3 forward = plume_v3_scale(back, -1.0);
	plume_vec3 up = orthogonal_up(forward, camera->up);
	plume_vec3 right = plume_v3_cross(forward, up);
	// Half extents of the bounds seen along the view, and their depth towards the eye.
	double margin_px = camera->margin * (camera->width < camera->height ? camera->width : camera->height);
	double room_x = camera->width - 2.0 * margin_px, room_y = camera->height - 2.0 * margin_px;
	double extent_x = 0.0, extent_y = 0.0, depth = 0.0, diagonal = plume_v3_distance(lo, hi);
	double distance = 0.0;
	double tan_y = tan(0.5 * camera->fov);
	// Perspective: the eye at distance d sees a corner (a, b, c) in the image when
	// |a| / (d - c) <= tan_x and |b| / (d - c) <= tan_y, the tangents shrunk by the margin.
	double fit_x = tan_y * room_x / camera->height, fit_y = tan_y * room_y / camera->height;
	for (int i = 0; i < 8; ++i) {
		plume_vec3 corner = {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
		plume_vec3 d = plume_v3_sub(corner, centre);
		double a = fabs(plume_v3_dot(d, right)), b = fabs(plume_v3_dot(d, up)), c = plume_v3_dot(d, back);
		extent_x = fmax(extent_x, a);
		extent_y = fmax(extent_y, b);
		depth = fmax(depth, c);
		distance = fmax(distance, c + fmax(a / fit_x, b / fit_y));
	}
	// The eye always stays outside the bounds.
	double clearance = 0.05 * diagonal + 1e-6;
	distance = fmax(distance, depth + clearance);
	if (camera->orthographic) {
		if (camera->ortho_height <= 0.0) {
			double scale_x = extent_x > 0.0 ? room_x / (2.0 * extent_x) : INFINITY;
			double scale_y = extent_y > 0.0 ? room_y / (2.0 * extent_y) : INFINITY;
			double scale = fmin(scale_x, scale_y); // px per m
			out.ortho_height = isfinite(scale) ? camera->height / scale : 1.0;
		}
		distance = depth + clearance;
	}
	out.automatic = false;
	out.target = centre;
	out.up = up;
	out.eye = plume_v3_mad(centre, distance, back);
	return apply_turntable(out);
}

plume_status rt_camera_check(const plume_camera *camera, plume_error *err)
{
	if (camera->width < 16 || camera->width > 16384 || camera->height < 16 || camera->height > 16384)
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: camera size is %dx%d, each allowed in [16, 16384]",
		                       camera->width, camera->height);
	if (!(camera->fov > 0.0 && camera->fov < 3.14159265358979323846))
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: camera fov is %g degrees, allowed (0, 180)",
		                       camera->fov / DEG);
	if (!(camera->margin >= 0.0 && camera->margin < 0.45))
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: camera margin is %g, allowed [0, 0.45)",
		                       camera->margin);
	if (!isfinite(camera->turntable))
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: camera turntable angle must be finite");
	if (camera->automatic) {
		if (!(plume_v3_length(camera->view_direction) > 0.0) || !isfinite(plume_v3_length(camera->view_direction)))
			return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: camera view_direction must be a non-zero vector");
		return PLUME_OK;
	}
	plume_vec3 forward = plume_v3_sub(camera->target, camera->eye);
	double length = plume_v3_length(forward);
	if (!(length > 0.0) || !isfinite(length))
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "raytrace: camera eye (%g, %g, %g) and target must be distinct finite points",
		                       camera->eye.x, camera->eye.y, camera->eye.z);
	if (!(plume_v3_length(plume_v3_cross(forward, camera->up)) > 1e-12 * length * plume_v3_length(camera->up)))
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: camera up must not be parallel to the view direction");
	if (camera->orthographic && !(camera->ortho_height > 0.0 && isfinite(camera->ortho_height)))
		return plume_error_set(err, PLUME_ERROR_SPEC, "raytrace: orthographic camera needs ortho_height > 0 m, got %g",
		                       camera->ortho_height);
	return PLUME_OK;
}

rt_camera rt_camera_make(const plume_camera *camera)
{
	rt_camera out = {0};
	out.eye = camera->eye;
	out.forward = plume_v3_normalize(plume_v3_sub(camera->target, camera->eye));
	out.up = orthogonal_up(out.forward, camera->up);
	out.right = plume_v3_cross(out.forward, out.up);
	double aspect = (double)camera->width / camera->height;
	out.orthographic = camera->orthographic;
	out.half_height = camera->orthographic ? 0.5 * camera->ortho_height : tan(0.5 * camera->fov);
	out.half_width = out.half_height * aspect;
	out.width = camera->width;
	out.height = camera->height;
	return out;
}

void rt_camera_ray(const rt_camera *camera, double x, double y, plume_vec3 *origin, plume_vec3 *direction)
{
	double u = (2.0 * x / camera->width - 1.0) * camera->half_width;
	double v = (1.0 - 2.0 * y / camera->height) * camera->half_height;
	if (camera->orthographic) {
		*origin = plume_v3_mad(plume_v3_mad(camera->eye, u, camera->right), v, camera->up);
		*direction = camera->forward;
	} else {
		*origin = camera->eye;
		*direction = plume_v3_normalize(plume_v3_mad(plume_v3_mad(camera->forward, u, camera->right), v, camera->up));
	}
}

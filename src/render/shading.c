// Fiber shading for barbs and the shaft, and colour conversions.
//
// A barb is a flat keratin ribbon, thin enough that light passes through it.
// Seen from the lit side it reflects like a fiber: a diffuse term that
// depends only on the angle between the light and the fiber (Kajiya & Kay
// 1989, eq. for the diffuse component: kd sin(T, L)) and a specular cone
// around the fiber. Seen from the unlit side it transmits a tinted fraction.
#include <math.h>

#include "render/raytrace_internal.h"

#define PI 3.14159265358979323846

double rt_srgb_to_linear(double c)
{
	c = fmin(fmax(c, 0.0), 1.0);
	return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

uint8_t rt_linear_to_srgb_byte(double c)
{
	c = fmin(fmax(c, 0.0), 1.0);
	double s = c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
	return (uint8_t)floor(s * 255.0 + 0.5);
}

plume_vec3 rt_color_linear(plume_color c)
{
	return plume_v3(rt_srgb_to_linear(c.r), rt_srgb_to_linear(c.g), rt_srgb_to_linear(c.b));
}

rt_fiber rt_fiber_from_def(const plume_raytrace_def *def)
{
	return (rt_fiber){
	    .model = def->shading,
	    .diffuse = def->diffuse,
	    .specular = def->specular,
	    .kk_exponent = def->kk_exponent,
	    .lobe_shift = def->lobe_shift,
	    .lobe_width = def->lobe_width,
	    .trt_weight = def->trt_weight,
	    .transmission = def->transmission,
	};
}

/// Normalised Gaussian of standard deviation beta at x (Marschner et al. 2003, the longitudinal M_p).
static double gaussian(double beta, double x) { return exp(-0.5 * x * x / (beta * beta)) / (beta * sqrt(2.0 * PI)); }

/// Specular part, white (R) and tinted (TRT) scalars.
static void specular_lobes(const rt_fiber *f, double cos_tl, double cos_tv, double *white, double *tinted)
{
	double sin_tl = sqrt(fmax(0.0, 1.0 - cos_tl * cos_tl));
	double sin_tv = sqrt(fmax(0.0, 1.0 - cos_tv * cos_tv));
	if (f->model == PLUME_SHADING_KAJIYA_KAY) {
		// Kajiya & Kay 1989: the highlight is the cone of mirror directions around the fiber, where
		// T.V = -T.L (v points to the eye); its cosine is sin(T,L) sin(T,V) - cos(T,L) cos(T,V).
		double cone = fmax(0.0, sin_tl * sin_tv - cos_tl * cos_tv);
		*white = f->specular * pow(cone, f->kk_exponent);
		*tinted = 0.0;
		return;
	}
	// Marschner et al. 2003, section 4: longitudinal angles from the normal plane, theta_i and theta_r;
	// theta_h = (theta_i + theta_r) / 2, theta_d = (theta_i - theta_r) / 2. The R lobe is centred at
	// alpha, TRT at -3 alpha / 2 with width 2 beta; S = M(theta_h) N / cos^2(theta_d), and the azimuthal
	// N is taken as the constant 1/4 (a flat ribbon has no circular cross-section to integrate over).
	double theta_i = asin(fmax(-1.0, fmin(1.0, cos_tl)));
	double theta_r = asin(fmax(-1.0, fmin(1.0, cos_tv)));
	double theta_h = 0.5 * (theta_i + theta_r), theta_d = 0.5 * (theta_i - theta_r);
	double cos_d = cos(theta_d);
	double inverse = 0.25 / fmax(cos_d * cos_d, 1e-3);
	double m_r = gaussian(f->lobe_width, theta_h - f->lobe_shift);
	double m_trt = gaussian(2.0 * f->lobe_width, theta_h + 1.5 * f->lobe_shift);
	*white = f->specular * m_r * inverse * sin_tl;
	*tinted = f->trt_weight * m_trt * inverse * sin_tl;
}

plume_vec3 rt_fiber_shade(const rt_fiber *fiber, plume_vec3 t, plume_vec3 n, plume_vec3 v, plume_vec3 l,
                          plume_vec3 albedo)
{
	double cos_tl = plume_v3_dot(t, l), cos_tv = plume_v3_dot(t, v);
	double n_l = plume_v3_dot(n, l);
	if (n_l <= 0.0) {
		// The light is on the far side: the ribbon passes on a tinted fraction, by the cosine on that side.
		return plume_v3_scale(albedo, fiber->transmission * -n_l);
	}
	double sin_tl = sqrt(fmax(0.0, 1.0 - cos_tl * cos_tl));
	double white, tinted;
	specular_lobes(fiber, cos_tl, cos_tv, &white, &tinted);
	// The diffuse term is Kajiya–Kay's sin(T, L), limited by the ribbon's own cosine so that a ribbon
	// lit edge-on goes dark (a flat barb, unlike a round hair, has a face).
	double diffuse = fiber->diffuse * fmin(sin_tl, 0.25 + 0.75 * n_l);
	return plume_v3(albedo.x * (diffuse + tinted) + white, albedo.y * (diffuse + tinted) + white,
	                albedo.z * (diffuse + tinted) + white);
}

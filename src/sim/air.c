// Quadratic aerodynamics of a thin sheet, per face, with wind and gusts.
//
// Each face of area A, unit normal n, moving at u relative to the air (the mean of its
// vertices' velocities less the wind at its centroid) feels the quasi-steady force
//   F = -1/2 rho A (C_n w (|u_n| + |u_t|) u_n n + C_t |u_t| u_t),   u_n = u . n,  u_t = u - u_n n:
// a pressure force normal to the sheet (C_n = 1.17 for a square plate broadside at Re ~ 1e4,
// Hoerner, Fluid-Dynamic Drag 1965, ch. 3), whose coefficient at an angle of attack alpha,
// C_N = C_n sin(alpha) (sin(alpha) + cos(alpha)), grows linearly with alpha near gliding as a
// plate's does (Rayleigh's C_N = 2 pi sin(alpha) / (4 + pi sin(alpha)); a normal force
// quadratic in u_n alone, C_n sin^2(alpha), let a tilted feather dive at 4 m/s), and skin friction along it (Blasius:
// C_f = 1.328 / sqrt(Re) per side, 0.07 for both sides at Re ~ 1.5e3, the Reynolds number of a feather falling at 0.5
// m/s). A normal force at an angle of attack alpha has a lift part as well as a drag part, so a tilted sheet glides;
// this is the quasi-steady translational part of the falling-plate models of Andersen, Pesavento & Wang 2005 (J. Fluid
// Mech. 541, 65-90, eqs. 2.7-2.9), whose rotational lift and added mass are left out.
//
// Centre of pressure. A uniform pressure acts at the area centroid and exerts no pitching
// moment; on a real plate the normal force acts ahead of mid-chord, at
//   x_cp / c = 1/2 - 3/4 cos(alpha) / (4 + pi sin(alpha))   (from the leading edge)
// (Rayleigh 1876, "On the resistance of fluids", Phil. Mag. 2, 430-441: 0.31 c gliding
// edge-first, the mid-chord broadside). The moment of this offset is what turns a falling
// card broadside and makes it pitch back and forth (flutter). At the start of each step the
// whole feather's angle of attack alpha and chord direction d (its in-plane velocity relative
// to the air) are measured, and each face's normal coefficient is weighted by
// w = max(0, 1 + e xi / I), xi its centroid's distance ahead of the area centroid along d,
// I the area-weighted mean of xi^2, e = (1/2 - x_cp / c) c, which moves the normal force's
// centre by exactly e when no weight is clipped.
//
// Newton sees the force as a dissipation potential. With the step's velocity affine in the
// unknowns, v(x) = s (x - b) (integrator.c), and the in-plane speed in the normal force taken
// at the start of the step (|u_t|_0), R(u) = rho A / 2 (C_n w (|u_n|^3 / 3 + |u_t|_0 u_n^2 / 2)
// + C_t |u_t|^3 / 3) has dR/du = -F, and the term R(u(x)) / s added to the incremental
// potential contributes -F / 3 to each vertex's gradient and s / 9 d2R/du2 to each block of the
// face's Hessian,
//   d2R/du2 = rho A / 2 (C_n w (2 |u_n| + |u_t|_0) n n^T + C_t (|u_t| P + u_t u_t^T / |u_t|)),
// P = I - n n^T, which is positive semidefinite (R is convex): the normal, area, weight, wind
// and |u_t|_0 are frozen at the start of the step, as the linear drag's normals are.
//
// Gusts: a divergence-free random field of PLUME_AIR_GUST_MODES Fourier modes (Kraichnan
// 1970, Phys. Fluids 13, 22-31), sum_k a p_k cos(kappa_k e_k . x - omega_k t + phi_k) with
// p_k normal to e_k, wavenumbers and frequencies spread log-uniformly over a factor 4
// about 2 pi / length and 2 pi / time, and a = speed sqrt(2 / K) so that the mean square of
// the gust velocity is speed^2. Drawn from the seed: the same seed, the same wind.
#include <math.h>
#include <string.h>

#include "core/alloc.h"
#include "sim/sim_internal.h"

static const double PI = 3.14159265358979323846;

static plume_vec3 random_unit(plume_rng *rng)
{
	// Uniform on the sphere (Marsaglia 1972 by z and azimuth).
	double z = plume_rng_range(rng, -1, 1), phi = plume_rng_range(rng, 0, 2 * PI), r = sqrt(fmax(0, 1 - z * z));
	return plume_v3(r * cos(phi), r * sin(phi), z);
}

bool plume_air_init(sim_air *air, const plume_air_def *def, int face_count)
{
	memset(air, 0, sizeof *air);
	air->def = *def;
	air->active = def->density > 0 && (def->normal_drag > 0 || def->tangential_drag > 0);
	if (!air->active)
		return true;
	air->face_count = face_count;
	size_t count = (size_t)(face_count > 0 ? face_count : 1);
	air->faces = plume_calloc(count, sizeof(sim_air_face));
	air->area = plume_calloc(count, sizeof(double));
	air->velocity = plume_calloc(count, sizeof(plume_vec3));
	if (air->faces == NULL || air->area == NULL || air->velocity == NULL)
		return false;
	plume_rng rng = plume_rng_seed(def->seed);
	for (int k = 0; k < PLUME_AIR_GUST_MODES; ++k) {
		air->wave[k] = random_unit(&rng);
		// A random direction made normal to the wave: the mode is divergence-free.
		plume_vec3 p = random_unit(&rng);
		p = plume_v3_sub(p, plume_v3_scale(air->wave[k], plume_v3_dot(p, air->wave[k])));
		double length = plume_v3_length(p);
		air->polarisation[k] = length > 1e-6 ? plume_v3_scale(p, 1 / length) : plume_v3(0, 0, 0);
		air->wavenumber[k] = 2 * PI / def->gust_length * exp(plume_rng_range(&rng, -log(2.0), log(2.0)));
		air->frequency[k] = 2 * PI / def->gust_time * exp(plume_rng_range(&rng, -log(2.0), log(2.0)));
		air->phase[k] = plume_rng_range(&rng, 0, 2 * PI);
	}
	return true;
}

void plume_air_free(sim_air *air)
{
	plume_free(air->faces);
	plume_free(air->area);
	plume_free(air->velocity);
	memset(air, 0, sizeof *air);
}

plume_vec3 plume_air_wind(const sim_air *air, plume_vec3 p, double t)
{
	plume_vec3 wind = air->def.wind;
	if (!(air->def.gust_speed > 0))
		return wind;
	double amplitude = air->def.gust_speed * sqrt(2.0 / PLUME_AIR_GUST_MODES);
	for (int k = 0; k < PLUME_AIR_GUST_MODES; ++k) {
		double angle = air->wavenumber[k] * plume_v3_dot(air->wave[k], p) - air->frequency[k] * t + air->phase[k];
		wind = plume_v3_mad(wind, amplitude * cos(angle), air->polarisation[k]);
	}
	return wind;
}

static plume_vec3 face_centroid(const plume_vec3 *x, const int *v)
{
	return plume_v3_scale(plume_v3_add(plume_v3_add(x[v[0]], x[v[1]]), x[v[2]]), 1.0 / 3);
}

/// The centre-of-pressure weights of the normal coefficients (see the top of the file);
/// area[f] and velocity[f] (relative to the air) per face, weights written into faces.
static void centre_of_pressure(plume_sim *sim, const double *area, const plume_vec3 *velocity)
{
	sim_air *air = &sim->air;
	const plume_vec3 *x = sim->x;
	double total = 0;
	plume_vec3 mean_velocity = {0, 0, 0}, normal = {0, 0, 0}, centre = {0, 0, 0};
	for (int f = 0; f < sim->face_count; ++f) {
		total += area[f];
		mean_velocity = plume_v3_mad(mean_velocity, area[f], velocity[f]);
		normal = plume_v3_mad(normal, area[f], air->faces[f].normal);
		centre = plume_v3_mad(centre, area[f], face_centroid(x, sim->faces + 3 * f));
	}
	// A crumpled sheet (normals that cancel) or one at rest has no angle of attack.
	double speed = plume_v3_length(mean_velocity);
	if (!(total > 0) || plume_v3_length(normal) < 0.5 * total || !(speed > 0))
		return;
	mean_velocity = plume_v3_scale(mean_velocity, 1 / total);
	centre = plume_v3_scale(centre, 1 / total);
	normal = plume_v3_normalize(normal);
	double along_normal = plume_v3_dot(mean_velocity, normal);
	plume_vec3 in_plane = plume_v3_mad(mean_velocity, -along_normal, normal);
	double in_plane_speed = plume_v3_length(in_plane);
	if (!(in_plane_speed > 1e-9 * speed))
		return;
	plume_vec3 chord = plume_v3_scale(in_plane, 1 / in_plane_speed);
	double alpha = atan2(fabs(along_normal), in_plane_speed);
	double lo = INFINITY, hi = -INFINITY, second = 0;
	for (int f = 0; f < sim->face_count; ++f) {
		double xi = plume_v3_dot(plume_v3_sub(face_centroid(x, sim->faces + 3 * f), centre), chord);
		lo = fmin(lo, xi), hi = fmax(hi, xi);
		second += area[f] * xi * xi;
	}
	second /= total;
	if (!(second > 0))
		return;
	double offset = 0.75 * (hi - lo) * cos(alpha) / (4 + PI * sin(alpha));
	for (int f = 0; f < sim->face_count; ++f) {
		double xi = plume_v3_dot(plume_v3_sub(face_centroid(x, sim->faces + 3 * f), centre), chord);
		air->faces[f].normal_coefficient *= fmax(0, 1 + offset * xi / second);
	}
}

void plume_air_begin(plume_sim *sim, double t)
{
	sim_air *air = &sim->air;
	const plume_vec3 *x = sim->x, *v = sim->v;
	double *area = air->area;
	plume_vec3 *velocity = air->velocity;
	for (int f = 0; f < sim->face_count; ++f) {
		const int *vf = sim->faces + 3 * f;
		plume_vec3 cross = plume_v3_cross(plume_v3_sub(x[vf[1]], x[vf[0]]), plume_v3_sub(x[vf[2]], x[vf[0]]));
		double twice = plume_v3_length(cross);
		sim_air_face *face = air->faces + f;
		area[f] = 0.5 * twice;
		face->factor = 0.5 * air->def.density * area[f];
		face->normal = twice > 0 ? plume_v3_scale(cross, 1 / twice) : plume_v3(0, 0, 0);
		face->normal_coefficient = air->def.normal_drag;
		face->tangential_coefficient = air->def.tangential_drag;
		face->wind = plume_air_wind(air, face_centroid(x, vf), t);
		plume_vec3 mean = plume_v3_scale(plume_v3_add(plume_v3_add(v[vf[0]], v[vf[1]]), v[vf[2]]), 1.0 / 3);
		velocity[f] = plume_v3_sub(mean, face->wind);
		face->sliding_speed =
		    plume_v3_length(plume_v3_mad(velocity[f], -plume_v3_dot(velocity[f], face->normal), face->normal));
	}
	if (air->def.centre_of_pressure)
		centre_of_pressure(sim, area, velocity);
}

double plume_air_face_potential(const sim_air_face *face, double s, const plume_vec3 x[3], const plume_vec3 base[3],
                                double *gradient, double *hessian)
{
	plume_vec3 mean = plume_v3_sub(plume_v3_add(plume_v3_add(x[0], x[1]), x[2]),
	                               plume_v3_add(plume_v3_add(base[0], base[1]), base[2]));
	plume_vec3 u = plume_v3_sub(plume_v3_scale(mean, s / 3), face->wind);
	plume_vec3 n = face->normal;
	double un = plume_v3_dot(u, n);
	plume_vec3 t = plume_v3_mad(u, -un, n);
	double tl = plume_v3_length(t);
	double cn = face->normal_coefficient, ct = face->tangential_coefficient, k = face->factor;
	double slide = face->sliding_speed;
	double energy = k * (cn * (fabs(un) * un * un / 3 + slide * un * un / 2) + ct * tl * tl * tl / 3) / s;
	if (gradient != NULL) {
		plume_vec3 normal_force = plume_v3_scale(n, cn * (fabs(un) + slide) * un);
		plume_vec3 force = plume_v3_scale(plume_v3_add(normal_force, plume_v3_scale(t, ct * tl)), k);
		for (int i = 0; i < 3; ++i) {
			gradient[3 * i] = force.x / 3;
			gradient[3 * i + 1] = force.y / 3;
			gradient[3 * i + 2] = force.z / 3;
		}
	}
	if (hessian != NULL) {
		const double nv[3] = {n.x, n.y, n.z}, tv[3] = {t.x, t.y, t.z};
		double block[9];
		for (int a = 0; a < 3; ++a)
			for (int b = 0; b < 3; ++b) {
				double projector = (a == b ? 1 : 0) - nv[a] * nv[b];
				double tangential = tl > 0 ? ct * (tl * projector + tv[a] * tv[b] / tl) : 0;
				block[3 * a + b] = k * (cn * (2 * fabs(un) + slide) * nv[a] * nv[b] + tangential) * s / 9;
			}
		for (int a = 0; a < 9; ++a)
			for (int b = 0; b < 9; ++b)
				hessian[9 * a + b] = block[3 * (a % 3) + b % 3];
	}
	return energy;
}

void plume_air_add(plume_sim *sim, const sim_problem *problem, const plume_vec3 *x, bool gradient, bool hessian)
{
	int count = sim->face_count;
#pragma omp parallel for schedule(static) if (count >= 4096)
	for (int f = 0; f < count; ++f) {
		const int *v = sim->faces + 3 * f;
		plume_vec3 local[3] = {x[v[0]], x[v[1]], x[v[2]]};
		plume_vec3 base[3] = {problem->velocity_base[v[0]], problem->velocity_base[v[1]], problem->velocity_base[v[2]]};
		double g[9], h[81];
		sim->face_energy[f] += plume_air_face_potential(sim->air.faces + f, problem->velocity_scale, local, base,
		                                                gradient ? g : NULL, hessian ? h : NULL);
		for (int i = 0; gradient && i < 9; ++i)
			sim->face_gradient[9 * f + i] += g[i];
		for (int i = 0; hessian && i < 81; ++i)
			sim->face_hessian[81 * f + i] += h[i];
	}
}

plume_status plume_air_def_validate(const plume_air_def *def, plume_error *err)
{
	const struct {
		const char *name;
		double value;
		bool positive;
	} numbers[] = {
	    {"density", def->density, false},
	    {"normal_drag", def->normal_drag, false},
	    {"tangential_drag", def->tangential_drag, false},
	    {"gusts.speed", def->gust_speed, false},
	    {"gusts.length", def->gust_length, true},
	    {"gusts.time", def->gust_time, true},
	};
	for (size_t i = 0; i < sizeof numbers / sizeof numbers[0]; ++i) {
		double value = numbers[i].value;
		bool ok = isfinite(value) && (numbers[i].positive ? value > 0 : value >= 0);
		if (!ok)
			return plume_error_set(err, PLUME_ERROR_SPEC, "$.air.%s is %g, allowed %s", numbers[i].name, value,
			                       numbers[i].positive ? "> 0" : ">= 0");
	}
	if (!isfinite(def->wind.x) || !isfinite(def->wind.y) || !isfinite(def->wind.z))
		return plume_error_set(err, PLUME_ERROR_SPEC, "$.air.wind is [%g, %g, %g], allowed finite numbers (m/s)",
		                       def->wind.x, def->wind.y, def->wind.z);
	return PLUME_OK;
}

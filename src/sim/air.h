// Private: quadratic per-face aerodynamics and wind (air.c).
#ifndef PLUME_SIM_AIR_H
#define PLUME_SIM_AIR_H

#include "plume/sim.h"

struct plume_sim;
struct sim_problem;

enum { PLUME_AIR_GUST_MODES = 32 };

/// What one face's air term needs, frozen at the start of a step.
typedef struct sim_air_face {
	/// (1/2) rho A, kg/m: the dynamic pressure's factor on this face.
	double factor;
	/// C_n times the face's centre-of-pressure weight, and C_t.
	double normal_coefficient;
	double tangential_coefficient;
	/// The face's in-plane speed relative to the air at the start of the step, m/s: the
	/// normal force grows with it (C_N ~ sin alpha near gliding, air.c).
	double sliding_speed;
	/// Unit normal at the start of the step.
	plume_vec3 normal;
	/// Air velocity at the face at the end of the step, m/s.
	plume_vec3 wind;
} sim_air_face;

typedef struct sim_air {
	bool active;
	plume_air_def def;
	int face_count;
	sim_air_face *faces;
	/// Scratch of the step's start: each face's area and velocity relative to the air.
	double *area;
	plume_vec3 *velocity;
	/// Random Fourier modes of the gusts (Kraichnan 1970): unit wave direction, wavenumber
	/// (1/m), angular frequency (1/s), phase and a polarisation normal to the wave direction.
	plume_vec3 wave[PLUME_AIR_GUST_MODES];
	plume_vec3 polarisation[PLUME_AIR_GUST_MODES];
	double wavenumber[PLUME_AIR_GUST_MODES];
	double frequency[PLUME_AIR_GUST_MODES];
	double phase[PLUME_AIR_GUST_MODES];
} sim_air;

/// Checks the definition; messages name the scene key ("$.air.density is -1, allowed >= 0").
plume_status plume_air_def_validate(const plume_air_def *def, plume_error *err);

/// Sets up the model (active when def->density > 0 and a coefficient is > 0).
bool plume_air_init(sim_air *air, const plume_air_def *def, int face_count);
void plume_air_free(sim_air *air);

/// The air velocity at point p and time t: uniform wind plus gusts.
plume_vec3 plume_air_wind(const sim_air *air, plume_vec3 p, double t);

/// Freezes every face's normal, area, wind (at time t, the end of the step) and
/// centre-of-pressure weight from sim->x and sim->v.
void plume_air_begin(struct plume_sim *sim, double t);

/// One face's dissipation potential R(u) / s with u = s (mean x - mean base) - wind,
/// R = factor (C_n (|u.n|^3 / 3 + sliding_speed (u.n)^2 / 2) + C_t |u_t|^3 / 3); its gradient (9) and Hessian (81) when
/// not NULL.
double plume_air_face_potential(const sim_air_face *face, double s, const plume_vec3 x[3], const plume_vec3 base[3],
                                double *gradient, double *hessian);

/// Adds every face's air term to sim->face_energy (and face_gradient, face_hessian).
void plume_air_add(struct plume_sim *sim, const struct sim_problem *problem, const plume_vec3 *x, bool gradient,
                   bool hessian);

#endif

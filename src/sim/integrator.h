// Private: time integrators written as incremental potentials (integrator.c).
#ifndef PLUME_SIM_INTEGRATOR_H
#define PLUME_SIM_INTEGRATOR_H

#include "plume/sim.h"

struct plume_sim;
struct sim_problem;

/// What a multistep integrator remembers between steps.
typedef struct sim_integrator {
	plume_integrator kind;
	/// BDF2: positions and velocities one step back, and that step's length (0: none yet).
	plume_vec3 *x_back;
	plume_vec3 *v_back;
	double h_back;
	/// v(x) = scale (x - velocity_base) of the current substep.
	plume_vec3 *velocity_base;
	/// The history at the start of the step, restored when the step is retried or fails.
	plume_vec3 *saved_x_back;
	plume_vec3 *saved_v_back;
	double saved_h_back;
} sim_integrator;

bool plume_integrator_init(sim_integrator *integrator, plume_integrator kind, int vertex_count);
void plume_integrator_free(sim_integrator *integrator);
void plume_integrator_save(sim_integrator *integrator, int vertex_count);
void plume_integrator_restore(sim_integrator *integrator, int vertex_count);

/// Sets up a (sub)step of length h from sim->x, sim->v: fills sim->predicted and the
/// problem's inertia weight and velocity map.
void plume_integrator_begin(struct plume_sim *sim, double h, struct sim_problem *problem);
/// After a converged solve: the velocities at the end of the step and the history.
void plume_integrator_end(struct plume_sim *sim, const struct sim_problem *problem);

#endif

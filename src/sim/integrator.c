// Time integrators as incremental potentials.
//
// Every integrator here makes the step's end positions x the minimiser of
//   Phi(x) = inertia/2 |x - x_pred|^2_M + E(x) - f.x + R(v(x)) / velocity_scale,
// where the end velocity is affine in x, v(x) = velocity_scale (x - velocity_base), and
// the acceleration is a(x) = inertia (x - x_pred). Stationarity is M a(x) = f(x) - dR/dv,
// the integrator's update (Kane et al. 2000 for the variational view; Gast et al. 2015,
// "Optimization integrator for large time steps", for BDF2 written this way).
//
// Implicit Euler (thesis eq. B.2): v = (x - x_n)/h, a = (v - v_n)/h, so inertia = 1/h^2,
// x_pred = x_n + h v_n, velocity_scale = 1/h, velocity_base = x_n.
//
// BDF2 with variable step (Hairer, Norsett & Wanner, Solving ODEs I, section III.5): with
// omega = h / h_back and
//   a0 = (1 + 2 omega)/(1 + omega), a1 = -(1 + omega), a2 = omega^2/(1 + omega)
// (3/2, -2, 1/2 for equal steps), both x and v obey a0 y_{n+1} + a1 y_n + a2 y_{n-1} = h y'_{n+1}:
//   v(x) = (a0/h)(x - b),      b = -(a1 x_n + a2 x_{n-1}) / a0 = x_n + (a2/a0)(x_n - x_{n-1}),
//   a(x) = (a0^2/h^2)(x - x_pred), x_pred = b - h (a1 v_n + a2 v_{n-1}) / a0^2.
// For equal steps x_pred = (4 x_n - x_{n-1})/3 + (2h/9)(4 v_n - v_{n-1}), inertia = 9/(4 h^2).
// The first step, and a step more than twice the one before (after substeps, where the
// variable-step formula loses zero-stability at omega > 1 + sqrt 2), is implicit Euler.
//
// Newmark's average acceleration (trapezoidal rule; inertia 4/h^2, x_pred = x_n + h v_n +
// h^2/4 a_n) was written this way and measured too (docs/simulation.md): it keeps the energy
// of the swinging feather to 1e-8 for half a second, but it does not damp the vane's
// unresolved vibrations (period ~ 4 steps), whose energy grows through the nonlinear terms
// until Newton fails (swing.json, t = 1.16 s). BDF2 damps them and keeps the swing.
#include <math.h>
#include <string.h>

#include "core/alloc.h"
#include "sim/sim_internal.h"

bool plume_integrator_init(sim_integrator *integrator, plume_integrator kind, int vertex_count)
{
	memset(integrator, 0, sizeof *integrator);
	integrator->kind = kind;
	size_t n = (size_t)(vertex_count > 0 ? vertex_count : 1);
	plume_vec3 **arrays[] = {&integrator->x_back, &integrator->v_back, &integrator->velocity_base,
	                         &integrator->saved_x_back, &integrator->saved_v_back};
	bool ok = true;
	for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i) {
		*arrays[i] = plume_calloc(n, sizeof(plume_vec3));
		ok = ok && *arrays[i] != NULL;
	}
	return ok;
}

void plume_integrator_free(sim_integrator *integrator)
{
	plume_free(integrator->x_back);
	plume_free(integrator->v_back);
	plume_free(integrator->velocity_base);
	plume_free(integrator->saved_x_back);
	plume_free(integrator->saved_v_back);
	memset(integrator, 0, sizeof *integrator);
}

void plume_integrator_save(sim_integrator *integrator, int vertex_count)
{
	size_t bytes = sizeof(plume_vec3) * (size_t)vertex_count;
	memcpy(integrator->saved_x_back, integrator->x_back, bytes);
	memcpy(integrator->saved_v_back, integrator->v_back, bytes);
	integrator->saved_h_back = integrator->h_back;
}

void plume_integrator_restore(sim_integrator *integrator, int vertex_count)
{
	size_t bytes = sizeof(plume_vec3) * (size_t)vertex_count;
	memcpy(integrator->x_back, integrator->saved_x_back, bytes);
	memcpy(integrator->v_back, integrator->saved_v_back, bytes);
	integrator->h_back = integrator->saved_h_back;
}

void plume_integrator_begin(plume_sim *sim, double h, sim_problem *problem)
{
	sim_integrator *integrator = &sim->integrator;
	int n = sim->vertex_count;
	const plume_vec3 *x = sim->x, *v = sim->v;
	memcpy(sim->previous, x, sizeof(plume_vec3) * (size_t)n);
	plume_vec3 *base = integrator->velocity_base, *predicted = sim->predicted;
	*problem = (sim_problem){
	    .dynamic = true, .h = h, .predicted = predicted, .velocity_base = base, .drag_normals = sim->normals};
	double omega = integrator->h_back > 0 ? h / integrator->h_back : 0;
	bool bdf2 = integrator->kind == PLUME_INTEGRATOR_BDF2 && omega > 0 && omega <= 2;
	double a0 = 1, a1 = -1, a2 = 0;
	if (bdf2) {
		a0 = (1 + 2 * omega) / (1 + omega);
		a1 = -(1 + omega);
		a2 = omega * omega / (1 + omega);
	}
	for (int i = 0; i < n; ++i) {
		plume_vec3 xb = bdf2 ? integrator->x_back[i] : x[i], vb = bdf2 ? integrator->v_back[i] : v[i];
		// b = -(a1 x_n + a2 x_{n-1}) / a0 written with a0 + a1 + a2 = 0, so that a vertex that
		// has not moved (a handle held still) gets exactly zero velocity.
		base[i] = plume_v3_mad(x[i], a2 / a0, plume_v3_sub(x[i], xb));
		plume_vec3 vsum = plume_v3_add(plume_v3_scale(v[i], a1), plume_v3_scale(vb, a2));
		predicted[i] = plume_v3_mad(base[i], -h / (a0 * a0), vsum);
	}
	problem->inertia = a0 * a0 / (h * h);
	problem->velocity_scale = a0 / h;
}

void plume_integrator_end(plume_sim *sim, const sim_problem *problem)
{
	sim_integrator *integrator = &sim->integrator;
	int n = sim->vertex_count;
	size_t bytes = sizeof(plume_vec3) * (size_t)n;
	memcpy(integrator->x_back, sim->previous, bytes);
	memcpy(integrator->v_back, sim->v, bytes);
	integrator->h_back = problem->h;
	for (int i = 0; i < n; ++i)
		sim->v[i] = plume_v3_scale(plume_v3_sub(sim->x[i], problem->velocity_base[i]), problem->velocity_scale);
}

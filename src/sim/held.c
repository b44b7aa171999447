// What handles may ask of the inextensible barbs they hold.
//
// A barb constraint whose two ends the handles hold is out of Newton's reach: its length
// is the handles' doing, and a motion that changes it asks for the impossible. So does a
// motion that pulls two held vertices farther apart than the chain of barb edges between
// them is long: every edge of the chain keeps its length, and no chain reaches past its
// own length. Newton, asked for either, cannot make the barbs hold: traced on a lab sample
// whose barbs run from clamp to clamp, a residual of 1e121 N after 50 iterations. Both are
// refused before the solve, saying where.
#include <limits.h>
#include <math.h>

#include "core/alloc.h"
#include "sim/sim_internal.h"

/// The bound on a barb's strain (issue 13: under 1e-8): past it the handles'
/// motion stretches or shortens an inextensible barb.
static const double HELD_BARB_STRAIN = 1e-8;

bool plume_sim_held_init(plume_sim *sim)
{
	int n = sim->vertex_count, m = sim->constraint_count;
	sim->barb_offsets = plume_calloc((size_t)n + 1, sizeof(int));
	sim->barb_incident = plume_alloc(sizeof(int) * (size_t)(2 * m > 0 ? 2 * m : 1));
	sim->held_mark = plume_alloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
	sim->held_stack = plume_alloc(sizeof(sim_chain_step) * (size_t)(n > 0 ? n : 1));
	if (!sim->barb_offsets || !sim->barb_incident || !sim->held_mark || !sim->held_stack)
		return false;
	// Each vertex's constraints, in compressed rows (counting sort by vertex).
	for (int k = 0; k < 2 * m; ++k)
		++sim->barb_offsets[sim->constraint_vertices[k] + 1];
	for (int v = 0; v < n; ++v)
		sim->barb_offsets[v + 1] += sim->barb_offsets[v];
	for (int v = 0; v < n; ++v)
		sim->held_mark[v] = sim->barb_offsets[v];
	for (int k = 0; k < 2 * m; ++k)
		sim->barb_incident[sim->held_mark[sim->constraint_vertices[k]]++] = k / 2;
	for (int v = 0; v < n; ++v)
		sim->held_mark[v] = -1;
	return true;
}

void plume_sim_held_free(plume_sim *sim)
{
	plume_free(sim->barb_offsets);
	plume_free(sim->barb_incident);
	plume_free(sim->held_mark);
	plume_free(sim->held_stack);
}

static bool vertex_held(const plume_sim *sim, int v)
{
	return sim->fixed[3 * v] && sim->fixed[3 * v + 1] && sim->fixed[3 * v + 2];
}

/// A barb edge held at both ends keeps its length.
static plume_status check_held_edges(const plume_sim *sim, plume_error *err)
{
	for (int k = 0; k < sim->constraint_count; ++k) {
		if (!plume_sim_constraint_held(sim, k))
			continue;
		int a = sim->constraint_vertices[2 * k], b = sim->constraint_vertices[2 * k + 1];
		double length = plume_v3_distance(sim->x[a], sim->x[b]), rest = sim->constraint_length[k];
		if (fabs(length - rest) > HELD_BARB_STRAIN * rest)
			return plume_error_set(err, PLUME_ERROR_SPEC,
			                       "the handles hold both ends of the barb edge between vertices %d and %d and "
			                       "change its length from %.6g m to %.6g m (strain %.3g), which its barb "
			                       "constraint forbids: hold one end only, or set the vane's barb_constraint to false",
			                       a, b, rest, length, fabs(length - rest) / rest);
	}
	return PLUME_OK;
}

/// Held vertices joined through free ones by a chain of barb edges are at most the chain's
/// length apart. A depth-first walk from each held vertex through the free ones finds, for
/// each held vertex it meets, one chain between them: the walk's own, which in a barb graph
/// with cycles need not be the shortest, so the test can miss a pair but never refuses one
/// that a chain can reach (barb graphs are trees of guides: the path is the only one).
static plume_status check_held_chains(plume_sim *sim, plume_error *err)
{
	int *mark = sim->held_mark;
	sim_chain_step *stack = sim->held_stack;
	for (int start = 0; start < sim->vertex_count; ++start) {
		if (sim->barb_offsets[start] == sim->barb_offsets[start + 1] || !vertex_held(sim, start))
			continue;
		// Each walk marks what it reached with a stamp of its own.
		if (sim->held_stamp == INT_MAX) {
			for (int v = 0; v < sim->vertex_count; ++v)
				mark[v] = -1;
			sim->held_stamp = 0;
		}
		int stamp = ++sim->held_stamp, top = 0;
		stack[top++] = (sim_chain_step){start, 0, 0.0};
		mark[start] = stamp;
		while (top > 0) {
			sim_chain_step at = stack[--top];
			for (int i = sim->barb_offsets[at.vertex]; i < sim->barb_offsets[at.vertex + 1]; ++i) {
				int k = sim->barb_incident[i];
				int next = sim->constraint_vertices[2 * k] == at.vertex ? sim->constraint_vertices[2 * k + 1]
				                                                        : sim->constraint_vertices[2 * k];
				if (mark[next] == stamp)
					continue;
				mark[next] = stamp;
				sim_chain_step step = {next, at.edges + 1, at.length + sim->constraint_length[k]};
				if (!vertex_held(sim, next)) {
					stack[top++] = step;
					continue;
				}
				// Each pair once, and single edges are check_held_edges's.
				if (next < start || step.edges == 1)
					continue;
				double distance = plume_v3_distance(sim->x[start], sim->x[next]);
				if (distance > (1 + HELD_BARB_STRAIN) * step.length)
					return plume_error_set(
					    err, PLUME_ERROR_SPEC,
					    "the handles hold vertices %d and %d %.6g m apart, but the chain of %d barb edges between "
					    "them is %.6g m long (stretched by %.3g), which its barb constraints forbid: hold the "
					    "chain at one end only, move the handles less far apart, or set the vane's barb_constraint "
					    "to false",
					    start, next, distance, step.edges, step.length, distance / step.length - 1);
			}
		}
	}
	return PLUME_OK;
}

plume_status plume_sim_check_held_barbs(plume_sim *sim, plume_error *err)
{
	plume_status status = check_held_edges(sim, err);
	return status == PLUME_OK ? check_held_chains(sim, err) : status;
}

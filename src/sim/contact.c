// Contact in the simulator: the IPC barrier (Li et al. 2020, "Incremental Potential
// Contact", section 4) added to the incremental potential over the pairs the broad phase
// finds, and continuous collision detection bounding every step (IPC section 5: the line
// search's largest step, and here also the start of every (sub)step).
//
// Primitives: point-triangle pairs (a vertex of one surface against a face of the other,
// or of the same surface when it does not own the vertex) and edge-edge pairs (no shared
// vertex); IPC section 4.1 shows these two kinds cover every distance between two
// triangle meshes. Candidates come from axis-aligned boxes inflated by half the barrier's
// reach d-hat (sim/bvh.h): a pair whose boxes do not overlap is farther apart than d-hat
// along some axis, so it contributes nothing, and the energy is exact whatever the
// candidate set. The potential is a pure function of the positions: an evaluation
// queries the broad phase again (a refit and a traversal), except along a Newton step,
// whose CCD candidates, over boxes swept along it, hold every pair in reach on it.
//
// The pattern of the Newton matrix must hold each active pair's 12 x 12 block. The pattern
// is rebuilt (with its symbolic analysis) only when an active pair couples two vertices it
// does not already couple; it then takes the blocks of every candidate (boxes inflated by
// d-hat / 2: a superset of the active pairs), so pairs that come into reach over the
// next iterations usually find their entries there.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/asserts.h"
#include "core/alloc.h"
#include "sim/ccd.h"
#include "sim/sim_internal.h"

/// m/s^2: the adaptive stiffness's least acceleration without (or with weaker) gravity.
static const double STANDARD_GRAVITY = 9.80665;
/// A pair of one surface closer than d-hat at rest, whose primitives are at most REST_RINGS
/// edges apart on the mesh, repels within REST_REACH of its rest distance.
static const double REST_REACH = 0.5;
enum { REST_RINGS = 3 };
/// The adaptive stiffness's floor doubles after a step whose pairs came closer than this
/// fraction of d-hat (IPC's "the barrier has difficulty pushing the bodies apart").
static const double DOUBLING_DISTANCE = 0.1;
/// The floor's ceiling, relative to the least acceleration (a bound on the doubling).
static const double MAX_ACCELERATION_RATIO = 1e6;

static int compare_edges(const void *a, const void *b)
{
	const int *p = a, *q = b;
	if (p[0] != q[0])
		return p[0] < q[0] ? -1 : 1;
	return (p[1] > q[1]) - (p[1] < q[1]);
}

/// Unique edges (low, high) of triangles, sorted. Returns the count, -1 when out of memory.
static int collect_edges(const int *faces, int face_count, int **out)
{
	int *edges = plume_alloc(sizeof(int) * 6 * (size_t)(face_count > 0 ? face_count : 1));
	if (edges == NULL)
		return -1;
	for (int f = 0; f < face_count; ++f)
		for (int k = 0; k < 3; ++k) {
			int a = faces[3 * f + k], b = faces[3 * f + (k + 1) % 3];
			edges[6 * f + 2 * k] = a < b ? a : b;
			edges[6 * f + 2 * k + 1] = a < b ? b : a;
		}
	qsort(edges, 3 * (size_t)face_count, 2 * sizeof(int), compare_edges);
	int unique = 0;
	for (int e = 0; e < 3 * face_count; ++e)
		if (unique == 0 || compare_edges(edges + 2 * (unique - 1), edges + 2 * e) != 0) {
			edges[2 * unique] = edges[2 * e];
			edges[2 * unique + 1] = edges[2 * e + 1];
			++unique;
		}
	*out = edges;
	return unique;
}

/// |d b(d^2) / dd| at d = d-hat / 2, over d-hat^3: 2 d |b'(d^2)| with b'(s) = -2 (s - s^) ln(s / s^)
/// - (s - s^)^2 / s, at s = s^ / 4: 3 ln 2 + 9 / 4 = 4.3294.
static double barrier_push_at_half(void) { return 3 * log(2.0) + 2.25; }

/// The adaptive stiffness's least acceleration, m/s^2: gravity, and at least standard gravity
/// (a shell without gravity still needs a barrier that holds a weight-like push).
static double minimum_acceleration(const plume_sim *sim)
{
	return fmax(STANDARD_GRAVITY, plume_v3_length(sim->def.gravity));
}

static bool find_candidates(plume_sim *sim, const plume_vec3 *x0, const plume_vec3 *x1, const plume_vec3 *body0,
                            const plume_vec3 *body1, double inflate);
static double pair_distance2(const sim_contact_pair *pair, const plume_vec3 p[4]);

static int compare_pairs(const void *a, const void *b)
{
	const sim_contact_pair *p = a, *q = b;
	if (p->type != q->type)
		return p->type < q->type ? -1 : 1;
	for (int k = 0; k < 4; ++k)
		if (p->vertices[k] != q->vertices[k])
			return p->vertices[k] < q->vertices[k] ? -1 : 1;
	return 0;
}

/// Vertex adjacency of the shell's edges (CSR: neighbours of v in list[start[v] .. start[v + 1])).
typedef struct adjacency {
	int *start, *list;
} adjacency;

static bool build_adjacency(const plume_sim *sim, adjacency *out)
{
	const sim_contact *contact = &sim->contact;
	int n = sim->vertex_count, m = contact->edge_count;
	out->start = plume_alloc(sizeof(int) * (size_t)(n + 1));
	out->list = plume_alloc(sizeof(int) * 2 * (size_t)(m > 0 ? m : 1));
	if (out->start == NULL || out->list == NULL)
		return false;
	memset(out->start, 0, sizeof(int) * (size_t)(n + 1));
	for (int e = 0; e < m; ++e)
		++out->start[contact->edges[2 * e] + 1], ++out->start[contact->edges[2 * e + 1] + 1];
	for (int v = 0; v < n; ++v)
		out->start[v + 1] += out->start[v];
	int *fill = plume_alloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
	if (fill == NULL)
		return false;
	memcpy(fill, out->start, sizeof(int) * (size_t)n);
	for (int e = 0; e < m; ++e) {
		int a = contact->edges[2 * e], b = contact->edges[2 * e + 1];
		out->list[fill[a]++] = b;
		out->list[fill[b]++] = a;
	}
	plume_free(fill);
	return true;
}

/// The primitives of a pair (the first `split` vertices against the rest) are joined by a path
/// of at most REST_RINGS mesh edges. depth[] (vertex_count entries, -1) and queue are scratch,
/// left as given.
static bool topologically_near(const adjacency *graph, const sim_contact_pair *pair, int *depth, int *queue)
{
	int split = pair->type == PLUME_CONTACT_POINT_TRIANGLE ? 1 : 2, head = 0, tail = 0;
	for (int k = 0; k < split; ++k)
		if (depth[pair->vertices[k]] < 0)
			depth[pair->vertices[k]] = 0, queue[tail++] = pair->vertices[k];
	while (head < tail) {
		int v = queue[head++];
		if (depth[v] == REST_RINGS)
			continue;
		for (int j = graph->start[v]; j < graph->start[v + 1]; ++j)
			if (depth[graph->list[j]] < 0)
				depth[graph->list[j]] = depth[v] + 1, queue[tail++] = graph->list[j];
	}
	bool near = false;
	for (int k = split; k < 4; ++k)
		near = near || depth[pair->vertices[k]] >= 0;
	for (int i = 0; i < tail; ++i)
		depth[queue[i]] = -1;
	return near;
}

/// Self-contact pairs closer than d-hat in the rest shape (sim->rest) whose primitives are at
/// most REST_RINGS edges apart, with their reach set to REST_REACH of their rest distance: a
/// barrier of full reach would push on the rest shape from the first step (docs/contact.md
/// "Pairs close at rest"). Pairs touching at rest keep d-hat (their evaluation reports them), and
/// so do pairs farther apart on the mesh (two feathers of one mesh, a vane folded at rest): the
/// barrier pushes those apart. False when out of memory.
static bool find_rest_close(plume_sim *sim)
{
	sim_contact *contact = &sim->contact;
	const plume_contact_def *def = &sim->def.contact;
	if (!def->enabled || !def->self_contact || sim->face_count == 0)
		return true;
	double dhat = def->distance;
	if (!find_candidates(sim, sim->rest, sim->rest, NULL, NULL, 0.5 * dhat))
		return false;
	adjacency graph = {NULL, NULL};
	int *depth = NULL, *queue = NULL;
	bool ok = true;
	for (int p = 0; p < contact->pair_count && ok; ++p) {
		sim_contact_pair pair = contact->pairs[p];
		plume_vec3 points[4];
		for (int k = 0; k < 4; ++k)
			points[k] = sim->rest[pair.vertices[k]];
		double d2 = pair_distance2(&pair, points);
		if (!(d2 < dhat * dhat && d2 > 0))
			continue;
		if (depth == NULL) {
			size_t n = (size_t)sim->vertex_count;
			depth = plume_alloc(sizeof(int) * n);
			queue = plume_alloc(sizeof(int) * n);
			ok = depth != NULL && queue != NULL && build_adjacency(sim, &graph);
			for (size_t v = 0; ok && v < n; ++v)
				depth[v] = -1;
			if (!ok)
				break;
		}
		if (!topologically_near(&graph, &pair, depth, queue))
			continue;
		if (PLUME_GROW(contact->rest_close, contact->rest_close_capacity, contact->rest_close_count + 1) != 0) {
			ok = false;
			break;
		}
		pair.distance2 = d2;
		pair.dhat = REST_REACH * sqrt(d2);
		contact->rest_close[contact->rest_close_count++] = pair;
	}
	plume_free(graph.start), plume_free(graph.list), plume_free(depth), plume_free(queue);
	// Sorted by key for the lookups.
	if (ok && contact->rest_close_count > 0) // (qsort of an empty, never allocated list is undefined)
		qsort(contact->rest_close, (size_t)contact->rest_close_count, sizeof(sim_contact_pair), compare_pairs);
	contact->pair_count = 0;
	return ok;
}

/// A candidate's reach: d-hat, or the reduced reach of a pair close at rest.
static double lookup_reach(const sim_contact *contact, const sim_contact_pair *pair, int vertex_count, double dhat)
{
	if (contact->rest_close_count == 0)
		return dhat;
	for (int k = 0; k < 4; ++k)
		if (pair->vertices[k] >= vertex_count)
			return dhat; // shell-obstacle
	const sim_contact_pair *found =
	    bsearch(pair, contact->rest_close, (size_t)contact->rest_close_count, sizeof(sim_contact_pair), compare_pairs);
	return found != NULL ? found->dhat : dhat;
}

double plume_contact_pair_reach(const plume_sim *sim, const sim_contact_pair *pair)
{
	return lookup_reach(&sim->contact, pair, sim->vertex_count, sim->def.contact.distance);
}

double plume_contact_pair_stiffness(const plume_sim *sim, const sim_contact_pair *pair)
{
	const plume_contact_def *def = &sim->def.contact;
	if (!def->adaptive_stiffness)
		return def->stiffness;
	// kappa |db/dd| at d = d-hat / 2 is 4.33 kappa d-hat^3 (b on squared distances): that force
	// holds the pair's heaviest shell vertex at the (sub)step's acceleration.
	double mass = 0;
	for (int k = 0; k < 4; ++k)
		if (pair->vertices[k] < sim->vertex_count)
			mass = fmax(mass, sim->mass[pair->vertices[k]]);
	if (!(mass > 0))
		return def->stiffness; // massless vertices (no density): nothing to scale by
	double dhat = def->distance;
	return sim->contact.acceleration * mass / (barrier_push_at_half() * dhat * dhat * dhat);
}

bool plume_contact_init(plume_sim *sim)
{
	sim_contact *contact = &sim->contact;
	memset(contact, 0, sizeof *contact);
	contact->min_distance = INFINITY;
	contact->step_min_distance = INFINITY;
	contact->acceleration = contact->acceleration_floor = minimum_acceleration(sim);
	contact->edge_count = collect_edges(sim->faces, sim->face_count, &contact->edges);
	return contact->edge_count >= 0 && find_rest_close(sim);
}

void plume_contact_free(sim_contact *contact)
{
	for (int t = 0; t < SIM_TREE_COUNT; ++t)
		plume_bvh_destroy(contact->trees[t]);
	void *arrays[] = {contact->edges,
	                  contact->obstacles,
	                  contact->body_rest,
	                  contact->body_start,
	                  contact->body_end,
	                  contact->body_x,
	                  contact->body_from,
	                  contact->body_faces,
	                  contact->body_edges,
	                  contact->boxes,
	                  contact->pairs,
	                  contact->active,
	                  contact->energy,
	                  contact->gradient,
	                  contact->hessian,
	                  contact->body_lag,
	                  contact->friction,
	                  contact->friction_gradient,
	                  contact->friction_hessian,
	                  contact->rest_close};
	for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i)
		plume_free(arrays[i]);
	plume_pair_list_free(&contact->overlaps);
	memset(contact, 0, sizeof *contact);
}

bool plume_contact_on(const plume_sim *sim)
{
	return sim->def.contact.enabled && (sim->def.contact.self_contact || sim->contact.obstacle_count > 0);
}

// ---------------------------------------------------------------------------
// Broad phase

/// The points' box, grown by inflate. (With libm's fmin and fmax, calls GCC does not
/// inline, this was 4.5 % of bird-flap.json's run, perf.)
static plume_aabb box_of(const plume_vec3 *points, int count, double inflate)
{
	plume_aabb box = {points[0], points[0]};
	for (int i = 1; i < count; ++i)
		box = plume_aabb_merge(box, (plume_aabb){points[i], points[i]});
	box.lower = plume_v3(box.lower.x - inflate, box.lower.y - inflate, box.lower.z - inflate);
	box.upper = plume_v3(box.upper.x + inflate, box.upper.y + inflate, box.upper.z + inflate);
	return box;
}

/// Boxes of primitives of `size` vertices (indices[size * p + k] into x0 and x1) over the
/// motion from x0 to x1, into the tree `tree` (built on first use, refit after).
static bool fill_tree(sim_contact *contact, int tree, const int *indices, int size, int count, const plume_vec3 *x0,
                      const plume_vec3 *x1, double inflate)
{
	if (PLUME_GROW(contact->boxes, contact->box_capacity, count > 0 ? count : 1) != 0)
		return false;
	for (int p = 0; p < count; ++p) {
		plume_vec3 points[6];
		for (int k = 0; k < size; ++k) {
			int v = indices != NULL ? indices[size * p + k] : p;
			points[k] = x0[v];
			points[size + k] = x1[v];
		}
		contact->boxes[p] = box_of(points, 2 * size, inflate);
	}
	if (contact->trees[tree] != NULL && contact->tree_size[tree] == count) {
		plume_bvh_refit(contact->trees[tree], contact->boxes);
		return true;
	}
	plume_bvh_destroy(contact->trees[tree]);
	contact->trees[tree] = NULL;
	contact->tree_size[tree] = count;
	return plume_bvh_create(contact->boxes, count, &contact->trees[tree], NULL) == PLUME_OK;
}

/// Room for every overlap of the last query (one growth per query, not per pair).
static bool reserve_pairs(sim_contact *contact)
{
	return PLUME_GROW(contact->pairs, contact->pair_capacity, contact->pair_count + contact->overlaps.count + 1) == 0;
}

static void push_pair(sim_contact *contact, plume_contact_pair_type type, int a, int b, int c, int d)
{
	contact->pairs[contact->pair_count++] = (sim_contact_pair){type, {a, b, c, d}, INFINITY, 0};
}

/// Point-triangle candidates: points of tree `points` (indices `point_index`, offset into
/// the combined numbering) against triangles of tree `faces`; pairs where the point is a
/// vertex of the triangle are left out.
/// A shell vertex a handle holds (all three coordinates), for shell-obstacle pairs.
static bool held(const plume_sim *sim, int v)
{
	return v < sim->vertex_count && sim->fixed[3 * v] && sim->fixed[3 * v + 1] && sim->fixed[3 * v + 2];
}

static bool any_held(const plume_sim *sim, const int *vertices, int count)
{
	for (int k = 0; k < count; ++k)
		if (held(sim, vertices[k]))
			return true;
	return false;
}

static bool query_point_triangle(plume_sim *sim, int points, int point_offset, int faces, const int *face_vertices,
                                 int face_offset)
{
	sim_contact *contact = &sim->contact;
	// Shell-obstacle pairs leave out the shell's primitives at a held vertex (the attachment).
	bool attachment = point_offset != face_offset;
	contact->overlaps.count = 0;
	if (contact->tree_size[points] == 0 || contact->tree_size[faces] == 0)
		return true;
	if (plume_bvh_overlaps(contact->trees[points], contact->trees[faces], &contact->overlaps, NULL) != PLUME_OK ||
	    !reserve_pairs(contact))
		return false;
	for (int k = 0; k < contact->overlaps.count; ++k) {
		int p = contact->overlaps.pairs[2 * k] + point_offset;
		const int *t = face_vertices + 3 * contact->overlaps.pairs[2 * k + 1];
		int a = t[0] + face_offset, b = t[1] + face_offset, c = t[2] + face_offset;
		int vertices[4] = {p, a, b, c};
		if (p == a || p == b || p == c || (attachment && any_held(sim, vertices, 4)))
			continue;
		push_pair(contact, PLUME_CONTACT_POINT_TRIANGLE, p, a, b, c);
	}
	return true;
}

static bool query_edge_edge(plume_sim *sim, int first, const int *first_edges, int first_offset, int second,
                            const int *second_edges, int second_offset)
{
	sim_contact *contact = &sim->contact;
	bool attachment = first_offset != second_offset;
	contact->overlaps.count = 0;
	if (contact->tree_size[first] == 0 || contact->tree_size[second] == 0)
		return true;
	if (plume_bvh_overlaps(contact->trees[first], contact->trees[second], &contact->overlaps, NULL) != PLUME_OK ||
	    !reserve_pairs(contact))
		return false;
	for (int k = 0; k < contact->overlaps.count; ++k) {
		const int *e = first_edges + 2 * contact->overlaps.pairs[2 * k];
		const int *f = second_edges + 2 * contact->overlaps.pairs[2 * k + 1];
		int a0 = e[0] + first_offset, a1 = e[1] + first_offset, b0 = f[0] + second_offset, b1 = f[1] + second_offset;
		int vertices[4] = {a0, a1, b0, b1};
		if (a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1 || (attachment && any_held(sim, vertices, 4)))
			continue;
		push_pair(contact, PLUME_CONTACT_EDGE_EDGE, a0, a1, b0, b1);
	}
	return true;
}

/// Every pair whose boxes, over the shell's motion x0 -> x1 and the obstacles' body0 ->
/// body1, inflated by `inflate`, overlap. Sorted by query, then by the trees' order: the
/// same on every run. False when out of memory.
static bool find_candidates(plume_sim *sim, const plume_vec3 *x0, const plume_vec3 *x1, const plume_vec3 *body0,
                            const plume_vec3 *body1, double inflate)
{
	sim_contact *contact = &sim->contact;
	int n = sim->vertex_count;
	bool self = sim->def.contact.self_contact, bodies = contact->body_face_count > 0;
	contact->pair_count = 0;
	bool ok = fill_tree(contact, SIM_TREE_VERTEX, NULL, 1, n, x0, x1, inflate) &&
	          fill_tree(contact, SIM_TREE_FACE, sim->faces, 3, sim->face_count, x0, x1, inflate) &&
	          fill_tree(contact, SIM_TREE_EDGE, contact->edges, 2, contact->edge_count, x0, x1, inflate);
	if (ok && bodies)
		ok = fill_tree(contact, SIM_TREE_BODY_VERTEX, NULL, 1, contact->body_vertex_count, body0, body1, inflate) &&
		     fill_tree(contact, SIM_TREE_BODY_FACE, contact->body_faces, 3, contact->body_face_count, body0, body1,
		               inflate) &&
		     fill_tree(contact, SIM_TREE_BODY_EDGE, contact->body_edges, 2, contact->body_edge_count, body0, body1,
		               inflate);
	if (ok && self)
		ok = query_point_triangle(sim, SIM_TREE_VERTEX, 0, SIM_TREE_FACE, sim->faces, 0) &&
		     query_edge_edge(sim, SIM_TREE_EDGE, contact->edges, 0, SIM_TREE_EDGE, contact->edges, 0);
	if (ok && bodies)
		ok = query_point_triangle(sim, SIM_TREE_VERTEX, 0, SIM_TREE_BODY_FACE, contact->body_faces, n) &&
		     query_point_triangle(sim, SIM_TREE_BODY_VERTEX, n, SIM_TREE_FACE, sim->faces, 0) &&
		     query_edge_edge(sim, SIM_TREE_EDGE, contact->edges, 0, SIM_TREE_BODY_EDGE, contact->body_edges, n);
	return ok;
}

static void gather_pair(const plume_sim *sim, const sim_contact_pair *pair, const plume_vec3 *x, const plume_vec3 *body,
                        plume_vec3 out[4])
{
	int n = sim->vertex_count;
	for (int k = 0; k < 4; ++k)
		out[k] = pair->vertices[k] < n ? x[pair->vertices[k]] : body[pair->vertices[k] - n];
}

static double pair_distance2(const sim_contact_pair *pair, const plume_vec3 p[4])
{
	return pair->type == PLUME_CONTACT_POINT_TRIANGLE ? plume_point_triangle_distance2(p[0], p[1], p[2], p[3], NULL)
	                                                  : plume_edge_edge_distance2(p[0], p[1], p[2], p[3], NULL);
}

// ---------------------------------------------------------------------------
// The barrier in the potential

/// The pattern holds every entry of the pair's block between free unknowns.
static bool pattern_holds(const plume_sim *sim, const sim_contact_pair *pair)
{
	int n = sim->vertex_count;
	for (int a = 0; a < 4; ++a)
		for (int b = a + 1; b < 4; ++b) {
			int va = pair->vertices[a], vb = pair->vertices[b];
			if (va >= n || vb >= n)
				continue;
			if (plume_sparse_find(&sim->kkt.system, 3 * va, 3 * vb) < 0)
				return false;
		}
	return true;
}

/// Rebuilds the KKT pattern with the blocks of every current candidate (obstacle vertices
/// left out: they are no unknowns).
static bool rebuild_pattern(plume_sim *sim)
{
	sim_contact *contact = &sim->contact;
	int n = sim->vertex_count;
	int friction = contact->friction_used ? contact->friction_count : 0, count = contact->pair_count + friction;
	int *blocks = plume_alloc(sizeof(int) * 4 * (size_t)(count > 0 ? count : 1));
	if (blocks == NULL)
		return false;
	for (int p = 0; p < count; ++p)
		for (int k = 0; k < 4; ++k) {
			int v = p < contact->pair_count ? contact->pairs[p].vertices[k]
			                                : contact->friction[p - contact->pair_count].vertices[k];
			blocks[4 * p + k] = v < n ? v : -1;
		}
	plume_status status = plume_kkt_set_extra_blocks(&sim->kkt, count, blocks, NULL);
	plume_free(blocks);
	++contact->pattern_rebuilds;
	return status == PLUME_OK;
}

static double fail(sim_contact *contact, plume_status status, const char *message)
{
	contact->failure = status;
	snprintf(contact->message, sizeof contact->message, "%s", message);
	return NAN;
}

static double evaluate_friction(plume_sim *sim, const plume_vec3 *x, bool hessian);
static bool friction_pattern_holds(const plume_sim *sim);

/// Finds the pairs in reach at x (contact->active) and their smallest distance. Returns
/// false when out of memory.
static bool find_active(plume_sim *sim, const plume_vec3 *x)
{
	sim_contact *contact = &sim->contact;
	double dhat = sim->def.contact.distance, closest = INFINITY;
	// Boxes inflated by d-hat / 2 overlap whenever the primitives are closer than d-hat.
	if (!contact->reuse_candidates && !find_candidates(sim, x, x, contact->body_x, contact->body_x, 0.5 * dhat))
		return false;
	for (int p = 0; p < contact->pair_count; ++p) {
		sim_contact_pair *pair = contact->pairs + p;
		plume_vec3 points[4];
		gather_pair(sim, pair, x, contact->body_x, points);
		pair->distance2 = pair_distance2(pair, points);
		if (pair->distance2 >= dhat * dhat)
			continue;
		pair->dhat = lookup_reach(contact, pair, sim->vertex_count, dhat);
		if (pair->distance2 >= pair->dhat * pair->dhat)
			continue;
		if (PLUME_GROW(contact->active, contact->active_capacity, contact->active_count + 1) != 0)
			return false;
		contact->active[contact->active_count++] = p;
		closest = fmin(closest, pair->distance2);
	}
	contact->min_distance = sqrt(closest);
	return true;
}

/// Per-pair buffers grow with the active list's capacity and are reused.
static bool grow_buffers(sim_contact *contact)
{
	if (contact->active_count <= contact->buffer_capacity)
		return true;
	size_t capacity = (size_t)contact->active_capacity;
	double *energy = plume_realloc(contact->energy, sizeof(double) * capacity);
	if (energy != NULL)
		contact->energy = energy;
	double *gradient = energy ? plume_realloc(contact->gradient, sizeof(double) * 12 * capacity) : NULL;
	if (gradient != NULL)
		contact->gradient = gradient;
	double *block = gradient ? plume_realloc(contact->hessian, sizeof(double) * 144 * capacity) : NULL;
	if (block == NULL)
		return false;
	contact->hessian = block;
	contact->buffer_capacity = contact->active_capacity;
	return true;
}

double plume_contact_evaluate(plume_sim *sim, const plume_vec3 *x, bool gradient, bool hessian, bool friction)
{
	sim_contact *contact = &sim->contact;
	const plume_contact_def *def = &sim->def.contact;
	contact->active_count = 0;
	contact->min_distance = INFINITY;
	contact->failure = PLUME_OK;
	contact->friction_used = friction && contact->friction_count > 0 && def->friction > 0;
	if (!find_active(sim, x))
		return fail(contact, PLUME_ERROR_MEMORY, "out of memory finding contact pairs");
	int count = contact->active_count;
	if (count > 0 && !(contact->min_distance > 0)) {
		// In contact: outside the barrier's domain. A line search's trial never gets here
		// (CCD); a start state can (a mesh or obstacle that touches itself).
		const sim_contact_pair *pair = contact->pairs + contact->active[0];
		for (int k = 0; k < count; ++k)
			if (!(contact->pairs[contact->active[k]].distance2 > 0))
				pair = contact->pairs + contact->active[k];
		fail(contact, PLUME_ERROR_NUMERIC, "");
		snprintf(contact->message, sizeof contact->message,
		         "contact: surfaces touch (%s pair of vertices %d %d %d %d; numbers from %d are obstacle vertices)",
		         pair->type == PLUME_CONTACT_POINT_TRIANGLE ? "point-triangle" : "edge-edge", pair->vertices[0],
		         pair->vertices[1], pair->vertices[2], pair->vertices[3], sim->vertex_count);
		return INFINITY;
	}
	if (!grow_buffers(contact))
		return fail(contact, PLUME_ERROR_MEMORY, "out of memory evaluating contact pairs");
	if (hessian) {
		bool holds = !contact->friction_used || friction_pattern_holds(sim);
		for (int k = 0; k < count && holds; ++k)
			holds = pattern_holds(sim, contact->pairs + contact->active[k]);
		if (!holds && !rebuild_pattern(sim))
			return fail(contact, PLUME_ERROR_MEMORY, "out of memory rebuilding the solver's pattern");
	}
	plume_vec3 *rest = sim->rest;
#pragma omp parallel for schedule(static) if (count >= 4096)
	for (int k = 0; k < count; ++k) {
		const sim_contact_pair *pair = contact->pairs + contact->active[k];
		plume_vec3 points[4], reference[4];
		gather_pair(sim, pair, x, contact->body_x, points);
		gather_pair(sim, pair, rest, contact->body_rest, reference);
		contact->energy[k] = plume_contact_pair_energy(pair->type, points, reference, pair->dhat,
		                                               plume_contact_pair_stiffness(sim, pair), true,
		                                               gradient || hessian ? contact->gradient + 12 * (size_t)k : NULL,
		                                               hessian ? contact->hessian + 144 * (size_t)k : NULL);
	}
	double total = 0;
	for (int k = 0; k < count; ++k)
		total += contact->energy[k];
	if (contact->friction_used) {
		double dissipation = evaluate_friction(sim, x, hessian);
		if (isnan(dissipation))
			return fail(contact, PLUME_ERROR_MEMORY, "out of memory evaluating friction");
		total += dissipation;
	}
	return total;
}

static void scatter_pair(plume_sim *sim, const int *vertices, const double *g, const double *h, double *gradient,
                         double *values)
{
	int n = sim->vertex_count;
	for (int a = 0; a < 12; ++a) {
		int va = vertices[a / 3];
		if (va >= n)
			continue;
		int i = 3 * va + a % 3;
		if (gradient != NULL)
			gradient[i] += g[a];
		if (values == NULL || sim->fixed[i])
			continue;
		for (int b = 0; b < 12; ++b) {
			int vb = vertices[b / 3];
			if (vb >= n)
				continue;
			int j = 3 * vb + b % 3;
			if (i > j || sim->fixed[j])
				continue; // the upper triangle holds each symmetric pair once
			int slot = plume_sparse_find(&sim->kkt.system, i, j);
			PLUME_ASSERT(slot >= 0); // plume_contact_evaluate made the pattern hold it
			values[slot] += h[12 * a + b];
		}
	}
}

void plume_contact_energies(plume_sim *sim, const plume_vec3 *x, double *barrier, double *friction)
{
	*barrier = *friction = 0;
	if (!plume_contact_on(sim))
		return;
	*barrier = plume_contact_evaluate(sim, x, false, false, false);
	if (sim->def.contact.friction > 0 && sim->contact.friction_count > 0)
		*friction = evaluate_friction(sim, x, false);
}

bool plume_contact_any(const plume_sim *sim) { return sim->contact.active_count > 0 || sim->contact.friction_used; }

void plume_contact_scatter(plume_sim *sim, double *gradient, double *values)
{
	sim_contact *contact = &sim->contact;
	for (int k = 0; k < contact->active_count; ++k)
		scatter_pair(sim, contact->pairs[contact->active[k]].vertices, contact->gradient + 12 * (size_t)k,
		             contact->hessian + 144 * (size_t)k, gradient, values);
	for (int k = 0; contact->friction_used && k < contact->friction_count; ++k)
		scatter_pair(sim, contact->friction[k].vertices, contact->friction_gradient + 12 * (size_t)k,
		             contact->friction_hessian + 144 * (size_t)k, gradient, values);
}

plume_vec3 plume_contact_obstacle_force(plume_sim *sim, int obstacle, const plume_vec3 *x)
{
	PLUME_ASSERT_INDEX(obstacle, sim->contact.obstacle_count);
	plume_contact_evaluate(sim, x, true, false, false);
	const sim_contact *contact = &sim->contact;
	const sim_obstacle *body = contact->obstacles + obstacle;
	int n = sim->vertex_count;
	plume_vec3 force = {0, 0, 0};
	for (int k = 0; k < contact->active_count; ++k) {
		const int *vertices = contact->pairs[contact->active[k]].vertices;
		const double *g = contact->gradient + 12 * (size_t)k;
		for (int a = 0; a < 4; ++a) {
			int v = vertices[a] - n - body->first_vertex;
			if (v >= 0 && v < body->vertex_count)
				force = plume_v3_sub(force, plume_v3(g[3 * a], g[3 * a + 1], g[3 * a + 2]));
		}
	}
	return force;
}

static void place_bodies(sim_contact *contact, double s, plume_vec3 *out)
{
	for (int i = 0; i < contact->body_vertex_count; ++i)
		out[i] = s == 1 ? contact->body_end[i] : plume_v3_lerp(contact->body_start[i], contact->body_end[i], s);
}

// ---------------------------------------------------------------------------
// Friction: IPC's lagged, smoothed Coulomb friction (Li et al. 2020, section 5.3 and
// eqs. 16-21). At a step's start each pair in reach gets its normal force lambda (the
// barrier's push), its tangent plane (normal to the closest points' direction) and the
// weights that make the closest points' relative displacement u = sum_j w_j (x_j - x_j^t);
// within the step the dissipation potential mu lambda f0(|T^T u|) opposes sliding, with f0
// IPC's C1 smoothing of |.| over eps = eps_v h: its Hessian, mu lambda w_i w_j T M T^T, is
// positive semidefinite as it is (M below), so it needs no projection.

/// The smoothing speed eps_v, m/s: below it friction acts as a viscous force (IPC uses 1e-3
/// times the scene's size per second; a feather is about a tenth of a metre).
static const double FRICTION_SPEED = 1e-4;

static bool friction_pattern_holds(const plume_sim *sim)
{
	for (int k = 0; k < sim->contact.friction_count; ++k) {
		sim_contact_pair pair = {PLUME_CONTACT_POINT_TRIANGLE, {0, 0, 0, 0}, 0, 0};
		memcpy(pair.vertices, sim->contact.friction[k].vertices, sizeof pair.vertices);
		if (!pattern_holds(sim, &pair))
			return false;
	}
	return true;
}

static double clamp01(double t) { return t < 0 ? 0 : t > 1 ? 1 : t; }

/// The weights of the closest points' difference (point minus triangle, or edge a minus edge
/// b) in the region the distance function chose.
static void closest_weights(const sim_contact_pair *pair, const plume_vec3 p[4], double w[4])
{
	plume_distance_kind kind;
	if (pair->type == PLUME_CONTACT_POINT_TRIANGLE) {
		plume_point_triangle_distance2(p[0], p[1], p[2], p[3], &kind);
		double b[3] = {0, 0, 0};
		int edge = kind == PLUME_PT_AB ? 0 : kind == PLUME_PT_BC ? 1 : kind == PLUME_PT_CA ? 2 : -1;
		if (kind <= PLUME_PT_C) {
			b[kind - PLUME_PT_A] = 1;
		} else if (edge >= 0) {
			int i = edge, j = (edge + 1) % 3;
			plume_vec3 e = plume_v3_sub(p[1 + j], p[1 + i]);
			double t = clamp01(plume_v3_dot(plume_v3_sub(p[0], p[1 + i]), e) / plume_v3_dot(e, e));
			b[i] = 1 - t, b[j] = t;
		} else {
			plume_vec3 e0 = plume_v3_sub(p[2], p[1]), e1 = plume_v3_sub(p[3], p[1]), r = plume_v3_sub(p[0], p[1]);
			double d00 = plume_v3_dot(e0, e0), d01 = plume_v3_dot(e0, e1), d11 = plume_v3_dot(e1, e1);
			double d20 = plume_v3_dot(r, e0), d21 = plume_v3_dot(r, e1), det = d00 * d11 - d01 * d01;
			b[1] = (d11 * d20 - d01 * d21) / det;
			b[2] = (d00 * d21 - d01 * d20) / det;
			b[0] = 1 - b[1] - b[2];
		}
		w[0] = 1, w[1] = -b[0], w[2] = -b[1], w[3] = -b[2];
		return;
	}
	plume_edge_edge_distance2(p[0], p[1], p[2], p[3], &kind);
	plume_vec3 ea = plume_v3_sub(p[1], p[0]), eb = plume_v3_sub(p[3], p[2]);
	double s = 0, t = 0;
	switch (kind) {
	case PLUME_EE_A0_B0: break;
	case PLUME_EE_A0_B1: t = 1; break;
	case PLUME_EE_A1_B0: s = 1; break;
	case PLUME_EE_A1_B1: s = 1, t = 1; break;
	case PLUME_EE_A0_B: t = clamp01(plume_v3_dot(plume_v3_sub(p[0], p[2]), eb) / plume_v3_dot(eb, eb)); break;
	case PLUME_EE_A1_B: s = 1, t = clamp01(plume_v3_dot(plume_v3_sub(p[1], p[2]), eb) / plume_v3_dot(eb, eb)); break;
	case PLUME_EE_A_B0: s = clamp01(plume_v3_dot(plume_v3_sub(p[2], p[0]), ea) / plume_v3_dot(ea, ea)); break;
	case PLUME_EE_A_B1: t = 1, s = clamp01(plume_v3_dot(plume_v3_sub(p[3], p[0]), ea) / plume_v3_dot(ea, ea)); break;
	default: {
		// The lines' closest points: minimise |a0 + s ea - b0 - t eb|^2.
		plume_vec3 r = plume_v3_sub(p[0], p[2]);
		double a = plume_v3_dot(ea, ea), b = plume_v3_dot(ea, eb), c = plume_v3_dot(eb, eb);
		double d = plume_v3_dot(ea, r), e = plume_v3_dot(eb, r), det = a * c - b * b;
		s = det > 0 ? clamp01((b * e - c * d) / det) : 0;
		t = det > 0 ? clamp01((a * e - b * d) / det) : 0;
	}
	}
	w[0] = 1 - s, w[1] = s, w[2] = -(1 - t), w[3] = -t;
}

/// The adaptive stiffness's acceleration for a (sub)step of length h (0: statics), m/s^2: what
/// the barrier must hold at d-hat / 2. Gravity and loads (the pushes of resting contact); in
/// dynamics the fastest shell or obstacle vertex's speed over h, the deceleration that stops
/// it within the step (a vertex hitting at v is stopped by m v / h, implicit Euler's inertia
/// m (x~ - x) / h^2 for a prediction x~ a step v h past the contact); at least the floor.
static double step_acceleration(const plume_sim *sim, double h)
{
	const sim_contact *contact = &sim->contact;
	double a = fmax(contact->acceleration_floor, minimum_acceleration(sim)), speed = 0;
	for (int i = 0; i < sim->vertex_count; ++i) {
		if (sim->mass[i] > 0)
			a = fmax(a, plume_v3_length(sim->load[i]) / sim->mass[i]);
		speed = fmax(speed, plume_v3_length(sim->v[i]));
	}
	if (h > 0 && sim->def.time_step > 0)
		for (int i = 0; i < contact->body_vertex_count; ++i)
			speed = fmax(speed, plume_v3_distance(contact->body_start[i], contact->body_end[i]) / sim->def.time_step);
	return h > 0 ? fmax(a, speed / h) : a;
}

static bool lag_friction(plume_sim *sim, double s0, double h);

bool plume_contact_stiffen(plume_sim *sim, double previous, double closest)
{
	sim_contact *contact = &sim->contact;
	double limit = DOUBLING_DISTANCE * sim->def.contact.distance;
	double ceiling = MAX_ACCELERATION_RATIO * minimum_acceleration(sim);
	if (!(closest < limit && closest < previous && contact->acceleration < ceiling))
		return false;
	contact->acceleration = fmin(2 * contact->acceleration, ceiling);
	return true;
}

bool plume_contact_lag_friction(plume_sim *sim, double s0, double h)
{
	sim_contact *contact = &sim->contact;
	contact->friction_count = 0;
	// The friction's normal forces are the barrier's pushes at the end of the last solve, with
	// its stiffness: the (sub)step's own is fixed after them.
	bool ok = lag_friction(sim, s0, h);
	contact->acceleration = step_acceleration(sim, h);
	return ok;
}

static bool lag_friction(plume_sim *sim, double s0, double h)
{
	sim_contact *contact = &sim->contact;
	const plume_contact_def *def = &sim->def.contact;
	if (!plume_contact_on(sim) || !(def->friction > 0) || !(h > 0))
		return true;
	contact->friction_epsilon = FRICTION_SPEED * h;
	place_bodies(contact, s0, contact->body_lag);
	double dhat = def->distance, dhat2 = dhat * dhat;
	if (!find_candidates(sim, sim->previous, sim->previous, contact->body_lag, contact->body_lag, 0.5 * dhat))
		return false;
	for (int p = 0; p < contact->pair_count; ++p) {
		const sim_contact_pair *pair = contact->pairs + p;
		plume_vec3 points[4];
		gather_pair(sim, pair, sim->previous, contact->body_lag, points);
		double d2 = pair_distance2(pair, points), db;
		if (!(d2 < dhat2 && d2 > 0))
			continue;
		double reach = plume_contact_pair_reach(sim, pair);
		if (!(d2 < reach * reach))
			continue;
		plume_barrier(d2, reach * reach, &db, NULL);
		if (PLUME_GROW(contact->friction, contact->friction_capacity, contact->friction_count + 1) != 0)
			return false;
		sim_friction_pair *f = contact->friction + contact->friction_count;
		memcpy(f->vertices, pair->vertices, sizeof f->vertices);
		closest_weights(pair, points, f->weights);
		plume_vec3 u = {0, 0, 0};
		for (int k = 0; k < 4; ++k)
			u = plume_v3_mad(u, f->weights[k], points[k]);
		double d = plume_v3_length(u);
		if (!(d > 0))
			continue;
		plume_vec3 n = plume_v3_scale(u, 1 / d);
		// Any unit vector across n, then the third axis.
		plume_vec3 axis = fabs(n.x) < 0.6 ? plume_v3(1, 0, 0) : plume_v3(0, 1, 0);
		f->tangent[0] = plume_v3_normalize(plume_v3_cross(n, axis));
		f->tangent[1] = plume_v3_cross(n, f->tangent[0]);
		// -dE/dd = -kappa b'(d^2) 2 d: the barrier's push (b' < 0 within reach).
		f->normal_force = -plume_contact_pair_stiffness(sim, pair) * db * 2 * sqrt(d2);
		++contact->friction_count;
	}
	int count = contact->friction_count > 0 ? contact->friction_count : 1;
	if (count > contact->friction_buffer_capacity) {
		double *g = plume_realloc(contact->friction_gradient, sizeof(double) * 12 * (size_t)count);
		if (g != NULL)
			contact->friction_gradient = g;
		double *hh = g ? plume_realloc(contact->friction_hessian, sizeof(double) * 144 * (size_t)count) : NULL;
		if (hh == NULL)
			return false;
		contact->friction_hessian = hh;
		contact->friction_buffer_capacity = count;
	}
	return true;
}

/// IPC's f0 (eq. 18) over eps, and f1(y) / y and the 2 x 2 matrix M of the Hessian.
static double friction_f0(double y, double eps)
{
	return y < eps ? y * y / eps - y * y * y / (3 * eps * eps) + eps / 3 : y;
}

static double evaluate_friction(plume_sim *sim, const plume_vec3 *x, bool hessian)
{
	sim_contact *contact = &sim->contact;
	double mu = sim->def.contact.friction, eps = contact->friction_epsilon, total = 0;
	int n = sim->vertex_count;
	for (int k = 0; k < contact->friction_count; ++k) {
		const sim_friction_pair *f = contact->friction + k;
		plume_vec3 u = {0, 0, 0};
		for (int j = 0; j < 4; ++j) {
			int v = f->vertices[j];
			plume_vec3 now = v < n ? x[v] : contact->body_x[v - n];
			plume_vec3 then = v < n ? sim->previous[v] : contact->body_lag[v - n];
			u = plume_v3_mad(u, f->weights[j], plume_v3_sub(now, then));
		}
		double v2[2] = {plume_v3_dot(f->tangent[0], u), plume_v3_dot(f->tangent[1], u)};
		double y = hypot(v2[0], v2[1]), scale = mu * f->normal_force;
		total += scale * friction_f0(y, eps);
		// d f0 / d v = (f1(y) / y) v; f1(y) / y = 2 / eps - y / eps^2 below eps, 1 / y above.
		double f1_over_y = y < eps ? 2 / eps - y / (eps * eps) : 1 / y;
		plume_vec3 tv = plume_v3_add(plume_v3_scale(f->tangent[0], v2[0]), plume_v3_scale(f->tangent[1], v2[1]));
		double *g = contact->friction_gradient + 12 * (size_t)k;
		for (int j = 0; j < 4; ++j) {
			double c = scale * f1_over_y * f->weights[j];
			g[3 * j] = c * tv.x, g[3 * j + 1] = c * tv.y, g[3 * j + 2] = c * tv.z;
		}
		if (!hessian)
			continue;
		// M = (f1/y) I + (d(f1/y)/dy / y) v v^T: below eps (2/eps - y/eps^2) I - v v^T / (eps^2 y),
		// above (I - v v^T / y^2) / y; both positive semidefinite (eigenvalues >= 0 for y <= eps).
		double m[2][2];
		for (int a = 0; a < 2; ++a)
			for (int b = 0; b < 2; ++b) {
				double outer = v2[a] * v2[b];
				double extra = y < eps ? (y > 0 ? -outer / (eps * eps * y) : 0) : -outer / (y * y * y);
				m[a][b] = (a == b ? f1_over_y : 0) + extra;
			}
		// T M T^T (3 x 3), then the 12 x 12 blocks w_i w_j scale T M T^T.
		double tm[3][3];
		const double t[2][3] = {{f->tangent[0].x, f->tangent[0].y, f->tangent[0].z},
		                        {f->tangent[1].x, f->tangent[1].y, f->tangent[1].z}};
		for (int r = 0; r < 3; ++r)
			for (int c = 0; c < 3; ++c) {
				double sum = 0;
				for (int a = 0; a < 2; ++a)
					for (int b = 0; b < 2; ++b)
						sum += t[a][r] * m[a][b] * t[b][c];
				tm[r][c] = sum;
			}
		double *h = contact->friction_hessian + 144 * (size_t)k;
		for (int i = 0; i < 12; ++i)
			for (int j = 0; j < 12; ++j)
				h[12 * i + j] = scale * f->weights[i / 3] * f->weights[j / 3] * tm[i % 3][j % 3];
	}
	return total;
}

// ---------------------------------------------------------------------------
// Continuous collision detection

double plume_contact_step_bound(plume_sim *sim, const plume_vec3 *x0, const plume_vec3 *x1, const plume_vec3 *body0,
                                const plume_vec3 *body1)
{
	sim_contact *contact = &sim->contact;
	// Pairs whose swept boxes do not overlap never touch; those that come within the
	// separation of their distance without touching are harmless (the barrier sees them
	// at the next evaluation). A margin of d-hat / 2 keeps rounding in the boxes harmless.
	if (!find_candidates(sim, x0, x1, body0, body1, 0.5 * sim->def.contact.distance))
		return NAN;
	double separation = sim->def.contact.ccd_separation, bound = 1;
	int count = contact->pair_count;
#pragma omp parallel for schedule(static) reduction(min : bound) if (count >= 4096)
	for (int p = 0; p < count; ++p) {
		const sim_contact_pair *pair = contact->pairs + p;
		plume_vec3 start[4], end[4];
		gather_pair(sim, pair, x0, body0, start);
		gather_pair(sim, pair, x1, body1, end);
		double t = pair->type == PLUME_CONTACT_POINT_TRIANGLE ? plume_ccd_point_triangle(start, end, separation)
		                                                      : plume_ccd_edge_edge(start, end, separation);
		bound = fmin(bound, t);
	}
	return bound;
}

/// The handle vertices of x at step fraction s (sim.c's plume_sim_place_handles, into any array).
static void place_handles(const plume_sim *sim, double s, plume_vec3 *x)
{
	for (int h = 0; h < sim->handle_count; ++h) {
		const sim_handle *handle = sim->handles + h;
		for (int i = 0; i < handle->count; ++i)
			x[handle->vertices[i]] = s == 1 ? handle->end[i] : plume_v3_lerp(handle->start[i], handle->end[i], s);
	}
}

/// Advances the prescribed motion (handles, obstacles) of the substep [s0, s1] from the fraction
/// *reached of it as far as CCD allows with the free vertices where they are in sim->x.
static plume_status advance_prescribed(plume_sim *sim, double s0, double s1, double *reached, plume_error *err)
{
	sim_contact *contact = &sim->contact;
	double from = s0 + *reached * (s1 - s0);
	memcpy(sim->scratch, sim->x, sizeof(plume_vec3) * (size_t)sim->vertex_count);
	place_handles(sim, s1, sim->scratch);
	place_bodies(contact, from, contact->body_from);
	place_bodies(contact, s1, contact->body_x);
	double t = plume_contact_step_bound(sim, sim->x, sim->scratch, contact->body_from, contact->body_x);
	if (isnan(t))
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory finding contact pairs");
	double next = t >= 1 ? 1 : *reached + t * (1 - *reached);
	if (!(next - *reached > 1e-6))
		return plume_error_set(
		    err, PLUME_ERROR_NUMERIC,
		    "the prescribed motion (handles, obstacles) cannot advance without closing a contact gap "
		    "by more than %g of it",
		    1 - sim->def.contact.ccd_separation);
	*reached = next;
	double s = next >= 1 ? s1 : s0 + next * (s1 - s0);
	place_handles(sim, s, sim->x);
	place_bodies(contact, s, contact->body_x);
	return PLUME_OK;
}

plume_status plume_contact_begin(plume_sim *sim, double s0, double s1, double *reached, plume_error *err)
{
	sim_contact *contact = &sim->contact;
	if (!plume_contact_on(sim)) {
		place_bodies(contact, s1, contact->body_x);
		*reached = 1;
		return PLUME_OK;
	}
	if (*reached > 0)
		return advance_prescribed(sim, s0, s1, reached, err);
	// Refitting keeps the trees' topology, which loosens as the shell deforms: build them
	// anew once a (sub)step.
	for (int t = 0; t < SIM_TREE_COUNT; ++t)
		contact->tree_size[t] = -1;
	place_bodies(contact, s0, contact->body_from);
	place_bodies(contact, s1, contact->body_x);
	double bound = plume_contact_step_bound(sim, sim->previous, sim->x, contact->body_from, contact->body_x);
	if (bound >= 1) {
		*reached = 1;
		return PLUME_OK;
	}
	// The inertial prediction closes a gap: free unknowns start where they were, and only the
	// prescribed motion (handles, obstacles) remains to check.
	for (int i = 0; i < 3 * sim->vertex_count; ++i)
		if (!sim->fixed[i])
			(&sim->x[i / 3].x)[i % 3] = (&sim->previous[i / 3].x)[i % 3];
	bound = plume_contact_step_bound(sim, sim->previous, sim->x, contact->body_from, contact->body_x);
	if (isnan(bound))
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory finding contact pairs");
	if (bound >= 1) {
		*reached = 1;
		return PLUME_OK;
	}
	// That closes a gap too: everything starts where it was, and the prescribed motion goes as
	// far as it can; the caller solves there and calls again for the rest.
	memcpy(sim->x, sim->previous, sizeof(plume_vec3) * (size_t)sim->vertex_count);
	return advance_prescribed(sim, s0, s1, reached, err);
}

void plume_contact_finish(plume_sim *sim)
{
	sim_contact *contact = &sim->contact;
	// IPC's doubling (Li et al. 2020, supplement "Adaptive barrier stiffness"): pairs that came
	// far inside the reach say the barrier is soft for this motion; later steps start stiffer.
	if (sim->def.contact.adaptive_stiffness &&
	    contact->step_min_distance < DOUBLING_DISTANCE * sim->def.contact.distance)
		contact->acceleration_floor =
		    fmin(2 * contact->acceleration_floor, MAX_ACCELERATION_RATIO * minimum_acceleration(sim));
	contact->step_min_distance = INFINITY;
	if (contact->body_vertex_count > 0) // no obstacles: no arrays (memcpy wants pointers even for 0 bytes)
		memcpy(contact->body_start, contact->body_end, sizeof(plume_vec3) * (size_t)contact->body_vertex_count);
}

// ---------------------------------------------------------------------------
// Obstacles

plume_status plume_sim_add_obstacle(plume_sim *sim, const plume_vec3 *positions, int vertex_count, const int *triangles,
                                    int triangle_count, int *obstacle, plume_error *err)
{
	PLUME_ASSERT_HANDLE(sim);
	PLUME_ASSERT(positions != NULL || vertex_count == 0);
	PLUME_ASSERT(triangles != NULL || triangle_count == 0);
	if (vertex_count < 3 || triangle_count < 1)
		return plume_error_set(err, PLUME_ERROR_SPEC, "an obstacle needs at least one triangle (%d vertices, %d given)",
		                       vertex_count, triangle_count);
	for (int i = 0; i < vertex_count; ++i)
		if (!isfinite(positions[i].x) || !isfinite(positions[i].y) || !isfinite(positions[i].z))
			return plume_error_set(err, PLUME_ERROR_SPEC, "obstacle vertex %d is not finite", i);
	for (int t = 0; t < triangle_count; ++t)
		for (int k = 0; k < 3; ++k) {
			int v = triangles[3 * t + k];
			if (v < 0 || v >= vertex_count)
				return plume_error_set(err, PLUME_ERROR_SPEC, "obstacle triangle %d uses vertex %d, allowed 0 to %d", t,
				                       v, vertex_count - 1);
			if (v == triangles[3 * t + (k + 1) % 3])
				return plume_error_set(err, PLUME_ERROR_SPEC, "obstacle triangle %d repeats vertex %d", t, v);
		}
	sim_contact *contact = &sim->contact;
	int first_vertex = contact->body_vertex_count, first_face = contact->body_face_count;
	int vertices = first_vertex + vertex_count, faces = first_face + triangle_count;
	int capacity = contact->body_vertex_capacity;
	if (PLUME_GROW(contact->obstacles, contact->obstacle_capacity, contact->obstacle_count + 1) != 0 ||
	    PLUME_GROW(contact->body_faces, contact->body_face_capacity, 3 * faces) != 0)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory adding an obstacle");
	plume_vec3 **arrays[] = {&contact->body_rest, &contact->body_start, &contact->body_end,
	                         &contact->body_x,    &contact->body_from,  &contact->body_lag};
	if (vertices > capacity) {
		for (size_t a = 0; a < sizeof arrays / sizeof arrays[0]; ++a) {
			plume_vec3 *grown = plume_realloc(*arrays[a], sizeof(plume_vec3) * (size_t)vertices);
			if (grown == NULL)
				return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory adding an obstacle");
			*arrays[a] = grown;
		}
		contact->body_vertex_capacity = vertices;
	}
	for (int i = 0; i < vertex_count; ++i)
		for (size_t a = 0; a < sizeof arrays / sizeof arrays[0]; ++a)
			(*arrays[a])[first_vertex + i] = positions[i];
	for (int i = 0; i < 3 * triangle_count; ++i)
		contact->body_faces[3 * first_face + i] = triangles[i] + first_vertex;
	int *edges = NULL;
	int edge_count = collect_edges(contact->body_faces, faces, &edges);
	if (edge_count < 0)
		return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory adding an obstacle");
	// Checked before it counts: the shell must not touch the new obstacle.
	int old_vertices = contact->body_vertex_count, old_faces = contact->body_face_count;
	int old_edge_count = contact->body_edge_count;
	int *old_edges = contact->body_edges;
	contact->body_vertex_count = vertices;
	contact->body_face_count = faces;
	contact->body_edges = edges;
	contact->body_edge_count = edge_count;
	bool self = sim->def.contact.self_contact;
	sim->def.contact.self_contact = false;
	bool found = find_candidates(sim, sim->x, sim->x, contact->body_x, contact->body_x, 0);
	sim->def.contact.self_contact = self;
	int touching = -1;
	for (int p = 0; found && p < contact->pair_count && touching < 0; ++p) {
		plume_vec3 points[4];
		gather_pair(sim, contact->pairs + p, sim->x, contact->body_x, points);
		if (!(pair_distance2(contact->pairs + p, points) > 0))
			touching = p;
	}
	if (!found || touching >= 0) {
		contact->body_vertex_count = old_vertices;
		contact->body_face_count = old_faces;
		contact->body_edges = old_edges;
		contact->body_edge_count = old_edge_count;
		plume_free(edges);
		if (!found)
			return plume_error_set(err, PLUME_ERROR_MEMORY, "out of memory adding an obstacle");
		const sim_contact_pair *pair = contact->pairs + touching;
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "the obstacle touches the shell (%s of shell vertices/obstacle vertices %d %d %d %d)",
		                       pair->type == PLUME_CONTACT_POINT_TRIANGLE ? "point-triangle" : "edge-edge",
		                       pair->vertices[0], pair->vertices[1], pair->vertices[2], pair->vertices[3]);
	}
	plume_free(old_edges);
	contact->obstacles[contact->obstacle_count] =
	    (sim_obstacle){first_vertex, vertex_count, first_face, triangle_count};
	*obstacle = contact->obstacle_count++;
	return PLUME_OK;
}

void plume_sim_set_obstacle_positions(plume_sim *sim, int obstacle, const plume_vec3 *positions)
{
	PLUME_ASSERT_HANDLE(sim);
	PLUME_ASSERT_INDEX(obstacle, sim->contact.obstacle_count); // an index from plume_sim_add_obstacle
	PLUME_ASSERT(positions != NULL);
	const sim_obstacle *body = sim->contact.obstacles + obstacle;
	for (int i = 0; i < body->vertex_count; ++i) {
		PLUME_ASSERT(isfinite(positions[i].x) && isfinite(positions[i].y) && isfinite(positions[i].z));
		sim->contact.body_end[body->first_vertex + i] = positions[i];
	}
}

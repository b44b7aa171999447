// plume sweep: the commands a sweep can run, the outputs each writes and the options
// of the calibration (whose spec is an object of its command-line options).
#include <ctype.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sweep.h"

// These lists follow what each command writes: cli/simulate.c write_summary, cli/lab.c
// write_traction and print_calibration, cli/mesh.c write_report, Zhang & Kanai's
// summary (src/model/zhang_kanai.c set_summary). Every number and boolean, strings left
// out (a run's error is its row's message). tests/cli/sweep.sh asks a real run of each
// command for every key listed and checks that its result file holds no number or
// boolean this list lacks, so a key added to a writer fails the test until it is here.
static const sweep_output simulate_outputs[] = {{"completed", NULL},
                                                {"failed_step", "by failed runs"},
                                                {"failed_time", "by failed runs"},
                                                {"steps", NULL},
                                                {"frames", NULL},
                                                {"time", NULL},
                                                {"duration", NULL},
                                                {"newton_iterations", NULL},
                                                {"newton_iterations_per_step", NULL},
                                                {"retried_steps", NULL},
                                                {"wall_seconds", NULL},
                                                {"seconds_assembly", NULL},
                                                {"seconds_factorization", NULL},
                                                {"seconds_solve", NULL},
                                                {"seconds_contact", NULL},
                                                {"cycle_period", "by cyclic scenes"},
                                                {"seconds_per_cycle", "by cyclic scenes"},
                                                {"contact_pairs_max", "with contact"},
                                                {"min_distance", "with contact"},
                                                {"intersecting_pairs", "with the intersection check"},
                                                {"frames_checked", "with the intersection check"},
                                                {"first_intersecting_step", "with the intersection check"},
                                                {"max_barb_strain", NULL},
                                                {"rachis_tip_deflection", NULL},
                                                {"vertices", NULL},
                                                {"vertex_count", NULL},
                                                {"faces", NULL},
                                                {"feather_count", NULL},
                                                {"feathers[<feather>].vertex_offset", NULL},
                                                {"feathers[<feather>].vertex_count", NULL},
                                                {"feathers[<feather>].face_offset", NULL},
                                                {"feathers[<feather>].face_count", NULL},
                                                {"barb_constraints", NULL},
                                                {"vane_min_principal_stretch", NULL},
                                                {"vane_max_out_of_plane", NULL},
                                                {"max_kinetic_energy", NULL},
                                                {"max_elastic_energy", NULL},
                                                {"handle_max_reaction[<handle>]", NULL},
                                                {"mesh_min_angle_deg", NULL},
                                                {"mesh_vane_min_angle_deg", NULL},
                                                {"mesh_excepted_count", NULL},
                                                {"mesh_aligned_fraction", NULL},
                                                {"mesh_guides_dropped", NULL},
                                                {NULL, NULL}};
static const sweep_output traction_outputs[] = {
    {"slope_pa", NULL},       {"strain_max", NULL},     {"steps", NULL},       {"newton_iterations", NULL},
    {"lateral_strain", NULL}, {"barb_angle_deg", NULL}, {"compression", NULL}, {NULL, NULL}};
static const sweep_output calibrate_outputs[] = {{"E_vv", NULL},
                                                 {"E_ww", NULL},
                                                 {"E_vw", NULL},
                                                 {"spread.E_vv.phase", "without --no-uncertainty"},
                                                 {"spread.E_vv.width", "without --no-uncertainty"},
                                                 {"spread.E_vv.mesh", "without --no-uncertainty"},
                                                 {"spread.E_vv.total", "without --no-uncertainty"},
                                                 {"spread.E_ww.phase", "without --no-uncertainty"},
                                                 {"spread.E_ww.width", "without --no-uncertainty"},
                                                 {"spread.E_ww.mesh", "without --no-uncertainty"},
                                                 {"spread.E_ww.total", "without --no-uncertainty"},
                                                 {"spread.E_vw.phase", "without --no-uncertainty"},
                                                 {"spread.E_vw.width", "without --no-uncertainty"},
                                                 {"spread.E_vw.mesh", "without --no-uncertainty"},
                                                 {"spread.E_vw.total", "without --no-uncertainty"},
                                                 {"sensitivity", "without --no-uncertainty"},
                                                 {"slopes.longitudinal", NULL},
                                                 {"slopes.transverse", NULL},
                                                 {"slopes.tilted_mesoscale", NULL},
                                                 {"slopes.tilted_macroscale", NULL},
                                                 {"phi", NULL},
                                                 {"E_b", NULL},
                                                 {"E_B", NULL},
                                                 {"aspect", NULL},
                                                 {"period", NULL},
                                                 {"phases", NULL},
                                                 {"protocol.longitudinal_strain_max", NULL},
                                                 {"protocol.transverse_strain_max", NULL},
                                                 {"protocol.tilted_strain_max", NULL},
                                                 {"protocol.steps", NULL},
                                                 {"protocol.compression_coefficient", NULL},
                                                 {"protocol.barb_constraint", NULL},
                                                 {"protocol.macroscale_element_count", NULL},
                                                 {"protocol.mesoscale_element_count", NULL},
                                                 {"protocol.width", NULL},
                                                 {"protocol.barbs_across", NULL},
                                                 {"protocol.aspect", NULL},
                                                 {"protocol.phases", NULL},
                                                 {"barb_constraint", NULL},
                                                 {"traction_tests", NULL},
                                                 {"solves", NULL},
                                                 {"bisection_iterations", NULL},
                                                 {NULL, NULL}};
static const sweep_output mesh_outputs[] = {{"edge_length", NULL},
                                            {"vertex_count", NULL},
                                            {"face_count", NULL},
                                            {"rachis_face_count", NULL},
                                            {"vane_face_count", NULL},
                                            {"barb_edge_count", NULL},
                                            {"min_angle_deg", NULL},
                                            {"vane_min_angle_deg", NULL},
                                            {"excepted_count", NULL},
                                            {"aligned_fraction", NULL},
                                            {"guides_dropped", NULL},
                                            {"barbs_averaged", NULL},
                                            {"vertices_trimmed", NULL},
                                            {"guide_count[0]", NULL},
                                            {"guide_count[1]", NULL},
                                            {"groups.<group>", NULL},
                                            {NULL, NULL}};
// generate writes summary.json for Zhang-Kanai feathers only (sweep_check refuses
// outputs of a generate sweep whose first feather has none).
static const sweep_output generate_outputs[] = {{"t_end", NULL},
                                                {"t_curr", NULL},
                                                {"unfurl_weight", NULL},
                                                {"barbs.left", NULL},
                                                {"barbs.right", NULL},
                                                {"developing", NULL},
                                                {"developing_kept", NULL},
                                                {"emitter_clamp_time.left", NULL},
                                                {"emitter_clamp_time.right", NULL},
                                                {"expansion", NULL},
                                                {"snapping.full", "with expansion"},
                                                {"snapping.partial", "with expansion"},
                                                {"snapping.unsnapped", "with expansion"},
                                                {NULL, NULL}};
static const sweep_output no_outputs[] = {{NULL, NULL}};

const sweep_command sweep_commands[SWEEP_COMMAND_COUNT] = {
    {"generate", {"generate", NULL}, PROBE_FEATHER, "summary.json", generate_outputs},
    {"mesh", {"mesh", NULL}, PROBE_MESH, "report.json", mesh_outputs},
    {"coat", {"coat", NULL}, PROBE_COAT, NULL, no_outputs},
    {"simulate", {"simulate", NULL}, PROBE_SCENE, "summary.json", simulate_outputs},
    {"lab traction", {"lab", "traction"}, PROBE_LAB, "traction.json", traction_outputs},
    {"lab calibrate", {"lab", "calibrate"}, PROBE_CALIBRATION, "stdout", calibrate_outputs},
    {"render frames", {"render", NULL}, PROBE_RENDER, NULL, no_outputs},
};

// Rendering a simulation's frames in ranges: the spec names the simulation folder, the
// one output folder every range writes into, and the range of each run.
const char *const sweep_render_keys[] = {"description", "simulation", "output", "first",  "count",
                                         "step",        "spp",        "size",   "format", NULL};
_Static_assert(sizeof sweep_commands / sizeof sweep_commands[0] == SWEEP_COMMAND_COUNT, "every command listed");

/// Whether key matches the pattern of an output: its text, with <group> standing for a
/// name (letters, digits, '_', '-') and <handle>, <feather> for an index; the text
/// standing for the placeholder goes to hole.
static bool output_matches(const char *pattern, const char *key, char *hole, size_t size)
{
	hole[0] = '\0';
	const char *open = strchr(pattern, '<');
	if (open == NULL)
		return strcmp(pattern, key) == 0;
	size_t prefix = (size_t)(open - pattern);
	if (strncmp(pattern, key, prefix) != 0)
		return false;
	const char *close = strchr(open, '>');
	bool name = strncmp(open, "<group>", 7) == 0;
	const char *k = key + prefix;
	size_t length = 0;
	for (unsigned char c; (c = (unsigned char)k[length]) != '\0'; ++length)
		if (!(name ? isalnum(c) || c == '_' || c == '-' : isdigit(c)))
			break;
	if (length == 0 || length >= size || strcmp(k + length, close + 1) != 0)
		return false;
	memcpy(hole, k, length);
	hole[length] = '\0';
	return true;
}

const sweep_output *sweep_output_find(const sweep_command *command, const char *key, char *hole, size_t size)
{
	for (const sweep_output *o = command->outputs; o->key != NULL; ++o)
		if (output_matches(o->key, key, hole, size))
			return o;
	return NULL;
}

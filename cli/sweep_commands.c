// plume sweep: the commands a sweep can run, the outputs each writes and the options
// of the calibration (whose spec is an object of its command-line options).
#include <math.h>
#include <stddef.h>

#include "sweep.h"

// These lists follow what each command writes (cli/simulate.c write_summary,
// cli/lab.c write_traction and run_calibrate, cli/mesh.c write_report,
// Zhang & Kanai's summary); tests/cli/sweep.sh checks every key against a real run.
static const char *const simulate_outputs[] = {"completed",
                                               "steps",
                                               "frames",
                                               "time",
                                               "newton_iterations",
                                               "newton_iterations_per_step",
                                               "retried_steps",
                                               "wall_seconds",
                                               "seconds_assembly",
                                               "seconds_factorization",
                                               "seconds_solve",
                                               "max_barb_strain",
                                               "rachis_tip_deflection",
                                               "vertices",
                                               "faces",
                                               "barb_constraints",
                                               "mesh_min_angle_deg",
                                               "mesh_aligned_fraction",
                                               "mesh_guides_dropped",
                                               NULL};
static const char *const traction_outputs[] = {"slope_pa",       "strain_max",     "steps",       "newton_iterations",
                                               "lateral_strain", "barb_angle_deg", "compression", NULL};
static const char *const calibrate_outputs[] = {"E_vv",
                                                "E_ww",
                                                "E_vw",
                                                "slopes.longitudinal",
                                                "slopes.transverse",
                                                "slopes.tilted_mesoscale",
                                                "slopes.tilted_macroscale",
                                                "traction_tests",
                                                "solves",
                                                "bisection_iterations",
                                                NULL};
static const char *const mesh_outputs[] = {
    "edge_length",   "vertex_count",     "face_count",     "rachis_face_count", "vane_face_count",  "barb_edge_count",
    "min_angle_deg", "aligned_fraction", "guides_dropped", "barbs_averaged",    "vertices_trimmed", NULL};
static const char *const no_outputs[] = {NULL};

const sweep_command sweep_commands[SWEEP_COMMAND_COUNT] = {
    {"generate", {"generate", NULL}, PROBE_FEATHER, NULL, no_outputs},
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

const calibration_key sweep_calibration_keys[SWEEP_CALIBRATION_KEY_COUNT] = {
    {"phi", "--phi", false, 0.0, 1.0},
    {"Eb", "--Eb", false, 0.0, INFINITY},
    {"EB", "--EB", false, 0.0, INFINITY},
    {"aspect", "--aspect", false, 0.0, INFINITY},
    {"period", "--period", false, 0.0, INFINITY},
    {"width", "--width", false, 0.0, INFINITY},
    {"elements", "--elements", true, 1.0, 1e8},
    {"macro_elements", "--macro-elements", true, 1.0, 1e8},
    {"phases", "--phases", true, 1.0, 1e8},
};
_Static_assert(sizeof sweep_calibration_keys / sizeof sweep_calibration_keys[0] == SWEEP_CALIBRATION_KEY_COUNT,
               "every calibration option listed");

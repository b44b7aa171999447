// Benchmark: the lab's calibration (thesis 5.2-5.3) at Phi_B = 0.12, 0.14, 0.16
// with thesis Table 5.1's moduli, and each study at its default size. Prints
// the wall time of each and the calibrated moduli.
//
// Usage: bench_lab [calibration|studies|all] [OUTPUT_DIR]   (defaults: all, /tmp)
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "plume/lab.h"
#include "bench_support.h"

static void calibrations(void)
{
	static const double phis[3] = {0.12, 0.14, 0.16}, E_b[3] = {4.04e4, 3.92e4, 3.79e4},
	                    E_B[3] = {2.8e9, 2.57e9, 2.25e9};
	plume_calibration_def protocol = plume_calibration_default_def();
	printf("calibration (thesis Table 5.1 -> Table 5.2), protocol \"%s\" (tilted eps_max %g, kappa %g Pa, "
	       "barb constraint %s), moduli +- total spread (Pa):\n",
	       plume_calibration_protocol_name(&protocol), protocol.tilted_strain_max,
	       protocol.mesoscale.compression_coefficient, protocol.barb_constraint ? "on" : "off");
	printf("%6s %22s %20s %20s %9s %9s %9s %9s %7s %7s\n", "Phi_B", "E_vv", "E_ww", "E_vw", "vw phase", "vw width",
	       "vw mesh", "sensitiv", "seconds", "solves");
	for (int k = 0; k < 3; ++k) {
		plume_calibration_def def = plume_calibration_default_def();
		def.mesoscale.bands.barb_fraction = phis[k];
		def.mesoscale.E_b = E_b[k];
		def.mesoscale.E_B = E_B[k];
		plume_calibration_result r;
		plume_error err = {0};
		double t0 = bench_now();
		bench_check("bench_lab", plume_lab_calibrate(&def, &r, &err), &err);
		printf("%6.2f %12.5g +- %-7.2g %10.5g +- %-7.2g %10.5g +- %-7.2g %9.3g %9.3g %9.3g %9.4f %7.1f %7d\n", phis[k],
		       r.E_vv, r.spread_vv.total, r.E_ww, r.spread_ww.total, r.E_vw, r.spread_vw.total, r.spread_vw.phase,
		       r.spread_vw.width, r.spread_vw.mesh, r.sensitivity, bench_now() - t0, r.solve_count);
		fflush(stdout);
	}
}

static void studies(const char *dir)
{
	printf("studies at their default sizes:\n");
	for (int k = 0; k < 4; ++k) {
		plume_study_def def = plume_study_default_def((plume_study_kind)k);
		const char *name = plume_study_name(def.kind);
		char csv[1024], png[1024], svg[1024], summary[1024];
		snprintf(csv, sizeof csv, "%s/bench-lab-%s.csv", dir, name);
		snprintf(png, sizeof png, "%s/bench-lab-%s.png", dir, name);
		snprintf(svg, sizeof svg, "%s/bench-lab-%s.svg", dir, name);
		plume_error err = {0};
		double t0 = bench_now();
		bench_check("bench_lab", plume_lab_study(&def, csv, png, svg, summary, sizeof summary, &err), &err);
		printf("  %-13s %8.2f s  %s\n", name, bench_now() - t0, summary);
		fflush(stdout);
	}
}

int main(int argc, char **argv)
{
	const char *what = argc > 1 ? argv[1] : "all";
	const char *dir = argc > 2 ? argv[2] : "/tmp";
	if (strcmp(what, "calibration") == 0 || strcmp(what, "all") == 0)
		calibrations();
	if (strcmp(what, "studies") == 0 || strcmp(what, "all") == 0)
		studies(dir);
	return 0;
}

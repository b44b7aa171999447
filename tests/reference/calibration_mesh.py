#!/usr/bin/python3
"""The calibrated shear modulus is a property of the model, not of its meshes
(issue 16, Tests): E_vw at Phi_B = 0.14 (thesis Table 5.1, the simulator's
default, `plume lab calibrate --phi 0.14 --Eb 3.92e4 --EB 2.57e9`) must stay
within 1 % when either mesh of the calibration is doubled:

- the mesoscale tilted sample, 4000 -> 8000 quadratic triangles (--elements),
  in every band phase the target is averaged over;
- the macroscale tilted sample, 2000 -> 4000 linear triangles with the barb
  constraint (--macro-elements), the model whose E_vw is fitted.

1 % is the issue's figure. What it guards: at the protocol's strain range a
1 % change of the tilted slope moves E_vw by 1.15 % (sensitivity 0.87), so a
mesh error the size of the mesoscale sample's own (0.3 % from the FEniCS
reference, tests/reference/lab_fenics.py) passes and one three times larger
does not. Measured (docs/lab.md): 19910.1 Pa; 19862.1 Pa (-0.24 %) with the
finer mesoscale mesh.

The three calibrations skip the uncertainty runs (--no-uncertainty): the fit is
the same. Each takes 30 s to 2 minutes on the 2-core development machine, so
this is a .ci/run step, not a ctest one.

Usage: calibration_mesh.py --plume build/plume
Exit 1 when a doubling moves E_vw by 1 % or more.
"""
import argparse
import json
import subprocess
import sys
import time

TOLERANCE = 1e-2
COMMAND = ["lab", "calibrate", "--phi", "0.14", "--Eb", "3.92e4", "--EB", "2.57e9", "--no-uncertainty"]


def calibrate(plume, extra):
    started = time.monotonic()
    out = subprocess.run([plume] + COMMAND + extra, check=True, capture_output=True, text=True).stdout
    result = json.loads(out)
    return result, time.monotonic() - started


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plume", required=True, help="the plume executable")
    args = parser.parse_args()
    base, seconds = calibrate(args.plume, [])
    protocol = base["protocol"]
    if protocol["name"] != "chapter-5":
        print("calibration_mesh: the default calibration is not the chapter-5 protocol: %s" % protocol)
        return 1
    print("%-44s E_vw %10.6g Pa  (%.0f s)" % ("default meshes (%d mesoscale, %d macroscale)"
                                              % (protocol["mesoscale_element_count"],
                                                 protocol["macroscale_element_count"]), base["E_vw"], seconds))
    failed = False
    doublings = [("mesoscale mesh doubled", ["--elements", str(2 * protocol["mesoscale_element_count"])]),
                 ("macroscale mesh doubled", ["--macro-elements", str(2 * protocol["macroscale_element_count"])])]
    for name, extra in doublings:
        result, seconds = calibrate(args.plume, extra)
        change = result["E_vw"] / base["E_vw"] - 1.0
        ok = abs(change) < TOLERANCE
        failed = failed or not ok
        print("%-44s E_vw %10.6g Pa  change %+.3f %% (tol %.0f %%) %s  (%.0f s)"
              % (name, result["E_vw"], 100 * change, 100 * TOLERANCE, "ok" if ok else "FAIL", seconds))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

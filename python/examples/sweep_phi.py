"""Calibrate the membrane moduli E_vv, E_ww, E_vw over a range of barb fractions Phi_B and plot them.

The measured slopes stay those of the thesis' vane (Table 5.1 at Phi_B = 0.14); for each Phi_B the
mesoscale moduli E_B, E_b that reproduce them follow in closed form (eqs. 5.3, 5.5), and the
calibration (thesis 5.2-5.3) fits the macroscale moduli to the mesoscale model's traction tests.

    PLUME_BUILD_DIR=build /usr/bin/python3 python/examples/sweep_phi.py -o sweep_phi.png [--scale 0.25]
"""

import argparse
import csv
import sys
import time

import numpy as np

try:
    import plume
except ImportError:  # run from the source tree: the package is python/plume
    import os

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    import plume

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("-o", "--output", default="sweep_phi.png", help="plot (PNG); a CSV beside it")
parser.add_argument("--phi", type=float, nargs="+", default=[0.08, 0.10, 0.12, 0.14, 0.16, 0.18, 0.20])
parser.add_argument("--scale", type=float, default=1.0, help="multiplies the element counts (0.25: quick)")
parser.add_argument("--phases", type=int, default=4, help="band phases the tilted slope is averaged over")
args = parser.parse_args()

# The measured slopes: those of the mesoscale model at the thesis' Phi_B = 0.14 (Table 5.1).
slope_long = plume.longitudinal_modulus(0.14, 2.57e9, 3.92e4)
slope_trans = plume.transverse_slope_rigid(0.14, 3.92e4, 0.4)
rows = []
for phi in args.phi:
    E_B, E_b = plume.mesoscale_moduli(phi, slope_long, slope_trans, 0.4)
    start = time.time()
    r = plume.calibrate(barb_fraction=phi, E_B=E_B, E_b=E_b, phase_count=args.phases,
                        element_count=max(200, int(4000 * args.scale)),
                        macroscale_elements=max(200, int(2000 * args.scale)))
    rows.append((phi, E_B, E_b, r["E_vv"], r["E_ww"], r["E_vw"], r["solve_count"], time.time() - start))
    print(f"Phi_B = {phi:.2f}: E_B = {E_B:.3g} Pa, E_b = {E_b:.3g} Pa -> E_vv = {r['E_vv']:.4g}, "
          f"E_ww = {r['E_ww']:.4g}, E_vw = {r['E_vw']:.4g} Pa ({r['solve_count']} solves, {rows[-1][-1]:.1f} s)",
          file=sys.stderr)

table = args.output.rsplit(".", 1)[0] + ".csv"
with open(table, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["phi", "E_B_pa", "E_b_pa", "E_vv_pa", "E_ww_pa", "E_vw_pa", "solves", "seconds"])
    w.writerows(rows)

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

data = np.array(rows)
fig, ax = plt.subplots(figsize=(6.4, 4.2))
for column, label in ((3, "$E_{vv}$"), (4, "$E_{ww}$"), (5, "$E_{vw}$")):
    ax.semilogy(data[:, 0], data[:, column], "o-", label=label)
ax.set_xlabel(r"barb fraction $\Phi_B$")
ax.set_ylabel("modulus [Pa]")
ax.set_title(r"Calibrated membrane moduli against $\Phi_B$ (same measured slopes)")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
fig.tight_layout()
fig.savefig(args.output, dpi=120)
print(f"wrote {args.output} and {table}")

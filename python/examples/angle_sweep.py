"""Thesis Figure 5.11 from Python: traction slopes of the mesoscale model and of the calibrated
macroscale model against the barb angle, for Phi_B = 0.12, 0.14, 0.16 (Table 5.1's moduli).

Each Phi_B is calibrated without the barb constraint (theta = 0 pulls along the barbs), then both
models are pulled at theta = 0, 15, ... 90 degrees on the 4 x 5.2 mm sample. `plume lab study angles`
does the same in C (and averages the mesoscale slope over band phases; this script uses one phase).

    PLUME_BUILD_DIR=build /usr/bin/python3 python/examples/angle_sweep.py -o angle_sweep.png [--scale 0.25]
"""

import argparse
import sys

import numpy as np

try:
    import plume
except ImportError:  # run from the source tree: the package is python/plume
    import os

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    import plume

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("-o", "--output", default="angle_sweep.png")
parser.add_argument("--scale", type=float, default=1.0, help="multiplies the element counts (0.25: quick)")
args = parser.parse_args()

TABLE_5_1 = {0.12: (2.8e9, 4.04e4), 0.14: (2.57e9, 3.92e4), 0.16: (2.25e9, 3.79e4)}  # Phi_B: (E_B, E_b)
angles = np.arange(0, 91, 15)
meso_elements, macro_elements = max(200, int(4000 * args.scale)), max(200, int(2000 * args.scale))
traction = {"strain_max": 0.4, "steps": 10, "tolerance": 1e-6, "accept_residual": 1e-4}
results = {}
for phi, (E_B, E_b) in TABLE_5_1.items():
    cal = plume.calibrate(barb_fraction=phi, E_B=E_B, E_b=E_b, barb_constraint=False,
                          element_count=meso_elements, macroscale_elements=macro_elements)
    meso, macro = [], []
    for angle in angles:
        sample = {"width": 0.004, "height": 0.0052, "thickness": 1.2e-4, "barb_angle_deg": float(angle)}
        meso.append(plume.traction({
            "sample": dict(sample, elements=meso_elements),
            "material": {"model": "mesoscale", "E_B": E_B, "E_b": E_b, "barb_fraction": phi, "band_period": 4e-4},
            "traction": traction})["slope"] / E_b)
        macro.append(plume.traction({
            "sample": dict(sample, elements=macro_elements, mesh="aligned"),
            "material": {"model": "macroscale", "E_vv": cal["E_vv"], "E_ww": cal["E_ww"], "E_vw": cal["E_vw"]},
            "traction": traction})["slope"] / E_b)
    results[phi] = (np.array(meso), np.array(macro))
    print(f"Phi_B = {phi}: E_vw = {cal['E_vw']:.4g} Pa; slope/E_b meso {np.round(meso, 2).tolist()}, "
          f"macro {np.round(macro, 2).tolist()}", file=sys.stderr)

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

fig, ax = plt.subplots(figsize=(6.4, 4.4))
for (phi, (meso, macro)), colour in zip(results.items(), ("C0", "C1", "C2")):
    ax.semilogy(angles, meso, "o", color=colour, label=rf"mesoscale, $\Phi_B$ = {phi}")
    ax.semilogy(angles, macro, "-", color=colour, label=rf"macroscale, $\Phi_B$ = {phi}")
ax.set_xlabel(r"barb angle $\theta$ [deg]")
ax.set_ylabel(r"slope / $E_b$")
ax.set_title("Traction slopes against barb angle (thesis Figure 5.11)")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(args.output, dpi=120)
print(f"wrote {args.output}")

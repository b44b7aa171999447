#!/usr/bin/python3
"""Measures the wrinkles of Figure 1's vane at the last frame of `plume simulate` runs: the
out-of-plane displacement along four lines across the crests (33 degrees from x, through
the wrinkled band beside the pulled handle), and the distances between its sign changes,
in mm, for the lobes that rise or sink more than 0.1 mm (the band's last lobe left out).
A regular wrinkle gives equal distances, half its wavelength.

Usage: measure_wrinkles.py RUN_DIR [RUN_DIR ...]
Each RUN_DIR holds frames/0000.obj (the rest shell) and its last frame as the highest-numbered
frames/NNNN.obj, as for plot_wrinkles.py (docs/physics-energies.md, "Wrinkles along the barbs").
"""
import glob
import os
import sys

import numpy as np
from matplotlib.tri import LinearTriInterpolator, Triangulation

from plot_wrinkles import read_obj

# Lines across the crests: centres in cm (rest position), direction 33 degrees from x.
CENTRES = [(-0.7, 19.35), (-0.55, 19.1), (-0.4, 18.85), (-0.25, 18.6)]
DIRECTION = np.array([np.cos(np.radians(33)), np.sin(np.radians(33))])
SMALLEST_LOBE_MM = 0.1


def lobe_widths(height, t):
    """Distances (mm) between sign changes of height - median along t (cm), lobes above the
    threshold, the last one left out."""
    centred = height - np.median(height)
    crossings = t[1:][np.sign(centred[1:]) != np.sign(centred[:-1])]
    widths = []
    for a, b in zip(crossings[:-1], crossings[1:]):
        inside = (t > a) & (t < b)
        if inside.any() and np.max(np.abs(centred[inside])) > SMALLEST_LOBE_MM:
            widths.append(round(10 * (b - a), 1))
    return widths[:-1]


def main(argv):
    if len(argv) < 2:
        sys.exit(__doc__)
    for run in argv[1:]:
        frames = sorted(glob.glob(os.path.join(run, "frames", "[0-9][0-9][0-9][0-9].obj")))
        rest, faces = read_obj(frames[0])
        last, _ = read_obj(frames[-1])
        shell = Triangulation(100 * rest[:, 0], 100 * rest[:, 1], faces)
        height = LinearTriInterpolator(shell, 1000 * last[:, 2])
        t = np.linspace(-1.0, 1.0, 2001)
        lines = []
        for cx, cy in CENTRES:
            z = np.array(height(cx + t * DIRECTION[0], cy + t * DIRECTION[1]).filled(np.nan))
            inside = ~np.isnan(z)
            lines.append(lobe_widths(z[inside], t[inside]))
        every = [w for line in lines for w in line]
        print(f"{run}: lobes {min(every)}-{max(every)} mm apart; by line {lines}")


if __name__ == "__main__":
    main(sys.argv)

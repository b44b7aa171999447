#!/usr/bin/python3
"""Plots the vane's out-of-plane displacement at the last frame of `plume simulate` runs,
over each run's rest shell, near Figure 1's pulled handle: one panel per run.

Usage: plot_wrinkles.py OUT.png RUN_DIR LABEL [RUN_DIR LABEL ...]
Each RUN_DIR holds frames/0000.obj (the rest shell) and its last frame as the highest-numbered
frames/NNNN.obj. Run by docs/images/make-sim.sh (Debian's python3-matplotlib).
"""
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402


def read_obj(path):
    """Vertices and triangles of an OBJ file (faces as written by plume: triangles)."""
    vertices, faces = [], []
    with open(path) as obj:
        for line in obj:
            if line.startswith("v "):
                vertices.append([float(t) for t in line.split()[1:4]])
            elif line.startswith("f "):
                faces.append([int(t.split("/")[0]) - 1 for t in line.split()[1:4]])
    return np.array(vertices), np.array(faces)


def main(argv):
    if len(argv) < 4 or len(argv) % 2 != 0:
        sys.exit(__doc__)
    out, runs = argv[1], list(zip(argv[2::2], argv[3::2]))
    fig, axes = plt.subplots(1, len(runs), figsize=(3.2 * len(runs), 4.2), squeeze=False)
    for ax, (run, label) in zip(axes[0], runs):
        frames = sorted(glob.glob(os.path.join(run, "frames", "[0-9][0-9][0-9][0-9].obj")))
        rest, faces = read_obj(frames[0])
        last, _ = read_obj(frames[-1])
        # Rest positions in cm, out of plane in mm: the feather lies in z = 0 with its base held.
        shell = Triangulation(100 * rest[:, 0], 100 * rest[:, 1], faces)
        colours = ax.tripcolor(shell, 1000 * last[:, 2], cmap="RdBu_r", vmin=-1.5, vmax=1.5, shading="gouraud")
        ax.triplot(shell, lw=0.15, color="k", alpha=0.25)
        ax.set_xlim(-2.4, 0.6)
        ax.set_ylim(16.5, 20.8)
        ax.set_aspect("equal")
        ax.set_title(label, fontsize=10)
        ax.set_xlabel("x (cm)")
    axes[0][0].set_ylabel("y (cm), rest position")
    fig.colorbar(colours, ax=axes[0].tolist(), shrink=0.8, label="out of plane at the last frame (mm)")
    fig.savefig(out, dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main(sys.argv)

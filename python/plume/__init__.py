"""plume from Python: feathers generated, meshed, simulated and rendered by libplume.

    import plume
    feather = plume.generate("examples/franco-walter/hawk.json")
    print(feather.points.shape)          # every barb point, a NumPy view
    shell = plume.mesh(feather, edge_length=0.01)
    image = plume.render(feather, width=400, height=400)

The binding is cffi in ABI mode over the installed libplume.so (docs/python.md).
"""

from ._lib import Error, bytes_in_use, library_path
from .coat import Coat, coat
from .feather import Feather, banded_colors, generate, ribbons
from .lab import calibrate, longitudinal_modulus, mesoscale_moduli, study, traction, transverse_slope_rigid
from .mesh import Mesh, mesh
from .render import render, render2d, write_png
from .sim import Simulation

__version__ = "0.1.0"

__all__ = [
    "Error", "Feather", "Mesh", "Coat", "Simulation", "generate", "ribbons", "banded_colors", "mesh", "coat",
    "render", "render2d",
    "write_png", "traction", "calibrate", "study", "mesoscale_moduli", "longitudinal_modulus",
    "transverse_slope_rigid", "bytes_in_use", "library_path",
]

"""plume feathers for Blender: grow feathers from plume's models, groom coats, simulate and bake.

Uses the plume Python package (python/ of the plume source, over libplume): an installed one
(`pip install ./python`), else the copy `make blender-addon` puts in this add-on's folder.
"""

bl_info = {
    "name": "plume feathers",
    "author": "plume",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > plume; Add > plume feather",
    "description": "Feathers (Franco-Walter, Streit-Heidrich, Zhang-Kanai), coats and shell simulation from libplume",
    "category": "Add Mesh",
}

import os
import sys

_HERE = os.path.dirname(os.path.abspath(__file__))
if _HERE not in sys.path:
    sys.path.append(_HERE)  # the bundled plume package, used when none is installed

from . import operators, panels  # noqa: E402

_modules = (operators, panels)


def register():
    for m in _modules:
        m.register()


def unregister():
    for m in reversed(_modules):
        m.unregister()

"""pip install ./python: the plume package over an installed libplume.

The build finds libplume through pkg-config (after `make install`), or a build folder named by
PLUME_BUILD_DIR (with the source tree's headers beside this folder). It writes two files into the
package: _cdef.h, the cffi declarations made from the headers it found (plume/_headers.py), and
_libpath.txt, the libplume.so it will load. Nothing is compiled (cffi ABI mode), so nothing is
downloaded either. There is deliberately no pyproject.toml: without one, pip runs this file with
the setuptools already installed (Debian's) instead of downloading one into an isolated build
environment, so `pip install ./python` works offline.
"""

import os
import pathlib
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent


def pkg_config(variable):
    try:
        out = subprocess.run(["pkg-config", f"--variable={variable}", "plume"], capture_output=True, text=True,
                             check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    return out or None


def locate():
    build = os.environ.get("PLUME_BUILD_DIR")
    if build:
        include = os.environ.get("PLUME_INCLUDE_DIR", str(HERE.parent / "include"))
        return include, str(pathlib.Path(build).resolve() / "libplume.so")
    include, libdir = pkg_config("includedir"), pkg_config("libdir")
    if include and libdir:
        return include, os.path.normpath(os.path.join(libdir, "libplume.so"))
    sys.exit("plume: libplume not found: run `make install` (pkg-config plume) or set PLUME_BUILD_DIR")


class BuildWithDeclarations(build_py):
    def run(self):
        super().run()
        import importlib.util

        # plume/_headers.py alone: importing the package would load the library.
        spec = importlib.util.spec_from_file_location("plume_headers", HERE / "plume" / "_headers.py")
        _headers = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(_headers)

        include, library = locate()
        text, _ = _headers.cdef(include)
        target = pathlib.Path(self.build_lib) / "plume"
        (target / "_cdef.h").write_text(text)
        (target / "_libpath.txt").write_text(library + "\n")


setup(
    name="plume",
    version="0.1.0",
    description="Feathers from Python: generation, meshing, simulation, rendering (libplume via cffi)",
    packages=["plume"],
    python_requires=">=3.9",
    install_requires=["cffi", "numpy"],
    cmdclass={"build_py": BuildWithDeclarations},
)

"""Fixtures of the binding's tests. CTest (tests/CMakeLists.txt) runs them with PLUME_BUILD_DIR
(the build folder: libplume.so and the plume CLI) and PLUME_SOURCE_DIR set; by hand:

    PLUME_BUILD_DIR=build /usr/bin/python3 -m pytest python/tests
"""

import os
import pathlib
import subprocess
import sys

import pytest

pytest.importorskip("numpy", reason="python3-numpy is not installed: the binding's tests are skipped")
pytest.importorskip("cffi", reason="python3-cffi is not installed: the binding's tests are skipped")

SOURCE = pathlib.Path(os.environ.get("PLUME_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BUILD = pathlib.Path(os.environ.get("PLUME_BUILD_DIR", SOURCE / "build")).resolve()
os.environ.setdefault("PLUME_BUILD_DIR", str(BUILD))
# The package from the source tree (not an installed copy), reading the source tree's headers.
sys.path.insert(0, str(SOURCE / "python"))
os.environ.setdefault("PLUME_INCLUDE_DIR", str(SOURCE / "include"))


@pytest.fixture(scope="session")
def source() -> pathlib.Path:
    return SOURCE


@pytest.fixture(scope="session")
def build() -> pathlib.Path:
    return BUILD


@pytest.fixture(scope="session")
def cli(build):
    """Runs the plume command; returns its CompletedProcess (failing the test on a non-zero exit)."""

    def run(*args, check=True):
        done = subprocess.run([str(build / "plume"), *map(str, args)], capture_output=True, text=True)
        if check and done.returncode != 0:
            pytest.fail(f"plume {' '.join(map(str, args))} failed: {done.stderr}")
        return done

    return run

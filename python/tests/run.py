"""CTest's entry to the binding's tests: runs pytest on this folder, or skips (exit 77, CTest's
SKIP_RETURN_CODE) with a message when pytest, NumPy or cffi is missing.
Usage: python3 run.py BUILD_DIR SOURCE_DIR"""

import importlib.util
import os
import sys

missing = [m for m in ("pytest", "numpy", "cffi") if importlib.util.find_spec(m) is None]
if missing:
    print(f"SKIP: {', '.join(missing)} not installed for {sys.executable}; "
          "install python3-pytest python3-numpy python3-cffi (scripts/deps.sh) to test the Python binding")
    sys.exit(77)

import pytest  # noqa: E402

os.environ["PLUME_BUILD_DIR"] = os.path.abspath(sys.argv[1])
os.environ["PLUME_SOURCE_DIR"] = os.path.abspath(sys.argv[2])
sys.dont_write_bytecode = True
sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", os.path.dirname(os.path.abspath(__file__))]))

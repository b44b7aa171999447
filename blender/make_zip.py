"""Builds the Blender add-on zip: plume_feathers/ with the plume package (its cffi declarations made
from include/plume) and the model presets of examples/ inside, ready for Edit > Preferences >
Add-ons > Install. libplume.so itself is found at run time (pkg-config after `make install`, or
PLUME_BUILD_DIR / PLUME_LIBRARY).
Usage: python3 blender/make_zip.py SOURCE_DIR OUTPUT.zip"""

import importlib.util
import pathlib
import sys
import zipfile

source = pathlib.Path(sys.argv[1]).resolve()
output = pathlib.Path(sys.argv[2])

spec = importlib.util.spec_from_file_location("plume_headers", source / "python" / "plume" / "_headers.py")
headers = importlib.util.module_from_spec(spec)
spec.loader.exec_module(headers)

output.parent.mkdir(parents=True, exist_ok=True)
temporary = output.with_suffix(".zip.tmp")
with zipfile.ZipFile(temporary, "w", zipfile.ZIP_DEFLATED) as z:
    for f in sorted((source / "blender" / "plume_feathers").glob("*.py")):
        z.write(f, f"plume_feathers/{f.name}")
    for f in sorted((source / "python" / "plume").glob("*.py")):
        z.write(f, f"plume_feathers/plume/{f.name}")
    z.writestr("plume_feathers/plume/_cdef.h", headers.cdef(source / "include")[0])
    for model in ("franco-walter", "streit-heidrich", "zhang-kanai"):
        for f in sorted((source / "examples" / model).glob("*.json")):
            z.write(f, f"plume_feathers/presets/{model}/{f.name}")
temporary.replace(output)
print(output)

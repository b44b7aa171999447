// plume — geometry export and import. Every writer replaces its file
// atomically: a failed call leaves whatever was there before.
#ifndef PLUME_IO_H
#define PLUME_IO_H

#include "plume/feather.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

/// Wavefront OBJ: shaft and barbs (and barbules) as polyline elements
/// "l v/vt ..." with texture coordinates, one object per part, so Blender and
/// Houdini import them as curves.
plume_status plume_write_obj(const plume_feather *feather, const char *path, plume_error *err);

/// USD text (.usda): shaft and barbs as BasisCurves with widths (diameters),
/// normals (barbs face them, as flat ribbons) and primvars:st texture
/// coordinates; metres, +Y up.
plume_status plume_write_usda(const plume_feather *feather, const char *path, plume_error *err);

/// JSON dump of the whole structure (schema in docs/feather-json.md).
plume_status plume_write_json(const plume_feather *feather, const char *path, plume_error *err);

/// Reads a JSON dump written by plume_write_json. The result equals the
/// feather that was written, bit for bit.
plume_status plume_read_json(const char *path, plume_feather **out, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_IO_H

// plume — geometry export and import. Every writer replaces its file
// atomically: a failed call leaves whatever was there before.
#ifndef PLUME_IO_H
#define PLUME_IO_H

#include "plume/feather.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

/// Wavefront OBJ: shaft and barbs (and barbules) as polylines with texture
/// coordinates, each written as consecutive two-vertex elements "l a b"
/// (which every importer reads whole), one object per part; one "vt" per "v",
/// in the same order.
plume_status plume_write_obj(const plume_feather *feather, const char *path, plume_error *err);

/// USD text (.usda): shaft and barbs as BasisCurves with widths (diameters),
/// normals (barbs face them, as flat ribbons) and primvars:st texture
/// coordinates; metres, +Y up.
plume_status plume_write_usda(const plume_feather *feather, const char *path, plume_error *err);

/// JSON dump of the whole structure (schema in docs/feather-json.md).
plume_status plume_write_json(const plume_feather *feather, const char *path, plume_error *err);

/// The same document with its numbers in a sidecar (version 2): path's JSON keeps
/// the structure, and every number array becomes a view {"offset", "count"} into
/// path with ".json" replaced by ".bin" (little-endian binary64), written next
/// to it. Exact like plume_write_json, about ten times faster, half the size.
plume_status plume_write_json_binary(const plume_feather *feather, const char *path, plume_error *err);

/// Reads a JSON dump written by plume_write_json or plume_write_json_binary. The result equals the
/// feather that was written, bit for bit.
plume_status plume_read_json(const char *path, plume_feather **out, plume_error *err);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_IO_H

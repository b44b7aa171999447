// Private: a glTF 2.0 binary (.glb) builder. The JSON chunk is built with
// jansson (the project's JSON library). The binary chunk is either one buffer
// in memory that grows as views are added (plume_glb_init), or spooled to a
// temporary file beside the destination as views are added, so that a writer
// holds none of it (plume_glb_init_spooled: the feather and coat writers, whose
// chunk can be gigabytes). plume_glb_write lays out the container (glTF 2.0
// spec, section 4.4 "GLB File Format Specification") and writes it atomically.
//
// Only what plume's writers need: one buffer, tightly packed views, accessors
// with min/max where the spec requires them (POSITION), meshes, nodes, one
// scene, materials and animations as plain jansson objects.
#ifndef PLUME_IO_GLB_H
#define PLUME_IO_GLB_H

#include <stddef.h>
#include <stdint.h>

#include <jansson.h>

#include "core/atomic_file.h"
#include "plume/core.h"

/// glTF accessor component types (spec 5.1.3).
enum {
	GLB_FLOAT = 5126,
	GLB_UNSIGNED_INT = 5125,
	GLB_UNSIGNED_SHORT = 5123,
};

/// bufferView targets (spec 5.11.4).
enum {
	GLB_ARRAY_BUFFER = 34962,
	GLB_ELEMENT_ARRAY_BUFFER = 34963,
	GLB_NO_TARGET = 0,
};

typedef struct plume_glb {
	json_t *root; ///< the glTF document
	json_t *buffer_views, *accessors, *meshes, *nodes, *materials, *animations;
	uint8_t *bytes; ///< the binary chunk (in memory)
	size_t size, capacity;
	bool spooled;            ///< the binary chunk goes to spool instead of bytes
	plume_atomic_file spool; ///< plume_glb_init_spooled: the binary chunk so far, removed by plume_glb_free
	size_t view_start;       ///< where the view being streamed (plume_glb_view_begin) starts
	bool failed;             ///< out of memory somewhere: plume_glb_write reports it
	int write_error;         ///< errno of the first failed write to the spool (0: none); plume_glb_write reports it
	bool too_large;          ///< the binary chunk passed the GLB's 4 GiB: plume_glb_write reports it
} plume_glb;

/// Starts an empty document (asset, one scene with no nodes yet). On failure the
/// builder is marked failed and plume_glb_write reports PLUME_ERROR_MEMORY.
void plume_glb_init(plume_glb *glb, const char *generator);

/// plume_glb_init with the binary chunk spooled to a temporary file beside path (the file
/// plume_glb_write will write), so that it is never held in memory. PLUME_ERROR_IO when
/// the temporary file cannot be created (nothing to free then).
plume_status plume_glb_init_spooled(plume_glb *glb, const char *generator, const char *path, plume_error *err);
void plume_glb_free(plume_glb *glb);

/// A view written in pieces: plume_glb_view_begin, any number of plume_glb_view_append,
/// then plume_glb_view_end, which adds the view (all the bytes appended) and returns its index.
void plume_glb_view_begin(plume_glb *glb);
void plume_glb_view_append(plume_glb *glb, const void *data, size_t size);
int plume_glb_view_end(plume_glb *glb, int target);

/// A float accessor of count elements of components floats on view; min and max
/// (components each) when not NULL (required for POSITION). Returns its index.
int plume_glb_float_accessor(plume_glb *glb, int view, int64_t count, int components, const float *min,
                             const float *max);

/// An unsigned 32-bit SCALAR accessor of count elements on view. Returns its index.
int plume_glb_index_accessor(plume_glb *glb, int view, int64_t count);

/// Appends count * components floats (given as doubles, rounded to float) as
/// a new accessor of type "SCALAR", "VEC2", "VEC3" or "VEC4". With bounds, the
/// accessor carries min and max (required for POSITION). Returns its index.
int plume_glb_floats(plume_glb *glb, const double *values, int count, int components, int target, bool bounds);

/// The same from floats already rounded.
int plume_glb_floats_f(plume_glb *glb, const float *values, int count, int components, int target, bool bounds);

/// Appends unsigned 32-bit indices as a SCALAR accessor. Returns its index.
int plume_glb_indices(plume_glb *glb, const uint32_t *values, int64_t count);

/// Adds obj to the named top-level array (meshes, nodes, ...), which takes the
/// reference, and returns its index.
int plume_glb_append(plume_glb *glb, json_t *array, json_t *obj);

/// Makes node a root of the scene.
void plume_glb_scene_root(plume_glb *glb, int node);

/// A double-sided, rough dielectric material whose base colour is factor
/// (linear RGBA) times the vertex colours when a primitive has COLOR_0.
int plume_glb_material(plume_glb *glb, const char *name, const double factor[4]);

/// Writes the container to path atomically.
/// An embedded PNG image (size bytes) as image, sampler and texture; returns the texture's index.
int plume_glb_png_texture(plume_glb *glb, const unsigned char *png, size_t size);

/// Gives material a base colour texture read through TEXCOORD_texcoord.
void plume_glb_material_texture(plume_glb *glb, int material, int texture, int texcoord);

plume_status plume_glb_write(plume_glb *glb, const char *path, plume_error *err);

/// sRGB component to linear (glTF's COLOR_0 and baseColorFactor are linear).
double plume_glb_linear(double srgb);

struct plume_mesh;
struct plume_gltf_def;

/// A node "name" with mesh "name": the shell's triangles with smooth normals,
/// texture coordinates and one primitive per material. Returns the node.
int plume_glb_shell_node(plume_glb *glb, const struct plume_mesh *mesh, const plume_vec3 *positions,
                         const struct plume_gltf_def *def, const char *name);

struct plume_barb_embedding;

/// A node `name` (and its mesh): the embedded feather carried by frames[0..frame_count) as one
/// LINES primitive whose morph target k moves it from frames[0] to frames[k].
/// Sets *ok false on failure. Returns the node.
int plume_glb_carried_feather(plume_glb *glb, const struct plume_barb_embedding *embedding,
                              const plume_vec3 *const *frames, int frame_count, const char *name,
                              const struct plume_gltf_def *def, bool *ok);

#endif

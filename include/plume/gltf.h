// plume — glTF 2.0 binary (.glb) export: feathers, shells, animated
// simulations and coats as files Blender, three.js and other glTF clients open.
//
// Every file is metres, +Y up (glTF's convention and plume's feather frame),
// one buffer inside the .glb, materials double-sided and rough, colours as
// linear COLOR_0 vertex attributes. Writers replace their file atomically.
#ifndef PLUME_GLTF_H
#define PLUME_GLTF_H

#include "plume/coat.h"
#include "plume/feather.h"
#include "plume/mesh.h"
#include "plume/render.h"

#ifdef __cplusplus
extern "C" {
#endif
PLUME_API_BEGIN

/// How curves (shaft, barbs, barbules) become glTF primitives.
typedef enum plume_gltf_curves {
	/// Flat ribbons: two vertices per curve point, offset by half the width across
	/// the curve in the plane that faces the point's normal; triangles, with the
	/// curve's normals, texture coordinates (s, t) and colours at both edges.
	PLUME_GLTF_RIBBONS = 0,
	/// Line segments (mode LINES) through the curve points, with texture coordinates
	/// and colours; no width. Blender imports them as edges.
	PLUME_GLTF_LINES = 1,
} plume_gltf_curves;

typedef struct plume_gltf_def {
	/// Default PLUME_GLTF_RIBBONS.
	plume_gltf_curves curves;
	/// Write the barbules (when the feather has any). Default true.
	bool barbules;
	/// When not NULL, barbs and barbules take their colour from it by (s, t)
	/// (Franco & Walter 4.4, plume_texture_sample_vane) and the shaft the colour at s = 0.
	const plume_texture *texture;
	/// Colours (sRGB) without a texture. Defaults: barbs hawk brown (0.45, 0.33, 0.22),
	/// shaft pale horn (0.78, 0.72, 0.62), as the ray tracer's.
	plume_color barb_color;
	plume_color shaft_color;
	/// Shell colours (sRGB) of vane and rachis faces. Defaults (0.70, 0.62, 0.50), (0.78, 0.72, 0.62).
	plume_color vane_color;
	plume_color rachis_color;
	/// PLUME_DEF_COOKIE, set by plume_gltf_default_def; do not change.
	uint32_t cookie;
} plume_gltf_def;

plume_gltf_def plume_gltf_default_def(void);

/// A feather: a root node "feather" with one child node and mesh per part
/// (shaft, left_vane, right_vane, barbules) and the afterfeather as a child
/// node "afterfeather" with its own parts. def may be NULL (defaults). The
/// ribbons are streamed to a temporary file beside path as they are made and
/// copied into it: the writer holds no copy of the geometry.
plume_status plume_write_glb(const plume_feather *feather, const plume_gltf_def *def, const char *path,
                             plume_error *err);

/// A shell: one mesh "shell" of triangles with smooth normals, texture
/// coordinates, and one primitive per material (vane, rachis) coloured by
/// def's vane/rachis colours. positions (vertex_count) replaces the rest shape
/// when not NULL. def may be NULL.
plume_status plume_mesh_write_glb(const plume_mesh *mesh, const plume_vec3 *positions, const plume_gltf_def *def,
                                  const char *path, plume_error *err);

/// A coat: the body surface as mesh "surface", and one node per feather
/// (feather_00000 ..., drawing order), translated to its follicle, whose mesh
/// holds the feather's parts relative to the follicle. Feathers with the same
/// geometry relative to their follicle (as stored: float32) share one mesh
/// (node instances, which every glTF importer reads; EXT_mesh_gpu_instancing is
/// not used because Blender 3.4's importer ignores it). def may be NULL. One
/// feather's arrays are held at a time (and an earlier one's to compare), the
/// binary chunk streamed as for plume_write_glb.
plume_status plume_coat_write_glb(const plume_coat *coat, const plume_gltf_def *def, const char *path,
                                  plume_error *err);

/// What plume_coat_write_glb wrote: feather nodes and distinct feather meshes.
typedef struct plume_coat_glb_report {
	int instances;
	int meshes;
} plume_coat_glb_report;

/// plume_coat_write_glb that also says how many instances and meshes it wrote (report may be NULL).
plume_status plume_coat_write_glb_report(const plume_coat *coat, const plume_gltf_def *def, const char *path,
                                         plume_coat_glb_report *report, plume_error *err);

/// An animated shell: frames of vertex positions collected one at a time,
/// written as one .glb whose mesh has one morph target per frame (the
/// displacement from the first frame) and one animation "simulation" whose
/// LINEAR weight keys at each frame's time select that frame's target alone,
/// which Blender's importer (shape keys with an action) and three.js
/// (AnimationMixer) both play. Frames are stored as floats.
typedef struct plume_mesh_animation plume_mesh_animation;

/// The mesh must outlive the animation. def may be NULL (colours as plume_mesh_write_glb).
plume_status plume_mesh_animation_create(const plume_mesh *mesh, const plume_gltf_def *def, plume_mesh_animation **out,
                                         plume_error *err);

/// Adds a frame at time seconds (times must increase): positions holds the
/// mesh's vertex_count positions.
plume_status plume_mesh_animation_add_frame(plume_mesh_animation *animation, double time, const plume_vec3 *positions,
                                            plume_error *err);

int plume_mesh_animation_frame_count(const plume_mesh_animation *animation);

struct plume_barb_embedding;

/// Carries a feather by the shell (include/plume/embed.h): the .glb then also has a
/// node "feather", the embedded feather's shaft, barbs and barbules as line
/// segments (LINES, with texture coordinates and colours) with one morph target per
/// frame, played by the same animation. At barb level this is large: about 12 bytes
/// per feather point and frame. The embedding must outlive the animation.
void plume_mesh_animation_set_feather(plume_mesh_animation *animation, const struct plume_barb_embedding *embedding);

/// Carries one more feather by the shell (a scene's many feathers, each embedded in its own
/// faces: plume_embedding_create_faces): node "feather_NAME" (NAME at most 23 bytes), written
/// like plume_mesh_animation_set_feather's "feather". The embedding must outlive the animation.
/// PLUME_ERROR_MEMORY.
plume_status plume_mesh_animation_add_feather(plume_mesh_animation *animation,
                                              const struct plume_barb_embedding *embedding, const char *name,
                                              plume_error *err);

/// Writes body's frames into this animation's .glb too: node "body", its mesh with one morph
/// target per frame, played by the same animation (an animated body a scene's feathers hang
/// on). body must hold as many frames as this animation, at the same times, when the .glb is
/// written (else PLUME_ERROR_SPEC), and outlive it. NULL removes it.
void plume_mesh_animation_set_body(plume_mesh_animation *animation, const plume_mesh_animation *body);

/// Writes the frames so far (at least one) as .glb.
plume_status plume_mesh_animation_write_glb(const plume_mesh_animation *animation, const char *path, plume_error *err);

/// Writes the frames so far (at least one) as USD text: one Mesh whose points
/// (and extent) are time samples at each frame's time code (seconds x 24,
/// timeCodesPerSecond 24), primvars:st, and primvars:displayColor per face
/// from the vane and rachis colours.
plume_status plume_mesh_animation_write_usda(const plume_mesh_animation *animation, const char *path, plume_error *err);

void plume_mesh_animation_destroy(plume_mesh_animation *animation);

PLUME_API_END
#ifdef __cplusplus
}
#endif

#endif // PLUME_GLTF_H

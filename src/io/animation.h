// Private: the frames of a plume_mesh_animation, shared by its glTF and USD writers.
#ifndef PLUME_IO_ANIMATION_H
#define PLUME_IO_ANIMATION_H

#include "plume/gltf.h"

struct plume_mesh_animation {
	const plume_mesh *mesh;
	plume_gltf_def def;
	int frame_count, frame_capacity;
	double *times;
	double *first;        ///< the first frame in double, the base the displacements are taken from
	float *displacements; ///< frame_count * vertex_count * 3: frame minus first frame
	/// The carried feathers (plume_mesh_animation_set_feather, plume_mesh_animation_add_feather) and their node names.
	const struct plume_barb_embedding **embeddings;
	char (*names)[32];
	int feather_count;
	const struct plume_mesh_animation *body; ///< plume_mesh_animation_set_body, or NULL
};

#endif

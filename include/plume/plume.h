// plume — feathers: generation, simulation, rendering. Include this one header.
#ifndef PLUME_H
#define PLUME_H

#include "plume/core.h"
#include "plume/feather.h"
#include "plume/io.h"
#include "plume/gltf.h"
#include "plume/intersect.h"
#include "plume/lab.h"
#include "plume/mesh.h"
#include "plume/model.h"
#include "plume/streit_heidrich.h"
#include "plume/zhang_kanai.h"
#include "plume/coat.h"
#include "plume/embed.h"
#include "plume/raytrace.h"
#include "plume/render.h"
#include "plume/scene.h"
#include "plume/body.h"
#include "plume/sim.h"

#endif // PLUME_H

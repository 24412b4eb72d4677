// The scene as every estimator sees it: the frame's parameters (camera, medium, image, seeds) and
// the lights (numbers in shared/bindings.h). PLUME_LIGHT_CHOICE adds the probabilities with which
// an estimator that picks one light per sample chooses it (ReSTIR's candidates); PLUME_HAS_ENV_MAP
// the environment map (shared/envmap.h).
#ifndef PLUME_SCENE_BINDINGS_GLSL
#define PLUME_SCENE_BINDINGS_GLSL

#include "../shared/bindings.h"
#include "../shared/gpu_types.h"

layout(std430, binding = BIND_FRAME) readonly buffer FrameBuffer { GpuFrame frame; };
layout(std430, binding = BIND_LIGHTS) readonly buffer LightBuffer { GpuLight lights[]; };
#ifdef PLUME_LIGHT_CHOICE
layout(std430, binding = BIND_LIGHT_CHOICE) readonly buffer LightChoiceBuffer { GpuLightChoice lightChoice[]; };
#endif
#ifdef PLUME_HAS_ENV_MAP
layout(std430, binding = BIND_ENV_MAP) readonly buffer EnvMapBuffer {
  GpuEnvMap envMap;
  float envData[];
};
#include "../shared/envmap.h"
#endif

#endif

// The scene as every estimator sees it: the frame's parameters (camera, medium, image, seeds) and
// the lights (numbers in shared/bindings.h). PLUME_LIGHT_CHOICE adds the probabilities with which
// an estimator that picks one light per sample chooses it (ReSTIR's candidates); PLUME_HAS_ENV_MAP
// the environment map (shared/envmap.h).
#ifndef PLUME_SCENE_BINDINGS_GLSL
#define PLUME_SCENE_BINDINGS_GLSL

#include "../shared/bindings.h"
#include "../shared/gpu_types.h"

// The frame's parameters are read once per invocation into a private copy (`frame`, loaded by
// scene_load_params() at a kernel's entry), as the volume's (volume/bindings.glsl).
layout(std430, binding = BIND_FRAME) readonly buffer FrameBuffer { GpuFrame frameParams; };
GpuFrame frame;
void scene_load_params() { frame = frameParams; }
// The lights as a texel buffer of uvec4, two per GpuLight (the same reason; surface/texels.glsl).
layout(binding = BIND_LIGHTS) uniform usamplerBuffer lightTexels;
GpuLight light_at(uint i) {
  uvec4 a = texelFetch(lightTexels, int(2u * i));
  uvec4 b = texelFetch(lightTexels, int(2u * i + 1u));
  GpuLight l;
  l.dirOrPos = uintBitsToFloat(a.xyz);
  l.type = a.w;
  l.emission = uintBitsToFloat(b.xyz);
  l.versine = uintBitsToFloat(b.w);
  return l;
}
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

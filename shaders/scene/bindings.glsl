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
// The map as one texel buffer of 32-bit words: the GpuEnvMap header (16 words, read once per
// invocation into `envMap` by scene_load_params) and then the data of shared/envmap.h, whose
// binary searches read it per lane (the same reason as above).
layout(binding = BIND_ENV_MAP) uniform usamplerBuffer envTexels;
const uint ENV_HEADER_WORDS = 16u;
#define ENV_DATA(i) uintBitsToFloat(texelFetch(envTexels, int(ENV_HEADER_WORDS + (i))).r)
GpuEnvMap envMap;
#include "../shared/envmap.h"
#endif

// The private copies of the scene's parameter blocks: first thing in every kernel that reads them.
void scene_load_params() {
  frame = frameParams;
#ifdef PLUME_HAS_ENV_MAP
  uvec4 h[4];
  for (int k = 0; k < 4; ++k) {
    h[k] = uvec4(texelFetch(envTexels, 4 * k).r, texelFetch(envTexels, 4 * k + 1).r, texelFetch(envTexels, 4 * k + 2).r,
                 texelFetch(envTexels, 4 * k + 3).r);
  }
  envMap.toLocal0 = uintBitsToFloat(h[0]);
  envMap.toLocal1 = uintBitsToFloat(h[1]);
  envMap.toLocal2 = uintBitsToFloat(h[2]);
  envMap.width = h[3].x;
  envMap.height = h[3].y;
  envMap.pad0 = h[3].z;
  envMap.pad1 = h[3].w;
#endif
}

#endif

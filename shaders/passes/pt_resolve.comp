// The path tracer's resolve kernel (pt/wavefront.glsl): a finished generation's samples merged
// into the pixels' running mean and M2, one invocation per pixel, in sample order (a loop of at
// most PathTracer's samples per generation, far below the driver's loop budget).
#version 450
#extension GL_GOOGLE_include_directive : require

#include "../shared/pt_wave.h"

// The host dispatches groups of PT_WAVE_GROUP (render/path_tracer.cpp): one constant for both.
layout(local_size_x = PT_WAVE_GROUP) in;

#include "../scene/bindings.glsl"
#include "../pt/wavefront.glsl"
#include "../shared/accumulate.h"

// Per pixel: ptAccum[2i] = (mean rgb, n), ptAccum[2i+1] = (M2 rgb, 0).
layout(std430, binding = BIND_PT_ACCUM) buffer AccumBuffer { vec4 ptAccum[]; };

void main() {
  scene_load_params();
  uint i = gl_GlobalInvocationID.x;
  if (i >= ptPush.pixelCount) return;
  uvec2 pixel = pt_list_pixel(ptPush.pixelBegin + i);
  uint index = pixel.y * frame.size.x + pixel.x - ptPush.accumBase;
  vec4 a = ptAccum[2u * index];
  vec3 m2a = ptAccum[2u * index + 1u].rgb;
  for (uint slot = i; slot < ptPush.slots; slot += ptPush.pixelCount) {
    acc_merge(a, m2a, pt_radiance(slot), vec3(0.0f), 1.0f);
  }
  ptAccum[2u * index] = a;
  ptAccum[2u * index + 1u] = vec4(m2a, 0.0f);
}

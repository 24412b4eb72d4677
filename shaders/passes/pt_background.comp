// The path tracer's background kernel (pt/wavefront.glsl): the pixels whose every camera ray
// misses the scene (the end of the pixel list, render/pixel_order.h), one invocation per pixel.
// Each of its samples draws the camera ray pt_camera would (the same stream and draws) and sees
// the environment along it, merged into the pixel's running mean and M2 in sample order, as
// pt_resolve would merge them: the same image bit for bit, without a path slot, a queue entry or a
// walk (on lavapipe the camera kernel ran every slot, ~60% of them such rays on the bundled
// smoke, at ~17% of the path tracer's time).
#version 450
#extension GL_GOOGLE_include_directive : require

#include "../shared/pt_wave.h"

// The host dispatches groups of PT_WAVE_GROUP (render/path_tracer.cpp): one constant for all.
layout(local_size_x = PT_WAVE_GROUP) in;

#include "../volume/bindings.glsl"
#include "../scene/bindings.glsl"
#include "../pt/wavefront.glsl"
#include "../pt/integrator.glsl"
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
#ifdef PLUME_HAS_ENV_MAP
  // ptPush.slots samples (the host keeps it far below the driver's loop budget).
  for (uint s = 0u; s < ptPush.slots; ++s) {
    RngState rng = pt_sample_rng(pixel, frame.firstSample + ptPush.sampleBase + s);
    acc_merge(a, m2a, light_escaped(pt_pixel_ray(pixel, rng)), vec3(0.0f), 1.0f);
  }
#else
  // Without a map the environment does not depend on the ray's direction: the samples are
  // ptPush.slots copies of one value, merged at once (the same bits as one at a time, since every
  // earlier sample of the pixel in this frame had that value too: shared/accumulate.h).
  acc_merge(a, m2a, light_escaped(vec3(0.0f, 0.0f, 1.0f)), vec3(0.0f), float(ptPush.slots));
#endif
  ptAccum[2u * index] = a;
  ptAccum[2u * index + 1u] = vec4(m2a, 0.0f);
}

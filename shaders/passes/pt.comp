// The GPU baseline (DESIGN §4.1): unidirectional volumetric path tracing, delta tracking for
// free flights, NEE with ratio tracking, HG phase sampling, Russian roulette. One thread per
// pixel, `frame.image.z` samples per dispatch, merged into a running mean and M2 per pixel
// (Chan et al.'s parallel variance update) so progressive batches give the variance of the mean.
// Variant defines: PLUME_HAS_SUN, PLUME_HAS_POINT, PLUME_HAS_ENV, PLUME_MULTI_BOUNCE.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "../shared/accumulate.h"
#include "../shared/gpu_types.h"
#include "../volume/bindings.glsl"

layout(std430, binding = 5) readonly buffer FrameBuffer { GpuFrame frame; };
layout(std430, binding = 6) readonly buffer LightBuffer { GpuLight lights[]; };
// Per pixel: accum[2i] = (mean rgb, n), accum[2i+1] = (M2 rgb, 0).
layout(std430, binding = 7) buffer AccumBuffer { vec4 accum[]; };

#include "../volume/volume.glsl"
#include "../volume/lights.glsl"

vec3 direct(vec3 x, vec3 rayDir, inout RngState rng) {
  vec3 sum = vec3(0.0f);
  for (uint i = 0u; i < frame.lights.x; ++i) sum += light_direct(lights[i], x, rayDir, frame.albedo.w, rng);
  return sum;
}

vec3 environmentSeen() {
  vec3 sum = vec3(0.0f);
#ifdef PLUME_HAS_ENV
  for (uint i = 0u; i < frame.lights.x; ++i) {
    if (uint(lights[i].params.x) == LIGHT_ENVIRONMENT) sum += lights[i].emission.rgb;
  }
#endif
  return sum;
}

vec3 tracePath(vec3 origin, vec3 dir, inout RngState rng) {
  vec3 radiance = vec3(0.0f);
  vec3 beta = vec3(1.0f);
  uint maxBounces = frame.image.w;
#ifdef PLUME_MULTI_BOUNCE
  for (uint scatterings = 0u;;) {
#else
  {
    uint scatterings = 0u;
#endif
    float t;
    if (!vol_sample_collision(origin, dir, DDA_INF, rng, t)) {
      // Lights are reached by NEE after the first vertex: only camera rays see the environment.
      if (scatterings == 0u) radiance += beta * environmentSeen();
      return radiance;
    }
    if (++scatterings > maxBounces) return radiance;
    vec3 x = origin + t * dir;
    beta *= frame.albedo.rgb;
    radiance += beta * direct(x, dir, rng);
#ifdef PLUME_MULTI_BOUNCE
    if (scatterings >= frame.seeds.w) {
      float q = min(1.0f, plume_max3(beta));
      if (rng_float(rng) >= q) return radiance;
      beta /= q;
    }
    dir = normalize(ph_hg_sample(dir, frame.albedo.w, rng_float2(rng)));
    origin = x;
#endif
  }
  return radiance;
}

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= frame.image.x || pixel.y >= frame.image.y) return;
  uint index = pixel.y * frame.image.x + pixel.x;
  vec4 batch = vec4(0.0f);  // (mean, n) of this dispatch's samples, and their M2
  vec3 m2 = vec3(0.0f);
  for (uint s = 0u; s < frame.image.z; ++s) {
    uint sampleIndex = frame.seeds.z + s;
    RngState rng = rng_init(pixel, frame.seeds.y, RNG_STREAM_PATH + (sampleIndex << 8u), frame.seeds.x);
    vec2 u = rng_float2(rng);
    // Box filter, row 0 at the top (DESIGN §2).
    vec3 dir = normalize(cam_direction(vec2(pixel) + u, frame.image.xy, frame.camPosition, frame.camForward,
                                       frame.camRight, frame.camUp));
    vec3 L = tracePath(frame.camPosition.xyz, dir, rng);
    acc_merge(batch, m2, L, vec3(0.0f), 1.0f);
  }
  // The batch into the accumulation.
  vec4 a = accum[2u * index];
  vec3 m2a = accum[2u * index + 1u].rgb;
  acc_merge(a, m2a, batch.rgb, m2, batch.w);
  accum[2u * index] = a;
  accum[2u * index + 1u] = vec4(m2a, 0.0f);
}

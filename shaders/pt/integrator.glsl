// The GPU baseline (DESIGN §4.1): unidirectional volumetric path tracing, delta tracking for
// free flights, next-event estimation with ratio tracking to every light, phase sampling, Russian
// roulette. `frame.spp` samples per pixel per dispatch, merged into a running mean and M2 per
// pixel (Chan et al.'s parallel variance update) so progressive batches give the variance of the
// mean. Variant defines: PLUME_HAS_SUN, PLUME_HAS_POINT, PLUME_HAS_ENV, PLUME_HAS_ENV_MAP,
// PLUME_MULTI_BOUNCE, PLUME_HAS_EMISSION (the medium's emission gathered along every segment by
// delta tracking).
// An environment map is reached two ways, combined by the power heuristic (Veach's thesis, eq.
// 9.15): next-event estimation draws a direction from the map (pdf p_l) and the path's next
// phase-sampled direction (pdf p_ph), which adds the map's radiance where it escapes; weights
// p_l² / (p_l² + p_ph²) and p_ph² / (p_l² + p_ph²). Every other light, a constant environment
// included, is reached by next-event estimation alone (only camera rays see it directly).
// Requires volume/bindings.glsl, scene/bindings.glsl and ptAccum (shaders/passes/pt.comp).
#ifndef PLUME_PT_INTEGRATOR_GLSL
#define PLUME_PT_INTEGRATOR_GLSL

#include "../shared/accumulate.h"
#include "../volume/grid.glsl"
#include "../volume/walk.glsl"
#include "../light/light.glsl"
#include "../integrator/vertex.glsl"

// Next-event estimation at a vertex x of a path arriving along rayDir: one sample per light.
vec3 pt_direct(uint kind, vec3 x, vec3 rayDir, inout RngState rng) {
  vec3 sum = vec3(0.0f);
  for (uint i = 0u; i < frame.lightCount; ++i) {
    GpuLight l = lights[i];
    vec2 u = vec2(0.0f);
    if (light_samples_direction(l)) u = rng_float2(rng);
    vec3 w;
    float dist;
    vec3 Le;
    if (!light_connect(l, x, light_sample_dir(l, x, rayDir, frame.g, u), w, dist, Le)) continue;
    float pdf = light_pdf(l, w, rayDir, frame.g);
    if (!(pdf > 0.0f)) continue;  // (an all-black map)
    float scatter = vtx_scatter(kind, rayDir, w);
    float mis = 1.0f;
#ifdef PLUME_HAS_ENV_MAP
    if (l.type == LIGHT_ENV_MAP) mis = pdf * pdf / (pdf * pdf + scatter * scatter);  // p_ph = phase
#endif
    float tr = vol_ratio_tracking(x, w, dist, rng);
    sum += Le * scatter * tr * (mis / pdf);
  }
  return sum;
}

#ifdef PLUME_HAS_ENV_MAP
// The environment map seen by a path that escapes along dir after a vertex that drew dir by
// phase sampling with pdf phasePdf: its power-heuristic weight against the map's NEE.
vec3 pt_escaped_map(vec3 dir, float phasePdf) {
  float pl = env_pdf(envMap, dir);
  return env_radiance(envMap, dir) * (phasePdf * phasePdf / (phasePdf * phasePdf + pl * pl));
}
#endif

vec3 pt_trace_path(vec3 origin, vec3 dir, inout RngState rng) {
  vec3 radiance = vec3(0.0f);
  vec3 beta = vec3(1.0f);
  float phasePdf = 0.0f;  // pdf of dir where a vertex drew it (the map's MIS)
  // With a map, a single-scattering path still follows its phase-sampled direction after its
  // vertex, to see whether it escapes (the map's MIS), so the loop runs.
#if defined(PLUME_MULTI_BOUNCE) || defined(PLUME_HAS_ENV_MAP)
#define PT_FOLLOWS_PHASE 1
  for (uint scatterings = 0u;;) {
#else
  {
    uint scatterings = 0u;
#endif
    float t;
#ifdef PLUME_HAS_EMISSION
    vec3 emitted;
    bool collided = vol_sample_collision_emitting(origin, dir, DDA_INF, rng, t, emitted);
    // Emission along this segment: a path of `scatterings` scattering vertices, counted up to
    // max_bounces like next-event estimation's (pbrt-v4's volpath does the same).
    radiance += beta * (vec3(1.0f) - vtx_albedo(VERTEX_MEDIUM)) * emitted;
    if (!collided) {
#else
    if (!vol_sample_collision(origin, dir, DDA_INF, rng, t)) {
#endif
      // Camera rays see every environment; after a vertex, only a map is seen (with its MIS
      // weight): the other lights are reached by NEE.
      if (scatterings == 0u) radiance += beta * light_escaped(dir);
#ifdef PLUME_HAS_ENV_MAP
      else radiance += beta * pt_escaped_map(dir, phasePdf);
#endif
      return radiance;
    }
    if (++scatterings > frame.maxBounces) return radiance;
    vec3 x = origin + t * dir;
    beta *= vtx_albedo(VERTEX_MEDIUM);  // delta tracking's collision weight
    radiance += beta * pt_direct(VERTEX_MEDIUM, x, dir, rng);
#ifdef PT_FOLLOWS_PHASE
    if (scatterings >= frame.rrStartBounce) {
      float q = min(1.0f, plume_max3(beta));
      if (rng_float(rng) >= q) return radiance;
      beta /= q;
    }
    vec3 next = normalize(vtx_sample(VERTEX_MEDIUM, dir, rng_float2(rng)));
    phasePdf = vtx_scatter(VERTEX_MEDIUM, dir, next);  // a medium vertex samples its phase exactly
    dir = next;
    origin = x;
#endif
  }
  return radiance;
}

#ifndef PT_SAMPLE_OFFSET
#define PT_SAMPLE_OFFSET 0u
#endif

// All of a dispatch's samples of one pixel, merged into the accumulation.
void pt_render_pixel(uvec2 pixel) {
  uint index = pixel.y * frame.size.x + pixel.x;
  vec4 batch = vec4(0.0f);  // (mean, n) of this dispatch's samples, and their M2
  vec3 m2 = vec3(0.0f);
  for (uint s = 0u; s < frame.spp; ++s) {
    uint sampleIndex = frame.firstSample + PT_SAMPLE_OFFSET + s;
    RngState rng = rng_init(pixel, frame.frameKey, RNG_STREAM_PATH + (sampleIndex << 8u), frame.seed);
    vec2 u = rng_float2(rng);
    // Box filter, row 0 at the top (DESIGN §2).
    vec3 dir = normalize(cam_direction(vec2(pixel) + u, frame.size, frame.camera));
    vec3 L = pt_trace_path(frame.camera.position, dir, rng);
    acc_merge(batch, m2, L, vec3(0.0f), 1.0f);
  }
  vec4 a = ptAccum[2u * index];
  vec3 m2a = ptAccum[2u * index + 1u].rgb;
  acc_merge(a, m2a, batch.rgb, m2, batch.w);
  ptAccum[2u * index] = a;
  ptAccum[2u * index + 1u] = vec4(m2a, 0.0f);
}

#endif

// The GPU baseline (DESIGN §4.1): unidirectional volumetric path tracing, delta tracking for
// free flights, next-event estimation with ratio tracking to every light, phase sampling, Russian
// roulette — organised as a wavefront (pt/wavefront.glsl): a path's segments and its vertices'
// shading are separate kernels over queues of paths. Each sample is merged into a running mean
// and M2 per pixel (Chan et al.'s parallel variance update), so the accumulation gives the
// variance of the mean. Variant defines: PLUME_HAS_SUN, PLUME_HAS_POINT, PLUME_HAS_ENV, PLUME_HAS_ENV_MAP,
// PLUME_MULTI_BOUNCE, PLUME_HAS_EMISSION (the medium's emission gathered along every segment by
// delta tracking).
// An environment map is reached two ways, combined by the power heuristic (Veach's thesis, eq.
// 9.15): next-event estimation draws a direction from the map (pdf p_l) and the path's next
// phase-sampled direction (pdf p_ph), which adds the map's radiance where it escapes; weights
// p_l² / (p_l² + p_ph²) and p_ph² / (p_l² + p_ph²). Every other light, a constant environment
// included, is reached by next-event estimation alone (only camera rays see it directly).
// Requires volume/bindings.glsl, scene/bindings.glsl and pt/wavefront.glsl.
#ifndef PLUME_PT_INTEGRATOR_GLSL
#define PLUME_PT_INTEGRATOR_GLSL

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

// With a map, a single-scattering path still follows its phase-sampled direction after its
// vertex, to see whether it escapes (the map's MIS).
#if defined(PLUME_MULTI_BOUNCE) || defined(PLUME_HAS_ENV_MAP)
#define PT_FOLLOWS_PHASE 1
#endif

// Extension (pt_extend.comp): the path in `slot` (a camera ray where `camera`) to its next real
// collision by delta tracking, gathering the medium's emission on the way. True where the path
// collided within max_bounces and waits for shading at its new vertex; otherwise it is finished
// (escaped, with the environment it sees, or past max_bounces) and its radiance is final.
bool pt_extend(uint slot, bool camera) {
  PtPath p;
  RngState rng = pt_slot_rng(slot, 0u);
  if (camera) {
    uvec2 pixel;
    pt_slot_sample(slot, pixel);
    vec2 u = rng_float2(rng);
    // Box filter, row 0 at the top (DESIGN §2).
    p.dir = normalize(cam_direction(vec2(pixel) + u, frame.size, frame.camera));
    p.origin = frame.camera.position;
    p.phasePdf = 0.0f;
    p.scatterings = 0u;
    p.beta = vec3(1.0f);
    p.radiance = vec3(0.0f);
    p.pad = 0u;
  } else {
    p = ptPaths[slot];
    rng.counter = p.counter;
  }
  float t;
  bool collided;
#ifdef PLUME_HAS_EMISSION
  vec3 emitted;
  collided = vol_sample_collision_emitting(p.origin, p.dir, DDA_INF, rng, t, emitted);
  // Emission along this segment: a path of `scatterings` scattering vertices, counted up to
  // max_bounces like next-event estimation's (pbrt-v4's volpath does the same).
  p.radiance += p.beta * (vec3(1.0f) - vtx_albedo(VERTEX_MEDIUM)) * emitted;
#else
  collided = vol_sample_collision(p.origin, p.dir, DDA_INF, rng, t);
#endif
  if (!collided) {
    // Camera rays see every environment; after a vertex, only a map is seen (with its MIS
    // weight): the other lights are reached by NEE.
    if (p.scatterings == 0u) p.radiance += p.beta * light_escaped(p.dir);
#ifdef PLUME_HAS_ENV_MAP
    else p.radiance += p.beta * pt_escaped_map(p.dir, p.phasePdf);
#endif
  } else if (++p.scatterings > frame.maxBounces) {
    collided = false;
  } else {
    p.origin += t * p.dir;
    p.beta *= vtx_albedo(VERTEX_MEDIUM);  // delta tracking's collision weight
  }
  p.counter = rng.counter;
  ptPaths[slot] = p;
  return collided;
}

// Shading (pt_shade.comp) of the path in `slot` at its newest vertex: next-event estimation,
// then (with more than one bounce, or a map to see) Russian roulette and a phase-sampled
// direction. True where the path goes on to another extension.
bool pt_shade(uint slot) {
  PtPath p = ptPaths[slot];
  RngState rng = pt_slot_rng(slot, p.counter);
  p.radiance += p.beta * pt_direct(VERTEX_MEDIUM, p.origin, p.dir, rng);
  bool more = false;
#ifdef PT_FOLLOWS_PHASE
  more = true;
  if (p.scatterings >= frame.rrStartBounce) {
    float q = min(1.0f, plume_max3(p.beta));
    if (rng_float(rng) >= q) {
      more = false;
    } else {
      p.beta /= q;
    }
  }
  if (more) {
    vec3 next = normalize(vtx_sample(VERTEX_MEDIUM, p.dir, rng_float2(rng)));
    p.phasePdf = vtx_scatter(VERTEX_MEDIUM, p.dir, next);  // a medium vertex samples its phase exactly
    p.dir = next;
  }
#endif
  p.counter = rng.counter;
  ptPaths[slot] = p;
  return more;
}

#endif

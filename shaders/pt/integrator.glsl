// The GPU baseline (DESIGN §4.1): unidirectional volumetric path tracing, delta tracking for
// free flights, next-event estimation with ratio tracking to every light, phase sampling, Russian
// roulette — organised as a wavefront (pt/wavefront.glsl): a path's segments and its vertices'
// shading are separate kernels over queues of paths. Each sample is merged into a running mean
// and M2 per pixel (Chan et al.'s parallel variance update), so the accumulation gives the
// variance of the mean. Variant defines: PLUME_HAS_SUN, PLUME_HAS_POINT, PLUME_HAS_ENV, PLUME_HAS_ENV_MAP,
// PLUME_MULTI_BOUNCE, PLUME_HAS_EMISSION (the medium's emission gathered along every segment by
// delta tracking), PLUME_HAS_SURFACES (a ray ends at the nearer of the medium's collision and the
// first surface; both are vertices, DESIGN §4.3), PLUME_HAS_EMITTERS (emissive triangles: NEE by
// area sampling and BSDF/phase-sampled hits, combined by the power heuristic).
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
#ifdef PLUME_HAS_SURFACES
#include "../surface/surfaces.glsl"
#endif
#include "../integrator/vertex.glsl"
#include "../integrator/path.glsl"

// Transmittance times visibility from the vertex along w over (0, dist): ratio tracking, and
// any surface in between blocks the light.
float pt_shadow(PathVertex v, vec3 w, float dist, inout RngState rng) {
  vec3 o = vtx_at_origin(v, w);
#ifdef PLUME_HAS_SURFACES
  if (surf_occluded(o, w, dist)) return 0.0f;
#endif
  return vol_ratio_tracking(o, w, dist, rng);
}

float pt_power_heuristic(float a, float b) { return a * a / (a * a + b * b); }

// Next-event estimation at a vertex of a path: one sample per light, and with emissive surfaces
// one point on them (area sampling in proportion to power, MIS against the vertex's own
// direction sampling, whose hits pt_extend weighs the other way).
vec3 pt_direct(PathVertex v, inout RngState rng) {
  vec3 sum = vec3(0.0f);
  for (uint i = 0u; i < frame.lightCount; ++i) {
    GpuLight l = light_at(i);
    vec2 u = vec2(0.0f);
    if (light_samples_direction(l)) u = rng_float2(rng);
    // The light's sample: direction w, reach dist and its unshadowed term a * b (two factors, in
    // the order they always multiplied the transmittance). Both kinds of sample end in the one
    // shadow walk below: a SIMD back end such as lavapipe runs a call site's walk under a mask
    // even where no lane takes its branch (a second call site for the surfaces' case cost every
    // medium vertex a masked walk per light).
    vec3 w;
    float dist;
    vec3 a;
    float b = 1.0f;
    bool lit;
#ifdef PLUME_HAS_SURFACES
    if (v.kind == VERTEX_SURFACE && l.type == LIGHT_ENVIRONMENT) {
      // A constant environment by the BSDF's own sampling (the medium's is its phase function,
      // which light_sample_dir draws).
      float pdf;
      a = l.emission * vtx_at_sample(v, u, w, pdf);
      dist = DDA_INF;
      lit = pdf > 0.0f;
    } else
#endif
    {
      vec3 Le;
      lit = light_connect(l, v.x, light_sample_dir(l, v.x, v.rayDir, frame.g, u), w, dist, Le);
      float pdf = lit ? light_pdf(l, w, v.rayDir, frame.g) : 0.0f;
      lit = lit && pdf > 0.0f;  // (an all-black map)
      a = Le * vtx_at_scatter(v, w);
      float mis = 1.0f;
#ifdef PLUME_HAS_ENV_MAP
      if (l.type == LIGHT_ENV_MAP) mis = pt_power_heuristic(pdf, vtx_at_pdf(v, w));
#endif
      b = mis / pdf;
    }
    if (lit) sum += a * pt_shadow(v, w, dist, rng) * b;
  }
#ifdef PLUME_HAS_EMITTERS
  uvec4 h = rng_next4(rng);
  uint prim;
  vec2 b;
  // The light ray's origin: the vertex, pushed off a surface to the side the path arrived from,
  // the only side it takes light from (a direction to the other side has scatter 0), so it is
  // known before the sample. The tree is descended there, so the sample's density is also the
  // one pt_extend's MIS evaluates at the same origin when the vertex's own sampling hits the
  // emitter: one descent per vertex instead of a second for the MIS weight.
  vec3 o = vtx_at_origin(v, -v.rayDir);
  vec3 receiver = vtx_receiver(v);
  float pdfArea = surf_sample_emitter_at(o, receiver, vec3(rng_to_float(h.x), rng_to_float(h.y), rng_to_float(h.z)), prim, b);
  vec3 p = surf_triangle_point(prim, b);
  vec3 toL = p - o;
  float dist = length(toL);
  vec3 w = toL / dist;
  float cosLight = -dot(surf_normal(prim), w);  // the back side emits nothing
  vec3 scatter = vtx_at_scatter(v, w);
  if (pdfArea > 0.0f && dist > 0.0f && cosLight > 0.0f && any(greaterThan(scatter, vec3(0.0f)))) {
    float g = dist * dist / cosLight;  // area to solid angle at the vertex
    // The MIS weight: the sample's own density, which pt_extend evaluates at the same origin with
    // the same receiver normal when the vertex's sampling hits the emitter (w leaves on the side
    // the path arrived from: scatter is 0 otherwise).
    float pdfMis = pdfArea * g;
    // Stop short of the emitter's own triangle.
    float tr = pt_shadow(v, w, dist - surf_offset_length(p), rng);
    sum += surf_emission(prim) * scatter * (tr * pt_power_heuristic(pdfMis, vtx_at_pdf(v, w)) / (pdfArea * g));
  }
#endif
  return sum;
}

#ifdef PLUME_HAS_ENV_MAP
// The environment map seen by a path that escapes along dir after a vertex that drew dir by
// phase sampling with pdf phasePdf: its power-heuristic weight against the map's NEE.
vec3 pt_escaped_map(vec3 dir, float phasePdf) {
  return env_radiance(envMap, dir) * pt_power_heuristic(phasePdf, env_pdf(envMap, dir));
}
#endif

// With a map (or emissive surfaces), a single-scattering path still follows its sampled direction
// after its vertex, to see whether it escapes to the map (or hits an emitter): their MIS.
#if defined(PLUME_MULTI_BOUNCE) || defined(PLUME_HAS_ENV_MAP) || defined(PLUME_HAS_EMITTERS)
#define PT_FOLLOWS_PHASE 1
#endif

// The camera ray of a sample of `pixel` (pt_background's), or of the path in `slot`: the stream's
// first two draws (a box filter over the pixel, row 0 at the top: DESIGN §2).
vec3 pt_pixel_ray(uvec2 pixel, inout RngState rng) {
  return normalize(cam_direction(vec2(pixel) + rng_float2(rng), frame.size, frame.camera));
}
vec3 pt_camera_ray(uint slot, inout RngState rng) {
  uvec2 pixel;
  pt_slot_sample(slot, pixel);
  return pt_pixel_ray(pixel, rng);
}

// The camera kernel (pt_camera.comp): true where the path in `slot`'s camera ray may meet the
// scene, for extension to follow it; a ray that certainly meets nothing (no surfaces, and the
// volume's box, where the density may be non-zero, missed: vol_may_meet) is finished here with
// the environment it sees, as extension would finish it. On a SIMD back end a camera ray that
// misses still costs its subgroup one masked pass of the whole walk, so culling those rays keeps
// extension's lanes on rays that walk (the bundled smoke: ~60% of the camera rays miss;
// notes/bench/kernels.md "Session 24").
bool pt_camera(uint slot) {
  RngState rng = pt_slot_rng(slot, 0u);
  vec3 dir = pt_camera_ray(slot, rng);
#ifdef PLUME_HAS_SURFACES
  return true;
#else
  if (vol_may_meet(frame.camera.position, dir)) return true;
  pt_set_radiance(slot, light_escaped(dir));
  return false;
#endif
}

// Extension (pt_extend.comp): the path in `slot` (a camera ray where `camera`: the slots
// pt_camera queued) to its next vertex: the medium's real collision by delta tracking (gathering
// its emission on the way), or the first surface if that is nearer (the medium is tracked only
// up to it; an emissive surface adds what it emits towards the path). True where the path found
// a vertex within max_bounces and waits for shading there; otherwise it is finished (escaped,
// with the environment it sees, or past max_bounces) and its radiance is final.
bool pt_extend(uint slot, bool camera) {
  PtPath p;
  RngState rng = pt_slot_rng(slot, 0u);
  if (camera) {
    p.dir = pt_camera_ray(slot, rng);
    p.origin = frame.camera.position;
    p.phasePdf = 0.0f;
    p.scatterings = 0u;
    p.beta = vec3(1.0f);
    p.radiance = vec3(0.0f);
    p.prim = PT_MEDIUM_VERTEX;
    p.shading = vec3(0.0f);
    p.pad = 0u;
  } else {
    p = pt_load(slot, false);
    rng.counter = p.counter;
  }
  PathSegment seg = path_segment(p.origin, p.dir, rng);
#ifdef PLUME_HAS_EMISSION
  // Emission along this segment: a path of `scatterings` scattering vertices, counted up to
  // max_bounces like next-event estimation's (pbrt-v4's volpath does the same).
  p.radiance += path_emission(seg, p.beta);
#endif
  bool vertex = path_has_vertex(seg);
  if (vertex) {
#ifdef PLUME_HAS_EMITTERS
    // The ray's origin before it moves to the vertex, and the receiver normal there (the previous
    // vertex's triangle: its normal on the ray's side; 0 after a medium vertex).
    vec3 origin = p.origin;
    vec3 receiver = p.prim != PT_MEDIUM_VERTEX ? surf_receiver(p.prim, p.dir) : vec3(0.0f);
#endif
    PathVertex v = path_vertex(seg, p.origin, p.dir, p.beta);
    p.prim = PT_MEDIUM_VERTEX;
#ifdef PLUME_HAS_SURFACES
    if (v.kind == VERTEX_SURFACE) {
      vec3 le = surf_emitted(v.prim, v.n, p.dir);
#ifdef PLUME_HAS_EMITTERS
      // After a vertex, weighted against that vertex's emitter sampling (its area density turned
      // into solid angle at the vertex: distance² / cosine), the light tree's at the ray's origin.
      if (p.scatterings > 0u && any(greaterThan(le, vec3(0.0f)))) {
        float pdfLight = surf_emitter_pdf_at(v.prim, origin, receiver) * seg.t * seg.t / abs(dot(v.n, p.dir));
        le *= pt_power_heuristic(p.phasePdf, pdfLight);
      }
#endif
      p.radiance += p.beta * le;
      p.prim = v.prim;
      p.shading = v.ns;
    }
#endif
  } else {
    // Camera rays see every environment; after a vertex, only a map is seen (with its MIS
    // weight): the other lights are reached by NEE.
    if (p.scatterings == 0u) p.radiance += p.beta * light_escaped(p.dir);
#ifdef PLUME_HAS_ENV_MAP
    else p.radiance += p.beta * pt_escaped_map(p.dir, p.phasePdf);
#endif
  }
  if (vertex && ++p.scatterings > frame.maxBounces) vertex = false;
  p.counter = rng.counter;
  // A finished path leaves only its radiance (pt_resolve reads nothing else). The ray (dir,
  // phasePdf) is the one shading drew, or the camera's: stored only for a camera ray.
  if (!vertex) {
    pt_set_radiance(slot, p.radiance);
    return false;
  }
  if (camera) {
    ptPaths[slot].dir = p.dir;
    ptPaths[slot].phasePdf = p.phasePdf;
  }
  pt_store_vertex(slot, p);
  return true;
}

// The vertex the path in p waits at (after pt_extend).
PathVertex pt_vertex(PtPath p) {
#ifdef PLUME_HAS_SURFACES
  if (p.prim != PT_MEDIUM_VERTEX) return vtx_surface(p.origin, p.dir, p.prim, p.shading);
#endif
  return vtx_medium(p.origin, p.dir);
}

// Shading (pt_shade.comp) of the path in `slot` at its newest vertex: next-event estimation,
// then (with more than one bounce, or a map or emitters to see) Russian roulette and a direction
// sampled by the vertex's phase function or BSDF. True where the path goes on to another
// extension.
bool pt_shade(uint slot) {
  PtPath p = pt_load(slot, true);
  RngState rng = pt_slot_rng(slot, p.counter);
  PathVertex v = pt_vertex(p);
  p.radiance += p.beta * pt_direct(v, rng);
  bool more = false;
#ifdef PT_FOLLOWS_PHASE
  // Roulette on the throughput; a BSDF that produced no direction also ends the path.
  more = path_roulette(p.scatterings, min(1.0f, plume_max3(p.beta)), rng, p.beta) &&
         path_scatter(v, rng_float2(rng), p.beta, p.origin, p.dir, p.phasePdf);
#endif
  pt_set_radiance(slot, p.radiance);
#ifdef PT_FOLLOWS_PHASE
  if (more) {
    p.counter = rng.counter;
    pt_store_ray(slot, p);
  }
#endif
  return more;
}

#endif

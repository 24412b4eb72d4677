// The bridge between ReSTIR's algorithm (shared/reservoir.h, shared/restir_types.h,
// shared/restir_mis.h) and our resources: domains (a pixel of a frame, with that frame's volume),
// light samples, the path contribution f_D(y) — approximate (the target p̂) or unbiased (final
// shading) — and reservoir and path storage. Candidates and the reuse step build on it
// (candidates.glsl, reuse.glsl). Requires restir/bindings.glsl.
#ifndef PLUME_RESTIR_BRIDGE_GLSL
#define PLUME_RESTIR_BRIDGE_GLSL

#include "../shared/rng.h"
#include "../volume/grid.glsl"
#include "../volume/walk.glsl"
#include "../light/light.glsl"
#include "../integrator/vertex.glsl"

#ifndef PLUME_RS_LIGHT_CANDIDATES
#define PLUME_RS_LIGHT_CANDIDATES 1  // light samples resampled at a candidate vertex (render/restir.cpp)
#endif
// Reservoirs per pixel and set: 1, or 2 where an emitting medium's paths that end in its emission
// have a reservoir of their own (class 0, in set s) beside the paths that end at a light or hit an
// emitter (class 1, in set s + RS_SETS): render.restir_emission_reservoir, render/restir.cpp. The
// two classes split the path space, so their estimates add; a pixel's one selected path no longer
// carries the colour of whichever end won (the fire's orange emission against the sky's blue).
#ifndef PLUME_RS_CLASSES
#define PLUME_RS_CLASSES 1
#endif

// A domain of the integral: one pixel of one frame (its camera and that frame's volume). The
// pixel's box filter is part of the path: a path starts with its position (u, v) in [0, 1]² inside
// the pixel, and the shift copies it, so a still camera's history is the same domain (identity
// shift, equal targets) and neighbours use the same sub-pixel offset.
struct RsDomain {
  vec3 origin;
  vec3 corner;  // un-normalised direction through the pixel's corner (u, v) = (0, 0)
  vec3 du;      // its change per unit of u (one pixel to the right)
  vec3 dv;      // and per unit of v (one pixel down)
  uint v;       // VOL_CURRENT or VOL_PREVIOUS
  vec3 k;       // the target's colour weights: p̂ = dot(k, f) (restir/colour.glsl)
};

uint rs_colour_slot(uint set, uint pixelIndex);

RsDomain rs_camera_domain(uvec2 pixel, GpuCamera cam, uint v, uint colourSet) {
  RsDomain D;
  D.k = rs_state(rs_colour_slot(colourSet, pixel.y * frame.size.x + pixel.x)).xyz;
  D.origin = cam.position;
  D.corner = cam_direction(vec2(pixel), frame.size, cam);
  D.du = (2.0f / float(frame.size.x)) * cam.tanHalfFovY * cam.aspect * cam.right;
  D.dv = (-2.0f / float(frame.size.y)) * cam.tanHalfFovY * cam.up;
  D.v = v;
  return D;
}

// The camera ray through the point (u, v) of the domain's pixel.
vec3 rs_domain_dir(RsDomain D, vec2 uv) { return normalize(D.corner + uv.x * D.du + uv.y * D.dv); }

RsDomain rs_current_domain(uvec2 pixel) { return rs_camera_domain(pixel, frame.camera, VOL_CURRENT, rsp.colourSet); }
RsDomain rs_previous_domain(uvec2 pixel) {
  return rs_camera_domain(pixel, rsp.prevCamera, VOL_PREVIOUS, rsp.colourHistorySet);
}

// A path's sub-pixel position, stored in RsPathHead.uv as two 16-bit fixed-point numbers;
// candidates quantise their draw first, so every domain sees exactly the stored value.
uint rs_pack_uv(vec2 uv) { return packUnorm2x16(uv); }
vec2 rs_unpack_uv(uint packed) { return unpackUnorm2x16(packed); }

float rs_luminance(vec3 c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

// The target's scalar of an RGB contribution c in a domain whose colour weights are k.
float rs_weigh(vec3 k, vec3 c) { return dot(k, c); }

// --- Light samples -------------------------------------------------------------------------------
// A path ends in a light sample (light index, two floats): a direction sample is stored as
// rs_encode_dir of it, and every domain reconnects to the decoded direction (or, for a point
// light or a delta sun, to the light itself).

// Draws a light sample at vertex vx: the light chosen with the probabilities the host stored
// (lightChoice; render/restir.cpp), then light_sample_dir (at a surface vertex a constant
// environment's direction by the BSDF's own sampling, as the path tracer's NEE). With emissive
// surfaces the choice's entry GpuFrame.lightCount is "a point on the emitters": a triangle from
// the light tree at vx and a uniform point in it (prim, barycentrics in ls; four more draws from
// rng, at every call). Returns the sample's pdf (the light's, at the stored direction, or per unit
// area on the emitters, times the choice probability) or 0.
float rs_sample_light(PathVertex vx, vec3 u, inout RngState rng, out uint light, out vec2 ls, out uint prim) {
  uint n = rsp.lightCount;
  light = 0u;
  prim = 0u;
  while (light + 1u < n && u.x >= lightChoice[light].cdf) ++light;
  float pdf = lightChoice[light].probability;
  ls = vec2(0.0f);
#ifdef PLUME_HAS_EMITTERS
  uvec4 e = rng_next4(rng);
  if (light == frame.lightCount) {
    return pdf * surf_sample_emitter_at(vx.x, vtx_receiver(vx), vec3(rng_to_float(e.x), rng_to_float(e.y), rng_to_float(e.z)), prim, ls);
  }
  GpuLight l = light_at(min(light, max(frame.lightCount, 1u) - 1u));  // (in range on every lane)
#else
  GpuLight l = light_at(light);
#endif
  if (!light_samples_direction(l)) return pdf;
#ifdef PLUME_HAS_SURFACES
  if (vx.kind == VERTEX_SURFACE && l.type == LIGHT_ENVIRONMENT) {
    vec3 w;
    float pdfDir;
    vtx_at_sample(vx, u.yz, w, pdfDir);
    if (!(pdfDir > 0.0f)) return 0.0f;
    ls = rs_encode_dir(w);
    return pdf * vtx_at_pdf(vx, rs_decode_dir(ls));
  }
#endif
  ls = rs_encode_dir(light_sample_dir(l, vec3(0.0f), vx.rayDir, frame.g, u.yz));
  return pdf * light_pdf(l, rs_decode_dir(ls), vx.rayDir, frame.g);
}

#if defined(PLUME_HAS_EMISSION) || defined(PLUME_HAS_EMITTERS)
// A path may end in emission (the medium's, or an emissive surface hit by a sampled direction).
#define RS_ENDS_IN_EMISSION 1
// The most vertices of a path a reservoir holds that ends in emission: one more than the light
// paths' min(max_bounces, K) (its last vertex only emits), at most RS_MAX_VERTICES. Longer
// emitting paths are the tail's (restir/shade.glsl); one-vertex ones final shading's.
uint rs_emission_vertices() {
  return min(min(frame.maxBounces + 1u, rsp.prefixVertices + 1u), RS_MAX_VERTICES);
}
#endif

#ifdef PLUME_HAS_EMITTERS
// The power heuristic (Veach's thesis, eq. 9.15) between the emitters' light samples and the
// vertices' own direction sampling, which both reach a point on an emitter: its solid-angle
// density as a light sample (the choice's entry, the triangle's area density, d² / cos at the
// light, d from the ray's origin) against the direction's density pdfDir at the vertex. A path
// that reaches an emitter is split into the two, f = w_light f + w_dir f, and each part is an
// integrand of its own in the reservoirs (its weight evaluated in the domain that evaluates f).
float rs_emitter_weight(float pdfThis, float pdfOther) {
  return pdfThis > 0.0f ? pdfThis * pdfThis / (pdfThis * pdfThis + pdfOther * pdfOther) : 0.0f;
}

// The light samples' solid-angle density at the ray origin o (the vertex, pushed off a surface
// towards the light: the point both ways of reaching the emitter agree on) with the vertex's
// receiver normal n (vtx_receiver; both ways agree on it too where the emitter lies on the side
// the path arrived from, the only side a surface vertex takes light from).
float rs_emitter_light_pdf(uint prim, vec3 o, vec3 n, float dist, float cosLight) {
  return lightChoice[frame.lightCount].probability * surf_emitter_pdf_at(prim, o, n) * dist * dist / cosLight;
}

// The emission of a hit on triangle prim at distance t along w from the ray origin o of a vertex
// (receiver normal `receiver`) whose direction sampling has density pdfDir there (vtx_at_pdf),
// with its MIS weight: the direction-sampling part of an emitter's light.
vec3 rs_emitter_hit(float pdfDir, uint prim, vec3 o, vec3 receiver, vec3 w, float t) {
  vec3 n = surf_normal(prim);
  vec3 Le = surf_emitted(prim, n, w);
  float pl = rs_emitter_light_pdf(prim, o, receiver, t, abs(dot(n, w)));
  return Le * rs_emitter_weight(pdfDir, pl);
}
#endif

// The connection from the path's last vertex vx to a light sample: where the light ray starts
// (o, pushed off a surface), its direction w and length `reach` (DDA_INF for distant lights; for
// a point on an emissive triangle, short of the triangle itself), and the unshadowed light term
// Le * scatter (for a point on an emissive triangle, per unit area: Le * scatter * cos_light / d²
// with its MIS weight against direction sampling, unless !withMis). False where it is 0 (the back
// of an emitter, a direction outside the sun's disk).
struct RsLightRay {
  vec3 o;
  vec3 w;
  float reach;
  vec3 value;
};

#ifdef PLUME_HAS_EMITTERS
// The MIS weight of a light sample on emissive triangle prim, at distance dist along w from the
// ray origin o of vertex vx, with cosine cosLight there, against the vertex's direction sampling.
float rs_light_sample_mis(PathVertex vx, uint prim, vec3 o, vec3 w, float dist, float cosLight) {
  return rs_emitter_weight(rs_emitter_light_pdf(prim, o, vtx_receiver(vx), dist, cosLight), vtx_at_pdf(vx, w));
}
#endif

bool rs_light_connect(PathVertex vx, uint light, vec2 ls, uint prim, bool withMis, out RsLightRay c) {
#ifdef PLUME_HAS_EMITTERS
  if (light == frame.lightCount) {
    vec3 p = surf_triangle_point(prim, ls);
    c.o = vtx_at_origin(vx, p - vx.x);
    vec3 toL = p - c.o;
    float dist = length(toL);
    c.w = toL / dist;
    float cosLight = -dot(surf_normal(prim), c.w);  // the back side emits nothing
    c.reach = dist - surf_offset_length(p);  // stop short of the emitter's own triangle
    c.value = vec3(0.0f);
    if (!(dist > 0.0f) || !(cosLight > 0.0f)) return false;
    vec3 scatter = vtx_at_scatter(vx, c.w);
    float mis = withMis ? rs_light_sample_mis(vx, prim, c.o, c.w, dist, cosLight) : 1.0f;
    c.value = surf_emission(prim) * scatter * (mis * cosLight / (dist * dist));
    return true;
  }
  GpuLight l = light_at(min(light, max(frame.lightCount, 1u) - 1u));
#else
  GpuLight l = light_at(light);
#endif
  vec3 Le;
  c.value = vec3(0.0f);
  c.o = vx.x;
  if (!light_connect(l, vx.x, rs_decode_dir(ls), c.w, c.reach, Le)) return false;
#ifdef PLUME_HAS_SURFACES
  c.o = vtx_at_origin(vx, c.w);
  c.value = Le * vtx_at_scatter(vx, c.w);
#else
  c.value = Le * vtx_scatter(VERTEX_MEDIUM, c.w, vx.rayDir);
#endif
  return true;
}

// The MIS weight of connection c (rs_light_connect) from vx to light sample (light, ls, prim)
// against the vertex's direction sampling (rs_emitter_weight; 1 for lights that direction sampling
// cannot reach).
float rs_light_mis(PathVertex vx, uint light, vec2 ls, uint prim, RsLightRay c) {
#ifdef PLUME_HAS_EMITTERS
  if (light == frame.lightCount) {
    float dist = length(surf_triangle_point(prim, ls) - c.o);
    return rs_light_sample_mis(vx, prim, c.o, c.w, dist, -dot(surf_normal(prim), c.w));
  }
#endif
  return 1.0f;
}

// The light ray from vx to a light sample (rs_light_connect, with its MIS weight if withMis), and
// with surfaces its visibility; false where the light term is 0.
bool rs_light_ray(PathVertex vx, uint light, vec2 ls, uint prim, bool withMis, out RsLightRay c) {
  if (!rs_light_connect(vx, light, ls, prim, withMis, c)) return false;
#ifdef PLUME_HAS_SURFACES
  if (surf_occluded(c.o, c.w, c.reach)) return false;
#endif
  return true;
}

// The target's transmittance along a light ray: the mean field's depth by the midpoint rule
// (vol_mean_tau_midpoints: far cheaper than the voxel walk of the path's own segments).
float rs_target_light_tr(uint v, RsLightRay c) {
  return exp(-min(vol_mean_tau_midpoints(v, c.o, c.w, c.reach), VOL_MAX_TAU));
}

// The light term at the path's last vertex vx: the connection's unshadowed term times the
// transmittance along the light ray (and, with surfaces, its visibility): the target's
// (rs_target_light_tr, without the emitters' MIS weight, as rs_path_contribution's target) or an
// unbiased one (residual ratio tracking on the fine grid of the current volume against the mean
// field, v = 0, with the MIS weight: the tail's light rays).
vec3 rs_light_term(uint v, PathVertex vx, uint light, vec2 ls, uint prim, bool unbiased, inout RngState rng) {
  RsLightRay c;
  if (!rs_light_ray(vx, light, ls, prim, unbiased, c)) return vec3(0.0f);
  float tr = unbiased ? vol_residual_tr(c.o, c.w, c.reach, rng) : rs_target_light_tr(v, c);
  return c.value * tr;
}

// A candidate vertex's light sample by resampled importance sampling (Talbot et al. 2005; the
// light-sample step of ReSTIR DI, Bitterli et al. 2020): PLUME_RS_LIGHT_CANDIDATES samples from
// rs_sample_light, one chosen in proportion to p̂_u / p_light with the unshadowed target
// p̂_u = lum(f * connection term) (f: the path's throughput up to vx; without the emitters' MIS
// weight, which costs a second descent of the light tree), which is positive wherever the
// shadowed term is, so the chosen sample's contribution weight
//   W = (1 / p̂_u(chosen)) * (1 / L) * sum_k p̂_u(l_k) / p_light(l_k)
// is unbiased for 1 / (its density) (RIS; GRIS accepts it as a candidate's weight). Among
// thousands of small emitters the unshadowed term's cosines and 1/d² find the lamps that face the
// vertex; the host compiles L > 1 with emissive surfaces only (render/restir.cpp says why).
// Returns W (0: no sample with a nonzero term) and the survivor's connection `chosenRay` (its
// value without the emitters' MIS weight), which the candidates' own resampling reads
// (candidates.glsl: one shadow ray per vertex, the survivor's).
float rs_resample_light(PathVertex vx, vec3 f, vec3 colour, inout RngState rng, out uint light, out vec2 ls, out uint prim,
                        out RsLightRay chosenRay) {
  float wSum = 0.0f;
  float chosen = 0.0f;
  light = 0u;
  ls = vec2(0.0f);
  prim = 0u;
  chosenRay = RsLightRay(vx.x, vec3(0.0f, 0.0f, 1.0f), 0.0f, vec3(0.0f));
  for (uint k = 0u; k < uint(PLUME_RS_LIGHT_CANDIDATES); ++k) {
    uvec4 h = rng_next4(rng);
    uint lk;
    vec2 lsk;
    uint pk;
    float pl = rs_sample_light(vx, vec3(rng_to_float(h.x), rng_to_float(h.y), rng_to_float(h.z)), rng, lk, lsk, pk);
    RsLightRay c;
    float ph = pl > 0.0f && rs_light_connect(vx, lk, lsk, pk, false, c) ? rs_weigh(colour, f * c.value) : 0.0f;
    float w = pl > 0.0f ? ph / pl : 0.0f;
    if (!(w > 0.0f) || isinf(w)) continue;
    wSum += w;
    if (rng_to_float(h.w) * wSum < w) {
      light = lk;
      ls = lsk;
      prim = pk;
      chosen = ph;
      chosenRay = c;
    }
  }
  return chosen > 0.0f ? wSum / (float(PLUME_RS_LIGHT_CANDIDATES) * chosen) : 0.0f;
}

// --- Path storage --------------------------------------------------------------------------------
uint rs_slot(uint set, uint pixelIndex) { return set * rsp.pixelCount + pixelIndex; }
uint rs_bounce_base(uint set, uint pixelIndex) { return rs_slot(set, pixelIndex) * rsp.bounceStride; }

// RsPacked from its four words as stored (restir/bindings.glsl rsReservoirTexels), and back.
RsPacked rs_packed(uvec4 words) {
  return RsPacked(uintBitsToFloat(words.x), uintBitsToFloat(words.y), uintBitsToFloat(words.z), words.w);
}
uvec4 rs_words(RsPacked p) { return uvec4(floatBitsToUint(vec3(p.w_sum, p.p_hat, p.W)), p.M_fixed); }

RsReservoir rs_load(uint set, uint pixelIndex) {
  bool dropped;
  RsReservoir r = rs_unpack(rs_packed(imageLoad(rsReservoirTexels, int(rs_slot(set, pixelIndex)))), dropped);
  if (dropped) atomicAdd(rsCounters[0], 1u);
  return r;
}

void rs_store(uint set, uint pixelIndex, RsReservoir r) {
  imageStore(rsReservoirTexels, int(rs_slot(set, pixelIndex)), rs_words(rs_pack(r)));
}

RsPathHead rs_load_head(uint set, uint pixelIndex) {
  uint i = 2u * rs_slot(set, pixelIndex);
  uvec4 a = rs_path_word(i);
  uvec4 b = rs_path_word(i + 1u);
  RsPathHead h;
  h.lightSample = uintBitsToFloat(a.xy);
  h.t1 = uintBitsToFloat(a.z);
  h.vertexCount = a.w;
  h.light = b.x;
  h.kinds = b.y;
  h.uv = b.z;
  h.lightPrim = b.w;
  return h;
}

void rs_store_head(uint set, uint pixelIndex, RsPathHead h) {
  uint i = 2u * rs_slot(set, pixelIndex);
  rs_set_path_word(i, uvec4(floatBitsToUint(h.lightSample), floatBitsToUint(h.t1), h.vertexCount));
  rs_set_path_word(i + 1u, uvec4(h.light, h.kinds, h.uv, h.lightPrim));
}

// A pixel's state between the dispatches of one pass (RS_STATE_SLOTS texels past the path heads,
// rs_state / rs_set_state): the candidates' running reservoir (restir/candidates.glsl), then final
// shading's tail (restir/shade.glsl).
const uint RS_ALL_SETS = RS_SETS * uint(PLUME_RS_CLASSES);  // the sets of every class
uint rs_state_slot(uint pixelIndex) { return 2u * RS_ALL_SETS * rsp.pixelCount + RS_STATE_SLOTS * pixelIndex; }
// A pixel's colour weights of set `set` (RestirParams::colourSet), past the state.
uint rs_colour_slot(uint set, uint pixelIndex) {
  return (2u * RS_ALL_SETS + RS_STATE_SLOTS + set) * rsp.pixelCount + pixelIndex;
}
// A pixel's lamp reservoir of set `set` (RestirParams::lampSet), past the colour weights.
uint rs_lamp_slot(uint set, uint pixelIndex) {
  return (2u * RS_ALL_SETS + RS_STATE_SLOTS + RS_COLOUR_SLOTS + set) * rsp.pixelCount + pixelIndex;
}

// Vertex count of the stored path (0: none), and marking a slot empty.
uint rs_path_length(uint set, uint pixelIndex) { return rs_path_word(2u * rs_slot(set, pixelIndex)).w; }
void rs_clear_path(uint set, uint pixelIndex) {
  uint i = 2u * rs_slot(set, pixelIndex);
  uvec4 a = rs_path_word(i);
  rs_set_path_word(i, uvec4(a.xyz, 0u));
}

void rs_copy_path(uint srcSet, uint srcPixel, uint dstSet, uint dstPixel) {
  uint s = 2u * rs_slot(srcSet, srcPixel);
  uint d = 2u * rs_slot(dstSet, dstPixel);
  uvec4 head = rs_path_word(s);
  rs_set_path_word(d, head);
  rs_set_path_word(d + 1u, rs_path_word(s + 1u));
  uint a = rs_bounce_base(srcSet, srcPixel);
  uint b = rs_bounce_base(dstSet, dstPixel);
  for (uint i = 1u; i < head.w; ++i) rs_set_bounce(b + i - 1u, rs_bounce(a + i - 1u));
}

// --- The reconnection shift ----------------------------------------------------------------------
// The vertex the reconnection shift stores by its place (shared/restir_types.h): the first surface
// vertex from the second on (kinds: RsPathHead.kinds, bit i - 1 for vertex i), 0 for none or
// with the copy shift. A function of the stored path alone, so every domain agrees on it.
uint rs_reconnect_vertex(uint kinds) {
#ifdef PLUME_RS_RECONNECT
  uint later = kinds & ~1u;
  return later != 0u ? uint(findLSB(later)) + 1u : 0u;
#else
  return 0u;
#endif
}

#ifdef PLUME_RS_RECONNECT
// The solid angle to area factor of the reconnection vertex x_r on triangle prim, reached along
// the unit direction w from a ray origin at distance d: |cos_r| / d².
float rs_reconnect_area_factor(uint prim, vec3 w, float d) { return abs(dot(surf_normal(prim), w)) / (d * d); }
#endif

// --- The path contribution f_D(y) ----------------------------------------------------------------
// y is the path stored at (set, pixel); D any domain. Vertices x_1 = o + t1 d(u, v), x_i = o_{i-1} +
// t_i w_i (o_i: x_i, pushed off a surface towards w_{i+1}); f = prod_i [T(o_{i-1}, x_i) v(x_i)] *
// prod_{i>=2} scatter(x_{i-1}, w_i) * light term, RGB, with v = sigma_s at a medium vertex and 1 at
// a surface vertex, whose place is the first surface hit along w_i (t_i is implied) and whose
// scatter is BSDF x cos (integrator/vertex.glsl); the shift's Jacobian is 1 at either kind. The
// shift fails (f = 0) where the copied path cannot exist in D: a medium vertex with zero density
// (or outside the volume) or behind a surface, a surface vertex whose ray meets no surface. A
// path ending in emission has sigma_a(x_n) Le(x_n) in place of sigma_s(x_n) and the light term.
// With the reconnection shift vertex r = rs_reconnect_vertex is the stored point x_r instead:
// o_{r-1} is connected to it (f = 0 where a surface lies between) and f carries its area factor.
//
// shading false: the target's f (every transmittance the mean field's), and est the product of
// the path's segment transmittances in it (not the light ray's: rs_target_parts). shading true
// (final shading, D the current frame's domain): f without the path's segment transmittances,
// and est an unbiased estimate of the ratio of the fine transmittances to the target's, so that
// f * (product of the segments' exp(-tau_c)) * est is unbiased for the path's contribution. The
// product is the target's own factor: p̂ / lum(f) (restir/shade.glsl), so no segment walks the
// mean field here; each takes vol_residual_ratio, and the light ray residual ratio tracking
// over the target's midpoint-rule transmittance.
// A light sample on an emissive triangle: the returned f leaves out its MIS weight against the
// vertex's direction sampling (rs_light_mis), which the path's integrand carries (the part of the
// emitter's light that light samples stand for). The target need not equal the integrand, only be
// positive wherever it is, and without the weight no target evaluation (reuse evaluates several a
// pixel) descends the light tree for its density: final shading multiplies it back in, `mis`
// (1 otherwise). On the city its time per frame -5 to -9% still, -2 to -6% moving, at the same
// error (notes/city.md "Session 37").
vec3 rs_path_contribution(RsDomain D, uint set, uint pixelIndex, bool shading, inout RngState rng, out float est,
                          out float mis) {
  est = 1.0f;
  mis = 1.0f;
  RsPathHead h = rs_load_head(set, pixelIndex);
  uint n = h.vertexCount;
  if (n == 0u) return vec3(0.0f);
  uint base = rs_bounce_base(set, pixelIndex);
  vec3 x = D.origin;
  vec3 w = rs_domain_dir(D, rs_unpack_uv(h.uv));
  float t = h.t1;
  vec3 f = vec3(1.0f);
  PathVertex vx = vtx_medium(x, w);
  PathVertex prev = vx;  // the vertex before vx (what sampled w)
  // A path ending in emission: its last vertex absorbs (sigma_a Le = sigma_t (1 - albedo) Le)
  // instead of scattering towards a light.
  bool emits = false;
#ifdef PLUME_HAS_EMISSION
  emits = h.light == RS_LIGHT_EMISSION;
#endif
  uint reconnect = rs_reconnect_vertex(h.kinds);
  for (uint i = 1u; i <= n; ++i) {
    // Vertex i = reconnect shares the others' one closest-hit traversal (lavapipe runs both sides
    // of a divergent branch): towards the stored point, up to just short of it, where any hit
    // is an occluder.
    bool rc = i == reconnect;
#ifdef PLUME_HAS_SURFACES
    float tHitMax = SURF_FAR;
#endif
    vec4 b = vec4(0.0f);
    if (i >= 2u) {
      b = rs_bounce(base + i - 2u);
      vec3 dir = b.xyz;
#ifdef PLUME_RS_RECONNECT
      vec3 p = vec3(0.0f);
      if (rc) {
        p = surf_triangle_point(floatBitsToUint(b.z), b.xy);
        dir = normalize(p - vtx_at_origin(vx, p - vx.x));
      }
#endif
#ifdef PLUME_HAS_SURFACES
      f *= vtx_at_scatter(vx, dir);
      x = vtx_at_origin(vx, dir);
      prev = vx;
#else
      f *= vtx_scatter(VERTEX_MEDIUM, w, dir);
#endif
      w = dir;
      t = b.w;
#ifdef PLUME_RS_RECONNECT
      if (rc) {
        t = length(p - x);
        if (!(t > 0.0f)) return vec3(0.0f);
        w = (p - x) / t;
        tHitMax = t - surf_offset_length(p);
      }
#endif
    }
    uint kind = vtx_kind(h.kinds, i);
#ifdef PLUME_HAS_SURFACES
    BvhHit hit = bvh_closest(x, w, 0.0f, tHitMax);
#ifdef PLUME_RS_RECONNECT
    if (rc) {
      if (hit.prim != BVH_NONE) return vec3(0.0f);  // occluded
      hit = BvhHit(t, floatBitsToUint(b.z), b.x, b.y);
    }
#endif
    if (kind == VERTEX_SURFACE) {
      if (hit.prim == BVH_NONE) return vec3(0.0f);
      t = hit.t;
    } else if (hit.prim != BVH_NONE && !(t < hit.t)) {
      return vec3(0.0f);
    }
#endif
    float tr = 1.0f;
    if (shading) {
      est *= vol_residual_ratio(x, w, t, rng);
    } else {
      tr = vol_mean_tr(D.v, x, w, t);
      est *= tr;
    }
#ifdef PLUME_RS_RECONNECT
    if (rc) tr *= rs_reconnect_area_factor(hit.prim, w, t);
#endif
    vec3 o = x;
    x += t * w;
#ifdef PLUME_HAS_SURFACES
    if (kind == VERTEX_SURFACE) {
#ifdef PLUME_HAS_EMITTERS
      if (h.light == RS_LIGHT_EMITTER_HIT && i == n) {
        return f * tr * rs_emitter_hit(vtx_at_pdf(prev, w), hit.prim, o, vtx_receiver(prev), w, t);  // i >= 2
      }
#endif
      vec3 ng = surf_normal(hit.prim);
      vx = vtx_surface(x, w, hit.prim, surf_shading_normal(hit.prim, vec2(hit.u, hit.v), ng));
      f *= tr;
      continue;
    }
    vx = vtx_medium(x, w);
#endif
    float sigma = vol_sigma_t_world(D.v, x);
    if (!(sigma > 0.0f)) return vec3(0.0f);
    vec3 a = vtx_albedo(kind);
    if (emits && i == n) a = vec3(1.0f) - a;
    f *= tr * sigma * a * vtx_shift_jacobian(kind);
  }
#ifdef PLUME_HAS_EMISSION
  if (emits) return f * vol_emitted_radiance_world(D.v, x);
#endif
#ifndef PLUME_HAS_SURFACES
  vx = vtx_medium(x, w);
#endif
  RsLightRay c;
  if (!rs_light_ray(vx, h.light, h.lightSample, h.lightPrim, false, c)) return vec3(0.0f);
  float trTarget = rs_target_light_tr(D.v, c);
  if (shading) {
    est *= vol_residual_tr(c.o, c.w, c.reach, rng) / trTarget;
    mis = rs_light_mis(vx, h.light, h.lightSample, h.lightPrim, c);
  }
  return f * c.value * trTarget;
}

// The target function p̂_D(y): deterministic (no random numbers are drawn on this path); and the
// product of the path's segment transmittances in it, segments (the factor of p̂ that the
// candidates' weights leave out: candidates.glsl).
float rs_target_parts(RsDomain D, uint set, uint pixelIndex, out float segments) {
  RngState unused = RngState(uvec4(0u), 0u);  // never drawn from: no hash to pay for
  float mis;
  return rs_weigh(D.k, rs_path_contribution(D, set, pixelIndex, false, unused, segments, mis));
}

float rs_target(RsDomain D, uint set, uint pixelIndex) {
  float segments;
  return rs_target_parts(D, set, pixelIndex, segments);
}

#endif

// Candidate paths (DESIGN §4.2 step 1). M random walks per pixel, each from its own uniform
// position (u, v) in the pixel: each vertex's distance comes from delta tracking in the mean
// field against the brick majorants (pdf sigma_c exp(-tau_c); volume/walk.glsl vol_mean_sample),
// each further direction from the vertex's scattering (HG), and every vertex ends one candidate
// with a light sample: a light chosen in proportion to its estimated power (render/restir.cpp
// lightChoice), or, with PLUME_RS_LIGHT_CANDIDATES = L > 1 (render.restir_light_candidates), the
// survivor of L such samples resampled by their unshadowed term (bridge.glsl rs_resample_light),
// whose RIS weight W_light stands for 1 / p_light below (the survivor then takes a shadow ray).
// The candidate ending at vertex j of walk m with light l is the path
// (u, v, t1, w2, t2, ..., w_j, t_j, l, light sample) with source pdf
//   p(y) = prod_i sigma_c(x_i) exp(-tau_i) * prod_{i>=2} phase_i * prod q (Russian roulette)
//          * p_light,
// and only "vertex j of some walk, light l" can produce it, so the M walks give it the MIS
// weight 1/M (GRIS allows candidates of one walk to be dependent: only marginals matter). The
// target's transmittance of each segment, exp(-tau_c) of the same mean field (restir/bridge.glsl
// rs_path_contribution), is the source pdf's too, so the walks carry neither and a candidate's
// weight p̂ / p needs no optical depth (the target clamps tau_c at VOL_MAX_TAU = 80, where the two
// part: a path beyond it is sampled with probability below e^-80); the reservoir's p̂ of the
// selected path, which reuse needs, is the target evaluated once on the stored path (rs_target).
// With an emitting medium (PLUME_HAS_EMISSION) every vertex from the second on also ends a candidate with
// its own emission (sigma_a Le at x_j, pdf without a light factor; light = RS_LIGHT_EMISSION), up
// to vertex max_bounces + 1: both ends go through the one reservoir, so reuse shares good
// emitters too. Emission seen directly (a one-vertex path) is final shading's, by tracking along
// the camera ray (restir/shade.glsl): every path is counted once. With emissive surfaces every
// surface vertex from the second on ends a candidate with the emitter it is (its
// direction-sampling part, MIS'd against the light samples), and the emitters seen directly go
// into a reservoir of their own (rs_lamp_reservoir), reused over time.
// The reservoir's confidence is M. A dispatch walks rsp.walksPerDispatch of the M walks
// (lavapipe's loop budget, docs/architecture.md: an invocation walks at most
// RS_CANDIDATE_VERTICES vertices, or one walk of K, whatever M): the walks stream their
// candidates into the pixel's running reservoir, kept between dispatches (w_sum and the
// candidates' random stream in the pixel's state slot, the selected path in the output set), and
// the dispatch of the last walk finalises it: the same draws in the same order as M walks in one
// invocation. Requires restir/bridge.glsl.
#ifndef PLUME_RESTIR_CANDIDATES_GLSL
#define PLUME_RESTIR_CANDIDATES_GLSL

#if defined(PLUME_RS_OUTSIDE) && defined(PLUME_HAS_SURFACES)
#error "PLUME_RS_OUTSIDE: a camera ray may meet a surface anywhere"
#endif
#if PLUME_RS_LIGHT_CANDIDATES > 1 && !defined(PLUME_HAS_SURFACES)
#error "light resampling (L > 1) is compiled with emissive surfaces only: the walk gathers its segments' transmittance there"
#endif

// The head of the path a candidate ending at vertex j of a walk stands for (vertices 2..j are the
// walk's, copied when the walk ends).
RsPathHead rs_candidate_head(uint uv, float t1, uint j, uint kinds, uint light, vec2 ls, uint prim) {
  RsPathHead h;
  h.lightSample = ls;
  h.t1 = t1;
  h.vertexCount = j;
  h.light = light;
  h.kinds = kinds;
  h.uv = uv;
  h.lightPrim = prim;
  return h;
}

#ifdef PLUME_HAS_EMITTERS
// Lamps seen directly: the paths of one vertex on an emitter's front (a camera ray's hit, weight
// 1: no light sample reaches the camera) have a reservoir of their own per pixel, not the light
// paths' (whose walks' camera-ray hits end no candidate): a lamp pixel's light-path reservoir
// then still stands for the light its neighbours reuse, and the lamp's own reservoir is reused
// by the one pixel that sees it, over time (notes/city.md "Session 16"). Its sample is a
// sub-pixel position (u, v); its target p̂_v(u, v) = Le x the mean field's transmittance of
// volume v along the ray to the first surface (0 where that is no emitter's front). Final
// shading adds W Le T along the sample's ray (restir/shade.glsl).
const uint RS_DIRECT_SIDE = 4u;
const uint RS_DIRECT_RAYS = RS_DIRECT_SIDE * RS_DIRECT_SIDE;

// Candidate i's sub-pixel position: a uniform point u of cell i of the RS_DIRECT_SIDE² grid.
vec2 rs_direct_uv(uint i, vec2 u) {
  vec2 cell = vec2(float(i % RS_DIRECT_SIDE), float(i / RS_DIRECT_SIDE));
  return min((cell + u) * (1.0f / float(RS_DIRECT_SIDE)), vec2(1.0f));
}

// Le's luminance at the first surface along the ray of sub-pixel position uv (0 where that is no
// emitter's front), the ray's direction and the hit's distance.
float rs_lamp_emitted(RsDomain D, uint uv, out vec3 dir, out float t) {
  dir = rs_domain_dir(D, rs_unpack_uv(uv));
  BvhHit hit = bvh_closest(D.origin, dir, 0.0f, SURF_FAR);
  t = hit.t;
  return hit.prim == BVH_NONE ? 0.0f : rs_luminance(surf_emitted(hit.prim, surf_normal(hit.prim), dir));
}

float rs_lamp_target(RsDomain D, uint v, uint uv) {
  vec3 dir;
  float t;
  float ph = rs_lamp_emitted(D, uv, dir, t);
  return ph > 0.0f ? ph * vol_mean_tr(v, D.origin, dir, t) : 0.0f;
}

// The frame's lamp reservoir of the pixel (set rsp.lampSet): RS_DIRECT_RAYS candidates, confidence
// 1 in all, resampled by Le alone, p̂'(u, v), so that W = w_sum / p̂'(Y) is an unbiased contribution
// weight of the selected Y (GRIS: any target of the candidates' own resampling gives one); the
// reservoir's p̂ is the target with the smoke's transmittance, evaluated once for Y, and the merge
// below and final shading use that W with it. One mean-field walk a pixel instead of one per ray
// that meets a lamp, masked per ray on a SIMD back end; the rays of one pixel see a lamp through
// nearly the same smoke, so Le alone selects about as well (notes/city.md "Session 29"). The
// candidates are drawn one of two ways:
// - on the emitter triangles the pixel may see (PLUME_RS_LAMP_TRIANGLES, the default:
//   rs_lamp_triangle_candidates), where no ray is spent on the part of the pixel they leave out
//   and the lamp's coverage of the pixel is computed, not sampled;
// - or ray i uniform on cell i of a RS_DIRECT_SIDE² grid of the rectangle [lo, hi] of the pixel
//   outside which no camera ray meets an emitter's front (rs_lamp_rect; p̂ is 0 outside it),
//   density RS_DIRECT_RAYS / A there (A its area; MIS weights "1 if (u, v) lies in cell i", a
//   partition of the rectangle): a lamp a tenth of a pixel across gets all the rays, not one in six.
// With a still camera the previous frame's reservoir at the same pixel (its confidence capped at c)
// is merged in with the generalised balance heuristic between the two domains, m_s(y) = M_s p̂_s(y) /
// Σ_j M_j p̂_j(y), p̂_s the target with the volume input s was rendered with (the shift is the
// identity: the same (u, v) in the same camera); with a still grid both targets are one function
// and m_s = M_s / ΣM. The canonical input covers every (u, v) a lamp is seen through, so the
// merge is unbiased.
// It runs in a pass of its own (passes/restir_lamps.comp) over the pixels whose camera rays may
// meet an emitter's front (rs_lamp_pixel: conservative), dense; the others' reservoirs are empty
// (every candidate's weight would be 0) and the candidates pass writes them (rs_lamp_skipped).
// Both draw from the start of the pixel's candidates stream, RS_LAMP_DRAWS numbers, and the
// walks go on from there.
const uint RS_LAMP_DRAWS = 4u * RS_DIRECT_RAYS;  // 4 per candidate (2 per ray in a rectangle); 2 more to merge

uint rs_lamp_draws() { return RS_LAMP_DRAWS + (rsp.lampHistory != 0u ? 2u : 0u); }

// The canonical candidates in the rectangle [lo, hi] of the pixel (2 draws a ray).
RsReservoir rs_lamp_rect_candidates(RsDomain D, vec2 lo, vec2 hi, inout RngState rng, out uint uv, out vec3 dirY,
                                    out float tY) {
  RsReservoir r = rs_empty();
  uv = 0u;
  dirY = vec3(0.0f);  // the selected ray's direction and hit distance
  tY = 0.0f;
  vec2 extent = hi - lo;
  float cellWeight = extent.x * extent.y * (1.0f / float(RS_DIRECT_RAYS));  // 1 / the density on the cell
  for (uint i = 0u; i < RS_DIRECT_RAYS; ++i) {
    uint c = rs_pack_uv(lo + extent * rs_direct_uv(i, rng_float2(rng)));
    vec3 dir;
    float t;
    float ph = rs_lamp_emitted(D, c, dir, t);
    if (rs_update(r, ph * cellWeight, ph, 0.0f, rng_float(rng))) {
      uv = c;
      dirY = dir;
      tY = t;
    }
  }
  return r;
}

#ifdef PLUME_RS_LAMP_TRIANGLES
const uint RS_LAMP_RAYS = 8u;  // candidates on the pieces (at most RS_DIRECT_RAYS: RS_LAMP_DRAWS)

// Le's luminance at the first surface along the ray of sub-pixel position uv where that is the
// front of triangle `prim` (0 elsewhere), the ray's direction and the hit's distance.
float rs_lamp_emitted_by(RsDomain D, uint uv, uint prim, out vec3 dir, out float t) {
  dir = rs_domain_dir(D, rs_unpack_uv(uv));
  BvhHit hit = bvh_closest(D.origin, dir, 0.0f, SURF_FAR);
  t = hit.t;
  return hit.prim == prim ? rs_luminance(surf_emitted(hit.prim, surf_normal(hit.prim), dir)) : 0.0f;
}

// The canonical candidates on the emitter triangles the pixel may see, 4 draws a candidate. The
// host cut the pixel into pieces (render/pixel_order.h emitterPixelTriangles): for each emitter
// triangle whose front a camera ray of the pixel may meet, the part of the pixel its projection
// covers, grown by a margin far above rounding, as a fan of triangles. The samples are pairs
// (j, x): piece j and a point x on it, with target p̂'(j, x) = Le where x's ray first meets the
// front of j's emitter, 0 elsewhere; since a ray first meets one surface and the pieces of one
// emitter do not overlap, the pairs where p̂' > 0 are the (u, v) where the lamps' target is (each
// with its one piece), so a contribution weight for (j, x) is one for (u, v) = x, in the history's
// merge and in final shading alike. Source: piece j with probability w_j / S (rs_lamp_weight: Le_j
// times the piece's area A_j; S the list's sum), x uniform on it, so p(j, x) = w_j / (S A_j); the
// RS_LAMP_RAYS candidates are stratified over the list's cumulative weights (candidate i's draw
// in [i, i + 1) S / RS_LAMP_RAYS), so their densities sum to RS_LAMP_RAYS p, and with the
// balance heuristic across them each weighs p̂'(j, x) / (RS_LAMP_RAYS p(j, x)) = S /
// RS_LAMP_RAYS where x sees j's emitter (A_j the area of the corners as read), 0 elsewhere.
// Where the lamps are seen unoccluded the estimate is exact but for the smoke's transmittance and
// the margins: the lamps' share of the pixel is the pieces' areas, not a count of rays.
RsReservoir rs_lamp_triangle_candidates(RsDomain D, uint start, uint count, inout RngState rng, out uint uv,
                                        out vec3 dirY, out float tY) {
  RsReservoir r = rs_empty();
  uv = 0u;
  dirY = vec3(0.0f);
  tY = 0.0f;
  float total = 0.0f;
  for (uint j = 0u; j < count; ++j) total += rs_lamp_weight(start, j);
  uint j = 0u;
  float prefix = count > 0u ? rs_lamp_weight(start, 0u) : 0.0f;  // of pieces 0 .. j
  // One candidate an iteration, so that a subgroup's lanes trace their rays together (a loop over
  // the pieces with the rays inside would trace as often as the lanes' pieces differ).
  for (uint i = 0u; i < RS_LAMP_RAYS && count > 0u; ++i) {
    float next = total * ((float(i) + rng_float(rng)) * (1.0f / float(RS_LAMP_RAYS)));
    // Its piece: the first whose prefix passes it (rounding's leftovers: the last piece).
    while (!(next < prefix) && j + 1u < count) prefix += rs_lamp_weight(start, ++j);
    vec2 a, b, c;
    uint prim = rs_lamp_piece(start, j, a, b, c);
    vec2 e1 = b - a, e2 = c - a;
    float area = 0.5f * abs(e1.x * e2.y - e1.y * e2.x);
    vec2 bary = surf_uniform_barycentrics(rng_float2(rng));
    uint x = rs_pack_uv(clamp(a + bary.x * e1 + bary.y * e2, vec2(0.0f), vec2(1.0f)));
    vec3 dir;
    float t;
    float ph = rs_lamp_emitted_by(D, x, prim, dir, t);
    if (rs_update(r, ph * total * area / (rs_lamp_weight(start, j) * float(RS_LAMP_RAYS)), ph, 0.0f, rng_float(rng))) {
      uv = x;
      dirY = dir;
      tY = t;
    }
  }
  return r;
}
#endif

// The lamp reservoir of the pass's pixel from its canonical candidates: p̂, the history's merge,
// stored in set rsp.lampSet.
void rs_lamp_reservoir(RsDomain D, uint pixelIndex, RsReservoir r, uint uv, vec3 dirY, float tY, inout RngState rng) {
  r.M = 1.0f;
  rs_finalize(r);
  // p̂(Y) = Le(Y) T(Y), rs_lamp_target's value, without tracing Y's ray again.
  r.p_hat = r.W > 0.0f ? r.p_hat * vol_mean_tr(VOL_CURRENT, D.origin, dirY, tY) : 0.0f;
  if (rsp.lampHistory != 0u) {
    vec4 stored = rs_state(rs_lamp_slot(1u - rsp.lampSet, pixelIndex));
    RsReservoir h = rs_empty();
    h.W = rs_is_finite(stored.x) && stored.x > 0.0f ? stored.x : 0.0f;
    h.M = min(stored.y, rsp.historyCap);  // c x the canonical confidence 1
    h.p_hat = stored.w;                   // in the history's domain
    uint huv = floatBitsToUint(stored.z);
    bool same = rsp.lampSameVolume != 0u;
    // Each input's sample in the other domain: the canonical's p̂_prev, the history's p̂_cur.
    float prevOfC = r.W > 0.0f ? (same ? r.p_hat : rs_lamp_target(D, VOL_PREVIOUS, uv)) : 0.0f;
    float curOfH = h.W > 0.0f ? (same ? h.p_hat : rs_lamp_target(D, VOL_CURRENT, huv)) : 0.0f;
    float mC = r.W > 0.0f ? r.p_hat / (r.p_hat + h.M * prevOfC) : 0.0f;
    float mH = h.W > 0.0f && h.p_hat > 0.0f ? h.M * h.p_hat / (curOfH + h.M * h.p_hat) : 0.0f;
    RsReservoir o = rs_empty();
    rs_merge(o, r, r.p_hat, 1.0f, mC, rng_float(rng));
    if (rs_merge(o, h, curOfH, 1.0f, mH, rng_float(rng))) uv = huv;
    rs_finalize(o);
    r = o;
  }
  rs_set_state(rs_lamp_slot(rsp.lampSet, pixelIndex), vec4(r.W, r.M, uintBitsToFloat(uv), r.p_hat));
}

// The lamp reservoir of a pixel outside the lamp pass's list: empty (its confidence is read by no
// one: the pixel stays outside the list while the camera is still, the only time a history is merged).
void rs_lamp_skipped(uint pixelIndex) { rs_set_state(rs_lamp_slot(rsp.lampSet, pixelIndex), vec4(0.0f, 1.0f, 0.0f, 0.0f)); }
#endif

// A class's running reservoir at the end of a dispatch that leaves walks to the next one: w_sum,
// the candidates' own target of the selected path and the random stream's position in the
// pixel's state slot (slot + 1: the emission's, PLUME_RS_CLASSES 2), the selected path's head in its set.
void rs_candidates_pause(uint slot, uint set, uint pixelIndex, RsReservoir r, RsPathHead head, uint counter, float segments) {
  rs_set_state(slot, vec4(r.w_sum, r.p_hat, uintBitsToFloat(counter), segments));
  rs_store_head(set, pixelIndex, head);
}

// A class's reservoir after the last walk, into set `set`: confidence M, the target of the
// selected path and its contribution weight.
void rs_candidates_finish(RsDomain D, uint set, uint pixelIndex, RsReservoir r, RsPathHead head, float segments, uint M) {
  r.M = float(M);
  rs_store_head(set, pixelIndex, head);
#if PLUME_RS_LIGHT_CANDIDATES > 1
  // The candidates' own target p̂' of light samples (rs_candidate_walks), so W = w_sum / p̂'(Y), p̂'(Y) the
  // value rs_update kept for Y times the segments' transmittances that every weight left out
  // (GRIS: any target of the candidates' own resampling that is positive wherever p̂ is gives an
  // unbiased contribution weight). p̂' is the target without those transmittances (the light
  // term with its visibility, the emitter hits' and the emission's terms alike), so the
  // reservoir's p̂, the target of Y, is p̂'(Y) times them: gathered while the walk went
  // (`segments`: the same mean-field transmittance of the same rays as rs_path_contribution's),
  // where until session 38 the target was evaluated once more from the stored path, tracing its
  // rays again (the city's still frames -2.4 ms of 13; reuse reads this value as the input's own
  // target, so the two must agree: GpuRestirSurfaces.CandidatesTargetIsTheTargetReuseEvaluates).
  // 0 where Y's light ray is blocked (p̂' is), and then the reservoir holds no path.
  float target = head.vertexCount > 0u && r.w_sum > 0.0f ? r.p_hat * segments : 0.0f;
  r.p_hat *= segments;
  rs_finalize(r);
  r.p_hat = target;
  if (!(target > 0.0f)) r.W = 0.0f;
#else
#ifndef PLUME_RS_OUTSIDE
  // The target of the selected path, with its transmittances (the weights' p̂ left them out).
  r.p_hat = head.vertexCount > 0u && r.w_sum > 0.0f ? rs_target(D, set, pixelIndex) : 0.0f;
#endif
  rs_finalize(r);
#endif
  if (r.W <= 0.0f) rs_clear_path(set, pixelIndex);
  rs_store(set, pixelIndex, r);
}

// The candidates that end in the medium's emission go to a reservoir of their own with two
// classes (bridge.glsl PLUME_RS_CLASSES: rE, headE, ... in set outSet; the others in outSet +
// RS_SETS), else to the one reservoir.
#if PLUME_RS_CLASSES > 1
#define RS_E_R rE
#define RS_E_HEAD headE
#define RS_E_KEEP keepE
#define RS_E_SEGMENTS segmentsKeepE
#else
#define RS_E_R r
#define RS_E_HEAD head
#define RS_E_KEEP keep
#define RS_E_SEGMENTS segmentsKeep
#endif

// Walks first .. first + rsp.walksPerDispatch - 1 (at most M - 1) of the pixel's M; the first
// dispatch also writes the pixel's lamp reservoir where the lamp pass does not (rs_lamp_skipped).
void rs_candidate_walks(uvec2 pixel, uint pixelIndex, uint outSet, uint first) {
  RsDomain D = rs_current_domain(pixel);
  RngState rng = rng_init(pixel, frame.frameKey, RNG_STREAM_CANDIDATES, frame.seed);
  uint M = rsp.candidates;
  float invM = 1.0f / float(M);
  // At most K = rsp.prefixVertices (<= RS_MAX_VERTICES) vertices, none for max_bounces 0; longer
  // paths: rs_tail (shade.glsl).
  uint maxVertices = min(min(frame.maxBounces, rsp.prefixVertices), RS_MAX_VERTICES);  // scatter to a light
#ifdef RS_ENDS_IN_EMISSION
  uint walkVertices = rs_emission_vertices();  // one more vertex that only emits
#else
  uint walkVertices = maxVertices;
#endif
#ifdef PLUME_RS_OUTSIDE
  // The variant for pixels whose camera rays miss the volume (render/pixel_order.h; scenes
  // without surfaces): each walk ends before its first vertex, so the reservoir is empty with
  // confidence M, as the walking variant finds there, and no walk's code is compiled in (a SIMD
  // back end such as lavapipe runs it under a mask otherwise). All M walks in one dispatch.
  walkVertices = 0u;
#endif
#ifndef PLUME_HAS_SURFACES
  float q = min(1.0f, plume_max3(vtx_albedo(VERTEX_MEDIUM)));  // the roulette's (below)
#endif
  // With two classes (PLUME_RS_CLASSES) r, head, keep hold the paths that end at a light, in set
  // setL; rE, headE, keepE those that end in the medium's emission, in outSet.
  uint setL = outSet + (PLUME_RS_CLASSES > 1 ? RS_SETS : 0u);
  uint base = rs_bounce_base(setL, pixelIndex);
  RsReservoir r = rs_empty();
  RsPathHead head = rs_candidate_head(0u, 0.0f, 0u, 0u, 0u, vec2(0.0f), 0u);
  // The mean field's transmittance along the selected candidate's segments: the factor of its
  // target that the weights leave out with light resampling (rs_candidates_finish).
  float segmentsKeep = 0.0f;
#if PLUME_RS_CLASSES > 1
  uint baseE = rs_bounce_base(outSet, pixelIndex);
  RsReservoir rE = rs_empty();
  RsPathHead headE = head;
  float segmentsKeepE = 0.0f;
#endif
  if (first != 0u) {  // the walks before this one
    vec4 state = rs_state(rs_state_slot(pixelIndex));
    r.w_sum = state.x;
    r.p_hat = state.y;  // the candidates' own target of the selected one
    rng.counter = floatBitsToUint(state.z);
    segmentsKeep = state.w;
    head = rs_load_head(setL, pixelIndex);
#if PLUME_RS_CLASSES > 1
    state = rs_state(rs_state_slot(pixelIndex) + 1u);
    rE.w_sum = state.x;
    rE.p_hat = state.y;
    segmentsKeepE = state.w;
    headE = rs_load_head(outSet, pixelIndex);
#endif
  }
#ifdef PLUME_HAS_EMITTERS
  // The lamp reservoir: the lamp pass's (passes/restir_lamps.comp), or empty; either way the
  // walks' numbers follow its draws.
  if (first == 0u) {
    if (!rs_lamp_pixel(pixelIndex)) rs_lamp_skipped(pixelIndex);
    rng.counter = rs_lamp_draws();
  }
#endif
  vec4 walk[RS_MAX_VERTICES - 1u];
#ifdef PLUME_RS_OUTSIDE
  uint last = M;
#else
  uint last = min(first + rsp.walksPerDispatch, M);
#endif
  // One loop over the vertices of the dispatch's walks, one after another: a lane whose walk
  // ends starts its next one while the others go on (a SIMD back end such as lavapipe runs a
  // loop while any lane needs it, so walks in a loop nested in the walks' loop cost the longest
  // walk of the subgroup each). The same draws in the same order as walk by walk.
  uint m = first;
  uint j = 0u;  // the vertex the next iteration samples; 0: walk m starts
  uint uv = 0u;
  vec3 x = D.origin;
  vec3 w = vec3(0.0f);
  vec3 f = vec3(1.0f);  // prefix of f_D, and of the source pdf, without the transmittances
  float pdf = 1.0f;     // exp(-tau_c) both hold (they cancel in the weights)
  float t1 = 0.0f;
  uint keep = 0u;   // vertices of this walk's selected candidate (0: none): copied when the walk ends
#if PLUME_RS_CLASSES > 1
  uint keepE = 0u;  // the same for the emission's reservoir
#endif
  uint kinds = 0u;  // this walk's vertex kinds so far (RsPathHead.kinds)
#if PLUME_RS_LIGHT_CANDIDATES > 1
  float segmentsWalk = 1.0f;  // the mean field's transmittance along the walk's segments so far
#endif
  vec4 slot = vec4(0.0f);  // vertex j's stored coordinates (j >= 2)
#ifdef PLUME_HAS_SURFACES
  PathVertex prev = vtx_medium(x, vec3(0.0f, 0.0f, 1.0f));  // the vertex that sampled w
#endif
  for (;;) {
    if (j == 0u) {
      if (m >= last) break;
      uv = rs_pack_uv(rng_float2(rng));  // the sub-pixel position: pdf 1 on the pixel
      x = D.origin;
      w = rs_domain_dir(D, rs_unpack_uv(uv));
      f = vec3(1.0f);
      pdf = 1.0f;
      t1 = 0.0f;
      keep = 0u;
#if PLUME_RS_CLASSES > 1
      keepE = 0u;
#endif
      kinds = 0u;
      slot = vec4(0.0f);
#if PLUME_RS_LIGHT_CANDIDATES > 1
      segmentsWalk = 1.0f;
#endif
#ifdef PLUME_HAS_SURFACES
      prev = vtx_medium(x, w);  // the camera's, first
#endif
      j = 1u;
      if (walkVertices == 0u) {  // no vertices (max_bounces 0): the walk is its draw of (u, v)
        ++m;
        j = 0u;
        continue;
      }
    }
    bool next = false;  // the walk goes on to vertex j + 1 (a `break` below ends it)
    do {
      float t;
      float sigmaC;
#ifdef PLUME_HAS_SURFACES
      // The nearer of the mean field's collision and the first surface: the surface is reached
      // with the probability of passing the mean field up to it, exp(-tau_c(0, t_hit)), the
      // target's transmittance to it (neither is carried).
      BvhHit hit = bvh_closest(x, w, 0.0f, SURF_FAR);
      float tMax = hit.prim != BVH_NONE ? hit.t : DDA_INF;
      bool collided = vol_mean_sample(x, w, tMax, rng, t, sigmaC);
#if PLUME_RS_LIGHT_CANDIDATES > 1
      // This segment's transmittance in the target (rs_path_contribution's vol_mean_tr of the
      // same ray up to the same vertex)
      if (collided || hit.prim != BVH_NONE) segmentsWalk *= vol_mean_tr(VOL_CURRENT, x, w, collided ? t : hit.t);
#endif
      PathVertex vx;
      if (!collided) {
        if (hit.prim == BVH_NONE) break;
        t = hit.t;
        vec3 o = x;
        x += t * w;
        vx = vtx_surface(x, w, hit.prim, surf_shading_normal(hit.prim, vec2(hit.u, hit.v), surf_normal(hit.prim)));
        slot = vec4(w, t);
#ifdef PLUME_RS_RECONNECT
        if (j >= 2u && rs_reconnect_vertex(kinds) == 0u) {
          // The reconnection vertex (bridge.glsl): stored by its place, measured in area
          float g = rs_reconnect_area_factor(hit.prim, w, t);
          pdf *= g;
          f *= g;
          slot = vec4(hit.u, hit.v, uintBitsToFloat(hit.prim), t);
        }
#endif
        kinds |= 1u << (j - 1u);
#ifdef PLUME_HAS_EMITTERS
        // The candidate ending with the emitter this direction hits (its direction-sampling
        // part, rs_emitter_hit); the camera ray's hit is the lamp reservoir's (rs_lamp_reservoir).
        if (j >= 2u) {
          float ph = rs_weigh(D.k, f * rs_emitter_hit(vtx_at_pdf(prev, w), hit.prim, o, vtx_receiver(prev), w, t));
          if (rs_update(r, invM * ph / pdf, ph, 0.0f, rng_float(rng))) {
            head = rs_candidate_head(uv, t1, j, kinds, RS_LIGHT_EMITTER_HIT, vec2(0.0f), 0u);
            keep = j;
#if PLUME_RS_LIGHT_CANDIDATES > 1
            segmentsKeep = segmentsWalk;
#endif
          }
        }
#endif
      } else {
#else
      if (!vol_mean_sample(x, w, DDA_INF, rng, t, sigmaC)) break;
#endif
      x += t * w;
      float sigma = vol_sigma_t_world(VOL_CURRENT, x);
      // f = 0 for this path and every extension of it (sigmaC: an exact voxel's density at the
      // collision, 0 only by rounding at the edge of a zero region, a set of measure 0)
      if (!(sigma > 0.0f) || !(sigmaC > 0.0f)) break;
      pdf *= sigmaC;            // the free-flight pdf sigmaC exp(-tau_c), less the transmittance
      vec3 fArrive = f * sigma;  // before x_j scatters or absorbs
      slot = vec4(w, t);
      f = fArrive * vtx_albedo(VERTEX_MEDIUM);
#ifdef PLUME_HAS_SURFACES
      vx = vtx_medium(x, w);
#endif
  #ifdef PLUME_HAS_EMISSION
      if (j >= 2u) {  // the candidate ending with x_j's emission: sigma_a Le instead of scattering
        float ph = rs_weigh(D.k, fArrive * (vec3(1.0f) - vtx_albedo(VERTEX_MEDIUM)) * vol_emitted_radiance_world(VOL_CURRENT, x));
        if (rs_update(RS_E_R, invM * ph / pdf, ph, 0.0f, rng_float(rng))) {
          RS_E_HEAD = rs_candidate_head(uv, t1, j, kinds, RS_LIGHT_EMISSION, vec2(0.0f), 0u);
          RS_E_KEEP = j;
#if PLUME_RS_LIGHT_CANDIDATES > 1
          RS_E_SEGMENTS = segmentsWalk;
#endif
        }
      }
  #endif
#ifdef PLUME_HAS_SURFACES
      }
#else
      PathVertex vx = vtx_medium(x, w);
#endif
      if (j == 1u) {
        t1 = t;
      } else {
        walk[j - 2u] = slot;
      }
#ifdef RS_ENDS_IN_EMISSION
      if (j > maxVertices) break;  // no scattering beyond max_bounces
#endif
      uint light;
      vec2 ls;
      uint prim;
#if PLUME_RS_LIGHT_CANDIDATES > 1
      // L light samples resampled by their unshadowed term (bridge.glsl)
      RsLightRay lightRay;
      float wLight = rs_resample_light(vx, f, D.k, rng, light, ls, prim, lightRay);
      float uSelect = rng_float(rng);
#else
      uvec4 h = rng_next4(rng);
      float pl = rs_sample_light(vx, vec3(rng_to_float(h.x), rng_to_float(h.y), rng_to_float(h.z)), rng, light, ls, prim);
      float wLight = pl > 0.0f ? 1.0f / pl : 0.0f;
      float uSelect = rng_to_float(h.w);
#endif
      if (wLight > 0.0f) {
#if PLUME_RS_LIGHT_CANDIDATES > 1
        // The candidates' own target for a light sample among emissive triangles: the target's
        // light term (visibility, the midpoint rule's transmittance, no MIS weight:
        // rs_path_contribution) on the survivor of the L samples, whose resampling left the
        // shadow ray out; one shadow ray a vertex. Without it (sessions 30-36) a walk's
        // selection was blind to visibility, and a kept path that turned out blocked left the
        // reservoir empty: on the city a moving frame's relMSE -20 to -24% with it, for +10% time
        // (notes/city.md "Session 37").
        float ph = rs_weigh(D.k, f * lightRay.value) * rs_target_light_tr(VOL_CURRENT, lightRay);
        if (ph > 0.0f && surf_occluded(lightRay.o, lightRay.w, lightRay.reach)) ph = 0.0f;
#else
        float ph = rs_weigh(D.k, f * rs_light_term(VOL_CURRENT, vx, light, ls, prim, false, rng));
#endif
        float weight = invM * ph * wLight / pdf;
        if (rs_update(r, weight, ph, 0.0f, uSelect)) {
          head = rs_candidate_head(uv, t1, j, kinds, light, ls, prim);
          keep = j;
#if PLUME_RS_LIGHT_CANDIDATES > 1
          segmentsKeep = segmentsWalk;
#endif
        }
      }
      if (j == walkVertices) break;
      if (j >= frame.rrStartBounce) {  // Russian roulette: its probability is part of the pdf
#ifdef PLUME_HAS_SURFACES
        // On the walk's throughput f / p, as the path tracer's: a fixed probability (the
        // medium's albedo, below) let nearly every walk over dark ground and walls run to
        // max_bounces, each vertex with its light samples and shadow ray, for paths that carry
        // a few percent of the light (on the city a moving frame -12% time, the same error:
        // notes/city.md "Session 38"). A function of the walk so far, so the pdf knows it.
        float q = min(1.0f, plume_max3(f) / pdf);
#endif
        if (!(rng_float(rng) < q)) break;
        pdf *= q;
      }
#ifdef PLUME_HAS_SURFACES
      vec3 wNext;
      float pdfDir;
      vtx_at_sample(vx, rng_float2(rng), wNext, pdfDir);
      if (!(pdfDir > 0.0f)) break;  // (a BSDF that produced no direction)
      vec3 scatter = vtx_at_scatter(vx, wNext);
      pdf *= pdfDir;
      f *= scatter;
      x = vtx_at_origin(vx, wNext);
      prev = vx;
#else
      vec3 wNext = vtx_sample(VERTEX_MEDIUM, w, rng_float2(rng));
      float phase = vtx_scatter(VERTEX_MEDIUM, w, wNext);
      pdf *= phase;
      f *= phase;
#endif
      w = wNext;
      next = true;
    } while (false);
    if (next && j < walkVertices) {
      ++j;
    } else {
      for (uint i = 0u; i + 2u <= keep; ++i) rs_set_bounce(base + i, walk[i]);
#if PLUME_RS_CLASSES > 1
      for (uint i = 0u; i + 2u <= keepE; ++i) rs_set_bounce(baseE + i, walk[i]);
#endif
      ++m;
      j = 0u;
    }
  }
  if (last < M) {
    rs_candidates_pause(rs_state_slot(pixelIndex), setL, pixelIndex, r, head, rng.counter, segmentsKeep);
#if PLUME_RS_CLASSES > 1
    rs_candidates_pause(rs_state_slot(pixelIndex) + 1u, outSet, pixelIndex, rE, headE, rng.counter, segmentsKeepE);
#endif
    return;
  }
  rs_candidates_finish(D, setL, pixelIndex, r, head, segmentsKeep, M);
#if PLUME_RS_CLASSES > 1
  rs_candidates_finish(D, outSet, pixelIndex, rE, headE, segmentsKeepE, M);
#endif
}

#endif

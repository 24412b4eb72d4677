// The one reuse step (DESIGN §4.2 steps 4-6), shared by temporal and spatial reuse: the
// canonical reservoir (index 0, always included) and neighbours, each with its own domain, are
// resampled into the canonical domain with the volume-aware shift (the path's coordinates
// copied, so Jacobian 1; a shift onto zero density gives p̂ = 0, a failure, and the MIS weights
// see the same zero from either side) and MIS weights from shared/restir_mis.h:
//   w_s = m_s(y_s) * p̂_c(y_s) * W_s,   W = Σ w / p̂_c(Y)   (GRIS Eq. 3.2-3.3).
// Requires restir/bridge.glsl.
#ifndef PLUME_RESTIR_REUSE_GLSL
#define PLUME_RESTIR_REUSE_GLSL

const uint RS_MAX_INPUTS = RS_MAX_NEIGHBOURS + 1u;

// The inputs of this invocation's reuse step, kept small: a domain is rebuilt from its pixel
// when needed (a few multiply-adds) rather than stored per input, since private arrays are
// memory on some devices (lavapipe). Input 0 is the canonical one, in the current frame.
struct RsInputs {
  uint count;                       // 1 + neighbours
  uint set;                         // reservoir set of every input but the history
  uint historySet;                  // reservoir set of input 1 when `history`
  bool history;                     // input 1 is the previous frame's (its domain, its volume)
  uint hasSample;                   // bit s: input s holds a path (W > 0, a stored path)
  uint pixel[RS_MAX_INPUTS];        // pixel index of each input
  RsReservoir res[RS_MAX_INPUTS];   // its reservoir (confidence already capped)
};

// One shader-private variable, not a by-value argument (a copy of the whole array per call is
// what a by-value struct compiles to).
RsInputs in_;

uint rs_input_set(uint j) { return (j == 1u && in_.history) ? in_.historySet : in_.set; }

RsDomain rs_input_domain(uint j) {
  uvec2 p = uvec2(in_.pixel[j] % frame.size.x, in_.pixel[j] / frame.size.x);
  return (j == 1u && in_.history) ? rs_previous_domain(p) : rs_current_domain(p);
}

#ifndef PLUME_RS_MIS
#define PLUME_RS_MIS RS_MIS_PAIRWISE
#endif
// PLUME_RS_SAME_DOMAIN 1: the temporal pass of a frame whose history has the current domain (a
// still camera over the volume it was rendered with; the host knows: Restir::fillFrame). The
// shift is the identity, the history pixel is the pixel itself, and every target is a stored
// one: the pipeline holds no target evaluation at all (on lavapipe the masked-off evaluations
// of the general pipeline cost ~10 ms per iteration at 128², session 23).
#ifndef PLUME_RS_SAME_DOMAIN
#define PLUME_RS_SAME_DOMAIN 0
#endif

// The cross-domain targets p̂_j(y_s), s != j, that the resampling weights and the MIS kind read:
// the neighbours' paths in the canonical domain (every kind), the canonical path in each
// neighbour's (pairwise), every pair (GBH). They are evaluated before resampling, in one loop
// around one call of rs_target: a SIMD back end such as lavapipe runs the straight-line code of
// every call site under a mask, and a loop's body at least once, so each call site the
// resampling loop and MIS had (one inside a loop nested in the other) cost a whole target walk
// even where no lane needed it (spatial reuse, session 23: ten walks' time for six targets).
const uint RS_PAIRS_MAX = RS_MAX_INPUTS * RS_MAX_INPUTS;
float rsCross[RS_PAIRS_MAX];  // p̂_j(y_s) at s * RS_MAX_INPUTS + j (shader-private, as in_)

uint rs_pair_count(uint count) {
  uint n = count - 1u;
  return PLUME_RS_MIS == RS_MIS_GBH ? count * n : PLUME_RS_MIS == RS_MIS_PAIRWISE ? 2u * n : n;
}

// Pair t of rs_pair_count(count): (s, j).
uvec2 rs_pair(uint t, uint count) {
  uint n = count - 1u;
  if (PLUME_RS_MIS == RS_MIS_GBH) {
    uint s = t / n;
    uint r = t - s * n;
    return uvec2(s, r >= s ? r + 1u : r);
  }
  return t < n ? uvec2(t + 1u, 0u) : uvec2(0u, t - n + 1u);
}

bool rs_has_sample(uint s) { return (in_.hasSample & (1u << s)) != 0u; }

void rs_cross_targets() {
#if !PLUME_RS_SAME_DOMAIN
  uint pairs = rs_pair_count(in_.count);
  for (uint t = 0u; t < pairs; ++t) {
    uvec2 sj = rs_pair(t, in_.count);
    float v = 0.0f;
    if (rs_has_sample(sj.x)) v = rs_target(rs_input_domain(sj.y), rs_input_set(sj.x), in_.pixel[sj.x]);
    rsCross[sj.x * RS_MAX_INPUTS + sj.y] = v;
  }
#endif
}

// p̂ of input s's path in input j's domain: the stored value when j == s (or in one domain),
// else rs_cross_targets' (for the pairs it evaluates; input s holding a path).
float rs_target_in(uint s, uint j) {
#if PLUME_RS_SAME_DOMAIN
  return in_.res[s].p_hat;
#else
  return j == s ? in_.res[s].p_hat : rsCross[s * RS_MAX_INPUTS + j];
#endif
}

// Resamples the inputs into input 0's domain; writes the reservoir and the selected path to
// (outSet, outPixel). The MIS kind is compiled in (PLUME_RS_MIS: RS_MIS_PAIRWISE, RS_MIS_GBH or
// RS_MIS_BIASED): a SIMD back end such as lavapipe runs every branch's straight-line code under
// a mask, so the kinds not taken cost time unless they are not there (-20 to -40% per pass).
// MIS (shared/restir_mis.h) reads the inputs through these accessors.
#define RS_MIS_M(j) in_.res[j].M
#define RS_MIS_OWN_TARGET(s) in_.res[s].p_hat
#define RS_MIS_TARGET(s, j) rs_target_in(s, j)
#include "../shared/restir_mis.h"

void rs_reuse(uint outSet, uint outPixel, inout RngState rng) {
#ifdef PLUME_RS_OUTSIDE
  // The variant for pixels whose camera rays miss the volume (render/pixel_order.h; scenes
  // without surfaces). Every target in such a pixel's domain is 0 (no shifted path has density at
  // its first vertex there) and its own input never holds a path, so every resampling weight is 0:
  // the result is an empty reservoir whose confidence is the inputs' summed in their order, as
  // rs_merge sums them in the walking variant. Nothing else of the step is compiled in.
  RsReservoir empty = rs_empty();
  for (uint s = 0u; s < in_.count; ++s) empty.M += in_.res[s].M;
  rs_finalize(empty);
  rs_clear_path(outSet, outPixel);
  rs_store(outSet, outPixel, empty);
#else
  float Msum = 0.0f;
  for (uint s = 0u; s < in_.count; ++s) Msum += in_.res[s].M;
  in_.hasSample = 0u;
  for (uint s = 0u; s < in_.count; ++s) {
    if (in_.res[s].W > 0.0f && rs_path_length(rs_input_set(s), in_.pixel[s]) > 0u) in_.hasSample |= 1u << s;
  }
  rs_cross_targets();
  RsReservoir out_ = rs_empty();
  uint selected = RS_MAX_INPUTS;
  for (uint s = 0u; s < in_.count; ++s) {
    RsReservoir rs_ = in_.res[s];
    float phC = 0.0f;
    float m = 0.0f;
    if (rs_has_sample(s)) {
      phC = rs_target_in(s, 0u);
      m = rs_mis_weight(PLUME_RS_MIS, s, in_.count, Msum, phC);
    }
    if (rs_merge(out_, rs_, phC, 1.0f, m, rng_float(rng))) selected = s;
  }
  rs_finalize(out_);
  if (selected < RS_MAX_INPUTS && out_.W > 0.0f) {
    rs_copy_path(rs_input_set(selected), in_.pixel[selected], outSet, outPixel);
  } else {
    out_.w_sum = 0.0f;
    out_.p_hat = 0.0f;
    out_.W = 0.0f;
    rs_clear_path(outSet, outPixel);
  }
  rs_store(outSet, outPixel, out_);
#endif
}

// The history pixel for `pixel` (DESIGN §4.2 step 5): the point at the fixed reprojection depth
// along the pixel centre's ray, projected with the previous camera. Depends on the pixel and the
// cameras only, never on a sample. False when it falls outside the previous image.
bool rs_reproject(uvec2 pixel, out uvec2 prevPixel) {
  prevPixel = pixel;
  vec3 dir = normalize(cam_direction(vec2(pixel) + 0.5f, frame.size, frame.camera));
  GpuCamera prev = rsp.prevCamera;
  vec3 p = frame.camera.position + rsp.reprojectionDepth * dir - prev.position;
  float z = dot(p, prev.forward);
  if (!(z > 0.0f)) return false;
  float px = dot(p, prev.right) / (z * prev.tanHalfFovY * prev.aspect);
  float py = dot(p, prev.up) / (z * prev.tanHalfFovY);
  vec2 f = vec2((px + 1.0f) * 0.5f * float(frame.size.x), (1.0f - py) * 0.5f * float(frame.size.y));
  if (!(f.x >= 0.0f && f.y >= 0.0f && f.x < float(frame.size.x) && f.y < float(frame.size.y))) return false;
  prevPixel = uvec2(f);
  return true;
}

// One reuse step for `pixel` (index `index`): temporal (the canonical reservoir of set inSet and
// the history of set histSet at the reprojected pixel, its confidence capped) or spatial
// `spatialRound` (k neighbours of set inSet in the disk, drawn from the pixel and the round only, never
// from the samples; or the one neighbour at the fixed offset of RestirParams, for tests). Output: set outSet.
void rs_reuse_pixel(uvec2 pixel, uint index, bool temporal, uint spatialRound, uint inSet, uint histSet, uint outSet) {
  in_.count = 1u;
  in_.set = inSet;
  in_.historySet = histSet;
  in_.history = false;
  in_.pixel[0] = index;
  in_.res[0] = rs_load(inSet, index);
  uint stream = temporal ? RNG_STREAM_TEMPORAL : RNG_STREAM_SPATIAL + (spatialRound << 8u);
  RngState rng = rng_init(pixel, frame.frameKey, stream, frame.seed);
  if (temporal) {
    uvec2 q = pixel;
#if PLUME_RS_SAME_DOMAIN
    if (true) {  // the identity shift (the host dispatches this pipeline with a valid history)
#else
    if (rsp.historyValid != 0u && rs_reproject(pixel, q)) {
#endif
      uint qi = q.y * frame.size.x + q.x;
      in_.history = true;
      in_.pixel[1] = qi;
      in_.res[1] = rs_load(histSet, qi);
      rs_cap_confidence(in_.res[1], rsp.historyCap * in_.res[0].M);
      in_.count = 2u;
    }
  } else {
    for (uint i = 0u; i < rsp.neighbours; ++i) {
      vec2 u = rng_float2(rng);  // neighbour offsets: uniform in the disk, independent of samples
      float radius = rsp.radius * sqrt(u.x);
      ivec2 q = ivec2(pixel) + ivec2(round(radius * vec2(cos(2.0f * PLUME_PI * u.y), sin(2.0f * PLUME_PI * u.y))));
      ivec2 fixedOffset = ivec2(rsp.fixedNeighbourX, rsp.fixedNeighbourY);
      if (fixedOffset != ivec2(0)) q = ivec2(pixel) + fixedOffset;  // tests: one neighbour, never symmetric
      if (any(lessThan(q, ivec2(0))) || q.x >= int(frame.size.x) || q.y >= int(frame.size.y)) continue;
      if (q == ivec2(pixel)) continue;
      uint qi = uint(q.y) * frame.size.x + uint(q.x);
      uint k = in_.count++;
      in_.pixel[k] = qi;
      in_.res[k] = rs_load(inSet, qi);
    }
  }
  rs_reuse(outSet, index, rng);
}

#endif

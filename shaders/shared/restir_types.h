// Volumetric ReSTIR (DESIGN §4.2): the path stored in a reservoir, the per-frame ReSTIR
// parameters, the push constants of the passes, and the MIS weights of reuse. Shared by C++
// and GLSL (common.h), so the tests check the weights on the CPU with the code the GPU runs.
//
// A path y, in the coordinates the shift copies (DESIGN §4.2 step 4):
//   (u, v)                  position inside the pixel (box filter), in pixels
//   t1                      distance of the first vertex along the pixel's camera ray (world units)
//   (w_i, t_i), i = 2..n    direction and distance of each further vertex (n <= RS_MAX_VERTICES)
//   (light, u)              the light sample that ends the path: light index and two floats
//                           (a direction for suns with a disk and the environment, unused for a
//                           delta sun or a point light; for the emissive triangles, light index
//                           GpuFrame.lightCount, the triangle and a point's barycentrics: a point
//                           in area measure); or light = RS_LIGHT_EMISSION: the path
//                           ends with the medium's emission at x_n (x_n absorbs instead of
//                           scattering: sigma_a Le there, n - 1 scattering vertices)
// Its contribution f_D(y) in a domain D (pixel of a frame, volume) is measured in du dv dt1 dw2 dt2 ... dw_L,
// so copying the coordinates into another domain has Jacobian 1 and the light reconnection to a
// direction or a point has none either. A surface vertex (bit i - 1 of RsPathHead.kinds set) is
// "the first surface along w_i": its coordinate is the direction alone (t_i is stored but implied
// by the domain's geometry), so the copy has Jacobian 1 there too, and the shift fails (f = 0)
// where the copied ray's first event is of the other kind (notes/restir.md "Surfaces").
// With the reconnection shift (render.restir_shift reconnect, PLUME_RS_RECONNECT) the first
// surface vertex r >= 2 (rs_reconnect_vertex of the kinds) is stored by its place instead: its
// slot holds (b1, b2, triangle, t), barycentrics of a point x_r on the triangle, and its
// coordinate is x_r in area measure dA(x_r), so f and the source pdf both carry
// |cos_r| / |x_r - o_{r-1}|² there (the solid angle to area conversion). Every domain reconnects
// its own vertex r - 1 to the same x_r (visibility and transmittance along the new segment), and
// the vertices after it are copied from x_r, so the path from x_r on is the same point set. The
// coordinates are still copied (Jacobian 1 in them); measured in the direction w_r, as the copy
// shift does, the same map has the GRIS reconnection Jacobian
// (|cos_r'| / |cos_r|) (|x_r - o_{r-1}|² / |x_r - o'_{r-1}|²).
#ifndef PLUME_SHARED_RESTIR_TYPES_H
#define PLUME_SHARED_RESTIR_TYPES_H

#include "common.h"
#include "gpu_types.h"

PLUME_NS_BEGIN

const uint RS_MAX_VERTICES = 16u;  // longest path a reservoir stores (render.restir_prefix <= this)
const uint RS_MAX_NEIGHBOURS = 8u;
// Final shading's tail (restir/shade.glsl) walks at most this many segments, each with a light
// ray, per dispatch of passes/restir_tail.comp: a bounded share of lavapipe's loop budget
// (docs/architecture.md) whatever max_bounces is. (32 per dispatch still had no cut in the dense
// bright cloud at 256 bounces, 128 had: notes/extreme.md.)
const uint RS_TAIL_SEGMENTS = 8u;
// The candidates walk at most this many vertices per invocation and dispatch (several walks of
// K vertices, or one; restir/candidates.glsl). (M 16 x K 16 = 256 had no cut in the dense bright
// cloud, M 64 x K 16 in one dispatch had: notes/extreme.md.)
const uint RS_CANDIDATE_VERTICES = 64u;
// Reservoir sets per pixel: candidates / temporal / spatial rotate through them (Restir::render).
const uint RS_SETS = 3u;
// vec4s per pixel of a pass's state between its dispatches (restir/bridge.glsl rs_state_slot):
// the candidates' running reservoir (1), the tail's walk (5, restir/shade.glsl RsTail).
const uint RS_STATE_SLOTS = 5u;
// vec4s per pixel of the targets' colour weights past the state (RestirParams::colourSet;
// restir/bridge.glsl rs_colour_slot): the weights of two sets (the current frame's and the
// history's, which its domain keeps until its reservoirs are gone), then the estimate of the
// pixel's radiance they come from (RS_COLOUR_ESTIMATE; restir/colour.glsl).
const uint RS_COLOUR_SLOTS = 3u;
const uint RS_COLOUR_ESTIMATE = 2u;
// vec4s per pixel of the lamp reservoirs (RestirParams::lampSet) past the colour weights, with emissive
// surfaces only: (W, M, packed (u, v), p̂) of each of the two sets (restir/bridge.glsl rs_lamp_slot).
const uint RS_LAMP_SLOTS = 2u;
// rsCounters[] (restir/bindings.glsl): [0] reservoirs dropped for non-finite weights,
// [RS_COUNTER_TAIL_ALIVE] tail walks still alive after a counting dispatch (Restir::render).
const uint RS_COUNTERS = 4u;
const uint RS_COUNTER_TAIL_ALIVE = 1u;
const uint RS_LIGHT_EMISSION = 0xFFFFFFFFu;  // RsPathHead.light of a path ending in emission
// RsPathHead.light of a path whose last vertex is an emissive surface hit by the direction sampled
// at the vertex before it (its emission weighted by MIS against the emitters' light samples)
const uint RS_LIGHT_EMITTER_HIT = 0xFFFFFFFEu;

const uint RS_MIS_PAIRWISE = 0u;  // pairwise MIS with confidence weights (default, O(k))
const uint RS_MIS_GBH = 1u;       // generalised balance heuristic (O(k^2))
const uint RS_MIS_BIASED = 2u;    // restir-biased: m_i = M_i / sum M, no MIS (biased)


// Stored path header (one per pixel and reservoir set); vertices 2..n live in a separate buffer
// of vec4(direction, t) (the reconnection vertex: vec4(b1, b2, triangle, t)),
// RestirParams.bounceStride (= max_bounces - 1) slots per pixel and set.
struct RsPathHead {
  vec2 lightSample;  // the light sample's two floats (rs_encode_dir of a direction, or unused)
  float t1;          // distance of the first vertex along the camera ray
  uint vertexCount;  // n (0: no path)
  uint light;        // index of the light that ends the path, or RS_LIGHT_EMISSION
  uint kinds;        // vertex kinds, one bit per vertex (integrator/vertex.glsl; 0: all media)
  uint uv;           // sub-pixel position (u, v) as two 16-bit unorms (restir/bridge.glsl)
  uint lightPrim;    // an emissive-triangle light sample's triangle (lightSample: its barycentrics)
};

// Per-frame parameters of the ReSTIR passes (beside GpuFrame, which holds the current camera),
// grouped by stage.
struct RestirParams {
  GpuCamera prevCamera;     // temporal: the previous frame's camera
  // Candidates (DESIGN §4.2 step 1)
  uint candidates;          // M
  uint bounceStride;        // path vertex slots per pixel and set (prefixVertices - 1, at least 1)
  uint pixelCount;
  uint lightCount;
  // Temporal reuse (step 5)
  uint historyValid;        // 1: the history set holds the previous frame's reservoirs
  uint historySameDomain;   // 1: the history's domain is the current one (still camera and volume):
                            // the host dispatches the same-domain temporal pipeline (restir/reuse.glsl)
  float historyCap;         // c: history confidence <= c * M
  float reprojectionDepth;  // world distance along the pixel's ray that is reprojected
  // Spatial reuse (step 6)
  uint neighbours;          // k
  float radius;             // px
  // Candidates and final shading: vertices a reservoir's path holds, min(restir_prefix,
  // max_bounces); final shading path-traces the paths with more (PLUME_RS_TAIL)
  uint prefixVertices;
  uint walksPerDispatch;    // candidates per dispatch: RS_CANDIDATE_VERTICES / walk length, at least 1
  // Spatial reuse with a fixed neighbour (RestirOptions::fixedNeighbourX/Y, tests only): when not
  // (0, 0), each round's one neighbour is the pixel at this offset (neighbours is 1)
  int fixedNeighbourX;
  int fixedNeighbourY;
  // Lamps seen directly (emissive triangles hit by the camera ray): a reservoir of their own per
  // pixel (restir/candidates.glsl rs_lamp_reservoir), two sets that alternate by frame.
  uint lampSet;             // this frame's set (the history's is the other)
  uint lampHistory;         // 1: the other set holds the previous frame's, same pixel (a still camera)
  uint lampSameVolume;      // 1: ... rendered with this frame's volume (its target is this frame's)
  // The targets' colour weights (restir/colour.glsl): the slot of this frame's and of the
  // history's (the same slot where they did not change since the previous frame).
  uint colourSet;
  uint colourHistorySet;
  uint pad2;
};

// Push constants: which reservoir sets a pass reads and writes.
struct RsPush {
  uint inSet;                // canonical input set
  uint historySet;           // temporal reuse's history set
  uint outSet;               // output set
  uint spatialRound;         // spatial reuse's round (its random stream)
  uint restartAccumulation;  // final shading: 1 restarts the accumulation, 0 adds to it
  uint candidate;            // candidates: the first walk m < M of this dispatch
  uint countAlive;           // tail: 1 counts the walks still alive after this dispatch
  uint listBegin;            // the dispatch's pixels: rsPixels[listBegin .. listBegin + listCount)
  uint listCount;            //   (restir/bindings.glsl rs_dispatch_pixel)
  uint colourStep;           // colour weights (passes/restir_colour.comp): 0 / 1 / 3 a walk into the estimate, 2 the weights
};

// --- Light sample encoding: a unit direction as (z, phi), exact enough for float storage ---
PLUME_FN vec2 rs_encode_dir(vec3 w) { return vec2(w.z, atan(w.y, w.x)); }

PLUME_FN vec3 rs_decode_dir(vec2 e) {
  float z = clamp(e.x, -1.0f, 1.0f);
  float r = sqrt(max(0.0f, 1.0f - z * z));
  return vec3(r * cos(e.y), r * sin(e.y), z);
}

// --- MIS weights of reuse (GRIS, Lin et al. 2022; DESIGN §4.2 steps 5-6) -----------------------
// Pairwise MIS with confidence weights (defensive form, Bitterli 2022 §9.1.3 extended to
// confidences): with canonical confidence Mc, neighbour confidences M_i and Msum = Mc + Σ M_i,
//   m_i(x) = (M_i / Msum) * b_i(x),   b_i(x) = M_i p̂_←i(x) / (M_i p̂_←i(x) + Mc p̂_c(x))
//   m_c(x) = Mc / Msum + Σ_i (M_i / Msum) * (1 - b_i(x))
// which sum to 1 for every x. p̂_←i(x) is the neighbour's target of x shifted into its domain
// (0 when that shift fails): a failed shift gives b_i = 0 whichever way it is taken.

// b_i: the neighbour's share of the pair (i, c) for a path with targets ph_i (neighbour domain)
// and ph_c (canonical domain). 0 when both are 0 (no technique can produce it).
PLUME_FN float rs_pair_share(float Mi, float ph_i, float Mc, float ph_c) {
  float a = Mi * ph_i;
  float d = a + Mc * ph_c;
  return d > 0.0f ? a / d : 0.0f;
}

// m_i for a neighbour's own sample shifted into the canonical domain.
PLUME_FN float rs_pairwise_neighbour(float Mi, float ph_i, float Mc, float ph_c, float Msum) {
  return Msum > 0.0f ? (Mi / Msum) * rs_pair_share(Mi, ph_i, Mc, ph_c) : 0.0f;
}

// One pair's term of m_c for the canonical sample (accumulate over i, then add Mc / Msum).
PLUME_FN float rs_pairwise_canonical_term(float Mi, float ph_i, float Mc, float ph_c, float Msum) {
  return Msum > 0.0f ? (Mi / Msum) * (1.0f - rs_pair_share(Mi, ph_i, Mc, ph_c)) : 0.0f;
}

// Generalised balance heuristic: m_j(x) = M_j p̂_←j(x) / Σ_l M_l p̂_←l(x); the caller sums the
// denominator over all domains (canonical included).
PLUME_FN float rs_gbh(float Mj, float ph_j, float denominator) {
  return denominator > 0.0f ? Mj * ph_j / denominator : 0.0f;
}

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::RsPathHead) == 32, "RsPathHead crosses the bus");
static_assert(offsetof(plume::shared::RsPathHead, vertexCount) == 12, "RsPathHead layout");
static_assert(offsetof(plume::shared::RestirParams, candidates) == 64, "RestirParams layout");
static_assert(sizeof(plume::shared::RestirParams) == 64 + 5 * 16, "RestirParams layout");
static_assert(sizeof(plume::shared::RsPush) == 40, "RsPush layout");
#endif

#endif

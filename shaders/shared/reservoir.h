// Weighted reservoir sampling / streaming resampled importance sampling (DESIGN §4.2 step 3),
// written once for GLSL and C++ (common.h). RTXDI style: exactly one resampling step
// (rs_update); streaming fresh candidates (rs_stream) and merging reservoirs (rs_merge) are thin
// wrappers that only compute the candidate's resampling weight.
//
// Weights follow generalised RIS (Lin et al. 2022, "Generalized Resampled Importance Sampling",
// GRIS; Eq. 3.2 and Alg. 1): candidate i with sample x_i, unbiased contribution weight W_i and
// MIS (resampling) weight m_i has resampling weight
//     w_i = m_i * p̂(T_i(x_i)) * W_i * |J_i|            (T_i: shift into the receiving domain)
// and the selected sample Y (chosen with probability w_i / Σw) gets
//     W_Y = (1 / p̂(Y)) * Σ_j w_j                       (rs_finalize).
// The m_i must sum to 1 over the candidates for every sample (e.g. 1/M for M i.i.d. fresh
// candidates), so unlike Bitterli et al. 2020 (Alg. 2 and 3: W = (1/p̂) (1/M) w_sum) no 1/M
// appears in rs_finalize: it lives in the MIS weights the caller passes.
//
// The reservoir holds weights only, never the sample (GLSL has no templates): rs_update returns
// true when the new candidate replaces the selected one, and the caller then copies its sample.
// Random numbers come from the caller (rng.h), so the code is deterministic for given inputs.
#ifndef PLUME_SHARED_RESERVOIR_H
#define PLUME_SHARED_RESERVOIR_H

#include "common.h"

PLUME_NS_BEGIN

// Working form (registers).
struct RsReservoir {
  float w_sum;  // Σ w_i of the candidates seen so far (Bitterli Alg. 2 w_sum)
  float M;      // confidence: number of candidates represented (a float so caps like
                // M_hist <= c * M_cur may be fractional); sums under merging
  float p_hat;  // target p̂ of the selected sample *in this reservoir's domain*
  float W;      // unbiased contribution weight of the selected sample; valid only after
                // rs_finalize (0 = no sample: empty, all weights zero, or a guard tripped)
};

// True for finite floats. Tests the exponent bits, so fast-math compilers cannot fold it away.
PLUME_FN bool rs_is_finite(float x) {
  return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u;
}

PLUME_FN RsReservoir rs_empty() {
  RsReservoir r;
  r.w_sum = 0.0f;
  r.M = 0.0f;
  r.p_hat = 0.0f;
  r.W = 0.0f;
  return r;
}

// The one resampling step (Bitterli Alg. 2 lines 3-6 "update"; GRIS Alg. 1 lines 5-7).
// Adds a candidate of resampling weight w >= 0 whose target in this domain is p_hat and whose
// confidence is M (1 for a fresh candidate, the other reservoir's M when merging). It is
// selected with probability w / (w_sum + w) using u uniform in [0, 1). Negative or
// non-finite weights are treated as 0 (the candidate is never selected) but still count in M,
// so that MIS weights computed from M stay consistent.
PLUME_FN bool rs_update(INOUT(RsReservoir) r, float w, float p_hat, float M, float u) {
  r.M += M;
  if (!rs_is_finite(w) || !(w > 0.0f)) return false;
  r.w_sum += w;
  if (u * r.w_sum < w) {
    r.p_hat = p_hat;
    return true;
  }
  return false;
}

// Streams a fresh candidate x drawn with density source_pdf (Talbot RIS; Bitterli Alg. 2
// line 4 with W_i = 1 / p(x_i)): w = m * p̂(x) / p(x). With M i.i.d. candidates, m = 1/M.
// A candidate with source_pdf <= 0 cannot have been drawn: weight 0.
PLUME_FN bool rs_stream(INOUT(RsReservoir) r, float p_hat, float source_pdf, float mis_weight,
                        float u) {
  float w = source_pdf > 0.0f ? mis_weight * p_hat / source_pdf : 0.0f;
  return rs_update(r, w, p_hat, 1.0f, u);
}

// Merges a finalised reservoir `other` (Bitterli Alg. 3 "combine"; GRIS Eq. 3.2): its sample,
// shifted into the receiving domain, has target p_hat_here there and shift Jacobian jacobian
// (1 for the identity and for the (t, ω) copy shift; 0 for a failed shift). mis_weight is the
// resampling weight m_i (pairwise MIS, generalised balance heuristic, or M_i / ΣM). The
// receiving reservoir's M grows by other.M whether or not the sample is selected.
PLUME_FN bool rs_merge(INOUT(RsReservoir) r, RsReservoir other, float p_hat_here,
                       float jacobian, float mis_weight, float u) {
  float w = mis_weight * p_hat_here * other.W * jacobian;
  return rs_update(r, w, p_hat_here, other.M, u);
}

// W = w_sum / p̂(Y) (GRIS Eq. 3.3), guarded: 0 when p̂ or w_sum is 0, negative or non-finite,
// or the quotient overflows. Call once after the last update.
PLUME_FN void rs_finalize(INOUT(RsReservoir) r) {
  bool ok = rs_is_finite(r.w_sum) && rs_is_finite(r.p_hat) && r.w_sum > 0.0f && r.p_hat > 0.0f;
  float W = ok ? r.w_sum / r.p_hat : 0.0f;
  r.W = rs_is_finite(W) ? W : 0.0f;
}

// Caps the confidence (temporal history: M_hist <= c * M_cur, DESIGN §4.2 step 5). With GRIS
// weights only the confidence changes; W stays the sample's unbiased contribution weight.
PLUME_FN void rs_cap_confidence(INOUT(RsReservoir) r, float max_M) { r.M = min(r.M, max_M); }

// Storage form: 16 bytes, four 32-bit words (std430 stride 16; static_asserts below).
// M is stored in unsigned fixed point with RS_M_FRAC_BITS fractional bits, so confidences that
// are multiples of 1/256 below RS_M_MAX survive a round trip exactly (integers up to 2^16 do).
struct RsPacked {
  float w_sum;
  float p_hat;
  float W;
  uint M_fixed;  // round(M * RS_M_SCALE), saturated at RS_M_MAX
};

const uint RS_M_FRAC_BITS = 8u;
const uint RS_M_FRAC_MASK = 0xFFu;   // (1 << RS_M_FRAC_BITS) - 1
const float RS_M_SCALE = 256.0f;     // 2^RS_M_FRAC_BITS
const float RS_M_MAX = 16777215.0f;  // (2^32 - 256) / 2^8: the largest M that fits

PLUME_FN RsPacked rs_pack(RsReservoir r) {
  RsPacked p;
  p.w_sum = r.w_sum;
  p.p_hat = r.p_hat;
  p.W = r.W;
  float M = rs_is_finite(r.M) ? clamp(r.M, 0.0f, RS_M_MAX) : 0.0f;
  p.M_fixed = uint(M * RS_M_SCALE + 0.5f);
  return p;
}

// Unpacks and drops non-finite or negative weights (RTXDI's unpack rule, so one bad value
// cannot spread through reuse): then w_sum = p_hat = W = 0, the confidence M is kept, and
// `dropped` is true so the caller can count it (DESIGN §4.2 step 3).
PLUME_FN RsReservoir rs_unpack(RsPacked p, OUT(bool) dropped) {
  RsReservoir r;
  r.w_sum = p.w_sum;
  r.p_hat = p.p_hat;
  r.W = p.W;
  r.M = float(p.M_fixed >> RS_M_FRAC_BITS) + float(p.M_fixed & RS_M_FRAC_MASK) / RS_M_SCALE;
  bool finite = rs_is_finite(p.w_sum) && rs_is_finite(p.p_hat) && rs_is_finite(p.W);
  dropped = !finite || p.w_sum < 0.0f || p.p_hat < 0.0f || p.W < 0.0f;
  if (dropped) {
    r.w_sum = 0.0f;
    r.p_hat = 0.0f;
    r.W = 0.0f;
  }
  return r;
}

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::RsPacked) == 16, "RsPacked crosses the bus: 4 words");
static_assert(offsetof(plume::shared::RsPacked, w_sum) == 0);
static_assert(offsetof(plume::shared::RsPacked, p_hat) == 4);
static_assert(offsetof(plume::shared::RsPacked, W) == 8);
static_assert(offsetof(plume::shared::RsPacked, M_fixed) == 12);
#endif

#endif

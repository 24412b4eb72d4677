// The MIS weight of one input of a reuse step (GRIS, Lin et al. 2022; DESIGN §4.2 steps 5-6),
// assembled from restir_types.h's terms. The code the GPU runs (restir/reuse.glsl) and the CPU
// tests (tests/test_restir_mis.cpp) call this one function. What it reads about the inputs comes
// through three macros the includer defines first, in the manner of PNanoVDB's accessors (GLSL
// has no callbacks), so that each caller evaluates only the targets the MIS kind needs:
//   RS_MIS_M(j)            confidence M_j of input j (input 0 is the canonical one)
//   RS_MIS_OWN_TARGET(s)   p̂_s(y_s): input s's sample in its own domain (its stored target)
//   RS_MIS_TARGET(s, j)    p̂_j(y_s): input s's sample shifted into input j's domain (0 if the
//                          shift fails; the own target when j == s); called for j >= 1 only
#ifndef PLUME_SHARED_RESTIR_MIS_H
#define PLUME_SHARED_RESTIR_MIS_H

#include "restir_types.h"

#if !defined(RS_MIS_M) || !defined(RS_MIS_OWN_TARGET) || !defined(RS_MIS_TARGET)
#error "define RS_MIS_M, RS_MIS_OWN_TARGET and RS_MIS_TARGET before including restir_mis.h"
#endif

PLUME_NS_BEGIN

// m_s(y_s) for input s of `count`, with Msum = Σ_j M_j and phC = p̂_c(y_s), the sample's target
// in the canonical domain (which the caller also needs for the resampling weight). The weights
// sum to 1 over s for every path (pairwise, GBH); RS_MIS_BIASED is the 1/M weight of
// `restir-biased` (confidence share, no MIS).
PLUME_FN float rs_mis_weight(uint misKind, uint s, uint count, float Msum, float phC) {
  if (misKind == RS_MIS_BIASED) return RS_MIS_M(s) / Msum;
  if (misKind == RS_MIS_GBH) {
    float denom = 0.0f;
    for (uint j = 0u; j < count; ++j) denom += RS_MIS_M(j) * (j == 0u ? phC : RS_MIS_TARGET(s, j));
    return rs_gbh(RS_MIS_M(s), RS_MIS_OWN_TARGET(s), denom);
  }
  float Mc = RS_MIS_M(0u);
  if (s == 0u) {
    float m = Mc / Msum;
    for (uint i = 1u; i < count; ++i) m += rs_pairwise_canonical_term(RS_MIS_M(i), RS_MIS_TARGET(0u, i), Mc, phC, Msum);
    return m;
  }
  return rs_pairwise_neighbour(RS_MIS_M(s), RS_MIS_OWN_TARGET(s), Mc, phC, Msum);
}

PLUME_NS_END

#endif

// Tier b (DESIGN §7): the MIS weights of ReSTIR's reuse step, computed by the function the GPU
// runs (shaders/shared/restir_mis.h rs_mis_weight, compiled here as C++), sum to 1 over the
// inputs for every path — pairwise MIS and the generalised balance heuristic, with failed shifts
// (target 0 in some domain) — and the share of a pair is its balance heuristic. Also the light
// sample's direction encoding.
#include <glm/glm.hpp>

#include <gtest/gtest.h>

#include <random>
#include <vector>

// The accessors rs_mis_weight reads (restir_mis.h): one path x evaluated in every domain, as if
// each input had produced it, so that sum_s m_s(x) must be 1.
namespace mis_table {
std::vector<float> M;   // confidence of input j
std::vector<float> ph;  // p̂_j(x): the path's target in input j's domain (0: the shift fails)
}  // namespace mis_table
#define RS_MIS_M(j) (::mis_table::M[j])
#define RS_MIS_OWN_TARGET(s) (::mis_table::ph[s])
#define RS_MIS_TARGET(s, j) (::mis_table::ph[j])
#include "shaders/shared/restir_mis.h"

using namespace plume;

namespace {

// Draws k + 1 confidences and targets of one path; the canonical domain can produce it.
void drawInputs(std::mt19937& rng, int trial, int k) {
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  mis_table::M.assign(k + 1, 0.0f);
  mis_table::ph.assign(k + 1, 0.0f);
  for (int i = 0; i <= k; ++i) {
    mis_table::M[i] = 1.0f + float(trial % 7) * U(rng);
    mis_table::ph[i] = U(rng) < 0.2f ? 0.0f : U(rng);  // failed shifts included
  }
  if (mis_table::ph[0] == 0.0f) mis_table::ph[0] = 0.5f;
}

float sumOverInputs(uint32_t kind, int k) {
  float Msum = 0;
  for (float m : mis_table::M) Msum += m;
  float sum = 0;
  for (int s = 0; s <= k; ++s) {
    // Inputs whose domain cannot produce x (target 0 there) never hold it: weight not counted.
    if (mis_table::ph[s] == 0.0f) continue;
    sum += shared::rs_mis_weight(kind, uint32_t(s), uint32_t(k + 1), Msum, mis_table::ph[0]);
  }
  return sum;
}

}  // namespace

TEST(RestirMis, PairwiseAndGbhWeightsSumToOne) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 1000; ++trial) {
    const int k = 1 + trial % 5;
    drawInputs(rng, trial, k);
    EXPECT_NEAR(sumOverInputs(shared::RS_MIS_PAIRWISE, k), 1.0f, 1e-5f) << "trial " << trial;
    EXPECT_NEAR(sumOverInputs(shared::RS_MIS_GBH, k), 1.0f, 1e-5f) << "trial " << trial;
  }
}

TEST(RestirMis, WeightsFailWhenATermIsDropped) {
  // The test can fail: the canonical weight without its pairwise terms (as if the loop over
  // neighbours were lost) no longer sums to 1 once some neighbour can produce the path.
  std::mt19937 rng(9);
  drawInputs(rng, 3, 3);
  mis_table::ph.assign({0.5f, 0.4f, 0.3f, 0.2f});
  float Msum = 0;
  for (float m : mis_table::M) Msum += m;
  const float full = sumOverInputs(shared::RS_MIS_PAIRWISE, 3);
  const float canonicalAlone = mis_table::M[0] / Msum;
  const float mc = shared::rs_mis_weight(shared::RS_MIS_PAIRWISE, 0u, 4u, Msum, mis_table::ph[0]);
  EXPECT_NEAR(full, 1.0f, 1e-5f);
  EXPECT_GT(mc, canonicalAlone + 1e-3f);
  EXPECT_GT(std::abs(full - (mc - canonicalAlone) - 1.0f), 1e-3f);
}

TEST(RestirMis, BiasedWeightIsTheConfidenceShare) {
  mis_table::M.assign({4.0f, 1.0f, 3.0f});
  mis_table::ph.assign({0.5f, 0.0f, 0.25f});
  EXPECT_FLOAT_EQ(shared::rs_mis_weight(shared::RS_MIS_BIASED, 2u, 3u, 8.0f, 0.5f), 3.0f / 8.0f);
}

TEST(RestirMis, PairShareIsThePairsBalanceHeuristic) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (int trial = 0; trial < 1000; ++trial) {
    const float Mi = 1.0f + 6.0f * U(rng), Mc = 1.0f + 6.0f * U(rng);
    const float phi = U(rng) < 0.2f ? 0.0f : U(rng), phc = U(rng);
    const float a = Mi * phi, d = a + Mc * phc;
    EXPECT_NEAR(shared::rs_pair_share(Mi, phi, Mc, phc), d > 0 ? a / d : 0.0f, 1e-6f);
  }
  EXPECT_EQ(shared::rs_pair_share(2.0f, 0.0f, 3.0f, 0.0f), 0.0f);
}

TEST(RestirMis, LightDirectionEncodingRoundTrips) {
  std::mt19937 rng(3);
  std::normal_distribution<float> N;
  for (int i = 0; i < 1000; ++i) {
    glm::vec3 w = glm::normalize(glm::vec3(N(rng), N(rng), N(rng)));
    glm::vec3 back = shared::rs_decode_dir(shared::rs_encode_dir(w));
    EXPECT_LT(glm::length(back - w), 1e-5f);
  }
}

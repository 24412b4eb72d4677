// Running per-pixel mean and variance of samples (DESIGN §2 Images: mean + variance of the
// mean): (mean rgb, n) and M2 rgb, the sum of squared deviations from the mean. One merge (Chan
// et al. 1979) adds a batch of nB samples with its own mean and M2; a single sample is the batch
// (sample, M2 = 0, nB = 1), which is Welford's update. Shared by the path tracer (pt_resolve.comp) and
// ReSTIR's final shading (restir_shade.comp); C++ and GLSL (common.h).
#ifndef PLUME_SHARED_ACCUMULATE_H
#define PLUME_SHARED_ACCUMULATE_H

#include "common.h"

PLUME_NS_BEGIN

PLUME_FN void acc_merge(INOUT(vec4) meanN, INOUT(vec3) m2, vec3 meanB, vec3 m2B, float nB) {
  float nA = meanN.w;
  float n = nA + nB;
  if (!(n > 0.0f)) return;
  vec3 d = meanB - vec3(meanN);
  meanN = vec4(vec3(meanN) + d * (nB / n), n);
  m2 = m2 + m2B + d * d * (nA * nB / n);
}

PLUME_NS_END

#endif

// The blackbody table's layout (core/blackbody.h), shared by the host that fills it and the
// shaders and tests that read it: BB_TABLE_SIZE entries of the normalised blackbody in linear
// Rec.709, spaced evenly in log T from BB_TABLE_MIN_K to BB_TABLE_MAX_K. Beyond the last entry
// the colour falls as (BB_TABLE_MAX_K / T)^4 (the Rayleigh-Jeans limit of a spectrum normalised
// by its own peak); at or below BB_TABLE_MIN_K (100 K) it is 0. The reader supplies the entries
// through the macro BB_TABLE(i) (a vec3), in the manner of PNanoVDB's accessors.
#ifndef PLUME_SHARED_BLACKBODY_H
#define PLUME_SHARED_BLACKBODY_H

#include "common.h"

PLUME_NS_BEGIN

const uint BB_TABLE_SIZE = 4096u;
const float BB_TABLE_MIN_K = 100.0f;
const float BB_TABLE_MAX_K = 1.0e6f;
const float BB_TABLE_LOG_RANGE = 9.21034037197618f;  // ln(BB_TABLE_MAX_K / BB_TABLE_MIN_K)

// The temperature of entry i.
PLUME_FN float bb_table_kelvin(uint i) {
  return BB_TABLE_MIN_K * exp(BB_TABLE_LOG_RANGE * float(i) / float(BB_TABLE_SIZE - 1u));
}

#ifdef BB_TABLE
// The normalised blackbody at T kelvin from the table.
PLUME_FN vec3 bb_lookup(float kelvin) {
  if (!(kelvin > BB_TABLE_MIN_K)) return vec3(0.0f);  // also NaN
  if (kelvin >= BB_TABLE_MAX_K) {
    float r = BB_TABLE_MAX_K / kelvin;
    return BB_TABLE(BB_TABLE_SIZE - 1u) * (r * r * r * r);
  }
  float x = log(kelvin / BB_TABLE_MIN_K) / BB_TABLE_LOG_RANGE * float(BB_TABLE_SIZE - 1u);
  uint i = min(uint(x), BB_TABLE_SIZE - 2u);
  float f = x - float(i);
  return BB_TABLE(i) * (1.0f - f) + BB_TABLE(i + 1u) * f;
}
#endif

PLUME_NS_END

#endif

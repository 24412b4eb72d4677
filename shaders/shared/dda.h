// A 3D DDA over a grid of cubic cells (Amanatides & Woo 1987), as a small state machine so the
// caller decides what to do per cell (pbrt-v4's majorant iterator in the same spirit). The ray
// is o + t d in the grid's space; t keeps the caller's units (world units for Plume: d is the
// world direction mapped to index space, not normalised).
#ifndef PLUME_SHARED_DDA_H
#define PLUME_SHARED_DDA_H

#include "common.h"

PLUME_NS_BEGIN

const float DDA_INF = 3.0e38f;

struct DdaState {
  float t;       // start of the next segment
  float tEnd;    // end of the ray inside the grid
  ivec3 cell;
  ivec3 stepDir;
  vec3 tNext;    // t at which the ray crosses the next boundary on each axis
  vec3 tDelta;   // t between boundaries on each axis
  ivec3 dims;
};

// The per-axis constants of a walk along d over cells of size cellSize (stepDir, tDelta): set
// once per ray, then dda_enter (re)starts the walk in any grid of such cells. Walks that restart
// a DDA at every brick (the mean field's voxels, the majorant bricks under a coarse cell) keep
// these out of their loops, where a SIMD back end pays for every value a loop writes
// (notes/bench/kernels.md "Session 29").
PLUME_FN void dda_axes(INOUT(DdaState) s, vec3 d, float cellSize) {
  for (int a = 0; a < 3; ++a) {
    if (abs(d[a]) < 1e-30f) {
      s.stepDir[a] = 0;
      s.tDelta[a] = DDA_INF;
    } else {
      s.stepDir[a] = d[a] > 0.0f ? 1 : -1;
      s.tDelta[a] = cellSize / abs(d[a]);
    }
  }
}

// Clips [tMin, tMax] to the grid [origin, origin + s.dims * cellSize] and starts the walk there
// (s.dims and dda_axes's constants set before). Returns false when the ray misses the grid.
PLUME_FN bool dda_enter(INOUT(DdaState) s, vec3 o, vec3 d, float tMin, float tMax, vec3 origin, float cellSize) {
  float t0 = tMin;
  float t1 = tMax;
  for (int a = 0; a < 3; ++a) {
    float lo = origin[a];
    float hi = origin[a] + float(s.dims[a]) * cellSize;
    if (abs(d[a]) < 1e-30f) {
      if (o[a] < lo || o[a] >= hi) t1 = -1.0f;
    } else {
      float ta = (lo - o[a]) / d[a];
      float tb = (hi - o[a]) / d[a];
      t0 = max(t0, min(ta, tb));
      t1 = min(t1, max(ta, tb));
    }
  }
  s.t = t0;
  s.tEnd = t1;
  if (!(t0 < t1)) return false;
  vec3 p = o + t0 * d;
  for (int a = 0; a < 3; ++a) {
    s.cell[a] = clamp(int(floor((p[a] - origin[a]) / cellSize)), 0, s.dims[a] - 1);
    if (abs(d[a]) < 1e-30f) {
      s.tNext[a] = DDA_INF;
    } else {
      float boundary = origin[a] + float(s.cell[a] + (d[a] > 0.0f ? 1 : 0)) * cellSize;
      s.tNext[a] = (boundary - o[a]) / d[a];
    }
  }
  return true;
}

// Clips [tMin, tMax] to the grid [origin, origin + dims * cellSize] and sets up the walk.
// Returns false when the ray misses the grid.
PLUME_FN bool dda_init(OUT(DdaState) s, vec3 o, vec3 d, float tMin, float tMax, vec3 origin,
                       float cellSize, ivec3 dims) {
  s.dims = dims;
  dda_axes(s, d, cellSize);
  return dda_enter(s, o, d, tMin, tMax, origin, cellSize);
}

// The next segment [t0, t1) and its cell; false when the ray has left the grid. Written with
// component masks instead of a dynamically indexed axis: SIMD back ends (lavapipe) handle a
// per-lane vector index poorly. Axes that tie step together (the ray crosses an edge).
PLUME_FN bool dda_next(INOUT(DdaState) s, OUT(float) t0, OUT(float) t1, OUT(ivec3) cell) {
  cell = s.cell;
  t0 = s.t;
  t1 = s.t;
  if (!(s.t < s.tEnd)) return false;
  float tMin = min(s.tNext.x, min(s.tNext.y, s.tNext.z));
  vec3 stepMask = vec3(equal(s.tNext, vec3(tMin)));
  t1 = min(tMin, s.tEnd);
  s.t = t1;
  s.cell += ivec3(stepMask) * s.stepDir;
  s.tNext += stepMask * s.tDelta;
  if (any(lessThan(s.cell, ivec3(0))) || any(greaterThanEqual(s.cell, s.dims))) s.t = s.tEnd;
  return true;
}

PLUME_NS_END

#endif

// One step of a path (DESIGN §4.1, §4.3), written once for the path tracer (pt/integrator.glsl:
// pt_extend, pt_shade) and ReSTIR's path-traced tail (restir/shade.glsl: rs_tail_segment):
// - the segment rule: a ray ends at the nearer of the medium's real collision (delta tracking,
//   gathering the medium's emission on the way) and the first surface, a vertex either way
//   (path_segment, path_has_vertex, path_vertex);
// - scattering at the vertex: Russian roulette, then the next direction by the vertex's phase
//   function or BSDF (path_roulette, path_scatter).
// The callers keep their own control flow (the path tracer's extension and shading are separate
// kernels; the tail walks several segments per dispatch) and their own estimators around these
// steps: what emission, emitter hits and escaping rays add, which vertices take next-event
// estimation, and the roulette's survival probability. Each call site inlines only the code its
// variant compiles (on lavapipe both sides of an `if` run).
// Requires volume/bindings.glsl, scene/bindings.glsl, and surface/surfaces.glsl with
// PLUME_HAS_SURFACES.
#ifndef PLUME_INTEGRATOR_PATH_GLSL
#define PLUME_INTEGRATOR_PATH_GLSL

#include "../shared/rng.h"
#include "../volume/grid.glsl"
#include "../volume/walk.glsl"
#include "vertex.glsl"

// Where a ray's segment ends.
struct PathSegment {
  bool collided;  // a real collision in the medium, before any surface
  float t;        // distance along the ray to the vertex: the collision's, else the surface hit's
#ifdef PLUME_HAS_EMISSION
  vec3 emitted;  // the medium's emission along the segment (vol_sample_collision_emitting)
#endif
#ifdef PLUME_HAS_SURFACES
  BvhHit hit;  // the first surface along the ray; prim BVH_NONE where there is none
#endif
};

// Tracks the ray (x, w) to the end of its segment: the first surface, then delta tracking up to
// it (draws from rng: the tracking's).
PathSegment path_segment(vec3 x, vec3 w, inout RngState rng) {
  PathSegment s;
  float tMax = DDA_INF;
#ifdef PLUME_HAS_SURFACES
  s.hit = bvh_closest(x, w, 0.0f, SURF_FAR);
  if (s.hit.prim != BVH_NONE) tMax = s.hit.t;
#endif
  float t;
#ifdef PLUME_HAS_EMISSION
  s.collided = vol_sample_collision_emitting(x, w, tMax, rng, t, s.emitted);
#else
  s.collided = vol_sample_collision(x, w, tMax, rng, t);
#endif
  s.t = t;
#ifdef PLUME_HAS_SURFACES
  if (!s.collided) s.t = s.hit.t;
#endif
  return s;
}

// Whether the segment ends at a surface (before any collision in the medium).
bool path_hits_surface(PathSegment s) {
#ifdef PLUME_HAS_SURFACES
  return !s.collided && s.hit.prim != BVH_NONE;
#else
  return false;
#endif
}

// Whether the segment ends in a vertex; otherwise the ray leaves the scene.
bool path_has_vertex(PathSegment s) { return s.collided || path_hits_surface(s); }

#ifdef PLUME_HAS_EMISSION
// The medium's emission along the segment into a path of throughput beta: delta tracking gathers
// sigma_t Le / majorant at every tentative collision, and (1 - albedo) sigma_t is sigma_a.
vec3 path_emission(PathSegment s, vec3 beta) { return beta * (vec3(1.0f) - vtx_albedo(VERTEX_MEDIUM)) * s.emitted; }
#endif

// The vertex the segment ends in (where path_has_vertex), with x moved along w to it; a medium
// collision multiplies beta by delta tracking's collision weight, the albedo.
PathVertex path_vertex(PathSegment s, inout vec3 x, vec3 w, inout vec3 beta) {
  x += s.t * w;
#ifdef PLUME_HAS_SURFACES
  if (!s.collided) {
    PathVertex v = vtx_surface(x, w, s.hit.prim, vec3(0.0f));
    v.ns = surf_shading_normal(s.hit.prim, vec2(s.hit.u, s.hit.v), v.n);
    return v;
  }
#endif
  beta *= vtx_albedo(VERTEX_MEDIUM);
  return vtx_medium(x, w);
}

// Russian roulette at vertex `index` (1-based) of a path, from frame.rrStartBounce on: the path
// survives with probability q (one draw) and its throughput beta is divided by q.
bool path_roulette(uint index, float q, inout RngState rng, inout vec3 beta) {
  if (index < frame.rrStartBounce) return true;
  if (rng_float(rng) >= q) return false;
  beta /= q;
  return true;
}

// The direction leaving vertex v, sampled by its phase function or BSDF (vtx_at_sample, from u):
// beta times f cos / pdf, and (x, w) the ray that leaves v, pdf the direction's density. False
// where no direction was produced: the path ends (x and w are left as they were).
bool path_scatter(PathVertex v, vec2 u, inout vec3 beta, inout vec3 x, inout vec3 w, out float pdf) {
  vec3 next;
  beta *= vtx_at_sample(v, u, next, pdf);
  if (!(pdf > 0.0f)) return false;
  x = vtx_at_origin(v, next);
  w = next;
  return true;
}

#endif

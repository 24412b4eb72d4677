// A path vertex has a kind, and what depends on it is decided here and nowhere else: the local
// scattering function (a medium's phase function; a surface's BSDF next), its sampling, the
// throughput of the vertex itself, and the Jacobian of ReSTIR's shift at it (DESIGN §4.2 step 4:
// a medium vertex's (t, w) coordinates are copied, Jacobian 1; a surface vertex will reconnect,
// Jacobian cosine ratio × squared-distance ratio).
// The path tracer's vertices carry their place and, on a surface, the triangle and shading normal
// (PathVertex and the vtx_at_* functions; PLUME_HAS_SURFACES compiles the surface kind in).
// Requires scene/bindings.glsl (the medium's albedo and g), and surface/surfaces.glsl with
// PLUME_HAS_SURFACES.
#ifndef PLUME_INTEGRATOR_VERTEX_GLSL
#define PLUME_INTEGRATOR_VERTEX_GLSL

#include "../shared/phase.h"

const uint VERTEX_MEDIUM = 0u;   // a real collision in a medium
const uint VERTEX_SURFACE = 1u;  // a surface hit (BSDF of its triangle's surface)

// The kind of vertex i (1-based) of a path whose kinds are packed one bit each (RsPathHead.kinds).
uint vtx_kind(uint kinds, uint i) { return (kinds >> (i - 1u)) & 1u; }

// Scattering at the vertex, from a path arriving along wIn to wOut (per unit solid angle of wOut).
float vtx_scatter(uint kind, vec3 wIn, vec3 wOut) { return ph_hg(dot(wIn, wOut), frame.g); }

// A direction sampled in proportion to vtx_scatter (whose value is then its pdf).
vec3 vtx_sample(uint kind, vec3 wIn, vec2 u) { return ph_hg_sample(wIn, frame.g, u); }

// The vertex's single-scattering albedo sigma_s / sigma_t: a medium vertex contributes
// sigma_t * albedo to a path in the (t, w) measure, and delta tracking's collision weight is the
// albedo alone.
vec3 vtx_albedo(uint kind) { return frame.albedo; }

// The Jacobian of the shift at the vertex (copied (t, w) coordinates: 1).
float vtx_shift_jacobian(uint kind) { return 1.0f; }

// A path vertex with what its scattering needs: a medium collision is its place and the arriving
// direction; a surface hit adds the triangle, its front geometric normal and the shading normal.
// Directions w point away from the vertex (towards a light, or the next vertex).
struct PathVertex {
  uint kind;
  vec3 x;
  vec3 rayDir;  // the arriving ray's propagation direction
  uint prim;    // VERTEX_SURFACE: the triangle (input index)
  vec3 n;       // VERTEX_SURFACE: geometric normal of the front side
  vec3 ns;      // VERTEX_SURFACE: shading normal
};

PathVertex vtx_medium(vec3 x, vec3 rayDir) {
  PathVertex v;
  v.kind = VERTEX_MEDIUM;
  v.x = x;
  v.rayDir = rayDir;
  v.prim = 0u;
  v.n = vec3(0.0f);
  v.ns = vec3(0.0f);
  return v;
}

#ifdef PLUME_HAS_SURFACES
PathVertex vtx_surface(vec3 x, vec3 rayDir, uint prim, vec3 ns) {
  PathVertex v = vtx_medium(x, rayDir);
  v.kind = VERTEX_SURFACE;
  v.prim = prim;
  v.n = surf_normal(prim);
  v.ns = ns;
  return v;
}

// w in the shading frame of a surface vertex (z: the shading normal).
vec3 vtx_local(PathVertex v, vec3 w) {
  vec3 s;
  vec3 t;
  plume_onb(v.ns, s, t);
  return vec3(dot(w, s), dot(w, t), dot(w, v.ns));
}

// Whether w leaves on the side the path arrived from (a reflection; nothing is transmitted).
bool vtx_reflects(PathVertex v, vec3 w) { return dot(v.n, w) * dot(v.n, v.rayDir) < 0.0f; }
#endif

#ifdef PLUME_HAS_EMITTERS
// The vertex's receiver normal for the light tree (shared/light_tree.h): on a surface its
// geometric normal on the side the path arrived from, the only side light reaches it from; 0 in
// a medium (the phase function takes light from every direction).
vec3 vtx_receiver(PathVertex v) {
  if (v.kind == VERTEX_SURFACE) return surf_receiver(v.prim, -v.rayDir);
  return vec3(0.0f);
}
#endif

// Light arriving from w scattered along -rayDir: the phase function, or f(wo, w) |cos| at the
// shading normal (0 across the geometric normal).
vec3 vtx_at_scatter(PathVertex v, vec3 w) {
#ifdef PLUME_HAS_SURFACES
  if (v.kind == VERTEX_SURFACE) {
    if (!vtx_reflects(v, w)) return vec3(0.0f);
    vec3 wi = vtx_local(v, w);
    return bsdf_eval(surf_bsdf(v.prim), vtx_local(v, -v.rayDir), wi) * abs(wi.z);
  }
#endif
  return vec3(vtx_scatter(VERTEX_MEDIUM, v.rayDir, w));
}

// The solid-angle density with which vtx_at_sample picks w.
float vtx_at_pdf(PathVertex v, vec3 w) {
#ifdef PLUME_HAS_SURFACES
  if (v.kind == VERTEX_SURFACE) {
    return vtx_reflects(v, w) ? bsdf_pdf(surf_bsdf(v.prim), vtx_local(v, -v.rayDir), vtx_local(v, w)) : 0.0f;
  }
#endif
  return vtx_scatter(VERTEX_MEDIUM, v.rayDir, w);
}

// A unit direction w and its density; returns vtx_at_scatter(w) / pdf, with pdf 0 where none was
// produced (a GGX reflection below the horizon, or across the geometric normal).
vec3 vtx_at_sample(PathVertex v, vec2 u, out vec3 w, out float pdf) {
#ifdef PLUME_HAS_SURFACES
  if (v.kind == VERTEX_SURFACE) {
    vec3 s;
    vec3 t;
    plume_onb(v.ns, s, t);
    vec3 wi;
    vec3 weight = bsdf_sample(surf_bsdf(v.prim), vtx_local(v, -v.rayDir), u, wi, pdf);
    w = normalize(wi.x * s + wi.y * t + wi.z * v.ns);
    if (!(pdf > 0.0f) || !vtx_reflects(v, w)) {
      pdf = 0.0f;
      return vec3(0.0f);
    }
    return weight;
  }
#endif
  w = normalize(vtx_sample(VERTEX_MEDIUM, v.rayDir, u));
  pdf = vtx_scatter(VERTEX_MEDIUM, v.rayDir, w);  // a medium vertex samples its phase exactly
  return vec3(1.0f);
}

// Where a ray from the vertex towards w starts: a surface pushes it off to w's side.
vec3 vtx_at_origin(PathVertex v, vec3 w) {
#ifdef PLUME_HAS_SURFACES
  if (v.kind == VERTEX_SURFACE) return surf_offset_origin(v.x, v.n, w);
#endif
  return v.x;
}

#endif

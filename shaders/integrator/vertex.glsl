// A path vertex has a kind, and what depends on it is decided here and nowhere else: the local
// scattering function (a medium's phase function; a surface's BSDF next), its sampling, the
// throughput of the vertex itself, and the Jacobian of ReSTIR's shift at it (DESIGN §4.2 step 4:
// a medium vertex's (t, w) coordinates are copied, Jacobian 1; a surface vertex will reconnect,
// Jacobian cosine ratio × squared-distance ratio).
// Requires scene/bindings.glsl (the medium's albedo and g).
#ifndef PLUME_INTEGRATOR_VERTEX_GLSL
#define PLUME_INTEGRATOR_VERTEX_GLSL

#include "../shared/phase.h"

const uint VERTEX_MEDIUM = 0u;  // a real collision in a medium

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

#endif

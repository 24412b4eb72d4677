// Surface BSDFs, evaluated and sampled in one place (DESIGN §2 "Surfaces"; shared by C++ and
// GLSL like phase.h): Lambertian diffuse and a GGX microfacet conductor (isotropic roughness
// alpha, Schlick's Fresnel from an RGB f0), sampled by the distribution of visible normals
// (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4)).
//
// Directions are in the local shading frame: z is the shading normal of the triangle's front
// side (the side from which its vertices run counter-clockwise). Unlike phase.h, both directions
// point AWAY from the surface (pbrt's convention): `wo` towards where the path came from (the
// camera side, -ray direction), `wi` towards where it goes next (the light). f(wo, wi) excludes
// the cosine; `bsdf_sample` returns f |wi.z| / pdf.
//
// Front and back: both BSDFs are two-sided. Seen from the back (wo.z < 0) a surface reflects as
// the mirror image of its front, f(wo, wi) = f(M wo, M wi) with M: z -> -z, so a ground plane or
// a thin sheet looks the same from either side whatever its winding. Nothing is transmitted: wo and
// wi on opposite sides give 0. Emission (an area light) leaves the front side only; that is the
// light's rule, not the BSDF's. Shading normals only shade: the caller decides sides with the
// geometric normal.
#ifndef PLUME_SHARED_BSDF_H
#define PLUME_SHARED_BSDF_H

#include "common.h"

PLUME_NS_BEGIN

const uint BSDF_DIFFUSE = 0u;
const uint BSDF_CONDUCTOR = 1u;
// Below this alpha the GGX lobe is narrower than float resolves in D and the pdf (1 / (pi alpha^2)
// at the peak); smaller roughnesses are clamped to it.
const float BSDF_MIN_ALPHA = 1e-3f;

struct Bsdf {
  vec3 color;   // diffuse: albedo; conductor: f0, the reflectance at normal incidence
  uint type;    // BSDF_*
  float alpha;  // conductor: GGX alpha (isotropic)
  float pad0;
  float pad1;
  float pad2;
};

// --- Lambert -------------------------------------------------------------------------------------
// f = albedo / pi; cosine-weighted sampling on wo's side, pdf |wi.z| / pi.
PLUME_FN float bsdf_lambert_pdf(vec3 wo, vec3 wi) {
  return wo.z * wi.z > 0.0f ? abs(wi.z) * PLUME_INV_PI : 0.0f;
}

PLUME_FN vec3 bsdf_lambert_sample(vec3 wo, vec2 u) {
  float r = sqrt(u.x);
  float phi = 2.0f * PLUME_PI * u.y;
  float z = sqrt(max(0.0f, 1.0f - u.x));
  return vec3(r * cos(phi), r * sin(phi), wo.z < 0.0f ? -z : z);
}

// --- GGX (Trowbridge-Reitz), isotropic, in the upper hemisphere ----------------------------------
// Normal distribution D(h) = alpha^2 / (pi (h.z^2 (alpha^2 - 1) + 1)^2) for a unit h, h.z > 0,
// with the denominator's 1 - h.z^2 written as h.x^2 + h.y^2: near the peak of a small alpha the
// first form cancels (at alpha 1e-3 its rounding changed the pdf by tens of percent).
PLUME_FN float bsdf_ggx_d(vec3 h, float alpha) {
  float a2 = alpha * alpha;
  float k = h.x * h.x + h.y * h.y + a2 * h.z * h.z;
  return h.z > 0.0f ? a2 / (PLUME_PI * k * k) : 0.0f;
}

// Smith's Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2.
PLUME_FN float bsdf_ggx_lambda(vec3 w, float alpha) {
  float t2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
  return 0.5f * (sqrt(1.0f + alpha * alpha * t2) - 1.0f);
}

PLUME_FN float bsdf_ggx_g1(vec3 w, float alpha) { return 1.0f / (1.0f + bsdf_ggx_lambda(w, alpha)); }

// Height-correlated masking-shadowing G2(wo, wi) = 1 / (1 + Lambda(wo) + Lambda(wi)).
PLUME_FN float bsdf_ggx_g2(vec3 wo, vec3 wi, float alpha) {
  return 1.0f / (1.0f + bsdf_ggx_lambda(wo, alpha) + bsdf_ggx_lambda(wi, alpha));
}

PLUME_FN vec3 bsdf_schlick(vec3 f0, float cosTheta) {
  float m = clamp(1.0f - cosTheta, 0.0f, 1.0f);
  float m2 = m * m;
  return f0 + (vec3(1.0f) - f0) * (m2 * m2 * m);
}

// A visible normal for wo (wo.z > 0), Heitz 2018 listing: stretch wo to the hemisphere
// configuration, sample the projected disk (warped towards the visible half), unstretch.
PLUME_FN vec3 bsdf_ggx_sample_vndf(vec3 wo, float alpha, vec2 u) {
  vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = lensq > 0.0f ? vec3(-vh.y, vh.x, 0.0f) / sqrt(lensq) : vec3(1.0f, 0.0f, 0.0f);
  vec3 t2 = cross(vh, t1);
  float r = sqrt(u.x);
  float phi = 2.0f * PLUME_PI * u.y;
  float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * sqrt(max(0.0f, 1.0f - p1 * p1)) + s * p2;
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-6f, nh.z)));
}

// f = F(wi.h) D(h) G2 / (4 wo.z wi.z), both directions in the upper hemisphere.
PLUME_FN vec3 bsdf_ggx_eval(vec3 f0, float alpha, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return vec3(0.0f);
  vec3 h = normalize(wo + wi);
  return bsdf_schlick(f0, dot(wi, h)) * (bsdf_ggx_d(h, alpha) * bsdf_ggx_g2(wo, wi, alpha) / (4.0f * wo.z * wi.z));
}

// The density of wi = reflect(wo, h) with h ~ D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z: the
// Jacobian of the reflection is 1 / (4 wo.h), so pdf(wi) = G1(wo) D(h) / (4 wo.z).
PLUME_FN float bsdf_ggx_pdf(float alpha, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  vec3 h = normalize(wo + wi);
  return bsdf_ggx_g1(wo, alpha) * bsdf_ggx_d(h, alpha) / (4.0f * wo.z);
}

// --- The BSDF of a material ----------------------------------------------------------------------
PLUME_FN float bsdf_alpha(Bsdf m) { return max(m.alpha, BSDF_MIN_ALPHA); }

// f(wo, wi) (no cosine), both sides.
PLUME_FN vec3 bsdf_eval(Bsdf m, vec3 wo, vec3 wi) {
  if (wo.z * wi.z <= 0.0f) return vec3(0.0f);
  if (m.type == BSDF_DIFFUSE) return m.color * PLUME_INV_PI;
  float s = wo.z < 0.0f ? -1.0f : 1.0f;  // the back side mirrors the front
  return bsdf_ggx_eval(m.color, bsdf_alpha(m), vec3(wo.x, wo.y, s * wo.z), vec3(wi.x, wi.y, s * wi.z));
}

// The solid-angle density with which bsdf_sample picks wi.
PLUME_FN float bsdf_pdf(Bsdf m, vec3 wo, vec3 wi) {
  if (wo.z * wi.z <= 0.0f) return 0.0f;
  if (m.type == BSDF_DIFFUSE) return bsdf_lambert_pdf(wo, wi);
  float s = wo.z < 0.0f ? -1.0f : 1.0f;
  return bsdf_ggx_pdf(bsdf_alpha(m), vec3(wo.x, wo.y, s * wo.z), vec3(wi.x, wi.y, s * wi.z));
}

// Samples wi; returns f |wi.z| / pdf, and pdf = 0 (weight 0) when no direction was produced
// (a GGX reflection below the horizon: that energy is lost, as in the single-scattering model).
PLUME_FN vec3 bsdf_sample(Bsdf m, vec3 wo, vec2 u, OUT(vec3) wi, OUT(float) pdf) {
  wi = vec3(0.0f, 0.0f, 1.0f);
  pdf = 0.0f;
  if (wo.z == 0.0f) return vec3(0.0f);
  if (m.type == BSDF_DIFFUSE) {
    wi = bsdf_lambert_sample(wo, u);
    pdf = bsdf_lambert_pdf(wo, wi);
    return pdf > 0.0f ? m.color : vec3(0.0f);  // f cos / pdf = albedo
  }
  float s = wo.z < 0.0f ? -1.0f : 1.0f;
  float alpha = bsdf_alpha(m);
  vec3 o = vec3(wo.x, wo.y, s * wo.z);
  vec3 h = bsdf_ggx_sample_vndf(o, alpha, u);
  vec3 i = 2.0f * dot(o, h) * h - o;
  if (i.z <= 0.0f) return vec3(0.0f);
  wi = vec3(i.x, i.y, s * i.z);
  // bsdf_ggx_pdf from the sampled h: the h that bsdf_ggx_pdf rebuilds as normalize(o + i) cancels
  // at grazing reflection (o.xy ~ -i.xy), which matters where D is narrow.
  pdf = bsdf_ggx_g1(o, alpha) * bsdf_ggx_d(h, alpha) / (4.0f * o.z);
  // f cos / pdf = F G2 / G1(wo), written out to avoid D / D.
  float lo = bsdf_ggx_lambda(o, alpha);
  return pdf > 0.0f ? bsdf_schlick(m.color, dot(i, h)) * ((1.0f + lo) / (1.0f + lo + bsdf_ggx_lambda(i, alpha))) : vec3(0.0f);
}

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::Bsdf) == 32, "Bsdf layout");
static_assert(offsetof(plume::shared::Bsdf, type) == 12, "Bsdf layout");
static_assert(offsetof(plume::shared::Bsdf, alpha) == 16, "Bsdf layout");
#endif

#endif

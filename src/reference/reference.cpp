#include "reference/reference.h"

#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "media/vdb_loader.h"
#include "reference/emission.h"
#include "reference/environment.h"
#include "reference/medium.h"
#include "reference/surfaces.h"
#include "shaders/shared/bsdf.h"
#include "shaders/shared/phase.h"
#include "shaders/shared/sampling.h"

#include <glm/geometric.hpp>
#include <glm/glm.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

namespace plume::ref {
namespace {

using glm::dvec3;
namespace sh = plume::shared;

// A light prepared for sampling: everything derived once per render.
struct PreparedLight {
  LightType type;
  dvec3 dir{0};         // sun: unit vector towards the sun
  float versine = 0.0f;  // sun: the disk's 1 - cos(angular radius); 0 = a delta direction
  dvec3 radiance{0};    // sun with a disk: L = E / (pi sin^2 alpha); environment: L
  dvec3 irradiance{0};  // delta sun
  dvec3 position{0};    // point
  dvec3 intensity{0};   // point
  std::shared_ptr<const ReferenceEnvironmentMap> map;  // environment with a map
};

struct Context {
  const ReferenceMedium* medium;
  std::vector<PreparedLight> lights;
  dvec3 albedo;
  float g;
  int maxBounces;
  int rrStartBounce;
  dvec3 environment{0};  // sum of constant environment radiance seen by escaping camera rays
  const ReferenceEnvironmentMap* map = nullptr;  // and the map's (at most one)
  const ReferenceEmission* emission = nullptr;  // the medium emits
  const ReferenceSurfaces* surfaces = nullptr;  // null: the scene has none
  EmitterStrategy emitterStrategy = EmitterStrategy::Mis;
  TrackingStats* tracking;
};

dvec3 toD(glm::vec3 v) { return dvec3(v); }

std::vector<PreparedLight> prepareLights(const Scene& scene) {
  std::vector<PreparedLight> out;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    PreparedLight p;
    p.type = l.type;
    switch (l.type) {
      case LightType::Sun: {
        p.dir = glm::normalize(toD(l.toLight));
        double alpha = glm::radians(double(l.angularRadiusDeg));
        if (alpha > 0) {
          p.versine = float(2.0 * std::sin(0.5 * alpha) * std::sin(0.5 * alpha));
          double sin2 = std::sin(alpha) * std::sin(alpha);
          p.radiance = toD(l.irradiance) / (M_PI * sin2);
        } else {
          p.irradiance = toD(l.irradiance);
        }
        break;
      }
      case LightType::Point:
        p.position = toD(l.position);
        p.intensity = toD(l.intensity);
        break;
      case LightType::Environment:
        p.radiance = toD(l.radiance) * double(l.scale);
        if (!l.map.empty()) p.map = std::make_shared<ReferenceEnvironmentMap>(l, scene.path + strf(": lights[%zu].map", i));
        break;
    }
    out.push_back(p);
  }
  return out;
}

double phase(double cosTheta, float g) { return sh::ph_hg(float(cosTheta), g); }

// Veach's power heuristic (beta = 2) for a sample of density pdfA against a strategy of density pdfB.
double powerHeuristic(double pdfA, double pdfB) {
  const double a = pdfA * pdfA, b = pdfB * pdfB;
  return a > 0.0 ? a / (a + b) : 0.0;
}

// A scattering vertex, the one place that dispatches on its kind (STYLE rule 2): a real collision
// in the medium, where light scatters by the HG phase function, or a surface hit, where it
// reflects by the surface's BSDF times the cosine at the shading normal (shared/bsdf.h, in the
// shading frame; directions on opposite sides of the geometric normal give 0: nothing is
// transmitted, and shading normals only shade). `rayDir` is the arriving ray's propagation
// direction; w is a direction away from the vertex (towards a light, or the next vertex).
struct Vertex {
  dvec3 x{0};
  dvec3 rayDir{0};
  const SurfaceHit* hit = nullptr;  // null: a medium vertex
  const sh::Bsdf* bsdf = nullptr;
  dvec3 s{0}, t{0};                 // surface: tangents of the shading frame (z = hit->shading)

  static Vertex medium(const dvec3& x, const dvec3& rayDir) { return {x, rayDir}; }
  static Vertex surface(const ReferenceSurfaces& surfaces, const SurfaceHit& hit, const dvec3& rayDir) {
    Vertex v{hit.point, rayDir, &hit, &surfaces.bsdf(hit)};
    // Duff et al. 2017, "Building an Orthonormal Basis, Revisited".
    const dvec3& n = hit.shading;
    const double sign = std::copysign(1.0, n.z), a = -1.0 / (sign + n.z), b = n.x * n.y * a;
    v.s = dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    v.t = dvec3(b, sign + n.y * n.y * a, -n.y);
    return v;
  }

  // Where a ray towards w starts: surfaces push it off the surface, to w's side.
  dvec3 origin(const dvec3& w) const { return hit ? ReferenceSurfaces::offsetOrigin(x, hit->normal, w) : x; }
  glm::vec3 local(const dvec3& w) const { return glm::vec3(glm::dot(w, s), glm::dot(w, t), glm::dot(w, hit->shading)); }
  // Whether wo = -rayDir and w lie on the same side of the geometric normal (reflection).
  bool reflects(const dvec3& w) const { return glm::dot(hit->normal, w) * glm::dot(hit->normal, rayDir) < 0.0; }

  // Light arriving from w scattered along -rayDir: phase(w . rayDir), or f(wo, w) |cos|.
  dvec3 scatter(float g, const dvec3& w) const {
    if (!hit) return dvec3(phase(glm::dot(w, rayDir), g));
    if (!reflects(w)) return dvec3(0.0);
    const glm::vec3 wi = local(w);
    return dvec3(sh::bsdf_eval(*bsdf, local(-rayDir), wi)) * double(std::abs(wi.z));
  }
  // The solid-angle density with which sample() picks w.
  double pdf(float g, const dvec3& w) const {
    if (!hit) return phase(glm::dot(w, rayDir), g);
    return reflects(w) ? double(sh::bsdf_pdf(*bsdf, local(-rayDir), local(w))) : 0.0;
  }
  // A direction w (not normalised for media) and its density; returns scatter(w) / pdf (0 with
  // pdf = 0 when the BSDF produced none).
  dvec3 sample(float g, glm::vec2 u, dvec3& w, double& pdf) const {
    if (!hit) {
      w = dvec3(sh::ph_hg_sample(glm::vec3(rayDir), g, u));
      pdf = phase(glm::dot(w, rayDir), g);
      return dvec3(1.0);
    }
    glm::vec3 wi;
    float p;
    const glm::vec3 weight = sh::bsdf_sample(*bsdf, local(-rayDir), u, wi, p);
    w = glm::normalize(double(wi.x) * s + double(wi.y) * t + double(wi.z) * hit->shading);
    pdf = p;
    if (!(p > 0.0f) || !reflects(w)) {
      pdf = 0.0;
      return dvec3(0.0);
    }
    return dvec3(weight);
  }
};

// Transmittance times visibility from the vertex along w over (0, dist): ratio tracking, and any
// surface in between blocks the light (Embree any hit).
double shadow(const Context& c, const Vertex& v, const dvec3& w, double dist, Pcg32& rng,
              const ReferenceMedium::Accessor& acc) {
  const Ray ray{v.origin(w), w};
  if (c.surfaces && c.surfaces->occluded(ray, dist)) return 0.0;
  return c.medium->ratioTracking(ray, dist, rng, acc, *c.tracking);
}

// Next-event estimation to one point on the emissive triangles (area sampling in proportion to
// power), weighted by MIS against the vertex's own direction sampling.
dvec3 estimateEmitter(const Context& c, const Vertex& v, Pcg32& rng, const ReferenceMedium::Accessor& acc) {
  const double uTriangle = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  const EmitterSample e = c.surfaces->sampleEmitter(uTriangle, u1, u2);
  const dvec3 toL = e.point - v.origin(e.point - v.x);
  const double dist = glm::length(toL);
  if (!(dist > 0.0)) return dvec3(0.0);
  const dvec3 w = toL / dist;
  const double cosLight = -glm::dot(e.normal, w);
  if (cosLight <= 0.0) return dvec3(0.0);  // the back side emits nothing
  const dvec3 f = v.scatter(c.g, w);
  if (f == dvec3(0.0)) return dvec3(0.0);
  const double pdf = e.pdfArea * dist * dist / cosLight;  // per solid angle at the vertex
  const double mis = c.emitterStrategy == EmitterStrategy::Mis ? powerHeuristic(pdf, v.pdf(c.g, w)) : 1.0;
  // Stop short of the emitter's own triangle.
  const double tr = shadow(c, v, w, dist - ReferenceSurfaces::offsetLength(e.point), rng, acc);
  return e.radiance * f * (tr * mis / pdf);
}

// Next-event estimation at a scattering vertex: light arriving from direction w (travelling along
// -w) scattered towards the camera (along -rayDir), by v.scatter (DESIGN §4.1).
dvec3 estimateDirect(const Context& c, const Vertex& v, Pcg32& rng, const ReferenceMedium::Accessor& acc) {
  dvec3 sum(0);
  const double inf = std::numeric_limits<double>::infinity();
  for (const PreparedLight& l : c.lights) {
    switch (l.type) {
      case LightType::Sun: {
        if (l.versine <= 0.0f) {
          double tr = shadow(c, v, l.dir, inf, rng, acc);
          sum += l.irradiance * v.scatter(c.g, l.dir) * tr;
        } else {
          glm::vec2 u(rng.uniform(), rng.uniform());
          dvec3 w = dvec3(sh::smp_uniform_cone(glm::vec3(l.dir), l.versine, u));
          double tr = shadow(c, v, w, inf, rng, acc);
          double pdf = 1.0 / (2.0 * M_PI * double(l.versine));
          sum += l.radiance * v.scatter(c.g, w) * tr / pdf;
        }
        break;
      }
      case LightType::Point: {
        dvec3 toL = l.position - v.x;
        double dist = glm::length(toL);
        if (dist <= 0) break;
        dvec3 w = toL / dist;
        double tr = shadow(c, v, w, dist, rng, acc);
        sum += l.intensity / (dist * dist) * v.scatter(c.g, w) * tr;
        break;
      }
      case LightType::Environment: {
        if (l.map) {
          // Importance sample the map (its own distribution): weight = L * scatter / pdf * T.
          const double uTexel = (double(rng.uniform()) + double(rng.uniform()) / 16777216.0);
          const double uPhi = rng.uniform(), uCos = rng.uniform();
          double pdf;
          const dvec3 w = l.map->sample(uTexel, uPhi, uCos, pdf);
          if (!(pdf > 0)) break;
          double tr = shadow(c, v, w, inf, rng, acc);
          sum += l.map->radiance(w) * v.scatter(c.g, w) * tr / pdf;
          break;
        }
        // Importance sample the phase function or BSDF: weight = L * scatter / pdf * T.
        glm::vec2 u(rng.uniform(), rng.uniform());
        dvec3 w;
        double pdf;
        const dvec3 weight = v.sample(c.g, u, w, pdf);
        if (weight == dvec3(0.0)) break;
        double tr = shadow(c, v, w, inf, rng, acc);
        sum += l.radiance * weight * tr;
        break;
      }
    }
  }
  if (c.surfaces && c.surfaces->hasEmitters() && c.emitterStrategy != EmitterStrategy::DirectionSamplingOnly)
    sum += estimateEmitter(c, v, rng, acc);
  return sum;
}

// Le of an emissive surface reached by a path: all of it for a camera ray; after a scattering
// vertex, the MIS weight against emitter sampling at that vertex (pdfDir: the density with which
// it chose this direction, per solid angle; the light's density converted by distance^2 / cos).
dvec3 emittedAtHit(const Context& c, const SurfaceHit& hit, const Ray& ray, int scatterings, double pdfDir) {
  const dvec3 le = c.surfaces->emitted(hit, ray.direction);
  if (le == dvec3(0.0) || scatterings == 0) return le;
  switch (c.emitterStrategy) {
    case EmitterStrategy::LightSamplingOnly: return dvec3(0.0);
    case EmitterStrategy::DirectionSamplingOnly: return le;
    case EmitterStrategy::Mis: break;
  }
  const double cosLight = std::abs(glm::dot(hit.normal, ray.direction));
  const double pdfLight = c.surfaces->emitterPdfArea(hit.triangle) * hit.t * hit.t / cosLight;
  return le * powerHeuristic(pdfDir, pdfLight);
}

// One camera path. A ray ends at the nearer of the medium's delta-tracking collision and the first
// surface (the medium is tracked only up to it); both are scattering vertices and count towards
// max_bounces alike.
dvec3 tracePath(const Context& c, Ray ray, Pcg32& rng, const ReferenceMedium::Accessor& acc,
                const ReferenceEmission::Accessor* emissionAcc) {
  dvec3 radiance(0), beta(1);
  double pdfDir = 0.0;  // the density of the last sampled direction (MIS at an emitter hit)
  const double inf = std::numeric_limits<double>::infinity();
  for (int scatterings = 0;; ) {
    SurfaceHit hit;
    const bool onSurface = c.surfaces && c.surfaces->intersect(ray, inf, hit);
    const double tMax = onSurface ? hit.t : inf;
    double t;
    bool collided;
    if (c.emission) {
      // Emission along the segment: sigma_t Le / majorant at every tentative collision estimates
      // the integral of T sigma_t Le; times 1 - albedo it is the integral of T sigma_a Le. The
      // path has `scatterings` scattering vertices, at most max_bounces as next-event estimation's.
      dvec3 emitted(0);
      collided = c.medium->sampleCollision(ray, tMax, rng, acc, t, *c.tracking, [&](double s, double sigma, double maj) {
        if (sigma > 0.0) emitted += sigma / maj * c.emission->radiance(*emissionAcc, ray.origin + s * ray.direction);
      });
      radiance += beta * (dvec3(1.0) - c.albedo) * emitted;
    } else {
      collided = c.medium->sampleCollision(ray, tMax, rng, acc, t, *c.tracking);
    }
    Vertex v;
    if (collided) {
      if (++scatterings > c.maxBounces) break;
      v = Vertex::medium(ray.origin + t * ray.direction, ray.direction);
      beta *= c.albedo;  // a real collision scatters with probability albedo: weight instead
    } else if (onSurface) {
      radiance += beta * emittedAtHit(c, hit, ray, scatterings, pdfDir);
      if (++scatterings > c.maxBounces) break;
      v = Vertex::surface(*c.surfaces, hit, ray.direction);
    } else {
      // Escaped. Light sources are reached by next-event estimation after the first vertex,
      // so only camera rays add the environment seen directly.
      if (scatterings == 0) radiance += beta * c.environment;
      if (scatterings == 0 && c.map) radiance += beta * c.map->radiance(ray.direction);
      break;
    }
    radiance += beta * estimateDirect(c, v, rng, acc);
    if (scatterings >= c.rrStartBounce) {
      double q = std::min(1.0, std::max({beta.x, beta.y, beta.z}));
      if (double(rng.uniform()) >= q) break;
      beta /= q;
    }
    glm::vec2 u(rng.uniform(), rng.uniform());
    dvec3 w;
    const dvec3 weight = v.sample(c.g, u, w, pdfDir);
    if (v.hit && !(pdfDir > 0.0)) break;
    beta *= weight;
    ray = {v.origin(w), glm::normalize(w)};
  }
  return radiance;
}

struct CameraFrame {
  dvec3 position, forward, right, up;
  double tanHalfY, aspect;
};

CameraFrame cameraFrame(const Camera& cam, int frame) {
  CameraPose pose = cam.poseAt(frame);
  CameraFrame f;
  f.position = toD(pose.position);
  f.forward = glm::normalize(toD(pose.lookAt - pose.position));
  f.right = glm::normalize(glm::cross(f.forward, toD(pose.up)));  // DESIGN §2: right-handed
  f.up = glm::cross(f.right, f.forward);
  f.tanHalfY = std::tan(glm::radians(double(pose.fovY)) * 0.5);
  f.aspect = double(cam.width) / cam.height;
  return f;
}

// Box filter: a uniform point in the pixel's square; row 0 at the top.
Ray cameraRay(const CameraFrame& f, const Camera& cam, int px, int py, double u, double v) {
  double sx = (2.0 * (px + u) / cam.width - 1.0) * f.tanHalfY * f.aspect;
  double sy = (1.0 - 2.0 * (py + v) / cam.height) * f.tanHalfY;
  return {f.position, glm::normalize(f.forward + sx * f.right + sy * f.up)};
}

}  // namespace

void checkReferenceSupports(const Scene&) {}

Image renderReference(const Scene& scene, openvdb::FloatGrid::ConstPtr density,
                      const ReferenceOptions& options, ReferenceStats* statsOut) {
  checkReferenceSupports(scene);
  const Medium& m = scene.medium();
  const RenderSettings& rs = scene.render;
  const Camera& cam = scene.camera;
  ReferenceMedium medium(density, m.densityScale);
  TrackingStats tracking;

  Context ctx;
  ctx.medium = &medium;
  ctx.lights = prepareLights(scene);
  ctx.albedo = toD(m.albedo);
  ctx.g = m.g;
  ctx.maxBounces = rs.maxBounces;
  ctx.rrStartBounce = rs.rrStartBounce;
  ctx.tracking = &tracking;
  for (const PreparedLight& l : ctx.lights) {
    if (l.type == LightType::Environment && !l.map) ctx.environment += l.radiance;
    if (l.map) ctx.map = l.map.get();
  }
  std::shared_ptr<const ReferenceSurfaces> surfaces = options.surfaces;
  if (!surfaces && !scene.surfaces.empty()) surfaces = std::make_shared<const ReferenceSurfaces>(scene);
  ctx.surfaces = surfaces.get();
  ctx.emitterStrategy = options.emitterStrategy;
  std::unique_ptr<ReferenceEmission> emission;
  if (m.emission) {
    openvdb::FloatGrid::ConstPtr grid = options.emission;
    if (!grid) grid = loadFloatGrid(m.vdbPath(options.frame), m.emission->grid).grid;
    emission = std::make_unique<ReferenceEmission>(grid, *m.emission);
    ctx.emission = emission.get();
  }

  const CameraFrame frame = cameraFrame(cam, options.frame);
  const int ts = options.tileSize;
  const int tilesX = (cam.width + ts - 1) / ts, tilesY = (cam.height + ts - 1) / ts;
  Image image(cam.width, cam.height, true);
  const uint64_t frameSeed = mix64(uint64_t(uint32_t(rs.seed)) ^ mix64(uint64_t(int64_t(options.frame))));
  std::unique_ptr<ProgressBar> bar;
  if (options.progress) bar = std::make_unique<ProgressBar>(strf("reference frame %d", options.frame), uint64_t(tilesX) * tilesY);

  const auto start = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 1), [&](const tbb::blocked_range<int>& r) {
    ReferenceMedium::Accessor acc = medium.accessor();
    std::optional<ReferenceEmission::Accessor> emissionAcc;
    if (emission) emissionAcc.emplace(emission->accessor());
    for (int tile = r.begin(); tile != r.end(); ++tile) {
      const int x0 = (tile % tilesX) * ts, y0 = (tile / tilesX) * ts;
      for (int py = y0; py < std::min(y0 + ts, cam.height); ++py) {
        for (int px = x0; px < std::min(x0 + ts, cam.width); ++px) {
          Pcg32 rng(frameSeed, uint64_t(py) * uint64_t(cam.width) + uint64_t(px));
          dvec3 sum(0), sumSq(0);
          for (int s = 0; s < rs.spp; ++s) {
            double u = rng.uniform(), v = rng.uniform();
            dvec3 L = tracePath(ctx, cameraRay(frame, cam, px, py, u, v), rng, acc, emissionAcc ? &*emissionAcc : nullptr);
            sum += L;
            sumSq += L * L;
          }
          const double n = rs.spp;
          dvec3 mean = sum / n;
          dvec3 varMean = n > 1 ? glm::max(dvec3(0), (sumSq - n * mean * mean) / (n * (n - 1))) : dvec3(0);
          image.setPixel(px, py, glm::vec3(mean));
          image.setVariance(px, py, glm::vec3(varMean));
        }
      }
      if (bar) bar->advance();
    }
  });
  if (bar) bar->finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  ReferenceStats stats;
  stats.seconds = seconds;
  stats.samples = uint64_t(cam.width) * cam.height * rs.spp;
  stats.truncatedTracking = tracking.truncated.load();
  stats.trackingSteps = tracking.steps.load();
  if (surfaces) {
    stats.surfaceTriangles = surfaces->triangleCount();
    stats.emissiveTriangles = surfaces->emitterCount();
  }
  if (stats.truncatedTracking > 0) {
    logWarn(strf("frame %d: %llu tracking loops hit the step cap (%llu steps) and were truncated",
                 options.frame, (unsigned long long)stats.truncatedTracking,
                 (unsigned long long)ReferenceMedium::kMaxTrackingSteps));
  }
  setCommonMeta(image, {.mode = "reference", .spp = rs.spp, .seed = rs.seed, .frame = options.frame,
                        .maxBounces = rs.maxBounces, .device = "cpu-reference"});
  image.meta["wall_time_s"] = strf("%.3f", seconds);
  image.meta["samples_per_s"] = strf("%.0f", stats.samplesPerSecond());
  image.meta["tracking_truncated"] = std::to_string(stats.truncatedTracking);
  image.meta["tracking_steps"] = std::to_string(stats.trackingSteps);
  if (surfaces) {
    image.meta["surface_triangles"] = std::to_string(stats.surfaceTriangles);
    image.meta["emissive_triangles"] = std::to_string(stats.emissiveTriangles);
  }
  if (statsOut) *statsOut = stats;
  return image;
}

}  // namespace plume::ref

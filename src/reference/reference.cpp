#include "reference/reference.h"

#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "media/vdb_loader.h"
#include "reference/emission.h"
#include "reference/environment.h"
#include "reference/medium.h"
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

// Next-event estimation at a real collision x; `rayDir` is the path's propagation direction
// (from the camera outwards). Light arriving from direction w (travelling along -w) scatters
// towards the camera (along -rayDir): cosTheta = dot(-w, -rayDir) = dot(w, rayDir).
dvec3 estimateDirect(const Context& c, const dvec3& x, const dvec3& rayDir, Pcg32& rng,
                     const ReferenceMedium::Accessor& acc) {
  dvec3 sum(0);
  const double inf = std::numeric_limits<double>::infinity();
  for (const PreparedLight& l : c.lights) {
    switch (l.type) {
      case LightType::Sun: {
        if (l.versine <= 0.0f) {
          double tr = c.medium->ratioTracking({x, l.dir}, inf, rng, acc, *c.tracking);
          sum += l.irradiance * phase(glm::dot(l.dir, rayDir), c.g) * tr;
        } else {
          glm::vec2 u(rng.uniform(), rng.uniform());
          dvec3 w = dvec3(sh::smp_uniform_cone(glm::vec3(l.dir), l.versine, u));
          double tr = c.medium->ratioTracking({x, w}, inf, rng, acc, *c.tracking);
          double pdf = 1.0 / (2.0 * M_PI * double(l.versine));
          sum += l.radiance * phase(glm::dot(w, rayDir), c.g) * tr / pdf;
        }
        break;
      }
      case LightType::Point: {
        dvec3 toL = l.position - x;
        double dist = glm::length(toL);
        if (dist <= 0) break;
        dvec3 w = toL / dist;
        double tr = c.medium->ratioTracking({x, w}, dist, rng, acc, *c.tracking);
        sum += l.intensity / (dist * dist) * phase(glm::dot(w, rayDir), c.g) * tr;
        break;
      }
      case LightType::Environment: {
        if (l.map) {
          // Importance sample the map (its own distribution): weight = L * phase / pdf * T.
          const double uTexel = (double(rng.uniform()) + double(rng.uniform()) / 16777216.0);
          const double uPhi = rng.uniform(), uCos = rng.uniform();
          double pdf;
          const dvec3 w = l.map->sample(uTexel, uPhi, uCos, pdf);
          if (!(pdf > 0)) break;
          double tr = c.medium->ratioTracking({x, w}, inf, rng, acc, *c.tracking);
          sum += l.map->radiance(w) * phase(glm::dot(w, rayDir), c.g) * tr / pdf;
          break;
        }
        // Importance sample the phase function: weight = L * phase / pdf * T = L * T.
        glm::vec2 u(rng.uniform(), rng.uniform());
        dvec3 w = dvec3(sh::ph_hg_sample(glm::vec3(rayDir), c.g, u));
        double tr = c.medium->ratioTracking({x, w}, inf, rng, acc, *c.tracking);
        sum += l.radiance * tr;
        break;
      }
    }
  }
  return sum;
}

// One camera path. Surfaces are refused earlier (checkReferenceSupports).
dvec3 tracePath(const Context& c, Ray ray, Pcg32& rng, const ReferenceMedium::Accessor& acc,
                const ReferenceEmission::Accessor* emissionAcc) {
  dvec3 radiance(0), beta(1);
  const double inf = std::numeric_limits<double>::infinity();
  for (int scatterings = 0;; ) {
    double t;
    bool collided;
    if (c.emission) {
      // Emission along the segment: sigma_t Le / majorant at every tentative collision estimates
      // the integral of T sigma_t Le; times 1 - albedo it is the integral of T sigma_a Le. The
      // path has `scatterings` scattering vertices, at most max_bounces as next-event estimation's.
      dvec3 emitted(0);
      collided = c.medium->sampleCollision(ray, inf, rng, acc, t, *c.tracking, [&](double s, double sigma, double maj) {
        if (sigma > 0.0) emitted += sigma / maj * c.emission->radiance(*emissionAcc, ray.origin + s * ray.direction);
      });
      radiance += beta * (dvec3(1.0) - c.albedo) * emitted;
    } else {
      collided = c.medium->sampleCollision(ray, inf, rng, acc, t, *c.tracking);
    }
    if (!collided) {
      // Escaped. Light sources are reached by next-event estimation after the first vertex,
      // so only camera rays add the environment seen directly.
      if (scatterings == 0) radiance += beta * c.environment;
      if (scatterings == 0 && c.map) radiance += beta * c.map->radiance(ray.direction);
      break;
    }
    if (++scatterings > c.maxBounces) break;
    const dvec3 x = ray.origin + t * ray.direction;
    beta *= c.albedo;  // a real collision scatters with probability albedo: weight instead
    radiance += beta * estimateDirect(c, x, ray.direction, rng, acc);
    if (scatterings >= c.rrStartBounce) {
      double q = std::min(1.0, std::max({beta.x, beta.y, beta.z}));
      if (double(rng.uniform()) >= q) break;
      beta /= q;
    }
    glm::vec2 u(rng.uniform(), rng.uniform());
    ray = {x, glm::normalize(dvec3(sh::ph_hg_sample(glm::vec3(ray.direction), c.g, u)))};
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

void checkReferenceSupports(const Scene& scene) {
  refuseSurfaces(scene);  // not rendered yet (issue 12)
}

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
  if (statsOut) *statsOut = stats;
  return image;
}

}  // namespace plume::ref

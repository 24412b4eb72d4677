#include "render/features.h"

#include <algorithm>
#include <string>

namespace plume {

gpu::ShaderDefines FeatureSet::defines() const {
  gpu::ShaderDefines d;
  if (sun) d.emplace_back("PLUME_HAS_SUN", "1");
  if (point) d.emplace_back("PLUME_HAS_POINT", "1");
  if (environment) d.emplace_back("PLUME_HAS_ENV", "1");
  if (envMap) d.emplace_back("PLUME_HAS_ENV_MAP", "1");
  if (multiBounce) d.emplace_back("PLUME_MULTI_BOUNCE", "1");
  if (emission) d.emplace_back("PLUME_HAS_EMISSION", "1");
  if (blackbody) d.emplace_back("PLUME_EMISSION_BLACKBODY", "1");
  if (surfaces) d.emplace_back("PLUME_HAS_SURFACES", "1");
  if (bvhStack > 0) d.emplace_back("PLUME_BVH_STACK", std::to_string(bvhStack));
  if (emitters) d.emplace_back("PLUME_HAS_EMITTERS", "1");
  if (hardwareFilter) d.emplace_back("PLUME_HW_FILTER", "1");
  if (kernelCounters) d.emplace_back("PLUME_KERNEL_COUNTERS", "1");
  return d;
}

std::string FeatureSet::name() const {
  std::string n;
  auto add = [&](bool on, const char* s) {
    if (!on) return;
    if (!n.empty()) n += '+';
    n += s;
  };
  add(sun, "sun");
  add(point, "point");
  add(environment, "env");
  add(envMap, "envmap");
  add(multiBounce, "multi");
  add(emission, blackbody ? "blackbody" : "emission");
  add(surfaces, "surfaces");
  add(emitters, "emitters");
  add(hardwareFilter, "hwfilter");
  add(kernelCounters, "counters");
  return n.empty() ? "none" : n;
}

FeatureSet featuresOf(const Scene& scene) {
  FeatureSet f;
  for (const Light& l : scene.lights) {
    f.sun |= l.type == LightType::Sun;
    f.point |= l.type == LightType::Point;
    f.environment |= l.type == LightType::Environment;
    f.envMap |= l.type == LightType::Environment && !l.map.empty();
  }
  for (const Medium& m : scene.media) {
    f.emission |= m.emission.has_value();
    f.blackbody |= m.emission && m.emission->blackbody;
  }
  f.surfaces = !scene.surfaces.empty();
  f.emitters = std::any_of(scene.surfaces.begin(), scene.surfaces.end(), [](const Surface& s) { return s.emits(); });
  // With emission a path also gathers light along the segment after its last scattering, so one
  // bounce already needs the path loop.
  f.multiBounce = scene.render.maxBounces > 1 || (f.emission && scene.render.maxBounces >= 1);
  return f;
}

}  // namespace plume

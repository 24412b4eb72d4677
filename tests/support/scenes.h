// Lights, surfaces and a scene for tests that build scenes in code.
#pragma once

#include "scene/scene.h"

#include <glm/geometric.hpp>

#include <string>

namespace plume::test {

// A scene with only its path and a square camera of `size` pixels at `position` looking at
// `lookAt` (40° vertical field of view): what the tests' scenes start from.
inline Scene sceneWithCamera(const std::string& path, glm::vec3 position, glm::vec3 lookAt, int size) {
  Scene s;
  s.path = path;
  s.camera.base.position = position;
  s.camera.base.lookAt = lookAt;
  s.camera.base.fovY = 40.0f;
  s.camera.width = s.camera.height = size;
  return s;
}

inline Light sunLight(glm::vec3 toLight, glm::vec3 irradiance) {
  Light l;
  l.type = LightType::Sun;
  l.toLight = glm::normalize(toLight);
  l.irradiance = irradiance;
  return l;
}

inline Light skyLight(glm::vec3 radiance) {
  Light l;
  l.type = LightType::Environment;
  l.radiance = radiance;
  return l;
}

// A plane surface (diffuse by default) of the given centre, normal and size.
inline Surface planeSurface(glm::vec3 centre, glm::vec3 normal, glm::vec2 size) {
  Surface s;
  s.plane = SurfacePlane{centre, normal, size};
  return s;
}

// A black plane that emits `radiance` from its front (the side `normal` points to).
inline Surface emitterSurface(glm::vec3 centre, glm::vec3 normal, glm::vec2 size, glm::vec3 radiance) {
  Surface s = planeSurface(centre, normal, size);
  s.albedo = glm::vec3(0.0f);
  s.emission = radiance;
  return s;
}

// The noise cloud (about [0, 2]³; support/grids.h makeNoiseGrid(32, 1.0 / 16, seed)) over a
// diffuse ground plane at y = 0, seen from the front, under a sun and a constant sky.
inline Scene smokeOverGroundScene(int size, int bounces) {
  Scene s = sceneWithCamera("surface-scene", {1.0f, 1.4f, 4.6f}, {1.0f, 0.7f, 1.0f}, size);
  s.media.push_back(Medium{});
  s.medium().densityScale = 3.0f;
  s.medium().albedo = glm::vec3(0.9f);
  s.medium().g = 0.3f;
  s.lights = {sunLight({0.5f, 1.0f, 0.3f}, {3.0f, 2.8f, 2.5f}), skyLight({0.10f, 0.12f, 0.16f})};
  Surface ground = planeSurface({1.0f, 0.0f, 1.0f}, {0, 1, 0}, {8.0f, 8.0f});
  ground.albedo = glm::vec3(0.6f, 0.5f, 0.4f);
  s.surfaces.push_back(ground);
  s.render.maxBounces = bounces;
  return s;
}

// The ground scene with an occluding quad between the sun and the smoke and a glossy copper
// conductor quad (GGX, alpha 0.3) beside it.
inline Scene occluderAndConductorScene(int size, int bounces) {
  Scene s = smokeOverGroundScene(size, bounces);
  Surface occluder = planeSurface({1.4f, 2.6f, 1.2f}, {0.2f, 1.0f, 0.1f}, {1.0f, 1.0f});
  occluder.albedo = glm::vec3(0.3f);
  Surface metal = planeSurface({2.4f, 0.8f, 0.4f}, {-1.0f, 0.2f, 0.6f}, {1.2f, 1.4f});
  metal.material = SurfaceMaterial::Conductor;
  metal.roughness = 0.3f;
  metal.f0 = glm::vec3(0.95f, 0.64f, 0.54f);
  s.surfaces.push_back(occluder);
  s.surfaces.push_back(metal);
  return s;
}

// The ground scene lit only by three emissive quads (one facing down onto the ground from
// `lowQuadHeight`, its back to the camera: at 2 cm only the bounce carries its light, and the
// points of the ground next to it see its light from very close, 1/d² up to 2500, which an
// estimator without BSDF-sampled hits (ReSTIR's: emitters by NEE only) resolves slowly).
inline Scene emissiveQuadsScene(int size, int bounces, float lowQuadHeight = 0.02f) {
  Scene s = smokeOverGroundScene(size, bounces);
  s.lights.clear();
  s.surfaces.push_back(emitterSurface({0.2f, 2.4f, 1.0f}, {0.3f, -1.0f, 0.0f}, {0.5f, 0.5f}, {12.0f, 9.0f, 6.0f}));
  s.surfaces.push_back(emitterSurface({1.8f, 2.2f, 0.6f}, {-0.2f, -1.0f, 0.3f}, {0.3f, 0.6f}, {4.0f, 6.0f, 12.0f}));
  s.surfaces.push_back(emitterSurface({1.0f, lowQuadHeight, 2.6f}, {0.0f, -1.0f, 0.0f}, {0.6f, 0.6f}, {50.0f, 50.0f, 50.0f}));
  return s;
}

// The ground scene lit by small lamps facing the camera, seen directly: six in front of the
// cloud and six behind it (seen through it, lighting it from behind), each 4 cm wide (a few
// percent of a 16² image's pixel), one 30 cm lamp in front, and a dim sky. Most of the lamp
// pixels' value is the one-segment path camera -> lamp, which covers a small part of the pixel.
inline Scene lampsSeenDirectlyScene(int size, int bounces) {
  Scene s = smokeOverGroundScene(size, bounces);
  s.lights = {skyLight({0.02f, 0.025f, 0.03f})};
  const glm::vec3 toCamera = glm::normalize(s.camera.base.position - glm::vec3(1.0f, 0.8f, 1.0f));
  const float xs[3] = {0.35f, 1.0f, 1.65f};
  for (int i = 0; i < 6; ++i) {
    const glm::vec3 front(xs[i % 3], 0.35f + 0.8f * float(i / 3), 2.3f);
    const glm::vec3 back(xs[i % 3] + 0.2f, 0.5f + 0.8f * float(i / 3), -0.2f);
    s.surfaces.push_back(emitterSurface(front, toCamera, {0.04f, 0.04f}, {40.0f, 32.0f, 24.0f}));
    s.surfaces.push_back(emitterSurface(back, toCamera, {0.04f, 0.04f}, {30.0f, 36.0f, 48.0f}));
  }
  s.surfaces.push_back(emitterSurface({0.6f, 1.9f, 2.4f}, toCamera, {0.3f, 0.3f}, {6.0f, 6.0f, 6.0f}));
  return s;
}

// A thin cloud over the ground between a white wall (x = 0.3, facing +x) and a glowing wall
// (x = 1.7, emitting towards -x, the only light but a dim sky), and a black fin between them
// (x = 1) as high as both, seen from above. The ground right of the fin sees the glowing wall
// from a few centimetres to a metre away, so the paths ground -> glowing wall that reuse moves
// between pixels reconnect to it over distances and cosines that differ by large factors (the
// reconnection shift's Jacobian, shared/restir_types.h); the ground left of the fin sees none of
// it, so reconnecting a path from the right into a pixel on the left must fail (visibility).
inline Scene wallsAndFinScene(int size, int bounces) {
  Scene s = smokeOverGroundScene(size, bounces);
  s.camera.base.position = {1.0f, 3.4f, 3.0f};
  s.camera.base.lookAt = {1.0f, 0.2f, 1.0f};
  s.medium().densityScale = 0.5f;
  s.lights = {skyLight({0.02f, 0.025f, 0.03f})};
  Surface left = planeSurface({0.3f, 0.6f, 1.0f}, {1.0f, 0.0f, 0.0f}, {1.2f, 3.0f});
  left.albedo = glm::vec3(0.9f);
  Surface fin = planeSurface({1.0f, 0.6f, 1.0f}, {1.0f, 0.0f, 0.0f}, {1.2f, 3.0f});
  fin.albedo = glm::vec3(0.0f);
  s.surfaces.push_back(left);
  s.surfaces.push_back(emitterSurface({1.7f, 0.6f, 1.0f}, {-1.0f, 0.0f, 0.0f}, {1.2f, 3.0f}, {2.0f, 1.8f, 1.5f}));
  s.surfaces.push_back(fin);
  return s;
}

// A thin cloud over a white ground in front of a white wall (1 x 0.6 at z = 0.2, facing +z) that a
// horizontal sun lights head-on while it grazes the ground (cosine 0), seen from above and close:
// the ground's light is mostly the wall's bounce, whose paths camera -> ground -> wall -> sun
// reconnect at the wall (the reconnection shift's vertex 2) from a few centimetres to a metre
// away, so the shift's Jacobian (shared/restir_types.h) differs by large factors between pixels a
// few rows apart, and for a small wall in front always on the same side.
inline Scene sunlitWallScene(int size, int bounces) {
  Scene s = sceneWithCamera("sunlit-wall", {1.0f, 1.9f, 2.0f}, {1.0f, 0.0f, 0.75f}, size);
  s.media.push_back(Medium{});
  s.medium().densityScale = 0.1f;
  s.medium().albedo = glm::vec3(0.9f);
  s.medium().g = 0.3f;
  s.lights = {sunLight({0.0f, 0.0f, 1.0f}, {3.0f, 2.8f, 2.5f}), skyLight({0.02f, 0.025f, 0.03f})};
  Surface ground = planeSurface({1.0f, 0.0f, 1.0f}, {0, 1, 0}, {8.0f, 8.0f});
  ground.albedo = glm::vec3(0.8f);
  Surface wall = planeSurface({1.0f, 0.3f, 0.2f}, {0, 0, 1}, {1.0f, 0.6f});
  wall.albedo = glm::vec3(0.9f);
  s.surfaces.push_back(ground);
  s.surfaces.push_back(wall);
  s.render.maxBounces = bounces;
  return s;
}

// The scene with its camera keyed to have moved by `offset` from its base pose at frame `frame`
// (interpolated from frame 1 on: a camera that moves every frame).
inline Scene cameraMovedBy(Scene s, int frame, glm::vec3 offset) {
  CameraKey key;
  key.frame = frame;
  key.pose = s.camera.base;
  key.pose.position += offset;
  s.camera.keys.push_back(key);
  return s;
}

}  // namespace plume::test

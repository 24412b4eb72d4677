// A frame's render key: what its pixels depend on (used by plume render/reference --resume,
// app/frame_output.h, and by the bench's reference cache, bench/bench.cpp).
#pragma once

#include "scene/scene.h"

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace plume {

// What a frame's pixels depend on besides the frame number, as ordered (name, value) pairs named
// after the scene file's keys ("camera.width", "media[0].density_scale", "max_bounces"). Stored
// in the EXR header as `render_key` ("name=value; name=value; ..."); --resume keeps a frame only
// if the stored text equals this run's, so any setting added here re-renders older frames.
struct RenderKey {
  std::vector<std::pair<std::string, std::string>> entries;

  void add(const std::string& name, const std::string& value) { entries.emplace_back(name, value); }
  std::string text() const;
  // The entries that differ from a stored text, e.g. "mode pt -> restir, camera.width 80 -> 64"
  // ("(unset)" for a name only one side has); empty when the texts are equal.
  std::string differences(const std::string& stored) const;
};

// The scene's part of a frame's key: the camera's size and its pose at `frame`, every medium
// (this frame's VDB path relative to the scene's folder, grids, density scale, albedo, g,
// emission), the lights and surfaces, and each render.* setting of the settings table except the
// frame range, for which `uses(key)` holds (the table's new settings are included by default).
// Not included: what only the history of a temporal estimator depends on (where a chunk starts,
// --preroll), the device, plume's version, and the contents of the files named (VDB, OBJ, maps).
RenderKey sceneRenderKey(const Scene& scene, int frame, const std::function<bool(const std::string&)>& uses);

}  // namespace plume

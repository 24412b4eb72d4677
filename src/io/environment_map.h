// Environment map images (DESIGN §2, §9): a lat-long (equirectangular) EXR, exactly twice as wide
// as high, channels R, G, B. Loading checks the size from the header before reading pixels,
// and zeroes texels that are not finite or are negative (counted: a warning, not an error).
// Shared by the GPU estimators (render/gpu_envmap.cpp) and the CPU reference, which build their
// own lookups and distributions from it.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace plume {

struct EnvironmentMapImage {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> texels;  // radiance, row-major, row 0 at the top (v = 0)
  uint64_t zeroedTexels = 0;      // NaN, Inf or negative texels set to 0 on load
};

// The most texels an estimator can take, and the device limit that sets it (named in errors).
struct EnvironmentMapLimit {
  uint64_t maxTexels = UINT64_MAX;
  std::string what;  // e.g. "the device's maxTexelBufferElements (134217728 words, ...)"
};

// Reads and checks the map of scene key `key` (e.g. "scene.json: lights[0].map"). Throws
// InputError naming the key and the file: unreadable, not 2:1, no R/G/B channel, more texels than
// `limit` allows. Logs a warning with the count of zeroed texels.
EnvironmentMapImage loadEnvironmentMap(const std::string& path, const std::string& key,
                                       const EnvironmentMapLimit& limit = {});

}  // namespace plume

// Linear RGB float images in memory, with an optional per-pixel variance of the mean (DESIGN §2
// Images) and string metadata for the file header. Reading and writing files: io/image.h.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace plume {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // 3 * width * height, row 0 at the top
  std::vector<float> var;  // empty, or 3 * width * height: variance of the mean per channel
  std::map<std::string, std::string> meta;

  Image() = default;
  Image(int w, int h, bool withVariance = false);

  bool hasVariance() const { return !var.empty(); }
  size_t pixelCount() const { return size_t(width) * size_t(height); }
  glm::vec3 pixel(int x, int y) const;
  void setPixel(int x, int y, glm::vec3 v);
  glm::vec3 variance(int x, int y) const;
  void setVariance(int x, int y, glm::vec3 v);
};

// The header entries every image plume renders carries (plume render, plume reference, plume
// view's screenshots), so that a file says what made it.
struct CommonMeta {
  std::string mode;               // pt, restir, restir-biased, reference
  int spp = 0;                    // samples (ReSTIR: iterations) per pixel
  int64_t seed = 0;
  int frame = 0;
  std::optional<int> maxBounces;  // absent from the viewer's screenshots (settings edited live)
  std::string device;
};
// Sets version, mode, spp, seed, frame, max_bounces (when given) and device in image.meta.
void setCommonMeta(Image& image, const CommonMeta& common);

}  // namespace plume

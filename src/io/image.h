// Linear RGB float images with an optional per-pixel variance of the mean (DESIGN §2 Images).
// EXR layout: channels R,G,B; variance as var.R, var.G, var.B; header string attributes from
// `meta` (renderer version, mode, spp, seed, wall time...). Writes are atomic.
#pragma once

#include <glm/vec3.hpp>

#include <map>
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

// Throws InputError naming the file on any failure; never leaves a partial file.
void writeExr(const std::string& path, const Image& image);
Image readExr(const std::string& path);

// Tone-mapped sRGB preview (exposure in stops, then a simple filmic curve). Never measured.
void writePng(const std::string& path, const Image& image, float exposureStops = 0.0f);
// 8-bit RGB rows, top row first (a captured window, an already tone-mapped buffer).
void writeRgb8Png(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb);

}  // namespace plume

#include "core/image.h"

namespace plume {

Image::Image(int w, int h, bool withVariance) : width(w), height(h) {
  rgb.assign(3 * pixelCount(), 0.0f);
  if (withVariance) var.assign(3 * pixelCount(), 0.0f);
}

glm::vec3 Image::pixel(int x, int y) const {
  size_t i = 3 * (size_t(y) * width + x);
  return {rgb[i], rgb[i + 1], rgb[i + 2]};
}

void Image::setPixel(int x, int y, glm::vec3 v) {
  size_t i = 3 * (size_t(y) * width + x);
  rgb[i] = v.x;
  rgb[i + 1] = v.y;
  rgb[i + 2] = v.z;
}

glm::vec3 Image::variance(int x, int y) const {
  size_t i = 3 * (size_t(y) * width + x);
  return {var[i], var[i + 1], var[i + 2]};
}

void Image::setVariance(int x, int y, glm::vec3 v) {
  size_t i = 3 * (size_t(y) * width + x);
  var[i] = v.x;
  var[i + 1] = v.y;
  var[i + 2] = v.z;
}

void setCommonMeta(Image& image, const CommonMeta& c) {
  image.meta["version"] = PLUME_VERSION;
  image.meta["mode"] = c.mode;
  image.meta["spp"] = std::to_string(c.spp);
  image.meta["seed"] = std::to_string(c.seed);
  image.meta["frame"] = std::to_string(c.frame);
  if (c.maxBounces) image.meta["max_bounces"] = std::to_string(*c.maxBounces);
  image.meta["device"] = c.device;
}

}  // namespace plume

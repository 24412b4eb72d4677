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

}  // namespace plume

#include "io/environment_map.h"

#include "core/error.h"
#include "core/log.h"
#include "io/image.h"

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>

#include <cmath>

namespace plume {

EnvironmentMapImage loadEnvironmentMap(const std::string& path, const std::string& key,
                                       const EnvironmentMapLimit& limit) {
  const std::string where = key + ": " + path;
  int width = 0, height = 0;
  try {
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    width = dw.max.x - dw.min.x + 1;
    height = dw.max.y - dw.min.y + 1;
  } catch (const std::exception& e) {
    throw InputError(where + ": cannot read EXR: " + e.what());
  }
  if (width <= 0 || height <= 0 || width != 2 * height) {
    throw InputError(where + strf(": a lat-long map must be twice as wide as high (got %d x %d)", width, height));
  }
  const uint64_t texels = uint64_t(width) * uint64_t(height);
  if (texels > limit.maxTexels) {
    throw InputError(where + strf(": %d x %d texels is more than %llu, the most ", width, height,
                                  (unsigned long long)limit.maxTexels) + limit.what + " allows");
  }
  Image image;
  try {
    image = readExr(path);
  } catch (const InputError& e) {
    throw InputError(key + ": " + e.what());
  }
  EnvironmentMapImage map;
  map.width = width;
  map.height = height;
  map.texels.resize(size_t(texels));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      glm::vec3 c = image.pixel(x, y);
      bool bad = false;
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(c[k]) || c[k] < 0.0f) {
          c[k] = 0.0f;
          bad = true;
        }
      }
      map.zeroedTexels += bad ? 1u : 0u;
      map.texels[size_t(y) * width + x] = c;
    }
  }
  if (map.zeroedTexels > 0) {
    logWarn(where + strf(": %llu texels with NaN, Inf or negative values set to 0",
                         (unsigned long long)map.zeroedTexels));
  }
  return map;
}

}  // namespace plume

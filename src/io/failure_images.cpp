#include "io/failure_images.h"

#include "io/image.h"

#include <filesystem>

namespace plume {

std::string writeFailureImages(const std::string& dir, const std::string& name, const Image& a, const Image& b,
                               const ZTestResult& result) {
  std::filesystem::create_directories(dir);
  const std::string base = (std::filesystem::path(dir) / name).string();
  writeExr(base + "_a.exr", a);
  writeExr(base + "_b.exr", b);
  writeExr(base + "_z.exr", zScoreImage(result));
  writeFailureReport(dir, name, result);
  return dir;
}

}  // namespace plume

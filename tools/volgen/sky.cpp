// `plume-volgen sky`: an analytic HDR sky as a lat-long EXR (volumes/README.md "sky/"), in the
// orientation of DESIGN §2 with up = +Y and rotate_y_deg = 0: texel (column c, row r) of a W x H
// map looks along d = (sin t sin p, cos t, -sin t cos p), t = pi (r + 0.5) / H, p = 2 pi (c + 0.5) / W.
// The model (radiance, linear Rec. 709), with y = d.y and gamma the angle between d and the sun:
//   sky (y >= 0):    L = zenith + (horizon - zenith) (1 - y)^3 + glow exp(-gamma / glowWidth)
//   ground (y < 0):  L = ground
//   sun disk:        L += E / (pi sin^2 alpha) where gamma <= alpha (a disk of irradiance E)
// Each texel is the mean over 8 x 8 sample directions spread uniformly in (u, v) inside it (a box
// filter: the sun's disk keeps its power up to that quadrature's error). Stored as half floats,
// ZIP-compressed; deterministic.
#include "volgen.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace volgen {

namespace {
struct V3 {
  double x, y, z;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 normalized(V3 a) { return a * (1.0 / std::sqrt(dot(a, a))); }
V3 vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }
}  // namespace

void writeSkyExr(const std::string& path, int width, int height, const std::vector<float>& rgb) {
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.insert("plume.content", Imf::StringAttribute("plume-volgen sky (lat-long, DESIGN §2)"));
  std::vector<half> h(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) h[i] = half(rgb[i]);
  Imf::FrameBuffer fb;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    header.channels().insert(names[c], Imf::Channel(Imf::HALF));
    fb.insert(names[c], Imf::Slice(Imf::HALF, (char*)(h.data() + c), 3 * sizeof(half), 3 * sizeof(half) * size_t(width)));
  }
  Imf::OutputFile out(path.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(height);
}

int runSky(const SkyParams& p) {
  if (p.height < 1) throw std::runtime_error("sky: --height must be >= 1");
  const int W = 2 * p.height, H = p.height;
  const V3 sun = normalized(vec(p.sunDir));
  const double alpha = p.sunRadiusDeg * M_PI / 180.0;
  const double sunL = p.sunIrradiance / (M_PI * std::sin(alpha) * std::sin(alpha));
  const V3 zenith = vec(p.zenith), horizon = vec(p.horizon), ground = vec(p.ground), glow = vec(p.glow);
  std::vector<float> rgb(size_t(W) * H * 3);
  constexpr int kSub = 8;
  for (int r = 0; r < H; ++r) {
    for (int c = 0; c < W; ++c) {
      V3 sum{0, 0, 0};
      for (int j = 0; j < kSub; ++j) {
        for (int i = 0; i < kSub; ++i) {
          const double t = M_PI * (r + (j + 0.5) / kSub) / H, ph = 2.0 * M_PI * (c + (i + 0.5) / kSub) / W;
          const V3 d{std::sin(t) * std::sin(ph), std::cos(t), -std::sin(t) * std::cos(ph)};
          const double gamma = std::acos(std::clamp(dot(d, sun), -1.0, 1.0));
          V3 L = ground;
          if (d.y >= 0.0) {
            const double k = std::pow(1.0 - d.y, 3.0);
            L = zenith * (1.0 - k) + horizon * k + glow * std::exp(-gamma / p.glowWidth);
          }
          if (gamma <= alpha) L = L + V3{sunL, sunL, sunL};
          sum = sum + L;
        }
      }
      sum = sum * (1.0 / (kSub * kSub));
      float* o = &rgb[3 * (size_t(r) * W + c)];
      o[0] = float(sum.x), o[1] = float(sum.y), o[2] = float(sum.z);
    }
  }
  std::filesystem::create_directories(std::filesystem::path(p.out).parent_path());
  writeSkyExr(p.out, W, H, rgb);
  std::printf("%s: %d x %d, sun radiance %.1f in a disk of %.2f deg, %llu bytes\n", p.out.c_str(), W, H, sunL,
              p.sunRadiusDeg, (unsigned long long)std::filesystem::file_size(p.out));
  return 0;
}

}  // namespace volgen

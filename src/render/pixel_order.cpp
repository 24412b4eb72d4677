#include "render/pixel_order.h"

#include "core/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace plume {

namespace {

// Calls f(x, y) for every pixel in tile order (kPixelOrderTile² tiles row-major, each tile's
// pixels row-major).
template <typename F>
void forEachInTileOrder(int width, int height, F&& f) {
  const int t = kPixelOrderTile;
  for (int ty = 0; ty < height; ty += t)
    for (int tx = 0; tx < width; tx += t)
      for (int y = ty; y < std::min(ty + t, height); ++y)
        for (int x = tx; x < std::min(tx + t, width); ++x) f(x, y);
}

}  // namespace

PixelOrder allPixels(int width, int height) {
  PLUME_CHECK(width > 0 && height > 0 && width <= 65536 && height <= 65536);
  PixelOrder order;
  order.pixels.reserve(size_t(width) * size_t(height));
  forEachInTileOrder(width, height, [&](int x, int y) { order.pixels.push_back(packPixel(uint32_t(x), uint32_t(y))); });
  order.inside = uint32_t(order.pixels.size());
  return order;
}

PixelOrder volumePixelOrder(const shared::GpuCamera& cam, int width, int height, glm::vec3 lo, glm::vec3 hi,
                            const glm::mat4& indexToWorld, bool empty) {
  PLUME_CHECK(width > 0 && height > 0 && width <= 65536 && height <= 65536);
  const size_t n = size_t(width) * size_t(height);
  auto all = [&](bool inside) {
    PixelOrder order = allPixels(width, height);
    if (!inside) order.inside = 0;
    return order;
  };
  if (empty) return all(false);
  // The box's corners on the image, in pixels (x right, y down: cam_direction's inverse). The
  // projection of the box is the convex hull of its corners' projections.
  const glm::dvec3 pos(cam.position), fwd(cam.forward), right(cam.right), up(cam.up);
  const double tanY = double(cam.tanHalfFovY), tanX = tanY * double(cam.aspect);
  std::array<glm::dvec2, 8> p;
  int behind = 0;
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? hi.x + kPixelOrderBoxMargin : lo.x - kPixelOrderBoxMargin,
                           (c & 2) ? hi.y + kPixelOrderBoxMargin : lo.y - kPixelOrderBoxMargin,
                           (c & 4) ? hi.z + kPixelOrderBoxMargin : lo.z - kPixelOrderBoxMargin);
    const glm::dvec3 d = glm::dvec3(glm::vec3(indexToWorld * glm::vec4(corner, 1.0f))) - pos;
    const double z = glm::dot(d, fwd);
    if (!(z > 1e-9 * std::max(1.0, glm::length(d)))) {
      ++behind;
      continue;
    }
    const double sx = glm::dot(d, right) / z / tanX, sy = glm::dot(d, up) / z / tanY;
    p[c] = glm::dvec2((sx + 1.0) * 0.5 * width, (1.0 - sy) * 0.5 * height);
    if (!std::isfinite(p[c].x) || !std::isfinite(p[c].y)) return all(true);
  }
  // Every ray leaves the camera forwards (cam_direction: forward plus a sideways part), so a box
  // wholly behind its plane is seen by no pixel; one that reaches the plane from in front (or
  // holds the camera) projects without bound: every pixel may see it.
  if (behind == 8) return all(false);
  if (behind > 0) return all(true);
  // Per row of pixels: the x-extent of the hull within the row's slab (grown by the margin) is
  // the extent of the corners inside the slab and of every segment between two corners where it
  // crosses the slab's edges (points of the hull, and they include the hull's own vertices there).
  std::vector<char> in(n, 0);
  const double m = kPixelOrderPixelMargin;
  for (int y = 0; y < height; ++y) {
    const double y0 = y - m, y1 = y + 1 + m;
    double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
    auto add = [&](double x) {
      xmin = std::min(xmin, x);
      xmax = std::max(xmax, x);
    };
    for (int a = 0; a < 8; ++a) {
      if (p[a].y >= y0 && p[a].y <= y1) add(p[a].x);
      for (int b = a + 1; b < 8; ++b) {
        const double ya = p[a].y, yb = p[b].y;
        for (double e : {y0, y1}) {
          if ((ya - e) * (yb - e) < 0.0) add(p[a].x + (p[b].x - p[a].x) * (e - ya) / (yb - ya));
        }
      }
    }
    if (!(xmin <= xmax)) continue;
    const int x0 = int(std::clamp(std::floor(xmin - m), 0.0, double(width)));
    const int x1 = int(std::clamp(std::ceil(xmax + m) + 1.0, 0.0, double(width)));
    for (int x = x0; x < x1; ++x) in[size_t(y) * width + x] = 1;
  }
  PixelOrder order;
  order.pixels.reserve(n);
  for (int pass = 1; pass >= 0; --pass) {
    forEachInTileOrder(width, height, [&](int x, int y) {
      if (in[size_t(y) * width + x] == pass) order.pixels.push_back(packPixel(uint32_t(x), uint32_t(y)));
    });
  }
  order.inside = uint32_t(std::count(in.begin(), in.end(), char(1)));
  return order;
}

}  // namespace plume

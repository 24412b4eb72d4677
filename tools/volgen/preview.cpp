// `plume-volgen preview`: a quick look at a grid, for people (not for measurements). Single
// scattering of a sun plus a constant ambient term, an orthographic camera along -z or -x, one
// pixel per voxel, nearest-voxel lookups; written as an 8-bit binary PGM.
#include "volgen.h"

#include <openvdb/io/File.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace volgen {

int runPreview(const PreviewParams& prm) {
  openvdb::io::File file(prm.in);
  file.open();
  auto base = file.readGrid(prm.grid);
  file.close();
  auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  if (!grid) {
    std::fprintf(stderr, "%s: grid \"%s\" is not a float grid\n", prm.in.c_str(), prm.grid.c_str());
    return 2;
  }
  openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  box.expand(2);
  if (prm.box > 0) box = openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(prm.box - 1));
  const openvdb::Coord lo = box.min(), dim = box.dim();
  const float h = float(grid->voxelSize()[0]);
  const int nx = dim.x(), ny = dim.y(), nz = dim.z();
  auto at = [&](int i, int j, int k) { return (size_t(k) * ny + j) * nx + i; };
  std::vector<float> sigma(size_t(nx) * ny * nz), tLight(sigma.size());
  auto acc = grid->getConstAccessor();
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) sigma[at(i, j, k)] = prm.densityScale * acc.getValue(lo.offsetBy(i, j, k)) * h;
  // Transmittance towards the sun, one voxel per step.
  const openvdb::Vec3f toSun = openvdb::Vec3f(0.6f, 1.0f, 0.45f).unit();
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        float tau = 0;
        openvdb::Vec3f p{float(i), float(j), float(k)};
        for (;;) {
          p += toSun;
          int a = int(std::lround(p[0])), b = int(std::lround(p[1])), c = int(std::lround(p[2]));
          if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz) break;
          tau += sigma[at(a, b, c)];
        }
        tLight[at(i, j, k)] = std::exp(-tau);
      }
  const bool alongZ = prm.axis != 'x';
  const int w = alongZ ? nx : nz, depth = alongZ ? nz : nx;
  std::vector<uint8_t> img(size_t(w) * ny);
  float maxTau = 0;  // largest optical depth along a pixel's line of sight
  for (int row = 0; row < ny; ++row)
    for (int col = 0; col < w; ++col) {
      int j = ny - 1 - row;  // row 0 at the top
      float T = 1, L = 0, tau = 0;
      for (int s = depth - 1; s >= 0; --s) {  // from the camera side backwards
        size_t v = alongZ ? at(col, j, s) : at(s, j, nz - 1 - col);
        float a = 1 - std::exp(-sigma[v]);
        tau += sigma[v];
        L += T * a * (0.9f * 2.2f * tLight[v] + 0.25f);
        T *= 1 - a;
      }
      L += T * 0.12f;  // background
      maxTau = std::max(maxTau, tau);
      float srgb = std::pow(std::clamp(L, 0.0f, 1.0f), 1.0f / 2.2f);
      img[size_t(row) * w + col] = uint8_t(std::lround(255 * srgb));
    }
  std::ofstream out(prm.out, std::ios::binary);
  out << "P5\n" << w << " " << ny << "\n255\n";
  out.write(reinterpret_cast<const char*>(img.data()), std::streamsize(img.size()));
  if (!out) {
    std::fprintf(stderr, "%s: cannot write\n", prm.out.c_str());
    return 2;
  }
  std::printf("%s: %dx%d, largest optical depth along the view %.3g\n", prm.out.c_str(), w, ny, maxTau);
  return 0;
}

}  // namespace volgen

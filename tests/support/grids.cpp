#include "support/grids.h"

#include "media/vdb_loader.h"

#include <cmath>

namespace plume::test {

openvdb::FloatGrid::Ptr makeBoxGrid(int n, double voxelSize, float value) {
  initOpenVdb();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
  grid->denseFill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(n - 1)), value, true);
  // denseFill may create active tiles; that is fine (and exercises tile handling).
  grid->setName("density");
  return grid;
}

openvdb::FloatGrid::Ptr makeRampGrid(int n, double voxelSize) {
  initOpenVdb();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
  auto acc = grid->getAccessor();
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) acc.setValue(openvdb::Coord(x, y, z), float(x) / float(n - 1));
  grid->setName("density");
  return grid;
}

openvdb::FloatGrid::Ptr makeNoiseGrid(int n, double voxelSize, unsigned seed) {
  initOpenVdb();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
  auto acc = grid->getAccessor();
  const double c = 0.5 * (n - 1), s = double(seed);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        double dx = (x - c) / c, dy = (y - c) / c, dz = (z - c) / c;
        double r = std::sqrt(dx * dx + dy * dy + dz * dz);
        double wobble = 0.5 + 0.25 * std::sin(5.1 * dx + s) * std::sin(4.3 * dy + 2 * s) * std::sin(6.7 * dz + 3 * s) +
                        0.25 * std::sin(13.0 * dx + 7.0 * dz + s);
        double v = std::max(0.0, 1.0 - r * r * 1.3) * wobble;
        if (v > 1e-3) acc.setValue(openvdb::Coord(x, y, z), float(std::min(1.0, v)));
      }
  grid->setName("density");
  return grid;
}

}  // namespace plume::test

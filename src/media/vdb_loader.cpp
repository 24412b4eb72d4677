// OpenVDB loading and sanitising (DESIGN §2): see vdb_loader.h for the contract.
#include "media/vdb_loader.h"

#include "core/error.h"
#include "core/log.h"

#include <openvdb/io/File.h>
#include <openvdb/tools/Count.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/combinable.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <mutex>

namespace plume {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw InputError(path + ": " + what);
}

// "half" for float grids written with half precision (OpenVDB reads them back as float).
std::string typeName(const openvdb::GridBase& grid) {
  std::string type = grid.valueType();
  if (type == "float" && grid.saveFloatAsHalf()) return "half";
  return type;
}

// Runs `body` (which reads the file) and turns every exception into an InputError naming it.
// OpenVDB reports I/O and format problems as openvdb::Exception, the standard library (and
// Blosc/zlib paths inside OpenVDB) as std::exception.
template <typename Body>
auto guarded(const std::string& path, Body&& body) {
  if (!std::filesystem::exists(path)) fail(path, "file not found");
  try {
    return body();
  } catch (const InputError&) {
    throw;
  } catch (const openvdb::Exception& e) {
    fail(path, std::string("cannot read OpenVDB file (") + e.what() + ")");
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read OpenVDB file (") + e.what() + ")");
  }
}

// Opens without delayed loading, so that a truncated file fails inside guarded() rather than
// later when a lazily loaded leaf is touched.
void openFile(openvdb::io::File& file) {
  file.open(/*delayLoad=*/false);
}

std::vector<std::string> gridNames(openvdb::io::File& file) {
  std::vector<std::string> names;
  for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(it.gridName());
  return names;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

// World-space AABB of the eight corners of an index box (a linear map sends corners to corners
// of the image parallelepiped, so their AABB bounds it).
openvdb::BBoxd worldBoundsOf(const openvdb::math::Transform& xform, const openvdb::CoordBBox& box) {
  openvdb::BBoxd out;
  if (box.empty()) return out;
  const openvdb::Vec3d lo = box.min().asVec3d(), hi = box.max().asVec3d();
  for (int c = 0; c < 8; ++c) {
    const openvdb::Vec3d p((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
    out.expand(xform.indexToWorld(p));
  }
  return out;
}

GridSummary summarise(const openvdb::GridBase& grid) {
  GridSummary s;
  s.name = grid.getName();
  s.type = typeName(grid);
  s.voxelSize = grid.voxelSize();
  s.linear = grid.transform().isLinear();
  s.indexBounds = grid.evalActiveVoxelBoundingBox();
  if (grid.activeVoxelCount() == 0) s.indexBounds = openvdb::CoordBBox();
  s.worldBounds = worldBoundsOf(grid.transform(), s.indexBounds);
  s.activeVoxels = grid.activeVoxelCount();
  if (const auto* f = dynamic_cast<const openvdb::FloatGrid*>(&grid)) {
    s.activeTiles = f->tree().activeTileCount();
    if (s.activeVoxels) {
      const auto mm = openvdb::tools::minMax(f->tree());
      s.minValue = mm.min(), s.maxValue = mm.max();
    }
  } else if (const auto* d = dynamic_cast<const openvdb::DoubleGrid*>(&grid)) {
    s.activeTiles = d->tree().activeTileCount();
    if (s.activeVoxels) {
      const auto mm = openvdb::tools::minMax(d->tree());
      s.minValue = float(mm.min()), s.maxValue = float(mm.max());
    }
  }
  return s;
}

// float and double grids become a FloatGrid (double values are rounded to float; out-of-range
// values become Inf and are then sanitised). Anything else is refused, naming its type.
openvdb::FloatGrid::Ptr toFloatGrid(const std::string& path, openvdb::GridBase::Ptr base) {
  if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(base)) return f;
  if (auto d = openvdb::gridPtrCast<openvdb::DoubleGrid>(base)) {
    auto tree = std::make_shared<openvdb::FloatTree>(d->tree());  // converting copy
    auto f = openvdb::FloatGrid::create(tree);
    f->setTransform(d->transform().copy());
    f->setName(d->getName());
    return f;
  }
  fail(path, "grid \"" + base->getName() + "\" has type " + typeName(*base) +
                 "; only scalar float, double or half grids can be a density");
}

void checkUsable(const std::string& path, const openvdb::FloatGrid& grid) {
  const std::string what = "grid \"" + grid.getName() + "\"";
  if (!grid.transform().isLinear())
    fail(path, what + " has a non-linear (" + grid.transform().mapType() +
                   ") transform; only linear transforms are supported");
  const float bg = grid.background();
  if (bg != 0.0f)
    fail(path, what + " has background " + std::to_string(bg) + "; only a background of 0 is supported");
}

}  // namespace

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

uint64_t sanitizeGrid(openvdb::FloatGrid& grid) {
  auto& tree = grid.tree();
  // Leaf voxels, in parallel over leaves.
  tbb::combinable<uint64_t> replaced([] { return uint64_t(0); });
  openvdb::tree::LeafManager<openvdb::FloatTree> leaves(tree);
  leaves.foreach([&](openvdb::FloatTree::LeafNodeType& leaf, size_t) {
    uint64_t n = 0;
    float* data = leaf.buffer().data();
    const auto& mask = leaf.getValueMask();
    for (openvdb::Index i = 0; i < openvdb::FloatTree::LeafNodeType::SIZE; ++i) {
      const float v = data[i];
      if (!mask.isOn(i)) {
        data[i] = 0.0f;
      } else if (!std::isfinite(v) || v < 0.0f) {
        data[i] = 0.0f;
        ++n;
      }
    }
    replaced.local() += n;
  });
  uint64_t count = replaced.combine(std::plus<uint64_t>());
  // Tiles (every level above the leaves), serially: there are few.
  auto it = tree.beginValueAll();
  it.setMaxDepth(openvdb::FloatTree::ValueAllIter::LEAF_DEPTH - 1);
  for (; it; ++it) {
    const float v = *it;
    if (!it.isValueOn()) {
      if (v != 0.0f) it.setValue(0.0f);
    } else if (!std::isfinite(v) || v < 0.0f) {
      it.setValue(0.0f);
      count += it.getVoxelCount();
    }
  }
  return count;
}

double maxMediumValue(const openvdb::FloatGrid& grid, double densityScale) {
  const openvdb::Vec3d vs = grid.voxelSize();
  const double side = std::min({vs.x(), vs.y(), vs.z()});
  if (!(densityScale > 0.0) || !(side > 0.0)) return std::numeric_limits<double>::infinity();
  return kMaxVoxelOpticalDepth / (densityScale * side);
}

uint64_t clampOpticalDepth(openvdb::FloatGrid& grid, double densityScale) {
  const double limitD = maxMediumValue(grid, densityScale);
  if (!(limitD < double(std::numeric_limits<float>::max()))) return 0;
  const float limit = float(limitD);
  tbb::combinable<uint64_t> clamped([] { return uint64_t(0); });
  openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid.tree());
  leaves.foreach([&](openvdb::FloatTree::LeafNodeType& leaf, size_t) {
    uint64_t n = 0;
    for (auto it = leaf.beginValueOn(); it; ++it) {
      if (*it > limit) it.setValue(limit), ++n;
    }
    clamped.local() += n;
  });
  uint64_t count = clamped.combine(std::plus<uint64_t>());
  auto it = grid.tree().beginValueOn();
  it.setMaxDepth(openvdb::FloatTree::ValueOnIter::LEAF_DEPTH - 1);
  for (; it; ++it) {
    if (*it > limit) {
      it.setValue(limit);
      count += it.getVoxelCount();
    }
  }
  return count;
}

void warnClamped(const LoadedGrid& grid, double densityScale) {
  logWarn(strf("%s: %llu values above %.4g (optical depth %g per voxel at density scale %g) clamped to it",
               grid.path.c_str(), (unsigned long long)grid.clampedValues, maxMediumValue(*grid.grid, densityScale),
               kMaxVoxelOpticalDepth, densityScale));
}

std::vector<GridSummary> inspectVdb(const std::string& path) {
  initOpenVdb();
  return guarded(path, [&] {
    openvdb::io::File file(path);
    openFile(file);
    std::vector<GridSummary> out;
    auto grids = file.getGrids();
    for (const auto& g : *grids) out.push_back(summarise(*g));
    file.close();
    return out;
  });
}

LoadedGrid loadFloatGrid(const std::string& path, const std::string& gridName) {
  initOpenVdb();
  return guarded(path, [&] {
    openvdb::io::File file(path);
    openFile(file);
    const auto names = gridNames(file);
    if (std::find(names.begin(), names.end(), gridName) == names.end())
      fail(path, "no grid named \"" + gridName + "\" (grids: " + joined(names) + ")");
    LoadedGrid out;
    out.grid = toFloatGrid(path, file.readGrid(gridName));
    file.close();
    out.grid->setName(gridName);
    checkUsable(path, *out.grid);
    out.path = path;
    out.name = gridName;
    out.replacedValues = sanitizeGrid(*out.grid);
    return out;
  });
}

}  // namespace plume

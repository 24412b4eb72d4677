// Loader tests (DESIGN §2): grid types, selection by name, refusals with clear messages,
// sanitising of voxels and tiles, tiles kept, empty grids, broken files, the real Blender cache.
#include "core/error.h"
#include "media/vdb_loader.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <vector>

namespace plume {
namespace {

using openvdb::Coord;

void writeVdb(const std::string& path, const openvdb::GridPtrVec& grids) {
  initOpenVdb();
  openvdb::io::File(path).write(grids);
}

// A small smooth field over a 20³ box (values in (0, 1], all exactly representable in float).
template <typename GridT>
typename GridT::Ptr makeField(const std::string& name) {
  auto g = GridT::create(0);
  g->setName(name);
  auto acc = g->getAccessor();
  for (int z = 0; z < 20; ++z)
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x)
        acc.setValue(Coord(x, y, z), float(0.5 + 0.5 * std::sin(0.3 * x) * std::cos(0.2 * y + 0.1 * z)) + 1e-3f);
  g->setTransform(openvdb::math::Transform::createLinearTransform(0.25));
  return g;
}

// Expects `fn` to throw an InputError whose message contains every string of `parts`.
template <typename Fn>
void expectInputError(Fn&& fn, const std::vector<std::string>& parts) {
  try {
    fn();
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const auto& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
  }
}

TEST(VdbLoader, FloatDoubleAndHalfGridsLoadAndAgree) {
  const std::string dir = test::outputDir("vdb_loader_types");
  auto f = makeField<openvdb::FloatGrid>("f");
  auto d = makeField<openvdb::DoubleGrid>("d");
  auto h = makeField<openvdb::FloatGrid>("h");
  h->setSaveFloatAsHalf(true);
  writeVdb(dir + "/types.vdb", {f, d, h});

  std::map<std::string, GridSummary> summary;  // the file does not keep the write order
  for (const auto& s : inspectVdb(dir + "/types.vdb")) summary[s.name] = s;
  ASSERT_EQ(summary.size(), 3u);
  EXPECT_EQ(summary["f"].type, "float");
  EXPECT_EQ(summary["d"].type, "double");
  EXPECT_EQ(summary["h"].type, "half");
  EXPECT_EQ(summary["f"].activeVoxels, 8000u);
  EXPECT_EQ(summary["f"].indexBounds, openvdb::CoordBBox(Coord(0), Coord(19)));
  EXPECT_NEAR(summary["f"].worldBounds.max().x(), 19 * 0.25, 1e-12);
  EXPECT_NEAR(summary["d"].voxelSize.x(), 0.25, 1e-12);
  EXPECT_FLOAT_EQ(summary["d"].maxValue, summary["f"].maxValue);

  const LoadedGrid lf = loadFloatGrid(dir + "/types.vdb", "f");
  const LoadedGrid ld = loadFloatGrid(dir + "/types.vdb", "d");
  const LoadedGrid lh = loadFloatGrid(dir + "/types.vdb", "h");
  EXPECT_EQ(lf.replacedValues + ld.replacedValues + lh.replacedValues, 0u);
  auto af = lf.grid->getConstAccessor(), ad = ld.grid->getConstAccessor(), ah = lh.grid->getConstAccessor();
  for (auto it = f->cbeginValueOn(); it; ++it) {
    const Coord c = it.getCoord();
    EXPECT_EQ(af.getValue(c), *it);
    EXPECT_EQ(ad.getValue(c), float(d->tree().getValue(c)));  // double rounded to float
    EXPECT_NEAR(ah.getValue(c), *it, std::ldexp(std::abs(*it), -11));  // half: 11-bit significand
    EXPECT_TRUE(ad.isValueOn(c) && ah.isValueOn(c));
  }
  EXPECT_EQ(ld.grid->activeVoxelCount(), 8000u);
  EXPECT_NEAR(ld.grid->voxelSize().x(), 0.25, 1e-12);
}

TEST(VdbLoader, GridChosenByNameAndMissingGridListsTheOthers) {
  const std::string path = test::outputDir("vdb_loader_names") + "/two.vdb";
  auto a = openvdb::FloatGrid::create(0);
  a->setName("alpha");
  a->tree().setValue(Coord(1, 2, 3), 0.25f);
  auto b = openvdb::FloatGrid::create(0);
  b->setName("beta");
  b->tree().setValue(Coord(1, 2, 3), 0.75f);
  writeVdb(path, {a, b});
  EXPECT_EQ(loadFloatGrid(path, "beta").grid->tree().getValue(Coord(1, 2, 3)), 0.75f);
  EXPECT_EQ(loadFloatGrid(path, "alpha").grid->tree().getValue(Coord(1, 2, 3)), 0.25f);
  expectInputError([&] { loadFloatGrid(path, "density"); },
                   {path + ": ", "no grid named \"density\"", "alpha, beta"});
}

TEST(VdbLoader, NonScalarGridsAreRefusedNamingTheirType) {
  const std::string path = test::outputDir("vdb_loader_vec3") + "/vec.vdb";
  auto v = openvdb::Vec3SGrid::create();
  v->setName("velocity");
  v->tree().setValue(Coord(0), openvdb::Vec3s(1, 2, 3));
  auto b = openvdb::BoolGrid::create();
  b->setName("mask");
  b->tree().setValue(Coord(0), true);
  auto i = openvdb::Int32Grid::create();
  i->setName("ids");
  i->tree().setValue(Coord(0), 7);
  writeVdb(path, {v, b, i});
  expectInputError([&] { loadFloatGrid(path, "velocity"); }, {path + ": ", "\"velocity\"", "vec3s"});
  expectInputError([&] { loadFloatGrid(path, "mask"); }, {path + ": ", "bool"});
  expectInputError([&] { loadFloatGrid(path, "ids"); }, {path + ": ", "int32"});
}

TEST(VdbLoader, FrustumTransformAndNonZeroBackgroundAreRefused) {
  const std::string dir = test::outputDir("vdb_loader_refused");
  auto g = makeField<openvdb::FloatGrid>("density");
  g->setTransform(openvdb::math::Transform::createFrustumTransform(
      openvdb::BBoxd(openvdb::Vec3d(0), openvdb::Vec3d(19)), 0.5, 2.0, 0.1));
  writeVdb(dir + "/frustum.vdb", {g});
  EXPECT_FALSE(inspectVdb(dir + "/frustum.vdb")[0].linear);
  expectInputError([&] { loadFloatGrid(dir + "/frustum.vdb", "density"); },
                   {dir + "/frustum.vdb: ", "non-linear", "Frustum"});

  auto bg = openvdb::FloatGrid::create(0.5f);
  bg->setName("density");
  bg->tree().setValue(Coord(0), 1.0f);
  writeVdb(dir + "/background.vdb", {bg});
  expectInputError([&] { loadFloatGrid(dir + "/background.vdb", "density"); },
                   {dir + "/background.vdb: ", "background"});
}

TEST(VdbLoader, NanInfAndNegativeVoxelsAndTilesAreReplacedAndCounted) {
  const std::string path = test::outputDir("vdb_loader_sanitise") + "/bad.vdb";
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  auto g = openvdb::FloatGrid::create(0);
  g->setName("density");
  auto acc = g->getAccessor();
  acc.setValue(Coord(0, 0, 0), nan);
  acc.setValue(Coord(1, 0, 0), inf);
  acc.setValue(Coord(2, 0, 0), -inf);
  acc.setValue(Coord(3, 0, 0), -0.5f);
  acc.setValue(Coord(4, 0, 0), 0.5f);   // kept
  acc.setValueOff(Coord(5, 0, 0), nan); // inactive: zeroed but not counted
  g->tree().addTile(1, Coord(64, 0, 0), -2.0f, true);  // 8³ active tiles
  g->tree().addTile(1, Coord(72, 0, 0), nan, true);
  g->tree().addTile(1, Coord(80, 0, 0), 0.75f, true);  // kept
  g->tree().addTile(1, Coord(88, 0, 0), inf, false);   // inactive: zeroed, not counted
  writeVdb(path, {g});
  const LoadedGrid l = loadFloatGrid(path, "density");
  EXPECT_EQ(l.replacedValues, 4u + 2u * 512u);
  const auto& t = l.grid->tree();
  for (int x = 0; x < 4; ++x) EXPECT_EQ(t.getValue(Coord(x, 0, 0)), 0.0f) << x;
  EXPECT_EQ(t.getValue(Coord(4, 0, 0)), 0.5f);
  EXPECT_EQ(t.getValue(Coord(5, 0, 0)), 0.0f);
  EXPECT_EQ(t.getValue(Coord(67, 3, 3)), 0.0f);
  EXPECT_EQ(t.getValue(Coord(75, 3, 3)), 0.0f);
  EXPECT_EQ(t.getValue(Coord(83, 3, 3)), 0.75f);
  EXPECT_EQ(t.getValue(Coord(91, 3, 3)), 0.0f);
  EXPECT_EQ(t.activeTileCount(), 3u);  // tiles stay tiles
}

TEST(VdbLoader, FogVolumeInteriorTilesArePreserved) {
  const std::string path = test::outputDir("vdb_loader_tiles") + "/sphere.vdb";
  auto sdf = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(40.0f, openvdb::Vec3f(0), 1.0f, 3.0f);
  openvdb::tools::sdfToFogVolume(*sdf);
  sdf->setName("density");
  ASSERT_GT(sdf->tree().activeTileCount(), 0u);
  writeVdb(path, {sdf});
  const LoadedGrid l = loadFloatGrid(path, "density");
  EXPECT_EQ(l.replacedValues, 0u);
  EXPECT_EQ(l.grid->tree().activeTileCount(), sdf->tree().activeTileCount());
  EXPECT_EQ(l.grid->tree().getValue(Coord(0, 0, 0)), 1.0f);   // deep inside: a tile
  EXPECT_EQ(l.grid->tree().getValue(Coord(5, -7, 11)), 1.0f);
  EXPECT_EQ(l.grid->tree().getValue(Coord(60, 0, 0)), 0.0f);  // outside
  const auto s = inspectVdb(path)[0];
  EXPECT_EQ(s.activeVoxels, sdf->activeVoxelCount());          // tile voxels included
  EXPECT_GT(s.activeVoxels, s.activeTiles * 512);
  EXPECT_EQ(s.maxValue, 1.0f);
}

TEST(VdbLoader, EmptyGridLoadsAsEmpty) {
  const std::string path = test::outputDir("vdb_loader_empty") + "/empty.vdb";
  auto g = openvdb::FloatGrid::create(0);
  g->setName("density");
  writeVdb(path, {g});
  const LoadedGrid l = loadFloatGrid(path, "density");
  EXPECT_EQ(l.grid->activeVoxelCount(), 0u);
  const auto s = inspectVdb(path);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].activeVoxels, 0u);
  EXPECT_TRUE(s[0].indexBounds.empty());
}

TEST(VdbLoader, MissingTruncatedAndGarbageFilesNameTheFile) {
  const std::string dir = test::outputDir("vdb_loader_broken");
  expectInputError([&] { loadFloatGrid(dir + "/nope.vdb", "density"); }, {dir + "/nope.vdb: ", "not found"});
  expectInputError([&] { inspectVdb(dir + "/nope.vdb"); }, {dir + "/nope.vdb: "});

  writeVdb(dir + "/full.vdb", {makeField<openvdb::FloatGrid>("density")});
  const auto size = std::filesystem::file_size(dir + "/full.vdb");
#if defined(__SANITIZE_ADDRESS__)
  // Not in the sanitized build (tools/test --sanitize): OpenVDB 10's bloscFromStream uses an
  // uninitialised chunk size when a cut file ends inside it, and may ask for terabytes. The
  // std::bad_alloc becomes an InputError here, but AddressSanitizer's operator new aborts instead
  // of throwing. tests/bad_inputs still runs its truncated.vdb through plume.
  const std::vector<double> fractions;
#else
  const std::vector<double> fractions = {0.9, 0.5, 0.1};
#endif
  for (double fraction : fractions) {
    const std::string cut = dir + "/cut.vdb";
    std::filesystem::copy_file(dir + "/full.vdb", cut, std::filesystem::copy_options::overwrite_existing);
    std::filesystem::resize_file(cut, uintmax_t(double(size) * fraction));
    expectInputError([&] { loadFloatGrid(cut, "density"); }, {cut + ": "});
    expectInputError([&] { inspectVdb(cut); }, {cut + ": "});
  }
  std::ofstream(dir + "/garbage.vdb") << std::string(3000, 'x') << "not an OpenVDB file";
  expectInputError([&] { loadFloatGrid(dir + "/garbage.vdb", "density"); }, {dir + "/garbage.vdb: "});
  std::ofstream(dir + "/zero.vdb");
  expectInputError([&] { inspectVdb(dir + "/zero.vdb"); }, {dir + "/zero.vdb: "});
}

TEST(VdbLoader, InfoCommandDescribesGridsAndBakes) {
  const std::string dir = test::outputDir("vdb_loader_info");
  writeVdb(dir + "/field.vdb", {makeField<openvdb::FloatGrid>("density"), makeField<openvdb::DoubleGrid>("heat")});
  const auto r = test::runPlume({"info", dir + "/field.vdb", "--bake"});
  EXPECT_EQ(r.exitCode, 0) << r.output;
  for (const char* s : {"grid \"density\"", "grid \"heat\"", "double", "voxel size      0.25", "active voxels   8000",
                        "[0 0 0] .. [19 19 19]", "bake float16", "bake float32", "bytes per active voxel"})
    EXPECT_NE(r.output.find(s), std::string::npos) << s << " not in:\n" << r.output;
  const auto bad = test::runPlume({"info", dir + "/field.vdb", "--bake", "--grid", "dens"});
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_NE(bad.output.find("no grid named \"dens\" (grids: "), std::string::npos) << bad.output;
}

TEST(VdbLoader, RealBlenderCacheLoadsDensityAndIgnoresOtherGrids) {
  const std::string shared = test::sharedVolumesPath();
  if (shared.empty()) GTEST_SKIP() << test::sharedVolumesMissing();
  const std::string path = shared + "/raw/fluid_data_0040.vdb";
  const auto grids = inspectVdb(path);
  std::vector<std::string> names;
  for (const auto& g : grids) names.push_back(g.name);
  EXPECT_NE(std::find(names.begin(), names.end(), "shadow"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "velocity"), names.end());
  const LoadedGrid l = loadFloatGrid(path, "density");
  EXPECT_GT(l.grid->activeVoxelCount(), 1000u);
  EXPECT_EQ(l.replacedValues, 0u);
  EXPECT_NEAR(l.grid->voxelSize().x(), 0.046875, 1e-9);
  const auto mm = openvdb::tools::minMax(l.grid->tree());
  EXPECT_GE(mm.min(), 0.0f);
  EXPECT_LE(mm.max(), 1.0f);
  expectInputError([&] { loadFloatGrid(path, "velocity"); }, {path + ": ", "vec3s"});
}

}  // namespace
}  // namespace plume

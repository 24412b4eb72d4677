// `plume-volgen badinputs`: broken VDB and EXR files for tests/bad_inputs (see cases.json there). Each is
// tiny and made deterministically; the scene files and the manifest are written by hand.
#include "volgen.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>

#include <cstdio>
#include <filesystem>

namespace volgen {
namespace {

openvdb::FloatGrid::Ptr smallGrid(const std::string& name, float background = 0.0f) {
  auto grid = openvdb::FloatGrid::create(background);
  grid->setName(name);
  grid->setTransform(linearTransform(1.0 / 32.0, openvdb::Vec3d(0.0)));
  auto acc = grid->getAccessor();
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) acc.setValue(openvdb::Coord(i, j, k), 0.25f * float(i + 1));
  return grid;
}

}  // namespace

int runBadInputs(const std::string& outDir) {
  namespace fs = std::filesystem;
  fs::create_directories(outDir);
  auto out = [&](const char* name) { return (fs::path(outDir) / name).string(); };

  // Not a VDB at all: text followed by hashed bytes.
  std::string garbage = "this is not an OpenVDB file, just bytes\n";
  for (uint32_t i = 0; i < 216; ++i) garbage += char(hash32(i, 77) & 0xff);
  writeBytes(out("garbage.vdb"), garbage);
  writeBytes(out("empty.vdb"), "");

  // The first half of a valid file: a complete header, a grid cut off in its tree.
  std::string whole = vdbBytes({smallGrid("density")});
  writeBytes(out("truncated.vdb"), whole.substr(0, whole.size() / 2));

  // Wrong grid type under the right name.
  auto vec = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  vec->setName("density");
  vec->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1.0f, 0.5f, 0.25f));
  writeVdb(out("vec3_density.vdb"), {vec});

  // No grid named "density" (only "smoke" and "temperature").
  writeVdb(out("no_density_grid.vdb"), {smallGrid("smoke"), smallGrid("temperature")});

  // A frustum transform (refused: DESIGN §2 allows linear transforms only).
  auto frustum = smallGrid("density");
  frustum->setTransform(openvdb::math::Transform::createFrustumTransform(
      openvdb::BBoxd(openvdb::Vec3d(0.0), openvdb::Vec3d(15.0)), /*taper=*/0.5, /*depth=*/2.0, /*voxelSize=*/1.0));
  writeVdb(out("frustum.vdb"), {frustum});

  // A non-zero background (refused: outside the active voxels would be an infinite fog).
  writeVdb(out("nonzero_background.vdb"), {smallGrid("density", 0.5f)});

  // Environment maps: not 2:1 (8 x 8), not an EXR, and a header that claims 32768 x 16384
  // texels (more than any device's storage buffer range allows at 20 bytes per texel, 2^32
  // bytes) with no pixels written: the size is refused from the header alone.
  writeSkyExr(out("env_square.exr"), 8, 8, std::vector<float>(8 * 8 * 3, 0.5f));
  writeBytes(out("env_garbage.exr"), garbage);
  {
    Imf::Header header(32768, 16384);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::HALF));
    Imf::OutputFile huge(out("env_huge.exr").c_str(), header);
  }

  for (const char* name : {"garbage.vdb", "empty.vdb", "truncated.vdb", "vec3_density.vdb", "no_density_grid.vdb",
                           "frustum.vdb", "nonzero_background.vdb", "env_square.exr", "env_garbage.exr", "env_huge.exr"}) {
    std::printf("%s: %llu bytes\n", out(name).c_str(), (unsigned long long)fs::file_size(out(name)));
  }
  return 0;
}

}  // namespace volgen

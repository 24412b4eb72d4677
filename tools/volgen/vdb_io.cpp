// Writing VDB files deterministically. OpenVDB stamps every archive with a random UUID (36 ASCII
// characters right after the fixed-size header); we overwrite it with one hashed from the rest of
// the file so that regenerating a volume gives byte-identical output.
#include "volgen.h"

#include <openvdb/io/File.h>
#include <openvdb/tools/Count.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

namespace volgen {
namespace fs = std::filesystem;

namespace {

// Header: magic (8) + file version (4) + library major, minor (4 + 4) + has-offsets flag (1).
constexpr size_t kUuidOffset = 21;
constexpr size_t kUuidLength = 36;

uint64_t fnv1a(const std::string& s, size_t from, uint64_t h) {
  for (size_t i = from; i < s.size(); ++i) {
    h ^= uint8_t(s[i]);
    h *= 0x100000001b3ull;
  }
  return h;
}

void replaceUuid(std::string& bytes) {
  if (bytes.size() < kUuidOffset + kUuidLength) throw std::runtime_error("VDB output too short");
  for (size_t i = 0; i < kUuidLength; ++i) {
    char c = bytes[kUuidOffset + i];
    bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    if (dash ? c != '-' : !std::isxdigit(uint8_t(c))) {
      throw std::runtime_error("unexpected VDB header layout (archive UUID not found)");
    }
  }
  uint64_t a = fnv1a(bytes, kUuidOffset + kUuidLength, 0xcbf29ce484222325ull);
  uint64_t b = fnv1a(bytes, kUuidOffset + kUuidLength, 0x84222325cbf29ce4ull ^ a);
  char text[40];
  std::snprintf(text, sizeof text, "%08x-%04x-4%03x-%04x-%012llx", uint32_t(a >> 32), uint32_t(a >> 16) & 0xffff,
                uint32_t(a) & 0xfff, (uint32_t(b >> 48) & 0x3fff) | 0x8000,
                (unsigned long long)(b & 0xffffffffffffull));
  bytes.replace(kUuidOffset, kUuidLength, text, kUuidLength);
}

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  if (!in) throw std::runtime_error(path + ": cannot read back");
  return s.str();
}

}  // namespace

std::string vdbBytes(const openvdb::GridPtrVec& grids, bool halfFloat) {
  for (const auto& g : grids) g->setSaveFloatAsHalf(halfFloat);
  // io::File needs a seekable file (it records grid offsets), so go through a temporary one.
  fs::path tmp = fs::temp_directory_path() / ("plume-volgen-" + std::to_string(::getpid()) + ".vdb");
  {
    openvdb::io::File file(tmp.string());
    file.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
    file.write(grids);
    file.close();
  }
  std::string bytes = readAll(tmp.string());
  fs::remove(tmp);
  replaceUuid(bytes);
  return bytes;
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error(path + ": cannot write");
}

void writeVdb(const std::string& path, const openvdb::GridPtrVec& grids, bool halfFloat) {
  writeBytes(path, vdbBytes(grids, halfFloat));
}

openvdb::math::Transform::Ptr linearTransform(double voxelSize, const openvdb::Vec3d& translation) {
  auto xf = openvdb::math::Transform::createLinearTransform(voxelSize);
  xf->postTranslate(translation);
  return xf;
}

std::string describe(const std::string& path, const openvdb::FloatGrid& grid) {
  float lo = 0, hi = 0;
  if (grid.activeVoxelCount() > 0) {
    auto mm = openvdb::tools::minMax(grid.tree());
    lo = mm.min();
    hi = mm.max();
  }
  std::error_code ec;
  auto size = fs::file_size(path, ec);
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s: grid \"%s\", %llu active voxels (%llu tiles), values [%.4g, %.4g], %.1f kB",
                path.c_str(), grid.getName().c_str(), (unsigned long long)grid.activeVoxelCount(),
                (unsigned long long)grid.tree().activeTileCount(), lo, hi, ec ? -1.0 : double(size) / 1000.0);
  return buf;
}

}  // namespace volgen

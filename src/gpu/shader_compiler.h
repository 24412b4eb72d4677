// Run-time GLSL -> SPIR-V with glslang: per-variant #defines, #include "..." resolved against
// the shader root (and the including file's folder), and an on-disk SPIR-V cache keyed by a
// hash of the source with all its includes, the defines and the compiler settings.
#pragma once

#ifdef PLUME_NO_GPU
#error "the CPU reference never includes gpu/: it is independent of what it checks (CMakeLists.txt)"
#endif

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace plume::gpu {

using ShaderDefines = std::vector<std::pair<std::string, std::string>>;

class ShaderCompiler {
 public:
  // cacheDir empty: no disk cache. Default shader root: PLUME_SHADER_DIR, overridable with
  // the environment variable PLUME_SHADER_DIR (an installed plume).
  explicit ShaderCompiler(std::string shaderRoot = {}, std::string cacheDir = {});

  // Throws InternalError (exit code 4: the same on every device) for a missing shader file and with
  // glslang's log on a compile or link error.
  std::vector<uint32_t> compile(const std::string& relPath, const ShaderDefines& defines);

  uint64_t compiles() const { return compiles_; }
  uint64_t cacheHits() const { return cacheHits_; }
  const std::string& shaderRoot() const { return root_; }
  static std::string defaultCacheDir();  // $XDG_CACHE_HOME/plume or ~/.cache/plume

 private:
  std::string readSource(const std::string& relPath) const;
  // Source text of the file and of every file it includes, recursively (for the cache key).
  void collectSources(const std::string& relPath, std::string& out, std::vector<std::string>& seen) const;

  std::string root_;
  std::string cacheDir_;
  uint64_t compiles_ = 0;
  uint64_t cacheHits_ = 0;
};

}  // namespace plume::gpu

#include "gpu/shader_compiler.h"

#include "core/error.h"
#include "core/hash.h"
#include "core/log.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <cstdlib>
#include <cstring>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <regex>
#include <sstream>

namespace plume::gpu {
namespace fs = std::filesystem;

namespace {

constexpr const char* kCompilerTag = "glslang12-vk1.2-spv1.5-v1";

void initGlslang() {
  static std::once_flag once;
  std::call_once(once, [] {
    glslang::InitializeProcess();
    std::atexit([] { glslang::FinalizeProcess(); });
  });
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return {};
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Resolves #include "name" against the including file's folder, then the shader root.
class Includer : public glslang::TShader::Includer {
 public:
  explicit Includer(std::string root) : root_(std::move(root)) {}
  IncludeResult* includeLocal(const char* name, const char* includer, size_t depth) override {
    fs::path dir = fs::path(includer).parent_path();
    for (const fs::path& candidate : {dir / name, fs::path(root_) / name}) {
      if (fs::exists(candidate)) {
        auto* text = new std::string(slurp(candidate));
        return new IncludeResult(candidate.string(), text->data(), text->size(), text);
      }
    }
    return nullptr;
  }
  IncludeResult* includeSystem(const char* name, const char* includer, size_t depth) override {
    return includeLocal(name, includer, depth);
  }
  void releaseInclude(IncludeResult* r) override {
    if (!r) return;
    delete static_cast<std::string*>(r->userData);
    delete r;
  }

 private:
  std::string root_;
};

}  // namespace

ShaderCompiler::ShaderCompiler(std::string shaderRoot, std::string cacheDir)
    : root_(std::move(shaderRoot)), cacheDir_(std::move(cacheDir)) {
  if (root_.empty()) {
    const char* env = std::getenv("PLUME_SHADER_DIR");
    root_ = env && *env ? env : PLUME_SHADER_DIR;
  }
}

std::string ShaderCompiler::defaultCacheDir() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg && *xdg) return (fs::path(xdg) / "plume").string();
  const char* home = std::getenv("HOME");
  return home && *home ? (fs::path(home) / ".cache" / "plume").string() : std::string();
}

std::string ShaderCompiler::readSource(const std::string& relPath) const {
  fs::path p = fs::path(root_) / relPath;
  if (!fs::exists(p)) {
    throw InternalError("shader not found: " + p.string() +
                        " (plume's installation is incomplete, or PLUME_SHADER_DIR names the wrong folder: set it "
                        "to the shaders/ folder of this plume)");
  }
  return slurp(p);
}

void ShaderCompiler::collectSources(const std::string& relPath, std::string& out,
                                    std::vector<std::string>& seen) const {
  for (const auto& s : seen) {
    if (s == relPath) return;
  }
  seen.push_back(relPath);
  std::string text = readSource(relPath);
  out += relPath + "\n" + text;
  static const std::regex inc(R"re(#\s*include\s*"([^"]+)")re");
  fs::path dir = fs::path(relPath).parent_path();
  for (auto it = std::sregex_iterator(text.begin(), text.end(), inc); it != std::sregex_iterator(); ++it) {
    std::string name = (*it)[1].str();
    std::string local = (dir / name).lexically_normal().string();
    collectSources(fs::exists(fs::path(root_) / local) ? local : name, out, seen);
  }
}

std::vector<uint32_t> ShaderCompiler::compile(const std::string& relPath, const ShaderDefines& defines) {
  std::string preamble;
  for (const auto& [name, value] : defines) preamble += "#define " + name + " " + value + "\n";

  std::string keySource = std::string(kCompilerTag) + "\n" + preamble;
  std::vector<std::string> seen;
  collectSources(relPath, keySource, seen);
  const std::string key = strf("%016llx", (unsigned long long)fnv1a(keySource));
  fs::path cacheFile;
  if (!cacheDir_.empty()) {
    cacheFile = fs::path(cacheDir_) / (fs::path(relPath).filename().string() + "." + key + ".spv");
    std::string blob = slurp(cacheFile);
    if (!blob.empty() && blob.size() % 4 == 0) {
      std::vector<uint32_t> spirv(blob.size() / 4);
      std::memcpy(spirv.data(), blob.data(), blob.size());
      if (spirv[0] == 0x07230203u) {
        ++cacheHits_;
        return spirv;
      }
    }
  }

  initGlslang();
  const std::string source = readSource(relPath);
  const std::string fullPath = (fs::path(root_) / relPath).string();
  glslang::TShader shader(EShLangCompute);
  const char* texts[] = {source.c_str()};
  const char* names[] = {fullPath.c_str()};
  shader.setStringsWithLengthsAndNames(texts, nullptr, names, 1);
  shader.setPreamble(preamble.c_str());
  shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);
  Includer includer(root_);
  const EShMessages messages = EShMessages(EShMsgSpvRules | EShMsgVulkanRules);
  if (!shader.parse(GetDefaultResources(), 450, false, messages, includer)) {
    throw InternalError("shader " + relPath + " failed to compile:\n" + shader.getInfoLog());
  }
  glslang::TProgram program;
  program.addShader(&shader);
  if (!program.link(messages)) {
    throw InternalError("shader " + relPath + " failed to link:\n" + program.getInfoLog());
  }
  std::vector<uint32_t> spirv;
  glslang::SpvOptions options;
  options.disableOptimizer = false;
  options.optimizeSize = false;
  glslang::GlslangToSpv(*program.getIntermediate(EShLangCompute), spirv, &options);
  ++compiles_;

  if (!cacheFile.empty()) {
    std::error_code ec;
    fs::create_directories(cacheDir_, ec);
    fs::path tmp = cacheFile;
    tmp += strf(".tmp%d", int(::getpid()));
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(spirv.data()), std::streamsize(spirv.size() * 4));
    out.close();
    if (out) fs::rename(tmp, cacheFile, ec);
    if (ec) fs::remove(tmp, ec);
  }
  return spirv;
}

}  // namespace plume::gpu

#include "core/atomic_file.h"

#include "core/error.h"
#include "core/log.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fcntl.h>
#include <unistd.h>

namespace plume {
namespace fs = std::filesystem;

namespace {
std::string tempNameFor(const std::string& target) {
  fs::path p(target);
  std::string name = strf(".%s.tmp%d", p.filename().c_str(), int(getpid()));
  return (p.parent_path() / name).string();
}
}  // namespace

void checkOutputWritable(const std::string& path) {
  fs::path p(path);
  fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw InputError(strf("%s: cannot write: folder %s does not exist", path.c_str(), dir.c_str()));
  }
  if (fs::is_directory(p, ec)) throw InputError(strf("%s: cannot write: is a folder", path.c_str()));
  if (access(dir.c_str(), W_OK) != 0) {
    throw InputError(strf("%s: cannot write: %s", path.c_str(), std::strerror(errno)));
  }
}

AtomicFile::AtomicFile(std::string target) : target_(std::move(target)) {
  checkOutputWritable(target_);
  temp_ = tempNameFor(target_);
}

AtomicFile::~AtomicFile() {
  if (!committed_) std::remove(temp_.c_str());
}

void AtomicFile::commit() {
  int fd = ::open(temp_.c_str(), O_RDONLY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
  if (std::rename(temp_.c_str(), target_.c_str()) != 0) {
    int err = errno;
    std::remove(temp_.c_str());
    throw InputError(strf("%s: cannot write: %s", target_.c_str(), std::strerror(err)));
  }
  committed_ = true;
}

}  // namespace plume

// Output files are written atomically: into a temporary file beside the target, renamed over
// it on commit(). An uncommitted AtomicFile removes its temporary file, so an interrupted or
// failed write never leaves a partial output behind.
#pragma once

#include <string>

namespace plume {

class AtomicFile {
 public:
  explicit AtomicFile(std::string target);  // throws InputError if the folder is not writable
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& tempPath() const { return temp_; }
  const std::string& target() const { return target_; }
  void commit();  // fsync + rename; throws InputError on failure

 private:
  std::string target_;
  std::string temp_;
  bool committed_ = false;
};

// Throws InputError naming `path` if a file cannot be created there (checked before long work).
void checkOutputWritable(const std::string& path);

}  // namespace plume

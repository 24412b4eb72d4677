#include "media/volume_frames.h"

#include "core/error.h"
#include "core/log.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace plume {

void checkVolumeFrames(const Scene& scene, int first, int last) {
  namespace fs = std::filesystem;
  for (size_t i = 0; i < scene.media.size(); ++i) {
    const Medium& m = scene.media[i];
    std::string firstProblem;
    int missing = 0;
    for (int frame = first; frame <= (m.animated() ? last : first); ++frame) {
      const std::string path = m.vdbPath(frame);
      std::error_code ec;
      const fs::file_status st = fs::status(path, ec);
      std::string problem;
      if (st.type() == fs::file_type::not_found) {
        problem = "file not found: " + path;
      } else if (ec) {
        problem = "cannot read " + path + ": " + ec.message();
      } else if (!fs::is_regular_file(st)) {
        problem = "not a regular file: " + path;
      } else if (::access(path.c_str(), R_OK) != 0) {
        problem = "cannot read " + path + ": " + std::strerror(errno);
      }
      if (problem.empty()) continue;
      if (missing++ == 0) firstProblem = m.animated() ? strf("frame %d: ", frame) + problem : problem;
    }
    if (missing == 0) continue;
    std::string more;
    if (missing > 1) more = strf(" (%d of frames %d-%d cannot be read)", missing, first, last);
    throw InputError(scene.path + strf(": media[%zu].vdb: ", i) + firstProblem + more);
  }
}

}  // namespace plume

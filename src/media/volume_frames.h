// The VDB files of a frame range, checked before any work starts.
#pragma once

#include "scene/scene.h"

namespace plume {

// Throws InputError "<scene>: media[i].vdb: frame F: file not found: <path>" (or "not a regular
// file", "cannot read") for the first frame in [first, last] whose VDB file of some medium cannot
// be read, so that a sequence with a hole fails before hours of rendering rather than at the hole.
// Frames --resume will skip are checked too: the range is what the job was asked for.
void checkVolumeFrames(const Scene& scene, int first, int last);

}  // namespace plume

// The light tree's descent (shaders/shared/light_tree.h lt_sample, lt_pmf) on the CPU, over the
// nodes that ltTestNodes points to: the shader's code, compiled once for every test.
#pragma once

#include "shaders/shared/light_tree.h"

#include <vector>

namespace plume::test {
inline const std::vector<shared::GpuLightNode>* ltTestNodes = nullptr;
}  // namespace plume::test

#define LT_NODE(i) (*plume::test::ltTestNodes)[i]
#include "shaders/shared/light_tree.h"
#undef LT_NODE

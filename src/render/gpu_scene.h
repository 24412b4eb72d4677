// The scene as the GPU estimators see it: lights and camera vectors in the shared GPU layout
// (shaders/shared/gpu_types.h). Shared by the path tracer and ReSTIR so that both render the same
// scene.
#pragma once

#include "gpu/pipeline.h"
#include "gpu/resources.h"
#include "io/image.h"
#include "scene/scene.h"
#include "shaders/shared/gpu_types.h"

#include <vector>

namespace plume {

// The scene's lights for the shaders (never empty: one zero light when the scene has none).
// Throws InputError for more than GPU_MAX_LIGHTS lights.
std::vector<shared::GpuLight> gpuLights(const Scene& scene);

// The lights as the shaders read them: a texel buffer of uvec4, two per light (scene/bindings.glsl).
gpu::TexelBuffer lightTexels(gpu::Context& ctx, const std::vector<shared::GpuLight>& lights);

// Camera of `frame` (DESIGN §2: right = normalize(cross(forward, up)), row 0 at the top).
shared::GpuCamera gpuCamera(const Camera& cam, int frame);
bool sameCamera(const shared::GpuCamera& a, const shared::GpuCamera& b);  // every field but the padding

// GpuFrame of `frame`: camera, medium, image size, bounces and light count from the scene;
// the random-stream seed and frame key from the caller.
shared::GpuFrame gpuFrame(const Scene& scene, int frame, uint32_t seed, uint32_t frameKey);

// The descriptor types of the kernels that walk the scene, every other binding being a storage
// buffer: the volume's (GpuVolumeResources::bindingTypes: ReSTIR's mean fields with `restir`, the
// emission atlas with `emission`), the lights and the environment map as texel buffers, and with
// `surfaces` the surfaces' (GpuSurfaces::bindingTypes, their binding numbers past `surfaceShift`).
gpu::BindingTypes sceneBindingTypes(bool restir, bool emission, bool surfaces, uint32_t surfaceShift);

// A progressive accumulation buffer (per pixel: vec4(mean rgb, n), vec4(M2 rgb, 0), Welford's
// update on the GPU) read back as the mean and the variance of the mean.
Image readAccumulation(const gpu::Buffer& accum, int width, int height);
// The same from an accumulation split into buffers of bandPixels pixels each (the last one shorter).
Image readAccumulation(const std::vector<gpu::Buffer>& bands, uint32_t bandPixels, int width, int height);

}  // namespace plume

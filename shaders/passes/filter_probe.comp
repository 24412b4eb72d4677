// The texture unit's trilinear filter, measured (render/filter_probe.cpp): a 2x2x2 image whose
// texel (x, y, z) holds x + 2y + 4z, read at fractions f spread over [0, 1)^3 the way
// volume/grid.glsl vol_filter reads the atlas (texel 0 + f, over the image's size). The filter of
// a linear function is the function: |filtered - (f.x + 2 f.y + 4 f.z)| is the weights' error,
// which the host divides by the 8 texels' spread (7).
#version 460
layout(local_size_x = 64) in;

layout(binding = 0) uniform sampler3D probeImage;
layout(std430, binding = 1) writeonly buffer ProbeOut { float probeError[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  // A three-dimensional Weyl sequence (the plastic number's powers), offset from the lattice.
  vec3 f = fract(vec3(float(i)) * vec3(0.7548776662f, 0.5698402910f, 0.4301597090f) + vec3(0.1234567f));
  float filtered = textureLod(probeImage, (f + 0.5f) / vec3(textureSize(probeImage, 0)), 0.0f).r;
  probeError[i] = abs(filtered - (f.x + 2.0f * f.y + 4.0f * f.z));
}

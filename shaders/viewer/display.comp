// Viewer display pass: the renderer's linear RGB mean (read in place from its accumulation) -> exposure -> the same filmic curve and
// sRGB encoding as the PNG previews (src/io/image.cpp toneMap) -> 8-bit pixels in the swapchain's
// byte order, fitted into the window (aspect kept, nearest neighbour, black borders). The output
// buffer is copied into the swapchain image with vkCmdCopyBufferToImage.
#version 450
layout(local_size_x = 16, local_size_y = 16) in;

// The renderer's accumulation: [2 * pixel] = (mean rgb, n), [2 * pixel + 1] = (M2 rgb, 0); row 0 at top.
layout(std430, binding = 0) readonly buffer Source { vec4 src[]; };
layout(std430, binding = 1) writeonly buffer Target { uint dst[]; };  // one packed pixel per texel

layout(push_constant) uniform Push {
  uvec4 size;  // source width, height; target width, height
  vec4 fit;    // target pixel of the source's top-left corner (x, y); source pixels per target pixel; exposure scale
  uvec4 flags; // x: 1 = BGRA byte order
} pc;

// Narkowicz's ACES fit, then the sRGB transfer function (identical to the PNG writer).
float disp_toneMap(float x) {
  x = (isnan(x) || isinf(x)) ? 0.0 : max(0.0, x);
  float y = clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
  return y <= 0.0031308 ? 12.92 * y : 1.055 * pow(y, 1.0 / 2.4) - 0.055;
}

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.size.z || p.y >= pc.size.w) return;
  vec2 s = (vec2(p) + 0.5 - pc.fit.xy) * pc.fit.z;
  vec3 c = vec3(0.0);
  if (s.x >= 0.0 && s.y >= 0.0 && s.x < float(pc.size.x) && s.y < float(pc.size.y)) {
    c = src[2u * (uint(s.y) * pc.size.x + uint(s.x))].rgb * pc.fit.w;
  }
  uvec3 b = uvec3(round(255.0 * vec3(disp_toneMap(c.r), disp_toneMap(c.g), disp_toneMap(c.b))));
  if (pc.flags.x != 0u) b = b.bgr;
  dst[p.y * pc.size.z + p.x] = b.x | (b.y << 8u) | (b.z << 16u) | (255u << 24u);
}

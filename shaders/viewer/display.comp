// Viewer display pass: the renderer's linear RGB mean (read in place from its accumulation) -> exposure -> the same filmic curve and
// sRGB encoding as the PNG previews (src/io/image.cpp toneMap) -> 8-bit pixels in the swapchain's
// byte order, fitted into the window (aspect kept, nearest neighbour, black borders). The output
// buffer is copied into the swapchain image with vkCmdCopyBufferToImage. On lavapipe the cost is
// per invocation and per store: one invocation per window pixel (a gather) cost 8.8 ms a frame at
// 320x180 in 1280x720, one per source pixel testing a 6 x 6 neighbourhood 5.5 ms, one per source
// pixel writing its solved block 3.8 ms, and with a 16-byte store per row of a 4-wide block
// ~2.6 ms (host-timed with the fill and the copy; docs/viewer.md).
#version 450
layout(local_size_x = 16, local_size_y = 16) in;

// The renderer's accumulation: [2 * pixel] = (mean rgb, n), [2 * pixel + 1] = (M2 rgb, 0); row 0 at top.
layout(std430, binding = 0) readonly buffer Source { vec4 src[]; };
layout(std430, binding = 1) writeonly buffer Target { uint dst[]; };  // one packed pixel per texel
layout(std430, binding = 1) writeonly buffer Target4 { uvec4 dst4[]; };  // the same, four at a time

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

// q of window pixel p along one axis (the source coordinate it samples): the expression every
// window pixel's mapping is defined by.
float disp_q(float p, float fit) { return (p + 0.5 - fit) * pc.fit.z; }

// The first window pixel along an axis (clamped to [0, n]) whose q is >= v: the closed-form
// estimate, moved by one where float rounding put it one off (q is monotonic in p).
int disp_first(float v, float fit, uint n) {
  float p = ceil(v / pc.fit.z + fit - 0.5);
  if (disp_q(p - 1.0, fit) >= v) p -= 1.0;
  else if (disp_q(p, fit) < v) p += 1.0;
  return int(clamp(p, 0.0, float(n)));
}

// One invocation per source pixel: its colour is tone-mapped once and written to every window
// pixel whose nearest source pixel it is (the window pixel p shows source pixel
// floor((p + 0.5 - fit.xy) * fit.z)). Tone mapping
// per window pixel cost ~15 ms a frame at 1280x720 on lavapipe (three pow per pixel, 16 window
// pixels per source pixel at the default fit); the border outside the fitted image is filled
// black before this pass (viewer/display.cpp).
void main() {
  uvec2 s = gl_GlobalInvocationID.xy;
  if (s.x >= pc.size.x || s.y >= pc.size.y) return;
  vec3 c = src[2u * (s.y * pc.size.x + s.x)].rgb * pc.fit.w;
  uvec3 b = uvec3(round(255.0 * vec3(disp_toneMap(c.r), disp_toneMap(c.g), disp_toneMap(c.b))));
  if (pc.flags.x != 0u) b = b.bgr;
  uint packed = b.x | (b.y << 8u) | (b.z << 16u) | (255u << 24u);
  // The window pixels that show s: along each axis, from the first p whose q = (p + 0.5 - fit) *
  // scale reaches s to the first whose q reaches s + 1 (estimated in closed form, then corrected by
  // the very expression every window pixel is tested with, so the blocks tile the window exactly as
  // the per-pixel rule floor(q) == s does), clamped to the window.
  ivec2 p0 = ivec2(disp_first(float(s.x), pc.fit.x, pc.size.z), disp_first(float(s.y), pc.fit.y, pc.size.w));
  ivec2 p1 = ivec2(disp_first(float(s.x + 1u), pc.fit.x, pc.size.z), disp_first(float(s.y + 1u), pc.fit.y, pc.size.w));
  if (p1.x - p0.x == 4 && (p0.x & 3) == 0 && (pc.size.z & 3u) == 0u) {
    // Blocks four pixels wide on a four-pixel grid (the default window's fit): one 16-byte store a row.
    for (int y = p0.y; y < p1.y; ++y) dst4[(uint(y) * pc.size.z + uint(p0.x)) >> 2u] = uvec4(packed);
  } else {
    for (int y = p0.y; y < p1.y; ++y) {
      for (int x = p0.x; x < p1.x; ++x) dst[uint(y) * pc.size.z + uint(x)] = packed;
    }
  }
}

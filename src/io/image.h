// Image files (the image itself: core/image.h). EXR layout: channels R,G,B; variance as var.R,
// var.G, var.B; header string attributes from `meta` (renderer version, mode, spp, seed, wall
// time...). Writes are atomic.
#pragma once

#include "core/image.h"

#include <string>
#include <vector>

namespace plume {

// Throws InputError naming the file on any failure; never leaves a partial file.
void writeExr(const std::string& path, const Image& image);
Image readExr(const std::string& path);

// Tone-mapped sRGB preview (exposure in stops, then a simple filmic curve). Never measured.
void writePng(const std::string& path, const Image& image, float exposureStops = 0.0f);
// 8-bit RGB rows, top row first (a captured window, an already tone-mapped buffer).
void writeRgb8Png(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb);

}  // namespace plume

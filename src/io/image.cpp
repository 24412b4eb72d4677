#include "io/image.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace plume {

namespace {
const char* kChannels[3] = {"R", "G", "B"};
const char* kVarChannels[3] = {"var.R", "var.G", "var.B"};
}  // namespace

void writeExr(const std::string& path, const Image& image) {
  AtomicFile file(path);
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& [key, value] : image.meta) {
      header.insert("plume." + key, Imf::StringAttribute(value));
    }
    Imf::FrameBuffer fb;
    const size_t xs = 3 * sizeof(float), ys = xs * size_t(image.width);
    for (int c = 0; c < 3; ++c) {
      header.channels().insert(kChannels[c], Imf::Channel(Imf::FLOAT));
      fb.insert(kChannels[c], Imf::Slice(Imf::FLOAT, (char*)(image.rgb.data() + c), xs, ys));
      if (image.hasVariance()) {
        header.channels().insert(kVarChannels[c], Imf::Channel(Imf::FLOAT));
        fb.insert(kVarChannels[c], Imf::Slice(Imf::FLOAT, (char*)(image.var.data() + c), xs, ys));
      }
    }
    Imf::OutputFile out(file.tempPath().c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(image.height);
  } catch (const std::exception& e) {
    throw InputError(strf("%s: cannot write EXR: %s", path.c_str(), e.what()));
  }
  file.commit();
}

Image readExr(const std::string& path) {
  try {
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    Image image(dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1,
                in.header().channels().findChannel("var.R") != nullptr);
    const size_t xs = 3 * sizeof(float), ys = xs * size_t(image.width);
    const ptrdiff_t origin = -ptrdiff_t(dw.min.x) - ptrdiff_t(dw.min.y) * image.width;
    Imf::FrameBuffer fb;
    for (int c = 0; c < 3; ++c) {
      if (!in.header().channels().findChannel(kChannels[c])) {
        throw InputError(strf("%s: EXR has no channel %s", path.c_str(), kChannels[c]));
      }
      fb.insert(kChannels[c],
                Imf::Slice(Imf::FLOAT, (char*)(image.rgb.data() + 3 * origin + c), xs, ys));
      if (image.hasVariance()) {
        fb.insert(kVarChannels[c],
                  Imf::Slice(Imf::FLOAT, (char*)(image.var.data() + 3 * origin + c), xs, ys));
      }
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    for (auto it = in.header().begin(); it != in.header().end(); ++it) {
      std::string name = it.name();
      if (name.rfind("plume.", 0) != 0) continue;
      if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) {
        image.meta[name.substr(6)] = s->value();
      }
    }
    return image;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(strf("%s: cannot read EXR: %s", path.c_str(), e.what()));
  }
}

namespace {
// Narkowicz's fit of the ACES filmic curve, then the sRGB transfer function.
float toneMap(float x) {
  x = std::max(0.0f, std::isfinite(x) ? x : 0.0f);
  float y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
  y = std::clamp(y, 0.0f, 1.0f);
  return y <= 0.0031308f ? 12.92f * y : 1.055f * std::pow(y, 1.0f / 2.4f) - 0.055f;
}
}  // namespace

void writePng(const std::string& path, const Image& image, float exposureStops) {
  const float scale = std::exp2(exposureStops);
  std::vector<unsigned char> pixels(3 * image.pixelCount());
  for (size_t i = 0; i < pixels.size(); ++i) {
    pixels[i] = (unsigned char)std::lround(255.0f * toneMap(scale * image.rgb[i]));
  }
  writeRgb8Png(path, image.width, image.height, pixels);
}

void writeRgb8Png(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb) {
  AtomicFile file(path);
  FILE* fp = std::fopen(file.tempPath().c_str(), "wb");
  if (!fp) throw InputError(strf("%s: cannot write PNG", path.c_str()));
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(fp);
    throw InputError(strf("%s: cannot write PNG", path.c_str()));
  }
  png_init_io(png, fp);
  png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) png_write_row(png, const_cast<unsigned char*>(rgb.data() + 3 * size_t(y) * width));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(fp) != 0) throw InputError(strf("%s: cannot write PNG", path.c_str()));
  file.commit();
}

}  // namespace plume

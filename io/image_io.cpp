#include "io/image_io.h"

#include "io/input_error.h"
#include "io/pending_file.h"
#include "materials/texture.h"

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

namespace ember {

namespace {

struct RawPixels {
  int width, height, channels;
  OIIO::TypeDesc format;
  std::vector<float> data;
};

RawPixels readRaw(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path + ": no such file");
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw InputError(path + ": cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  RawPixels raw{spec.width, spec.height, spec.nchannels, spec.format, {}};
  if (raw.width <= 0 || raw.height <= 0 || raw.channels <= 0)
    throw InputError(path + ": image has no pixels");
  raw.data.resize(size_t(raw.width) * size_t(raw.height) * size_t(raw.channels));
  if (!in->read_image(0, 0, 0, raw.channels, OIIO::TypeDesc::FLOAT, raw.data.data()))
    throw InputError(path + ": cannot decode image: " + in->geterror());
  in->close();
  return raw;
}

Color pixelRgb(const float* p, int channels) {
  return channels >= 3 ? Color(p[0], p[1], p[2]) : Color(p[0]);
}

void writeWithOiio(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                   const void* pixels) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw std::runtime_error(path + ": cannot create image writer: " + OIIO::geterror());
  if (!out->open(path, spec))
    throw std::runtime_error(path + ": cannot open for writing: " + out->geterror());
  if (!out->write_image(type, pixels)) throw std::runtime_error(path + ": write failed: " + out->geterror());
  if (!out->close()) throw std::runtime_error(path + ": close failed: " + out->geterror());
}

}  // namespace

TextureImage readTexture(const std::string& path, ColorEncoding encoding) {
  const RawPixels raw = readRaw(path);
  const bool integer =
      raw.format.basetype == OIIO::TypeDesc::UINT8 || raw.format.basetype == OIIO::TypeDesc::UINT16;
  const bool srgb = encoding == ColorEncoding::Srgb || (encoding == ColorEncoding::Auto && integer);
  TextureImage tex{raw.width, raw.height, {}};
  tex.texels.resize(size_t(raw.width) * size_t(raw.height));
  for (size_t i = 0; i < tex.texels.size(); ++i) {
    Color c = pixelRgb(&raw.data[i * size_t(raw.channels)], raw.channels);
    if (srgb) c = Color(srgbToLinear(c.x), srgbToLinear(c.y), srgbToLinear(c.z));
    if (!isFinite(c)) throw InputError(path + ": texture contains NaN or infinite texels");
    tex.texels[i] = glm::max(c, Color(0.0f));
  }
  return tex;
}

TextureImage textureFromBytes(const uint8_t* data, int width, int height, int channels, bool srgb) {
  TextureImage tex{width, height, {}};
  tex.texels.resize(size_t(width) * size_t(height));
  for (size_t i = 0; i < tex.texels.size(); ++i) {
    const uint8_t* p = data + i * size_t(channels);
    Color c = channels >= 3 ? Color(p[0], p[1], p[2]) / 255.0f : Color(p[0] / 255.0f);
    if (srgb) c = Color(srgbToLinear(c.x), srgbToLinear(c.y), srgbToLinear(c.z));
    tex.texels[i] = c;
  }
  return tex;
}

Image readImageRgb(const std::string& path) {
  const RawPixels raw = readRaw(path);
  Image img(raw.width, raw.height);
  for (int y = 0; y < raw.height; ++y)
    for (int x = 0; x < raw.width; ++x) {
      const size_t i = (size_t(y) * size_t(raw.width) + size_t(x)) * size_t(raw.channels);
      img.set(x, y, pixelRgb(&raw.data[i], raw.channels));
    }
  return img;
}

Metadata readStringMetadata(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path + ": no such file");
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw InputError(path + ": cannot read image: " + OIIO::geterror());
  Metadata out;
  for (const OIIO::ParamValue& p : in->spec().extra_attribs)
    if (p.type() == OIIO::TypeDesc::STRING) out.emplace_back(p.name().string(), p.get_string());
  in->close();
  return out;
}

void writeExr(const std::string& path, const Image& image, const Metadata& metadata) {
  writeAtomically(path, [&](const std::string& tmp) {
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B"};
    spec.attribute("compression", "zip");
    for (const auto& [key, value] : metadata) spec.attribute(key, value);
    writeWithOiio(tmp, spec, OIIO::TypeDesc::FLOAT, image.rgb.data());
  });
}

void writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb8) {
  writeAtomically(path, [&](const std::string& tmp) {
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    writeWithOiio(tmp, spec, OIIO::TypeDesc::UINT8, rgb8.data());
  });
}

}  // namespace ember

// The image plugin (io/image_plugin.h) on OpenImageIO: every format OpenImageIO reads (PNG, JPEG,
// TIFF at 8, 16 and 32 bits, TX, EXR, HDR, WebP, DDS, JPEG 2000...), the top level of its first
// subimage, in the file's own integer type where it has one (so that the caller decodes 8- and
// 16-bit values exactly as its other readers do) and as floats otherwise.
#include "io/image_plugin.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <memory>

namespace ember {
namespace {

namespace oiio = OIIO;

// OpenImageIO's last error for this thread, or `fallback`.
std::string lastError(const std::string& fallback) {
  std::string e = oiio::geterror();
  return e.empty() ? fallback : e;
}

std::string readOpen(oiio::ImageInput& in, int64_t maxPixels, PluginPixels& out) {
  const oiio::ImageSpec& spec = in.spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) return "image has no pixels";
  if (spec.depth > 1) return "volume images are not textures";
  const int64_t pixels = int64_t(spec.width) * int64_t(spec.height);
  if (spec.width > maxPixels || spec.height > maxPixels || pixels > maxPixels)
    return "image of " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
           " pixels is larger than Ember reads (" + std::to_string(maxPixels) + " pixels)";
  out.width = spec.width;
  out.height = spec.height;
  out.channels = spec.nchannels;
  out.channelNames = spec.channelnames;
  out.format = in.format_name();
  const size_t count = size_t(pixels) * size_t(spec.nchannels);
  const oiio::TypeDesc stored = spec.format;
  // A file's integer samples are kept as integers: scaled to [0, 1] by the caller, they are then the
  // same floats its built-in readers give. Signed and wider integers, half and float: floats.
  bool ok;
  if (stored == oiio::TypeDesc::UINT8) {
    out.type = PluginPixels::Type::U8;
    out.u8.resize(count);
    ok = in.read_image(0, 0, 0, spec.nchannels, oiio::TypeDesc::UINT8, out.u8.data());
  } else if (stored == oiio::TypeDesc::UINT16) {
    out.type = PluginPixels::Type::U16;
    out.u16.resize(count);
    ok = in.read_image(0, 0, 0, spec.nchannels, oiio::TypeDesc::UINT16, out.u16.data());
  } else {
    out.type = PluginPixels::Type::F32;
    out.f32.resize(count);
    ok = in.read_image(0, 0, 0, spec.nchannels, oiio::TypeDesc::FLOAT, out.f32.data());
  }
  if (!ok) {
    std::string e = in.geterror();
    return e.empty() ? lastError("cannot read its pixels") : e;
  }
  return "";
}

// Colours as stored: OpenImageIO would otherwise premultiply PNG, TGA and TIFF colours by an
// unassociated alpha (darkening a glTF base colour wherever its alpha is below 1), which the
// built-in readers, and glTF, do not.
const oiio::ImageSpec& readConfig() {
  static const oiio::ImageSpec config = [] {
    oiio::ImageSpec c;
    c.attribute("oiio:UnassociatedAlpha", 1);
    return c;
  }();
  return config;
}

class OiioImagePlugin final : public ImagePlugin {
 public:
  OiioImagePlugin() {
    // Ember reads images from its own threads; OpenImageIO's thread pool would only compete.
    oiio::attribute("threads", 1);
  }

  std::string read(const std::string& path, int64_t maxPixels, PluginPixels& out) const override {
    auto in = oiio::ImageInput::open(path, &readConfig());
    if (!in) return lastError("no reader for this file");
    return readOpen(*in, maxPixels, out);
  }

  std::string readMemory(const void* data, size_t size, const std::string& name, int64_t maxPixels,
                         PluginPixels& out) const override {
    oiio::Filesystem::IOMemReader proxy(data, size);
    // The name's extension picks the first reader tried; OpenImageIO then tries every reader
    // that takes an in-memory proxy.
    auto in = oiio::ImageInput::open(name, &readConfig(), &proxy);
    if (!in) return lastError("no reader for this image");
    return readOpen(*in, maxPixels, out);
  }

  std::string write(const std::string& path, const PluginPixels& px) const override {
    const oiio::TypeDesc type = px.type == PluginPixels::Type::U8    ? oiio::TypeDesc::UINT8
                                : px.type == PluginPixels::Type::U16 ? oiio::TypeDesc::UINT16
                                                                     : oiio::TypeDesc::FLOAT;
    const void* data = px.type == PluginPixels::Type::U8    ? static_cast<const void*>(px.u8.data())
                       : px.type == PluginPixels::Type::U16 ? static_cast<const void*>(px.u16.data())
                                                            : static_cast<const void*>(px.f32.data());
    const size_t count = size_t(px.width) * size_t(px.height) * size_t(px.channels);
    const size_t have = px.type == PluginPixels::Type::U8    ? px.u8.size()
                        : px.type == PluginPixels::Type::U16 ? px.u16.size()
                                                             : px.f32.size();
    if (px.width <= 0 || px.height <= 0 || px.channels <= 0 || have != count) return "no pixels to write";
    const oiio::ImageSpec spec(px.width, px.height, px.channels, type);
    const bool tx = path.size() > 3 && path.compare(path.size() - 3, 3, ".tx") == 0;
    if (tx) {
      const oiio::ImageBuf source(spec, const_cast<void*>(data));
      oiio::ImageSpec config;
      config.format = type;
      if (!oiio::ImageBufAlgo::make_texture(oiio::ImageBufAlgo::MakeTxTexture, source, path, config))
        return lastError("cannot make the texture");
      return "";
    }
    auto out = oiio::ImageOutput::create(path);
    if (!out) return lastError("no writer for this file name");
    if (!out->open(path, spec) || !out->write_image(type, data) || !out->close()) {
      std::string e = out->geterror();
      return e.empty() ? lastError("cannot write") : e;
    }
    return "";
  }

  std::string describe() const override {
    std::string formats;
    oiio::getattribute("input_format_list", formats);
    return "OpenImageIO " + std::string(OIIO_VERSION_STRING) + " (reads " + formats + ")";
  }
};

}  // namespace
}  // namespace ember

extern "C" __attribute__((visibility("default"))) ember::ImagePlugin* ember_create_image_plugin(
    int abiVersion) {
  if (abiVersion != ember::ImagePlugin::kAbiVersion) return nullptr;
  static ember::OiioImagePlugin plugin;
  return &plugin;
}

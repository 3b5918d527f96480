// The image plugin (io/image_plugin.h) on OpenImageIO: its still-image formats (PNG, JPEG, TIFF at
// 8, 16 and 32 bits, TX, EXR, HDR, WebP, DDS, JPEG 2000, PSD, GIF, BMP, PNM, SGI, ICO, Targa), the
// top level of the first subimage, in the file's own integer type where it has one (so that the
// caller decodes 8- and 16-bit values exactly as its other readers do) and as floats otherwise;
// and filtered lookups through its TextureSystem.
#include "io/image_plugin.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imagecache.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

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

// The formats images are read in: OpenImageIO's still-image readers. Its readers of video (ffmpeg),
// camera raw, DICOM, FITS, HEIF and OpenVDB are left out: no texture comes in them, and a file that
// is not an image should not reach decoders of that size. Targa, whose header has no signature,
// is tried last.
constexpr const char* kImageFormats[] = {"png", "jpeg", "tiff", "openexr", "hdr", "webp", "dds",  "jpeg2000",
                                         "psd", "gif",  "bmp",  "pnm",     "sgi", "ico",  "targa"};

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

// Images Ember decoded, by the names they are registered under with the texture system's cache.
struct MemoryImage {
  const float* rgb = nullptr;
  int width = 0, height = 0;
};
std::mutex registryMutex;
std::unordered_map<std::string, MemoryImage> registry;

// An ImageInput that reads a registered image from memory: the texture system's cache opens it
// by name (ImageCache::add_file with this creator) and reads its scanlines when it needs them.
class MemoryInput final : public oiio::ImageInput {
 public:
  const char* format_name() const override { return "ember_memory"; }
  bool open(const std::string& name, oiio::ImageSpec& spec) override {
    {
      std::lock_guard<std::mutex> lock(registryMutex);
      const auto it = registry.find(name);
      if (it == registry.end()) return false;
      image_ = it->second;
    }
    m_spec = oiio::ImageSpec(image_.width, image_.height, 3, oiio::TypeDesc::FLOAT);
    spec = m_spec;
    return true;
  }
  bool close() override { return true; }
  bool read_native_scanline(int subimage, int miplevel, int y, int, void* data) override {
    if (subimage != 0 || miplevel != 0 || y < 0 || y >= image_.height) return false;
    const size_t row = size_t(image_.width) * 3;
    std::memcpy(data, image_.rgb + size_t(y) * row, row * sizeof(float));
    return true;
  }

 private:
  MemoryImage image_;
};

oiio::ImageInput* createMemoryInput() {
  return new MemoryInput;
}

// One texture system for the process, kept until it exits: OpenImageIO 2.4's
// TextureSystem::destroy deletes its implementation through a pointer of another type (AddressSanitizer:
// new-delete-type-mismatch), and a static pointer keeps everything it holds reachable.
oiio::TextureSystem& textureSystem() {
  static oiio::TextureSystem* const ts = [] {
    oiio::TextureSystem* t = oiio::TextureSystem::create(/*shared=*/false);
    // MIP levels made on first use for images that have none, kept in 64x64 tiles.
    t->attribute("automip", 1);
    t->attribute("autotile", 64);
    // The cache's size: EMBER_TEXTURE_CACHE_MB, else 1 GiB. Textures looked up from their files
    // (addTextureFile) keep only the tiles that fit.
    float megabytes = 1024.0f;
    if (const char* env = std::getenv("EMBER_TEXTURE_CACHE_MB")) {
      const float v = std::strtof(env, nullptr);
      if (v > 0.0f && std::isfinite(v)) megabytes = v;
    }
    t->attribute("max_memory_MB", megabytes);
    // A grey file's one channel answers for all three; colours unpremultiplied, as read() reads
    // them (glTF and scene textures are not premultiplied by their alpha).
    t->attribute("gray_to_rgb", 1);
    t->attribute("unassociatedalpha", 1);
    return t;
  }();
  return *ts;
}

oiio::TextureOpt::Wrap oiioWrap(ImagePlugin::Wrap w) {
  switch (w) {
    case ImagePlugin::Wrap::Clamp:
      return oiio::TextureOpt::WrapClamp;
    case ImagePlugin::Wrap::Mirror:
      return oiio::TextureOpt::WrapMirror;
    case ImagePlugin::Wrap::Repeat:
      break;
  }
  return oiio::TextureOpt::WrapPeriodic;
}

class OiioImagePlugin final : public ImagePlugin {
 public:
  OiioImagePlugin() {
    // Ember reads images from its own threads; OpenImageIO's thread pool would only compete.
    oiio::attribute("threads", 1);
  }

  std::string read(const std::string& path, int64_t maxPixels, PluginPixels& out) const override {
    // The reader is the first of the image formats below that recognises the contents.
    for (const char* format : kImageFormats) {
      auto in = oiio::ImageInput::create(format);
      if (!in || !in->valid_file(path)) continue;
      oiio::ImageSpec spec;
      if (!in->open(path, spec, readConfig())) {
        std::string e = in->geterror();
        return e.empty() ? lastError("cannot open it as " + std::string(format)) : e;
      }
      return readOpen(*in, maxPixels, out);
    }
    return "not an image in a format Ember reads through OpenImageIO";
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

  const void* addTexture(const float* rgb, int width, int height) const override {
    static std::atomic<uint64_t> counter{0};
    const std::string name = "ember-memory-" + std::to_string(counter++);
    {
      std::lock_guard<std::mutex> lock(registryMutex);
      registry[name] = MemoryImage{rgb, width, height};
    }
    oiio::TextureSystem& ts = textureSystem();
    const oiio::ustring key(name);
    if (!ts.imagecache()->add_file(key, &createMemoryInput)) return nullptr;
    return ts.get_texture_handle(key);
  }

  const void* addTextureFile(const std::string& path, bool integersAreLinear, TextureFile& info,
                             std::string& error) const override {
    oiio::TextureSystem& ts = textureSystem();
    oiio::ImageCache& cache = *ts.imagecache();
    const oiio::ustring name(path);
    oiio::ImageSpec spec;
    if (!cache.get_imagespec(name, spec, 0, 0, /*native=*/true)) {
      error = cache.geterror();
      if (error.empty()) error = "cannot open it";
      return nullptr;
    }
    // Only the formats read() reads (the cache would otherwise open videos and camera raws too).
    oiio::ustring format;
    cache.get_image_info(name, 0, 0, oiio::ustring("fileformat"), oiio::TypeString, &format);
    bool known = false;
    for (const char* f : kImageFormats) known = known || format == f;
    if (!known) {
      error = "not an image in a format Ember reads through OpenImageIO";
      return nullptr;
    }
    info.width = spec.width;
    info.height = spec.height;
    info.channels = spec.nchannels;
    const auto base = oiio::TypeDesc::BASETYPE(spec.format.basetype);
    info.floating =
        base == oiio::TypeDesc::HALF || base == oiio::TypeDesc::FLOAT || base == oiio::TypeDesc::DOUBLE;
    int levels = 1;
    cache.get_image_info(name, 0, 0, oiio::ustring("miplevels"), oiio::TypeInt, &levels);
    info.mipmapped = levels > 1;
    if ((!info.floating && !integersAreLinear) || info.channels == 2) return nullptr;
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1) {
      error = "not a 2D image";
      return nullptr;
    }
    // The bounds, row by row through the cache (its tiles come and go; memory stays bounded).
    const int nc = std::min(spec.nchannels, 3);
    std::vector<float> row(size_t(spec.width) * size_t(nc));
    double sum[3] = {0.0, 0.0, 0.0};
    float lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::numeric_limits<float>::infinity();
      hi[c] = -std::numeric_limits<float>::infinity();
    }
    for (int y = spec.y; y < spec.y + spec.height; ++y) {
      if (!cache.get_pixels(name, 0, 0, spec.x, spec.x + spec.width, y, y + 1, spec.z, spec.z + 1, 0, nc,
                            oiio::TypeFloat, row.data())) {
        error = cache.geterror();
        if (error.empty()) error = "cannot read row " + std::to_string(y - spec.y);
        return nullptr;
      }
      for (int x = 0; x < spec.width; ++x)
        for (int c = 0; c < 3; ++c) {
          const float v = row[size_t(x) * size_t(nc) + size_t(std::min(c, nc - 1))];
          if (!std::isfinite(v)) {
            error =
                "texel (" + std::to_string(x) + ", " + std::to_string(y - spec.y) + ") is NaN or infinite";
            return nullptr;
          }
          lo[c] = std::min(lo[c], v);
          hi[c] = std::max(hi[c], v);
          sum[c] += double(v);
        }
    }
    // Negative texels: the decoder clamps them to 0, which lookups from the file could not.
    if (lo[0] < 0.0f || lo[1] < 0.0f || lo[2] < 0.0f) return nullptr;
    const double texels = double(spec.width) * double(spec.height);
    for (int c = 0; c < 3; ++c) {
      info.min[c] = lo[c];
      info.max[c] = hi[c];
      info.mean[c] = float(sum[c] / texels);
    }
    auto* handle = ts.get_texture_handle(name);
    if (!handle) error = "the texture system cannot take it";
    return handle;
  }

  bool lookup(const void* texture, Wrap wrapS, Wrap wrapT, float s, float t, float dsdx, float dtdx,
              float dsdy, float dtdy, float rgb[3]) const override {
    oiio::TextureSystem& ts = textureSystem();
    thread_local oiio::TextureSystem::Perthread* thread = ts.get_perthread_info();
    oiio::TextureOpt opt;
    opt.swrap = oiioWrap(wrapS);
    opt.twrap = oiioWrap(wrapT);
    opt.mipmode = oiio::TextureOpt::MipModeTrilinear;
    opt.interpmode = oiio::TextureOpt::InterpBilinear;
    auto* handle = static_cast<oiio::TextureSystem::TextureHandle*>(const_cast<void*>(texture));
    return ts.texture(handle, thread, opt, s, t, dsdx, dtdx, dsdy, dtdy, 3, rgb);
  }

  std::string describe() const override {
    std::string formats;
    for (const char* format : kImageFormats)
      if (oiio::ImageInput::create(format)) {
        if (!formats.empty()) formats += ',';
        formats += format;
      }
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

// The image plugin: OpenImageIO behind a module that `ember` loads on first use.
//
// Why a module: libOpenImageIO has 37 direct dependencies (ffmpeg, OpenCV, DCMTK, OpenVDB...) and
// linking it costs every process start about 0.25 s, `ember --help` included. So OpenImageIO is
// linked only into `libember_oiio.so` (io/oiio/), which `imagePlugin()` dlopens the first time an
// image is read. A build or an install without the module still renders: images then go through
// the built-in readers (io/image_io.h says which), and `ember info` says so.
//
// The interface crosses the module boundary as plain C++ of the same compiler and standard library
// (both sides are built together by this project); the module links nothing of Ember's.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ember {

// An image's top level, as stored: `channels` per pixel, rows from the top of the image.
struct PluginPixels {
  enum class Type { U8, U16, F32 };
  int width = 0, height = 0, channels = 0;
  Type type = Type::U8;
  std::vector<uint8_t> u8;    // Type::U8
  std::vector<uint16_t> u16;  // Type::U16
  std::vector<float> f32;     // Type::F32 (half, float and every other type, converted)
  std::vector<std::string> channelNames;
  std::string format;  // OpenImageIO's name of the file format ("png", "tiff", "openexr"...)
};

class ImagePlugin {
 public:
  static constexpr int kAbiVersion = 3;
  virtual ~ImagePlugin() = default;
  // The largest width x height read (the caller's limit), checked before pixels are allocated.
  // Returns "" on success, else the reason, without the file's name.
  virtual std::string read(const std::string& path, int64_t maxPixels, PluginPixels& out) const = 0;
  // Writes `pixels` in the format the path's extension names (U8, U16 or F32 as stored); ".tx"
  // writes a tiled, MIP-mapped texture (OpenImageIO's maketx). Returns "" or the reason.
  virtual std::string write(const std::string& path, const PluginPixels& pixels) const = 0;
  // "OpenImageIO 2.4.7" and the formats it reads.
  virtual std::string describe() const = 0;

  // Filtered textures, through OpenImageIO's TextureSystem. addTexture serves an image Ember has
  // decoded (linear RGB floats, rows from the top; they must outlive the process's lookups) to the
  // texture system from memory, which makes its MIP levels on first use. nullptr on failure.
  virtual const void* addTexture(const float* rgb, int width, int height) const = 0;
  // A texture looked up straight from its file: its tiles are read when a lookup needs them and
  // kept in the texture system's cache (EMBER_TEXTURE_CACHE_MB, default 1024), its MIP levels the
  // file's own (a .tx, a tiled MIP-mapped EXR) or made on first use. Level 0 is read once, row by
  // row through the cache, for the bounds of its first three channels (a single channel counts
  // for all three), so memory stays within the cache however large the file.
  struct TextureFile {
    int width = 0, height = 0, channels = 0;
    bool floating = false;  // stored as half or float (else integers, normalised to [0, 1])
    bool mipmapped = false;
    float min[3] = {0, 0, 0}, max[3] = {0, 0, 0}, mean[3] = {0, 0, 0};
  };
  // Fills `info` and returns the handle, or nullptr and the reason (without the file's name) in
  // `error`. Also nullptr, with `error` empty, for a file this cannot serve as stored: integers
  // when `integersAreLinear` is false (they are sRGB-encoded, and the texture system would filter
  // the encoded values), two channels (grey and alpha), or negative texels (which the decoder
  // clamps to 0). NaN or infinite texels are an error.
  virtual const void* addTextureFile(const std::string& path, bool integersAreLinear, TextureFile& info,
                                     std::string& error) const = 0;
  enum class Wrap { Clamp, Repeat, Mirror };
  // The texture at (s, t) (s along the width, t down the rows, [0, 1] over the image), filtered
  // trilinearly over the footprint the derivatives span. False on a read error.
  virtual bool lookup(const void* texture, Wrap wrapS, Wrap wrapT, float s, float t, float dsdx, float dtdx,
                      float dsdy, float dtdy, float rgb[3]) const = 0;
};

// The plugin, loaded on the first call (thread-safe); nullptr when it cannot be: then
// imagePluginError() says why. EMBER_OIIO_PLUGIN names the module file to load instead of the
// search (beside the executable, then the build tree); EMBER_OIIO_PLUGIN=none disables it.
const ImagePlugin* imagePlugin();
const std::string& imagePluginError();

}  // namespace ember

// The module's one export: a new plugin if its ABI is `abiVersion`, else nullptr.
extern "C" ember::ImagePlugin* ember_create_image_plugin(int abiVersion);

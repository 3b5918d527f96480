#include "io/image_io.h"

#include "io/image_plugin.h"
#include "io/input_error.h"
#include "io/pending_file.h"
#include "materials/texture.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfTestFile.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <bit>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <sstream>
#include <type_traits>

namespace ember {

namespace {

// An image file's pixels as floats, `channels` per pixel, rows from the top.
struct RawPixels {
  int width = 0, height = 0, channels = 0;
  bool integer = false;  // stored as 8- or 16-bit integers (then sRGB-encoded unless told otherwise)
  std::vector<float> data;
};

void checkExists(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path + ": no such file");
}

// At most 16384 x 16384 pixels (3 GB as float RGB): a header that claims more is rejected before
// anything of its size is allocated. Fuzzing builds take 1024 x 1024, so that a mutated header
// costs a fuzz input milliseconds and megabytes rather than seconds and gigabytes; the checks
// behind the limit are the same.
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
constexpr int64_t kMaxPixels = int64_t(1) << 20;
#else
constexpr int64_t kMaxPixels = int64_t(1) << 28;
#endif

// OpenEXR sizes its line-offset tables by the header's data window before we see it: its own
// limits on a side, checked as it reads the header, keep a mutated header from allocating
// gigabytes there.
void limitOpenExr() {
  static const bool once = [] {
    const int side = int(std::min<int64_t>(kMaxPixels, int64_t(1) << 20));
    Imf::Header::setMaxImageSize(side, side);
    Imf::Header::setMaxTileSize(side, side);
    return true;
  }();
  (void)once;
}

// OpenEXR allocates each header attribute at the size the file declares for it: a mutated size of
// a gigabyte costs a gigabyte before the read fails. So the attributes are walked here first (name,
// type name, 32-bit size, value; an empty name ends a header, and an empty header ends the headers
// of a multi-part file), and a size that runs past the end of the file is rejected. Only the
// headers are read: each value is skipped by seeking, so the pixels are read once, by OpenEXR.
void checkExrAttributeSizes(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const auto fileSize = uint64_t(std::max<std::streamoff>(0, in.tellg()));
  const auto truncated = [&] { return InputError(path + ": EXR file ends inside its header"); };
  char version[8];
  if (!in.seekg(0) || !in.read(version, sizeof version)) throw truncated();
  const bool multiPart = (uint8_t(version[5]) & 0x10) != 0;  // version field bit 12
  const auto readString = [&]() {
    std::string text;
    for (char c; in.get(c);) {
      if (c == 0) return text;
      text += c;
    }
    throw truncated();
  };
  for (bool firstOfHeader = true;;) {
    const std::string name = readString();
    if (name.empty()) {
      if (!multiPart || firstOfHeader) return;  // the end of the (last) header
      firstOfHeader = true;
      continue;
    }
    firstOfHeader = false;
    readString();      // the type name
    int32_t size = 0;  // little-endian, as x86 and ARM hosts are
    if (!in.read(reinterpret_cast<char*>(&size), sizeof size)) throw truncated();
    const uint64_t pos = uint64_t(in.tellg());
    if (size < 0 || uint64_t(size) > fileSize - pos)
      throw InputError(path + ": EXR header attribute '" + name + "' declares " + std::to_string(size) +
                       " bytes, more than the file holds");
    in.seekg(std::streamoff(size), std::ios::cur);
  }
}

void checkSize(const std::string& path, int64_t width, int64_t height) {
  if (width <= 0 || height <= 0) throw InputError(path + ": image has no pixels");
  if (width > kMaxPixels || height > kMaxPixels || width * height > kMaxPixels)
    throw InputError(path + ": image of " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels is larger than Ember reads (" + std::to_string(kMaxPixels) + " pixels)");
}

// The channels an EXR's pixels are read from: R, G and B when it has any of them (a missing one
// reads as 0), else Y (luminance), else its first channel, read as grey.
std::vector<std::string> exrColourChannels(const Imf::ChannelList& channels) {
  if (channels.findChannel("R") || channels.findChannel("G") || channels.findChannel("B"))
    return {"R", "G", "B"};
  if (channels.findChannel("Y")) return {"Y"};
  if (channels.begin() != channels.end()) return {channels.begin().name()};
  return {};
}

// An EXR opened for reading, its header checked first (limitOpenExr, checkExrAttributeSizes), and
// its data window's size checked.
struct OpenedExr {
  Imf::InputFile file;
  Imath::Box2i window;
  int64_t width, height;
  explicit OpenedExr(const std::string& path)
      : file((limitOpenExr(), checkExrAttributeSizes(path), path.c_str())),
        window(file.header().dataWindow()),
        width(int64_t(window.max.x) - window.min.x + 1),
        height(int64_t(window.max.y) - window.min.y + 1) {
    checkSize(path, width, height);
  }
};

// The string attributes of an open EXR's header (its ember:* metadata among them).
Metadata stringAttributes(const Imf::Header& header) {
  Metadata out;
  for (auto it = header.begin(); it != header.end(); ++it)
    if (const auto* a = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
      out.emplace_back(it.name(), a->value());
  return out;
}

RawPixels readExr(const std::string& path) {
  try {
    OpenedExr exr(path);
    Imf::InputFile& file = exr.file;
    const Imath::Box2i window = exr.window;
    const int64_t width = exr.width, height = exr.height;
    const std::vector<std::string> names = exrColourChannels(file.header().channels());
    if (names.empty()) throw InputError(path + ": image has no channels");
    RawPixels raw{int(width), int(height), int(names.size()), false, {}};
    raw.data.resize(size_t(width) * size_t(height) * names.size());
    Imf::FrameBuffer frame;
    const size_t xStride = names.size() * sizeof(float), yStride = xStride * size_t(width);
    for (size_t c = 0; c < names.size(); ++c)
      frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, raw.data.data() + c, window, xStride, yStride));
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return raw;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {  // OpenEXR's exceptions (Iex) and std::bad_alloc
    throw InputError(path + ": cannot read image: " + e.what());
  }
}

std::vector<unsigned char> fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() > size_t(std::numeric_limits<int>::max()))
    throw InputError(path + ": image file too large");
  return bytes;
}

// PNG, JPEG, BMP, TGA, PSD, GIF, PNM and Radiance HDR through stb_image: 8- and 16-bit files as
// integers scaled to [0, 1], HDR files as their floats.
RawPixels readStb(const std::string& path, const std::vector<unsigned char>& bytes) {
  const auto* data = bytes.data();
  const int size = int(bytes.size());
  RawPixels raw;
  const auto fail = [&]() {
    return InputError(path +
                      ": cannot read image: " + (stbi_failure_reason() ? stbi_failure_reason() : "unknown"));
  };
  if (!stbi_info_from_memory(data, size, &raw.width, &raw.height, &raw.channels)) throw fail();
  checkSize(path, raw.width, raw.height);
  if (raw.channels <= 0) throw InputError(path + ": image has no channels");
  const size_t count = size_t(raw.width) * size_t(raw.height) * size_t(raw.channels);
  int w = 0, h = 0, n = 0;
  if (stbi_is_hdr_from_memory(data, size)) {
    const std::unique_ptr<float, decltype(&stbi_image_free)> px(
        stbi_loadf_from_memory(data, size, &w, &h, &n, 0), &stbi_image_free);
    if (!px) throw fail();
    raw.data.assign(px.get(), px.get() + count);
  } else {
    // 8- or 16-bit integers, scaled so that the largest value reads as 1.
    const auto scaled = [&](auto* pixels, float maxValue) {
      const std::unique_ptr<std::remove_pointer_t<decltype(pixels)>, decltype(&stbi_image_free)> px(
          pixels, &stbi_image_free);
      if (!px) throw fail();
      raw.integer = true;
      raw.data.resize(count);
      for (size_t i = 0; i < count; ++i) raw.data[i] = float(px.get()[i]) / maxValue;
    };
    if (stbi_is_16_bit_from_memory(data, size))
      scaled(stbi_load_16_from_memory(data, size, &w, &h, &n, 0), 65535.0f);
    else
      scaled(stbi_load_from_memory(data, size, &w, &h, &n, 0), 255.0f);
  }
  if (w != raw.width || h != raw.height || n != raw.channels)
    throw InputError(path + ": image changed size while decoding");
  return raw;
}

// Portable float map (PFM), as pbrt and Mitsuba read it: "PF" (RGB) or "Pf" (grey), the width and
// height, then a scale whose sign gives the byte order (negative: little-endian), then the floats,
// rows from the bottom of the image.
bool isPfm(const std::vector<unsigned char>& bytes) {
  return bytes.size() >= 3 && bytes[0] == 'P' && (bytes[1] == 'F' || bytes[1] == 'f') &&
         std::isspace(bytes[2]);
}

RawPixels readPfm(const std::string& path, const std::vector<unsigned char>& bytes) {
  const std::string head(bytes.begin(), bytes.begin() + ptrdiff_t(std::min<size_t>(bytes.size(), 256)));
  std::istringstream in(head);
  std::string magic;
  int64_t width = 0, height = 0;
  double scale = 0.0;
  if (!(in >> magic >> width >> height >> scale) || !std::isspace(in.get()))
    throw InputError(path + ": PFM header is malformed");
  checkSize(path, width, height);
  if (!std::isfinite(scale) || scale == 0.0) throw InputError(path + ": PFM header gives an invalid scale");
  const int channels = magic == "PF" ? 3 : 1;
  const size_t count = size_t(width) * size_t(height) * size_t(channels);
  const size_t offset = size_t(in.tellg());
  if (bytes.size() - offset < count * sizeof(float))
    throw InputError(path + ": PFM file is shorter than its header says (" + std::to_string(width) + "x" +
                     std::to_string(height) + ")");
  const bool fileLittle = scale < 0.0, hostLittle = std::endian::native == std::endian::little;
  RawPixels raw{int(width), int(height), channels, false, std::vector<float>(count)};
  const size_t row = size_t(width) * size_t(channels);
  for (size_t y = 0; y < size_t(height); ++y)
    for (size_t i = 0; i < row; ++i) {
      uint32_t bits = 0;
      std::memcpy(&bits, &bytes[offset + ((size_t(height) - 1 - y) * row + i) * sizeof(float)], sizeof bits);
      if (fileLittle != hostLittle) bits = __builtin_bswap32(bits);
      std::memcpy(&raw.data[y * row + i], &bits, sizeof bits);
    }
  return raw;
}

// Any format OpenImageIO reads, through the image plugin: 8- and 16-bit integers scaled to [0, 1]
// as readStb scales them, so that both give the same floats for the same samples.
RawPixels readPlugin(const std::string& path, const ImagePlugin& plugin) {
  PluginPixels px;
  const std::string error = plugin.read(path, kMaxPixels, px);
  if (!error.empty()) throw InputError(path + ": cannot read image: " + error);
  RawPixels raw{px.width, px.height, px.channels, px.type != PluginPixels::Type::F32, {}};
  switch (px.type) {
    case PluginPixels::Type::U8:
      raw.data.resize(px.u8.size());
      for (size_t i = 0; i < px.u8.size(); ++i) raw.data[i] = float(px.u8[i]) / 255.0f;
      break;
    case PluginPixels::Type::U16:
      raw.data.resize(px.u16.size());
      for (size_t i = 0; i < px.u16.size(); ++i) raw.data[i] = float(px.u16[i]) / 65535.0f;
      break;
    case PluginPixels::Type::F32:
      raw.data = std::move(px.f32);
      break;
  }
  return raw;
}

// The file's first bytes, enough to tell a PFM (isPfm) before reading the whole file.
std::vector<unsigned char> fileHead(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  std::vector<unsigned char> head(3);
  in.read(reinterpret_cast<char*>(head.data()), std::streamsize(head.size()));
  head.resize(size_t(in.gcount()));
  return head;
}

RawPixels readRaw(const std::string& path) {
  checkExists(path);
  if (Imf::isOpenExrFile(path.c_str())) return readExr(path);
  if (isPfm(fileHead(path))) return readPfm(path, fileBytes(path));
  // The plugin reads the file itself: no copy of it here.
  if (const ImagePlugin* plugin = imagePlugin()) return readPlugin(path, *plugin);
  return readStb(path, fileBytes(path));
}

Color pixelRgb(const float* p, int channels) {
  return channels >= 3 ? Color(p[0], p[1], p[2]) : Color(p[0]);
}

}  // namespace

TextureImage readTexture(const std::string& path, ColorEncoding encoding) {
  const RawPixels raw = readRaw(path);
  const bool srgb = encoding == ColorEncoding::Srgb || (encoding == ColorEncoding::Auto && raw.integer);
  TextureImage tex{raw.width, raw.height, {}};
  tex.texels.resize(size_t(raw.width) * size_t(raw.height));
  for (size_t i = 0; i < tex.texels.size(); ++i) {
    Color c = pixelRgb(&raw.data[i * size_t(raw.channels)], raw.channels);
    if (srgb) c = Color(decodeSrgb(c.x), decodeSrgb(c.y), decodeSrgb(c.z));
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
    if (srgb) c = Color(decodeSrgb(c.x), decodeSrgb(c.y), decodeSrgb(c.z));
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
  checkExists(path);
  if (!Imf::isOpenExrFile(path.c_str())) {
    readRaw(path);  // an unreadable file is an error here too; other formats carry no metadata we read
    return {};
  }
  try {
    limitOpenExr();
    checkExrAttributeSizes(path);
    const Imf::InputFile file(path.c_str());
    return stringAttributes(file.header());
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read image: " + e.what());
  }
}

void writeExr(const std::string& path, const Image& image, const Metadata& metadata) {
  writeExr(path, image, {}, metadata);
}

void writeExr(const std::string& path, const Image& image, const std::vector<ImageLayer>& layers,
              const Metadata& metadata) {
  const size_t pixels = size_t(image.width) * size_t(image.height);
  for (const ImageLayer& layer : layers)
    if (layer.pixels.size() != pixels * layer.channels.size())
      throw std::invalid_argument(path + ": layer " + layer.channels.front() + " has the wrong size");
  writeAtomically(path, [&](const std::string& tmp) {
    try {
      Imf::Header header(image.width, image.height);
      header.compression() = Imf::ZIP_COMPRESSION;
      for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
      Imf::FrameBuffer frame;
      // OpenEXR's slices take a non-const base pointer, but an output file only reads through it.
      const auto add = [&](const std::string& name, const float* first, size_t stride) {
        if (header.channels().findChannel(name))
          throw std::invalid_argument("two layers write channel " + name);
        header.channels().insert(name, Imf::Channel(Imf::FLOAT));
        char* base = reinterpret_cast<char*>(const_cast<float*>(first));
        frame.insert(name, Imf::Slice(Imf::FLOAT, base, stride * sizeof(float),
                                      stride * sizeof(float) * size_t(image.width)));
      };
      const char* rgb[] = {"R", "G", "B"};
      for (size_t c = 0; c < 3; ++c) add(rgb[c], image.rgb.data() + c, 3);
      for (const ImageLayer& layer : layers)
        for (size_t c = 0; c < layer.channels.size(); ++c)
          add(layer.channels[c], layer.pixels.data() + c, layer.channels.size());
      Imf::OutputFile file(tmp.c_str(), header);
      file.setFrameBuffer(frame);
      file.writePixels(image.height);
    } catch (const std::exception& e) {
      throw std::runtime_error(path + ": cannot write EXR: " + e.what());
    }
  });
}

ExrChannels readExrChannels(const std::string& path) {
  checkExists(path);
  if (!Imf::isOpenExrFile(path.c_str())) throw InputError(path + ": not an OpenEXR file");
  try {
    OpenedExr exr(path);
    Imf::InputFile& file = exr.file;
    const Imath::Box2i window = exr.window;
    const int64_t width = exr.width, height = exr.height;
    ExrChannels out;
    out.width = int(width);
    out.height = int(height);
    Imf::FrameBuffer frame;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
        throw InputError(path + ": channel " + it.name() + " is subsampled; Ember reads whole channels");
      std::vector<float>& data = out.channels[it.name()];
      data.resize(size_t(width) * size_t(height));
      frame.insert(it.name(), Imf::Slice::Make(Imf::FLOAT, data.data(), window, sizeof(float),
                                               sizeof(float) * size_t(width)));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    out.metadata = stringAttributes(file.header());
    return out;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read image: " + e.what());
  }
}

void writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb8) {
  writeAtomically(path, [&](const std::string& tmp) {
    if (!stbi_write_png(tmp.c_str(), width, height, 3, rgb8.data(), width * 3))
      throw std::runtime_error(path + ": cannot write PNG");
  });
}

}  // namespace ember

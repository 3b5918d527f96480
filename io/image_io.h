// Image files: textures in, linear float EXR and 8-bit PNG out. EXR through OpenEXR; PFM (portable
// float map) read here; every other format through OpenImageIO's image plugin (io/image_plugin.h:
// PNG, JPEG, TIFF at 8, 16 and 32 bits, TX, HDR, WebP...), or, where the plugin cannot be loaded,
// through stb_image (PNG, JPEG, BMP, TGA, PSD, GIF, PNM, HDR). PNG out through stb_image_write.
// Every output is written to a temporary file in the destination folder and renamed into place,
// so a failed or interrupted run never leaves a half-written image under the requested name.
#pragma once

#include "renderer/film.h"

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace ember {

enum class ColorEncoding { Auto, Srgb, Linear };

struct TextureImage {
  int width = 0;
  int height = 0;
  std::vector<Color> texels;  // linear, row 0 = first row of the file
};

// Reads any of the formats above, told apart by their contents, not their names. Auto decodes 8-
// and 16-bit integer files from sRGB and keeps float files (EXR, HDR, PFM) linear. One or two channels
// are read as grey; an EXR is read from its R, G, B channels, else Y, else its first channel.
TextureImage readTexture(const std::string& path, ColorEncoding encoding);
// Same, from pixels already decoded to 8 bits per channel (e.g. by tinygltf).
TextureImage textureFromBytes(const uint8_t* data, int width, int height, int channels, bool srgb);

// An image file as linear float RGB, its channels chosen as readTexture's (no colour decoding).
Image readImageRgb(const std::string& path);

using Metadata = std::vector<std::pair<std::string, std::string>>;
void writeExr(const std::string& path, const Image& image, const Metadata& metadata = {});
// A multilayer EXR: the colour as R, G, B and each layer's channels under their own names.
void writeExr(const std::string& path, const Image& image, const std::vector<ImageLayer>& layers,
              const Metadata& metadata);
// Every channel of an EXR by name (width * height floats each), and its string attributes; an
// InputError naming the file for anything else.
struct ExrChannels {
  int width = 0, height = 0;
  std::map<std::string, std::vector<float>> channels;
  Metadata metadata;
  bool has(const std::string& name) const { return channels.count(name) != 0; }
};
ExrChannels readExrChannels(const std::string& path);
// The string attributes of an EXR's header (its ember:* metadata); none for other formats.
Metadata readStringMetadata(const std::string& path);
void writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb8);

}  // namespace ember

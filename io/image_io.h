// Image files through OpenImageIO: textures in, linear float EXR and 8-bit PNG out. Every output is
// written to a temporary file in the destination folder and renamed into place, so a failed or
// interrupted run never leaves a half-written image under the requested name.
#pragma once

#include "renderer/film.h"

#include <cstdint>
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

// Reads any format OIIO knows. Auto decodes 8- and 16-bit integer files from sRGB and keeps float
// files (EXR, HDR) linear. One or two channels are read as grey.
TextureImage readTexture(const std::string& path, ColorEncoding encoding);
// Same, from pixels already decoded to 8 bits per channel (e.g. by tinygltf).
TextureImage textureFromBytes(const uint8_t* data, int width, int height, int channels, bool srgb);

// The first three channels of an image file as linear float RGB (no colour decoding).
Image readImageRgb(const std::string& path);

using Metadata = std::vector<std::pair<std::string, std::string>>;
void writeExr(const std::string& path, const Image& image, const Metadata& metadata = {});
// The string attributes of an image file's header (an EXR's ember:* metadata).
Metadata readStringMetadata(const std::string& path);
void writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb8);

}  // namespace ember

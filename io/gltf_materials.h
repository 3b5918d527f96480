// glTF 2.0 materials as Ember sees them (docs/gltf.md has the table): pbrMetallicRoughness with
// all its textures becomes a GltfPbrMaterial; normal, emissive and alpha textures become a mesh's
// SurfaceMaps and MeshOpacity; KHR_materials_emissive_strength, _transmission, _ior, _volume
// (thickness) and KHR_texture_transform are read. Each glTF material is converted once.
#pragma once

#include "io/image_plugin.h"
#include "materials/surface_maps.h"
#include "renderer/scene.h"

#include <tiny_gltf.h>

#include <map>
#include <string>

namespace ember {

struct GltfSurface {
  const Material* material = nullptr;
  // The highest texture coordinate set a texture of the material reads, and where: a primitive
  // without that TEXCOORD_n cannot use the material.
  int maxTexCoord = 0;
  std::string maxTexCoordWhere;
  bool needsTangents = false;  // a normal map other than the surface's own reads tangents (the coat's)
  Color emission{0.0f};        // emissiveFactor x emissiveStrength
  bool doubleSided = false;    // both faces emit (and are shaded with the normal facing the viewer)
  std::shared_ptr<const SurfaceMaps> maps;
  std::shared_ptr<const MeshOpacity> opacity;
};

class GltfMaterialReader {
 public:
  // `filtering`: images become trilinear textures through this plugin (GltfImportOptions);
  // null: the samplers' filters.
  GltfMaterialReader(const tinygltf::Model& model, const std::string& path, Scene& scene,
                     const ImagePlugin* filtering = nullptr)
      : model_(model), path_(path), scene_(scene), filtering_(filtering) {}

  // The surface for material index `index` (-1 or out of range: the spec's default material).
  // `vertexColors`: the primitive has COLOR_0, which multiplies the base colour and its alpha;
  // the two uses of a material get a surface each.
  const GltfSurface& surface(int index, bool vertexColors = false);

 private:
  struct Decoded {  // an image's channels, not yet colour-decoded
    int width = 0, height = 0, channels = 0;
    const std::vector<unsigned char>* bytes = nullptr;  // 8-bit images: tinygltf's own pixels
    std::vector<float> values;                          // 16-bit images: as floats in [0, 1]
  };
  enum class Channels { SrgbRgb, LinearRgb, Alpha, MetallicRoughness, Red, Green };

  GltfSurface convert(int index, bool vertexColors);
  // The textureInfo `key` of an extension object (a plain JSON value), or null without one.
  std::shared_ptr<const Texture> extensionTexture(const tinygltf::Value& ext, const char* key,
                                                  Channels channels, const Color& scale,
                                                  const std::string& where, float* normalScale = nullptr);
  std::shared_ptr<const Texture> texture(const tinygltf::TextureInfo& info, Channels channels,
                                         const Color& scale, const std::string& where);
  std::shared_ptr<const Texture> texture(int index, int texCoord, const tinygltf::ExtensionMap& extensions,
                                         Channels channels, const Color& scale, const std::string& where);
  const Decoded* decode(int image, const std::string& where);
  // The texels of `channels` (glTF's use of the image's channels) from a 16-bit image's floats, or
  // the tables and byte positions that give the same values from an 8-bit image's bytes.
  static std::vector<Color> floatTexels(const Decoded& img, Channels channels);
  static ImageTexture::ByteChannels byteChannels(const Decoded& img, Channels channels);
  // The floats those tables give, texel by texel (for a filtered texture, which keeps floats).
  static std::vector<Color> byteTexels(const Decoded& img, const ImageTexture::ByteChannels& in);
  [[noreturn]] void fail(const std::string& where, const std::string& what) const;
  void warn(const std::string& where, const std::string& what) const;

  const tinygltf::Model& model_;
  std::string path_;
  Scene& scene_;
  const ImagePlugin* filtering_;
  std::map<std::pair<int, bool>, GltfSurface> surfaces_;
  GltfSurface* converting_ = nullptr;  // the surface convert() is filling: texture() notes its sets
  std::map<int, Decoded> images_;
};

}  // namespace ember

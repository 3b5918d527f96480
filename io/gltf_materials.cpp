#include "io/gltf_materials.h"

#include "io/filtered_texture.h"
#include "io/input_error.h"
#include "materials/gltf_pbr.h"
#include "materials/lambertian.h"

#include <cstdio>
#include <cstring>
#include <functional>

namespace ember {

namespace {

float numberOr(const tinygltf::Value& object, const char* key, float fallback) {
  if (!object.IsObject() || !object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  return v.IsNumber() ? float(v.GetNumberAsDouble()) : std::numeric_limits<float>::quiet_NaN();
}

const tinygltf::Value* extension(const tinygltf::ExtensionMap& extensions, const char* name) {
  const auto it = extensions.find(name);
  return it == extensions.end() ? nullptr : &it->second;
}

// Extension objects nested inside an extension (a transmissionTexture's KHR_texture_transform)
// reach us as plain JSON values rather than tinygltf's parsed ExtensionMap.
tinygltf::ExtensionMap extensionsOf(const tinygltf::Value& info) {
  tinygltf::ExtensionMap out;
  const tinygltf::Value& ext = info.Get("extensions");
  for (const std::string& key : ext.Keys()) out[key] = ext.Get(key);
  return out;
}

TextureWrap wrapMode(int glMode) {
  if (glMode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return TextureWrap::Clamp;
  if (glMode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return TextureWrap::Mirror;
  return TextureWrap::Repeat;  // the spec's default
}

}  // namespace

void GltfMaterialReader::fail(const std::string& where, const std::string& what) const {
  throw InputError(path_ + ": " + where + ": " + what);
}

void GltfMaterialReader::warn(const std::string& where, const std::string& what) const {
  std::fprintf(stderr, "ember: %s: %s: %s\n", path_.c_str(), where.c_str(), what.c_str());
}

const GltfSurface& GltfMaterialReader::surface(int index, bool vertexColors) {
  if (index < 0 || size_t(index) >= model_.materials.size()) index = -1;
  const std::pair<int, bool> key(index, vertexColors);
  if (const auto it = surfaces_.find(key); it != surfaces_.end()) return it->second;
  GltfSurface& out = surfaces_[key];
  out = convert(index, vertexColors);
  converting_ = nullptr;
  return out;
}

std::shared_ptr<const Texture> GltfMaterialReader::extensionTexture(const tinygltf::Value& ext,
                                                                    const char* key, Channels channels,
                                                                    const Color& scale,
                                                                    const std::string& where,
                                                                    float* normalScale) {
  if (!ext.Has(key)) return nullptr;
  const std::string w = where + "." + key;
  const tinygltf::Value& info = ext.Get(key);
  if (!info.IsObject()) fail(w, "expected a textureInfo object");
  const float tex = numberOr(info, "index", -1.0f);
  if (!(tex >= 0.0f && tex < 1e9f)) fail(w + ".index", "expected a texture index");
  const float texCoord = numberOr(info, "texCoord", 0.0f);
  if (!(texCoord >= 0.0f && texCoord < 16.0f)) fail(w + ".texCoord", "expected 0..15");
  if (normalScale) {
    *normalScale = numberOr(info, "scale", 1.0f);
    if (!std::isfinite(*normalScale)) fail(w + ".scale", "expected a number");
  }
  return texture(int(tex), int(texCoord),
                 info.Has("extensions") ? extensionsOf(info) : tinygltf::ExtensionMap{}, channels, scale, w);
}

namespace {

// A factor array of `n` finite numbers (KHR extension colours), or `fallback` without one.
Color colorFactor(const tinygltf::Value& ext, const char* key, const Color& fallback,
                  const std::string& where, float maxValue,
                  const std::function<void(const std::string&, const std::string&)>& fail) {
  if (!ext.Has(key)) return fallback;
  const tinygltf::Value& c = ext.Get(key);
  if (!c.IsArray() || c.ArrayLen() != 3) fail(where + "." + key, "expected 3 numbers");
  Color out;
  for (int k = 0; k < 3; ++k) {
    out[k] = c.Get(k).IsNumber() ? float(c.Get(k).GetNumberAsDouble()) : -1.0f;
    if (!(out[k] >= 0.0f && out[k] <= maxValue))
      fail(where + "." + key,
           "expected numbers in [0, " + (maxValue > 1e30f ? std::string("inf") : "1") + ")");
  }
  return out;
}

}  // namespace

GltfSurface GltfMaterialReader::convert(int index, bool vertexColors) {
  GltfSurface out;
  converting_ = &out;
  if (index < 0) {
    // The specification's default material (section 3.9.6): every property at its default, i.e.
    // a white, fully rough metal.
    GltfPbrInputs in;
    in.baseColor = std::make_shared<ConstantTexture>(Color(1.0f));
    if (vertexColors) in.baseColor = std::make_shared<VertexColorTexture>(std::move(in.baseColor));
    in.metallicRoughness = std::make_shared<ConstantTexture>(Color(0.0f, 1.0f, 1.0f));
    out.material = scene_.addMaterial("(glTF default)", std::make_unique<GltfPbrMaterial>(std::move(in)));
    return out;
  }
  const tinygltf::Material& m = model_.materials[size_t(index)];
  const std::string where = "materials[" + std::to_string(index) + "]";
  const auto& pbr = m.pbrMetallicRoughness;

  glm::vec4 baseFactor(1.0f);
  if (!pbr.baseColorFactor.empty()) {
    if (pbr.baseColorFactor.size() != 4) fail(where + ".baseColorFactor", "expected 4 numbers");
    for (int c = 0; c < 4; ++c) baseFactor[c] = float(pbr.baseColorFactor[size_t(c)]);
  }
  const float metallic = float(pbr.metallicFactor), roughness = float(pbr.roughnessFactor);
  for (float v : {baseFactor.x, baseFactor.y, baseFactor.z, baseFactor.w, metallic, roughness})
    if (!std::isfinite(v)) fail(where, "non-finite factor");
  // Factors outside [0, 1] are invalid; exporters round to 1.0000001, so clamp rather than refuse.
  baseFactor = glm::clamp(baseFactor, glm::vec4(0.0f), glm::vec4(1.0f));

  GltfPbrInputs in;
  const Color baseRgb(baseFactor);
  in.baseColor = texture(pbr.baseColorTexture, Channels::SrgbRgb, baseRgb, where + ".baseColorTexture");
  if (!in.baseColor) in.baseColor = std::make_shared<ConstantTexture>(baseRgb);
  // COLOR_0 multiplies the base colour (glTF 2.0 section 3.9.2).
  if (vertexColors) in.baseColor = std::make_shared<VertexColorTexture>(std::move(in.baseColor));
  const Color mr(0.0f, std::clamp(roughness, 0.0f, 1.0f), std::clamp(metallic, 0.0f, 1.0f));
  in.metallicRoughness = texture(pbr.metallicRoughnessTexture, Channels::MetallicRoughness, mr,
                                 where + ".metallicRoughnessTexture");
  if (!in.metallicRoughness) in.metallicRoughness = std::make_shared<ConstantTexture>(mr);

  if (const tinygltf::Value* ext = extension(m.extensions, "KHR_materials_transmission")) {
    const std::string w = where + ".extensions.KHR_materials_transmission";
    const float factor = numberOr(*ext, "transmissionFactor", 0.0f);
    if (!(factor >= 0.0f && factor <= 1.0f)) fail(w + ".transmissionFactor", "expected a number in [0, 1]");
    if (ext->Has("transmissionTexture")) {
      const tinygltf::Value& info = ext->Get("transmissionTexture");
      (void)info;
      in.transmission = extensionTexture(*ext, "transmissionTexture", Channels::Red, Color(factor), w);
    }
    if (!in.transmission && factor > 0.0f) in.transmission = std::make_shared<ConstantTexture>(Color(factor));
  }
  if (const tinygltf::Value* ext = extension(m.extensions, "KHR_materials_ior")) {
    in.ior = numberOr(*ext, "ior", 1.5f);
    // 0 is allowed too: a dielectric that reflects totally, for specular-glossiness conversions.
    if (!((in.ior >= 1.0f && in.ior < 10.0f) || in.ior == 0.0f))
      fail(where + ".extensions.KHR_materials_ior.ior", "expected 0 or a number in [1, 10)");
  }
  const auto failAt = [this](const std::string& w, const std::string& what) { fail(w, what); };
  // KHR_materials_specular: the strength in the texture's alpha, the colour (sRGB) in its RGB.
  if (const tinygltf::Value* ext = extension(m.extensions, "KHR_materials_specular")) {
    const std::string w = where + ".extensions.KHR_materials_specular";
    const float factor = numberOr(*ext, "specularFactor", 1.0f);
    if (!(factor >= 0.0f && factor <= 1.0f)) fail(w + ".specularFactor", "expected a number in [0, 1]");
    const Color color = colorFactor(*ext, "specularColorFactor", Color(1.0f), w, 1e38f, failAt);
    in.specular = extensionTexture(*ext, "specularTexture", Channels::Alpha, Color(factor), w);
    if (!in.specular && factor != 1.0f) in.specular = std::make_shared<ConstantTexture>(Color(factor));
    in.specularColor = extensionTexture(*ext, "specularColorTexture", Channels::SrgbRgb, color, w);
    if (!in.specularColor && color != Color(1.0f))
      in.specularColor = std::make_shared<ConstantTexture>(color);
  }
  // KHR_materials_sheen: colour (sRGB RGB) and roughness (alpha) textures.
  if (const tinygltf::Value* ext = extension(m.extensions, "KHR_materials_sheen")) {
    const std::string w = where + ".extensions.KHR_materials_sheen";
    const Color color = colorFactor(*ext, "sheenColorFactor", Color(0.0f), w, 1.0f, failAt);
    const float roughness = numberOr(*ext, "sheenRoughnessFactor", 0.0f);
    if (!(roughness >= 0.0f && roughness <= 1.0f))
      fail(w + ".sheenRoughnessFactor", "expected a number in [0, 1]");
    in.sheenColor = extensionTexture(*ext, "sheenColorTexture", Channels::SrgbRgb, color, w);
    if (!in.sheenColor && !isBlack(color)) in.sheenColor = std::make_shared<ConstantTexture>(color);
    in.sheenRoughness = extensionTexture(*ext, "sheenRoughnessTexture", Channels::Alpha, Color(roughness), w);
    if (!in.sheenRoughness) in.sheenRoughness = std::make_shared<ConstantTexture>(Color(roughness));
  }
  // KHR_materials_iridescence: weight (R), thickness (G) between the minimum and maximum, the
  // film's ior.
  if (const tinygltf::Value* ext = extension(m.extensions, "KHR_materials_iridescence")) {
    const std::string w = where + ".extensions.KHR_materials_iridescence";
    const float factor = numberOr(*ext, "iridescenceFactor", 0.0f);
    if (!(factor >= 0.0f && factor <= 1.0f)) fail(w + ".iridescenceFactor", "expected a number in [0, 1]");
    in.iridescenceIor = numberOr(*ext, "iridescenceIor", 1.3f);
    if (!(in.iridescenceIor >= 1.0f && in.iridescenceIor < 10.0f))
      fail(w + ".iridescenceIor", "expected a number in [1, 10)");
    in.iridescenceThicknessMin = numberOr(*ext, "iridescenceThicknessMinimum", 100.0f);
    in.iridescenceThicknessMax = numberOr(*ext, "iridescenceThicknessMaximum", 400.0f);
    for (const auto& [key, value] : {std::pair{"iridescenceThicknessMinimum", in.iridescenceThicknessMin},
                                     std::pair{"iridescenceThicknessMaximum", in.iridescenceThicknessMax}})
      if (!(value >= 0.0f && value < 1e6f)) fail(w + "." + key, "expected a thickness >= 0 (nm)");
    in.iridescence = extensionTexture(*ext, "iridescenceTexture", Channels::Red, Color(factor), w);
    if (!in.iridescence && factor > 0.0f) in.iridescence = std::make_shared<ConstantTexture>(Color(factor));
    in.iridescenceThickness =
        extensionTexture(*ext, "iridescenceThicknessTexture", Channels::Green, Color(1.0f), w);
  }
  // KHR_materials_anisotropy: strength, rotation, and a texture of direction (RG) and strength (B).
  if (const tinygltf::Value* ext = extension(m.extensions, "KHR_materials_anisotropy")) {
    const std::string w = where + ".extensions.KHR_materials_anisotropy";
    in.anisotropyStrength = numberOr(*ext, "anisotropyStrength", 0.0f);
    if (!(in.anisotropyStrength >= 0.0f && in.anisotropyStrength <= 1.0f))
      fail(w + ".anisotropyStrength", "expected a number in [0, 1]");
    in.anisotropyRotation = numberOr(*ext, "anisotropyRotation", 0.0f);
    if (!std::isfinite(in.anisotropyRotation)) fail(w + ".anisotropyRotation", "expected a number (radians)");
    in.anisotropy = extensionTexture(*ext, "anisotropyTexture", Channels::LinearRgb, Color(1.0f), w);
    // The direction lives in the mesh's tangent frame: meshes without TANGENT get generated ones.
    out.needsTangents = out.needsTangents || in.anisotropyStrength > 0.0f;
  }
  // KHR_materials_clearcoat: weight (R), roughness (G) and a normal map of the coat's own.
  if (const tinygltf::Value* ext = extension(m.extensions, "KHR_materials_clearcoat")) {
    const std::string w = where + ".extensions.KHR_materials_clearcoat";
    const float factor = numberOr(*ext, "clearcoatFactor", 0.0f);
    if (!(factor >= 0.0f && factor <= 1.0f)) fail(w + ".clearcoatFactor", "expected a number in [0, 1]");
    const float roughness = numberOr(*ext, "clearcoatRoughnessFactor", 0.0f);
    if (!(roughness >= 0.0f && roughness <= 1.0f))
      fail(w + ".clearcoatRoughnessFactor", "expected a number in [0, 1]");
    in.clearcoat = extensionTexture(*ext, "clearcoatTexture", Channels::Red, Color(factor), w);
    if (!in.clearcoat && factor > 0.0f) in.clearcoat = std::make_shared<ConstantTexture>(Color(factor));
    in.clearcoatRoughness =
        extensionTexture(*ext, "clearcoatRoughnessTexture", Channels::Green, Color(roughness), w);
    if (!in.clearcoatRoughness) in.clearcoatRoughness = std::make_shared<ConstantTexture>(Color(roughness));
    in.clearcoatNormal = extensionTexture(*ext, "clearcoatNormalTexture", Channels::LinearRgb, Color(1.0f), w,
                                          &in.clearcoatNormalScale);
    out.needsTangents = out.needsTangents || in.clearcoatNormal != nullptr;
  }
  if (const tinygltf::Value* ext = extension(m.extensions, "KHR_materials_volume")) {
    const float thickness = numberOr(*ext, "thicknessFactor", 0.0f);
    if (!(thickness >= 0.0f))
      fail(where + ".extensions.KHR_materials_volume.thicknessFactor", "expected >= 0");
    in.thinWalled = thickness == 0.0f;
    // Attenuation: radiance falls to attenuationColor over attenuationDistance (default infinity).
    const float distance = numberOr(*ext, "attenuationDistance", std::numeric_limits<float>::infinity());
    if (!(distance > 0.0f))
      fail(where + ".extensions.KHR_materials_volume.attenuationDistance", "expected > 0");
    Color color(1.0f);
    if (ext->Has("attenuationColor")) {
      const tinygltf::Value& c = ext->Get("attenuationColor");
      if (!c.IsArray() || c.ArrayLen() != 3)
        fail(where + ".extensions.KHR_materials_volume.attenuationColor", "expected 3 numbers");
      for (int k = 0; k < 3; ++k)
        color[k] = c.Get(k).IsNumber() ? float(c.Get(k).GetNumberAsDouble()) : -1.0f;
      if (!(color.x >= 0.0f && color.y >= 0.0f && color.z >= 0.0f && color.x <= 1.0f && color.y <= 1.0f &&
            color.z <= 1.0f))
        fail(where + ".extensions.KHR_materials_volume.attenuationColor", "expected numbers in [0, 1]");
    }
    if (std::isfinite(distance))
      for (int k = 0; k < 3; ++k)  // a colour of 0 absorbs everything: a large finite coefficient
        in.absorption[k] = color[k] > 0.0f ? -std::log(color[k]) / distance : 1e30f;
  }
  std::string name = m.name.empty() ? "material" + std::to_string(index) : m.name;
  if (vertexColors) name += " (COLOR_0)";
  out.material = scene_.addMaterial(name, std::make_unique<GltfPbrMaterial>(in));

  // Emission: emissiveFactor x KHR_materials_emissive_strength, unscaled (Blender writes both so).
  // A doubleSided material is lit, and so emits, on its back face too (section 3.9.5: the back
  // face is shaded with the reversed normal); a single-sided one only on the front.
  out.doubleSided = m.doubleSided;
  if (!m.emissiveFactor.empty()) {
    if (m.emissiveFactor.size() != 3) fail(where + ".emissiveFactor", "expected 3 numbers");
    out.emission = Color(float(m.emissiveFactor[0]), float(m.emissiveFactor[1]), float(m.emissiveFactor[2]));
  }
  if (const tinygltf::Value* ext = extension(m.extensions, "KHR_materials_emissive_strength")) {
    const float strength = numberOr(*ext, "emissiveStrength", 1.0f);
    if (!(strength >= 0.0f && std::isfinite(strength)))
      fail(where + ".extensions.KHR_materials_emissive_strength.emissiveStrength", "expected a number >= 0");
    out.emission *= strength;
  }
  if (!isFinite(out.emission) || out.emission.x < 0.0f || out.emission.y < 0.0f || out.emission.z < 0.0f)
    fail(where + ".emissiveFactor", "expected finite numbers >= 0");

  auto maps = std::make_shared<SurfaceMaps>();
  if (!isBlack(out.emission))
    maps->emission = texture(m.emissiveTexture, Channels::SrgbRgb, Color(1.0f), where + ".emissiveTexture");
  if (m.normalTexture.index >= 0) {
    maps->normalMap = texture(m.normalTexture.index, m.normalTexture.texCoord, m.normalTexture.extensions,
                              Channels::LinearRgb, Color(1.0f), where + ".normalTexture");
    maps->normalScale = float(m.normalTexture.scale);
    if (!std::isfinite(maps->normalScale)) fail(where + ".normalTexture.scale", "expected a number");
  }
  // KHR_materials_unlit: the surface shows its base colour (times COLOR_0) whatever the lighting,
  // which a path tracer renders as a black surface emitting that colour: seen directly and in
  // reflections, as viewers show it, and lighting what faces it by that much.
  if (extension(m.extensions, "KHR_materials_unlit")) {
    out.material = scene_.addMaterial(
        name + " (unlit)", std::make_unique<Lambertian>(std::make_shared<ConstantTexture>(Color(0.0f))));
    out.emission = baseRgb;
    maps->normalMap = nullptr;
    maps->emission =
        texture(pbr.baseColorTexture, Channels::SrgbRgb, Color(1.0f), where + ".baseColorTexture");
    if (vertexColors)
      maps->emission = std::make_shared<VertexColorTexture>(
          maps->emission ? maps->emission : std::make_shared<ConstantTexture>(Color(1.0f)));
  }
  if (maps->emission || maps->normalMap) out.maps = std::move(maps);

  // Alpha coverage (section 3.9.4): baseColorFactor.a times the base colour texture's alpha.
  const std::string alphaMode = m.alphaMode.empty() ? "OPAQUE" : m.alphaMode;
  if (alphaMode == "MASK" || alphaMode == "BLEND") {
    const AlphaMode mode = alphaMode == "MASK" ? AlphaMode::Mask : AlphaMode::Blend;
    const float cutoff = float(m.alphaCutoff);
    if (!(cutoff >= 0.0f)) fail(where + ".alphaCutoff", "expected a number >= 0");
    std::shared_ptr<const Texture> alpha =
        texture(pbr.baseColorTexture, Channels::Alpha, Color(baseFactor.w), where + ".baseColorTexture");
    const bool opaque = mode == AlphaMode::Mask ? baseFactor.w >= cutoff : baseFactor.w >= 1.0f;
    if (!alpha && !opaque) alpha = std::make_shared<ConstantTexture>(Color(baseFactor.w));
    if (!alpha && vertexColors) alpha = std::make_shared<ConstantTexture>(Color(baseFactor.w));
    if (alpha) out.opacity = std::make_shared<AlphaOpacity>(std::move(alpha), mode, cutoff, vertexColors);
  } else if (alphaMode != "OPAQUE") {
    fail(where + ".alphaMode", "unknown alpha mode '" + alphaMode + "'; valid: OPAQUE, MASK, BLEND");
  }
  return out;
}

std::shared_ptr<const Texture> GltfMaterialReader::texture(const tinygltf::TextureInfo& info,
                                                           Channels channels, const Color& scale,
                                                           const std::string& where) {
  if (info.index < 0) return nullptr;
  return texture(info.index, info.texCoord, info.extensions, channels, scale, where);
}

std::shared_ptr<const Texture> GltfMaterialReader::texture(int index, int texCoord,
                                                           const tinygltf::ExtensionMap& extensions,
                                                           Channels channels, const Color& scale,
                                                           const std::string& where) {
  if (size_t(index) >= model_.textures.size()) fail(where, "texture index out of range");
  const tinygltf::Texture& tex = model_.textures[size_t(index)];
  if (tex.source < 0 || size_t(tex.source) >= model_.images.size())
    fail(where, "texture " + std::to_string(index) + " has no valid image source");
  const Decoded* img = decode(tex.source, where);
  if (!img) return nullptr;

  TextureWrap wrapS = TextureWrap::Repeat, wrapT = TextureWrap::Repeat;
  TextureFilter filter = TextureFilter::Bilinear;
  if (tex.sampler >= 0) {
    if (size_t(tex.sampler) >= model_.samplers.size()) fail(where, "sampler index out of range");
    const tinygltf::Sampler& s = model_.samplers[size_t(tex.sampler)];
    wrapS = wrapMode(s.wrapS);
    wrapT = wrapMode(s.wrapT);
    if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) filter = TextureFilter::Nearest;
  }
  std::shared_ptr<const Texture> out;
  if (filtering_ && filter != TextureFilter::Nearest) {
    const std::vector<Color> texels =
        img->bytes ? byteTexels(*img, byteChannels(*img, channels)) : floatTexels(*img, channels);
    try {
      out = std::make_shared<FilteredImageTexture>(*filtering_,
                                                   path_ + ": images[" + std::to_string(tex.source) + "]",
                                                   img->width, img->height, texels, wrapS, wrapT, scale);
    } catch (const InputError& e) {
      fail(where, e.what());
    }
    scene_.filteredTextures = true;
  } else if (img->bytes) {
    out = std::make_shared<ImageTexture>(img->width, img->height, byteChannels(*img, channels), filter, wrapS,
                                         wrapT, scale);
  } else {
    out = std::make_shared<ImageTexture>(img->width, img->height, floatTexels(*img, channels), filter, wrapS,
                                         wrapT, scale);
  }

  if (const tinygltf::Value* t = extension(extensions, "KHR_texture_transform")) {
    const std::string w = where + ".extensions.KHR_texture_transform";
    Vec2 offset(0.0f), scaleUv(1.0f);
    const float rotation = numberOr(*t, "rotation", 0.0f);
    for (const char* key : {"offset", "scale"}) {
      if (!t->Has(key)) continue;
      const tinygltf::Value& v = t->Get(key);
      if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber())
        fail(w + "." + key, "expected 2 numbers");
      const Vec2 value(float(v.Get(0).GetNumberAsDouble()), float(v.Get(1).GetNumberAsDouble()));
      (std::strcmp(key, "offset") == 0 ? offset : scaleUv) = value;
    }
    if (!std::isfinite(rotation) || !isFinite(Vec3(offset, 0.0f)) || !isFinite(Vec3(scaleUv, 0.0f)))
      fail(w, "expected finite numbers");
    if (t->Has("texCoord")) {
      const float tc = numberOr(*t, "texCoord", 0.0f);
      if (!(tc >= 0.0f && tc < 16.0f)) fail(w + ".texCoord", "expected 0..15");
      texCoord = int(tc);
    }
    out = std::make_shared<UvTransformTexture>(std::move(out), offset, rotation, scaleUv);
  }
  if (texCoord != 0) out = std::make_shared<TexCoordSetTexture>(std::move(out), texCoord);
  if (converting_ && texCoord > converting_->maxTexCoord) {
    converting_->maxTexCoord = texCoord;
    converting_->maxTexCoordWhere = where;
  }
  return out;
}

std::vector<Color> GltfMaterialReader::floatTexels(const Decoded& img, Channels channels) {
  const size_t n = size_t(img.width) * size_t(img.height);
  const int ch = img.channels;
  std::vector<Color> texels(n);
  for (size_t i = 0; i < n; ++i) {
    const float* p = &img.values[i * size_t(ch)];
    const Color rgb = ch >= 3 ? Color(p[0], p[1], p[2]) : Color(p[0]);
    switch (channels) {
      case Channels::SrgbRgb:
        texels[i] = Color(decodeSrgb(rgb.x), decodeSrgb(rgb.y), decodeSrgb(rgb.z));
        break;
      case Channels::LinearRgb:
        texels[i] = rgb;
        break;
      case Channels::Alpha:
        texels[i] = Color(ch == 4 ? p[3] : ch == 2 ? p[1] : 1.0f);
        break;
      case Channels::MetallicRoughness:
        texels[i] = Color(0.0f, rgb.y, rgb.z);
        break;
      case Channels::Red:
        texels[i] = Color(rgb.x);
        break;
      case Channels::Green:
        texels[i] = Color(ch >= 3 ? rgb.y : rgb.x);
        break;
    }
  }
  return texels;
}

std::vector<Color> GltfMaterialReader::byteTexels(const Decoded& img, const ImageTexture::ByteChannels& in) {
  const size_t n = size_t(img.width) * size_t(img.height);
  std::vector<Color> texels(n);
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c)
      texels[i][int(c)] =
          in.tables[c][in.source[c] < 0 ? 0 : in.bytes[i * size_t(in.stride) + size_t(in.source[c])]];
  return texels;
}

ImageTexture::ByteChannels GltfMaterialReader::byteChannels(const Decoded& img, Channels channels) {
  // The same choices as floatTexels, channel by channel: which byte, and the table of its values.
  const int ch = img.channels;
  // b / 255.0f, as the float path divides (decode() for 16 bits, image_io's readers for 8).
  const auto plain = [](int b) { return float(b) / 255.0f; };
  ImageTexture::ByteChannels in;
  in.bytes = img.bytes->data();
  in.stride = ch;
  const auto constant = [&](int c, float v) {
    in.source[size_t(c)] = -1;
    in.tables[size_t(c)].fill(v);
  };
  for (int c = 0; c < 3; ++c) {
    const int rgbSource = ch >= 3 ? c : 0;
    switch (channels) {
      case Channels::SrgbRgb:
      case Channels::LinearRgb:
        in.source[size_t(c)] = rgbSource;
        break;
      case Channels::Alpha:
        in.source[size_t(c)] = ch == 4 ? 3 : ch == 2 ? 1 : -1;
        break;
      case Channels::MetallicRoughness:
        in.source[size_t(c)] = c == 0 ? -1 : rgbSource;
        break;
      case Channels::Red:
        in.source[size_t(c)] = 0;
        break;
      case Channels::Green:
        in.source[size_t(c)] = ch >= 3 ? 1 : 0;
        break;
    }
    for (int b = 0; b < 256; ++b)
      in.tables[size_t(c)][size_t(b)] = channels == Channels::SrgbRgb ? decodeSrgb(plain(b)) : plain(b);
  }
  if (channels == Channels::Alpha && ch != 4 && ch != 2)
    for (int c = 0; c < 3; ++c) constant(c, 1.0f);
  if (channels == Channels::MetallicRoughness) constant(0, 0.0f);
  return in;
}

const GltfMaterialReader::Decoded* GltfMaterialReader::decode(int image, const std::string& where) {
  if (const auto it = images_.find(image); it != images_.end())
    return it->second.values.empty() && !it->second.bytes ? nullptr : &it->second;
  Decoded& d = images_[image];
  const tinygltf::Image& img = model_.images[size_t(image)];
  if (img.width <= 0 || img.height <= 0 || img.image.empty() || (img.bits != 8 && img.bits != 16) ||
      img.component < 1 || img.component > 4) {
    warn(where, "image " + std::to_string(image) + " could not be decoded; using the factor alone");
    return nullptr;
  }
  const size_t count = size_t(img.width) * size_t(img.height) * size_t(img.component);
  if (img.image.size() < count * size_t(img.bits / 8))
    fail(where, "decoded image is smaller than its size says");
  d.width = img.width;
  d.height = img.height;
  d.channels = img.component;
  if (img.bits == 8) {
    d.bytes = &img.image;
    return &d;
  }
  d.values.resize(count);
  for (size_t i = 0; i < count; ++i) {
    uint16_t v;
    std::memcpy(&v, &img.image[2 * i], 2);
    d.values[i] = v / 65535.0f;
  }
  return &d;
}

}  // namespace ember

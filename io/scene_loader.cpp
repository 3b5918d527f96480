#include "io/scene_loader.h"

#include "io/filtered_texture.h"
#include "io/image_plugin.h"

#include "accel/box.h"
#include "accel/cone.h"
#include "accel/cylinder.h"
#include "accel/disc.h"
#include "accel/flipped_shape.h"
#include "accel/sphere.h"
#include "accel/triangle.h"
#include "io/gltf_loader.h"
#include "io/image_io.h"
#include "io/json_reader.h"
#include "materials/lambertian.h"
#include "materials/mixed.h"
#include "materials/phong.h"
#include "materials/specular.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>

namespace ember {

namespace fs = std::filesystem;

bool isGltfPath(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".gltf" || ext == ".glb";
}

class JsonSceneLoader {
 public:
  // `materialsOf`: a scene whose materials the entries may name (entries read again for an edit
  // go into a scratch scene but refer to the edited scene's materials).
  JsonSceneLoader(const std::string& path, Scene& scene, JsonSceneIndex* index = nullptr,
                  const Scene* materialsOf = nullptr)
      : path_(path), baseDir_(fs::path(path).parent_path()), scene_(scene), index_(index) {
    if (!materialsOf) return;
    for (size_t i = 0; i < materialsOf->materials.size(); ++i)
      materials_[materialsOf->materialNames[i]] = materialsOf->materials[i].get();
    if (const auto black = materials_.find("(black)"); black != materials_.end()) black_ = black->second;
  }

  void load(const JsonNode& root) {
    root.allowKeys(
        {"image", "camera", "render", "environment", "materials", "shapes", "lights", "description", "name"});
    if (auto image = root.find("image")) readImage(*image);
    readCamera(root.at("camera"));
    if (auto render = root.find("render")) readRender(*render);
    if (auto env = root.find("environment")) readEnvironment(*env);
    if (auto materials = root.find("materials")) readMaterials(*materials);
    if (auto shapes = root.find("shapes"))
      for (size_t i = 0; i < shapes->arraySize(); ++i) readShape((*shapes)[i]);
    if (auto lights = root.find("lights"))
      for (size_t i = 0; i < lights->arraySize(); ++i) {
        if (index_) index_->lights.push_back(scene_.lights.size());
        scene_.lights.push_back(readLight((*lights)[i]));
      }
  }

  void readShape(const JsonNode& s) {
    JsonSceneIndex::Range range;
    if (s.has("type") && s.at("type").isString() && s.at("type").string() == "mesh") {
      range = {true, scene_.meshes.size(), 0};
      readShapeEntry(s);
      range.count = scene_.meshes.size() - range.first;
    } else {
      range = {false, scene_.shapes.size(), 1};
      scene_.shapes.push_back(*readShapeEntry(s));
    }
    if (index_) index_->shapes.push_back(range);
  }

  void readImage(const JsonNode& n) {
    n.allowKeys({"width", "height"});
    if (n.has("width")) scene_.settings.width = n.at("width").integer(1, 16384);
    if (n.has("height")) scene_.settings.height = n.at("height").integer(1, 16384);
  }

  void readCamera(const JsonNode& n) { scene_.cameraParams = readCameraParams(n); }

  CameraParams readCameraParams(const JsonNode& n) {
    n.allowKeys({"type", "origin", "target", "up", "fov_y_deg", "half_height"});
    const std::string type = n.has("type") ? n.at("type").string() : "pinhole";
    if (type != "pinhole" && type != "orthographic")
      n.at("type").fail("unknown camera type; valid types are: pinhole, orthographic");
    CameraParams c;
    if (type == "orthographic") {
      c.projection = Projection::Orthographic;
      c.orthoHalfHeight = n.at("half_height").positive();
      if (n.has("fov_y_deg")) n.at("fov_y_deg").fail("not used by an orthographic camera");
    } else if (n.has("half_height")) {
      n.at("half_height").fail("only used by an orthographic camera");
    }
    c.origin = n.at("origin").vec3();
    c.target = n.at("target").vec3();
    c.up = n.has("up") ? n.at("up").direction() : Vec3(0.0f, 1.0f, 0.0f);
    c.fovYDeg = n.has("fov_y_deg") ? n.at("fov_y_deg").positive() : 40.0f;
    if (c.fovYDeg >= 180.0f) n.at("fov_y_deg").fail("expected a number in (0, 180)");
    const Vec3 f = c.target - c.origin;
    if (glm::length(f) == 0.0f) n.at("target").fail("must differ from origin");
    if (glm::length(glm::cross(glm::normalize(f), c.up)) < 1e-6f)
      (n.has("up") ? n.at("up") : n)
          .fail("up must not be parallel to the view direction (the default up is +y)");
    return c;
  }

 private:
  void readRender(const JsonNode& n) {
    n.allowKeys({"spp", "max_depth", "rr_depth", "seed", "background", "sampler", "strategy",
                 "caustic_tracing", "caustic_paths_per_pixel"});
    RenderSettings& s = scene_.settings;
    if (n.has("spp")) s.spp = n.at("spp").integer(1, 1 << 24);
    if (n.has("max_depth")) s.maxDepth = n.at("max_depth").integer(-1, 100000);
    if (n.has("rr_depth")) s.rrDepth = n.at("rr_depth").integer(1, 100000);
    if (n.has("seed")) s.seed = n.at("seed").unsignedInteger();
    if (auto sampler = n.find("sampler")) {
      const std::string v = sampler->string();
      if (v == "sobol")
        s.sampler = SamplerType::Sobol;
      else if (v == "independent")
        s.sampler = SamplerType::Independent;
      else
        sampler->fail("unknown sampler '" + v + "'; valid: independent, sobol");
    }
    if (auto strategy = n.find("strategy")) {
      const std::string v = strategy->string();
      const std::optional<Strategy> parsed = parseStrategy(v);
      if (!parsed) strategy->fail("unknown strategy '" + v + "'; valid: " + std::string(kStrategyNames));
      s.strategy = *parsed;
    }
    s.traceCaustics = n.boolean("caustic_tracing", s.traceCaustics);
    if (auto paths = n.find("caustic_paths_per_pixel")) {
      s.causticPathsPerPixel = paths->positive();
      if (s.causticPathsPerPixel > 64.0f) paths->fail("must be at most 64");
    }
    scene_.background = n.color("background", Color(0.0f));
  }

  // The optional "filter" key of a texture or environment map; `trilinear` (textures only) sets
  // *trilinear and reads as bilinear.
  static TextureFilter readFilter(const JsonNode& n, bool* trilinear = nullptr) {
    const auto f = n.find("filter");
    if (!f) return TextureFilter::Bilinear;
    const std::string v = f->string();
    if (v == "nearest") return TextureFilter::Nearest;
    if (v == "trilinear" && trilinear) {
      *trilinear = true;
      return TextureFilter::Bilinear;
    }
    if (v != "bilinear")
      f->fail("unknown filter '" + v + "'; valid: nearest, bilinear" + (trilinear ? ", trilinear" : ""));
    return TextureFilter::Bilinear;
  }

  void readEnvironment(const JsonNode& n) {
    n.allowKeys({"map", "scale", "rotate_y_deg", "filter"});
    if (!isBlack(scene_.background)) n.fail("give either render.background or environment, not both");
    const JsonNode file = n.at("map");
    const TextureFilter filter = readFilter(n);
    try {
      const std::string path = (baseDir_ / file.string()).string();
      scene_.environmentMap = loadEnvironmentMap(path, n.color("scale", Color(1.0f)), filter);
      scene_.sourceFiles.push_back(path);
    } catch (const InputError& e) {
      file.fail(e.what());
    }
    scene_.environmentRotateYDeg = n.number("rotate_y_deg", 0.0f);
  }

  std::shared_ptr<const Texture> readTexture(const JsonNode& n) {
    if (!n.isObject()) return std::make_shared<ConstantTexture>(n.color());
    n.allowKeys({"texture", "encoding", "filter", "wrap", "scale"});
    const JsonNode file = n.at("texture");
    ColorEncoding encoding = ColorEncoding::Auto;
    if (auto e = n.find("encoding")) {
      const std::string v = e->string();
      if (v == "srgb")
        encoding = ColorEncoding::Srgb;
      else if (v == "linear")
        encoding = ColorEncoding::Linear;
      else if (v != "auto")
        e->fail("unknown encoding '" + v + "'; valid: auto, srgb, linear");
    }
    bool trilinear = false;
    const TextureFilter filter = readFilter(n, &trilinear);
    const ImagePlugin* plugin = trilinear ? imagePlugin() : nullptr;
    if (trilinear && !plugin)
      n.at("filter").fail("filter 'trilinear' needs the OpenImageIO plugin, which could not be loaded: " +
                          imagePluginError());
    TextureWrap wrap = TextureWrap::Repeat;
    if (auto w = n.find("wrap")) {
      const std::string v = w->string();
      if (v == "clamp")
        wrap = TextureWrap::Clamp;
      else if (v == "mirror")
        wrap = TextureWrap::Mirror;
      else if (v != "repeat")
        w->fail("unknown wrap '" + v + "'; valid: clamp, repeat, mirror");
    }
    const fs::path texPath = baseDir_ / file.string();
    if (trilinear && encoding != ColorEncoding::Srgb) {
      // Linear texels are filtered straight from the file, tile by tile within the texture cache
      // (a .tx set larger than memory renders); sRGB ones are decoded first, below.
      ImagePlugin::TextureFile info;
      std::string error;
      const void* handle =
          plugin->addTextureFile(texPath.string(), encoding == ColorEncoding::Linear, info, error);
      if (!error.empty()) file.fail(texPath.string() + ": " + error);
      if (handle) {
        scene_.sourceFiles.push_back(texPath.string());
        scene_.filteredTextures = true;
        return std::make_shared<FilteredImageTexture>(*plugin, texPath.string(), handle, info, wrap,
                                                      n.color("scale", Color(1.0f)));
      }
    }
    TextureImage img;
    try {
      img = ember::readTexture(texPath.string(), encoding);
      scene_.sourceFiles.push_back(texPath.string());
    } catch (const InputError& e) {
      file.fail(e.what());
    }
    if (trilinear) {
      scene_.filteredTextures = true;
      try {
        return std::make_shared<FilteredImageTexture>(*plugin, texPath.string(), img.width, img.height,
                                                      img.texels, wrap, n.color("scale", Color(1.0f)));
      } catch (const InputError& e) {
        file.fail(e.what());
      }
    }
    return std::make_shared<ImageTexture>(img.width, img.height, std::move(img.texels), filter, wrap,
                                          n.color("scale", Color(1.0f)));
  }

  void readMaterials(const JsonNode& n) {
    n.requireObject();
    for (auto it = n.raw().begin(); it != n.raw().end(); ++it) {
      const JsonNode m = n.at(it.key());
      materials_[it.key()] = scene_.addMaterial(it.key(), readMaterial(m));
    }
  }

 public:
  std::unique_ptr<Material> readMaterial(const JsonNode& m) {
    const std::string type = m.at("type").string();
    if (type == "diffuse" || type == "lambertian") {
      m.allowKeys({"type", "reflectance"});
      auto r = m.has("reflectance") ? readTexture(m.at("reflectance"))
                                    : std::make_shared<ConstantTexture>(Color(0.5f));
      if (maxComponent(r->maxValue()) > 1.0f) m.at("reflectance").fail("reflectance must be <= 1");
      return std::make_unique<Lambertian>(std::move(r));
    }
    if (type == "phong") {
      m.allowKeys({"type", "kd", "ks", "exponent"});
      auto kd = m.has("kd") ? readTexture(m.at("kd")) : std::make_shared<ConstantTexture>(Color(0.5f));
      const Color ks = m.color("ks", Color(0.0f));
      const float exponent = m.positive("exponent", 32.0f);
      const Color sum = kd->maxValue() + ks;
      if (maxComponent(sum) > 1.0f + 1e-6f)
        m.fail("kd + ks must be <= 1 in every channel (energy conservation)");
      return std::make_unique<Phong>(std::move(kd), ks, exponent);
    }
    if (type == "mirror") {
      m.allowKeys({"type", "reflectance"});
      return std::make_unique<Mirror>(m.color("reflectance", Color(1.0f)));
    }
    if (type == "refraction") {
      m.allowKeys({"type", "ior_inside", "ior_outside", "transmittance"});
      return std::make_unique<Refraction>(m.color("transmittance", Color(1.0f)),
                                          m.positive("ior_inside", 1.5f), m.positive("ior_outside", 1.0f));
    }
    if (type == "dielectric") {
      m.allowKeys({"type", "ior_inside", "ior_outside"});
      return std::make_unique<Dielectric>(m.positive("ior_inside", 1.5f), m.positive("ior_outside", 1.0f));
    }
    if (type == "mixed") {
      m.allowKeys({"type", "kd", "ks", "kr", "kt", "exponent", "ior"});
      MixedCoefficients c;
      c.kd = m.has("kd") ? readTexture(m.at("kd")) : std::make_shared<ConstantTexture>(Color(0.0f));
      c.ks = m.color("ks", Color(0.0f));
      c.kr = m.color("kr", Color(0.0f));
      c.kt = m.color("kt", Color(0.0f));
      c.exponent = m.positive("exponent", 32.0f);
      c.ior = m.positive("ior", 1.5f);
      const Color kdMax = c.kd->maxValue();
      const float probabilities =
          maxComponent(kdMax) + maxComponent(c.ks) + maxComponent(c.kr) + maxComponent(c.kt);
      if (probabilities > 1.0f + 1e-6f)
        m.fail("the largest channels of kd, ks, kr and kt must sum to <= 1 (they are event probabilities)");
      return std::make_unique<Mixed>(std::move(c));
    }
    m.at("type").fail(
        "unknown material type '" + type +
        "'; valid types are: diffuse (alias lambertian), phong, mirror, refraction, dielectric, mixed");
  }

 private:
  const Material* materialFor(const JsonNode& s, bool emissive) {
    if (!s.has("material")) {
      if (emissive) return blackMaterial();
      s.at("material");  // reports it as missing
    }
    return materialNamed(s.at("material"));
  }

  const Material* materialNamed(const JsonNode& m) {
    const std::string name = m.string();
    const auto it = materials_.find(name);
    if (it == materials_.end()) {
      std::string valid;
      for (const auto& [k, v] : materials_) valid += (valid.empty() ? "" : ", ") + k;
      m.fail("unknown material '" + name + "'; defined materials are: " + (valid.empty() ? "(none)" : valid));
    }
    return it->second;
  }

  const Material* blackMaterial() {
    if (!black_)
      black_ = scene_.addMaterial(
          "(black)", std::make_unique<Lambertian>(std::make_shared<ConstantTexture>(Color(0.0f))));
    return black_;
  }

 public:
  static std::string shapeName(const JsonNode& s, const std::string& type) {
    if (s.has("id")) return s.at("id").string();
    if (s.has("name")) return s.at("name").string();
    return type;
  }

  // The shape's entry; a mesh's entries go straight into the scene (nullopt).
  std::optional<Scene::ShapeEntry> readShapeEntry(const JsonNode& s) {
    const std::string type = s.at("type").string();
    const Color emission = s.color("emission", Color(0.0f));
    auto common = [&](std::initializer_list<std::string_view> extra) {
      std::vector<std::string_view> keys{"type",     "id",           "name",     "material",
                                         "emission", "flip_normals", "two_sided"};
      keys.insert(keys.end(), extra.begin(), extra.end());
      checkKeys(s, keys);
    };
    std::unique_ptr<Shape> shape;
    if (type == "sphere") {
      common({"center", "radius"});
      shape = std::make_unique<Sphere>(s.at("center").vec3(), s.at("radius").positive());
    } else if (type == "disc" || type == "disk") {
      common({"center", "normal", "radius"});
      shape = std::make_unique<Disc>(s.at("center").vec3(), s.at("normal").direction(),
                                     s.at("radius").positive());
    } else if (type == "cylinder") {
      common({"p0", "p1", "radius", "caps"});
      const Vec3 p0 = s.at("p0").vec3(), p1 = s.at("p1").vec3();
      if (!(glm::length(p1 - p0) > 0.0f)) s.at("p1").fail("must differ from p0");
      shape = std::make_unique<Cylinder>(p0, p1, s.at("radius").positive(), s.boolean("caps", true));
    } else if (type == "cone") {
      common({"base_center", "apex", "radius", "cap_base"});
      const Vec3 base = s.at("base_center").vec3(), apex = s.at("apex").vec3();
      if (!(glm::length(apex - base) > 0.0f)) s.at("apex").fail("must differ from base_center");
      shape = std::make_unique<Cone>(base, apex, s.at("radius").positive(), s.boolean("cap_base", true));
    } else if (type == "box") {
      common({"center", "size", "rotate_y_deg", "rotation"});
      const JsonNode size = s.at("size");
      if (size.arraySize() != 3) size.fail("expected an array of 3 numbers > 0");
      const Vec3 sz(size[0].positive(), size[1].positive(), size[2].positive());
      glm::mat3 rotation(1.0f);
      if (auto r = s.find("rotate_y_deg"))
        rotation = glm::mat3(glm::rotate(Mat4(1.0f), glm::radians(r->number()), Vec3(0.0f, 1.0f, 0.0f)));
      if (auto r = s.find("rotation")) rotation = glm::mat3(readRotation(*r)) * rotation;
      shape = std::make_unique<Box>(s.at("center").vec3(), sz, rotation);
    } else if (type == "triangle") {
      common({"vertices", "uvs"});
      std::array<Vec3, 3> v = readPoints<3>(s.at("vertices"));
      std::array<Vec2, 3> uv{Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
      if (auto u = s.find("uvs")) uv = readUvs<3>(*u);
      if (!(glm::length(glm::cross(v[1] - v[0], v[2] - v[0])) > 0.0f))
        s.at("vertices").fail("degenerate triangle (zero area)");
      shape = std::make_unique<Triangle>(v, uv);
    } else if (type == "quad") {
      common({"vertices", "uvs"});
      std::array<Vec3, 4> v = readPoints<4>(s.at("vertices"));
      std::array<Vec2, 4> uv{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
      if (auto u = s.find("uvs")) uv = readUvs<4>(*u);
      const Vec3 normal = glm::cross(v[1] - v[0], v[2] - v[0]);
      if (!(glm::length(normal) > 0.0f)) s.at("vertices").fail("degenerate quad (zero area)");
      const float size = glm::length(v[2] - v[0]);
      if (std::abs(glm::dot(glm::normalize(normal), v[3] - v[0])) > 1e-4f * size)
        s.at("vertices").fail("the four vertices of a quad must lie in one plane");
      shape = std::make_unique<Quad>(v, uv);
    } else if (type == "mesh") {
      common({"file", "transform", "materials", "variant", "texture_filter"});
      if (s.has("flip_normals")) s.at("flip_normals").fail("not supported for meshes");
      readMesh(s, emission);
      return std::nullopt;
    } else {
      s.at("type").fail("unknown shape type '" + type +
                        "'; valid types are: sphere, disc, cylinder, cone, box, triangle, quad, mesh");
    }
    if (s.boolean("flip_normals", false)) shape = std::make_unique<FlippedShape>(std::move(shape));
    return Scene::ShapeEntry{shapeName(s, type), std::move(shape), materialFor(s, !isBlack(emission)),
                             emission, s.boolean("two_sided", false)};
  }

 private:
  static void checkKeys(const JsonNode& s, const std::vector<std::string_view>& keys) {
    s.requireObject();
    for (auto it = s.raw().begin(); it != s.raw().end(); ++it) {
      bool known = it.key() == "note";
      for (std::string_view k : keys) known = known || it.key() == k;
      if (known) continue;
      std::string valid;
      for (std::string_view k : keys) valid.append(valid.empty() ? "" : ", ").append(k);
      s.at(it.key()).fail("unknown key; valid keys for this shape are: " + valid);
    }
  }

  template <size_t N>
  static std::array<Vec3, N> readPoints(const JsonNode& n) {
    if (n.arraySize() != N) n.fail("expected " + std::to_string(N) + " vertices");
    std::array<Vec3, N> out;
    for (size_t i = 0; i < N; ++i) out[i] = n[i].vec3();
    return out;
  }
  template <size_t N>
  static std::array<Vec2, N> readUvs(const JsonNode& n) {
    if (n.arraySize() != N) n.fail("expected " + std::to_string(N) + " uv pairs");
    std::array<Vec2, N> out;
    for (size_t i = 0; i < N; ++i) out[i] = n[i].vec2();
    return out;
  }

  static Mat4 readRotation(const JsonNode& r) {
    r.allowKeys({"axis", "degrees"});
    return glm::rotate(Mat4(1.0f), glm::radians(r.at("degrees").number()), r.at("axis").direction());
  }

 public:
  static Mat4 readTransform(const JsonNode& t) {
    t.allowKeys({"matrix", "translate", "rotate", "rotate_y_deg", "scale"});
    if (auto m = t.find("matrix")) {
      if (t.raw().size() != 1) t.fail("'matrix' cannot be combined with translate/rotate/scale");
      if (m->arraySize() != 16) m->fail("expected 16 numbers (row-major 4x4)");
      Mat4 out;
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out[c][r] = (*m)[size_t(r * 4 + c)].number();
      return out;
    }
    // Applied to points as scale, then rotate, then translate.
    Mat4 out(1.0f);
    if (auto tr = t.find("translate")) out = glm::translate(out, tr->vec3());
    if (auto r = t.find("rotate")) out = out * readRotation(*r);
    if (auto r = t.find("rotate_y_deg")) out = glm::rotate(out, glm::radians(r->number()), Vec3(0, 1, 0));
    if (auto sc = t.find("scale")) {
      const Vec3 s = sc->isNumber() ? Vec3(sc->positive()) : sc->vec3();
      if (!(s.x > 0 && s.y > 0 && s.z > 0)) sc->fail("expected scale factors > 0");
      out = glm::scale(out, s);
    }
    return out;
  }

 private:
  void readMesh(const JsonNode& s, const Color& emission) {
    const JsonNode file = s.at("file");
    const fs::path meshPath = baseDir_ / file.string();
    GltfImportOptions options;
    options.transform = s.has("transform") ? readTransform(s.at("transform")) : Mat4(1.0f);
    options.materialOverride = s.has("material") ? materialFor(s, false) : nullptr;
    if (auto byName = s.find("materials")) {
      // {"glTF material name": "Ember material name", ...}
      if (options.materialOverride) byName->fail("'material' and 'materials' cannot be combined");
      byName->requireObject();
      for (auto it = byName->raw().begin(); it != byName->raw().end(); ++it)
        options.materialsByName[it.key()] = materialNamed(byName->at(it.key()));
    }
    if (auto variant = s.find("variant")) options.variant = variant->string();
    if (auto filter = s.find("texture_filter")) {
      const std::string v = filter->string();
      if (v != "bilinear" && v != "trilinear")
        filter->fail("unknown texture filter '" + v + "'; valid: bilinear, trilinear");
      options.trilinearTextures = v == "trilinear";
    }
    const size_t first = scene_.meshes.size();
    try {
      importGltf(meshPath.string(), scene_, options);
    } catch (const InputError& e) {
      file.fail(e.what());
    }
    if (!isBlack(emission))
      for (size_t i = first; i < scene_.meshes.size(); ++i) scene_.meshes[i].emission = emission;
    if (auto twoSided = s.find("two_sided")) {
      const bool v = twoSided->boolean();
      for (size_t i = first; i < scene_.meshes.size(); ++i) scene_.meshes[i].twoSidedEmission = v;
    }
  }

 public:
  std::unique_ptr<Light> readLight(const JsonNode& l) {
    const std::string type = l.at("type").string();
    if (type == "point") {
      l.allowKeys({"type", "id", "name", "position", "intensity"});
      return std::make_unique<PointLight>(l.at("position").vec3(), l.at("intensity").color());
    }
    if (type == "spot") {
      l.allowKeys({"type", "id", "name", "position", "direction", "intensity", "inner_deg", "outer_deg"});
      const float outer = l.positive("outer_deg", 45.0f), inner = l.nonNegative("inner_deg", 0.0f);
      if (!(inner < outer && outer <= 90.0f)) l.fail("expected 0 <= inner_deg < outer_deg <= 90");
      return std::make_unique<SpotLight>(l.at("position").vec3(), l.at("direction").direction(),
                                         l.at("intensity").color(), glm::radians(inner), glm::radians(outer));
    }
    if (type == "directional") {
      l.allowKeys({"type", "id", "name", "direction", "irradiance"});
      // `direction` is where the light travels (glTF's -z of the light node), so it arrives from -direction.
      return std::make_unique<DirectionalLight>(-l.at("direction").direction(), l.at("irradiance").color());
    }
    l.at("type").fail("unknown light type '" + type + "'; valid types are: point, spot, directional");
  }

 private:
  std::string path_;
  fs::path baseDir_;
  Scene& scene_;
  JsonSceneIndex* index_;
  std::map<std::string, const Material*> materials_;
  const Material* black_ = nullptr;
};

namespace {}  // namespace

std::shared_ptr<const ImageTexture> loadEnvironmentMap(const std::string& path, const Color& scale,
                                                       TextureFilter filter) {
  TextureImage img = readTexture(path, ColorEncoding::Auto);
  // Equirectangular: u wraps around, v (the poles) clamps.
  return std::make_shared<ImageTexture>(img.width, img.height, std::move(img.texels), filter,
                                        TextureWrap::Repeat, scale);
}

namespace {

// A camera that frames the bounds from the front (+z) and a little above.
CameraParams framingCamera(const Bounds& b, float aspect) {
  const Vec3 center = 0.5f * (b.lower + b.upper);
  const float radius = std::max(0.5f * glm::length(b.upper - b.lower), 1e-3f);
  CameraParams c;
  c.fovYDeg = 40.0f;
  const float halfFov = glm::radians(c.fovYDeg) * 0.5f * std::min(1.0f, aspect);
  const float distance = 1.1f * radius / std::sin(halfFov);
  c.origin = center + distance * glm::normalize(Vec3(0.0f, 0.35f, 1.0f));
  c.target = center;
  c.up = Vec3(0.0f, 1.0f, 0.0f);
  return c;
}

Scene loadGltfScene(const std::string& path, const LoadOptions& load) {
  Scene scene;
  scene.sourcePath = path;
  GltfImportOptions options;
  options.camera = load.camera;
  options.variant = load.variant;
  options.trilinearTextures = load.trilinearTextures;
  const GltfImport imported = importGltf(path, scene, options);
  if (imported.triangles + imported.points + imported.segments == 0)
    throw InputError(path + ": the scene contains nothing to render");
  Bounds bounds;
  for (const auto& m : scene.meshes) bounds.extend(m.worldBounds());
  for (const auto& s : scene.shapes) bounds.extend(s.shape->bounds());
  scene.settings.height = 384;
  if (imported.camera) {
    scene.cameraParams = *imported.camera;
    const float aspect = imported.cameraAspect > 0.0f ? imported.cameraAspect : 4.0f / 3.0f;
    scene.settings.width = std::max(1, int(std::lround(384.0f * aspect)));
  } else {
    scene.settings.width = 512;
    scene.cameraParams = framingCamera(bounds, 512.0f / 384.0f);
  }
  // A file lit by its own lights (KHR_lights_punctual, or emission brighter than 1, which only
  // KHR_materials_emissive_strength gives and which is how Blender exports light-giving emission)
  // is lit by them alone, as Blender renders it. Every other file, glowing screens and LEDs whose
  // emissive factor is at most 1 included, gets a uniform white environment, as glTF viewers
  // light a model. `--env` overrides either choice.
  const auto lightGiving = [](const Color& emission) { return maxComponent(emission) > 1.0f; };
  const bool emissive = std::any_of(scene.meshes.begin(), scene.meshes.end(),
                                    [&](const auto& m) { return lightGiving(m.emission); }) ||
                        std::any_of(scene.shapes.begin(), scene.shapes.end(),
                                    [&](const auto& s) { return lightGiving(s.emission); });
  if (!load.environmentGiven) {
    if (imported.lights == 0 && !emissive) {
      scene.background = Color(1.0f);
      std::fprintf(stderr,
                   "ember: environment: white, radiance 1 (%s has no light-giving emission or KHR light; "
                   "--env none|white|r,g,b|FILE overrides)\n",
                   path.c_str());
    } else {
      std::fprintf(stderr, "ember: environment: none (%s is lit by its own %s; --env adds one)\n",
                   path.c_str(), imported.lights ? "KHR lights" : "emission");
    }
  }
  return scene;
}

}  // namespace

Scene loadJsonScene(const std::string& path, JsonSceneIndex* index) {
  const nlohmann::json doc = JsonNode::parseFile(path);
  Scene scene;
  scene.sourcePath = path;
  scene.sourceFiles.push_back(path);
  JsonSceneLoader(path, scene, index).load(JsonNode(doc, "", path));
  return scene;
}

Scene loadJsonScene(const nlohmann::json& document, const std::string& name, JsonSceneIndex* index) {
  Scene scene;
  scene.sourcePath = name;
  JsonSceneLoader(name, scene, index).load(JsonNode(document, "", name));
  return scene;
}

JsonEntryReader::JsonEntryReader(const Scene& scene, const std::string& file)
    : file_(file),
      scratch_(std::make_unique<Scene>()),
      loader_(std::make_unique<JsonSceneLoader>(file, *scratch_, nullptr, &scene)) {}
JsonEntryReader::~JsonEntryReader() = default;

void JsonEntryReader::adoptInto(Scene& scene) {
  for (size_t i = 0; i < scratch_->materials.size(); ++i)
    scene.addMaterial(scratch_->materialNames[i], std::move(scratch_->materials[i]));
  scene.sourceFiles.insert(scene.sourceFiles.end(), scratch_->sourceFiles.begin(),
                           scratch_->sourceFiles.end());
  scene.filteredTextures = scene.filteredTextures || scratch_->filteredTextures;
  scratch_ = std::make_unique<Scene>();
  loader_ = std::make_unique<JsonSceneLoader>(file_, *scratch_, nullptr, &scene);
}

nlohmann::json cameraJson(const CameraParams& c) {
  const auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  nlohmann::json j = {{"origin", vec(c.origin)}, {"target", vec(c.target)}, {"up", vec(c.up)}};
  if (c.projection == Projection::Orthographic) {
    j["type"] = "orthographic";
    j["half_height"] = c.orthoHalfHeight;
  } else {
    j["fov_y_deg"] = c.fovYDeg;
  }
  return j;
}

CameraParams JsonEntryReader::camera(const nlohmann::json& value) const {
  return loader_->readCameraParams(JsonNode(value, "camera", file_));
}

std::unique_ptr<Material> JsonEntryReader::material(const nlohmann::json& value,
                                                    const std::string& name) const {
  return loader_->readMaterial(JsonNode(value, "materials." + name, file_));
}

Scene::ShapeEntry JsonEntryReader::shape(const nlohmann::json& value, const std::string& path) const {
  const JsonNode node(value, path, file_);
  if (node.isObject() && node.has("type") && node.at("type").isString() && node.at("type").string() == "mesh")
    node.at("type").fail("a mesh entry cannot be read again into a built scene; load the scene again");
  return *loader_->readShapeEntry(node);
}

Mat4 JsonEntryReader::transform(const nlohmann::json& value, const std::string& path) const {
  return JsonSceneLoader::readTransform(JsonNode(value, path, file_));
}

std::unique_ptr<Light> JsonEntryReader::light(const nlohmann::json& value, const std::string& path) const {
  return loader_->readLight(JsonNode(value, path, file_));
}

Scene loadScene(const std::string& path, const LoadOptions& options) {
  if (!fs::exists(path)) throw InputError(path + ": no such file");
  if (fs::is_directory(path)) throw InputError(path + ": is a directory, not a scene file");
  if (!isGltfPath(path) && !options.variant.empty())
    throw InputError(path +
                     ": --variant selects a KHR_materials_variants variant of a glTF file; in a JSON scene "
                     "a mesh entry takes \"variant\"");
  if (!isGltfPath(path) && options.camera >= 0)
    throw InputError(path + ": --camera selects a camera of a glTF file; a JSON scene has one camera");
  return isGltfPath(path) ? loadGltfScene(path, options) : loadJsonScene(path);
}

}  // namespace ember

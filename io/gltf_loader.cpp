#include "io/gltf_loader.h"

#include "accel/cylinder.h"
#include "accel/mesh_instance.h"
#include "accel/sphere.h"
#include "io/gltf_compression.h"
#include "io/gltf_materials.h"
#include "io/image_plugin.h"
#include "io/input_error.h"

#include <tiny_gltf.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string_view>

namespace ember {

namespace {

constexpr int kModePoints = 0, kModeLines = 1, kModeLineLoop = 2, kModeLineStrip = 3, kModeTriangles = 4,
              kModeStrip = 5, kModeFan = 6;

class GltfImporter {
 public:
  GltfImporter(const std::string& path, Scene& scene, const GltfImportOptions& options)
      : path_(path),
        scene_(scene),
        options_(options),
        materials_(model_, path, scene, options.trilinearTextures ? imagePlugin() : nullptr) {
    if (options.trilinearTextures && !imagePlugin())
      throw InputError(
          path + ": trilinear texture filtering needs the OpenImageIO plugin, which could not be loaded: " +
          imagePluginError());
  }

  GltfImport run() {
    load();
    checkVersion(model_.asset.version, model_.asset.minVersion);
    decodeDeferredImages(model_, path_);  // PNG, JPEG...: all at once, in parallel
    decodeCompressedData(model_, path_);  // meshopt, Draco, WebP: plain data from here on
    checkPrimitiveArrays();
    checkExtensions();
    result_.cameraCount = model_.cameras.size();
    if (options_.camera >= 0 && size_t(options_.camera) >= model_.cameras.size())
      fail("cameras", "camera " + std::to_string(options_.camera) + " requested, but the file has " +
                          std::to_string(model_.cameras.size()));
    for (size_t i = 0; i < model_.materials.size(); ++i) {
      result_.materialNames.push_back(model_.materials[i].name);
      if (options_.materialsByName.count(model_.materials[i].name))
        usedOverrides_.insert(model_.materials[i].name);
    }
    for (const auto& [name, material] : options_.materialsByName)
      if (!usedOverrides_.count(name)) {
        std::string known;
        for (const auto& m : model_.materials)
          known.append(known.empty() ? "'" : ", '").append(m.name).append("'");
        fail("materials",
             "no material named '" + name + "'; the file has: " + (known.empty() ? "none" : known));
      }
    readVariants();
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      int sceneIndex = model_.defaultScene;
      if (sceneIndex < 0 || size_t(sceneIndex) >= model_.scenes.size()) sceneIndex = 0;
      roots = model_.scenes[size_t(sceneIndex)].nodes;
    } else {
      // No scene at all: every node that is nobody's child is a root.
      std::set<int> children;
      for (const auto& node : model_.nodes) children.insert(node.children.begin(), node.children.end());
      for (int i = 0; i < int(model_.nodes.size()); ++i)
        if (!children.count(i)) roots.push_back(i);
    }
    countPlacements();
    std::vector<int> stack;
    const size_t firstMesh = scene_.meshes.size();
    for (int root : roots) visit(root, Mat4(1.0f), stack);
    makePointsAndLines(firstMesh);
    scene_.materialVariants.insert(scene_.materialVariants.end(), result_.variants.begin(),
                                   result_.variants.end());
    if (options_.camera >= 0 && !result_.camera)
      fail("cameras[" + std::to_string(options_.camera) + "]", "no node of the scene uses this camera");
    return result_;
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw InputError(path_ + ": " + where + ": " + what);
  }

  static bool recordingRead(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                            void* files) {
    const bool ok = tinygltf::ReadWholeFile(out, err, path, nullptr);
    if (ok) static_cast<std::vector<std::string>*>(files)->push_back(path);
    return ok;
  }

  void load() {
    namespace fs = std::filesystem;
    if (!fs::exists(path_)) throw InputError(path_ + ": no such file");
    tinygltf::TinyGLTF loader;
    // tinygltf reads the file and its external buffers and images through these callbacks; the
    // reads are recorded so that a checkpoint's identity covers them (Scene::sourceFiles).
    tinygltf::FsCallbacks callbacks{&tinygltf::FileExists, &tinygltf::ExpandFilePath, &recordingRead,
                                    &tinygltf::WriteWholeFile, &scene_.sourceFiles};
    loader.SetFsCallbacks(callbacks);
    loader.SetImageLoader(gltfImageLoader(), &model_);  // WebP and KTX2 too (io/gltf_compression.h)
    std::string err, warn;
    std::string ext = fs::path(path_).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    const size_t recorded = scene_.sourceFiles.size();
    bool ok = ext == ".glb" ? loader.LoadBinaryFromFile(&model_, &err, &warn, path_)
                            : loader.LoadASCIIFromFile(&model_, &err, &warn, path_);
    // tinygltf refuses Draco primitives' indices without a bufferView and meshopt fallback buffers
    // without data: retried with those patched out (io/gltf_compression.h), from memory.
    if (const auto patched = ok ? std::nullopt : patchCompressedGltf(path_)) {
      scene_.sourceFiles.resize(recorded);  // read again below, the file itself by us
      scene_.sourceFiles.push_back(path_);
      model_ = tinygltf::Model();
      err.clear();
      const size_t slash = path_.find_last_of("/\\");
      const std::string dir = slash == std::string::npos ? "" : path_.substr(0, slash);  // as tinygltf's
      ok = ext == ".glb" ? loader.LoadBinaryFromMemory(
                               &model_, &err, &warn, reinterpret_cast<const unsigned char*>(patched->data()),
                               unsigned(patched->size()), dir)
                         : loader.LoadASCIIFromString(&model_, &err, &warn, patched->data(),
                                                      unsigned(patched->size()), dir);
    }
    if (!ok) {
      // tinygltf trips over glTF 1.0's schema and over the data of extensions it cannot decode
      // before we see the file's version and extensionsRequired: name the cause rather than its
      // symptom.
      const nlohmann::json doc = fileJson();
      if (doc.is_object() && doc.contains("asset") && doc["asset"].is_object()) {
        const nlohmann::json& asset = doc["asset"];
        const auto text = [&](const char* key) {
          return asset.contains(key) && asset[key].is_string() ? asset[key].get<std::string>()
                                                               : std::string();
        };
        checkVersion(text("version"), text("minVersion"));
      }
      // glTF 1.0 kept its objects in dictionaries keyed by id, where 2.0 has arrays; a 1.0 file
      // without its asset object is still recognisable by them.
      if (doc.is_object())
        for (const char* key : {"accessors", "buffers", "meshes", "nodes"})
          if (doc.contains(key) && doc[key].is_object())
            fail(key, std::string("an object keyed by id, as in glTF 1.0; ") + kReadsOnlyGltf2);
      for (const std::string& ext : requiredExtensions(doc))
        if (!supportedExtensions().count(ext))
          fail("extensionsRequired", "the file requires " + ext + ", which Ember does not support");
      while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
      throw InputError(path_ + ": cannot load glTF: " + (err.empty() ? "unknown error" : err));
    }
  }

  static const std::set<std::string>& supportedExtensions() {
    static const std::set<std::string> supported = {
        "KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_transmission",
        "KHR_materials_ior", "KHR_materials_volume", "KHR_texture_transform", "KHR_materials_specular",
        "KHR_materials_sheen", "KHR_materials_clearcoat", "KHR_materials_unlit", "KHR_materials_iridescence",
        "KHR_materials_anisotropy", "KHR_materials_variants", "KHR_mesh_quantization",
        // io/gltf_compression.cpp; KHR_texture_basisu by its textures' PNG/JPEG fallbacks alone.
        "EXT_meshopt_compression", "KHR_draco_mesh_compression", "EXT_texture_webp", "KHR_texture_basisu"};
    return supported;
  }

  // The file's JSON read straight from it (.gltf, or a .glb's JSON chunk, which starts at byte 20
  // in binary glTF 1.0 and 2.0 alike); a discarded value when it cannot be read.
  nlohmann::json fileJson() const {
    std::ifstream in(path_, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    if (bytes.size() >= 20 && bytes.compare(0, 4, "glTF") == 0) {
      uint32_t length = 0;
      std::memcpy(&length, bytes.data() + 12, 4);
      bytes = bytes.substr(20, std::min<size_t>(length, bytes.size() - 20));
    }
    return nlohmann::json::parse(bytes, nullptr, /*allow_exceptions=*/false);
  }

  // The end of every message refusing a file of another glTF version.
  static constexpr const char* kReadsOnlyGltf2 =
      "Ember reads glTF 2.0 (convert the file, e.g. with the Khronos glTF-Pipeline or Blender's glTF 2.0 "
      "exporter)";

  // glTF 1.0 files (collada2gltf and other early exporters) follow another schema, which tinygltf
  // reads as an empty 2.0 model or refuses with a message about its symptoms: name the version.
  // As the 2.0 specification asks of loaders (section 3.2, "Asset"), a file whose major version
  // is not 2, or whose minVersion is newer than 2.0, is refused. An absent version is left to
  // tinygltf, which requires the asset object.
  void checkVersion(const std::string& version, const std::string& minVersion) const {
    // <major>.<minor> as the schema writes it; a bare <major> is taken as <major>.0.
    const auto parse = [](const std::string& text, int& major, int& minor) {
      const auto digits = [](std::string_view v) {
        return !v.empty() && v.size() <= 6 &&
               std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; });
      };
      const size_t dot = std::min(text.find('.'), text.size());
      const std::string_view a(text.data(), dot);
      const std::string_view b = dot < text.size() ? std::string_view(text).substr(dot + 1) : "0";
      if (!digits(a) || !digits(b)) return false;
      major = std::stoi(std::string(a));
      minor = std::stoi(std::string(b));
      return true;
    };
    int major = 0, minor = 0;
    if (!version.empty()) {
      if (!parse(version, major, minor))
        fail("asset.version", "'" + version + "' is not a glTF version of the form <major>.<minor>");
      if (major != 2) fail("asset.version", "the file is glTF " + version + "; " + kReadsOnlyGltf2);
    }
    if (!minVersion.empty()) {
      if (!parse(minVersion, major, minor))
        fail("asset.minVersion", "'" + minVersion + "' is not a glTF version of the form <major>.<minor>");
      if (major != 2 || minor > 0)
        fail("asset.minVersion", "the file needs a glTF " + minVersion + " reader; Ember reads glTF 2.0");
    }
  }

  // tinygltf reads a mesh whose `primitives` is not an array as a mesh without primitives, and the
  // scene then silently lacks it: name the field instead. The JSON is read again only then.
  void checkPrimitiveArrays() const {
    nlohmann::json doc;
    for (size_t i = 0; i < model_.meshes.size(); ++i) {
      if (!model_.meshes[i].primitives.empty()) continue;
      if (doc.is_null()) doc = fileJson();
      if (!doc.is_object() || !doc.contains("meshes") || !doc["meshes"].is_array() ||
          i >= doc["meshes"].size())
        return;
      const nlohmann::json& mesh = doc["meshes"][i];
      if (mesh.is_object() && mesh.contains("primitives") && !mesh["primitives"].is_array())
        fail("meshes[" + std::to_string(i) + "].primitives",
             std::string("must be an array of primitives, not ") + mesh["primitives"].type_name());
    }
  }

  // extensionsRequired of the file's JSON (fileJson); empty when it cannot be read.
  static std::vector<std::string> requiredExtensions(const nlohmann::json& doc) {
    std::vector<std::string> out;
    if (doc.is_object() && doc.contains("extensionsRequired") && doc["extensionsRequired"].is_array())
      for (const auto& e : doc["extensionsRequired"])
        if (e.is_string()) out.push_back(e.get<std::string>());
    return out;
  }

  // Extensions we implement (docs/gltf.md); any other one used is named in one warning, and one
  // the file requires is an error, since the file cannot be rendered correctly without it.
  void checkExtensions() const {
    const std::set<std::string>& supported = supportedExtensions();
    for (const std::string& ext : model_.extensionsRequired)
      if (!supported.count(ext))
        fail("extensionsRequired", "the file requires " + ext + ", which Ember does not support");
    std::string ignored;
    for (const std::string& ext : model_.extensionsUsed)
      if (!supported.count(ext)) ignored += (ignored.empty() ? "" : ", ") + ext;
    if (!ignored.empty())
      std::fprintf(stderr, "ember: %s: ignoring unsupported glTF extensions: %s\n", path_.c_str(),
                   ignored.c_str());
  }

  // KHR_materials_variants: the file's variant names, and the index of the one asked for.
  void readVariants() {
    const auto ext = model_.extensions.find("KHR_materials_variants");
    if (ext != model_.extensions.end()) {
      const tinygltf::Value& variants = ext->second.Get("variants");
      if (!variants.IsArray()) fail("extensions.KHR_materials_variants.variants", "expected an array");
      for (size_t i = 0; i < variants.ArrayLen(); ++i) {
        const tinygltf::Value& name = variants.Get(int(i)).Get("name");
        if (!name.IsString())
          fail("extensions.KHR_materials_variants.variants[" + std::to_string(i) + "].name",
               "expected a string");
        result_.variants.push_back(name.Get<std::string>());
      }
    }
    if (options_.variant.empty()) return;
    for (size_t i = 0; i < result_.variants.size(); ++i)
      if (result_.variants[i] == options_.variant) variant_ = int(i);
    if (variant_ < 0) {
      std::string known;
      for (const std::string& v : result_.variants)
        known.append(known.empty() ? "'" : ", '").append(v).append("'");
      fail("extensions.KHR_materials_variants",
           "no variant named '" + options_.variant + "'; the file has: " + (known.empty() ? "none" : known));
    }
  }

  // The material a primitive takes: the chosen variant's where the primitive maps it
  // (KHR_materials_variants mappings), else its own.
  int materialOf(const tinygltf::Primitive& prim, const std::string& where) const {
    if (variant_ < 0) return prim.material;
    const auto ext = prim.extensions.find("KHR_materials_variants");
    if (ext == prim.extensions.end()) return prim.material;
    const std::string w = where + ".extensions.KHR_materials_variants.mappings";
    const tinygltf::Value& mappings = ext->second.Get("mappings");
    if (!mappings.IsArray()) fail(w, "expected an array");
    for (size_t i = 0; i < mappings.ArrayLen(); ++i) {
      const tinygltf::Value& mapping = mappings.Get(int(i));
      const tinygltf::Value& variants = mapping.Get("variants");
      const tinygltf::Value& material = mapping.Get("material");
      const std::string wi = w + "[" + std::to_string(i) + "]";
      if (!variants.IsArray()) fail(wi + ".variants", "expected an array");
      if (!material.IsNumber() || material.GetNumberAsDouble() < 0.0 ||
          material.GetNumberAsDouble() >= double(model_.materials.size()))
        fail(wi + ".material", "expected a material index below " + std::to_string(model_.materials.size()));
      for (size_t k = 0; k < variants.ArrayLen(); ++k)
        if (variants.Get(int(k)).IsNumber() && variants.Get(int(k)).GetNumberAsInt() == variant_)
          return material.GetNumberAsInt();
    }
    return prim.material;
  }

  static Mat4 localMatrix(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) {
      Mat4 m;
      for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = float(node.matrix[size_t(i)]);  // column-major
      return m;
    }
    Mat4 m(1.0f);
    if (node.translation.size() == 3)
      m = glm::translate(
          m, Vec3(float(node.translation[0]), float(node.translation[1]), float(node.translation[2])));
    if (node.rotation.size() == 4) {
      const glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]),
                        float(node.rotation[2]));  // glTF stores x, y, z, w
      m = m * glm::mat4_cast(glm::normalize(q));
    }
    if (node.scale.size() == 3)
      m = glm::scale(m, Vec3(float(node.scale[0]), float(node.scale[1]), float(node.scale[2])));
    return m;
  }

  // `parent`: where the node's parent lies in the file; options_.transform places the file.
  void visit(int index, const Mat4& parent, std::vector<int>& stack) {
    const std::string where = "nodes[" + std::to_string(index) + "]";
    if (index < 0 || size_t(index) >= model_.nodes.size()) fail(where, "node index out of range");
    for (int s : stack)
      if (s == index) fail(where, "the node hierarchy contains a cycle");
    const tinygltf::Node& node = model_.nodes[size_t(index)];
    const Mat4 inFile = parent * localMatrix(node);
    // The loader's transform last, so that an edit placing the file anew (Scene::MeshEntry::inFile)
    // computes each placement as a load of the edited scene does.
    const Mat4 world = options_.transform * inFile;
    for (int i = 0; i < 16; ++i)
      if (!std::isfinite(world[i / 4][i % 4])) fail(where, "non-finite transform");
    if (node.camera >= 0 && !result_.camera && (options_.camera < 0 || node.camera == options_.camera))
      readCamera(node.camera, world, where + ".camera");
    if (const auto ext = node.extensions.find("KHR_lights_punctual"); ext != node.extensions.end())
      readLight(ext->second, world, where + ".extensions.KHR_lights_punctual");
    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size()) fail(where + ".mesh", "mesh index out of range");
      const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
      for (size_t p = 0; p < mesh.primitives.size(); ++p)
        readPrimitive(mesh.primitives[p], world, inFile,
                      "meshes[" + std::to_string(node.mesh) + "].primitives[" + std::to_string(p) + "]");
    }
    stack.push_back(index);
    for (int child : node.children) visit(child, inFile, stack);
    stack.pop_back();
  }

  void readCamera(int index, const Mat4& world, const std::string& where) {
    if (size_t(index) >= model_.cameras.size()) fail(where, "camera index out of range");
    const tinygltf::Camera& cam = model_.cameras[size_t(index)];
    CameraParams c;
    // A camera looks down its node's -z with +y up (glTF 2.0 section 3.10.1).
    c.origin = Vec3(world * glm::vec4(0, 0, 0, 1));
    const Vec3 forward = glm::normalize(Vec3(world * glm::vec4(0, 0, -1, 0)));
    c.target = c.origin + forward;
    c.up = glm::normalize(Vec3(world * glm::vec4(0, 1, 0, 0)));
    float aspect = 0.0f;
    if (cam.type == "perspective") {
      c.fovYDeg = glm::degrees(float(cam.perspective.yfov));
      if (!(c.fovYDeg > 0.0f && c.fovYDeg < 180.0f)) fail(where, "yfov must lie in (0, pi)");
      aspect = float(cam.perspective.aspectRatio);
    } else if (cam.type == "orthographic") {
      c.projection = Projection::Orthographic;
      c.orthoHalfHeight = float(cam.orthographic.ymag);
      const float xmag = float(cam.orthographic.xmag);
      if (!(c.orthoHalfHeight > 0.0f && xmag > 0.0f && std::isfinite(c.orthoHalfHeight) &&
            std::isfinite(xmag)))
        fail(where, "orthographic xmag and ymag must be > 0");
      aspect = xmag / c.orthoHalfHeight;
    } else {
      fail(where, "unknown camera type '" + cam.type + "'; valid: perspective, orthographic");
    }
    if (!isFinite(c.origin) || !isFinite(forward) || !isFinite(c.up))
      fail(where, "degenerate camera transform");
    result_.camera = c;
    result_.cameraAspect = std::isfinite(aspect) && aspect > 0.0f ? aspect : 0.0f;
  }

  // KHR_lights_punctual, photometric to radiometric with 683 lm/W (docs/gltf.md): point and spot
  // intensity [cd] / 683 = W/sr, directional illuminance [lux] / 683 = W/m^2. This is exactly the
  // inverse of Blender's exporter (W / (4 pi) * 683 cd, W/m^2 * 683 lux), so Blender scenes come out
  // as bright as Blender renders them. `range` is ignored (the spec allows it): lights fall off
  // with the inverse square law only.
  void readLight(const tinygltf::Value& ext, const Mat4& world, const std::string& where) {
    if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber())
      fail(where, "expected {\"light\": index}");
    const int index = ext.Get("light").GetNumberAsInt();
    if (index < 0 || size_t(index) >= model_.lights.size()) fail(where, "light index out of range");
    const tinygltf::Light& l = model_.lights[size_t(index)];
    Color color(1.0f);
    if (l.color.size() == 3) color = Color(float(l.color[0]), float(l.color[1]), float(l.color[2]));
    const Color radiometric = color * float(l.intensity) / 683.0f;
    if (!isFinite(radiometric) || radiometric.x < 0.0f || radiometric.y < 0.0f || radiometric.z < 0.0f)
      fail(where, "light colour and intensity must be finite and >= 0");
    const Vec3 position(world * glm::vec4(0, 0, 0, 1));
    const Vec3 direction = glm::normalize(Vec3(world * glm::vec4(0, 0, -1, 0)));  // lights shine along -z
    // `range` (0: infinite) is a world distance: "light properties are unaffected by node
    // transforms" (KHR_lights_punctual).
    const float range = float(l.range);
    if (!(l.range >= 0.0 && std::isfinite(range)))
      fail("lights[" + std::to_string(index) + "].range", "expected a number > 0 (or none, for infinite)");
    if (l.type == "point") {
      scene_.lights.push_back(std::make_unique<PointLight>(position, radiometric, range));
    } else if (l.type == "spot") {
      scene_.lights.push_back(std::make_unique<SpotLight>(position, direction, radiometric,
                                                          float(l.spot.innerConeAngle),
                                                          float(l.spot.outerConeAngle), range));
    } else if (l.type == "directional") {
      scene_.lights.push_back(std::make_unique<DirectionalLight>(-direction, radiometric));
    } else {
      fail(where, "unknown light type '" + l.type + "'; valid: point, spot, directional");
    }
    ++result_.lights;
  }

  // Reads `count` elements of accessor `index` as floats (normalised integers are converted),
  // after checking every byte it touches lies inside its buffer view and buffer.
  std::vector<float> readFloats(int index, int expectedType, const std::string& where, size_t& count) {
    const tinygltf::Accessor& acc = checkedAccessor(index, where);
    if (acc.type != expectedType) fail(where, "unexpected accessor type");
    const int components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
    count = checkedCount(acc, where);
    std::vector<float> out(count * size_t(components), 0.0f);
    // Integer components are normalised when the accessor says so (always for TEXCOORD and COLOR
    // in core glTF; KHR_mesh_quantization allows the rest): unsigned c / max, signed max(c / max, -1).
    forEachElement(acc, where, [&](const uint8_t* src, size_t i) {
      for (int c = 0; c < components; ++c) {
        float v;
        switch (acc.componentType) {
          case TINYGLTF_COMPONENT_TYPE_FLOAT:
            std::memcpy(&v, src + 4 * c, 4);
            break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            v = acc.normalized ? src[c] / 255.0f : float(src[c]);
            break;
          case TINYGLTF_COMPONENT_TYPE_BYTE: {
            const auto b = static_cast<int8_t>(src[c]);
            v = acc.normalized ? std::max(b / 127.0f, -1.0f) : float(b);
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t s;
            std::memcpy(&s, src + 2 * c, 2);
            v = acc.normalized ? s / 65535.0f : float(s);
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t s;
            std::memcpy(&s, src + 2 * c, 2);
            v = acc.normalized ? std::max(s / 32767.0f, -1.0f) : float(s);
            break;
          }
          default:
            fail(where, "unsupported component type " + std::to_string(acc.componentType));
        }
        if (!std::isfinite(v)) fail(where, "contains NaN or infinite values");
        out[i * size_t(components) + size_t(c)] = v;
      }
    });
    return out;
  }

  std::vector<uint32_t> readIndices(int index, const std::string& where) {
    const tinygltf::Accessor& acc = checkedAccessor(index, where);
    if (acc.type != TINYGLTF_TYPE_SCALAR) fail(where, "index accessor must be SCALAR");
    std::vector<uint32_t> out(checkedCount(acc, where));
    forEachElement(acc, where, [&](const uint8_t* src, size_t i) {
      switch (acc.componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          out[i] = src[0];
          break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          uint16_t s;
          std::memcpy(&s, src, 2);
          out[i] = s;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
          std::memcpy(&out[i], src, 4);
          break;
        default:
          fail(where, "index component type must be an unsigned integer");
      }
    });
    return out;
  }

  const tinygltf::Accessor& checkedAccessor(int index, const std::string& where) const {
    if (index < 0 || size_t(index) >= model_.accessors.size())
      fail(where, "accessor index " + std::to_string(index) + " out of range");
    return model_.accessors[size_t(index)];
  }

  // Calls fn(element bytes, i) for each of the accessor's elements i that is stored: the buffer
  // view's elements in order, then each sparse substitution (glTF 2.0 section 3.6.2.3: the base
  // elements, or zeros without a buffer view, with `count` of them replaced by the values at the
  // indices given). Elements stored nowhere are zeros, which callers' outputs start as.
  template <typename Fn>
  void forEachElement(const tinygltf::Accessor& acc, const std::string& where, Fn fn) const {
    const size_t elementSize = elementSizeOf(acc, where);
    if (acc.bufferView >= 0) {
      const ElementBytes base =
          elementBytes(acc.bufferView, acc.byteOffset, acc.count, elementSize, true, where);
      for (size_t i = 0; i < acc.count; ++i) fn(base.first + i * base.stride, i);
    }
    if (acc.sparse.isSparse) forEachSparseElement(acc, elementSize, where + ".sparse", fn);
  }

  template <typename Fn>
  void forEachSparseElement(const tinygltf::Accessor& acc, size_t elementSize, const std::string& where,
                            Fn fn) const {
    const auto& sparse = acc.sparse;
    if (sparse.count < 1 || size_t(sparse.count) > acc.count)
      fail(where + ".count", "expected 1.." + std::to_string(acc.count) + " (the accessor's count), got " +
                                 std::to_string(sparse.count));
    const size_t count = size_t(sparse.count);
    const int indexSize = tinygltf::GetComponentSizeInBytes(uint32_t(sparse.indices.componentType));
    if (sparse.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        sparse.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        sparse.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(where + ".indices.componentType", "must be an unsigned integer type");
    const ElementBytes indices = elementBytes(sparse.indices.bufferView, sparse.indices.byteOffset, count,
                                              size_t(indexSize), false, where + ".indices");
    const ElementBytes values = elementBytes(sparse.values.bufferView, sparse.values.byteOffset, count,
                                             elementSize, false, where + ".values");
    size_t previous = 0;
    for (size_t j = 0; j < count; ++j) {
      uint32_t index = 0;
      std::memcpy(&index, indices.first + j * size_t(indexSize), size_t(indexSize));  // little-endian
      if (index >= acc.count)
        fail(where + ".indices", "index " + std::to_string(index) + " (entry " + std::to_string(j) +
                                     ") is past the accessor's " + std::to_string(acc.count) + " elements");
      if (j > 0 && index <= previous)
        fail(where + ".indices", "indices must strictly increase (entry " + std::to_string(j) + ")");
      previous = index;
      fn(values.first + j * elementSize, size_t(index));
    }
  }

  size_t elementSizeOf(const tinygltf::Accessor& acc, const std::string& where) const {
    const int componentSize = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
    const int components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
    if (componentSize <= 0 || components <= 0) fail(where, "invalid component type or accessor type");
    return size_t(componentSize) * size_t(components);
  }

  // Elements an accessor without a buffer view may have: all zeros but for sparse substitutions,
  // so its count is bounded by nothing in the file. 2^24 is far more vertices than a mesh Ember
  // can render on one machine has, and its arrays stay within a few hundred MB.
  static constexpr size_t kMaxElementsWithoutView = size_t(1) << 24;

  // The accessor's count, checked before anything is allocated for it: the elements of a buffer
  // view must lie inside it (elementBytes), and a count without one is capped.
  size_t checkedCount(const tinygltf::Accessor& acc, const std::string& where) const {
    const size_t elementSize = elementSizeOf(acc, where);
    if (acc.bufferView >= 0)
      elementBytes(acc.bufferView, acc.byteOffset, acc.count, elementSize, true, where);
    else if (acc.count > kMaxElementsWithoutView)
      fail(where, "an accessor without a bufferView may have at most " +
                      std::to_string(kMaxElementsWithoutView) + " elements, not " +
                      std::to_string(acc.count));
    return acc.count;
  }

  struct ElementBytes {
    const uint8_t* first;
    size_t stride;
  };
  // Where `count` elements of `elementSize` bytes start in buffer view `viewIndex` at `byteOffset`,
  // after checking that every byte lies inside the view and its buffer. Sparse indices and values
  // are tightly packed: their views may not set byteStride (`strided` false).
  ElementBytes elementBytes(int viewIndex, size_t byteOffset, size_t count, size_t elementSize, bool strided,
                            const std::string& where) const {
    if (viewIndex < 0 || size_t(viewIndex) >= model_.bufferViews.size())
      fail(where, "bufferView index " + std::to_string(viewIndex) + " out of range");
    const tinygltf::BufferView& view = model_.bufferViews[size_t(viewIndex)];
    if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
      fail(where, "buffer index out of range");
    const tinygltf::Buffer& buffer = model_.buffers[size_t(view.buffer)];
    if (!strided && view.byteStride) fail(where, "the bufferView of sparse data must not set byteStride");
    const size_t stride = view.byteStride ? view.byteStride : elementSize;
    if (stride < elementSize) fail(where, "byteStride smaller than the element size");
    if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset)
      fail(where, "bufferView extends past the end of its buffer (buffer has " +
                      std::to_string(buffer.data.size()) + " bytes)");
    const uint8_t* first = buffer.data.data() + view.byteOffset;
    if (count == 0) return {first, stride};
    // Element k occupies [byteOffset + k stride, + elementSize): all of them fit if the first does
    // and the last starts within the room after it. Divided, not multiplied: a count from the
    // file can make `stride * count` wrap.
    if (byteOffset > view.byteLength || elementSize > view.byteLength - byteOffset ||
        count - 1 > (view.byteLength - byteOffset - elementSize) / stride)
      fail(where, std::to_string(count) + " elements of " + std::to_string(elementSize) + " bytes (stride " +
                      std::to_string(stride) + ") from byte " + std::to_string(byteOffset) +
                      " read past the end of the bufferView (" + std::to_string(view.byteLength) + " bytes)");
    return {first + byteOffset, stride};
  }

  // glTF points and lines have no width (rasterisers draw them one pixel wide), which a path tracer
  // cannot see. Ember renders them as small spheres and capped cylinders of a radius relative to the
  // scene's size (kCurveRadius x the bounds' diagonal), made in makePointsAndLines() once every
  // primitive is read.
  static constexpr float kCurveRadius = 0.004f;
  struct PointsOrLines {
    std::vector<Vec3> points;
    std::vector<std::pair<uint32_t, uint32_t>> segments;  // empty for POINTS
    int material;
    std::string where;
  };

  void readPointsOrLines(const tinygltf::Primitive& prim, int mode, const Mat4& world,
                         const std::vector<float>& positions, size_t vertexCount, const std::string& where) {
    PointsOrLines item{{}, {}, materialOf(prim, where), where};
    for (size_t i = 0; i < vertexCount; ++i)
      item.points.push_back(
          Vec3(world * glm::vec4(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2], 1.0f)));
    std::vector<uint32_t> order;
    if (prim.indices >= 0) {
      order = readIndices(prim.indices, where + ".indices");
      for (uint32_t idx : order)
        if (idx >= vertexCount) fail(where + ".indices", "index " + std::to_string(idx) + " out of range");
    } else {
      for (uint32_t i = 0; i < vertexCount; ++i) order.push_back(i);
    }
    if (mode == kModePoints) {
      std::vector<Vec3> used;
      for (uint32_t idx : order) used.push_back(item.points[idx]);
      item.points = std::move(used);
    } else if (mode == kModeLines) {
      for (size_t i = 0; i + 1 < order.size(); i += 2) item.segments.emplace_back(order[i], order[i + 1]);
    } else {  // kModeLineStrip or kModeLineLoop: consecutive vertices, the loop closed
      static_assert(kModeLineStrip == kModeLineLoop + 1);
      for (size_t i = 0; i + 1 < order.size(); ++i) item.segments.emplace_back(order[i], order[i + 1]);
      if (mode == kModeLineLoop && order.size() > 2) item.segments.emplace_back(order.back(), order.front());
    }
    pointsAndLines_.push_back(std::move(item));
  }

  void makePointsAndLines(size_t firstMesh) {
    if (pointsAndLines_.empty()) return;
    Bounds bounds;
    for (size_t i = firstMesh; i < scene_.meshes.size(); ++i) bounds.extend(scene_.meshes[i].worldBounds());
    for (const PointsOrLines& item : pointsAndLines_)
      for (const Vec3& p : item.points) bounds.extend(p);
    const float radius = std::max(kCurveRadius * glm::length(bounds.upper - bounds.lower), 1e-6f);
    for (const PointsOrLines& item : pointsAndLines_) {
      const GltfSurface& surface = materials_.surface(item.material);
      const Material* material = options_.materialOverride ? options_.materialOverride : surface.material;
      if (item.segments.empty()) {
        for (const Vec3& p : item.points)
          scene_.shapes.push_back({item.where, std::make_unique<Sphere>(p, radius), material,
                                   surface.emission, surface.doubleSided});
        result_.points += item.points.size();
      }
      for (const auto& [a, b] : item.segments) {
        if (item.points[a] == item.points[b]) continue;
        scene_.shapes.push_back({item.where,
                                 std::make_unique<Cylinder>(item.points[a], item.points[b], radius, true),
                                 material, surface.emission, surface.doubleSided});
        ++result_.segments;
      }
    }
  }

  // What makes two primitives the same triangles: their mode and the accessors of their indices
  // and vertex attributes (not their material). Nodes that place the same triangles share one mesh
  // (Scene::MeshEntry::toWorld): files reuse an accessor under several meshes of different
  // materials, as MetalRoughSpheresNoTextures does for its 98 spheres.
  static std::string geometryKey(const tinygltf::Primitive& prim) {
    std::string key = std::to_string(prim.mode) + "/" + std::to_string(prim.indices);
    for (const auto& [name, accessor] : prim.attributes)  // a std::map: in name order
      key += "/" + name + "=" + std::to_string(accessor);
    return key;
  }

  // How many times the file places each primitive's triangles (every node's mesh, reachable or not).
  void countPlacements() {
    for (const tinygltf::Node& node : model_.nodes)
      if (node.mesh >= 0 && size_t(node.mesh) < model_.meshes.size())
        for (const tinygltf::Primitive& prim : model_.meshes[size_t(node.mesh)].primitives)
          ++placements_[geometryKey(prim)];
  }

  void readPrimitive(const tinygltf::Primitive& prim, const Mat4& world, const Mat4& inFile,
                     const std::string& where) {
    const int mode = prim.mode < 0 ? kModeTriangles : prim.mode;
    if (mode < kModePoints || mode > kModeFan)
      fail(where + ".mode", "unknown primitive mode " + std::to_string(mode));
    if (mode != kModeTriangles && mode != kModeStrip && mode != kModeFan) {
      const auto pos = prim.attributes.find("POSITION");
      if (pos == prim.attributes.end()) fail(where, "primitive has no POSITION attribute");
      size_t vertexCount = 0;
      const std::vector<float> positions =
          readFloats(pos->second, TINYGLTF_TYPE_VEC3, where + ".attributes.POSITION", vertexCount);
      readPointsOrLines(prim, mode, world, positions, vertexCount, where);
      return;
    }
    // Triangles placed more than once are read once, in object space, and placed by the node's
    // transform; the rest are transformed into world space as they are read.
    const std::string key = geometryKey(prim);
    const bool shared = placements_[key] > 1 && MeshInstance::placeable(world);
    std::shared_ptr<TriangleMesh> mesh;
    if (shared) {
      std::shared_ptr<TriangleMesh>& cached = sharedMeshes_[key];
      if (!cached) cached = readTriangles(prim, mode, Mat4(1.0f), where);
      mesh = cached;
    } else {
      mesh = readTriangles(prim, mode, world, where);
    }
    if (mesh->indices.empty()) return;

    result_.triangles += mesh->indices.size();
    ++result_.primitives;
    const int materialIndex = materialOf(prim, where);
    const GltfSurface& surface = materials_.surface(materialIndex, !mesh->colors.empty());
    if (surface.maxTexCoord >= mesh->texCoordSetCount())
      fail(surface.maxTexCoordWhere, "texCoord " + std::to_string(surface.maxTexCoord) + " names TEXCOORD_" +
                                         std::to_string(surface.maxTexCoord) + ", which " + where +
                                         " does not have");
    if (surface.needsTangents && mesh->tangents.empty()) mesh->generateTangents();
    const Material* material = surface.material;
    if (options_.materialOverride) {
      material = options_.materialOverride;
    } else if (materialIndex >= 0 && size_t(materialIndex) < model_.materials.size()) {
      const auto it = options_.materialsByName.find(model_.materials[size_t(materialIndex)].name);
      if (it != options_.materialsByName.end()) material = it->second;
    }
    std::optional<Mat4> toWorld;
    if (shared && surface.opacity) {
      // Alpha-tested triangles stay in world space: the opacity filter hashes the ray Embree hands
      // it, which for an instance is in object space, and is the material's, not the mesh's.
      mesh = MeshInstance(mesh.get(), world).baked();
    } else if (shared) {
      toWorld = world;
    }
    if (!shared || surface.opacity) mesh->opacity = surface.opacity;
    scene_.meshes.push_back({std::move(mesh), material, surface.emission, surface.maps, surface.doubleSided,
                             toWorld, toWorld ? std::optional<Mat4>(inFile) : std::nullopt});
  }

  std::shared_ptr<TriangleMesh> readTriangles(const tinygltf::Primitive& prim, int mode, const Mat4& world,
                                              const std::string& where) {
    const auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) fail(where, "primitive has no POSITION attribute");
    size_t vertexCount = 0;
    const std::vector<float> positions =
        readFloats(pos->second, TINYGLTF_TYPE_VEC3, where + ".attributes.POSITION", vertexCount);
    auto mesh = std::make_shared<TriangleMesh>();
    mesh->name = where;
    const glm::mat3 normalMatrix = glm::transpose(glm::inverse(glm::mat3(world)));
    mesh->positions.resize(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i)
      mesh->positions[i] =
          Vec3(world * glm::vec4(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2], 1.0f));

    if (const auto nrm = prim.attributes.find("NORMAL"); nrm != prim.attributes.end()) {
      size_t n = 0;
      const std::vector<float> normals =
          readFloats(nrm->second, TINYGLTF_TYPE_VEC3, where + ".attributes.NORMAL", n);
      if (n != vertexCount) fail(where + ".attributes.NORMAL", "count differs from POSITION");
      mesh->normals.resize(n);
      for (size_t i = 0; i < n; ++i) {
        const Vec3 v = normalMatrix * Vec3(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
        const float len = glm::length(v);
        mesh->normals[i] = len > 0.0f ? v / len : Vec3(0.0f);
      }
    }
    if (const auto uv = prim.attributes.find("TEXCOORD_0"); uv != prim.attributes.end()) {
      size_t n = 0;
      const std::vector<float> uvs =
          readFloats(uv->second, TINYGLTF_TYPE_VEC2, where + ".attributes.TEXCOORD_0", n);
      if (n != vertexCount) fail(where + ".attributes.TEXCOORD_0", "count differs from POSITION");
      mesh->uvs.resize(n);
      for (size_t i = 0; i < n; ++i) mesh->uvs[i] = Vec2(uvs[2 * i], uvs[2 * i + 1]);
    }
    // TEXCOORD_1, TEXCOORD_2, ...: read up to the first set the primitive lacks (sets are numbered
    // without gaps, glTF 2.0 section 3.7.2.1).
    for (int set = 1;; ++set) {
      const auto it = prim.attributes.find("TEXCOORD_" + std::to_string(set));
      if (it == prim.attributes.end()) break;
      const std::string w = where + ".attributes." + it->first;
      size_t n = 0;
      const std::vector<float> uvs = readFloats(it->second, TINYGLTF_TYPE_VEC2, w, n);
      if (n != vertexCount) fail(w, "count differs from POSITION");
      std::vector<Vec2>& out = mesh->texCoordSets.emplace_back(n);
      for (size_t i = 0; i < n; ++i) out[i] = Vec2(uvs[2 * i], uvs[2 * i + 1]);
    }
    // COLOR_0 multiplies the base colour and its alpha (glTF 2.0 section 3.9.2): RGB or RGBA,
    // float or normalised unsigned integers.
    if (const auto col = prim.attributes.find("COLOR_0"); col != prim.attributes.end()) {
      const std::string w = where + ".attributes.COLOR_0";
      const tinygltf::Accessor& acc = checkedAccessor(col->second, w);
      if (acc.type != TINYGLTF_TYPE_VEC3 && acc.type != TINYGLTF_TYPE_VEC4)
        fail(w, "expected a VEC3 or VEC4 accessor");
      const int components = acc.type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
      size_t n = 0;
      const std::vector<float> colors = readFloats(col->second, acc.type, w, n);
      if (n != vertexCount) fail(w, "count differs from POSITION");
      mesh->colors.resize(n);
      for (size_t i = 0; i < n; ++i) {
        const float* c = &colors[size_t(components) * i];
        mesh->colors[i] = glm::clamp(glm::vec4(c[0], c[1], c[2], components == 4 ? c[3] : 1.0f), 0.0f, 1.0f);
        if (!std::isfinite(c[0] + c[1] + c[2] + (components == 4 ? c[3] : 0.0f)))
          fail(w, "non-finite colour at vertex " + std::to_string(i));
      }
    }
    if (const auto tan = prim.attributes.find("TANGENT");
        tan != prim.attributes.end() && !mesh->normals.empty()) {
      size_t n = 0;
      const std::vector<float> tangents =
          readFloats(tan->second, TINYGLTF_TYPE_VEC4, where + ".attributes.TANGENT", n);
      if (n != vertexCount) fail(where + ".attributes.TANGENT", "count differs from POSITION");
      mesh->tangents.resize(n);
      const glm::mat3 linear(world);  // tangents are directions on the surface: transformed like edges
      // A mirroring transform flips the handedness of the (T, B, N) frame.
      const float handedness = glm::determinant(linear) < 0.0f ? -1.0f : 1.0f;
      for (size_t i = 0; i < n; ++i) {
        const Vec3 t = linear * Vec3(tangents[4 * i], tangents[4 * i + 1], tangents[4 * i + 2]);
        mesh->tangents[i] = glm::vec4(t, tangents[4 * i + 3] * handedness);
      }
    }

    std::vector<uint32_t> order;
    if (prim.indices >= 0) {
      order = readIndices(prim.indices, where + ".indices");
      for (uint32_t idx : order)
        if (idx >= vertexCount)
          fail(where + ".indices", "index " + std::to_string(idx) + " out of range (" +
                                       std::to_string(vertexCount) + " vertices)");
    } else {
      order.resize(vertexCount);
      for (size_t i = 0; i < vertexCount; ++i) order[i] = uint32_t(i);
    }
    appendTriangles(*mesh, order, mode);
    return mesh;
  }

  static void appendTriangles(TriangleMesh& mesh, const std::vector<uint32_t>& order, int mode) {
    auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
      if (a == b || b == c || a == c) return;  // degenerate (strip restarts, bad data)
      mesh.indices.emplace_back(a, b, c);
    };
    if (mode == kModeTriangles) {
      for (size_t i = 0; i + 2 < order.size(); i += 3) add(order[i], order[i + 1], order[i + 2]);
    } else if (mode == kModeStrip) {
      for (size_t i = 0; i + 2 < order.size(); ++i)
        i % 2 ? add(order[i + 1], order[i], order[i + 2]) : add(order[i], order[i + 1], order[i + 2]);
    } else {
      for (size_t i = 1; i + 1 < order.size(); ++i) add(order[0], order[i], order[i + 1]);
    }
  }

  std::string path_;
  Scene& scene_;
  GltfImportOptions options_;
  tinygltf::Model model_;
  GltfMaterialReader materials_;
  GltfImport result_;
  std::set<std::string> usedOverrides_;
  std::vector<PointsOrLines> pointsAndLines_;
  int variant_ = -1;                       // index of options_.variant among the file's variants
  std::map<std::string, int> placements_;  // geometryKey -> node uses
  std::map<std::string, std::shared_ptr<TriangleMesh>> sharedMeshes_;  // in object space
};

}  // namespace

GltfImport importGltf(const std::string& path, Scene& scene, const GltfImportOptions& options) {
  return GltfImporter(path, scene, options).run();
}

}  // namespace ember

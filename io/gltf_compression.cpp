#include "io/gltf_compression.h"

#include "io/input_error.h"

#include <draco/compression/decode.h>
#include <meshoptimizer.h>
#include <webp/decode.h>

#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

namespace ember {

namespace {

constexpr const char* kMeshopt = "EXT_meshopt_compression";
constexpr const char* kDraco = "KHR_draco_mesh_compression";
constexpr const char* kWebp = "EXT_texture_webp";
constexpr const char* kBasisu = "KHR_texture_basisu";

// The largest WebP image decoded, as io/image_io.cpp limits the other image readers (smaller in
// fuzzing builds, so that each input stays fast).
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
constexpr int64_t kMaxWebpPixels = int64_t(1) << 20;
#else
constexpr int64_t kMaxWebpPixels = int64_t(1) << 28;
#endif

// No EXT_meshopt_compression bitstream decodes to more than 64 times its size: attribute data
// spends at least 2 header bits per group of 16 elements on every byte of an element, triangle
// data a byte per triangle and index data a byte per index (the specification's Appendix A). A
// count beyond that is refused before anything is allocated for it.
constexpr size_t kMaxMeshoptExpansion = 64;

std::string str(size_t v) {
  return std::to_string(v);
}

class CompressionDecoder {
 public:
  CompressionDecoder(tinygltf::Model& model, const std::string& path) : model_(model), path_(path) {}

  void run() {
    decodeMeshopt();
    decodeDraco();
    resolveTextures();
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw InputError(path_ + ": " + where + ": " + what);
  }
  void warn(const std::string& where, const std::string& what) const {
    std::fprintf(stderr, "ember: %s: %s: %s\n", path_.c_str(), where.c_str(), what.c_str());
  }

  bool required(const std::string& extension) const {
    return std::find(model_.extensionsRequired.begin(), model_.extensionsRequired.end(), extension) !=
           model_.extensionsRequired.end();
  }

  // A non-negative integer property of an extension object, nullopt when absent. (tinygltf keeps
  // JSON integers as int, larger ones wrapped, and the rest as double: a wrapped value is only ever
  // compared with the real sizes below.)
  std::optional<size_t> integer(const tinygltf::Value& object, const std::string& key,
                                const std::string& where) const {
    if (!object.Has(key)) return std::nullopt;
    const tinygltf::Value& v = object.Get(key);
    const double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
    if (!(d >= 0.0 && d <= 9007199254740992.0 && d == std::floor(d)))
      fail(where + "." + key, "expected an integer >= 0");
    return size_t(d);
  }
  size_t requiredInteger(const tinygltf::Value& object, const std::string& key,
                         const std::string& where) const {
    const std::optional<size_t> v = integer(object, key, where);
    if (!v) fail(where, "'" + key + "' is required");
    return *v;
  }
  std::string text(const tinygltf::Value& object, const std::string& key, const std::string& where,
                   const char* fallback) const {
    if (!object.Has(key)) {
      if (!fallback) fail(where, "'" + key + "' is required");
      return fallback;
    }
    const tinygltf::Value& v = object.Get(key);
    if (!v.IsString()) fail(where + "." + key, "expected a string");
    return v.Get<std::string>();
  }

  // EXT_meshopt_compression: each compressed buffer view is decoded into one new buffer and made
  // to point at its bytes there, so that accessors, sparse data and images read plain data. The
  // view's own buffer is then no longer read: it may be a fallback without data.
  void decodeMeshopt() {
    struct Placed {
      size_t view, offset, length;
    };
    std::vector<Placed> placed;
    std::vector<unsigned char> out;
    for (size_t i = 0; i < model_.bufferViews.size(); ++i) {
      const tinygltf::BufferView& view = model_.bufferViews[i];
      const auto it = view.extensions.find(kMeshopt);
      if (it == view.extensions.end()) continue;
      const std::string where = "bufferViews[" + str(i) + "].extensions." + kMeshopt;
      const tinygltf::Value& ext = it->second;
      if (!ext.IsObject()) fail(where, "expected an object");
      const size_t buffer = requiredInteger(ext, "buffer", where);
      const size_t byteOffset = integer(ext, "byteOffset", where).value_or(0);
      const size_t byteLength = requiredInteger(ext, "byteLength", where);
      const size_t stride = requiredInteger(ext, "byteStride", where);
      const size_t count = requiredInteger(ext, "count", where);
      const std::string mode = text(ext, "mode", where, nullptr);
      const std::string filter = text(ext, "filter", where, "NONE");
      // The specification's conditions for a valid extension object, which are also what the
      // decoders assume (meshoptimizer asserts them).
      if (mode != "ATTRIBUTES" && mode != "TRIANGLES" && mode != "INDICES")
        fail(where + ".mode", "'" + mode + "' is not ATTRIBUTES, TRIANGLES or INDICES");
      if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
        fail(where + ".filter", "'" + filter + "' is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
      if (mode == "ATTRIBUTES") {
        if (stride == 0 || stride % 4 != 0 || stride > 256)
          fail(where + ".byteStride",
               "must be a multiple of 4 up to 256 in ATTRIBUTES mode, not " + str(stride));
      } else {
        if (stride != 2 && stride != 4)
          fail(where + ".byteStride", "must be 2 or 4 in " + mode + " mode, not " + str(stride));
        if (filter != "NONE") fail(where + ".filter", "must be NONE in " + mode + " mode");
      }
      if (mode == "TRIANGLES" && count % 3 != 0)
        fail(where + ".count", "must be a multiple of 3 in TRIANGLES mode, not " + str(count));
      if (filter == "OCTAHEDRAL" && stride != 4 && stride != 8)
        fail(where + ".byteStride", "must be 4 or 8 with the OCTAHEDRAL filter, not " + str(stride));
      if (filter == "QUATERNION" && stride != 8)
        fail(where + ".byteStride", "must be 8 with the QUATERNION filter, not " + str(stride));
      if (view.byteStride != 0 && view.byteStride != stride)
        fail(where + ".byteStride",
             str(stride) + " differs from the bufferView's byteStride " + str(view.byteStride));
      if (buffer >= model_.buffers.size())
        fail(where + ".buffer",
             "buffer index " + str(buffer) + " out of range (" + str(model_.buffers.size()) + " buffers)");
      const std::vector<unsigned char>& source = model_.buffers[buffer].data;
      if (byteOffset > source.size() || byteLength > source.size() - byteOffset)
        fail(where, "byteOffset " + str(byteOffset) + " + byteLength " + str(byteLength) +
                        " reads past the end of buffer " + str(buffer) + " (" + str(source.size()) +
                        " bytes)");
      const size_t decodedSize = count * stride;  // count < 2^53, stride <= 256: no overflow
      if (decodedSize != view.byteLength)
        fail(where, "count " + str(count) + " x byteStride " + str(stride) + " = " + str(decodedSize) +
                        " bytes, but the bufferView's byteLength is " + str(view.byteLength) +
                        " (the specification requires them equal)");
      if (decodedSize / kMaxMeshoptExpansion > byteLength)
        fail(where, str(byteLength) + " compressed bytes cannot hold " + str(count) + " elements of " +
                        str(stride) + " bytes");

      const size_t offset = (out.size() + 3) / 4 * 4;
      out.resize(offset + decodedSize);
      unsigned char* dst = out.data() + offset;
      const unsigned char* src = source.data() + byteOffset;
      const int rc = mode == "ATTRIBUTES"  ? meshopt_decodeVertexBuffer(dst, count, stride, src, byteLength)
                     : mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(dst, count, stride, src, byteLength)
                                           : meshopt_decodeIndexSequence(dst, count, stride, src, byteLength);
      if (rc != 0)
        fail(where, "the " + mode + " data (" + str(byteLength) + " bytes from byte " + str(byteOffset) +
                        " of buffer " + str(buffer) +
                        ") cannot be decoded: truncated or corrupt (meshoptimizer error " +
                        std::to_string(rc) + ")");
      // The filters of Appendix B run in place on the decoded elements.
      if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(dst, count, stride);
      if (filter == "QUATERNION") meshopt_decodeFilterQuat(dst, count, stride);
      if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(dst, count, stride);
      placed.push_back({i, offset, decodedSize});
    }
    if (placed.empty()) return;
    tinygltf::Buffer decoded;
    decoded.name = "EXT_meshopt_compression data decoded by Ember";
    decoded.data = std::move(out);
    model_.buffers.push_back(std::move(decoded));
    for (const Placed& p : placed) {
      tinygltf::BufferView& view = model_.bufferViews[p.view];
      view.buffer = int(model_.buffers.size()) - 1;
      view.byteOffset = p.offset;
      view.byteLength = p.length;
    }
  }

  // KHR_draco_mesh_compression: each compressed primitive is decoded and gets new accessors for
  // its indices (uint32) and for the attributes the extension names (float, dequantised and
  // normalised by Draco), in one new buffer. The accessors it had describe the same data but have
  // no bufferView; the specification has loaders ignore their storage.
  void decodeDraco() {
    int outBuffer = -1;
    const auto addAccessor = [&](const void* data, size_t bytes, int componentType, int type, size_t count,
                                 int target) {
      if (outBuffer < 0) {
        model_.buffers.emplace_back().name = "KHR_draco_mesh_compression data decoded by Ember";
        outBuffer = int(model_.buffers.size()) - 1;
      }
      std::vector<unsigned char>& d = model_.buffers[size_t(outBuffer)].data;
      d.resize((d.size() + 3) / 4 * 4);
      tinygltf::BufferView view;
      view.buffer = outBuffer;
      view.byteOffset = d.size();
      view.byteLength = bytes;
      view.target = target;
      d.insert(d.end(), static_cast<const unsigned char*>(data),
               static_cast<const unsigned char*>(data) + bytes);
      model_.bufferViews.push_back(view);
      tinygltf::Accessor accessor;
      accessor.bufferView = int(model_.bufferViews.size()) - 1;
      accessor.componentType = componentType;
      accessor.type = type;
      accessor.count = count;
      model_.accessors.push_back(accessor);
      return int(model_.accessors.size()) - 1;
    };
    for (size_t m = 0; m < model_.meshes.size(); ++m)
      for (size_t p = 0; p < model_.meshes[m].primitives.size(); ++p) {
        tinygltf::Primitive& prim = model_.meshes[m].primitives[p];
        const auto it = prim.extensions.find(kDraco);
        if (it == prim.extensions.end()) continue;
        const std::string primWhere = "meshes[" + str(m) + "].primitives[" + str(p) + "]";
        const std::string where = primWhere + ".extensions." + kDraco;
        const tinygltf::Value& ext = it->second;
        if (!ext.IsObject()) fail(where, "expected an object");
        const size_t viewIndex = requiredInteger(ext, "bufferView", where);
        if (viewIndex >= model_.bufferViews.size())
          fail(where + ".bufferView", "bufferView index " + str(viewIndex) + " out of range");
        const tinygltf::BufferView view = model_.bufferViews[viewIndex];
        const std::string viewName = "bufferViews[" + str(viewIndex) + "]";
        if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
          fail(where + ".bufferView",
               viewName + " names buffer " + std::to_string(view.buffer) + ", out of range");
        const std::vector<unsigned char>& data = model_.buffers[size_t(view.buffer)].data;
        if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
          fail(where + ".bufferView", viewName + " (" + str(view.byteLength) + " bytes from byte " +
                                          str(view.byteOffset) + ") extends past the end of buffer " +
                                          std::to_string(view.buffer) + " (" + str(data.size()) + " bytes)");
        // Draco decodes triangle faces whichever of the two modes the primitive has (the
        // specification's "Restrictions on geometry type"); they become a TRIANGLES list.
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP)
          fail(primWhere + ".mode",
               "a Draco-compressed primitive must be TRIANGLES (4) or TRIANGLE_STRIP (5), not " +
                   std::to_string(mode));
        if (!ext.Has("attributes") || !ext.Get("attributes").IsObject())
          fail(where + ".attributes", "expected an object of Draco attribute ids");

        draco::DecoderBuffer in;
        in.Init(reinterpret_cast<const char*>(data.data() + view.byteOffset), view.byteLength);
        const auto geometry = draco::Decoder::GetEncodedGeometryType(&in);
        if (!geometry.ok())
          fail(where, viewName + " does not hold Draco data: " + geometry.status().error_msg_string());
        if (geometry.value() != draco::TRIANGULAR_MESH)
          fail(where, viewName + " holds a Draco point cloud, not a triangle mesh");
        draco::Decoder decoder;
        auto decoded = decoder.DecodeMeshFromBuffer(&in);
        if (!decoded.ok())
          fail(where, "the Draco data in " + viewName +
                          " cannot be decoded: " + decoded.status().error_msg_string());
        const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
        if (!mesh) fail(where, "the Draco data in " + viewName + " cannot be decoded");
        const uint32_t points = mesh->num_points();

        std::vector<uint32_t> indices;
        indices.reserve(size_t(mesh->num_faces()) * 3);
        for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f)
          for (int k = 0; k < 3; ++k) {
            const uint32_t v = mesh->face(f)[k].value();
            if (v >= points)
              fail(where, "face " + str(f.value()) + " names point " + str(v) + " of " + str(points));
            indices.push_back(v);
          }
        const int indexAccessor =
            addAccessor(indices.data(), indices.size() * 4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                        TINYGLTF_TYPE_SCALAR, indices.size(), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);

        const tinygltf::Value& ids = ext.Get("attributes");
        for (const std::string& name : ids.Keys()) {
          const std::string at = where + ".attributes." + name;
          const auto attribute = prim.attributes.find(name);
          // The extension's attributes must be a subset of the primitive's; one that is not has no
          // accessor to fill, and nothing reads it.
          if (attribute == prim.attributes.end()) continue;
          const size_t id = requiredInteger(ids, name, where + ".attributes");
          if (attribute->second < 0 || size_t(attribute->second) >= model_.accessors.size())
            fail(primWhere + ".attributes." + name,
                 "accessor index " + std::to_string(attribute->second) + " out of range");
          const int type = model_.accessors[size_t(attribute->second)].type;
          const int components = tinygltf::GetNumComponentsInType(uint32_t(type));
          if (components < 1 || components > 4)
            fail(primWhere + ".attributes." + name,
                 "a Draco attribute's accessor must be SCALAR or VEC2 to VEC4");
          const draco::PointAttribute* a =
              id <= UINT32_MAX ? mesh->GetAttributeByUniqueId(uint32_t(id)) : nullptr;
          if (!a) fail(at, "the Draco data has no attribute with unique id " + str(id));
          if (a->num_components() != components)
            fail(at, "the Draco attribute has " + std::to_string(a->num_components()) +
                         " components, its accessor's type " + std::to_string(components));
          // glTF reads a normalised signed integer c as max(c / max, -1) (section 3.11); Draco
          // divides by max alone.
          const bool signedNormalised =
              a->normalized() && (a->data_type() == draco::DT_INT8 || a->data_type() == draco::DT_INT16 ||
                                  a->data_type() == draco::DT_INT32);
          std::vector<float> values(size_t(points) * size_t(components));
          for (draco::PointIndex pt(0); pt < points; ++pt) {
            const draco::AttributeValueIndex value = a->mapped_index(pt);
            float* dst = &values[size_t(pt.value()) * size_t(components)];
            if (value.value() >= a->size() || !a->ConvertValue<float>(value, int8_t(components), dst))
              fail(at, "point " + str(pt.value()) + " has no valid value");
            if (signedNormalised)
              for (int c = 0; c < components; ++c) dst[c] = std::max(dst[c], -1.0f);
          }
          prim.attributes[name] = addAccessor(values.data(), values.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                              type, points, TINYGLTF_TARGET_ARRAY_BUFFER);
        }
        prim.indices = indexAccessor;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
      }
  }

  // EXT_texture_webp: a texture whose WebP image decoded uses it as its source; one whose image did
  // not falls back to its own `source` unless there is none or the file requires the extension.
  // KHR_texture_basisu: no KTX2 / Basis Universal decoder is packaged in Debian, so the texture's
  // own `source` (the PNG or JPEG fallback the extension provides for) is used, and a texture that
  // has none, or a file that requires the extension, is refused.
  void resolveTextures() {
    for (size_t i = 0; i < model_.textures.size(); ++i) {
      tinygltf::Texture& tex = model_.textures[i];
      const std::string at = "textures[" + str(i) + "].extensions.";
      if (const auto it = tex.extensions.find(kWebp); it != tex.extensions.end()) {
        const std::string where = at + kWebp;
        if (!it->second.IsObject()) fail(where, "expected an object");
        const size_t image = requiredInteger(it->second, "source", where);
        if (image >= model_.images.size())
          fail(where + ".source",
               "image index " + str(image) + " out of range (" + str(model_.images.size()) + " images)");
        const tinygltf::Image& img = model_.images[image];
        if (img.width > 0 && img.height > 0 && !img.image.empty()) {
          tex.source = int(image);
        } else {
          const std::string what = "images[" + str(image) + "] is not a WebP image that libwebp can decode";
          if (required(kWebp) || tex.source < 0)
            fail(where + ".source", what + ", and the texture has no fallback source");
          warn(where + ".source",
               what + "; using the fallback source images[" + std::to_string(tex.source) + "]");
        }
      }
      if (tex.extensions.count(kBasisu) && (required(kBasisu) || tex.source < 0))
        fail(at + kBasisu,
             "KTX2 / Basis Universal textures cannot be decoded (Ember has no KTX2 decoder); the texture "
             "needs a PNG or JPEG fallback `source`, with KHR_texture_basisu left out of extensionsRequired");
    }
  }

  tinygltf::Model& model_;
  const std::string& path_;
};

bool startsWith(const unsigned char* bytes, size_t size, const char* magic, size_t length, size_t at = 0) {
  return size >= at + length && std::memcmp(bytes + at, magic, length) == 0;
}

bool loadImage(tinygltf::Image* image, const int index, std::string* err, std::string* warn, int reqWidth,
               int reqHeight, const unsigned char* bytes, int size, void* userData) {
  const auto* model = static_cast<const tinygltf::Model*>(userData);
  const std::string where = "images[" + std::to_string(index) + "]";
  // tinygltf passes &buffer.data[view.byteOffset] and view.byteLength for an image in a buffer
  // view without checking either against the buffer.
  if (image->bufferView >= 0) {
    const size_t v = size_t(image->bufferView);
    const tinygltf::BufferView* view =
        model && v < model->bufferViews.size() ? &model->bufferViews[v] : nullptr;
    const tinygltf::Buffer* buffer = view && view->buffer >= 0 && size_t(view->buffer) < model->buffers.size()
                                         ? &model->buffers[size_t(view->buffer)]
                                         : nullptr;
    if (!buffer || view->byteOffset > buffer->data.size() ||
        view->byteLength > buffer->data.size() - view->byteOffset) {
      if (err)
        *err += where + ": bufferView " + std::to_string(v) + " lies outside its buffer" +
                (buffer ? " (" + str(buffer->data.size()) + " bytes)" : std::string()) + "\n";
      return false;
    }
  }
  const size_t n = size > 0 ? size_t(size) : 0;
  // RIFF....WEBP (the WebP container), or the MIME type the file gives.
  if ((startsWith(bytes, n, "RIFF", 4) && startsWith(bytes, n, "WEBP", 4, 8)) ||
      image->mimeType == "image/webp") {
    image->mimeType = "image/webp";
    image->image.clear();
    image->width = image->height = 0;
    int width = 0, height = 0;
    // A WebP image that cannot be decoded stays empty: decodeCompressedData names the texture that
    // needs it, or uses its fallback.
    if (!WebPGetInfo(bytes, n, &width, &height) || width <= 0 || height <= 0 ||
        int64_t(width) * height > kMaxWebpPixels)
      return true;
    uint8_t* rgba = WebPDecodeRGBA(bytes, n, &width, &height);
    if (!rgba) return true;
    image->image.assign(rgba, rgba + size_t(width) * size_t(height) * 4);
    WebPFree(rgba);
    image->width = width;
    image->height = height;
    image->component = 4;  // as tinygltf's own loader gives every image
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    return true;
  }
  // KTX2 (its 12-byte identifier, or the MIME type): left empty for decodeCompressedData to judge
  // whether the texture has a fallback, rather than failing the whole file as stb_image would.
  if (startsWith(bytes, n, "\xABKTX 20\xBB\r\n\x1A\n", 12) || image->mimeType == "image/ktx2") {
    image->mimeType = "image/ktx2";
    return true;
  }
  // PNG, JPEG and the rest: kept encoded here and decoded once the whole file is read, every image
  // at once (decodeDeferredImages). Decoding them one by one inside tinygltf's parse was most of a
  // textured file's load time.
  (void)reqWidth;
  (void)reqHeight;
  (void)err;
  (void)warn;
  image->image.assign(bytes, bytes + n);
  image->as_is = true;
  return true;
}

}  // namespace

void decodeCompressedData(tinygltf::Model& model, const std::string& path) {
  CompressionDecoder(model, path).run();
}

tinygltf::LoadImageDataFunction gltfImageLoader() {
  return &loadImage;
}

void decodeDeferredImages(tinygltf::Model& model, const std::string& path) {
  std::vector<std::string> errors(model.images.size());
  tbb::parallel_for(size_t(0), model.images.size(), [&](size_t i) {
    tinygltf::Image& image = model.images[i];
    if (!image.as_is) return;
    const std::vector<unsigned char> bytes = std::move(image.image);
    image.image.clear();
    image.as_is = false;
    std::string warn;
    // tinygltf's own loader (stb_image; its user data read as LoadImageDataOption: none, its
    // defaults), exactly as tinygltf would have called it while parsing.
    if (!tinygltf::LoadImageData(&image, int(i), &errors[i], &warn, 0, 0, bytes.data(), int(bytes.size()),
                                 nullptr) &&
        errors[i].empty())
      errors[i] = "images[" + std::to_string(i) + "]: cannot decode";
  });
  // The first failing image, as tinygltf's parse would have stopped at it.
  for (std::string& e : errors) {
    if (e.empty()) continue;
    while (!e.empty() && (e.back() == '\n' || e.back() == '\r')) e.pop_back();
    throw InputError(path + ": cannot load glTF: " + e);
  }
}

std::optional<std::string> patchCompressedGltf(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(file)), {});
  // Binary glTF: a 12-byte header, then the JSON chunk (length, type, data) and the rest.
  const bool glb = bytes.size() >= 12 && bytes.compare(0, 4, "glTF") == 0;
  std::string json = bytes, rest;
  if (glb) {
    uint32_t length = 0, type = 0;
    if (bytes.size() < 20) return std::nullopt;
    std::memcpy(&length, bytes.data() + 12, 4);
    std::memcpy(&type, bytes.data() + 16, 4);
    if (type != 0x4E4F534Au || length > bytes.size() - 20) return std::nullopt;
    json = bytes.substr(20, length);
    rest = bytes.substr(20 + size_t(length));
  }
  nlohmann::json doc = nlohmann::json::parse(json, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return std::nullopt;
  const auto array = [&](const char* key) -> nlohmann::json* {
    return doc.contains(key) && doc[key].is_array() ? &doc[key] : nullptr;
  };
  const auto extension = [](const nlohmann::json& o, const char* name) -> const nlohmann::json* {
    if (!o.is_object() || !o.contains("extensions") || !o["extensions"].is_object()) return nullptr;
    const nlohmann::json& e = o["extensions"];
    return e.contains(name) && e[name].is_object() ? &e[name] : nullptr;
  };
  bool changed = false;

  // A Draco primitive's indices accessor without a bufferView (its data is in the Draco bitstream):
  // tinygltf refuses it, and decodeCompressedData gives the primitive new indices anyway.
  const nlohmann::json* accessors = array("accessors");
  if (nlohmann::json* meshes = array("meshes"))
    for (nlohmann::json& mesh : *meshes) {
      if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
      for (nlohmann::json& prim : mesh["primitives"]) {
        if (!extension(prim, kDraco) || !prim.contains("indices") || !prim["indices"].is_number_unsigned())
          continue;
        const size_t index = prim["indices"].get<size_t>();
        if (accessors && index < accessors->size() && (*accessors)[index].is_object() &&
            !(*accessors)[index].contains("bufferView")) {
          prim.erase("indices");
          changed = true;
        }
      }
    }

  // A meshopt fallback buffer without a uri (tagged `fallback`, or read only by compressed views):
  // tinygltf tries to load it as a file (or, in a .glb, as the binary chunk), though nothing is
  // ever read from it. A data URI of one zero byte stands in (tinygltf refuses an empty one);
  // buffer 0 of a .glb is its binary chunk.
  if (nlohmann::json* buffers = array("buffers")) {
    std::vector<int> compressedReads(buffers->size(), 0), plainReads(buffers->size(), 0);
    if (const nlohmann::json* views = array("bufferViews"))
      for (const nlohmann::json& view : *views)
        if (view.is_object() && view.contains("buffer") && view["buffer"].is_number_unsigned()) {
          const size_t b = view["buffer"].get<size_t>();
          if (b < buffers->size()) ++(extension(view, kMeshopt) ? compressedReads : plainReads)[b];
        }
    for (size_t i = glb ? 1 : 0; i < buffers->size(); ++i) {
      nlohmann::json& buffer = (*buffers)[i];
      if (!buffer.is_object() || buffer.contains("uri")) continue;
      const nlohmann::json* ext = extension(buffer, kMeshopt);
      const bool tagged = ext && ext->contains("fallback") && (*ext)["fallback"] == true;
      if (tagged || (compressedReads[i] > 0 && plainReads[i] == 0)) {
        buffer["uri"] = "data:application/octet-stream;base64,AA==";
        buffer["byteLength"] = 1;
        changed = true;
      }
    }
  }
  if (!changed) return std::nullopt;
  if (bytes.size() > UINT32_MAX / 2) return std::nullopt;  // tinygltf's from-memory loaders take 32-bit sizes

  std::string patched = doc.dump();
  if (!glb) return patched;
  while (patched.size() % 4) patched += ' ';  // the JSON chunk is padded with spaces
  std::string out = bytes.substr(0, 8);       // magic and version
  const auto put = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  put(uint32_t(12 + 8 + patched.size() + rest.size()));
  put(uint32_t(patched.size()));
  put(0x4E4F534Au);  // "JSON"
  return out + patched + rest;
}

}  // namespace ember

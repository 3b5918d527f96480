// Compressed glTF (io/gltf_compression.h): files written here with the encoders of the same Debian
// libraries the loader decodes with (meshoptimizer, Draco, libwebp) must load as the uncompressed
// file does, and malformed ones must fail with an InputError naming the file and the place.
#include "cli_runner.h"
#include "gltf_builder.h"
#include "io/gltf_compression.h"
#include "io/gltf_loader.h"
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "test_fixtures.h"
#include "test_paths.h"

#include <dlfcn.h>
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <webp/encode.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>

namespace ember {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::GltfBuilder;
using test::TempDir;

struct MeshData {
  std::vector<GltfBuilder::Vertex> vertices;
  std::vector<uint32_t> indices;
};

// A UV sphere of radius 1 (the vertices of GltfBuilder::addSphere), small enough to stay fast.
MeshData sphere(int rings = 6, int segments = 10) {
  MeshData m;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const float theta = float(M_PI) * float(i) / float(rings),
                  phi = 2.0f * float(M_PI) * float(j) / float(segments);
      const float n[3] = {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
      m.vertices.push_back({{n[0], n[1], n[2]},
                            {n[0], n[1], n[2]},
                            {float(j) / float(segments), float(i) / float(rings)},
                            {0, 0, 0, 1}});
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = uint32_t(i * (segments + 1) + j), b = a + uint32_t(segments + 1);
      if (i > 0) m.indices.insert(m.indices.end(), {a, b, a + 1});  // no degenerate pole triangles
      if (i < rings - 1) m.indices.insert(m.indices.end(), {a + 1, b, b + 1});
    }
  return m;
}

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t v = uint32_t(bytes[i]) << 16 | (i + 1 < bytes.size() ? uint32_t(bytes[i + 1]) << 8 : 0) |
                       (i + 2 < bytes.size() ? bytes[i + 2] : 0);
    out += digits[v >> 18];
    out += digits[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? digits[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? digits[v & 63] : '=';
  }
  return out;
}

// A compressed file: its JSON and the bytes of its buffer 0 (a data URI in a .gltf, the binary
// chunk of a .glb).
struct GltfFile {
  json doc;
  std::vector<uint8_t> bin;

  std::string write(const std::string& path) const {
    json d = doc;
    if (path.size() > 4 && path.substr(path.size() - 4) == ".glb") {
      d["buffers"][0].erase("uri");
      d["buffers"][0]["byteLength"] = bin.size();
      std::string text = d.dump();
      while (text.size() % 4) text += ' ';
      std::string chunk(bin.begin(), bin.end());
      while (chunk.size() % 4) chunk += '\0';
      std::string out = "glTF";
      const auto put = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
      put(2);
      put(uint32_t(12 + 8 + text.size() + 8 + chunk.size()));
      put(uint32_t(text.size()));
      out += "JSON" + text;
      put(uint32_t(chunk.size()));
      out += std::string("BIN\0", 4) + chunk;
      std::ofstream(path, std::ios::binary) << out;
    } else {
      d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(bin);
      d["buffers"][0]["byteLength"] = bin.size();
      std::ofstream(path, std::ios::binary) << d.dump(1);
    }
    return path;
  }
};

json sceneOfOneMesh(json primitive, const std::vector<std::string>& extensions) {
  return {{"asset", {{"version", "2.0"}}},
          {"extensionsUsed", extensions},
          {"extensionsRequired", extensions},
          {"buffers", json::array({json::object()})},
          {"bufferViews", json::array()},
          {"accessors", json::array()},
          {"meshes", json::array({{{"primitives", json::array({primitive})}}})},
          {"nodes", json::array({{{"mesh", 0}}})},
          {"scenes", json::array({{{"nodes", {0}}}})},
          {"scene", 0}};
}

template <typename T>
std::vector<uint8_t> bytesOf(const std::vector<T>& v) {
  std::vector<uint8_t> out(v.size() * sizeof(T));
  std::memcpy(out.data(), v.data(), out.size());
  return out;
}

struct MeshoptOptions {
  bool octahedralNormals = false;     // NORMAL as normalised int8 through the OCTAHEDRAL filter
  bool exponentialPositions = false;  // POSITION through the EXPONENTIAL filter
  bool indexSequence16 = false;       // INDICES mode with 16-bit indices instead of 32-bit TRIANGLES
};

// `mesh` with every buffer view EXT_meshopt_compression-compressed into buffer 0, beside a fallback
// buffer 1 without data. Views: 0 POSITION, 1 NORMAL, 2 TEXCOORD_0, 3 indices.
GltfFile meshoptFile(const MeshData& mesh, const MeshoptOptions& o = {}) {
  std::vector<std::string> extensions = {"EXT_meshopt_compression"};
  if (o.octahedralNormals) extensions.push_back("KHR_mesh_quantization");
  GltfFile f{sceneOfOneMesh({{"attributes", json::object()}, {"mode", 4}}, extensions), {}};
  size_t fallbackSize = 0;
  const auto addView = [&](const std::vector<uint8_t>& encoded, size_t count, size_t stride,
                           const std::string& mode, const std::string& filter, json accessor) {
    while (f.bin.size() % 4) f.bin.push_back(0);
    json ext = {{"buffer", 0},
                {"byteOffset", f.bin.size()},
                {"byteLength", encoded.size()},
                {"byteStride", stride},
                {"count", count},
                {"mode", mode}};
    if (!filter.empty()) ext["filter"] = filter;
    f.bin.insert(f.bin.end(), encoded.begin(), encoded.end());
    json view = {{"buffer", 1},
                 {"byteOffset", fallbackSize},
                 {"byteLength", count * stride},
                 {"extensions", {{"EXT_meshopt_compression", ext}}}};
    if (mode == "ATTRIBUTES") view["byteStride"] = stride;
    fallbackSize += (count * stride + 3) / 4 * 4;
    f.doc["bufferViews"].push_back(view);
    accessor["bufferView"] = f.doc["bufferViews"].size() - 1;
    accessor["count"] = count;
    f.doc["accessors"].push_back(accessor);
    return f.doc["accessors"].size() - 1;
  };
  const auto attributes = [](const std::vector<uint8_t>& raw, size_t count, size_t stride) {
    std::vector<uint8_t> out(meshopt_encodeVertexBufferBound(count, stride));
    out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), raw.data(), count, stride));
    return out;
  };
  const size_t n = mesh.vertices.size();
  std::vector<float> pos, nrm4, uv;
  for (const auto& v : mesh.vertices) {
    pos.insert(pos.end(), v.p, v.p + 3);
    nrm4.insert(nrm4.end(), {v.n[0], v.n[1], v.n[2], 0.0f});
    uv.insert(uv.end(), v.uv, v.uv + 2);
  }
  json& prim = f.doc["meshes"][0]["primitives"][0];
  std::vector<uint8_t> posBytes = bytesOf(pos);
  if (o.exponentialPositions) meshopt_encodeFilterExp(posBytes.data(), n, 12, 24, pos.data());
  prim["attributes"]["POSITION"] =
      addView(attributes(posBytes, n, 12), n, 12, "ATTRIBUTES", o.exponentialPositions ? "EXPONENTIAL" : "",
              {{"componentType", 5126}, {"type", "VEC3"}, {"min", {-1, -1, -1}}, {"max", {1, 1, 1}}});
  if (o.octahedralNormals) {
    std::vector<uint8_t> oct(4 * n);
    meshopt_encodeFilterOct(oct.data(), n, 4, 8, nrm4.data());
    prim["attributes"]["NORMAL"] = addView(attributes(oct, n, 4), n, 4, "ATTRIBUTES", "OCTAHEDRAL",
                                           {{"componentType", 5120}, {"normalized", true}, {"type", "VEC3"}});
  } else {
    std::vector<float> nrm;
    for (size_t i = 0; i < n; ++i) nrm.insert(nrm.end(), &nrm4[4 * i], &nrm4[4 * i] + 3);
    prim["attributes"]["NORMAL"] = addView(attributes(bytesOf(nrm), n, 12), n, 12, "ATTRIBUTES", "",
                                           {{"componentType", 5126}, {"type", "VEC3"}});
  }
  prim["attributes"]["TEXCOORD_0"] = addView(attributes(bytesOf(uv), n, 8), n, 8, "ATTRIBUTES", "",
                                             {{"componentType", 5126}, {"type", "VEC2"}});
  const std::vector<uint32_t>& idx = mesh.indices;
  std::vector<uint8_t> enc;
  if (o.indexSequence16) {
    enc.resize(meshopt_encodeIndexSequenceBound(idx.size(), n));
    enc.resize(meshopt_encodeIndexSequence(enc.data(), enc.size(), idx.data(), idx.size()));
    prim["indices"] =
        addView(enc, idx.size(), 2, "INDICES", "", {{"componentType", 5123}, {"type", "SCALAR"}});
  } else {
    enc.resize(meshopt_encodeIndexBufferBound(idx.size(), n));
    enc.resize(meshopt_encodeIndexBuffer(enc.data(), enc.size(), idx.data(), idx.size()));
    prim["indices"] =
        addView(enc, idx.size(), 4, "TRIANGLES", "", {{"componentType", 5125}, {"type", "SCALAR"}});
  }
  f.doc["buffers"].push_back(
      {{"byteLength", fallbackSize}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
  return f;
}

// `mesh` as one KHR_draco_mesh_compression primitive (buffer view 0); the accessors have no
// bufferView. Lossless unless `quantised` (then 14-bit positions, 10-bit normals, 12-bit UVs, as
// exporters' defaults are).
GltfFile dracoFile(const MeshData& mesh, bool quantised) {
  draco::TriangleSoupMeshBuilder builder;
  const int faces = int(mesh.indices.size() / 3);
  builder.Start(faces);
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int nrm = builder.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32);
  const int uv = builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
  for (int f = 0; f < faces; ++f) {
    const auto& a = mesh.vertices[mesh.indices[3 * size_t(f)]];
    const auto& b = mesh.vertices[mesh.indices[3 * size_t(f) + 1]];
    const auto& c = mesh.vertices[mesh.indices[3 * size_t(f) + 2]];
    builder.SetAttributeValuesForFace(pos, draco::FaceIndex(f), a.p, b.p, c.p);
    builder.SetAttributeValuesForFace(nrm, draco::FaceIndex(f), a.n, b.n, c.n);
    builder.SetAttributeValuesForFace(uv, draco::FaceIndex(f), a.uv, b.uv, c.uv);
  }
  const std::unique_ptr<draco::Mesh> dm = builder.Finalize();
  draco::Encoder encoder;
  if (quantised) {
    encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 14);
    encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, 10);
    encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, 12);
  }
  draco::EncoderBuffer out;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(*dm, &out).ok());
  GltfFile f{sceneOfOneMesh({{"attributes", {{"POSITION", 1}, {"NORMAL", 2}, {"TEXCOORD_0", 3}}},
                             {"indices", 0},
                             {"mode", 4},
                             {"extensions",
                              {{"KHR_draco_mesh_compression",
                                {{"bufferView", 0},
                                 {"attributes",
                                  {{"POSITION", dm->attribute(pos)->unique_id()},
                                   {"NORMAL", dm->attribute(nrm)->unique_id()},
                                   {"TEXCOORD_0", dm->attribute(uv)->unique_id()}}}}}}}},
                            {"KHR_draco_mesh_compression"}),
             std::vector<uint8_t>(out.data(), out.data() + out.size())};
  f.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 0}, {"byteLength", out.size()}});
  const size_t points = dm->num_points();
  f.doc["accessors"] = {{{"componentType", 5125}, {"count", 3 * faces}, {"type", "SCALAR"}},
                        {{"componentType", 5126},
                         {"count", points},
                         {"type", "VEC3"},
                         {"min", {-1, -1, -1}},
                         {"max", {1, 1, 1}}},
                        {{"componentType", 5126}, {"count", points}, {"type", "VEC3"}},
                        {{"componentType", 5126}, {"count", points}, {"type", "VEC2"}}};
  return f;
}

std::string writePlain(const TempDir& dir, const MeshData& mesh) {
  GltfBuilder b;
  b.addMesh(mesh.vertices, mesh.indices, -1);
  EXPECT_TRUE(b.write(dir.file("plain.gltf")));
  return dir.file("plain.gltf");
}

const TriangleMesh& importedMesh(const std::string& path, Scene& scene) {
  importGltf(path, scene);
  if (scene.meshes.size() != 1) throw std::runtime_error(path + ": expected one mesh");
  return *scene.meshes[0].mesh;
}

// The InputError's message of loading `path` (empty when it loads).
std::string loadError(const std::string& path) {
  try {
    Scene scene;
    importGltf(path, scene);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Each triangle as its three corners (position, normal, uv), rotated to start at the smallest
// corner (keeping the winding), sorted: the same for two meshes with the same triangles whatever
// their vertex and triangle order.
using Corner = std::array<float, 8>;
std::vector<std::array<Corner, 3>> canonicalTriangles(const TriangleMesh& m) {
  std::vector<std::array<Corner, 3>> out;
  for (const glm::uvec3& t : m.indices) {
    std::array<Corner, 3> tri;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = t[k];
      tri[size_t(k)] = {m.positions[v].x, m.positions[v].y, m.positions[v].z, m.normals[v].x,
                        m.normals[v].y,   m.normals[v].z,   m.uvs[v].x,       m.uvs[v].y};
    }
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    out.push_back(tri);
  }
  std::sort(out.begin(), out.end());
  return out;
}

#define EXPECT_ERROR(path, ...)                                                                   \
  do {                                                                                            \
    const std::string message = loadError(path);                                                  \
    EXPECT_NE(message.find(path), std::string::npos) << "no error naming the file: " << message;  \
    for (const std::string& part : {__VA_ARGS__})                                                 \
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message; \
  } while (0)

TEST(GltfMeshopt, LoadsTheSameTrianglesPositionsNormalsAndUvsAsTheUncompressedFile) {
  TempDir dir;
  const MeshData mesh = sphere();
  Scene plainScene, meshoptScene, glbScene, sequenceScene;
  const TriangleMesh& plain = importedMesh(writePlain(dir, mesh), plainScene);
  // Exact: the codecs are lossless without filters, and keep the order of vertices and indices.
  const std::string gltf = meshoptFile(mesh).write(dir.file("m.gltf"));
  const std::string glb = meshoptFile(mesh).write(dir.file("m.glb"));
  const std::string sequence = meshoptFile(mesh, {.indexSequence16 = true}).write(dir.file("s.gltf"));
  const std::vector<std::pair<std::string, Scene*>> files = {
      {gltf, &meshoptScene}, {glb, &glbScene}, {sequence, &sequenceScene}};
  for (const auto& [path, scene] : files) {
    const TriangleMesh& m = importedMesh(path, *scene);
    EXPECT_EQ(m.positions, plain.positions) << path;
    EXPECT_EQ(m.normals, plain.normals) << path;
    EXPECT_EQ(m.uvs, plain.uvs) << path;
    EXPECT_EQ(m.indices, plain.indices) << path;
  }
  EXPECT_EQ(plain.indices.size(), mesh.indices.size() / 3);
  // The retried load (tinygltf refuses the fallback buffer) records the file once, for checkpoints.
  EXPECT_EQ(std::count(meshoptScene.sourceFiles.begin(), meshoptScene.sourceFiles.end(), gltf), 1);
}

TEST(GltfMeshopt, FiltersDecodeToTheEncodedValues) {
  TempDir dir;
  const MeshData mesh = sphere();
  Scene plainScene, scene;
  const TriangleMesh& plain = importedMesh(writePlain(dir, mesh), plainScene);
  const TriangleMesh& m = importedMesh(
      meshoptFile(mesh, {.octahedralNormals = true, .exponentialPositions = true}).write(dir.file("f.gltf")),
      scene);
  ASSERT_EQ(m.positions.size(), plain.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.positions[i][c], plain.positions[i][c], 1e-6f) << i;
    // 8-bit octahedral normals: within a few degrees.
    EXPECT_GT(glm::dot(m.normals[i], plain.normals[i]), 0.999f) << i;
  }
  EXPECT_EQ(m.indices, plain.indices);
}

// Nothing Ember reads is a quaternion, so the QUATERNION filter is checked on a decoded view.
TEST(GltfMeshopt, QuaternionFilterDecodesTheRotations) {
  const std::vector<float> q = {0, 0,    0, 1,    0.5f,   0.5f,  0.5f,  0.5f,
                                0, 0.6f, 0, 0.8f, -0.36f, 0.48f, 0.64f, 0.48f};
  std::vector<uint8_t> filtered(16 * 2);
  meshopt_encodeFilterQuat(filtered.data(), 4, 8, 16, q.data());
  std::vector<uint8_t> encoded(meshopt_encodeVertexBufferBound(4, 8));
  encoded.resize(meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), filtered.data(), 4, 8));
  tinygltf::Model model;
  model.buffers.emplace_back().data = encoded;
  tinygltf::BufferView& view = model.bufferViews.emplace_back();
  view.buffer = 0;
  view.byteLength = 32;
  view.extensions["EXT_meshopt_compression"] =
      tinygltf::Value(tinygltf::Value::Object{{"buffer", tinygltf::Value(0)},
                                              {"byteLength", tinygltf::Value(int(encoded.size()))},
                                              {"byteStride", tinygltf::Value(8)},
                                              {"count", tinygltf::Value(4)},
                                              {"mode", tinygltf::Value(std::string("ATTRIBUTES"))},
                                              {"filter", tinygltf::Value(std::string("QUATERNION"))}});
  decodeCompressedData(model, "memory.gltf");
  const tinygltf::BufferView& decoded = model.bufferViews[0];
  ASSERT_EQ(decoded.buffer, 1);
  ASSERT_EQ(decoded.byteLength, 32u);
  for (int i = 0; i < 4; ++i) {
    int16_t s[4];
    std::memcpy(s, model.buffers[1].data.data() + decoded.byteOffset + 8 * size_t(i), 8);
    float dot = 0.0f;
    for (int c = 0; c < 4; ++c) dot += s[c] / 32767.0f * q[4 * size_t(i) + size_t(c)];
    EXPECT_NEAR(std::abs(dot), 1.0f, 1e-3f) << "quaternion " << i;  // q and -q are one rotation
  }
}

TEST(GltfMeshopt, MalformedExtensionsAreErrorsNamingTheBufferView) {
  TempDir dir;
  const GltfFile good = meshoptFile(sphere());
  const std::string v0 = "bufferViews[0].extensions.EXT_meshopt_compression";
  const std::string v3 = "bufferViews[3].extensions.EXT_meshopt_compression";
  struct Case {
    std::function<void(json& doc, std::vector<uint8_t>& bin)> mutate;
    std::vector<std::string> expected;
  };
  const auto ext = [](json& doc, int view) -> json& {
    return doc["bufferViews"][view]["extensions"]["EXT_meshopt_compression"];
  };
  const std::vector<Case> cases = {
      {[&](json& d, auto&) { ext(d, 0)["byteLength"] = ext(d, 0)["byteLength"].get<int>() / 2; },
       {v0 + ": the ATTRIBUTES data", "cannot be decoded: truncated or corrupt"}},
      {[&](json& d, auto&) { ext(d, 3)["byteLength"] = ext(d, 3)["byteLength"].get<int>() - 1; },
       {v3 + ": the TRIANGLES data", "cannot be decoded"}},
      {[&](json& d, auto&) { ext(d, 0)["byteLength"] = 100000; },
       {v0 + ": byteOffset 0 + byteLength 100000 reads past the end of buffer 0"}},
      {[&](json& d, auto& bin) { ext(d, 1)["byteOffset"] = bin.size() + 1; },
       {"bufferViews[1].extensions", "reads past the end of buffer 0"}},
      {[&](json& d, auto&) { ext(d, 0)["buffer"] = 1; }, {v0 + ": byteOffset 0", "past the end of buffer 1"}},
      {[&](json& d, auto&) { ext(d, 0)["buffer"] = 7; }, {v0 + ".buffer: buffer index 7 out of range"}},
      {[&](json& d, auto&) { ext(d, 0)["mode"] = "FOO"; }, {v0 + ".mode: 'FOO' is not ATTRIBUTES"}},
      {[&](json& d, auto&) { ext(d, 0)["filter"] = "OCTAHEDRAL"; },
       {v0 + ".byteStride: must be 4 or 8 with the OCTAHEDRAL filter"}},
      {[&](json& d, auto&) { ext(d, 0)["filter"] = "BLUR"; }, {v0 + ".filter: 'BLUR'"}},
      {[&](json& d, auto&) { ext(d, 3)["filter"] = "EXPONENTIAL"; },
       {v3 + ".filter: must be NONE in TRIANGLES mode"}},
      {[&](json& d, auto&) {
         ext(d, 0)["byteStride"] = 6;
         d["bufferViews"][0].erase("byteStride");
       },
       {v0 + ".byteStride: must be a multiple of 4"}},
      {[&](json& d, auto&) { ext(d, 3)["byteStride"] = 3; }, {v3 + ".byteStride: must be 2 or 4"}},
      {[&](json& d, auto&) { d["bufferViews"][0]["byteStride"] = 16; },
       {v0 + ".byteStride: 12 differs from the bufferView's byteStride 16"}},
      {[&](json& d, auto&) {
         ext(d, 3)["count"] = 4;
         d["bufferViews"][3]["byteLength"] = 16;
       },
       {v3 + ".count: must be a multiple of 3"}},
      {[&](json& d, auto&) { ext(d, 0)["count"] = ext(d, 0)["count"].get<int>() + 1; },
       {v0 + ": count", "the bufferView's byteLength is"}},
      // A count far beyond what the compressed bytes can hold is refused before it is allocated.
      {[&](json& d, auto&) {
         ext(d, 0)["count"] = 100000000;
         d["bufferViews"][0]["byteLength"] = 1200000000;
       },
       {v0 + ":", "compressed bytes cannot hold 100000000 elements"}},
      {[&](json& d, auto&) { ext(d, 0)["byteLength"] = -5; }, {v0 + ".byteLength: expected an integer >= 0"}},
      {[&](json& d, auto&) { ext(d, 0).erase("count"); }, {v0 + ": 'count' is required"}},
      // tinygltf keeps only objects as extensions: the view is read as plain data, from the
      // fallback buffer.
      {[&](json& d, auto&) { ext(d, 0) = "compressed"; },
       {"meshes[0].primitives[0].attributes.POSITION: bufferView extends past the end of its buffer"}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    GltfFile f = good;
    cases[i].mutate(f.doc, f.bin);
    const std::string path = f.write(dir.file("bad" + std::to_string(i) + ".gltf"));
    const std::string message = loadError(path);
    EXPECT_NE(message.find(path + ": "), std::string::npos) << "case " << i << ": " << message;
    for (const std::string& part : cases[i].expected)
      EXPECT_NE(message.find(part), std::string::npos)
          << "case " << i << ": '" << part << "' not in: " << message;
  }
}

// Every truncation and many single-byte corruptions of the compressed data load or fail with an
// InputError; none crashes (the sanitizer builds run this too).
TEST(GltfMeshopt, CorruptDataNeverCrashes) {
  TempDir dir;
  const GltfFile good = meshoptFile(sphere(3, 4));
  for (size_t i = 0; i < good.bin.size(); i += 3) {
    for (const bool truncate : {false, true}) {
      GltfFile f = good;
      if (truncate)
        f.bin.resize(i);
      else
        f.bin[i] ^= 0x5A;
      const std::string path = f.write(dir.file("c.gltf"));
      try {
        Scene scene;
        importGltf(path, scene);
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      }
    }
  }
}

TEST(GltfDraco, LoadsTheSameTrianglesAsTheUncompressedFile) {
  TempDir dir;
  const MeshData mesh = sphere();
  Scene plainScene, dracoScene;
  const TriangleMesh& plain = importedMesh(writePlain(dir, mesh), plainScene);
  // Lossless Draco keeps every value but may reorder vertices and triangles.
  const TriangleMesh& m = importedMesh(dracoFile(mesh, false).write(dir.file("d.gltf")), dracoScene);
  EXPECT_EQ(canonicalTriangles(m), canonicalTriangles(plain));
  EXPECT_EQ(m.indices.size(), mesh.indices.size() / 3);
}

TEST(GltfDraco, QuantisedDataLoadsWithinTheQuantisationError) {
  TempDir dir;
  const MeshData mesh = sphere();
  Scene scene;
  const TriangleMesh& m = importedMesh(dracoFile(mesh, true).write(dir.file("q.glb")), scene);
  ASSERT_EQ(m.indices.size(), mesh.indices.size() / 3);
  for (size_t i = 0; i < m.positions.size(); ++i) {
    EXPECT_NEAR(glm::length(m.positions[i]), 1.0f, 1e-3f) << i;  // 14 bits over [-1, 1]
    EXPECT_GT(glm::dot(m.normals[i], m.positions[i]), 0.995f) << i;
    // Each vertex's uv is the one of some original vertex at that position.
    float best = 1.0f;
    for (const auto& v : mesh.vertices)
      if (glm::length(Vec3(v.p[0], v.p[1], v.p[2]) - m.positions[i]) < 1e-3f)
        best = std::min(best, glm::length(Vec2(v.uv[0], v.uv[1]) - m.uvs[i]));
    EXPECT_LT(best, 1e-3f) << i;
  }
}

// Debian's assimp-testmodels carries one Draco file, COLLADA2GLTF's 2CylinderEngine: 29 meshes
// whose accessors say how many indices each primitive decodes to.
TEST(GltfDraco, AssimpTwoCylinderEngineLoadsEveryTriangle) {
  const std::string path = test::assimpGltfDir() + "/draco/2CylinderEngine.gltf";
  if (!fs::exists(path)) GTEST_SKIP() << path << " not found (Debian package assimp-testmodels)";
  std::ifstream in(path);
  const json doc = json::parse(in);
  // Triangles per mesh from its primitives' index accessors, summed over the nodes that place it.
  std::vector<size_t> perMesh;
  for (const json& m : doc["meshes"]) {
    size_t t = 0;
    for (const json& p : m["primitives"])
      t += doc["accessors"][p["indices"].get<size_t>()]["count"].get<size_t>() / 3;
    perMesh.push_back(t);
  }
  size_t expected = 0;
  for (const json& node : doc["nodes"])
    if (node.contains("mesh")) expected += perMesh[node["mesh"].get<size_t>()];
  Scene scene;
  const GltfImport r = importGltf(path, scene);
  EXPECT_EQ(r.triangles, expected);
  EXPECT_GT(expected, 100000u);
}

TEST(GltfDraco, MalformedDataIsAnErrorNamingThePrimitive) {
  TempDir dir;
  const GltfFile good = dracoFile(sphere(), true);
  const std::string where = "meshes[0].primitives[0].extensions.KHR_draco_mesh_compression";
  struct Case {
    std::function<void(json& doc, std::vector<uint8_t>& bin)> mutate;
    std::vector<std::string> expected;
  };
  const auto ext = [](json& doc) -> json& {
    return doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"];
  };
  const std::vector<Case> cases = {
      {[](json&, auto& bin) { bin[0] = 'X'; }, {where + ": bufferViews[0] does not hold Draco data"}},
      {[](json& d, auto& bin) { d["bufferViews"][0]["byteLength"] = bin.size() / 2; },
       {where + ": the Draco data in bufferViews[0] cannot be decoded"}},
      {[](json& d, auto& bin) { d["bufferViews"][0]["byteOffset"] = bin.size() - 4; },
       {where + ".bufferView: bufferViews[0]", "extends past the end of buffer 0"}},
      {[&](json& d, auto&) { ext(d)["bufferView"] = 5; },
       {where + ".bufferView: bufferView index 5 out of range"}},
      {[&](json& d, auto&) { ext(d)["attributes"]["POSITION"] = 9; },
       {where + ".attributes.POSITION: the Draco data has no attribute with unique id 9"}},
      {[&](json& d, auto&) { ext(d).erase("attributes"); }, {where + ".attributes: expected an object"}},
      {[&](json& d, auto&) { d["accessors"][2]["type"] = "VEC2"; },
       {where + ".attributes.NORMAL: the Draco attribute has 3 components"}},
      {[](json& d, auto&) { d["meshes"][0]["primitives"][0]["mode"] = 1; },
       {"meshes[0].primitives[0].mode: a Draco-compressed primitive must be TRIANGLES"}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    GltfFile f = good;
    cases[i].mutate(f.doc, f.bin);
    const std::string path = f.write(dir.file("bad" + std::to_string(i) + ".gltf"));
    const std::string message = loadError(path);
    EXPECT_NE(message.find(path + ": "), std::string::npos) << "case " << i << ": " << message;
    for (const std::string& part : cases[i].expected)
      EXPECT_NE(message.find(part), std::string::npos)
          << "case " << i << ": '" << part << "' not in: " << message;
  }
}

TEST(GltfDraco, CorruptDataNeverCrashes) {
  TempDir dir;
  const GltfFile good = dracoFile(sphere(3, 4), true);
  for (size_t i = 0; i < good.bin.size(); ++i) {
    for (const bool truncate : {false, true}) {
      GltfFile f = good;
      if (truncate) {
        f.bin.resize(i);
        f.doc["bufferViews"][0]["byteLength"] = i;
      } else {
        f.bin[i] ^= 0xA5;
      }
      const std::string path = f.write(dir.file("c.gltf"));
      try {
        Scene scene;
        importGltf(path, scene);
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      }
    }
  }
}

// A 4x4 texture of distinct opaque texels.
std::vector<unsigned char> texels() {
  std::vector<unsigned char> t;
  for (int i = 0; i < 16; ++i)
    t.insert(t.end(), {uint8_t(17 * i), uint8_t(255 - 13 * i), uint8_t(40 + 9 * i), 255});
  return t;
}

std::vector<uint8_t> webp(const std::vector<unsigned char>& rgba, int width, int height) {
  uint8_t* out = nullptr;
  const size_t size = WebPEncodeLosslessRGBA(rgba.data(), width, height, 4 * width, &out);
  std::vector<uint8_t> bytes(out, out + size);
  WebPFree(out);
  return bytes;
}

// A quad with a base colour texture, NEAREST-filtered: `pixels` as its PNG source.
GltfBuilder texturedQuad(const std::vector<unsigned char>& pixels) {
  GltfBuilder b;
  tinygltf::Material m;
  m.pbrMetallicRoughness.metallicFactor = 0.0;
  m.pbrMetallicRoughness.roughnessFactor = 1.0;
  m.pbrMetallicRoughness.baseColorTexture.index =
      b.addTexture(4, 4, 4, pixels, TINYGLTF_TEXTURE_WRAP_REPEAT, TINYGLTF_TEXTURE_WRAP_REPEAT,
                   TINYGLTF_TEXTURE_FILTER_NEAREST);
  b.addQuad(1.0f, b.addMaterial(m));
  return b;
}

// Adds `bytes` as image `mimeType` in a buffer view and names it in texture 0's `extension`.
void addExtensionImage(GltfBuilder& b, const std::string& extension, const std::vector<uint8_t>& bytes,
                       const std::string& mimeType, bool required) {
  tinygltf::Image image;
  image.bufferView = b.addBufferView(bytes.data(), bytes.size());
  image.mimeType = mimeType;
  b.model().images.push_back(image);
  b.model().textures[0].extensions[extension] =
      tinygltf::Value(tinygltf::Value::Object{{"source", tinygltf::Value(int(b.model().images.size()) - 1)}});
  b.model().extensionsUsed.push_back(extension);
  if (required) b.model().extensionsRequired.push_back(extension);
}

// 8x8 pixels of the quad filling an orthographic view, under a white sky.
Image renderQuad(const TempDir& dir, const std::string& gltf) {
  Scene scene = loadScene(dir.write("scene.json", R"({"image": {"width": 8, "height": 8},
    "camera": {"type": "orthographic", "origin": [0, 0, 5], "target": [0, 0, 0], "half_height": 1},
    "render": {"background": 1, "sampler": "independent"},
    "shapes": [{"type": "mesh", "file": ")" + gltf + R"("}]})"));
  scene.build();
  return test::renderFilm(scene, 4, 1).mean();
}

bool sameImage(const Image& a, const Image& b) {
  return a.width == b.width && a.height == b.height && a.rgb == b.rgb;
}

TEST(GltfWebp, WebpBaseColourRendersLikeTheSameTexelsInPng) {
  TempDir dir;
  const std::vector<unsigned char> black(64, 0);
  GltfBuilder png = texturedQuad(texels());
  ASSERT_TRUE(png.write(dir.file("png.gltf")));
  // The PNG source of the WebP file is black: only the decoded WebP gives the PNG file's render.
  GltfBuilder withFallback = texturedQuad(black);
  addExtensionImage(withFallback, "EXT_texture_webp", webp(texels(), 4, 4), "image/webp", false);
  ASSERT_TRUE(withFallback.write(dir.file("fallback.gltf")));
  GltfBuilder webpOnly = texturedQuad(texels());
  addExtensionImage(webpOnly, "EXT_texture_webp", webp(texels(), 4, 4), "image/webp", true);
  webpOnly.model().textures[0].source = -1;
  ASSERT_TRUE(webpOnly.write(dir.file("webp.gltf")));
  GltfBuilder blackPng = texturedQuad(black);
  ASSERT_TRUE(blackPng.write(dir.file("black.gltf")));

  const Image reference = renderQuad(dir, dir.file("png.gltf"));
  EXPECT_TRUE(sameImage(renderQuad(dir, dir.file("fallback.gltf")), reference));
  EXPECT_TRUE(sameImage(renderQuad(dir, dir.file("webp.gltf")), reference));
  EXPECT_FALSE(sameImage(renderQuad(dir, dir.file("black.gltf")), reference));  // the texture shows
}

TEST(GltfWebp, BrokenWebpIsAnErrorWithoutAFallbackAndAWarningWithOne) {
  TempDir dir;
  std::vector<uint8_t> broken = webp(texels(), 4, 4);
  broken.resize(broken.size() / 2);  // RIFF...WEBP header intact, image data cut
  GltfBuilder required = texturedQuad(texels());
  addExtensionImage(required, "EXT_texture_webp", broken, "image/webp", true);
  required.model().textures[0].source = -1;
  ASSERT_TRUE(required.write(dir.file("required.gltf")));
  EXPECT_ERROR(dir.file("required.gltf"), "textures[0].extensions.EXT_texture_webp.source: images[1]",
               "not a WebP image that libwebp can decode", "no fallback source");
  // Through the command line: exit status 1, the message, no output file.
  const auto r =
      test::runEmber("render '" + dir.file("required.gltf") + "' --spp 1 -q -o " + dir.file("x.exr"));
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("required.gltf: textures[0].extensions.EXT_texture_webp.source"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir.file("x.exr")));

  // Optional, with a PNG source: that is used.
  GltfBuilder optional = texturedQuad(texels());
  addExtensionImage(optional, "EXT_texture_webp", broken, "image/webp", false);
  ASSERT_TRUE(optional.write(dir.file("optional.gltf")));
  ASSERT_TRUE(texturedQuad(texels()).write(dir.file("png.gltf")));
  EXPECT_TRUE(sameImage(renderQuad(dir, dir.file("optional.gltf")), renderQuad(dir, dir.file("png.gltf"))));
}

TEST(GltfBasisu, FallbackSourceIsUsedAndWithoutOneTheTextureIsNamed) {
  TempDir dir;
  // A KTX2 identifier and nothing a decoder could use: none is packaged, so none is tried.
  std::vector<uint8_t> ktx2 = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
  ktx2.resize(64, 0);
  GltfBuilder optional = texturedQuad(texels());
  addExtensionImage(optional, "KHR_texture_basisu", ktx2, "image/ktx2", false);
  ASSERT_TRUE(optional.write(dir.file("optional.gltf")));
  ASSERT_TRUE(texturedQuad(texels()).write(dir.file("png.gltf")));
  EXPECT_TRUE(sameImage(renderQuad(dir, dir.file("optional.gltf")), renderQuad(dir, dir.file("png.gltf"))));

  for (const bool hasFallback : {false, true}) {
    GltfBuilder required = texturedQuad(texels());
    addExtensionImage(required, "KHR_texture_basisu", ktx2, "image/ktx2", true);
    if (!hasFallback) required.model().textures[0].source = -1;
    const std::string path = dir.file(hasFallback ? "required.gltf" : "nofallback.gltf");
    ASSERT_TRUE(required.write(path));
    EXPECT_ERROR(
        path, "textures[0].extensions.KHR_texture_basisu: KTX2 / Basis Universal textures cannot be decoded",
        "PNG or JPEG fallback");
  }
}

// An image in a buffer view that lies outside its buffer: tinygltf hands over the bytes unchecked.
TEST(GltfImages, ImageViewPastItsBufferIsAnError) {
  TempDir dir;
  GltfBuilder b = texturedQuad(texels());
  addExtensionImage(b, "EXT_texture_webp", webp(texels(), 4, 4), "image/webp", false);
  b.model().bufferViews.back().byteLength += 1000;
  ASSERT_TRUE(b.write(dir.file("past.gltf")));
  EXPECT_ERROR(dir.file("past.gltf"), "images[1]: bufferView", "lies outside its buffer");
}

// Debian's libdraco.so and libdraco.a carry a tinygltf of another version: linked before
// libtinygltf, its objects replace tinygltf's functions and loading crashes (cmake/Dependencies.cmake).
TEST(GltfCompression, TinygltfIsLibtinygltf) {
  Dl_info info{};
  ASSERT_NE(dladdr(reinterpret_cast<void*>(&tinygltf::LoadImageData), &info), 0);
  EXPECT_NE(std::string(info.dli_fname).find("libtinygltf"), std::string::npos) << info.dli_fname;
}

// fuzz/seeds holds one file of each kind, so that the fuzzer starts inside the decoders; they are
// written by the disabled test below and must load with the data they were written from.
TEST(GltfCompression, FuzzSeedsLoad) {
  for (const char* seed : {"meshopt.gltf", "meshopt.glb", "draco.gltf", "webp.gltf"}) {
    const std::string path = test::sourcePath(std::string("fuzz/seeds/") + seed);
    Scene scene;
    EXPECT_NO_THROW(loadScene(path)) << path;
    const GltfImport r = importGltf(path, scene);
    const size_t expected = std::string(seed) == "webp.gltf" ? 2 : sphere(3, 4).indices.size() / 3;  // a quad
    EXPECT_EQ(r.triangles, expected) << seed;
  }
}

// ember_unit_tests --gtest_also_run_disabled_tests --gtest_filter='*WriteFuzzSeeds' rewrites them.
TEST(GltfCompression, DISABLED_WriteFuzzSeeds) {
  const MeshData mesh = sphere(3, 4);
  meshoptFile(mesh, {.octahedralNormals = true, .exponentialPositions = true})
      .write(test::sourcePath("fuzz/seeds/meshopt.gltf"));
  meshoptFile(mesh, {.indexSequence16 = true}).write(test::sourcePath("fuzz/seeds/meshopt.glb"));
  dracoFile(mesh, true).write(test::sourcePath("fuzz/seeds/draco.gltf"));
  GltfBuilder b = texturedQuad(texels());
  addExtensionImage(b, "EXT_texture_webp", webp(texels(), 4, 4), "image/webp", true);
  b.model().textures[0].source = -1;
  ASSERT_TRUE(b.write(test::sourcePath("fuzz/seeds/webp.gltf")));
}

}  // namespace
}  // namespace ember

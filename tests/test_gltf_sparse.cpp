// glTF sparse accessors (glTF 2.0 section 3.6.2.3): an accessor's elements are its buffer view's,
// or zeros without one, with `count` of them replaced by the values at the indices given. Khronos'
// SimpleSparseAccessor sample and exporters that store shape keys write them. The loader must read
// them as the dense data they stand for, and refuse malformed ones with an error naming the place.
#include "cli_runner.h"
#include "gltf_builder.h"
#include "io/gltf_loader.h"
#include "io/input_error.h"
#include "renderer/scene.h"

#include <gtest/gtest.h>

#include <cstring>
#include <functional>

namespace ember {
namespace {

using test::GltfBuilder;
using test::TempDir;

// The builder's quad: vertices (-1, 1, 0), (1, 1, 0), (1, -1, 0), (-1, -1, 0).
constexpr float kQuad[4][3] = {{-1, 1, 0}, {1, 1, 0}, {1, -1, 0}, {-1, -1, 0}};

int positionAccessor(GltfBuilder& b) {
  return b.model().meshes.at(0).primitives.at(0).attributes.at("POSITION");
}

std::vector<Vec3> importedPositions(const std::string& path) {
  Scene scene;
  importGltf(path, scene);
  if (scene.meshes.size() != 1) return {};
  return scene.meshes[0].mesh->positions;
}

std::vector<uint8_t> bytesOf(const void* data, size_t n) {
  const auto* p = static_cast<const uint8_t*>(data);
  return std::vector<uint8_t>(p, p + n);
}

// Makes accessor `accessor` sparse: `values` (packed elements of its type) replace its elements at
// `indices`, stored as `indexType`. Both views start with `lead` bytes that are not theirs, which
// the sparse byteOffsets step over.
void addSparse(GltfBuilder& b, int accessor, const std::vector<uint32_t>& indices, int indexType,
               std::vector<uint8_t> values, size_t lead = 0) {
  const size_t indexSize = indexType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 1
                           : indexType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2
                                                                                 : 4;
  std::vector<uint8_t> indexBytes(lead, 0xEE);
  for (const uint32_t i : indices)
    for (size_t k = 0; k < indexSize; ++k) indexBytes.push_back(uint8_t(i >> (8 * k)));
  values.insert(values.begin(), lead, 0xEE);
  const int indexView = b.addBufferView(indexBytes.data(), indexBytes.size());
  const int valueView = b.addBufferView(values.data(), values.size());
  auto& sparse = b.model().accessors.at(size_t(accessor)).sparse;
  sparse.isSparse = true;
  sparse.count = int(indices.size());
  sparse.indices.bufferView = indexView;
  sparse.indices.byteOffset = int(lead);
  sparse.indices.componentType = indexType;
  sparse.values.bufferView = valueView;
  sparse.values.byteOffset = int(lead);
}

// Turns the quad's POSITION accessor into a sparse one: the quad's vertices at `indices` as values
// (indices stored as `indexType`), over the base view (whose replaced elements are overwritten with
// a far-away point first, so that only a correct substitution gives the quad back) or over zeros.
void makeSparse(GltfBuilder& b, const std::vector<uint32_t>& indices, int indexType, bool keepBase,
                size_t lead = 0) {
  tinygltf::Model& m = b.model();
  tinygltf::Accessor& acc = m.accessors.at(size_t(positionAccessor(b)));
  if (keepBase) {
    const tinygltf::BufferView& view = m.bufferViews.at(size_t(acc.bufferView));
    for (const uint32_t i : indices) {
      const float far[3] = {50.0f, -70.0f, 90.0f};
      std::memcpy(m.buffers[0].data.data() + view.byteOffset + acc.byteOffset + 12 * i, far, 12);
    }
  } else {
    acc.bufferView = -1;
  }
  std::vector<float> values;
  for (const uint32_t i : indices) values.insert(values.end(), kQuad[i], kQuad[i] + 3);
  addSparse(b, positionAccessor(b), indices, indexType, bytesOf(values.data(), values.size() * sizeof(float)),
            lead);
}

void expectQuadVertex(const std::vector<Vec3>& p, size_t i, const char* what) {
  ASSERT_GT(p.size(), i) << what;
  EXPECT_EQ(p[i], Vec3(kQuad[i][0], kQuad[i][1], kQuad[i][2])) << what << ", vertex " << i;
}

TEST(GltfSparse, ValuesReplaceTheirBaseElements) {
  const TempDir dir;
  for (const int indexType : {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT}) {
    for (const size_t lead : {0u, 8u}) {  // the sparse views' byteOffsets
      GltfBuilder b;
      b.addQuad(1.0f, -1);
      makeSparse(b, {1, 2}, indexType, true, lead);
      const std::string path =
          dir.file("sparse" + std::to_string(indexType) + "-" + std::to_string(lead) + ".gltf");
      ASSERT_TRUE(b.write(path));
      const std::vector<Vec3> p = importedPositions(path);
      ASSERT_EQ(p.size(), 4u);
      for (size_t i = 0; i < 4; ++i) expectQuadVertex(p, i, "over a base view");
    }
  }
}

TEST(GltfSparse, WithoutABaseViewTheOtherElementsAreZero) {
  const TempDir dir;
  GltfBuilder b;
  b.addQuad(1.0f, -1);
  makeSparse(b, {0, 1, 3}, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false);
  ASSERT_TRUE(b.write(dir.file("zeros.gltf")));
  const std::vector<Vec3> p = importedPositions(dir.file("zeros.gltf"));
  ASSERT_EQ(p.size(), 4u);
  for (const size_t i : {0u, 1u, 3u}) expectQuadVertex(p, i, "over zeros");
  EXPECT_EQ(p[2], Vec3(0.0f));
}

// The quad's triangles (0, 3, 2) and (0, 2, 1), with the second one's last two indices spoiled to
// (3, 3) in the base view and put back by sparse substitution.
TEST(GltfSparse, IndicesCanBeSparse) {
  const TempDir dir;
  GltfBuilder dense;
  dense.addQuad(1.0f, -1);
  ASSERT_TRUE(dense.write(dir.file("dense.gltf")));
  GltfBuilder b;
  b.addQuad(1.0f, -1);
  tinygltf::Model& m = b.model();
  const int indices = m.meshes.at(0).primitives.at(0).indices;
  const tinygltf::Accessor& acc = m.accessors.at(size_t(indices));
  ASSERT_EQ(acc.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  const uint32_t spoiled[2] = {3, 3}, right[2] = {2, 1};
  std::memcpy(m.buffers[0].data.data() + m.bufferViews.at(size_t(acc.bufferView)).byteOffset + 4 * 4, spoiled,
              8);
  addSparse(b, indices, {4, 5}, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, bytesOf(right, sizeof right));
  ASSERT_TRUE(b.write(dir.file("sparse.gltf")));
  Scene expected, loaded;
  importGltf(dir.file("dense.gltf"), expected);
  importGltf(dir.file("sparse.gltf"), loaded);
  ASSERT_EQ(loaded.meshes.size(), 1u);
  EXPECT_EQ(loaded.meshes[0].mesh->indices, expected.meshes[0].mesh->indices);
}

// Sparse values are elements of the accessor's own type, so normalised integers are normalised.
TEST(GltfSparse, NormalisedValuesAreNormalised) {
  const TempDir dir;
  GltfBuilder b;
  b.addQuad(1.0f, -1);
  const uint8_t base[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  const int view = b.addBufferView(base, sizeof base);
  tinygltf::Accessor uv;
  uv.bufferView = view;
  uv.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  uv.normalized = true;
  uv.type = TINYGLTF_TYPE_VEC2;
  uv.count = 4;
  b.model().accessors.push_back(uv);
  const int accessor = int(b.model().accessors.size()) - 1;
  b.model().meshes.at(0).primitives.at(0).attributes["TEXCOORD_0"] = accessor;
  const uint8_t values[4] = {255, 0, 51, 102};
  addSparse(b, accessor, {1, 3}, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, bytesOf(values, sizeof values));
  ASSERT_TRUE(b.write(dir.file("uv.gltf")));
  Scene scene;
  importGltf(dir.file("uv.gltf"), scene);
  ASSERT_EQ(scene.meshes.size(), 1u);
  const std::vector<Vec2>& uvs = scene.meshes[0].mesh->uvs;
  ASSERT_EQ(uvs.size(), 4u);
  EXPECT_EQ(uvs[0], Vec2(0.0f));
  EXPECT_EQ(uvs[1], Vec2(1.0f, 0.0f));
  EXPECT_EQ(uvs[2], Vec2(0.0f));
  EXPECT_EQ(uvs[3], Vec2(51 / 255.0f, 102 / 255.0f));
}

// Counts are checked before anything is allocated for them, without arithmetic that can wrap:
// 6148914691236517206 VEC3 floats are 2^64 + 8 bytes, which wrapped to 8 and let a sparse index
// write past a two-float array (found in review).
TEST(GltfSparse, CountsThatWouldWrapOrExhaustMemoryAreRefused) {
  const TempDir dir;
  for (const bool withView : {false, true}) {
    GltfBuilder b;
    b.addQuad(1.0f, -1);
    makeSparse(b, {1}, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, withView);
    b.model().accessors.at(size_t(positionAccessor(b))).count = size_t(6148914691236517206ull);
    const std::string path = dir.file(withView ? "wrap-view.gltf" : "wrap-zeros.gltf");
    ASSERT_TRUE(b.write(path));
    Scene scene;
    try {
      importGltf(path, scene);
      ADD_FAILURE() << path << " loaded";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("POSITION"), std::string::npos) << message;
      EXPECT_NE(message.find(withView ? "past the end of the bufferView" : "at most 16777216"),
                std::string::npos)
          << message;
    }
  }
}

// Each malformed sparse accessor is an InputError naming the file and the part of the accessor.
TEST(GltfSparse, MalformedSparseDataIsAnInputErrorNamingIt) {
  struct Case {
    const char* what;
    std::function<void(GltfBuilder&)> spoil;
    const char* expected;  // in the message
  };
  const auto sparseOf = [](GltfBuilder& b) -> decltype(tinygltf::Accessor::sparse)& {
    return b.model().accessors.at(size_t(positionAccessor(b))).sparse;
  };
  const Case cases[] = {
      {"an index past the accessor",
       [&](GltfBuilder& b) {
         const auto& s = sparseOf(b);
         b.model().buffers[0].data[b.model().bufferViews.at(size_t(s.indices.bufferView)).byteOffset + 2] = 4;
       },
       "sparse.indices: index 4"},
      {"indices out of order",
       [&](GltfBuilder& b) {
         const auto& s = sparseOf(b);
         b.model().buffers[0].data[b.model().bufferViews.at(size_t(s.indices.bufferView)).byteOffset + 2] = 0;
       },
       "strictly increase"},
      {"a count above the accessor's", [&](GltfBuilder& b) { sparseOf(b).count = 5; }, "sparse.count"},
      {"a count of zero", [&](GltfBuilder& b) { sparseOf(b).count = 0; }, "sparse.count"},
      {"float indices",
       [&](GltfBuilder& b) { sparseOf(b).indices.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT; },
       "sparse.indices.componentType"},
      {"values past their view", [&](GltfBuilder& b) { sparseOf(b).values.byteOffset = 12; },
       "sparse.values"},
      {"a missing values view", [&](GltfBuilder& b) { sparseOf(b).values.bufferView = 99; }, "sparse.values"},
      {"strided indices",
       [&](GltfBuilder& b) {
         b.model().bufferViews.at(size_t(sparseOf(b).indices.bufferView)).byteStride = 4;
       },
       "byteStride"},
  };
  const TempDir dir;
  for (const Case& c : cases) {
    GltfBuilder b;
    b.addQuad(1.0f, -1);
    makeSparse(b, {1, 2}, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true);
    c.spoil(b);
    const std::string path = dir.file("bad.gltf");
    ASSERT_TRUE(b.write(path)) << c.what;
    Scene scene;
    try {
      importGltf(path, scene);
      ADD_FAILURE() << c.what << ": loaded without an error";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("bad.gltf"), std::string::npos) << c.what << ": " << message;
      EXPECT_NE(message.find("POSITION"), std::string::npos) << c.what << ": " << message;
      EXPECT_NE(message.find(c.expected), std::string::npos) << c.what << ": " << message;
    }
  }
}

}  // namespace
}  // namespace ember

// Instancing (accel/mesh_instance.h): a glTF mesh placed by several nodes is stored once and traced
// as Embree instances, and every hit on a placement equals, within float rounding, the hit on a
// copy of the mesh transformed into the world, which is what the loader makes of a mesh used once.
#include "core/rng.h"
#include "core/sampling.h"
#include "io/scene_loader.h"

#include <gtest/gtest.h>

#include "gltf_builder.h"

#include <glm/gtc/quaternion.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace ember {
namespace {

// Placements with a translation, a rotation, a non-uniform scale and a mirroring scale.
struct Placement {
  std::vector<double> translation, rotation, scale;
};
const std::vector<Placement> kPlacements = {
    {{0, 0, 0}, {}, {}},
    {{2.5, 0, 0}, {0.2588, 0, 0, 0.9659}, {}},
    {{0, 2.5, -1}, {}, {1.5, 0.5, 1}},
    {{-2.5, 0, 0.5}, {0, 0.3827, 0, 0.9239}, {-1, 1, 1}},
    {{0, -2.5, 0}, {0.1, 0.2, 0.3, 0.927}, {0.7, 1.3, -0.9}},
};

// A small UV sphere with tangents at every placement: `shared` places one mesh (and a second mesh
// object over the same accessors with another material, as MetalRoughSpheresNoTextures does);
// otherwise each placement has accessors of its own.
std::string writeSpheres(const std::string& name, bool shared, bool emissive = false, bool alpha = false) {
  test::GltfBuilder b;
  tinygltf::Material red, blue;
  red.pbrMetallicRoughness.baseColorFactor = {0.8, 0.2, 0.1, alpha ? 0.5 : 1.0};
  if (alpha) red.alphaMode = "BLEND";
  if (emissive) red.emissiveFactor = {2.0, 2.0, 2.0};
  blue = red;
  blue.pbrMetallicRoughness.baseColorFactor[2] = 0.9;
  const int materials[2] = {b.addMaterial(red), b.addMaterial(blue)};
  const float c[3] = {0.0f, 0.0f, 0.0f};
  int firstNode = -1;
  for (size_t i = 0; i < kPlacements.size(); ++i) {
    int node;
    if (!shared || i == 0) {
      node = b.addSphere(c, 1.0f, materials[i % 2], 6, 12, /*withTangents=*/true);
      firstNode = i == 0 ? node : firstNode;
    } else {
      tinygltf::Mesh mesh = b.model().meshes[size_t(b.model().nodes[size_t(firstNode)].mesh)];
      mesh.primitives[0].material = materials[i % 2];
      b.model().meshes.push_back(mesh);
      tinygltf::Node n;
      n.mesh = int(b.model().meshes.size()) - 1;
      node = b.addRootNode(n);
    }
    tinygltf::Node& n = b.model().nodes[size_t(node)];
    n.translation = kPlacements[i].translation;
    n.rotation = kPlacements[i].rotation;
    n.scale = kPlacements[i].scale;
  }
  // ctest runs the tests as processes side by side: each writes files of its own.
  const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const std::string path = (std::filesystem::temp_directory_path() / (test + "_" + name)).string();
  EXPECT_TRUE(b.write(path));
  return path;
}

Scene loadBuilt(const std::string& path) {
  Scene scene = loadScene(path);
  scene.build();
  return scene;
}

TEST(Instancing, AMeshPlacedByManyNodesIsStoredOnce) {
  const Scene scene = loadBuilt(writeSpheres("ember_instanced.gltf", true));
  ASSERT_EQ(scene.meshes.size(), kPlacements.size());
  for (const Scene::MeshEntry& entry : scene.meshes) {
    EXPECT_EQ(entry.mesh, scene.meshes.front().mesh);
    EXPECT_TRUE(entry.toWorld.has_value());
  }
  EXPECT_TRUE(scene.accel().hasInstances());
  EXPECT_EQ(scene.triangleCount(), kPlacements.size() * scene.uniqueTriangleCount());

  const Scene copies = loadBuilt(writeSpheres("ember_copies.gltf", false));
  EXPECT_FALSE(copies.accel().hasInstances());
  EXPECT_EQ(copies.triangleCount(), copies.uniqueTriangleCount());
  EXPECT_EQ(copies.triangleCount(), scene.triangleCount());
}

// Rays from all around at points well inside each placement's silhouette (so that the float
// rounding of the two transforms never decides between a hit and a miss): the same triangle,
// point, normals, texture coordinates and tangent, to float precision.
TEST(Instancing, HitsEqualThoseOnTheMeshCopiedIntoTheWorld) {
  const Scene instanced = loadBuilt(writeSpheres("ember_instanced.gltf", true));
  const Scene copies = loadBuilt(writeSpheres("ember_copies.gltf", false));
  Rng rng(7, 3);
  size_t hits = 0;
  for (const Placement& placement : kPlacements) {
    const Vec3 centre(placement.translation[0], placement.translation[1], placement.translation[2]);
    for (int i = 0; i < 400; ++i) {
      const Vec3 dir = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
      const Vec3 target = centre + 0.3f * sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
      const Ray ray{target - 6.0f * dir, dir};
      SurfaceHit a, b;
      const bool hitA = instanced.intersect(ray, a), hitB = copies.intersect(ray, b);
      ASSERT_EQ(hitA, hitB) << "ray " << i;
      if (!hitA) continue;
      ++hits;
      const float tolerance = 2e-5f * (1.0f + maxAbsComponent(a.p));
      EXPECT_NEAR(a.t, b.t, tolerance);
      EXPECT_LT(glm::length(a.p - b.p), tolerance);
      EXPECT_LE(a.pError, 8.0f * b.pError + 1e-6f) << "an error bound far above the copy's";
      EXPECT_GE(a.pError, 0.5f * b.pError) << "an error bound below the copy's";
      EXPECT_GT(glm::dot(a.ng, b.ng), 0.99999f);
      EXPECT_GT(glm::dot(a.ns, b.ns), 0.99999f);
      EXPECT_LT(glm::length(a.uv - b.uv), 1e-5f);
      const glm::vec4 ta = a.attributes->tangentAt(a.prim, a.bary),
                      tb = b.attributes->tangentAt(b.prim, b.bary);
      ASSERT_NE(ta.w, 0.0f) << "the test needs tangents";
      EXPECT_NEAR(ta.w, tb.w, 1e-5f) << "the bitangent sign follows a mirroring placement";
      EXPECT_LT(glm::length(Vec3(ta) - Vec3(tb)), 1e-4f * (1.0f + glm::length(Vec3(tb))));
      EXPECT_GT(glm::dot(a.attributes->normalAt(a.prim, a.bary), b.attributes->normalAt(b.prim, b.bary)),
                0.99999f);
    }
  }
  EXPECT_GT(hits, kPlacements.size() * 300);
}

// An emissive placement needs a light per world triangle, and an alpha-blended one an opacity
// filter that hashes world rays: both are copied into the world instead.
TEST(Instancing, EmissiveAndAlphaPlacementsAreCopiedIntoTheWorld) {
  const Scene emissive = loadBuilt(writeSpheres("ember_instanced_emissive.gltf", true, true));
  EXPECT_FALSE(emissive.accel().hasInstances());
  // A light per placed triangle, beside the environment (if any).
  EXPECT_EQ(emissive.lights.size() - (emissive.environment() ? 1u : 0u), emissive.triangleCount());
  const Scene alpha = loadBuilt(writeSpheres("ember_instanced_alpha.gltf", true, false, true));
  EXPECT_FALSE(alpha.accel().hasInstances());
  for (const Scene::MeshEntry& entry : alpha.meshes) EXPECT_NE(entry.mesh->opacity, nullptr);
}

}  // namespace
}  // namespace ember

// A renderable scene: what the loaders (io/) fill in, plus what build() derives from it — the
// Embree acceleration structure, one area light per emitting shape and the light sampler.
#pragma once

#include "accel/embree_accel.h"
#include "accel/mesh_instance.h"
#include "core/surface_hit.h"
#include "materials/material.h"
#include "materials/surface_maps.h"
#include "renderer/camera.h"
#include "renderer/caustic_tracer.h"
#include "renderer/light.h"
#include "renderer/light_sampler.h"
#include "renderer/sampler.h"
#include "renderer/strategy.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ember {

struct RenderSettings {
  int width = 256;
  int height = 256;
  int spp = 64;
  int maxDepth = -1;  // longest path in segments; -1 = unbounded (Russian roulette ends paths)
  int rrDepth = 5;    // Russian roulette starts after this many segments
  uint64_t seed = 0;
  SamplerType sampler = SamplerType::Sobol;  // docs/performance.md: lower error at equal time
  Strategy strategy = Strategy::Mis;
  // Caustics (light through mirrors and glass onto diffuse surfaces) by light tracing
  // (renderer/caustic_tracer.h) instead of by the path tracer alone.
  bool traceCaustics = true;
  // Light paths per pixel and sample index. Measured on cornell-area (docs/performance.md): 0.25,
  // 0.5 and 1 leave its error within 2% of each other while the tracer's time doubles with each.
  float causticPathsPerPixel = 0.5f;
};

class Scene {
 public:
  struct ShapeEntry {
    std::string name;
    std::unique_ptr<Shape> shape;
    const Material* material = nullptr;
    Color emission{0.0f};
    bool twoSidedEmission = false;  // emits on both sides, not only on the side of its normal
  };
  struct MeshEntry {
    // Shared where one mesh is placed several times (a glTF mesh used by several nodes).
    std::shared_ptr<TriangleMesh> mesh;
    const Material* material = nullptr;
    Color emission{0.0f};
    std::shared_ptr<const SurfaceMaps> maps;  // normal map, emissive texture; null = none
    bool twoSidedEmission = false;            // glTF doubleSided: both faces emit
    // Unset: the mesh is in world space. Set: the mesh is in its own object space, and this places
    // it (MeshInstance::placeable must hold); build() then traces it as an Embree instance, so
    // entries sharing a mesh share one BVH (an emissive one is baked into world space instead).
    std::optional<Mat4> toWorld;
    // Instances from a glTF file: where the file's nodes place this one, before the transform that
    // places the file (toWorld = transform · inFile), so an edit can place the file anew.
    std::optional<Mat4> inFile;
    Bounds worldBounds() const;
  };

  // --- filled in by a loader --------------------------------------------------------------
  std::string sourcePath;
  // Every file the loaders read (the scene file, glTF files and their buffers and images,
  // textures, environment maps), in reading order: a checkpoint's identity hashes them all.
  std::vector<std::string> sourceFiles;
  RenderSettings settings;
  CameraParams cameraParams;
  Color background{0.0f};  // constant environment radiance; black = none
  // An equirectangular environment map (linear radiance), used instead of `background` when set.
  std::shared_ptr<const ImageTexture> environmentMap;
  float environmentRotateYDeg = 0.0f;
  // Some texture is filtered over the footprint of each hit: surfaceHit then works it out.
  bool filteredTextures = false;
  // Every hit computes its texture coordinates, as the uv AOV needs (renderer/aov.h); otherwise
  // hits on analytic shapes whose material reads none skip them. Set before build().
  bool uvOnEveryHit = false;
  std::vector<std::unique_ptr<Material>> materials;
  std::vector<std::string> materialNames;  // parallel to materials
  // The KHR_materials_variants names of the glTF files loaded (`ember info` lists them).
  std::vector<std::string> materialVariants;
  std::vector<ShapeEntry> shapes;
  std::vector<MeshEntry> meshes;
  std::vector<std::unique_ptr<Light>> lights;  // point lights; build() appends the derived ones

  const Material* addMaterial(std::string name, std::unique_ptr<Material> material);

  // --- derived by build() -------------------------------------------------------------------
  void build();
  bool built() const { return accel_ != nullptr; }
  // The lights a loader put in `lights` (point, spot, directional); build() appends the rest.
  size_t loadedLightCount() const { return accel_ ? loadedLightCount_ : lights.size(); }
  // Edits of a built scene (the Python module's Scene.set_*), each re-deriving only what depends
  // on what changed, with the same result as build() from scratch:
  // - update(), after editing cameraParams, settings, materials or the entries' material pointers,
  //   emissions, `lights`' loaded entries (lights added after build() need build()), background
  //   or environment: the lights, records, light sampler, camera and caustic tracer are derived
  //   again, the BVHs kept. Where an edit changes
  //   what the acceleration structure holds (a shape's ray-mask bit moves when a flat shape starts
  //   or stops emitting, a material starts reading texture coordinates, an instanced mesh starts
  //   emitting and must be baked into world space) it builds everything.
  // - replaceShape(): shape i traced by a new shape; Embree rebuilds only its user geometries' BVH
  //   (all of them, if the new shape's flat/convex kind differs: its mask bit may move).
  // - setMeshTransforms(): mesh entries placed anew ({entry, toWorld}); only the instance level is
  //   rebuilt where every such entry is an instance, everything where one is baked or emissive.
  void update();
  void replaceShape(size_t i, std::unique_ptr<Shape> shape);
  void setMeshTransforms(const std::vector<std::pair<size_t, Mat4>>& placements);
  // Material i replaced: every entry that used it now uses the new one; then update().
  void replaceMaterial(size_t i, std::unique_ptr<Material> material);
  // A number no other build() in this process has had (0: never built): what caches of facts
  // derived from a built scene key on, where a scene's address could be a rebuilt or new one's.
  uint64_t buildSerial() const { return buildSerial_; }

  // `mask`: the Embree ray mask (all bits, or SurfaceHit::maskFor of the surface it leaves).
  bool intersect(const Ray& ray, SurfaceHit& hit, uint32_t mask = kAllRayMask) const;
  // The full record of a hit the accelerator found for `ray` (alone or in a batch).
  void surfaceHit(const Ray& ray, const RawHit& raw, SurfaceHit& hit) const;
  // Geometries in the acceleration structure: every geomID is below this.
  size_t geometryCount() const { return records_.size(); }
  // Prefetch hints for loops that settle many hits (packet/hit_prefetch.h): surfaceHit on a
  // triangle reads its indices, then its vertices, two dependent loads that on a large mesh go to
  // memory. prefetchTriangle starts the first (and the triangle light's pointer), prefetchVertices,
  // some hits later, the second (it reads the indices). Both do nothing for analytic shapes.
  // Worth issuing only when the meshes' indices and vertex attributes are larger than a core's
  // share of the last-level cache (kPrefetchMeshBytes): on the million-triangle scaling scene
  // (28 MB) they saved 3-7% of the render time; on scenes/gltf-mixed.json (250 K triangles)
  // they cost 1% more instructions and gained nothing measurable.
  static constexpr size_t kPrefetchMeshBytes = size_t(16) << 20;
  bool prefetchesMeshHits() const { return meshBytes_ > kPrefetchMeshBytes; }
  void prefetchTriangle(uint32_t geomID, uint32_t primID) const;
  void prefetchVertices(uint32_t geomID, uint32_t primID) const;
  // True when something blocks the ray before ray.tMax (a shadow ray from core/ray_spawn.h).
  // `mask`: the Embree ray mask (all bits, or a surface's SurfaceHit::maskToward and a light's shadowMask).
  bool occluded(const Ray& ray, uint32_t mask = kAllRayMask) const;

  const Camera& camera() const { return camera_; }
  const LightSampler& lightSampler() const { return lightSampler_; }
  const EnvironmentLight* environment() const { return environment_; }
  // The light tracer of the scene's caustics: its casters are the shapes and meshes with a
  // Dirac lobe, its lights the analytic area lights (renderer/caustic_tracer.h).
  const CausticTracer& causticTracer() const { return causticTracer_; }
  Bounds bounds() const { return bounds_; }
  const EmbreeAccel& accel() const { return *accel_; }
  // Rays per packet of the batched kernels (EmbreeAccel::setPacketWidth): --packet-width, tests.
  void setPacketWidth(unsigned width) { accel_->setPacketWidth(width); }
  size_t triangleCount() const;        // placed: what the image shows
  size_t uniqueTriangleCount() const;  // stored: each shared mesh counted once

  // What surfaceHit knows of a geometry (Embree geomID) before it is hit: for loops that settle
  // hits in their own form (packet/wave_integrator.h).
  struct GeometryRecord {
    const Shape* shape = nullptr;
    const TriangleMesh* mesh = nullptr;
    const Material* material = nullptr;
    const Light* light = nullptr;
    Color emission{0.0f};
    bool twoSidedEmission = false;
    const SurfaceMaps* maps = nullptr;
    const MeshInstance* instance = nullptr;  // where the mesh is placed as an instance
    int64_t firstTriangleLight = -1;  // emissive meshes: index of primitive 0's light in triangleLights_
    bool readsUv = true;              // whether the material reads the hit's texture coordinates
    float uvDensity = 0.0f;           // shapes: Shape::uvDensity
    bool deltaLobes = false;          // the material's Material::hasDeltaLobes, asked once
    uint32_t maskFront = kAllRayMask, maskBack = kAllRayMask;  // SurfaceHit's of its hits
  };
  const GeometryRecord& record(uint32_t geomID) const { return records_[geomID]; }

 private:
  std::vector<CausticCaster> findCausticCasters() const;
  // What the acceleration structure holds beyond the geometry itself, from the entries: when it
  // differs from the last build's, update() builds everything.
  struct GeometryKey {
    std::vector<uint32_t> ownBits;  // each shape's own ray-mask bit, 0 = none
    std::vector<bool> readsUv;      // each shape's
    std::vector<bool> baked;        // each mesh entry's: an instance traced as a world-space copy
    bool operator==(const GeometryKey&) const = default;
  };
  GeometryKey geometryKey() const;
  void buildGeometry();
  void deriveShading();

  std::unique_ptr<EmbreeAccel> accel_;
  GeometryKey builtKey_;
  struct EnvironmentKey {
    std::shared_ptr<const ImageTexture> map;
    float rotateYDeg = 0.0f;
    Color background{0.0f};
  } builtEnvironment_;                                // what the environment light was made from
  std::vector<uint32_t> shapeGeomIDs_, meshGeomIDs_;  // per entry; meshes without triangles: ~0u
  std::vector<const Light*> triangleLights_;
  size_t loadedLightCount_ = 0;
  std::vector<GeometryRecord> records_;  // indexed by Embree geomID
  std::vector<std::unique_ptr<MeshInstance>> instances_;
  std::vector<std::unique_ptr<TriangleMesh>> bakedMeshes_;  // emissive instances, in world space
  Camera camera_;
  LightSampler lightSampler_;
  const EnvironmentLight* environment_ = nullptr;
  CausticTracer causticTracer_;
  Bounds bounds_;
  size_t meshBytes_ = 0;  // the meshes' indices and vertex attributes
  uint64_t buildSerial_ = 0;
};

}  // namespace ember

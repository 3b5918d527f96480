#include "renderer/scene.h"

#include "accel/sphere.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

namespace ember {

namespace {

// A sphere around bounds: the box's centre and half its diagonal.
CausticCaster boundingSphere(const Bounds& b) {
  return {0.5f * (b.lower + b.upper), 0.5f * glm::length(b.upper - b.lower)};
}

}  // namespace

std::vector<CausticCaster> Scene::findCausticCasters() const {
  // Every surface with a Dirac lobe must be a caster: the light tracer owns the paths whose first
  // bounce from the light is on one, and aims only at casters.
  std::vector<CausticCaster> casters;
  for (const ShapeEntry& entry : shapes) {
    if (!entry.material || !entry.material->hasDeltaLobes()) continue;
    if (const auto* sphere = dynamic_cast<const Sphere*>(entry.shape.get()))
      casters.push_back({sphere->center(), sphere->radius()});
    else
      casters.push_back(boundingSphere(entry.shape->bounds()));
  }
  for (const MeshEntry& entry : meshes)
    if (!entry.mesh->indices.empty() && entry.material && entry.material->hasDeltaLobes())
      casters.push_back(boundingSphere(entry.worldBounds()));
  return casters;
}

const Material* Scene::addMaterial(std::string name, std::unique_ptr<Material> material) {
  materials.push_back(std::move(material));
  materialNames.push_back(std::move(name));
  return materials.back().get();
}

Scene::GeometryKey Scene::geometryKey() const {
  // Embree has 32 mask bits: each goes to one flat shape or convex solid's boundary (Shape::flat,
  // Shape::convexSide), flat emitters first (their shadow rays skip them too), and any such
  // shapes past the 32nd are tested as before.
  GeometryKey key;
  key.ownBits.assign(shapes.size(), 0u);
  unsigned maskBits = 0;
  for (const bool flatEmitters : {true, false})
    for (size_t i = 0; i < shapes.size(); ++i) {
      const Shape& s = *shapes[i].shape;
      const bool flatEmitter = s.flat() && !isBlack(shapes[i].emission);
      if (maskBits < 32 && flatEmitter == flatEmitters && (s.flat() || s.convexSide() != 0))
        key.ownBits[i] = 1u << maskBits++;
    }
  // Analytic shapes have no surface maps and AreaLight's radiance is uniform, so the material
  // is the only reader of their UV (were emission textures added, they would read it too).
  for (const ShapeEntry& entry : shapes)
    key.readsUv.push_back(uvOnEveryHit || !entry.material || entry.material->readsUv());
  for (const MeshEntry& entry : meshes) key.baked.push_back(entry.toWorld && !isBlack(entry.emission));
  return key;
}

void Scene::build() {
  // Building again (after editing the scene) first drops the lights the last build derived.
  if (accel_) lights.resize(loadedLightCount_);
  loadedLightCount_ = lights.size();
  buildGeometry();
  deriveShading();
}

void Scene::buildGeometry() {
  accel_ = std::make_unique<EmbreeAccel>();
  builtKey_ = geometryKey();
  records_.clear();
  instances_.clear();
  bakedMeshes_.clear();
  meshBytes_ = 0;
  shapeGeomIDs_.assign(shapes.size(), ~0u);
  meshGeomIDs_.assign(meshes.size(), ~0u);
  for (size_t i = 0; i < shapes.size(); ++i) {
    ShapeEntry& entry = shapes[i];
    const uint32_t ownBit = builtKey_.ownBits[i];
    const uint32_t id =
        accel_->addShape(entry.shape.get(), builtKey_.readsUv[i], ownBit ? ownBit : kAllRayMask);
    GeometryRecord rec;
    rec.shape = entry.shape.get();
    rec.readsUv = builtKey_.readsUv[i];
    rec.uvDensity = entry.shape->uvDensity();
    const bool flat = entry.shape->flat();
    const int convex = entry.shape->convexSide();
    rec.maskFront = flat || convex > 0 ? ~ownBit : kAllRayMask;
    rec.maskBack = flat || convex < 0 ? ~ownBit : kAllRayMask;
    if (records_.size() <= id) records_.resize(id + 1);
    records_[id] = rec;
    shapeGeomIDs_[i] = id;
  }
  std::unordered_map<const TriangleMesh*, uint32_t> prototypes;  // shared mesh -> its BVH
  for (size_t j = 0; j < meshes.size(); ++j) {
    MeshEntry& entry = meshes[j];
    if (entry.mesh->indices.empty()) continue;
    if (entry.maps && entry.maps->normalMap && entry.mesh->tangents.empty()) entry.mesh->generateTangents();
    // The mesh as traced: the entry's own, or, for an emissive instance, whose every world triangle
    // is a light, a world-space copy.
    const TriangleMesh* mesh = entry.mesh.get();
    const MeshInstance* instance = nullptr;
    bool newData = true;  // whether this mesh's bytes are not counted yet
    uint32_t id;
    if (builtKey_.baked[j]) {
      bakedMeshes_.push_back(MeshInstance(mesh, *entry.toWorld).baked());
      mesh = bakedMeshes_.back().get();
      id = accel_->addMesh(mesh);
    } else if (entry.toWorld) {
      const auto [it, first] = prototypes.try_emplace(mesh, 0u);
      if (first) it->second = accel_->addPrototype(mesh);
      instances_.push_back(std::make_unique<MeshInstance>(mesh, *entry.toWorld));
      instance = instances_.back().get();
      id = accel_->addInstance(it->second, *entry.toWorld);
      newData = first;
    } else {
      id = accel_->addMesh(mesh);
    }
    if (records_.size() <= id) records_.resize(id + 1);
    GeometryRecord rec;
    rec.mesh = mesh;
    rec.instance = instance;
    records_[id] = rec;
    meshGeomIDs_[j] = id;
    if (!newData) continue;
    const TriangleMesh& m = *mesh;
    meshBytes_ += m.indices.size() * sizeof(m.indices[0]) + m.positions.size() * sizeof(m.positions[0]) +
                  m.normals.size() * sizeof(m.normals[0]) + m.uvs.size() * sizeof(m.uvs[0]) +
                  m.tangents.size() * sizeof(m.tangents[0]);
  }
  accel_->commit();
  bounds_ = accel_->bounds();
  if (bounds_.empty()) {
    bounds_.extend(Vec3(-1.0f));
    bounds_.extend(Vec3(1.0f));
  }
}

void Scene::deriveShading() {
  // The environment light tabulates its map for sampling (milliseconds per megapixel): kept while
  // what it was made from is unchanged. deriveShading adds it last.
  std::unique_ptr<Light> environment;
  if (environment_ && lights.size() > loadedLightCount_ && lights.back().get() == environment_ &&
      builtEnvironment_.map == environmentMap && builtEnvironment_.rotateYDeg == environmentRotateYDeg &&
      builtEnvironment_.background == background) {
    environment = std::move(lights.back());
    lights.pop_back();
  }
  builtEnvironment_ = {environmentMap, environmentRotateYDeg, background};
  lights.resize(loadedLightCount_);
  environment_ = nullptr;
  static std::atomic<uint64_t> builds{0};
  buildSerial_ = ++builds;
  triangleLights_.clear();
  std::vector<Light*> allLights;
  for (auto& light : lights) allLights.push_back(light.get());
  for (size_t i = 0; i < shapes.size(); ++i) {
    const ShapeEntry& entry = shapes[i];
    GeometryRecord& rec = records_[shapeGeomIDs_[i]];
    rec.material = entry.material;
    rec.emission = entry.emission;
    rec.twoSidedEmission = entry.twoSidedEmission;
    rec.deltaLobes = entry.material && entry.material->hasDeltaLobes();
    rec.light = nullptr;
    if (isBlack(entry.emission)) continue;
    lights.push_back(std::make_unique<AreaLight>(entry.shape.get(), entry.emission, entry.twoSidedEmission));
    // Shadow rays skip flat emitters only: one aimed at a curved emitter's far side, sampled by
    // area from close by, must still be blocked by its near side.
    const uint32_t ownBit = builtKey_.ownBits[i];
    lights.back()->shadowMask = entry.shape->flat() && ownBit ? ~ownBit : kAllRayMask;
    allLights.push_back(lights.back().get());
    rec.light = lights.back().get();
  }
  for (size_t j = 0; j < meshes.size(); ++j) {
    if (meshGeomIDs_[j] == ~0u) continue;
    const MeshEntry& entry = meshes[j];
    GeometryRecord& rec = records_[meshGeomIDs_[j]];
    rec.material = entry.material;
    rec.emission = entry.emission;
    rec.twoSidedEmission = entry.twoSidedEmission;
    rec.maps = entry.maps.get();
    rec.deltaLobes = entry.material && entry.material->hasDeltaLobes();
    rec.firstTriangleLight = -1;
    if (isBlack(entry.emission)) continue;
    // Every triangle of an emissive mesh is a light of its own, chosen by power like the rest.
    rec.firstTriangleLight = int64_t(triangleLights_.size());
    for (uint32_t prim = 0; prim < rec.mesh->indices.size(); ++prim) {
      lights.push_back(std::make_unique<TriangleLight>(rec.mesh, prim, entry.emission,
                                                       entry.maps ? entry.maps->emission.get() : nullptr,
                                                       entry.twoSidedEmission));
      allLights.push_back(lights.back().get());
      triangleLights_.push_back(lights.back().get());
    }
  }

  if (environmentMap || !isBlack(background)) {
    if (environment)
      lights.push_back(std::move(environment));
    else if (environmentMap)
      lights.push_back(std::make_unique<EnvironmentLight>(environmentMap, environmentRotateYDeg));
    else
      lights.push_back(std::make_unique<EnvironmentLight>(background));
    environment_ = static_cast<const EnvironmentLight*>(lights.back().get());
    allLights.push_back(lights.back().get());
  }
  const float radius = 0.5f * glm::length(bounds_.upper - bounds_.lower);
  lightSampler_ = LightSampler(allLights, radius);
  camera_ = Camera(cameraParams, settings.width, settings.height);

  std::vector<CausticCaster> casters = findCausticCasters();
  // A caster without finite bounds (a NaN vertex) cannot be aimed at: then none is traced.
  const bool finite = std::all_of(casters.begin(), casters.end(), [](const CausticCaster& c) {
    return std::isfinite(c.radius) && std::isfinite(c.center.x) && std::isfinite(c.center.y) &&
           std::isfinite(c.center.z);
  });
  // Every light a path can start from (Light::sampleEmission): area lights, emissive triangles,
  // point and spot lights.
  std::vector<const Light*> emitters;
  for (const auto& light : lights) {
    EmissionPoint probe;
    light->causticTraced = false;
    if (light->sampleEmission(Vec2(0.5f), probe)) emitters.push_back(light.get());
  }
  causticTracer_ = CausticTracer(finite ? std::move(casters) : std::vector<CausticCaster>{}, emitters,
                                 camera_.perspective(), settings.causticPathsPerPixel);
  if (causticTracer_.enabled())
    for (const Light* light : emitters) const_cast<Light*>(light)->causticTraced = true;
}

void Scene::update() {
  if (!accel_ || geometryKey() != builtKey_ || meshes.size() != meshGeomIDs_.size() ||
      shapes.size() != shapeGeomIDs_.size()) {
    build();
    return;
  }
  deriveShading();
}

void Scene::replaceShape(size_t i, std::unique_ptr<Shape> shape) {
  const bool sameKind =
      shape->flat() == shapes.at(i).shape->flat() && shape->convexSide() == shapes[i].shape->convexSide();
  shapes[i].shape = std::move(shape);
  if (!accel_) return;
  if (!sameKind) {
    build();
    return;
  }
  GeometryRecord& rec = records_[shapeGeomIDs_[i]];
  rec.shape = shapes[i].shape.get();
  rec.uvDensity = rec.shape->uvDensity();
  accel_->replaceShape(shapeGeomIDs_[i], rec.shape);
  accel_->commit();
  bounds_ = accel_->bounds();
  update();
}

void Scene::setMeshTransforms(const std::vector<std::pair<size_t, Mat4>>& placements) {
  bool instancesOnly = accel_ != nullptr;
  for (const auto& [i, toWorld] : placements) {
    MeshEntry& entry = meshes.at(i);
    instancesOnly = instancesOnly && i < meshGeomIDs_.size() && entry.toWorld && !builtKey_.baked[i] &&
                    meshGeomIDs_[i] != ~0u;
    entry.toWorld = toWorld;
  }
  if (!accel_) return;
  if (!instancesOnly) {
    build();
    return;
  }
  for (const auto& [i, toWorld] : placements) {
    // The record keeps its instance's address: the instance is placed anew where it is.
    *const_cast<MeshInstance*>(records_[meshGeomIDs_[i]].instance) =
        MeshInstance(meshes[i].mesh.get(), toWorld);
    accel_->setInstanceTransform(meshGeomIDs_[i], toWorld);
  }
  accel_->commit();
  bounds_ = accel_->bounds();
  deriveShading();
}

void Scene::replaceMaterial(size_t i, std::unique_ptr<Material> material) {
  const Material* old = materials.at(i).get();
  for (ShapeEntry& entry : shapes)
    if (entry.material == old) entry.material = material.get();
  for (MeshEntry& entry : meshes)
    if (entry.material == old) entry.material = material.get();
  materials[i] = std::move(material);
  if (accel_) update();
}

bool Scene::intersect(const Ray& ray, SurfaceHit& hit, uint32_t mask) const {
  RawHit raw;
  if (!accel_->intersect(ray, raw, mask)) return false;
  surfaceHit(ray, raw, hit);
  return true;
}

void Scene::surfaceHit(const Ray& ray, const RawHit& raw, SurfaceHit& hit) const {
  const GeometryRecord& rec = records_[raw.geomID];
  hit.t = raw.t;
  hit.p = ray.origin + raw.t * ray.dir;
  // The rounding error of o + t d grows with t, and with it the offset of every ray leaving the
  // hit (core/ray_spawn.h). So a triangle's hit point is interpolated from its vertices, and a
  // shape's hit found from farther away than its own coordinates' magnitude is projected onto
  // the shape: either way the error then depends on the scene's coordinates, not on how far the
  // ray came. (Nearer hits keep o + t d, whose bound is then at most twice the projected one; the
  // projection costs ~5% of a render.)
  if (rec.shape) {
    hit.ng = raw.ng;
    const LocalHit local{raw.t, raw.ng, raw.uv};
    hit.uv = rec.readsUv ? rec.shape->surfaceUv(local) : Vec2(0.0f);
    const float magnitude = maxAbsComponent(hit.p);
    if (raw.t > magnitude) {
      const SurfacePoint onSurface = rec.shape->projectToSurface(hit.p, local);
      hit.p = onSurface.p;
      hit.pError = onSurface.error;
    } else {
      hit.pError = roundingErrorBound(magnitude + raw.t);
    }
    hit.ns = raw.ng;  // every analytic shape is shaded with its geometric normal
    hit.attributes = nullptr;
  } else {
    const MeshInstance* instance = rec.instance;
    hit.p = instance ? instance->pointAt(raw.primID, raw.uv.x, raw.uv.y)
                     : rec.mesh->pointAt(raw.primID, raw.uv.x, raw.uv.y);
    hit.pError = instance ? instance->pointError(raw.primID) : rec.mesh->pointError(raw.primID);
    const TriangleMesh::Surface s = instance ? instance->surfaceAt(raw.primID, raw.uv.x, raw.uv.y)
                                             : rec.mesh->surfaceAt(raw.primID, raw.uv.x, raw.uv.y);
    hit.ng = s.ng;
    hit.uv = s.uv;
    hit.attributes = instance ? static_cast<const VertexAttributes*>(instance) : rec.mesh;
    hit.prim = raw.primID;
    hit.bary = raw.uv;
    Vec3 ns = s.ns;
    if (rec.maps && rec.maps->normalMap)
      ns = rec.maps->perturb(s.ns, s.tangent, hit.texCoord(rec.maps->normalMap->texCoordSet()));
    // Keep the shading normal in the geometric normal's hemisphere.
    hit.ns = glm::dot(ns, s.ng) < 0.0f ? -ns : ns;
  }
  hit.uvFootprint = 0.0f;
  if (filteredTextures) {
    const float density = rec.shape ? rec.uvDensity : hit.attributes->uvDensity(raw.primID);
    hit.uvFootprint = camera_.footprintAt(hit.p, hit.ng) * density;
  }
  hit.material = rec.material;
  hit.light =
      rec.firstTriangleLight >= 0 ? triangleLights_[size_t(rec.firstTriangleLight) + raw.primID] : rec.light;
  hit.emission = rec.emission;
  hit.twoSidedEmission = rec.twoSidedEmission;
  hit.maskFront = rec.maskFront;
  hit.maskBack = rec.maskBack;
  if (rec.maps && rec.maps->emission && !isBlack(rec.emission))
    hit.emission *= rec.maps->emission->evalFresh(hit);
}

void Scene::prefetchTriangle(uint32_t geomID, uint32_t primID) const {
  const GeometryRecord& rec = records_[geomID];
  if (!rec.mesh) return;
  __builtin_prefetch(&rec.mesh->indices[primID]);
  if (rec.firstTriangleLight >= 0)
    __builtin_prefetch(&triangleLights_[size_t(rec.firstTriangleLight) + primID]);
}

void Scene::prefetchVertices(uint32_t geomID, uint32_t primID) const {
  const TriangleMesh* mesh = records_[geomID].mesh;
  if (!mesh) return;
  const glm::uvec3& idx = mesh->indices[primID];
  // What surfaceHit reads of each vertex (TriangleMesh::pointAt, pointError and surfaceAt).
  for (const uint32_t v : {idx.x, idx.y, idx.z}) {
    __builtin_prefetch(&mesh->positions[v]);
    if (!mesh->normals.empty()) __builtin_prefetch(&mesh->normals[v]);
    if (!mesh->uvs.empty()) __builtin_prefetch(&mesh->uvs[v]);
    if (!mesh->tangents.empty()) __builtin_prefetch(&mesh->tangents[v]);
  }
}

bool Scene::occluded(const Ray& ray, uint32_t mask) const {
  return accel_->occluded(ray, 0.0f, mask);
}

size_t Scene::triangleCount() const {
  size_t n = 0;
  for (const MeshEntry& m : meshes) n += m.mesh->indices.size();
  return n;
}

size_t Scene::uniqueTriangleCount() const {
  std::unordered_set<const TriangleMesh*> seen;
  size_t n = 0;
  for (const MeshEntry& m : meshes)
    if (seen.insert(m.mesh.get()).second) n += m.mesh->indices.size();
  return n;
}

Bounds Scene::MeshEntry::worldBounds() const {
  return toWorld ? MeshInstance(mesh.get(), *toWorld).bounds() : mesh->bounds();
}

}  // namespace ember

// Writes small glTF 2.0 files for tests with tinygltf's own writer: quads and UV spheres with
// normals, UVs and optional tangents, materials, PNG textures embedded as data URIs, cameras.
#pragma once

#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace ember::test {

class GltfBuilder {
 public:
  GltfBuilder() {
    model_.asset.version = "2.0";
    model_.buffers.emplace_back();
    model_.scenes.emplace_back();
    model_.defaultScene = 0;
  }

  tinygltf::Model& model() { return model_; }

  int addMaterial(const tinygltf::Material& material) {
    model_.materials.push_back(material);
    return int(model_.materials.size()) - 1;
  }

  // An 8-bit image (row 0 = top) as an embedded PNG texture; returns the texture index.
  int addTexture(int width, int height, int components, const std::vector<unsigned char>& pixels,
                 int wrapS = TINYGLTF_TEXTURE_WRAP_REPEAT, int wrapT = TINYGLTF_TEXTURE_WRAP_REPEAT,
                 int magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR) {
    tinygltf::Image image;
    image.width = width;
    image.height = height;
    image.component = components;
    image.bits = 8;
    image.pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image.image = pixels;
    image.mimeType = "image/png";
    model_.images.push_back(image);
    tinygltf::Sampler sampler;
    sampler.wrapS = wrapS;
    sampler.wrapT = wrapT;
    sampler.magFilter = magFilter;
    model_.samplers.push_back(sampler);
    tinygltf::Texture texture;
    texture.source = int(model_.images.size()) - 1;
    texture.sampler = int(model_.samplers.size()) - 1;
    model_.textures.push_back(texture);
    return int(model_.textures.size()) - 1;
  }

  struct Vertex {
    float p[3];
    float n[3];
    float uv[2];
    float t[4];
  };

  // One mesh of triangles on its own root node; returns the node index.
  int addMesh(const std::vector<Vertex>& vertices, const std::vector<uint32_t>& indices, int material,
              bool withTangents = false) {
    std::vector<float> pos, nrm, uv, tan;
    std::vector<double> lo(3, 1e30), hi(3, -1e30);
    for (const Vertex& v : vertices) {
      for (int i = 0; i < 3; ++i) {
        pos.push_back(v.p[i]);
        nrm.push_back(v.n[i]);
        lo[size_t(i)] = std::min(lo[size_t(i)], double(v.p[i]));
        hi[size_t(i)] = std::max(hi[size_t(i)], double(v.p[i]));
      }
      uv.insert(uv.end(), v.uv, v.uv + 2);
      tan.insert(tan.end(), v.t, v.t + 4);
    }
    tinygltf::Primitive prim;
    prim.attributes["POSITION"] = addAccessor(pos.data(), pos.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                              TINYGLTF_TYPE_VEC3, vertices.size());
    model_.accessors.back().minValues = lo;
    model_.accessors.back().maxValues = hi;
    prim.attributes["NORMAL"] = addAccessor(nrm.data(), nrm.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                            TINYGLTF_TYPE_VEC3, vertices.size());
    prim.attributes["TEXCOORD_0"] = addAccessor(uv.data(), uv.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                TINYGLTF_TYPE_VEC2, vertices.size());
    if (withTangents)
      prim.attributes["TANGENT"] = addAccessor(tan.data(), tan.size() * 4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                               TINYGLTF_TYPE_VEC4, vertices.size());
    prim.indices = addAccessor(indices.data(), indices.size() * 4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                               TINYGLTF_TYPE_SCALAR, indices.size());
    prim.material = material;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh mesh;
    mesh.primitives.push_back(prim);
    model_.meshes.push_back(mesh);
    tinygltf::Node node;
    node.mesh = int(model_.meshes.size()) - 1;
    return addRootNode(node);
  }

  // The square [-h, h]^2 in the plane z = 0 facing +z, uv (0, 0) at the top-left (-h, +h) corner
  // and (uvMax, uvMax) at the bottom-right; tangent +x (the +u direction), w = 1.
  int addQuad(float h, int material, float uvMax = 1.0f, bool withTangents = false) {
    const std::vector<Vertex> v = {{{-h, h, 0}, {0, 0, 1}, {0, 0}, {1, 0, 0, 1}},
                                   {{h, h, 0}, {0, 0, 1}, {uvMax, 0}, {1, 0, 0, 1}},
                                   {{h, -h, 0}, {0, 0, 1}, {uvMax, uvMax}, {1, 0, 0, 1}},
                                   {{-h, -h, 0}, {0, 0, 1}, {0, uvMax}, {1, 0, 0, 1}}};
    return addMesh(v, {0, 3, 2, 0, 2, 1}, material, withTangents);
  }

  // A UV sphere of `rings` x `segments` quads split into triangles, centred at c.
  int addSphere(const float c[3], float radius, int material, int rings = 96, int segments = 192,
                bool withTangents = false) {
    std::vector<Vertex> v;
    std::vector<uint32_t> idx;
    for (int i = 0; i <= rings; ++i)
      for (int j = 0; j <= segments; ++j) {
        const float theta = float(M_PI) * float(i) / float(rings),
                    phi = 2.0f * float(M_PI) * float(j) / float(segments);
        const float n[3] = {std::sin(theta) * std::cos(phi), std::cos(theta),
                            -std::sin(theta) * std::sin(phi)};
        Vertex vert{{c[0] + radius * n[0], c[1] + radius * n[1], c[2] + radius * n[2]},
                    {n[0], n[1], n[2]},
                    {float(j) / float(segments), float(i) / float(rings)},
                    {-std::sin(phi), 0.0f, -std::cos(phi), 1.0f}};  // along +u: d(position)/d(phi)
        v.push_back(vert);
      }
    for (int i = 0; i < rings; ++i)
      for (int j = 0; j < segments; ++j) {
        const uint32_t a = uint32_t(i * (segments + 1) + j), b = a + uint32_t(segments + 1);
        idx.insert(idx.end(), {a, b, a + 1, a + 1, b, b + 1});
      }
    return addMesh(v, idx, material, withTangents);
  }

  int addCamera(const tinygltf::Camera& camera, const std::vector<double>& translation) {
    model_.cameras.push_back(camera);
    tinygltf::Node node;
    node.camera = int(model_.cameras.size()) - 1;
    node.translation = translation;
    return addRootNode(node);
  }

  int addRootNode(const tinygltf::Node& node) {
    model_.nodes.push_back(node);
    model_.scenes[0].nodes.push_back(int(model_.nodes.size()) - 1);
    return int(model_.nodes.size()) - 1;
  }

  // Appends `bytes` to the buffer (4-byte aligned) as a buffer view of their own; returns its index.
  int addBufferView(const void* data, size_t bytes) {
    tinygltf::Buffer& buffer = model_.buffers[0];
    while (buffer.data.size() % 4) buffer.data.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.data.size();
    view.byteLength = bytes;
    buffer.data.resize(buffer.data.size() + bytes);
    std::memcpy(buffer.data.data() + view.byteOffset, data, bytes);
    model_.bufferViews.push_back(view);
    return int(model_.bufferViews.size()) - 1;
  }

  bool write(const std::string& path) {
    tinygltf::TinyGLTF writer;
    return writer.WriteGltfSceneToFile(&model_, path, /*embedImages=*/true, /*embedBuffers=*/true,
                                       /*prettyPrint=*/true, /*writeBinary=*/false);
  }

 private:
  int addAccessor(const void* data, size_t bytes, int componentType, int type, size_t count) {
    tinygltf::Accessor accessor;
    accessor.bufferView = addBufferView(data, bytes);
    accessor.componentType = componentType;
    accessor.type = type;
    accessor.count = count;
    model_.accessors.push_back(accessor);
    return int(model_.accessors.size()) - 1;
  }

  tinygltf::Model model_;
};

}  // namespace ember::test

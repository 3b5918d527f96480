// Compressed glTF data, decoded into plain glTF before the loader reads it (docs/gltf.md):
// EXT_meshopt_compression buffer views (meshoptimizer), KHR_draco_mesh_compression primitives
// (Draco), EXT_texture_webp images (libwebp), and KHR_texture_basisu, which has no decoder in
// Debian and falls back to the texture's own source. Specifications: KhronosGroup/glTF,
// extensions/2.0/Vendor/EXT_meshopt_compression, extensions/2.0/Khronos/KHR_draco_mesh_compression,
// extensions/2.0/Vendor/EXT_texture_webp and extensions/2.0/Khronos/KHR_texture_basisu.
#pragma once

#include <tiny_gltf.h>

#include <optional>
#include <string>

namespace ember {

// Rewrites `model` so that the rest of the loader reads plain data: every meshopt-compressed buffer
// view is decoded into a new buffer and points at it; every Draco primitive gets new accessors
// (float attributes, uint32 indices, mode TRIANGLES) in one more buffer; a texture with a decoded
// EXT_texture_webp image uses it as its `source`. Every offset, length and count is checked
// against the buffers first. Throws InputError("path: glTF.path: what") for bad or undecodable
// data, and for a KHR_texture_basisu texture that has no usable fallback.
void decodeCompressedData(tinygltf::Model& model, const std::string& path);

// tinygltf's image loader (TinyGLTF::SetImageLoader) with WebP added: WebP images are decoded with
// libwebp to 8-bit RGBA, like tinygltf's own loader gives PNGs; KTX2 images are left empty for
// decodeCompressedData to judge; everything else is kept encoded (Image::as_is) for
// decodeDeferredImages. Its user data must be the tinygltf::Model being loaded: tinygltf hands a
// buffer view's image bytes over without checking that the view lies inside its buffer, and the
// loader does.
tinygltf::LoadImageDataFunction gltfImageLoader();

// Decodes the images gltfImageLoader kept encoded, in parallel, with tinygltf::LoadImageData as
// tinygltf's parse would have; the first that fails throws InputError("path: cannot load glTF: ...").
void decodeDeferredImages(tinygltf::Model& model, const std::string& path);

// tinygltf 2.7 refuses two things these extensions write: a Draco primitive's `indices` accessor
// without a bufferView ("accessor[N] invalid bufferView"), and a meshopt fallback buffer without a
// uri. Returns the file at `path` (a .gltf's JSON, or a whole .glb) with those primitives' `indices`
// dropped (the Draco data brings its own) and those buffers made one-byte data URIs, for
// TinyGLTF::LoadASCIIFromString / LoadBinaryFromMemory; nullopt when the file has neither.
std::optional<std::string> patchCompressedGltf(const std::string& path);

}  // namespace ember

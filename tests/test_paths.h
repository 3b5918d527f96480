// Locations the tests read from: the repository's own data, and the optional shared assets.
#pragma once

#include <filesystem>
#include <string>

namespace ember::test {

inline std::string sourcePath(const std::string& relative) {
  return std::string(EMBER_SOURCE_DIR) + "/" + relative;
}

// The Khronos glTF sample models sit in ../shared/assets/gltf beside a developer's checkout; they
// are not part of the repository, so tests that need them skip when they are absent.
inline std::string sharedGltfDir() {
  if (const char* env = std::getenv("EMBER_SHARED_GLTF")) return env;
  return std::filesystem::weakly_canonical(sourcePath("../shared/assets/gltf")).string();
}

// Debian's assimp-testmodels package: valid and deliberately broken glTF files.
inline std::string assimpGltfDir() {
  return "/usr/share/assimp/models/glTF2";
}

}  // namespace ember::test

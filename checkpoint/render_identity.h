// What makes two renders the same render: the content of every file the scene was loaded from,
// and every setting that decides which samples are drawn and how they are estimated. A checkpoint
// stores it and a resumed render must match it; every EXR carries its hash so that `ember merge`
// combines only sample ranges of one render.
#pragma once

#include "renderer/scene.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace ember {

struct RenderIdentity {
  struct File {
    std::string path;
    uint64_t hash = 0;  // XXH3-64 of the file's bytes
  };
  std::string scene;        // the scene file as given on the command line
  std::vector<File> files;  // Scene::sourceFiles, in reading order
  int width = 0, height = 0, maxDepth = 0, rrDepth = 0;
  uint64_t seed = 0;
  std::string sampler, strategy;
  std::string caustics = "trace";  // "trace": light-traced caustics (renderer/caustic_tracer.h), "path": not
  int camera = -1;                 // --camera
  std::string env;                 // --env, verbatim (its file, if any, is among `files`)
  std::string variant;             // --variant (KHR_materials_variants); empty: the default materials
  std::string textureFilter;       // --texture-filter trilinear; empty: the glTF samplers' own

  // XXH3-64 over the files' hashes and every setting above: equal iff the renders are the same.
  uint64_t hash() const;
  nlohmann::json toJson() const;
  // Throws InputError naming `origin` for a malformed object.
  static RenderIdentity fromJson(const nlohmann::json& j, const std::string& origin);
  // The first way `now` differs from this one, in words, or "" if they are the same render.
  std::string differenceFrom(const RenderIdentity& now) const;
};

// XXH3-64 of a file's bytes; InputError if it cannot be read.
uint64_t hashFile(const std::string& path);

// The identity of a loaded scene rendered with its settings (and --camera / --env as given).
RenderIdentity identityOf(const Scene& scene, const std::string& sceneArg, int camera,
                          const std::string& variant, const std::string& env);

// A 16-digit hexadecimal rendering of a hash, as written to EXR metadata.
std::string hexHash(uint64_t h);

}  // namespace ember

#include "checkpoint/render_identity.h"

#include "io/input_error.h"

#include <xxhash.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

namespace ember {

namespace {

struct StateDeleter {
  void operator()(XXH3_state_t* s) const { XXH3_freeState(s); }
};

void feed(XXH3_state_t* s, const std::string& text) {
  const uint64_t n = text.size();
  XXH3_64bits_update(s, &n, sizeof n);  // length-prefixed: "ab" + "c" never equals "a" + "bc"
  XXH3_64bits_update(s, text.data(), text.size());
}

template <typename T>
void feedValue(XXH3_state_t* s, T v) {
  XXH3_64bits_update(s, &v, sizeof v);
}

}  // namespace

uint64_t hashFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read");
  std::unique_ptr<XXH3_state_t, StateDeleter> state(XXH3_createState());
  XXH3_64bits_reset(state.get());
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    XXH3_64bits_update(state.get(), buffer.data(), size_t(in.gcount()));
  }
  if (in.bad()) throw InputError(path + ": read error");
  return XXH3_64bits_digest(state.get());
}

uint64_t RenderIdentity::hash() const {
  std::unique_ptr<XXH3_state_t, StateDeleter> state(XXH3_createState());
  XXH3_state_t* s = state.get();
  XXH3_64bits_reset(s);
  feedValue(s, uint64_t(files.size()));
  for (const File& f : files) feedValue(s, f.hash);  // contents, not paths: a moved copy is the same scene
  feedValue(s, width);
  feedValue(s, height);
  feedValue(s, maxDepth);
  feedValue(s, rrDepth);
  feedValue(s, seed);
  feed(s, sampler);
  feed(s, strategy);
  feed(s, caustics);
  feedValue(s, camera);
  feed(s, env);
  if (!variant.empty()) feed(s, variant);  // absent from checkpoints written before variants
  if (!textureFilter.empty()) feed(s, "texture_filter=" + textureFilter);  // likewise
  return XXH3_64bits_digest(s);
}

std::string hexHash(uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

nlohmann::json RenderIdentity::toJson() const {
  nlohmann::json fs = nlohmann::json::array();
  for (const File& f : files) fs.push_back({{"path", f.path}, {"xxh3", hexHash(f.hash)}});
  return {{"scene", scene},        {"files", fs},
          {"width", width},        {"height", height},
          {"max_depth", maxDepth}, {"rr_depth", rrDepth},
          {"seed", seed},          {"sampler", sampler},
          {"strategy", strategy},  {"caustics", caustics},
          {"camera", camera},      {"env", env},
          {"variant", variant},    {"texture_filter", textureFilter}};
}

RenderIdentity RenderIdentity::fromJson(const nlohmann::json& j, const std::string& origin) {
  try {
    RenderIdentity id;
    id.scene = j.at("scene").get<std::string>();
    for (const auto& f : j.at("files"))
      id.files.push_back(
          {f.at("path").get<std::string>(), std::stoull(f.at("xxh3").get<std::string>(), nullptr, 16)});
    id.width = j.at("width").get<int>();
    id.height = j.at("height").get<int>();
    id.maxDepth = j.at("max_depth").get<int>();
    id.rrDepth = j.at("rr_depth").get<int>();
    id.seed = j.at("seed").get<uint64_t>();
    id.sampler = j.at("sampler").get<std::string>();
    id.strategy = j.at("strategy").get<std::string>();
    id.caustics = j.at("caustics").get<std::string>();
    if (id.caustics != "trace" && id.caustics != "path")
      throw InputError(origin + ": caustics '" + id.caustics + "' is neither trace nor path");
    id.camera = j.at("camera").get<int>();
    id.env = j.at("env").get<std::string>();
    id.variant = j.value("variant", std::string());
    id.textureFilter = j.value("texture_filter", std::string());
    if (!id.textureFilter.empty() && id.textureFilter != "trilinear")
      throw InputError(origin + ": texture filter '" + id.textureFilter + "' is not trilinear");
    if (id.width <= 0 || id.height <= 0 || id.width > 16384 || id.height > 16384)
      throw InputError(origin + ": image size " + std::to_string(id.width) + "x" + std::to_string(id.height) +
                       " is out of range");
    return id;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(origin + ": malformed render identity (" + e.what() + ")");
  }
}

std::string RenderIdentity::differenceFrom(const RenderIdentity& now) const {
  auto differs = [](const std::string& what, const auto& a, const auto& b) {
    std::ostringstream os;
    os << what << " was " << a << ", is now " << b;
    return os.str();
  };
  if (files.size() != now.files.size())
    return differs("the number of files the scene loads", files.size(), now.files.size());
  for (size_t i = 0; i < files.size(); ++i)
    if (files[i].hash != now.files[i].hash) return now.files[i].path + " has changed since the checkpoint";
  if (width != now.width || height != now.height)
    return differs("the image size", std::to_string(width) + "x" + std::to_string(height),
                   std::to_string(now.width) + "x" + std::to_string(now.height));
  if (maxDepth != now.maxDepth) return differs("max depth", maxDepth, now.maxDepth);
  if (rrDepth != now.rrDepth) return differs("Russian roulette depth", rrDepth, now.rrDepth);
  if (seed != now.seed) return differs("the seed", seed, now.seed);
  if (sampler != now.sampler) return differs("the sampler", sampler, now.sampler);
  if (strategy != now.strategy) return differs("the strategy", strategy, now.strategy);
  if (caustics != now.caustics) return differs("caustics", caustics, now.caustics);
  if (camera != now.camera) return differs("the camera", camera, now.camera);
  if (env != now.env) return differs("the environment", "'" + env + "'", "'" + now.env + "'");
  if (variant != now.variant) return differs("the variant", "'" + variant + "'", "'" + now.variant + "'");
  if (textureFilter != now.textureFilter)
    return differs("the texture filter", "'" + textureFilter + "'", "'" + now.textureFilter + "'");
  return "";
}

RenderIdentity identityOf(const Scene& scene, const std::string& sceneArg, int camera,
                          const std::string& variant, const std::string& env) {
  RenderIdentity id;
  id.scene = sceneArg;
  for (const std::string& f : scene.sourceFiles) id.files.push_back({f, hashFile(f)});
  const RenderSettings& s = scene.settings;
  id.width = s.width;
  id.height = s.height;
  id.maxDepth = s.maxDepth;
  id.rrDepth = s.rrDepth;
  id.seed = s.seed;
  id.sampler = s.sampler == SamplerType::Sobol ? "sobol" : "independent";
  id.strategy = std::string(strategyName(s.strategy));
  id.caustics = s.traceCaustics ? "trace" : "path";
  id.camera = camera;
  id.env = env;
  id.variant = variant;
  return id;
}

}  // namespace ember

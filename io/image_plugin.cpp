#include "io/image_plugin.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>

namespace ember {

namespace {

constexpr const char* kModuleName = "libember_oiio.so";

struct Loaded {
  const ImagePlugin* plugin = nullptr;
  std::string error;
};

std::vector<std::filesystem::path> candidates() {
  std::vector<std::filesystem::path> out;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    out.push_back(exe.parent_path() / kModuleName);
    out.push_back(exe.parent_path() / ".." / "lib" / "ember" / kModuleName);
  }
#ifdef EMBER_PLUGIN_BUILD_DIR
  out.push_back(std::filesystem::path(EMBER_PLUGIN_BUILD_DIR) / kModuleName);
#endif
  return out;
}

Loaded load() {
  Loaded loaded;
  std::vector<std::filesystem::path> paths;
  if (const char* named = std::getenv("EMBER_OIIO_PLUGIN"); named && *named) {
    if (std::string(named) == "none") {
      loaded.error = "disabled by EMBER_OIIO_PLUGIN=none";
      return loaded;
    }
    paths.emplace_back(named);
  } else {
    paths = candidates();
  }
  std::string tried;
  for (const auto& path : paths) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      tried += (tried.empty() ? "" : ", ") + path.string();
      continue;
    }
    // RTLD_LOCAL: OpenImageIO's symbols stay the module's own.
    void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module) {
      const char* why = dlerror();
      loaded.error = path.string() + ": " + (why ? why : "dlopen failed");
      return loaded;
    }
    using Create = ImagePlugin* (*)(int);
    auto create = reinterpret_cast<Create>(dlsym(module, "ember_create_image_plugin"));
    if (!create) {
      loaded.error = path.string() + ": not an Ember image plugin (no ember_create_image_plugin)";
      return loaded;
    }
    loaded.plugin = create(ImagePlugin::kAbiVersion);
    if (!loaded.plugin) loaded.error = path.string() + ": built for another version of Ember";
    // The module stays loaded for the life of the process: the plugin lives as long.
    return loaded;
  }
  loaded.error = std::string(kModuleName) + " not found (looked at " + tried + ")";
  return loaded;
}

const Loaded& loadedOnce() {
  static const Loaded loaded = load();
  return loaded;
}

}  // namespace

const ImagePlugin* imagePlugin() {
  return loadedOnce().plugin;
}

const std::string& imagePluginError() {
  return loadedOnce().error;
}

}  // namespace ember

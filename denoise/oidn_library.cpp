#include "denoise/oidn_library.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <vector>

namespace ember {

namespace {

constexpr const char* kSoname = "libOpenImageDenoise.so.2";

// libOpenImageDenoise.so.2 inside the pyoidn package of an environment's site-packages.
void addPyoidnIn(const std::filesystem::path& libRoot, std::vector<std::string>& candidates) {
  std::error_code ec;
  if (!std::filesystem::is_directory(libRoot, ec)) return;
  for (const auto& entry : std::filesystem::directory_iterator(libRoot, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("python3", 0) != 0) continue;
    const std::filesystem::path lib = entry.path() / "site-packages/pyoidn/oidn/lib" / kSoname;
    if (std::filesystem::exists(lib, ec)) candidates.push_back(lib.string());
  }
}

struct Loaded {
  OidnApi api;
  std::string path;
  std::string why;
  bool ok = false;
};

template <class F>
bool resolve(void* handle, const char* name, F& out, std::string& missing) {
  out = reinterpret_cast<F>(dlsym(handle, name));
  if (!out) missing += std::string(missing.empty() ? "" : ", ") + name;
  return out != nullptr;
}

Loaded load() {
  Loaded l;
  std::vector<std::string> candidates;
  const char* given = std::getenv("EMBER_OIDN_LIBRARY");
  if (given && *given) {
    candidates.push_back(given);
  } else {
    if (const char* venv = std::getenv("VIRTUAL_ENV"))
      addPyoidnIn(std::filesystem::path(venv) / "lib", candidates);
    addPyoidnIn(std::filesystem::path(EMBER_OIDN_VENV) / "lib", candidates);
    if (const char* home = std::getenv("HOME"))
      addPyoidnIn(std::filesystem::path(home) / ".local/lib", candidates);
    candidates.push_back(kSoname);
  }
  std::string tried;
  for (const std::string& path : candidates) {
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* e = dlerror();
      tried += "\n  " + path + ": " + (e ? e : "cannot be loaded");
      continue;
    }
    std::string missing;
    OidnApi& a = l.api;
    resolve(handle, "oidnNewDevice", a.newDevice, missing);
    resolve(handle, "oidnSetDeviceInt", a.setDeviceInt, missing);
    resolve(handle, "oidnCommitDevice", a.commitDevice, missing);
    resolve(handle, "oidnReleaseDevice", a.releaseDevice, missing);
    resolve(handle, "oidnGetDeviceError", a.getDeviceError, missing);
    resolve(handle, "oidnNewFilter", a.newFilter, missing);
    resolve(handle, "oidnSetSharedFilterImage", a.setSharedFilterImage, missing);
    resolve(handle, "oidnSetFilterBool", a.setFilterBool, missing);
    resolve(handle, "oidnSetFilterInt", a.setFilterInt, missing);
    resolve(handle, "oidnCommitFilter", a.commitFilter, missing);
    resolve(handle, "oidnExecuteFilter", a.executeFilter, missing);
    resolve(handle, "oidnReleaseFilter", a.releaseFilter, missing);
    if (!missing.empty()) {  // an OIDN 1.x, or not OIDN at all
      tried += "\n  " + path + ": not OIDN 2 (no " + missing + ")";
      dlclose(handle);
      continue;
    }
    l.path = path;
    l.ok = true;
    return l;
  }
  l.why =
      std::string("Intel Open Image Denoise 2 (") + kSoname + ") was not found; tried:" + tried +
      "\nInstall it with scripts/setup-deps.sh (the pyoidn wheel in the repository's .venv), `pip install "
      "pyoidn` in an active virtual environment, or point EMBER_OIDN_LIBRARY at the library";
  return l;
}

const Loaded& loaded() {
  static const Loaded l = load();
  return l;
}

}  // namespace

const OidnApi* oidnLibrary(std::string& why) {
  const Loaded& l = loaded();
  if (!l.ok) why = l.why;
  return l.ok ? &l.api : nullptr;
}

std::string oidnLibraryPath() {
  return loaded().ok ? loaded().path : std::string();
}

}  // namespace ember

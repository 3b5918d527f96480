// Intel Open Image Denoise (OIDN), loaded at run time. Debian 12 packages no OIDN, and the PyPI wheel
// `pyoidn` ships libOpenImageDenoise.so.2 (with its CPU device and trained weights) but no headers,
// so Ember declares the few functions of OIDN's C API it calls (Apache-2.0, oidn.h of OIDN 2.x) and
// resolves them with dlopen. The library found first, in this order, is used:
//  1. $EMBER_OIDN_LIBRARY: a path to libOpenImageDenoise.so.2 (an error if it does not load);
//  2. the pyoidn package of the active virtual environment ($VIRTUAL_ENV);
//  3. the pyoidn package of the repository's .venv, where scripts/setup-deps.sh installs it;
//  4. the pyoidn package of the user's site-packages (pip install --user);
//  5. libOpenImageDenoise.so.2 on the loader's path (a system or LD_LIBRARY_PATH install).
// The wheel's OIDN runs on the oneTBB that Ember already links (Debian's 2021.8): the loader reuses
// the loaded libtbb.so.12 rather than the wheel's copy.
#pragma once

#include <cstddef>
#include <string>

namespace ember {

struct OidnApi {
  using Device = void*;
  using Filter = void*;
  static constexpr int kDeviceCpu = 1;        // OIDN_DEVICE_TYPE_CPU
  static constexpr int kFormatFloat3 = 3;     // OIDN_FORMAT_FLOAT3
  static constexpr int kQualityBalanced = 5;  // OIDN_QUALITY_BALANCED
  static constexpr int kQualityHigh = 6;      // OIDN_QUALITY_HIGH
  Device (*newDevice)(int type) = nullptr;
  void (*setDeviceInt)(Device, const char* name, int value) = nullptr;
  void (*commitDevice)(Device) = nullptr;
  void (*releaseDevice)(Device) = nullptr;
  int (*getDeviceError)(Device, const char** message) = nullptr;
  Filter (*newFilter)(Device, const char* type) = nullptr;
  void (*setSharedFilterImage)(Filter, const char* name, void* data, int format, size_t width, size_t height,
                               size_t byteOffset, size_t pixelByteStride, size_t rowByteStride) = nullptr;
  void (*setFilterBool)(Filter, const char* name, bool value) = nullptr;
  void (*setFilterInt)(Filter, const char* name, int value) = nullptr;
  void (*commitFilter)(Filter) = nullptr;
  void (*executeFilter)(Filter) = nullptr;
  void (*releaseFilter)(Filter) = nullptr;
};

// The library, loaded on first use and kept for the process; null where none was found, with
// `why` saying where Ember looked and how to install it.
const OidnApi* oidnLibrary(std::string& why);
// The file the library was loaded from (empty before a successful oidnLibrary call).
std::string oidnLibraryPath();

}  // namespace ember

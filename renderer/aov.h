// Arbitrary output variables (AOVs): what a render can write beside its colour, as layers of the
// one EXR (docs/aovs.md defines each). Albedo and normal are taken where OIDN asks for them: at
// the first vertex with a non-Dirac lobe, mirrors and smooth glass followed through (OIDN's
// documentation of its auxiliary images; Cycles' denoising passes do the same). Depth, position and
// texture coordinates are those of the camera ray's own hit. Each camera sample gives one value of
// each, and the film averages them as it averages colour, so the layers follow the render's sample
// range through passes, checkpoints, merges and MPI.
#pragma once

#include "core/math.h"

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace ember {

enum class Aov : uint32_t {
  Albedo = 1u << 0,
  Normal = 1u << 1,
  Depth = 1u << 2,
  Position = 1u << 3,
  Uv = 1u << 4,
  Variance = 1u << 5,
  Spp = 1u << 6,
};

// A set of AOVs, as bits.
class AovSet {
 public:
  constexpr AovSet() = default;
  constexpr explicit AovSet(uint32_t bits) : bits_(bits) {}
  bool has(Aov a) const { return (bits_ & uint32_t(a)) != 0; }
  void add(Aov a) { bits_ |= uint32_t(a); }
  bool empty() const { return bits_ == 0; }
  uint32_t bits() const { return bits_; }
  // Whether the path tracer must record anything per sample (variance and spp come from the
  // colour's own sums).
  bool perSample() const { return (bits_ & ~(uint32_t(Aov::Variance) | uint32_t(Aov::Spp))) != 0; }
  // Whether the camera ray's hit is recorded (depth, position, uv), with the coverage they need.
  bool geometric() const { return has(Aov::Depth) || has(Aov::Position) || has(Aov::Uv); }
  bool operator==(const AovSet&) const = default;

 private:
  uint32_t bits_ = 0;
};

// Every AOV's name, in the order of the layers: albedo, normal, depth, position, uv, variance, spp.
inline constexpr const char* kAovNames = "albedo, normal, depth, position, uv, variance, spp";
// "albedo,normal", "all" or "none"; nullopt (and `error` set) for an unknown or empty name.
std::optional<AovSet> parseAovs(std::string_view list, std::string& error);
// The names of the set, comma-separated in the order above (parseAovs reads it back).
std::string aovList(AovSet set);

// One camera sample's AOVs as the path tracer records them (PathIntegrator's aov steps).
struct AovSample {
  Color albedo{0.0f};  // from surfaceFound until albedoKnown: the Dirac chain's weight, clamped to [0, 1]
  Vec3 normal{0.0f};
  Vec3 position{0.0f};
  Vec2 uv{0.0f};
  float depth = 0.0f;
  bool hit = false;           // the camera ray hit a surface (position, depth and uv are set)
  bool surfaceFound = false;  // the albedo vertex was reached: normal set, albedo pending
  bool albedoKnown = false;   // albedo holds the vertex's albedo
  bool resolved() const { return albedoKnown; }
};

// The film's per-pixel sums for a set, in doubles, channel by channel in this order:
// albedo (3), normal (3), coverage (1: how many samples hit a surface), depth (1), position (3),
// uv (2), each present only where the set asks for it (coverage with any geometric AOV).
struct AovLayout {
  int albedo = -1, normal = -1, coverage = -1, depth = -1, position = -1, uv = -1;
  int channels = 0;
  explicit AovLayout(AovSet set);
};

}  // namespace ember

// Which estimator of direct light the path integrator uses (renderer/path_integrator.h). All
// three are unbiased and must agree in expectation; they differ in variance.
#pragma once

#include <optional>
#include <string_view>

namespace ember {

enum class Strategy {
  Mis,   // light and BSDF sampling, combined by the power heuristic (Veach 1997, section 9.2)
  Bsdf,  // BSDF sampling only: emitters count when a path hits them; delta lights are never found
  Light  // light sampling at every non-delta vertex; emission hit after a delta lobe still counts
};

inline std::string_view strategyName(Strategy s) {
  switch (s) {
    case Strategy::Bsdf:
      return "bsdf";
    case Strategy::Light:
      return "light";
    case Strategy::Mis:
      break;
  }
  return "mis";
}

inline std::optional<Strategy> parseStrategy(std::string_view name) {
  if (name == "mis") return Strategy::Mis;
  if (name == "bsdf") return Strategy::Bsdf;
  if (name == "light") return Strategy::Light;
  return std::nullopt;
}

inline constexpr std::string_view kStrategyNames = "mis, bsdf, light";

}  // namespace ember

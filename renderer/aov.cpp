#include "renderer/aov.h"

#include <array>
#include <utility>

namespace ember {

namespace {

constexpr std::array<std::pair<const char*, Aov>, 7> kNamed = {{{"albedo", Aov::Albedo},
                                                                {"normal", Aov::Normal},
                                                                {"depth", Aov::Depth},
                                                                {"position", Aov::Position},
                                                                {"uv", Aov::Uv},
                                                                {"variance", Aov::Variance},
                                                                {"spp", Aov::Spp}}};

}  // namespace

std::optional<AovSet> parseAovs(std::string_view list, std::string& error) {
  AovSet set;
  if (list == "none") return set;
  if (list == "all") {
    for (const auto& [name, aov] : kNamed) set.add(aov);
    return set;
  }
  size_t begin = 0;
  for (;;) {
    const size_t comma = list.find(',', begin);
    const std::string_view name = list.substr(begin, comma == std::string_view::npos ? comma : comma - begin);
    bool known = false;
    for (const auto& [known_name, aov] : kNamed)
      if (name == known_name) {
        set.add(aov);
        known = true;
      }
    if (!known) {
      error = name.empty() ? std::string("an empty AOV name in '") + std::string(list) + "'"
                           : "unknown AOV '" + std::string(name) + "'";
      error += " (known: " + std::string(kAovNames) + ", all, none)";
      return std::nullopt;
    }
    if (comma == std::string_view::npos) return set;
    begin = comma + 1;
  }
}

std::string aovList(AovSet set) {
  std::string out;
  for (const auto& [name, aov] : kNamed)
    if (set.has(aov)) {
      if (!out.empty()) out += ',';
      out += name;
    }
  return out.empty() ? "none" : out;
}

AovLayout::AovLayout(AovSet set) {
  const auto take = [&](bool wanted, int width, int& at) {
    if (!wanted) return;
    at = channels;
    channels += width;
  };
  take(set.has(Aov::Albedo), 3, albedo);
  take(set.has(Aov::Normal), 3, normal);
  take(set.geometric(), 1, coverage);
  take(set.has(Aov::Depth), 1, depth);
  take(set.has(Aov::Position), 3, position);
  take(set.has(Aov::Uv), 2, uv);
}

}  // namespace ember

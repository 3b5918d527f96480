#include "checkpoint/checkpoint_file.h"

#include "io/input_error.h"
#include "io/pending_file.h"
#include "renderer/adaptive.h"
#include "renderer/render.h"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace ember {

namespace {

constexpr char kMagic[8] = {'E', 'M', 'B', 'E', 'R', 'C', 'K', 'P'};

template <typename T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

template <typename T>
void putArray(std::string& out, const std::vector<T>& v) {
  if (v.empty()) return;  // an empty vector's data() may be null, which memcpy may not take
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

// Reads forward through the bytes of a file, failing with the file's name when they run out.
class Reader {
 public:
  Reader(const std::string& bytes, const std::string& path) : bytes_(bytes), path_(path) {}
  template <typename T>
  T get(const char* what) {
    T v;
    need(sizeof v, what);
    std::memcpy(&v, bytes_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  template <typename T>
  void getArray(std::vector<T>& v, const char* what) {
    if (v.empty()) return;  // an empty vector's data() may be null, which memcpy may not take
    need(v.size() * sizeof(T), what);
    std::memcpy(v.data(), bytes_.data() + at_, v.size() * sizeof(T));
    at_ += v.size() * sizeof(T);
  }
  std::string getString(size_t n, const char* what) {
    need(n, what);
    std::string s = bytes_.substr(at_, n);
    at_ += n;
    return s;
  }
  size_t offset() const { return at_; }

 private:
  void need(size_t n, const char* what) {
    if (bytes_.size() - at_ < n)
      throw InputError(path_ + ": truncated checkpoint: it ends in the " + what + " (" +
                       std::to_string(bytes_.size()) + " bytes)");
  }
  const std::string& bytes_;
  const std::string& path_;
  size_t at_ = 0;
};

void writeFileDurably(const std::string& path, const std::string& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw InputError(path + ": cannot create: " + std::strerror(errno));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string why = std::strerror(errno);
      ::close(fd);
      throw InputError(path + ": write failed: " + why);
    }
    done += size_t(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) throw InputError(path + ": could not be flushed to disk");
}

}  // namespace

void writeCheckpoint(const std::string& path, const Checkpoint& c) {
  const nlohmann::json header = {{"identity", c.identity.toJson()},
                                 {"first_sample", c.firstSample},
                                 {"spp", c.spp},
                                 {"pass_spp", c.passSpp},
                                 {"passes", c.passes},
                                 {"output", c.output},
                                 {"aovs", aovList(c.film.aovs())},
                                 {"budgets", !c.film.budgets().empty()},
                                 {"adaptive_target", c.adaptiveTarget},
                                 {"adaptive_pilot_spp", c.adaptivePilotSpp},
                                 {"ember_version", c.emberVersion}};
  const std::string text = header.dump();
  std::string bytes(kMagic, sizeof kMagic);
  put(bytes, kCheckpointFormat);
  put(bytes, uint32_t(text.size()));
  bytes += text;
  putArray(bytes, c.film.sums());
  putArray(bytes, c.film.sumsOfSquares());
  putArray(bytes, c.film.counts());
  putArray(bytes, c.film.aovSums());
  putArray(bytes, c.film.budgets());
  put(bytes, uint64_t(XXH3_64bits(bytes.data(), bytes.size())));

  writeAtomically(path, [&](const std::string& tmp) { writeFileDurably(tmp, bytes); });
}

Checkpoint readCheckpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": no such checkpoint file");
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  Reader r(bytes, path);
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw InputError(path + ": not an Ember checkpoint (no EMBERCKP signature)");
  r.getString(sizeof kMagic, "signature");
  const uint32_t format = r.get<uint32_t>("format version");
  if (format != kCheckpointFormat)
    throw InputError(path + ": checkpoint format " + std::to_string(format) + "; this Ember reads format " +
                     std::to_string(kCheckpointFormat));
  // The checksum first: a corrupted header must not be trusted for sizes.
  if (bytes.size() < r.offset() + sizeof(uint64_t))
    throw InputError(path + ": truncated checkpoint (" + std::to_string(bytes.size()) + " bytes)");
  uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - sizeof stored, sizeof stored);
  const uint32_t headerSize = r.get<uint32_t>("header size");
  if (uint64_t(headerSize) + r.offset() + sizeof(uint64_t) > bytes.size())
    throw InputError(path + ": truncated checkpoint: it ends in the header");
  if (XXH3_64bits(bytes.data(), bytes.size() - sizeof stored) != stored)
    throw InputError(path + ": corrupted checkpoint (checksum mismatch): truncated or modified");

  const std::string text = r.getString(headerSize, "header");
  const nlohmann::json header = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!header.is_object()) throw InputError(path + ": corrupted checkpoint header (not JSON)");
  Checkpoint c;
  AovSet aovs;
  bool budgets = false;
  try {
    c.identity = RenderIdentity::fromJson(header.at("identity"), path);
    c.firstSample = header.at("first_sample").get<uint64_t>();
    c.spp = header.at("spp").get<int>();
    c.passSpp = header.at("pass_spp").get<int>();
    c.passes = header.at("passes").get<int>();
    c.output = header.at("output").get<std::string>();
    c.emberVersion = header.at("ember_version").get<std::string>();
    std::string error;
    const std::optional<AovSet> parsed = parseAovs(header.at("aovs").get<std::string>(), error);
    if (!parsed) throw InputError(path + ": corrupted checkpoint header (" + error + ")");
    aovs = *parsed;
    budgets = header.at("budgets").get<bool>();
    c.adaptiveTarget = header.at("adaptive_target").get<double>();
    c.adaptivePilotSpp = header.at("adaptive_pilot_spp").get<int>();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": corrupted checkpoint header (" + e.what() + ")");
  }
  if (!std::isfinite(c.adaptiveTarget) || c.adaptiveTarget < 0.0 || c.adaptivePilotSpp < 0 ||
      (c.adaptiveTarget > 0.0 && c.adaptivePilotSpp < 1) || (budgets && !(c.adaptiveTarget > 0.0)))
    throw InputError(path + ": corrupted checkpoint header (adaptive sampling settings)");
  if (c.spp < 1 || c.passSpp < 1 || c.passes < 0 || c.passes > passCount(c.spp, c.passSpp))
    throw InputError(path + ": corrupted checkpoint header (inconsistent sample counts)");
  c.film = Film(c.identity.width, c.identity.height, aovs);
  r.getArray(c.film.sums(), "sums");
  r.getArray(c.film.sumsOfSquares(), "sums of squares");
  r.getArray(c.film.counts(), "counts");
  r.getArray(c.film.aovSums(), "AOV sums");
  if (budgets) {
    c.film.budgets().resize(c.film.pixelCount());
    r.getArray(c.film.budgets(), "budgets");
  }
  if (r.offset() + sizeof(uint64_t) != bytes.size())
    throw InputError(path + ": corrupted checkpoint (" + std::to_string(bytes.size() - r.offset() - 8) +
                     " unexpected bytes after the pixels' state)");
  const uint32_t expected = uint32_t(std::min(c.spp, c.passes * c.passSpp));
  for (uint32_t n : c.film.counts())
    if (n > expected)
      throw InputError(path + ": corrupted checkpoint (a pixel holds more samples than its passes)");
  for (size_t i = 0; i < c.film.budgets().size(); ++i) {
    const uint32_t b = c.film.budgets()[i];
    if (b < uint32_t(c.adaptivePilotSpp) || b > kMaxAdaptiveBudget || c.film.counts()[i] > b)
      throw InputError(path + ": corrupted checkpoint (pixel " + std::to_string(i) + "'s sample budget " +
                       std::to_string(b) + " is impossible)");
  }
  return c;
}

}  // namespace ember

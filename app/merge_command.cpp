// `ember merge A.exr B.exr ... -o out.exr`: renders of disjoint sample ranges of one render
// (--first-sample, separate machines or MPI-less clusters) combined into the image of their union.
// Each input's mean is weighted by its spp, in double; the result equals one render of all the
// ranges to float rounding of the inputs (about 1e-7 relative).
#include "app/commands.h"

#include "io/image_io.h"
#include "io/input_error.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace ember::cli {

namespace {

struct MergeArgs {
  std::vector<std::string> inputs;
  std::string output;
  std::vector<std::string> variances;  // --variance: each input's variance-of-the-mean EXR, in order
  std::string varianceOutput;
};

// The keys that must agree between inputs: together they say "the same render".
// The settings first, so that an error names the one that differs; the scene hash covers them too.
constexpr const char* kIdentityKeys[] = {"ember:seed",      "ember:sampler",  "ember:strategy",
                                         "ember:max_depth", "ember:rr_depth", "ember:scene_hash"};

struct Input {
  std::string path;
  std::map<std::string, std::string> meta;
  Image image;
  uint64_t first = 0;
  uint64_t spp = 0;
};

uint64_t number(const Input& in, const std::string& key) {
  const auto it = in.meta.find(key);
  if (it == in.meta.end())
    throw InputError(in.path + ": no " + key + " attribute: not an image rendered by Ember");
  try {
    size_t used = 0;
    const unsigned long long v = std::stoull(it->second, &used);
    if (used != it->second.size()) throw std::invalid_argument("trailing characters");
    return v;
  } catch (const std::exception&) {
    throw InputError(in.path + ": " + key + " is '" + it->second + "', not a count");
  }
}

int runMerge(const MergeArgs& a) {
  if (a.inputs.size() < 2) throw InputError("merge needs at least two images");
  if (!a.variances.empty() && a.variances.size() != a.inputs.size())
    throw InputError("--variance needs one variance EXR per input (" + std::to_string(a.inputs.size()) +
                     "), got " + std::to_string(a.variances.size()));
  if (a.variances.empty() != a.varianceOutput.empty())
    throw InputError("--variance and --variance-output go together");
  std::vector<Input> inputs;
  for (const std::string& path : a.inputs) {
    Input in;
    in.path = path;
    for (auto& [k, v] : readStringMetadata(path)) in.meta[k] = v;
    in.first = number(in, "ember:first_sample");
    in.spp = number(in, "ember:spp");
    if (in.spp == 0) throw InputError(path + ": holds no samples");
    in.image = readImageRgb(path);
    inputs.push_back(std::move(in));
  }
  const Input& base = inputs.front();
  for (const Input& in : inputs) {
    for (const char* key : kIdentityKeys) {
      const auto mine = in.meta.find(key), theirs = base.meta.find(key);
      if (mine == in.meta.end())
        throw InputError(in.path + ": no " + key + " attribute: not an image rendered by Ember");
      if (theirs->second != mine->second)
        throw InputError(in.path + ": " + key + " is " + mine->second + ", but " + base.path + " has " +
                         theirs->second + ": they are not sample ranges of the same render");
    }
    if (in.image.width != base.image.width || in.image.height != base.image.height)
      throw InputError(in.path + ": " + std::to_string(in.image.width) + "x" +
                       std::to_string(in.image.height) + " pixels, but " + base.path + " has " +
                       std::to_string(base.image.width) + "x" + std::to_string(base.image.height));
  }
  // Disjoint ranges: sorted by first sample, each must end before the next begins.
  std::vector<const Input*> order;
  for (const Input& in : inputs) order.push_back(&in);
  std::sort(order.begin(), order.end(), [](const Input* x, const Input* y) { return x->first < y->first; });
  for (size_t i = 1; i < order.size(); ++i)
    if (order[i - 1]->first + order[i - 1]->spp > order[i]->first)
      throw InputError(order[i]->path + ": samples [" + std::to_string(order[i]->first) + ", " +
                       std::to_string(order[i]->first + order[i]->spp) + ") overlap " + order[i - 1]->path +
                       "'s [" + std::to_string(order[i - 1]->first) + ", " +
                       std::to_string(order[i - 1]->first + order[i - 1]->spp) + ")");

  uint64_t total = 0;
  for (const Input& in : inputs) total += in.spp;
  Image out(base.image.width, base.image.height);
  for (size_t i = 0; i < out.rgb.size(); ++i) {
    double sum = 0.0;
    for (const Input& in : inputs) sum += double(in.image.rgb[i]) * double(in.spp);
    out.rgb[i] = float(sum / double(total));
  }
  std::string ranges;
  for (const Input* in : order)
    ranges +=
        (ranges.empty() ? "" : ",") + std::to_string(in->first) + "-" + std::to_string(in->first + in->spp);
  Metadata meta;
  for (const auto& [k, v] : base.meta)
    if (k.rfind("ember:", 0) == 0 && k != "ember:render_seconds" && k != "ember:passes" &&
        k != "ember:spp_requested")
      meta.emplace_back(k, v);
  for (auto& [k, v] : meta) {
    if (k == "ember:spp") v = std::to_string(total);
    if (k == "ember:first_sample") v = std::to_string(order.front()->first);
  }
  meta.emplace_back("ember:sample_ranges", ranges);
  meta.emplace_back("Software", std::string("ember ") + EMBER_VERSION + " merge");
  if (!a.variances.empty()) {
    // Each input's mean m and variance of the mean v over n samples give back its sum of squares,
    // Q = (n - 1) n v + n m^2; the union's variance of the mean is then
    // (sum Q - N M^2) / ((N - 1) N) with N = sum n and M the merged mean.
    std::vector<Image> vars;
    for (size_t k = 0; k < a.variances.size(); ++k) {
      vars.push_back(readImageRgb(a.variances[k]));
      if (vars.back().width != base.image.width || vars.back().height != base.image.height)
        throw InputError(a.variances[k] + ": its size differs from " + inputs[k].path + "'s");
    }
    Image var(base.image.width, base.image.height);
    const double total_ = double(total);
    for (size_t i = 0; i < var.rgb.size(); ++i) {
      double q = 0.0;
      for (size_t k = 0; k < inputs.size(); ++k) {
        const double n = double(inputs[k].spp), m = inputs[k].image.rgb[i];
        q += (n - 1.0) * n * double(vars[k].rgb[i]) + n * m * m;
      }
      const double mean = out.rgb[i];
      var.rgb[i] =
          total > 1 ? float(std::max(0.0, (q - total_ * mean * mean) / ((total_ - 1.0) * total_))) : 0.0f;
    }
    writeExr(a.varianceOutput, var, meta);
  }
  writeExr(a.output, out, meta);
  std::fprintf(stderr, "ember: merged %zu images, %llu spp (samples %s) -> %s\n", inputs.size(),
               static_cast<unsigned long long>(total), ranges.c_str(), a.output.c_str());
  return 0;
}

}  // namespace

Runner addMergeCommand(CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Combine EXRs of disjoint sample ranges of one render (--first-sample) into one image");
  cmd->add_option("inputs", args->inputs, "EXRs written by `ember render` of the same scene and settings")
      ->required();
  cmd->add_option("-o,--output", args->output, "Output EXR")->required();
  cmd->add_option("--variance", args->variances,
                  "Each input's variance EXR (ember render --variance), in the order of the inputs");
  cmd->add_option("--variance-output", args->varianceOutput,
                  "Where to write the merged variance of the mean");
  return [args] { return runMerge(*args); };
}

}  // namespace ember::cli

// `ember merge A.exr B.exr ... -o out.exr`: renders of disjoint sample ranges of one render
// (--first-sample, separate machines or MPI-less clusters) combined into the image of their union.
// Each input's mean is weighted by its spp, in double; the result equals one render of all the
// ranges to float rounding of the inputs (about 1e-7 relative). AOV layers (docs/aovs.md) merge by
// their own definitions: per-sample means by spp, depth, position and uv by the samples that hit a
// surface (spp times coverage), the variance from each input's sums it gives back, spp by adding.
#include "app/commands.h"

#include "io/image_io.h"
#include "io/input_error.h"

#include <algorithm>
#include <cstdio>
#include <limits>
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
                                         "ember:max_depth", "ember:rr_depth", "ember:scene_hash",
                                         "ember:aovs"};

struct Input {
  std::string path;
  std::map<std::string, std::string> meta;
  ExrChannels exr;
  // Its spp and coverage layers, where it has them (set once the inputs are read).
  mutable const float* sppLayer = nullptr;
  mutable const float* coverage = nullptr;
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
    in.exr = readExrChannels(path);
    for (auto& [k, v] : in.exr.metadata) in.meta[k] = v;
    if (!in.meta.count("ember:aovs")) in.meta["ember:aovs"] = "none";  // written before AOVs, or without
    in.first = number(in, "ember:first_sample");
    in.spp = number(in, "ember:spp");
    if (in.spp == 0) throw InputError(path + ": holds no samples");
    for (const char* c : {"R", "G", "B"})
      if (!in.exr.has(c)) throw InputError(path + ": no " + c + " channel: not an image rendered by Ember");
    // A denoised colour is no longer a mean of samples: averaging two is not their union's image.
    if (in.meta.count("ember:denoiser") || in.exr.has("noisy.R"))
      throw InputError(path +
                       ": a denoised image; merge the renders without --denoise, then denoise the merged "
                       "one (ember denoise)");
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
    if (in.exr.width != base.exr.width || in.exr.height != base.exr.height)
      throw InputError(in.path + ": " + std::to_string(in.exr.width) + "x" + std::to_string(in.exr.height) +
                       " pixels, but " + base.path + " has " + std::to_string(base.exr.width) + "x" +
                       std::to_string(base.exr.height));
    for (const auto& [name, data] : base.exr.channels)
      if (!in.exr.has(name))
        throw InputError(in.path + ": no " + name + " channel, which " + base.path + " has");
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
  const int width = base.exr.width, height = base.exr.height;
  const size_t pixels = size_t(width) * size_t(height);
  // Input k's samples at pixel i: its spp layer's, else its spp everywhere.
  for (const Input& in : inputs) {
    const auto it = in.exr.channels.find("spp");
    in.sppLayer = it != in.exr.channels.end() ? it->second.data() : nullptr;
    const auto c = in.exr.channels.find("coverage");
    in.coverage = c != in.exr.channels.end() ? c->second.data() : nullptr;
  }
  const auto samples = [&](const Input& in, size_t i) {
    return in.sppLayer ? double(in.sppLayer[i]) : double(in.spp);
  };
  const auto hits = [&](const Input& in, size_t i) {
    return samples(in, i) * (in.coverage ? double(in.coverage[i]) : 1.0);
  };
  // Every channel: a mean over the samples (weights `samples`) or over the hits (`hits`).
  std::map<std::string, std::vector<float>> merged;
  for (const auto& [name, data] : base.exr.channels) {
    if (name == "spp" || name.rfind("variance.", 0) == 0) continue;
    const bool overHits = name == "Z" || name.rfind("P.", 0) == 0 || name.rfind("uv.", 0) == 0;
    std::vector<float>& out = merged[name];
    out.resize(pixels);
    std::vector<const float*> values;
    for (const Input& in : inputs) values.push_back(in.exr.channels.at(name).data());
    for (size_t i = 0; i < pixels; ++i) {
      double sum = 0.0, weight = 0.0;
      for (size_t k = 0; k < inputs.size(); ++k) {
        const double w = overHits ? hits(inputs[k], i) : samples(inputs[k], i);
        if (w > 0.0) sum += double(values[k][i]) * w;
        weight += w;
      }
      out[i] = weight > 0.0  ? float(sum / weight)
               : name == "Z" ? std::numeric_limits<float>::infinity()
                             : 0.0f;
    }
  }
  if (base.exr.has("spp")) {
    std::vector<float>& out = merged["spp"];
    out.resize(pixels);
    for (size_t i = 0; i < pixels; ++i) {
      double n = 0.0;
      for (const Input& in : inputs) n += samples(in, i);
      out[i] = float(n);
    }
  }
  // The variance of the union's mean from each input's mean m_k and variance of the mean v_k over
  // n_k samples (Chan et al. 1979's pairwise update, which takes no difference of large sums):
  // (sum (n_k - 1) n_k v_k + sum n_k (m_k - M)^2) / ((N - 1) N), N = sum n_k, M the union's mean.
  const auto mergeVariance = [&](const std::vector<const std::vector<float>*>& vars,
                                 const std::string& colour, std::vector<float>& out) {
    out.resize(pixels);
    std::vector<const float*> means;
    for (const Input& in : inputs) means.push_back(in.exr.channels.at(colour).data());
    for (size_t i = 0; i < pixels; ++i) {
      double n = 0.0, sum = 0.0;
      for (size_t k = 0; k < inputs.size(); ++k) {
        n += samples(inputs[k], i);
        sum += samples(inputs[k], i) * double(means[k][i]);
      }
      if (!(n > 1.0)) {
        out[i] = 0.0f;
        continue;
      }
      const double mean = sum / n;
      double q = 0.0;
      for (size_t k = 0; k < inputs.size(); ++k) {
        const double nk = samples(inputs[k], i), d = double(means[k][i]) - mean;
        q += (nk - 1.0) * nk * double((*vars[k])[i]) + nk * d * d;
      }
      out[i] = float(q / ((n - 1.0) * n));
    }
  };
  for (const char* c : {"R", "G", "B"})
    if (base.exr.has(std::string("variance.") + c)) {
      std::vector<const std::vector<float>*> vars;
      for (const Input& in : inputs) vars.push_back(&in.exr.channels.at(std::string("variance.") + c));
      mergeVariance(vars, c, merged[std::string("variance.") + c]);
    }
  Image out(width, height);
  for (size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < 3; ++c) out.rgb[3 * i + size_t(c)] = merged.at(std::string(1, "RGB"[c]))[i];
  std::vector<ImageLayer> layers;
  for (const auto& [name, data] : merged)
    if (name != "R" && name != "G" && name != "B") layers.push_back({{name}, data});
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
    std::vector<Image> vars;
    for (size_t k = 0; k < a.variances.size(); ++k) {
      vars.push_back(readImageRgb(a.variances[k]));
      if (vars.back().width != width || vars.back().height != height)
        throw InputError(a.variances[k] + ": its size differs from " + inputs[k].path + "'s");
    }
    Image var(width, height);
    for (int c = 0; c < 3; ++c) {
      std::vector<std::vector<float>> channel(vars.size(), std::vector<float>(pixels));
      std::vector<const std::vector<float>*> pointers;
      for (size_t k = 0; k < vars.size(); ++k) {
        for (size_t i = 0; i < pixels; ++i) channel[k][i] = vars[k].rgb[3 * i + size_t(c)];
        pointers.push_back(&channel[k]);
      }
      std::vector<float> merged_;
      mergeVariance(pointers, std::string(1, "RGB"[c]), merged_);
      for (size_t i = 0; i < pixels; ++i) var.rgb[3 * i + size_t(c)] = merged_[i];
    }
    writeExr(a.varianceOutput, var, meta);
  }
  writeExr(a.output, out, layers, meta);
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

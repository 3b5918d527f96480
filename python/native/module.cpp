// The `ember._ember` extension: scenes loaded, edited and rendered by the code of `ember render`,
// and the command line's image helpers. python/ember/__init__.py wraps it in the public, typed API.
#include "io/image_comparison.h"
#include "io/image_io.h"
#include "io/input_error.h"
#include "io/scene_summary.h"
#include "io/tonemap.h"
#include "python/native/numpy_arrays.h"
#include "python/native/python_json.h"
#include "python/native/render_call.h"
#include "python/native/scene_handle.h"

#include <nanobind/nanobind.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/variant.h>
#include <nanobind/stl/vector.h>

#include <cstring>

namespace nb = nanobind;
using namespace nb::literals;
using namespace ember;
using namespace ember::python;

namespace {

Image imageFrom(const FloatArray& a, const char* what) {
  if (a.ndim() != 3 || a.shape(2) != 3)
    throw nb::value_error(
        (std::string(what) + ": expected a float32 array of shape (height, width, 3)").c_str());
  Image image(int(a.shape(1)), int(a.shape(0)));
  std::memcpy(image.rgb.data(), a.data(), image.rgb.size() * sizeof(float));
  return image;
}

std::optional<Image> optionalImage(const std::optional<FloatArray>& a, const char* what) {
  return a ? std::optional<Image>(imageFrom(*a, what)) : std::nullopt;
}

nb::dict compare(const FloatArray& imageArray, const FloatArray& referenceArray,
                 const std::optional<FloatArray>& varianceArray, const std::optional<FloatArray>& stderrArray,
                 std::optional<double> maxRelmse, std::optional<double> maxFlip, double alpha, int pool,
                 float ppd, bool ldr) {
  const Image image = imageFrom(imageArray, "image");
  const Image reference = imageFrom(referenceArray, "reference");
  const std::optional<Image> variance = optionalImage(varianceArray, "variance");
  const std::optional<Image> refStderr = optionalImage(stderrArray, "ref_stderr");
  ComparisonOptions options;
  options.maxRelmse = maxRelmse;
  options.maxFlip = maxFlip;
  options.alpha = alpha;
  options.variancePool = pool;
  options.pixelsPerDegree = ppd;
  options.ldr = ldr;
  Comparison c;
  {
    nb::gil_scoped_release release;
    c = compareImages(image, reference, variance ? &*variance : nullptr, refStderr ? &*refStderr : nullptr,
                      options);
  }
  return nb::cast<nb::dict>(fromJson(comparisonJson(c, options, image.width, image.height)));
}

nb::object tonemap(const FloatArray& array, float key, std::optional<float> white) {
  const Image image = imageFrom(array, "image");
  ReinhardParams params;
  params.key = key;
  params.white = white;
  ReinhardResult result = tonemapReinhard(image, params);
  auto* owned = new std::vector<uint8_t>(std::move(result.rgb8));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<uint8_t>*>(p); });
  const size_t shape[3] = {size_t(image.height), size_t(image.width), 3};
  return nb::ndarray<nb::numpy, uint8_t>(owned->data(), 3, shape, owner).cast();
}

// layers: (channel names, float32 array of (H, W) or (H, W, channels)) pairs.
void writeExrFile(const std::string& path, const FloatArray& array,
                  const std::vector<std::pair<std::vector<std::string>, FloatArray>>& layers,
                  const Metadata& metadata) {
  const Image image = imageFrom(array, "image");
  std::vector<ImageLayer> out;
  for (const auto& [channels, pixels] : layers) {
    const size_t expected = size_t(image.width) * size_t(image.height) * channels.size();
    if (pixels.size() != expected || pixels.shape(0) != size_t(image.height) ||
        pixels.shape(1) != size_t(image.width))
      throw nb::value_error(("layer " + channels.front() + ": its shape differs from the image's").c_str());
    out.push_back({channels, std::vector<float>(pixels.data(), pixels.data() + expected)});
  }
  nb::gil_scoped_release release;
  writeExr(path, image, out, metadata);
}

// (width, height, {channel: flat float32 array}, {attribute: value})
nb::tuple readExrFile(const std::string& path) {
  ExrChannels exr;
  {
    nb::gil_scoped_release release;
    exr = readExrChannels(path);
  }
  nb::dict channels, metadata;
  for (auto& [name, pixels] : exr.channels)
    channels[name.c_str()] = pixelArray(std::move(pixels), exr.height, exr.width, 1);
  for (const auto& [key, value] : exr.metadata) metadata[key.c_str()] = value;
  return nb::make_tuple(exr.width, exr.height, channels, metadata);
}

SceneHandle loadFile(const std::string& path, int camera, const std::string& variant) {
  LoadOptions options;
  options.camera = camera;
  options.variant = variant;
  nb::gil_scoped_release release;
  return SceneHandle::fromFile(path, options);
}

SceneHandle loadDocument(nb::handle document, const std::string& name) {
  nlohmann::json json = toJson(document, "");
  nb::gil_scoped_release release;
  return SceneHandle::fromDocument(std::move(json), name);
}

// Edits take the GIL's protection against a render of the same scene in another thread: the
// patch is converted first (which may run Python code, and so switch threads), then `busy` checked
// and the scene changed without the GIL ever being let go in between.
template <class F>
void edit(SceneHandle& h, F&& f) {
  if (h.busy) throw std::runtime_error("this scene is rendering in another thread; edit it afterwards");
  f();
}

}  // namespace

NB_MODULE(_ember, m) {
  m.doc() = "Ember's native module; use the `ember` package (docs/python.md)";
  static nb::exception<InputError> sceneError(m, "SceneError", PyExc_ValueError);

  nb::class_<SceneHandle>(m, "SceneHandle")
      .def_prop_ro("name", &SceneHandle::name)
      .def_prop_ro("is_json", &SceneHandle::isJson)
      .def_prop_ro("width", [](const SceneHandle& h) { return h.scene().settings.width; })
      .def_prop_ro("height", [](const SceneHandle& h) { return h.scene().settings.height; })
      .def_prop_ro("document", [](const SceneHandle& h) { return fromJson(h.document()); })
      .def("info", [](const SceneHandle& h) { return fromJson(sceneSummary(h.scene())); })
      .def(
          "render",
          [](SceneHandle& h, std::optional<int> spp, std::optional<uint64_t> seed, int threads,
             uint64_t firstSample, std::optional<std::string> strategy, std::vector<std::string> aovs,
             nb::object progress, int passSpp) {
            RenderRequest r{spp, seed, threads, firstSample, strategy, std::move(aovs), progress, passSpp};
            return renderScene(h, r);
          },
          "spp"_a.none(), "seed"_a.none(), "threads"_a, "first_sample"_a, "strategy"_a.none(), "aovs"_a,
          "progress"_a.none(), "pass_spp"_a)
      .def("set_camera",
           [](SceneHandle& h, nb::dict patch) {
             const nlohmann::json p = toJson(patch, "camera");
             edit(h, [&] { h.setCamera(p); });
           })
      .def("set_material",
           [](SceneHandle& h, const std::string& name, nb::dict patch) {
             const nlohmann::json p = toJson(patch, "materials." + name);
             edit(h, [&] { h.setMaterial(name, p); });
           })
      .def("set_shape",
           [](SceneHandle& h, SceneHandle::Key key, nb::dict patch) {
             const nlohmann::json p = toJson(patch, "shapes");
             edit(h, [&] { h.setShape(key, p); });
           })
      .def("set_background",
           [](SceneHandle& h, nb::handle value) {
             const nlohmann::json v = toJson(value, "render.background");
             edit(h, [&] { h.setBackground(v); });
           })
      .def("set_light", [](SceneHandle& h, SceneHandle::Key key, nb::dict patch) {
        const nlohmann::json p = toJson(patch, "lights");
        edit(h, [&] { h.setLight(key, p); });
      });

  m.def("load_file", &loadFile, "path"_a, "camera"_a, "variant"_a);
  m.def("load_document", &loadDocument, "document"_a, "name"_a);
  m.def("compare", &compare, "image"_a, "reference"_a, "variance"_a.none(), "ref_stderr"_a.none(),
        "max_relmse"_a.none(), "max_flip"_a.none(), "alpha"_a, "variance_pool"_a, "ppd"_a, "ldr"_a);
  m.def("tonemap", &tonemap, "image"_a, "key"_a, "white"_a.none());
  m.def("write_exr", &writeExrFile, "path"_a, "image"_a, "layers"_a, "metadata"_a);
  m.def("read_exr", &readExrFile, "path"_a);
}

// The `ember._ember` module: a scene loaded by the same loader as `ember render`, rendered by the
// same render() and wave driver into a numpy array that owns the film's mean (no second copy).
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include <memory>
#include <optional>
#include <string>

namespace nb = nanobind;
using namespace nb::literals;

namespace {

// A built scene, as `ember render` builds it from the same file.
struct PyScene {
  std::unique_ptr<ember::Scene> scene;
};

PyScene load(const std::string& path) {
  PyScene s;
  s.scene = std::make_unique<ember::Scene>(ember::loadScene(path));
  s.scene->build();
  return s;
}

// The scene's image at spp samples per pixel: the mean of the film render() fills, as `ember render`
// fills it with the same settings.
nb::ndarray<nb::numpy, float, nb::shape<-1, -1, 3>> render(PyScene& self, std::optional<int> spp,
                                                           std::optional<uint64_t> seed, int threads,
                                                           uint64_t firstSample) {
  const ember::Scene& scene = *self.scene;
  const ember::RenderSettings& s = scene.settings;
  ember::RenderOptions options;
  options.spp = spp.value_or(s.spp);
  options.seed = seed.value_or(s.seed);
  options.threads = threads;
  options.firstSample = firstSample;
  options.sampler = s.sampler;
  if (options.spp < 1) throw nb::value_error("spp must be at least 1");
  const std::unique_ptr<ember::Integrator> integrator = ember::makeIntegrator(s, ember::Kernel::Wave);
  auto* pixels = new std::vector<float>();
  {
    nb::gil_scoped_release release;
    ember::Film film(s.width, s.height);
    ember::render(scene, *integrator, options, film);
    *pixels = film.mean().rgb;
  }
  nb::capsule owner(pixels, [](void* p) noexcept { delete static_cast<std::vector<float>*>(p); });
  return nb::ndarray<nb::numpy, float, nb::shape<-1, -1, 3>>(pixels->data(),
                                                             {size_t(s.height), size_t(s.width), 3}, owner);
}

}  // namespace

NB_MODULE(_ember, m) {
  m.doc() = "Ember's native module: load scenes and render them to numpy arrays";
  static nb::exception<ember::InputError> sceneError(m, "SceneError", PyExc_ValueError);
  nb::class_<PyScene>(m, "Scene", "A loaded, built scene (ember.load)")
      .def("render", &render, "spp"_a = nb::none(), "seed"_a = nb::none(), "threads"_a = 0,
           "first_sample"_a = 0,
           "Render to a float32 numpy array of shape (height, width, 3), linear radiance; spp and seed "
           "default "
           "to the scene's own")
      .def_prop_ro("width", [](const PyScene& s) { return s.scene->settings.width; })
      .def_prop_ro("height", [](const PyScene& s) { return s.scene->settings.height; });
  m.def("load", &load, "path"_a,
        "Load an Ember JSON scene or a glTF file; raises ember.SceneError naming the file and place");
}

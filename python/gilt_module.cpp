// `import gilt`: the Python front end. It calls the same entry points as the command line
// (api/methods.h, api/compare.h, radiosity/solver/solver.h) and hands back NumPy arrays and dicts.
//
// Every long call runs on a worker thread with the GIL released; the calling thread wakes every
// 50 ms to let Python look for signals, and a Ctrl-C there calls raytrace_core::util::request_stop(),
// which ends the run at its next work item with KeyboardInterrupt.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>

#include "api/compare.h"
#include "api/methods.h"
#include "api/statistics.h"
#include "radiosity/solver/budget.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/util/parallel.h"

namespace py = pybind11;
namespace rc = gilt::raytrace_core;
namespace api = gilt::api;
namespace radiosity = gilt::radiosity;

namespace {

/// Runs `work` on a worker thread without the GIL, checking for Python signals meanwhile.
template <class Work>
auto run_interruptible(Work&& work) -> decltype(work()) {
  using Result = decltype(work());
  rc::util::clear_stop();
  std::optional<Result> result;
  std::exception_ptr error;
  bool done = false, signalled = false;
  std::mutex mutex;
  std::condition_variable finished;
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        result.emplace(work());
      } catch (...) {
        error = std::current_exception();
      }
      const std::lock_guard lock(mutex);
      done = true;
      finished.notify_one();
    });
    std::unique_lock lock(mutex);
    while (!done) {
      finished.wait_for(lock, std::chrono::milliseconds(50));
      if (done || signalled) continue;
      lock.unlock();
      {
        py::gil_scoped_acquire acquire;
        // A handler that raised (KeyboardInterrupt) leaves its exception set: stop the run and
        // raise it once the worker has ended.
        if (PyErr_CheckSignals() != 0) signalled = true, rc::util::request_stop();
      }
      lock.lock();
    }
    lock.unlock();
    worker.join();
  }
  rc::util::clear_stop();
  if (signalled) throw py::error_already_set();
  if (error) std::rethrow_exception(error);
  return std::move(*result);
}

/// A JSON value as the Python object json.loads would make of it.
py::object to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

py::tuple to_tuple(const rc::Vec3& v) { return py::make_tuple(v.x, v.y, v.z); }

rc::Vec3 to_vec3(const py::sequence& s, const char* name) {
  if (py::len(s) != 3) throw rc::InputError(std::string(name) + ": expected three numbers");
  const rc::Vec3 v(s[0].cast<float>(), s[1].cast<float>(), s[2].cast<float>());
  if (!rc::is_finite(v)) throw rc::InputError(std::string(name) + ": coordinates must be finite");
  return v;
}

/// An H × W × 3 float32 array of linear RGB.
py::array_t<float> to_array(const rc::render::Film& film) {
  const std::vector<rc::Rgb> pixels = film.pixels();
  py::array_t<float> out({py::ssize_t(film.height()), py::ssize_t(film.width()), py::ssize_t(3)});
  float* data = out.mutable_data();
  for (size_t i = 0; i < pixels.size(); ++i) data[3 * i] = pixels[i].r, data[3 * i + 1] = pixels[i].g, data[3 * i + 2] = pixels[i].b;
  return out;
}

/// An N × 3 float32 array of per-vertex colours or positions.
template <class T>
py::array_t<float> rows_of_three(const std::vector<T>& values) {
  py::array_t<float> out({py::ssize_t(values.size()), py::ssize_t(3)});
  float* data = out.mutable_data();
  for (size_t i = 0; i < values.size(); ++i)
    for (int c = 0; c < 3; ++c) data[3 * i + c] = values[i][c];
  return out;
}

/// A loaded, committed scene; the camera may be replaced before rendering.
struct PyScene {
  rc::scene::Scene scene;
  std::string name;
};

PyScene load(const std::string& path, std::optional<std::string> env, float env_scale, float env_rotate,
             std::optional<std::vector<float>> sun, std::optional<float> sky, std::optional<py::object> camera) {
  rc::io::ExtraLighting extra;
  if (env) extra.env_file = *env;
  extra.env_scale = env_scale, extra.env_rotate_degrees = env_rotate;
  if (sun) {
    if (sun->size() < 2 || sun->size() > 3)
      throw rc::InputError("sun: expected (elevation, azimuth) or (elevation, azimuth, irradiance)");
    extra.sun = true;
    extra.sun_elevation_degrees = (*sun)[0], extra.sun_azimuth_degrees = (*sun)[1];
    if (sun->size() == 3) extra.sun_irradiance = (*sun)[2];
  }
  if (sky) {
    if (!(*sky >= 1.0f && *sky <= 64.0f)) throw rc::InputError("sky: the turbidity must be from 1 to 64");
    extra.sky_turbidity = *sky;
  }
  PyScene s{rc::io::load_scene(path, extra), path};
  if (camera && !camera->is_none()) rc::io::select_camera(s.scene, py::str(*camera).cast<std::string>());
  return s;
}

rc::scene::Camera make_camera(py::sequence look_from, py::sequence look_at, py::sequence up, float vfov, float aperture,
                       float focus_distance, float ortho_height) {
  rc::scene::Camera c;
  c.look_from = to_vec3(look_from, "look_from"), c.look_at = to_vec3(look_at, "look_at"), c.up = to_vec3(up, "up");
  c.vfov_degrees = vfov, c.aperture_radius = aperture, c.focus_distance = focus_distance;
  c.orthographic = ortho_height > 0.0f, c.ortho_height = ortho_height;
  c.validate();
  return c;
}

py::tuple render(PyScene& s, const std::string& method, std::optional<int> spp, std::optional<double> time,
                 std::optional<int> width, std::optional<int> height, uint64_t seed, int threads,
                 const std::string& sampler, const std::string& light_sampler, int max_depth,
                 const api::PhotonOptions& photon, std::optional<int> elements, const std::string& radiosity_view) {
  rc::render::RenderSettings settings;
  const auto [w, h] = api::image_size(s.scene, width, height);
  settings.width = w, settings.height = h;
  if (spp && time) throw rc::InputError("give spp or time, not both");
  settings.spp = spp.value_or(s.scene.render.spp);
  if (settings.spp < 1) throw rc::InputError("spp: must be at least 1");
  if (time) {
    if (!(*time > 0.0 && *time <= 86400.0)) throw rc::InputError("time: a positive number of seconds up to a day");
    settings.time_limit = *time;
  }
  if (threads < 0) throw rc::InputError("threads: 0 (all) or more");
  if (max_depth < 0) throw rc::InputError("max_depth: 0 (the method's default) or more");
  settings.seed = seed, settings.threads = threads, settings.progress = false;
  settings.sampler = rc::render::parse_sampler(sampler);
  s.scene.set_light_sampling(rc::scene::parse_light_sampling(light_sampler));
  const rc::scene::Camera camera = s.scene.effective_camera(float(settings.width) / float(settings.height));
  api::MethodOptions options;
  options.max_depth = max_depth;
  photon.apply(options);
  if (elements) {
    if (*elements < 1) throw rc::InputError("elements: must be at least 1");
    options.solver.mesh.elements = *elements;
  }
  if (radiosity_view != "two-pass" && radiosity_view != "mesh")
    throw rc::InputError("radiosity_view " + radiosity_view + ": expected two-pass or mesh");
  options.radiosity_view = radiosity_view == "mesh" ? radiosity::bake::ViewMode::mesh : radiosity::bake::ViewMode::two_pass;
  const api::MethodResult result =
      run_interruptible([&] { return api::run_method(s.scene, camera, method, settings, options); });
  nlohmann::json stats = api::run_statistics(s.scene, method, settings, result);
  stats["scene"] = s.name;
  return py::make_tuple(to_array(result.film), to_python(stats));
}

py::dict solve_radiosity(PyScene& s, std::optional<int> elements, std::optional<double> time, double tolerance,
                         const std::string& solver, uint64_t seed, int threads) {
  radiosity::solver::SolverSettings settings;
  if (elements) {
    if (*elements < 1) throw rc::InputError("elements: must be at least 1");
    settings.mesh.elements = *elements;
  }
  if (time) {
    if (!(*time > 0.0 && *time <= 86400.0)) throw rc::InputError("time: a positive number of seconds up to a day");
    settings.time_limit = *time;
  }
  if (!(tolerance > 0.0 && tolerance < 1.0)) throw rc::InputError("tolerance: from 0 to 1, exclusive");
  if (solver == "auto") settings.solver = radiosity::solver::SolverKind::automatic;
  else if (solver == "progressive") settings.solver = radiosity::solver::SolverKind::progressive;
  else if (solver == "hierarchical") settings.solver = radiosity::solver::SolverKind::hierarchical;
  else throw rc::InputError("solver " + solver + ": expected auto, progressive or hierarchical");
  if (threads < 0) throw rc::InputError("threads: 0 (all) or more");
  settings.tolerance = tolerance, settings.seed = seed, settings.threads = threads, settings.progress = false;
  // Under a time budget a mesh left to gilt is sized to fit it, as in `gilt radiosity --time`.
  const radiosity::solver::Solution sol = run_interruptible([&] {
    return time ? radiosity::solver::solve_within(s.scene, settings, *time) : radiosity::solver::solve(s.scene, settings);
  });

  py::array_t<uint32_t> indices({py::ssize_t(sol.mesh.element_count()), py::ssize_t(3)});
  uint32_t* data = indices.mutable_data();
  for (size_t e = 0; e < sol.mesh.element_count(); ++e)
    for (int c = 0; c < 3; ++c) data[3 * e + c] = sol.mesh.elements[e][c];
  nlohmann::json stats = api::solution_statistics(sol, settings);
  stats["scene"] = s.name;
  stats["warnings"] = sol.mesh_report.warnings;
  py::dict out;
  out["positions"] = rows_of_three(sol.mesh.positions);
  out["normals"] = rows_of_three(sol.mesh.normals);
  out["indices"] = indices;
  out["radiosity"] = rows_of_three(sol.vertex_radiosity);
  out["irradiance"] = rows_of_three(sol.vertex_irradiance);
  out["stats"] = to_python(stats);
  return out;
}

py::list compare(PyScene& s, std::vector<std::string> methods, std::vector<double> budgets, int width, int height,
                 std::optional<std::string> reference, double reference_time, const std::string& reference_method,
                 uint64_t seed, int threads, const std::string& sampler, const std::string& light_sampler,
                 std::optional<std::string> output) {
  api::CompareSettings settings;
  settings.methods = std::move(methods), settings.budgets = std::move(budgets);
  settings.width = width, settings.height = height;
  if (reference) settings.reference_file = *reference;
  settings.reference_time = reference_time, settings.reference_method = reference_method;
  settings.seed = seed, settings.threads = threads, settings.sampler = sampler, settings.light_sampler = light_sampler;
  settings.progress = false;
  if (output) settings.output = *output;
  settings.scene_name = s.name;
  api::check_settings(settings);
  const api::Report report = run_interruptible([&] { return api::compare_methods(s.scene, settings); });
  py::list out;
  for (const api::ReportEntry& e : report.entries) out.append(to_python(api::entry_json(e)));
  return out;
}

}  // namespace

PYBIND11_MODULE(gilt, m) {
  m.doc() = "gilt: global illumination (path tracing, radiosity, photon mapping) from Python";
  m.attr("__version__") = "0.1.0";
  m.attr("METHODS") = api::kMethods;

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const rc::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const rc::Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });

  py::class_<rc::scene::Camera>(m, "Camera", "A pinhole or thin-lens camera")
      .def(py::init(&make_camera), py::arg("look_from"), py::arg("look_at"), py::arg("up") = py::make_tuple(0, 1, 0),
           py::arg("vfov") = 40.0f, py::arg("aperture") = 0.0f, py::arg("focus_distance") = 0.0f,
           py::arg("ortho_height") = 0.0f,
           "A camera at look_from looking at look_at. vfov in degrees; aperture (lens radius) and\n"
           "focus_distance for depth of field; ortho_height > 0 makes it orthographic, the film that many\n"
           "scene units high.")
      .def_property_readonly("look_from", [](const rc::scene::Camera& c) { return to_tuple(c.look_from); })
      .def_property_readonly("look_at", [](const rc::scene::Camera& c) { return to_tuple(c.look_at); })
      .def_property_readonly("up", [](const rc::scene::Camera& c) { return to_tuple(c.up); })
      .def_readonly("vfov", &rc::scene::Camera::vfov_degrees)
      .def_readonly("orthographic", &rc::scene::Camera::orthographic)
      .def_readonly("ortho_height", &rc::scene::Camera::ortho_height)
      .def("__repr__", [](const rc::scene::Camera& c) {
        return "gilt.Camera(look_from=" + py::repr(to_tuple(c.look_from)).cast<std::string>() +
               ", look_at=" + py::repr(to_tuple(c.look_at)).cast<std::string>() +
               ", vfov=" + std::to_string(c.vfov_degrees) + ")";
      });

  py::class_<PyScene>(m, "Scene", "A scene loaded from a file (.obj, .gltf, .glb, .ply, .json) or a built-in name")
      .def(py::init(&load), py::arg("path"), py::kw_only(), py::arg("env") = py::none(), py::arg("env_scale") = 1.0f,
           py::arg("env_rotate") = 0.0f, py::arg("sun") = py::none(), py::arg("sky") = py::none(),
           py::arg("camera") = py::none(),
           "Loads a scene. env: an .exr or .hdr environment; sun: (elevation, azimuth[, irradiance]) in "
           "degrees; sky: Preetham turbidity; camera: one of the file's cameras by number or name")
      .def_property_readonly("triangles", [](const PyScene& s) { return s.scene.triangle_count(); })
      .def_property_readonly("lights", [](const PyScene& s) { return s.scene.lights().size(); })
      .def_property_readonly("warnings", [](const PyScene& s) { return s.scene.warnings; })
      .def_property_readonly("cameras",
                             [](const PyScene& s) {
                               std::vector<std::string> names;
                               for (const auto& c : s.scene.cameras) names.push_back(c.name);
                               return names;
                             })
      .def_property_readonly("size", [](const PyScene& s) { return py::make_tuple(s.scene.render.width, s.scene.render.height); })
      .def_property(
          "camera", [](const PyScene& s) { return s.scene.effective_camera(); },
          [](PyScene& s, const rc::scene::Camera& c) {
            c.validate();
            s.scene.camera = c;
          },
          "The camera renders use: the file's, a framing of the scene's bounds, or one set here")
      .def("__repr__", [](const PyScene& s) {
        return "<gilt.Scene " + s.name + ": " + std::to_string(s.scene.triangle_count()) + " triangles, " +
               std::to_string(s.scene.lights().size()) + " lights>";
      });

  m.def(
      "render",
      [](PyScene& s, const std::string& method, std::optional<int> spp, std::optional<double> time,
         std::optional<int> width, std::optional<int> height, uint64_t seed, int threads, const std::string& sampler,
         const std::string& light_sampler, int max_depth, std::optional<uint64_t> photons,
         std::optional<uint64_t> caustic_photons, int k, float radius, int gather_rays, float alpha,
         std::optional<int> elements, const std::string& radiosity_view) {
        const api::PhotonOptions photon{photons, caustic_photons, k, radius, gather_rays, alpha};
        return render(s, method, spp, time, width, height, seed, threads, sampler, light_sampler, max_depth, photon,
                      elements, radiosity_view);
      },
      py::arg("scene"), py::kw_only(), py::arg("method") = "path", py::arg("spp") = py::none(),
      py::arg("time") = py::none(), py::arg("width") = py::none(), py::arg("height") = py::none(), py::arg("seed") = 0,
      py::arg("threads") = 0, py::arg("sampler") = "sobol", py::arg("light_sampler") = "bvh", py::arg("max_depth") = 0,
      py::arg("photons") = py::none(), py::arg("caustic_photons") = py::none(), py::arg("k") = 50,
      py::arg("radius") = 0.0f, py::arg("gather_rays") = 1, py::arg("alpha") = 2.0f / 3.0f,
      py::arg("elements") = py::none(), py::arg("radiosity_view") = "two-pass",
      "Renders with one of gilt.METHODS for spp samples per pixel or time seconds (preparation included).\n"
      "photons, caustic_photons, k, radius, gather_rays, alpha: the photon methods' options, elements\n"
      "and radiosity_view the radiosity method's, as on the command line. Returns (image, stats): an\n"
      "H x W x 3 float32 array of linear RGB and the statistics of `gilt render --json` as a dict. The\n"
      "same arguments give the same image, whatever `threads`.");
  m.def("radiosity", &solve_radiosity, py::arg("scene"), py::kw_only(), py::arg("elements") = py::none(),
        py::arg("time") = py::none(), py::arg("tolerance") = 1e-3, py::arg("solver") = "auto", py::arg("seed") = 0,
        py::arg("threads") = 0,
        "Solves radiosity. Returns a dict: positions (V x 3), normals (V x 3), indices (F x 3, uint32,\n"
        "counter-clockwise from the front), radiosity and irradiance per vertex (V x 3, W/m^2), and\n"
        "stats, those of `gilt radiosity --json`.");
  m.def("compare", &compare, py::arg("scene"), py::kw_only(), py::arg("methods") = api::kMethods,
        py::arg("budgets") = std::vector<double>{1, 2, 4, 8, 16}, py::arg("width") = 256, py::arg("height") = 256,
        py::arg("reference") = py::none(), py::arg("reference_time") = 60.0, py::arg("reference_method") = "auto",
        py::arg("seed") = 0, py::arg("threads") = 0, py::arg("sampler") = "sobol", py::arg("light_sampler") = "bvh",
        py::arg("output") = py::none(),
        "Every method at every time budget against one reference, as `gilt compare`. Returns the\n"
        "metrics as a list of dicts (one per method and budget, the entries of metrics.json); with\n"
        "output, also writes the report folder.");
}

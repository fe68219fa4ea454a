// `gilt compare SCENE -o REPORT_DIR`: every method at every time budget on the same camera,
// each image's error against a reference, and the report (cli/report.h).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/methods.h"
#include "cli/report.h"
#include "raytrace_core/error.h"
#include "raytrace_core/io/image_error.h"
#include "raytrace_core/io/image_io.h"
#include "raytrace_core/path_tracer.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/io/staged_file.h"
#include "photonmap/photon_map.h"

namespace gilt::cli {
namespace rc = gilt::raytrace_core;
namespace fs = std::filesystem;
namespace {

struct CompareOptions {
  std::string scene, output;
  rc::ExtraLighting lighting;
  std::string methods = "path,photon,sppm,radiosity,whitted";
  std::string budgets = "1,2,4,8,16";
  std::string reference;
  std::string reference_method = "auto";  ///< path, sppm, or auto (sppm where caustics are)
  std::string camera;  ///< --camera N|NAME; empty: the scene's own
  double reference_time = 60.0;
  int width = 256, height = 256;
  uint64_t seed = 0;
  std::string sampler = "sobol";  ///< the methods' samplers; the reference always uses Sobol
  std::string light_sampler = "bvh";  ///< the methods' choice of light; the reference always uses the BVH
  int threads = 0;
  float exposure = 0.0f;
  bool quiet = false;
};

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// FNV-1a over raw bytes, for the reference cache key.
struct Hasher {
  uint64_t h = 0xcbf29ce484222325ull;
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  }
  template <class T>
  void value(const T& v) { bytes(&v, sizeof v); }
  template <class T>
  void vector(const std::vector<T>& v) { value(v.size()), bytes(v.data(), v.size() * sizeof(T)); }
};

/// A key for the loaded scene's content (geometry, materials, lights), the camera and the
/// reference's settings: a second compare of the same thing reuses the reference.
std::string reference_key(const rc::Scene& scene, const rc::Camera& camera, const CompareOptions& o,
                          const std::string& method) {
  Hasher k;
  const std::string version = "gilt-reference-5";  // 4: halves drawn with the Sobol sampler; 5: the light BVH
  k.bytes(version.data(), version.size());
  k.bytes(method.data(), method.size());
  for (const rc::TriangleMesh& m : scene.meshes) k.vector(m.positions), k.vector(m.indices), k.vector(m.normals), k.value(m.material);
  for (const rc::Sphere& s : scene.spheres) k.value(s);
  for (const rc::Material& m : scene.materials) {
    k.value(m.kind), k.value(m.albedo), k.value(m.emission), k.value(m.specular), k.value(m.exponent), k.value(m.ior);
    k.value(m.absorption), k.value(m.two_sided_emission), k.value(m.metallic), k.value(m.roughness);
    k.value(m.transmission_tint), k.value(m.thin_walled);
  }
  for (const rc::Light& l : scene.punctual_lights) {
    k.value(l.kind), k.value(l.position), k.value(l.direction), k.value(l.intensity), k.value(l.irradiance);
    k.value(l.radiance), k.value(l.cos_inner), k.value(l.cos_outer);
    if (l.map) k.value(l.map->width()), k.value(l.map->rotate_degrees()), k.vector(l.map->texels());
  }
  // Field by field: Camera has padding after its bool, whose bytes are not part of its value.
  k.value(camera.look_from), k.value(camera.look_at), k.value(camera.up), k.value(camera.vfov_degrees);
  k.value(camera.aperture_radius), k.value(camera.focus_distance), k.value(uint8_t(camera.orthographic));
  k.value(camera.ortho_height);
  k.value(o.width), k.value(o.height), k.value(o.reference_time), k.value(o.seed);
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(k.h));
  return text;
}

fs::path cache_folder() {
  if (const char* dir = std::getenv("GILT_CACHE_DIR"); dir && *dir) return fs::path(dir);
  if (const char* dir = std::getenv("XDG_CACHE_HOME"); dir && *dir) return fs::path(dir) / "gilt";
  if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "gilt";
  return {};
}

struct Reference {
  std::vector<rc::Rgb> pixels;
  /// Per pixel and channel, the variance of `pixels` estimated from the two halves (empty for a
  /// --reference file, whose noise is unknown).
  std::vector<rc::Rgb> variance;
  std::string description;
  double noise = 0.0;
};

Reference make_reference(const rc::Scene& scene, const rc::Camera& camera, const CompareOptions& o) {
  Reference ref;
  if (!o.reference.empty()) {
    const rc::Image image = rc::read_image(o.reference);
    if (image.width != o.width || image.height != o.height)
      throw rc::InputError("--reference " + o.reference + ": " + std::to_string(image.width) + "x" +
                           std::to_string(image.height) + " does not match the report's " + std::to_string(o.width) +
                           "x" + std::to_string(o.height) + " (set --width and --height)");
    for (const rc::Rgb& p : image.pixels)
      if (!p.is_finite()) throw rc::InputError("--reference " + o.reference + ": has NaN or infinite pixels");
    ref.pixels = image.pixels;
    ref.description = "the file " + o.reference;
    return ref;
  }
  // The method: SPPM where light reaches diffuse surfaces through mirrors or glass (caustics),
  // which a path tracer finds only by chance (and never from a point light or the sun), the path
  // tracer elsewhere.
  std::string method = o.reference_method, why;
  if (method == "auto") {
    const photonmap::MapNeeds needs = photonmap::map_needs(scene);
    method = needs.caustic ? "sppm" : "path";
    why = needs.caustic ? ", chosen for the scene's caustics (light through mirrors or glass onto diffuse surfaces)"
                        : ", chosen as the scene has no caustics";
  }
  const fs::path folder = cache_folder();
  const std::string key = reference_key(scene, camera, o, method);
  const fs::path exr = folder / ("reference-" + key + ".exr"), meta = folder / ("reference-" + key + ".json");
  const fs::path variance_exr = folder / ("reference-" + key + "-variance.exr");
  if (!folder.empty() && fs::exists(exr) && fs::exists(meta) && fs::exists(variance_exr)) {
    try {
      const rc::Image image = rc::read_image(exr.string()), variance = rc::read_image(variance_exr.string());
      const nlohmann::json j = nlohmann::json::parse(std::ifstream(meta));
      if (image.width == o.width && image.height == o.height && variance.width == o.width &&
          variance.height == o.height) {
        ref.pixels = image.pixels;
        ref.variance = variance.pixels;
        ref.noise = j.at("noise").get<double>();
        ref.description = j.at("description").get<std::string>() + " (cached in " + exr.string() + ")";
        return ref;
      }
    } catch (const std::exception&) {
      // A damaged cache entry is rendered again below.
    }
  }
  // Two independent halves: their difference measures the reference's own noise (for SPPM its
  // noise alone: the blur of its shrinking radius is the same in both halves).
  rc::RenderSettings s;
  s.width = o.width, s.height = o.height, s.threads = o.threads, s.progress = !o.quiet;
  s.time_limit = o.reference_time / 2.0;
  const rc::PathSettings path;
  auto half = [&](uint64_t seed, rc::RenderStats& stats) {
    s.seed = seed;
    if (method == "sppm") {
      MethodResult result = run_method(scene, camera, method, s, MethodOptions{});
      stats = result.stats;
      return result.film.pixels();
    }
    return rc::render_image(scene, camera, s,
                            [&](const rc::Ray& ray, rc::SampleContext& ctx) { return rc::path_radiance(scene, ray, ctx, path); },
                            &stats)
        .pixels();
  };
  if (!o.quiet) std::fprintf(stderr, "gilt compare: %s reference, %.0f s\n", method.c_str(), o.reference_time);
  rc::RenderStats sa, sb;
  const std::vector<rc::Rgb> a = half(o.seed ^ 0x5eed0001ull, sa), b = half(o.seed ^ 0x5eed0002ull, sb);
  const float wa = float(sa.spp) / float(sa.spp + sb.spp);
  ref.pixels.resize(a.size());
  for (size_t i = 0; i < a.size(); ++i) ref.pixels[i] = a[i] * wa + b[i] * (1.0f - wa);
  // Each half carries about √2 times the noise of the mean: halve their mutual error.
  ref.noise = 0.5 * rc::mean_relative_error(a, b);
  // Its variance per pixel, when both halves got samples (a budget too short for one leaves the
  // noise unknown, and the errors uncorrected).
  if (wa > 0.0f && wa < 1.0f) ref.variance = rc::reference_variance(a, b, wa);
  ref.description = (method == "sppm" ? "SPPM, " + std::to_string(sa.spp + sb.spp) + " iterations in "
                                       : "path tracer, " + std::to_string(sa.spp + sb.spp) + " spp in ") +
                    std::to_string(int(std::lround(sa.seconds + sb.seconds))) + " s" + why;
  if (!folder.empty()) {
    std::error_code ec;
    fs::create_directories(folder, ec);
    try {
      rc::write_image(exr.string(), rc::Image{o.width, o.height, ref.pixels});
      if (!ref.variance.empty()) rc::write_image(variance_exr.string(), rc::Image{o.width, o.height, ref.variance});
      rc::StagedFile m(meta, nlohmann::json{{"noise", ref.noise}, {"description", ref.description}}.dump());
      m.commit();
    } catch (const std::exception& e) {
      std::cerr << "gilt: warning: could not cache the reference in " << folder.string() << ": " << e.what() << "\n";
    }
  }
  return ref;
}

void fill_errors(ReportEntry& e, const std::vector<rc::Rgb>& image, const Reference& ref) {
  const rc::ImageError error = rc::image_error(image, ref.pixels, ref.variance);
  e.rmse = error.rmse, e.relmse = error.relmse, e.mae = error.mae, e.mre = error.mean_relative;
  e.mean_ratio = error.mean_ratio;
  e.relmse_stderr = error.relmse_stderr;
  e.rmse_measured = error.rmse_measured, e.relmse_measured = error.relmse_measured;
}

/// Radiosity against the path tracer in object space: at up to 64 element centroids (where the
/// Gouraud value is the element's mean), outgoing radiance Le + ρE/π with E from 1,024
/// cosine-distributed path-traced samples, mean |L_radiosity − L_path| / (L_path + 0.01).
double object_space_error(const rc::Scene& scene, const radiosity::Solution& sol, uint64_t seed) {
  const size_t ne = sol.mesh.element_count();
  if (ne == 0) return 0.0;
  const size_t stride = std::max<size_t>(1, ne / 64);
  const rc::PathSettings path;
  double sum = 0.0;
  size_t count = 0;
  for (size_t e = 0; e < ne; e += stride) {
    const auto& el = sol.mesh.elements[e];
    const rc::Vec3 p = (sol.mesh.positions[el[0]] + sol.mesh.positions[el[1]] + sol.mesh.positions[el[2]]) / 3.0f;
    const rc::Vec3 n = sol.mesh.element_normal[e];
    rc::SurfacePoint at;
    at.p = p;
    at.p_error = rc::error_gamma(16) * rc::abs(p);
    at.ng = n;
    const rc::Frame frame = rc::Frame::from_normal(n);
    rc::Rgb incoming(0.0f);
    constexpr int kSamples = 1024;
    for (int i = 0; i < kSamples; ++i) {
      rc::SampleContext ctx{rc::Sampler(rc::Rng::for_item(seed, e, uint64_t(i))), 0};
      const rc::Vec3 w = frame.to_world(rc::sample_cosine_hemisphere(ctx.sampler.uniform2()));
      incoming += rc::path_radiance(scene, rc::spawn_ray(at, w), ctx, path);
    }
    const rc::Material& m = scene.materials[sol.mesh.element_material[e]];
    const rc::Rgb reference = m.emission + m.albedo * incoming / float(kSamples);  // ρ/π · π · mean L
    const rc::Rgb solved = sol.element_radiosity[e] * rc::kInvPi;
    for (int c = 0; c < 3; ++c) sum += std::abs(solved[c] - reference[c]) / (reference[c] + 0.01);
    ++count;
  }
  return sum / (3.0 * double(count));
}

void write_error_png(const fs::path& file, const std::vector<rc::Rgb>& image, const std::vector<rc::Rgb>& ref, int w,
                     int h) {
  // write_image encodes PNG as sRGB from linear values: hand it the linear values of the colours.
  std::vector<rc::Rgb> colours(image.size());
  auto linear = [](unsigned char v) {
    const float c = v / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
  };
  for (size_t i = 0; i < image.size(); ++i) {
    double e = 0.0;
    for (int c = 0; c < 3; ++c) e += std::abs(image[i][c] - ref[i][c]) / (ref[i][c] + 0.01);
    unsigned char rgb[3];
    error_colour(e / 3.0, rgb);
    colours[i] = rc::Rgb(linear(rgb[0]), linear(rgb[1]), linear(rgb[2]));
  }
  rc::write_image(file.string(), rc::Image{w, h, colours});
}

std::string budget_name(double b) {
  char text[32];
  std::snprintf(text, sizeof text, "%gs", b);
  return text;
}

void run_compare(const CompareOptions& o) {
  const std::vector<std::string> methods = split(o.methods);
  if (methods.empty()) throw rc::InputError("--methods: name at least one method");
  for (const std::string& m : methods)
    if (std::find(kMethods.begin(), kMethods.end(), m) == kMethods.end())
      throw rc::InputError("--methods: unknown method '" + m + "' (path, photon, sppm, radiosity, whitted)");
  std::vector<double> budgets;
  for (const std::string& b : split(o.budgets)) {
    char* end = nullptr;
    const double v = std::strtod(b.c_str(), &end);
    if (end == b.c_str() || *end != '\0' || !std::isfinite(v) || !(v > 0.0) || v > 86400.0)
      throw rc::InputError("--budgets: '" + b + "' is not a positive number of seconds");
    budgets.push_back(v);
  }
  if (budgets.empty()) throw rc::InputError("--budgets: give at least one budget");
  std::sort(budgets.begin(), budgets.end());
  budgets.erase(std::unique(budgets.begin(), budgets.end()), budgets.end());
  if (fs::exists(o.output) && !fs::is_directory(o.output))
    throw rc::InputError("-o " + o.output + ": exists and is not a folder");
  const fs::path parent = fs::absolute(o.output).parent_path();
  if (!fs::is_directory(parent)) throw rc::InputError("-o " + o.output + ": folder " + parent.string() + " does not exist");

  rc::Scene scene = rc::load_scene(o.scene, o.lighting);
  if (!o.camera.empty()) rc::select_camera(scene, o.camera);
  for (const std::string& w : scene.warnings) std::cerr << "gilt: warning: " << w << "\n";
  if (scene.lights().empty()) std::cerr << "gilt: warning: the scene has no lights: every image will be black\n";
  const rc::Camera camera = scene.effective_camera(float(o.width) / float(std::max(o.height, 1)));
  const Reference ref = make_reference(scene, camera, o);

  const fs::path folder = o.output;
  fs::create_directories(folder / "images");
  Report report;
  report.scene = o.scene;
  report.width = o.width, report.height = o.height, report.exposure = o.exposure;
  report.sampler = o.sampler;
  report.light_sampler = o.light_sampler;
  scene.set_light_sampling(rc::parse_light_sampling(o.light_sampler));  // after the reference
  report.reference = ref.description;
  report.reference_noise_mre = ref.noise;
  if (!ref.variance.empty()) {
    const rc::ImageError floor = rc::image_error(ref.pixels, ref.pixels, ref.variance);
    report.reference_relmse_floor = floor.relmse_floor;
    report.reference_mse_floor = floor.mse_floor;
  }
  report.methods = methods;
  report.budgets = budgets;
  report.reference_png = "images/reference.png";
  rc::write_image((folder / "images/reference.exr").string(), rc::Image{o.width, o.height, ref.pixels});
  rc::write_image((folder / report.reference_png).string(), rc::Image{o.width, o.height, ref.pixels}, o.exposure);

  rc::RenderSettings settings;
  settings.width = o.width, settings.height = o.height, settings.seed = o.seed, settings.threads = o.threads;
  settings.sampler = rc::parse_sampler(o.sampler);
  settings.progress = false;
  if (!o.quiet) std::printf("  method     budget s  actual s  relMSE      mean rel. error  mean / reference\n");
  for (double budget : budgets) {
    for (const std::string& m : methods) {
      settings.time_limit = budget;
      // Preparation scaled to the budget: fewer photons and elements when time is short.
      MethodOptions mo;
      const double share = std::min(1.0, budget / 8.0);
      mo.photon.photons.global_photons = mo.photon.photons.caustic_photons =
          std::max<uint64_t>(20000, uint64_t(200000 * share));
      mo.solver.mesh.elements = int(std::clamp(1000.0 * budget, 500.0, double(radiosity::kDefaultElements)));
      mo.solver.progress = false;
      const MethodResult result = run_method(scene, camera, m, settings, mo);
      const std::vector<rc::Rgb> pixels = result.film.pixels();
      ReportEntry e;
      e.method = m, e.budget = budget, e.seconds = result.stats.seconds, e.spp = result.stats.spp;
      if (result.photon) e.photons = result.photon->paths;
      if (result.sppm) e.photons = result.sppm->photons;
      if (result.solution) e.shots = result.solution->shots;
      e.notes = result.notes;
      fill_errors(e, pixels, ref);
      if (result.solution) e.object_space_error = object_space_error(scene, *result.solution, o.seed);
      const std::string stem = "images/" + m + "_" + budget_name(budget);
      e.image_exr = stem + ".exr", e.image_png = stem + ".png", e.error_png = stem + "_error.png";
      rc::write_image((folder / e.image_exr).string(), rc::Image{o.width, o.height, pixels});
      rc::write_image((folder / e.image_png).string(), rc::Image{o.width, o.height, pixels}, o.exposure);
      write_error_png(folder / e.error_png, pixels, ref.pixels, o.width, o.height);
      if (!o.quiet)
        std::printf("  %-9s  %8g  %8.2f  %-10.4g  %6.2f %%         %.4f\n", m.c_str(), budget, e.seconds, e.relmse,
                    100 * e.mre, e.mean_ratio);
      std::fflush(stdout);
      report.entries.push_back(e);
    }
  }
  write_report(folder, report);
  if (!o.quiet) std::printf("  report: %s\n", (folder / "index.html").string().c_str());
}

}  // namespace

std::function<void()> add_compare_command(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand("compare", "Render every method at every time budget and report error against time");
  cmd->add_option("scene", o->scene, "Scene file or built-in name")->required();
  add_lighting_options(*cmd, o->lighting);
  add_camera_option(*cmd, o->camera);
  cmd->add_option("-o,--output", o->output, "Report folder (index.html, metrics.json, metrics.csv, images/)")->required();
  cmd->add_option("--methods", o->methods, "Comma-separated methods (default path,photon,sppm,radiosity,whitted)");
  cmd->add_option("--budgets", o->budgets, "Comma-separated time budgets in seconds (default 1,2,4,8,16)");
  auto* ref = cmd->add_option("--reference", o->reference, "Reference image (.exr) instead of a path-traced one");
  cmd->add_option("--reference-time", o->reference_time,
                  "Seconds for the path-traced reference (default 60; cached by scene content and camera)")
      ->check(finite_number())
      ->check(CLI::Range(0.1, 1e6))
      ->excludes(ref);
  cmd->add_option("--reference-method", o->reference_method,
                  "How the reference is rendered: path, sppm, or auto (default: sppm when the scene has caustics)")
      ->check(CLI::IsMember({"auto", "path", "sppm"}))
      ->excludes(ref);
  cmd->add_option("--width", o->width, "Image width (default 256)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", o->height, "Image height (default 256)")->check(CLI::Range(1, 16384));
  cmd->add_option("--seed", o->seed, "Random seed")->check(unsigned_integer());
  cmd->add_option("--light-sampler", o->light_sampler,
                  "The methods' choice of light to sample: bvh (default) or power; the reference uses bvh")
      ->check(CLI::IsMember({"bvh", "power"}));
  cmd->add_option("--sampler", o->sampler, "The methods' camera samples: sobol (default) or independent")
      ->check(CLI::IsMember({"independent", "sobol"}));
  cmd->add_option("--threads", o->threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_option("--exposure", o->exposure, "Exposure of the PNG images (EV)")
      ->check(finite_number())
      ->check(CLI::Range(-64.0f, 64.0f));
  cmd->add_flag("-q,--quiet", o->quiet, "No progress or table");
  return [o] { run_compare(*o); };
}

}  // namespace gilt::cli

#include "api/compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/methods.h"
#include "photonmap/photon_map.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/image_error.h"
#include "raytrace_core/util/image_io.h"
#include "raytrace_core/util/staged_file.h"
#include "raytrace_core/render/path_tracer.h"

namespace gilt::api {
namespace rc = gilt::raytrace_core;
namespace fs = std::filesystem;
namespace {

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
std::string reference_key(const rc::scene::Scene& scene, const rc::scene::Camera& camera,
                          const CompareSettings& o, const std::string& method) {
  Hasher k;
  const std::string version = "gilt-reference-5";  // 4: halves drawn with the Sobol sampler; 5: the light BVH
  k.bytes(version.data(), version.size());
  k.bytes(method.data(), method.size());
  for (const rc::scene::TriangleMesh& m : scene.meshes) k.vector(m.positions), k.vector(m.indices), k.vector(m.normals), k.value(m.material);
  for (const rc::scene::Sphere& s : scene.spheres) k.value(s);
  for (const rc::scene::Material& m : scene.materials) {
    k.value(m.kind), k.value(m.albedo), k.value(m.emission), k.value(m.specular), k.value(m.exponent), k.value(m.ior);
    k.value(m.absorption), k.value(m.two_sided_emission), k.value(m.metallic), k.value(m.roughness);
    k.value(m.transmission_tint), k.value(m.thin_walled);
  }
  for (const rc::scene::Light& l : scene.punctual_lights) {
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

Reference make_reference(const rc::scene::Scene& scene, const rc::scene::Camera& camera,
                         const CompareSettings& o) {
  Reference ref;
  if (!o.reference_file.empty()) {
    const rc::util::Image image = rc::util::read_image(o.reference_file);
    if (image.width != o.width || image.height != o.height)
      throw rc::InputError("--reference " + o.reference_file + ": " + std::to_string(image.width) + "x" +
                           std::to_string(image.height) + " does not match the report's " + std::to_string(o.width) +
                           "x" + std::to_string(o.height) + " (set --width and --height)");
    for (const rc::Rgb& p : image.pixels)
      if (!p.is_finite()) throw rc::InputError("--reference " + o.reference_file + ": has NaN or infinite pixels");
    ref.pixels = image.pixels;
    ref.description = "the file " + o.reference_file;
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
      const rc::util::Image image = rc::util::read_image(exr.string()),
                            variance = rc::util::read_image(variance_exr.string());
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
  rc::render::RenderSettings s;
  s.width = o.width, s.height = o.height, s.threads = o.threads, s.progress = o.progress;
  s.time_limit = o.reference_time / 2.0;
  const rc::render::PathSettings path;
  auto half = [&](uint64_t seed, rc::render::RenderStats& stats) {
    s.seed = seed;
    if (method == "sppm") {
      MethodResult result = run_method(scene, camera, method, s, MethodOptions{});
      stats = result.stats;
      return result.film.pixels();
    }
    return rc::render::render_image(scene, camera, s,
                            [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, path); },
                            &stats)
        .pixels();
  };
  if (o.progress) std::fprintf(stderr, "gilt compare: %s reference, %.0f s\n", method.c_str(), o.reference_time);
  rc::render::RenderStats sa, sb;
  const std::vector<rc::Rgb> a = half(o.seed ^ 0x5eed0001ull, sa), b = half(o.seed ^ 0x5eed0002ull, sb);
  const float wa = float(sa.spp) / float(sa.spp + sb.spp);
  ref.pixels.resize(a.size());
  for (size_t i = 0; i < a.size(); ++i) ref.pixels[i] = a[i] * wa + b[i] * (1.0f - wa);
  // Each half carries about √2 times the noise of the mean: halve their mutual error.
  ref.noise = 0.5 * rc::util::mean_relative_error(a, b);
  // Its variance per pixel, when both halves got samples (a budget too short for one leaves the
  // noise unknown, and the errors uncorrected).
  if (wa > 0.0f && wa < 1.0f) ref.variance = rc::util::reference_variance(a, b, wa);
  ref.description = (method == "sppm" ? "SPPM, " + std::to_string(sa.spp + sb.spp) + " iterations in "
                                       : "path tracer, " + std::to_string(sa.spp + sb.spp) + " spp in ") +
                    std::to_string(int(std::lround(sa.seconds + sb.seconds))) + " s" + why;
  if (!folder.empty()) {
    std::error_code ec;
    fs::create_directories(folder, ec);
    try {
      rc::util::write_image(exr.string(), rc::util::Image{o.width, o.height, ref.pixels});
      if (!ref.variance.empty()) rc::util::write_image(variance_exr.string(), rc::util::Image{o.width, o.height, ref.variance});
      rc::util::StagedFile m(meta,
                             nlohmann::json{{"noise", ref.noise}, {"description", ref.description}}.dump());
      m.commit();
    } catch (const std::exception& e) {
      std::cerr << "gilt: warning: could not cache the reference in " << folder.string() << ": " << e.what() << "\n";
    }
  }
  return ref;
}

void fill_errors(ReportEntry& e, const std::vector<rc::Rgb>& image, const Reference& ref) {
  const rc::util::ImageError error = rc::util::image_error(image, ref.pixels, ref.variance);
  e.rmse = error.rmse, e.relmse = error.relmse, e.mae = error.mae, e.mre = error.mean_relative;
  e.mean_ratio = error.mean_ratio;
  e.relmse_stderr = error.relmse_stderr;
  e.rmse_measured = error.rmse_measured, e.relmse_measured = error.relmse_measured;
}

/// Radiosity against the path tracer in object space: at up to 64 element centroids (where the
/// Gouraud value is the element's mean), outgoing radiance Le + ρE/π with E from 1,024
/// cosine-distributed path-traced samples, mean |L_radiosity − L_path| / (L_path + 0.01).
double object_space_error(const rc::scene::Scene& scene, const radiosity::solver::Solution& sol,
                          uint64_t seed) {
  const size_t ne = sol.mesh.element_count();
  if (ne == 0) return 0.0;
  const size_t stride = std::max<size_t>(1, ne / 64);
  const rc::render::PathSettings path;
  double sum = 0.0;
  size_t count = 0;
  for (size_t e = 0; e < ne; e += stride) {
    const auto& el = sol.mesh.elements[e];
    const rc::Vec3 p = (sol.mesh.positions[el[0]] + sol.mesh.positions[el[1]] + sol.mesh.positions[el[2]]) / 3.0f;
    const rc::Vec3 n = sol.mesh.element_normal[e];
    rc::scene::SurfacePoint at;
    at.p = p;
    at.p_error = rc::scene::error_gamma(16) * rc::abs(p);
    at.ng = n;
    const rc::Frame frame = rc::Frame::from_normal(n);
    rc::Rgb incoming(0.0f);
    constexpr int kSamples = 1024;
    for (int i = 0; i < kSamples; ++i) {
      rc::render::SampleContext ctx{rc::render::Sampler(rc::util::Rng::for_item(seed, e, uint64_t(i))), 0};
      const rc::Vec3 w = frame.to_world(rc::util::sample_cosine_hemisphere(ctx.sampler.uniform2()));
      incoming += rc::render::path_radiance(scene, rc::scene::spawn_ray(at, w), ctx, path);
    }
    const rc::scene::Material& m = scene.materials[sol.mesh.element_material[e]];
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
  rc::util::write_image(file.string(), rc::util::Image{w, h, colours});
}

std::string budget_name(double b) {
  char text[32];
  std::snprintf(text, sizeof text, "%gs", b);
  return text;
}

/// Restores the scene's light sampling when the comparison ends, however it ends.
class LightSamplingScope {
 public:
  LightSamplingScope(rc::scene::Scene& scene, rc::scene::LightSampling mode)
      : scene_(scene), saved_(scene.light_sampler().mode()) {
    scene_.set_light_sampling(mode);
  }
  ~LightSamplingScope() { scene_.set_light_sampling(saved_); }
  LightSamplingScope(const LightSamplingScope&) = delete;
  LightSamplingScope& operator=(const LightSamplingScope&) = delete;

 private:
  rc::scene::Scene& scene_;
  rc::scene::LightSampling saved_;
};

/// A time budget gilt accepts: more than nothing, at most a day.
bool valid_budget(double seconds) { return std::isfinite(seconds) && seconds > 0.0 && seconds <= 86400.0; }

}  // namespace

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

std::vector<double> parse_budgets(const std::string& text, const std::string& flag) {
  std::vector<double> budgets;
  for (const std::string& b : split_list(text)) {
    char* end = nullptr;
    const double v = std::strtod(b.c_str(), &end);
    if (end == b.c_str() || *end != '\0' || !valid_budget(v))
      throw rc::InputError(flag + ": '" + b + "' is not a positive number of seconds");
    budgets.push_back(v);
  }
  if (budgets.empty()) throw rc::InputError(flag + ": give at least one budget");
  return budgets;
}

void check_settings(const CompareSettings& o) {
  if (o.methods.empty()) throw rc::InputError("--methods: name at least one method");
  for (const std::string& m : o.methods)
    if (std::find(kMethods.begin(), kMethods.end(), m) == kMethods.end())
      throw rc::InputError("--methods: unknown method '" + m + "' (path, photon, sppm, radiosity, whitted)");
  if (o.budgets.empty()) throw rc::InputError("--budgets: give at least one budget");
  for (double v : o.budgets)
    if (!valid_budget(v))
      throw rc::InputError("--budgets: " + std::to_string(v) + " is not a positive number of seconds up to a day");
  if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
    throw rc::InputError("--width and --height: from 1 to 16384 pixels");
  if (o.reference_file.empty()) {
    if (o.reference_method != "auto" && o.reference_method != "path" && o.reference_method != "sppm")
      throw rc::InputError("--reference-method " + o.reference_method + ": expected auto, path or sppm");
    if (!std::isfinite(o.reference_time) || !(o.reference_time >= 0.1) || o.reference_time > 1e6)
      throw rc::InputError("--reference-time: from 0.1 to 1e6 seconds");
  }
  rc::render::parse_sampler(o.sampler);
  rc::scene::parse_light_sampling(o.light_sampler);
  if (!std::isfinite(o.exposure)) throw rc::InputError("--exposure: must be a finite number");
  if (o.threads < 0) throw rc::InputError("--threads: 0 (all) or more");
  if (!o.output.empty()) {
    if (fs::exists(o.output) && !fs::is_directory(o.output))
      throw rc::InputError("-o " + o.output.string() + ": exists and is not a folder");
    const fs::path parent = fs::absolute(o.output).parent_path();
    if (!fs::is_directory(parent))
      throw rc::InputError("-o " + o.output.string() + ": folder " + parent.string() + " does not exist");
  }
}

Report compare_methods(rc::scene::Scene& scene, const CompareSettings& given,
                       const std::function<void(const ReportEntry&)>& each) {
  CompareSettings o = given;
  check_settings(o);
  std::sort(o.budgets.begin(), o.budgets.end());
  o.budgets.erase(std::unique(o.budgets.begin(), o.budgets.end()), o.budgets.end());
  const rc::scene::Camera camera = scene.effective_camera(float(o.width) / float(std::max(o.height, 1)));
  const Reference ref = make_reference(scene, camera, o);

  const fs::path& folder = o.output;
  const bool files = !folder.empty();
  if (files) fs::create_directories(folder / "images");
  Report report;
  report.scene = o.scene_name;
  report.width = o.width, report.height = o.height, report.exposure = o.exposure;
  report.sampler = o.sampler;
  report.light_sampler = o.light_sampler;
  const LightSamplingScope sampling(scene,
                                    rc::scene::parse_light_sampling(o.light_sampler));  // after the reference
  report.reference = ref.description;
  report.reference_noise_mre = ref.noise;
  if (!ref.variance.empty()) {
    const rc::util::ImageError floor = rc::util::image_error(ref.pixels, ref.pixels, ref.variance);
    report.reference_relmse_floor = floor.relmse_floor;
    report.reference_mse_floor = floor.mse_floor;
  }
  report.methods = o.methods;
  report.budgets = o.budgets;
  if (files) {
    report.reference_png = "images/reference.png";
    rc::util::write_image((folder / "images/reference.exr").string(),
                          rc::util::Image{o.width, o.height, ref.pixels});
    rc::util::write_image((folder / report.reference_png).string(), rc::util::Image{o.width, o.height, ref.pixels}, o.exposure);
  }

  rc::render::RenderSettings settings;
  settings.width = o.width, settings.height = o.height, settings.seed = o.seed, settings.threads = o.threads;
  settings.sampler = rc::render::parse_sampler(o.sampler);
  // Each method's run reports its own stages (the budgets run minutes in all).
  settings.progress = o.progress;
  for (double budget : o.budgets) {
    for (const std::string& m : o.methods) {
      settings.time_limit = budget;
      // Preparation scaled to the budget: fewer photons when time is short (run_method sizes the
      // radiosity mesh to the budget itself).
      MethodOptions mo;
      const double share = std::min(1.0, budget / 8.0);
      mo.photon.photons.global_photons = mo.photon.photons.caustic_photons =
          std::max<uint64_t>(20000, uint64_t(200000 * share));
      mo.solver.progress = o.progress;
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
      if (files) {
        const std::string stem = "images/" + m + "_" + budget_name(budget);
        e.image_exr = stem + ".exr", e.image_png = stem + ".png", e.error_png = stem + "_error.png";
        rc::util::write_image((folder / e.image_exr).string(), rc::util::Image{o.width, o.height, pixels});
        rc::util::write_image((folder / e.image_png).string(), rc::util::Image{o.width, o.height, pixels},
                              o.exposure);
        write_error_png(folder / e.error_png, pixels, ref.pixels, o.width, o.height);
      }
      report.entries.push_back(e);
      if (each) each(report.entries.back());
    }
  }
  if (files) write_report(folder, report);
  return report;
}

}  // namespace gilt::api

#pragma once
// A comparison of methods: every method at every time budget on one scene and camera, each
// image's error against one reference (path-traced or SPPM, cached by the scene's content, or
// read from a file), and the report of api/report.h. `gilt compare` and the Python module's
// gilt.compare() both call compare_methods().

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "api/report.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::api {

/// What to compare and how.
struct CompareSettings {
  std::vector<std::string> methods = {"path", "photon", "sppm", "radiosity", "whitted"};
  std::vector<double> budgets = {1, 2, 4, 8, 16};  ///< seconds per method and image
  std::string reference_file;      ///< an image of width × height to compare against; empty: render one
  std::string reference_method = "auto";  ///< path, sppm, or auto (sppm where the scene has caustics)
  double reference_time = 60.0;    ///< seconds for a rendered reference (two halves)
  int width = 256, height = 256;
  uint64_t seed = 0;
  std::string sampler = "sobol";   ///< the methods' camera samples; the reference always uses Sobol
  std::string light_sampler = "bvh";  ///< the methods' choice of light; the reference always uses the BVH
  int threads = 0;                 ///< 0 = all
  float exposure = 0.0f;           ///< of the report's PNG images (EV)
  bool progress = true;            ///< the reference's progress bar and notices on stderr
  /// The report's folder (index.html, metrics.json, metrics.csv, images/); empty: no files, the
  /// metrics are only returned.
  std::filesystem::path output;
  std::string scene_name;          ///< how the report names the scene
};

/// Splits "a,b,c" into its non-empty items.
std::vector<std::string> split_list(const std::string& text);

/// Parses a comma-separated list of budgets in seconds ("1,2,4"): each positive and at most a
/// day; sorted, duplicates dropped. Throws InputError naming `flag`.
std::vector<double> parse_budgets(const std::string& text, const std::string& flag = "--budgets");

/// Checks the settings (methods, budgets, size, samplers, reference, output folder) and throws
/// InputError for the first bad one; compare_methods calls it first.
void check_settings(const CompareSettings& settings);

/// Runs the comparison. The settings are checked before any rendering. `each` is called after every
/// entry, in the report's order. The scene's light sampling is set to `light_sampler` for the
/// methods and restored before returning.
Report compare_methods(raytrace_core::scene::Scene& scene, const CompareSettings& settings,
                       const std::function<void(const ReportEntry&)>& each = {});

}  // namespace gilt::api

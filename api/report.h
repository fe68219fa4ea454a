#pragma once
// The `gilt compare` report: index.html (images side by side at one exposure, a false-colour
// error image under each, the metrics table, the best method per budget, and a log-log plot of
// error against time as inline SVG: no scripts, fonts or anything else from the network),
// metrics.json and metrics.csv.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace gilt::api {

/// One method at one budget.
struct ReportEntry {
  std::string method;
  double budget = 0.0;         ///< seconds asked for
  double seconds = 0.0;        ///< seconds taken, preparation included
  int spp = 0;                 ///< samples per pixel, or SPPM iterations
  uint64_t photons = 0;        ///< photon paths traced (photon, sppm)
  uint64_t shots = 0;          ///< radiosity shots
  /// √mean (I − R)² over pixels and channels, and mean (I − R)² / (R² + 0.01), each less the
  /// reference's own noise when it is known (raytrace_core/util/image_error.h): estimates of the
  /// error against the exact image. relmse may then come out below 0 by about relmse_stderr.
  double rmse = 0.0;
  double relmse = 0.0;
  double relmse_stderr = 0.0;  ///< standard error of relmse, from its per-pixel terms
  double rmse_measured = 0.0, relmse_measured = 0.0;  ///< against the reference as it is
  double mae = 0.0;            ///< mean |I − R|
  double mre = 0.0;            ///< mean |I − R| / (R + 0.01), the measure of gilt's benchmarks
  double mean_ratio = 1.0;     ///< Σ I / Σ R: the image's overall brightness against the reference's
  std::optional<double> object_space_error;  ///< radiosity: vertex radiance against path-traced estimates
  std::string image_png, image_exr, error_png;  ///< relative to the report folder
  std::vector<std::string> notes;
};

/// Everything the report shows.
struct Report {
  std::string scene;
  int width = 0, height = 0;
  float exposure = 0.0f;
  std::string sampler = "sobol";   ///< the methods' camera samples (--sampler)
  std::string light_sampler = "bvh";  ///< the methods' choice of light (--light-sampler)
  std::string reference;            ///< how the reference was made or where it came from
  double reference_noise_mre = 0.0; ///< the reference's own noise in the mre measure (0: unknown)
  /// What a perfect image would measure against the reference, in relMSE and MSE: its noise
  /// floor, subtracted from every entry's errors (0: unknown, nothing subtracted).
  double reference_relmse_floor = 0.0, reference_mse_floor = 0.0;
  std::string reference_png;
  std::vector<std::string> methods;
  std::vector<double> budgets;
  std::vector<ReportEntry> entries;
};

/// One entry as metrics.json lists it (method, budget_seconds, seconds, spp_or_iterations,
/// photons, shots, the errors, mean_ratio, the image files, notes, object_space_error).
nlohmann::json entry_json(const ReportEntry& entry);

/// Writes index.html, metrics.json and metrics.csv into `folder` (each file atomically).
void write_report(const std::filesystem::path& folder, const Report& report);

/// Colour of a relative error in the false-colour images and the legend (log scale from 1e-3,
/// dark blue, to 1, red), as 8-bit sRGB.
void error_colour(double relative_error, unsigned char rgb[3]);

}  // namespace gilt::api

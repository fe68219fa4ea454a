// Photon index: build time for a million photons and queries per second for the two uses of the
// photon mapper, k = 50 nearest (density estimation) and every photon within a radius (SPPM), for
// both kinds of index (FLANN kd-tree, hash grid). One thread; the figures are per core.
//
// The photons look like a photon map of the built-in cornell scene: 80 % spread over its surfaces
// in proportion to area, 20 % in a dense caustic-like blob on the floor. Queries are other random
// surface points. The k = 50 search is capped at the radius that 90 % of queries need to find 50;
// the fixed radius is the median distance of the 50th neighbour, so a radius query finds about 50.
//
// Nothing is timed until both kinds have answered a few hundred queries exactly like a linear scan
// over all the photons; any difference stops the program.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "photonmap/photon_index.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/scene/scene.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;
namespace pm = gilt::photonmap;
using pm::IndexKind;
using pm::Neighbour;
using pm::PhotonIndex;
using rc::Vec3;

namespace {

constexpr size_t kPhotons = 1'000'000;
constexpr double kCausticFraction = 0.2;
constexpr float kCausticSigma = 15.0f;  // mm: a caustic a few centimetres across
constexpr size_t kQueries = 100'000;
constexpr size_t kChecked = 300;
constexpr size_t kK = 50;
constexpr uint64_t kSeed = 2025;

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "bench_photon_index: %s\n", message.c_str());
  std::exit(EXIT_FAILURE);
}

/// Area-weighted random points on the scene's triangles (the light excluded).
class SurfaceSampler {
 public:
  explicit SurfaceSampler(const rc::scene::Scene& scene) {
    for (const rc::scene::TriangleMesh& mesh : scene.meshes) {
      if (mesh.name == "light") continue;
      for (size_t t = 0; t < mesh.triangle_count(); ++t) {
        const Vec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                   c = mesh.positions[mesh.indices[3 * t + 2]];
        const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
        total_ += area;
        cdf_.push_back(total_);
        triangles_.push_back({a, b, c});
      }
    }
  }
  Vec3 sample(rc::util::Rng& rng) const {
    const double u = rng.uniform() * total_;
    const size_t t =
        std::min<size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin(), triangles_.size() - 1);
    float b1 = rng.uniform(), b2 = rng.uniform();
    if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
    const Triangle& tri = triangles_[t];
    return tri.a + b1 * (tri.b - tri.a) + b2 * (tri.c - tri.a);
  }
  double area() const { return total_; }

 private:
  struct Triangle {
    Vec3 a, b, c;
  };
  std::vector<Triangle> triangles_;
  std::vector<double> cdf_;
  double total_ = 0.0;
};

struct Workload {
  std::vector<Vec3> photons, queries;
  float knn_max_distance2 = 0.0f;  // cap of the k = 50 search
  float radius2 = 0.0f;            // fixed radius of the SPPM-style search
  double surface_area = 0.0;
};

Workload make_workload() {
  const rc::scene::Scene scene = rc::io::load_scene("cornell");
  const SurfaceSampler sampler(scene);
  Workload w;
  w.surface_area = sampler.area();
  rc::util::Rng rng(kSeed);
  const auto caustic = static_cast<size_t>(kCausticFraction * double(kPhotons));
  w.photons.reserve(kPhotons);
  for (size_t i = 0; i < kPhotons - caustic; ++i) w.photons.push_back(sampler.sample(rng));
  for (size_t i = 0; i < caustic;
       ++i) {  // Gaussian blob on the floor (y = 0) under the tall block's shadow side
    const float r = kCausticSigma * std::sqrt(-2.0f * std::log(1.0f - rng.uniform()));
    const float phi = 2.0f * rc::kPi * rng.uniform();
    w.photons.push_back({400.0f + r * std::cos(phi), 0.0f, 150.0f + r * std::sin(phi)});
  }
  rc::util::Rng query_rng(kSeed + 1);
  for (size_t i = 0; i < kQueries; ++i) w.queries.push_back(sampler.sample(query_rng));
  return w;
}

// ---------------------------------------------------------------------------------------------
// Correctness before timing.

/// Linear scan: the k nearest within max_distance2, ordered by pm::closer.
std::vector<Neighbour> scan_knn(const std::vector<Vec3>& points, const Vec3& q, size_t k,
                                float max_distance2) {
  std::vector<Neighbour> found;
  for (size_t i = 0; i < points.size(); ++i) {
    const float d2 = pm::distance2(q, points[i]);
    if (d2 <= max_distance2) found.push_back({static_cast<uint32_t>(i), d2});
  }
  std::sort(found.begin(), found.end(), pm::closer);
  if (found.size() > k) found.resize(k);
  return found;
}

bool same(const std::vector<Neighbour>& a, const std::vector<Neighbour>& b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](const Neighbour& x, const Neighbour& y) {
           return x.index == y.index && x.distance2 == y.distance2;
         });
}

void check(const char* name, const PhotonIndex& index, const Workload& w) {
  std::vector<Neighbour> got(kK);
  for (size_t q = 0; q < kChecked; ++q) {
    const Vec3& query = w.queries[q * (kQueries / kChecked)];
    got.resize(kK);
    got.resize(index.knn(query, kK, w.knn_max_distance2, got.data()));
    if (!same(got, scan_knn(w.photons, query, kK, w.knn_max_distance2)))
      fail(std::string(name) + ": k = 50 query " + std::to_string(q) + " differs from the linear scan");
    got.clear();
    index.for_each_within(query, w.radius2, [&](Neighbour n) { got.push_back(n); });
    std::sort(got.begin(), got.end(), pm::closer);
    if (!same(got, scan_knn(w.photons, query, kPhotons, w.radius2)))
      fail(std::string(name) + ": radius query " + std::to_string(q) + " differs from the linear scan");
  }
}

// ---------------------------------------------------------------------------------------------
// Timed parts.

void BM_Build(benchmark::State& state, const Workload* w, IndexKind kind, float cell) {
  for (auto _ : state) {
    PhotonIndex index(w->photons, kind, cell);
    benchmark::DoNotOptimize(index.size());
  }
  state.counters["photons"] = double(w->photons.size());
}

void BM_Knn(benchmark::State& state, const Workload* w, const PhotonIndex* index) {
  Neighbour out[kK];
  size_t q = 0, found = 0;
  for (auto _ : state) {
    found += index->knn(w->queries[q], kK, w->knn_max_distance2, out);
    benchmark::DoNotOptimize(out[0]);
    if (++q == w->queries.size()) q = 0;
  }
  state.counters["queries"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["found"] = double(found) / double(state.iterations());
}

void BM_Radius(benchmark::State& state, const Workload* w, const PhotonIndex* index) {
  size_t q = 0, found = 0;
  for (auto _ : state) {
    index->for_each_within(w->queries[q], w->radius2, [&found](Neighbour n) { found += n.index != ~0u; });
    if (++q == w->queries.size()) q = 0;
  }
  benchmark::DoNotOptimize(found);
  state.counters["queries"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["found"] = double(found) / double(state.iterations());
}

/// Console output as usual, keeping each benchmark's result (the median when repeated) for the
/// summary table.
class Recorder : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred) continue;
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name != "median") continue;
      results[run.run_name.function_name] = run;
    }
  }
  std::map<std::string, Run> results;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return EXIT_FAILURE;

  Workload w = make_workload();

  // The cap and the fixed radius come from the distances of the 50th neighbour.
  const PhotonIndex kd_tree(w.photons, IndexKind::kd_tree);
  {
    std::vector<float> d2;
    Neighbour out[kK];
    for (size_t q = 0; q < 2000; ++q) {
      if (kd_tree.knn(w.queries[q], kK, rc::kInfinity, out) == kK) d2.push_back(out[kK - 1].distance2);
    }
    std::sort(d2.begin(), d2.end());
    w.knn_max_distance2 = d2[d2.size() * 9 / 10];
    w.radius2 = d2[d2.size() / 2];
  }
  const float radius = std::sqrt(w.radius2);
  const PhotonIndex hash_grid(w.photons, IndexKind::hash_grid);
  const PhotonIndex hash_grid_r(w.photons, IndexKind::hash_grid, radius);
  const PhotonIndex hash_grid_2r(w.photons, IndexKind::hash_grid, 2.0f * radius);

  check("kd_tree", kd_tree, w);
  check("hash_grid", hash_grid, w);
  check("hash_grid cell = r", hash_grid_r, w);
  check("hash_grid cell = 2r", hash_grid_2r, w);
  std::printf(
      "bench_photon_index: %zu photons on cornell's surfaces (%.2f m², %.0f %% in a caustic blob of σ %.0f "
      "mm), "
      "%zu query points on the surfaces\n"
      "checked: %zu k = 50 and radius queries per index equal a linear scan (indices and distances)\n"
      "k = 50 cap: %.2f mm (90th percentile of the 50th-neighbour distance); fixed radius r: %.2f mm "
      "(median)\n"
      "hash grid cell: automatic %.2f mm\n\n",
      w.photons.size(), w.surface_area * 1e-6, 100.0 * kCausticFraction, double(kCausticSigma),
      w.queries.size(), kChecked, std::sqrt(double(w.knn_max_distance2)), double(radius),
      double(hash_grid.cell_size()));
  std::fflush(stdout);

  benchmark::RegisterBenchmark("Build/kd_tree", BM_Build, &w, IndexKind::kd_tree, 0.0f)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Build/hash_grid", BM_Build, &w, IndexKind::hash_grid, 0.0f)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Build/hash_grid_cell_r", BM_Build, &w, IndexKind::hash_grid, radius)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Knn50/kd_tree", BM_Knn, &w, &kd_tree);
  benchmark::RegisterBenchmark("Knn50/hash_grid", BM_Knn, &w, &hash_grid);
  benchmark::RegisterBenchmark("Knn50/hash_grid_cell_r", BM_Knn, &w, &hash_grid_r);
  benchmark::RegisterBenchmark("Radius/kd_tree", BM_Radius, &w, &kd_tree);
  benchmark::RegisterBenchmark("Radius/hash_grid", BM_Radius, &w, &hash_grid);
  benchmark::RegisterBenchmark("Radius/hash_grid_cell_r", BM_Radius, &w, &hash_grid_r);
  benchmark::RegisterBenchmark("Radius/hash_grid_cell_2r", BM_Radius, &w, &hash_grid_2r);
  Recorder recorder;
  benchmark::RunSpecifiedBenchmarks(&recorder);

  // Summary: build in ms, queries per second (one thread); "-" where a figure was not measured.
  auto figure = [&](const std::string& name, bool build) {
    const auto it = recorder.results.find(name);
    if (it == recorder.results.end()) return std::string("-");
    char text[32];
    if (build)
      std::snprintf(text, sizeof text, "%.1f", it->second.GetAdjustedRealTime());
    else
      std::snprintf(text, sizeof text, "%.0f", it->second.counters.at("queries").value);
    return std::string(text);
  };
  std::printf("\n== Photon index, %zu photons, one thread ==\n", w.photons.size());
  std::printf("  %-18s %10s %16s %18s\n", "index", "build ms", "k=50 queries/s", "radius queries/s");
  for (const std::string name : {"kd_tree", "hash_grid", "hash_grid_cell_r", "hash_grid_cell_2r"}) {
    std::printf("  %-18s %10s %16s %18s\n", name.c_str(), figure("Build/" + name, true).c_str(),
                figure("Knn50/" + name, false).c_str(), figure("Radius/" + name, false).c_str());
  }
  std::printf(
      "  (hash_grid: automatic cell, %.2f mm; cell_r / cell_2r: the cell is the fixed radius / twice it)\n",
      double(hash_grid.cell_size()));
  benchmark::Shutdown();
  return EXIT_SUCCESS;
}

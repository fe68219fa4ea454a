// Ray-core throughput against raw Embree: Mrays/s for primary, shadow and diffuse-bounce rays on
// a scene of about a million triangles. Each ray set is traced once through Scene::intersect /
// Scene::occluded and once through rtcIntersect1 / rtcOccluded1 on the same Embree scene, with
// the Embree structures filled exactly as the core fills them, so the difference between the two
// is the cost of the core's own layer. Target: the core keeps at least 90 % of raw Embree's
// throughput (scripts/run-benchmarks.sh computes the ratios).
//
// Nothing is timed until both paths have been shown to agree on every ray: same primitive,
// bit-identical t and barycentrics, same occlusion answer. Any disagreement stops the program.

#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"
#include "raytrace_core/scene/scene.h"

namespace rc = gilt::raytrace_core;
using rc::Vec3;

namespace {

constexpr int kTerrainQuads = 708;  // per side: 2 · 708² = 1,002,528 terrain triangles
constexpr int kImageSize = 512;     // primary rays: one per pixel of a 512 × 512 image
constexpr uint64_t kSeed = 2024;

// The room is the box [−1, 1] × [−0.5, 1.5] × [−1, 1]; the terrain covers its floor.
constexpr float kRoomLow = -0.5f, kRoomHigh = 1.5f;
// A rectangular light just in front of the x = −1 wall, low enough that the hills cast long
// shadows: the shadow rays then cross the terrain at grazing angles.
constexpr uint32_t kLightMesh = 2;
constexpr float kLightX = -0.99f, kLightHalfWidth = 0.3f, kLightLow = 0.25f, kLightHigh = 0.65f;

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "bench_raycore: %s\n", message.c_str());
  std::exit(EXIT_FAILURE);
}

/// Height of the hilly terrain above (x, z): a few smooth waves, about ±0.2 in all.
float terrain_height(float x, float z) {
  return 0.10f * std::sin(6.0f * x) * std::cos(5.0f * z) + 0.05f * std::sin(19.0f * x + 13.0f * z) +
         0.03f * std::cos(37.0f * z - 23.0f * x) + 0.015f * std::sin(71.0f * x) * std::sin(67.0f * z);
}

/// Appends quad a b c d as triangles (a, b, c) and (a, c, d): counter-clockwise seen from its front.
void add_quad(rc::scene::TriangleMesh& mesh, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), {a, b, c, d});
  mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

/// A closed room whose floor is a terrain of about a million triangles, lit by a quad light on
/// one wall. Mesh 0: walls, 1: terrain, 2: light.
rc::scene::Scene make_scene() {
  rc::scene::Scene scene;
  scene.name = "bench-terrain-room";
  scene.materials = {rc::scene::Material::make_diffuse("wall", rc::Rgb(0.7f)),
                     rc::scene::Material::make_diffuse("ground", rc::Rgb(0.5f)),
                     rc::scene::Material::make_emitter("light", rc::Rgb(10.0f))};

  // Walls facing inwards; the eight corners are shared, so the box is watertight.
  rc::scene::TriangleMesh& walls = scene.meshes.emplace_back();
  walls.name = "walls";
  walls.material = 0;
  auto corner = [](int i) {
    return Vec3(i & 1 ? 1.0f : -1.0f, i & 2 ? kRoomHigh : kRoomLow, i & 4 ? 1.0f : -1.0f);
  };
  add_quad(walls, corner(0), corner(1), corner(5), corner(4));  // floor, normal +y
  add_quad(walls, corner(2), corner(6), corner(7), corner(3));  // ceiling, normal −y
  add_quad(walls, corner(0), corner(2), corner(3), corner(1));  // z = −1, normal +z
  add_quad(walls, corner(4), corner(5), corner(7), corner(6));  // z = +1, normal −z
  add_quad(walls, corner(0), corner(4), corner(6), corner(2));  // x = −1, normal +x
  add_quad(walls, corner(1), corner(3), corner(7), corner(5));  // x = +1, normal −x

  rc::scene::TriangleMesh& terrain = scene.meshes.emplace_back();
  terrain.name = "terrain";
  terrain.material = 1;
  constexpr int n = kTerrainQuads;
  terrain.positions.reserve(size_t(n + 1) * (n + 1));
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const float x = -1.0f + 2.0f * float(i) / n, z = -1.0f + 2.0f * float(j) / n;
      terrain.positions.emplace_back(x, terrain_height(x, z), z);
    }
  }
  terrain.indices.reserve(size_t(6) * n * n);
  auto vertex = [](int i, int j) { return static_cast<uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      // Wound so that the front faces +y.
      const uint32_t a = vertex(i, j), b = vertex(i, j + 1), c = vertex(i + 1, j + 1), d = vertex(i + 1, j);
      terrain.indices.insert(terrain.indices.end(), {a, b, c, a, c, d});
    }
  }

  rc::scene::TriangleMesh& light = scene.meshes.emplace_back();
  light.name = "light";
  light.material = 2;
  const float x = kLightX, s = kLightHalfWidth;
  // Faces +x, into the room.
  add_quad(light, Vec3(x, kLightLow, s), Vec3(x, kLightLow, -s), Vec3(x, kLightHigh, -s),
           Vec3(x, kLightHigh, s));

  rc::scene::Camera camera;
  camera.look_from = Vec3(0.0f, 1.0f, 0.95f);
  camera.look_at = Vec3(0.0f, -0.05f, -0.4f);
  camera.vfov_degrees = 65.0f;
  scene.camera = camera;

  scene.commit();
  if (!scene.warnings.empty()) fail("unexpected warning while building the scene: " + scene.warnings.front());
  return scene;
}

// --- Raw Embree, with the structures filled field by field as Scene::intersect / occluded do. ---

RTCRayHit raw_intersect(RTCScene scene, const rc::scene::Ray& ray) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = ray.origin.x;
  rh.ray.org_y = ray.origin.y;
  rh.ray.org_z = ray.origin.z;
  rh.ray.tnear = 0.0f;
  rh.ray.dir_x = ray.direction.x;
  rh.ray.dir_y = ray.direction.y;
  rh.ray.dir_z = ray.direction.z;
  rh.ray.time = 0.0f;
  rh.ray.tfar = ray.tmax;
  rh.ray.mask = ~0u;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &context, &rh);
  return rh;
}

bool raw_occluded(RTCScene scene, const rc::scene::Ray& ray) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r;
  r.org_x = ray.origin.x;
  r.org_y = ray.origin.y;
  r.org_z = ray.origin.z;
  r.tnear = 0.0f;
  r.dir_x = ray.direction.x;
  r.dir_y = ray.direction.y;
  r.dir_z = ray.direction.z;
  r.time = 0.0f;
  r.tfar = ray.tmax;
  r.mask = ~0u;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(scene, &context, &r);
  return r.tfar < 0.0f;
}

RTCScene embree_of(const rc::scene::Scene& scene) { return static_cast<RTCScene>(scene.embree_scene()); }

// --- The ray sets, generated once from fixed seeds. ---

struct RaySets {
  std::vector<rc::scene::Ray> primary, shadow, diffuse;
};

/// Index of the random stream of each ray kind, so the three sets draw independent numbers.
enum class Stream : uint64_t { primary, shadow, diffuse };

RaySets make_rays(const rc::scene::Scene& scene) {
  RaySets sets;
  const rc::scene::Camera camera = scene.effective_camera();
  sets.primary.reserve(size_t(kImageSize) * kImageSize);
  for (int y = 0; y < kImageSize; ++y) {
    for (int x = 0; x < kImageSize; ++x) {
      const uint64_t pixel = uint64_t(y) * kImageSize + x;
      rc::util::Rng rng = rc::util::Rng::for_item(kSeed, pixel, uint64_t(Stream::primary));
      const rc::Vec2 jitter = rng.uniform2();
      const rc::Vec2 film((x + jitter.x) / kImageSize, (y + jitter.y) / kImageSize);
      sets.primary.push_back(camera.generate_ray(film, rc::Vec2(0.5f), 1.0f));
    }
  }

  // Shadow and bounce rays leave every primary hit except those on the light itself.
  for (size_t i = 0; i < sets.primary.size(); ++i) {
    const rc::scene::Ray& ray = sets.primary[i];
    const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    if (!hit) fail("primary ray " + std::to_string(i) + " left the closed room");
    if (hit->geom_id == kLightMesh) continue;
    const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);

    rc::util::Rng shadow_rng = rc::util::Rng::for_item(kSeed, i, uint64_t(Stream::shadow));
    const uint32_t light_triangle = shadow_rng.uniform() < 0.5f ? 0 : 1;  // the two halves have equal area
    const rc::scene::SurfaceInteraction on_light = scene.triangle_point(
        kLightMesh, light_triangle, rc::util::sample_uniform_triangle(shadow_rng.uniform2()));
    sets.shadow.push_back(rc::scene::spawn_shadow_ray(si, on_light));

    rc::util::Rng bounce_rng = rc::util::Rng::for_item(kSeed, i, uint64_t(Stream::diffuse));
    const Vec3 n = glm::dot(ray.direction, si.ng) < 0.0f ? si.ng : -si.ng;  // the side the ray came from
    const Vec3 wi =
        rc::Frame::from_normal(n).to_world(rc::util::sample_cosine_hemisphere(bounce_rng.uniform2()));
    sets.diffuse.push_back(rc::scene::spawn_ray(si, wi));
  }
  return sets;
}

// --- Correctness before timing. ---

/// What one ray set looked like, for the record.
struct SetSummary {
  size_t rays = 0, hits = 0, occluded = 0;
};

/// Traces every ray through the core and through raw Embree, both queries each, and stops the
/// program at the first disagreement.
SetSummary check_agreement(const char* kind, const rc::scene::Scene& scene,
                           const std::vector<rc::scene::Ray>& rays) {
  const RTCScene raw_scene = embree_of(scene);
  SetSummary summary;
  summary.rays = rays.size();
  for (size_t i = 0; i < rays.size(); ++i) {
    const std::string where = std::string(kind) + " ray " + std::to_string(i) + ": ";
    const std::optional<rc::scene::Hit> core = scene.intersect(rays[i]);
    const RTCRayHit raw = raw_intersect(raw_scene, rays[i]);
    const bool raw_hit = raw.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    if (core.has_value() != raw_hit)
      fail(where + "the core reports " + (core ? "a hit" : "a miss") + ", raw Embree " +
           (raw_hit ? "a hit" : "a miss"));
    if (core) {
      if (core->geom_id != raw.hit.geomID || core->prim_id != raw.hit.primID)
        fail(where + "the core hits primitive " + std::to_string(core->geom_id) + "/" +
             std::to_string(core->prim_id) + ", raw Embree " + std::to_string(raw.hit.geomID) + "/" +
             std::to_string(raw.hit.primID));
      if (std::bit_cast<uint32_t>(core->t) != std::bit_cast<uint32_t>(raw.ray.tfar) ||
          std::bit_cast<uint32_t>(core->u) != std::bit_cast<uint32_t>(raw.hit.u) ||
          std::bit_cast<uint32_t>(core->v) != std::bit_cast<uint32_t>(raw.hit.v))
        fail(where + "t or barycentrics differ between the core and raw Embree");
      ++summary.hits;
    }
    const bool core_blocked = scene.occluded(rays[i]);
    if (core_blocked != raw_occluded(raw_scene, rays[i]))
      fail(where + "the core and raw Embree disagree on occlusion");
    if (core_blocked != core.has_value()) fail(where + "Scene::occluded and Scene::intersect disagree");
    summary.occluded += core_blocked;
  }
  return summary;
}

/// Checks that the scene behaves as built: every primary and bounce ray stays inside the closed
/// room, no bounce ray hits the planar triangle it leaves, no shadow ray is stopped by the light
/// it aims at, and the shadow rays are neither all blocked nor all free.
void check_scene_sanity(const rc::scene::Scene& scene, const RaySets& sets, const SetSummary& primary,
                        const SetSummary& shadow, const SetSummary& diffuse) {
  if (primary.hits != primary.rays) fail("some primary rays missed the closed room");
  if (diffuse.hits != diffuse.rays)
    fail("some bounce rays escaped the closed room: self-intersection policy broken?");
  if (shadow.occluded == 0 || shadow.occluded == shadow.rays)
    fail("the shadow rays are all blocked or all free: the scene does not test what it should");
  for (size_t i = 0; i < sets.shadow.size(); ++i) {
    const std::optional<rc::scene::Hit> blocker = scene.intersect(sets.shadow[i]);
    if (blocker && blocker->geom_id == kLightMesh)
      fail("shadow ray " + std::to_string(i) + " is blocked by the light it aims at");
  }
  // Bounce ray k starts on the surface hit by the k-th primary ray that did not land on the light.
  size_t k = 0;
  for (const rc::scene::Ray& ray : sets.primary) {
    const rc::scene::Hit from = *scene.intersect(ray);
    if (from.geom_id == kLightMesh) continue;
    const rc::scene::Hit to = *scene.intersect(sets.diffuse[k]);
    if (to.geom_id == from.geom_id && to.prim_id == from.prim_id)
      fail("bounce ray " + std::to_string(k) + " hit the triangle it leaves");
    ++k;
  }
}

// --- Timed loops. ---

constexpr size_t kChunk = 1024;  // rays per task of the multi-threaded loops

/// Traces every ray once per iteration, one after the other on this thread.
template <class Query>
void trace(benchmark::State& state, const std::vector<rc::scene::Ray>& rays, Query query) {
  for (auto _ : state)
    for (const rc::scene::Ray& ray : rays) query(ray);
  // Rays per second, shown as "rays=…M/s".
  state.counters["rays"] =
      benchmark::Counter(double(state.iterations()) * double(rays.size()), benchmark::Counter::kIsRate);
}

/// Traces every ray once per iteration in chunks spread over at most `threads` threads by
/// gilt's parallel_for, as the renderers do.
template <class Query>
void trace_parallel(benchmark::State& state, const std::vector<rc::scene::Ray>& rays, Query query,
                    int threads) {
  const rc::util::ThreadLimit limit(threads);
  const size_t chunks = (rays.size() + kChunk - 1) / kChunk;
  for (auto _ : state) {
    rc::util::parallel_for(chunks, [&rays, &query](size_t c) {
      const size_t end = std::min(rays.size(), (c + 1) * kChunk);
      for (size_t i = c * kChunk; i < end; ++i) query(rays[i]);
    });
  }
  state.counters["rays"] =
      benchmark::Counter(double(state.iterations()) * double(rays.size()), benchmark::Counter::kIsRate);
}

void register_benchmarks(const rc::scene::Scene& scene, const RaySets& sets) {
  const RTCScene raw = embree_of(scene);
  auto core_closest = [&scene](const rc::scene::Ray& ray) {
    std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    benchmark::DoNotOptimize(hit);
  };
  auto raw_closest = [raw](const rc::scene::Ray& ray) {
    RTCRayHit rh = raw_intersect(raw, ray);
    benchmark::DoNotOptimize(rh);
  };
  auto core_any = [&scene](const rc::scene::Ray& ray) {
    bool blocked = scene.occluded(ray);
    benchmark::DoNotOptimize(blocked);
  };
  auto raw_any = [raw](const rc::scene::Ray& ray) {
    bool blocked = raw_occluded(raw, ray);
    benchmark::DoNotOptimize(blocked);
  };

  // Single-thread loops are timed in CPU time, which other load on the machine disturbs least;
  // the two-thread ones ("…/threads:2/real_time") in wall time.
  auto add = [](const char* name, const std::vector<rc::scene::Ray>& rays, auto query, int threads) {
    if (threads == 1) {
      benchmark::RegisterBenchmark(name, [&rays, query](benchmark::State& state) {
        trace(state, rays, query);
      })->Unit(benchmark::kMillisecond);
      return;
    }
    benchmark::RegisterBenchmark(
        name,
        [&rays, query](benchmark::State& state) { trace_parallel(state, rays, query, int(state.range(0))); })
        ->ArgName("threads")
        ->Arg(threads)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
  };
  for (int threads : {1, 2}) {
    add("BM_Core_Primary", sets.primary, core_closest, threads);
    add("BM_Embree_Primary", sets.primary, raw_closest, threads);
    add("BM_Core_Shadow", sets.shadow, core_any, threads);
    add("BM_Embree_Shadow", sets.shadow, raw_any, threads);
    add("BM_Core_Diffuse", sets.diffuse, core_closest, threads);
    add("BM_Embree_Diffuse", sets.diffuse, raw_closest, threads);
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return EXIT_FAILURE;

  const rc::scene::Scene scene = make_scene();
  const RaySets sets = make_rays(scene);
  const SetSummary primary = check_agreement("primary", scene, sets.primary);
  const SetSummary shadow = check_agreement("shadow", scene, sets.shadow);
  const SetSummary diffuse = check_agreement("diffuse", scene, sets.diffuse);
  check_scene_sanity(scene, sets, primary, shadow, diffuse);

  const double blocked_percent = 100.0 * double(shadow.occluded) / double(shadow.rays);
  std::fprintf(
      stderr,
      "bench_raycore: %zu triangles; %zu primary, %zu shadow (%.1f %% blocked) and %zu diffuse rays; "
      "core and raw Embree agree on every ray\n",
      scene.triangle_count(), primary.rays, shadow.rays, blocked_percent, diffuse.rays);
  benchmark::AddCustomContext("triangles", std::to_string(scene.triangle_count()));
  benchmark::AddCustomContext("primary_rays", std::to_string(primary.rays));
  benchmark::AddCustomContext("shadow_rays", std::to_string(shadow.rays));
  benchmark::AddCustomContext("shadow_blocked_percent", std::to_string(blocked_percent));
  benchmark::AddCustomContext("diffuse_rays", std::to_string(diffuse.rays));

  register_benchmarks(scene, sets);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return EXIT_SUCCESS;
}

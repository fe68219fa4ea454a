// Photon tracing into the caustic and global maps, and density estimation over them (Jensen
// 1996; the Epanechnikov kernel as in Silverman 1986, "Density Estimation for Statistics and Data
// Analysis", which unlike Jensen's cone filter is a consistent kernel of its own).

#include "photonmap/photon_map.h"

#include <algorithm>
#include <chrono>

#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"
#include "raytrace_core/util/rng.h"

namespace gilt::photonmap {
namespace {

/// Photons traced per parallel task; tasks are joined in order, so the maps do not depend on
/// the thread count.
constexpr uint64_t kChunk = 4096;

/// Emits photons first, …, first + count − 1 and keeps those `keep` accepts, in photon order,
/// each with its power divided by `count`.
template <class Keep>
std::vector<Photon> trace_map(const rc::scene::Scene& scene, uint64_t first, uint64_t count, uint64_t stream,
                              const PhotonSettings& settings, uint64_t& paths, Keep keep) {
  const auto& lights = scene.lights();
  const rc::util::Distribution1D& choice = scene.light_distribution();
  const size_t chunks = size_t((count + kChunk - 1) / kChunk);
  std::vector<std::vector<Photon>> stored(chunks);
  // Under several processes each traces the chunks it owns; they are joined in chunk order.
  rc::util::distributed_chunks<Photon>(stored, [&](size_t c, std::vector<Photon>& out) {
    for (uint64_t i = c * kChunk; i < std::min(count, (c + 1) * kChunk); ++i) {
      rc::util::Rng rng = rc::util::Rng::for_item(settings.seed, first + i, stream);
      const uint32_t li = choice.sample(rng.uniform());
      const float pmf = choice.pmf(li);
      if (!(pmf > 0.0f)) continue;
      const rc::Vec2 u_position = rng.uniform2(), u_direction = rng.uniform2();
      const rc::scene::EmissionSample es =
          rc::scene::sample_emission(scene, lights[li], u_position, u_direction);
      if (es.power.is_black()) continue;
      const rc::Rgb power = es.power / (pmf * float(count));
      trace_photon_path(scene, es.ray, power, rng, settings.max_depth,
                        [&](const Photon& p, int depth, bool specular_only) { return keep(p, depth, specular_only, out); });
    }
  });
  paths += count;
  size_t total = 0;
  for (const auto& s : stored) total += s.size();
  std::vector<Photon> photons;
  photons.reserve(total);
  for (const auto& s : stored) photons.insert(photons.end(), s.begin(), s.end());
  return photons;
}

/// trace_map's `keep` for the global map (and its irradiance sites): every photon after at least
/// one diffuse bounce, neither direct light nor a caustic; the path goes on.
bool keep_global(const Photon& p, int, bool specular_only, std::vector<Photon>& out) {
  if (!specular_only) out.push_back(p);
  return true;
}

/// Epanechnikov's kernel on a disk of squared radius r2, normalised over the disk:
/// 2 / (π r²) · (1 − d² / r²).
float epanechnikov(float d2, float r2) { return 2.0f * rc::kInvPi / r2 * std::max(0.0f, 1.0f - d2 / r2); }

/// Runs the k-nearest query and calls f(photon, kernel weight) for each photon that agrees with
/// the query's normal. Returns the squared radius of the disk (0 when nothing was found).
template <class F>
float for_each_estimate_photon(const PhotonMap& map, const EstimateQuery& q, EstimateScratch& scratch, F&& f) {
  if (map.empty() || q.k == 0 || !(q.max_radius2 > 0.0f)) return 0.0f;
  if (scratch.neighbours.size() < q.k) scratch.neighbours.resize(q.k);
  const size_t found = map.index.knn(q.position, q.k, q.max_radius2, scratch.neighbours.data());
  if (found == 0) return 0.0f;
  // The disk reaches the k-th photon; with fewer found, it is the whole search radius.
  const float r2 = found == q.k ? scratch.neighbours[found - 1].distance2 : q.max_radius2;
  if (!(r2 > 0.0f)) return 0.0f;
  for (size_t i = 0; i < found; ++i) {
    const Photon& p = map.photons[scratch.neighbours[i].index];
    if (glm::dot(decode_direction(p.normal), q.normal) < kSameSurfaceCosine) continue;
    const float w = epanechnikov(scratch.neighbours[i].distance2, r2);
    if (w > 0.0f) f(p, w);
  }
  return r2;
}

/// What an estimate over the disk of squared radius r2 is divided by: its coverage, held at 0.1
/// and above (as SPPM holds its own), or 1 where it is unknown (a sphere in the ball) or where
/// nothing was found.
float coverage_divisor(const rc::scene::Scene& scene, const PhotonMap& map, const EstimateQuery& q,
                       float r2) {
  if (!(r2 > 0.0f)) return 1.0f;
  const double c = disk_coverage(scene, map.sides, q.position, q.normal, r2, kSameSurfaceCosine);
  return c < 0.0 ? 1.0f : float(std::max(c, 0.1));
}

}  // namespace

void PhotonMap::build_index(IndexKind kind) {
  std::vector<rc::Vec3> positions(photons.size());
  for (size_t i = 0; i < photons.size(); ++i) positions[i] = photons[i].position;
  index = PhotonIndex(positions, kind);
}

MapNeeds map_needs(const rc::scene::Scene& scene) {
  MapNeeds needs;
  bool specular = false, reflective = false;
  auto visit = [&](uint32_t material) {
    const rc::scene::Material& m = scene.materials[material];
    if (m.is_traced_through()) specular = true;
    else if (rc::scene::diffuse_reflectance(m).max_component() > 1e-4f ||
             m.kind == rc::scene::MaterialKind::glossy ||
             m.kind == rc::scene::MaterialKind::metallic_roughness)
      reflective = true;
  };
  for (const rc::scene::TriangleMesh& m : scene.meshes) visit(m.material);
  for (const rc::scene::Sphere& s : scene.spheres) visit(s.material);
  if (scene.lights().empty()) {
    needs.caustic_reason = needs.global_reason = "no lights";
    return needs;
  }
  needs.caustic = specular;
  if (!specular) needs.caustic_reason = "no specular surface";
  needs.global = reflective;
  if (!reflective) needs.global_reason = "no diffuse or glossy surface reflects light (no interreflection)";
  return needs;
}

PhotonMaps trace_photons(const rc::scene::Scene& scene, const PhotonSettings& settings) {
  if (!scene.committed()) throw std::logic_error("trace_photons: the scene was not committed");
  const auto start = std::chrono::steady_clock::now();
  PhotonMaps maps;
  const MapNeeds needs = map_needs(scene);
  if (!needs.caustic) maps.skipped.push_back("caustic map skipped: " + needs.caustic_reason);
  else if (settings.caustic_photons == 0) maps.skipped.push_back("caustic map skipped: --caustic-photons 0");
  if (!needs.global) maps.skipped.push_back("global map skipped: " + needs.global_reason);
  else if (settings.global_photons == 0) maps.skipped.push_back("global map skipped: --photons 0");

  if (needs.global && settings.global_photons > 0) {
    // Rounds of global_photons paths until half as many photons are stored: in an open scene
    // or an interior lit through its windows most paths from a distant light store nothing, and
    // a sparse map's estimates are biased. Each round's photons carry 1 / global_photons of the
    // power; with r rounds they are scaled by 1 / r.
    const uint64_t round = settings.global_photons;
    const int most_rounds = std::max({settings.global_rounds, settings.global_time_rounds, 1});
    for (int r = 0; r < most_rounds; ++r) {
      const std::vector<Photon> more =
          trace_map(scene, maps.global.emitted, round, 0xb000000000ull, settings, maps.paths, keep_global);
      maps.global.emitted += round;
      maps.global.photons.insert(maps.global.photons.end(), more.begin(), more.end());
      // A first round that stores nothing finds a scene with no interreflection worth a map.
      if (maps.global.photons.empty()) break;
      // Under a time budget a map that most paths leave without a photon (an open scene, an
      // interior lit through its windows) takes more rounds while its time lasts; rank 0's
      // clock decides for every process. A closed room stores most of its paths, and there more
      // photons cost the render its samples (cornell at 2 s: relMSE 7 times higher).
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const bool more_time = rc::util::processes().broadcast_value(seconds < settings.global_seconds) &&
                             2 * maps.global.photons.size() < maps.global.emitted && r + 1 < settings.global_time_rounds;
      const bool sparse = 2 * maps.global.photons.size() < round && r + 1 < settings.global_rounds;
      if (!sparse && !more_time) break;
    }
    const float rounds = float(maps.global.emitted / round);
    if (rounds > 1.0f)
      for (Photon& p : maps.global.photons) p.power /= rounds;
    maps.global.build_index(settings.index);
  }
  if (needs.caustic && settings.caustic_photons > 0) {
    maps.caustic.emitted = settings.caustic_photons;
    maps.caustic.photons = trace_map(scene, 0, settings.caustic_photons, 0xc000000000ull, settings, maps.paths,
                                     [](const Photon& p, int depth, bool specular_only, std::vector<Photon>& out) {
                                       // Light → specular⁺ → here: a caustic; the path ends either way.
                                       if (specular_only && depth > 0) out.push_back(p);
                                       return false;
                                     });
    maps.caustic.build_index(settings.index);
  }
  maps.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return maps;
}

std::vector<Photon> trace_global_sites(const rc::scene::Scene& scene, const PhotonSettings& settings,
                                       uint64_t paths, uint64_t& traced) {
  if (!scene.committed()) throw std::logic_error("trace_global_sites: the scene was not committed");
  // Path numbers from 2^62 on, far from the maps' (which count from 0), on a stream of their own.
  return trace_map(scene, uint64_t(1) << 62, paths, 0xb100000000ull, settings, traced, keep_global);
}

namespace {

rc::Rgb radiance_estimate(const rc::scene::Scene* scene, const PhotonMap& map, const EstimateQuery& query,
                          const rc::scene::Material& material, const rc::Frame& shading,
                          const rc::Vec3& wo_local, EstimateScratch& scratch) {
  rc::Rgb sum(0.0f);
  const bool lambertian = material.kind == rc::scene::MaterialKind::diffuse;
  const float r2 = for_each_estimate_photon(map, query, scratch, [&](const Photon& p, float w) {
    if (lambertian) {
      sum += p.power * w;
    } else {
      const rc::Vec3 wi = shading.to_local(decode_direction(p.direction));
      sum += rc::scene::bsdf_eval(material, wo_local, wi) * p.power * w;
    }
  });
  if (scene && !sum.is_black()) sum = sum / coverage_divisor(*scene, map, query, r2);
  // Lambertian: f = ρ/π for every photon, taken out of the sum.
  return lambertian ? material.albedo * sum * rc::kInvPi : sum;
}

rc::Rgb irradiance_estimate(const rc::scene::Scene* scene, const PhotonMap& map, const EstimateQuery& query,
                            EstimateScratch& scratch) {
  rc::Rgb sum(0.0f);
  const float r2 = for_each_estimate_photon(map, query, scratch, [&](const Photon& p, float w) { sum += p.power * w; });
  if (scene && !sum.is_black()) sum = sum / coverage_divisor(*scene, map, query, r2);
  return sum;
}

}  // namespace

rc::Rgb estimate_radiance(const PhotonMap& map, const EstimateQuery& query,
                          const rc::scene::Material& material, const rc::Frame& shading,
                          const rc::Vec3& wo_local, EstimateScratch& scratch) {
  return radiance_estimate(nullptr, map, query, material, shading, wo_local, scratch);
}

rc::Rgb estimate_irradiance(const PhotonMap& map, const EstimateQuery& query, EstimateScratch& scratch) {
  return irradiance_estimate(nullptr, map, query, scratch);
}

rc::Rgb estimate_radiance(const rc::scene::Scene& scene, const PhotonMap& map, const EstimateQuery& query,
                          const rc::scene::Material& material, const rc::Frame& shading,
                          const rc::Vec3& wo_local, EstimateScratch& scratch) {
  return radiance_estimate(&scene, map, query, material, shading, wo_local, scratch);
}

rc::Rgb estimate_irradiance(const rc::scene::Scene& scene, const PhotonMap& map, const EstimateQuery& query,
                            EstimateScratch& scratch) {
  return irradiance_estimate(&scene, map, query, scratch);
}

}  // namespace gilt::photonmap

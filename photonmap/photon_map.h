#pragma once
// Pass 1 of photon mapping (Jensen 1996, "Global Illumination Using Photon Maps"): photons leave
// the lights in proportion to their power and are stored where they meet diffuse or glossy
// surfaces, in two maps:
//   caustic map  paths light → specular⁺ → diffuse (the photon stops there);
//   global map   photons that have bounced off a diffuse surface at least once before the hit
//                (direct light is left to shadow rays).
// Then the density estimate that turns the photons around a point into reflected radiance.

#include <cstdint>
#include <string>
#include <vector>

#include "photonmap/coverage.h"
#include "photonmap/photon.h"
#include "photonmap/photon_index.h"
#include "raytrace_core/scene/material.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::photonmap {

/// How many photons to emit and how far to follow them. The defaults are the documented ones.
struct PhotonSettings {
  /// Paths emitted for the global map per round (0: no global map); rounds go on until half as
  /// many photons are stored, or the first round stores none, or global_rounds rounds.
  uint64_t global_photons = 200'000;
  int global_rounds = 16;
  /// Rounds also go on, past half a round stored or global_rounds, while fewer photons are stored
  /// than half the paths emitted, until the global map has taken this many seconds or
  /// global_time_rounds rounds: under a time budget, a share of it for a denser map of an open
  /// scene (0: none; the map then depends on the machine's speed, as a budget's passes do).
  double global_seconds = 0.0;
  int global_time_rounds = 64;
  uint64_t caustic_photons = 200'000;  ///< emitted for the caustic map (0: no caustic map)
  int max_depth = 1 << 16;             ///< bounces per photon path at most; Russian roulette ends
                                       ///< paths long before (a low cap would bias albedo near 1)
  uint64_t seed = 0;
  IndexKind index = IndexKind::hash_grid;  ///< search structure over the stored photons (bench_photon --index)
};

/// Stored photons of one map and their search structure. Each photon's power already includes
/// the 1 / emitted factor, so a density estimate sums powers directly.
struct PhotonMap {
  std::vector<Photon> photons;
  uint64_t emitted = 0;  ///< photon paths emitted for this map
  PhotonIndex index;
  /// The triangle sides that hold photons, for the estimates with coverage (the photon mapper
  /// counts every side: every_side in photonmap/coverage.h).
  SurfaceSides sides;

  bool empty() const { return photons.empty(); }
  /// Builds `index` over the photon positions.
  void build_index(IndexKind kind);
};

/// Both maps, and what the tracing pass did and skipped.
struct PhotonMaps {
  PhotonMap global, caustic;
  std::vector<std::string> skipped;  ///< "caustic map skipped: no specular surface", …
  uint64_t paths = 0;                ///< photon paths traced, both maps
  double seconds = 0.0;
};

/// Whether a scene needs each map: a caustic map only with a mirror or dielectric surface, a
/// global map only when some diffuse or glossy surface reflects light (albedo above 1e-4) and
/// more than one such bounce can happen. `reason` says why a map is not needed.
struct MapNeeds {
  bool caustic = false, global = false;
  std::string caustic_reason, global_reason;
};
MapNeeds map_needs(const rc::scene::Scene& scene);

/// Traces the photons of both maps (in parallel; photon i of a map draws from its own random
/// stream, so the maps are identical for any thread count) and builds their indexes.
PhotonMaps trace_photons(const rc::scene::Scene& scene, const PhotonSettings& settings);

/// Photons as the global map would store them (after at least one diffuse bounce) from `paths`
/// further paths, on a random stream of their own, so that they are independent of the maps'
/// photons; `traced` grows by the paths traced. The two-pass mapper precomputes irradiance at
/// their positions (photon_mapper.h says why not at the map's own photons).
std::vector<Photon> trace_global_sites(const rc::scene::Scene& scene, const PhotonSettings& settings,
                                       uint64_t paths, uint64_t& traced);

/// Scratch space for density estimates, one per thread: queries do not allocate.
struct EstimateScratch {
  std::vector<Neighbour> neighbours;
};

/// A photon counts in a density estimate (the photon method's k nearest, SPPM's disk) when its
/// stored normal lies within about 25° of the query's lit side (cos 25° ≈ 0.9): on the same
/// surface, a little curved or tessellated, but not on the other side of a sheet, on a wall
/// meeting it in a crease, or on a facet turned well away. Both methods divide by the coverage
/// of the surface that passes the same test. A wider test mixes orientations: on a column's lit
/// side the facets turned away from the light hold fewer photons, and at 60° SPPM's image of
/// Šibenik came out 0.9 % dark at any radius (bench/README.md, "SPPM's test of a photon's
/// surface"); the photon method's k nearest took in photons from creases and came out 13 % bright.
inline constexpr float kSameSurfaceCosine = 0.9f;

/// A density-estimate query: where, which way the surface faces, how many photons and how far.
struct EstimateQuery {
  rc::Vec3 position;
  rc::Vec3 normal;     ///< unit geometric normal on the side being lit
  size_t k = 50;       ///< nearest photons
  float max_radius2 = 0.0f;
};

/// Reflected radiance (W·sr⁻¹·m⁻²) towards wo from the photons around the query: the k nearest
/// within the maximum radius whose stored normal agrees with the query's (same side, within
/// about 25°), each weighted by the BSDF and by Epanechnikov's kernel over the disk of the
/// k-th photon's distance (or the maximum radius when fewer are found).
rc::Rgb estimate_radiance(const PhotonMap& map, const EstimateQuery& query,
                          const rc::scene::Material& material, const rc::Frame& shading,
                          const rc::Vec3& wo_local, EstimateScratch& scratch);

/// Irradiance (W·m⁻²) at the query from the same photons, with the same kernel.
rc::Rgb estimate_irradiance(const PhotonMap& map, const EstimateQuery& query, EstimateScratch& scratch);

/// The same two estimates divided by the share of their disk that the map's photon-holding
/// surface covers (disk_coverage, held at 0.1 and above), which takes away their darkening at
/// edges, in corners and on thin parts. `scene` is the one the map was traced in.
rc::Rgb estimate_radiance(const rc::scene::Scene& scene, const PhotonMap& map, const EstimateQuery& query,
                          const rc::scene::Material& material, const rc::Frame& shading,
                          const rc::Vec3& wo_local, EstimateScratch& scratch);
rc::Rgb estimate_irradiance(const rc::scene::Scene& scene, const PhotonMap& map, const EstimateQuery& query,
                            EstimateScratch& scratch);

/// The photon-tracing loop, shared by the two-pass mapper and SPPM: follows a photon path from
/// an emitted ray, calling store(photon, depth, specular_only) at every diffuse or glossy hit
/// (depth 0 = straight from the light; specular_only = only mirror and glass bounces before;
/// store may take the hit as a fourth argument),
/// which returns false to end the path. Russian roulette by the bounce's albedo keeps the power
/// of surviving photons steady. Returns the number of rays traced.
template <class Store>
uint64_t trace_photon_path(const rc::scene::Scene& scene, rc::scene::Ray ray, rc::Rgb power,
                           rc::util::Rng& rng, int max_depth, Store&& store);

}  // namespace gilt::photonmap

#include "photonmap/photon_map_inl.h"

#pragma once
// Pass 2 of photon mapping (Jensen 1996; "Realistic Image Synthesis Using Photon Mapping", 2001):
// camera rays through mirrors and glass to the first diffuse or glossy point x, where
//   direct light   comes from light sampling, MIS-weighted against the gather rays (Veach 1995);
//   caustics       come from the caustic map's density estimate at x;
//   indirect light comes from a final gather: cosine- (BSDF-) distributed rays from x whose hits
//                  look up irradiance precomputed at a fraction of the global photons
//                  (Christensen 1999, "Faster Photon Map Global Illumination"), each point's
//                  irradiance being direct light by shadow rays plus both maps' estimates.

#include <cstdint>
#include <string>
#include <vector>

#include "photonmap/photon_map.h"
#include "raytrace_core/render/render.h"

namespace gilt::photonmap {

/// Two-pass photon mapping. The defaults are the documented ones; zero radii are derived from the
/// scene's size.
struct PhotonMapperSettings {
  PhotonSettings photons;
  int k = 50;                  ///< photons per density estimate
  float max_radius = 0.0f;     ///< largest estimate radius (scene units); 0: 5 % of the scene's bounding radius
  /// Final-gather rays per camera sample (0: no final gather; the global map is then read
  /// directly at x). One: a pixel's spp samples then gather spp rays, stratified together, and at
  /// equal time the camera samples that 16 rays apiece would have cost average the direct light,
  /// the caustic map and the pixel's area as well: on cornell-caustics at 16 s relMSE fell from
  /// 0.0021 at 16 rays to 0.00095 at 4, 0.00064 at 2 and 0.00061 at 1 (bench/README.md).
  int gather_rays = 1;
  int precompute_stride = 4;   ///< irradiance is precomputed at sites from one path in n of the global map's
                               ///< paths (about one per n-th global photon; see the constructor)
  int direct_samples = 16;     ///< shadow rays per precomputed irradiance point
  int max_depth = 32;          ///< specular bounces followed from the camera and along gather rays
  IndexKind index = IndexKind::hash_grid;  ///< over the irradiance points (bench_photon --index)
};

/// What building the mapper did.
struct PhotonMapperStats {
  size_t global_photons = 0, caustic_photons = 0, irradiance_points = 0;
  uint64_t paths = 0;
  double trace_seconds = 0.0, precompute_seconds = 0.0;
  float max_radius = 0.0f;
  std::vector<std::string> skipped;  ///< passes not run and why
};

/// The photon maps of a scene, ready to render from. radiance() is a RadianceFunction for
/// raytrace_core::render::render_image; it is const and thread-safe.
class PhotonMapper {
 public:
  /// Traces the photons, builds the indexes and precomputes irradiance. `scene` must outlive it.
  PhotonMapper(const rc::scene::Scene& scene, const PhotonMapperSettings& settings);

  /// Radiance along a camera ray (W·sr⁻¹·m⁻²).
  rc::Rgb radiance(const rc::scene::Ray& ray, rc::render::SampleContext& ctx) const;

  const PhotonMapperStats& stats() const { return stats_; }
  const PhotonMaps& maps() const { return maps_; }

  /// Irradiance at a point from the precomputed points (nearest with an agreeing normal), or
  /// computed on the spot when none is near (W·m⁻²). `normal` faces the side being lit.
  rc::Rgb irradiance(const rc::Vec3& p, const rc::Vec3& normal, rc::render::Sampler& sampler) const;

 private:
  struct IrradiancePoint {
    rc::Vec3 position;
    uint32_t normal;  ///< encode_direction
    rc::Rgb irradiance;
  };

  rc::Rgb compute_irradiance(const rc::Vec3& p, const rc::Vec3& normal, rc::render::Sampler& sampler, int direct_samples) const;
  rc::Rgb shade(const rc::scene::SurfaceInteraction& si, const rc::Vec3& wo_world,
                rc::render::SampleContext& ctx) const;

  const rc::scene::Scene& scene_;
  PhotonMapperSettings settings_;
  PhotonMaps maps_;
  std::vector<IrradiancePoint> points_;
  PhotonIndex point_index_;
  float max_radius2_ = 0.0f;
  PhotonMapperStats stats_;
};

}  // namespace gilt::photonmap

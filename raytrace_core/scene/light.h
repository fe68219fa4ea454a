#pragma once
// Light sources: emissive triangles and spheres (area lights), point, spot, directional and a
// constant environment, and sampling of each from a point to be lit.

#include <cstdint>
#include <memory>
#include <span>

#include "raytrace_core/scene/environment_map.h"
#include "raytrace_core/scene/material.h"
#include "raytrace_core/scene/ray.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::raytrace_core::scene {

class Scene;

/// The kind of a light.
enum class LightKind : uint8_t {
  area_triangle,  ///< one emissive triangle: (geom_id, prim_id) of the scene's mesh
  area_sphere,    ///< one emissive sphere: prim_id indexes Scene::spheres
  point,          ///< isotropic point: `intensity` in W·sr⁻¹
  spot,           ///< point with a cone: `intensity` on the axis, smooth falloff from inner to outer
  directional,    ///< parallel light along `direction`: `irradiance` in W·m⁻² on a perpendicular plane
  environment,    ///< radiance from every direction at infinity: constant, or an image (`map`)
};

/// One light. Area lights take their radiance from the material of their primitive.
struct Light {
  LightKind kind = LightKind::point;
  uint32_t geom_id = 0, prim_id = 0;  ///< area lights: the emitting primitive
  Vec3 position{0.0f};                ///< point, spot
  Vec3 direction{0.0f, -1.0f, 0.0f};  ///< spot axis, or direction of travel of directional light (unit)
  Rgb intensity{0.0f};                ///< point, spot: W·sr⁻¹
  Rgb irradiance{0.0f};               ///< directional: W·m⁻²
  Rgb radiance{0.0f};                 ///< environment: W·sr⁻¹·m⁻², times the map's texel when there is one
  std::shared_ptr<const EnvironmentMap> map{};  ///< environment: an image of the sky (else constant)
  float cos_inner = 1.0f, cos_outer = 0.0f;  ///< spot cone, cosines of the half angles
  /// Directional: cosine of the angular radius of the disk it comes from (the sun's 0.27°); 1 is
  /// a point at infinity. Each light sample then comes from a direction uniform over the disk,
  /// which softens shadows, its irradiance on a plane facing it unchanged. Light sampling
  /// stands for it at every surface it can sample (a delta light to MIS); rays no light sampling
  /// stands for (camera rays, rays after a mirror or glass) see the disk (escaped_radiance).
  float cos_angle = 1.0f;
};

/// Light arriving at a point from one sampled position on a light.
struct LightSample {
  Rgb radiance{0.0f};  ///< incident radiance (delta lights: intensity / distance², or irradiance)
  Vec3 wi{0.0f};       ///< unit direction from the lit point towards the light
  float pdf = 0.0f;    ///< solid-angle density of wi (delta lights: 1); excludes light selection
  bool delta = false;  ///< point, spot or directional: not reachable by BSDF sampling
  Ray shadow_ray;      ///< visibility test between the lit point and the light sample
};

/// Whether `light` is an environment of one radiance in every direction (no map).
inline bool is_constant_environment(const Light& light) { return light.kind == LightKind::environment && !light.map; }

/// Samples light `light` from the reference surface point; empty radiance when nothing arrives.
///
/// `receiving` is the unit normal of the side of ref's surface that takes light (LightQuery::n),
/// or zero when light from every direction counts (a surface that transmits, a point in a
/// medium). Only a constant environment uses it: cosine-distributed about `receiving`, each of its
/// samples gives a Lambertian receiver under an open sky exactly its irradiance, where sampling
/// it over the whole sphere wastes half the samples below the horizon and weighs the rest by
/// cos θ (a standard deviation 1.29 times the mean). pbrt-v4 samples a uniform infinite light
/// over the sphere, or leaves it to BSDF sampling when its caller allows an incomplete density.
LightSample sample_light(const Scene& scene, const Light& light, const SurfacePoint& ref, Vec2 u,
                        const Vec3& receiving = Vec3(0.0f));

/// Whether a triangle light is sampled from p by the solid angle it subtends, and that angle.
///
/// Sampled by area, a direction towards the light has density r² / (A·cos θ) = r³ / (A·h) in
/// solid angle (h: p's distance from the light's plane), so across the light it varies as the
/// cube of the distance, between the nearest point of the triangle and its farthest corner.
/// Where that spread is small (the light small or far, as from most of a room) area sampling
/// already draws directions almost uniformly over the solid angle, at a fraction of the cost;
/// where it is large (beside or close to the light) it spikes, and solid-angle sampling is
/// used, when the angle is in the range samples_by_solid_angle allows. The test depends on p and
/// the triangle alone, so sample_light and light_pdf decide alike. 0: sampled by area.
double triangle_light_solid_angle(const Scene& scene, const Light& light, const Vec3& p);

/// Solid-angle density with which sample_light picks direction wi reaching the light at `on_light`
/// (area lights) from `ref`; environment ignores on_light. Zero for delta lights. `receiving` as
/// for sample_light: the density is sample_light's for the same one.
float light_pdf(const Scene& scene, const Light& light, const SurfacePoint& ref, const Vec3& wi,
                const SurfacePoint& on_light, const Vec3& receiving = Vec3(0.0f));

/// A ray of light leaving a light, for tracing photons.
struct EmissionSample {
  Ray ray;             ///< origin on the light (or outside the scene, on the bounding box's outline,
                       ///< for directional and environment light), direction of travel (unit)
  Rgb power{0.0f};     ///< W carried by this sample: emitted radiance·cos / (area pdf · direction pdf);
                       ///< averaged over samples it is light_power() (nearly, for an environment
                       ///< map or a directional light's disk)
  Vec3 normal{0.0f};   ///< surface normal at the origin (area lights), else the direction
};

/// Samples an emitted ray from `light`: area lights uniformly by area and cosine-distributed in
/// direction (either side if two-sided), point lights uniformly over the sphere, spot lights
/// uniformly inside the outer cone, directional and environment light from the outline of the
/// scene's bounding box seen along the direction of travel (an environment map's directions drawn
/// by its importance sampling). Zero power when the sample carries none.
EmissionSample sample_emission(const Scene& scene, const Light& light, Vec2 u_position, Vec2 u_direction);

/// Emitted power of the light in W (per channel), used to choose lights in proportion to power.
Rgb light_power(const Scene& scene, const Light& light);

/// Radiance of environment light `light` arriving from direction w (unit, pointing away from the
/// scene): its constant radiance, times its map's texel in that direction when it has a map.
Rgb environment_radiance(const Light& light, const Vec3& w);
/// The sum of environment_radiance over the environment lights among `lights`: what a ray that
/// leaves the scene along w sees. Pass Scene::punctual_lights: lights() also holds every emitting
/// triangle, and visiting them per escaped ray made a scene of 15,000 emitters 20 times slower.
Rgb environment_radiance(std::span<const Light> lights, const Vec3& w);

/// Radiance of the disks of the directional lights among `lights` that w (unit, towards the
/// light) falls in: irradiance / solid angle of the disk, so that the disk seen gives what a
/// light sample of it gives. None for a directional light without a disk (cos_angle = 1).
Rgb sun_disk_radiance(std::span<const Light> lights, const Vec3& w);

/// What a ray leaving the scene along w sees when no light sampling stands for it (a camera ray,
/// a ray after a mirror or glass): the environment, and the directional lights' disks. Pass
/// Scene::punctual_lights.
Rgb escaped_radiance(std::span<const Light> lights, const Vec3& w);

/// Radiance emitted by a surface of material m towards direction w leaving it (front = ng side).
Rgb emitted_radiance(const Material& m, const Vec3& ng, const Vec3& w);

}  // namespace gilt::raytrace_core::scene

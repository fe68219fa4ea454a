#pragma once
// The scene: triangle meshes and analytic spheres with materials, lights and a camera, traversed
// by Embree in robust mode.
//
// Fill the public data (a loader does this), then call commit(): it validates the geometry,
// drops degenerate triangles, builds the Embree scene and the light list. Queries are const and
// thread-safe after commit().

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <span>
#include <vector>

#include "raytrace_core/scene/camera.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/scene/light_sampler.h"
#include "raytrace_core/scene/material.h"
#include "raytrace_core/util/math.h"
#include "raytrace_core/scene/ray.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::raytrace_core::scene {

/// Where a mesh came from in the model file it was read from, so that results computed on the
/// scene (baked colours) can be written back onto that file's own vertices.
struct MeshOrigin {
  int32_t file = -1;       ///< index into Scene::model_files; -1: built by code, not read from a file
  int32_t node = -1;       ///< glTF: the node that placed this instance of the mesh
  int32_t mesh = -1;       ///< glTF: the mesh
  int32_t primitive = -1;  ///< glTF: the primitive; its vertex i is this mesh's vertex i
  /// OBJ and PLY: the file's vertex (OBJ: its `v` line, from 0) of each mesh vertex; empty when
  /// vertex i is the file's vertex i.
  std::vector<uint32_t> vertex;
};

/// An indexed triangle mesh of one material.
struct TriangleMesh {
  std::string name;
  MeshOrigin origin;
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;     ///< per-vertex shading normals, empty or one per position
  std::vector<Vec2> uvs;         ///< per-vertex texture coordinates, empty or one per position
  /// Per-vertex tangent (xyz) and handedness (w = ±1, the bitangent being w · n × t) of the
  /// material's normal map: a loader's (glTF's TANGENT), else made by commit() when the material
  /// has one (normal_map.h). commit() empties it for materials without one.
  std::vector<glm::vec4> tangents;
  std::vector<uint32_t> indices; ///< three per triangle, counter-clockwise seen from the front
  uint32_t material = 0;
  /// commit() drops triangles of no area, which renumbers the rest. A mesh whose triangle index
  /// is a key into arrays kept elsewhere (radiosity elements: Hit::prim_id is the element) keeps
  /// them instead; no ray hits them and point queries pass them by.
  bool keep_degenerate = false;

  size_t triangle_count() const { return indices.size() / 3; }
};

/// An analytic sphere. Its front (outside) is the emitting side of an emissive sphere.
struct Sphere {
  Vec3 center{0.0f};
  float radius = 1.0f;
  uint32_t material = 0;
};

/// Render defaults a scene file may set; the command line overrides them.
struct RenderDefaults {
  int width = 512;
  int height = 512;
  int spp = 64;
};

/// Rounding-error bound factor γ(n) = nε / (1 − nε) with ε = 2⁻²⁴ (Higham; PBRT §3.9).
constexpr float error_gamma(int n) {
  constexpr float eps = 0x1p-24f;
  return (n * eps) / (1.0f - n * eps);
}

/// Compact result of a closest-hit query; surface() expands it when shading needs it.
struct Hit {
  float t = kInfinity;
  uint32_t geom_id = 0;  ///< mesh index, or Scene::sphere_geom_id() for spheres
  uint32_t prim_id = 0;  ///< triangle index within the mesh, or sphere index
  float u = 0.0f, v = 0.0f;  ///< barycentrics of the triangle's second and third vertex
};

/// Everything shading needs about a hit point.
struct SurfaceInteraction : SurfacePoint {
  Vec3 ns{0.0f, 0.0f, 1.0f};  ///< unit shading normal, on the same side as ng
  Vec2 uv{0.0f};
  /// Change of uv across the footprint of the camera pixel whose cone made the hit (Ray::spread,
  /// Ray::width), along its two axes; zero for other rays, whose lookups read the finest level.
  Vec2 duv_dx{0.0f}, duv_dy{0.0f};
  /// The cone of the ray that made the hit, at the hit: its width (Ray::width + Ray::spread × the
  /// distance) and its spread. continue_ray carries it on.
  float cone_width = 0.0f, cone_spread = 0.0f;
  uint32_t material = 0;
  int32_t light = -1;          ///< index into Scene::lights() when the surface emits, else −1
  bool front_face = true;      ///< the ray arrived on the ng side
};

/// A ray leaving si in `direction` that carries on the cone of the camera ray whose path reached
/// si: it starts as wide as the cone was at si and widens by the pixel's angle. So a hit after
/// any bounce filters its textures over the pixel's angle times the path's length so far, never
/// less than the camera ray's own footprint there. pbrt-v4 takes the footprint the camera would
/// see at such a hit (CameraBase::Approximate_dp_dxy); the path's length is at least the
/// camera's distance, so this footprint is at least as wide, and needs no camera.
inline Ray continue_ray(const SurfaceInteraction& si, const Vec3& direction) {
  Ray ray = spawn_ray(si, direction);
  ray.width = si.cone_width;
  ray.spread = si.cone_spread;
  return ray;
}

/// A scene ready for ray queries after commit().
class Scene {
 public:
  Scene();
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // --- Scene description, filled by loaders before commit(). ---
  std::string name;
  std::vector<TriangleMesh> meshes;
  std::vector<Sphere> spheres;
  std::vector<Material> materials;
  std::vector<TextureImage> textures;  ///< the images materials read (TextureRef::image)
  std::vector<Light> punctual_lights;  ///< point, spot, directional and environment lights
  std::optional<Camera> camera;        ///< the scene's own camera, if it has one
  std::vector<NamedCamera> cameras;    ///< every camera its files define, in file order (select_camera)
  RenderDefaults render;
  std::vector<std::string> warnings;   ///< non-fatal problems found while loading or committing
  std::vector<std::string> model_files;  ///< the mesh files read, as given (see MeshOrigin::file)

  /// Validates the description (throws InputError naming the mesh and field on NaN or infinite
  /// coordinates, bad indices or material references), drops degenerate triangles with a
  /// warning, and builds the acceleration structure and the light list. Call once.
  void commit();
  bool committed() const { return committed_; }

  // --- Queries, valid after commit(). ---

  /// Closest intersection along the ray within (0, tmax], if any.
  std::optional<Hit> intersect(const Ray& ray) const;
  /// True when anything blocks the ray within (0, tmax].
  bool occluded(const Ray& ray) const;
  /// Surface details of a hit found along `ray`.
  SurfaceInteraction surface(const Ray& ray, const Hit& hit) const;
  /// The point nearest to p, closer than `radius`, on a triangle of mesh `geom_id` whose
  /// geometric normal has a cosine above `min_cosine` with the unit vector n; its distance is
  /// the Hit's t and (u, v) its barycentrics. Ties go to the lower triangle index.
  std::optional<Hit> nearest_triangle(uint32_t geom_id, const Vec3& p, float radius, const Vec3& n,
                                      float min_cosine) const;
  /// Whether triangle prim_id of mesh geom_id lies on a closed surface, one that bounds a solid
  /// (closed_surface.h); spheres always do. Worked out per mesh on first use, then kept.
  bool on_closed_surface(uint32_t geom_id, uint32_t prim_id) const;
  /// Calls f(geom_id, prim_id) for every triangle whose bounding box reaches within `radius`
  /// of p (a superset of the triangles that do: the caller tests the triangle itself), in no set
  /// order.
  void for_each_triangle_near(const Vec3& p, float radius,
                              const std::function<void(uint32_t geom_id, uint32_t prim_id)>& f) const;

  /// All lights: one per emissive triangle and sphere, then the punctual lights.
  const std::vector<Light>& lights() const { return lights_; }
  /// Indices into lights() of the environment lights, so that a ray escaping the scene need not
  /// visit every emitting triangle to find them.
  std::span<const uint32_t> environment_lights() const { return environment_lights_; }
  /// Light chosen with probability proportional to its power: where photons start.
  const util::Distribution1D& light_distribution() const { return light_distribution_; }
  /// Light chosen for a point to be lit (next-event estimation), and its probability for MIS.
  const LightSampler& light_sampler() const { return light_sampler_; }
  /// How light_sampler() chooses: by the light BVH (default) or by power alone. Set before rendering.
  void set_light_sampling(LightSampling mode) { light_sampler_.set_mode(mode); }
  /// Bounds of all finite geometry.
  const Bounds3& bounds() const { return bounds_; }
  /// Geometry id Embree gives the spheres.
  uint32_t sphere_geom_id() const { return static_cast<uint32_t>(meshes.size()); }
  /// Total triangle count after commit().
  size_t triangle_count() const;
  /// The camera to render with: the scene's own, or a default view that frames its bounds for an
  /// image of the given aspect ratio (width / height; 0: the scene's render size).
  Camera effective_camera(float aspect = 0.0f) const;

  /// Area of one triangle or sphere, in scene units².
  float primitive_area(uint32_t geom_id, uint32_t prim_id) const;
  /// Material of one primitive.
  const Material& primitive_material(uint32_t geom_id, uint32_t prim_id) const;
  /// The material as it is at one surface point: the scene's own when it is not textured,
  /// else `scratch` filled with its parameters looked up at si.uv, filtered over the footprint
  /// si.duv_dx, si.duv_dy.
  const Material& shading_material(const SurfaceInteraction& si, Material& scratch) const;
  /// Mean albedo of a material over a triangle with texture coordinates uv0, uv1, uv2.
  Rgb mean_albedo(const Material& m, Vec2 uv0, Vec2 uv1, Vec2 uv2) const;
  /// Emitted radiance factor of a material at texture coordinates uv (emission × emission texture).
  Rgb emission_at(const Material& m, Vec2 uv) const;
  /// Tangent-space normal that material m's normal or height map gives at `uv` (m must have one,
  /// and the scene textures).
  Vec3 mapped_normal(const Material& m, Vec2 uv) const;
  /// Mean emitted radiance factor over one primitive: what its light's power is built from.
  Rgb mean_emission(uint32_t geom_id, uint32_t prim_id) const;
  /// The scene's opened textures (null when it has none).
  const TextureSet* texture_set() const { return texture_set_.get(); }
  /// Surface point on a triangle at barycentrics (b1, b2) of its second and third vertex.
  SurfaceInteraction triangle_point(uint32_t geom_id, uint32_t prim_id, Vec2 barycentrics) const;
  /// Point on sphere `prim_id` in the direction `dir` (unit) from its centre.
  SurfaceInteraction sphere_point(uint32_t prim_id, const Vec3& dir) const;

  /// The Embree scene handle, for benchmarks comparing against raw Embree calls.
  void* embree_scene() const;

 private:
  /// Fills si.duv_dx, si.duv_dy with the footprint of `ray`'s cone (Ray::spread) at its hit on a
  /// triangle with texture coordinates.
  void pixel_footprint(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const;
  /// The uv change along world-space offset v in the plane of the triangle with corners c.
  static Vec2 uv_offset(const TriangleMesh& mesh, const uint32_t* c, const Vec3& v);
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<Light> lights_;
  std::vector<uint32_t> environment_lights_;
  util::Distribution1D light_distribution_;
  LightSampler light_sampler_;
  Bounds3 bounds_;
  bool committed_ = false;
  std::vector<int32_t> first_light_of_mesh_;  // light index of triangle 0 of an emissive mesh, or −1
  std::vector<int32_t> light_of_sphere_;      // light index of each sphere, or −1
  std::unique_ptr<TextureSet> texture_set_;
};

}  // namespace gilt::raytrace_core::scene

// Scene validation, Embree traversal (robust mode) and hit-point reconstruction.
//
// Triangles go to Embree's built-in triangle geometry. Spheres are an Embree user geometry
// intersected in double precision with the numerically stable quadratic of Haines et al.,
// "Precision Improvements for Ray/Sphere Intersection" (Ray Tracing Gems, 2019), so that the
// 1e5-radius walls of the smallpt scene intersect as cleanly as a unit sphere.

#include "raytrace_core/scene/scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <string>

#include "raytrace_core/scene/closed_surface.h"
#include "raytrace_core/scene/normal_map.h"
#include "raytrace_core/util/closest_point.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"

namespace gilt::raytrace_core::scene {
namespace {

std::string embree_error_message(RTCError code) {
  switch (code) {
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    default: return "error " + std::to_string(static_cast<int>(code));
  }
}

// Embree reports errors through a C callback, which must not throw: keep the message and let
// commit() throw after the call that failed.
thread_local std::string embree_last_message;
void on_embree_error(void*, RTCError, const char* message) { embree_last_message = message ? message : ""; }

void check_embree(RTCDevice device, const char* what) {
  const RTCError code = rtcGetDeviceError(device);
  if (code != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree: ") + what + ": " + embree_error_message(code) +
                             (embree_last_message.empty() ? "" : ": " + embree_last_message));
}

/// The process-wide Embree device, created on first use.
RTCDevice embree_device() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice(nullptr);
    if (!d) throw std::runtime_error("Embree: cannot create a device: " + embree_error_message(rtcGetDeviceError(nullptr)));
    rtcSetDeviceErrorFunction(d, on_embree_error, nullptr);
    return d;
  }();
  return device;
}

/// Nearest root of the ray–sphere quadratic within (tnear, tfar], or a negative value.
double intersect_sphere(const Sphere& s, const DVec3& o, const DVec3& d, double tnear, double tfar) {
  const DVec3 f = o - DVec3(s.center);
  const double a = glm::dot(d, d);
  const double b_half = glm::dot(f, d);
  const DVec3 l = f - (b_half / a) * d;  // f minus its projection on d: avoids b² − 4ac cancellation
  const double r = s.radius;
  const double disc = r * r - glm::dot(l, l);
  if (disc < 0.0) return -1.0;
  const double c = glm::dot(f, f) - r * r;
  const double q = -b_half - std::copysign(std::sqrt(a * disc), b_half);
  double t0 = c / q, t1 = q / a;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > tnear && t0 <= tfar) return t0;
  if (t1 > tnear && t1 <= tfar) return t1;
  return -1.0;
}

void sphere_bounds(const RTCBoundsFunctionArguments* args) {
  const auto& spheres = *static_cast<const std::vector<Sphere>*>(args->geometryUserPtr);
  const Sphere& s = spheres[args->primID];
  RTCBounds* b = args->bounds_o;
  // Round outwards so the box contains the exact sphere.
  b->lower_x = std::nextafter(s.center.x - s.radius, -kInfinity);
  b->lower_y = std::nextafter(s.center.y - s.radius, -kInfinity);
  b->lower_z = std::nextafter(s.center.z - s.radius, -kInfinity);
  b->upper_x = std::nextafter(s.center.x + s.radius, kInfinity);
  b->upper_y = std::nextafter(s.center.y + s.radius, kInfinity);
  b->upper_z = std::nextafter(s.center.z + s.radius, kInfinity);
}

// Scene queries use rtcIntersect1 / rtcOccluded1 only, so callbacks always see N == 1.
void sphere_intersect(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  const auto& spheres = *static_cast<const std::vector<Sphere>*>(args->geometryUserPtr);
  auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
  const DVec3 o(rh->ray.org_x, rh->ray.org_y, rh->ray.org_z);
  const DVec3 d(rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z);
  const double t = intersect_sphere(spheres[args->primID], o, d, rh->ray.tnear, rh->ray.tfar);
  if (t < 0.0) return;
  rh->ray.tfar = static_cast<float>(t);
  const DVec3 n = o + t * d - DVec3(spheres[args->primID].center);
  rh->hit.Ng_x = static_cast<float>(n.x);
  rh->hit.Ng_y = static_cast<float>(n.y);
  rh->hit.Ng_z = static_cast<float>(n.z);
  rh->hit.u = rh->hit.v = 0.0f;
  rh->hit.primID = args->primID;
  rh->hit.geomID = args->geomID;
  rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

void sphere_occluded(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;
  const auto& spheres = *static_cast<const std::vector<Sphere>*>(args->geometryUserPtr);
  auto* ray = reinterpret_cast<RTCRay*>(args->ray);
  const DVec3 o(ray->org_x, ray->org_y, ray->org_z);
  const DVec3 d(ray->dir_x, ray->dir_y, ray->dir_z);
  if (intersect_sphere(spheres[args->primID], o, d, ray->tnear, ray->tfar) >= 0.0) ray->tfar = -kInfinity;
}

bool finite3(const Vec3& v) { return is_finite(v); }

}  // namespace

/// What a mesh whose material has coverage needs to answer, at a hit, whether the ray stops.
struct AlphaTest {
  const TriangleMesh* mesh = nullptr;
  const TextureSet* textures = nullptr;
  const Material* material = nullptr;
  bool alpha_in_rgb = false;  ///< the alpha texture has no alpha channel: its first one is coverage

  float coverage(uint32_t prim, float b1, float b2) const {
    float a = material->alpha;
    if (material->alpha_texture.valid() && textures) {
      const uint32_t* c = &mesh->indices[3 * size_t(prim)];
      const Vec2 uv = mesh->uvs.empty() ? Vec2(b1, b2)
                                        : (1.0f - b1 - b2) * mesh->uvs[c[0]] + b1 * mesh->uvs[c[1]] + b2 * mesh->uvs[c[2]];
      const Texel t = textures->lookup(material->alpha_texture.image, material->alpha_texture.st(uv));
      a *= alpha_in_rgb ? t.rgb.r : t.alpha;
    }
    return a;
  }
};

namespace {

/// A number in [0, 1) fixed by the ray and the primitive: BLEND's stochastic choice, the same
/// every time the same ray meets the same triangle (so results do not depend on threads).
float coverage_sample(const Vec3& o, const Vec3& d, uint32_t geom, uint32_t prim) {
  uint64_t h = 0x9e3779b97f4a7c15ull ^ (uint64_t(geom) << 32 | prim);
  for (float f : {o.x, o.y, o.z, d.x, d.y, d.z}) {
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    h = (h ^ bits) * 0xff51afd7ed558ccdull;
    h ^= h >> 33;
  }
  h *= 0xc4ceb9fe1a85ec53ull;
  h ^= h >> 33;
  return float(h >> 40) * 0x1p-24f;
}

/// Embree's filter for intersection and occlusion alike: rejects a hit where the surface is
/// not there (below the cutoff, or not chosen by its alpha).
void alpha_filter(const RTCFilterFunctionNArguments* args) {
  if (!args->valid[0]) return;
  const auto& test = *static_cast<const AlphaTest*>(args->geometryUserPtr);
  const uint32_t prim = RTCHitN_primID(args->hit, args->N, 0);
  const float a = test.coverage(prim, RTCHitN_u(args->hit, args->N, 0), RTCHitN_v(args->hit, args->N, 0));
  bool keep;
  if (test.material->alpha_mode == AlphaMode::mask) {
    keep = a >= test.material->alpha_cutoff;
  } else {
    const Vec3 o(RTCRayN_org_x(args->ray, args->N, 0), RTCRayN_org_y(args->ray, args->N, 0), RTCRayN_org_z(args->ray, args->N, 0));
    const Vec3 d(RTCRayN_dir_x(args->ray, args->N, 0), RTCRayN_dir_y(args->ray, args->N, 0), RTCRayN_dir_z(args->ray, args->N, 0));
    keep = coverage_sample(o, d, RTCHitN_geomID(args->hit, args->N, 0), prim) < a;
  }
  if (!keep) args->valid[0] = 0;
}


// --- Scene::commit's passes, in the order it runs them. ---

/// Pass 1. Reads every material and the number of textures; writes nothing. Throws InputError
/// naming the first material whose parameters are not finite, out of range or refer to a
/// texture that does not exist.
void validate_materials(const std::vector<Material>& materials, size_t texture_count, const std::string& where) {
  for (size_t mi = 0; mi < materials.size(); ++mi) {
    const Material& m = materials[mi];
    const std::string id = where + ": material '" + m.name + "'";
    if (!m.albedo.is_finite() || !m.specular.is_finite() || !m.emission.is_finite() || !m.absorption.is_finite() ||
        !std::isfinite(m.exponent) || !std::isfinite(m.ior))
      throw InputError(id + ": parameters must be finite numbers");
    if (m.albedo.r < 0 || m.albedo.g < 0 || m.albedo.b < 0 || m.specular.r < 0 || m.specular.g < 0 || m.specular.b < 0 ||
        m.emission.r < 0 || m.emission.g < 0 || m.emission.b < 0 || m.absorption.r < 0 || m.absorption.g < 0 ||
        m.absorption.b < 0 || m.exponent < 0)
      throw InputError(id + ": reflectance, emission, absorption and exponent must not be negative");
    if (m.kind == MaterialKind::dielectric && !(m.ior > 0.0f)) throw InputError(id + ": ior must be positive");
    if (!(m.metallic >= 0.0f && m.metallic <= 1.0f) || !(m.roughness >= 0.0f && m.roughness <= 1.0f))
      throw InputError(id + ": metallic and roughness must lie in [0, 1]");
    if (!m.transmission_tint.is_finite() || m.transmission_tint.min_component() < 0.0f ||
        m.transmission_tint.max_component() > 1.0f)
      throw InputError(id + ": transmission tint must lie in [0, 1]");
    if (!std::isfinite(m.normal_scale)) throw InputError(id + ": normal map scale must be finite");
    for (const TextureRef* t : m.texture_refs()) {
      if (t->image >= int32_t(texture_count) || t->image < -1)
        throw InputError(id + ": refers to texture " + std::to_string(t->image) + " but there are " +
                         std::to_string(texture_count));
      for (float x : t->map)
        if (!std::isfinite(x)) throw InputError(id + ": texture transform must be finite");
    }
    if (!(m.alpha >= 0.0f && m.alpha <= 1.0f) || !(m.alpha_cutoff >= 0.0f && m.alpha_cutoff <= 1.0f))
      throw InputError(id + ": alpha and alpha cutoff must lie in [0, 1]");
  }
}

/// Throws InputError unless `material` is the index of one of `material_count` materials.
void check_material_index(uint32_t material, size_t material_count, const std::string& where,
                          const std::string& what) {
  if (material >= material_count)
    throw InputError(where + ": " + what + " refers to material " + std::to_string(material) + " but there are " +
                     std::to_string(material_count));
}

/// Pass 2a, for one mesh (`what` names it). Reads the mesh's arrays and the materials; writes
/// the mesh's uvs (non-finite ones become 0) and normals (unusable ones become 0, i.e. fall back
/// to ng), and to `warnings` when a textured material's mesh has no uvs. Throws InputError on a
/// bad material index, index count, array size or a non-finite vertex.
void check_mesh_arrays(TriangleMesh& mesh, const std::vector<Material>& materials, const std::string& where,
                       const std::string& what, std::vector<std::string>& warnings) {
  check_material_index(mesh.material, materials.size(), where, what);
  if (mesh.indices.size() % 3 != 0) throw InputError(where + ": " + what + ": index count is not a multiple of 3");
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
    throw InputError(where + ": " + what + ": has " + std::to_string(mesh.normals.size()) + " normals for " +
                     std::to_string(mesh.positions.size()) + " positions");
  if (mesh.uvs.empty() && mesh.material < materials.size() && materials[mesh.material].is_textured() &&
      !mesh.indices.empty())
    warnings.push_back(where + ": " + what + ": has no texture coordinates, so its material's texture reads one texel");
  for (Vec2& uv : mesh.uvs)
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = Vec2(0.0f);
  if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
    throw InputError(where + ": " + what + ": has " + std::to_string(mesh.uvs.size()) + " texture coordinates for " +
                     std::to_string(mesh.positions.size()) + " positions");
  for (size_t vi = 0; vi < mesh.positions.size(); ++vi)
    if (!finite3(mesh.positions[vi]))
      throw InputError(where + ": " + what + ": vertex " + std::to_string(vi) + " has a NaN or infinite coordinate");
  for (Vec3& n : mesh.normals)
    if (!finite3(n) || glm::dot(n, n) == 0.0f) n = Vec3(0.0f);  // unusable normal: fall back to ng
}

/// Pass 2b, for one mesh (`what` names it). Reads its positions and indices; writes its indices
/// without the triangles of no (or no finite) area, unless it keeps them (keep_degenerate).
/// Returns how many it dropped. Throws InputError on an index past the vertices.
size_t drop_degenerate_triangles(TriangleMesh& mesh, const std::string& where, const std::string& what) {
  size_t dropped = 0;
  std::vector<uint32_t> kept;
  kept.reserve(mesh.indices.size());
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t i0 = mesh.indices[3 * t], i1 = mesh.indices[3 * t + 1], i2 = mesh.indices[3 * t + 2];
    if (i0 >= mesh.positions.size() || i1 >= mesh.positions.size() || i2 >= mesh.positions.size())
      throw InputError(where + ": " + what + ": triangle " + std::to_string(t) + " refers to a vertex past the " +
                       std::to_string(mesh.positions.size()) + " it has");
    const Vec3 c = glm::cross(mesh.positions[i1] - mesh.positions[i0], mesh.positions[i2] - mesh.positions[i0]);
    const float len2 = glm::dot(c, c);
    if ((!(len2 > 0.0f) || !std::isfinite(len2)) && !mesh.keep_degenerate) {
      ++dropped;
      continue;
    }
    kept.insert(kept.end(), {i0, i1, i2});
  }
  mesh.indices = std::move(kept);
  return dropped;
}

/// Pass 2c, for one mesh of material m. Reads the mesh and m's normal map; writes its tangents:
/// none without a normal map (or uvs); else the file's (glTF's TANGENT) when it gives a usable
/// one for every vertex, else made here.
void prepare_tangents(TriangleMesh& mesh, const Material& m) {
  if (!m.normal_texture.valid() || mesh.uvs.empty()) {
    mesh.tangents.clear();
  } else {
    const bool usable = mesh.tangents.size() == mesh.positions.size() &&
                        std::all_of(mesh.tangents.begin(), mesh.tangents.end(), [](const glm::vec4& t) {
                          return std::isfinite(t.x + t.y + t.z + t.w) && glm::dot(Vec3(t), Vec3(t)) > 0.0f;
                        });
    if (!usable) mesh.tangents = generate_tangents(mesh, m.normal_texture);
  }
}

/// Pass 2: passes 2a–2c over every mesh, in order. Reads and writes the meshes; reads the
/// materials; writes to `warnings` (one line for all dropped triangles, after the meshes' own).
void repair_meshes(std::vector<TriangleMesh>& meshes, const std::vector<Material>& materials,
                   const std::string& where, std::vector<std::string>& warnings) {
  size_t dropped = 0;
  for (size_t gi = 0; gi < meshes.size(); ++gi) {
    TriangleMesh& mesh = meshes[gi];
    const std::string what = "mesh '" + (mesh.name.empty() ? std::to_string(gi) : mesh.name) + "'";
    check_mesh_arrays(mesh, materials, where, what, warnings);
    dropped += drop_degenerate_triangles(mesh, where, what);
    prepare_tangents(mesh, materials[mesh.material]);
  }
  if (dropped > 0) warnings.push_back(where + ": " + std::to_string(dropped) + " degenerate triangle(s) dropped");
}

/// Pass 3. Reads the spheres and the number of materials; writes nothing. Throws InputError on
/// a bad material index, a non-finite centre or a radius that is not positive.
void validate_spheres(const std::vector<Sphere>& spheres, size_t material_count, const std::string& where) {
  for (size_t si = 0; si < spheres.size(); ++si) {
    const Sphere& s = spheres[si];
    check_material_index(s.material, material_count, where, "sphere " + std::to_string(si));
    if (!finite3(s.center) || !std::isfinite(s.radius) || !(s.radius > 0.0f))
      throw InputError(where + ": sphere " + std::to_string(si) + ": centre must be finite and radius positive");
  }
}

/// Pass 4. Reads the punctual lights, checks them all (throws InputError on an area light, a
/// non-finite parameter or a spot or directional light without a direction), then writes their
/// directions normalised.
void validate_punctual_lights(std::vector<Light>& lights, const std::string& where) {
  for (size_t li = 0; li < lights.size(); ++li) {
    const Light& l = lights[li];
    const std::string id = where + ": light " + std::to_string(li);
    if (l.kind == LightKind::area_triangle || l.kind == LightKind::area_sphere)
      throw InputError(id + ": area lights come from emissive materials, not the light list");
    if (!finite3(l.position) || !finite3(l.direction) || !l.intensity.is_finite() || !l.irradiance.is_finite() ||
        !l.radiance.is_finite() || !std::isfinite(l.cos_inner) || !std::isfinite(l.cos_outer))
      throw InputError(id + ": parameters must be finite numbers");
    if ((l.kind == LightKind::spot || l.kind == LightKind::directional) && !(glm::dot(l.direction, l.direction) > 0.0f))
      throw InputError(id + ": direction must not be zero");
  }
  for (Light& l : lights)
    if (glm::dot(l.direction, l.direction) > 0.0f) l.direction = glm::normalize(l.direction);
}

/// Pass 5a, for mesh `geom_id` of material m. Reads the mesh; writes a triangle geometry of it
/// into `scene` under that id and, when m has coverage, an AlphaTest into `alpha_tests` (which
/// keeps the addresses of mesh, m and textures: they must outlive the scene).
void attach_mesh_geometry(RTCDevice device, RTCScene scene, const TriangleMesh& mesh, unsigned geom_id,
                          const Material& m, const TextureSet* textures,
                          std::vector<std::unique_ptr<AlphaTest>>& alpha_tests) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), mesh.positions.size()));
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    vb[3 * i] = mesh.positions[i].x;
    vb[3 * i + 1] = mesh.positions[i].y;
    vb[3 * i + 2] = mesh.positions[i].z;
  }
  auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(uint32_t), mesh.triangle_count()));
  std::copy(mesh.indices.begin(), mesh.indices.end(), ib);
  if (m.has_coverage()) {
    auto test = std::make_unique<AlphaTest>();
    test->mesh = &mesh;  // the vector's elements stay put when the Scene is moved
    test->textures = textures;
    test->material = &m;
    test->alpha_in_rgb = m.alpha_in_colour && m.alpha_texture.valid() && textures &&
                         textures->channels(m.alpha_texture.image) % 2 == 1;
    rtcSetGeometryUserData(geom, test.get());
    rtcSetGeometryIntersectFilterFunction(geom, alpha_filter);
    rtcSetGeometryOccludedFilterFunction(geom, alpha_filter);
    alpha_tests.push_back(std::move(test));
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, geom_id);
  rtcReleaseGeometry(geom);
}

/// Pass 5b. Reads the spheres; writes their stable copy `kept` (Embree's user data) and one user
/// geometry of them all into `scene` under `geom_id`.
void attach_sphere_geometry(RTCDevice device, RTCScene scene, const std::vector<Sphere>& spheres,
                            std::vector<Sphere>& kept, unsigned geom_id) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geom, static_cast<unsigned>(spheres.size()));
  kept = spheres;
  rtcSetGeometryUserData(geom, &kept);
  rtcSetGeometryBoundsFunction(geom, sphere_bounds, nullptr);
  rtcSetGeometryIntersectFunction(geom, sphere_intersect);
  rtcSetGeometryOccludedFunction(geom, sphere_occluded);
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, geom_id);
  rtcReleaseGeometry(geom);
}

/// Pass 6. Reads the meshes' indexed vertices and the spheres; returns the box around them.
Bounds3 geometry_bounds(const std::vector<TriangleMesh>& meshes, const std::vector<Sphere>& spheres) {
  Bounds3 bounds{};
  for (const TriangleMesh& mesh : meshes)
    for (uint32_t i : mesh.indices) bounds.extend(mesh.positions[i]);
  for (const Sphere& s : spheres) {
    bounds.extend(s.center - Vec3(s.radius));
    bounds.extend(s.center + Vec3(s.radius));
  }
  return bounds;
}

/// The light tables Scene::commit fills (its private members).
struct LightTables {
  std::vector<Light>& lights;
  std::vector<int32_t>& first_light_of_mesh;
  std::vector<int32_t>& light_of_sphere;
  std::vector<uint32_t>& environment_lights;
};

/// Pass 7. Reads the meshes, spheres, their materials and the punctual lights; writes `out`:
/// one light per emissive triangle (mesh by mesh), then per emissive sphere, then the punctual
/// lights, with the index of each emissive mesh's first light, of each sphere's light and of
/// the environment lights.
void collect_lights(const std::vector<TriangleMesh>& meshes, const std::vector<Sphere>& spheres,
                    const std::vector<Material>& materials, const std::vector<Light>& punctual_lights,
                    uint32_t sphere_geom_id, const LightTables& out) {
  out.lights.clear();
  out.first_light_of_mesh.assign(meshes.size(), -1);
  out.light_of_sphere.assign(spheres.size(), -1);
  for (size_t gi = 0; gi < meshes.size(); ++gi) {
    if (!materials[meshes[gi].material].is_emissive() || meshes[gi].triangle_count() == 0) continue;
    out.first_light_of_mesh[gi] = static_cast<int32_t>(out.lights.size());
    for (size_t t = 0; t < meshes[gi].triangle_count(); ++t) {
      Light l;
      l.kind = LightKind::area_triangle;
      l.geom_id = static_cast<uint32_t>(gi);
      l.prim_id = static_cast<uint32_t>(t);
      out.lights.push_back(l);
    }
  }
  for (size_t si = 0; si < spheres.size(); ++si) {
    if (!materials[spheres[si].material].is_emissive()) continue;
    out.light_of_sphere[si] = static_cast<int32_t>(out.lights.size());
    Light l;
    l.kind = LightKind::area_sphere;
    l.geom_id = sphere_geom_id;
    l.prim_id = static_cast<uint32_t>(si);
    out.lights.push_back(l);
  }
  out.lights.insert(out.lights.end(), punctual_lights.begin(), punctual_lights.end());
  for (size_t i = out.lights.size() - punctual_lights.size(); i < out.lights.size(); ++i)
    if (out.lights[i].kind == LightKind::environment) out.environment_lights.push_back(uint32_t(i));
}
}  // namespace

struct AlphaTest;

struct Scene::Impl {
  RTCScene scene = nullptr;
  std::once_flag closed_once;  // on_closed_surface's table, made on first use
  std::vector<std::vector<char>> closed;
  std::vector<std::unique_ptr<AlphaTest>> alpha_tests;  // Embree's user data for cut-out meshes
  std::vector<Sphere> spheres;  // Embree's user data: a stable copy that survives moves of Scene
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
  }
};

Scene::Scene() : impl_(std::make_unique<Impl>()) {}
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

// A driver over named passes (above): validate the description, repair the meshes, build
// Embree's scene, then the bounds and the lights. Each pass throws before the next one runs.
void Scene::commit() {
  if (committed_) throw std::logic_error("Scene::commit called twice");
  const std::string where = name.empty() ? std::string("scene") : name;

  // Validate the description (and repair what can be) before anything is built.
  validate_materials(materials, textures.size(), where);
  if (!textures.empty()) texture_set_ = std::make_unique<TextureSet>(textures);
  repair_meshes(meshes, materials, where, warnings);
  validate_spheres(spheres, materials.size(), where);
  validate_punctual_lights(punctual_lights, where);
  if (camera) camera->validate();

  // Build Embree's scene: mesh gi is geometry gi, the spheres one geometry after them.
  RTCDevice device = embree_device();
  impl_->scene = rtcNewScene(device);
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  for (size_t gi = 0; gi < meshes.size(); ++gi)
    attach_mesh_geometry(device, impl_->scene, meshes[gi], static_cast<unsigned>(gi), materials[meshes[gi].material],
                         texture_set_.get(), impl_->alpha_tests);
  if (!spheres.empty()) attach_sphere_geometry(device, impl_->scene, spheres, impl_->spheres, sphere_geom_id());
  rtcCommitScene(impl_->scene);
  check_embree(device, "building the scene");

  bounds_ = geometry_bounds(meshes, spheres);

  // Lights: every emissive triangle and sphere, then the punctual lights; chosen by power.
  collect_lights(meshes, spheres, materials, punctual_lights, sphere_geom_id(),
                 {lights_, first_light_of_mesh_, light_of_sphere_, environment_lights_});
  committed_ = true;  // light_power needs bounds and geometry queries
  // In blocks, in parallel: a textured emitter's power filters its texture over the triangle.
  std::vector<float> power(lights_.size());
  constexpr size_t kLightsPerItem = 256;
  util::parallel_for((lights_.size() + kLightsPerItem - 1) / kLightsPerItem, [&](size_t b) {
    for (size_t i = b * kLightsPerItem; i < std::min(lights_.size(), (b + 1) * kLightsPerItem); ++i)
      power[i] = light_power(*this, lights_[i]).average();
  });
  light_distribution_ = util::Distribution1D(power);
  light_sampler_ = LightSampler(*this, lights_, power);
}

std::optional<Hit> Scene::intersect(const Ray& ray) const {
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
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  return Hit{rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v};
}

namespace {

/// Embree's point query of the ball of `radius` about p, each primitive whose bounds reach it
/// handed to `callback` with `user`.
void point_query(RTCScene scene, const Vec3& p, float radius, RTCPointQueryFunction callback, void* user) {
  RTCPointQuery query;
  query.x = p.x;
  query.y = p.y;
  query.z = p.z;
  query.time = 0.0f;
  query.radius = radius;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(scene, &query, &context, callback, user);
}

/// State of one nearest_triangle query, handed to Embree's point-query callback.
struct NearestQuery {
  const TriangleMesh* mesh;
  uint32_t geom_id;
  Vec3 p, n;
  float min_cosine;
  Hit best;
  float best_distance2;
};

bool nearest_triangle_callback(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<NearestQuery*>(args->userPtr);
  if (args->geomID != q->geom_id) return false;
  const uint32_t* idx = &q->mesh->indices[3 * size_t(args->primID)];
  const Vec3 &a = q->mesh->positions[idx[0]], &b = q->mesh->positions[idx[1]], &c = q->mesh->positions[idx[2]];
  const Vec3 normal = glm::cross(b - a, c - a);
  const float length = glm::length(normal);
  if (!(length > 0.0f) || !(glm::dot(normal, q->n) > q->min_cosine * length)) return false;
  const Vec2 uv = util::closest_point_on_triangle(q->p, a, b, c);
  const Vec3 x = (1.0f - uv.x - uv.y) * a + uv.x * b + uv.y * c;
  const float d2 = glm::dot(x - q->p, x - q->p);
  if (d2 > q->best_distance2 || (d2 == q->best_distance2 && args->primID > q->best.prim_id)) return false;
  q->best = Hit{std::sqrt(d2), q->geom_id, args->primID, uv.x, uv.y};
  q->best_distance2 = d2;
  args->query->radius = std::sqrt(d2);
  return true;
}

}  // namespace

std::optional<Hit> Scene::nearest_triangle(uint32_t geom_id, const Vec3& p, float radius, const Vec3& n,
                                           float min_cosine) const {
  if (geom_id >= meshes.size() || !(radius > 0.0f)) return std::nullopt;
  // Searched in balls growing eightfold up to `radius`: most callers ask about points on or next
  // to a face (an element's vertex snapped back onto the face it was meshed from), which the
  // smallest ball settles after a handful of triangles, where one search of the whole radius
  // meets every triangle whose box reaches into it before the first hit shrinks it. The nearest
  // face inside a ball is the nearest inside `radius`, ties included, so the answer is the same.
  for (float reach = radius * (1.0f / 64.0f);; reach = std::min(radius, reach * 8.0f)) {
    NearestQuery q{&meshes[geom_id], geom_id, p, n, min_cosine, Hit{}, sqr(reach)};
    q.best.prim_id = ~0u;
    point_query(impl_->scene, p, reach, nearest_triangle_callback, &q);
    if (q.best.prim_id != ~0u) return q.best;
    if (reach >= radius) return std::nullopt;
  }
}

namespace {

/// State of one for_each_triangle_near query, handed to Embree's point-query callback.
struct NearQuery {
  const std::function<void(uint32_t, uint32_t)>* f;
  uint32_t mesh_count;
};

bool near_triangle_callback(RTCPointQueryFunctionArguments* args) {
  const auto* q = static_cast<const NearQuery*>(args->userPtr);
  if (args->geomID < q->mesh_count) (*q->f)(args->geomID, args->primID);
  return false;  // the radius stays
}

}  // namespace

bool Scene::on_closed_surface(uint32_t geom_id, uint32_t prim_id) const {
  if (geom_id >= meshes.size()) return true;  // a sphere
  // On one thread: callers ask from inside parallel loops, and a parallel loop here could hand
  // this thread one of their tasks, which would ask again inside the call_once.
  std::call_once(impl_->closed_once, [&] {
    impl_->closed.resize(meshes.size());
    for (size_t m = 0; m < meshes.size(); ++m) impl_->closed[m] = triangles_on_closed_surfaces(meshes[m]);
  });
  const std::vector<char>& closed = impl_->closed[geom_id];
  return prim_id < closed.size() && closed[prim_id] != 0;
}

void Scene::for_each_triangle_near(const Vec3& p, float radius,
                                   const std::function<void(uint32_t geom_id, uint32_t prim_id)>& f) const {
  if (!(radius > 0.0f) || !std::isfinite(radius)) return;
  NearQuery q{&f, static_cast<uint32_t>(meshes.size())};
  point_query(impl_->scene, p, radius, near_triangle_callback, &q);
}

bool Scene::occluded(const Ray& ray) const {
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
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(impl_->scene, &context, &r);
  return r.tfar < 0.0f;
}

SurfaceInteraction Scene::triangle_point(uint32_t geom_id, uint32_t prim_id, Vec2 b) const {
  const TriangleMesh& mesh = meshes[geom_id];
  const uint32_t i0 = mesh.indices[3 * prim_id], i1 = mesh.indices[3 * prim_id + 1], i2 = mesh.indices[3 * prim_id + 2];
  const Vec3 &p0 = mesh.positions[i0], &p1 = mesh.positions[i1], &p2 = mesh.positions[i2];
  const float b0 = 1.0f - b.x - b.y;
  SurfaceInteraction si;
  si.p = b0 * p0 + b.x * p1 + b.y * p2;
  // Error of the barycentric combination (PBRT §3.9.4), with room for b0's own rounding.
  si.p_error = error_gamma(7) * (abs(b0 * p0) + abs(b.x * p1) + abs(b.y * p2));
  si.ng = glm::normalize(glm::cross(p1 - p0, p2 - p0));
  si.ns = si.ng;
  if (!mesh.normals.empty()) {
    const Vec3 n = b0 * mesh.normals[i0] + b.x * mesh.normals[i1] + b.y * mesh.normals[i2];
    const float len2 = glm::dot(n, n);
    if (len2 > 0.0f && std::isfinite(len2)) si.ns = glm::dot(n, si.ng) < 0.0f ? -n / std::sqrt(len2) : n / std::sqrt(len2);
  }
  if (!mesh.uvs.empty()) si.uv = b0 * mesh.uvs[i0] + b.x * mesh.uvs[i1] + b.y * mesh.uvs[i2];
  else si.uv = b;
  si.material = mesh.material;
  if (!mesh.tangents.empty() && texture_set_) {
    // The normal before it was turned to ng's side: the tangents were made against it.
    Vec3 n = si.ns;
    bool flipped = false;
    if (!mesh.normals.empty()) {
      const Vec3 raw = b0 * mesh.normals[i0] + b.x * mesh.normals[i1] + b.y * mesh.normals[i2];
      flipped = glm::dot(raw, si.ng) < 0.0f;
      if (flipped) n = -n;
    }
    const glm::vec4 tangent = b0 * mesh.tangents[i0] + b.x * mesh.tangents[i1] + b.y * mesh.tangents[i2];
    Vec3 mapped = tangent_to_world(n, glm::vec4(Vec3(tangent), mesh.tangents[i0].w), mapped_normal(materials[mesh.material], si.uv));
    if (flipped) mapped = -mapped;
    // A tilt past the geometric surface would shade the surface from behind: keep the smooth normal.
    if (glm::dot(mapped, si.ng) > 1e-3f) si.ns = mapped;
  }
  if (first_light_of_mesh_[geom_id] >= 0) si.light = first_light_of_mesh_[geom_id] + static_cast<int32_t>(prim_id);
  return si;
}

SurfaceInteraction Scene::sphere_point(uint32_t prim_id, const Vec3& dir) const {
  const Sphere& s = spheres[prim_id];
  const DVec3 n = glm::normalize(DVec3(dir));
  SurfaceInteraction si;
  si.p = Vec3(DVec3(s.center) + double(s.radius) * n);  // exact on the sphere up to the final rounding
  si.p_error = error_gamma(3) * abs(si.p);
  si.ng = Vec3(n);
  si.ns = si.ng;
  si.uv = Vec2(std::atan2(si.ng.y, si.ng.x) * kInv2Pi + 0.5f, std::acos(std::clamp(si.ng.z, -1.0f, 1.0f)) * kInvPi);
  si.material = s.material;
  si.light = light_of_sphere_[prim_id];
  return si;
}

SurfaceInteraction Scene::surface(const Ray& ray, const Hit& hit) const {
  SurfaceInteraction si;
  if (hit.geom_id == sphere_geom_id()) {
    // Re-project the hit onto the sphere in double precision.
    const DVec3 p = DVec3(ray.origin) + double(hit.t) * DVec3(ray.direction);
    si = sphere_point(hit.prim_id, Vec3(p - DVec3(spheres[hit.prim_id].center)));
  } else {
    si = triangle_point(hit.geom_id, hit.prim_id, Vec2(hit.u, hit.v));
  }
  if (ray.spread > 0.0f || ray.width > 0.0f) {  // a camera path's ray: its cone at the hit
    si.cone_width = ray.width + ray.spread * hit.t * glm::length(ray.direction);
    si.cone_spread = ray.spread;
    if (!std::isfinite(si.cone_width)) si.cone_width = si.cone_spread = 0.0f;
    if (si.cone_width > 0.0f && hit.geom_id != sphere_geom_id()) pixel_footprint(ray, hit, si);
  }
  si.front_face = glm::dot(ray.direction, si.ng) < 0.0f;
  return si;
}

void Scene::pixel_footprint(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const {
  const TriangleMesh& mesh = meshes[hit.geom_id];
  if (mesh.uvs.empty()) return;
  const uint32_t* c = &mesh.indices[3 * size_t(hit.prim_id)];
  // The cone's circle, `width` across, laid on the triangle's plane: an ellipse whose short axis
  // is `width` long, across the ray, and whose long axis, along the ray's trace on the plane, is
  // width / |cos θ| (θ bounded off grazing, where the footprint would cover the whole plane).
  const Vec3 d = glm::normalize(ray.direction);
  const float width = si.cone_width;
  const float cos_theta = std::max(std::fabs(glm::dot(d, si.ng)), 0.05f);
  const Vec3 across = glm::cross(si.ng, d);
  const float across_length = glm::length(across);
  if (!(width > 0.0f) || !std::isfinite(width) || !(across_length > 1e-6f)) {
    // Head-on: a circle; any two perpendicular axes in the plane.
    const Frame f = Frame::from_normal(si.ng);
    si.duv_dx = uv_offset(mesh, c, f.to_world(Vec3(width, 0.0f, 0.0f)));
    si.duv_dy = uv_offset(mesh, c, f.to_world(Vec3(0.0f, width, 0.0f)));
  } else {
    const Vec3 a = across / across_length, along = glm::cross(a, si.ng);
    si.duv_dx = uv_offset(mesh, c, width * a);
    si.duv_dy = uv_offset(mesh, c, (width / cos_theta) * along);
  }
  if (!std::isfinite(si.duv_dx.x + si.duv_dx.y + si.duv_dy.x + si.duv_dy.y)) si.duv_dx = si.duv_dy = Vec2(0.0f);
}

Vec2 Scene::uv_offset(const TriangleMesh& mesh, const uint32_t* c, const Vec3& v) {
  // v = b1 e1 + b2 e2 in the triangle's plane, solved through the Gram matrix of e1, e2.
  const Vec3 e1 = mesh.positions[c[1]] - mesh.positions[c[0]], e2 = mesh.positions[c[2]] - mesh.positions[c[0]];
  const float g11 = glm::dot(e1, e1), g12 = glm::dot(e1, e2), g22 = glm::dot(e2, e2);
  const float det = g11 * g22 - g12 * g12;
  if (!(det > 0.0f)) return Vec2(0.0f);
  const float r1 = glm::dot(v, e1), r2 = glm::dot(v, e2);
  const float b1 = (g22 * r1 - g12 * r2) / det, b2 = (g11 * r2 - g12 * r1) / det;
  return b1 * (mesh.uvs[c[1]] - mesh.uvs[c[0]]) + b2 * (mesh.uvs[c[2]] - mesh.uvs[c[0]]);
}

float Scene::primitive_area(uint32_t geom_id, uint32_t prim_id) const {
  if (geom_id == sphere_geom_id()) return 4.0f * kPi * sqr(spheres[prim_id].radius);
  const TriangleMesh& mesh = meshes[geom_id];
  const Vec3& p0 = mesh.positions[mesh.indices[3 * prim_id]];
  const Vec3& p1 = mesh.positions[mesh.indices[3 * prim_id + 1]];
  const Vec3& p2 = mesh.positions[mesh.indices[3 * prim_id + 2]];
  return 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
}

const Material& Scene::primitive_material(uint32_t geom_id, uint32_t prim_id) const {
  if (geom_id == sphere_geom_id()) return materials[spheres[prim_id].material];
  return materials[meshes[geom_id].material];
}

const Material& Scene::shading_material(const SurfaceInteraction& si, Material& scratch) const {
  const Material& m = materials[si.material];
  if (!m.is_textured() || !texture_set_) return m;
  // Field by field rather than `scratch = m`, so a long name is not copied at every hit.
  scratch.kind = m.kind;
  scratch.specular = m.specular;
  scratch.exponent = m.exponent;
  scratch.ior = m.ior;
  scratch.absorption = m.absorption;
  scratch.transmission_tint = m.transmission_tint;
  scratch.thin_walled = m.thin_walled;
  scratch.two_sided_emission = m.two_sided_emission;
  for (TextureRef* t : scratch.texture_refs()) *t = TextureRef{};
  const auto read = [&](const TextureRef& t) {
    return texture_set_->lookup(t.image, t.st(si.uv), t.st_delta(si.duv_dx), t.st_delta(si.duv_dy));
  };
  scratch.albedo = m.albedo_texture.valid() ? m.albedo * read(m.albedo_texture).rgb : m.albedo;
  scratch.metallic = m.metallic;
  scratch.roughness = m.roughness;
  if (m.metallic_roughness_texture.valid()) {  // glTF: roughness in green, metalness in blue
    const Rgb t = read(m.metallic_roughness_texture).rgb;
    scratch.roughness = m.roughness * std::clamp(t.g, 0.0f, 1.0f);
    scratch.metallic = m.metallic * std::clamp(t.b, 0.0f, 1.0f);
  }
  scratch.emission = emission_at(m, si.uv);
  return scratch;
}

Vec3 Scene::mapped_normal(const Material& m, Vec2 uv) const {
  const TextureRef& t = m.normal_texture;
  const Vec2 st = t.st(uv);
  if (!m.normal_is_height) return decode_normal_texel(texture_set_->lookup(t.image, st).rgb, m.normal_scale);
  // Central differences one texel apart; grey heights are read from the first channel.
  const Vec2 texel = texture_set_->texel_size(t.image);
  const auto height = [&](float ds, float dt) { return texture_set_->lookup(t.image, st + Vec2(ds, dt)).rgb.r; };
  const float dh_ds = 0.5f * (height(texel.x, 0.0f) - height(-texel.x, 0.0f));
  const float dh_dup = 0.5f * (height(0.0f, -texel.y) - height(0.0f, texel.y));
  return height_normal(dh_ds, dh_dup, m.normal_scale);
}

Rgb Scene::emission_at(const Material& m, Vec2 uv) const {
  if (!m.emission_texture.valid() || !texture_set_ || m.emission.is_black()) return m.emission;
  const TextureRef& t = m.emission_texture;
  return m.emission * clamp(texture_set_->lookup(t.image, t.st(uv)).rgb, 0.0f, kInfinity);
}

Rgb Scene::mean_albedo(const Material& m, Vec2 uv0, Vec2 uv1, Vec2 uv2) const {
  if (!m.albedo_texture.valid() || !texture_set_) return m.albedo;
  const TextureRef& t = m.albedo_texture;
  return m.albedo * texture_set_->triangle_mean(t.image, t.st(uv0), t.st(uv1), t.st(uv2)).rgb;
}

Rgb Scene::mean_emission(uint32_t geom_id, uint32_t prim_id) const {
  const Material& m = primitive_material(geom_id, prim_id);
  if (!m.emission_texture.valid() || !texture_set_ || m.emission.is_black() || geom_id == sphere_geom_id())
    return m.emission;
  const TriangleMesh& mesh = meshes[geom_id];
  if (mesh.uvs.empty()) return emission_at(m, Vec2(0.0f));
  const TextureRef& t = m.emission_texture;
  const Vec2 a = t.st(mesh.uvs[mesh.indices[3 * prim_id]]), b = t.st(mesh.uvs[mesh.indices[3 * prim_id + 1]]),
             c = t.st(mesh.uvs[mesh.indices[3 * prim_id + 2]]);
  return m.emission * clamp(texture_set_->triangle_mean(t.image, a, b, c).rgb, 0.0f, kInfinity);
}

size_t Scene::triangle_count() const {
  size_t n = 0;
  for (const TriangleMesh& m : meshes) n += m.triangle_count();
  return n;
}

Camera Scene::effective_camera(float aspect) const {
  if (camera) return *camera;
  if (!(aspect > 0.0f)) aspect = float(render.width) / float(std::max(render.height, 1));
  return default_camera(bounds_, aspect);
}

void* Scene::embree_scene() const { return impl_->scene; }

}  // namespace gilt::raytrace_core::scene

// Light sampling: area lights by the solid angle they subtend (triangles, where it is neither tiny
// nor nearly a hemisphere; by area otherwise) or by the cone they subtend (spheres),
// delta lights directly, an environment map by its importance and a constant environment by the
// cosine about the receiving side, or uniformly over the sphere (PBRT 4th ed., ch. 12).

#include "raytrace_core/scene/light.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "raytrace_core/util/closest_point.h"
#include "raytrace_core/util/sampling.h"
#include "raytrace_core/util/spherical_triangle.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::raytrace_core::scene {
namespace {

/// Area density converted to solid angle as seen from ref: pdf_A · d² / |cos θ_light|.
float area_to_solid_angle(float pdf_area, const Vec3& ref, const SurfacePoint& on_light) {
  const Vec3 d = on_light.p - ref;
  const float dist2 = glm::dot(d, d);
  const float cos_light = std::fabs(glm::dot(on_light.ng, d)) / std::sqrt(dist2);
  if (!(cos_light > 0.0f) || !(dist2 > 0.0f)) return 0.0f;
  return pdf_area * dist2 / cos_light;
}

/// sin²θ_max and 1 − cos θ_max of the cone a sphere subtends from a point outside it.
struct SphereCone {
  float cos_max, one_minus_cos;
};
SphereCone sphere_cone(const Sphere& s, const Vec3& p) {
  const double d2 = glm::dot(DVec3(p) - DVec3(s.center), DVec3(p) - DVec3(s.center));
  const double sin2 = double(s.radius) * s.radius / d2;
  const double cos_max = std::sqrt(std::max(0.0, 1.0 - sin2));
  return {static_cast<float>(cos_max), static_cast<float>(sin2 / (1.0 + cos_max))};  // 1 − cos without cancellation
}

bool inside_sphere(const Sphere& s, const Vec3& p) {
  const DVec3 d = DVec3(p) - DVec3(s.center);
  return glm::dot(d, d) <= double(s.radius) * s.radius;
}

/// Smooth spot falloff between the outer and inner cone.
float spot_falloff(const Light& l, const Vec3& w_from_light) {
  const float c = glm::dot(w_from_light, l.direction);
  if (c >= l.cos_inner) return 1.0f;
  if (c <= l.cos_outer) return 0.0f;
  const float x = (c - l.cos_outer) / (l.cos_inner - l.cos_outer);
  return x * x * (3.0f - 2.0f * x);
}

/// The direction a directional light's sample travels: its own, or towards a point of its disk
/// (Light::cos_angle) drawn uniformly.
Vec3 directional_travel(const Light& light, Vec2 u) {
  if (!(light.cos_angle < 1.0f)) return light.direction;
  return Frame::from_normal(light.direction).to_world(util::sample_uniform_cone(u, light.cos_angle));
}

/// The scene's bounding box seen along a direction: the convex outline of its corners projected
/// onto the plane through its centre perpendicular to that direction, in the plane's frame
/// (s, t), counter-clockwise. Every line along the direction that crosses the box crosses the
/// outline, so photons from a distant light start on it rather than on a disk of the bounding
/// radius: a cube's outline covers 42–74 % of that disk, a flatter box's less.
struct BoxOutline {
  std::array<Vec2, 9> corner{};  // up to 6 hull corners (room for Andrew's chain)
  int count = 0;
  float area = 0.0f;
};

BoxOutline box_outline(const Bounds3& b, const Frame& frame) {
  const Vec3 half = 0.5f * (b.hi - b.lo);
  std::array<Vec2, 8> p;
  for (int i = 0; i < 8; ++i) {
    const Vec3 q((i & 1 ? 1.0f : -1.0f) * half.x, (i & 2 ? 1.0f : -1.0f) * half.y, (i & 4 ? 1.0f : -1.0f) * half.z);
    p[size_t(i)] = Vec2(glm::dot(q, frame.s), glm::dot(q, frame.t));
  }
  std::sort(p.begin(), p.end(), [](Vec2 a, Vec2 c) { return a.x < c.x || (a.x == c.x && a.y < c.y); });
  // Andrew's monotone chain: lower hull left to right, then upper hull right to left.
  const auto cross = [](Vec2 o, Vec2 a, Vec2 c) { return (a.x - o.x) * (c.y - o.y) - (a.y - o.y) * (c.x - o.x); };
  BoxOutline out;
  int k = 0;
  for (int i = 0; i < 8; ++i) {
    while (k >= 2 && cross(out.corner[size_t(k - 2)], out.corner[size_t(k - 1)], p[size_t(i)]) <= 0.0f) --k;
    out.corner[size_t(k++)] = p[size_t(i)];
  }
  for (int i = 6, lower = k + 1; i >= 0; --i) {
    while (k >= lower && cross(out.corner[size_t(k - 2)], out.corner[size_t(k - 1)], p[size_t(i)]) <= 0.0f) --k;
    out.corner[size_t(k++)] = p[size_t(i)];
  }
  out.count = std::max(0, k - 1);  // the last repeats the first
  for (int i = 1; i + 1 < out.count; ++i)
    out.area += 0.5f * cross(out.corner[0], out.corner[size_t(i)], out.corner[size_t(i + 1)]);
  return out;
}

/// A point uniform over the outline (a fan of triangles from its first corner, one chosen by
/// area with u.x, which is then reused within it).
Vec2 sample_outline(const BoxOutline& o, Vec2 u) {
  float target = u.x * o.area;
  for (int i = 1; i + 1 < o.count; ++i) {
    const Vec2 a = o.corner[0], b = o.corner[size_t(i)], c = o.corner[size_t(i + 1)];
    const float area = 0.5f * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
    if (target < area || i + 2 == o.count) {
      const float ux = std::clamp(area > 0.0f ? target / area : 0.0f, 0.0f, kOneMinusEpsilon);
      const Vec2 bary = util::sample_uniform_triangle(Vec2(ux, u.y));
      return a + (b - a) * bary.x + (c - a) * bary.y;
    }
    target -= area;
  }
  return o.count > 0 ? o.corner[0] : Vec2(0.0f);
}

/// Area of the bounding box's outline seen along unit w.
float box_outline_area(const Bounds3& b, const Vec3& w) {
  const Vec3 d = b.hi - b.lo;
  return std::fabs(w.x) * d.y * d.z + std::fabs(w.y) * d.x * d.z + std::fabs(w.z) * d.x * d.y;
}

}  // namespace

Rgb emitted_radiance(const Material& m, const Vec3& ng, const Vec3& w) {
  if (m.two_sided_emission || glm::dot(ng, w) > 0.0f) return m.emission;
  return Rgb(0.0f);
}

namespace {

/// The corners of a triangle light.
std::array<DVec3, 3> light_corners(const Scene& scene, const Light& light) {
  const TriangleMesh& mesh = scene.meshes[light.geom_id];
  const uint32_t* i = &mesh.indices[3 * size_t(light.prim_id)];
  return {DVec3(mesh.positions[i[0]]), DVec3(mesh.positions[i[1]]), DVec3(mesh.positions[i[2]])};
}

/// Whether area sampling's density varies across the triangle (a, b, c) seen from p by more
/// than a factor of 2 (see triangle_light_solid_angle in light.h): the cube of the farthest
/// corner's distance over the nearest point's.
bool density_spreads(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  constexpr float kSpread = 2.0f;  // largest ratio of densities left to area sampling
  const Vec2 nb = util::closest_point_on_triangle(p, a, b, c);
  const Vec3 nearest = (1.0f - nb.x - nb.y) * a + nb.x * b + nb.y * c;
  const float r_near2 = glm::dot(nearest - p, nearest - p);
  const float r_far2 = std::max({glm::dot(a - p, a - p), glm::dot(b - p, b - p), glm::dot(c - p, c - p)});
  // (r_far / r_near)³ > kSpread, squared to stay with squared distances.
  return r_far2 * r_far2 * r_far2 > kSpread * kSpread * r_near2 * r_near2 * r_near2;
}

/// The spherical triangle a triangle light spans from p, when it is sampled by the solid angle
/// it subtends there; nothing when it is sampled by area. sample_light and light_pdf both
/// decide through here, from p and the triangle alone.
std::optional<util::SphericalTriangle> solid_angle_sampling(const Scene& scene, const Light& light,
                                                            const Vec3& p) {
  const TriangleMesh& mesh = scene.meshes[light.geom_id];
  const uint32_t* i = &mesh.indices[3 * size_t(light.prim_id)];
  const Vec3 &a = mesh.positions[i[0]], &b = mesh.positions[i[1]], &c = mesh.positions[i[2]];
  if (!density_spreads(p, a, b, c)) return std::nullopt;
  std::optional<util::SphericalTriangle> t =
      util::SphericalTriangle::from(DVec3(p), DVec3(a), DVec3(b), DVec3(c));
  if (t && !util::samples_by_solid_angle(t->solid_angle())) t.reset();
  return t;
}

/// Barycentric coordinates (of the second and third corners) where the ray from p along w meets
/// the plane of the triangle, clamped into the triangle against rounding (Möller & Trumbore 1997).
Vec2 barycentrics_along(const std::array<DVec3, 3>& c, const DVec3& p, const DVec3& w) {
  const DVec3 e1 = c[1] - c[0], e2 = c[2] - c[0];
  const DVec3 pv = glm::cross(w, e2);
  const double det = glm::dot(e1, pv);
  if (det == 0.0) return Vec2(1.0f / 3.0f);
  const DVec3 tv = p - c[0];
  const DVec3 qv = glm::cross(tv, e1);
  double b1 = std::max(0.0, glm::dot(tv, pv) / det), b2 = std::max(0.0, glm::dot(w, qv) / det);
  if (b1 + b2 > 1.0) {
    const double sum = b1 + b2;
    b1 /= sum, b2 /= sum;
  }
  return Vec2(float(b1), float(b2));
}

}  // namespace

double triangle_light_solid_angle(const Scene& scene, const Light& light, const Vec3& p) {
  const std::optional<util::SphericalTriangle> t = solid_angle_sampling(scene, light, p);
  return t ? t->solid_angle() : 0.0;
}

LightSample sample_light(const Scene& scene, const Light& light, const SurfacePoint& ref, Vec2 u,
                         const Vec3& receiving) {
  LightSample ls;
  switch (light.kind) {
    case LightKind::area_triangle:
    case LightKind::area_sphere: {
      SurfaceInteraction q;
      float pdf = 0.0f;
      if (light.kind == LightKind::area_triangle) {
        if (const std::optional<util::SphericalTriangle> st = solid_angle_sampling(scene, light, ref.p)) {
          // A direction uniform over the solid angle, and the point where it meets the light.
          const DVec3 w = st->sample(u);
          q = scene.triangle_point(light.geom_id, light.prim_id, barycentrics_along(light_corners(scene, light), DVec3(ref.p), w));
          pdf = float(1.0 / st->solid_angle());
        } else {
          q = scene.triangle_point(light.geom_id, light.prim_id, util::sample_uniform_triangle(u));
          pdf = area_to_solid_angle(1.0f / scene.primitive_area(light.geom_id, light.prim_id), ref.p, q);
        }
      } else {
        const Sphere& s = scene.spheres[light.prim_id];
        if (inside_sphere(s, ref.p)) {
          q = scene.sphere_point(light.prim_id, util::sample_uniform_sphere(u));
          pdf = area_to_solid_angle(1.0f / scene.primitive_area(light.geom_id, light.prim_id), ref.p, q);
        } else {
          // Uniform direction in the subtended cone, then the nearer intersection with the sphere.
          const SphereCone cone = sphere_cone(s, ref.p);
          const DVec3 to_center = DVec3(s.center) - DVec3(ref.p);
          const double dc = glm::length(to_center);
          const Frame frame = Frame::from_normal(Vec3(to_center / dc));
          // Work from 1 − cos θ: for a small or distant sphere cos θ is within a few floats of 1,
          // and 1 − cos² θ would snap the directions onto a few rings.
          const float one_minus_cos = u.x * cone.one_minus_cos;
          const float cos_theta = 1.0f - one_minus_cos;
          const float sin_theta = safe_sqrt(one_minus_cos * (2.0f - one_minus_cos));
          const float phi = 2.0f * kPi * u.y;
          const Vec3 wi = frame.to_world(Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta));
          // Distance along wi to the sphere: dc cos θ − sqrt(r² − dc² sin² θ).
          const double r = s.radius;
          const double sin2 = double(sin_theta) * sin_theta;
          const double ds = dc * cos_theta - std::sqrt(std::max(0.0, r * r - dc * dc * sin2));
          const DVec3 hit = DVec3(ref.p) + ds * DVec3(wi);
          q = scene.sphere_point(light.prim_id, Vec3(hit - DVec3(s.center)));
          pdf = 1.0f / (2.0f * kPi * cone.one_minus_cos);
        }
      }
      const Vec3 d = q.p - ref.p;
      const float dist = glm::length(d);
      if (!(pdf > 0.0f) || !(dist > 0.0f) || !std::isfinite(pdf)) return ls;
      ls.wi = d / dist;
      ls.pdf = pdf;
      const Material& m = scene.primitive_material(light.geom_id, light.prim_id);
      ls.radiance = emitted_radiance(m, q.ng, -ls.wi);
      if (m.emission_texture.valid() && !ls.radiance.is_black()) ls.radiance = scene.emission_at(m, q.uv);
      ls.shadow_ray = spawn_shadow_ray(ref, q);
      return ls;
    }
    case LightKind::point:
    case LightKind::spot: {
      const Vec3 d = light.position - ref.p;
      const float dist2 = glm::dot(d, d);
      if (!(dist2 > 0.0f)) return ls;
      ls.wi = d / std::sqrt(dist2);
      ls.pdf = 1.0f;
      ls.delta = true;
      ls.radiance = light.intensity / dist2;
      if (light.kind == LightKind::spot) ls.radiance *= spot_falloff(light, -ls.wi);
      ls.shadow_ray = spawn_shadow_ray(ref, light.position);
      return ls;
    }
    case LightKind::directional:
      ls.wi = -directional_travel(light, u);
      ls.pdf = 1.0f;
      ls.delta = true;
      ls.radiance = light.irradiance;
      ls.shadow_ray = spawn_shadow_ray_to_infinity(ref, ls.wi);
      return ls;
    case LightKind::environment:
      if (light.map) {  // by the map's power
        const EnvironmentMap::Sample s = light.map->sample(u);
        if (!(s.pdf > 0.0f)) return ls;
        ls.wi = s.wi;
        ls.pdf = s.pdf;
        ls.radiance = light.radiance * s.radiance;
      } else if (receiving != Vec3(0.0f)) {  // cosine-distributed over the receiving side
        ls.wi = Frame::from_normal(receiving).to_world(util::sample_cosine_hemisphere(u));
        ls.pdf = util::cosine_hemisphere_pdf(glm::dot(ls.wi, receiving));
        if (!(ls.pdf > 0.0f)) return ls;  // on the horizon, within rounding
        ls.radiance = light.radiance;
      } else {
        ls.wi = util::sample_uniform_sphere(u);
        ls.pdf = util::uniform_sphere_pdf();
        ls.radiance = light.radiance;
      }
      ls.shadow_ray = spawn_shadow_ray_to_infinity(ref, ls.wi);
      return ls;
  }
  return ls;
}

float light_pdf(const Scene& scene, const Light& light, const SurfacePoint& ref, const Vec3& wi,
                const SurfacePoint& on_light, const Vec3& receiving) {
  switch (light.kind) {
    case LightKind::area_triangle:
      if (const std::optional<util::SphericalTriangle> st = solid_angle_sampling(scene, light, ref.p))
        return float(1.0 / st->solid_angle());
      return area_to_solid_angle(1.0f / scene.primitive_area(light.geom_id, light.prim_id), ref.p, on_light);
    case LightKind::area_sphere: {
      const Sphere& s = scene.spheres[light.prim_id];
      if (inside_sphere(s, ref.p))
        return area_to_solid_angle(1.0f / scene.primitive_area(light.geom_id, light.prim_id), ref.p, on_light);
      return 1.0f / (2.0f * kPi * sphere_cone(s, ref.p).one_minus_cos);
    }
    case LightKind::environment:
      if (light.map) return light.map->pdf(wi);
      return receiving != Vec3(0.0f) ? util::cosine_hemisphere_pdf(glm::dot(wi, receiving))
                                     : util::uniform_sphere_pdf();
    case LightKind::point:
    case LightKind::spot:
    case LightKind::directional: return 0.0f;
  }
  return 0.0f;
}

EmissionSample sample_emission(const Scene& scene, const Light& light, Vec2 u_position, Vec2 u_direction) {
  EmissionSample es;
  switch (light.kind) {
    case LightKind::area_triangle:
    case LightKind::area_sphere: {
      const SurfaceInteraction q =
          light.kind == LightKind::area_triangle
              ? scene.triangle_point(light.geom_id, light.prim_id, util::sample_uniform_triangle(u_position))
              : scene.sphere_point(light.prim_id, util::sample_uniform_sphere(u_position));
      const Material& m = scene.primitive_material(light.geom_id, light.prim_id);
      Vec3 n = q.ng;
      float sides = 1.0f;
      if (m.two_sided_emission) {
        // The first coordinate picks the side and is stretched back to [0, 1).
        sides = 2.0f;
        if (u_direction.x < 0.5f) {
          n = -n;
          u_direction.x *= 2.0f;
        } else {
          u_direction.x = std::min(kOneMinusEpsilon, 2.0f * u_direction.x - 1.0f);
        }
      }
      const Vec3 w = Frame::from_normal(n).to_world(util::sample_cosine_hemisphere(u_direction));
      // Le cos / (1/A · cos/π · 1/sides) = Le π A · sides.
      es.power = scene.emission_at(m, q.uv) * (sides * kPi * scene.primitive_area(light.geom_id, light.prim_id));
      SurfacePoint from = q;
      from.ng = n;
      es.ray = spawn_ray(from, w);
      es.normal = n;
      return es;
    }
    case LightKind::point:
    case LightKind::spot: {
      Vec3 w;
      if (light.kind == LightKind::point) {
        w = util::sample_uniform_sphere(u_direction);
        es.power = light.intensity * (4.0f * kPi);
      } else {
        w = Frame::from_normal(light.direction)
                .to_world(util::sample_uniform_cone(u_direction, light.cos_outer));
        es.power = light.intensity * (spot_falloff(light, w) / util::uniform_cone_pdf(light.cos_outer));
      }
      es.ray = Ray{light.position, w};
      es.normal = w;
      return es;
    }
    case LightKind::directional:
    case LightKind::environment: {
      // A point of the bounding box's outline seen along the direction of travel, moved back
      // outside the bounding sphere: every line through the scene crosses the outline.
      Vec3 w = light.kind == LightKind::directional ? directional_travel(light, u_direction) : Vec3(0.0f);
      Rgb radiance_over_pdf(0.0f);  // environment: L(−w) / pdf(−w)
      if (light.kind == LightKind::environment && light.map) {
        const EnvironmentMap::Sample s = light.map->sample(u_direction);
        if (!(s.pdf > 0.0f)) return es;
        w = -s.wi;
        radiance_over_pdf = light.radiance * s.radiance / s.pdf;
      } else if (light.kind == LightKind::environment) {
        w = -util::sample_uniform_sphere(u_direction);
        radiance_over_pdf = light.radiance / util::uniform_sphere_pdf();
      }
      const Bounds3& b = scene.bounds();
      const Vec3 center = 0.5f * (b.lo + b.hi);
      const float radius = std::max(b.radius(), 1e-30f);
      const Frame frame = Frame::from_normal(w);
      const BoxOutline outline = box_outline(b, frame);
      if (!(outline.area > 0.0f)) return es;  // a flat scene seen edge on: nothing crosses it
      const Vec2 d = sample_outline(outline, u_position);
      es.ray = Ray{center - w * (1.01f * radius) + frame.s * d.x + frame.t * d.y, w};
      es.normal = w;
      es.power = (light.kind == LightKind::directional ? light.irradiance : radiance_over_pdf) * outline.area;
      return es;
    }
  }
  return es;
}

Rgb environment_radiance(const Light& light, const Vec3& w) {
  return light.map ? light.radiance * light.map->radiance(w) : light.radiance;
}

Rgb environment_radiance(std::span<const Light> lights, const Vec3& w) {
  Rgb sum(0.0f);
  for (const Light& l : lights)
    if (l.kind == LightKind::environment) sum += environment_radiance(l, w);
  return sum;
}

Rgb sun_disk_radiance(std::span<const Light> lights, const Vec3& w) {
  Rgb sum(0.0f);
  for (const Light& l : lights)
    if (l.kind == LightKind::directional && l.cos_angle < 1.0f && glm::dot(w, -l.direction) >= l.cos_angle)
      sum += l.irradiance / (2.0f * kPi * (1.0f - l.cos_angle));
  return sum;
}

Rgb escaped_radiance(std::span<const Light> lights, const Vec3& w) {
  return environment_radiance(lights, w) + sun_disk_radiance(lights, w);
}

Rgb light_power(const Scene& scene, const Light& light) {
  const Bounds3& b = scene.bounds();
  switch (light.kind) {
    case LightKind::area_triangle:
    case LightKind::area_sphere: {
      const Material& m = scene.primitive_material(light.geom_id, light.prim_id);
      const float sides = m.two_sided_emission ? 2.0f : 1.0f;
      return scene.mean_emission(light.geom_id, light.prim_id) * (sides * kPi * scene.primitive_area(light.geom_id, light.prim_id));
    }
    case LightKind::point: return light.intensity * (4.0f * kPi);
    case LightKind::spot:
      // ∫ falloff over the sphere: full cone to cos_inner, then the smoothstep band (its mean is ½).
      return light.intensity * (2.0f * kPi * (1.0f - 0.5f * (light.cos_inner + light.cos_outer)));
    // Distant lights: what crosses the bounding box's outline (sample_emission). A directional
    // light's disk is counted as its centre direction (its outline's area changes by a fraction
    // of the order of the disk's radius squared).
    case LightKind::directional: return b.empty() ? Rgb(0.0f) : light.irradiance * box_outline_area(b, light.direction);
    case LightKind::environment: {
      // Over all directions the outline's mean area is a quarter of the box's surface area
      // (Cauchy's formula), so a constant sky's power is π L S; a map counts as a constant sky of
      // its mean radiance.
      if (b.empty()) return Rgb(0.0f);
      const Vec3 d = b.hi - b.lo;
      const float surface = 2.0f * (d.x * d.y + d.y * d.z + d.x * d.z);
      const Rgb mean = light.map ? light.radiance * light.map->mean_radiance() : light.radiance;
      return mean * (kPi * surface);
    }
  }
  return Rgb(0.0f);
}

}  // namespace gilt::raytrace_core::scene

#include "photonmap/coverage.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"


namespace gilt::photonmap {
namespace {

/// ∫ (ρ² − s²) dA over the part within distance ρ of the origin of the triangle (origin, u1, u2)
/// in the plane, s the distance to the origin, signed by the triangle's orientation. In polar
/// coordinates about the origin the edge u1u2 lies at R(α) = d / cos α, α measured from the foot
/// of the perpendicular of length d, and ∫₀^m (ρ² − s²) s ds = ρ² m² / 2 − m⁴ / 4 with m = min(R, ρ):
/// a constant ρ⁴ / 4 where the edge lies outside the disk, and with R inside it an integral of
/// sec² α and sec⁴ α, whose antiderivatives are tan α and tan α + tan³ α / 3.
double edge_wedge(glm::dvec2 u1, glm::dvec2 u2, double rho2) {
  const glm::dvec2 e = u2 - u1;
  const double length = glm::length(e);
  const double cross = u1.x * u2.y - u1.y * u2.x;
  if (!(length > 0.0) || cross == 0.0) return 0.0;
  const glm::dvec2 along = e / length;
  const double d = std::fabs(cross) / length;
  const double x1 = glm::dot(u1, along), x2 = glm::dot(u2, along);  // x1 < x2
  const double a1 = std::atan(x1 / d), a2 = std::atan(x2 / d);
  double sum = 0.0, chord_angle = 0.0;
  if (d * d < rho2) {
    const double w = std::sqrt(rho2 - d * d);  // half the chord the edge's line cuts from the disk
    const double xa = std::max(x1, -w), xb = std::min(x2, w);
    if (xa < xb) {
      const double ta = xa / d, tb = xb / d;
      chord_angle = std::atan(tb) - std::atan(ta);
      sum += 0.5 * rho2 * d * d * (tb - ta) - 0.25 * d * d * d * d * ((tb - ta) + (tb * tb * tb - ta * ta * ta) / 3.0);
    }
  }
  sum += 0.25 * rho2 * rho2 * std::max(0.0, (a2 - a1) - chord_angle);
  return cross > 0.0 ? sum : -sum;
}

}  // namespace

SurfaceSides::SurfaceSides(const rc::scene::Scene& scene) {
  first_.resize(scene.meshes.size());
  uint64_t total = 0;
  for (size_t g = 0; g < scene.meshes.size(); ++g) {
    first_[g] = total;
    total += scene.meshes[g].indices.size() / 3;
  }
  counts_.assign(2 * total, 0);
}

void SurfaceSides::add(const rc::scene::Scene& scene, uint32_t geom_id, uint32_t prim_id,
                       const rc::Vec3& normal) {
  if (geom_id >= first_.size()) return;  // a sphere
  const rc::scene::TriangleMesh& mesh = scene.meshes[geom_id];
  const uint32_t* idx = &mesh.indices[3 * size_t(prim_id)];
  const rc::Vec3 &a = mesh.positions[idx[0]], &b = mesh.positions[idx[1]], &c = mesh.positions[idx[2]];
  const bool front = glm::dot(glm::cross(b - a, c - a), normal) >= 0.0f;
  std::atomic_ref<uint64_t>(counts_[2 * (first_[geom_id] + prim_id) + (front ? 0 : 1)])
      .fetch_add(1, std::memory_order_relaxed);
}

SurfaceSides every_side(const rc::scene::Scene& scene) {
  SurfaceSides sides(scene);
  std::fill(sides.counts().begin(), sides.counts().end(), 1);
  return sides;
}

SurfaceSides open_sides(const rc::scene::Scene& scene, int rays) {
  SurfaceSides sides(scene);
  std::vector<uint64_t>& reached = sides.counts();
  const size_t count = reached.size();
  constexpr uint32_t kEscaped = ~0u, kNothing = ~0u - 1;
  // Where each side's rays land: the side they meet (the one facing back along the ray), or the
  // sky. Winding does not enter: a ray reaches whichever side of a triangle faces it.
  std::vector<uint32_t> lands(count * size_t(rays), kNothing);
  for (uint32_t g = 0; g < scene.meshes.size(); ++g) {
    const rc::scene::TriangleMesh& mesh = scene.meshes[g];
    rc::util::parallel_for(mesh.indices.size() / 3, [&](size_t t) {
      const uint32_t* idx = &mesh.indices[3 * t];
      const rc::Vec3 &a = mesh.positions[idx[0]], &b = mesh.positions[idx[1]], &c = mesh.positions[idx[2]];
      const rc::Vec3 cross = glm::cross(b - a, c - a);
      const float length = glm::length(cross);
      if (!(length > 0.0f) || !std::isfinite(length)) return;
      for (int side = 0; side < 2; ++side) {
        const size_t s = sides.side_index(g, uint32_t(t)) + size_t(side);
        rc::scene::SurfacePoint sp;
        sp.ng = (side == 0 ? 1.0f : -1.0f) * cross / length;
        sp.p_error = rc::Vec3(1e-6f) * (glm::abs(a) + glm::abs(b) + glm::abs(c) + 1.0f);
        const rc::Frame frame = rc::Frame::from_normal(sp.ng);
        for (int i = 0; i < rays; ++i) {
          rc::util::Rng rng = rc::util::Rng::for_item(0x5157u, s, uint64_t(i));
          // A uniform point of the triangle (the folded square), kept off its edges.
          rc::Vec2 u = rng.uniform2();
          if (u.x + u.y > 1.0f) u = rc::Vec2(1.0f) - u;
          u = 0.05f + 0.9f * u;
          sp.p = a + u.x * (b - a) + u.y * (c - a);
          const rc::Vec3 d = frame.to_world(rc::util::sample_cosine_hemisphere(rng.uniform2()));
          const auto hit = scene.intersect(rc::scene::spawn_ray(sp, d));
          uint32_t& out = lands[s * size_t(rays) + size_t(i)];
          if (!hit) {
            out = kEscaped;
          } else if (hit->geom_id != scene.sphere_geom_id()) {
            const rc::scene::TriangleMesh& other = scene.meshes[hit->geom_id];
            const uint32_t* j = &other.indices[3 * size_t(hit->prim_id)];
            const rc::Vec3 n = glm::cross(other.positions[j[1]] - other.positions[j[0]],
                                          other.positions[j[2]] - other.positions[j[0]]);
            out = uint32_t(sides.side_index(hit->geom_id, hit->prim_id) + (glm::dot(n, d) < 0.0f ? 0 : 1));
          }
        }
      }
    });
  }
  // Light reaches a side that sees the sky, and any side that sees a side light reaches (the
  // same segment carries it back): a search outwards from the sides that see the sky.
  std::vector<uint32_t> first(count + 1, 0), from;
  for (size_t s = 0; s < count; ++s)
    for (int i = 0; i < rays; ++i)
      if (const uint32_t h = lands[s * size_t(rays) + size_t(i)]; h < kNothing) ++first[h + 1];
  for (size_t s = 0; s < count; ++s) first[s + 1] += first[s];
  from.resize(first[count]);
  std::vector<uint32_t> fill(first.begin(), first.end() - 1);
  std::vector<uint32_t> queue;
  for (size_t s = 0; s < count; ++s) {
    bool sky = false;
    for (int i = 0; i < rays; ++i) {
      const uint32_t h = lands[s * size_t(rays) + size_t(i)];
      if (h == kEscaped) sky = true;
      else if (h < kNothing) from[fill[h]++] = uint32_t(s);
    }
    if (sky) reached[s] = 1, queue.push_back(uint32_t(s));
  }
  for (size_t q = 0; q < queue.size(); ++q)
    for (uint32_t k = first[queue[q]]; k < first[queue[q] + 1]; ++k)
      if (!reached[from[k]]) reached[from[k]] = 1, queue.push_back(from[k]);
  return sides;
}

double kernel_integral(const rc::Vec3& a, const rc::Vec3& b, const rc::Vec3& c, const rc::Vec3& p, float r2) {
  if (!(r2 > 0.0f)) return 0.0;
  const glm::dvec3 da(a), db(b), dc(c), dp(p);
  const glm::dvec3 normal = glm::cross(db - da, dc - da);
  const double twice_area = glm::length(normal);
  if (!(twice_area > 0.0)) return 0.0;
  const glm::dvec3 n = normal / twice_area;
  // The ball meets the triangle's plane in a disk of radius ρ about p's foot, where the kernel
  // is (ρ² − s²) / r².
  const double h = glm::dot(dp - da, n), rho2 = double(r2) - h * h;
  if (!(rho2 > 0.0)) return 0.0;
  const glm::dvec3 foot = dp - h * n;
  const glm::dvec3 s = glm::normalize(db - da), t = glm::cross(n, s);
  auto in_plane = [&](const glm::dvec3& x) { return glm::dvec2(glm::dot(x - foot, s), glm::dot(x - foot, t)); };
  const glm::dvec2 u[3] = {in_plane(da), in_plane(db), in_plane(dc)};
  const double sum = edge_wedge(u[0], u[1], rho2) + edge_wedge(u[1], u[2], rho2) + edge_wedge(u[2], u[0], rho2);
  return std::fabs(sum) / double(r2);
}

double disk_coverage(const rc::scene::Scene& scene, const SurfaceSides& sides, const rc::Vec3& p,
                     const rc::Vec3& n, float r2, float min_cosine) {
  if (sides.empty() || !(r2 > 0.0f)) return 0.0;
  const float r = std::sqrt(r2);
  for (const rc::scene::Sphere& s : scene.spheres)
    if (!scene.materials[s.material].is_traced_through() && std::fabs(glm::length(s.center - p) - s.radius) < r)
      return -1.0;
  double sum = 0.0;
  scene.for_each_triangle_near(p, r, [&](uint32_t geom_id, uint32_t prim_id) {
    const rc::scene::TriangleMesh& mesh = scene.meshes[geom_id];
    const uint32_t* idx = &mesh.indices[3 * size_t(prim_id)];
    const rc::Vec3 &a = mesh.positions[idx[0]], &b = mesh.positions[idx[1]], &c = mesh.positions[idx[2]];
    const rc::Vec3 cross = glm::cross(b - a, c - a);
    const float length = glm::length(cross);
    if (!(length > 0.0f)) return;
    const float cosine = glm::dot(cross, n) / length;
    // The side whose photons the estimate takes: the one facing along n, if it is turned close
    // enough to n and holds photons.
    const bool front = cosine >= 0.0f;
    if (std::fabs(cosine) < min_cosine || !sides.holds(geom_id, prim_id, front)) return;
    sum += kernel_integral(a, b, c, p, r2);
  });
  return sum * 2.0 / (rc::kPi * double(r2));
}

}  // namespace gilt::photonmap

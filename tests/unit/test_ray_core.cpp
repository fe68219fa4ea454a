// Ray core against brute force: every closest hit Embree reports must agree with a linear scan
// over all primitives in double precision, closed meshes must be watertight at shared edges and
// vertices, and spawned rays must never re-hit the surface they leave.

#include <gtest/gtest.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <optional>

#include "raytrace_core/scene/scene.h"
#include "raytrace_core/scene/straight_transmittance.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"
#include "tests/support/test_scenes.h"

namespace rc = gilt::raytrace_core;
using rc::DVec3;
using rc::Vec3;

namespace {

struct BruteHit {
  double t;
  uint32_t geom, prim;
};

/// Möller–Trumbore in double precision.
std::optional<double> hit_triangle(const DVec3& o, const DVec3& d, const DVec3& p0, const DVec3& p1, const DVec3& p2) {
  const DVec3 e1 = p1 - p0, e2 = p2 - p0, pv = glm::cross(d, e2);
  const double det = glm::dot(e1, pv);
  if (det == 0.0) return std::nullopt;
  const DVec3 tv = o - p0;
  const double u = glm::dot(tv, pv) / det;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  const DVec3 qv = glm::cross(tv, e1);
  const double v = glm::dot(d, qv) / det;
  if (v < 0.0 || u + v > 1.0) return std::nullopt;
  const double t = glm::dot(e2, qv) / det;
  return t > 0.0 ? std::optional<double>(t) : std::nullopt;
}

std::optional<double> hit_sphere(const DVec3& o, const DVec3& d, const rc::scene::Sphere& s) {
  const DVec3 f = o - DVec3(s.center);
  const double a = glm::dot(d, d), b = glm::dot(f, d), c = glm::dot(f, f) - double(s.radius) * s.radius;
  const double disc = b * b - a * c;
  if (disc < 0.0) return std::nullopt;
  const double t0 = (-b - std::sqrt(disc)) / a, t1 = (-b + std::sqrt(disc)) / a;
  if (t0 > 0.0) return t0;
  if (t1 > 0.0) return t1;
  return std::nullopt;
}

/// All hits along the ray, nearest first.
std::vector<BruteHit> brute_hits(const rc::scene::Scene& scene, const rc::scene::Ray& ray) {
  std::vector<BruteHit> hits;
  const DVec3 o(ray.origin), d(ray.direction);
  for (size_t g = 0; g < scene.meshes.size(); ++g) {
    const auto& m = scene.meshes[g];
    for (size_t t = 0; t < m.triangle_count(); ++t) {
      const auto h = hit_triangle(o, d, DVec3(m.positions[m.indices[3 * t]]), DVec3(m.positions[m.indices[3 * t + 1]]),
                                  DVec3(m.positions[m.indices[3 * t + 2]]));
      if (h) hits.push_back({*h, uint32_t(g), uint32_t(t)});
    }
  }
  for (size_t s = 0; s < scene.spheres.size(); ++s)
    if (auto h = hit_sphere(o, d, scene.spheres[s])) hits.push_back({*h, scene.sphere_geom_id(), uint32_t(s)});
  std::sort(hits.begin(), hits.end(), [](const BruteHit& a, const BruteHit& b) { return a.t < b.t; });
  return hits;
}

rc::scene::Scene random_scene(uint64_t seed) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
  rc::util::Rng rng(seed);
  for (int g = 0; g < 3; ++g) {
    rc::scene::TriangleMesh mesh;
    for (int t = 0; t < 200; ++t) {
      const Vec3 c(rng.uniform() * 10 - 5, rng.uniform() * 10 - 5, rng.uniform() * 10 - 5);
      for (int k = 0; k < 3; ++k) {
        mesh.positions.push_back(c + Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) * 2.0f);
        mesh.indices.push_back(uint32_t(mesh.positions.size() - 1));
      }
    }
    scene.meshes.push_back(std::move(mesh));
  }
  for (int s = 0; s < 20; ++s)
    scene.spheres.push_back({Vec3(rng.uniform() * 10 - 5, rng.uniform() * 10 - 5, rng.uniform() * 10 - 5),
                             0.1f + rng.uniform(), 0});
  scene.commit();
  return scene;
}

}  // namespace

// Every hit agrees with brute force. Float traversal and double brute force can disagree only
// when two surfaces lie within float rounding of each other along the ray, so a different
// primitive is accepted only if brute force puts it within a relative 1e-4 of the nearest t
// (single-precision ray-triangle tests carry relative errors of a few ulps ~ 1e-6; 1e-4 leaves
// room for grazing angles). Such ties are counted and must stay rare.
TEST(RayCore, ClosestHitMatchesBruteForce) {
  const rc::scene::Scene scene = random_scene(7);
  rc::util::Rng rng(11);
  int ties = 0, hits = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Vec3 o(rng.uniform() * 16 - 8, rng.uniform() * 16 - 8, rng.uniform() * 16 - 8);
    const rc::scene::Ray ray{o, rc::util::sample_uniform_sphere(rng.uniform2()), rc::kInfinity};
    const auto hit = scene.intersect(ray);
    const auto brute = brute_hits(scene, ray);
    ASSERT_EQ(hit.has_value(), !brute.empty()) << "ray " << i;
    EXPECT_EQ(scene.occluded(ray), !brute.empty()) << "ray " << i;
    if (!hit) continue;
    ++hits;
    const BruteHit& b = brute.front();
    if (hit->geom_id == b.geom && hit->prim_id == b.prim) {
      EXPECT_NEAR(hit->t, b.t, 1e-4 * b.t + 1e-6) << "ray " << i;
    } else {
      ++ties;
      bool found = false;
      for (const BruteHit& other : brute)
        if (other.geom == hit->geom_id && other.prim == hit->prim_id) found = std::abs(other.t - b.t) <= 1e-4 * b.t;
      EXPECT_TRUE(found) << "ray " << i << ": Embree hit a primitive brute force does not place at the nearest t";
    }
  }
  EXPECT_GT(hits, n / 10) << "too few rays hit for the comparison to mean anything";
  EXPECT_LE(ties, n / 1000) << "too many near-ties between float and double traversal";
}

// The Ray's tmax bounds the search: a hit beyond it is not reported.
TEST(RayCore, RespectsTmax) {
  const rc::scene::Scene scene = random_scene(3);
  rc::util::Rng rng(5);
  for (int i = 0; i < 2000; ++i) {
    rc::scene::Ray ray{Vec3(rng.uniform() * 16 - 8, rng.uniform() * 16 - 8, rng.uniform() * 16 - 8),
                rc::util::sample_uniform_sphere(rng.uniform2()), rc::kInfinity};
    const auto hit = scene.intersect(ray);
    if (!hit) continue;
    ray.tmax = hit->t * 0.999f;
    const auto brute = brute_hits(scene, ray);
    if (brute.front().t < ray.tmax * (1 - 1e-4)) continue;  // another surface lies just in front (tie)
    EXPECT_FALSE(scene.intersect(ray).has_value()) << "ray " << i;
  }
}

// Rays aimed exactly at the vertices and edge midpoints of a closed mesh, from inside and from
// outside, must hit it. Embree's robust mode uses a watertight ray-triangle test (Woop et al.
// 2013), so the tolerated miss count is zero.
TEST(RayCore, ClosedMeshIsWatertight) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
  scene.meshes.push_back(gilt::test::icosphere(3));
  scene.commit();
  const auto& mesh = scene.meshes[0];
  std::vector<Vec3> targets(mesh.positions);
  for (size_t t = 0; t < mesh.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k)
      targets.push_back(0.5f * (mesh.positions[mesh.indices[3 * t + k]] + mesh.positions[mesh.indices[3 * t + (k + 1) % 3]]));
  rc::util::Rng rng(1);
  int misses = 0, rays = 0;
  for (const Vec3& target : targets) {
    // From inside: from the centre and from random interior points.
    for (int k = 0; k < 4; ++k) {
      const Vec3 o = k == 0 ? Vec3(0.0f) : 0.3f * rc::util::sample_uniform_sphere(rng.uniform2());
      misses += !scene.intersect({o, target - o, rc::kInfinity}).has_value();
      ++rays;
    }
    // From outside, towards the target, only where every face around the target faces the
    // origin: a ray that grazes a silhouette edge may touch it or pass it, either is correct.
    // Facet normals of this icosphere stay within ~7° of the radial direction, so a ray within
    // 70° of the radial direction (cos > 0.34) meets only front faces around the target.
    const Vec3 o = 3.0f * rc::util::sample_uniform_sphere(rng.uniform2());
    if (glm::dot(glm::normalize(o - target), glm::normalize(target)) > 0.34f) {
      misses += !scene.intersect({o, target - o, rc::kInfinity}).has_value();
      ++rays;
    }
  }
  EXPECT_EQ(misses, 0) << "of " << rays << " rays aimed at shared edges and vertices";
}

// A ray spawned from a hit point never hits the surface it leaves: for a convex icosphere seen
// from outside, reflected rays must escape; rays sent inward must reach the far side, not t ≈ 0.
TEST(RayCore, SpawnedRaysDoNotSelfIntersect) {
  // Scaled, or translated far from the origin (not both: a 1e-4 object at 1e5 is below float
  // resolution, 0.008 there).
  const std::pair<float, float> cases[] = {{1.0f, 0.0f}, {1e-4f, 0.0f}, {1e4f, 0.0f}, {1.0f, 1e5f}};
  for (const auto& [scale, offset] : cases) {
    {
      rc::scene::Scene scene;
      scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
      rc::scene::TriangleMesh mesh = gilt::test::icosphere(2);
      for (Vec3& p : mesh.positions) p = p * scale + Vec3(offset);
      scene.meshes.push_back(std::move(mesh));
      scene.spheres.push_back({Vec3(3.0f * scale + offset, offset, offset), scale, 0});
      scene.commit();
      rc::util::Rng rng(2);
      int self_hits = 0;
      for (int i = 0; i < 4000; ++i) {
        const bool sphere = i % 2;
        const Vec3 centre = sphere ? scene.spheres[0].center : Vec3(offset);
        const Vec3 o = centre + 4.0f * scale * rc::util::sample_uniform_sphere(rng.uniform2());
        const rc::scene::Ray ray{o, centre - o + 0.5f * scale * rc::util::sample_uniform_sphere(rng.uniform2()), rc::kInfinity};
        const auto hit = scene.intersect(ray);
        if (!hit) continue;
        const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
        Vec3 out = rc::util::sample_cosine_hemisphere(rng.uniform2());
        const rc::Frame frame = rc::Frame::from_normal(si.ng);
        // Outward: the convex surface must not be hit again.
        const auto again = scene.intersect(rc::scene::spawn_ray(si, frame.to_world(out)));
        if (again && again->geom_id == hit->geom_id && again->prim_id == hit->prim_id) ++self_hits;
        // Inward: the far side, at a distance comparable to the diameter.
        out.z = -out.z;
        const auto inner = scene.intersect(rc::scene::spawn_ray(si, frame.to_world(out)));
        if (!inner || inner->t < 1e-3f * scale) ++self_hits;
      }
      EXPECT_EQ(self_hits, 0) << "scale " << scale << ", offset " << offset;
    }
  }
}

// The shadow ray between two mutually visible points on facing walls is unoccluded, at any scale,
// with and without flush-to-zero arithmetic (Embree's worker threads run with it; a wall on the
// plane z = 0 once shadowed itself there through a hit at t = −0).
TEST(RayCore, ShadowRayBetweenSurfacesIsClear) {
  const unsigned saved = _mm_getcsr();
  for (int ftz = 0; ftz < 2; ++ftz)
  for (float scale : {1e-3f, 1.0f, 1e3f}) {
    _MM_SET_FLUSH_ZERO_MODE(ftz ? _MM_FLUSH_ZERO_ON : _MM_FLUSH_ZERO_OFF);
    _MM_SET_DENORMALS_ZERO_MODE(ftz ? _MM_DENORMALS_ZERO_ON : _MM_DENORMALS_ZERO_OFF);
    rc::scene::Scene scene;
    scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
    rc::scene::TriangleMesh box;
    // Two facing unit squares at z = 0 (facing +z) and z = 1 (facing −z).
    box.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (Vec3& p : box.positions) p *= scale;
    box.indices = {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6};
    scene.meshes.push_back(box);
    scene.commit();
    rc::util::Rng rng(9);
    int blocked = 0;
    for (int i = 0; i < 2000; ++i) {
      const rc::scene::SurfaceInteraction a = scene.triangle_point(0, i % 2, rc::util::sample_uniform_triangle(rng.uniform2()));
      const rc::scene::SurfaceInteraction b = scene.triangle_point(0, 2 + i % 2, rc::util::sample_uniform_triangle(rng.uniform2()));
      blocked += scene.occluded(rc::scene::spawn_shadow_ray(a, b));
    }
    EXPECT_EQ(blocked, 0) << "scale " << scale << (ftz ? ", flush-to-zero" : "");
  }
  _mm_setcsr(saved);
}

namespace {

/// A closed slab [−1, 1]² × [0, thickness] wound outwards, as a pane of glass is modelled.
rc::scene::TriangleMesh slab(float thickness, uint32_t material) {
  rc::scene::TriangleMesh m;
  m.material = material;
  for (int k = 0; k < 8; ++k)
    m.positions.push_back({k & 1 ? 1.0f : -1.0f, k & 2 ? 1.0f : -1.0f, k & 4 ? thickness : 0.0f});
  // Each face's corners counter-clockwise seen from outside.
  m.indices = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
               2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  return m;
}

}  // namespace

// A shadow ray through a pane of glass carries what both interfaces let through, in closed form:
// (1 − F)² with F Fresnel's reflectance for η = 1.5 (0.04 head-on; at 60°, rs² = 0.176571 and
// rp² = 0.001802 give F = 0.089187), times e^(−σ d / cos θ) where the glass absorbs; a diffuse
// surface beyond blocks it unless the ray ends first; frosted glass blocks it.
TEST(RayCore, StraightTransmittanceThroughAPane) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
  scene.materials.push_back(rc::scene::Material::make_dielectric("glass", 1.5f));
  scene.materials.push_back(rc::scene::Material::make_dielectric("tinted", 1.5f, rc::Rgb(0.5f, 1.0f, 2.0f)));
  const float d = 0.04f;
  scene.meshes.push_back(slab(d, 1));
  rc::scene::TriangleMesh tinted = slab(d, 2);
  for (Vec3& p : tinted.positions) p.x += 10.0f;
  scene.meshes.push_back(tinted);
  rc::scene::TriangleMesh floor;  // a diffuse plate 1 under the tinted pane only
  floor.positions = {{8, -2, -1}, {12, -2, -1}, {12, 2, -1}, {8, 2, -1}};
  floor.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(floor);
  scene.commit();

  const auto through = [&](Vec3 from, Vec3 dir, float tmax = rc::kInfinity) {
    rc::scene::Ray ray{from, dir, tmax};
    return rc::scene::straight_transmittance(scene, ray);
  };
  const float head_on = 0.96f * 0.96f;
  const rc::Rgb clear = through({0.1f, 0.2f, 1.0f}, {0, 0, -1});
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(clear[c], head_on, 1e-5f);
  const float s60 = std::sqrt(3.0f) / 2.0f;
  const float oblique = (1.0f - 0.089187f) * (1.0f - 0.089187f);
  EXPECT_NEAR(through({-1.0f, 0.0f, 1.0f}, {s60, 0.0f, -0.5f}).g, oblique, 1e-5f);
  // Upwards through the same pane, from below: the same light.
  EXPECT_NEAR(through({0.1f, 0.2f, -1.0f}, {0, 0, 1}).r, head_on, 1e-5f);
  // Missing the glass: everything.
  EXPECT_EQ(through({5.0f, 0.0f, 1.0f}, {0, 0, -1}), rc::Rgb(1.0f));
  // The tinted pane, ending above the plate: its absorption over d.
  const rc::Rgb tint = through({10.1f, 0.2f, 1.0f}, {0, 0, -1}, 1.9f);
  EXPECT_NEAR(tint.r, head_on * std::exp(-0.5f * d), 1e-5f);
  EXPECT_NEAR(tint.b, head_on * std::exp(-2.0f * d), 1e-5f);
  // Frosted glass spreads what it lets through into a lobe: not a straight line, so blocked.
  scene.materials[1].roughness = 0.5f;
  ASSERT_TRUE(scene.materials[1].is_rough_dielectric());
  EXPECT_EQ(through({0.1f, 0.2f, 1.0f}, {0, 0, -1}), rc::Rgb(0.0f));
  // Going on to the plate (and beyond): blocked.
  EXPECT_EQ(through({10.1f, 0.2f, 1.0f}, {0, 0, -1}), rc::Rgb(0.0f));
  EXPECT_EQ(through({10.1f, 0.2f, 1.0f}, {0, 0, -1}, 2.1f), rc::Rgb(0.0f));
}

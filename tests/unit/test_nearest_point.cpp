// The nearest-point query (closest_point_on_triangle, Scene::nearest_triangle) against brute
// force: a dense barycentric grid for one triangle, a linear scan of every triangle for the scene.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "raytrace_core/util/closest_point.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"
#include "raytrace_core/scene/scene.h"

namespace rc = gilt::raytrace_core;
using rc::Vec2;
using rc::Vec3;

namespace {

Vec3 at(const Vec3& a, const Vec3& b, const Vec3& c, Vec2 uv) { return (1.0f - uv.x - uv.y) * a + uv.x * b + uv.y * c; }

}  // namespace

// A grid of 201 × 201 barycentric steps holds a point within h = |longest edge| / 200 of any
// point of the triangle, so brute force overestimates the true distance d by at most h; the
// closed form must never be farther than the grid's best, and never nearer than d − h.
TEST(NearestPoint, ClosestPointOnTriangleMatchesAGrid) {
  rc::util::Rng rng(3);
  for (int trial = 0; trial < 300; ++trial) {
    auto random_point = [&] { return Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0f - 2.0f; };
    const Vec3 a = random_point(), b = random_point(), c = random_point(), p = random_point() * 2.0f;
    const Vec2 uv = rc::util::closest_point_on_triangle(p, a, b, c);
    ASSERT_GE(uv.x, -1e-6f);
    ASSERT_GE(uv.y, -1e-6f);
    ASSERT_LE(uv.x + uv.y, 1.0f + 1e-5f);
    const float found = glm::length(at(a, b, c, uv) - p);
    float best = std::numeric_limits<float>::max();
    constexpr int kSteps = 200;
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; i + j <= kSteps; ++j)
        best = std::min(best, glm::length(at(a, b, c, Vec2(float(i), float(j)) / float(kSteps)) - p));
    const float h = std::max({glm::length(b - a), glm::length(c - a), glm::length(c - b)}) / kSteps;
    EXPECT_LE(found, best + 1e-5f) << "trial " << trial;
    EXPECT_GE(found, best - h - 1e-5f) << "trial " << trial;
  }
}

// Scene::nearest_triangle against a scan of every triangle of the mesh, with the same radius and
// facing test; the two must agree on the distance (to float rounding) and, but for exact ties,
// on the triangle. Half the queries lie next to a face, where the query's first, smallest ball
// settles them; the rest anywhere, where it grows to the whole radius.
TEST(NearestPoint, SceneQueryMatchesALinearScan) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
  rc::util::Rng rng(5);
  rc::scene::TriangleMesh mesh;
  for (int t = 0; t < 400; ++t) {
    const Vec3 c(rng.uniform() * 10 - 5, rng.uniform() * 10 - 5, rng.uniform() * 10 - 5);
    for (int k = 0; k < 3; ++k) {
      mesh.positions.push_back(c + Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) * 2.0f);
      mesh.indices.push_back(uint32_t(mesh.positions.size() - 1));
    }
  }
  scene.meshes.push_back(mesh);
  scene.spheres.push_back({Vec3(0.0f), 1.0f, 0});  // other geometry is never returned
  scene.commit();
  const rc::scene::TriangleMesh& m = scene.meshes[0];
  int found = 0;
  for (int i = 0; i < 3000; ++i) {
    Vec3 p(rng.uniform() * 12 - 6, rng.uniform() * 12 - 6, rng.uniform() * 12 - 6);
    const Vec3 n = rc::util::sample_uniform_sphere(rng.uniform2());
    const float radius = 0.2f + 2.0f * rng.uniform();
    if (i % 2 == 1) {
      // Every other query next to a face (nearer than radius / 64, the query's first ball), as an
      // element's vertex is to the face it was meshed from.
      const size_t t = size_t(rng.uniform() * float(m.triangle_count())) % m.triangle_count();
      const Vec2 uv = rc::util::sample_uniform_triangle(rng.uniform2());
      p = at(m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]],
             m.positions[m.indices[3 * t + 2]], uv) +
          rc::util::sample_uniform_sphere(rng.uniform2()) * (radius * 0.01f * rng.uniform());
    }
    const float min_cosine = i % 3 == 0 ? -2.0f : 0.5f;  // every third query accepts any facing
    float best = radius;
    int best_t = -1;
    for (size_t t = 0; t < m.triangle_count(); ++t) {
      const Vec3 &a = m.positions[m.indices[3 * t]], &b = m.positions[m.indices[3 * t + 1]],
                 &c = m.positions[m.indices[3 * t + 2]];
      const Vec3 normal = glm::normalize(glm::cross(b - a, c - a));
      if (!(glm::dot(normal, n) > min_cosine)) continue;
      const float d = glm::length(at(a, b, c, rc::util::closest_point_on_triangle(p, a, b, c)) - p);
      if (d < best) best = d, best_t = int(t);
    }
    const auto hit = scene.nearest_triangle(0, p, radius, n, min_cosine);
    ASSERT_EQ(hit.has_value(), best_t >= 0) << "query " << i;
    if (!hit) continue;
    ++found;
    EXPECT_NEAR(hit->t, best, 1e-5f * (1.0f + best)) << "query " << i;
    const Vec3 &a = m.positions[m.indices[3 * hit->prim_id]], &b = m.positions[m.indices[3 * hit->prim_id + 1]],
               &c = m.positions[m.indices[3 * hit->prim_id + 2]];
    EXPECT_NEAR(glm::length(at(a, b, c, Vec2(hit->u, hit->v)) - p), hit->t, 1e-5f * (1.0f + best)) << "query " << i;
  }
  EXPECT_GT(found, 300) << "too few queries found a triangle for the comparison to mean anything";
}

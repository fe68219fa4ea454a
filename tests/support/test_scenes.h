#pragma once
// Small scenes and helpers shared by the tests.

#include <cmath>
#include <cstdint>
#include <vector>

#include "raytrace_core/render/render.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::test {
namespace rc = gilt::raytrace_core;

/// Unit-radius icosphere subdivided `levels` times, outward-facing, as one closed mesh.
inline rc::scene::TriangleMesh icosphere(int levels, uint32_t material = 0) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<rc::Vec3> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                             {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<uint32_t> f = {0, 11, 5, 0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                             4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                             6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2,  10, 8, 6,  7, 9, 8, 1};
  for (rc::Vec3& v : p) v = glm::normalize(v);
  for (int l = 0; l < levels; ++l) {
    std::vector<uint32_t> next;
    std::vector<std::pair<uint64_t, uint32_t>> cache;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      for (const auto& [k, v] : cache)
        if (k == key) return v;
      p.push_back(glm::normalize(0.5f * (p[a] + p[b])));
      cache.emplace_back(key, uint32_t(p.size() - 1));
      return uint32_t(p.size() - 1);
    };
    for (size_t i = 0; i < f.size(); i += 3) {
      const uint32_t a = f[i], b = f[i + 1], c = f[i + 2];
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    f = std::move(next);
  }
  rc::scene::TriangleMesh mesh;
  mesh.name = "icosphere";
  mesh.positions = std::move(p);
  mesh.indices = std::move(f);
  mesh.material = material;
  return mesh;
}

/// A quad (a, b, c, d) as two triangles, counter-clockwise seen from its front.
inline rc::scene::TriangleMesh quad(rc::Vec3 a, rc::Vec3 b, rc::Vec3 c, rc::Vec3 d) {
  rc::scene::TriangleMesh m;
  m.name = "quad";
  m.positions = {a, b, c, d};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

/// A uniform sky of `radiance`.
inline rc::scene::Light uniform_sky(float radiance) {
  rc::scene::Light l;
  l.kind = rc::scene::LightKind::environment;
  l.radiance = rc::Rgb(radiance);
  return l;
}

/// Mean of all pixels of a film, per channel averaged.
inline double film_mean(const rc::render::Film& film) {
  double sum = 0.0;
  for (const rc::Rgb& c : film.pixels()) sum += c.average();
  return sum / (double(film.width()) * film.height());
}

}  // namespace gilt::test

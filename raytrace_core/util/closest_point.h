#pragma once
// Nearest point of a triangle to a point in space, by the triangle's Voronoi regions (Ericson,
// "Real-Time Collision Detection", 2005, §5.1.5).

#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::util {

/// Barycentrics (b1, b2) of the second and third vertex of the point of triangle (a, b, c)
/// nearest to p; the point is (1 − b1 − b2)·a + b1·b + b2·c. Degenerate triangles give a
/// nearest point on their edges.
inline Vec2 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return Vec2(0.0f, 0.0f);  // vertex a
  const Vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return Vec2(1.0f, 0.0f);  // vertex b
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return Vec2(d1 / (d1 - d3), 0.0f);  // edge ab
  const Vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return Vec2(0.0f, 1.0f);  // vertex c
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return Vec2(0.0f, d2 / (d2 - d6));  // edge ac
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {  // edge bc
    const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return Vec2(1.0f - w, w);
  }
  const float sum = va + vb + vc;
  if (!(sum > 0.0f)) return Vec2(0.0f, 0.0f);  // degenerate: every region test failed
  return Vec2(vb / sum, vc / sum);              // interior
}

}  // namespace gilt::raytrace_core::util

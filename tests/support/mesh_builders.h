#pragma once
// Triangle meshes built in code for the radiosity tests: quads, turned and tilted boxes, and the
// small ceiling lamp most test scenes are lit by.

#include <array>
#include <cmath>
#include <cstdint>

#include "raytrace_core/scene/scene.h"

namespace gilt::test {
namespace rc = gilt::raytrace_core;

/// Appends the quad (c0, c1, c2, c3) as two triangles; its front is the side it winds
/// counter-clockwise about.
inline void add_quad(rc::scene::TriangleMesh& mesh, const std::array<rc::Vec3, 4>& c) {
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), c.begin(), c.end());
  mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

/// Appends a closed box with outward faces: half sizes `half`, tilted by `tilt` radians about x,
/// then turned by `turn` about y, then moved to `center`. Corner i has x, y, z at the + side
/// where bit 0, 1, 2 of i is set; its bottom (y = −half.y) is the third quad, indices 12–17 of
/// those appended.
inline void add_box(rc::scene::TriangleMesh& mesh, const rc::Vec3& center, const rc::Vec3& half, float turn,
                    float tilt = 0.0f) {
  const float cy = std::cos(turn), sy = std::sin(turn), cx = std::cos(tilt), sx = std::sin(tilt);
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  for (int i = 0; i < 8; ++i) {
    const rc::Vec3 p((i & 1 ? 1.f : -1.f) * half.x, (i & 2 ? 1.f : -1.f) * half.y,
                     (i & 4 ? 1.f : -1.f) * half.z);
    const rc::Vec3 q(p.x, cx * p.y - sx * p.z, sx * p.y + cx * p.z);
    mesh.positions.push_back(center + rc::Vec3(cy * q.x + sy * q.z, q.y, -sy * q.x + cy * q.z));
  }
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads)
    mesh.indices.insert(mesh.indices.end(),
                        {base + q[0], base + q[1], base + q[2], base + q[0], base + q[2], base + q[3]});
}

/// Adds a 1 × 1 lamp of material `material` at height `height` over the origin, facing down.
inline void add_ceiling_lamp(rc::scene::Scene& scene, uint32_t material, float height = 3.0f) {
  rc::scene::TriangleMesh lamp;
  lamp.name = "lamp";
  lamp.material = material;
  add_quad(lamp, {rc::Vec3(-0.5f, height, -0.5f), rc::Vec3(0.5f, height, -0.5f), rc::Vec3(0.5f, height, 0.5f),
                  rc::Vec3(-0.5f, height, 0.5f)});
  scene.meshes.push_back(std::move(lamp));
}

}  // namespace gilt::test

// Which triangles bound a solid (raytrace_core/scene/closed_surface.h): a cube is closed, a cube
// without its bottom is not, each piece of a mesh is judged on its own, and corners written once
// per face are welded by position first.

#include <gtest/gtest.h>

#include <vector>

#include "raytrace_core/scene/closed_surface.h"

namespace rc = gilt::raytrace_core;
using rc::Vec3;

namespace {

/// The unit cube [0, 1]³ shifted by `at`, twelve triangles, wound outward; `bottom` keeps its
/// bottom face (the first two triangles); `shared` writes 8 corners, else 3 per triangle.
rc::scene::TriangleMesh cube(Vec3 at, bool bottom, bool shared) {
  std::vector<Vec3> corners;
  for (int v = 0; v < 8; ++v) corners.push_back(at + Vec3(v & 1 ? 1 : 0, v & 2 ? 1 : 0, v & 4 ? 1 : 0));
  std::vector<uint32_t> faces = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  if (!bottom) faces.erase(faces.begin(), faces.begin() + 6);
  rc::scene::TriangleMesh m;
  if (shared) {
    m.positions = corners;
    m.indices = faces;
  } else {
    for (uint32_t c : faces) {
      m.indices.push_back(uint32_t(m.positions.size()));
      m.positions.push_back(corners[c]);
    }
  }
  return m;
}

/// `b` appended to `a` as one mesh.
rc::scene::TriangleMesh join(rc::scene::TriangleMesh a, const rc::scene::TriangleMesh& b) {
  const uint32_t base = uint32_t(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (uint32_t i : b.indices) a.indices.push_back(base + i);
  return a;
}

}  // namespace

TEST(ClosedSurface, ACubeIsClosedAndACubeWithoutItsBottomIsNot) {
  for (const bool shared : {true, false}) {
    const std::vector<char> closed = rc::scene::triangles_on_closed_surfaces(cube(Vec3(0.0f), true, shared));
    EXPECT_EQ(closed, std::vector<char>(12, 1)) << (shared ? "shared corners" : "corners per face");
    const std::vector<char> open = rc::scene::triangles_on_closed_surfaces(cube(Vec3(0.0f), false, shared));
    EXPECT_EQ(open, std::vector<char>(10, 0)) << (shared ? "shared corners" : "corners per face");
  }
}

TEST(ClosedSurface, EachPieceIsJudgedOnItsOwn) {
  const rc::scene::TriangleMesh both =
      join(cube(Vec3(0.0f), true, true), cube(Vec3(3.0f, 0.0f, 0.0f), false, false));
  const std::vector<char> closed = rc::scene::triangles_on_closed_surfaces(both);
  ASSERT_EQ(closed.size(), 22u);
  for (size_t t = 0; t < 12; ++t) EXPECT_EQ(closed[t], 1) << t;
  for (size_t t = 12; t < 22; ++t) EXPECT_EQ(closed[t], 0) << t;
}

// Two cubes sharing an edge make an edge with four triangles: not the boundary of one solid.
TEST(ClosedSurface, AnEdgeOfFourTrianglesIsNotClosed) {
  const rc::scene::TriangleMesh touching =
      join(cube(Vec3(0.0f), true, true), cube(Vec3(1.0f, 1.0f, 0.0f), true, true));
  const std::vector<char> closed = rc::scene::triangles_on_closed_surfaces(touching);
  for (char c : closed) EXPECT_EQ(c, 0);
}

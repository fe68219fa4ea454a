// The default view of a scene without a camera (raytrace_core/scene/camera.h, default_camera): every
// corner of the bounds is in the picture, and the model fills it rather than sitting small in the
// middle.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "raytrace_core/scene/camera.h"
#include "raytrace_core/util/rng.h"

namespace gilt::raytrace_core::scene {
namespace {

/// Where a point lands on the film of `c` for an image of `aspect`, in [0,1]² when it is in view,
/// found by inverting the pinhole projection and confirmed with generate_ray's own ray.
Vec2 film_position(const Camera& c, Vec3 p, float aspect) {
  const Vec3 w = glm::normalize(c.look_at - c.look_from);
  const Vec3 u = glm::normalize(glm::cross(w, c.up));
  const Vec3 v = glm::cross(u, w);
  const Vec3 d = p - c.look_from;
  const float depth = glm::dot(d, w);
  EXPECT_GT(depth, 0.0f) << "the corner is behind the camera";
  const float half_h = std::tan(0.5f * c.vfov_degrees * kPi / 180.0f), half_w = half_h * aspect;
  const Vec2 film(0.5f * (1.0f + glm::dot(d, u) / (depth * half_w)), 0.5f * (1.0f - glm::dot(d, v) / (depth * half_h)));
  const Ray ray = c.generate_ray(film, Vec2(0.5f), aspect);
  EXPECT_LT(glm::length(ray.direction - glm::normalize(d)), 1e-5f) << "the projection disagrees with generate_ray";
  return film;
}

TEST(DefaultCamera, EveryCornerIsInViewAndTheBoxFillsIt) {
  util::Rng rng(17);
  for (int trial = 0; trial < 200; ++trial) {
    Bounds3 b;
    const Vec3 centre(20.0f * rng.uniform() - 10.0f, 20.0f * rng.uniform() - 10.0f, 20.0f * rng.uniform() - 10.0f);
    // Half extents from 10⁻³ to 10³: flat, long and tall boxes as well as cubes.
    const Vec3 half(std::pow(10.0f, 6.0f * rng.uniform() - 3.0f), std::pow(10.0f, 6.0f * rng.uniform() - 3.0f),
                    std::pow(10.0f, 6.0f * rng.uniform() - 3.0f));
    b.extend(centre - half);
    b.extend(centre + half);
    const float aspect = std::pow(4.0f, 2.0f * rng.uniform() - 1.0f);  // 1/4 to 4
    const Camera c = default_camera(b, aspect);
    EXPECT_NO_THROW(c.validate());
    float reach = 0.0f;  // the farthest a corner lands from the image's centre, as a share of its half size
    for (int k = 0; k < 8; ++k) {
      const Vec3 corner((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z);
      const Vec2 f = film_position(c, corner, aspect);
      EXPECT_GE(f.x, 0.0f);
      EXPECT_LE(f.x, 1.0f);
      EXPECT_GE(f.y, 0.0f);
      EXPECT_LE(f.y, 1.0f);
      reach = std::max({reach, std::abs(2.0f * f.x - 1.0f), std::abs(2.0f * f.y - 1.0f)});
    }
    // The front face touches the margin (1/1.08 of the way to the edge) in the binding direction;
    // a bounding-sphere framing reaches as little as 1/√3 of it for a cube, less for a long box.
    EXPECT_NEAR(reach, 1.0f / 1.08f, 1e-3f) << "trial " << trial << ", aspect " << aspect;
  }
}

TEST(DefaultCamera, AnEmptySceneGetsAValidCamera) {
  EXPECT_NO_THROW(default_camera(Bounds3{}, 1.5f).validate());
  Bounds3 point;
  point.extend(Vec3(1.0f, 2.0f, 3.0f));
  EXPECT_NO_THROW(default_camera(point, 0.0f).validate());  // a single point, and no aspect
}

}  // namespace
}  // namespace gilt::raytrace_core::scene

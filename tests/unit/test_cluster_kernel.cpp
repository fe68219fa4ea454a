// The kernel between two clusters averaged over their extent (radiosity/solver/cluster_kernel.h),
// against Howell's closed form for coaxial disks and against quadrature for squares in general
// position, and the covariance of a triangle against its moments.

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "radiosity/solver/cluster_kernel.h"
#include "raytrace_core/util/rng.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;

namespace {

using glm::dvec3;
using gilt::raytrace_core::Vec3;

// The right triangle (0,0), (1,0), (0,1): E[x] = 1/3, E[x²] = 1/6, E[xy] = 1/12, so
// Var x = 1/18 and Cov(x, y) = −1/36.
TEST(ClusterKernel, TriangleCovarianceIsItsSecondMoment) {
  const glm::dmat3 c = rad::solver::triangle_covariance(dvec3(0, 0, 0), dvec3(1, 0, 0), dvec3(0, 1, 0));
  EXPECT_NEAR(c[0][0], 1.0 / 18.0, 1e-12);
  EXPECT_NEAR(c[1][1], 1.0 / 18.0, 1e-12);
  EXPECT_NEAR(c[0][1], -1.0 / 36.0, 1e-12);
  EXPECT_NEAR(c[1][0], -1.0 / 36.0, 1e-12);
  EXPECT_EQ(c[2][2], 0.0);
}

// Coaxial disks of radii a and b at distance h (Howell's catalogue, C-41): with A = a / h,
// B = b / h and X = 1 + (1 + B²) / A², F(a → b) = (X − √(X² − 4 B² / A²)) / 2, and the mean kernel
// over the two disks is π F / (π b²) = F / b², against 1 / h² at the centres. The average's
// factor 1 / (1 + A² + B²) is exact to first order in the disks' covariances; what it leaves is of
// the order of their product, A² B².
TEST(ClusterKernel, CoaxialDisksMatchHowell) {
  for (const auto& [A, B] : {std::pair{0.1, 0.1}, {0.3, 0.2}, {0.5, 0.5}, {0.5, 0.1}, {1.0, 1.0}, {0.2, 1.5}}) {
    const double X = 1.0 + (1.0 + B * B) / (A * A);
    const double F = 0.5 * (X - std::sqrt(X * X - 4.0 * B * B / (A * A)));
    const double exact = F / (B * B);  // the mean kernel times h², with h = 1
    // Uniform disk of radius r: variance r² / 4 along each axis of its plane.
    glm::mat3 C(0.0f);
    C[0][0] = C[1][1] = float((A * A + B * B) / 4.0);
    const double scale = rad::solver::cluster_kernel_scale(Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, -1), C);
    EXPECT_NEAR(scale, exact, A * A * B * B) << "A " << A << " B " << B;
    EXPECT_LT(std::abs(scale - exact), 0.1 * std::abs(1.0 - exact)) << "A " << A << " B " << B;
  }
}

// Two squares in general position that face each other (both cosines at the centres at least 0.5),
// each at most 0.4 of the distance across. The reference is a 40 × 40 midpoint rule on each
// square (2.6 million pairs; its own error is of order (side / 40)², below 10⁻⁴ of the kernel).
// Read at the centres the kernel errs by up to 6 %; averaged, the error left is of fourth order
// in the extent. Over 40 random configurations the mean error must fall at least fivefold
// (measured: from 1.6 % to 0.06 %), and no configuration's error may exceed the fourth-order scale
// ((a + b) / |d|)⁴ / 4.
TEST(ClusterKernel, SquaresInGeneralPositionAgreeWithQuadrature) {
  rc::util::Rng rng(17);
  auto unit = [&] {
    for (;;) {
      const dvec3 v(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
      const double l = glm::length(v);
      if (l > 0.1 && l <= 1.0) return v / l;
    }
  };
  auto frame = [](const dvec3& n, dvec3& t, dvec3& b) {
    t = glm::normalize(glm::cross(n, std::abs(n.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0)));
    b = glm::cross(n, t);
  };
  constexpr int kGrid = 40;
  double centre_error = 0.0, average_error = 0.0;
  int configurations = 0;
  while (configurations < 40) {
    const dvec3 d = unit(), n_r0 = unit(), n_s0 = unit();
    const dvec3 n_r = glm::dot(n_r0, d) < 0.0 ? -n_r0 : n_r0, n_s = glm::dot(n_s0, d) > 0.0 ? -n_s0 : n_s0;
    if (glm::dot(n_r, d) < 0.5 || -glm::dot(n_s, d) < 0.5) continue;
    const double a = 0.05 + 0.35 * rng.uniform(), b = 0.05 + 0.35 * rng.uniform();
    dvec3 tr, br, ts, bs;
    frame(n_r, tr, br);
    frame(n_s, ts, bs);
    double sum = 0.0;
    for (int i = 0; i < kGrid * kGrid; ++i) {
      const dvec3 x = a * (((i % kGrid) + 0.5) / kGrid - 0.5) * tr + a * (((i / kGrid) + 0.5) / kGrid - 0.5) * br;
      for (int j = 0; j < kGrid * kGrid; ++j) {
        const dvec3 y = d + b * (((j % kGrid) + 0.5) / kGrid - 0.5) * ts + b * (((j / kGrid) + 0.5) / kGrid - 0.5) * bs;
        const dvec3 u = y - x;
        const double uu = glm::dot(u, u);
        sum += std::max(0.0, glm::dot(n_r, u)) * std::max(0.0, -glm::dot(n_s, u)) / (uu * uu);
      }
    }
    const double mean = sum / double(kGrid * kGrid * kGrid * kGrid);
    const double centre = glm::dot(n_r, d) * -glm::dot(n_s, d);  // |d| = 1
    // A uniform square of side a: variance a² / 12 along each of its axes.
    const glm::dmat3 C = a * a / 12.0 * (glm::outerProduct(tr, tr) + glm::outerProduct(br, br)) +
                         b * b / 12.0 * (glm::outerProduct(ts, ts) + glm::outerProduct(bs, bs));
    const double averaged =
        centre * rad::solver::cluster_kernel_scale(Vec3(d), Vec3(n_r), Vec3(n_s), glm::mat3(C));
    centre_error += std::abs(centre - mean) / mean;
    average_error += std::abs(averaged - mean) / mean;
    EXPECT_LT(std::abs(averaged - mean) / mean, std::pow(a + b, 4.0) / 4.0) << "a " << a << " b " << b;
    ++configurations;
  }
  RecordProperty("mean_error_at_centres", std::to_string(centre_error / configurations));
  RecordProperty("mean_error_averaged", std::to_string(average_error / configurations));
  EXPECT_LT(average_error, centre_error / 5.0);
}

// Where an end does not face the other at the centres the expansion says nothing: factor 1.
TEST(ClusterKernel, NoFactorWhereTheEndsDoNotFace) {
  glm::mat3 C(0.01f);
  EXPECT_EQ(rad::solver::cluster_kernel_scale(Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(0, 0, -1), C), 1.0f);
  EXPECT_EQ(rad::solver::cluster_kernel_scale(Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1), C), 1.0f);
  EXPECT_EQ(rad::solver::cluster_kernel_scale(Vec3(0.0f), Vec3(0, 0, 1), Vec3(0, 0, -1), C), 1.0f);
}

}  // namespace

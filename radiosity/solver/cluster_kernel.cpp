// See cluster_kernel.h.
#include "radiosity/solver/cluster_kernel.h"

#include <algorithm>
#include <cmath>

namespace gilt::radiosity::solver {

glm::dmat3 triangle_covariance(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 g = (a + b + c) / 3.0;
  glm::dmat3 out(0.0);
  for (const glm::dvec3& v : {a, b, c}) out += glm::outerProduct(v - g, v - g);
  return out / 12.0;
}

float cluster_kernel_scale(const Vec3& d, const Vec3& n_r, const Vec3& n_s, const glm::mat3& C) {
  const float s = glm::dot(d, d), p = glm::dot(n_r, d), q = -glm::dot(n_s, d);
  if (!(s > 0.0f && p > 0.0f && q > 0.0f)) return 1.0f;
  const Vec3 Cd = C * d, Cn_s = C * n_s;
  const float trace = C[0][0] + C[1][1] + C[2][2];
  const float delta = -glm::dot(n_r, Cn_s) / (p * q) + 4.0f * glm::dot(n_s, Cd) / (q * s) -
                      4.0f * glm::dot(n_r, Cd) / (p * s) - 2.0f * trace / s + 12.0f * glm::dot(d, Cd) / (s * s);
  if (!std::isfinite(delta)) return 1.0f;
  return delta < 0.0f ? 1.0f / (1.0f - delta) : std::min(2.0f, 1.0f + delta);
}

}  // namespace gilt::radiosity::solver

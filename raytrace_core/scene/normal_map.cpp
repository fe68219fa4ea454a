#include "raytrace_core/scene/normal_map.h"

#include <cmath>

#include "raytrace_core/scene/scene.h"

namespace gilt::raytrace_core::scene {

namespace {

/// Some unit vector orthogonal to unit n (Duff et al. 2017's branchless basis).
Vec3 any_orthogonal(const Vec3& n) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z), b = n.x * n.y * a;
  return {1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
}

}  // namespace

std::vector<glm::vec4> generate_tangents(const TriangleMesh& mesh, const TextureRef& map) {
  const size_t nv = mesh.positions.size();
  std::vector<Vec3> along_s(nv, Vec3(0.0f)), along_t(nv, Vec3(0.0f)), face_normal(nv, Vec3(0.0f));
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    const uint32_t* c = &mesh.indices[3 * f];
    const Vec3 e1 = mesh.positions[c[1]] - mesh.positions[c[0]], e2 = mesh.positions[c[2]] - mesh.positions[c[0]];
    const Vec3 area_normal = glm::cross(e1, e2);  // twice the area, along the face normal
    for (int k = 0; k < 3; ++k) face_normal[c[k]] += area_normal;
    if (mesh.uvs.empty()) continue;
    const Vec2 st0 = map.st(mesh.uvs[c[0]]);
    const Vec2 d1 = map.st(mesh.uvs[c[1]]) - st0, d2 = map.st(mesh.uvs[c[2]]) - st0;
    const float det = d1.x * d2.y - d2.x * d1.y;
    if (!(std::fabs(det) > 0.0f) || !std::isfinite(det)) continue;  // no (s, t) frame on this face
    // ∂p/∂s and ∂p/∂t solve [e1 e2] = [∂p/∂s ∂p/∂t] [d1 d2]; weighted by the face's area.
    const float weight = glm::length(area_normal) / std::fabs(det);
    const Vec3 dp_ds = (d2.y * e1 - d1.y * e2) * (weight * std::copysign(1.0f, det));
    const Vec3 dp_dt = (d1.x * e2 - d2.x * e1) * (weight * std::copysign(1.0f, det));
    if (!is_finite(dp_ds) || !is_finite(dp_dt)) continue;
    for (int k = 0; k < 3; ++k) {
      along_s[c[k]] += dp_ds;
      along_t[c[k]] += dp_dt;
    }
  }
  std::vector<glm::vec4> tangents(nv);
  for (size_t v = 0; v < nv; ++v) {
    Vec3 n = mesh.normals.empty() || glm::dot(mesh.normals[v], mesh.normals[v]) == 0.0f ? face_normal[v] : mesh.normals[v];
    n = glm::dot(n, n) > 0.0f ? glm::normalize(n) : Vec3(0.0f, 0.0f, 1.0f);
    Vec3 t = along_s[v] - n * glm::dot(n, along_s[v]);
    const float len2 = glm::dot(t, t);
    if (!(len2 > 0.0f) || !std::isfinite(len2)) {
      tangents[v] = glm::vec4(any_orthogonal(n), 1.0f);
      continue;
    }
    t /= std::sqrt(len2);
    // The bitangent runs up the image, against +t.
    const float w = glm::dot(glm::cross(n, t), -along_t[v]) < 0.0f ? -1.0f : 1.0f;
    tangents[v] = glm::vec4(t, w);
  }
  return tangents;
}

Vec3 tangent_to_world(const Vec3& n, const glm::vec4& tangent, const Vec3& t) {
  Vec3 x = Vec3(tangent) - n * glm::dot(n, Vec3(tangent));
  const float len2 = glm::dot(x, x);
  if (!(len2 > 1e-12f) || !std::isfinite(len2)) return n;
  x /= std::sqrt(len2);
  const Vec3 y = (tangent.w < 0.0f ? -1.0f : 1.0f) * glm::cross(n, x);
  const Vec3 m = t.x * x + t.y * y + t.z * n;
  const float m2 = glm::dot(m, m);
  return m2 > 0.0f && std::isfinite(m2) ? m / std::sqrt(m2) : n;
}

Vec3 decode_normal_texel(const Rgb& texel, float scale) {
  const Vec3 t((2.0f * texel.r - 1.0f) * scale, (2.0f * texel.g - 1.0f) * scale, 2.0f * texel.b - 1.0f);
  const float len2 = glm::dot(t, t);
  return len2 > 0.0f && std::isfinite(len2) ? t / std::sqrt(len2) : Vec3(0.0f, 0.0f, 1.0f);
}

Vec3 height_normal(float dh_ds, float dh_dup, float scale) {
  return glm::normalize(Vec3(-scale * dh_ds, -scale * dh_dup, 1.0f));
}

}  // namespace gilt::raytrace_core::scene

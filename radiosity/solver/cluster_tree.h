#pragma once
// Private to the hierarchical solver (hierarchical.cpp and the files beside it): the cluster tree
// over the mesh's elements and what is read of its nodes. Holds the node (bounds, mean normal and
// spread, area, albedo, covariance), the tree and its builder (make_tree), the "sends nothing"
// tests, how a node's elements face a direction, the direction bins and the cluster models that
// send and receive by them (Moments, intensity, towards), the sampling of a visibility ray's end
// on a node, and pull. Reads the mesh and per-element values; writes only the trees and sums it
// returns. The small helpers are inline here: they run inside the linker's refine and the walks.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "radiosity/mesh/element_scene.h"
#include "radiosity/mesh/mesh.h"
#include "radiosity/solver/form_factor.h"
#include "raytrace_core/util/math.h"
#include "raytrace_core/util/rgb.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::solver::detail {

using mesh::mesh_surface_point;
using mesh::RadiosityMesh;
using rc::Rgb;
using rc::Vec3;

inline constexpr float kPi = rc::kPi;
inline constexpr uint32_t kNone = ~0u;
/// Slack of the "sends nothing" tests, as a slope over the nearest distance between the two: a
/// source within 10⁻⁴ rad of the receiver's plane, as seen from every point of the receiver,
/// sends at most 10⁻⁴ of its light (the same bound as kTangentSlope).
inline constexpr float kPlaneSlack = 1e-4f;

/// One vector per colour channel: Σ B A n and the irradiance vector W.
struct RgbVec {
  Vec3 c[3] = {Vec3(0.0f), Vec3(0.0f), Vec3(0.0f)};
  void add(const Rgb& w, const Vec3& d) {
    for (int k = 0; k < 3; ++k) c[k] += w[k] * d;
  }
  void add(const RgbVec& o) {
    for (int k = 0; k < 3; ++k) c[k] += o.c[k];
  }
  Rgb dot(const Vec3& d) const { return Rgb(glm::dot(c[0], d), glm::dot(c[1], d), glm::dot(c[2], d)); }
};

struct Node {
  uint32_t first = 0, count = 0;  ///< elements order[first .. first + count)
  uint32_t right = kNone;         ///< second child (the first is the next node); kNone for a leaf
  rc::Bounds3 box;                ///< of the elements' vertices
  Vec3 center{0.0f};              ///< area-weighted centroid
  float radius = 0.0f;            ///< of a sphere about center holding every vertex
  Vec3 normal{0.0f};              ///< unit area-weighted mean normal (0 when it cancels)
  float spread = 2.0f;            ///< max |n_k − normal| over the elements
  float low = 0.0f, high = 0.0f;  ///< least and greatest normal·(x − center) over the vertices
  float area = 0.0f;
  Vec3 area_vector{0.0f};      ///< Σ A_k n_k
  float albedo = 0.0f;         ///< area-weighted mean reflectance (channel mean)
  glm::mat3 covariance{0.0f};  ///< of its points about center, uniform by area

  bool leaf() const { return right == kNone; }
};

/// How a node's elements face a direction ω: all in front (n_k·ω ≥ 0 for every k, since
/// n_k·ω ≥ n̄·ω − |n_k − n̄|), all behind, or some each way.
enum class Facing { front, back, mixed };

/// With `margin` = sin of the largest angle between ω and the directions it stands for, the
/// answer holds for all of them.
inline Facing facing(const Node& node, const Vec3& omega, float margin = 0.0f) {
  if (node.spread >= 2.0f) return Facing::mixed;
  const float c = glm::dot(node.normal, omega), bound = node.spread + margin;
  return c >= bound ? Facing::front : (c <= -bound ? Facing::back : Facing::mixed);
}

/// The element hierarchy, nodes in depth-first pre-order (a parent before its children).
struct Tree {
  std::vector<Node> nodes;
  std::vector<uint32_t> order;  ///< elements in leaf order
  std::vector<SourceTriangle> triangles;

  uint32_t element(const Node& leaf) const { return order[leaf.first]; }
};

/// The element hierarchy over the mesh's elements, each element reflecting `albedo` (see
/// TreeBuilder in cluster_tree.cpp).
Tree make_tree(const RadiosityMesh& mesh, std::span<const Rgb> albedo);

/// True when no point of `to` lies in front of any element of `from` (beyond the slack): from
/// then sends nothing to `to`, and receives nothing from it. Bounds n_k·(x − y) for x in `to`,
/// y in `from`, by n̄·(x − y) plus the normals' spread times the largest |x − y|.
inline bool behind(const Node& from, const Node& to) {
  const Vec3 d = to.center - from.center;
  const float dist = glm::length(d), far = dist + from.radius + to.radius;
  const float near = std::max(0.0f, dist - from.radius - to.radius);
  // The greatest n̄_from·(x − c_to) over `to`: its radius, or less when the two face alike, or
  // when they face opposite ways (n̄_from·y = −n̄_to·y + (n̄_from + n̄_to)·y): a cluster of twins
  // lying on the elements they were made from is behind them, and they behind it.
  const float to_high = std::min({to.radius, to.high + glm::length(from.normal - to.normal) * to.radius,
                                  -to.low + glm::length(from.normal + to.normal) * to.radius});
  const float reach = glm::dot(from.normal, d) + to_high - from.low + from.spread * far;
  // (Plus rounding: two clusters in one plane lie on it to within float precision of their size.)
  return reach <= kPlaneSlack * near + 1e-6f * far;
}

/// The same with a point receiver (p, n) as `to`: the node sends nothing to it.
inline bool sends_nothing(const Node& s, const Vec3& p, const Vec3& n) {
  const Vec3 d = s.center - p;
  const float dist = glm::length(d), far = dist + s.radius, near = std::max(0.0f, dist - s.radius);
  if (glm::dot(n, d) + s.radius <= kPlaneSlack * near) return true;  // behind the receiver's plane
  return glm::dot(s.normal, -d) - s.low + s.spread * far <= kPlaneSlack * near;
}

/// Six direction bins: ±x, ±y, ±z by w's largest component.
inline constexpr int kDirectionBins = 6;
inline int direction_bin(const Vec3& w) {
  const Vec3 a = glm::abs(w);
  const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
  return 2 * axis + (w[axis] < 0.0f ? 1 : 0);
}

/// Σ B A n of a node's elements, per bin of their normals.
struct Moments {
  RgbVec bins[kDirectionBins];
  void add(const Rgb& power, const Vec3& n) { bins[direction_bin(n)].add(power, n); }
  void add(const Moments& o) {
    for (int b = 0; b < kDirectionBins; ++b) bins[b].add(o.bins[b]);
  }
  RgbVec total() const {
    RgbVec t;
    for (const RgbVec& b : bins) t.add(b);
    return t;
  }
};

/// Radiant intensity (W·sr⁻¹) of a node towards unit direction ω: Σ B A max(0, n·ω) / π over its
/// elements, as Σ over normal bins of max(0, ω·Σ B A n). Exact where each bin's elements all
/// face ω or all face away (always for a flat node); where they split, the parts cancel and the
/// bin gives less. The bins keep a wall's sunlit outer face from shining through to its inner
/// face, which a two-band model of the node (¼ Σ B A + ½ ω·Σ B A n) sends a quarter of its power.
inline Rgb intensity(std::span<const RgbVec> bins, const Vec3& omega) {
  Rgb out(0.0f);
  for (const RgbVec& bin : bins) {
    const Rgb along = bin.dot(omega);
    for (int k = 0; k < 3; ++k) out[k] += std::max(0.0f, along[k]);
  }
  return out * (1.0f / kPi);
}
inline Rgb intensity(const Moments& moment, const Vec3& omega) {
  return intensity(std::span<const RgbVec>(moment.bins), omega);
}

/// What a node sends towards (or receives from) unit direction ω, by the cluster models above:
/// `total` is Σ x_k A_k and `moment` Σ x_k A_k n_k for some per-element x (radiosity, or 1).
inline float towards(const Node& node, float total, const Vec3& moment, const Vec3& omega) {
  const float along = glm::dot(omega, moment);
  switch (facing(node, omega)) {
    case Facing::front:
      return std::max(0.0f, along);
    case Facing::back:
      return 0.0f;
    case Facing::mixed:
      break;
  }
  return std::max(0.0f, 0.25f * total + 0.5f * along);
}

/// A point for a visibility ray on node `s`'s elements. The element is drawn by walking down
/// the tree, each child taken in proportion to weight(child) (what it exchanges with the other
/// end of the ray), so that the ray tests the part of a cluster that carries the light: a
/// cluster holding a bright roof and a dark plate under it must not be seen through the plate.
/// Children that both weigh nothing are taken by area. Uniform by area within the element.
template <class Weight>
rc::scene::SurfacePoint sample_point(const Tree& tree, const RadiosityMesh& mesh, uint32_t s, Weight weight,
                                     rc::util::Rng& rng) {
  while (!tree.nodes[s].leaf()) {
    const uint32_t a = s + 1, b = tree.nodes[s].right;
    float wa = weight(a), wb = weight(b);
    if (!(wa + wb > 0.0f)) wa = tree.nodes[a].area, wb = tree.nodes[b].area;
    s = rng.uniform() * (wa + wb) < wa ? a : b;
  }
  const uint32_t e = tree.element(tree.nodes[s]);
  const rc::Vec2 b = rc::util::sample_uniform_triangle(rng.uniform2());
  const auto& el = mesh.elements[e];
  const Vec3 q =
      (1.0f - b.x - b.y) * mesh.positions[el[0]] + b.x * mesh.positions[el[1]] + b.y * mesh.positions[el[2]];
  return mesh_surface_point(q, mesh.element_normal[e]);
}

/// Σ B A and Σ B A n of every node, from the element radiosities (leaves up).
void pull(const Tree& tree, const RadiosityMesh& mesh, std::span<const Rgb> radiosity,
          std::vector<Rgb>& power, std::vector<Moments>& moment);

}  // namespace gilt::radiosity::solver::detail

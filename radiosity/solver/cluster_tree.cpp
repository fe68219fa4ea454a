// The cluster tree of the hierarchical solver (see cluster_tree.h): TreeBuilder, which reads the
// mesh's elements and their albedo and writes the tree (median splits, or splits by facing, and
// each node's summary), and pull, which reads element radiosities and writes each node's sums.

#include "radiosity/solver/cluster_tree.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <tuple>
#include <utility>

#include "radiosity/solver/cluster_kernel.h"

namespace gilt::radiosity::solver::detail {
namespace {

/// split_by_layer's least gap between layers, as a fraction of the node's radius.
constexpr float kLayerGap = 1e-4f;

class TreeBuilder {
 public:
  TreeBuilder(const RadiosityMesh& mesh, std::span<const Rgb> albedo) : mesh_(mesh), albedo_(albedo) {
    const size_t n = mesh.element_count();
    centroid_.resize(n);
    for (size_t e = 0; e < n; ++e) {
      const auto& el = mesh.elements[e];
      centroid_[e] = (mesh.positions[el[0]] + mesh.positions[el[1]] + mesh.positions[el[2]]) / 3.0f;
    }
  }

  Tree build() {
    const size_t n = mesh_.element_count();
    tree_.order.resize(n);
    std::iota(tree_.order.begin(), tree_.order.end(), 0u);
    tree_.nodes.reserve(2 * n);
    if (n > 0) add(0, uint32_t(n));
    tree_.triangles.resize(n);
    for (size_t e = 0; e < n; ++e) {
      const auto& el = mesh_.elements[e];
      tree_.triangles[e] =
          SourceTriangle(mesh_.positions[el[0]], mesh_.positions[el[1]], mesh_.positions[el[2]]);
    }
    return std::move(tree_);
  }

 private:
  uint32_t add(uint32_t first, uint32_t count) {
    const uint32_t index = uint32_t(tree_.nodes.size());
    tree_.nodes.push_back(summarise(first, count));
    if (count > 1) {
      // Median split along the longest extent of the centroids; ties broken by element index so
      // the tree, and everything after it, is the same on every run.
      rc::Bounds3 cb;
      for (uint32_t i = first; i < first + count; ++i) cb.extend(centroid_[tree_.order[i]]);
      const Vec3 ext = cb.diagonal();
      const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
      uint32_t half = count / 2;
      auto begin = tree_.order.begin() + first;
      std::nth_element(begin, begin + half, begin + count, [&](uint32_t a, uint32_t b) {
        const float ca = centroid_[a][axis], cb2 = centroid_[b][axis];
        return ca < cb2 || (ca == cb2 && a < b);
      });
      if (tree_.nodes[index].spread >= 1.0f)
        half = split_by_facing(first, count, half);
      else
        half = split_by_layer(first, count, half, tree_.nodes[index]);
      add(first, half);
      const uint32_t right = add(first + half, count - half);
      tree_.nodes[index].right = right;
    }
    return index;
  }

  /// A node whose elements face both ways (two faces of a wall or a roof slab, a column) is
  /// split by the side its elements face rather than by position when that leaves much less of
  /// its area in children that still face both ways. Such a child can be neither wholly in front
  /// of a direction nor wholly behind it, so its links take the cluster models, which share
  /// one visible fraction among all its elements: a slab's sunlit top and its ceiling, a few
  /// centimetres apart with nothing between them, read the same open rays, and the sun on the
  /// roof leaked into the room below (a closed box under a sun at link tolerance 2e-4). The side
  /// is the sign of n·a for the principal axis a of Σ A n nᵀ. `half` is the positional split, already
  /// applied; returns the size of the first child.
  uint32_t split_by_facing(uint32_t first, uint32_t count, uint32_t half) {
    auto begin = tree_.order.begin() + first;
    const float positional = mixed_area(first, half) + mixed_area(first + half, count - half);
    // Principal axis of the normals by power iteration, from the axis of the largest diagonal.
    double m[3][3] = {};
    for (uint32_t i = first; i < first + count; ++i) {
      const uint32_t e = tree_.order[i];
      const DVec3 n(mesh_.element_normal[e]);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m[r][c] += mesh_.element_area[e] * n[r] * n[c];
    }
    DVec3 a(0.0);
    a[m[0][0] >= m[1][1] && m[0][0] >= m[2][2] ? 0 : (m[1][1] >= m[2][2] ? 1 : 2)] = 1.0;
    for (int it = 0; it < 32; ++it) {
      const DVec3 b(m[0][0] * a.x + m[0][1] * a.y + m[0][2] * a.z,
                    m[1][0] * a.x + m[1][1] * a.y + m[1][2] * a.z,
                    m[2][0] * a.x + m[2][1] * a.y + m[2][2] * a.z);
      const double len = glm::length(b);
      if (!(len > 0.0)) return half;
      a = b / len;
    }
    std::vector<uint32_t> trial(begin, begin + count);
    const auto front = std::stable_partition(trial.begin(), trial.end(), [&](uint32_t e) {
      return glm::dot(DVec3(mesh_.element_normal[e]), a) >= 0.0;
    });
    const uint32_t split = uint32_t(front - trial.begin());
    if (split == 0 || split == count) return half;
    std::vector<uint32_t> positional_order(begin, begin + count);
    std::copy(trial.begin(), trial.end(), begin);
    const float facing_split = mixed_area(first, split) + mixed_area(first + split, count - split);
    if (facing_split < 0.5f * positional) return split;
    std::copy(positional_order.begin(), positional_order.end(), begin);
    return half;
  }

  /// A node whose elements face one way but lie in separate layers along its normal, with empty
  /// space between them (a floor over the floor of a crawl space below it, the floors of two
  /// storeys, the treads of a stair), is split between the layers rather than by position. The
  /// cluster models treat a flat node as one plane and share one visible fraction among its
  /// elements, but an upper layer may hide a lower one from everything above: in the furnace
  /// family's atrium, clusters holding pieces of the courtyard's floor and of the enclosure's
  /// floor 1.3 below it took a quarter of the ceiling's light on all of them, and the courtyard's
  /// floor gathered 0.70 of what a closed furnace sends. Connected pieces of one surface share
  /// vertices, so their spans along the normal overlap and are never split this way. Of the gaps,
  /// the one leaving the children most nearly equal in count is taken; `half` is the positional
  /// split, already applied; returns the size of the first child.
  uint32_t split_by_layer(uint32_t first, uint32_t count, uint32_t half, const Node& node) {
    struct Span {
      float low, high;
      uint32_t element;
    };
    std::vector<Span> spans(count);
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t e = tree_.order[first + i];
      Span s{std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(), e};
      for (uint32_t v : mesh_.elements[e]) {
        const float h = glm::dot(node.normal, mesh_.positions[v] - node.center);
        s.low = std::min(s.low, h), s.high = std::max(s.high, h);
      }
      spans[i] = s;
    }
    std::sort(spans.begin(), spans.end(), [](const Span& a, const Span& b) {
      return a.low < b.low || (a.low == b.low && a.element < b.element);
    });
    // Layers closer than this are one surface's, apart by rounding.
    const float least_gap = kLayerGap * node.radius;
    uint32_t best = 0;
    float reach = spans[0].high;
    for (uint32_t i = 1; i < count; ++i) {
      if (spans[i].low - reach > least_gap && std::min(i, count - i) > std::min(best, count - best)) best = i;
      reach = std::max(reach, spans[i].high);
    }
    if (best == 0) return half;
    for (uint32_t i = 0; i < count; ++i) tree_.order[first + i] = spans[i].element;
    return best;
  }

  /// The unit area-weighted mean normal of elements [first, first + count) of the order (0 where
  /// the normals cancel) and their spread about it, the largest |n_k − mean| (2 where they
  /// cancel): Node::normal and Node::spread.
  std::pair<Vec3, float> normal_and_spread(uint32_t first, uint32_t count) const {
    double area = 0.0;
    DVec3 sum(0.0);
    for (uint32_t i = first; i < first + count; ++i) {
      const uint32_t e = tree_.order[i];
      area += mesh_.element_area[e];
      sum += double(mesh_.element_area[e]) * DVec3(mesh_.element_normal[e]);
    }
    const double len = glm::length(sum);
    if (!(len > 1e-6 * area && len > 0.0)) return {Vec3(0.0f), 2.0f};
    const Vec3 mean(sum / len);
    float spread = 0.0f;
    for (uint32_t i = first; i < first + count; ++i)
      spread = std::max(spread, glm::length(mesh_.element_normal[tree_.order[i]] - mean));
    return {mean, spread};
  }

  /// The area of elements [first, first + count) of the order when they face both ways (their
  /// normals' spread is 1 or more, as Node::spread), else 0.
  float mixed_area(uint32_t first, uint32_t count) const {
    if (normal_and_spread(first, count).second < 1.0f) return 0.0f;
    double area = 0.0;
    for (uint32_t i = first; i < first + count; ++i) area += mesh_.element_area[tree_.order[i]];
    return float(area);
  }

  Node summarise(uint32_t first, uint32_t count) const {
    Node node;
    node.first = first;
    node.count = count;
    double area = 0.0, albedo = 0.0;
    DVec3 weighted_centroid(0.0), weighted_normal(0.0);
    for (uint32_t i = first; i < first + count; ++i) {
      const uint32_t e = tree_.order[i];
      const double a = mesh_.element_area[e];
      area += a;
      albedo += a * albedo_[e].average();
      weighted_centroid += a * DVec3(centroid_[e]);
      weighted_normal += a * DVec3(mesh_.element_normal[e]);
      for (uint32_t v : mesh_.elements[e]) node.box.extend(mesh_.positions[v]);
    }
    node.area = float(area);
    node.area_vector = Vec3(weighted_normal);
    node.albedo = area > 0.0 ? float(albedo / area) : 0.0f;
    node.center = area > 0.0 ? Vec3(weighted_centroid / area) : node.box.center();
    std::tie(node.normal, node.spread) = normal_and_spread(first, count);
    float radius2 = 0.0f;
    float low = 0.0f, high = 0.0f;
    glm::dmat3 second(0.0);
    for (uint32_t i = first; i < first + count; ++i) {
      const uint32_t e = tree_.order[i];
      const auto& el = mesh_.elements[e];
      const DVec3 g = DVec3(centroid_[e]) - DVec3(node.center);
      second += double(mesh_.element_area[e]) *
                (triangle_covariance(DVec3(mesh_.positions[el[0]]), DVec3(mesh_.positions[el[1]]),
                                     DVec3(mesh_.positions[el[2]])) +
                 glm::outerProduct(g, g));
      for (uint32_t v : mesh_.elements[e]) {
        const Vec3 d = mesh_.positions[v] - node.center;
        radius2 = std::max(radius2, glm::dot(d, d));
        const float h = glm::dot(node.normal, d);
        low = std::min(low, h), high = std::max(high, h);
      }
    }
    if (area > 0.0) node.covariance = glm::mat3(second / area);
    node.radius = std::sqrt(radius2) * (1.0f + 1e-6f);
    node.low = low, node.high = high;
    return node;
  }

  const RadiosityMesh& mesh_;
  std::span<const Rgb> albedo_;
  std::vector<Vec3> centroid_;
  Tree tree_;
};

}  // namespace

Tree make_tree(const RadiosityMesh& mesh, std::span<const Rgb> albedo) {
  return TreeBuilder(mesh, albedo).build();
}

void pull(const Tree& tree, const RadiosityMesh& mesh, std::span<const Rgb> radiosity,
          std::vector<Rgb>& power, std::vector<Moments>& moment) {
  const size_t n = tree.nodes.size();
  power.assign(n, Rgb(0.0f));
  moment.assign(n, Moments{});
  for (size_t i = n; i-- > 0;) {
    const Node& node = tree.nodes[i];
    if (node.leaf()) {
      const uint32_t e = tree.element(node);
      power[i] = radiosity[e] * mesh.element_area[e];
      moment[i].add(power[i], mesh.element_normal[e]);
    } else {
      for (size_t c : {i + 1, size_t(node.right)}) {
        power[i] += power[c];
        moment[i].add(moment[c]);
      }
    }
  }
}

}  // namespace gilt::radiosity::solver::detail

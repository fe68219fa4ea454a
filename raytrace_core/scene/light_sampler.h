#pragma once
// Choosing a light to sample from a point to be lit: a light BVH that weighs each cluster of
// lights by its power, its distance and how it faces the point (Conty Estevez & Kulla 2018,
// "Importance Sampling of Many Lights with Adaptive Tree Splitting"), for emitting triangles,
// spheres, point and spot lights; distant lights (directional, environment) are chosen by power.
//
// Sampling descends the tree once, O(log n), and the probability of any one light is found by
// the same descent along that light's path from the root, so the probability a BSDF-sampled
// ray's light is given for MIS is the one light sampling used, to the bit.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::raytrace_core::scene {

/// Where light is sought: a point and the side of its surface that receives light.
struct LightQuery {
  Vec3 p{0.0f};
  Vec3 n{0.0f};            ///< unit normal of the receiving side; zero: light from any direction counts
  bool two_sided = false;  ///< light from behind n counts too (a surface that transmits)
};

/// The normal sample_light and light_pdf take as the receiving side: n, or zero when light from
/// behind n counts too.
inline Vec3 receiving_normal(const LightQuery& query) { return query.two_sided ? Vec3(0.0f) : query.n; }

/// A light chosen for a query, and the probability of choosing it.
struct LightChoice {
  uint32_t light = 0;  ///< index into the lights the sampler was built over
  float pmf = 0.0f;    ///< 0: no light can reach the query, nothing was chosen
};

/// How lights are chosen for next-event estimation.
enum class LightSampling : uint8_t {
  bvh,    ///< by power, distance and orientation (the default)
  power,  ///< by power alone, wherever the point (the choice before the light BVH)
};

/// Parses "bvh" or "power" (throws InputError otherwise).
LightSampling parse_light_sampling(const std::string& name);
/// "bvh" or "power".
const char* light_sampling_name(LightSampling mode);

/// Chooses one light among a scene's for a point to be lit.
class LightSampler {
 public:
  LightSampler() = default;
  /// Builds over `lights` (Scene::lights()), their scalar powers `power` (zero: never chosen).
  LightSampler(const Scene& scene, std::span<const Light> lights, std::span<const float> power);

  /// A light drawn for `query` with probability pmf; `u` in [0, 1).
  LightChoice sample(const LightQuery& query, float u) const;
  /// The probability that sample() draws light `light` for `query`.
  float pmf(const LightQuery& query, uint32_t light) const;
  /// Number of lights that can be chosen at all (0: the scene has none with power).
  size_t size() const { return power_.size(); }

  /// Choose by the BVH (default) or by power alone.
  void set_mode(LightSampling mode) { mode_ = mode; }
  LightSampling mode() const { return mode_; }
  /// Nodes of the tree (for tests and statistics).
  size_t node_count() const { return nodes_.size(); }
  /// Depth of the deepest leaf (the root is 0).
  int depth() const { return depth_; }

  /// One node: bounds of its lights' positions, a cone holding their emission directions, and
  /// their summed power. Interior nodes have their first child next to them and their second
  /// at `index`; leaves hold one light, `index`. Its leaves are [first, last) in depth-first order.
  struct Node {
    Vec3 lo{kInfinity}, hi{-kInfinity};  ///< bounds of the emitting positions
    Vec3 centre{0.0f};        ///< of the box
    float radius2 = 0.0f;     ///< squared radius of the box's bounding sphere about centre
    Vec3 axis{0.0f, 0.0f, 1.0f};
    float cos_spread = 1.0f;  ///< cosine of θo: every emitting surface's normal lies within θo of axis
    float sin_spread = 0.0f;
    float cos_falloff = 0.0f; ///< cosine of θe: each emits up to θe beyond its normal (π/2: a cosine lobe)
    float power = 0.0f;
    uint32_t index = 0;
    uint32_t first = 0, last = 0;
    bool leaf = false;
    bool two_sided = false;  ///< some light in it emits on both sides of its normal
  };
  /// The importance of a node for a query: an upper estimate of the light it can send there,
  /// power · cos θ' / d², zero only where no light of the node can reach the query's side.
  static float importance(const Node& node, const LightQuery& query);
  /// Whether the query is far enough from a node, and its lights' normals close enough, that
  /// its children's importances differ little: the node's lights are then chosen by power.
  static bool distant_cluster(const Node& node, const LightQuery& query);

 private:
  /// Builds the subtree over lights order[begin, end) (leaves: each light's node) and returns
  /// its root's index; `trail` holds the branches taken to reach it.
  int build(std::vector<uint32_t>& order, std::vector<Node>& leaves, size_t begin, size_t end, int depth,
            uint64_t trail);

  /// Probability of choosing leaf `leaf` (depth-first position) by power within `cluster`.
  float cluster_pmf(const Node& cluster, uint32_t leaf) const;

  LightSampling mode_ = LightSampling::bvh;
  util::Distribution1D power_;           // every light by power: the distant lights' choice, and mode power
  float tree_share_ = 0.0f;        // probability of descending the tree (its lights' share of power)
  util::Distribution1D distant_;         // the directional and environment lights, by power
  std::vector<uint32_t> distant_index_;  // light index of each entry of distant_
  std::vector<Node> nodes_;
  std::vector<double> prefix_;     // summed power of the leaves before each, in depth-first order
  std::vector<uint32_t> leaf_light_;  // light of each leaf, in depth-first order
  std::vector<uint32_t> leaf_of_light_;  // each light's position in leaf_light_
  std::vector<uint64_t> trail_;    // per light: its branch at each level (bit d = 1: second child), or distant_ slot
  std::vector<int8_t> trail_depth_;  // per light: its leaf's depth; −1 never chosen; −2 distant
  int depth_ = 0;
};

}  // namespace gilt::raytrace_core::scene

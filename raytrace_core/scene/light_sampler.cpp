#include "raytrace_core/scene/light_sampler.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "raytrace_core/util/error.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::raytrace_core::scene {

namespace {

/// Cosines within this of a grazing angle count as reaching: rounding in the bounds' angles must
/// never give a light that can reach the query a probability of zero.
constexpr float kGrazing = 1e-4f;
/// Below this depth splits minimise the orientation-aware cost; past it, lights are split in
/// halves, so no leaf lies deeper than 32 + log2(lights) < 64, the bits of a light's trail.
constexpr int kCostDepth = 32;
constexpr int kBins = 12;

/// cos and sin of max(0, a − b) for angles a, b in [0, π] given by their cosines and sines.
inline void angle_minus(float cos_a, float sin_a, float cos_b, float sin_b, float& cos_out, float& sin_out) {
  if (cos_a >= cos_b) {  // a ≤ b
    cos_out = 1.0f;
    sin_out = 0.0f;
    return;
  }
  cos_out = cos_a * cos_b + sin_a * sin_b;
  sin_out = sin_a * cos_b - cos_a * sin_b;
}

/// A node's angles while building: θo (spread of the normals about the axis), θe (emission
/// beyond a normal), radians.
struct Cone {
  Vec3 axis{0.0f, 0.0f, 1.0f};
  float spread = 0.0f;
  float falloff = 0.0f;
};

Cone cone_of(const LightSampler::Node& n) {
  return {n.axis, std::acos(std::clamp(n.cos_spread, -1.0f, 1.0f)), std::acos(std::clamp(n.cos_falloff, -1.0f, 1.0f))};
}

/// The smallest cone (of this construction) holding the normals of both cones.
Cone merge(const Cone& a, const Cone& b) {
  Cone out;
  out.falloff = std::max(a.falloff, b.falloff);
  const float between = std::acos(std::clamp(glm::dot(a.axis, b.axis), -1.0f, 1.0f));
  if (between + b.spread <= a.spread) return {a.axis, a.spread, out.falloff};
  if (between + a.spread <= b.spread) return {b.axis, b.spread, out.falloff};
  const float spread = 0.5f * (a.spread + between + b.spread);
  const Vec3 across = b.axis - glm::dot(a.axis, b.axis) * a.axis;
  const float across_length = glm::length(across);
  if (spread >= kPi || !(across_length > 1e-7f)) return {a.axis, kPi, out.falloff};
  const float turn = spread - a.spread;  // rotate a's axis towards b's by this much
  out.axis = glm::normalize(std::cos(turn) * a.axis + std::sin(turn) * (across / across_length));
  out.spread = spread;
  return out;
}

/// Conty Estevez & Kulla's orientation measure: the integral over directions of the cosine-
/// weighted emission a cone of normals with spread θo and falloff θe can send.
double orientation_measure(const Cone& c) {
  const double o = c.spread, w = std::min(double(c.spread) + c.falloff, double(kPi));
  return 2.0 * kPi * (1.0 - std::cos(o)) +
         0.5 * kPi * (2.0 * w * std::sin(o) - std::cos(o - 2.0 * w) - 2.0 * o * std::sin(o) + std::cos(o));
}

double surface_area(const Vec3& lo, const Vec3& hi) {
  const Vec3 d = glm::max(hi - lo, Vec3(0.0f));
  return 2.0 * (double(d.x) * d.y + double(d.y) * d.z + double(d.z) * d.x);
}

/// The union of two nodes' lights (a may be empty: power 0 and inverted bounds).
LightSampler::Node merge(const LightSampler::Node& a, const LightSampler::Node& b) {
  if (!(a.power > 0.0f)) return b;
  LightSampler::Node out;
  out.lo = glm::min(a.lo, b.lo);
  out.hi = glm::max(a.hi, b.hi);
  const Cone c = merge(cone_of(a), cone_of(b));
  out.axis = c.axis;
  out.cos_spread = std::cos(c.spread);
  out.cos_falloff = std::cos(c.falloff);
  out.power = a.power + b.power;
  out.two_sided = a.two_sided || b.two_sided;
  return out;
}

/// The cost of a node in the split search: power × orientation measure × surface area.
double node_cost(const LightSampler::Node& n, double area_floor) {
  if (!(n.power > 0.0f)) return 0.0;
  return double(n.power) * orientation_measure(cone_of(n)) * std::max(surface_area(n.lo, n.hi), area_floor);
}

/// The bounds of one light, or a node of power 0 for a light the tree does not hold.
LightSampler::Node light_node(const Scene& scene, const Light& light, float power) {
  LightSampler::Node n;
  n.leaf = true;
  n.power = power;
  n.cos_falloff = 0.0f;  // area lights emit in a cosine lobe about the normal (θe = π/2)
  switch (light.kind) {
    case LightKind::area_triangle: {
      const TriangleMesh& mesh = scene.meshes[light.geom_id];
      const uint32_t* i = &mesh.indices[3 * size_t(light.prim_id)];
      const Vec3 p0 = mesh.positions[i[0]], p1 = mesh.positions[i[1]], p2 = mesh.positions[i[2]];
      n.lo = glm::min(p0, glm::min(p1, p2));
      n.hi = glm::max(p0, glm::max(p1, p2));
      const Vec3 normal = glm::cross(p1 - p0, p2 - p0);
      const float length = glm::length(normal);
      if (!(length > 0.0f)) return {};
      n.axis = normal / length;
      n.cos_spread = 1.0f;
      n.two_sided = scene.primitive_material(light.geom_id, light.prim_id).two_sided_emission;
      return n;
    }
    case LightKind::area_sphere: {
      const Sphere& s = scene.spheres[light.prim_id];
      n.lo = s.center - Vec3(s.radius);
      n.hi = s.center + Vec3(s.radius);
      n.cos_spread = -1.0f;
      return n;
    }
    case LightKind::point:
      n.lo = n.hi = light.position;
      n.cos_spread = -1.0f;
      return n;
    case LightKind::spot:
      n.lo = n.hi = light.position;
      n.axis = light.direction;
      n.cos_spread = light.cos_outer;
      n.cos_falloff = 1.0f;  // nothing beyond the outer cone
      // Weighted by intensity as a point light is, not by the power a narrow cone holds: the
      // importance estimates the light arriving inside the cone.
      n.power = 4.0f * kPi * light.intensity.average();
      return n;
    case LightKind::directional:
    case LightKind::environment: break;
  }
  return {};
}

/// Fills in what importance() reads besides the bounds: the box's centre and bounding radius.
void finish(LightSampler::Node& n) {
  n.centre = 0.5f * (n.lo + n.hi);
  const Vec3 half = 0.5f * (n.hi - n.lo);
  n.radius2 = glm::dot(half, half);
  n.sin_spread = safe_sqrt(1.0f - n.cos_spread * n.cos_spread);
}

/// Squared sine of the angle a cluster's bounding sphere may subtend, and cosine of its normals'
/// spread, within which distant_cluster chooses among its lights by power. Within 11.5°, the
/// distance factor of two lights of equal power differs by 2.25 at most; the importance is an
/// estimate that ignores visibility and the BSDF anyway. On bench/README's many-emitter room,
/// relMSE × spp stayed within 2 % from 2.9° (sin² 0.0025) to 11.5° while samples per second rose by
/// a quarter.
constexpr float kClusterSin2 = 0.04f;  // 11.5°
constexpr float kClusterCosSpread = 0.995f;  // 5.7°

}  // namespace

LightSampling parse_light_sampling(const std::string& name) {
  if (name == "bvh") return LightSampling::bvh;
  if (name == "power") return LightSampling::power;
  throw InputError("light sampler \"" + name + "\": expected bvh or power");
}

const char* light_sampling_name(LightSampling mode) { return mode == LightSampling::bvh ? "bvh" : "power"; }

bool LightSampler::distant_cluster(const Node& node, const LightQuery& query) {
  if (node.cos_spread < kClusterCosSpread) return false;
  const Vec3 d = query.p - node.centre;
  return node.radius2 < kClusterSin2 * glm::dot(d, d);
}

float LightSampler::importance(const Node& node, const LightQuery& query) {
  const Vec3 d = query.p - node.centre;
  const float d2 = glm::dot(d, d);
  const float r2 = node.radius2;
  // The bounding sphere of the box, seen from the query: every light point's direction lies
  // within θb of the centre's. Inside it, any direction (θb = π).
  float cos_b = -1.0f, sin_b = 0.0f;
  if (d2 > r2) {
    const float sin2 = r2 / d2;
    sin_b = std::sqrt(sin2);
    cos_b = safe_sqrt(1.0f - sin2);
  }
  const Vec3 wi = d2 > 0.0f ? d / std::sqrt(d2) : Vec3(0.0f, 0.0f, 1.0f);  // from the lights to the query

  // Emission: the angle θ' between the nearest normal and the nearest light point's direction
  // towards the query, θ' = max(0, θw − θo − θb); nothing reaches past θo + θe.
  float cos_w = glm::dot(node.axis, wi);
  if (node.two_sided) cos_w = std::fabs(cos_w);
  const float sin_w = safe_sqrt(1.0f - cos_w * cos_w);
  float cos_x, sin_x, cos_p, sin_p;
  angle_minus(cos_w, sin_w, node.cos_spread, node.sin_spread, cos_x, sin_x);
  angle_minus(cos_x, sin_x, cos_b, sin_b, cos_p, sin_p);
  if (cos_p < node.cos_falloff - kGrazing) return 0.0f;
  float value = node.power * std::max(cos_p, kGrazing) / std::max(std::max(d2, r2), 1e-30f);

  // Reception: the query's surface sees the nearest light point at θi' = max(0, θi − θb).
  if (query.n != Vec3(0.0f)) {
    float cos_i = -glm::dot(query.n, wi);
    if (query.two_sided) cos_i = std::fabs(cos_i);
    const float sin_i = safe_sqrt(1.0f - cos_i * cos_i);
    float cos_ip, sin_ip;
    angle_minus(cos_i, sin_i, cos_b, sin_b, cos_ip, sin_ip);
    if (cos_ip < -kGrazing) return 0.0f;
    value *= std::max(cos_ip, kGrazing);
  }
  return std::isfinite(value) ? value : 3e38f;
}

LightSampler::LightSampler(const Scene& scene, std::span<const Light> lights, std::span<const float> power)
    : power_(power) {
  trail_.assign(lights.size(), 0);
  trail_depth_.assign(lights.size(), -1);
  leaf_of_light_.assign(lights.size(), 0);
  std::vector<Node> leaves(lights.size());
  std::vector<uint32_t> order;
  std::vector<float> distant_power;
  double tree_power = 0.0, all_power = 0.0;
  for (uint32_t i = 0; i < lights.size(); ++i) {
    const float p = power_.size() > 0 ? power_.pmf(i) : 0.0f;
    if (!(p > 0.0f)) continue;
    all_power += p;
    if (lights[i].kind == LightKind::directional || lights[i].kind == LightKind::environment) {
      trail_depth_[i] = -2;
      trail_[i] = distant_index_.size();
      distant_index_.push_back(i);
      distant_power.push_back(p);
      continue;
    }
    leaves[i] = light_node(scene, lights[i], power[i]);
    if (!(leaves[i].power > 0.0f)) continue;
    tree_power += p;
    order.push_back(i);
  }
  distant_ = util::Distribution1D(distant_power);
  tree_share_ = all_power > 0.0 ? float(tree_power / all_power) : 0.0f;
  if (distant_.size() == 0) tree_share_ = order.empty() ? 0.0f : 1.0f;
  if (!order.empty()) {
    nodes_.reserve(2 * order.size());
    prefix_.reserve(order.size() + 1);
    prefix_.push_back(0.0);
    leaf_light_.reserve(order.size());
    build(order, leaves, 0, order.size(), 0, 0);
  }
}

int LightSampler::build(std::vector<uint32_t>& order, std::vector<Node>& leaves, size_t begin, size_t end, int depth,
                        uint64_t trail) {
  const size_t at = nodes_.size();
  depth_ = std::max(depth_, depth);
  if (end - begin == 1) {
    const uint32_t light = order[begin];
    nodes_.push_back(leaves[light]);
    Node& leaf = nodes_[at];
    finish(leaf);
    leaf.index = light;
    leaf.first = uint32_t(leaf_light_.size());
    leaf.last = leaf.first + 1;
    prefix_.push_back(prefix_.back() + double(leaf.power));
    leaf_light_.push_back(light);
    trail_[light] = trail;
    trail_depth_[light] = int8_t(depth);
    leaf_of_light_[light] = leaf.first;
    return int(at);
  }
  Node all;
  Vec3 lo(kInfinity), hi(-kInfinity);  // bounds of the lights' box centres
  for (size_t k = begin; k < end; ++k) {
    const Node& n = leaves[order[k]];
    all = merge(all, n);
    lo = glm::min(lo, 0.5f * (n.lo + n.hi));
    hi = glm::max(hi, 0.5f * (n.lo + n.hi));
  }
  finish(all);
  all.leaf = false;
  nodes_.push_back(all);

  const Vec3 extent = hi - lo;
  const auto centre = [&](uint32_t light, int axis) { return 0.5f * (leaves[light].lo[axis] + leaves[light].hi[axis]); };
  // The bin of a light's centre along an axis, for both the search and the partition.
  const auto bin_of = [&](uint32_t light, int axis) {
    return std::clamp(int(kBins * (centre(light, axis) - lo[axis]) / extent[axis]), 0, kBins - 1);
  };
  size_t middle = begin;
  if (depth < kCostDepth) {
    // Binned search over the three axes for the split of least power × orientation × area,
    // regularised against thin slabs by the box's longest side over the split axis's.
    const Vec3 box = all.hi - all.lo;
    const float longest = std::max(box.x, std::max(box.y, box.z));
    const double floor = 1e-3 * surface_area(all.lo, all.hi);
    double best = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_bin = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(extent[axis] > 0.0f)) continue;
      std::array<Node, kBins> bins{};
      for (size_t k = begin; k < end; ++k) {
        Node& bin = bins[bin_of(order[k], axis)];
        bin = merge(bin, leaves[order[k]]);
      }
      std::array<double, kBins> below{};
      Node acc;
      for (int b = 0; b < kBins - 1; ++b) {
        acc = merge(acc, bins[b]);
        below[b] = node_cost(acc, floor);
      }
      acc = Node{};
      const double regular = box[axis] > 0.0f ? double(longest) / box[axis] : 1.0;
      for (int b = kBins - 1; b > 0; --b) {
        acc = merge(acc, bins[b]);
        const double cost = regular * (below[b - 1] + node_cost(acc, floor));
        if (cost < best) {
          best = cost;
          best_axis = axis;
          best_bin = b;
        }
      }
    }
    if (best_axis >= 0) {
      const int axis = best_axis;
      middle = size_t(std::partition(order.begin() + begin, order.begin() + end,
                                     [&](uint32_t light) { return bin_of(light, axis) < best_bin; }) -
                      order.begin());
    }
  }
  if (middle == begin || middle == end) {
    // No cost split (all centres alike, or too deep): halves along the longest extent.
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    middle = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end, [&](uint32_t a, uint32_t b) {
      const float ca = centre(a, axis), cb = centre(b, axis);
      return ca < cb || (ca == cb && a < b);
    });
  }
  build(order, leaves, begin, middle, depth + 1, trail);
  const int second = build(order, leaves, middle, end, depth + 1, trail | (uint64_t(1) << depth));
  nodes_[at].index = uint32_t(second);
  nodes_[at].first = nodes_[at + 1].first;
  nodes_[at].last = nodes_[second].last;
  return int(at);
}

float LightSampler::cluster_pmf(const Node& cluster, uint32_t leaf) const {
  return float((prefix_[leaf + 1] - prefix_[leaf]) / (prefix_[cluster.last] - prefix_[cluster.first]));
}

LightChoice LightSampler::sample(const LightQuery& query, float u) const {
  if (power_.size() == 0) return {};
  if (mode_ == LightSampling::power) {
    const uint32_t i = power_.sample(u);
    return {i, power_.pmf(i)};
  }
  if (!(u < tree_share_)) {
    const float v = std::min((u - tree_share_) / (1.0f - tree_share_), 0x1.fffffep-1f);
    const uint32_t j = distant_.sample(v);
    return {distant_index_[j], (1.0f - tree_share_) * distant_.pmf(j)};
  }
  // Descend with u fixed and the interval of [0, 1) that the node holds narrowing around it.
  const double v = double(u) / double(tree_share_);
  double lo = 0.0, width = 1.0;
  float pmf = tree_share_;
  uint32_t at = 0;
  while (!nodes_[at].leaf) {
    const Node& n = nodes_[at];
    if (distant_cluster(n, query)) {
      // Among the cluster's leaves by power: the leaf whose share of the cluster's summed power
      // holds v. The last leaf takes any target at or past the second-to-last's end.
      const double target = prefix_[n.first] + std::clamp((v - lo) / width, 0.0, 1.0) * (prefix_[n.last] - prefix_[n.first]);
      const auto found = std::upper_bound(prefix_.begin() + n.first + 1, prefix_.begin() + n.last, target);
      const uint32_t leaf = uint32_t(found - prefix_.begin()) - 1;
      return {leaf_light_[leaf], pmf * cluster_pmf(n, leaf)};
    }
    const float first = importance(nodes_[at + 1], query), second = importance(nodes_[n.index], query);
    if (!(first + second > 0.0f)) return {};
    const float p_first = first / (first + second);
    const double split = lo + width * double(p_first);
    if (v < split || p_first == 1.0f) {
      width *= double(p_first);
      pmf *= p_first;
      ++at;
    } else {
      lo = split;
      width *= 1.0 - double(p_first);
      pmf *= 1.0f - p_first;
      at = n.index;
    }
  }
  if (at == 0 && !(importance(nodes_[0], query) > 0.0f)) return {};
  return {nodes_[at].index, pmf};
}

float LightSampler::pmf(const LightQuery& query, uint32_t light) const {
  if (light >= trail_depth_.size() || power_.size() == 0) return 0.0f;
  if (mode_ == LightSampling::power) return power_.pmf(light);
  const int depth = trail_depth_[light];
  if (depth == -2) return (1.0f - tree_share_) * distant_.pmf(uint32_t(trail_[light]));
  if (depth < 0) return 0.0f;
  float pmf = tree_share_;
  uint32_t at = 0;
  for (int level = 0; level < depth; ++level) {
    if (distant_cluster(nodes_[at], query)) return pmf * cluster_pmf(nodes_[at], leaf_of_light_[light]);
    const float first = importance(nodes_[at + 1], query), second = importance(nodes_[nodes_[at].index], query);
    if (!(first + second > 0.0f)) return 0.0f;
    const float p_first = first / (first + second);
    if ((trail_[light] >> level) & 1u) {
      pmf *= 1.0f - p_first;
      at = nodes_[at].index;
    } else {
      pmf *= p_first;
      ++at;
    }
  }
  if (at == 0 && !(importance(nodes_[0], query) > 0.0f)) return 0.0f;
  return pmf;
}

}  // namespace gilt::raytrace_core::scene

#pragma once
// Private to the hierarchical solver: gathering light at receivers from the tree. PackedSources
// is what a gather over the links reads of each source node; Gathered what a receiving node
// collects, and irradiance_at how an element below it reads that. TreeWalk gathers at a vertex
// by walking down the tree (the final gather, and emitted_irradiance). Reads the tree, the
// nodes' sums (pull) and the scene's visibility; writes the irradiance it returns and its counts.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "radiosity/solver/cluster_tree.h"
#include "radiosity/solver/hierarchical.h"
#include "raytrace_core/util/rng.h"

namespace gilt::radiosity::solver::detail {

/// What the links read of a source node in one gather, packed for them: its centre and area, its
/// power, and its non-empty normal bins (bins[first .. next node's first) of a shared pool). A
/// gather reads one of these per link, in the order of the links' sources, so it is the links'
/// memory traffic: 32 bytes and a bin or two (most nodes are flat) against the 132-byte node
/// and six 36-byte bins. The bins kept are the non-zero ones in bin order, and a zero bin adds
/// exactly nothing to intensity(), so the sums are the same to the bit.
struct PackedSources {
  struct Source {
    Vec3 center;
    uint32_t first;
    Rgb power;
    float area;
  };
  std::vector<Source> nodes;  ///< one per tree node, and one more closing the last node's bins
  std::vector<RgbVec> bins;

  void pack(const Tree& tree, std::span<const Rgb> power, std::span<const Moments> moment);

  /// intensity() of node s towards ω.
  Rgb intensity(uint32_t s, const Vec3& omega) const {
    return detail::intensity(std::span(bins).subspan(nodes[s].first, nodes[s + 1].first - nodes[s].first),
                             omega);
  }
};

/// What a node has gathered: the irradiance vector of flat receivers, and for curved ones, per
/// bin of the links' directions w, the irradiance vector W_b = Σ J w and the sum S_b = Σ J over
/// the links whose w falls in the bin.
struct Gathered {
  RgbVec flat;
  RgbVec bins[kDirectionBins];
  Rgb sums[kDirectionBins];
};

/// An element of normal n under a curved receiver takes S_b E[max(0, n·w)] from each bin b, the
/// expectation over the bin's directions read from their mean x = n·W_b / S_b and their spread
/// s = √(1 − κ²), κ = |W_b| / S_b: the ramp max(0, x) smoothed over [−s, s] by (x + s)² / 4s.
/// Exact for one link (s = 0: max(0, J n·w)) and for directions spread evenly over the sphere
/// (x = 0, s = 1: ¼ S_b); for an even hemisphere it gives 0.54, 0.22 and 0.04 for normals along,
/// across and against it, where the answer is 0.5, 0.25 and 0. The two-band model it replaces,
/// max(0, ¼ Σ J + ½ n·Σ J w), gave an element turned 90° from a lone source a quarter of its
/// light, and one facing it three quarters: it moved light from the elements of a carved or curved
/// cluster that face a bright source to those that do not (HierarchicalRadiosity.
/// ABallsFacesTakeTheLightOfTheirOwnSide).
inline Rgb irradiance_at(const Gathered& g, const Vec3& n) {
  Rgb out = g.flat.dot(n);
  for (int k = 0; k < 3; ++k) out[k] = std::max(0.0f, out[k]);
  for (int i = 0; i < kDirectionBins; ++i) {
    const Rgb b = g.bins[i].dot(n);
    for (int k = 0; k < 3; ++k) {
      const float sum = g.sums[i][k];
      if (!(sum > 0.0f)) continue;
      const float kappa = std::min(1.0f, glm::length(g.bins[i].c[k]) / sum);
      const float x = b[k] / sum, spread = std::sqrt(std::max(0.0f, 1.0f - kappa * kappa));
      const float phi =
          x >= spread ? x : (x <= -spread ? 0.0f : (x + spread) * (x + spread) / (4.0f * spread));
      out[k] += sum * phi;
    }
  }
  return out;
}

struct WalkCounts {
  uint64_t rays = 0, nodes = 0, form_factors = 0;
};

/// Irradiance at a vertex from every element's radiosity, by a walk down the tree: a cluster is
/// taken whole, as a point source seen through `rays` shadow rays, when the irradiance it may carry
/// wrongly (F̂ B times the point-source error (r/d)², or all of it where its elements face both
/// ways) is below `epsilon`; an element by Lambert's formula. With more than one ray, a probe of
/// min(rays, 4) that finds the node partly hidden is extended to `rays` (read by extended_fraction).
struct TreeWalk {
  const HierarchicalInput& in;
  const Tree& tree;
  std::span<const Rgb> radiosity;  ///< per element
  const std::vector<Rgb>& power;
  const std::vector<Moments>& moment;

  Rgb irradiance(size_t v, double epsilon, int rays, rc::util::Rng& rng, std::vector<uint32_t>& stack,
                 WalkCounts& counts) const;
};

}  // namespace gilt::radiosity::solver::detail

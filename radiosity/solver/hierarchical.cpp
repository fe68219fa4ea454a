// Hierarchical radiosity with clustering: Hanrahan, Salzman & Aupperle 1991, "A Rapid
// Hierarchical Radiosity Algorithm"; clusters: Smits, Arvo & Greenberg 1994, "A Clustering
// Algorithm for Radiosity in Complex Environments", and Sillion 1995, "A Unified Hierarchical
// Algorithm for Global Illumination with Scattering Volumes and Object Clusters"; final gather:
// Lischinski, Tampieri & Greenberg 1993, "Combining Hierarchical Radiosity and Discontinuity
// Meshing".
//
// The hierarchy is a binary tree over the elements (median splits of their centroids), so a
// cluster is a compact piece of one surface near the leaves and a group of objects near the
// root. Linking starts from the root paired with itself and splits the larger end of a pair
// until the oracle accepts it: the power the link may carry wrongly, ρ_R A_R F̂ B_S times the
// point-source error ((r_R + r_S)/d)², where F̂ = A_S / (π d²) bounds the form factor from R to S
// at a gap d, must stay below link_tolerance × the scene's reflected power (and, where
// HierarchicalSettings::receiver_share is set, below link_tolerance × R's own reflected power
// / receiver_share). A pair of elements
// that the oracle never accepts gets an exact link: Lambert's point-to-triangle factor at the
// receiver's centroid. Pairs that provably exchange nothing (each end behind the other's
// surfaces, coplanar pieces of one wall) are dropped before any test.
//
// Clusters emit and receive through two models. A flat cluster (every element within about 20°
// of its mean normal) sends I(ω) = ω·Σ B_k A_k n_k / π, exact for a plane, and receives the
// irradiance vector W = Σ J w (J the irradiance facing the source, w towards it), so that an
// element below it with normal n gets n·W: exact when every source is in front of it. A
// curved or scattered cluster sends by bins of its elements' normals (intensity, in
// cluster_tree.h) and receives by bins of the links' directions (irradiance_at, in tree_walk.h);
// the oracle's error factor is then 1, so such links are accepted only where little light travels.
//
// The parts of the method live beside this file, in namespace detail: the tree and the cluster
// models (cluster_tree.h), the links and the Linker that makes them (linker.h), gathering from the
// tree (tree_walk.h) and the cut of the tree among processes (process_cut.h). This file holds the
// solve that drives them (HierarchicalSolve: the ladder of link tolerances, the iteration and the
// final gather) and the entry points of hierarchical.h.

#include "radiosity/solver/hierarchical.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

#include <oneapi/tbb/parallel_sort.h>

#include "radiosity/solver/cluster_tree.h"
#include "radiosity/solver/ladder_forecast.h"
#include "radiosity/solver/linker.h"
#include "radiosity/solver/process_cut.h"
#include "radiosity/solver/tree_walk.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"
#include "raytrace_core/util/progress.h"
#include "raytrace_core/util/rng.h"

namespace gilt::radiosity::solver {

using mesh::RadiosityMesh;
namespace {

using namespace detail;

/// The most an element may reflect of what a unit radiosity everywhere sends it (see the
/// iteration in solve_hierarchical).
constexpr float kMaxReflectedGain = 0.99f;
/// The iteration stops when its area-weighted mean relative change per element falls below the
/// tolerance; an element darker than this fraction of the scene's mean radiosity counts its
/// change against that mean instead, so that black corners do not set the pace.
constexpr double kResidualFloor = 0.01;
/// Chebyshev's iteration (see solve_hierarchical) reads its bound β on the spectrum from at most
/// this many Jacobi steps, and holds it within [least, most].
constexpr int kChebyshevWarmUp = 6;
constexpr double kChebyshevLeast = 0.2, kChebyshevMost = 0.99;
/// It reads β again when the residual falls this much (relatively) slower than β allows.
constexpr double kChebyshevSlack = 0.05;
/// A timed solve iterates its ladder's levels above the last to this many times the tolerance.
constexpr double kLadderLoosening = 10.0;
/// A timed solve foretells a level by refining every this-many-th of the pairs it refines.
constexpr size_t kTrialStride = 50;
/// The final gather's probe takes every this-many-th vertex.
constexpr uint32_t kGatherProbeStride = 61;
/// `auto` skips the final gather when it would trace more than this many times the links' rays.
constexpr double kGatherRayShare = 4.0;

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// The iteration's state over one level's links: a level iterated loosely and then to the
/// tolerance goes on as one iteration.
struct IterationState {
  int steps = 0;
  std::array<double, 3> step{}, last_step{}, ratio{}, last_ratio{};
  // Chebyshev's state: omega = 0 while the steps are plain Jacobi; 1 after the plain step that
  // is its x_1 = J(x_0); ω_k after that. A restart makes the next step plain again.
  double omega = 0.0, last_residual = 0.0;
  int chebyshev_steps = 0;
  bool plain_next = false;
  double first_residual = 0.0;  // the residual after the first gather on these links
};

/// One level of the ladder of link tolerances as it is to be linked: its tolerance, whether it
/// is the ladder's last, the time its linking keeps back for the last level's iteration, and the
/// pairs it splits (summed over processes).
struct LevelPlan {
  double tolerance = 0.0;
  bool last = false;
  double reserve = 0.0;
  size_t splits = 1;
  /// A first level foretold by a trial (`expanded`): the pairs the trial's expansion left open,
  /// to link from instead of the open pairs, and the links that expansion made on the way.
  bool expanded = false;
  std::vector<OpenPair> start;
  LinkLevel head;
};

/// The state of one hierarchical solve, which solve_hierarchical's passes read and write in turn.
struct HierarchicalSolve {
  HierarchicalSolve(const HierarchicalInput& input, const HierarchicalSettings& s, HierarchicalResult& r)
      : in(input), settings(s), result(r), mesh(input.mesh), ne(mesh.element_count()), nv(mesh.vertex_count()) {}

  const HierarchicalInput& in;
  const HierarchicalSettings& settings;
  HierarchicalResult& result;
  const RadiosityMesh& mesh;
  const size_t ne, nv;
  // Under several processes rank 0's clock decides for all, so that they stay in step.
  const rc::util::Processes& group = rc::util::processes();
  Counters counters;
  std::chrono::steady_clock::time_point last_lap = std::chrono::steady_clock::now();

  Tree tree;
  SubtreeCut cut;
  // Direct irradiance per element (mean of its vertices) and the reflected radiosity; the
  // first bounce's power, the area and the albedo summed by area.
  std::vector<Rgb> direct, radiosity;
  double reflected = 0.0, area = 0.0, albedo = 0.0;
  // The oracle's estimate of each node's reflected power.
  std::vector<float> power_estimate;
  std::vector<Vec3> moment_estimate;
  double total_estimate = 0.0;
  // The ladder of link tolerances, and the links, grouped by receiver for gathering.
  double link_tolerance = 0.0;
  bool timed = false;
  std::vector<double> ladder;
  std::vector<Link> links, exact_links;
  std::vector<OpenPair> open_pairs;
  std::vector<uint32_t> receivers, first_link;
  // One gathering step: pull B up the tree, gather over the links, push the gathered irradiance
  // down to the elements.
  std::vector<Rgb> power, indirect;
  std::vector<Moments> moment;
  PackedSources packed;
  std::vector<Gathered> gathered;
  std::vector<float> gain;  // see bound_gains
  // The iteration (see iterate).
  std::vector<Rgb> next, last_indirect, older_indirect;
  double beta = 0.0;  // Chebyshev's bound on the spectrum, once read
  IterationState state;
  bool finished = true;  // whether the present links' iteration reached the tolerance
  // A timed solve's costs per link, as last measured (the constants until a level measures them).
  double merge_per_link = kMergeSecondsPerLink, gather_per_link = kGatherSecondsPerLink;
  double last_gather_seconds = 0.0;  // the last gather's, to stop before one would end past the limit
  // The final gather.
  double mean_indirect = 0.0;
  std::vector<Rgb> gathered_at;

  bool out_of_time() const { return group.broadcast_value(in.out_of_time && in.out_of_time()); }

  /// Seconds since the last call (the first: since the solve began).
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_lap).count();
    last_lap = now;
    return seconds;
  }

  /// Reads the mesh and the albedo; writes the tree, its cut and result.nodes.
  void build_tree() {
    tree = make_tree(mesh, in.albedo);
    result.nodes = tree.nodes.size();
    if (tree.nodes.size() >= Link::kExactBit) throw std::length_error("hierarchical radiosity: more than 2^31 tree nodes");
    // Under several processes the tree is cut into subtrees of at most 1/256 of its nodes (a
    // node's subtree is the range of nodes that follows it), dealt out round-robin. Each process
    // links and gathers at the receivers in its subtrees, and all of them at the few hundred nodes
    // above the cut; it pushes down into its own subtrees, and the elements' irradiance is joined,
    // 12 bytes an element per gather. Every value is summed in one process's order.
    cut = group.count() > 1 ? cut_tree(tree, group.count()) : SubtreeCut{};
  }

  /// Reads the direct irradiance (per element, else per vertex) and the albedo; writes `direct`,
  /// the first reflected `radiosity`, and `reflected`, `area` and `albedo`. False when nothing is
  /// reflected.
  bool first_bounce() {
    direct.resize(ne), radiosity.resize(ne);
    for (size_t e = 0; e < ne; ++e) {
      const auto& el = mesh.elements[e];
      direct[e] = in.element_direct.empty() ? (in.direct_irradiance[el[0]] + in.direct_irradiance[el[1]] +
                                               in.direct_irradiance[el[2]]) * (1.0f / 3.0f)
                                            : in.element_direct[e];
      radiosity[e] = in.albedo[e] * direct[e];
      reflected += double(radiosity[e].average()) * mesh.element_area[e];
      area += mesh.element_area[e];
      albedo += double(in.albedo[e].average()) * mesh.element_area[e];
    }
    return reflected > 0.0;
  }

  /// The oracle's estimate of each element's reflected radiosity: the first bounce plus the
  /// later ones spread evenly, (mean first-bounce radiosity) / (1 − ρ̄) as irradiance. Reads
  /// `direct`, `reflected`, `area`, `albedo`; writes power_estimate, moment_estimate and
  /// total_estimate, per node.
  void estimate_power() {
    const double mean_albedo = std::min(0.95, albedo / area);
    const float ambient = float(reflected / area / (1.0 - mean_albedo));
    power_estimate.assign(tree.nodes.size(), 0.0f);
    moment_estimate.assign(tree.nodes.size(), Vec3(0.0f));
    for (size_t i = tree.nodes.size(); i-- > 0;) {
      const Node& node = tree.nodes[i];
      if (node.leaf()) {
        const uint32_t e = tree.element(node);
        power_estimate[i] = (in.albedo[e] * (direct[e] + Rgb(ambient))).average() * mesh.element_area[e];
        moment_estimate[i] = power_estimate[i] * mesh.element_normal[e];
        total_estimate += power_estimate[i];
      } else {
        power_estimate[i] = power_estimate[i + 1] + power_estimate[node.right];
        moment_estimate[i] = moment_estimate[i + 1] + moment_estimate[node.right];
      }
    }
  }

  /// Links, grouped by receiver for gathering. Without a time limit they are made once, at the
  /// requested tolerance. With one, a ladder of tolerances from 1,000 times coarser runs down to
  /// it, each level's iteration started from the last level's solution (below: while time is
  /// left): a coarse solution in time beats a fine one cut off before it iterates. Each level
  /// refines the pairs the last one accepted rather than linking again from the root: the split
  /// decisions above them would be the same, and their visible fractions are kept, so the ladder
  /// makes the same links as linking once at its last tolerance. It spends more doing so, on the
  /// rays of pairs a later level splits and on the upper levels' iterations: on Šibenik's nave
  /// the four levels to 2e-5 took 57 s where one link at 2e-5 took 44 s.
  ///
  /// Reads the settings and whether the solve is timed; writes the ladder, the root pair to open
  /// and the gathering's and iteration's arrays.
  void plan_ladder() {
    link_tolerance = settings.link_tolerance > 0.0 ? settings.link_tolerance : kDefaultLinkTolerance;
    timed = bool(in.seconds_left);
    if (timed)
      for (double t = link_tolerance * 1000.0; t > link_tolerance * 1.5; t /= 10.0) ladder.push_back(t);
    ladder.push_back(link_tolerance);
    open_pairs.push_back(OpenPair{0, 0, -1.0f});
    indirect.assign(ne, Rgb(0.0f));
    gathered.resize(tree.nodes.size());
    gain.assign(ne, 1.0f);
    next.resize(ne), last_indirect.resize(ne), older_indirect.resize(ne);
  }

  /// Gathers at the receivers [lo, hi) over their links: reads the links and `packed`, adds to
  /// `gathered`.
  void gather_receivers(size_t lo, size_t hi) {
    for (size_t g = lo; g < hi; ++g) {
      const Node& R = tree.nodes[receivers[g]];
      Gathered& acc = gathered[receivers[g]];
      const Vec3 exact_dir = R.leaf() ? mesh.element_normal[tree.element(R)] : Vec3(0.0f);
      for (uint32_t l = first_link[g]; l < first_link[g + 1]; ++l) {
        const Link& link = links[l];
        const uint32_t source = link.source();
        const PackedSources::Source& S = packed.nodes[source];
        Vec3 dir = exact_dir;
        if (!link.exact()) {
          const Vec3 d = S.center - R.center;
          dir = d / std::sqrt(glm::dot(d, d));
        }
        const Rgb j = link.exact() ? S.power * (link.factor / S.area) : packed.intensity(source, -dir) * link.factor;
        const Facing side = facing(R, dir);
        if (side == Facing::front) {
          acc.flat.add(j, dir);
        } else if (side == Facing::mixed) {
          const int bin = direction_bin(dir);
          acc.bins[bin].add(j, dir);
          acc.sums[bin] += j;
        }
      }
    }
  }

  /// Under several processes: gathers at the receivers above the cut (every process) and at
  /// those in this process's subtrees, into `gathered`.
  void gather_by_subtree() {
    // Receivers are sorted by node: a subtree's are a range of them.
    auto first_at = [&](uint32_t node) {
      return size_t(std::lower_bound(receivers.begin(), receivers.end(), node) - receivers.begin());
    };
    const std::vector<Subtree>& parts = cut.subtrees;
    std::vector<size_t> above;  // receivers above the cut
    for (size_t c = 0, g = 0; c <= parts.size(); ++c) {
      const size_t to = c < parts.size() ? first_at(parts[c].root) : receivers.size();
      for (; g < to; ++g) above.push_back(g);
      if (c < parts.size()) g = first_at(parts[c].end);
    }
    rc::util::parallel_for((above.size() + 63) / 64, [&](size_t chunk) {
      for (size_t i = chunk * 64; i < std::min(above.size(), chunk * 64 + 64); ++i) gather_receivers(above[i], above[i] + 1);
    });
    rc::util::parallel_for_owned(parts.size(), [&](size_t c) { gather_receivers(first_at(parts[c].root), first_at(parts[c].end)); });
  }

  Rgb leaf_irradiance(size_t i) const {
    return irradiance_at(gathered[i], mesh.element_normal[tree.element(tree.nodes[i])]);
  }

  /// One gathering step: pulls the element radiosities `from` up the tree (power, moment,
  /// packed), gathers over the links into `gathered`, pushes that down to the leaves and writes
  /// each element's irradiance to `out`.
  void gather(std::span<const Rgb> from, std::vector<Rgb>& out) {
    pull(tree, mesh, from, power, moment);
    packed.pack(tree, power, moment);
    std::fill(gathered.begin(), gathered.end(), Gathered{});
    if (group.count() == 1) {
      rc::util::parallel_for((receivers.size() + 63) / 64, [&](size_t chunk) {
        gather_receivers(chunk * 64, std::min(receivers.size(), chunk * 64 + 64));
      });
    } else {
      gather_by_subtree();
    }
    for (size_t i = 0; i < tree.nodes.size(); ++i) {
      const Node& node = tree.nodes[i];
      if (node.leaf()) continue;
      for (size_t c : {i + 1, size_t(node.right)}) {
        gathered[c].flat.add(gathered[i].flat);
        for (int b = 0; b < kDirectionBins; ++b) gathered[c].bins[b].add(gathered[i].bins[b]), gathered[c].sums[b] += gathered[i].sums[b];
      }
    }
    if (group.count() == 1) {
      for (size_t i = 0; i < tree.nodes.size(); ++i)
        if (tree.nodes[i].leaf()) out[tree.element(tree.nodes[i])] = leaf_irradiance(i);
      return;
    }
    const std::vector<Subtree>& parts = cut.subtrees;
    std::vector<std::vector<Rgb>> values(parts.size());
    rc::util::parallel_for_owned(parts.size(), [&](size_t c) {
      for (uint32_t i = parts[c].root; i < parts[c].end; ++i)
        if (tree.nodes[i].leaf()) values[c].push_back(leaf_irradiance(i));
    });
    rc::util::join_chunks(values);
    for (size_t c = 0; c < parts.size(); ++c) {
      size_t k = 0;
      for (uint32_t i = parts[c].root; i < parts[c].end; ++i)
        if (tree.nodes[i].leaf()) out[tree.element(tree.nodes[i])] = values[c][k++];
    }
  }

  /// Under a unit radiosity everywhere an element gathers at most 1 (a closed room's white
  /// furnace); the links' estimate scatters about that, by their visibility noise. Where they
  /// promise so much more that the element would reflect more than it gathers (ρ·c ≥ 1: surfaces
  /// a hair apart whose point-to-element factors overlap, clusters packed with area), the Jacobi
  /// iteration would grow without bound: a room of overlapping boxes lying 10⁻³ above the floor
  /// reached 10³³. Such an element's gathering is scaled so that ρ·c = 0.99, which bounds every
  /// row of the iteration below 1 and makes it a contraction; elsewhere nothing changes.
  ///
  /// Reads the links; writes `gain` and result.clamped_elements.
  void bound_gains() {
    std::fill(gain.begin(), gain.end(), 1.0f);
    result.clamped_elements = 0;
    std::vector<Rgb> unit(ne, Rgb(1.0f)), capacity(ne);
    gather(unit, capacity);
    for (size_t e = 0; e < ne; ++e) {
      const float reflects = in.albedo[e].max_component() * capacity[e].max_component();
      if (reflects > kMaxReflectedGain) gain[e] = kMaxReflectedGain / reflects, ++result.clamped_elements;
    }
    if (settings.keep_closure) {
      result.element_closure.resize(ne);
      for (size_t e = 0; e < ne; ++e) result.element_closure[e] = capacity[e].average();
    }
  }

  /// One step of the iteration (see iterate): gathers from `radiosity` into `indirect`, reflects
  /// into `next` (Chebyshev's extrapolation where it runs) and measures the residual. Reads and
  /// writes the iterates, `state`, result.residual and result.iterations; true for Chebyshev's step.
  bool iteration_step() {
    older_indirect.swap(last_indirect);  // x_{k−1}'s
    last_indirect.swap(indirect);        // x_k's
    gather(radiosity, indirect);
    double total = 0.0;
    state.last_step = state.step, state.last_ratio = state.ratio, state.step = {};
    for (size_t e = 0; e < ne; ++e) {
      indirect[e] *= gain[e];
      next[e] = in.albedo[e] * (direct[e] + indirect[e]);
      total += double(next[e].average()) * mesh.element_area[e];
    }
    const double floor = kResidualFloor * total / area;
    double change = 0.0;
    for (size_t e = 0; e < ne; ++e) {
      const Rgb delta = next[e] - radiosity[e];
      change += (std::fabs(delta.r) + std::fabs(delta.g) + std::fabs(delta.b)) / 3.0 * mesh.element_area[e] /
                std::max(double(next[e].average()), floor);
      for (int k = 0; k < 3; ++k) state.step[size_t(k)] += double(delta[k]) * mesh.element_area[e];
    }
    for (size_t k = 0; k < 3; ++k) state.ratio[k] = state.last_step[k] > 0.0 ? state.step[k] / state.last_step[k] : 0.0;
    state.last_residual = result.residual;
    result.residual = total > 0.0 ? change / area : 0.0;
    ++result.iterations, ++state.steps;
    if (state.steps == 1) state.first_residual = result.residual;
    const bool chebyshev = state.omega >= 1.0 && !state.plain_next;
    if (chebyshev) {
      const double omega = state.omega == 1.0 ? 1.0 / (1.0 - 0.5 * beta * beta)
                                              : 1.0 / (1.0 - 0.25 * beta * beta * state.omega);
      state.omega = omega;
      ++state.chebyshev_steps;
      for (size_t e = 0; e < ne; ++e) {
        for (int k = 0; k < 3; ++k)
          indirect[e][k] = std::max(0.0f, older_indirect[e][k] + float(omega) * (indirect[e][k] - older_indirect[e][k]));
        next[e] = in.albedo[e] * (direct[e] + indirect[e]);
      }
    }
    return chebyshev;
  }

  /// After a step that did not stop the iteration: reads β (`beta`) from the Jacobi steps'
  /// ratios in `state`, or reads it again where Chebyshev's residual falls too slowly (restarting
  /// its recurrence in `state`).
  void read_beta(bool chebyshev) {
    if (beta == 0.0 && state.steps >= 3) {
      // λ from the Jacobi steps' ratios, once two successive ones agree to a fifth, or after
      // kChebyshevWarmUp steps; a later level of the ladder starts with the last level's.
      double lambda = 0.0;
      bool settled = true;
      for (size_t k = 0; k < 3; ++k) {
        lambda = std::max(lambda, state.ratio[k]);
        settled = settled && std::abs(state.ratio[k] - state.last_ratio[k]) <= 0.2 * state.ratio[k];
      }
      if (settled || state.steps >= kChebyshevWarmUp) beta = std::clamp(lambda, kChebyshevLeast, kChebyshevMost);
    } else if (chebyshev && state.chebyshev_steps >= 3 && state.last_residual > 0.0) {
      // The power iteration reads λ low while faster components still decay beside it. An
      // eigenvalue μ above β decays by q = (t + √(t² − 1)) / a per step, t = μ / β and
      // a = (1 + √(1 − β²)) / β: where the residual falls more slowly than β allows, μ is
      // read back from q and the recurrence restarts with β = μ (Manteuffel 1977 adapts
      // its parameters the same way).
      const double q = result.residual / state.last_residual, a = (1.0 + std::sqrt(1.0 - beta * beta)) / beta;
      if (q < 1.0 && q * a > 1.0 + kChebyshevSlack) {
        const double y = q * a, mu = 0.5 * (y + 1.0 / y) * beta;
        if (mu > beta * (1.0 + kChebyshevSlack)) {
          beta = std::min(mu, kChebyshevMost);
          state.plain_next = true, state.chebyshev_steps = 0;
        }
      }
    }
  }

  /// Where the iteration stopped on plain Jacobi steps, adds the tail of the geometric series
  /// along the last change (see iterate) to `indirect` and `radiosity`, where λ has settled.
  /// Writes result.tail_added.
  void add_tail() {
    std::array<float, 3> tail{};
    for (size_t k = 0; k < 3; ++k) {
      const double l = state.ratio[k];
      if (l > 0.0 && l < kMaxReflectedGain && std::abs(l - state.last_ratio[k]) <= 0.02 * l) tail[k] = float(l / (1.0 - l));
    }
    result.tail_added = tail[0] > 0.0f || tail[1] > 0.0f || tail[2] > 0.0f;
    for (size_t e = 0; e < ne; ++e) {
      for (int k = 0; k < 3; ++k)
        indirect[e][k] = std::max(0.0f, indirect[e][k] + tail[size_t(k)] * (indirect[e][k] - last_indirect[e][k]));
      radiosity[e] = in.albedo[e] * (direct[e] + indirect[e]);
    }
  }

  /// Jacobi iteration: gather, then reflect, x ← J(x) = ρ (E + G x). It converges from below,
  /// each step's change a factor λ (the largest eigenvalue of ρ·gather) smaller than the last:
  /// on Šibenik's nave (80,258 elements) λ ≈ 0.7, and 16 gathers reached a relative change of
  /// 7.5 · 10⁻⁴.
  ///
  /// Chebyshev's semi-iteration (Golub & Varga 1961; Saad, "Iterative Methods for Sparse Linear
  /// Systems", §12.1) takes the same gathers further: x_{k+1} = x_{k−1} + ω_{k+1} (J(x_k) − x_{k−1}),
  /// with ω_2 = 1 / (1 − β²/2), ω_{k+1} = 1 / (1 − β² ω_k / 4), damps every error component
  /// whose eigenvalue lies in [−β, β] by β / (1 + √(1 − β²)) per gather, 0.41 against Jacobi's
  /// 0.7 at β = 0.7, and still converges, more slowly, for any eigenvalue in (−1, 1). The matrix
  /// ρ F is similar to a symmetric one (reciprocity, A F = (A F)ᵀ), so its eigenvalues are real;
  /// the links' models make it only nearly so. β is λ read from the first Jacobi steps (the
  /// ratio of their area-weighted changes, as a power iteration reads it), and kept for the
  /// ladder's later levels. Iterates are held non-negative.
  ///
  /// The stop: the residual r = J(x) − x (per element, relative, area-weighted) bounds the error
  /// x* − x by r / (1 − λ), so Chebyshev's iteration stops at r < tolerance · (1 − β). Where it
  /// never started (a solve that converged within the first Jacobi steps), the plain Jacobi stop
  /// leaves about λ / (1 − λ) times the last change ungathered: 4 times the tolerance in a white
  /// furnace of ρ = 0.8, which read 0.3 % dark. Once λ has settled (two successive ratios of the
  /// changes agree), that tail is added: the geometric series' sum along the last change
  /// (Aitken's extrapolation, per channel).
  ///
  /// Iterates over the present links from the present solution until the residual is below
  /// `tolerance` (or time runs out), going on from where the last call on these links stopped;
  /// the gathers add to result.iterations. Reads and writes the iterates, `state` and `beta`;
  /// writes result.residual, result.chebyshev_beta and result.tail_added.
  void iterate(double tolerance) {
    result.tail_added = false;
    // The count of gathers is not known ahead (the iteration stops at the tolerance): the
    // progress counts them against the most there may be.
    rc::util::Progress progress("radiosity: iterating",
                                uint64_t(std::max(0, settings.max_iterations - result.iterations)), "gathers",
                                settings.progress);
    while (result.iterations < settings.max_iterations) {
      if (out_of_time()) break;
      // Under a time limit a gather takes about as long as the last: none starts that would end past it.
      if (timed && group.broadcast_value(in.seconds_left() < last_gather_seconds)) break;
      const auto step_start = std::chrono::steady_clock::now();
      const bool chebyshev = iteration_step();
      last_gather_seconds = seconds_since(step_start);
      progress.advance(1);
      radiosity.swap(next);
      if (beta > 0.0 ? result.residual < tolerance * (1.0 - beta) : result.residual < tolerance) break;
      read_beta(chebyshev);
      // A plain step, once β is known, is the recurrence's x_1 = J(x_0).
      if (!chebyshev && beta > 0.0) state.omega = 1.0, state.plain_next = false;
    }
    result.chebyshev_beta = beta;
    if (beta > 0.0 || state.steps < 3 || tolerance > settings.tolerance) return;
    add_tail();
  }

  double chebyshev_rate() const {
    const double b = beta > 0.0 ? beta : kChebyshevMost;
    return b / (1.0 + std::sqrt(1.0 - b * b));
  }
  /// Gathers, a plain restart step included, to bring the residual down by `factor`.
  double gathers_to(double factor) const {
    return 1.0 + std::ceil(std::log(std::max(factor, 1.0)) / -std::log(chebyshev_rate()));
  }

  Linker linker_at(double t) {
    return Linker(in, tree, power_estimate, moment_estimate, t * total_estimate, settings, counters);
  }

  /// The ladder's levels above the last are iterated only to kLadderLoosening times the
  /// tolerance: the next level starts from that solution and its own iteration takes it the rest
  /// of the way, so the cheap coarse gathers do the bulk of the converging. The level where the
  /// ladder stops is then iterated on to the tolerance. On Šibenik's nave (2e-2 down to 2e-5,
  /// no time limit to speak of) the three upper levels took 9, 4 and 5 gathers.
  ///
  /// A level is started only when it is foretold to finish, linking and iterating, in the time
  /// left: one cut off while it links is time lost. Its linking is foretold by a trial on a
  /// fiftieth of the pairs it refines (below). An extrapolation from the last level's cost per
  /// pair split erred long by about 2 on Šibenik (19.3, 10.7 and 8.2 µs per split from level to
  /// level; 16.6 s foretold for a quarter decade that took 8.7 s), and so stopped the ladder
  /// a quarter decade short or more. While a level links, the time the last level needs to
  /// finish its iteration is kept back: a linking that runs into it stops, and the last level
  /// finishes instead.
  ///
  /// The level is foretold by a trial: every kTrialStride-th pair it would refine is refined
  /// (and the result dropped), and the whole is foretold at the trial's seconds and links
  /// per pair. A gather costs what the last level's did per link, and the gathers needed
  /// bring the residual the last level's first gather left down to the target at
  /// Chebyshev's rate. Where the whole decade is foretold too long, three quarters, half or
  /// a quarter of it may fit, and is then the ladder's last level.
  ///
  /// Reads the open pairs, the last level's record, the links and the time left; writes `plan`
  /// and adds the trial's seconds to result.link_seconds. False when not even a quarter fits.
  bool foretell_level(size_t level, LevelPlan& plan) {
    const LadderLevel& before = result.ladder.back();
    const double per_gather = before.iterate_seconds / std::max(1, before.iterations + 1);  // bounding the gains: one
    plan.reserve = finished ? 0.0 : per_gather * gathers_to(kLadderLoosening);
    std::vector<OpenPair> trial_pairs;
    for (size_t i = 0; i < open_pairs.size(); i += kTrialStride) trial_pairs.push_back(open_pairs[i]);
    const double scale = double(open_pairs.size()) / double(std::max<size_t>(1, trial_pairs.size()));
    bool fits = false;
    for (int quarters = 4; quarters >= 1 && !fits; --quarters) {
      const double t = std::max(ladder[level], before.link_tolerance * std::pow(10.0, -0.25 * quarters));
      const bool final_level = plan.last || quarters < 4;
      const double target = (final_level ? 1.0 : kLadderLoosening) * settings.tolerance * (1.0 - beta);
      const double gathers = 1.0 + gathers_to(before.first_residual / std::max(target, 1e-30));
      const std::optional<Trial> trial = run_trial(t, trial_pairs, scale);
      if (!trial) break;
      const LevelForecast f =
          solver::foretell_level(*trial, double(exact_links.size()), merge_per_link, gather_per_link, gathers);
      fits = group.broadcast_value(f.total() <= in.seconds_left());
      if (fits) plan.tolerance = t, plan.last = final_level;
    }
    if (!fits) return false;
    plan.splits = size_t(group.total(linker_at(plan.tolerance).splits(open_pairs)));
    return true;
  }

  /// Refines `pairs` (every stride-th of a level's, `scale` = the level's count over theirs) at
  /// tolerance t, timed, and drops what it made; its seconds count as linking. Nothing when it
  /// ran out of time or was foretold over before it finished (trial_keep_back).
  std::optional<Trial> run_trial(double t, std::span<const OpenPair> pairs, double scale) {
    const uint64_t rays = counters.rays, form_factors = counters.form_factors;
    const auto trial_start = std::chrono::steady_clock::now();
    const std::optional<LinkLevel> made = linker_at(t)
                                              .owned_by(cut.owner, group.rank())
                                              .keeping_back(trial_keep_back(in.seconds_left(), scale))
                                              .link(pairs);
    const double seconds = seconds_since(trial_start);
    result.link_seconds += seconds;
    counters.rays = rays, counters.form_factors = form_factors;
    if (!made) return std::nullopt;
    return Trial{seconds, double(made->exact.size() + made->far.size()), scale};
  }

  /// A timed solve's first level (one process only): from the ladder's top down to
  /// kFirstLevelDecades decades coarser, the first tolerance whose links, merged and gathered
  /// kFirstLevelGathers times, are foretold to fit in the time left. Each is foretold by
  /// expanding the root pair breadth first to about 1,024 trial pairs' worth and refining every
  /// kTrialStride-th of the open pairs; the chosen level links from that expansion. Coarser
  /// tolerances are put at the ladder's head, so the ladder still runs down to the one asked for.
  /// A coarse reflected solution in time beats none: on a furnished room of 145,000 elements at
  /// `--time 20` the top level (2e-3) linked 17 M links and had no time left to gather them.
  ///
  /// Reads the tree, the ladder and the time left; writes `plan` (its tolerance, start pairs and
  /// head links), the ladder and result.link_seconds. False when not even the coarsest fits.
  bool foretell_first_level(LevelPlan& plan) {
    const double top = ladder.front();
    for (int decades = 0; decades <= kFirstLevelDecades; ++decades) {
      const double t = top * std::pow(10.0, decades);
      const auto expand_start = std::chrono::steady_clock::now();
      LevelPlan trial_plan;
      const uint64_t rays = counters.rays, form_factors = counters.form_factors;
      trial_plan.start = linker_at(t).keeping_open_pairs(!plan.last || decades > 0).expand(open_pairs, kTrialStride * 1024,
                                                                                            trial_plan.head);
      const double expand_seconds = seconds_since(expand_start);
      result.link_seconds += expand_seconds;
      std::vector<OpenPair> trial_pairs;
      for (size_t i = 0; i < trial_plan.start.size(); i += kTrialStride) trial_pairs.push_back(trial_plan.start[i]);
      const double scale = double(trial_plan.start.size()) / double(std::max<size_t>(1, trial_pairs.size()));
      const uint64_t expand_rays = counters.rays, expand_form_factors = counters.form_factors;
      const std::optional<Trial> trial = run_trial(t, trial_pairs, scale);
      counters.rays = expand_rays, counters.form_factors = expand_form_factors;
      if (!trial) {
        counters.rays = rays, counters.form_factors = form_factors;
        continue;
      }
      const double head = double(trial_plan.head.exact.size() + trial_plan.head.far.size());
      const LevelForecast f = solver::foretell_level(*trial, head, merge_per_link, gather_per_link, kFirstLevelGathers);
      if (!(f.total() <= in.seconds_left())) {
        counters.rays = rays, counters.form_factors = form_factors;
        continue;
      }
      for (int d = 1; d <= decades; ++d) ladder.insert(ladder.begin(), top * std::pow(10.0, d));
      plan.tolerance = t;
      plan.last = ladder.size() == 1;
      plan.expanded = true;
      plan.start = std::move(trial_plan.start);
      plan.head = std::move(trial_plan.head);
      // The links it keeps back from: its merge and two gathers, or linking that runs into them
      // stops and leaves the time to the rest of the solve.
      plan.reserve = f.merge + 2.0 * f.iterate / kFirstLevelGathers;
      return true;
    }
    return false;
  }

  /// Links in order of receiver: the exact ones stay in order from level to level, and each
  /// level's new exact and far links are sorted on their own and merged in. Reads what the
  /// level made (and empties it); writes exact_links, links, open_pairs, receivers, first_link.
  void merge_links(LinkLevel& made, bool last) {
    tbb::parallel_sort(made.exact.begin(), made.exact.end());
    const size_t exact_before = exact_links.size();
    exact_links.insert(exact_links.end(), made.exact.begin(), made.exact.end());
    made.exact = {};
    std::inplace_merge(exact_links.begin(), exact_links.begin() + std::ptrdiff_t(exact_before), exact_links.end());
    open_pairs = std::move(made.open);
    tbb::parallel_sort(made.far.begin(), made.far.end());
    if (last)
      links = std::move(exact_links);
    else
      links = exact_links;
    const size_t exact_count = links.size();
    links.insert(links.end(), made.far.begin(), made.far.end());
    made.far = {};
    std::inplace_merge(links.begin(), links.begin() + std::ptrdiff_t(exact_count), links.end());
    receivers.clear();
    first_link.clear();
    for (uint32_t i = 0; i < links.size(); ++i)
      if (i == 0 || links[i].receiver != links[i - 1].receiver)
        receivers.push_back(links[i].receiver), first_link.push_back(i);
    first_link.push_back(uint32_t(links.size()));
  }

  /// Puts the links and pairs a first level's expansion made (`head`, emptied) in front of the
  /// ones linked from it.
  static void add_head(LinkLevel& head, LinkLevel& made) {
    if (head.exact.empty() && head.far.empty() && head.open.empty()) return;
    head.exact.insert(head.exact.end(), made.exact.begin(), made.exact.end());
    head.far.insert(head.far.end(), made.far.begin(), made.far.end());
    head.open.insert(head.open.end(), made.open.begin(), made.open.end());
    made = std::move(head);
    head = LinkLevel{};
  }

  /// Links one level of the ladder as planned: refines the open pairs (or the plan's start pairs,
  /// adding its head links, which it empties) and merges the links made. Writes the links
  /// (merge_links), `record`'s linking and result's links, link_tolerance, link_rays and
  /// link_seconds, and the merge's cost per link. False when the linking ran out of time
  /// (result.linking_stopped).
  bool link_level(LevelPlan& plan, LadderLevel& record) {
    record.link_tolerance = plan.tolerance;
    record.open_pairs = count_as_one_process(open_pairs, cut.owner);
    record.splits = plan.splits;
    Linker linker = linker_at(plan.tolerance);
    char label[64];
    std::snprintf(label, sizeof label, "radiosity: linking at tolerance %.3g", plan.tolerance);
    rc::util::Progress progress(label, 0, "chunks of pairs", settings.progress);
    linker.owned_by(cut.owner, group.rank())
        .keeping_open_pairs(!plan.last)
        .keeping_back(plan.reserve)
        .reporting(&progress);
    const auto link_start = std::chrono::steady_clock::now();
    std::optional<LinkLevel> made = linker.link(plan.expanded ? std::span<const OpenPair>(plan.start)
                                                               : std::span<const OpenPair>(open_pairs));
    progress.finish();
    if (!made) {
      result.link_seconds += seconds_since(link_start);
      result.linking_stopped = true;
      return false;
    }
    add_head(plan.head, *made);
    const auto merge_start = std::chrono::steady_clock::now();
    merge_links(*made, plan.last);
    if (timed) merge_per_link = seconds_since(merge_start) / double(std::max<size_t>(1, links.size()));
    record.link_seconds = seconds_since(link_start);
    result.link_seconds += record.link_seconds;
    result.links = record.links = count_as_one_process(links, cut.owner);
    result.link_tolerance = plan.tolerance;
    result.link_rays = counters.rays;
    return true;
  }

  /// Iterates a newly linked level from the present solution: its last level to the tolerance,
  /// the others to kLadderLoosening times it. Writes the gains, the iterates, `finished`,
  /// `record`'s iteration and result's; appends `record` to result.ladder.
  void iterate_level(bool last, LadderLevel& record) {
    const auto iterate_start = std::chrono::steady_clock::now();
    result.iterations = 0;
    result.residual = 0.0;
    state = IterationState{};
    const auto bound_start = std::chrono::steady_clock::now();
    bound_gains();
    last_gather_seconds = seconds_since(bound_start);
    iterate(last ? settings.tolerance : kLadderLoosening * settings.tolerance);
    if (timed) gather_per_link = last_gather_seconds / double(std::max<size_t>(1, links.size()));
    finished = last;
    record.iterations = result.iterations;
    record.first_residual = state.first_residual;
    record.residual = result.residual;
    record.iterate_seconds = seconds_since(iterate_start);
    result.iterate_seconds += record.iterate_seconds;
    result.ladder.push_back(record);
  }

  /// Where the ladder stopped on a level iterated loosely, iterates it on to the tolerance and
  /// adds to its record (finishing_iterations, residual, iterate_seconds).
  void finish_iteration() {
    if (finished) return;
    const auto iterate_start = std::chrono::steady_clock::now();
    const int before = result.iterations;
    iterate(settings.tolerance);
    LadderLevel& record = result.ladder.back();
    record.finishing_iterations = result.iterations - before;
    record.residual = result.residual;
    record.iterate_seconds += seconds_since(iterate_start);
    result.iterate_seconds += seconds_since(iterate_start);
  }

  /// Pulls the solution's radiosity up the tree (power, moment), for the final gather's walk;
  /// ends the iteration's lap of the clock.
  void pull_solution() {
    pull(tree, mesh, radiosity, power, moment);
    lap();
  }

  /// Vertices first take the area-weighted mean of their elements' gathered irradiance; the
  /// final gather then replaces it while time allows. Reads `indirect`; writes
  /// result.vertex_irradiance and mean_indirect.
  void average_to_vertices() {
    {
      std::vector<double> weight(nv, 0.0);
      std::vector<Rgb> sum(nv, Rgb(0.0f));
      for (size_t e = 0; e < ne; ++e)
        for (uint32_t v : mesh.elements[e])
          sum[v] += indirect[e] * mesh.element_area[e], weight[v] += mesh.element_area[e];
      for (size_t v = 0; v < nv; ++v)
        if (weight[v] > 0.0) result.vertex_irradiance[v] = sum[v] * float(1.0 / weight[v]);
    }
    for (size_t e = 0; e < ne; ++e) mean_indirect += double(indirect[e].average()) * mesh.element_area[e];
    mean_indirect /= area;
  }

  /// Gathers at the listed vertices in parallel, each process at the chunks of 64 it owns, into
  /// gathered_at; adds to the counters. False when time ran out first on any process, or when
  /// fewer than `keep_back` seconds were left (0: none kept back).
  bool gather_at(const TreeWalk& walker, const std::vector<uint32_t>& list, double keep_back = 0.0,
                 rc::util::Progress* progress = nullptr) {
    std::atomic<bool> stopped{false};
    const uint64_t rays_before = counters.rays, nodes_before = counters.gather_nodes,
                   form_factors_before = counters.form_factors;
    rc::util::parallel_for_owned((list.size() + 63) / 64, [&](size_t chunk) {
      if (stopped.load(std::memory_order_relaxed) || (in.out_of_time && in.out_of_time()) ||
          (keep_back > 0.0 && in.seconds_left && in.seconds_left() < keep_back)) {
        stopped = true;
        return;
      }
      WalkCounts walk;
      std::vector<uint32_t> stack;
      for (size_t i = chunk * 64; i < std::min(list.size(), chunk * 64 + 64); ++i) {
        const uint32_t v = list[i];
        const double epsilon = settings.gather_tolerance *
                               std::max(double(result.vertex_irradiance[v].average()), 0.05 * mean_indirect);
        rc::util::Rng rng = rc::util::Rng::for_item(settings.seed, v, 0x5200000000ull);
        gathered_at[v] = walker.irradiance(v, epsilon, 1, rng, stack, walk);
      }
      counters.rays += walk.rays;
      counters.gather_nodes += walk.nodes;
      counters.form_factors += walk.form_factors;
      if (progress) progress->advance(std::min(list.size(), chunk * 64 + 64) - chunk * 64);
    });
    if (group.count() == 1) return !stopped;
    std::vector<Rgb> values(list.size());
    for (size_t i = 0; i < list.size(); ++i) values[i] = gathered_at[list[i]];
    rc::util::join_ranges(std::span(values), 64);
    for (size_t i = 0; i < list.size(); ++i) gathered_at[list[i]] = values[i];
    counters.rays = rays_before + group.total(counters.rays - rays_before);
    counters.gather_nodes = nodes_before + group.total(counters.gather_nodes - nodes_before);
    counters.form_factors = form_factors_before + group.total(counters.form_factors - form_factors_before);
    return !group.any(stopped);
  }

  /// Final gather: each vertex walks the tree from the root, taking a cluster whole when the
  /// irradiance it may carry wrongly is below gather_tolerance of the vertex's own indirect
  /// irradiance (at least 5 % of the scene's mean), and elements by Lambert's formula.
  ///
  /// A probe of every kGatherProbeStride-th vertex (at most about 1,024 of them) predicts what
  /// the whole gather costs. `auto` skips it when it would trace more than kGatherRayShare times
  /// the links' shadow rays: on a large interior (Šibenik: 3,000–9,000 nodes per vertex, four to
  /// ten times the linking's time) it costs minutes and moves the result by less than the links'
  /// own error, while on a compact scene it is a fraction of the solve and sharpens the vertices.
  /// Under a time limit it is skipped when the prediction does not fit in the time left.
  ///
  /// Reads the solution (radiosity, power, moment) and result.vertex_irradiance; writes
  /// result.vertex_irradiance when complete, result.final_gather, its note and predicted rays.
  void final_gather() {
    result.final_gather = false;
    if (settings.final_gather == FinalGather::never) {
      result.final_gather_note = "not asked for";
      return;
    }
    // A timed solve without links has no reflected light to gather: its probe would be time lost.
    if (timed && links.empty()) {
      result.final_gather_note = "skipped: no links were made in the time";
      return;
    }
    const TreeWalk walker{in, tree, radiosity, power, moment};
    gathered_at.resize(nv);
    std::vector<uint32_t> probe, rest;
    const size_t stride = std::max<size_t>(kGatherProbeStride, nv / 1024);
    for (uint32_t v = 0; v < nv; ++v) (v % stride == 0 ? probe : rest).push_back(v);
    const uint64_t rays_before = counters.rays;
    const auto probe_start = std::chrono::steady_clock::now();
    const double scale = double(nv) / double(std::max<size_t>(1, probe.size()));
    // Under a time limit the probe stops once the gather it foretells could no longer fit: with
    // L seconds left, a probe that takes more than L / (1 + kFinalGatherMargin (scale − 1)).
    const double probe_keep_back =
        timed ? in.seconds_left() * (1.0 - 1.0 / (1.0 + kFinalGatherMargin * std::max(0.0, scale - 1.0))) : 0.0;
    bool complete = gather_at(walker, probe, probe_keep_back);
    result.final_gather_predicted_rays = uint64_t(double(counters.rays - rays_before) * scale);
    const double predicted_seconds = group.broadcast_value(seconds_since(probe_start) * (scale - 1.0));
    if (complete && settings.final_gather == FinalGather::automatic &&
        double(result.final_gather_predicted_rays) > kGatherRayShare * double(std::max<uint64_t>(1, result.link_rays))) {
      result.final_gather_note = "skipped: it would trace about " + std::to_string(result.final_gather_predicted_rays) +
                                 " shadow rays, more than " + std::to_string(int(kGatherRayShare)) +
                                 " times the links' " + std::to_string(result.link_rays);
      complete = false;
    } else if (complete && timed && group.broadcast_value(!final_gather_fits(predicted_seconds, in.seconds_left()))) {
      char note[160];
      std::snprintf(note, sizeof note, "skipped: it would take about %.3g s, %.3g s were left", predicted_seconds,
                    std::max(0.0, in.seconds_left()));
      result.final_gather_note = note;
      complete = false;
    } else if (complete) {
      rc::util::Progress progress("radiosity: final gather", rest.size(), "vertices", settings.progress);
      complete = gather_at(walker, rest, 0.0, &progress);
      result.final_gather = complete;
      result.final_gather_note = complete ? "at every vertex" : "stopped by --time";
    } else {
      result.final_gather_note = "skipped: its probe ran past the time it could take under --time";
    }
    // A partial gather would leave its boundary visible between vertices that had it and their
    // neighbours that did not: only a complete one is used.
    if (result.final_gather)
      for (size_t v = 0; v < nv; ++v) result.vertex_irradiance[v] = gathered_at[v];
  }

  /// Writes the final gather's seconds and the counters to the result.
  void report() {
    result.gather_seconds = lap();
    result.shadow_rays = counters.rays;
    result.form_factors = counters.form_factors;
    result.gather_nodes = counters.gather_nodes;
  }
};

}  // namespace

std::vector<Rgb> emitted_irradiance(const HierarchicalInput& in, std::span<const Rgb> emitted,
                                    size_t first_vertex, const HierarchicalSettings& settings, int rays,
                                    uint64_t* shadow_rays) {
  const RadiosityMesh& mesh = in.mesh;
  const size_t ne = mesh.element_count(), nv = mesh.vertex_count();
  std::vector<Rgb> out(nv, Rgb(0.0f));
  double total = 0.0, area = 0.0;
  for (size_t e = 0; e < ne; ++e) {
    total += double(emitted[e].average()) * mesh.element_area[e];
    area += mesh.element_area[e];
  }
  if (!(total > 0.0) || first_vertex >= nv) return out;
  const Tree tree = make_tree(mesh, in.albedo);
  std::vector<Rgb> power;
  std::vector<Moments> moment;
  pull(tree, mesh, emitted, power, moment);
  const TreeWalk walker{in, tree, emitted, power, moment};
  // The emitted power spread over every surface: a scale of the direct irradiance.
  const double epsilon = settings.gather_tolerance * total / area;
  std::atomic<uint64_t> ray_count{0};
  const size_t count = nv - first_vertex;
  rc::util::parallel_for_owned((count + 63) / 64, [&](size_t chunk) {
    WalkCounts walk;
    std::vector<uint32_t> stack;
    for (size_t v = first_vertex + chunk * 64; v < std::min(nv, first_vertex + chunk * 64 + 64); ++v) {
      rc::util::Rng rng = rc::util::Rng::for_item(settings.seed, v, 0x5300000000ull);
      out[v] = walker.irradiance(v, epsilon, rays, rng, stack, walk);
    }
    ray_count += walk.rays;
  });
  rc::util::join_ranges(std::span(out), 64, first_vertex);
  if (shadow_rays) *shadow_rays += rc::util::processes().total(ray_count);
  return out;
}

HierarchicalResult solve_hierarchical(const HierarchicalInput& in, const HierarchicalSettings& settings) {
  HierarchicalResult result;
  result.vertex_irradiance.assign(in.mesh.vertex_count(), Rgb(0.0f));
  if (in.mesh.element_count() == 0) return result;
  HierarchicalSolve solve(in, settings, result);
  solve.build_tree();
  if (!solve.first_bounce()) return result;
  solve.estimate_power();
  solve.plan_ladder();
  // The ladder, level by level: foretell (below the first), link, iterate.
  for (size_t level = 0; level < solve.ladder.size(); ++level) {
    LevelPlan plan;
    plan.tolerance = solve.ladder[level];
    plan.last = level + 1 == solve.ladder.size();
    const bool foretold = level > 0                         ? solve.foretell_level(level, plan)
                          : solve.timed && solve.group.count() == 1 ? solve.foretell_first_level(plan)
                                                                    : true;
    if (!foretold) {
      result.linking_stopped = true;
      break;
    }
    LadderLevel record;
    if (!solve.link_level(plan, record)) break;
    solve.iterate_level(plan.last, record);
    if (plan.last) break;
  }
  solve.finish_iteration();
  solve.pull_solution();
  solve.average_to_vertices();
  solve.final_gather();
  solve.report();
  return result;
}

}  // namespace gilt::radiosity::solver

#pragma once
// Private to the hierarchical solver: the links between clusters and the Linker that makes them.
// Linking starts from the root paired with itself (or from pairs a coarser level accepted) and
// splits the larger end of a pair until the error oracle accepts it (see hierarchical.cpp's
// opening comment). Reads the tree, the oracle's power estimates and the scene's visibility;
// writes the links and the accepted pairs it returns, and counts rays and form factors.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "radiosity/solver/cluster_tree.h"
#include "radiosity/solver/hierarchical.h"
#include "raytrace_core/util/progress.h"

namespace gilt::radiosity::solver::detail {

/// Random streams of a link's shadow rays: the pilot that decides, and the estimate an accepted
/// link carries where the pilot's count would be biased (see Linker::refine).
inline constexpr uint64_t kPilotStream = 0x5100000000ull, kEstimateStream = 0x5400000000ull;

/// A link: node `receiver` gathers from node `source`. Far links give the irradiance facing the
/// source, I_S(−ω)·factor with factor = V κ / r² (κ the kernel's average over the two ends'
/// extent, cluster_kernel_scale), along ω, the unit direction from the receiver's centre to the
/// source's; exact links (element to element) give B_S·factor with factor = F·V, F the element's
/// mean factor to the source (SourceTriangle::form_factor_from), along the receiver's normal.
/// Twelve bytes: the direction is found again from the nodes when gathering (a far link's, from
/// its receiver's centre to its source's, as split_mixed made it; an exact link's, the receiving
/// element's normal), since a 300k-triangle interior at tolerance 2e-6 holds 120 million links,
/// and at 28 bytes with the sort's buffer those took 10 GB.
struct Link {
  static constexpr uint32_t kExactBit = 0x80000000u;
  uint32_t receiver;
  uint32_t tagged_source;  ///< the source node, kExactBit set for an exact link
  float factor;

  Link(uint32_t r, uint32_t s, float f, bool exact)
      : receiver(r), tagged_source(s | (exact ? kExactBit : 0u)), factor(f) {}
  uint32_t source() const { return tagged_source & ~kExactBit; }
  bool exact() const { return (tagged_source & kExactBit) != 0u; }
  /// Links ordered by receiver, then source: one receiver's links are adjacent, in an order that
  /// does not depend on how they were made (a pair of nodes is linked at most once).
  friend bool operator<(const Link& a, const Link& b) {
    return a.receiver != b.receiver ? a.receiver < b.receiver : a.tagged_source < b.tagged_source;
  }
};

struct Counters {
  std::atomic<uint64_t> rays{0}, form_factors{0}, gather_nodes{0};
};

/// A pair of nodes to refine, with its visible fractions when already known (else −1): the
/// pilot's, which decides, and the one from rays of its own that a link accepted on the pilot
/// carries (see Linker::refine).
struct OpenPair {
  uint32_t receiver, source;
  float visible = -1.0f, estimate = -1.0f;
  float error = 0.0f;  ///< for an accepted pair: the error bound it was accepted with
};

/// What linking to one tolerance made: exact element-to-element links (final at any
/// tolerance), far links, and the far pairs they came from (accepted or wholly hidden), which a
/// finer tolerance refines further instead of linking again from the root.
struct LinkLevel {
  std::vector<Link> exact, far;
  std::vector<OpenPair> open;
};

class Linker {
 public:
  bool out_of_time() const {
    return (in_.out_of_time && in_.out_of_time()) ||
           (keep_back_ > 0.0 && in_.seconds_left && in_.seconds_left() < keep_back_);
  }

  Linker(const HierarchicalInput& in, const Tree& tree, std::span<const float> power_estimate,
         std::span<const Vec3> moment_estimate, double epsilon, const HierarchicalSettings& settings,
         Counters& counters)
      : in_(in),
        tree_(tree),
        power_(power_estimate),
        moment_(moment_estimate),
        epsilon_(epsilon),
        settings_(settings),
        counters_(counters) {}

  /// Under several processes: the owner of each node (owners_of), and this process's rank.
  Linker& owned_by(std::span<const int> owner, int rank) {
    owner_ = owner;
    rank_ = rank;
    return *this;
  }

  /// Whether to keep the accepted far pairs (`LinkLevel::open`) for a finer level to refine.
  Linker& keeping_open_pairs(bool keep) {
    keep_open_ = keep;
    return *this;
  }

  /// Under a time limit: stop (link() returns nothing) once fewer than `seconds` are left.
  Linker& keeping_back(double seconds) {
    keep_back_ = seconds;
    return *this;
  }

  /// Reports link()'s chunks of pairs as they finish (null: none).
  Linker& reporting(rc::util::Progress* progress) {
    progress_ = progress;
    return *this;
  }

  /// How many of the accepted pairs `open` (a coarser level's) this linker would split rather
  /// than accept again: those whose error or pilot no longer passes (see refine).
  size_t splits(std::span<const OpenPair> open) const;

  /// Refines `start` breadth first, on this thread, until at least `at_least` pairs are open (as
  /// one process would count them) or none are: the links and accepted pairs made on the way go
  /// to `made`, and the open pairs are returned. link() on them, with `made` added, makes the
  /// same links as link() on `start`.
  std::vector<OpenPair> expand(std::span<const OpenPair> start, size_t at_least, LinkLevel& made);

  /// The links made by refining every pair of `start` to this linker's tolerance (the root
  /// pair {0, 0} to link afresh), or nothing when `in.out_of_time` said stop before it finished.
  std::optional<LinkLevel> link(std::span<const OpenPair> start);

 private:
  /// Whether a link into `receiver` whose error bound is `error` passes the oracle: below the
  /// tolerance's share of the scene's reflected power and of the receiver's own over
  /// settings.receiver_share (power_[0], the root's, is the scene's).
  bool acceptable(double error, uint32_t receiver) const {
    return error <= epsilon_ &&
           (!(settings_.receiver_share > 0.0) ||
            error * settings_.receiver_share * double(power_[0]) <= epsilon_ * double(power_[receiver]));
  }

  /// Whether this process refines pairs, and keeps links, that receive at `node`.
  bool mine(uint32_t node) const { return owner_.empty() || owner_[node] < 0 || owner_[node] == rank_; }
  /// Where the work on a pair receiving at `node` is counted: the counts are summed over
  /// processes, and the pairs above the cut, refined by every process, are counted by rank 0.
  Counters& count_for(uint32_t node) {
    return owner_.empty() || owner_[node] == rank_ || (owner_[node] < 0 && rank_ == 0) ? counters_
                                                                                       : uncounted_;
  }
  /// Drops the links or pairs that receive at another process's nodes.
  template <class T>
  void keep_mine(std::vector<T>& items) const {
    if (!owner_.empty()) std::erase_if(items, [&](const T& x) { return !mine(x.receiver); });
  }
  void keep_mine(LinkLevel& level) const {
    keep_mine(level.exact);
    keep_mine(level.far);
    keep_mine(level.open);
  }

  /// Accepts, drops or splits the pair (r, s): links go to `out` (with the accepted far pairs,
  /// which a finer tolerance may split), halves to `pending`. A known visible fraction (≥ 0)
  /// saves the pair's shadow rays.
  void refine(const OpenPair& pair, LinkLevel& out, std::vector<OpenPair>& pending);

  /// The visible fraction between nodes r and s, by link_rays shadow rays (1 when nothing can
  /// block them).
  float visibility(uint32_t r, uint32_t s, uint64_t stream = kPilotStream);

  /// Emits the far link (r, s), or, where an end has elements facing both ways (where the
  /// cluster models are only approximate), links between its children instead, down to
  /// kMixedDepth levels; parts that face away are dropped. All share the pair's visibility.
  void split_mixed(uint32_t r, uint32_t s, int r_depth, int s_depth, float visible,
                   std::vector<Link>& links) const;

  const HierarchicalInput& in_;
  const Tree& tree_;
  std::span<const float> power_;
  std::span<const Vec3> moment_;
  double epsilon_;
  const HierarchicalSettings& settings_;
  Counters& counters_;
  Counters uncounted_;
  std::span<const int> owner_;
  int rank_ = 0;
  bool keep_open_ = false;
  double keep_back_ = 0.0;
  rc::util::Progress* progress_ = nullptr;
};

}  // namespace gilt::radiosity::solver::detail

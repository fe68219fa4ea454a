#pragma once
// Private to the hierarchical solver: how its work is shared among processes. The tree is cut
// into subtrees dealt out round-robin (cut_tree), and counts of links and pairs are read as one
// process would hold them (count_as_one_process). Reads the tree and the node owners; writes
// only the cut it returns.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "radiosity/solver/cluster_tree.h"
#include "raytrace_core/util/processes.h"

namespace gilt::radiosity::solver::detail {

/// A node and the nodes of its subtree, [root, end).
struct Subtree {
  uint32_t root, end;
};

/// The tree cut for several processes: subtrees of at most 1/256 of the nodes each, in node
/// order, and each node's owner: the rank of its subtree (subtree i is rank i mod count's), or
/// −1 above the cut.
struct SubtreeCut {
  std::vector<Subtree> subtrees;
  std::vector<int> owner;
};

/// Cuts `tree` for `count` processes (see SubtreeCut).
SubtreeCut cut_tree(const Tree& tree, int count);

/// How many of `items` (links or pairs, each with a receiver node) one process would hold, when
/// each process holds those receiving at its own nodes and all hold those above the cut (owner
/// −1): the ones above the cut once, the rest summed over processes. Empty `owner`: one process.
template <class Items>
size_t count_as_one_process(const Items& items, std::span<const int> owner) {
  if (owner.empty()) return items.size();
  const size_t shared =
      size_t(std::count_if(items.begin(), items.end(), [&](const auto& x) { return owner[x.receiver] < 0; }));
  return shared + size_t(rc::util::processes().total(items.size() - shared));
}

}  // namespace gilt::radiosity::solver::detail

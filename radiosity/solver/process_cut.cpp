// The hierarchical solver's cut of its tree among processes (see process_cut.h): reads the
// tree, writes the subtrees and each node's owner.

#include "radiosity/solver/process_cut.h"

namespace gilt::radiosity::solver::detail {

SubtreeCut cut_tree(const Tree& tree, int count) {
  const size_t n = tree.nodes.size(), most = std::max<size_t>(1, n / 256);
  SubtreeCut cut;
  cut.owner.assign(n, -1);
  if (n == 0) return cut;
  std::vector<uint32_t> end(n);
  for (size_t i = n; i-- > 0;) end[i] = tree.nodes[i].leaf() ? uint32_t(i + 1) : end[tree.nodes[i].right];
  std::vector<uint32_t> stack{0};
  while (!stack.empty()) {
    const uint32_t i = stack.back();
    stack.pop_back();
    if (tree.nodes[i].leaf() || end[i] - i <= most) {
      const int rank = int(cut.subtrees.size() % size_t(count));
      cut.subtrees.push_back({i, end[i]});
      std::fill(cut.owner.begin() + i, cut.owner.begin() + end[i], rank);
    } else {
      stack.push_back(tree.nodes[i].right);
      stack.push_back(i + 1);
    }
  }
  return cut;
}

}  // namespace gilt::radiosity::solver::detail

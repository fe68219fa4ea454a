#pragma once
// Nearest-neighbour and fixed-radius queries over photon positions, for density estimation
// (k nearest photons) and SPPM (every photon within a radius). Two interchangeable structures:
// FLANN's single kd-tree with its points reordered into leaf order, and a uniform grid whose
// occupied cells are hashed into an open-addressing table, each cell's points contiguous.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <type_traits>

#include "raytrace_core/util/math.h"

namespace gilt::photonmap {

namespace rc = gilt::raytrace_core;

/// Which search structure a PhotonIndex builds.
enum class IndexKind {
  kd_tree,    ///< FLANN KDTreeSingleIndex, reordered (good for any query, any density)
  hash_grid,  ///< hashed uniform grid (best when queries have about one cell's radius)
};

/// One query result: the point's index in the positions given to the index, and its squared
/// distance to the query (scene units²).
struct Neighbour {
  uint32_t index;
  float distance2;
};

/// Squared distance exactly as both indexes compute it, ((dx² + dy²) + dz²) in float, so their
/// results can be compared bit for bit with a linear scan.
inline float distance2(const rc::Vec3& a, const rc::Vec3& b) {
  const float dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
  return dx * dx + dy * dy + dz * dz;
}

/// Strict order of neighbours: by squared distance, ties by index. knn returns the first k of
/// the points within range in this order, so its answer is unique.
inline bool closer(const Neighbour& a, const Neighbour& b) {
  return a.distance2 < b.distance2 || (a.distance2 == b.distance2 && a.index < b.index);
}

/// k-nearest-neighbour and fixed-radius index over a fixed set of points. Queries are const,
/// thread-safe and do not allocate. The index keeps its own copy of the points.
class PhotonIndex {
 public:
  PhotonIndex();
  /// Builds the index over `positions` (at most 2³¹ − 1 points, all finite). hash_cell_size is
  /// the grid's cell edge in scene units (about the typical query radius); 0 chooses it from the
  /// point count and bounds, for about 20 points per occupied cell (on surfaces, the radius of a
  /// 50-point query). The kd-tree ignores it.
  PhotonIndex(std::span<const rc::Vec3> positions, IndexKind kind, float hash_cell_size = 0.0f);
  ~PhotonIndex();
  PhotonIndex(PhotonIndex&&) noexcept;
  PhotonIndex& operator=(PhotonIndex&&) noexcept;

  /// Number of indexed points.
  size_t size() const;
  /// The structure built.
  IndexKind kind() const;
  /// Edge of the hash grid's cells in scene units (0 for the kd-tree or an empty index).
  float cell_size() const;

  /// The k nearest points with squared distance <= max_distance2, sorted by closer() (increasing
  /// distance, ties by index). Writes at most k into out (capacity >= k) and returns the count.
  size_t knn(const rc::Vec3& query, size_t k, float max_distance2, Neighbour* out) const;

  /// Calls f(Neighbour) for every point with squared distance <= radius2, in no particular order.
  template <class F>
  void for_each_within(const rc::Vec3& query, float radius2, F&& f) const {
    using Callable = std::remove_reference_t<F>;
    visit_within(
        query, radius2,
        [](void* callable, Neighbour neighbour) { (*static_cast<Callable*>(callable))(neighbour); },
        const_cast<void*>(static_cast<const void*>(std::addressof(f))));
  }

 private:
  struct Impl;
  /// Type-erased callback of for_each_within: a plain function pointer and its context.
  using Visitor = void (*)(void* context, Neighbour neighbour);
  void visit_within(const rc::Vec3& query, float radius2, Visitor visitor, void* context) const;

  std::unique_ptr<Impl> impl_;
};

}  // namespace gilt::photonmap

// Photon index. kd-tree: FLANN's KDTreeSingleIndex (Muja & Lowe 2014, "Scalable Nearest Neighbor
// Algorithms for High Dimensional Data"), an exact single tree with points reordered into leaf
// order. Hash grid: a uniform grid whose occupied cells live in an open-addressing hash table, as
// in SPPM (Hachisuka & Jensen 2009, "Stochastic Progressive Photon Mapping"); points are counting-
// sorted by cell. Both collect the k best in a max-heap kept in the caller's buffer, ordered by
// closer(), so ties at equal distance resolve by index and both answer exactly like a linear scan.

#include "photonmap/photon_index.h"

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace gilt::photonmap {

namespace {

using rc::Vec3;
static_assert(sizeof(Vec3) == 3 * sizeof(float), "FLANN reads positions as rows of 3 floats");

// ---------------------------------------------------------------------------------------------
// The k best so far, as a max-heap (by closer()) on the caller's buffer.

class BestK {
 public:
  BestK(Neighbour* out, size_t k, float max_distance2) : out_(out), k_(k), max_distance2_(max_distance2) {}

  /// Squared distance above which a point cannot enter: the worst kept one once k are kept.
  float bound2() const { return count_ < k_ ? max_distance2_ : out_[0].distance2; }

  void offer(uint32_t index, float distance2) {
    const Neighbour candidate{index, distance2};
    if (count_ < k_) {
      if (!(distance2 <= max_distance2_)) return;
      out_[count_++] = candidate;
      std::push_heap(out_, out_ + count_, closer);
    } else if (closer(candidate, out_[0])) {
      replace_top(candidate);
    }
  }

  /// Sorts the kept neighbours by closer() and returns their count.
  size_t finish() {
    std::sort_heap(out_, out_ + count_, closer);
    return count_;
  }

 private:
  void replace_top(const Neighbour& candidate) {
    size_t hole = 0;
    for (;;) {
      size_t child = 2 * hole + 1;
      if (child >= k_) break;
      if (child + 1 < k_ && closer(out_[child], out_[child + 1])) ++child;
      if (!closer(candidate, out_[child])) break;
      out_[hole] = out_[child];
      hole = child;
    }
    out_[hole] = candidate;
  }

  Neighbour* out_;
  size_t k_;
  size_t count_ = 0;
  float max_distance2_;
};

// ---------------------------------------------------------------------------------------------
// kd-tree: FLANN.

using FlannDistance = flann::L2_3D<float>;  // squared Euclidean distance, ((dx² + dy²) + dz²)
using FlannTree = flann::KDTreeSingleIndex<FlannDistance>;

// FLANN 1.9.2's KDTreeSingleIndex::findNeighbors builds a std::vector of per-axis distances on
// every call, so each query would allocate. Its two steps, computeInitialDistances and
// searchLevel<false>, are private; they are called here directly with a per-thread scratch
// vector. Explicit instantiations skip access checking ([temp.spec.general]/6), so instantiating
// Expose with a pointer to a private member defines a friend function that returns the pointer.
// Should FLANN change these members, this stops compiling rather than misbehaving; the plain
// fallback is tree_->findNeighbors(result, q, flann::SearchParams()), one small allocation a query.
template <auto Member, class Tag>
struct Expose {
  friend constexpr auto exposed(Tag) { return Member; }
};
struct InitialDistancesTag {
  friend constexpr auto exposed(InitialDistancesTag);
};
struct SearchLevelTag {
  friend constexpr auto exposed(SearchLevelTag);
};
struct RootNodeTag {
  friend constexpr auto exposed(RootNodeTag);
};
template struct Expose<&FlannTree::computeInitialDistances, InitialDistancesTag>;
template struct Expose<&FlannTree::searchLevel<false>, SearchLevelTag>;
template struct Expose<&FlannTree::root_node_, RootNodeTag>;

/// FLANN result set for knn: FLANN offers a point when its distance is below worstDist(), which
/// is kept just above the heap's bound so that ties reach BestK, which breaks them by index.
class KnnResultSet final : public flann::ResultSet<float> {
 public:
  explicit KnnResultSet(BestK& best) : best_(best) { update(); }
  bool full() const override { return false; }
  void addPoint(float distance2, size_t index) override {
    best_.offer(static_cast<uint32_t>(index), distance2);
    update();
  }
  float worstDist() const override { return worst_; }

 private:
  void update() { worst_ = std::nextafter(best_.bound2(), std::numeric_limits<float>::infinity()); }
  BestK& best_;
  float worst_ = 0.0f;
};

/// FLANN result set for a fixed radius: every point with distance2 <= radius2 goes to the visitor.
template <class Visit>
class RadiusResultSet final : public flann::ResultSet<float> {
 public:
  RadiusResultSet(float radius2, Visit& visit)
      : radius2_(radius2),
        worst_(std::nextafter(radius2, std::numeric_limits<float>::infinity())),
        visit_(visit) {}
  bool full() const override { return true; }
  void addPoint(float distance2, size_t index) override {
    if (distance2 <= radius2_) visit_(static_cast<uint32_t>(index), distance2);
  }
  float worstDist() const override { return worst_; }

 private:
  float radius2_, worst_;
  Visit& visit_;
};

class KdTree {
 public:
  void build(std::span<const Vec3> positions) {
    if (positions.empty()) return;
    // FLANN keeps row pointers into this matrix but, with reordering, searches only its own copy.
    const flann::Matrix<float> rows(const_cast<float*>(&positions[0].x), positions.size(), 3);
    tree_ = std::make_unique<FlannTree>(rows, flann::KDTreeSingleIndexParams(kLeafSize, /*reorder=*/true));
    tree_->buildIndex();
  }

  void search(const Vec3& query, flann::ResultSet<float>& result) const {
    if (!tree_) return;
    thread_local std::vector<float> axis_distances(3);
    std::fill(axis_distances.begin(), axis_distances.end(), 0.0f);
    const float* q = &query.x;
    const float root_distance2 = ((*tree_).*exposed(InitialDistancesTag{}))(q, axis_distances);
    // FLANN prunes a subtree when its bound × eps_scale exceeds worstDist(). Its bounds are sums
    // updated by adding and subtracting, which can round above the exact value; scaling them down
    // by a few ulps keeps every subtree holding a point at the boundary distance.
    constexpr float kEpsScale = 1.0f - 0x1p-20f;
    ((*tree_).*exposed(SearchLevelTag{}))(result, q, (*tree_).*exposed(RootNodeTag{}), root_distance2,
                                          axis_distances, kEpsScale);
  }

 private:
  static constexpr int kLeafSize = 10;
  std::unique_ptr<FlannTree> tree_;
};

// ---------------------------------------------------------------------------------------------
// Hash grid.

/// Relative float rounding allowance for cell assignment and distance bounds (a few ulps).
constexpr float kRoundoff = 4.0f * std::numeric_limits<float>::epsilon();
/// Mean points per occupied cell that the automatic cell size aims at. On a surface of density ρ
/// the disc holding k = 50 points has r²ρ = 50/π ≈ 16, so cells of about 20 points are about that
/// radius: a k = 50 or an SPPM query of similar size then looks at a 3 × 3 × 3 block of cells.
constexpr float kTargetOccupancy = 20.0f;
constexpr int kCoordinateBits = 21;  // three cell coordinates packed in a 64-bit key
constexpr int64_t kMaxCells = (int64_t{1} << kCoordinateBits) - 2;
constexpr uint64_t kEmptyKey = ~uint64_t{0};

class HashGrid {
 public:
  void build(std::span<const Vec3> positions, float cell_size);
  float cell_size() const { return cell_; }

  /// Calls visit(cell_begin, cell_end) for every occupied cell whose box may hold a point within
  /// sqrt(bound2()) of the query, visiting rings of cells outwards until bound2() is covered.
  template <class Bound, class Visit>
  void rings(const Vec3& query, Bound bound2, Visit visit) const;

  /// Calls visit(index, distance2) for each point with distance2 <= radius2.
  template <class Visit>
  void within(const Vec3& query, float radius2, Visit visit) const;

  /// Scans points [begin, end) of the sorted order, calling visit(index, distance2).
  template <class Visit>
  void scan(const Vec3& query, uint32_t begin, uint32_t end, Visit& visit) const {
    for (uint32_t i = begin; i < end; ++i) visit(ids_[i], distance2(query, points_[i]));
  }

 private:
  struct Slot {
    uint64_t key = kEmptyKey;
    uint32_t begin = 0, end = 0;  // the cell's range in points_ (a count while building)
  };

  size_t home(uint64_t key) const { return static_cast<size_t>((key * 0x9e3779b97f4a7c15ull) >> shift_); }
  int64_t coordinate(float x, int axis) const {
    const auto c = static_cast<int64_t>((x - origin_[axis]) * inv_cell_);
    return std::clamp<int64_t>(c, 0, dims_[axis] - 1);
  }
  uint64_t key_of(const Vec3& p) const {
    return static_cast<uint64_t>(coordinate(p.x, 0)) |
           static_cast<uint64_t>(coordinate(p.y, 1)) << kCoordinateBits |
           static_cast<uint64_t>(coordinate(p.z, 2)) << (2 * kCoordinateBits);
  }
  static uint64_t key_of(int64_t x, int64_t y, int64_t z) {
    return static_cast<uint64_t>(x) | static_cast<uint64_t>(y) << kCoordinateBits |
           static_cast<uint64_t>(z) << (2 * kCoordinateBits);
  }
  const Slot* find(uint64_t key) const {
    for (size_t i = home(key);; i = (i + 1) & mask_) {
      const Slot& slot = table_[i];
      if (slot.key == key) return &slot;
      if (slot.key == kEmptyKey) return nullptr;
    }
  }
  void set_cell_size(float cell, const rc::Bounds3& bounds);
  size_t count_cells(std::span<const Vec3> positions);

  float cell_ = 0.0f, inv_cell_ = 0.0f;
  Vec3 origin_{0.0f};
  int64_t dims_[3] = {1, 1, 1};
  rc::Bounds3 bounds_;
  float margin_ = 0.0f;  // scene units by which rounding may misplace a point relative to its cell
  std::vector<Slot> table_;
  size_t mask_ = 0;
  int shift_ = 64;
  std::vector<Vec3> points_;  // sorted by cell
  std::vector<uint32_t> ids_;
};

void HashGrid::set_cell_size(float cell, const rc::Bounds3& bounds) {
  const Vec3 extent = bounds.diagonal();
  const float largest = std::max({extent.x, extent.y, extent.z});
  // At most kMaxCells per axis, and never so small that (x − origin) / cell loses its meaning.
  cell =
      std::max({cell, largest / static_cast<float>(kMaxCells) * 1.001f, std::numeric_limits<float>::min()});
  cell_ = cell;
  inv_cell_ = 1.0f / cell;
  origin_ = bounds.lo;
  for (int a = 0; a < 3; ++a) {
    dims_[a] = std::clamp<int64_t>(static_cast<int64_t>(extent[a] * inv_cell_) + 1, 1, kMaxCells);
  }
  const Vec3 magnitude = glm::max(rc::abs(bounds.lo), rc::abs(bounds.hi));
  margin_ = kRoundoff * (std::max({magnitude.x, magnitude.y, magnitude.z}) + largest) + 1e-5f * cell;
}

/// Fills the table with the occupied cells and their point counts; returns the number of cells.
size_t HashGrid::count_cells(std::span<const Vec3> positions) {
  size_t capacity = std::bit_ceil(std::max<size_t>(64, positions.size() / 4));
  table_.assign(capacity, Slot{});
  mask_ = capacity - 1;
  shift_ = 64 - std::countr_zero(capacity);
  size_t cells = 0;
  for (const Vec3& p : positions) {
    const uint64_t key = key_of(p);
    size_t i = home(key);
    while (table_[i].key != key && table_[i].key != kEmptyKey) i = (i + 1) & mask_;
    if (table_[i].key == kEmptyKey) {
      table_[i].key = key;
      if (++cells * 2 > capacity) {  // keep the load at most one half: double and reinsert
        std::vector<Slot> old;
        old.swap(table_);
        capacity *= 2;
        table_.assign(capacity, Slot{});
        mask_ = capacity - 1;
        shift_ = 64 - std::countr_zero(capacity);
        for (const Slot& slot : old) {
          if (slot.key == kEmptyKey) continue;
          size_t j = home(slot.key);
          while (table_[j].key != kEmptyKey) j = (j + 1) & mask_;
          table_[j] = slot;
        }
        i = home(key);
        while (table_[i].key != key) i = (i + 1) & mask_;
      }
    }
    ++table_[i].end;
  }
  return cells;
}

void HashGrid::build(std::span<const Vec3> positions, float cell_size) {
  if (positions.empty()) return;
  for (const Vec3& p : positions) bounds_.extend(p);

  if (cell_size > 0.0f) {
    set_cell_size(cell_size, bounds_);
    count_cells(positions);
  } else {
    // Photons lie on surfaces, so guess the cell from the bounding box's surface area, then
    // correct it from the measured occupancy, whose growth with the cell size tells the points'
    // dimension (2 on surfaces, 1 along lines, 3 in volumes).
    const Vec3 e = bounds_.diagonal();
    const auto n = static_cast<float>(positions.size());
    const float area = 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
    const float largest = std::max({e.x, e.y, e.z});
    float cell = area > 0.0f ? std::sqrt(area * kTargetOccupancy / n)
                             : (largest > 0.0f ? largest * kTargetOccupancy / n : 1.0f);
    float previous_cell = 0.0f, previous_occupancy = 0.0f, dimension = 2.0f;
    for (int pass = 0; pass < 3; ++pass) {
      set_cell_size(cell, bounds_);
      const float occupancy = n / static_cast<float>(count_cells(positions));
      if (occupancy > kTargetOccupancy / 1.5f && occupancy < kTargetOccupancy * 1.5f) break;
      if (pass == 2 || cell_ != cell) break;  // out of passes, or clamped by the coordinate range
      if (previous_occupancy > 0.0f && occupancy != previous_occupancy) {
        dimension =
            std::clamp(std::log(occupancy / previous_occupancy) / std::log(cell / previous_cell), 1.0f, 3.0f);
      }
      previous_cell = cell;
      previous_occupancy = occupancy;
      cell *= std::pow(kTargetOccupancy / occupancy, 1.0f / dimension);
    }
  }

  // Counting sort: turn counts into ranges, then place every point in its cell's range.
  uint32_t offset = 0;
  for (Slot& slot : table_) {
    const uint32_t count = slot.end;
    slot.begin = slot.end = offset;
    offset += count;
  }
  points_.resize(positions.size());
  ids_.resize(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    const uint64_t key = key_of(positions[i]);
    size_t s = home(key);
    while (table_[s].key != key) s = (s + 1) & mask_;
    const uint32_t at = table_[s].end++;
    points_[at] = positions[i];
    ids_[at] = static_cast<uint32_t>(i);
  }
}

template <class Bound, class Visit>
void HashGrid::rings(const Vec3& query, Bound bound2, Visit visit) const {
  if (points_.empty()) return;
  // Nothing to find when even the points' bounding box is out of reach.
  const Vec3 gap = glm::max(glm::max(bounds_.lo - query, query - bounds_.hi), Vec3(0.0f));
  if (distance2(gap, Vec3(0.0f)) * (1.0f - kRoundoff) > bound2()) return;

  // The query's cell (unclamped, possibly outside the grid) and its position inside it, in cells.
  int64_t c[3];
  float f[3];
  const Vec3 local = (query - origin_) * inv_cell_;
  for (int a = 0; a < 3; ++a) {
    const float x =
        std::clamp(local[a], -static_cast<float>(kMaxCells) * 2, static_cast<float>(kMaxCells) * 2);
    c[a] = static_cast<int64_t>(std::floor(x));
    f[a] = x - static_cast<float>(c[a]);
  }
  const Vec3 far_from_origin = rc::abs(query - origin_);
  const float margin =
      margin_ + kRoundoff * std::max({far_from_origin.x, far_from_origin.y, far_from_origin.z});
  // Distance (cells) from the query to the nearer face of its own cell, per axis.
  const float inner = std::min({f[0], 1.0f - f[0], f[1], 1.0f - f[1], f[2], 1.0f - f[2]});

  // Rings closer than the grid are empty; past the last one the whole grid has been seen.
  int64_t first = 0, last = 0;
  for (int a = 0; a < 3; ++a) {
    first = std::max({first, -c[a], c[a] - (dims_[a] - 1)});
    last = std::max({last, c[a], dims_[a] - 1 - c[a]});
  }

  // Lower bound of the squared distance from the query to any point of cell offset (dx, dy, dz).
  const float cell2 = cell_ * cell_;
  auto cell_gap2 = [&](int64_t dx, int64_t dy, int64_t dz) {
    const int64_t d[3] = {dx, dy, dz};
    float sum = 0.0f;
    for (int a = 0; a < 3; ++a) {
      const float g = d[a] < 0 ? f[a] + static_cast<float>(-d[a] - 1)
                               : (d[a] > 0 ? 1.0f - f[a] + static_cast<float>(d[a] - 1) : 0.0f);
      sum += g * g;
    }
    const float g = std::max(0.0f, std::sqrt(sum * cell2) - margin);
    return g * g * (1.0f - kRoundoff);
  };
  auto try_cell = [&](int64_t x, int64_t y, int64_t z) {
    if (cell_gap2(x - c[0], y - c[1], z - c[2]) > bound2()) return;
    if (const Slot* slot = find(key_of(x, y, z))) visit(slot->begin, slot->end);
  };

  for (int64_t s = first; s <= last; ++s) {
    const int64_t x0 = std::max<int64_t>(c[0] - s, 0), x1 = std::min(c[0] + s, dims_[0] - 1);
    const int64_t y0 = std::max<int64_t>(c[1] - s, 0), y1 = std::min(c[1] + s, dims_[1] - 1);
    const int64_t z0 = std::max<int64_t>(c[2] - s, 0), z1 = std::min(c[2] + s, dims_[2] - 1);
    for (int64_t z = z0; z <= z1; ++z) {
      const bool z_face = z == c[2] - s || z == c[2] + s;
      for (int64_t y = y0; y <= y1; ++y) {
        if (z_face || y == c[1] - s || y == c[1] + s) {
          for (int64_t x = x0; x <= x1; ++x) try_cell(x, y, z);
        } else {
          if (c[0] - s >= 0) try_cell(c[0] - s, y, z);
          if (s > 0 && c[0] + s < dims_[0]) try_cell(c[0] + s, y, z);
        }
      }
    }
    // Every point not yet seen lies outside the cube of rings 0..s.
    const float covered = std::max(0.0f, (static_cast<float>(s) + inner) * cell_ - margin);
    if (covered * covered * (1.0f - kRoundoff) > bound2()) return;
  }
}

template <class Visit>
void HashGrid::within(const Vec3& query, float radius2, Visit visit) const {
  if (points_.empty() || !(radius2 >= 0.0f)) return;
  const Vec3 far_from_origin = rc::abs(query - origin_);
  const float margin =
      margin_ + kRoundoff * std::max({far_from_origin.x, far_from_origin.y, far_from_origin.z});
  const float reach = std::sqrt(radius2) * (1.0f + kRoundoff) + margin;
  int64_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    const float limit = static_cast<float>(kMaxCells) * 2;
    const float l = std::clamp((query[a] - reach - origin_[a]) * inv_cell_, -limit, limit);
    const float h = std::clamp((query[a] + reach - origin_[a]) * inv_cell_, -limit, limit);
    lo[a] = std::max<int64_t>(static_cast<int64_t>(std::floor(l)), 0);
    hi[a] = std::min<int64_t>(static_cast<int64_t>(std::floor(h)), dims_[a] - 1);
    if (lo[a] > hi[a]) return;
  }
  // Cells of the box that the sphere misses are skipped by their distance to the query.
  const Vec3 local = (query - origin_) * inv_cell_;
  for (int64_t z = lo[2]; z <= hi[2]; ++z) {
    const float gz = std::max({0.0f, static_cast<float>(z) - local.z, local.z - static_cast<float>(z + 1)});
    for (int64_t y = lo[1]; y <= hi[1]; ++y) {
      const float gy = std::max({0.0f, static_cast<float>(y) - local.y, local.y - static_cast<float>(y + 1)});
      for (int64_t x = lo[0]; x <= hi[0]; ++x) {
        const float gx =
            std::max({0.0f, static_cast<float>(x) - local.x, local.x - static_cast<float>(x + 1)});
        const float g = std::max(0.0f, std::sqrt(gx * gx + gy * gy + gz * gz) * cell_ - margin);
        if (g * g * (1.0f - kRoundoff) > radius2) continue;
        if (const Slot* slot = find(key_of(x, y, z))) {
          for (uint32_t i = slot->begin; i < slot->end; ++i) {
            const float d2 = distance2(query, points_[i]);
            if (d2 <= radius2) visit(ids_[i], d2);
          }
        }
      }
    }
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------

struct PhotonIndex::Impl {
  IndexKind kind = IndexKind::kd_tree;
  size_t size = 0;
  KdTree kd_tree;
  HashGrid hash_grid;
};

PhotonIndex::PhotonIndex(std::span<const Vec3> positions, IndexKind kind, float hash_cell_size)
    : impl_(std::make_unique<Impl>()) {
  if (positions.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    throw std::length_error("PhotonIndex: more than 2^31 - 1 points");
  }
  impl_->kind = kind;
  impl_->size = positions.size();
  switch (kind) {
    case IndexKind::kd_tree:
      impl_->kd_tree.build(positions);
      break;
    case IndexKind::hash_grid:
      impl_->hash_grid.build(positions, hash_cell_size);
      break;
  }
}

PhotonIndex::PhotonIndex() = default;
PhotonIndex::~PhotonIndex() = default;
PhotonIndex::PhotonIndex(PhotonIndex&&) noexcept = default;
PhotonIndex& PhotonIndex::operator=(PhotonIndex&&) noexcept = default;

size_t PhotonIndex::size() const { return impl_ ? impl_->size : 0; }
IndexKind PhotonIndex::kind() const { return impl_ ? impl_->kind : IndexKind::kd_tree; }
float PhotonIndex::cell_size() const {
  return impl_ && impl_->kind == IndexKind::hash_grid ? impl_->hash_grid.cell_size() : 0.0f;
}

size_t PhotonIndex::knn(const Vec3& query, size_t k, float max_distance2, Neighbour* out) const {
  if (!impl_ || impl_->size == 0 || k == 0 || !(max_distance2 >= 0.0f)) return 0;
  BestK best(out, k, max_distance2);
  switch (impl_->kind) {
    case IndexKind::kd_tree: {
      KnnResultSet result(best);
      impl_->kd_tree.search(query, result);
      break;
    }
    case IndexKind::hash_grid: {
      const HashGrid& grid = impl_->hash_grid;
      auto offer = [&best](uint32_t index, float d2) { best.offer(index, d2); };
      grid.rings(
          query, [&best] { return best.bound2(); },
          [&](uint32_t begin, uint32_t end) { grid.scan(query, begin, end, offer); });
      break;
    }
  }
  return best.finish();
}

void PhotonIndex::visit_within(const Vec3& query, float radius2, Visitor visitor, void* context) const {
  if (!impl_ || impl_->size == 0 || !(radius2 >= 0.0f)) return;
  auto visit = [visitor, context](uint32_t index, float d2) { visitor(context, Neighbour{index, d2}); };
  switch (impl_->kind) {
    case IndexKind::kd_tree: {
      RadiusResultSet<decltype(visit)> result(radius2, visit);
      impl_->kd_tree.search(query, result);
      break;
    }
    case IndexKind::hash_grid:
      impl_->hash_grid.within(query, radius2, visit);
      break;
  }
}

}  // namespace gilt::photonmap

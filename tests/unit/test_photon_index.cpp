// The photon index against its brute-force twin, a linear scan: both kinds (FLANN kd-tree, hash
// grid) must return exactly the scan's k nearest (distances bit for bit, ties resolved by index)
// and exactly the scan's set within a radius, on uniform, planar (many exact ties), clustered and
// degenerate point sets. Queries must not allocate, checked by counting calls to the global
// operator new, replaced in this file. The octahedral direction code is held to its stated bound.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "photonmap/photon.h"
#include "photonmap/photon_index.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/rng.h"

// ---------------------------------------------------------------------------------------------
// Counting global allocation functions (every replaceable form that allocates).

namespace {
std::atomic<size_t> g_allocations{0};

void* counted_allocation(std::size_t size, std::size_t alignment) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (size == 0) size = 1;
  void* p = alignment > alignof(std::max_align_t)
                ? std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment)
                : std::malloc(size);
  return p;
}
// Out of line so that GCC, inlining the replaced operator delete, does not pair free() with new.
[[gnu::noinline]] void counted_free(void* p) noexcept { std::free(p); }
}  // namespace

void* operator new(std::size_t size) {
  if (void* p = counted_allocation(size, 0)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  if (void* p = counted_allocation(size, 0)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, std::align_val_t alignment) {
  if (void* p = counted_allocation(size, static_cast<std::size_t>(alignment))) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t alignment) {
  if (void* p = counted_allocation(size, static_cast<std::size_t>(alignment))) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return counted_allocation(size, 0); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return counted_allocation(size, 0); }
void operator delete(void* p) noexcept { counted_free(p); }
void operator delete[](void* p) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { counted_free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { counted_free(p); }

namespace {

namespace pm = gilt::photonmap;
namespace rc = gilt::raytrace_core;
using pm::IndexKind;
using pm::Neighbour;
using pm::PhotonIndex;
using rc::Vec3;

constexpr float kInf = std::numeric_limits<float>::infinity();

// ---------------------------------------------------------------------------------------------
// Point sets. Sizes keep the whole file near a second in Release and a few under ASan.

constexpr size_t kPoints = 6000;
constexpr int kQueries = 150;

Vec3 uniform3(rc::util::Rng& rng) { return {rng.uniform(), rng.uniform(), rng.uniform()}; }

/// Uniform in the unit cube.
std::vector<Vec3> cube_points(size_t n, uint64_t seed) {
  rc::util::Rng rng(seed);
  std::vector<Vec3> points(n);
  for (Vec3& p : points) p = uniform3(rng);
  return points;
}

/// The floor, back wall and two side walls of a unit room: every point lies exactly on one of
/// four planes, half of them on a regular lattice (so many distances tie exactly).
std::vector<Vec3> room_points(size_t n, uint64_t seed) {
  rc::util::Rng rng(seed);
  std::vector<Vec3> points(n);
  for (size_t i = 0; i < n; ++i) {
    float u = rng.uniform(), v = rng.uniform();
    if (i % 2 == 0) {  // lattice of spacing 1/32
      u = std::floor(u * 32.0f) / 32.0f;
      v = std::floor(v * 32.0f) / 32.0f;
    }
    switch (i % 4) {
      case 0:
        points[i] = {u, 0.0f, v};
        break;
      case 1:
        points[i] = {u, v, 0.0f};
        break;
      case 2:
        points[i] = {0.0f, u, v};
        break;
      default:
        points[i] = {1.0f, u, v};
        break;
    }
  }
  return points;
}

/// A caustic: half of the points in a small dense blob (σ = 0.005) on the floor, the rest sparse
/// over a 4 × 4 × 4 box.
std::vector<Vec3> clustered_points(size_t n, uint64_t seed) {
  rc::util::Rng rng(seed);
  std::vector<Vec3> points(n);
  for (size_t i = 0; i < n; ++i) {
    if (i % 2 == 0) {
      // Box–Muller for a Gaussian disc on the floor plane y = 0.
      const float r = 0.005f * std::sqrt(-2.0f * std::log(1.0f - rng.uniform()));
      const float phi = 2.0f * rc::kPi * rng.uniform();
      points[i] = {1.3f + r * std::cos(phi), 0.0f, 0.7f + r * std::sin(phi)};
    } else {
      points[i] = 4.0f * uniform3(rng);
    }
  }
  return points;
}

/// Queries: random points around the set's bounds, points of the set itself, and far outside.
std::vector<Vec3> queries_for(const std::vector<Vec3>& points, uint64_t seed) {
  rc::util::Rng rng(seed);
  rc::Bounds3 bounds;
  for (const Vec3& p : points) bounds.extend(p);
  std::vector<Vec3> queries;
  for (int i = 0; i < kQueries; ++i) {
    switch (i % 5) {
      case 0:
      case 1:
        queries.push_back(bounds.lo + uniform3(rng) * bounds.diagonal());
        break;
      case 2:
        queries.push_back(points[rng.next_u32() % points.size()]);
        break;
      case 3:
        queries.push_back(points[rng.next_u32() % points.size()] + 1e-3f * (uniform3(rng) - 0.5f));
        break;
      default:
        queries.push_back(bounds.center() + (2.0f + uniform3(rng)) * bounds.diagonal());
        break;
    }
  }
  return queries;
}

// ---------------------------------------------------------------------------------------------
// Brute-force twin.

/// Every point with its squared distance to the query, sorted by closer().
std::vector<Neighbour> scan_sorted(const std::vector<Vec3>& points, const Vec3& query) {
  std::vector<Neighbour> all(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    all[i] = {static_cast<uint32_t>(i), pm::distance2(query, points[i])};
  }
  std::sort(all.begin(), all.end(), pm::closer);
  return all;
}

std::vector<Neighbour> scan_knn(const std::vector<Neighbour>& sorted, size_t k, float max_distance2) {
  std::vector<Neighbour> result;
  for (const Neighbour& n : sorted) {
    if (result.size() == k || !(n.distance2 <= max_distance2)) break;
    result.push_back(n);
  }
  return result;
}

std::vector<Neighbour> scan_within(const std::vector<Neighbour>& sorted, float radius2) {
  std::vector<Neighbour> result;
  for (const Neighbour& n : sorted) {
    if (!(n.distance2 <= radius2)) break;
    result.push_back(n);
  }
  std::sort(result.begin(), result.end(),
            [](const Neighbour& a, const Neighbour& b) { return a.index < b.index; });
  return result;
}

std::vector<Neighbour> index_knn(const PhotonIndex& index, const Vec3& query, size_t k, float max_distance2) {
  std::vector<Neighbour> out(k);
  out.resize(index.knn(query, k, max_distance2, out.data()));
  return out;
}

std::vector<Neighbour> index_within(const PhotonIndex& index, const Vec3& query, float radius2) {
  std::vector<Neighbour> out;
  index.for_each_within(query, radius2, [&](Neighbour n) { out.push_back(n); });
  std::sort(out.begin(), out.end(), [](const Neighbour& a, const Neighbour& b) { return a.index < b.index; });
  return out;
}

/// Empty string when equal, else the first difference.
std::string difference(const std::vector<Neighbour>& got, const std::vector<Neighbour>& want) {
  if (got.size() != want.size()) {
    return "count " + std::to_string(got.size()) + " instead of " + std::to_string(want.size());
  }
  for (size_t i = 0; i < got.size(); ++i) {
    if (got[i].index != want[i].index || got[i].distance2 != want[i].distance2) {
      return "entry " + std::to_string(i) + ": index " + std::to_string(got[i].index) + " d2 " +
             std::to_string(got[i].distance2) + " instead of " + std::to_string(want[i].index) + " d2 " +
             std::to_string(want[i].distance2);
    }
  }
  return {};
}

struct Variant {
  const char* name;
  IndexKind kind;
  float cell_scale;  // hash grid: cell size relative to the automatic one (1: automatic)
};
// The grid is also tried with cells far smaller and far larger than it would choose.
const Variant kVariants[] = {{"kd_tree", IndexKind::kd_tree, 1.0f},
                             {"hash_grid", IndexKind::hash_grid, 1.0f},
                             {"hash_grid_small_cells", IndexKind::hash_grid, 0.1f},
                             {"hash_grid_large_cells", IndexKind::hash_grid, 20.0f}};

PhotonIndex make_index(const std::vector<Vec3>& points, const Variant& variant) {
  if (variant.kind == IndexKind::hash_grid && variant.cell_scale != 1.0f) {
    const PhotonIndex automatic(points, IndexKind::hash_grid);
    return PhotonIndex(points, IndexKind::hash_grid, automatic.cell_size() * variant.cell_scale);
  }
  return PhotonIndex(points, variant.kind);
}

/// Compares every variant with the scan for k ∈ {1, 8, 50} × radius caps, and fixed radii.
void expect_matches_scan(const std::vector<Vec3>& points, uint64_t seed) {
  const std::vector<Vec3> queries = queries_for(points, seed);
  rc::Bounds3 bounds;
  for (const Vec3& p : points) bounds.extend(p);
  const float scale = std::max(bounds.radius(), 1e-3f);
  const float radii2[] = {0.0f, rc::sqr(0.01f * scale), rc::sqr(0.05f * scale), kInf};

  std::vector<std::vector<Neighbour>> scans;
  for (const Vec3& query : queries) scans.push_back(scan_sorted(points, query));

  for (const Variant& variant : kVariants) {
    SCOPED_TRACE(variant.name);
    const PhotonIndex index = make_index(points, variant);
    ASSERT_EQ(index.size(), points.size());
    ASSERT_EQ(index.kind(), variant.kind);
    for (size_t q = 0; q < queries.size(); ++q) {
      const std::vector<Neighbour>& sorted = scans[q];
      for (size_t k : {size_t{1}, size_t{8}, size_t{50}}) {
        for (float max2 : radii2) {
          const std::string diff =
              difference(index_knn(index, queries[q], k, max2), scan_knn(sorted, k, max2));
          ASSERT_TRUE(diff.empty()) << "knn query " << q << " k " << k << " max_distance2 " << max2 << ": "
                                    << diff;
        }
      }
      for (float radius2 : radii2) {
        if (radius2 == kInf) continue;
        const std::string diff =
            difference(index_within(index, queries[q], radius2), scan_within(sorted, radius2));
        ASSERT_TRUE(diff.empty()) << "within query " << q << " radius2 " << radius2 << ": " << diff;
      }
    }
  }
}

TEST(PhotonIndex, UniformCubeMatchesScan) { expect_matches_scan(cube_points(kPoints, 1), 11); }

TEST(PhotonIndex, CoplanarRoomSurfacesMatchScan) { expect_matches_scan(room_points(kPoints, 2), 12); }

TEST(PhotonIndex, ClusteredCausticMatchesScan) { expect_matches_scan(clustered_points(kPoints, 3), 13); }

TEST(PhotonIndex, RoomIsFullOfTies) {
  // The coplanar set is there for its ties: make sure it has them (else the test above proves less).
  const std::vector<Vec3> points = room_points(kPoints, 2);
  const std::vector<Neighbour> sorted = scan_sorted(points, points[0]);
  size_t ties = 0;
  for (size_t i = 1; i < 50; ++i) ties += sorted[i].distance2 == sorted[i - 1].distance2;
  EXPECT_GE(ties, 10u);
}

TEST(PhotonIndex, EmptyIndexFindsNothing) {
  const std::vector<Vec3> none;
  const PhotonIndex defaulted;
  EXPECT_EQ(defaulted.size(), 0u);
  Neighbour out[4];
  EXPECT_EQ(defaulted.knn(Vec3(0.0f), 4, kInf, out), 0u);
  for (const Variant& variant : kVariants) {
    const PhotonIndex index(none, variant.kind);
    EXPECT_EQ(index.size(), 0u);
    EXPECT_EQ(index.knn(Vec3(0.0f), 4, kInf, out), 0u);
    int visits = 0;
    index.for_each_within(Vec3(0.0f), kInf, [&](Neighbour) { ++visits; });
    EXPECT_EQ(visits, 0);
  }
}

TEST(PhotonIndex, DegenerateSetsMatchScan) {
  const std::vector<std::vector<Vec3>> sets = {
      {Vec3(0.5f, -2.0f, 3.0f)},                                                             // one point
      std::vector<Vec3>(500, Vec3(1.0f, 2.0f, 3.0f)),                                        // all identical
      {Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f), Vec3(2.0f, 0.0f, 0.0f), Vec3(3.0f, 0.0f, 0.0f)},  // a line
      cube_points(37, 4),  // fewer points than k
  };
  for (size_t s = 0; s < sets.size(); ++s) {
    SCOPED_TRACE("set " + std::to_string(s));
    const std::vector<Vec3>& points = sets[s];
    std::vector<Vec3> queries = {points[0], points.back(), Vec3(1.0f, 2.0f, 3.5f), Vec3(-100.0f, 50.0f, 0.0f),
                                 0.5f * (points[0] + points.back())};
    for (const Variant& variant : kVariants) {
      SCOPED_TRACE(variant.name);
      const PhotonIndex index = make_index(points, variant);
      for (const Vec3& query : queries) {
        const std::vector<Neighbour> sorted = scan_sorted(points, query);
        for (size_t k : {size_t{0}, size_t{1}, size_t{3}, size_t{50}, size_t{1000}}) {
          for (float max2 : {0.0f, 0.25f, kInf}) {
            EXPECT_EQ(difference(index_knn(index, query, k, max2), scan_knn(sorted, k, max2)), "")
                << "k " << k << " max_distance2 " << max2;
          }
        }
        for (float radius2 : {0.0f, 0.25f, 1e6f}) {
          EXPECT_EQ(difference(index_within(index, query, radius2), scan_within(sorted, radius2)), "")
              << "radius2 " << radius2;
        }
      }
    }
  }
}

TEST(PhotonIndex, RadiusZeroFindsOnlyCoincidentPoints) {
  std::vector<Vec3> points = cube_points(1000, 5);
  points.push_back(points[10]);
  for (const Variant& variant : kVariants) {
    SCOPED_TRACE(variant.name);
    const PhotonIndex index = make_index(points, variant);
    Neighbour out[8];
    ASSERT_EQ(index.knn(points[10], 8, 0.0f, out), 2u);
    EXPECT_EQ(out[0].index, 10u);
    EXPECT_EQ(out[1].index, 1000u);
    EXPECT_EQ(out[0].distance2, 0.0f);
    EXPECT_EQ(index.knn(points[10] + Vec3(1e-4f, 0.0f, 0.0f), 8, 0.0f, out), 0u);
    EXPECT_EQ(index.knn(points[10], 8, -1.0f, out), 0u);  // a negative cap admits nothing
  }
}

TEST(PhotonIndex, ParallelQueriesMatchSerialOnes) {
  const std::vector<Vec3> points = clustered_points(kPoints, 6);
  const std::vector<Vec3> queries = queries_for(points, 16);
  constexpr size_t k = 20;
  for (const Variant& variant : kVariants) {
    SCOPED_TRACE(variant.name);
    const PhotonIndex index = make_index(points, variant);
    std::vector<Neighbour> parallel(queries.size() * k), serial(queries.size() * k);
    std::vector<size_t> parallel_count(queries.size()), serial_count(queries.size());
    rc::util::parallel_for(queries.size(),
                     [&](size_t q) { parallel_count[q] = index.knn(queries[q], k, kInf, &parallel[q * k]); });
    for (size_t q = 0; q < queries.size(); ++q)
      serial_count[q] = index.knn(queries[q], k, kInf, &serial[q * k]);
    ASSERT_EQ(parallel_count, serial_count);
    for (size_t i = 0; i < serial.size(); ++i) {
      ASSERT_EQ(parallel[i].index, serial[i].index);
      ASSERT_EQ(parallel[i].distance2, serial[i].distance2);
    }
  }
}

TEST(PhotonIndex, QueriesDoNotAllocate) {
  const std::vector<Vec3> points = clustered_points(kPoints, 7);
  const std::vector<Vec3> queries = queries_for(points, 17);
  Neighbour out[50];
  for (const Variant& variant : kVariants) {
    SCOPED_TRACE(variant.name);
    const PhotonIndex index = make_index(points, variant);
    // Warm-up: the kd-tree's per-thread scratch is made on the first query of a thread.
    size_t checksum = index.knn(queries[0], 50, kInf, out);
    index.for_each_within(queries[0], 0.01f, [&](Neighbour n) { checksum += n.index; });

    const size_t before = g_allocations.load();
    for (const Vec3& query : queries) {
      checksum += index.knn(query, 50, kInf, out);
      checksum += index.knn(query, 50, 0.001f, out);
      index.for_each_within(query, 0.01f, [&](Neighbour n) { checksum += n.index; });
    }
    const size_t allocations = g_allocations.load() - before;
    EXPECT_EQ(allocations, 0u) << "checksum " << checksum;
  }
}

TEST(PhotonIndex, AllocationCounterCounts) {
  // The replacement operator new is the one in use (else the test above proves nothing).
  const size_t before = g_allocations.load();
  void* p = ::operator new(24);
  ::operator delete(p);
  EXPECT_EQ(g_allocations.load() - before, 1u);
}

// ---------------------------------------------------------------------------------------------
// Octahedral directions.

double angle_between(const Vec3& a, const Vec3& b) {
  const glm::dvec3 x(a), y(b);
  return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y));
}

TEST(DirectionEncoding, AxesRoundTripExactly) {
  const Vec3 axes[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const Vec3& axis : axes) {
    const Vec3 decoded = pm::decode_direction(pm::encode_direction(axis));
    EXPECT_EQ(decoded, axis) << axis.x << " " << axis.y << " " << axis.z;
  }
  // −0 components fold like +0 ones.
  EXPECT_EQ(pm::decode_direction(pm::encode_direction(Vec3(-0.0f, -0.0f, -1.0f))), Vec3(0, 0, -1));
  EXPECT_EQ(pm::decode_direction(pm::encode_direction(Vec3(0.0f))), Vec3(0, 0, 1));  // no direction: +z
}

TEST(DirectionEncoding, RoundTripErrorBelowStatedBound) {
  rc::util::Rng rng(99);
  double worst = 0.0;
  auto check = [&](Vec3 v) {
    v = glm::normalize(v);
    const Vec3 decoded = pm::decode_direction(pm::encode_direction(v));
    ASSERT_NEAR(glm::length(decoded), 1.0f, 1e-6f);
    worst = std::max(worst, angle_between(v, decoded));
  };
  // Octant diagonals, the middle of each octahedron face where the code is coarsest, and the
  // seams of the fold (z = 0 and the diagonals of the lower hemisphere).
  for (int s = 0; s < 8; ++s) check(Vec3(s & 1 ? -1 : 1, s & 2 ? -1 : 1, s & 4 ? -1 : 1));
  for (int i = 0; i < 2000; ++i) {
    const float phi = 2.0f * rc::kPi * rng.uniform();
    check(Vec3(std::cos(phi), std::sin(phi), 0.0f));
    check(Vec3(std::cos(phi), std::sin(phi), -1e-4f));
  }
  // Uniform on the sphere.
  for (int i = 0; i < 200000; ++i) {
    const float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * rc::kPi * rng.uniform();
    const float r = rc::safe_sqrt(1.0f - z * z);
    check(Vec3(r * std::cos(phi), r * std::sin(phi), z));
  }
  RecordProperty("max_angular_error_radians", std::to_string(worst));
  EXPECT_LT(worst, pm::kDirectionEncodingMaxError);
  // The bound is not loose by orders of magnitude: the measured error reaches most of it.
  EXPECT_GT(worst, 0.5 * pm::kDirectionEncodingMaxError);
}

TEST(DirectionEncoding, PhotonIsThirtyTwoBytes) {
  pm::Photon photon{Vec3(1, 2, 3), rc::Rgb(0.5f), pm::encode_direction(Vec3(0, 1, 0)),
                    pm::encode_direction(Vec3(0, 0, -1))};
  EXPECT_EQ(sizeof photon, 32u);
  EXPECT_EQ(pm::decode_direction(photon.direction), Vec3(0, 1, 0));
  EXPECT_EQ(pm::decode_direction(photon.normal), Vec3(0, 0, -1));
}

}  // namespace

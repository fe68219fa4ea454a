#pragma once
// How much of a density estimate's disk lies on surface that can hold its photons.
//
// A k-nearest estimate divides the kernel-weighted power of the photons in a ball by the
// kernel's integral over a full flat disk. Past an open edge, into a corner or on a thin part
// the ball holds less such surface than that disk, and the estimate comes out dark there: the
// boundary bias of kernel density estimates (Silverman 1986). The coverage is the same kernel's
// integral over the surface the ball does hold: the sides of the scene's triangles on which the
// map stored photons, turned within the estimate's normal test of the query's normal. Dividing
// by it makes the estimate unbiased wherever the photon density is constant over the ball,
// whatever the shape of the surface in it.
//
// The photon mapper's global map applies it over every triangle side (every_side); SPPM has a
// stochastic coverage of its own (photonmap/sppm.cpp). See bench/README.md, "The photon
// method's biases", for what it changed on Šibenik.

#include <cstdint>
#include <vector>

#include "raytrace_core/scene/scene.h"

namespace gilt::photonmap {

namespace rc = gilt::raytrace_core;

/// Which sides of a scene's triangles a photon map stored photons on: a count per side, two per
/// triangle (front: the side the geometric normal (b − a) × (c − a) faces).
class SurfaceSides {
 public:
  SurfaceSides() = default;
  explicit SurfaceSides(const rc::scene::Scene& scene);

  bool empty() const { return counts_.empty(); }
  /// Records one photon stored on triangle prim_id of mesh geom_id, on the side its normal (the
  /// stored photon normal, facing where the photon came from) lies. Thread-safe.
  void add(const rc::scene::Scene& scene, uint32_t geom_id, uint32_t prim_id, const rc::Vec3& normal);
  /// Whether any photon was stored on that side.
  bool holds(uint32_t geom_id, uint32_t prim_id, bool front) const {
    return counts_[2 * (size_t(first_[geom_id]) + prim_id) + (front ? 0 : 1)] > 0;
  }
  /// The counts, for joining those of several processes (element-wise sum).
  std::vector<uint64_t>& counts() { return counts_; }
  /// Index of triangle prim_id of mesh geom_id's front side in counts() (its back: one more).
  size_t side_index(uint32_t geom_id, uint32_t prim_id) const { return 2 * (size_t(first_[geom_id]) + prim_id); }

 private:
  std::vector<uint64_t> first_;   ///< flat index of each mesh's first triangle
  std::vector<uint64_t> counts_;  ///< photons per triangle side
};

/// Every side of every triangle of the scene, counted as holding photons: the coverage the
/// photon mapper divides by. On Šibenik open_sides reaches 99.6 % of the sides, and this is the
/// same to that; where it counts a side that faces into a closed solid, a disk reaching it is
/// divided by too much and reads dark.
SurfaceSides every_side(const rc::scene::Scene& scene);

/// The triangle sides light from outside the scene can reach: a side that one of `rays`
/// cosine-distributed rays, from points spread over it, sees the sky from, and any side that
/// one of its rays meets a reached side from. Winding does not enter (a ray reaches whichever
/// side faces it), so surfaces modelled inside out do not fool it; sides facing into closed
/// solids are not reached. Unlike the sides a map's photons happened to reach, it does not
/// leave out small triangles no photon hit by chance. A scene lit only from inside (a closed
/// room with a lamp) reaches no side: give such scenes every side.
SurfaceSides open_sides(const rc::scene::Scene& scene, int rays = 8);

/// The kernel 2 / (π r²) · (1 − d² / r²) integrated over the triangle sides within distance
/// √r2 of p that hold photons and face within `min_cosine` of the unit normal n: 1 for a full
/// flat disk, less at an edge or in a corner, more where folded surface crowds the ball. Returns
/// 0 when no such side reaches the ball, and -1 when a sphere that can hold photons does (the
/// coverage is then unknown).
double disk_coverage(const rc::scene::Scene& scene, const SurfaceSides& sides, const rc::Vec3& p,
                     const rc::Vec3& n, float r2, float min_cosine);

/// ∫ (1 − |y − p|² / r2)⁺ dA(y) over the triangle abc, in closed form (unnormalised: a full
/// flat disk through p gives π r2 / 2).
double kernel_integral(const rc::Vec3& a, const rc::Vec3& b, const rc::Vec3& c, const rc::Vec3& p, float r2);

}  // namespace gilt::photonmap

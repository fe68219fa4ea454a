#pragma once
// Hierarchical radiosity with clustering for the light reflected between diffuse surfaces:
// links between element clusters at the level an error oracle accepts (Hanrahan, Salzman &
// Aupperle 1991), clusters over whole surfaces so that linking starts from one root pair rather
// than every pair of patches (Smits, Arvo & Greenberg 1994; Sillion 1995), gathering with
// push–pull, and a final gather at the mesh vertices (Lischinski, Tampieri & Greenberg 1993).
// The direct light (punctual lights, sky, emitting elements) is computed by the caller with
// shadow rays at every vertex; this pass adds what it leaves out: every later bounce.

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "radiosity/mesh/mesh.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::radiosity::solver {

using rc::Rgb;
using rc::Vec3;

/// The link tolerance for solutions whose vertices are the answer (exports, the mesh view).
inline constexpr double kDefaultLinkTolerance = 2e-6;

/// Whether the vertex final gather runs.
enum class FinalGather {
  automatic,  ///< when a probe of its cost predicts at most kGatherRayShare times the links' rays
  always,
  never,      ///< for a view that gathers per pixel, or when asked
};

/// Parameters of the hierarchical pass; the defaults are the documented defaults.
struct HierarchicalSettings {
  /// A link is accepted when the power it may carry wrongly is below this fraction of the
  /// scene's reflected power (the BF·A oracle, with the point-source error (size/distance)²).
  /// 0 takes the default of the use: kDefaultLinkTolerance, or a two-pass view's own
  /// (solver_settings_for in radiosity/bake/view.h).
  double link_tolerance = 0.0;
  /// The scene-wide bound is loose where little light arrives: a link into a dim or small
  /// receiver may carry much of its light wrongly and still pass. With a share s > 0 a link is
  /// also held below link_tolerance times its receiver's own reflected power over s: the
  /// scene-wide bound holds for receivers with at least s of the scene's power, and one with
  /// less is bounded relative to its own. 0 (the default) drops the receiver's bound, for solves
  /// whose vertex final gather bounds each vertex by its own light (gather_tolerance); the
  /// two-pass view, which reads the links' light without one, takes kTwoPassReceiverShare
  /// (radiosity/bake/view.h).
  double receiver_share = 0.0;
  /// A cluster stands in for its elements in the vertex final gather when the irradiance it may
  /// carry wrongly is below this fraction of the local indirect irradiance.
  double gather_tolerance = 0.02;
  int link_rays = 4;        ///< shadow rays per link (between random points of the two ends)
  double tolerance = 1e-3;  ///< stop iterating when the solution changes by less than this (relative)
  int max_iterations = 200;
  /// Gather at every vertex from the hierarchy at the end (see FinalGather); without it, a
  /// vertex takes the area-weighted mean of its elements' gathered irradiance.
  FinalGather final_gather = FinalGather::automatic;
  uint64_t seed = 0;
  bool progress = false;  ///< report linking, iterating and the final gather on stderr (rc::util::Progress)
  bool keep_closure =
      false;  ///< keep each element's closure (HierarchicalResult::element_closure; diagnostics)
};

/// How many points each vertex's visibility rays start from (see visibility_origins in solver.h).
inline constexpr size_t kVisibilityOrigins = 4;

/// What the pass needs to know of the scene: the mesh, the scene its visibility rays are traced
/// against (element_scene()), where each vertex receives, each element's reflectance and each
/// vertex's direct irradiance.
struct HierarchicalInput {
  const mesh::RadiosityMesh& mesh;
  const rc::scene::Scene& geometry;
  std::span<const rc::scene::SurfacePoint>
      vertex_point;  ///< per vertex: receiver point (see receiver_points)
  std::span<const rc::scene::SurfacePoint> visibility_origin;  ///< kVisibilityOrigins per vertex (see visibility_origins)
  std::span<const Rgb> albedo;                     ///< per element
  std::span<const Rgb> direct_irradiance;          ///< per vertex, W·m⁻²
  /// Whether a segment between the two boxes' contents may be blocked at all (false: no rays).
  std::function<bool(const rc::Bounds3&)> may_be_blocked;
  /// Called between steps; returning true stops the pass early (the result is then partial).
  std::function<bool()> out_of_time;
  /// Seconds left of a time limit; empty when there is none. With it the links are made coarse
  /// first and refined while the time allows (see solve_hierarchical).
  std::function<double()> seconds_left;
  /// Per element: the mean direct irradiance over it, which it reflects into the scene. Empty:
  /// the mean of its vertices' `direct_irradiance`.
  std::span<const Rgb> element_direct = {};
};

/// One level of a timed solve's ladder of link tolerances (see solve_hierarchical).
struct LadderLevel {
  double link_tolerance = 0.0;
  size_t open_pairs = 0;  ///< the last level's pairs this one refined (1: the root pair)
  size_t splits = 0;      ///< of those, the ones it split rather than accepted again
  size_t links = 0;
  double link_seconds = 0.0;  ///< linking, and ordering the links by receiver
  int iterations = 0;         ///< gathers to the level's own tolerance
  int finishing_iterations = 0;  ///< gathers on to the solve's tolerance where the ladder stopped here
  double first_residual = 0.0, residual = 0.0;  ///< after the first gather and the last
  double iterate_seconds = 0.0;  ///< bounding the gains and iterating
};

/// The reflected (indirect) irradiance at every vertex, and what it took.
struct HierarchicalResult {
  std::vector<Rgb> vertex_irradiance;  ///< indirect only, W·m⁻²
  size_t nodes = 0, links = 0;
  int iterations = 0;
  double residual = 0.0;  ///< relative change of the last iteration
  bool tail_added = false;  ///< whether the iteration's geometric tail was added (see solve_hierarchical)
  double chebyshev_beta = 0.0;  ///< the bound on the iteration's spectrum Chebyshev's steps used (0: none)
  size_t clamped_elements = 0;  ///< elements whose links promised more light than they can reflect (scaled down)
  /// Per element, with HierarchicalSettings::keep_closure: the channel mean of the irradiance its
  /// links gather from a unit radiosity everywhere, Σ F over what it sees. In a closed scene it is
  /// 1 for every element; below 1 the links lose light there, above 1 they promise too much.
  std::vector<float> element_closure;
  uint64_t shadow_rays = 0, form_factors = 0;
  uint64_t gather_nodes = 0;  ///< clusters and elements the vertex final gather evaluated
  bool final_gather = true;   ///< false when it did not run to the end (vertices then take their elements' mean)
  std::string final_gather_note;  ///< how it ran, or why not ("at every vertex", "skipped: ...")
  uint64_t final_gather_predicted_rays = 0;  ///< what its probe predicted for every vertex
  double link_tolerance = 0.0;  ///< the tolerance of the links used (coarser than asked when time ran short)
  bool linking_stopped = false; ///< time ran out while linking at link_tolerance / 10 (or at all)
  uint64_t link_rays = 0;       ///< shadow rays traced while linking
  double link_seconds = 0.0, iterate_seconds = 0.0, gather_seconds = 0.0;  ///< tree and links; iterations; final gather
  std::vector<LadderLevel> ladder;  ///< the levels linked, coarsest first (one without a time limit)
};

/// Direct irradiance at vertices first_vertex.. from elements that emit `emitted` radiosity
/// (W·m⁻², per element), by the final gather's walk down a tree of the elements, with `rays`
/// shadow rays per node in a penumbra (a probe of up to 4 first). Earlier vertices get 0.
/// `in.direct_irradiance` is not used. Adds the rays traced to *shadow_rays.
std::vector<Rgb> emitted_irradiance(const HierarchicalInput& in, std::span<const Rgb> emitted,
                                    size_t first_vertex, const HierarchicalSettings& settings, int rays,
                                    uint64_t* shadow_rays);

/// Solves the interreflection above the given direct light: links, iterates to `tolerance`,
/// then gathers at every vertex from the cluster hierarchy.
HierarchicalResult solve_hierarchical(const HierarchicalInput& in, const HierarchicalSettings& settings);

}  // namespace gilt::radiosity::solver

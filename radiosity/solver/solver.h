#pragma once
// Progressive-refinement radiosity (Cohen, Chen, Wallace & Greenberg 1988) with receiver-vertex
// to source-element form factors (Wallace, Elmquist & Haines 1989): the patch (a few adjacent
// elements of one surface) with the most unshot power shoots to every vertex; each element's
// unoccluded form factor is analytic (Lambert), the visible fraction of the patch comes from
// shadow rays to stratified points on it.

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <string>

#include "radiosity/mesh/mesh.h"
#include "radiosity/solver/hierarchical.h"
#include "raytrace_core/util/progress.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::radiosity::solver {

using rc::Rgb;

/// How the light reflected between surfaces is solved (the direct light is gathered at every
/// vertex by shadow rays either way).
enum class SolverKind {
  automatic,     ///< chosen by the element count (see choose_solver)
  progressive,   ///< progressive refinement: every patch shoots to every vertex, O(n²)
  hierarchical,  ///< hierarchical radiosity with clustering and a vertex final gather, about O(n log n)
};

/// "auto", "progressive" or "hierarchical".
const char* to_string(SolverKind kind);

/// At and above this many elements `automatic` picks the hierarchical solver.
inline constexpr size_t kHierarchicalElements = 20000;

/// Share of --time after which imprinting and remeshing stop (pieces not yet imprinted keep their
/// input triangles, pieces not yet remeshed their imprinted ones): meshing is preparation, and
/// the solve needs the rest.
inline constexpr double kMeshShare = 0.2;

/// Solver parameters; the defaults are the documented defaults.
struct SolverSettings {
  SolverKind solver = SolverKind::automatic;
  HierarchicalSettings hierarchical;  ///< its tolerance and seed are taken from the fields below
  mesh::MeshSettings mesh;
  double tolerance = 1e-3;   ///< stop when unshot power < tolerance × emitted power
  double time_limit = 0.0;   ///< seconds for the whole solve, meshing included (0 = no limit); imprinting
                             ///< and remeshing stop after kMeshShare of it, refinement after 30 %, and no shot
                             ///< starts that would end past it less the time kept back (below)
  /// Under time_limit: seconds of it kept back for what the caller does after the solve (writing
  /// the export), after_seconds plus after_seconds_per_element per element of the final mesh (see
  /// seconds_kept_back). The solve stops that much before its limit; without a limit, unused.
  double after_seconds = 0.0;
  double after_seconds_per_element = 0.0;
  int visibility_samples = 16;  ///< shadow rays per vertex–patch pair in a penumbra (a quarter in
                                ///< each quarter of the source); pairs a 4-ray probe finds all open or all blocked take 4
  int reflected_visibility_probe = 1;  ///< probe side (rays = side²) for patches that only reflect light
  int patch_elements = 16;             ///< elements per shooting patch (1: every element shoots alone)
  int subdivision_levels = 2;          ///< adaptive subdivision may halve the mesh's edge this many times
  double subdivision_threshold = 0.6;  ///< bisect an element whose vertices' direct irradiance spreads by more
                                       ///< than this fraction of the brightest
  /// Progressive refinement stopped before its tolerance gathers its unshot light for a display's
  /// ambient term (Solution::vertex_ambient; solver_settings_for in radiosity/bake/view.h sets it).
  /// Exports never show the ambient term, so they leave the time to the shots.
  bool gather_ambient = false;
  uint64_t seed = 0;
  int threads = 0;           ///< 0 = all
  bool progress = true;
};

/// The solution on the mesh. Radiance is what the path tracer sees: L = B / π for a Lambertian
/// surface, in W·sr⁻¹·m⁻².
struct Solution {
  mesh::RadiosityMesh mesh;
  std::vector<Rgb> vertex_radiosity;   ///< B (W·m⁻²): emitted + reflected, leaving the front
  std::vector<Rgb> vertex_irradiance;  ///< E (W·m⁻²) arriving at the front
  std::vector<Rgb> vertex_direct;      ///< the part of E straight from the lights and emitting surfaces
  std::vector<Rgb> vertex_punctual;    ///< the part of E straight from point, spot and directional lights
  std::vector<Rgb> element_radiosity;  ///< mean of the element's vertices (exported per face)
  std::vector<Rgb> element_albedo;     ///< reflectance, textured materials' mean over the element
  std::vector<Rgb> vertex_albedo;      ///< area-weighted mean of the vertex's elements' reflectance
  /// Per element: the mean over it of E straight from the lights (stratified points) and the
  /// emitting surfaces (its vertices' mean); what it reflects into the scene. Both solvers.
  std::vector<Rgb> element_direct;

  // What the solve did.
  SolverKind solver = SolverKind::progressive;  ///< the one that ran
  std::string solver_reason;                    ///< why it was chosen
  uint64_t shots = 0;            ///< patches shot
  size_t patches = 0;            ///< shooting patches the elements were grouped into
  size_t refined_elements = 0;   ///< elements bisected by adaptive subdivision
  uint64_t form_factors = 0;     ///< vertex–element form factors evaluated
  uint64_t shadow_rays = 0;
  uint64_t skipped_pairs = 0;    ///< vertex–patch pairs whose visibility the scene proved without rays
  size_t nodes = 0, links = 0;   ///< hierarchical: clusters and elements in the tree, links between them
  int iterations = 0;            ///< hierarchical: gathering iterations
  uint64_t gather_nodes = 0;     ///< hierarchical: nodes the vertex final gather evaluated
  bool final_gather = false;     ///< hierarchical: the vertex final gather ran to the end
  std::string final_gather_note; ///< hierarchical: how the final gather ran, or why it did not
  double link_tolerance = 0.0;   ///< hierarchical: the tolerance of the links used
  bool linking_stopped = false;  ///< hierarchical: time ran out while linking finer
  /// hierarchical under a time limit: no level of links fitted, so the reflected light was shot
  /// by progressive refinement for the time left instead (`shots`, `residual`)
  bool shot_without_links = false;
  int element_direct_samples =
      0;  ///< hierarchical: samples per element and light of the elements' direct light
  double residual = 0.0;         ///< progressive: unshot power / emitted power at the end;
                                 ///< hierarchical: relative change of the last iteration
  bool tail_added = false;       ///< hierarchical: the iteration's geometric tail was added
  double chebyshev_beta = 0.0;   ///< hierarchical: the spectral bound of Chebyshev's iteration (0: plain Jacobi)
  std::vector<LadderLevel> ladder;  ///< hierarchical: the link tolerances a timed solve went through
  std::vector<float>
      element_closure;  ///< hierarchical, with hierarchical.keep_closure: HierarchicalResult::element_closure
  /// Ambient radiosity (W·m⁻²) standing in for the light not yet shot, for displaying a partial
  /// solution only (Cohen, Chen, Wallace & Greenberg 1988): the area-weighted mean unshot
  /// radiosity times the interreflection factor 1 / (1 − ρ̄). Never part of exported values.
  Rgb ambient{0.0f};
  /// Progressive, stopped before its tolerance: the ambient term gathered where the unshot light
  /// lands (ambient_gather.h), irradiance (W·m⁻²) per vertex, which displays use in place of
  /// `ambient`; empty otherwise. Never part of exported values.
  std::vector<Rgb> vertex_ambient;
  double ambient_escaped = 0.0;  ///< the share of the ambient gather's rays that met no surface
  double seconds = 0.0;
  double seconds_kept_back = 0.0;  ///< of the time limit, for what follows the solve (see SolverSettings::after_seconds)
  /// Where the time went: meshing, the direct light with adaptive subdivision, and the
  /// interreflection (hierarchical: linking, iterating, the final gather; progressive: shooting).
  double mesh_seconds = 0.0, direct_seconds = 0.0, link_seconds = 0.0, iterate_seconds = 0.0, gather_seconds = 0.0,
         shoot_seconds = 0.0;
  bool convex_enclosure = false; ///< nothing can occlude (an empty convex room): no visibility rays at all
  mesh::MeshReport mesh_report;

  /// Radiance at vertex v (W·sr⁻¹·m⁻²).
  Rgb vertex_radiance(size_t v) const { return vertex_radiosity[v] * (1.0f / 3.14159265358979f); }
};

/// Where each vertex of the mesh receives light: just inside one of its elements and in front of
/// the mesh's other elements (see solver.cpp). `geometry` is element_scene() of the mesh, whose
/// rays place the points. Advances `progress` (if any) by one per vertex.
std::vector<Vec3> receiver_points(const rc::scene::Scene& geometry, const mesh::RadiosityMesh& mesh,
                                  rc::util::Progress* progress = nullptr);

/// Where each vertex's visibility rays start: kVisibilityOrigins points per vertex (vertex v's at
/// [v · kVisibilityOrigins, (v + 1) · kVisibilityOrigins)), towards the centroids of elements
/// spread around its fan, half as far as the nearest centroid, just above those elements and in
/// front of the mesh around them (the receiver point of receiver_points stands in where none is). A vertex
/// colour stands for the surface around the vertex, and a ray from the vertex alone decides on a line: on
/// Šibenik, vertices where a moulding meets a wall saw every light through the wall's edge and came out black
/// while the surface on either side was lit. Advances `progress` (if any) by one per vertex.
std::vector<rc::scene::SurfacePoint> visibility_origins(const rc::scene::Scene& geometry,
                                                        const mesh::RadiosityMesh& mesh,
                                                        std::span<const Vec3> receivers,
                                                        rc::util::Progress* progress = nullptr);

/// The solver `settings` asks for on a mesh of `elements` elements, and why.
SolverKind choose_solver(const SolverSettings& settings, size_t elements, std::string* why = nullptr);

/// Seconds of settings.time_limit a solve on a mesh of `elements` elements keeps back for what
/// follows it: after_seconds + after_seconds_per_element × elements (0 without a time limit).
double seconds_kept_back(const SolverSettings& settings, size_t elements);

/// Meshes and solves the committed scene.
Solution solve(const rc::scene::Scene& scene, const SolverSettings& settings);

/// What solve() will do on a scene, found by meshing it without solving.
struct SolvePlan {
  size_t elements = 0, vertices = 0;  ///< before adaptive subdivision
  size_t contact_edges = 0;           ///< see MeshReport
  size_t buried_faces = 0;            ///< input faces removed before remeshing (see MeshReport)
  size_t buried_elements = 0;         ///< flat elements removed after it (see MeshReport)
  double buried_area = 0.0;           ///< their area, scene units²
  double meshed_area = 0.0;           ///< area of the meshed input surfaces, scene units²
  float max_edge = 0.0f;
  bool convex_enclosure = false;      ///< nothing can occlude: no visibility rays at all
  size_t occluder_boxes = 0;          ///< boxes that shadow rays are tested against first
  size_t punctual_lights = 0;         ///< point, spot, directional and environment lights, shot unmeshed
  size_t specular_surfaces = 0;       ///< meshes and spheres left to ray tracing (mirror, glass)
  SolverKind solver = SolverKind::progressive;  ///< what `automatic` resolves to here
  std::string solver_reason;
  std::vector<std::pair<std::string, double>> mesh_stage_seconds;  ///< see MeshReport::stage_seconds
};
SolvePlan plan_solve(const rc::scene::Scene& scene, const SolverSettings& settings);

}  // namespace gilt::radiosity::solver

#pragma once
// Object-space check of a radiosity solution: the irradiance at a sample of its vertices against
// independent path-traced estimates at the same points, with the estimates' own noise, so a
// reader knows which differences the check can resolve.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "radiosity/solver/solver.h"

namespace gilt::radiosity::bake {

/// How many vertices to check and how hard.
struct CheckSettings {
  int points = 64;        ///< vertices checked, spread evenly over the vertex list
  int samples = 4096;     ///< cosine-distributed path-traced samples per vertex
  uint64_t seed = 0;

  /// Throws rc::InputError naming the field when a value is out of range.
  void validate() const;
};

/// One vertex of the element check, as `gilt radiosity --check N --check-points FILE` writes it.
struct VertexCheckPoint {
  uint32_t vertex = 0;         ///< index in the exported element mesh
  Vec3 position{0.0f};
  Vec3 normal{0.0f};
  float disk_radius = 0.0f;    ///< the disk of input surface the reference averages over
  Rgb reference{0.0f};         ///< path-traced irradiance over the disk
  Rgb standard_error{0.0f};    ///< of `reference`
  Rgb solved{0.0f};            ///< the solution's (or its final gather's) irradiance at the vertex
};

/// The check's findings, over the checked vertices and the three channels. The mean relative
/// error divides by the reference plus 1 % of its mean, and a few nearly dark vertices still
/// rule it; the relative mean absolute error weighs every vertex by its light.
struct CheckResult {
  size_t points = 0;                 ///< vertices compared
  double mean_relative_error = 0.0;  ///< mean |E_solution − E_path| / (E_path + 0.01 Ē_path)
  double relative_mean_absolute_error = 0.0;  ///< Σ |E_solution − E_path| / Σ E_path: not ruled by dark vertices
  double reference_noise = 0.0;      ///< the same mean of the estimates' standard errors (noise and the
                                     ///< surface's variation within each disk)
  double seconds = 0.0;
  std::vector<VertexCheckPoint> compared;  ///< the vertices compared, in vertex order
};

/// Compares the solution's vertex irradiance with path-traced irradiance averaged over the input
/// surface around each vertex (a disk half as wide as the distance to its nearest element
/// centroid, seen along the vertex normal, with a white Lambertian standing in for the surface
/// where each path starts; see check.cpp). A vertex is left out when fewer than two of the path
/// tracer's views land on its material. Each
/// vertex's estimate draws from its own random stream, so the result is the same for any thread
/// count.
CheckResult check_against_path_tracer(const rc::scene::Scene& scene, const solver::Solution& solution, const CheckSettings& settings);

struct InputColours;  // radiosity/bake/onto_input.h

/// One point of a surface check, as `gilt radiosity --check-points` writes it: enough to score
/// another bake (Blender's, an older gilt's) against the same path-traced reference.
struct SurfaceCheckPoint {
  uint32_t mesh = 0;              ///< scene mesh
  uint32_t triangle = 0;          ///< its triangle
  uint32_t file_vertex[3] = {};   ///< the corners as the input file numbers them (OBJ `v` line from 0, PLY
                                  ///< vertex, glTF primitive vertex)
  float weight[3] = {};           ///< barycentric weights of the corners
  Vec3 position{0.0f};
  Rgb albedo{0.0f};
  Rgb reference{0.0f};            ///< path-traced irradiance
  Rgb standard_error{0.0f};       ///< of `reference`
  Rgb baked{0.0f};                ///< the bake's irradiance
};

/// How a bake (colours on the input's vertices, a lightmap, the exported elements) compares with
/// the path tracer at random points inside the input's faces, over the compared points and the
/// three channels; every figure is 0 when no point was compared.
struct SurfaceCheckResult {
  size_t points = 0;           ///< points compared
  size_t unlit = 0;            ///< points left out: on buried faces, or no path-traced sample found light
  /// Points whose baked value was found, of those that are neither buried nor unlit: the ones
  /// compared, so always `points`. Only the element check can miss one (no exported face within
  /// reach, see check_element_colours), counted in `uncovered`; the input and lightmap checks
  /// read their bake on the very face drawn from, and leave `uncovered` at 0.
  size_t covered = 0;
  size_t uncovered = 0;        ///< points the check would have compared but the bake has no value for
  double relative_mse = 0.0;   ///< mean (E_baked − E_path)² / (E_path² + (0.01 Ē_path)²)
  double reference_share = 0.0;  ///< what the estimates' own variance adds to it (same mean of se²)
  double mean_relative_error = 0.0;  ///< mean |E_baked − E_path| / (E_path + 0.01 Ē_path)
  double mean_ratio = 0.0;           ///< Σ E_baked / Σ E_path: the bake's bias in brightness (1 = none)
  double seconds = 0.0;
  std::vector<SurfaceCheckPoint> compared;  ///< the points compared, in drawing order

  /// covered / (covered + uncovered), 0 when both are 0.
  double covered_share() const;
};

/// Writes `result.compared` as CSV with a header line (atomically); throws rc::InputError when
/// the file cannot be written.
void write_check_points(const std::string& path, const rc::scene::Scene& scene,
                        const SurfaceCheckResult& result);
/// The same for the element check: one line per compared vertex (index, position, normal, disk
/// radius, reference with its standard error, solved irradiance).
void write_check_points(const std::string& path, const CheckResult& result);

/// Draws `settings.points` points uniformly by area over the faces that `irradiance` (an
/// InputColours fitted with Quantity::irradiance) covers, from `settings.seed`, and compares
/// the interpolated colours with path-traced irradiance there: the path tracer looks straight
/// down the face normal at the point, at a white, unlit Lambertian standing in for the surface
/// there, E = π L, `settings.samples` samples per point. Mirrors and glass are not drawn from,
/// and a point with something lying on it (the path tracer's ray hits another surface) is left out,
/// and so is a buried point (input_triangle_buried for its face, which the fit leaves out, or
/// input_point_buried for the point: inside a closed solid or under an object) or one no
/// path-traced sample brings any light to: no one sees their colour. A point is compared on the
/// side `side` names, or without it on its face's front, or its back where no light reaches the
/// front.
/// `side`, when given, names the side the bake read at each point (SolutionAtInput::side: its
/// arguments the point and its face's unit normal as wound, its result that normal or its
/// negation), and the point is compared there.
using BakedSide = std::function<Vec3(const Vec3& p, const Vec3& face_normal)>;
SurfaceCheckResult check_input_colours(const rc::scene::Scene& scene, const InputColours& irradiance,
                                       const CheckSettings& settings, const BakedSide& side = {});

struct Lightmap;  // radiosity/bake/lightmap.h

/// The same check for a lightmap of irradiance (`--lightmap`): the baked value at each point is
/// the atlas read bilinearly at the point's UV, as a viewer reads it.
SurfaceCheckResult check_lightmap(const rc::scene::Scene& scene, const Lightmap& irradiance,
                                  const CheckSettings& settings, const BakedSide& side = {});

/// The same check for gilt's element mesh as exported (`--onto elements`), at the same random
/// points inside the input's faces, drawn over every input mesh the mesher meshes (mirrors and
/// glass aside). `exported` is the mesh write_solution writes (the solution's mesh
/// snapped_to_input, then without_coincident) and `vertex_irradiance` its irradiance per vertex
/// (Solution::vertex_irradiance: without_coincident keeps the vertex numbering). A point's value
/// is read from the nearest exported element within 10⁻⁴ of the scene's bounding-box diagonal
/// that faces the way the point's side does (geometric normals within 2.5°; each point is
/// compared on one side of its face, front or back at random, as the export has an element on
/// every side light reaches), interpolated
/// barycentrically at the point of the element nearest to it, found by a point query of a BVH
/// over the elements (O(log n) a point). A point with no such element is counted in `uncovered`
/// and left out of the figures: on a flat input, a share below 1 is a hole in the export, or a
/// side light reaches that has no element. Throws std::logic_error when vertex_irradiance does not match the
/// mesh.
SurfaceCheckResult check_element_colours(const rc::scene::Scene& scene, const mesh::RadiosityMesh& exported,
                                         const std::vector<Rgb>& vertex_irradiance,
                                         const CheckSettings& settings);

}  // namespace gilt::radiosity::bake

#pragma once
// Vertex colours for a triangle mesh that are to show a field known over its faces, once a
// viewer interpolates them linearly across each face (Gouraud). Two ways:
// - least squares (Kavan, Bargteil & Sloan 2011, "Least Squares Vertex Baking"): the colours
//   whose interpolation is nearest the field in L² over the faces' area, with a small smoothness
//   term so that vertices with little area around them stay defined;
// - a point sample of the field at each vertex, which is what a vertex bake in most tools does
//   (Blender's "Bake to Color Attribute" among them). On coarse meshes, whose triangles are
//   larger than the light's detail, it shows whatever the vertex happens to see: a vertex in a
//   shadow blackens a whole floor.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "radiosity/bake/vertex_split.h"
#include "raytrace_core/util/math.h"
#include "raytrace_core/util/progress.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::radiosity {
namespace rc = gilt::raytrace_core;
}  // namespace gilt::radiosity

namespace gilt::radiosity::bake {

using rc::Rgb;
using rc::Vec3;

/// How vertex colours are fitted.
enum class VertexFit : uint8_t {
  least_squares,  ///< L² fit of the interpolated colours to the field over the faces (default)
  point,          ///< the field at each vertex
};

/// "least-squares" or "point".
const char* to_string(VertexFit fit);

/// The field at surface point p of face `face` (its index in the index list, divided by three),
/// whose front has unit normal n; nothing where it is unknown (such points do not count in the
/// fit). At a vertex (point fit) `face` is one of the vertex's faces. Called from several
/// threads at once.
using SurfaceField = std::function<std::optional<Rgb>(const Vec3& p, const Vec3& n, size_t face)>;

/// Weight of the smoothness term against the fit: the squared colour difference along each edge
/// of a face counts kFitSmoothness times a third of the face's area. Small enough that a sharp
/// change across one face is kept (tested), large enough that a vertex whose faces have no
/// samples, or are slivers, takes its neighbours' colour instead of an arbitrary one.
inline constexpr double kFitSmoothness = 1e-3;

/// A face is cut into at most this many parts per edge for the least-squares quadrature.
inline constexpr int kMaxFitSplit = 48;

/// What fitting did.
struct FitStats {
  uint64_t samples = 0;          ///< field evaluations
  uint64_t missing = 0;          ///< of which found no value
  int iterations = 0;            ///< conjugate-gradient iterations (largest of the three channels)
};

/// Colours for `positions` (the mesh's vertices, in the field's space) whose triangles are
/// `indices` (three per face, counter-clockwise seen from the front). Least squares samples each
/// face at the centroids of a regular split into parts whose edges are at most `spacing` (at
/// least 2, at most kMaxFitSplit per edge). Colours are never negative: the fit's overshoot at a
/// sharp change is clamped. Vertices no face uses are black.
/// Advances `progress` (if any) by one per face sampled (per vertex for VertexFit::point).
std::vector<Rgb> fit_vertex_colours(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                                    const SurfaceField& field, VertexFit fit, float spacing,
                                    FitStats* stats = nullptr, rc::util::Progress* progress = nullptr);

/// Where a split fit (fit_split_colours) gives the faces around a vertex colours of their own.
struct SplitRules {
  /// Faces whose normals are further apart than this cosine (30°, the mesher's crease) do not
  /// share: a floor meeting a wall sees different light.
  float crease_cos = 0.8660254f;
  /// Faces of different keys do not share (their materials: radiance and radiosity jump with the
  /// albedo). Empty: one key.
  std::span<const uint32_t> face_key;
  /// Nor do two faces whose own fits (each face's best linear colour, alone) jump across their
  /// edge by at least kLightEdgeRatio at both its ends, the same way: a shadow line along an
  /// edge. Least squares only; a point fit has no face fits to compare.
  bool light_edges = true;
};

/// The jump in colour (the sum of its channels) across an edge that splits it as a shadow line:
/// twice as bright on one side as on the other, at both ends. Past that a shared colour is a
/// visible compromise on both faces; below it, the faces' own fits are too noisy to tell (with a
/// final gather) and splitting shows the noise as seams. Colours within 1 % of the mesh's mean
/// colour of zero count as that 1 % (a dark corner is not a shadow line).
inline constexpr float kLightEdgeRatio = 2.0f;

/// As fit_vertex_colours, with the vertices split into `wedges` (vertex_split.h) by `rules`: one
/// colour per wedge, fitted over the wedge's faces, with no smoothness term across a split. For
/// an output whose vertices can be split (glTF); the least-squares quadrature is the same.
std::vector<Rgb> fit_split_colours(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                                   const SurfaceField& field, VertexFit fit, float spacing,
                                   const SplitRules& rules, Wedges& wedges, FitStats* stats = nullptr,
                                   rc::util::Progress* progress = nullptr);

}  // namespace gilt::radiosity::bake

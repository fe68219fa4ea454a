#pragma once
// A radiosity solution written onto the user's own model (`gilt radiosity --onto input`): the
// model file the scene was read from comes back with its structure, geometry and everything
// else as it was, plus one colour per vertex fitted to the solution over its faces
// (radiosity/bake/vertex_fit.h). The other export (radiosity/bake/export.h) writes gilt's element mesh.
//
// glTF (.gltf or .glb in, either out): every primitive the solution covers gets
//   COLOR_0     float VEC3, the quantity × 2^exposure clamped to [0, 1] (display-referred
//               linear, as the glTF specification requires of COLOR_0; viewers multiply the
//               material's base colour by it);
//   _RADIANCE, _IRRADIANCE or _RADIOSITY  float VEC3, the quantity itself (HDR);
// nodes, meshes, primitives, materials, textures, animations, skins and extensions are kept, and
// so are the accessors and buffers the input had, byte for byte. A mesh placed by several nodes
// is split, one copy per node, since each instance is lit differently (Blender's bake does the
// same). A .glb output stands alone: the input's buffers and images that live in files beside it
// move into its binary chunk. A .gltf output keeps them where they are, its relative URIs
// rewritten to reach the same files from the output's folder, and its new data go in a .bin
// beside it, named after it.
//
// OBJ in, OBJ out: every line as it was, `v` lines with a colour after the position's own text
// (radiosity/bake/onto_obj.cpp). PLY in, PLY out: every element and property as it was, with colour
// properties added to the vertices (radiosity/bake/onto_ply.cpp).

#include <atomic>
#include <chrono>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "radiosity/bake/export.h"
#include "radiosity/solver/solver.h"
#include "radiosity/bake/vertex_fit.h"
#include "radiosity/bake/view.h"

namespace gilt::radiosity::bake {

/// A bake's final gather (SolutionAtInput).
/// Under a time limit, points reached after `deadline` read the solution instead, and are
/// counted as such: the bake is then complete but only partly gathered.
struct BakeGather {
  int rays = 0;       ///< samples per point (one shadow ray and one gather ray each); 0: read the solution
  uint64_t seed = 0;
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  bool progress = false;  ///< report the bake's long loops on stderr (rc::util::Progress)
};

/// Points a bake evaluated, by how.
struct BakeGatherCount {
  uint64_t gathered = 0;  ///< traced from the point
  uint64_t late = 0;      ///< read from the solution because the deadline had passed
};

/// Points a bake evaluated, by the side of the surface they read (see SolutionAtInput).
struct BakeSides {
  uint64_t points = 0;  ///< points an element stands for
  uint64_t back =
      0;  ///< read from an element facing against the face's winding (light reaches only its back)
  /// Lit on both sides, by irradiances that differ by more than kSidesDiffer times: the bake
  /// carries the front's, and the face's back shows the wrong light.
  uint64_t differ = 0;
};

/// Irradiances whose ratio exceeds this are "different" sides (BakeSides::differ).
inline constexpr float kSidesDiffer = 2.0f;

/// Which vertices a bake onto the input model colours.
enum class InputVertices : uint8_t {
  as_read,  ///< the file's own: OBJ `v` lines, PLY vertices, glTF primitives' vertices
  file,     ///< an OBJ's or PLY's own vertices, written as glTF: one colour per file vertex
  split,    ///< welded by position, then split where the light jumps across an edge (glTF out)
};

/// Colours for the vertices of the meshes read from one model file.
struct InputColours {
  int32_t file = -1;                        ///< index into Scene::model_files
  /// glTF: per scene mesh (one per primitive placed by a node), one per vertex, or one per wedge
  /// when `wedges` splits its vertices; empty: not baked.
  std::vector<std::vector<Rgb>> per_mesh;
  /// A split bake (fit_input_colours with `split`; any glTF output): per scene mesh, its vertices
  /// split into wedges where the light jumps across an edge (vertex_split.h); the wedges'
  /// vertices are the mesh's own. Empty: no split.
  std::vector<Wedges> wedges;
  size_t welded_vertices = 0;  ///< a split bake's positions over the whole file (file: its vertices)
  /// Vertices the glTF output holds for the baked meshes (each mesh's vertices and its wedges).
  size_t written_vertices() const {
    size_t n = 0;
    for (const std::vector<Rgb>& c : per_mesh) n += c.size();
    return n;
  }
  /// OBJ and PLY: one per vertex of the file (its `v` lines, its vertex element), fitted over the
  /// faces of every material at once, since the file has one colour per vertex.
  std::vector<Rgb> per_file_vertex;
  FitStats stats;
  /// The colour at corner `corner` (an index into its index list) of scene mesh m.
  Rgb at_corner(const rc::scene::Scene& scene, size_t m, size_t corner) const;
  /// Whether scene mesh m was baked.
  bool covers(size_t m) const;
  BakeGatherCount gather;   ///< with a final gather: how its points were evaluated
  BakeSides sides;          ///< which side of the surface its points read
  size_t buried_faces = 0;  ///< input faces left out of the fit: inside closed solids or under objects
  double seconds = 0.0;
};

/// The model file `--onto input` writes onto: the scene's only model file. Throws InputError
/// when the scene was not read from one, or from several.
int32_t onto_input_file(const rc::scene::Scene& scene);

/// The solution's `quantity` at a point of the input model: irradiance read from the nearest
/// element facing the same way (RadiosityView::locate), with the direct light of point, spot and
/// directional lights replaced by its own shadow ray from the point, turned into the quantity by
/// the point's material (B = π·Le + ρ·E, L = B/π). Nothing where no element is near. Safe to call
/// from several threads at once; scene and solution must outlive it.
///
/// With a final gather (`gather.rays` > 0), the irradiance is instead traced from the point
/// (RadiosityView::gathered_irradiance): every light by shadow rays, and the light other surfaces
/// reflect by gather rays that read the solution where they land. Each point draws from its own
/// random stream, keyed by its coordinates and gather.seed, so the bake is the same for any
/// thread count.
class SolutionAtInput {
 public:
  SolutionAtInput(const rc::scene::Scene& scene, const solver::Solution& solution, Quantity quantity, BakeGather gather = {});
  std::optional<Rgb> operator()(const rc::scene::Material& m, const Vec3& p, const Vec3& n) const;
  BakeGatherCount gather_count() const { return {gathered_.load(), late_.load()}; }
  BakeSides sides_count() const { return {points_.load(), back_.load(), differ_.load()}; }
  /// The side of the input face at p, with unit normal `face_normal` as wound, that a bake
  /// reads there: `face_normal` or its negation (see choose() in onto_input.cpp).
  Vec3 side(const Vec3& p, const Vec3& face_normal) const;

 private:
  /// Which element a point reads, on which side (see choose()).
  struct Side {
    std::optional<RadiosityView::Location> at, other;  ///< the element read; the one on the other side
    Vec3 normal{0.0f};                                 ///< the side read
    bool back = false;                                 ///< against the face's winding
    bool both = false;                                 ///< an element lies on the point on each side
  };
  Side choose(const Vec3& p, const Vec3& face_normal) const;

 public:
 private:
  Rgb gathered(const Vec3& p, const Vec3& n) const;
  Rgb read(const RadiosityView::Location& at, const Vec3& p, const Vec3& n) const;

  const rc::scene::Scene& scene_;
  const solver::Solution& solution_;
  RadiosityView view_;
  Quantity quantity_;
  BakeGather gather_;
  mutable std::atomic<uint64_t> gathered_{0}, late_{0};
  mutable std::atomic<uint64_t> points_{0}, back_{0}, differ_{0};
  std::vector<const rc::scene::Light*> delta_lights_;
  bool exact_direct_ = false;
};

/// For each face of `indices` (three per face): 1 when the mesher's burial test finds it inside a
/// closed solid or under an object standing on it (input_triangle_buried). Bakes leave those out:
/// no one sees them, and the nearest element facing their way belongs to another surface. (On
/// Šibenik such points made 98 % of the check's squared error.)
std::vector<char> input_faces_buried(const rc::scene::Scene& scene, std::span<const Vec3> positions,
                                     std::span<const uint32_t> indices);

/// Fits the solution's `quantity` onto the vertices of every non-specular mesh read from the
/// model file (onto_input_file), by `fit` over the faces, at a quadrature spacing of half the
/// solution's target edge. Each point's irradiance E is turned into the quantity by its face's
/// material (B = π·Le + ρ·E, L = B/π) before fitting, so a vertex shared by two materials gets
/// the colour nearest both.
///
/// With InputVertices::split (a glTF output), every mesh of the file is fitted at once, its
/// vertices welded where their positions are equal, then split into wedges by
/// fit_split_colours (creases, materials, shadow lines along edges); with ::file, at once over
/// the file's own vertices. Colours go in per_mesh and wedges.
InputColours fit_input_colours(const rc::scene::Scene& scene, const solver::Solution& solution, VertexFit fit,
                               Quantity quantity, BakeGather gather = {},
                               InputVertices vertices = InputVertices::as_read);

/// The vertices `--onto input` gives colours for, writing `output` (`keep`: --keep-vertices):
/// glTF, whose index lists let one position carry several colours, splits them, unless kept;
/// kept, a glTF input keeps its own, and an OBJ or PLY one its file's (InputVertices::file).
/// OBJ and PLY outputs keep the file's own.
InputVertices input_vertices(const std::string& output, const rc::scene::Scene& scene, bool keep);

/// cos 30°: the mesher splits vertices at creases sharper than 30° (MeshSettings), so a point of
/// the input under a vertex belongs to the vertex's side when its normal is within 30° of the vertex's.
inline constexpr float kSameSideOfCrease = 0.8660254f;

/// Per vertex of the element mesh: half the distance to the nearest centroid of its elements, the
/// radius of the patch of surface its colour stands for.
std::vector<float> vertex_disk_radius(const mesh::RadiosityMesh& mesh);

/// The point of the input surface under vertex v, displaced by `offset` in its tangent plane: the
/// first input face a ray straight down the vertex normal meets, from `radius` above to `radius`
/// below, when it has the vertex's material and faces its side of any crease (the face's front or
/// back, whichever the ray meets: the side of the returned point, whose normals face the ray's
/// origin). With the ray.
struct InputPoint {
  rc::scene::Ray ray;
  rc::scene::SurfaceInteraction si;
};
std::optional<InputPoint> input_surface_under(const rc::scene::Scene& scene, const mesh::RadiosityMesh& mesh, size_t v,
                                              const Vec3& offset, float radius);

/// `gilt radiosity --onto elements --bake-gather N`: the solution with each vertex's irradiance the
/// mean of N samples (RadiosityView::gathered_sample: one shadow ray, one gather ray), each from
/// its own point of the input under the vertex's disk (vertex_disk_radius, input_surface_under)
/// at that input face's normal, and its radiosity and the element means recomputed from it; past
/// gather.deadline a vertex keeps the solve's value and counts as late. On a scan the
/// remeshed surface's smoothed normals and coarser silhouette move shadows and facing; the gather
/// sees the input itself. Vertices with no input surface under them keep the solve's value;
/// vertex_direct and vertex_punctual stay the solve's. For exports and checks, not for a view.
solver::Solution gather_at_vertices(const rc::scene::Scene& scene, const solver::Solution& solution, BakeGather gather,
                            BakeGatherCount* count = nullptr);

/// Throws InputError unless write_onto_input can write `path` for the scene: called before
/// solving, so a mistyped output does not cost a solve.
void check_onto_output(const std::string& path, const rc::scene::Scene& scene);

/// Writes the model file with the colours added; the format follows the output's extension and
/// must be the input's (.gltf and .glb are interchangeable). Throws InputError for a format
/// that does not match, or an output that would overwrite an input file.
void write_onto_input(const std::string& path, const rc::scene::Scene& scene, const InputColours& colours,
                      const ExportSettings& settings);

/// OBJ writer behind write_onto_input (radiosity/bake/onto_obj.cpp): `v x y z r g b`, the quantity
/// × 2^exposure clamped to [0, 1] and sRGB-encoded (to_srgb): display values, which Blender's
/// OBJ importer decodes to linear and MeshLab shows as they are (OBJ has no place for the HDR
/// values).
void write_onto_obj(const std::string& input, const std::string& output, const InputColours& colours,
                    const ExportSettings& settings);

/// PLY writer behind write_onto_input (radiosity/bake/onto_ply.cpp): the input's own format, with
/// uchar red/green/blue (8-bit sRGB after exposure) and float <quantity>_red/_green/_blue added
/// to the vertex element.
void write_onto_ply(const std::string& input, const std::string& output, const InputColours& colours,
                    const ExportSettings& settings);

/// glTF writer behind write_onto_input (radiosity/bake/onto_gltf.cpp).
void write_onto_gltf(const std::string& input, const std::string& output, const rc::scene::Scene& scene,
                     const InputColours& colours, const ExportSettings& settings);

}  // namespace gilt::radiosity::bake

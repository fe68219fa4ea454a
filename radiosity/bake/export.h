#pragma once
// Writing a radiosity solution as a mesh with one colour per vertex, for game engines, Blender
// and MeshLab. Files are written atomically (temporary file, then rename).

#include <cstdint>
#include <string>

#include "radiosity/solver/solver.h"

namespace gilt::radiosity::bake {

/// Which per-vertex value becomes the colour.
enum class Quantity : uint8_t {
  radiance,    ///< outgoing radiance L (W·sr⁻¹·m⁻²): what the path tracer shows (default)
  irradiance,  ///< incident irradiance E (W·m⁻²)
  radiosity,   ///< radiosity B (W·m⁻²)
};

/// Export options.
struct ExportSettings {
  Quantity quantity = Quantity::radiance;
  /// PLY: only the 8-bit sRGB colours, without the float quantity beside them.
  bool srgb8 = false;
  /// PLY and OBJ: the quantity itself as linear float colours, unclamped (gilt's convention
  /// before display colours became the default; no viewer shows these as meant).
  bool linear_float = false;
  /// Display colours (PLY and OBJ by default, glTF COLOR_0) show the quantity × 2^exposure.
  float exposure = 0.0f;
  bool progress = false;  ///< report snapping the vertices onto the input on stderr (rc::util::Progress)
};

/// Linear value to a display value: scaled, clamped to [0, 1], sRGB-encoded (IEC 61966-2-1).
float to_srgb(float linear, float scale);

/// to_srgb as an 8-bit code, rounded.
uint8_t to_srgb8(float linear, float scale);

/// Appends " x" with nine significant digits, which bring every float back exactly even through
/// a parser that rounds slightly off; std::to_chars ignores the locale, unlike printf.
void append_float(std::string& out, float x);

/// "radiance", "irradiance" or "radiosity".
const char* to_string(Quantity quantity);

/// The glTF attribute that holds the quantity itself (HDR, float VEC3) beside the clamped COLOR_0:
/// "_RADIANCE", "_IRRADIANCE" or "_RADIOSITY" (an application-specific name, as glTF asks).
const char* gltf_attribute(Quantity quantity);

/// Quantity from its name ("radiance", "irradiance", "radiosity"); throws InputError otherwise.
Quantity parse_quantity(const std::string& name);

/// What snapped_to_input did.
struct SnapStats {
  size_t not_moved = 0;            ///< vertices left in place (none of their input within reach, or a fold)
  size_t kept_to_avoid_folds = 0;  ///< of which moves taken back because an element would turn over
  size_t moved_far = 0;            ///< vertices moved by more than 10⁻³ of the scene's bounding-box diagonal
  double largest = 0.0;            ///< the longest move, scene units
  size_t coincident_merged = 0;    ///< elements dropped by without_coincident
  size_t back_to_back = 0;         ///< pairs of coincident elements facing opposite ways, both kept
};

/// The mesh with every vertex moved to the nearest point of the input meshes its elements were
/// meshed from, on triangles facing within 60° of the vertex normal and within `reach`; vertices
/// with none keep their place, and so do the vertices of an element the moves would turn over
/// (and every vertex of a mesh without element_surface and element_normal for each element).
/// write_solution exports this. Advances `progress` (if any) by one per vertex.
mesh::RadiosityMesh snapped_to_input(const rc::scene::Scene& scene, const mesh::RadiosityMesh& mesh,
                                     float reach, SnapStats* stats = nullptr,
                                     rc::util::Progress* progress = nullptr);

/// The mesh without elements that repeat an earlier element: the same three corner positions (to
/// the bit, after snapping) in the same turning order, so the same face facing the same way, which
/// every viewer would show z-fighting. The first is kept (its duplicates carry the same light, to
/// the solution's noise). Pairs facing opposite ways are the two sides of a thin sheet and keep
/// their own light: both stay, counted in `back_to_back` (viewers that cull back faces, as glTF
/// asks for single-sided materials, show each from its side). Vertices are not renumbered.
mesh::RadiosityMesh without_coincident(const mesh::RadiosityMesh& mesh, SnapStats* stats = nullptr);

/// Writes the mesh with per-vertex colours by extension (docs/exports.md): .ply (binary
/// little-endian; uchar `red green blue`, the quantity × 2^exposure as 8-bit sRGB, and float
/// `<quantity>_red _green _blue`, the quantity itself; uchar only with srgb8; float `red green
/// blue` = the quantity with linear_float), .obj (`v x y z r g b` with display colours, the
/// quantity × 2^exposure clamped and sRGB-encoded, or the quantity itself with linear_float;
/// materials in a .mtl beside it), .gltf / .glb (COLOR_0 as linear float RGB, the quantity ×
/// 2^exposure clamped to [0, 1] as glTF requires, and the quantity itself in gltf_attribute;
/// materials as baseColorFactor / emissive). The vertices are snapped_to_input first (within half the
/// solution's target edge), then coincident elements dropped (without_coincident); `snap`
/// receives what both did. Throws InputError for an unsupported
/// extension or an unwritable destination.
void write_solution(const std::string& path, const rc::scene::Scene& scene, const solver::Solution& solution,
                    const ExportSettings& settings, SnapStats* snap = nullptr);

/// What write_solution is foretold to take on a mesh of n elements: seconds + seconds_per_element
/// × n, snapping, merging and encoding included (measured on two cores: bench/README.md, "The
/// solver's budget").
struct WriteForecast {
  double seconds = 0.0;
  double seconds_per_element = 0.0;
  /// The forecast at `elements` elements.
  double at(size_t elements) const { return seconds + seconds_per_element * double(elements); }
};

/// The forecast for a file of `path`'s type (.ply, .obj, .gltf, .glb); zero for any other.
WriteForecast write_forecast(const std::string& path);

/// What a bake onto the input model is foretold to take, fitting and writing included (its
/// seconds; no part per element): a part per input triangle, and with `lightmap_size` > 0 a part
/// per texel of the SIZE × SIZE atlas. Without --bake-gather; a gather keeps its own deadline.
WriteForecast onto_input_forecast(size_t input_triangles, int lightmap_size);

}  // namespace gilt::radiosity::bake

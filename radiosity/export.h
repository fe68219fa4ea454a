#pragma once
// Writing a radiosity solution as a mesh with one colour per vertex, for game engines, Blender
// and MeshLab. Files are written atomically (temporary file, then rename).

#include <cstdint>
#include <string>

#include "radiosity/solver.h"

namespace gilt::radiosity {

/// Which per-vertex value becomes the colour.
enum class Quantity : uint8_t {
  radiance,    ///< outgoing radiance L (W·sr⁻¹·m⁻²): what the path tracer shows (default)
  irradiance,  ///< incident irradiance E (W·m⁻²)
  radiosity,   ///< radiosity B (W·m⁻²)
};

/// Export options.
struct ExportSettings {
  Quantity quantity = Quantity::radiance;
  bool srgb8 = false;      ///< PLY only: 8-bit sRGB colours (after 2^exposure) instead of float
  float exposure = 0.0f;   ///< with srgb8
};

/// Linear value to an 8-bit sRGB code: scaled, clamped to [0, 1], encoded (IEC 61966-2-1), rounded.
uint8_t to_srgb8(float linear, float scale);

/// "radiance", "irradiance" or "radiosity".
const char* to_string(Quantity quantity);

/// Quantity from its name ("radiance", "irradiance", "radiosity"); throws InputError otherwise.
Quantity parse_quantity(const std::string& name);

/// Writes the mesh with per-vertex colours by extension: .ply (binary little-endian, float
/// `red green blue` by default, uchar with srgb8), .obj (`v x y z r g b` with linear colours,
/// materials in a .mtl beside it), .gltf / .glb (COLOR_0 as linear float RGB, materials as
/// baseColorFactor / emissive). Throws InputError for an unsupported extension or an unwritable
/// destination.
void write_solution(const std::string& path, const rc::Scene& scene, const Solution& solution,
                    const ExportSettings& settings);

}  // namespace gilt::radiosity

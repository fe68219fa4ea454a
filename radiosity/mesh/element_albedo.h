#pragma once
// Each element's reflectance: its material's albedo, times the mean of the material's base-colour
// texture over the part of the input surface the element stands for.

#include <vector>

#include "radiosity/mesh/mesh.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::radiosity::mesh {

/// Reflectance per element. For a textured material, 16 stratified points of the element are
/// carried to the nearest point of the input mesh it came from (facing its way); there the
/// texture is read at that point's texture coordinates, filtered over the point's share of the
/// element as the input triangle maps it into the image. Remeshed elements cross the input's UV
/// seams freely, which is why each point finds its own input triangle rather than the element
/// carrying UVs. Deterministic and independent of the thread count.
std::vector<rc::Rgb> element_reflectance(const rc::scene::Scene& scene, const RadiosityMesh& mesh);

}  // namespace gilt::radiosity::mesh

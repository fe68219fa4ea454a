#pragma once
// Shading normals from images: tangent-space normal maps (glTF's normalTexture, MTL's `norm`) and
// height maps (MTL's `bump`). Both tilt the interpolated vertex normal within a tangent frame
// whose tangent runs along the image's +s and whose bitangent runs up the image (−t), the frame
// glTF's normal textures are drawn in (+x right, +y up, +z out of the surface).
//
// Tangents are generated per vertex from the texture coordinates the map reads, as Lengyel's
// method has it (Lengyel 2001, "Computing tangent space basis vectors for an arbitrary mesh"):
// each triangle's ∂p/∂s and ∂p/∂t, area-weighted, summed at its corners, then made orthogonal
// to the vertex normal; the sign w records a mirrored layout. This is MikkTSpace's construction
// without its splitting of vertices at mirror seams, which the glTF specification recommends
// for files without TANGENT; a vertex shared by mirrored halves gets the halves' mean.

#include <vector>

#include "raytrace_core/util/math.h"
#include "raytrace_core/scene/texture.h"

namespace gilt::raytrace_core::scene {

struct TriangleMesh;

/// Per-vertex tangents (xyz, unit, orthogonal to the vertex normal) and handedness (w = ±1) of
/// `map`'s (s, t) frame over `mesh`, whose uvs must be set. A vertex no triangle gives a usable
/// frame gets some tangent orthogonal to its normal, w = +1.
std::vector<glm::vec4> generate_tangents(const TriangleMesh& mesh, const TextureRef& map);

/// The unit normal that tangent-space normal `t` (x along tangent, y along bitangent, z along n)
/// stands for, at a point with unit interpolated normal n and interpolated tangent (xyz, w).
/// Returns n unchanged when the tangent is unusable (zero or parallel to n).
Vec3 tangent_to_world(const Vec3& n, const glm::vec4& tangent, const Vec3& t);

/// A normal texture's texel decoded (x, y scaled by `scale`, as glTF's normalTexture.scale).
Vec3 decode_normal_texel(const Rgb& texel, float scale);

/// Tangent-space normal of a height field from its central differences along +s and up the
/// image (−t), per texel width, multiplied by `scale` (MTL's -bm): heights rising by their full
/// range over each texel width make a 45° slope.
Vec3 height_normal(float dh_ds, float dh_dup, float scale);

}  // namespace gilt::raytrace_core::scene

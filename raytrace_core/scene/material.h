#pragma once
// Surface materials: a closed set, so an enum and a switch rather than virtual classes.

#include <cstdint>
#include <array>
#include <string>

#include "raytrace_core/util/rgb.h"
#include "raytrace_core/scene/texture.h"

namespace gilt::raytrace_core::scene {

/// The scattering model of a material.
enum class MaterialKind : uint8_t {
  diffuse,     ///< Lambertian: f = albedo / π, reflects on both sides
  glossy,      ///< Lambertian `albedo` plus energy-normalised Phong lobe `specular`, `exponent`
  mirror,      ///< perfect specular reflection tinted by `specular`
  /// Glass: Fresnel reflection and refraction with `ior`, Beer–Lambert `absorption`; a perfect
  /// interface, or GGX microfacets (Walter et al. 2007) when `roughness` is above zero
  dielectric,
  /// glTF 2.0's metallic-roughness model (its specification's appendix B): base colour `albedo`,
  /// `metallic`, `roughness`; a GGX specular lobe with Schlick's Fresnel, over a Lambertian base
  /// for the dielectric part (F0 from `ior`) and tinted by the base colour for the metal part.
  metallic_roughness,
};

/// How a surface's coverage (alpha) is read (glTF's alphaMode; MTL's map_d is a mask).
enum class AlphaMode : uint8_t {
  opaque,  ///< alpha is ignored
  mask,    ///< a cutout: where alpha < alpha_cutoff, rays pass through as if nothing were there
  blend,   ///< stochastic transparency: a ray stops with probability alpha, else passes
};

/// A material. Emission is independent of the scattering kind: any surface may emit.
struct Material {
  std::string name;
  MaterialKind kind = MaterialKind::diffuse;
  Rgb albedo{0.8f};       ///< diffuse reflectance in [0, 1] (diffuse, glossy)
  Rgb specular{0.0f};     ///< Phong specular reflectance (glossy) or mirror reflectance (mirror)
  float exponent = 0.0f;  ///< Phong exponent n ≥ 0 (glossy)
  float ior = 1.5f;       ///< index of refraction inside, relative to outside (dielectric)
  Rgb absorption{0.0f};   ///< absorption coefficient σa per scene unit inside (dielectric)
  float metallic = 0.0f;  ///< metal fraction in [0, 1] (metallic_roughness)
  /// Perceptual roughness in [0, 1]; GGX α = roughness² (metallic_roughness, and dielectric, where
  /// make_dielectric's 0 is a perfect interface)
  float roughness = 1.0f;
  /// Dielectric: transmitted light is multiplied by this colour (glTF's base colour of a
  /// transmissive material; white for MTL glass).
  Rgb transmission_tint{1.0f};
  /// Dielectric: an infinitely thin sheet (glTF transmission without KHR_materials_volume) —
  /// transmitted rays pass straight through, unbent, and no medium lies behind the surface.
  bool thin_walled = false;
  Rgb emission{0.0f};     ///< emitted radiance, W·sr⁻¹·m⁻², from the front face
  bool two_sided_emission = false;  ///< emit from both faces
  /// Base colour: `albedo` is multiplied by this texture's linear RGB where it is set (glTF's
  /// baseColorFactor × baseColorTexture; MTL's Kd × map_Kd, as the MTL specification has it).
  TextureRef albedo_texture;
  /// metallic_roughness: metallic × the texture's blue channel, roughness × its green (linear data).
  TextureRef metallic_roughness_texture;
  /// Emission is multiplied by this texture's linear RGB where it is set (glTF's emissiveTexture,
  /// MTL's map_Ke).
  TextureRef emission_texture;
  /// Shading normals read from an image (normal_map.h): a tangent-space normal map, its x and y
  /// scaled by `normal_scale` (glTF's normalTexture and its scale, MTL's `norm`), or a height map
  /// whose heights, in texel widths, are multiplied by `normal_scale` (MTL's `bump` and its -bm).
  TextureRef normal_texture;
  bool normal_is_height = false;
  float normal_scale = 1.0f;

  /// Coverage: `alpha` times the alpha texture where set (its alpha channel, or its first
  /// channel when it has none), read by `alpha_mode`.
  AlphaMode alpha_mode = AlphaMode::opaque;
  float alpha = 1.0f;
  float alpha_cutoff = 0.5f;
  TextureRef alpha_texture;
  /// An alpha texture without an alpha channel holds coverage in its first channel (MTL's
  /// map_d); else (glTF's base colour) such a texture is fully opaque.
  bool alpha_in_colour = false;

  /// Every image reference the material holds, for code that walks them all.
  std::array<TextureRef*, 5> texture_refs() {
    return {&albedo_texture, &metallic_roughness_texture, &emission_texture, &normal_texture, &alpha_texture};
  }
  std::array<const TextureRef*, 5> texture_refs() const {
    return {&albedo_texture, &metallic_roughness_texture, &emission_texture, &normal_texture, &alpha_texture};
  }

  /// True when some parameter varies over the surface and must be looked up at each point.
  bool is_textured() const {
    return albedo_texture.valid() || metallic_roughness_texture.valid() || emission_texture.valid() ||
           normal_texture.valid();
  }
  /// True when rays may pass through parts of the surface.
  bool has_coverage() const { return alpha_mode != AlphaMode::opaque && (alpha < 1.0f || alpha_texture.valid()); }

  /// True when the surface emits light.
  bool is_emissive() const { return !emission.is_black(); }
  /// True when every scattering direction is a delta (mirror, smooth dielectric): no light sampling.
  bool is_specular() const { return kind == MaterialKind::mirror || (kind == MaterialKind::dielectric && !is_rough_dielectric()); }
  /// A dielectric whose GGX α = roughness² is above kMinGgxAlpha: a microfacet interface that
  /// reflects and refracts into lobes (rough_dielectric.h); at or below it, a perfect interface.
  bool is_rough_dielectric() const;
  /// True when the surface has no Lambertian part: mirror and glass, smooth or rough. Radiosity
  /// and photon mapping store no light on such a surface; they follow rays through it instead.
  bool is_traced_through() const { return kind == MaterialKind::mirror || kind == MaterialKind::dielectric; }

  /// Material of the given kind with default parameters, named.
  static Material make_diffuse(std::string name, Rgb albedo);
  static Material make_emitter(std::string name, Rgb radiance, Rgb albedo = Rgb(0.0f));
  static Material make_mirror(std::string name, Rgb reflectance = Rgb(1.0f));
  static Material make_dielectric(std::string name, float ior, Rgb absorption = Rgb(0.0f));
  static Material make_glossy(std::string name, Rgb albedo, Rgb specular, float exponent);
  static Material make_metallic_roughness(std::string name, Rgb base_colour, float metallic, float roughness,
                                          float ior = 1.5f);
};

}  // namespace gilt::raytrace_core::scene

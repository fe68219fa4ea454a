// Material factories. Parameters a kind does not use are zeroed so that no module reads a
// meaningless default (e.g. the 0.8 diffuse albedo of a mirror).

#include "raytrace_core/scene/material.h"

#include <utility>

#include "raytrace_core/scene/microfacet.h"

namespace gilt::raytrace_core::scene {

Material Material::make_diffuse(std::string name, Rgb albedo) {
  Material m;
  m.name = std::move(name);
  m.kind = MaterialKind::diffuse;
  m.albedo = albedo;
  return m;
}

Material Material::make_emitter(std::string name, Rgb radiance, Rgb albedo) {
  Material m = make_diffuse(std::move(name), albedo);
  m.emission = radiance;
  return m;
}

Material Material::make_mirror(std::string name, Rgb reflectance) {
  Material m;
  m.name = std::move(name);
  m.kind = MaterialKind::mirror;
  m.albedo = Rgb(0.0f);
  m.specular = reflectance;
  return m;
}

Material Material::make_dielectric(std::string name, float ior, Rgb absorption) {
  Material m;
  m.name = std::move(name);
  m.kind = MaterialKind::dielectric;
  m.albedo = Rgb(0.0f);
  m.ior = ior;
  m.absorption = absorption;
  m.roughness = 0.0f;
  return m;
}

bool Material::is_rough_dielectric() const { return kind == MaterialKind::dielectric && sqr(roughness) > kMinGgxAlpha; }

Material Material::make_glossy(std::string name, Rgb albedo, Rgb specular, float exponent) {
  Material m;
  m.name = std::move(name);
  m.kind = MaterialKind::glossy;
  m.albedo = albedo;
  m.specular = specular;
  m.exponent = exponent;
  return m;
}

Material Material::make_metallic_roughness(std::string name, Rgb base_colour, float metallic, float roughness,
                                           float ior) {
  Material m;
  m.name = std::move(name);
  m.kind = MaterialKind::metallic_roughness;
  m.albedo = base_colour;
  m.metallic = metallic;
  m.roughness = roughness;
  m.ior = ior;
  return m;
}

}  // namespace gilt::raytrace_core::scene

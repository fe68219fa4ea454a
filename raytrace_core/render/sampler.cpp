#include "raytrace_core/render/sampler.h"

#include "raytrace_core/util/error.h"

namespace gilt::raytrace_core::render {

SamplerKind parse_sampler(const std::string& name) {
  if (name == "sobol") return SamplerKind::sobol;
  if (name == "independent") return SamplerKind::independent;
  throw InputError("sampler \"" + name + "\": expected independent or sobol");
}

float Sampler::sobol_1d() {
  const uint64_t h = dimension_seed();
  return util::sobol::to_unit_float(scrambled_dimension0(shuffled_index(uint32_t(h)), uint32_t(h >> 32)));
}

Vec2 Sampler::sobol_2d() {
  const uint64_t h = dimension_seed();
  const uint32_t i = shuffled_index(uint32_t(h));
  const uint32_t sx = uint32_t(h >> 32), sy = uint32_t(h >> 16) * 0x9e3779b9u + sx;
  return {util::sobol::to_unit_float(scrambled_dimension0(i, sx)), util::sobol::to_unit_float(util::sobol::owen_scramble(util::sobol::dimension1(i), sy))};
}

const char* sampler_name(SamplerKind kind) { return kind == SamplerKind::sobol ? "sobol" : "independent"; }

}  // namespace gilt::raytrace_core::render

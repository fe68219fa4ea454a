#include "radiosity/solver/element_direct.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

#include "radiosity/mesh/element_scene.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/scene/straight_transmittance.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::solver {

using mesh::mesh_surface_point;
using mesh::RadiosityMesh;
using rc::kPi;
using rc::Rgb;
using rc::Vec3;

namespace {

/// The side of the grid of points element_punctual_irradiance takes for `samples`.
int element_grid_side(int samples) {
  return std::max(1, int(std::lround(std::sqrt(double(std::max(1, samples))))));
}

/// The mean element area of the mesh (0 without elements).
double mean_element_area(const RadiosityMesh& mesh) {
  double sum = 0.0;
  for (float a : mesh.element_area) sum += double(a);
  return mesh.element_count() > 0 ? sum / double(mesh.element_count()) : 0.0;
}

/// How many times the grid's side an element of `area` takes (see element_punctual_irradiance).
int element_grid_scale(float area, double mean_area) {
  const double relative_area = mean_area > 0.0 ? double(area) / mean_area : 1.0;
  return std::clamp(int(std::ceil(std::sqrt(relative_area))), 1, 8);
}

}  // namespace

std::vector<Rgb> element_punctual_irradiance(const rc::scene::Scene& scene, const rc::scene::Scene& geometry,
                                             const RadiosityMesh& mesh, int samples, uint64_t seed,
                                             uint64_t& rays, rc::util::Progress* progress) {
  const size_t ne = mesh.element_count();
  std::vector<Rgb> out(ne, Rgb(0.0f));
  if (scene.punctual_lights.empty()) return out;
  const int base_side = element_grid_side(samples);
  const double mean_area = mean_element_area(mesh);
  std::atomic<uint64_t> traced{0};
  rc::util::parallel_for_owned((ne + 255) / 256, [&](size_t chunk) {
    uint64_t count = 0;
    std::vector<int> pairing;
    for (size_t e = chunk * 256; e < std::min(ne, chunk * 256 + 256); ++e) {
      const int side = base_side * element_grid_scale(mesh.element_area[e], mean_area);
      pairing.resize(size_t(side * side));
      const auto& el = mesh.elements[e];
      const Vec3 n = mesh.element_normal[e];
      const rc::Frame frame = rc::Frame::from_normal(n);
      Rgb sum(0.0f);
      for (size_t li = 0; li < scene.punctual_lights.size(); ++li) {
        const rc::scene::Light& light = scene.punctual_lights[li];
        rc::util::Rng rng = rc::util::Rng::for_item(seed, e, 0xb000000000ull + li);
        // Points stratified over the element and directions (sky) over the hemisphere, their
        // strata paired at random.
        std::iota(pairing.begin(), pairing.end(), 0);
        for (size_t k = pairing.size(); k > 1; --k)
          std::swap(pairing[k - 1], pairing[std::min(k - 1, size_t(rng.uniform() * float(k)))]);
        for (int i = 0; i < side; ++i)
          for (int j = 0; j < side; ++j) {
            const rc::Vec2 b =
                rc::util::sample_uniform_triangle({(i + rng.uniform()) / side, (j + rng.uniform()) / side});
            const Vec3 q = (1.0f - b.x - b.y) * mesh.positions[el[0]] + b.x * mesh.positions[el[1]] +
                           b.y * mesh.positions[el[2]];
            const rc::scene::SurfacePoint at = mesh_surface_point(q, n);
            ++count;
            if (light.kind == rc::scene::LightKind::environment) {
              const int k = pairing[size_t(i * side + j)];
              const rc::Vec2 u((k / side + rng.uniform()) / side, (k % side + rng.uniform()) / side);
              const Vec3 w = frame.to_world(rc::util::sample_cosine_hemisphere(u));
              // Through glass too: a path finds the sky through a window (see punctual_irradiance).
              const Rgb through =
                  rc::scene::straight_transmittance(geometry, rc::scene::spawn_shadow_ray_to_infinity(at, w));
              if (!through.is_black()) sum += through * rc::scene::environment_radiance(light, w) * kPi;
              continue;
            }
            const rc::scene::LightSample ls = rc::scene::sample_light(scene, light, at, rng.uniform2());
            const float cos_theta = glm::dot(ls.wi, n);
            if (!(cos_theta > 0.0f) || ls.radiance.is_black()) continue;
            if (!geometry.occluded(ls.shadow_ray)) sum += ls.radiance * cos_theta;
          }
      }
      out[e] = sum * (1.0f / float(side * side));
    }
    traced += count;
    if (progress) progress->advance(std::min(ne, chunk * 256 + 256) - chunk * 256);
  });
  rc::util::join_ranges(std::span(out), 256);
  rays += rc::util::processes().total(traced);
  return out;
}

int element_samples_within(const RadiosityMesh& mesh, size_t lights, int samples, double rays_per_second,
                           double seconds) {
  const double mean_area = mean_element_area(mesh);
  double scale = 0.0;  // Σ over elements of the grid scale squared: rays = side² × lights × scale
  for (float a : mesh.element_area) {
    const int g = element_grid_scale(a, mean_area);
    scale += double(g * g);
  }
  for (int side = element_grid_side(samples); side > 1; --side)
    if (double(side * side) * double(lights) * scale <= rays_per_second * seconds) return side * side;
  return 1;
}

}  // namespace gilt::radiosity::solver

// Diagnostic: the hierarchical solver's first bounce of a directional light at the points the
// camera sees, against (a) a cosine gather of 64 rays from the same element point in the element
// scene reading the solver's own element radiosity (albedo × element_direct), and (b) the same
// gather from the input point in the input scene reading the sun at each hit point (a path
// tracer's second vertex, front faces only and both faces). The scene's other lights are
// dropped; the solve uses the two-pass view's settings with one Jacobi gather. Usage:
// first_bounce_probe SCENE [LINK_TOLERANCE] [ELEMENTS]; FINAL_GATHER=1 takes the vertices from
// the vertex final gather of the direct light's reflection instead of the links; LINK_RAYS sets
// the shadow rays per link (HierarchicalSettings::link_rays); PIXCSV and
// ELEMCSV name CSV dumps (per pixel: x, y, element, surface, solver, gather, input gather; per
// element: centroid, normal, area, surface, direct irradiance).

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

#include "radiosity/mesh/element_scene.h"
#include "radiosity/solver/solver.h"
#include "radiosity/bake/view.h"
#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"
#include "raytrace_core/scene/scene.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;
using rc::Rgb;
using rc::Vec3;

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  rc::scene::Scene scene = rc::io::load_scene_file(argv[1]);
  // The sun alone.
  std::erase_if(scene.punctual_lights, [](const rc::scene::Light& l) { return l.kind != rc::scene::LightKind::directional; });
  scene.commit();
  const rc::scene::Light& sun = scene.punctual_lights.at(0);
  const Vec3 wi = -glm::normalize(sun.direction);
  rad::solver::SolverSettings ss;
  ss.mesh.elements = argc > 3 ? std::atoi(argv[3]) : rad::mesh::kDefaultElements;
  ss.solver = rad::solver::SolverKind::hierarchical;
  ss.hierarchical.link_tolerance = argc > 2 ? std::atof(argv[2]) : 2e-4;
  ss.hierarchical.max_iterations = 1;
  ss.progress = false;
  ss = rad::bake::solver_settings_for(rad::bake::ViewMode::two_pass, ss);
  if (const char* r = std::getenv("LINK_RAYS")) ss.hierarchical.link_rays = std::atoi(r);
  // The final gather alone: no iteration, so the radiosity it gathers is the first reflection.
  if (std::getenv("FINAL_GATHER")) ss.hierarchical.final_gather = rad::solver::FinalGather::always, ss.hierarchical.max_iterations = 0;
  const rad::solver::Solution sol = rad::solver::solve(scene, ss);
  const rad::mesh::RadiosityMesh& mesh = sol.mesh;
  std::printf("solved: %zu elements, %zu links, %d iterations, final gather %d\n", mesh.element_count(), sol.links,
              sol.iterations, int(sol.final_gather));
  const rc::scene::Scene geo = rad::mesh::element_scene(scene, mesh);
  if (const char* path = std::getenv("ELEMCSV")) {
    std::FILE* f = std::fopen(path, "w");
    for (size_t e = 0; e < mesh.element_count(); ++e) {
      const auto& el = mesh.elements[e];
      const Vec3 c = (mesh.positions[el[0]] + mesh.positions[el[1]] + mesh.positions[el[2]]) / 3.0f, n = mesh.element_normal[e];
      std::fprintf(f, "%zu,%g,%g,%g,%g,%g,%g,%g,%u,%g\n", e, c.x, c.y, c.z, n.x, n.y, n.z, mesh.element_area[e],
                   mesh.element_surface[e], sol.element_direct[e].luminance());
    }
    std::fclose(f);
  }
  const float L = sol.mesh_report.max_edge, reach = 2.0f * L;
  const auto albedo = [&](uint32_t m) {
    return rc::scene::diffuse_reflectance(scene.materials[m]).luminance();
  };
  const auto elem_b = [&](uint32_t e) { return albedo(mesh.element_material[e]) * sol.element_direct[e].luminance(); };
  const float E = sun.irradiance.luminance();

  const rc::scene::Camera cam = scene.effective_camera(256.0f / 192.0f);
  const Vec3 fwd = glm::normalize(cam.look_at - cam.look_from), right = glm::normalize(glm::cross(fwd, cam.up)),
             up = glm::cross(right, fwd);
  const float th = std::tan(0.5f * cam.vfov_degrees * 3.14159265f / 180.0f);
  rc::util::Rng rng(29);
  double solver = 0, gather_elem = 0, gather_point = 0, truth_front = 0, truth_both = 0, pixels = 0;
  const int rays = 64;
  std::FILE* pix = std::getenv("PIXCSV") ? std::fopen(std::getenv("PIXCSV"), "w") : nullptr;
  for (int y = 0; y < 192; ++y)
    for (int x = 0; x < 256; ++x) {
      const Vec3 d = glm::normalize(fwd + ((2 * (x + 0.5f) / 256 - 1) * th * 256.0f / 192.0f) * right +
                                    ((1 - 2 * (y + 0.5f) / 192) * th) * up);
      const rc::scene::Ray cr{cam.look_from, d, rc::kInfinity};
      const auto ch = scene.intersect(cr);
      if (!ch) continue;
      const rc::scene::SurfaceInteraction si = scene.surface(cr, *ch);
      if (scene.materials[si.material].is_traced_through()) continue;
      const Vec3 lit = si.front_face ? si.ng : -si.ng;
      const auto loc = geo.nearest_triangle(0, si.p, reach, lit, 0.5f);
      if (!loc) continue;
      const float rho = albedo(si.material);
      pixels += 1;
      const auto& el = mesh.elements[loc->prim_id];
      const float b0 = 1 - loc->u - loc->v;
      auto first = [&](uint32_t v) { return (sol.vertex_irradiance[v] - sol.vertex_direct[v]).luminance(); };
      solver += rho * (b0 * first(el[0]) + loc->u * first(el[1]) + loc->v * first(el[2]));
      const Vec3 q = b0 * mesh.positions[el[0]] + loc->u * mesh.positions[el[1]] + loc->v * mesh.positions[el[2]];
      const Vec3 n = mesh.element_normal[loc->prim_id];
      const rc::Frame fe = rc::Frame::from_normal(n), fi = rc::Frame::from_normal(lit);
      rc::scene::SurfacePoint at_in = si;
      at_in.ng = lit;
      double ge = 0, gp = 0, tf = 0, tb = 0;
      for (int r = 0; r < rays; ++r) {
        const Vec3 wl = rc::util::sample_cosine_hemisphere(rng.uniform2());
        const rc::scene::Ray re = rc::scene::spawn_ray(rad::mesh::mesh_surface_point(q, n), fe.to_world(wl));
        if (const auto he = geo.intersect(re); he && he->geom_id == 0 && geo.surface(re, *he).front_face) {
          ge += elem_b(he->prim_id);
          const Vec3 n2 = mesh.element_normal[he->prim_id];
          const float c2 = glm::dot(n2, wi);
          if (c2 > 0 && !geo.occluded(rc::scene::spawn_shadow_ray_to_infinity(rad::mesh::mesh_surface_point(re.origin + he->t * re.direction, n2), wi)))
            gp += albedo(mesh.element_material[he->prim_id]) * E * c2;
        }
        const rc::scene::Ray ri = rc::scene::spawn_ray(at_in, fi.to_world(wl));
        if (const auto hi = scene.intersect(ri)) {
          const rc::scene::SurfaceInteraction sj = scene.surface(ri, *hi);
          const Vec3 lj = sj.front_face ? sj.ng : -sj.ng;
          rc::scene::SurfacePoint sp = sj;
          sp.ng = lj;
          const float c2 = glm::dot(lj, wi);
          if (c2 > 0 && !scene.occluded(rc::scene::spawn_shadow_ray_to_infinity(sp, wi))) {
            const double b = albedo(sj.material) * E * c2;
            tb += b;
            if (sj.front_face) tf += b;
          }
        }
      }
      if (pix) std::fprintf(pix, "%d,%d,%u,%u,%g,%g,%g\n", x, y, loc->prim_id, mesh.element_surface[loc->prim_id],
                            rho * (b0 * first(el[0]) + loc->u * first(el[1]) + loc->v * first(el[2])), rho * ge / rays,
                            rho * tf / rays);
      gather_elem += rho * ge / rays;
      gather_point += rho * gp / rays;
      truth_front += rho * tf / rays;
      truth_both += rho * tb / rays;
    }
  std::printf("camera points with an element: %.0f\n", pixels);
  std::printf("first-bounce reflected light (rho x E1, mean per pixel):\n");
  std::printf("  solver (links, vertices interpolated)   %.5g\n", solver / pixels);
  std::printf("  gather, element scene, element means    %.5g  (solver / this %.4f)\n", gather_elem / pixels, solver / gather_elem);
  std::printf("  gather, element scene, sun at hit point %.5g\n", gather_point / pixels);
  std::printf("  gather, input, sun at hit, front faces  %.5g  (solver / this %.4f)\n", truth_front / pixels, solver / truth_front);
  std::printf("  gather, input, sun at hit, both faces   %.5g  (solver / this %.4f)\n", truth_both / pixels, solver / truth_both);
  return 0;
}

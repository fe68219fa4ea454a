// Diagnostic: where a closed white furnace's light goes in the radiosity solution. Every surface
// emits Le and reflects ρ, so the irradiance at every point is π Le straight from the emitters
// and π Le / (1 − ρ) in all. Prints the area-weighted means over the elements, and the plain
// means over the vertices, of the solution's direct and total irradiance as fractions of those,
// and the share of vertices more than 5 % off. Usage: furnace_probe SCENE [progressive|hierarchical]
// [mesh|two-pass] [LINK_TOLERANCE [RECEIVER_SHARE]]; the scene's single material gives Le and ρ. VERTCSV
// names a CSV of every vertex (position, normal, direct and total as fractions, its elements, their least
// area, twin or not); PROBE_VERTEX=v prints what 256 cosine rays from vertex v (or from its visibility origin
// PROBE_ORIGIN=k) meet in the element scene. (On the furnace family's dome it showed the middle of the
// enclosure's floor removed as buried under the building's one-sided floor: rays from under it escaped.)
// CAMERA_PIXELS prints what the scene's camera sees of the solution, 96 × 72 pixels on the elements, and
// the vertices that carry most of its excess and its shortfall. (On the furnished furnace it found the
// floor round table legs reading 1.4 of the direct light: the tree walk read the legs at the vertex and
// the room behind them from origins beside the legs.)

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <tuple>
#include <vector>

#include "radiosity/bake/view.h"
#include "radiosity/mesh/element_scene.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  rc::scene::Scene scene = rc::io::load_scene_file(argv[1]);
  scene.commit();
  const rc::scene::Material& m = scene.materials.at(0);
  const double le = m.emission.average(), rho = rc::scene::diffuse_reflectance(m).average();
  const double direct = M_PI * le, total = M_PI * le / (1.0 - rho);
  rad::solver::SolverSettings ss;
  ss.progress = false;
  ss.solver = argc > 2 && std::strcmp(argv[2], "progressive") == 0 ? rad::solver::SolverKind::progressive
                                                                   : rad::solver::SolverKind::hierarchical;
  const auto mode = argc > 3 && std::strcmp(argv[3], "mesh") == 0 ? rad::bake::ViewMode::mesh
                                                                  : rad::bake::ViewMode::two_pass;
  ss = rad::bake::solver_settings_for(mode, ss);
  if (argc > 4) ss.hierarchical.link_tolerance = std::atof(argv[4]);
  if (argc > 5) ss.hierarchical.receiver_share = std::atof(argv[5]);
  ss.hierarchical.keep_closure = true;
  const rad::solver::Solution sol = rad::solver::solve(scene, ss);
  const auto& mesh = sol.mesh;
  std::printf(
      "le %g rho %g: %zu elements, %zu vertices, %zu links at %g, %d iterations, residual %g, final gather "
      "%d\n",
      le, rho, mesh.element_count(), mesh.vertex_count(), sol.links, sol.link_tolerance, sol.iterations,
      sol.residual, int(sol.final_gather));
  double area = 0, d_el = 0, t_el = 0, ed_el = 0;
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& el = mesh.elements[e];
    const double a = mesh.element_area[e];
    double d = 0, t = 0;
    for (uint32_t v : el)
      d += sol.vertex_direct[v].average() / 3.0, t += sol.vertex_irradiance[v].average() / 3.0;
    area += a, d_el += a * d, t_el += a * t;
    if (!sol.element_direct.empty()) ed_el += a * sol.element_direct[e].average();
  }
  double d_v = 0, t_v = 0;
  size_t off = 0;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    d_v += sol.vertex_direct[v].average(), t_v += sol.vertex_irradiance[v].average();
    off += std::abs(sol.vertex_irradiance[v].average() / total - 1.0) > 0.05;
  }
  if (const char* path = std::getenv("VERTCSV")) {
    // Per vertex: position, normal, direct and total as fractions, elements around it, their
    // least area, and whether they are twins (2), twinned (1) or one-sided (0).
    std::vector<int> count(mesh.vertex_count(), 0), side(mesh.vertex_count(), 0);
    std::vector<float> least(mesh.vertex_count(), 1e30f);
    for (size_t e = 0; e < mesh.element_count(); ++e)
      for (uint32_t v : mesh.elements[e]) {
        ++count[v];
        least[v] = std::min(least[v], mesh.element_area[e]);
        side[v] = mesh.element_two_sided.empty() ? 0 : mesh.element_two_sided[e];
      }
    std::FILE* f = std::fopen(path, "w");
    std::fprintf(f, "v,x,y,z,nx,ny,nz,direct,total,elements,least_area,side\n");
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
      const auto p = mesh.positions[v], n = mesh.normals[v];
      std::fprintf(f, "%zu,%g,%g,%g,%g,%g,%g,%g,%g,%d,%g,%d\n", v, p.x, p.y, p.z, n.x, n.y, n.z,
                   sol.vertex_direct[v].average() / direct, sol.vertex_irradiance[v].average() / total,
                   count[v], least[v], side[v]);
    }
    std::fclose(f);
  }
  if (const char* probe = std::getenv("PROBE_VERTEX")) {
    // What cosine-weighted rays from just in front of one vertex meet in the element scene.
    const size_t v = std::strtoul(probe, nullptr, 10);
    const rc::scene::Scene geo = rad::mesh::element_scene(scene, mesh);
    const rc::Vec3 n = mesh.normals[v];
    // From the vertex, or from one of its visibility origins (PROBE_ORIGIN=k).
    rc::Vec3 p = mesh.positions[v] + 1e-3f * n;
    if (const char* k = std::getenv("PROBE_ORIGIN")) {
      const rc::scene::Scene elements = rad::mesh::element_scene(scene, mesh);
      const auto origins =
          rad::solver::visibility_origins(elements, mesh, rad::solver::receiver_points(elements, mesh));
      p = origins.at(rad::solver::kVisibilityOrigins * v + std::strtoul(k, nullptr, 10)).p;
      std::printf("origin %s at (%.4f %.4f %.4f)\n", k, p.x, p.y, p.z);
    }
    const rc::Frame frame = rc::Frame::from_normal(n);
    rc::util::Rng rng(1);
    int counts[4] = {0, 0, 0, 0};
    for (int i = 0; i < 256; ++i) {
      const rc::Vec3 w = frame.to_world(rc::util::sample_cosine_hemisphere(rng.uniform2()));
      const auto h = geo.intersect(rc::scene::spawn_ray(rad::mesh::mesh_surface_point(p, n), w));
      if (!h) {
        ++counts[0];
        continue;
      }
      if (h->geom_id != 0) {
        ++counts[1];
        continue;
      }
      const bool front = glm::dot(w, mesh.element_normal[h->prim_id]) < 0.0f;
      ++counts[front ? 2 : 3];
      if (i < 12) {
        const auto& el = mesh.elements[h->prim_id];
        const rc::Vec3 c = (mesh.positions[el[0]] + mesh.positions[el[1]] + mesh.positions[el[2]]) / 3.0f;
        std::printf("  ray %d: t %.3f element %u at (%.2f %.2f %.2f) normal (%.2f %.2f %.2f) %s side %d\n", i,
                    h->t, h->prim_id, c.x, c.y, c.z, mesh.element_normal[h->prim_id].x,
                    mesh.element_normal[h->prim_id].y, mesh.element_normal[h->prim_id].z,
                    front ? "front" : "back",
                    mesh.element_two_sided.empty() ? 0 : int(mesh.element_two_sided[h->prim_id]));
      }
    }
    std::printf(
        "vertex %zu at (%.3f %.3f %.3f) n (%.2f %.2f %.2f): escaped %d, other %d, fronts %d, backs %d\n", v,
        mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z, n.x, n.y, n.z, counts[0], counts[1],
        counts[2], counts[3]);
  }
  if (std::getenv("CAMERA_PIXELS")) {
    // What the scene's camera sees of the solution: each pixel of a 96 × 72 image meets an element
    // (the side facing the ray, where the element has a twin) and reads its vertices' direct and
    // total irradiance at the hit's barycentrics. Prints the pixels' means and the vertices that
    // carry most of the excess, by the pixels' weights.
    const rc::scene::Scene geo = rad::mesh::element_scene(scene, mesh);
    std::map<std::tuple<long, long, long>, std::vector<uint32_t>> at;  // elements by centroid
    auto centroid = [&](size_t e) {
      const auto& el = mesh.elements[e];
      return (mesh.positions[el[0]] + mesh.positions[el[1]] + mesh.positions[el[2]]) / 3.0f;
    };
    auto key = [](const rc::Vec3& c) {
      return std::make_tuple(std::lround(c.x * 1e4f), std::lround(c.y * 1e4f), std::lround(c.z * 1e4f));
    };
    for (size_t e = 0; e < mesh.element_count(); ++e) at[key(centroid(e))].push_back(uint32_t(e));
    const rc::scene::Camera camera = scene.effective_camera(96.0f / 72.0f);
    std::vector<double> excess(mesh.vertex_count(), 0.0), weight(mesh.vertex_count(), 0.0);
    double sum_d = 0.0, sum_t = 0.0;
    int hits = 0;
    for (int y = 0; y < 72; ++y)
      for (int x = 0; x < 96; ++x) {
        const rc::scene::Ray ray =
            camera.generate_ray({(x + 0.5f) / 96.0f, (y + 0.5f) / 72.0f}, {0.5f, 0.5f}, 96.0f / 72.0f);
        const auto h = geo.intersect(ray);
        if (!h || h->geom_id != 0) continue;
        uint32_t e = h->prim_id;
        for (uint32_t other : at[key(centroid(e))])
          if (glm::dot(mesh.element_normal[other], ray.direction) < 0.0f) e = other;
        const auto& el = mesh.elements[e];
        // The hit's barycentrics belong to the element met; a twin lists its corners in reverse.
        float b[3] = {1.0f - h->u - h->v, h->u, h->v};
        if (e != h->prim_id) std::swap(b[1], b[2]);
        double d = 0.0, t = 0.0;
        for (int k = 0; k < 3; ++k)
          d += b[k] * sol.vertex_direct[el[k]].average() / direct,
              t += b[k] * sol.vertex_irradiance[el[k]].average() / total;
        for (int k = 0; k < 3; ++k) excess[el[k]] += b[k] * (t - 1.0), weight[el[k]] += b[k];
        sum_d += d, sum_t += t, ++hits;
      }
    std::printf("camera: %d pixels on elements, direct %.4f, total %.4f\n", hits, sum_d / std::max(1, hits),
                sum_t / std::max(1, hits));
    std::vector<size_t> order(mesh.vertex_count());
    for (size_t v = 0; v < order.size(); ++v) order[v] = v;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return excess[a] > excess[b]; });
    // The fifteen that carry most excess, then the fifteen that carry most shortfall.
    for (size_t j = 0; j < 30 && j < order.size(); ++j) {
      const size_t v = j < 15 ? order[j] : order[order.size() - 1 - (j - 15)];
      if (j == 15) std::printf("  ...\n");
      const auto p = mesh.positions[v], n = mesh.normals[v];
      std::printf(
          "  vertex %zu at (%.3f %.3f %.3f) n (%.2f %.2f %.2f): pixels %.2f, excess %.3f, direct %.3f, total "
          "%.3f\n",
          v, p.x, p.y, p.z, n.x, n.y, n.z, weight[v], excess[v], sol.vertex_direct[v].average() / direct,
          sol.vertex_irradiance[v].average() / total);
    }
  }
  if (!sol.element_closure.empty()) {
    // The links' closure: the sum of each element's link factors, 1 in any closed scene.
    std::vector<std::pair<float, float>> by_closure;  // (closure, area)
    double closure_area = 0.0, closure_sum = 0.0, under = 0.0, over = 0.0;
    for (size_t e = 0; e < mesh.element_count(); ++e) {
      const float c = sol.element_closure[e], a = mesh.element_area[e];
      by_closure.emplace_back(c, a);
      closure_area += a, closure_sum += double(c) * a;
      under += c < 0.9f ? a : 0.0f, over += c > 1.1f ? a : 0.0f;
    }
    std::sort(by_closure.begin(), by_closure.end());
    auto quantile = [&](double q) {
      double acc = 0.0;
      for (const auto& [c, a] : by_closure)
        if ((acc += a) >= q * closure_area) return c;
      return by_closure.back().first;
    };
    std::printf(
        "closure (by area): mean %.4f, 5 %% %.3f, median %.3f, 95 %% %.3f; %.1f %% of the area below 0.9, "
        "%.1f %% above 1.1\n",
        closure_sum / closure_area, quantile(0.05), quantile(0.5), quantile(0.95),
        100.0 * under / closure_area, 100.0 * over / closure_area);
  }
  const double nv = double(mesh.vertex_count());
  std::printf("elements (by area): direct %.4f, total %.4f, element_direct %.4f\n", d_el / area / direct,
              t_el / area / total, ed_el / area / direct);
  std::printf("vertices (plain):   direct %.4f, total %.4f, %.1f %% off by more than 5 %%\n",
              d_v / nv / direct, t_v / nv / total, 100.0 * double(off) / nv);
  return 0;
}

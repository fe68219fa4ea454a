// Diagnostic: the global photon map's indirect irradiance at the points the camera sees, against
// path-traced indirect irradiance there (cosine rays from the point; each hit's outgoing radiance
// by the path tracer, escaped rays and emission seen straight from the point left out: the light
// that has bounced at least once, which is what the global map holds). Usage:
// photon_probe SCENE [GLOBAL_PATHS_PER_ROUND] [K] [RAYS]; prints the ratio of the sums and of
// the point-by-point medians, for all points and by thirds of the path-traced value. COVER=1
// divides the estimates by their coverage (see below); DUMP=1 prints every point, with the
// photons its disk found and those that passed the normal test.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "photonmap/coverage.h"
#include "photonmap/photon_map.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"

namespace rc = gilt::raytrace_core;
namespace pm = gilt::photonmap;

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  rc::scene::Scene scene = rc::io::load_scene(argv[1]);
  pm::PhotonSettings ps;
  ps.global_photons = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 200000;
  ps.caustic_photons = 0;
  const size_t k = argc > 3 ? size_t(std::atoi(argv[3])) : 50;
  const int rays = argc > 4 ? std::atoi(argv[4]) : 256;
  pm::PhotonMaps maps = pm::trace_photons(scene, ps);
  // COVER=1: the estimates divided by their disk's coverage (photonmap/coverage.h) over every
  // side of every triangle, as the photon mapper divides them. COVER=open: only over the sides
  // open_sides finds light from outside can reach, with a count of the stored photons that lie
  // on the others.
  const bool cover = std::getenv("COVER") != nullptr;
  if (cover && std::string(std::getenv("COVER")) == "open") {
    maps.global.sides = pm::open_sides(scene);
    size_t open = 0;
    for (uint64_t c : maps.global.sides.counts()) open += c;
    std::printf("open sides: %zu of %zu\n", open, maps.global.sides.counts().size());
    // How many stored photons lie on sides open_sides calls closed (the photon's own triangle
    // found by a short ray back along its normal, which faces where it came from).
    size_t on_closed = 0, found = 0;
    for (const pm::Photon& ph : maps.global.photons) {
      const rc::Vec3 n = pm::decode_direction(ph.normal);
      rc::scene::Ray back{ph.position + 1e-3f * n, -n};
      back.tmax = 2e-3f;
      const auto h = scene.intersect(back);
      if (!h || h->geom_id == scene.sphere_geom_id()) continue;
      ++found;
      const rc::scene::TriangleMesh& m = scene.meshes[h->geom_id];
      const uint32_t* j = &m.indices[3 * size_t(h->prim_id)];
      const bool front = glm::dot(glm::cross(m.positions[j[1]] - m.positions[j[0]], m.positions[j[2]] - m.positions[j[0]]), n) >= 0.0f;
      if (!maps.global.sides.holds(h->geom_id, h->prim_id, front)) ++on_closed;
    }
    std::printf("photons on sides called closed: %zu of %zu found\n", on_closed, found);
  } else if (cover) {
    maps.global.sides = pm::every_side(scene);
  }
  std::printf("%zu global photons from %llu paths\n", maps.global.photons.size(), (unsigned long long)maps.paths);
  const float max_r = 0.05f * scene.bounds().radius();
  const rc::scene::Camera camera = scene.effective_camera(256.0f / 192.0f);
  rc::render::RenderSettings rs;
  rs.width = 256;
  rs.height = 192;
  rs.filter.radius = 0.0f;
  struct Point { double photon, path; };
  std::vector<Point> points;
  pm::EstimateScratch scratch;
  const rc::render::PathSettings path;
  for (int y = 4; y < 192; y += 8)
    for (int x = 4; x < 256; x += 8) {
      rc::render::Sampler cs(rc::util::Rng::for_item(1, uint64_t(y) * 256 + x, 0));
      const rc::scene::Ray ray = rc::render::camera_ray(camera, rs, x, y, cs);
      const auto hit = scene.intersect(ray);
      if (!hit) continue;
      const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
      if (scene.materials[si.material].is_traced_through()) continue;
      const rc::Vec3 n = glm::dot(-ray.direction, si.ng) > 0.0f ? si.ng : -si.ng;
      const pm::EstimateQuery q{si.p, n, k, max_r * max_r};
      const double photon = (cover ? pm::estimate_irradiance(scene, maps.global, q, scratch)
                                   : pm::estimate_irradiance(maps.global, q, scratch)).average();
      const rc::Frame frame = rc::Frame::from_normal(n);
      double sum = 0.0;
      for (int i = 0; i < rays; ++i) {
        rc::util::Rng rng = rc::util::Rng::for_item(2, uint64_t(y) * 256 + x, uint64_t(i));
        const rc::Vec3 d = frame.to_world(rc::util::sample_cosine_hemisphere(rng.uniform2()));
        const rc::scene::Ray r = rc::scene::spawn_ray(si, d);
        const auto h = scene.intersect(r);
        if (!h) continue;
        rc::render::SampleContext ctx{rc::render::Sampler(rng)};
        rc::Rgb l = path_radiance(scene, r, ctx, path);
        const rc::scene::SurfaceInteraction sy = scene.surface(r, *h);
        const rc::scene::Material& my = scene.materials[sy.material];
        if (my.is_emissive()) l -= rc::scene::emitted_radiance(my, sy.ng, -d);
        sum += l.average();
      }
      points.push_back({photon, rc::kPi * sum / rays});
      if (std::getenv("DUMP")) {
        // Photons within the disk: all, and those that pass the normal test.
        std::vector<pm::Neighbour> nb(k);
        const size_t found = maps.global.index.knn(si.p, k, max_r * max_r, nb.data());
        size_t agree = 0;
        for (size_t i = 0; i < found; ++i) agree += glm::dot(pm::decode_direction(maps.global.photons[nb[i].index].normal), n) >= 0.9f;
        std::printf("P %d %d %.3f %.3f %.3f n %.2f %.2f %.2f photon %.4f path %.4f found %zu agree %zu r %.3f\n", x, y, si.p.x, si.p.y, si.p.z, n.x, n.y, n.z,
                    photon, rc::kPi * sum / rays, found, agree, found ? std::sqrt(nb[found - 1].distance2) : 0.0f);
      }
    }
  auto report = [&](const char* label, auto keep) {
    double a = 0, b = 0;
    std::vector<double> ratios;
    for (const Point& p : points)
      if (keep(p)) {
        a += p.photon, b += p.path;
        if (p.path > 0) ratios.push_back(p.photon / p.path);
      }
    if (ratios.empty()) return;
    std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
    std::printf("%-28s %4zu points: sum ratio %.3f, median ratio %.3f\n", label, ratios.size(), a / b,
                ratios[ratios.size() / 2]);
  };
  std::vector<double> path_values;
  for (const Point& p : points) path_values.push_back(p.path);
  std::sort(path_values.begin(), path_values.end());
  const double q1 = path_values[path_values.size() / 3], q2 = path_values[2 * path_values.size() / 3];
  report("all", [](const Point&) { return true; });
  report("darkest third", [&](const Point& p) { return p.path <= q1; });
  report("middle third", [&](const Point& p) { return p.path > q1 && p.path <= q2; });
  report("brightest third", [&](const Point& p) { return p.path > q2; });
  return 0;
}

// Diagnostic: does the radiosity element scene (element_scene()) let light through where the
// input does not? Meshes the scene as `gilt compare` does at a 60-s budget (ELEMENTS, default
// 4,000) and, for the scene's directional light (the sun):
//  - element points as element_punctual_irradiance samples them (16 per sun-facing element):
//    lit through the element scene but shadowed in the input, the point carried to the nearest
//    point of its own input mesh (so that the input's curve, of which the element is a chord,
//    does not shadow it); also traced against the input unprojected, as an earlier experiment
//    did. "Interior": an upward ray from the input point meets the input (INTERIOR=1 classifies
//    only those leaks);
//  - cosine gather rays from interior element points and from the points the camera sees
//    (256 × 192, located on their element as the view does), from the element point in the
//    element scene and from the input point in the input: a leak is an element-scene ray that
//    goes past the input's first hit by more than 0.01 L without hitting an element standing for
//    that hit (within 0.15 L, facing the ray's side); each is classified by the blocker: not
//    covered by an element, within 0.1 L of an open (welded-border) edge, or beside an element;
//  - the same gather from a vertex of the located element, by hit distance.
// Usage: crack_probe SCENE [ELEMENTS] [LEAKS.csv] [GATHER_LEAKS.csv]; CAMCSV, VCSV, NCSV name
// further CSV dumps (camera leaks, vertex leaks, vertex near hits).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "radiosity/mesh/element_scene.h"
#include "radiosity/mesh/mesh.h"
#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/util/closest_point.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"
#include "raytrace_core/scene/scene.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;
using rc::Vec3;

namespace {

struct Key {
  float x, y, z;
  bool operator<(const Key& o) const { return std::memcmp(this, &o, sizeof(Key)) < 0; }
};
Key key(const Vec3& p) { return {p.x + 0.0f, p.y + 0.0f, p.z + 0.0f}; }

/// Distance between segments p0-p1 and q0-q1 (sampled along the first: diagnostic only).
float segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);
float point_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const float t = std::clamp(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-30f), 0.0f, 1.0f);
  return glm::length(p - (a + t * ab));
}

float segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  float best = 1e30f;
  for (int i = 0; i <= 64; ++i) best = std::min(best, point_segment(p0 + (p1 - p0) * (i / 64.0f), q0, q1));
  return best;
}

}  // namespace

/// The point of input mesh s nearest to q within `reach`, facing within 60 degrees of n, as a
/// surface point whose normal is the input triangle's, turned to n's side; none when there is none.
std::optional<rc::scene::SurfacePoint> input_point(const rc::scene::Scene& scene, uint32_t s, const Vec3& q,
                                                   float reach, const Vec3& n) {
  if (s >= scene.meshes.size()) return std::nullopt;
  const auto near = scene.nearest_triangle(s, q, reach, n, 0.5f);
  if (!near) return std::nullopt;
  const rc::scene::TriangleMesh& tm = scene.meshes[s];
  const Vec3 a = tm.positions[tm.indices[3 * near->prim_id]], b = tm.positions[tm.indices[3 * near->prim_id + 1]],
             c = tm.positions[tm.indices[3 * near->prim_id + 2]];
  const Vec3 p_in = (1 - near->u - near->v) * a + near->u * b + near->v * c;
  Vec3 n_in = glm::normalize(glm::cross(b - a, c - a));
  if (glm::dot(n_in, n) < 0) n_in = -n_in;
  return rad::mesh::mesh_surface_point(p_in, n_in);
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: crack_probe SCENE [ELEMENTS] [CSV]\n");
    return 2;
  }
  const rc::scene::Scene scene = rc::io::load_scene(argv[1]);
  std::FILE* camcsv = std::getenv("CAMCSV") ? std::fopen(std::getenv("CAMCSV"), "w") : nullptr;
  rad::mesh::MeshSettings ms;
  ms.elements = argc > 2 ? std::atoi(argv[2]) : rad::mesh::kDefaultElements;
  rad::mesh::MeshReport report;
  const rad::mesh::RadiosityMesh mesh = rad::mesh::build_mesh(scene, ms, &report);
  const rc::scene::Scene geo = rad::mesh::element_scene(scene, mesh);
  std::printf("elements %zu, vertices %zu, edge %.4g, contact edges %zu, buried faces %zu, buried elements %zu, "
              "buried area %.4g of %.4g\n",
              mesh.element_count(), mesh.vertex_count(), report.max_edge, report.contact_edges, report.buried_faces,
              report.buried_elements, report.buried_area, report.meshed_area);
  const float L = report.max_edge;
  {
    std::vector<size_t> per(scene.meshes.size(), 0);
    for (uint32_t s : mesh.element_surface) if (s < per.size()) ++per[s];
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
      rc::Bounds3 b;
      for (const Vec3& p : scene.meshes[m].positions) b.extend(p);
      std::printf("mesh %zu '%s' material '%s': %zu triangles, %zu elements, y %.3g..%.3g\n", m, scene.meshes[m].name.c_str(),
                  scene.materials[scene.meshes[m].material].name.c_str(), scene.meshes[m].triangle_count(), per[m], b.lo.y, b.hi.y);
    }
  }
  const rc::Bounds3 box = scene.bounds();
  std::printf("scene bounds (%.3g %.3g %.3g) - (%.3g %.3g %.3g)\n", box.lo.x, box.lo.y, box.lo.z, box.hi.x, box.hi.y,
              box.hi.z);

  // Open edges of the element mesh, its vertices welded by position.
  std::map<std::pair<Key, Key>, int> uses;
  for (const auto& e : mesh.elements)
    for (int k = 0; k < 3; ++k) {
      Key a = key(mesh.positions[e[k]]), b = key(mesh.positions[e[(k + 1) % 3]]);
      if (b < a) std::swap(a, b);
      ++uses[{a, b}];
    }
  std::vector<std::pair<Vec3, Vec3>> open;
  size_t nonmanifold = 0;
  for (const auto& [edge, count] : uses) {
    if (count == 1) open.push_back({Vec3(edge.first.x, edge.first.y, edge.first.z), Vec3(edge.second.x, edge.second.y, edge.second.z)});
    nonmanifold += count > 2;
  }
  std::printf("welded edges %zu: open %zu, non-manifold %zu\n", uses.size(), open.size(), nonmanifold);

  // Input coverage: area-weighted points on meshed input triangles, distance to the nearest element.
  {
    rc::util::Rng rng(11);
    double total = 0.0, uncovered_far = 0.0, uncovered_mid = 0.0;
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
      const rc::scene::TriangleMesh& tm = scene.meshes[m];
      if (scene.materials[tm.material].is_traced_through()) continue;
      for (size_t t = 0; t < tm.triangle_count(); ++t) {
        const Vec3 a = tm.positions[tm.indices[3 * t]], b = tm.positions[tm.indices[3 * t + 1]],
                   c = tm.positions[tm.indices[3 * t + 2]];
        const float area = 0.5f * glm::length(glm::cross(b - a, c - a));
        const int n = int(area / (0.01f * L * L) + rng.uniform());
        for (int i = 0; i < n; ++i) {
          const rc::Vec2 u = rc::util::sample_uniform_triangle(rng.uniform2());
          const Vec3 p = (1 - u.x - u.y) * a + u.x * b + u.y * c;
          const auto near = geo.nearest_triangle(0, p, L, Vec3(0, 0, 1), -2.0f);
          const float d = near ? near->t : L;
          total += 1;
          if (d > 0.1f * L) uncovered_mid += 1;
          if (d > 0.5f * L) uncovered_far += 1;
        }
      }
    }
    std::printf("input coverage: %.0f points, %.3f %% farther than 0.1 L from an element, %.3f %% farther than 0.5 L\n",
                total, 100.0 * uncovered_mid / total, 100.0 * uncovered_far / total);
  }

  const rc::scene::Light* sun = nullptr;
  for (const rc::scene::Light& l : scene.punctual_lights)
    if (l.kind == rc::scene::LightKind::directional) sun = &l;
  if (!sun) {
    std::fprintf(stderr, "no directional light\n");
    return 1;
  }
  const Vec3 wi = -glm::normalize(sun->direction);

  struct Leak {
    Vec3 q, h;
    float t_in, d_cover, d_open, cos_blocker;
    uint32_t cover_surface = 99, cover_element = 0;
    Vec3 ray_d{0.0f};
    uint32_t element, blocker_mesh, blocker_prim;
    bool blocker_front, blocker_buried, interior;
    int category;
  };
  std::vector<Leak> leaks;
  double lit_elem = 0.0, lit_input = 0.0, both = 0.0, points = 0.0;
  double in_lit_raw = 0.0, in_raw_self = 0.0;
  double in_points = 0.0, in_lit_elem = 0.0, in_lit_input = 0.0, in_leak = 0.0;
  size_t n_in_leak = 0;
  size_t n_lit_elem = 0, n_leak = 0, n_reverse = 0, n_noinput = 0;
  const int side = 4;
  std::vector<float> sun_elem(mesh.element_count(), 0.0f);  // element scene, mean over the element: W/m^2
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& el = mesh.elements[e];
    const Vec3 n = mesh.element_normal[e];
    const float cos_e = glm::dot(n, wi);
    if (!(cos_e > 0.0f)) continue;
    const float w = mesh.element_area[e] * cos_e / float(side * side);
    rc::util::Rng rng = rc::util::Rng::for_item(5, e, 0);
    for (int i = 0; i < side; ++i)
      for (int j = 0; j < side; ++j) {
        const rc::Vec2 b = rc::util::sample_uniform_triangle({(i + rng.uniform()) / side, (j + rng.uniform()) / side});
        const Vec3 q = (1.0f - b.x - b.y) * mesh.positions[el[0]] + b.x * mesh.positions[el[1]] + b.y * mesh.positions[el[2]];
        points += w;
        const bool elem_blocked = geo.occluded(rc::scene::spawn_shadow_ray_to_infinity(rad::mesh::mesh_surface_point(q, n), wi));
        // The input point: nearest on the element's own input mesh, facing within 60 degrees.
        const uint32_t s = mesh.element_surface[e];
        const std::optional<rc::scene::SurfacePoint> found = input_point(scene, s, q, 2.0f * L, n);
        if (!found) {
          ++n_noinput;
          continue;
        }
        const rc::scene::SurfacePoint& at_in = *found;
        std::optional<rc::scene::Hit> hit;
        const rc::scene::Ray ray_in = rc::scene::spawn_shadow_ray_to_infinity(at_in, wi);
        if (glm::dot(at_in.ng, wi) > 0.0f) hit = scene.intersect(ray_in);
        const bool input_blocked = glm::dot(at_in.ng, wi) <= 0.0f || hit.has_value();
        // As the README's experiment did: the element's own point traced against the input.
        const bool raw_blocked = scene.occluded(rc::scene::spawn_shadow_ray_to_infinity(rad::mesh::mesh_surface_point(q, n), wi));
        // Interior: under a roof (an upward ray from the input point meets the input).
        const bool interior = scene.occluded(rc::scene::spawn_shadow_ray_to_infinity(at_in, Vec3(0, 1, 0)));
        if (interior) {
          in_points += w;
          if (!elem_blocked) in_lit_elem += w;
          if (!input_blocked) in_lit_input += w;
          if (!raw_blocked) in_lit_raw += w;
          if (!elem_blocked && raw_blocked && !input_blocked) in_raw_self += w;
          if (!elem_blocked && input_blocked) in_leak += w, ++n_in_leak;
        }
        if (!elem_blocked) lit_elem += w, ++n_lit_elem, sun_elem[e] += sun->irradiance.luminance() * cos_e / float(side * side);
        if (!input_blocked) lit_input += w;
        if (!elem_blocked && !input_blocked) both += w;
        if (elem_blocked && !input_blocked) ++n_reverse;
        if (!elem_blocked && input_blocked) {
          ++n_leak;
          Leak k{};
          k.q = q;
          k.element = uint32_t(e);
          k.interior = interior;
          if (!hit) {  // the input point faces away from the sun
            k.category = 0;
            k.t_in = 0;
            leaks.push_back(k);
            continue;
          }
          k.t_in = hit->t;
          k.h = ray_in.origin + hit->t * wi;
          k.blocker_mesh = hit->geom_id;
          k.blocker_prim = hit->prim_id;
          k.blocker_front = scene.surface(ray_in, *hit).front_face;
          const auto cover = geo.nearest_triangle(0, k.h, L, Vec3(0, 0, 1), -2.0f);
          k.d_cover = cover ? cover->t : L;
          k.d_open = 1e30f;
          for (const auto& [u, v] : open) k.d_open = std::min(k.d_open, point_segment(k.h, u, v));
          leaks.push_back(k);
        }
      }
  }
  std::printf("sun: %zu element points lit in the element scene; leaks (lit there, shadowed in input) %zu, "
              "reverse %zu, no input point %zu\n",
              n_lit_elem, n_leak, n_reverse, n_noinput);
  std::printf("sun irradiance x area: element scene %.4g, input %.4g, ratio %.4f; leak share of element-lit %.4f\n",
              lit_elem, lit_input, lit_elem / lit_input, (lit_elem - both) / lit_elem);

  std::printf("interior (under a roof): sun irradiance x area: element scene %.4g, input %.4g, ratio %.4f; "
              "leaks %zu, %.4f of element-lit\n",
              in_lit_elem, in_lit_input, in_lit_elem / in_lit_input, n_in_leak, in_leak / in_lit_elem);
  std::printf("interior: element points traced against the input unprojected: %.4g lit (%.4f of the element scene's); "
              "lit in both the element scene and the projected input point but shadowed so: %.4f of the element scene's\n",
              in_lit_raw, in_lit_raw / in_lit_elem, in_raw_self / in_lit_elem);
  // Categories.
  const bool interior_only = std::getenv("INTERIOR") != nullptr;
  size_t cat_facing = 0, cat_near_self = 0, cat_uncovered = 0, cat_open = 0, cat_beside = 0;
  for (Leak& k : leaks) {
    if (interior_only && !k.interior) { k.category = -1; continue; }
    if (k.category == 0 && k.t_in == 0) {
      ++cat_facing;
      continue;
    }
    if (k.t_in < 0.05f * L) k.category = 1, ++cat_near_self;
    else if (k.d_cover > 0.1f * L) k.category = 2, ++cat_uncovered;
    else if (k.d_open < 0.1f * L) k.category = 3, ++cat_open;
    else k.category = 4, ++cat_beside;
  }
  std::printf("leak categories: input point faces away %zu; blocker within 0.05 L %zu; blocker not covered by an "
              "element (> 0.1 L) %zu; blocker within 0.1 L of an open edge %zu; beside a covering element %zu\n",
              cat_facing, cat_near_self, cat_uncovered, cat_open, cat_beside);
  // Buried test on uncovered blockers (costly: only those).
  size_t buried = 0;
  for (Leak& k : leaks)
    if (k.category == 2) {
      const rc::scene::TriangleMesh& tm = scene.meshes[k.blocker_mesh];
      const uint32_t* idx = &tm.indices[3 * size_t(k.blocker_prim)];
      k.blocker_buried = rad::mesh::input_triangle_buried(scene, tm.positions[idx[0]], tm.positions[idx[1]], tm.positions[idx[2]]);
      buried += k.blocker_buried;
    }
  std::printf("  of the uncovered blockers, %zu are input triangles that test as buried\n", buried);
  // Gather rays from interior points (cosine over the element's front, as a form factor sees):
  // the reflected sunlight each reaches in the element scene, against the same ray in the input.
  {
    rc::util::Rng rng(17);
    double read_elem = 0, read_in = 0, rays = 0, leak_rays = 0, leak_light = 0, leak_sky = 0, rev_light = 0;
    size_t n_leak_sky = 0, n_leak_lit = 0;
    std::vector<Leak> gleaks;
    const auto reflected = [&](uint32_t e) {
      return rc::scene::diffuse_reflectance(scene.materials[mesh.element_material[e]]).luminance() * sun_elem[e] / 3.14159265f;
    };
    for (size_t e = 0; e < mesh.element_count(); ++e) {
      const auto& el = mesh.elements[e];
      const Vec3 n = mesh.element_normal[e];
      const uint32_t s = mesh.element_surface[e];
      if (s >= scene.meshes.size()) continue;
      for (int r = 0; r < 4; ++r) {
        const rc::Vec2 b = rc::util::sample_uniform_triangle(rng.uniform2());
        const Vec3 q = (1.0f - b.x - b.y) * mesh.positions[el[0]] + b.x * mesh.positions[el[1]] + b.y * mesh.positions[el[2]];
        const std::optional<rc::scene::SurfacePoint> found = input_point(scene, s, q, 2.0f * L, n);
        if (!found) continue;
        const rc::scene::SurfacePoint& at_in = *found;
        if (!scene.occluded(rc::scene::spawn_shadow_ray_to_infinity(at_in, Vec3(0, 1, 0)))) continue;  // interior only
        const Vec3 wl = rc::util::sample_cosine_hemisphere(rng.uniform2());
        const Vec3 w = rc::Frame::from_normal(n).to_world(wl);
        if (!(glm::dot(w, at_in.ng) > 0.0f)) continue;
        rays += 1;
        const rc::scene::Ray ray_e = rc::scene::spawn_ray(rad::mesh::mesh_surface_point(q, n), w);
        const rc::scene::Ray ray_i = rc::scene::spawn_ray(at_in, w);
        const auto he = geo.intersect(ray_e);
        const auto hi = scene.intersect(ray_i);
        float le = 0.0f, li = 0.0f;
        if (he && he->geom_id == 0 && geo.surface(ray_e, *he).front_face) le = reflected(he->prim_id);
        if (hi) {
          const rc::scene::SurfaceInteraction si = scene.surface(ray_i, *hi);
          const Vec3 lit = si.front_face ? si.ng : -si.ng;
          const auto loc = geo.nearest_triangle(0, si.p, 2.0f * L, lit, 0.5f);
          if (loc) li = reflected(loc->prim_id);
        }
        read_elem += le;
        read_in += li;
        const float te = he ? he->t : 1e30f;
        // The element hit stands for the input's blocker when the blocker's point lies within
        // 0.15 L of the hit element (a chord of a curved or detailed surface, hit at a grazing angle).
        bool same = false;
        if (hi && he && he->geom_id == 0) {
          const Vec3 h = ray_i.origin + hi->t * w;
          const auto& ee = mesh.elements[he->prim_id];
          const rc::Vec2 uv = rc::util::closest_point_on_triangle(h, mesh.positions[ee[0]], mesh.positions[ee[1]], mesh.positions[ee[2]]);
          const Vec3 x = (1 - uv.x - uv.y) * mesh.positions[ee[0]] + uv.x * mesh.positions[ee[1]] + uv.y * mesh.positions[ee[2]];
          const rc::scene::SurfaceInteraction sb = scene.surface(ray_i, *hi);
          const Vec3 side_b = glm::dot(sb.ng, w) < 0.0f ? sb.ng : -sb.ng;  // the blocker's side the ray meets
          same = glm::length(x - h) < 0.15f * L && glm::dot(side_b, mesh.element_normal[he->prim_id]) > 0.5f;
        }
        if (hi && te > hi->t + 0.01f * L && !same) {
          leak_rays += 1;
          leak_light += le;
          if (!he) leak_sky += 1, ++n_leak_sky;
          if (le > 0) ++n_leak_lit;
          Leak k{};
          k.q = q;
          k.element = uint32_t(e);
          k.t_in = hi->t;
          k.h = ray_i.origin + hi->t * w;
          k.blocker_mesh = hi->geom_id;
          k.blocker_prim = hi->prim_id;
          k.blocker_front = scene.surface(ray_i, *hi).front_face;
          const auto cover = geo.nearest_triangle(0, k.h, L, Vec3(0, 0, 1), -2.0f);
          k.d_cover = cover ? cover->t : L;
          k.cover_surface = cover ? mesh.element_surface[cover->prim_id] : 99;
          k.cover_element = cover ? cover->prim_id : 0;
          k.ray_d = w;
          k.d_open = 1e30f;
          k.interior = le > 0;  // reused: the leak reads sunlight
          if (le > 0 || !he) {
            const Vec3 s0 = ray_i.origin + std::max(0.0f, hi->t - L) * w, s1 = ray_i.origin + (hi->t + L) * w;
            for (const auto& [u, v] : open) {
              if (point_segment(k.h, u, v) > 3 * L) continue;
              k.d_open = std::min(k.d_open, segment_segment(s0, s1, u, v));
            }
            const rc::scene::SurfaceInteraction si = scene.surface(ray_i, *hi);
            k.cos_blocker = std::abs(glm::dot(si.ng, w));
          }
          k.category = !he ? 5 : 6;
          gleaks.push_back(k);
        }
        if (he && hi && hi->t > te + 0.1f * L) rev_light += li;
      }
    }
    std::printf("gather from interior points: %.0f rays; reflected sun read: element scene %.5g, input %.5g, ratio %.4f\n",
                rays, read_elem / rays, read_in / rays, read_elem / read_in);
    std::printf("  rays passing the input's first hit by > 0.1 L in the element scene: %.0f (%.3f %%), %zu to the sky, "
                "%zu to a sunlit element; their sunlight %.4f of the element scene's total; reverse %.4f\n",
                leak_rays, 100 * leak_rays / rays, n_leak_sky, n_leak_lit, leak_light / read_elem, rev_light / read_in);
    size_t cover = 0, open_near = 0, beside = 0;
    for (const Leak& k : gleaks) {
      if (!(k.interior || k.category == 5)) continue;
      if (k.d_cover > 0.1f * L) ++cover;
      else if (k.d_open < 0.1f * L) ++open_near;
      else ++beside;
    }
    std::printf("  sunlit or sky leaks by blocker: not covered by an element %zu, within 0.1 L of an open edge %zu, "
                "beside a covering element %zu\n", cover, open_near, beside);
    if (argc > 4) {
      std::ofstream csv(argv[4]);
      csv << "qx,qy,qz,hx,hy,hz,t_in,d_cover,d_open,element,surface,blocker_mesh,blocker_prim,front,sunlit,category,cos,cover_surface,cover_element,dx,dy,dz\n";
      for (const Leak& k : gleaks)
        csv << k.q.x << ',' << k.q.y << ',' << k.q.z << ',' << k.h.x << ',' << k.h.y << ',' << k.h.z << ',' << k.t_in << ','
            << k.d_cover << ',' << k.d_open << ',' << k.element << ',' << mesh.element_surface[k.element] << ','
            << k.blocker_mesh << ',' << k.blocker_prim << ',' << k.blocker_front << ',' << k.interior << ','
            << k.category << ',' << k.cos_blocker << ',' << k.cover_surface << ',' << k.cover_element << ','
            << k.ray_d.x << ',' << k.ray_d.y << ',' << k.ray_d.z << '\n';
    }
  }
  // Camera-weighted: points the camera sees (256 x 192), each located on its element as the view
  // does, gather 16 cosine rays from the element point (element scene) and from the input point.
  {
    const rc::scene::Camera cam = scene.effective_camera(256.0f / 192.0f);
    const Vec3 fwd = glm::normalize(cam.look_at - cam.look_from), right = glm::normalize(glm::cross(fwd, cam.up)),
               up = glm::cross(right, fwd);
    const float th = std::tan(0.5f * cam.vfov_degrees * 3.14159265f / 180.0f);
    const auto reflected = [&](uint32_t e) {
      return rc::scene::diffuse_reflectance(scene.materials[mesh.element_material[e]]).luminance() * sun_elem[e] / 3.14159265f;
    };
    rc::util::Rng rng(23);
    double cam_bin[2][4] = {};
    double true_v_bin[4] = {};
    double read_near = 0, read_ve = 0, read_v_bin[4] = {}, read_n_bin[4] = {};
    double read_v = 0, nv_rays = 0, vleak = 0, vleak_below = 0;
    std::FILE* ncsv = std::getenv("NCSV") ? std::fopen(std::getenv("NCSV"), "w") : nullptr;
    if (ncsv) std::fprintf(ncsv, "v,elem,hit,px,py,pz,nx,ny,nz,hnx,hny,hnz,t,l,size,surf,hsurf,wx,wy,wz\n");
    std::FILE* vcsv = std::getenv("VCSV") ? std::fopen(std::getenv("VCSV"), "w") : nullptr;
    double ex_bin[2][4] = {}, ex_abs[2][4] = {}, ex_lit[2] = {};
    double read_pt = 0;
    double read_t = 0, read_e = 0, read_i = 0, leak_e = 0, leak_sky = 0, nrays = 0, nleak = 0, unlocated = 0, pix = 0;
    double leak_open = 0, leak_uncovered = 0, leak_beside = 0;
    for (int y = 0; y < 192; ++y)
      for (int x = 0; x < 256; ++x) {
        const Vec3 d = glm::normalize(fwd + ((2 * (x + 0.5f) / 256 - 1) * th * 256.0f / 192.0f) * right +
                                      ((1 - 2 * (y + 0.5f) / 192) * th) * up);
        const rc::scene::Ray cr{cam.look_from, d, rc::kInfinity};
        const auto ch = scene.intersect(cr);
        if (!ch) continue;
        const rc::scene::SurfaceInteraction si = scene.surface(cr, *ch);
        if (scene.materials[si.material].is_traced_through()) continue;
        ++pix;
        const Vec3 lit = si.front_face ? si.ng : -si.ng;
        const auto loc = geo.nearest_triangle(0, si.p, 2.0f * L, lit, 0.5f);
        if (!loc) {
          ++unlocated;
          continue;
        }
        {
          const bool other = mesh.element_surface[loc->prim_id] != ch->geom_id;
          const int bin = loc->t < 0.01f * L ? 0 : loc->t < 0.05f * L ? 1 : loc->t < 0.15f * L ? 2 : 3;
          cam_bin[other][bin] += 1;
        }
        const auto& el = mesh.elements[loc->prim_id];
        const Vec3 q = (1 - loc->u - loc->v) * mesh.positions[el[0]] + loc->u * mesh.positions[el[1]] + loc->v * mesh.positions[el[2]];
        const Vec3 n = mesh.element_normal[loc->prim_id];
        {
          // The same gather from one of the element's vertices, chosen by barycentric weight.
          const float u = rng.uniform();
          const int k = u < 1 - loc->u - loc->v ? 0 : u < 1 - loc->v ? 1 : 2;
          const uint32_t v = el[k];
          const Vec3 c = (mesh.positions[el[0]] + mesh.positions[el[1]] + mesh.positions[el[2]]) / 3.0f;
          const Vec3 nv = mesh.normals[v];
          const Vec3 towards = c - mesh.positions[v];
          const float size = glm::length(towards);
          const Vec3 pv = mesh.positions[v] + 1e-3f * (towards - glm::dot(towards, nv) * nv + size * nv);
          const rc::Frame fv = rc::Frame::from_normal(nv);
          std::optional<rc::scene::SurfacePoint> vin;
          {
            const uint32_t sv = mesh.element_surface[loc->prim_id];
            const auto nn = sv < scene.meshes.size() ? scene.nearest_triangle(sv, pv, 2.0f * L, nv, 0.5f) : std::nullopt;
            if (nn) {
              const rc::scene::TriangleMesh& tm = scene.meshes[sv];
              const Vec3 a = tm.positions[tm.indices[3 * nn->prim_id]], bb = tm.positions[tm.indices[3 * nn->prim_id + 1]],
                         cc = tm.positions[tm.indices[3 * nn->prim_id + 2]];
              Vec3 ni = glm::normalize(glm::cross(bb - a, cc - a));
              if (glm::dot(ni, nv) < 0) ni = -ni;
              vin = rad::mesh::mesh_surface_point((1 - nn->u - nn->v) * a + nn->u * bb + nn->v * cc, ni);
            }
          }
          for (int r = 0; r < 16; ++r) {
            const Vec3 w = fv.to_world(rc::util::sample_cosine_hemisphere(rng.uniform2()));
            const auto hv = geo.intersect(rc::scene::spawn_ray(rad::mesh::mesh_surface_point(pv, nv), w));
            float lv = 0.0f;
            if (hv && hv->geom_id == 0 && glm::dot(mesh.element_normal[hv->prim_id], w) < 0.0f) lv = reflected(hv->prim_id);
            read_v += lv;
            if (hv) read_v_bin[hv->t < 0.02f * L ? 0 : hv->t < 0.1f * L ? 1 : hv->t < 0.5f * L ? 2 : 3] += lv;
            if (hv && lv > 0) {
              // The sun at the input point under the hit: what the element's mean stands for there.
              const uint32_t e2 = hv->prim_id, s2 = mesh.element_surface[e2];
              const Vec3 x2 =
                  rc::scene::spawn_ray(rad::mesh::mesh_surface_point(pv, nv), w).origin + hv->t * w;
              const Vec3 n2 = mesh.element_normal[e2];
              float tr = 0.0f;
              const auto nn = s2 < scene.meshes.size() ? scene.nearest_triangle(s2, x2, L, n2, 0.5f) : std::nullopt;
              if (nn) {
                const rc::scene::TriangleMesh& tm = scene.meshes[s2];
                const Vec3 a = tm.positions[tm.indices[3 * nn->prim_id]], bb = tm.positions[tm.indices[3 * nn->prim_id + 1]],
                           cc = tm.positions[tm.indices[3 * nn->prim_id + 2]];
                Vec3 ni = glm::normalize(glm::cross(bb - a, cc - a));
                if (glm::dot(ni, n2) < 0) ni = -ni;
                const rc::scene::SurfacePoint sp = rad::mesh::mesh_surface_point((1 - nn->u - nn->v) * a + nn->u * bb + nn->v * cc, ni);
                const float cs = glm::dot(ni, wi);
                if (cs > 0 && !scene.occluded(rc::scene::spawn_shadow_ray_to_infinity(sp, wi)))
                  tr = rc::scene::diffuse_reflectance(scene.materials[mesh.element_material[e2]]).luminance() * sun->irradiance.luminance() * cs / 3.14159265f;
              }
              const int bin = hv->t < 0.02f * L ? 0 : hv->t < 0.1f * L ? 1 : hv->t < 0.5f * L ? 2 : 3;
              true_v_bin[bin] += tr;
            }
            if (hv && lv > 0 && hv->t < 0.02f * L && ncsv) {
              const uint32_t he2 = hv->prim_id;
              const Vec3 ne2 = mesh.element_normal[he2];
              std::fprintf(ncsv, "%u,%u,%u,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%u,%u,%g,%g,%g\n", v, loc->prim_id, he2,
                           mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z, nv.x, nv.y, nv.z, ne2.x, ne2.y,
                           ne2.z, hv->t, lv, size, mesh.element_surface[loc->prim_id], mesh.element_surface[he2], w.x, w.y, w.z);
            }
            nv_rays += 1;
            {
              // Variants: near the vertex inside the element (barycentric 0.9) with the element's normal,
              // and at the vertex with the element's normal.
              const Vec3 ne = mesh.element_normal[loc->prim_id];
              const Vec3 pn = 0.9f * mesh.positions[v] + 0.05f * (3.0f * c - mesh.positions[v]);
              const rc::Frame fe = rc::Frame::from_normal(ne);
              const Vec3 we = fe.to_world(fv.to_local(w));
              const auto h1 = geo.intersect(rc::scene::spawn_ray(rad::mesh::mesh_surface_point(pn, ne), we));
              if (h1 && h1->geom_id == 0 && glm::dot(mesh.element_normal[h1->prim_id], we) < 0.0f) {
                read_near += reflected(h1->prim_id);
                read_n_bin[h1->t < 0.02f * L ? 0 : h1->t < 0.1f * L ? 1 : h1->t < 0.5f * L ? 2 : 3] += reflected(h1->prim_id);
              }
              const Vec3 pve = mesh.positions[v] + 1e-3f * (towards - glm::dot(towards, ne) * ne + size * ne);
              const auto h2 = geo.intersect(rc::scene::spawn_ray(rad::mesh::mesh_surface_point(pve, ne), we));
              if (h2 && h2->geom_id == 0 && glm::dot(mesh.element_normal[h2->prim_id], we) < 0.0f) read_ve += reflected(h2->prim_id);
            }
            if (!(lv > 0.0f) || !vin) continue;
            // Against the input from the vertex's input point: does the element ray pass the input's blocker?
            const rc::scene::Ray ri = rc::scene::spawn_ray(*vin, w);
            const auto hi = scene.intersect(ri);
            if (!hi || glm::dot(w, vin->ng) <= 0.0f) {
              if (glm::dot(w, vin->ng) <= 0.0f) vleak_below += lv;
              continue;
            }
            const Vec3 h = ri.origin + hi->t * w;
            const auto& ee = mesh.elements[hv->prim_id];
            const rc::Vec2 uv = rc::util::closest_point_on_triangle(h, mesh.positions[ee[0]], mesh.positions[ee[1]], mesh.positions[ee[2]]);
            const Vec3 xx = (1 - uv.x - uv.y) * mesh.positions[ee[0]] + uv.x * mesh.positions[ee[1]] + uv.y * mesh.positions[ee[2]];
            const rc::scene::SurfaceInteraction sb = scene.surface(ri, *hi);
            const Vec3 side_b = glm::dot(sb.ng, w) < 0.0f ? sb.ng : -sb.ng;
            const bool vsame = glm::length(xx - h) < 0.15f * L && glm::dot(side_b, mesh.element_normal[hv->prim_id]) > 0.5f;
            if (!vsame && hv->t > hi->t + 0.01f * L) {
              vleak += lv;
              if (vcsv) std::fprintf(vcsv, "%u,%g,%g,%g,%g,%g,%g,%g,%u,%u,%g,%g\n", v, pv.x, pv.y, pv.z, h.x, h.y, h.z, hi->t,
                                     hi->geom_id, mesh.element_surface[hv->prim_id], hv->t, lv);
            }
          }
        }
        rc::scene::SurfacePoint at_in = si;
        at_in.ng = lit;
        const rc::Frame frame = rc::Frame::from_normal(lit);
        for (int r = 0; r < 16; ++r) {
          const Vec3 w = frame.to_world(rc::util::sample_cosine_hemisphere(rng.uniform2()));
          if (!(glm::dot(w, n) > 0.0f)) continue;
          nrays += 1;
          const rc::scene::Ray ray_e = rc::scene::spawn_ray(rad::mesh::mesh_surface_point(q, n), w);
          const rc::scene::Ray ray_i = rc::scene::spawn_ray(at_in, w);
          const auto he = geo.intersect(ray_e);
          const auto hi = scene.intersect(ray_i);
          float le = 0.0f, li = 0.0f;
          if (he && he->geom_id == 0 && geo.surface(ray_e, *he).front_face) {
            le = reflected(he->prim_id);
            // The sun at the hit point itself, in the element scene: what a finer direct light would give.
            const Vec3 ne2 = mesh.element_normal[he->prim_id];
            const float c2 = glm::dot(ne2, wi);
            const Vec3 x2 = ray_e.origin + he->t * w;
            if (c2 > 0.0f && !geo.occluded(rc::scene::spawn_shadow_ray_to_infinity(rad::mesh::mesh_surface_point(x2, ne2), wi)))
              read_pt += rc::scene::diffuse_reflectance(scene.materials[mesh.element_material[he->prim_id]]).luminance() *
                         sun->irradiance.luminance() * c2 / 3.14159265f;
          }
          if (hi) {
            const rc::scene::SurfaceInteraction sj = scene.surface(ray_i, *hi);
            const Vec3 lj = sj.front_face ? sj.ng : -sj.ng;
            // Truth: the sun at the input point itself.
            float truth = 0.0f;
            const float cs = glm::dot(lj, wi);
            rc::scene::SurfacePoint sp = sj;
            sp.ng = lj;
            if (cs > 0.0f && !scene.occluded(rc::scene::spawn_shadow_ray_to_infinity(sp, wi)))
              truth = rc::scene::diffuse_reflectance(scene.materials[sj.material]).luminance() * sun->irradiance.luminance() * cs / 3.14159265f;
            read_t += truth;
            const auto lo = geo.nearest_triangle(0, sj.p, 0.5f * L, lj, 0.5f);
            li = lo ? reflected(lo->prim_id) : truth;
            if (lo) {
              const double excess = li - truth;
              const bool other = mesh.element_surface[lo->prim_id] != hi->geom_id;
              const int bin = lo->t < 0.01f * L ? 0 : lo->t < 0.05f * L ? 1 : lo->t < 0.15f * L ? 2 : 3;
              ex_bin[other][bin] += excess;
              ex_abs[other][bin] += std::abs(excess);
              // the located element's own lit fraction vs the point's
              ex_lit[truth > 0 ? 1 : 0] += excess;
            }
          }
          read_e += le;
          read_i += li;
          const float te = he ? he->t : 1e30f;
          bool same = false;
          Vec3 h(0.0f);
          if (hi) h = ray_i.origin + hi->t * w;
          if (hi && he && he->geom_id == 0) {
            const auto& ee = mesh.elements[he->prim_id];
            const rc::Vec2 uv = rc::util::closest_point_on_triangle(h, mesh.positions[ee[0]], mesh.positions[ee[1]], mesh.positions[ee[2]]);
            const Vec3 xx = (1 - uv.x - uv.y) * mesh.positions[ee[0]] + uv.x * mesh.positions[ee[1]] + uv.y * mesh.positions[ee[2]];
            const rc::scene::SurfaceInteraction sb = scene.surface(ray_i, *hi);
            const Vec3 side_b = glm::dot(sb.ng, w) < 0.0f ? sb.ng : -sb.ng;
            same = glm::length(xx - h) < 0.15f * L && glm::dot(side_b, mesh.element_normal[he->prim_id]) > 0.5f;
          }
          if (hi && te > hi->t + 0.01f * L && !same) {
            nleak += 1;
            leak_e += le;
            if (!he) leak_sky += 1;
            if (le > 0) {
              const auto cover = geo.nearest_triangle(0, h, L, Vec3(0, 0, 1), -2.0f);
              const float dc = cover ? cover->t : L;
              float dop = 1e30f;
              const Vec3 s0 = ray_i.origin + std::max(0.0f, hi->t - L) * w, s1 = ray_i.origin + (hi->t + L) * w;
              for (const auto& [u, v] : open)
                if (point_segment(h, u, v) < 3 * L) dop = std::min(dop, segment_segment(s0, s1, u, v));
              if (dc > 0.1f * L) leak_uncovered += le;
              else if (dop < 0.1f * L) leak_open += le;
              else leak_beside += le;
              if (camcsv) std::fprintf(camcsv, "%g,%g,%g,%g,%g,%g,%g,%g,%g,%u,%u,%g\n", q.x, q.y, q.z, h.x, h.y, h.z,
                                       hi->t, dc, dop, hi->geom_id, cover ? mesh.element_surface[cover->prim_id] : 99u, le);
            }
          }
        }
      }
    std::printf("camera: %.0f pixels on diffuse surfaces, %.0f without an element; %.0f gather rays\n", pix, unlocated, nrays);
    std::printf("  reflected sun read: truth (input rays, sun at the hit) %.5g; input rays reading the element there %.5g "
                "(%.4f of truth); element-scene rays reading elements %.5g (%.4f of truth, %.4f of the previous)\n",
                read_t / nrays, read_i / nrays, read_i / read_t, read_e / nrays, read_e / read_t, read_e / read_i);
    std::printf("  element-scene rays reading the sun at the hit point instead of the element's mean: %.5g; mean / point %.4f\n",
                read_pt / nrays, read_e / read_pt);
    std::printf("  vertex gather (element scene, from a vertex of the located element): %.5g per ray, %.4f of the point gather\n",
                read_v / nv_rays, (read_v / nv_rays) / (read_e / nrays));
    std::printf("  near the vertex inside the element (element normal): %.4f of the point gather; at the vertex with the "
                "element's normal: %.4f\n", (read_near / nv_rays) / (read_e / nrays), (read_ve / nv_rays) / (read_e / nrays));
    std::printf("  by hit distance <0.02L/<0.1L/<0.5L/more, per ray: vertex %.3g %.3g %.3g %.3g; near-vertex point %.3g %.3g %.3g %.3g\n",
                read_v_bin[0] / nv_rays, read_v_bin[1] / nv_rays, read_v_bin[2] / nv_rays, read_v_bin[3] / nv_rays,
                read_n_bin[0] / nv_rays, read_n_bin[1] / nv_rays, read_n_bin[2] / nv_rays, read_n_bin[3] / nv_rays);
    std::printf("  vertex gather, sun at the input point under each lit hit (vs the element's mean), per ray: %.3g %.3g %.3g %.3g\n",
                true_v_bin[0] / nv_rays, true_v_bin[1] / nv_rays, true_v_bin[2] / nv_rays, true_v_bin[3] / nv_rays);
    std::printf("  of the vertex gather's sunlight: %.4f through the input's blocker (leaks), %.4f below the input point's plane\n",
                vleak / read_v, vleak_below / read_v);
    for (int o = 0; o < 2; ++o)
      std::printf("  camera points located on an element of the %s mesh at <0.01L/<0.05L/<0.15L/more: %.4f %.4f %.4f %.4f\n",
                  o ? "other" : "same", cam_bin[o][0] / pix, cam_bin[o][1] / pix, cam_bin[o][2] / pix, cam_bin[o][3] / pix);
    for (int o = 0; o < 2; ++o)
      std::printf("  excess of the located element over the truth, %s mesh, by distance <0.01L/<0.05L/<0.15L/more: "
                  "%.4f %.4f %.4f %.4f (abs %.4f %.4f %.4f %.4f) of truth\n", o ? "other" : "same",
                  ex_bin[o][0] / read_t, ex_bin[o][1] / read_t, ex_bin[o][2] / read_t, ex_bin[o][3] / read_t,
                  ex_abs[o][0] / read_t, ex_abs[o][1] / read_t, ex_abs[o][2] / read_t, ex_abs[o][3] / read_t);
    std::printf("  excess where the point is shadowed %.4f, sunlit %.4f of truth\n", ex_lit[0] / read_t, ex_lit[1] / read_t);
    std::printf("  leak rays %.0f (%.3f %%), %.0f to the sky; their sunlight %.4f of the element scene's "
                "(uncovered blocker %.4f, open edge %.4f, beside %.4f)\n",
                nleak, 100 * nleak / nrays, leak_sky, leak_e / read_e, leak_uncovered / read_e, leak_open / read_e,
                leak_beside / read_e);
  }
  if (argc > 3) {
    std::ofstream csv(argv[3]);
    csv << "qx,qy,qz,hx,hy,hz,t_in,d_cover,d_open,element,surface,blocker_mesh,blocker_prim,front,buried,interior,category\n";
    for (const Leak& k : leaks)
      csv << k.q.x << ',' << k.q.y << ',' << k.q.z << ',' << k.h.x << ',' << k.h.y << ',' << k.h.z << ',' << k.t_in << ','
          << k.d_cover << ',' << k.d_open << ',' << k.element << ',' << mesh.element_surface[k.element] << ','
          << k.blocker_mesh << ',' << k.blocker_prim << ',' << k.blocker_front << ',' << k.blocker_buried << ',' << k.interior << ','
          << k.category << '\n';
  }
  return 0;
}

// The radiosity mesh: each diffuse or glossy surface is mended and remeshed (mesh_repair.cpp),
// spheres are tessellated as geodesic spheres, and vertices are split along creases so that a
// vertex's normal belongs to one smooth side of the surface.

#include "radiosity/mesh/mesh.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "radiosity/mesh/mesh_detail.h"
#include "radiosity/mesh/sides.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/progress.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::mesh {
namespace detail {
namespace {

/// Largest element count build_mesh() accepts: far beyond what a solver can shoot, small enough
/// that a mistaken size fails with a message instead of exhausting memory.
constexpr double kMaxElements = 2e7;

/// CGAL's isotropic remeshing splits edges longer than 4/3 of its target and collapses those
/// shorter than 4/5; the halves of split edges land low in that range, so its mean edge settles
/// below the target. Measured on the Cornell box with borders cut to the target (L = 20, 40, 80 and
/// the default): mean edge 0.89–0.91 of the target. Asking for L / 0.89 makes the mean edge L and
/// the element count the one requested, within a few per cent.
constexpr double kRemeshTargetScale = 1.12;

/// Area of an equilateral triangle of unit edge, √3/4.
constexpr double kUnitEquilateralArea = 0.43301270189221932338;

DVec3 triangle_cross(const TriangleSoup& soup, const std::array<uint32_t, 3>& t) {
  return glm::cross(soup.points[t[1]] - soup.points[t[0]], soup.points[t[2]] - soup.points[t[0]]);
}

/// Union–find over triangle corners.
struct FanSets {
  std::vector<size_t> parent;
  size_t find(size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
};

}  // namespace

TriangleSoup tessellate_sphere(const DVec3& center, double radius, int frequency) {
  const int n = std::max(1, frequency);
  // Icosahedron: the cyclic permutations of (0, ±1, ±φ); its faces are the triples of mutually
  // adjacent corners (edge length 2), turned to face outwards.
  const double phi = 0.5 * (1.0 + std::sqrt(5.0));
  std::vector<DVec3> corners;
  for (double a : {-1.0, 1.0})
    for (double b : {-phi, phi}) {
      corners.emplace_back(0.0, a, b);
      corners.emplace_back(a, b, 0.0);
      corners.emplace_back(b, 0.0, a);
    }
  const auto adjacent = [&](int i, int j) {
    return std::abs(glm::distance(corners[i], corners[j]) - 2.0) < 1e-9;
  };
  std::vector<std::array<int, 3>> faces;
  for (int i = 0; i < 12; ++i)
    for (int j = i + 1; j < 12; ++j)
      for (int k = j + 1; k < 12; ++k)
        if (adjacent(i, j) && adjacent(j, k) && adjacent(i, k)) {
          const DVec3 normal = glm::cross(corners[j] - corners[i], corners[k] - corners[i]);
          if (glm::dot(normal, corners[i]) > 0.0)
            faces.push_back({i, j, k});
          else
            faces.push_back({i, k, j});
        }

  // A point of the subdivision is a weighted sum of icosahedron corners with integer weights
  // summing to n; keyed by its (corner, weight) pairs in corner order, points on shared edges and
  // corners are found once and computed once, so neighbouring faces share them exactly.
  using Key = std::array<int, 6>;
  std::map<Key, uint32_t> index_of;
  TriangleSoup soup;
  const auto point = [&](const std::array<int, 3>& face, int wb, int wc) {
    std::array<std::pair<int, int>, 3> terms = {{{face[0], n - wb - wc}, {face[1], wb}, {face[2], wc}}};
    std::sort(terms.begin(), terms.end());
    Key key{};
    int m = 0;
    for (const auto& [corner, weight] : terms)
      if (weight > 0) {
        key[m++] = corner;
        key[m++] = weight;
      }
    for (; m < 6; m += 2) key[m] = -1;
    const auto [it, inserted] = index_of.emplace(key, static_cast<uint32_t>(soup.points.size()));
    if (inserted) {
      DVec3 sum(0.0);
      for (int i = 0; i < 6 && key[i] >= 0; i += 2) sum += double(key[i + 1]) * corners[key[i]];
      soup.points.push_back(center + radius * glm::normalize(sum));
    }
    return it->second;
  };
  soup.triangles.reserve(size_t(20) * n * n);
  for (const auto& face : faces)
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j) {
        soup.triangles.push_back({point(face, i, j), point(face, i + 1, j), point(face, i, j + 1)});
        if (i + j + 1 < n)
          soup.triangles.push_back({point(face, i + 1, j), point(face, i + 1, j + 1), point(face, i, j + 1)});
      }
  return soup;
}

SplitSurface split_sharp_vertices(const TriangleSoup& soup, double sharp_angle_degrees) {
  const size_t nt = soup.triangles.size();
  std::vector<DVec3> face_cross(nt);  // |cross| = twice the area
  std::vector<DVec3> face_normal(nt);
  for (size_t t = 0; t < nt; ++t) {
    face_cross[t] = triangle_cross(soup, soup.triangles[t]);
    face_normal[t] = glm::normalize(face_cross[t]);
  }

  // Corner 3t + k is triangle t at its k-th vertex. Two triangles that share an edge smoothly,
  // with opposite windings along it (a manifold, consistently oriented edge), put the two
  // corners at each end of the edge in one set; every set becomes an output vertex. Edges of
  // three or more triangles, or of two wound the same way, join nothing, so any input gives
  // a surface whose every vertex has a single fan.
  struct EdgeUse {
    uint64_t key;      // the two vertex indices, smaller first
    uint32_t corner;   // corner of the edge's first vertex (in winding order)
    bool forward;      // winding runs from the smaller index to the larger
  };
  std::vector<EdgeUse> uses;
  uses.reserve(3 * nt);
  for (size_t t = 0; t < nt; ++t)
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t a = soup.triangles[t][k], b = soup.triangles[t][(k + 1) % 3];
      uses.push_back({uint64_t(std::min(a, b)) << 32 | std::max(a, b), uint32_t(3 * t + k), a < b});
    }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.corner < y.corner;
  });
  std::vector<uint64_t> cuts;
  cuts.reserve(soup.cuts.size());
  for (const auto& [a, b] : soup.cuts) cuts.push_back(uint64_t(std::min(a, b)) << 32 | std::max(a, b));
  std::sort(cuts.begin(), cuts.end());
  const double cos_sharp = std::cos(sharp_angle_degrees * (3.14159265358979323846 / 180.0));
  FanSets sets;
  sets.parent.resize(3 * nt);
  std::iota(sets.parent.begin(), sets.parent.end(), size_t{0});
  const auto next_corner = [](uint32_t c) { return c - c % 3 + (c % 3 + 1) % 3; };
  for (size_t i = 0; i + 1 < uses.size(); ++i) {
    const EdgeUse &x = uses[i], &y = uses[i + 1];
    if (x.key != y.key || (i + 2 < uses.size() && uses[i + 2].key == x.key) || (i > 0 && uses[i - 1].key == x.key))
      continue;  // a border, or an edge of three or more triangles
    if (x.forward == y.forward) continue;  // wound the same way: the two sides disagree on the front
    if (std::binary_search(cuts.begin(), cuts.end(), x.key)) continue;  // a contact line
    if (glm::dot(face_normal[x.corner / 3], face_normal[y.corner / 3]) < cos_sharp) continue;
    // x runs a → b, y runs b → a: a's corners are x.corner and y's second, b's the converse.
    sets.parent[sets.find(x.corner)] = sets.find(next_corner(y.corner));
    sets.parent[sets.find(next_corner(x.corner))] = sets.find(y.corner);
  }

  // Output vertices in order of their input vertex, then of their first corner.
  std::vector<std::pair<uint32_t, uint32_t>> roots;  // (input vertex, corner) of each set's root
  roots.reserve(3 * nt);
  for (uint32_t c = 0; c < 3 * nt; ++c)
    if (sets.find(c) == c) roots.emplace_back(soup.triangles[c / 3][c % 3], c);
  std::sort(roots.begin(), roots.end());
  std::vector<uint32_t> output_of_root(3 * nt, UINT32_MAX);
  SplitSurface out;
  out.positions.reserve(roots.size());
  out.normals.assign(roots.size(), DVec3(0.0));
  for (const auto& [vertex, root] : roots) {
    output_of_root[root] = static_cast<uint32_t>(out.positions.size());
    out.positions.push_back(soup.points[vertex]);
  }
  out.corners.resize(nt);
  for (uint32_t c = 0; c < 3 * nt; ++c) {
    const uint32_t v = output_of_root[sets.find(c)];
    out.corners[c / 3][c % 3] = v;
    out.normals[v] += face_cross[c / 3];  // area-weighted
  }
  // A fan of faces that cancel (possible only where the input folds back on itself) takes the
  // normal of one of its faces.
  for (DVec3& n : out.normals) {
    const double length = glm::length(n);
    n = length > 0.0 ? n / length : DVec3(0.0);
  }
  for (uint32_t c = 0; c < 3 * nt; ++c) {
    DVec3& n = out.normals[out.corners[c / 3][c % 3]];
    if (n == DVec3(0.0)) n = face_normal[c / 3];
  }
  return out;
}

namespace {

bool is_meshed(const rc::scene::Material& material) {
  return !material.is_traced_through();  // diffuse, glossy and metallic-roughness: their diffuse part
}

const rc::scene::Material& material_of(const rc::scene::Scene& scene, uint32_t material,
                                       const std::string& what) {
  if (material >= scene.materials.size())
    throw rc::InputError(what + " refers to material " + std::to_string(material) + " but there are " +
                         std::to_string(scene.materials.size()));
  return scene.materials[material];
}

std::string mesh_label(const rc::scene::TriangleMesh& mesh, size_t index) {
  return "mesh '" + (mesh.name.empty() ? std::to_string(index) : mesh.name) + "'";
}

/// Geodesic-sphere frequency whose 20·f² triangles have the area of equilateral triangles of
/// edge `edge_length`.
int sphere_frequency(double radius, double edge_length) {
  const double triangles =
      4.0 * 3.14159265358979323846 * radius * radius / (kUnitEquilateralArea * edge_length * edge_length);
  return std::max(1, static_cast<int>(std::lround(std::sqrt(triangles / 20.0))));
}

/// Drops triangles without area (possible only from rounding at extreme scales): they have no
/// normal and receive nothing.
void drop_flat_triangles(TriangleSoup& soup) {
  std::erase_if(soup.triangles, [&](const std::array<uint32_t, 3>& t) {
    const DVec3 c = triangle_cross(soup, t);
    return !(glm::dot(c, c) > 0.0);
  });
}

/// Appends a surface's vertices and elements to the radiosity mesh.
void append(RadiosityMesh& out, const SplitSurface& surface, uint32_t material, uint32_t surface_id) {
  const auto base = static_cast<uint32_t>(out.positions.size());
  for (size_t v = 0; v < surface.positions.size(); ++v) {
    out.positions.push_back(Vec3(surface.positions[v]));
    out.normals.push_back(Vec3(surface.normals[v]));
    out.vertex_material.push_back(material);
  }
  for (const auto& corners : surface.corners) {
    const std::array<uint32_t, 3> element = {base + corners[0], base + corners[1], base + corners[2]};
    // Normal and area from the stored (single-precision) positions, so they describe exactly the
    // triangle the solver sees.
    const DVec3 a(out.positions[element[0]]), b(out.positions[element[1]]), c(out.positions[element[2]]);
    const DVec3 cross = glm::cross(b - a, c - a);
    const double length = glm::length(cross);
    if (!(length > 0.0)) continue;  // collapsed by rounding to float
    out.elements.push_back(element);
    out.element_material.push_back(material);
    out.element_surface.push_back(surface_id);
    out.element_normal.push_back(Vec3(cross / length));
    out.element_area.push_back(static_cast<float>(0.5 * length));
  }
}

void warn_counts(MeshReport& report, const std::string& label, const RepairCounts& c) {
  const auto warn = [&](size_t count, const char* what) {
    if (count > 0) report.warnings.push_back(label + ": " + std::to_string(count) + " " + what);
  };
  warn(c.merged_vertices, "duplicate vertices merged");
  warn(c.removed_degenerate, "degenerate faces removed");
  warn(c.removed_duplicates, "duplicate faces removed");
  warn(c.reoriented, "faces reoriented to agree with their neighbours");
  warn(c.duplicated_vertices, "vertices duplicated to make the surface manifold");
  warn(c.self_intersecting, "pairs of faces intersect each other (meshed as they are)");
  warn(c.self_intersections_uncounted, "pieces not searched for faces that intersect each other: --time left no time");
  warn(c.contacts_failed, "touching surfaces whose contact lines could not be imprinted");
  warn(c.contact_segments_lost, "pieces of contact line left out (an end outside its face by rounding)");
  warn(c.remesh_failed, "pieces could not be remeshed and keep their input triangles");
  warn(c.not_imprinted, "pieces that touch other surfaces keep no contact lines: --time left no time to imprint them");
  warn(c.not_remeshed, "pieces keep their input triangles: --time left no time to remesh them");
}

double meshed_area(const rc::scene::Scene& scene) {
  double area = 0.0;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const rc::scene::TriangleMesh& mesh = scene.meshes[m];
    if (!is_meshed(material_of(scene, mesh.material, mesh_label(mesh, m)))) continue;
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      const DVec3 a(mesh.positions.at(mesh.indices[3 * t])), b(mesh.positions.at(mesh.indices[3 * t + 1])),
          c(mesh.positions.at(mesh.indices[3 * t + 2]));
      area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
  }
  for (size_t s = 0; s < scene.spheres.size(); ++s) {
    const rc::scene::Sphere& sphere = scene.spheres[s];
    if (!is_meshed(material_of(scene, sphere.material, "sphere " + std::to_string(s)))) continue;
    area += 4.0 * 3.14159265358979323846 * double(sphere.radius) * double(sphere.radius);
  }
  return area;
}

/// For each mesh of the scene, the other meshes whose bounding boxes meet its own (grown by a
/// millionth of the scene's size): the only ones that can touch it.
std::vector<std::vector<size_t>> touching_meshes(const rc::scene::Scene& scene) {
  std::vector<rc::Bounds3> boxes(scene.meshes.size());
  rc::Bounds3 all;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    for (uint32_t i : scene.meshes[m].indices) boxes[m].extend(scene.meshes[m].positions.at(i));
    if (!boxes[m].empty()) all.extend(boxes[m].lo), all.extend(boxes[m].hi);
  }
  std::vector<std::vector<size_t>> out(scene.meshes.size());
  if (all.empty()) return out;
  const Vec3 grow(1e-6f * glm::length(all.hi - all.lo));
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (boxes[m].empty()) continue;
    const rc::Bounds3 box{boxes[m].lo - grow, boxes[m].hi + grow};
    for (size_t o = 0; o < scene.meshes.size(); ++o)
      if (o != m && !boxes[o].empty() && box.overlaps(boxes[o])) out[m].push_back(o);
  }
  return out;
}

/// Directions, in a frame around the normal, along which burial is tested: the normal and two
/// rings of six (polar angles 45° and 75°, the second turned by 30°).
std::vector<DVec3> burial_directions() {
  std::vector<DVec3> dirs{{0.0, 0.0, 1.0}};
  for (int ring = 0; ring < 2; ++ring) {
    const double polar = (ring == 0 ? 45.0 : 75.0) * (3.14159265358979323846 / 180.0);
    for (int k = 0; k < 6; ++k) {
      const double azimuth = (60.0 * k + 30.0 * ring) * (3.14159265358979323846 / 180.0);
      dirs.emplace_back(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth), std::cos(polar));
    }
  }
  return dirs;
}

/// Largest share of the meshed area that burial may remove. Solids standing on or in other
/// surfaces hide a few per cent of them (the Cornell blocks 2.9 % of the box); far more means a
/// scene whose surfaces face the wrong way, and then nothing is removed.
constexpr double kMaxBuriedShare = 0.25;

/// Walks from the back of an open sheet that light could still reach: kLightWalks walks of up to
/// kLightWalkBounces diffuse bounces each.
constexpr int kLightWalks = 8, kLightWalkBounces = 4;

/// Whether light reaches the point `at` (on the side its normal faces) within a few diffuse
/// bounces, as orient_sides asks of the meshed pieces: a shadow ray to a light drawn at random
/// arrives, a ray escapes to a lit sky, or one meets a surface emitting towards it; glass lets
/// light through. Every surface met is taken as reflecting on the side met. Seeded by the point.
bool light_reaches(const rc::scene::Scene& scene, const rc::scene::SurfacePoint& at) {
  const std::vector<rc::scene::Light>& lights = scene.lights();
  uint64_t key = 0;
  std::memcpy(&key, &at.p, sizeof(float) * 2);
  key ^= uint64_t(std::bit_cast<uint32_t>(at.p.z)) * 0x9e3779b97f4a7c15ull;
  for (int walk = 0; walk < kLightWalks; ++walk) {
    rc::util::Rng rng = rc::util::Rng::for_item(0xb0e1ull, key, uint64_t(walk));
    rc::scene::SurfacePoint sp = at;
    for (int bounce = 0; bounce < kLightWalkBounces; ++bounce) {
      const Vec3 n = sp.ng;
      if (!lights.empty()) {
        const rc::scene::Light& light = lights[rng.next_u32() % lights.size()];
        const rc::scene::LightSample ls = rc::scene::sample_light(scene, light, sp, rng.uniform2(), n);
        if (!ls.radiance.is_black() && glm::dot(ls.wi, n) > 0.0f && !scene.occluded(ls.shadow_ray))
          return true;
      }
      const Vec3 w = rc::Frame::from_normal(n).to_world(rc::util::sample_cosine_hemisphere(rng.uniform2()));
      const rc::scene::Ray ray = rc::scene::spawn_ray(sp, w);
      const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
      if (!hit) {
        if (!rc::scene::escaped_radiance(scene.punctual_lights, w).is_black()) return true;
        break;
      }
      const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
      const rc::scene::Material& m = scene.materials[si.material];
      if (m.kind == rc::scene::MaterialKind::dielectric) return true;
      if (m.is_emissive() && !rc::scene::emitted_radiance(m, si.ng, -w).is_black()) return true;
      sp = si;
      if (glm::dot(sp.ng, w) > 0.0f) sp.ng = -sp.ng;  // the side the walk met
    }
  }
  return false;
}

/// Whether every test ray from `at` over its front hemisphere (see burial_directions) first
/// hits the back of an opaque surface, no light reaches the point, and the camera cannot see it.
/// Inside a closed surface nothing more is asked. Behind an open sheet it is: a floor slab
/// modelled as one quad facing up may have a room under it, lit through its windows, or the
/// space over a furnace's floor, lit by every surface round it (the furnace family's dome lost
/// the middle of its enclosure's floor, 2 % of its light, that way), while the floor under a
/// block that has no bottom face is as dark as the floor under a closed one.
bool enclosed(const rc::scene::Scene& scene, const rc::scene::SurfacePoint& at) {
  static const std::vector<DVec3> dirs = burial_directions();
  const rc::Frame frame = rc::Frame::from_normal(at.ng);
  bool behind_a_sheet = false;
  for (const DVec3& dir : dirs) {
    const rc::scene::Ray ray = rc::scene::spawn_ray(at, frame.to_world(Vec3(dir)));
    const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    if (!hit) return false;
    const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
    // Open, or enclosed by glass that lets light in.
    if (si.front_face || scene.materials[si.material].kind == rc::scene::MaterialKind::dielectric)
      return false;
    behind_a_sheet = behind_a_sheet || !scene.on_closed_surface(hit->geom_id, hit->prim_id);
  }
  if (behind_a_sheet && light_reaches(scene, at)) return false;
  // A room modelled inside out (its walls facing outwards) encloses what is in it just as a
  // block encloses the floor under it; the camera inside tells the two apart where it looks.
  const Vec3 camera = scene.effective_camera().look_from;
  return !(glm::dot(camera - at.p, at.ng) > 0.0f && !scene.occluded(rc::scene::spawn_shadow_ray(at, camera)));
}

/// The points of a triangle at which burial is tested: its centroid and three points near its
/// corners (barycentric 2/3, 1/6, 1/6).
std::array<DVec3, 4> burial_points(const DVec3& a, const DVec3& b, const DVec3& d) {
  return {(a + b + d) / 3.0, (4.0 * a + b + d) / 6.0, (a + 4.0 * b + d) / 6.0, (a + b + 4.0 * d) / 6.0};
}

/// Whether the triangle (a, b, d) is buried: all its burial_points are enclosed, seen from its
/// front.
bool triangle_buried(const rc::scene::Scene& scene, const DVec3& a, const DVec3& b, const DVec3& d) {
  const DVec3 cross = glm::cross(b - a, d - a);
  if (!(glm::dot(cross, cross) > 0.0)) return false;
  for (const DVec3& p : burial_points(a, b, d)) {
    rc::scene::SurfacePoint at;
    at.p = Vec3(p);
    at.p_error = rc::scene::error_gamma(16) * rc::abs(at.p);
    at.ng = Vec3(glm::normalize(cross));
    if (!enclosed(scene, at)) return false;
  }
  return true;
}

double triangle_area(const DVec3& a, const DVec3& b, const DVec3& d) { return 0.5 * glm::length(glm::cross(b - a, d - a)); }

/// Marks the triangles of an imprinted input surface that are buried (triangle_buried): they lie
/// inside a closed solid or under an object standing on them (with the contact lines imprinted,
/// a triangle lies wholly on one side of them), so they can neither receive nor send light. The
/// test runs on the input's own surface, not on remeshed elements, which are chords of a curved
/// input and lie up to their sagitta inside it: from there a convex scan sees its own input
/// from behind in every direction (the Stanford bunny lost 84 % of its area that way). A
/// surface inside-out with respect to its neighbours is never buried (its rays leave the
/// scene), nor is one enclosed by glass or in view of the camera. A face lying flat on another
/// and facing it (a closed box's base on the floor) is not found and is kept: it receives
/// nothing and costs only its own elements. Triangles not begun by `deadline` are kept, and
/// counted in `untested`. Returns the buried area.
double mark_buried(const rc::scene::Scene& scene, const TriangleSoup& surface, std::vector<char>& buried,
                   std::chrono::steady_clock::time_point deadline, std::atomic<size_t>& untested) {
  buried.assign(surface.triangles.size(), 0);
  // In parallel over triangles (a furnished room's furniture is one mesh of most of its faces),
  // the area summed afterwards in triangle order, so it does not depend on the thread count.
  rc::util::parallel_for(surface.triangles.size(), [&](size_t t) {
    if (std::chrono::steady_clock::now() >= deadline) {
      ++untested;
      return;
    }
    const auto& c = surface.triangles[t];
    buried[t] = triangle_buried(scene, surface.points[c[0]], surface.points[c[1]], surface.points[c[2]]);
  });
  double area = 0.0;
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& c = surface.triangles[t];
    if (buried[t]) area += triangle_area(surface.points[c[0]], surface.points[c[1]], surface.points[c[2]]);
  }
  return area;
}

/// Whether p lies on input mesh `mesh_index` to within `tolerance` along the normal n.
bool on_input(const rc::scene::Scene& scene, const DVec3& p, const DVec3& n, uint32_t mesh_index,
              double tolerance) {
  for (const double side : {1.0, -1.0}) {
    const rc::scene::Ray ray{Vec3(p + side * tolerance * n), Vec3(-side * n),
                             static_cast<float>(2.0 * tolerance)};
    const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    if (hit && hit->geom_id == mesh_index) return true;
  }
  return false;
}

/// The same test on the elements of a remeshed surface that are the input surface itself: flat
/// (all three vertex normals within 0.26° of the element's) and with every burial point on the
/// input mesh to within 10⁻⁴ of the element's size. A flat element can still bridge a groove or
/// a rim of the input and lie inside it (one on the milk truck's cab did, and was removed though
/// in view). It finds what imprinting left whole: a floor under an object that stands a rounding
/// error above it, or one that intersects itself and so imprints nothing. Returns the area.
double mark_buried_flat(const rc::scene::Scene& scene, const SplitSurface& surface, uint32_t mesh_index,
                        std::vector<char>& buried, std::chrono::steady_clock::time_point deadline,
                        std::atomic<size_t>& untested) {
  buried.assign(surface.corners.size(), 0);
  rc::util::parallel_for(surface.corners.size(), [&](size_t t) {  // as mark_buried
    if (std::chrono::steady_clock::now() >= deadline) {
      ++untested;
      return;
    }
    const auto& c = surface.corners[t];
    const DVec3 &a = surface.positions[c[0]], &b = surface.positions[c[1]], &d = surface.positions[c[2]];
    const DVec3 n = glm::normalize(glm::cross(b - a, d - a));
    if (!(glm::dot(n, surface.normals[c[0]]) > 0.99999 && glm::dot(n, surface.normals[c[1]]) > 0.99999 &&
          glm::dot(n, surface.normals[c[2]]) > 0.99999))
      return;
    const double size = std::max({glm::distance(a, b), glm::distance(b, d), glm::distance(d, a)});
    bool on_surface = true;
    for (const DVec3& p : burial_points(a, b, d))
      on_surface = on_surface && on_input(scene, p, n, mesh_index,
                                          1e-4 * size + double(rc::scene::error_gamma(16)) * glm::length(p));
    buried[t] = on_surface && triangle_buried(scene, a, b, d);
  });
  double area = 0.0;
  for (size_t t = 0; t < surface.corners.size(); ++t) {
    const auto& c = surface.corners[t];
    if (buried[t]) area += triangle_area(surface.positions[c[0]], surface.positions[c[1]], surface.positions[c[2]]);
  }
  return area;
}

/// Removes the marked triangles and the vertices only they used. Returns the number removed.
size_t remove_triangles(SplitSurface& surface, const std::vector<char>& remove) {
  const size_t removed = static_cast<size_t>(std::count(remove.begin(), remove.end(), char{1}));
  if (removed == 0) return 0;
  SplitSurface kept;
  std::vector<uint32_t> renumber(surface.positions.size(), UINT32_MAX);
  for (size_t t = 0; t < surface.corners.size(); ++t) {
    if (remove[t]) continue;
    std::array<uint32_t, 3> corners{};
    for (int k = 0; k < 3; ++k) {
      uint32_t& v = renumber[surface.corners[t][k]];
      if (v == UINT32_MAX) {
        v = static_cast<uint32_t>(kept.positions.size());
        kept.positions.push_back(surface.positions[surface.corners[t][k]]);
        kept.normals.push_back(surface.normals[surface.corners[t][k]]);
      }
      corners[k] = v;
    }
    kept.corners.push_back(corners);
  }
  surface = std::move(kept);
  return removed;
}

// build_mesh's passes, over one MeshingState. Each mesh's slot is written by its own task, so the
// passes run over meshes in parallel and give the same result for any thread count.
struct MeshingState {
  const rc::scene::Scene& scene;
  const MeshSettings& settings;
  MeshReport& rep;
  float edge_length = 0.0f;
  double area = 0.0;
  size_t mesh_count = 0, surface_count = 0;
  std::vector<std::vector<size_t>> touching;
  std::vector<char> meshed, repair;  ///< per mesh: remeshed; mended (meshed, or touching one that is)
  std::vector<RepairCounts> counts;
  std::vector<std::vector<char>> buried;  ///< per mesh: imprinted input faces found buried
  std::vector<double> buried_area;
  std::vector<size_t> imprinted_faces;
  double total_buried = 0.0;
  std::atomic<size_t> untested{0};  ///< faces and elements not tested for burial: out of time
  std::vector<SplitSurface> surfaces;  ///< per mesh, then per sphere: the remeshed surface
  std::vector<std::vector<char>> buried_elements;
  std::vector<double> buried_element_area;
  std::chrono::steady_clock::time_point stage_start = std::chrono::steady_clock::now();

  MeshingState(const rc::scene::Scene& s, const MeshSettings& m, MeshReport& r)
      : scene(s), settings(m), rep(r) {}

  /// Records the seconds since the last stage ended under `name`.
  void end_stage(const char* name) {
    const auto now = std::chrono::steady_clock::now();
    rep.stage_seconds.emplace_back(name, std::chrono::duration<double>(now - stage_start).count());
    stage_start = now;
  }
  /// Input faces of the meshes `which` marks, for progress counts.
  uint64_t faces_of(const std::vector<char>& which) const {
    uint64_t faces = 0;
    for (size_t m = 0; m < mesh_count; ++m)
      if (which[m]) faces += scene.meshes[m].indices.size() / 3;
    return faces;
  }
  /// Whether `buried_total` is too much of the surface to be believed buried; warns if so.
  bool too_much(double buried_total) {
    if (buried_total <= kMaxBuriedShare * area) return false;
    rep.warnings.push_back(std::to_string(static_cast<int>(std::lround(100.0 * buried_total / area))) +
                           " % of the surface area looks buried inside other surfaces; nothing was removed "
                           "(do some surfaces face the wrong way?)");
    return true;
  }
};

/// Reads the scene and settings; sets the edge length, the area, and which meshes are meshed and
/// mended (every mesh that is meshed or touches one that is: the meshed ones are remeshed from
/// it, and all of them imprint their neighbours). False when there is nothing to mesh.
bool plan_meshing(MeshingState& st) {
  const rc::scene::Scene& scene = st.scene;
  if (!(st.settings.sharp_angle_degrees >= 0.0f && st.settings.sharp_angle_degrees <= 180.0f))
    throw rc::InputError("mesh: sharp_angle_degrees must lie in [0, 180]");
  if (st.settings.remesh_iterations < 0) throw rc::InputError("mesh: remesh_iterations must be ≥ 0");
  st.edge_length = target_edge_length(scene, st.settings);
  st.rep.max_edge = st.edge_length;
  st.area = meshed_area(scene);
  st.rep.meshed_area = st.area;
  if (!(st.area > 0.0) || !(st.edge_length > 0.0f)) return false;
  const double expected = st.area / (kUnitEquilateralArea * double(st.edge_length) * st.edge_length);
  if (expected > kMaxElements)
    throw rc::InputError("mesh: an edge length of " + std::to_string(st.edge_length) + " gives about " +
                         std::to_string(static_cast<long long>(expected)) + " elements (at most " +
                         std::to_string(static_cast<long long>(kMaxElements)) + "); ask for fewer");
  st.mesh_count = scene.meshes.size();
  st.surface_count = st.mesh_count + scene.spheres.size();
  st.surfaces.resize(st.surface_count);
  st.counts.resize(st.mesh_count);
  st.buried.resize(st.mesh_count);
  st.buried_area.assign(st.mesh_count, 0.0);
  st.touching = touching_meshes(scene);
  st.meshed.assign(st.mesh_count, 0);
  st.repair.assign(st.mesh_count, 0);
  for (size_t m = 0; m < st.mesh_count; ++m)
    if (is_meshed(material_of(scene, scene.meshes[m].material, mesh_label(scene.meshes[m], m)))) {
      st.meshed[m] = st.repair[m] = 1;
      for (size_t t : st.touching[m]) st.repair[t] = 1;
    }
  return true;
}

/// Reads `repair`; mends those meshes into `repaired`.
void repair_pass(MeshingState& st, RepairedMeshes& repaired) {
  rc::util::Progress progress("mesh: repairing", st.faces_of(st.repair), "faces", st.settings.progress);
  rc::util::parallel_for(st.mesh_count, [&](size_t m) {
    if (!st.repair[m]) return;
    repaired.repair(m, st.scene.meshes[m], st.settings.deadline);
    progress.advance(st.scene.meshes[m].indices.size() / 3);
  });
}

/// Reads `meshed` and `touching`; imprints the contact lines on each meshed mesh, then marks
/// which imprinted faces are buried (rays need the committed scene), in `buried`, `buried_area`
/// and `imprinted_faces`. What is buried is removed before remeshing, so no element is made for it.
void imprint_pass(MeshingState& st, RepairedMeshes& repaired) {
  std::vector<TriangleSoup> imprinted(st.mesh_count);
  {
    rc::util::Progress progress("mesh: imprinting contact lines", st.faces_of(st.meshed), "faces", st.settings.progress);
    rc::util::parallel_for(st.mesh_count, [&](size_t m) {
      if (st.meshed[m])
        imprinted[m] = repaired.imprint(m, st.touching[m], &st.counts[m], &progress, st.settings.deadline);
    });
  }
  st.end_stage("imprint");
  st.imprinted_faces.assign(st.mesh_count, 0);
  rc::util::parallel_for(st.mesh_count, [&](size_t m) {
    st.imprinted_faces[m] = imprinted[m].triangles.size();
    if (st.meshed[m] && st.scene.committed())
      st.buried_area[m] = mark_buried(st.scene, imprinted[m], st.buried[m], st.settings.deadline, st.untested);
    imprinted[m] = TriangleSoup();
  });
  st.end_stage("buried faces");
  st.total_buried = std::accumulate(st.buried_area.begin(), st.buried_area.end(), 0.0);
  if (st.too_much(st.total_buried)) {
    for (auto& flags : st.buried) flags.clear();
    st.total_buried = 0.0;
  } else {
    for (const auto& flags : st.buried)
      st.rep.buried_faces += static_cast<size_t>(std::count(flags.begin(), flags.end(), char{1}));
  }
}

/// Reads `buried`; remeshes each meshed mesh without its buried faces into `surfaces` and marks
/// its flat elements that are buried, and tessellates each meshed sphere.
void remesh_pass(MeshingState& st, RepairedMeshes& repaired) {
  const rc::scene::Scene& scene = st.scene;
  const RemeshParams params{kRemeshTargetScale * st.edge_length, st.settings.sharp_angle_degrees,
                            st.settings.remesh_iterations};
  st.buried_elements.resize(st.mesh_count);
  st.buried_element_area.assign(st.mesh_count, 0.0);
  rc::util::Progress remeshing("mesh: remeshing",
                         std::accumulate(st.imprinted_faces.begin(), st.imprinted_faces.end(), uint64_t{0}), "faces",
                         st.settings.progress);
  rc::util::parallel_for(st.surface_count, [&](size_t s) {
    if (s < st.mesh_count) {
      if (!st.meshed[s]) return;
      TriangleSoup soup = repaired.remesh(s, st.buried[s], params, &st.counts[s], &remeshing, st.settings.deadline);
      drop_flat_triangles(soup);
      st.surfaces[s] = split_sharp_vertices(soup, st.settings.sharp_angle_degrees);
      if (scene.committed() && st.total_buried <= kMaxBuriedShare * st.area)
        st.buried_element_area[s] =
            mark_buried_flat(scene, st.surfaces[s], static_cast<uint32_t>(s), st.buried_elements[s],
                             st.settings.deadline, st.untested);
    } else {
      const rc::scene::Sphere& sphere = scene.spheres[s - st.mesh_count];
      if (!is_meshed(scene.materials[sphere.material])) return;
      const DVec3 center(sphere.center);
      TriangleSoup soup = tessellate_sphere(center, sphere.radius, sphere_frequency(sphere.radius, st.edge_length));
      // Smooth everywhere: vertices stay shared and their normals are radial.
      SplitSurface& surface = st.surfaces[s];
      surface.positions = soup.points;
      for (const DVec3& p : soup.points) surface.normals.push_back(glm::normalize(p - center));
      surface.corners = std::move(soup.triangles);
    }
  });
  remeshing.finish();
}

/// Reads `surfaces` and the buried elements; removes those (unless too much would go), appends
/// every surface to `out` in scene order and adds each mesh's repair counts to the report.
void assemble_pass(MeshingState& st, RadiosityMesh& out) {
  MeshReport& rep = st.rep;
  const double element_buried = std::accumulate(st.buried_element_area.begin(), st.buried_element_area.end(), 0.0);
  if (element_buried > 0.0 && !st.too_much(st.total_buried + element_buried)) {
    st.total_buried += element_buried;
    for (size_t m = 0; m < st.mesh_count; ++m)
      rep.buried_elements += remove_triangles(st.surfaces[m], st.buried_elements[m]);
  }
  rep.buried_area = st.total_buried;
  if (st.untested > 0)
    rep.warnings.push_back(std::to_string(st.untested.load()) +
                           " faces and elements were not tested for lying buried inside other surfaces: --time left "
                           "no time (they are kept)");
  for (size_t s = 0; s < st.surface_count; ++s) {
    const uint32_t material =
        s < st.mesh_count ? st.scene.meshes[s].material : st.scene.spheres[s - st.mesh_count].material;
    append(out, st.surfaces[s], material, static_cast<uint32_t>(s));
    if (s >= st.mesh_count) continue;
    const RepairCounts& c = st.counts[s];
    rep.merged_vertices += c.merged_vertices;
    rep.removed_degenerate += c.removed_degenerate;
    rep.reoriented += c.reoriented;
    rep.self_intersecting += c.self_intersecting;
    rep.contact_edges += c.contact_edges;
    rep.pieces_not_imprinted += c.not_imprinted;
    rep.pieces_not_remeshed += c.not_remeshed;
    warn_counts(rep, mesh_label(st.scene.meshes[s], s), c);
  }
  rep.elements = out.element_count();
}

}  // namespace
}  // namespace detail

bool input_triangle_buried(const rc::scene::Scene& scene, const Vec3& a, const Vec3& b, const Vec3& c) {
  return detail::triangle_buried(scene, rc::DVec3(a), rc::DVec3(b), rc::DVec3(c));
}

bool input_point_buried(const rc::scene::Scene& scene, const Vec3& p, const Vec3& n) {
  rc::scene::SurfacePoint at;
  at.p = p;
  at.p_error = rc::scene::error_gamma(16) * rc::abs(p);
  at.ng = n;
  return detail::enclosed(scene, at);
}

float target_edge_length(const rc::scene::Scene& scene, const MeshSettings& settings) {
  if (!std::isfinite(settings.max_edge) || settings.max_edge < 0.0f)
    throw rc::InputError("mesh: max_edge must be a finite length ≥ 0, not " +
                         std::to_string(settings.max_edge));
  if (settings.elements < 0)
    throw rc::InputError("mesh: elements must be ≥ 0, not " + std::to_string(settings.elements));
  if (settings.max_edge > 0.0f) return settings.max_edge;
  const int elements = settings.elements > 0 ? settings.elements : kDefaultElements;
  const double area = detail::meshed_area(scene);
  // N equilateral triangles of edge L cover N·(√3/4)·L² = A.
  return static_cast<float>(std::sqrt(area / (detail::kUnitEquilateralArea * elements)));
}

RadiosityMesh build_mesh(const rc::scene::Scene& scene, const MeshSettings& settings, MeshReport* report) {
  using namespace detail;
  MeshReport local_report;
  MeshReport& rep = report ? *report : local_report;
  rep = MeshReport{};
  RadiosityMesh out;
  // Surfaces are independent: each pass meshes them in parallel, and the last appends them in
  // scene order, so the result does not depend on the thread count. Each stage is timed, and
  // shows its progress in input faces when asked to.
  MeshingState st(scene, settings, rep);
  if (!plan_meshing(st)) return out;
  st.stage_start = std::chrono::steady_clock::now();
  RepairedMeshes repaired(st.mesh_count);
  repair_pass(st, repaired);
  st.end_stage("repair");
  {
    rc::util::Progress progress("mesh: finding contacts", 0, "pairs of pieces", settings.progress);
    repaired.find_contacts(&progress, settings.deadline);
  }
  st.end_stage("contacts");
  imprint_pass(st, repaired);  // ends the "imprint" and "buried faces" stages
  remesh_pass(st, repaired);
  st.end_stage("remesh");
  assemble_pass(st, out);
  st.end_stage("assemble");
  if (settings.two_sided && scene.committed()) {
    const SidesReport sides = orient_sides(scene, out);
    rep.turned_elements = sides.turned_elements;
    rep.two_sided_elements = sides.two_sided_elements;
    rep.elements = out.element_count();
    st.end_stage("sides");
  }
  // The remesher keeps the input's borders, creases and contact lines where they are, so a model
  // of many small faces cannot be meshed coarser than they allow.
  // (Twins behind surfaces lit on both sides are not counted: they are the same surface.)
  const size_t meshed = out.element_count() - rep.two_sided_elements;
  if (settings.elements > 0 && settings.max_edge == 0.0f && meshed > 2 * size_t(settings.elements))
    rep.warnings.push_back(
        "asked for about " + std::to_string(settings.elements) + " elements, meshed " +
        std::to_string(meshed) +
        ": the remesher keeps the input's borders, creases and contact lines, and makes no "
        "element coarser than they allow (the edge length asked for is " +
        std::to_string(st.edge_length) + ")");
  return out;
}

}  // namespace gilt::radiosity::mesh

// Progressive refinement radiosity: Cohen, Chen, Wallace & Greenberg 1988, "A Progressive
// Refinement Approach to Fast Radiosity Image Generation". Receiver-vertex to source-element
// form factors, analytic with ray-traced visibility: Wallace, Elmquist & Haines 1989.
//
// The unknowns are vertex values: B_v = B0_v + ρ_v Σ_j F(v → j) B̄_j, where B̄_j is the mean of
// element j's vertex radiosities and F(v → j) the point-to-element factor. Each row of F sums to
// at most 1 (exactly 1 in a closed scene), so the iteration contracts by ρ_max in the max norm:
// it cannot diverge for any albedo below 1, and all terms stay non-negative.

#include "radiosity/solver/solver.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <span>
#include <string>
#include <unordered_map>

#include "radiosity/mesh/element_albedo.h"
#include "radiosity/mesh/element_scene.h"
#include "radiosity/solver/ambient_gather.h"
#include "radiosity/solver/element_direct.h"
#include "radiosity/solver/form_factor.h"
#include "radiosity/solver/probe_fraction.h"
#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/scene/straight_transmittance.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"
#include "raytrace_core/util/progress.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::solver {

using mesh::MeshReport;
using mesh::MeshSettings;
using mesh::RadiosityMesh;
using mesh::build_mesh;
using mesh::element_reflectance;
using mesh::element_scene;
using mesh::mesh_surface_point;
using mesh::split_longest_edges;
using mesh::target_edge_length;
namespace {

using rc::DVec3;

constexpr float kPi = rc::kPi;

constexpr auto surface_point = mesh_surface_point;

/// The elements around each vertex: vertex v's are fan[offsets[v] .. offsets[v + 1]), in
/// element order.
std::pair<std::vector<uint32_t>, std::vector<uint32_t>> element_fans(const RadiosityMesh& mesh) {
  const size_t nv = mesh.vertex_count();
  std::vector<uint32_t> offsets(nv + 1, 0), fan(3 * mesh.element_count());
  for (const auto& e : mesh.elements)
    for (uint32_t v : e) ++offsets[v + 1];
  for (size_t v = 0; v < nv; ++v) offsets[v + 1] += offsets[v];
  std::vector<uint32_t> next(offsets.begin(), offsets.end() - 1);
  for (uint32_t e = 0; e < mesh.element_count(); ++e)
    for (uint32_t v : mesh.elements[e]) fan[next[v]++] = e;
  return {std::move(offsets), std::move(fan)};
}

/// How many of five probes (along the normal and four directions 60° from it, each `reach`
/// long) from a candidate receiver hit the back of a surface: a receiver that sees a back so
/// close lies behind part of the mesh around it.
/// Probing stops once `enough` backs are seen (the callers only compare the count with the
/// fewest so far, or with zero). The back of a two-sided element is its twin's front.
int backs_seen(const rc::scene::Scene& scene, const RadiosityMesh& mesh, const Vec3& p, const Vec3& n,
               float reach, int enough) {
  const rc::scene::SurfacePoint at = surface_point(p, n);
  const rc::Frame frame = rc::Frame::from_normal(n);
  static const std::array<Vec3, 5> dirs = {Vec3(0.0f, 0.0f, 1.0f), Vec3(0.8660254f, 0.0f, 0.5f),
                                           Vec3(-0.8660254f, 0.0f, 0.5f), Vec3(0.0f, 0.8660254f, 0.5f),
                                           Vec3(0.0f, -0.8660254f, 0.5f)};
  int backs = 0;
  for (const Vec3& d : dirs) {
    if (backs >= enough) break;
    rc::scene::Ray ray = rc::scene::spawn_ray(at, frame.to_world(d));
    ray.tmax = reach;
    const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    backs +=
        hit && !scene.surface(ray, *hit).front_face && !(hit->geom_id == 0 && mesh.two_sided(hit->prim_id));
  }
  return backs;
}

}  // namespace

/// Where a vertex receives: a thousandth of the way towards the centroid of one of its elements.
/// A vertex in a corner lies in the planes of the walls beside it, sees them edge-on and would
/// miss their light (its form factors to a closed box sum to 1/4, not 1); just inside its
/// element it sees them as the surface around it does, and its shadow rays do not start on the
/// other wall. Where the surface bends (a rounded edge, a scanned body) a point inside one
/// element lies behind the planes of its neighbours, and rays leaving it near the tangent plane
/// meet their backs; a fan of chords bridging a rounded edge can lean its vertex normal far
/// from any of its elements. So each element of the vertex is tried in turn, the move first
/// kept in the tangent plane and lifted along the normal by as much, then straight, and last a
/// lift alone along the vertex's and each element's normal; the first candidate whose probes
/// (backs_seen, reaching twice the element's size) meet no back is taken, or else the one that
/// meets fewest. (Traced against the input instead of the elements, the milk truck's rounded
/// roof edge came out as a ragged black band.)
std::vector<Vec3> receiver_points(const rc::scene::Scene& geometry, const RadiosityMesh& mesh,
                                  rc::util::Progress* progress) {
  const size_t nv = mesh.vertex_count();
  const auto [offsets, fan] = element_fans(mesh);
  std::vector<Vec3> origin(mesh.positions);
  rc::util::parallel_for_owned((nv + 255) / 256, [&](size_t chunk) {
    for (size_t v = chunk * 256; v < std::min(nv, chunk * 256 + 256); ++v) {
      const Vec3 p = mesh.positions[v], n = mesh.normals[v];
      int fewest = std::numeric_limits<int>::max();
      const auto consider = [&](const Vec3& candidate, float reach) {
        const int backs = backs_seen(geometry, mesh, candidate, n, reach, fewest);
        if (backs < fewest) fewest = backs, origin[v] = candidate;
      };
      for (uint32_t i = offsets[v]; i < offsets[v + 1] && fewest > 0; ++i) {
        const auto& e = mesh.elements[fan[i]];
        const Vec3 towards = (mesh.positions[e[0]] + mesh.positions[e[1]] + mesh.positions[e[2]]) / 3.0f - p;
        const float size = glm::length(towards);
        consider(p + 1e-3f * (towards - glm::dot(towards, n) * n + size * n), 2.0f * size);
        if (fewest > 0) consider(p + 1e-3f * towards, 2.0f * size);
      }
      // A vertex whose fan bridges a rounded edge with chords (its normal leaning far from its
      // elements') may find every element's centroid behind the others: lift it straight out.
      for (uint32_t i = offsets[v]; i < offsets[v + 1] && fewest > 0; ++i) {
        const auto& e = mesh.elements[fan[i]];
        const float size = glm::length((mesh.positions[e[0]] + mesh.positions[e[1]] + mesh.positions[e[2]]) / 3.0f - p);
        consider(p + 1e-3f * size * n, 2.0f * size);
        if (fewest > 0) consider(p + 1e-3f * size * mesh.element_normal[fan[i]], 2.0f * size);
      }
    }
    if (progress) progress->advance(std::min(nv, chunk * 256 + 256) - chunk * 256);
  });
  rc::util::join_ranges(std::span(origin), 256);
  return origin;
}

std::vector<rc::scene::SurfacePoint> visibility_origins(const rc::scene::Scene& geometry,
                                                        const RadiosityMesh& mesh,
                                                        std::span<const Vec3> receivers,
                                                        rc::util::Progress* progress) {
  const size_t nv = mesh.vertex_count();
  const auto [offsets, fan] = element_fans(mesh);
  std::vector<rc::scene::SurfacePoint> out(kVisibilityOrigins * nv);
  rc::util::parallel_for_owned((nv + 255) / 256, [&](size_t chunk) {
    for (size_t v = chunk * 256; v < std::min(nv, chunk * 256 + 256); ++v) {
      const Vec3 p = mesh.positions[v];
      const size_t count = offsets[v + 1] - offsets[v];
      auto centroid = [&](uint32_t e) {
        const auto& el = mesh.elements[e];
        return (mesh.positions[el[0]] + mesh.positions[el[1]] + mesh.positions[el[2]]) / 3.0f;
      };
      // The surface a vertex colour stands for: a disk half as wide as the distance to the
      // nearest centroid of its elements (the radius check_against_path_tracer samples).
      float radius = std::numeric_limits<float>::max();
      for (uint32_t i = offsets[v]; i < offsets[v + 1]; ++i) radius = std::min(radius, 0.5f * glm::distance(centroid(fan[i]), p));
      size_t taken = 0;
      for (size_t j = 0; j < kVisibilityOrigins && j < count; ++j) {
        const uint32_t e = fan[offsets[v] + j * count / std::min(count, kVisibilityOrigins)];
        const Vec3 towards = centroid(e) - p;
        const float size = glm::length(towards);
        if (!(size > 0.0f)) continue;
        const Vec3 n = mesh.element_normal[e];
        const Vec3 q = p + towards * (radius / size) + (1e-3f * size) * n;
        if (backs_seen(geometry, mesh, q, n, 2.0f * size, 1) == 0)
          out[kVisibilityOrigins * v + taken++] = surface_point(q, n);
      }
      if (taken == 0) out[kVisibilityOrigins * v + taken++] = surface_point(receivers[v], mesh.normals[v]);
      for (size_t k = taken; k < kVisibilityOrigins; ++k) out[kVisibilityOrigins * v + k] = out[kVisibilityOrigins * v + k % taken];
    }
    if (progress) progress->advance(std::min(nv, chunk * 256 + 256) - chunk * 256);
  });
  rc::util::join_ranges(std::span(out), 256 * kVisibilityOrigins);
  return out;
}

namespace {

/// Potential occluders: boxes around every part of the scene that could block a segment between
/// two mesh points. A segment between two points of a convex region never crosses the region's
/// boundary planes, so elements lying on a plane that has every mesh vertex on its front (a wall
/// of the room) never block anything; what remains are the blocks, spheres and other objects
/// inside, plus every mirror and dielectric (meshed or not, they are opaque to the solver).
std::vector<rc::Bounds3> occluder_boxes(const rc::scene::Scene& scene, const RadiosityMesh& mesh) {
  // Distinct element planes: a box has six, however finely it is meshed.
  const float scale = std::max(1e-30f, scene.bounds().radius());
  const float eps = 1e-4f * scale;
  std::map<std::array<long, 4>, bool> hull;  // plane key → every vertex on or in front of it
  auto key_of = [&](size_t e) {
    const Vec3 n = mesh.element_normal[e];
    const float d = glm::dot(n, mesh.positions[mesh.elements[e][0]]) / scale;
    return std::array<long, 4>{std::lround(n.x * 1e4f), std::lround(n.y * 1e4f), std::lround(n.z * 1e4f),
                               std::lround(d * 1e4f)};
  };
  std::vector<std::array<long, 4>> keys(mesh.element_count());
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    keys[e] = key_of(e);
    if (hull.count(keys[e]) || hull.size() > 256) continue;
    const Vec3 n = mesh.element_normal[e];
    const float d = glm::dot(n, mesh.positions[mesh.elements[e][0]]);
    bool all_in_front = true;
    for (const Vec3& p : mesh.positions)
      if (glm::dot(n, p) - d < -eps) {
        all_in_front = false;
        break;
      }
    hull.emplace(keys[e], all_in_front);
  }
  std::map<uint32_t, rc::Bounds3> by_surface;
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto it = hull.find(keys[e]);
    if (it != hull.end() && it->second) continue;
    rc::Bounds3& b = by_surface[mesh.element_surface[e]];
    for (uint32_t v : mesh.elements[e]) b.extend(mesh.positions[v]);
  }
  std::vector<rc::Bounds3> boxes;
  for (auto& [surface, b] : by_surface) boxes.push_back(b);
  for (const rc::scene::TriangleMesh& m : scene.meshes) {
    if (!scene.materials[m.material].is_traced_through()) continue;
    rc::Bounds3 b;
    for (uint32_t i : m.indices) b.extend(m.positions[i]);
    if (!b.empty()) boxes.push_back(b);
  }
  for (const rc::scene::Sphere& sp : scene.spheres)
    if (scene.materials[sp.material].is_traced_through()) boxes.push_back({sp.center - Vec3(sp.radius), sp.center + Vec3(sp.radius)});
  // Grow each box by the rounding slack so the test stays conservative.
  for (rc::Bounds3& b : boxes) {
    b.lo -= Vec3(eps);
    b.hi += Vec3(eps);
  }
  return boxes;
}

/// True when the tetrahedron (p, a, b, c), which holds every segment from p to the triangle,
/// may meet the box: its bounding box overlaps the box and no face plane of the tetrahedron
/// has the whole box outside. Conservative: it may say yes when the two are disjoint.
bool tetrahedron_may_meet_box(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const rc::Bounds3& box) {
  const Vec3 lo = glm::min(glm::min(p, a), glm::min(b, c)), hi = glm::max(glm::max(p, a), glm::max(b, c));
  if (lo.x > box.hi.x || lo.y > box.hi.y || lo.z > box.hi.z || hi.x < box.lo.x || hi.y < box.lo.y || hi.z < box.lo.z)
    return false;
  const Vec3 v[4] = {p, a, b, c};
  static constexpr int faces[4][4] = {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};  // 3 on the face, 1 opposite
  for (const auto& f : faces) {
    Vec3 n = glm::cross(v[f[1]] - v[f[0]], v[f[2]] - v[f[0]]);
    if (glm::dot(n, v[f[3]] - v[f[0]]) > 0.0f) n = -n;  // outward
    if (glm::dot(n, n) == 0.0f) continue;              // flat tetrahedron: skip this plane
    // The box corner least far along n: if even it is outside, the whole box is.
    const Vec3 corner(n.x > 0 ? box.lo.x : box.hi.x, n.y > 0 ? box.lo.y : box.hi.y, n.z > 0 ? box.lo.z : box.hi.z);
    if (glm::dot(n, corner - v[f[0]]) > 0.0f) return false;
  }
  return true;
}

/// Largest shooting patch: the per-vertex scratch arrays live on the stack.
constexpr size_t kMaxPatchElements = SourceBatch::kMaxBatch;

/// Shooting patches: groups of adjacent elements of one surface and material, all facing about
/// the same way, grown breadth-first from a seed so they come out compact. Shooting a patch
/// sends each element's own unshot radiosity through its own exact form factor; only the
/// visibility estimate is shared, so the patch size trades shadow-ray count against how finely
/// visibility resolves across the source.
struct Patches {
  std::vector<uint32_t> offsets{0};  ///< patch q holds elements[offsets[q] .. offsets[q + 1])
  std::vector<uint32_t> elements;

  size_t count() const { return offsets.size() - 1; }
  std::span<const uint32_t> of(size_t q) const {
    return {elements.data() + offsets[q], elements.data() + offsets[q + 1]};
  }
};

Patches build_patches(const RadiosityMesh& mesh, int patch_elements) {
  const size_t target = std::clamp<size_t>(size_t(std::max(1, patch_elements)), 1, kMaxPatchElements);
  const size_t ne = mesh.element_count();
  // Elements across each edge (vertices are split at material and sharp-normal changes, so an
  // edge joins elements of one smooth surface).
  std::unordered_map<uint64_t, std::array<uint32_t, 2>> by_edge;
  by_edge.reserve(ne * 2);
  auto edge_key = [](uint32_t a, uint32_t b) { return uint64_t(std::min(a, b)) << 32 | std::max(a, b); };
  constexpr uint32_t none = ~0u;
  for (uint32_t e = 0; e < ne; ++e)
    for (int i = 0; i < 3; ++i) {
      auto [it, fresh] = by_edge.try_emplace(edge_key(mesh.elements[e][i], mesh.elements[e][(i + 1) % 3]),
                                             std::array<uint32_t, 2>{e, none});
      if (!fresh && it->second[1] == none) it->second[1] = e;
    }
  Patches patches;
  patches.elements.reserve(ne);
  std::vector<bool> taken(ne, false);
  std::vector<uint32_t> queue;
  for (uint32_t seed = 0; seed < ne; ++seed) {
    if (taken[seed]) continue;
    queue.assign(1, seed);
    taken[seed] = true;
    const size_t first = patches.elements.size();
    for (size_t head = 0; head < queue.size() && patches.elements.size() - first < target; ++head) {
      const uint32_t e = queue[head];
      patches.elements.push_back(e);
      for (int i = 0; i < 3; ++i) {
        const auto& pair = by_edge[edge_key(mesh.elements[e][i], mesh.elements[e][(i + 1) % 3])];
        const uint32_t other = pair[0] == e ? pair[1] : pair[0];
        if (other == none || taken[other] || mesh.element_material[other] != mesh.element_material[seed] ||
            mesh.element_surface[other] != mesh.element_surface[seed] ||
            glm::dot(mesh.element_normal[other], mesh.element_normal[seed]) < 0.9f)
          continue;
        taken[other] = true;
        queue.push_back(other);
      }
    }
    // Queued elements that did not fit go back to the pool.
    for (size_t i = patches.elements.size() - first; i < queue.size(); ++i) taken[queue[i]] = false;
    patches.offsets.push_back(uint32_t(patches.elements.size()));
  }
  return patches;
}

/// Irradiance at a vertex with unit normal n from a punctual or environment light of `scene`,
/// with visibility traced against `geometry` from the vertex's visibility origins `from`.
/// The sky reaches it through glass (straight_transmittance), as a path through a window finds
/// it; a point, spot or directional light does not, for no path can meet one through glass,
/// and the view, tracing the direct light the camera sees, would draw the surface unlit.
Rgb punctual_irradiance(const rc::scene::Scene& scene, const rc::scene::Scene& geometry,
                        const rc::scene::Light& light, std::span<const rc::scene::SurfacePoint> from,
                        const Vec3& n, rc::util::Rng& rng, int samples, uint64_t& rays) {
  const size_t first = size_t(rng.uniform() * float(kVisibilityOrigins));  // rays take the origins in turn
  if (light.kind == rc::scene::LightKind::environment) {
    // E = ∫ L V cos dω, by cosine-weighted stratified directions: π times the mean of L over
    // the unblocked ones (π L times the fraction unblocked for a constant sky).
    const rc::Frame frame = rc::Frame::from_normal(n);
    const int side = std::max(1, int(std::sqrt(double(samples))));
    Rgb open(0.0f);
    for (int i = 0; i < side; ++i)
      for (int j = 0; j < side; ++j) {
        const rc::Vec2 u((i + rng.uniform()) / side, (j + rng.uniform()) / side);
        ++rays;
        const rc::scene::SurfacePoint& at = from[(first + size_t(i * side + j)) % kVisibilityOrigins];
        const Vec3 w = frame.to_world(rc::util::sample_cosine_hemisphere(u));
        const Rgb through =
            rc::scene::straight_transmittance(geometry, rc::scene::spawn_shadow_ray_to_infinity(at, w));
        if (!through.is_black()) open += through * rc::scene::environment_radiance(light, w);
      }
    return open * (kPi / float(side * side));
  }
  const rc::scene::LightSample ls = rc::scene::sample_light(scene, light, from[first], rng.uniform2());
  const float cos_theta = glm::dot(ls.wi, n);
  if (!(cos_theta > 0.0f) || ls.radiance.is_black()) return Rgb(0.0f);
  ++rays;
  if (geometry.occluded(ls.shadow_ray)) return Rgb(0.0f);
  return ls.radiance * cos_theta;
}

/// A patch about to shoot: its elements, each with its own form-factor geometry and the
/// radiosity it sends (W·m⁻²), and how its visibility is estimated.
struct ShootingPatch {
  std::vector<uint32_t> elements;
  std::vector<SourceTriangle> triangles;
  SourceBatch batch;
  std::vector<Rgb> radiosity;
  std::array<std::array<float, kMaxPatchElements>, 4> channels;  ///< radiosity r, g, b and their mean
  rc::Bounds3 box;
  Vec3 center{0.0f};        ///< of the box
  float bound = 0.0f;       ///< radius of a sphere about `center` that holds the patch
  bool flat = false;        ///< every element faces `normal` (within float rounding)
  Vec3 normal{0.0f};        ///< the first element's
  float low_offset = 0.0f;  ///< the least normal · x over the patch's corners
  bool emitter = false;  ///< sharp shadows: the per-element occluder test and the adaptive probe
  int probe = 2;         ///< side of the first stratified visibility probe (rays = probe²)
  int strata = 4;        ///< a penumbra takes strata² rays, a quarter in each quarter of the patch (emitters only)

  void assign(const RadiosityMesh& mesh, std::span<const uint32_t> source, std::vector<Rgb>& unshot) {
    elements.assign(source.begin(), source.end());
    triangles.resize(source.size());
    radiosity.resize(source.size());
    box = rc::Bounds3{};
    for (size_t k = 0; k < source.size(); ++k) {
      radiosity[k] = unshot[source[k]];
      unshot[source[k]] = Rgb(0.0f);
      for (int c = 0; c < 3; ++c) channels[c][k] = radiosity[k][c];
      // The weights that sample visibility: an overshooting patch may send negative light.
      channels[3][k] = std::abs(radiosity[k].average());
      const auto& el = mesh.elements[source[k]];
      triangles[k] = SourceTriangle(mesh.positions[el[0]], mesh.positions[el[1]], mesh.positions[el[2]]);
      for (uint32_t v : el) box.extend(mesh.positions[v]);
    }
    batch.assign(triangles);
    center = 0.5f * (box.lo + box.hi);
    bound = 0.5f * glm::length(box.hi - box.lo);
    normal = mesh.element_normal[source[0]];
    flat = true;
    low_offset = std::numeric_limits<float>::max();
    for (uint32_t e : source) {
      flat &= glm::dot(mesh.element_normal[e], normal) >= kParallel;
      for (uint32_t v : mesh.elements[e]) low_offset = std::min(low_offset, glm::dot(normal, mesh.positions[v]));
    }
  }

  /// Whether the whole patch sends nothing to a receiver at p with normal n, by three bounds:
  /// the patch lies behind the receiver's tangent plane; the receiver lies behind the plane of a
  /// flat patch; or the two face the same way in parallel planes, where cos θ at the receiver
  /// and at the source cannot both be positive (this takes in every receiver on the patch's own
  /// wall). Exact except for the last, whose "parallel" allows float rounding of unit normals:
  /// within kParallel the planes meet at 6·10⁻⁴ rad at most, and a source at that slope sends
  /// at most 6·10⁻⁴ of its light.
  bool sends_nothing_to(const Vec3& p, const Vec3& n) const {
    if (glm::dot(n, center - p) <= -bound) return true;
    return flat && (glm::dot(normal, p) <= low_offset || glm::dot(n, normal) >= kParallel);
  }

  static constexpr float kParallel = 1.0f - 2e-7f;
};

/// Counters of one worker.
struct Counts {
  uint64_t form_factors = 0, rays = 0, skipped = 0;
};

/// What receives light: the mesh with the points its vertices receive at, and the occluders.
struct Receivers {
  const rc::scene::Scene& scene;                   ///< the input: its lights
  const RadiosityMesh& mesh;
  rc::scene::Scene geometry;                ///< what visibility rays are traced against (element_scene)
  std::vector<Vec3> origin;                 ///< per vertex, see receiver_points
  std::vector<rc::scene::SurfacePoint> point;      ///< per vertex: origin as a surface point
  std::vector<rc::scene::SurfacePoint>
      spread;  ///< kVisibilityOrigins per vertex, where its shadow rays start
  std::vector<rc::Bounds3> occluders;

  bool progress = false;  ///< report placing the receivers on stderr

  Receivers(const rc::scene::Scene& s, const RadiosityMesh& m, bool report)
      : scene(s), mesh(m), occluders(occluder_boxes(s, m)), progress(report) {
    update();
  }
  void update() {
    geometry = element_scene(scene, mesh);
    rc::util::Progress placing("radiosity: placing receivers", 2 * mesh.vertex_count(), "vertices", progress);
    origin = receiver_points(geometry, mesh, &placing);
    point.resize(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) point[v] = surface_point(origin[v], mesh.normals[v]);
    spread = visibility_origins(geometry, mesh, origin, &placing);
  }
  /// Vertex v's visibility origins.
  std::span<const rc::scene::SurfacePoint> origins(size_t v) const {
    return std::span<const rc::scene::SurfacePoint>(spread).subspan(kVisibilityOrigins * v,
                                                                    kVisibilityOrigins);
  }

  /// A patch's shares of what a vertex receives, per element, as a running sum for sampling
  /// (receive). Elements that send nothing get empty intervals, which sampling never picks.
  struct Shares {
    std::array<float, kMaxPatchElements> cdf;
    size_t m = 0;       ///< the patch's element count
    size_t last = 0;    ///< the last element with a share, for rounding at the top of the sum
    float total = 0.0f;
    bool sends(size_t k) const { return k == 0 ? cdf[0] > 0.0f : cdf[k] > cdf[k - 1]; }
  };

  /// Occluders that the box around p and the patch misses cannot block; for the sharp shadows
  /// of emitters the remaining ones are tested against each element's tetrahedron. False when
  /// nothing can block the patch from p.
  bool occluders_may_block(const ShootingPatch& src, const Vec3& p, const Shares& shares) const {
    bool may_be_blocked = false;
    const rc::Bounds3 reach{glm::min(src.box.lo, p), glm::max(src.box.hi, p)};
    for (const rc::Bounds3& box : occluders) {
      if (!reach.overlaps(box)) continue;
      if (!src.emitter) {
        may_be_blocked = true;
        break;
      }
      for (size_t k = 0; k <= shares.last && !may_be_blocked; ++k) {
        if (!shares.sends(k)) continue;
        const auto& el = mesh.elements[src.elements[k]];
        may_be_blocked =
            tetrahedron_may_meet_box(p, mesh.positions[el[0]], mesh.positions[el[1]], mesh.positions[el[2]], box);
      }
      if (may_be_blocked) break;
    }
    return may_be_blocked;
  }

  /// What of `gathered` (the patch's light at vertex v, unshadowed) gets past the occluders, by
  /// shadow rays: points on the patch, each drawn in proportion to what its element sends to v,
  /// a ray from one of v's origins (taken in turn) to the point at u of the patch's sample
  /// square, whose u.x picks the element by the running sum and is then stretched back to [0, 1).
  Rgb visible(const ShootingPatch& src, size_t v, const Shares& shares, const Rgb& gathered,
              rc::util::Rng& rng, Counts& counts) const {
    const std::span<const rc::scene::SurfacePoint> from = origins(v);
    const size_t first = size_t(rng.uniform() * float(kVisibilityOrigins));
    size_t ray_index = 0;
    const auto& cdf = shares.cdf;
    auto open_at = [&](float ux, float uy) {
      ux *= shares.total;
      size_t k = size_t(std::upper_bound(cdf.begin(), cdf.begin() + shares.m, ux) - cdf.begin());
      k = std::min(k, shares.last);
      const float lo = k ? cdf[k - 1] : 0.0f;
      ux = std::clamp((ux - lo) / std::max(cdf[k] - lo, 1e-30f), 0.0f, rc::kOneMinusEpsilon);
      const rc::Vec2 bary = rc::util::sample_uniform_triangle({ux, uy});
      const auto& el = mesh.elements[src.elements[k]];
      const Vec3 q = (1.0f - bary.x - bary.y) * mesh.positions[el[0]] + bary.x * mesh.positions[el[1]] +
                     bary.y * mesh.positions[el[2]];
      ++counts.rays;
      const rc::scene::SurfacePoint& at = from[(first + ray_index++) % kVisibilityOrigins];
      return geometry.occluded(rc::scene::spawn_shadow_ray(at, surface_point(q, mesh.element_normal[src.elements[k]]))) ? 0 : 1;
    };
    // A point drawn uniformly in quarter j of the square (x by bit 0, y by bit 1).
    auto open_in_quarter = [&](int j) {
      const float ux = (float(j & 1) + rng.uniform()) * 0.5f;
      const float uy = (float(j >> 1) + rng.uniform()) * 0.5f;
      return open_at(ux, uy);
    };
    if (!src.emitter || src.probe != 2 || src.strata <= 2) {
      // Side × side strata, one ray each.
      const int side = src.probe;
      int open = 0;
      for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) {
          const float ux = (float(i) + rng.uniform()) / float(side);
          const float uy = (float(j) + rng.uniform()) / float(side);
          open += open_at(ux, uy);
        }
      return gathered * (float(open) / float(side * side));
    }
    // Emitters' sharp shadows: a probe of one ray per quarter; where it finds a mix (a penumbra),
    // as many rays in all as the full set of strata, each quarter's drawn independently in it,
    // read without the probe's bias (quartered_fraction). A probe that finds all open or all
    // blocked stands.
    std::array<int, 4> hits;
    for (int j = 0; j < 4; ++j) hits[j] = open_in_quarter(j);
    const int probe_open = hits[0] + hits[1] + hits[2] + hits[3];
    if (probe_open == 0) return Rgb(0.0f);
    if (probe_open == 4) return gathered;
    const int per_quarter = std::max(2, (src.strata * src.strata + 3) / 4);
    for (int j = 0; j < 4; ++j)
      for (int t = 1; t < per_quarter; ++t) hits[j] += open_in_quarter(j);
    return gathered * float(quartered_fraction(hits, per_quarter));
  }

  /// Irradiance (W·m⁻²) at vertex v from the patch: each element's exact (or far-field) form
  /// factor times its radiosity, times the patch's visible fraction seen from v. `kept`, when
  /// given, holds the patch's form factors at v (one per element): read when `known`, else
  /// computed and stored there.
  Rgb receive(const ShootingPatch& src, size_t v, rc::util::Rng& rng, Counts& counts, float* kept = nullptr,
              bool known = false) const {
    const Vec3& p = origin[v];
    const Vec3& n = mesh.normals[v];
    if (src.sends_nothing_to(p, n)) return Rgb(0.0f);
    Shares shares;
    const size_t m = shares.m = src.elements.size();
    std::array<float, SourceBatch::kMaxBatch> computed;
    const float* factor = kept;
    if (!kept || !known) {
      counts.form_factors += m;
      src.batch.form_factors(p, n, computed.data());
      if (kept) std::copy_n(computed.data(), m, kept);
      factor = computed.data();
    }
    std::array<float, kMaxPatchElements>& cdf = shares.cdf;
    float r = 0.0f, g = 0.0f, b = 0.0f, total = 0.0f;
    for (size_t k = 0; k < m; ++k) {
      const float f = factor[k];
      r += f * src.channels[0][k];
      g += f * src.channels[1][k];
      b += f * src.channels[2][k];
      total += f * src.channels[3][k];
      cdf[k] = total;
    }
    if (!(total > 0.0f)) return Rgb(0.0f);
    shares.total = total;
    const Rgb gathered(r, g, b);
    size_t last = m - 1;
    while (last > 0 && !(cdf[last] > cdf[last - 1])) --last;
    shares.last = last;
    if (!occluders_may_block(src, p, shares)) {
      ++counts.skipped;
      return gathered;
    }
    return visible(src, v, shares, gathered, rng, counts);
  }
};

/// Memory for progressive refinement's kept form factors (a patch's at every vertex; about
/// elements × vertices × 4 bytes in all, 31 MB at 3,660 elements): past it, later patches'
/// factors are computed at every shot.
constexpr size_t kFactorCacheBytes = size_t(512) << 20;

/// Share of a time budget that adaptive subdivision may use before it stops refining.
constexpr double kRefinementShare = 0.3;
/// The ambient gather of a solve that had no time for the reflected light (keep_unsolved_ambient):
/// elements per run of the mesh's order, and rays per run.
constexpr size_t kUnsolvedPatchElements = 32;
constexpr int kUnsolvedRays = 16;

/// Share of the time left to the solve that the elements' direct light may take under a budget.
constexpr double kElementDirectShare = 0.25;

/// Luminance-like scalar of a colour, for refinement decisions.
float level(const Rgb& c) { return c.average(); }

/// Seconds since `start`.
double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Meshes the scene (solve's first step). Reads the settings; writes sol.mesh, its report and
/// sol.mesh_seconds.
void mesh_scene(const rc::scene::Scene& scene, const SolverSettings& settings, std::chrono::steady_clock::time_point start,
                Solution& sol) {
  MeshSettings mesh_settings = settings.mesh;
  mesh_settings.progress = settings.progress;
  // Under --time, imprinting and remeshing end at meshing's share of the budget; the pieces not
  // begun by then are left as they were. Processes must all mesh alike, so several never cut it short.
  if (settings.time_limit > 0.0 && rc::util::processes().count() == 1)
    mesh_settings.deadline = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                         std::chrono::duration<double>(kMeshShare * settings.time_limit));
  sol.mesh = build_mesh(scene, mesh_settings, &sol.mesh_report);
  sol.mesh_seconds = seconds_since(start);
}

/// Progressive refinement's state from shot to shot (SolveState::shoot_progressive): every
/// element holds the light it reflects and has not shot yet.
struct Shooting {
  std::vector<Rgb> unshot;     ///< per element
  double emitted_power = 0.0;  ///< what the lights send, directly and by one reflection
  Patches patches;
  double total_area = 0.0;
  // Each patch's form factors at every vertex, kept from its first shot for its later ones
  // while they fit in kFactorCacheBytes: they depend on the geometry alone, and a patch
  // shoots several times (about four on cornell), so its later shots trace only visibility.
  std::vector<std::vector<float>> factor_rows;
  size_t cached_bytes = 0;
  std::vector<Rgb> received;  ///< irradiance added by the current shot, per vertex
  ShootingPatch source;
  double last_shot = 0.0;  ///< seconds
};

/// The state of one solve (below), on the mesh it made, which its passes read and write in turn.
struct SolveState {
  SolveState(const rc::scene::Scene& s, const SolverSettings& st, Solution& so,
             std::chrono::steady_clock::time_point t)
      : scene(s),
        settings(st),
        sol(so),
        start(t),
        mesh(so.mesh),
        receivers(s, so.mesh, st.progress),
        strata(std::max(1, int(std::round(std::sqrt(double(st.visibility_samples)))))) {
    sol.convex_enclosure = receivers.occluders.empty();
    // The solver is chosen on the mesh before refinement, as plan_solve() sees it, and chosen
    // again after it (choose_after_refinement).
    sol.solver = choose_solver(settings, mesh.element_count(), &sol.solver_reason);
    elements_as_meshed = mesh.element_count();
    hierarchical = sol.solver == SolverKind::hierarchical;
    hs = settings.hierarchical;
    hs.tolerance = settings.tolerance;
    hs.seed = settings.seed;
    hs.progress = settings.progress;
  }

  const rc::scene::Scene& scene;
  const SolverSettings& settings;
  Solution& sol;
  const std::chrono::steady_clock::time_point start;
  RadiosityMesh& mesh;
  Receivers receivers;
  const int strata;
  std::atomic<uint64_t> rays{0}, form_factors{0}, skipped{0};
  // Under several processes (mpirun) each computes the chunks of vertices or elements it owns
  // and the results are joined, so every process holds one process's arrays. The counts of such
  // a loop are summed over the processes, and rank 0's clock makes every decision about time.
  const rc::util::Processes& group = rc::util::processes();
  bool hierarchical = false;
  size_t elements_as_meshed = 0;  ///< what the solver was first chosen on
  HierarchicalSettings hs;
  std::vector<Rgb> direct_punctual, direct_emitted;  // irradiance per vertex
  std::vector<Rgb> direct_delta;  // the part of direct_punctual from point, spot and directional lights
  size_t nv = 0, ne = 0;  // of the final mesh
  double direct_rays_per_second = 0.0;  // the last gather_direct's shadow rays per second (0: none)

  double elapsed() const { return seconds_since(start); }
  auto albedo(uint32_t material) const { return rc::scene::diffuse_reflectance(scene.materials[material]); }
  /// What element e emits, B0 = π Le. An emitter emits on the side its input face was wound to
  /// face, as the path tracer's do, unless its material emits on both: the twin orient_sides puts
  /// behind a lamp whose back sees a lit ceiling emits nothing (it made the lit family's vaulted
  /// colonnade, hung with 432 lamps, read 1.23 of the path tracer).
  Rgb element_emitted(size_t e) const {
    const rc::scene::Material& m = scene.materials[mesh.element_material[e]];
    return mesh.twin(e) && !m.two_sided_emission ? Rgb(0.0f) : m.emission * kPi;
  }
  bool is_emitter(size_t e) const { return !element_emitted(e).is_black(); }
  void add_counts(const Counts& c) {
    form_factors += c.form_factors;
    rays += c.rays;
    skipped += c.skipped;
  }
  void joined_counts(uint64_t rays_before, uint64_t form_factors_before, uint64_t skipped_before) {
    if (group.count() == 1) return;
    uint64_t own[3] = {rays - rays_before, form_factors - form_factors_before, skipped - skipped_before};
    group.sum(own);
    rays = rays_before + own[0], form_factors = form_factors_before + own[1], skipped = skipped_before + own[2];
  }
  bool over_budget(double seconds) const {
    return group.broadcast_value(settings.time_limit > 0.0 && seconds > settings.time_limit);
  }
  /// The time limit less what is kept back for the export, on the mesh as it stands.
  double solve_limit() const { return settings.time_limit - seconds_kept_back(settings, mesh.element_count()); }
  /// Whether `seconds` since the start run past solve_limit().
  bool over_solve_limit(double seconds) const {
    return group.broadcast_value(settings.time_limit > 0.0 && seconds > solve_limit());
  }
  bool may_be_blocked(const rc::Bounds3& reach) const {
    return std::any_of(receivers.occluders.begin(), receivers.occluders.end(),
                       [&](const rc::Bounds3& box) { return reach.overlaps(box); });
  }
  std::function<bool(const rc::Bounds3&)> blocking() const {
    return [this](const rc::Bounds3& reach) { return may_be_blocked(reach); };
  }

  /// The emitting patches, to shoot direct light at the vertices (none for the hierarchical
  /// solver, whose tree walk takes the emitters: emitted_by_tree).
  std::vector<ShootingPatch> emitting_patches() const {
    const Patches patches = build_patches(mesh, settings.patch_elements);
    std::vector<ShootingPatch> emitters;
    std::vector<Rgb> radiosity(mesh.element_count());
    for (size_t q = 0; q < patches.count() && !hierarchical; ++q) {
      if (!is_emitter(patches.of(q)[0])) continue;
      for (uint32_t e : patches.of(q)) radiosity[e] = element_emitted(e);
      ShootingPatch& sp = emitters.emplace_back();
      sp.assign(mesh, patches.of(q), radiosity);
      sp.emitter = true;
      sp.probe = std::min(2, strata);
      sp.strata = strata;
    }
    return emitters;
  }

  /// Emitting elements by the tree walk (hierarchical solver): the patches would make pass 1
  /// cost the vertex count times the emitter count. Writes direct_emitted from first_vertex on.
  void emitted_by_tree(size_t first_vertex) {
    const size_t nv_now = mesh.vertex_count();
    std::vector<Rgb> emission(mesh.element_count());
    for (size_t e = 0; e < emission.size(); ++e) emission[e] = element_emitted(e);
    // The materials' own albedo is enough here (it only weighs links in the tree walk), and the
    // textured means cost a few seconds per 100,000 elements at every refinement step.
    std::vector<Rgb> rho(mesh.element_count());
    for (size_t e = 0; e < rho.size(); ++e) rho[e] = albedo(mesh.element_material[e]);
    const HierarchicalInput input{mesh, receivers.geometry, receivers.point, receivers.spread, rho, {}, blocking(), {}, {}};
    uint64_t tree_rays = 0;
    const std::vector<Rgb> e = emitted_irradiance(input, emission, first_vertex, hs, settings.visibility_samples, &tree_rays);
    for (size_t v = first_vertex; v < nv_now; ++v) direct_emitted[v] = e[v];
    rays += tree_rays;
  }

  /// Pass 1, direct light, at the vertices from first_vertex on: every vertex gathers from the
  /// punctual lights and from the emitting patches. Reads the mesh and receivers; writes (and
  /// grows to the vertex count) direct_punctual, direct_delta and direct_emitted; adds to the counts.
  void gather_direct(size_t first_vertex) {
    const std::vector<ShootingPatch> emitters = emitting_patches();
    const size_t nv_now = mesh.vertex_count();
    direct_punctual.resize(nv_now, Rgb(0.0f));
    direct_delta.resize(nv_now, Rgb(0.0f));
    direct_emitted.resize(nv_now, Rgb(0.0f));
    const size_t count = nv_now - first_vertex;
    const uint64_t rays_before = rays, form_factors_before = form_factors, skipped_before = skipped;
    const double seconds_before = elapsed();
    rc::util::Progress progress("radiosity: direct light", count, "vertices", settings.progress);
    rc::util::parallel_for_owned((count + 127) / 128, [&](size_t chunk) {
      Counts counts;
      for (size_t v = first_vertex + chunk * 128; v < std::min(nv_now, first_vertex + chunk * 128 + 128); ++v) {
        for (size_t li = 0; li < scene.punctual_lights.size(); ++li) {
          rc::util::Rng rng = rc::util::Rng::for_item(settings.seed, v, 0x9000000000ull + li);
          const rc::scene::Light& light = scene.punctual_lights[li];
          const Rgb e = punctual_irradiance(scene, receivers.geometry, light, receivers.origins(v), mesh.normals[v], rng,
                                            settings.visibility_samples, counts.rays);
          direct_punctual[v] += e;
          if (light.kind != rc::scene::LightKind::environment) direct_delta[v] += e;
        }
        for (size_t q = 0; q < emitters.size(); ++q) {
          // Keyed by the emitter's first element, which refinement never renumbers.
          rc::util::Rng rng =
              rc::util::Rng::for_item(settings.seed, v, 0xa000000000ull + emitters[q].elements[0]);
          direct_emitted[v] += receivers.receive(emitters[q], v, rng, counts);
        }
      }
      add_counts(counts);
      progress.advance(std::min(nv_now, first_vertex + chunk * 128 + 128) - (first_vertex + chunk * 128));
    });
    for (auto* values : {&direct_punctual, &direct_delta, &direct_emitted}) rc::util::join_ranges(std::span(*values), 128, first_vertex);
    joined_counts(rays_before, form_factors_before, skipped_before);
    const double seconds = elapsed() - seconds_before;
    if (rays > rays_before && seconds > 0.0) direct_rays_per_second = double(rays - rays_before) / seconds;
    if (hierarchical) emitted_by_tree(first_vertex);
  }

  /// Elements whose vertices' direct irradiance spreads by more than the threshold times the
  /// brightest of them (plus a floor of 1 % of the mean, so that darkness does not refine).
  std::vector<uint32_t> steep_elements() const {
    double mean = 0.0, area = 0.0;
    for (size_t e = 0; e < mesh.element_count(); ++e) {
      const auto& el = mesh.elements[e];
      for (uint32_t v : el) mean += double(level(direct_punctual[v] + direct_emitted[v])) * mesh.element_area[e] / 3.0;
      area += mesh.element_area[e];
    }
    const float floor = float(0.01 * mean / std::max(area, 1e-30));
    std::vector<uint32_t> marked;
    for (uint32_t e = 0; e < mesh.element_count(); ++e) {
      if (is_emitter(e)) continue;
      float lo = std::numeric_limits<float>::max(), hi = 0.0f;
      for (uint32_t v : mesh.elements[e]) {
        const float x = level(direct_punctual[v] + direct_emitted[v]);
        lo = std::min(lo, x), hi = std::max(hi, x);
      }
      if (hi - lo > float(settings.subdivision_threshold) * (hi + floor)) marked.push_back(e);
    }
    return marked;
  }

  /// Sharp shadows and near-field falloff show up in the direct light, so this is where the
  /// mesh is refined: elements whose vertices disagree steeply are bisected and only the new
  /// vertices gather. Vertex indices are stable under refinement, so the arrays just grow.
  /// Writes the mesh, the receivers, the direct light (gather_direct) and sol.refined_elements.
  void refine_direct() {
    const float base_edge = target_edge_length(scene, settings.mesh);
    const float min_edge = base_edge * std::ldexp(1.0f, -settings.subdivision_levels);
    for (int round = 0; round < 2 * settings.subdivision_levels; ++round) {
      // With a time budget, refinement stops once it has used its share, so shooting gets the rest.
      if (over_budget(elapsed() / kRefinementShare)) break;
      const std::vector<uint32_t> marked = steep_elements();
      const size_t first_new = mesh.vertex_count();
      if (marked.empty() || split_longest_edges(mesh, marked, min_edge * 1.5f) == 0) break;
      receivers.update();
      gather_direct(first_new);
      sol.refined_elements += marked.size();
    }
  }

  /// `automatic` chose progressive refinement on the mesh as meshed; refinement at steep direct
  /// light can multiply its elements (a small generated dome: 9,742 to 59,630), and progressive
  /// refinement's cost grows with their square. From kHierarchicalElements on, the hierarchical
  /// solver takes the interreflection instead. Pass 1 is done by then: its emitting surfaces
  /// came from the shooting patches rather than the tree walk, which gives the same irradiance.
  /// On the small lit family at `--time 15` the bakes' mean went from 0.787 to 1.009 of the path
  /// tracer's on the dome, 0.988 to 0.998 on the colonnade and 0.972 to 0.978 on the storeys
  /// (bench/README.md, "The solver chosen after refinement").
  void choose_after_refinement() {
    if (settings.solver != SolverKind::automatic || hierarchical ||
        mesh.element_count() < kHierarchicalElements)
      return;
    sol.solver = SolverKind::hierarchical;
    sol.solver_reason = std::to_string(elements_as_meshed) + " elements as meshed, " +
                        std::to_string(mesh.element_count()) +
                        " after refining at steep direct light: progressive refinement would cost about n², "
                        "hierarchical about n log n";
    hierarchical = true;
  }

  /// The direct light's totals on the final mesh. Reads the direct light; writes nv, ne,
  /// sol.direct_seconds, the vertices' irradiance (direct so far), direct and punctual parts,
  /// and the elements' and vertices' albedo.
  void keep_direct() {
    sol.direct_seconds = elapsed() - sol.mesh_seconds;
    nv = mesh.vertex_count(), ne = mesh.element_count();
    sol.vertex_irradiance.resize(nv);
    for (size_t v = 0; v < nv; ++v) sol.vertex_irradiance[v] = direct_punctual[v] + direct_emitted[v];
    sol.vertex_direct = sol.vertex_irradiance;
    sol.vertex_punctual = direct_delta;
    sol.element_albedo = element_reflectance(scene, mesh);
    sol.vertex_albedo.assign(nv, Rgb(0.0f));
    std::vector<float> weight(nv, 0.0f);
    for (size_t e = 0; e < ne; ++e)
      for (uint32_t v : mesh.elements[e]) {
        sol.vertex_albedo[v] += sol.element_albedo[e] * mesh.element_area[e];
        weight[v] += mesh.element_area[e];
      }
    for (size_t v = 0; v < nv; ++v)
      sol.vertex_albedo[v] = weight[v] > 0.0f ? sol.vertex_albedo[v] * (1.0f / weight[v]) : albedo(mesh.vertex_material[v]);
  }

  /// Progressive refinement's start: reads the direct light; writes the unshot light (each
  /// element's reflection of its vertices' irradiance), the emitted power, the patches (and
  /// sol.patches) and the total area.
  void start_shooting(Shooting& shot) {
    // What each element reflects of the direct light: its own mean of the lights' irradiance
    // (element_punctual_irradiance), not its vertices' mean, and its vertices' mean of the
    // emitting surfaces'. With the vertex mean, a sun patch through a window that few vertices
    // catch lit the room by as much as those vertices happened to see: on the outward storeys
    // of the generated family the two-pass render's mean spread from 0.87 to 1.06 of the path
    // tracer's over seven seeds. The hierarchical fallback has them already.
    if (sol.element_direct.empty()) {
      uint64_t element_rays = 0;
      rc::util::Progress progress("radiosity: direct light on elements", ne, "elements", settings.progress);
      sol.element_direct = element_punctual_irradiance(
          scene, receivers.geometry, mesh, element_direct_samples(), settings.seed, element_rays, &progress);
      progress.finish();
      rays += element_rays;
      for (size_t e = 0; e < ne; ++e) {
        const auto& el = mesh.elements[e];
        sol.element_direct[e] +=
            (direct_emitted[el[0]] + direct_emitted[el[1]] + direct_emitted[el[2]]) * (1.0f / 3.0f);
      }
    }
    shot.unshot.resize(ne);
    const std::vector<Rgb>& element_rho = sol.element_albedo;
    for (size_t e = 0; e < ne; ++e) {
      const auto& el = mesh.elements[e];
      const Rgb rho = element_rho[e];
      const Rgb emitted_light =
          (direct_emitted[el[0]] + direct_emitted[el[1]] + direct_emitted[el[2]]) * (1.0f / 3.0f);
      shot.emitted_power += double(element_emitted(e).average()) * mesh.element_area[e];
      shot.emitted_power +=
          double((rho * (sol.element_direct[e] - emitted_light)).average()) * mesh.element_area[e];
      shot.unshot[e] = rho * sol.element_direct[e];
    }
    if (!(shot.emitted_power > 0.0))
      sol.mesh_report.warnings.push_back("the scene has no lights: the radiosity is zero everywhere");

    shot.patches = build_patches(mesh, settings.patch_elements);
    sol.patches = shot.patches.count();
    for (size_t e = 0; e < ne; ++e) shot.total_area += mesh.element_area[e];
    shot.factor_rows.resize(shot.patches.count());
  }

  /// The patch with the most unshot power, of either sign (see the overshoot in aim), and that
  /// power; writes sol.residual, the unshot power over the emitted.
  std::pair<size_t, double> brightest_patch(const Shooting& shot) {
    size_t src = 0;
    double best = -1.0, best_signed = 0.0, unshot_power = 0.0;
    for (size_t q = 0; q < shot.patches.count(); ++q) {
      double p = 0.0;
      for (uint32_t e : shot.patches.of(q)) p += double(shot.unshot[e].average()) * mesh.element_area[e];
      unshot_power += std::abs(p);
      if (std::abs(p) > best) best = std::abs(p), best_signed = p, src = q;
    }
    sol.residual = unshot_power / shot.emitted_power;
    return {src, best_signed};
  }

  /// Reflected light is soft: one stratified ray per pair and shot estimates its visibility
  /// without bias, and the noise averages out over the many shots that reach each vertex.
  /// Overshooting (Feda & Purgathofer 1992): a patch with light to send also sends now what it
  /// will receive later, estimated as its reflectance times the mean unshot radiosity of the
  /// rest of the scene, and keeps that amount as negative unshot light, which a later shot of
  /// its own corrects. A patch whose unshot light is negative sends it as it is.
  ///
  /// Makes patch `src` (of unshot power `best_signed`) the shot's source; writes shot.source and
  /// the patch's unshot light.
  void aim(Shooting& shot, size_t src, double best_signed) {
    const std::vector<Rgb>& element_rho = sol.element_albedo;
    std::vector<Rgb>& unshot = shot.unshot;
    const std::span<const uint32_t> shooting = shot.patches.of(src);
    Rgb overshoot(0.0f);
    if (best_signed > 0.0) {
      Rgb own(0.0f), all(0.0f);
      double own_area = 0.0;
      for (uint32_t e : shooting) own += unshot[e] * mesh.element_area[e], own_area += mesh.element_area[e];
      for (size_t e = 0; e < ne; ++e) all += unshot[e] * mesh.element_area[e];
      if (shot.total_area - own_area > 0.0) {
        const Rgb rest = (all - own) * float(1.0 / (shot.total_area - own_area));
        overshoot = Rgb(std::max(rest.r, 0.0f), std::max(rest.g, 0.0f), std::max(rest.b, 0.0f));
      }
    }
    for (uint32_t e : shooting) unshot[e] += element_rho[e] * overshoot;
    shot.source.assign(mesh, shooting, unshot);
    for (uint32_t e : shooting) unshot[e] = element_rho[e] * overshoot * -1.0f;
    shot.source.emitter = false;
    shot.source.probe = std::min(settings.reflected_visibility_probe, strata);
    shot.source.strata = shot.source.probe;
  }

  /// Shoots shot.source (patch `src`) at every vertex: writes shot.received, adds it to the
  /// vertices' irradiance and its reflection to the unshot light; keeps the patch's form factors
  /// while they fit; counts the shot (sol.shots) and adds to the counts.
  void shoot(Shooting& shot, size_t src) {
    const uint64_t shot_index = sol.shots++;
    const uint64_t rays_before = rays, form_factors_before = form_factors, skipped_before = skipped;
    std::vector<float>& row = shot.factor_rows[src];
    const bool known = !row.empty();
    const size_t width = shot.source.elements.size(), row_bytes = nv * width * sizeof(float);
    if (!known && shot.cached_bytes + row_bytes <= kFactorCacheBytes) {
      row.resize(nv * width);
      shot.cached_bytes += row_bytes;
    }
    std::vector<Rgb>& received = shot.received;
    rc::util::parallel_for_owned((nv + 255) / 256, [&](size_t chunk) {
      Counts counts;
      for (size_t v = chunk * 256; v < std::min(nv, chunk * 256 + 256); ++v) {
        rc::util::Rng rng = rc::util::Rng::for_item(settings.seed, v, shot_index);
        received[v] = receivers.receive(shot.source, v, rng, counts, row.empty() ? nullptr : &row[v * width], known);
      }
      add_counts(counts);
    });
    rc::util::join_ranges(std::span(received), 256);
    joined_counts(rays_before, form_factors_before, skipped_before);
    // Vertex irradiance → element unshot radiosity: ρ_e times the mean of its vertices' gain.
    for (size_t v = 0; v < nv; ++v) sol.vertex_irradiance[v] += received[v];
    for (size_t e = 0; e < ne; ++e) {
      const auto& el = mesh.elements[e];
      shot.unshot[e] += sol.element_albedo[e] * (received[el[0]] + received[el[1]] + received[el[2]]) * (1.0f / 3.0f);
    }
  }

  /// The light left unshot, as an ambient term: its mean radiosity over 1 − ρ̄. Writes sol.ambient.
  void keep_ambient(const Shooting& shot) {
    Rgb unshot_sum(0.0f), reflectance_sum(0.0f);
    double area = 0.0;
    for (size_t e = 0; e < ne; ++e) {
      unshot_sum += shot.unshot[e] * mesh.element_area[e];
      reflectance_sum += sol.element_albedo[e] * mesh.element_area[e];
      area += mesh.element_area[e];
    }
    if (area > 0.0) {
      const float inv_area = float(1.0 / area);
      const Rgb rho = reflectance_sum * inv_area;
      for (int k = 0; k < 3; ++k) sol.ambient[k] = unshot_sum[k] * inv_area / std::max(1e-3f, 1.0f - rho[k]);
    }
  }

  /// When the time ran out before any of the reflected light was solved (no links, no shots):
  /// all of it is unshot, ρ times each element's direct light, and a display gathers it as the
  /// ambient term (gather_ambient) over runs of kUnsolvedPatchElements elements in the mesh's
  /// order, kUnsolvedRays rays each, rather than showing the direct light alone. Cohen's term
  /// alone assumes a closed room: the Stanford bunny on its floor under a lamp and sky
  /// (wrap/bunny-lit.json, --time 2) read 0.907 of the path tracer without any, 1.146 with
  /// Cohen's. A residual of 1 says nothing was solved. Writes sol.ambient, sol.vertex_ambient,
  /// sol.ambient_escaped, sol.residual and a warning.
  void keep_unsolved_ambient() {
    Shooting shot;
    shot.unshot.resize(ne);
    for (size_t e = 0; e < ne; ++e) {
      const auto& el = mesh.elements[e];
      const Rgb direct =
          e < sol.element_direct.size()
              ? sol.element_direct[e]
              : (sol.vertex_direct[el[0]] + sol.vertex_direct[el[1]] + sol.vertex_direct[el[2]]) *
                    (1.0f / 3.0f);
      shot.unshot[e] = sol.element_albedo[e] * direct;
    }
    keep_ambient(shot);
    sol.residual = 1.0;
    if (settings.gather_ambient) {
      std::vector<uint32_t> offsets, elements(ne);
      std::iota(elements.begin(), elements.end(), 0u);
      for (size_t e = 0; e < ne; e += kUnsolvedPatchElements) offsets.push_back(uint32_t(e));
      offsets.push_back(uint32_t(ne));
      AmbientGather gathered = gather_ambient(receivers.geometry, mesh, offsets, elements, shot.unshot,
                                              sol.element_albedo, kUnsolvedRays, settings.seed);
      rays += gathered.rays;
      sol.vertex_ambient = std::move(gathered.vertex_ambient);
      sol.ambient_escaped = gathered.escaped;
    }
    sol.mesh_report.warnings.push_back(
        "--time left no time for the reflected light: none of it was solved, and a display shows an "
        "estimate of it gathered with a few rays (the ambient term)");
  }

  /// Pass 2, progressive refinement on the final mesh: shoots the patch with the most unshot
  /// light until what is left falls below the tolerance (or the time runs out). Reads the direct
  /// light; adds the interreflection to sol.vertex_irradiance; writes sol.residual, shots,
  /// patches, ambient and shoot_seconds.
  void shoot_progressive() {
    const double shoot_start = elapsed();
    Shooting shot;
    start_shooting(shot);
    // Progress in per mille of the way from the emitted power down to tolerance × emitted, on a log scale.
    rc::util::Progress progress("radiosity", 1000, "‰", settings.progress);
    uint64_t shown = 0;
    shot.received.assign(nv, Rgb(0.0f));
    while (shot.emitted_power > 0.0) {
      const auto [src, best_signed] = brightest_patch(shot);
      const double done = std::clamp(std::log(sol.residual) / std::log(settings.tolerance), 0.0, 1.0);
      if (uint64_t(done * 1000) > shown) progress.advance(uint64_t(done * 1000) - shown), shown = uint64_t(done * 1000);
      if (sol.residual < settings.tolerance) break;
      // A shot takes about as long as the last one: stop before one would end past the budget,
      // and the ambient gather after it.
      if (over_solve_limit(elapsed() + shot.last_shot + ambient_gather_seconds(shot))) break;
      const double shot_start = elapsed();
      aim(shot, src, best_signed);
      shoot(shot, src);
      shot.last_shot = elapsed() - shot_start;
    }
    progress.finish();
    // An overshoot and the negative shot that corrects it see their own visibility rays, so where
    // they disagree a dim vertex can be left below zero, which no irradiance is: held at zero.
    for (Rgb& e : sol.vertex_irradiance) e = Rgb(std::max(e.r, 0.0f), std::max(e.g, 0.0f), std::max(e.b, 0.0f));
    keep_ambient(shot);
    const int gather_rays = ambient_gather_rays(shot);
    if (settings.gather_ambient && sol.residual > settings.tolerance && gather_rays > 0) {
      AmbientGather gathered =
          gather_ambient(receivers.geometry, mesh, shot.patches.offsets, shot.patches.elements, shot.unshot,
                         sol.element_albedo, gather_rays, settings.seed);
      rays += gathered.rays;
      sol.vertex_ambient = std::move(gathered.vertex_ambient);
      sol.ambient_escaped = gathered.escaped;
    }
    sol.shoot_seconds = elapsed() - shoot_start;
  }

  /// Foretold seconds of gather_ambient with kAmbientRaysPerPatch rays at the vertices' direct
  /// light's rate (a closest hit costs about twice a shadow ray); 0 untimed. The shots keep it back.
  double ambient_gather_seconds(const Shooting& shot) const {
    if (!settings.gather_ambient || !(settings.time_limit > 0.0) || !(direct_rays_per_second > 0.0))
      return 0.0;
    return 2.0 * double(shot.patches.count()) * kAmbientRaysPerPatch / direct_rays_per_second;
  }

  /// Gather rays per patch for the time left: kAmbientRaysPerPatch, fewer where the last shot
  /// took more than foretold, and none below kAmbientLeastRays (Cohen's term is used then).
  int ambient_gather_rays(const Shooting& shot) const {
    const double seconds = ambient_gather_seconds(shot);
    if (!(seconds > 0.0)) return kAmbientRaysPerPatch;
    const double left = group.broadcast_value(solve_limit() - elapsed());
    const int rays = int(std::min(1.0, std::max(0.0, left) / seconds) * kAmbientRaysPerPatch);
    return rays >= kAmbientLeastRays ? rays : 0;
  }

  /// Copies the hierarchical solve's result into the solution, its interreflection added to
  /// sol.vertex_irradiance, and its counts into ours.
  void keep_hierarchical(const HierarchicalResult& h) {
    for (size_t v = 0; v < nv; ++v) sol.vertex_irradiance[v] += h.vertex_irradiance[v];
    sol.nodes = h.nodes;
    sol.links = h.links;
    sol.iterations = h.iterations;
    if (h.clamped_elements > 0)
      sol.mesh_report.warnings.push_back(std::to_string(h.clamped_elements) +
                                         " elements were promised more reflected light than they can return "
                                         "(surfaces a hair apart?); their gathering was scaled down to keep the "
                                         "solution bounded");
    sol.residual = h.residual;
    sol.tail_added = h.tail_added;
    sol.chebyshev_beta = h.chebyshev_beta;
    sol.ladder = h.ladder;
    sol.element_closure = h.element_closure;
    sol.gather_nodes = h.gather_nodes;
    sol.final_gather = h.final_gather;
    sol.final_gather_note = h.final_gather_note;
    sol.link_tolerance = h.link_tolerance;
    sol.linking_stopped = h.linking_stopped;
    sol.link_seconds = h.link_seconds;
    sol.iterate_seconds = h.iterate_seconds;
    sol.gather_seconds = h.gather_seconds;
    rays += h.shadow_rays;
    form_factors += h.form_factors;
  }

  /// Samples per element and light of the elements' direct light: settings.visibility_samples,
  /// or under a time limit as many as fit in kElementDirectShare of the time left to the solve at
  /// the rate the vertices' direct light was traced (a 1.0M-element room takes 16 × 2 lights ×
  /// 1.0M rays otherwise, 7 s, before linking can start). Writes sol.element_direct_samples.
  int element_direct_samples() {
    int samples = settings.visibility_samples;
    if (settings.time_limit > 0.0 && direct_rays_per_second > 0.0) {
      const double seconds = kElementDirectShare * std::max(0.0, solve_limit() - elapsed());
      // Rank 0's choice, so that every process traces its elements alike.
      samples = group.broadcast_value(element_samples_within(mesh, scene.punctual_lights.size(), samples,
                                                             direct_rays_per_second, seconds));
      if (samples < settings.visibility_samples)
        sol.mesh_report.warnings.push_back("the direct light on elements took " + std::to_string(samples) +
                                           " sample(s) per element and light, not " +
                                           std::to_string(settings.visibility_samples) +
                                           ": --time left no more");
    }
    sol.element_direct_samples = samples;
    return samples;
  }

  /// Pass 2, hierarchical: the interreflection above the direct light, gathered at every vertex
  /// (solve_hierarchical). Reads the direct light; writes sol.element_direct and what
  /// keep_hierarchical keeps.
  void gather_hierarchical() {
    const std::vector<Rgb>& rho = sol.element_albedo;
    // What each element reflects of the direct light: its own mean of the lights' irradiance,
    // and the mean of its vertices' for emitting surfaces (resolved by refinement there).
    uint64_t element_rays = 0;
    rc::util::Progress progress("radiosity: direct light on elements", ne, "elements", settings.progress);
    std::vector<Rgb> element_direct = element_punctual_irradiance(
        scene, receivers.geometry, mesh, element_direct_samples(), settings.seed, element_rays, &progress);
    progress.finish();
    rays += element_rays;
    for (size_t e = 0; e < ne; ++e) {
      const auto& el = mesh.elements[e];
      element_direct[e] += (direct_emitted[el[0]] + direct_emitted[el[1]] + direct_emitted[el[2]]) * (1.0f / 3.0f);
    }
    const HierarchicalInput input{mesh, receivers.geometry, receivers.point, receivers.spread, rho, sol.vertex_irradiance, blocking(),
                                  [this] { return settings.time_limit > 0.0 && elapsed() > solve_limit(); },
                                  settings.time_limit > 0.0 ? std::function<double()>([this] { return solve_limit() - elapsed(); })
                                                            : std::function<double()>(),
                                  element_direct};
    if (std::all_of(sol.vertex_irradiance.begin(), sol.vertex_irradiance.end(),
                    [](const Rgb& e) { return e.is_black(); }))
      sol.mesh_report.warnings.push_back("the scene has no lights: the radiosity is zero everywhere");
    const HierarchicalResult h = solve_hierarchical(input, hs);
    sol.element_direct = std::move(element_direct);
    keep_hierarchical(h);
  }

  /// Radiosity from irradiance: emitted plus reflected, per vertex and per element (the mean of
  /// its vertices); and the counts and seconds.
  void finish() {
    sol.vertex_radiosity.resize(nv);
    // A vertex emits what its elements do (a twin's vertices are its own: see element_emitted).
    std::vector<Rgb> vertex_emitted(nv, Rgb(0.0f));
    for (size_t e = 0; e < ne; ++e)
      for (uint32_t v : mesh.elements[e]) vertex_emitted[v] = element_emitted(e);
    for (size_t v = 0; v < nv; ++v)
      sol.vertex_radiosity[v] = vertex_emitted[v] + sol.vertex_albedo[v] * sol.vertex_irradiance[v];
    sol.element_radiosity.resize(ne);
    for (size_t e = 0; e < ne; ++e) {
      const auto& el = mesh.elements[e];
      sol.element_radiosity[e] =
          (sol.vertex_radiosity[el[0]] + sol.vertex_radiosity[el[1]] + sol.vertex_radiosity[el[2]]) * (1.0f / 3.0f);
    }
    sol.form_factors = form_factors;
    sol.shadow_rays = rays;
    sol.skipped_pairs = skipped;
    sol.seconds = elapsed();
    sol.seconds_kept_back = seconds_kept_back(settings, ne);
  }
};

}  // namespace

const char* to_string(SolverKind kind) {
  switch (kind) {
    case SolverKind::automatic: return "auto";
    case SolverKind::progressive: return "progressive";
    case SolverKind::hierarchical: return "hierarchical";
  }
  return "?";
}

double seconds_kept_back(const SolverSettings& settings, size_t elements) {
  if (!(settings.time_limit > 0.0)) return 0.0;
  return std::max(0.0, settings.after_seconds) + std::max(0.0, settings.after_seconds_per_element) * double(elements);
}

SolverKind choose_solver(const SolverSettings& settings, size_t elements, std::string* why) {
  auto say = [&](std::string text) {
    if (why) *why = std::move(text);
  };
  if (settings.solver != SolverKind::automatic) {
    say("asked for");
    return settings.solver;
  }
  if (elements >= kHierarchicalElements) {
    say(std::to_string(elements) + " elements: progressive refinement would cost about n², hierarchical about n log n");
    return SolverKind::hierarchical;
  }
  say(std::to_string(elements) + " elements (below " + std::to_string(kHierarchicalElements) +
      "): progressive refinement is exact per vertex and fast enough");
  return SolverKind::progressive;
}

SolvePlan plan_solve(const rc::scene::Scene& scene, const SolverSettings& settings) {
  if (!scene.committed()) throw std::logic_error("radiosity::solver::plan_solve: the scene was not committed");
  SolvePlan plan;
  MeshReport report;
  MeshSettings mesh_settings = settings.mesh;
  mesh_settings.progress = settings.progress;
  const RadiosityMesh mesh = build_mesh(scene, mesh_settings, &report);
  plan.elements = mesh.element_count();
  plan.vertices = mesh.vertex_count();
  plan.max_edge = report.max_edge;
  plan.contact_edges = report.contact_edges;
  plan.buried_faces = report.buried_faces;
  plan.buried_elements = report.buried_elements;
  plan.buried_area = report.buried_area;
  plan.meshed_area = report.meshed_area;
  plan.mesh_stage_seconds = report.stage_seconds;
  plan.occluder_boxes = occluder_boxes(scene, mesh).size();
  plan.convex_enclosure = plan.occluder_boxes == 0;
  plan.punctual_lights = scene.punctual_lights.size();
  plan.solver = choose_solver(settings, plan.elements, &plan.solver_reason);
  for (const rc::scene::TriangleMesh& m : scene.meshes) plan.specular_surfaces += scene.materials[m.material].is_traced_through();
  for (const rc::scene::Sphere& s : scene.spheres) plan.specular_surfaces += scene.materials[s.material].is_traced_through();
  return plan;
}

Solution solve(const rc::scene::Scene& scene, const SolverSettings& settings) {
  if (!scene.committed()) throw std::logic_error("radiosity::solver::solve: the scene was not committed");
  if (!(settings.tolerance > 0.0) || !std::isfinite(settings.tolerance))
    throw rc::InputError("--tolerance must be a positive number");
  if (settings.visibility_samples < 1) throw rc::InputError("visibility samples must be at least 1");
  if (settings.subdivision_levels < 0) throw rc::InputError("subdivision levels must be at least 0");
  if (!(settings.subdivision_threshold > 0.0) || !std::isfinite(settings.subdivision_threshold))
    throw rc::InputError("the subdivision threshold must be a positive number");
  const auto start = std::chrono::steady_clock::now();
  const rc::util::ThreadLimit limit(settings.threads);

  Solution sol;
  mesh_scene(scene, settings, start, sol);
  SolveState state(scene, settings, sol, start);
  // Pass 1, direct light, refining the mesh where it changes steeply.
  state.gather_direct(0);
  state.refine_direct();
  state.choose_after_refinement();
  state.keep_direct();
  // Pass 2, the interreflection.
  if (state.hierarchical) {
    state.gather_hierarchical();
    // No level of links fitted in the time (a furnished room's clusters, close together, split
    // down to millions of links at any tolerance): the brightest patches shoot in what is left, a
    // coarse reflected solution rather than none.
    if (settings.time_limit > 0.0 && sol.links == 0 && !state.over_solve_limit(state.elapsed())) {
      sol.shot_without_links = true;
      state.shoot_progressive();
    } else if (settings.time_limit > 0.0 && sol.links == 0) {
      state.keep_unsolved_ambient();
    }
  } else
    state.shoot_progressive();
  state.finish();
  return sol;
}

}  // namespace gilt::radiosity::solver

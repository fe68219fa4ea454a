// Object-space check. The path tracer looks straight down, along the vertex normal, at points of
// the input surface around each checked vertex, with a white, unlit Lambertian standing in for the
// surface where it lands (PathSettings::first_surface). Its estimate of the radiance leaving that
// stand-in, with next-event estimation and MIS, is E/π whatever the surface really is: a
// metallic-roughness surface is checked as a Lambertian one, and a texel's colour does not enter.
// Sampling the incoming radiance by cosine-distributed directions instead leaves a small light to
// chance (7.5 % noise at 4,096 samples on the Cornell box, against 2.6 % this way). The points
// fill a disk around the vertex, half as wide as the distance to its nearest element centroid,
// on the vertex's side of any crease: a vertex colour stands for that much surface, and a finely
// detailed input (a scan) varies within it in ways no vertex colour can follow.
// The surface checks draw random points inside the input's faces instead, look at each the same
// way, and read the bake there: the input's own vertex colours, its lightmap, or the exported
// element lying on the point (found by a BVH point query, as snapped_to_input finds the input).

#include "radiosity/bake/check.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "radiosity/mesh/element_scene.h"
#include "radiosity/bake/lightmap.h"
#include "radiosity/bake/onto_input.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/staged_file.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::bake {

using mesh::RadiosityMesh;
using mesh::element_scene;
using mesh::input_point_buried;
using mesh::input_triangle_buried;
using solver::Solution;
using solver::receiver_points;

void CheckSettings::validate() const {
  if (points < 1) throw rc::InputError("check: points must be at least 1, not " + std::to_string(points));
  if (samples < 2) throw rc::InputError("check: samples must be at least 2, not " + std::to_string(samples));
}

namespace {

/// Path settings whose first surface is a white, unlit Lambertian: π times their radiance
/// estimate is the irradiance where the path starts.
rc::render::PathSettings irradiance_probe() {
  static const rc::scene::Material white = rc::scene::Material::make_diffuse("irradiance probe", Rgb(1.0f));
  rc::render::PathSettings path;
  path.first_surface = &white;
  return path;
}

}  // namespace

CheckResult check_against_path_tracer(const rc::scene::Scene& scene, const Solution& solution, const CheckSettings& settings) {
  settings.validate();
  const auto start = std::chrono::steady_clock::now();
  CheckResult result;
  const RadiosityMesh& mesh = solution.mesh;
  const size_t nv = mesh.vertex_count();
  if (nv == 0) return result;
  const size_t count = std::min(nv, size_t(settings.points));
  const std::vector<Vec3> origin = receiver_points(element_scene(scene, mesh), mesh);
  // Each vertex stands for the surface around it, a disk of vertex_disk_radius.
  const std::vector<float> radius = vertex_disk_radius(mesh);
  std::vector<Rgb> mean(count), standard_error(count);
  std::vector<char> usable(count, 0);
  const rc::render::PathSettings path = irradiance_probe();
  rc::util::parallel_for(count, [&](size_t i) {
    const size_t v = i * nv / count;
    const Vec3 n = mesh.normals[v];
    const rc::Frame frame = rc::Frame::from_normal(n);
    const float r = radius[v];
    Rgb sum(0.0f), sum_squares(0.0f);
    int taken = 0;
    for (int s = 0; s < settings.samples; ++s) {
      rc::render::SampleContext ctx{rc::render::Sampler(rc::util::Rng::for_item(settings.seed, v, 0xc0ffee0000ull + uint64_t(s))), 0};
      const rc::Vec2 u = rc::util::sample_uniform_disk(ctx.sampler.uniform2()) * r;
      // Only the surface on the vertex's side of a crease (vertices are split at 30°) counts.
      const Vec3 offset = origin[v] - mesh.positions[v] + frame.to_world(Vec3(u.x, u.y, 0.0f));
      const std::optional<InputPoint> under = input_surface_under(scene, mesh, v, offset, r);
      if (!under) continue;
      const rc::scene::Ray& ray = under->ray;
      const Rgb e = rc::render::path_radiance(scene, ray, ctx, path) * rc::kPi;
      sum += e;
      sum_squares += e * e;
      ++taken;
    }
    if (taken < 2) return;
    const float n_samples = float(taken);
    mean[i] = sum / n_samples;
    for (int c = 0; c < 3; ++c) {
      const float variance = std::max(0.0f, (sum_squares[c] - sum[c] * sum[c] / n_samples) / (n_samples - 1.0f));
      standard_error[i][c] = std::sqrt(variance / n_samples);
    }
    usable[i] = 1;
  });
  double reference_mean = 0.0;
  size_t used = 0;
  for (size_t i = 0; i < count; ++i)
    if (usable[i]) reference_mean += mean[i].average(), ++used;
  if (used == 0) return result;
  const double floor = 0.01 * reference_mean / double(used);
  double error = 0.0, noise = 0.0, absolute = 0.0, total = 0.0;
  for (size_t i = 0; i < count; ++i) {
    if (!usable[i]) continue;
    const size_t v = i * nv / count;
    const Rgb& solved = solution.vertex_irradiance[v];
    for (int c = 0; c < 3; ++c) {
      const double denominator = double(mean[i][c]) + floor;
      if (!(denominator > 0.0)) continue;  // black everywhere: nothing to compare
      error += std::abs(double(solved[c]) - double(mean[i][c])) / denominator;
      absolute += std::abs(double(solved[c]) - double(mean[i][c]));
      total += double(mean[i][c]);
      noise += double(standard_error[i][c]) / denominator;
    }
    result.compared.push_back({uint32_t(v), mesh.positions[v], mesh.normals[v], radius[v], mean[i], standard_error[i], solved});
  }
  result.points = used;
  result.mean_relative_error = error / (3.0 * double(used));
  result.reference_noise = noise / (3.0 * double(used));
  result.relative_mean_absolute_error = total > 0.0 ? absolute / total : 0.0;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

namespace {

/// A point drawn for a surface check: face `triangle` of scene mesh `mesh`, at barycentrics
/// `weight`, position `position`, unit face normal `normal`.
struct DrawnPoint {
  uint32_t mesh, triangle;
  float weight[3];
  Vec3 position, normal;
};

/// The baked irradiance at a drawn point, or nothing where the bake has no value there.
using BakedAt = std::function<std::optional<Rgb>(const DrawnPoint&)>;

/// What became of a drawn point.
enum class Outcome : uint8_t {
  skipped,    ///< something lies on it: not counted
  compared,   ///< compared with the path tracer
  unlit,      ///< buried, or no path-traced sample found light
  uncovered,  ///< would have been compared, but the bake has no value there
};

/// A face a surface check may draw points on.
struct CheckFace {
  uint32_t mesh, triangle;
};

/// One drawn point's outcome: the path-traced mean irradiance and its variance of the mean, the
/// baked value, and where it lies (filled when compared).
struct CheckedPoint {
  Outcome outcome = Outcome::skipped;
  Rgb baked, mean, variance;
  SurfaceCheckPoint where;
};

/// Reads the scene; returns the faces the bake covers and their areas, the weights points are
/// drawn by (mirror and glass faces, which carry no radiosity of their own, are left out).
std::vector<CheckFace> checked_faces(const rc::scene::Scene& scene,
                                     const std::function<bool(size_t)>& drawn_from,
                                     std::vector<float>& area) {
  std::vector<CheckFace> faces;
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const rc::scene::TriangleMesh& mesh = scene.meshes[m];
    const rc::scene::Material& mat = scene.materials[mesh.material];
    if (!drawn_from(m) || mat.is_traced_through()) continue;
    for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      const Vec3 &a = mesh.positions[mesh.indices[3 * t]], &b = mesh.positions[mesh.indices[3 * t + 1]],
                 &c = mesh.positions[mesh.indices[3 * t + 2]];
      faces.push_back({m, t});
      area.push_back(0.5f * glm::length(glm::cross(b - a, c - a)));
    }
  }
  return faces;
}

/// Which side of a drawn point is compared.
enum class Sides : uint8_t {
  /// The front, or the back where no light reaches the front: the side a bake carries (one
  /// colour per point; it reads the back where the mesher turned the surface over).
  lit,
  /// Either, drawn at random: an element export has an element on each side light reaches.
  either,
};

/// A point's path-traced irradiance below this fraction of the mean over the drawn points is no
/// light: a sample can bring an emitter's light at a grazing angle of a rounding error (1e-14 of
/// it on the outside of a closed furnace, whose faces emit inwards).
constexpr double kUnlitFraction = 1e-6;

/// A point on its way through the check: drawn, then traced on one side, then perhaps the other.
struct PointInCheck {
  DrawnPoint point;
  bool face_buried = false;  ///< on a face inside a solid or under an object (input_triangle_buried)
  bool buried = false;       ///< that, or the point buried on the side traced (input_point_buried)
  bool blocked = false;      ///< something lies on the point, or coincides with its face
  Rgb mean{0.0f}, variance{0.0f};
};

/// Draws point i on `face` with `rng`, on its front, or with Sides::either on a side drawn at random.
PointInCheck draw_point(const rc::scene::Scene& scene, const CheckFace& face, rc::util::Rng& rng,
                        Sides sides) {
  const rc::scene::TriangleMesh& mesh = scene.meshes[face.mesh];
  const uint32_t* corner = &mesh.indices[3 * size_t(face.triangle)];
  const rc::Vec2 uv = rc::util::sample_uniform_triangle(rng.uniform2());
  PointInCheck out;
  DrawnPoint& point = out.point;
  point = DrawnPoint{face.mesh, face.triangle, {1.0f - uv.x - uv.y, uv.x, uv.y}, Vec3(0.0f), Vec3(0.0f)};
  for (int k = 0; k < 3; ++k) point.position += point.weight[k] * mesh.positions[corner[k]];
  point.normal = glm::normalize(glm::cross(mesh.positions[corner[1]] - mesh.positions[corner[0]],
                                           mesh.positions[corner[2]] - mesh.positions[corner[0]]));
  if (sides == Sides::either && rng.uniform() < 0.5f) point.normal = -point.normal;
  // Inside a solid or under an object: no one sees it (the fit leaves buried faces out too).
  out.face_buried = input_triangle_buried(scene, mesh.positions[corner[0]], mesh.positions[corner[1]],
                                          mesh.positions[corner[2]]);
  return out;
}

/// Path-traces the irradiance of point i on the side its normal faces: settings.samples samples,
/// along rays `step` above it, each looking straight down at it.
void trace_point(const rc::scene::Scene& scene, PointInCheck& at, size_t i, float step,
                 const rc::render::PathSettings& path, const CheckSettings& settings) {
  const Vec3 &p = at.point.position, &n = at.point.normal;
  at.buried = at.face_buried || input_point_buried(scene, p, n);
  at.mean = at.variance = Rgb(0.0f);
  if (at.buried) return;
  Rgb sum(0.0f), sum_squares(0.0f);
  for (int s = 0; s < settings.samples; ++s) {
    rc::render::SampleContext ctx{
        rc::render::Sampler(rc::util::Rng::for_item(settings.seed, i, 0xc0ffee0000ull + uint64_t(s))), 0};
    const rc::scene::Ray ray{p + step * n, -n, 2.0f * step};
    const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    // Something lies on the point, or coincides with its face (a duplicate, facing either way).
    if (!hit || hit->geom_id != at.point.mesh || hit->prim_id != at.point.triangle) {
      at.blocked = true;
      return;
    }
    const Rgb e = rc::render::path_radiance(scene, ray, ctx, path) * rc::kPi;
    sum += e;
    sum_squares += e * e;
  }
  const float ns = float(settings.samples);
  at.mean = sum / ns;
  for (int c = 0; c < 3; ++c)
    at.variance[c] = std::max(0.0f, (sum_squares[c] - sum[c] * sum[c] / ns) / (ns - 1.0f)) / ns;
}

/// The mean path-traced irradiance over the points traced (neither buried nor blocked).
double mean_traced(const std::vector<PointInCheck>& points) {
  double sum = 0.0;
  size_t n = 0;
  for (const PointInCheck& at : points)
    if (!at.buried && !at.blocked) sum += at.mean.average(), ++n;
  return n > 0 ? sum / double(n) : 0.0;
}

/// The outcome of a traced point: unlit below `unlit` (or buried), else compared with `baked_at`.
CheckedPoint outcome_of(const rc::scene::Scene& scene, const PointInCheck& at, double unlit,
                        const BakedAt& baked_at) {
  CheckedPoint out;
  if (at.blocked) return out;
  if (at.buried || !(at.mean.average() > unlit)) {
    out.outcome = Outcome::unlit;
    return out;
  }
  // Whether the bake has a value here is asked last, of points that would be compared: a
  // buried or unlit point is no hole in it.
  const std::optional<Rgb> value = baked_at(at.point);
  if (!value) {
    out.outcome = Outcome::uncovered;
    return out;
  }
  const rc::scene::TriangleMesh& mesh = scene.meshes[at.point.mesh];
  const uint32_t* corner = &mesh.indices[3 * size_t(at.point.triangle)];
  out.mean = at.mean;
  out.variance = at.variance;
  out.baked = *value;
  SurfaceCheckPoint& where = out.where;
  where.mesh = at.point.mesh;
  where.triangle = at.point.triangle;
  for (int k = 0; k < 3; ++k) {
    where.file_vertex[k] = mesh.origin.vertex.empty() ? corner[k] : mesh.origin.vertex[corner[k]];
    where.weight[k] = at.point.weight[k];
  }
  where.position = at.point.position;
  where.albedo = scene.materials[mesh.material].albedo;
  out.outcome = Outcome::compared;
  return out;
}

/// Reads the compared points; writes the scores into `result` (relative MSE with a floor of 1 %
/// of the mean reference, the reference's own noise share, mean relative error and ratio).
void score_points(std::vector<CheckedPoint>& points, size_t used, double reference_mean, SurfaceCheckResult& result) {
  const double floor = 0.01 * reference_mean / double(used);
  double squared = 0.0, share = 0.0, relative = 0.0, baked_sum = 0.0, reference_sum = 0.0;
  for (CheckedPoint& point : points) {
    if (point.outcome != Outcome::compared) continue;
    for (int c = 0; c < 3; ++c) {
      const double r = point.mean[c], d = double(point.baked[c]) - r;
      squared += d * d / (r * r + floor * floor);
      share += double(point.variance[c]) / (r * r + floor * floor);
      relative += std::abs(d) / (r + floor);
      baked_sum += double(point.baked[c]);
      reference_sum += r;
    }
    SurfaceCheckPoint& at = point.where;
    at.reference = point.mean;
    at.baked = point.baked;
    for (int c = 0; c < 3; ++c) at.standard_error[c] = std::sqrt(point.variance[c]);
    result.compared.push_back(at);
  }
  result.points = used;
  result.covered = used;
  result.relative_mse = squared / (3.0 * double(used));
  result.reference_share = share / (3.0 * double(used));
  result.mean_relative_error = relative / (3.0 * double(used));
  result.mean_ratio = reference_sum > 0.0 ? baked_sum / reference_sum : 0.0;
}

/// The check behind check_input_colours, check_lightmap and check_element_colours: draws
/// settings.points points by area over the faces of the scene meshes `drawn_from(m)` accepts
/// (mirrors and glass never), path-traces the irradiance at each and compares it with `baked_at`.
SurfaceCheckResult check_baked(const rc::scene::Scene& scene, const std::function<bool(size_t)>& drawn_from,
                               const BakedAt& baked_at, const CheckSettings& settings, Sides sides,
                               const BakedSide& side = {}) {
  settings.validate();
  const auto start = std::chrono::steady_clock::now();
  std::vector<float> area;
  const std::vector<CheckFace> faces = checked_faces(scene, drawn_from, area);
  SurfaceCheckResult result;
  const rc::util::Distribution1D pick(area);
  if (pick.size() == 0) return result;
  const float step = 1e-4f * glm::length(scene.bounds().diagonal());
  const size_t count = size_t(settings.points);
  std::vector<PointInCheck> drawn(count);
  const rc::render::PathSettings path = irradiance_probe();
  rc::util::parallel_for(count, [&](size_t i) {
    rc::util::Rng rng = rc::util::Rng::for_item(settings.seed, i, 0x5eed0f00ull);
    const CheckFace& face = faces[pick.sample(rng.uniform())];
    drawn[i] = draw_point(scene, face, rng, sides);
    if (side) drawn[i].point.normal = side(drawn[i].point.position, drawn[i].point.normal);
    trace_point(scene, drawn[i], i, step, path, settings);
  });
  // What counts as no light is known once the points are traced; with Sides::lit, the points
  // whose front has none are traced again on their back.
  double unlit = kUnlitFraction * mean_traced(drawn);
  if (sides == Sides::lit && !side) {
    rc::util::parallel_for(count, [&](size_t i) {
      PointInCheck& at = drawn[i];
      if (at.blocked || at.face_buried || at.mean.average() > unlit) return;
      at.point.normal = -at.point.normal;
      trace_point(scene, at, i, step, path, settings);
    });
    unlit = kUnlitFraction * mean_traced(drawn);
  }
  std::vector<CheckedPoint> points(count);
  rc::util::parallel_for(count, [&](size_t i) { points[i] = outcome_of(scene, drawn[i], unlit, baked_at); });
  double reference_mean = 0.0;
  size_t used = 0;
  for (const CheckedPoint& point : points) {
    if (point.outcome == Outcome::compared) reference_mean += point.mean.average(), ++used;
    if (point.outcome == Outcome::unlit) ++result.unlit;
    if (point.outcome == Outcome::uncovered) ++result.uncovered;
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (used == 0) return result;
  score_points(points, used, reference_mean, result);
  return result;
}

}  // namespace

void write_check_points(const std::string& path, const rc::scene::Scene& scene,
                        const SurfaceCheckResult& result) {
  std::string out =
      "gltf_mesh,gltf_primitive,v0,v1,v2,w0,w1,w2,x,y,z,albedo_r,albedo_g,albedo_b,reference_r,reference_g,"
      "reference_b,standard_error_r,standard_error_g,standard_error_b,baked_r,baked_g,baked_b\n";
  char line[512];
  const auto rgb = [&](const Rgb& c) {
    std::snprintf(line, sizeof line, ",%.9g,%.9g,%.9g", double(c.r), double(c.g), double(c.b));
    out += line;
  };
  for (const SurfaceCheckPoint& p : result.compared) {
    const rc::scene::MeshOrigin& origin = scene.meshes[p.mesh].origin;
    std::snprintf(line, sizeof line, "%d,%d,%u,%u,%u,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", origin.mesh, origin.primitive,
                  p.file_vertex[0], p.file_vertex[1], p.file_vertex[2], double(p.weight[0]), double(p.weight[1]),
                  double(p.weight[2]), double(p.position.x), double(p.position.y), double(p.position.z));
    out += line;
    rgb(p.albedo);
    rgb(p.reference);
    rgb(p.standard_error);
    rgb(p.baked);
    out += '\n';
  }
  rc::util::StagedFile(path, out).commit();
}

void write_check_points(const std::string& path, const CheckResult& result) {
  std::string out =
      "vertex,x,y,z,nx,ny,nz,disk_radius,reference_r,reference_g,reference_b,standard_error_r,standard_error_g,"
      "standard_error_b,solved_r,solved_g,solved_b\n";
  char line[512];
  for (const VertexCheckPoint& p : result.compared) {
    std::snprintf(line, sizeof line,
                  "%u,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", p.vertex,
                  double(p.position.x), double(p.position.y), double(p.position.z), double(p.normal.x),
                  double(p.normal.y), double(p.normal.z), double(p.disk_radius), double(p.reference.r),
                  double(p.reference.g), double(p.reference.b), double(p.standard_error.r),
                  double(p.standard_error.g), double(p.standard_error.b), double(p.solved.r), double(p.solved.g),
                  double(p.solved.b));
    out += line;
  }
  rc::util::StagedFile(path, out).commit();
}

SurfaceCheckResult check_input_colours(const rc::scene::Scene& scene, const InputColours& irradiance,
                                       const CheckSettings& settings, const BakedSide& side) {
  const auto baked_at = [&](const DrawnPoint& at) -> std::optional<Rgb> {
    Rgb value(0.0f);
    for (size_t k = 0; k < 3; ++k)
      value += at.weight[k] * irradiance.at_corner(scene, at.mesh, 3 * size_t(at.triangle) + k);
    return value;
  };
  return check_baked(
      scene, [&](size_t m) { return scene.meshes[m].origin.file == irradiance.file && irradiance.covers(m); },
      baked_at, settings, Sides::lit, side);
}

SurfaceCheckResult check_lightmap(const rc::scene::Scene& scene, const Lightmap& irradiance,
                                  const CheckSettings& settings, const BakedSide& side) {
  return check_baked(
      scene,
      [&](size_t m) {
        return scene.meshes[m].origin.file == irradiance.file && !irradiance.corner_uv[m].empty();
      },
      [&](const DrawnPoint& at) -> std::optional<Rgb> {
        return irradiance.at(at.mesh, at.triangle, at.weight[1], at.weight[2]);
      },
      settings, Sides::lit, side);
}

SurfaceCheckResult check_element_colours(const rc::scene::Scene& scene, const RadiosityMesh& exported,
                                         const std::vector<Rgb>& vertex_irradiance,
                                         const CheckSettings& settings) {
  if (vertex_irradiance.size() != exported.vertex_count())
    throw std::logic_error("check_element_colours: " + std::to_string(vertex_irradiance.size()) +
                           " irradiance values for " + std::to_string(exported.vertex_count()) + " vertices");
  const auto start = std::chrono::steady_clock::now();
  // The elements in a BVH (geometry 0 of element_scene, its primitive ids the element indices).
  std::optional<rc::scene::Scene> elements;
  if (exported.element_count() > 0) elements.emplace(element_scene(scene, exported));
  const float reach = 1e-4f * glm::length(scene.bounds().diagonal());
  const float facing = std::cos(2.5f * rc::kPi / 180.0f);
  const auto baked_at = [&](const DrawnPoint& at) -> std::optional<Rgb> {
    if (!elements) return std::nullopt;
    const std::optional<rc::scene::Hit> near =
        elements->nearest_triangle(0, at.position, reach, at.normal, facing);
    if (!near) return std::nullopt;
    const std::array<uint32_t, 3>& corner = exported.elements[near->prim_id];
    return (1.0f - near->u - near->v) * vertex_irradiance[corner[0]] +
           near->u * vertex_irradiance[corner[1]] + near->v * vertex_irradiance[corner[2]];
  };
  // Every input mesh of every file (check_baked leaves out mirrors and glass, which are not meshed).
  SurfaceCheckResult result = check_baked(
      scene, [](size_t) { return true; }, baked_at, settings, Sides::either);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

double SurfaceCheckResult::covered_share() const {
  return covered + uncovered > 0 ? double(covered) / double(covered + uncovered) : 0.0;
}

}  // namespace gilt::radiosity::bake

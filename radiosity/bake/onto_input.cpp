// `--onto input`: fitting the solution onto the model's own vertices, and choosing its writer.

#include "radiosity/bake/onto_input.h"

#include <array>
#include <bit>
#include <chrono>
#include <filesystem>
#include <functional>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "radiosity/bake/view.h"
#include "radiosity/mesh/element_scene.h"
#include "raytrace_core/io/loaders.h"
#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/progress.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::bake {

using mesh::RadiosityMesh;
using mesh::input_triangle_buried;
using mesh::mesh_surface_point;
using solver::Solution;

namespace fs = std::filesystem;
using rc::InputError;

int32_t onto_input_file(const rc::scene::Scene& scene) {
  if (scene.model_files.empty())
    throw InputError("--onto input writes onto the model file the scene was read from, and " + scene.name +
                     " has none (a built-in scene, or a JSON scene of spheres only): use --onto elements");
  if (scene.model_files.size() > 1) {
    std::string names;
    for (const std::string& f : scene.model_files) names += (names.empty() ? "" : ", ") + f;
    throw InputError("--onto input writes onto one model file, and " + scene.name + " reads " +
                     std::to_string(scene.model_files.size()) + " (" + names +
                     "): bake each on its own, or use --onto elements");
  }
  return 0;
}

SolutionAtInput::SolutionAtInput(const rc::scene::Scene& scene, const Solution& solution, Quantity quantity,
                                 BakeGather gather)
    : scene_(scene), solution_(solution), view_(scene, solution, ViewMode::mesh, /*ambient=*/false),
      quantity_(quantity), gather_(gather) {
  // Point, spot and directional lights reach each point by its own shadow ray against the input,
  // so a sun patch or a sharp shadow falls as it does on the input's faces, not as the elements'
  // vertices caught it; the rest (sky, emitting surfaces, interreflection) is the solution's,
  // interpolated over the nearest element facing the same way.
  for (const rc::scene::Light& l : scene.punctual_lights)
    if (l.kind != rc::scene::LightKind::environment) delta_lights_.push_back(&l);
  exact_direct_ = !delta_lights_.empty() && solution.vertex_punctual.size() == solution.mesh.vertex_count();
}

SolutionAtInput::Side SolutionAtInput::choose(const Vec3& p, const Vec3& face_normal) const {
  // The side to read: the one whose element lies on the point, the nearer where only one does
  // (the mesher turned the surface over where light reaches only its back). Where light reaches
  // both sides, an element lies on each: the one the mesher made from the surface (not its twin)
  // is read, so that every face of a piece reads the same side however each face is wound (a
  // model wound face by face at random would otherwise blend its two sides at every shared
  // vertex), and the face's front where neither is a twin (two sheets back to back).
  Side out;
  const std::optional<RadiosityView::Location> front = view_.locate(p, face_normal);
  const std::optional<RadiosityView::Location> back = view_.locate(p, -face_normal);
  const float on = 1e-4f * view_.reach();
  bool use_back = back && (!front || back->distance + on < front->distance);
  out.both = front && back && std::abs(back->distance - front->distance) <= on;
  if (out.both) use_back = solution_.mesh.twin(front->element) && !solution_.mesh.twin(back->element);
  out.at = use_back ? back : front;
  out.normal = use_back ? -face_normal : face_normal;
  out.back = use_back;
  out.other = use_back ? front : back;
  return out;
}

Vec3 SolutionAtInput::side(const Vec3& p, const Vec3& face_normal) const {
  return choose(p, face_normal).normal;
}

std::optional<Rgb> SolutionAtInput::operator()(const rc::scene::Material& m, const Vec3& p,
                                               const Vec3& face_normal) const {
  const Side side = choose(p, face_normal);
  if (!side.at) return std::nullopt;
  const Vec3& n = side.normal;
  ++points_;
  back_ += side.back;
  if (side.both) {
    const auto irradiance = [&](const RadiosityView::Location& l) {
      const auto& c = solution_.mesh.elements[l.element];
      const std::vector<Rgb>& e = solution_.vertex_irradiance;
      return (e[c[0]] * (1.0f - l.u - l.v) + e[c[1]] * l.u + e[c[2]] * l.v).average();
    };
    const float a = irradiance(*side.at), b = irradiance(*side.other);
    if (std::max(a, b) > kSidesDiffer * std::min(a, b)) ++differ_;
  }
  const Rgb e = gather_.rays > 0 && std::chrono::steady_clock::now() < gather_.deadline
                    ? gathered(p, n)
                    : read(*side.at, p, n);
  const Rgb radiosity = m.emission * rc::kPi + rc::scene::diffuse_reflectance(m) * e;
  return quantity_ == Quantity::irradiance ? e : quantity_ == Quantity::radiosity ? radiosity : radiosity / rc::kPi;
}

Rgb SolutionAtInput::gathered(const Vec3& p, const Vec3& n) const {
  ++gathered_;
  // The point's own sampler, keyed by its position and normal: the same for any thread order.
  const auto bits = [](float x) { return uint64_t(std::bit_cast<uint32_t>(x)); };
  const uint64_t key =
      rc::util::mix64(bits(p.x) | bits(p.y) << 32) ^ rc::util::mix64(bits(p.z) | bits(n.x) << 32);
  const uint64_t point = key ^ rc::util::mix64(bits(n.y) | bits(n.z) << 32);
  rc::render::SampleContext ctx{
      rc::render::Sampler::for_pixel_sample(rc::render::SamplerKind::sobol, gather_.seed, point, 0), 0};
  return view_.gathered_irradiance(mesh_surface_point(p, n), gather_.rays, ctx);
}

Rgb SolutionAtInput::read(const RadiosityView::Location& at, const Vec3& p, const Vec3& n) const {
  if (gather_.rays > 0) ++late_;
  const auto& corner = solution_.mesh.elements[at.element];
  const auto interpolate = [&](const std::vector<Rgb>& per_vertex) {
    return per_vertex[corner[0]] * (1.0f - at.u - at.v) + per_vertex[corner[1]] * at.u + per_vertex[corner[2]] * at.v;
  };
  Rgb e = interpolate(solution_.vertex_irradiance);
  if (exact_direct_) {
    e = rc::clamp(e - interpolate(solution_.vertex_punctual), 0.0f, std::numeric_limits<float>::max());
    const rc::scene::SurfacePoint sp = mesh_surface_point(p, n);
    for (const rc::scene::Light* light : delta_lights_) {
      const rc::scene::LightSample ls = rc::scene::sample_light(scene_, *light, sp, rc::Vec2(0.5f));
      const float cos_theta = glm::dot(ls.wi, n);
      if (cos_theta > 0.0f && !ls.radiance.is_black() && !scene_.occluded(ls.shadow_ray)) e += ls.radiance * cos_theta;
    }
  }
  return e;
}

std::vector<char> input_faces_buried(const rc::scene::Scene& scene, std::span<const Vec3> positions,
                                     std::span<const uint32_t> indices) {
  std::vector<char> buried(indices.size() / 3, 0);
  rc::util::parallel_for(buried.size(), [&](size_t f) {
    buried[f] = input_triangle_buried(scene, positions[indices[3 * f]], positions[indices[3 * f + 1]],
                                      positions[indices[3 * f + 2]]);
  });
  return buried;
}

Rgb InputColours::at_corner(const rc::scene::Scene& scene, size_t m, size_t corner) const {
  const rc::scene::TriangleMesh& mesh = scene.meshes[m];
  const uint32_t v = mesh.indices[corner];
  if (per_mesh.empty()) return per_file_vertex[mesh.origin.vertex.empty() ? v : mesh.origin.vertex[v]];
  return per_mesh[m][wedges.empty() || wedges[m].of_corner.empty() ? v : wedges[m].of_corner[corner]];
}

bool InputColours::covers(size_t m) const {
  return per_mesh.empty() ? !per_file_vertex.empty() : !per_mesh[m].empty();
}

namespace {

bool is_gltf(const std::string& path) {
  const std::string ext = rc::io::lower_extension(path);
  return ext == ".gltf" || ext == ".glb";
}

}  // namespace

InputVertices input_vertices(const std::string& output, const rc::scene::Scene& scene, bool keep) {
  if (!is_gltf(output)) return InputVertices::as_read;
  if (!keep) return InputVertices::split;
  return is_gltf(scene.model_files[size_t(onto_input_file(scene))]) ? InputVertices::as_read
                                                                    : InputVertices::file;
}

namespace {

/// The baked faces of every mesh read from the model file, as one mesh whose vertices are welded
/// where their positions are equal bit for bit (a glTF primitive's vertices are split at its UV
/// and normal seams, and an OBJ's at its own `v` lines; the light is continuous across both), or
/// not `by_position`, one per vertex of the file (an OBJ's `v` lines).
struct WeldedInput {
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;
  std::vector<uint32_t> face_material;
  std::vector<std::pair<uint32_t, uint32_t>>
      corner_origin;  ///< per corner: scene mesh, corner in its index list
};

struct PositionBitsHash {
  size_t operator()(const std::array<uint32_t, 3>& k) const {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (uint32_t x : k) h = (h ^ x) * 0x100000001B3ull;
    return size_t(h ^ (h >> 29));
  }
};

WeldedInput weld_input(const rc::scene::Scene& scene,
                       const std::function<bool(const rc::scene::TriangleMesh&)>& baked, bool by_position) {
  WeldedInput w;
  std::unordered_map<std::array<uint32_t, 3>, uint32_t, PositionBitsHash> index_of;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const rc::scene::TriangleMesh& mesh = scene.meshes[m];
    if (!baked(mesh)) continue;
    for (size_t c = 0; c < mesh.indices.size(); ++c) {
      const uint32_t v = mesh.indices[c];
      const Vec3 p = mesh.positions[v];
      const std::array<uint32_t, 3> key =
          by_position
              ? std::array<uint32_t, 3>{std::bit_cast<uint32_t>(p.x), std::bit_cast<uint32_t>(p.y),
                                        std::bit_cast<uint32_t>(p.z)}
              : std::array<uint32_t, 3>{mesh.origin.vertex.empty() ? v : mesh.origin.vertex[v], 0u, 0u};
      const auto [it, added] = index_of.try_emplace(key, uint32_t(w.positions.size()));
      if (added) w.positions.push_back(p);
      w.indices.push_back(it->second);
      w.corner_origin.emplace_back(uint32_t(m), uint32_t(c));
      if (c % 3 == 0) w.face_material.push_back(mesh.material);
    }
  }
  return w;
}

}  // namespace

InputColours fit_input_colours(const rc::scene::Scene& scene, const Solution& solution, VertexFit fit,
                               Quantity quantity, BakeGather gather, InputVertices vertices) {
  const auto start = std::chrono::steady_clock::now();
  InputColours out;
  out.file = onto_input_file(scene);
  const std::string ext = rc::io::lower_extension(scene.model_files[size_t(out.file)]);
  const bool per_file_vertex = vertices == InputVertices::as_read && (ext == ".obj" || ext == ".ply");
  const float spacing = 0.5f * solution.mesh_report.max_edge;
  const SolutionAtInput at_input(scene, solution, quantity, gather);
  const auto value = [&](const rc::scene::Material& m, const Vec3& p, const Vec3& n) {
    return at_input(m, p, n);
  };
  const auto baked = [&](const rc::scene::TriangleMesh& mesh) {
    return mesh.origin.file == out.file && !scene.materials[mesh.material].is_traced_through();
  };

  const auto buried_faces = [&](std::span<const Vec3> positions, std::span<const uint32_t> indices) {
    std::vector<char> buried = input_faces_buried(scene, positions, indices);
    for (char b : buried) out.buried_faces += size_t(b);
    return buried;
  };

  if (vertices != InputVertices::as_read) {  // glTF out: every face of the file at once, welded
    const WeldedInput welded = weld_input(scene, baked, /*by_position=*/vertices == InputVertices::split);
    const std::vector<char> buried = buried_faces(welded.positions, welded.indices);
    const SurfaceField field = [&](const Vec3& p, const Vec3& n, size_t face) -> std::optional<Rgb> {
      if (buried[face]) return std::nullopt;
      return value(scene.materials[welded.face_material[face]], p, n);
    };
    rc::util::Progress progress("bake: onto the input",
                                fit == VertexFit::point ? welded.positions.size() : welded.indices.size() / 3,
                                fit == VertexFit::point ? "vertices" : "faces", gather.progress);
    SplitRules rules;
    rules.face_key = welded.face_material;
    Wedges wedges;
    std::vector<Rgb> colours;
    if (vertices == InputVertices::file) {  // one colour per vertex of the file, as its own format holds
      wedges = one_wedge_per_vertex(welded.indices);
      const std::vector<Rgb> per_vertex =
          fit_vertex_colours(welded.positions, welded.indices, field, fit, spacing, &out.stats, &progress);
      for (uint32_t v : wedges.vertex) colours.push_back(per_vertex[v]);
    } else {
      colours = fit_split_colours(welded.positions, welded.indices, field, fit, spacing, rules, wedges, &out.stats,
                                  &progress);
    }
    out.welded_vertices = welded.positions.size();
    // Each scene mesh's own wedges: wedges of the fit at the mesh's vertices (its seams stay:
    // each side keeps its own UVs and normals). Vertex v's first wedge keeps its number, v, and
    // further ones follow the mesh's vertices, so that a mesh nothing splits stays as it was.
    out.per_mesh.resize(scene.meshes.size());
    out.wedges.resize(scene.meshes.size());
    std::vector<std::vector<uint32_t>> first(scene.meshes.size());  // per vertex: the fit's wedge that is v
    std::vector<std::unordered_map<uint64_t, uint32_t>> extra(scene.meshes.size());
    for (size_t c = 0; c < welded.indices.size(); ++c) {
      const auto [m, corner] = welded.corner_origin[c];
      const size_t vertices = scene.meshes[m].positions.size();
      Wedges& mw = out.wedges[m];
      if (mw.of_corner.empty()) {
        mw.of_corner.assign(scene.meshes[m].indices.size(), 0);
        mw.vertex.resize(vertices);
        std::iota(mw.vertex.begin(), mw.vertex.end(), 0u);
        out.per_mesh[m].assign(vertices, Rgb(0.0f));  // vertices no baked face uses stay black
        first[m].assign(vertices, UINT32_MAX);
      }
      const uint32_t v = scene.meshes[m].indices[corner], w = wedges.of_corner[c];
      if (first[m][v] == UINT32_MAX) {
        first[m][v] = w;
        out.per_mesh[m][v] = colours[w];
      }
      if (first[m][v] == w) {
        mw.of_corner[corner] = v;
        continue;
      }
      const auto [it, added] = extra[m].try_emplace((uint64_t(w) << 32) | v, uint32_t(mw.vertex.size()));
      if (added) {
        mw.vertex.push_back(v);
        out.per_mesh[m].push_back(colours[w]);
      }
      mw.of_corner[corner] = it->second;
    }
  } else if (!per_file_vertex) {  // glTF: each primitive instance on its own
    out.per_mesh.resize(scene.meshes.size());
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
      const rc::scene::TriangleMesh& mesh = scene.meshes[m];
      if (!baked(mesh)) continue;
      const rc::scene::Material& material = scene.materials[mesh.material];
      const std::vector<char> buried = buried_faces(mesh.positions, mesh.indices);
      const SurfaceField field = [&](const Vec3& p, const Vec3& n, size_t face) -> std::optional<Rgb> {
        if (buried[face]) return std::nullopt;
        return value(material, p, n);
      };
      rc::util::Progress progress("bake: onto " + mesh.name,
                                  fit == VertexFit::point ? mesh.positions.size() : mesh.triangle_count(),
                                  fit == VertexFit::point ? "vertices" : "faces", gather.progress);
      out.per_mesh[m] =
          fit_vertex_colours(mesh.positions, mesh.indices, field, fit, spacing, &out.stats, &progress);
    }
  } else {  // OBJ, PLY: the file's vertices, shared by the meshes of its materials
    std::vector<Vec3> positions;
    std::vector<uint32_t> indices;
    std::vector<uint32_t> face_material;
    for (const rc::scene::TriangleMesh& mesh : scene.meshes) {
      if (mesh.origin.file != out.file) continue;
      const auto file_vertex = [&mesh](uint32_t v) { return mesh.origin.vertex.empty() ? v : mesh.origin.vertex[v]; };
      for (uint32_t v = 0; v < mesh.positions.size(); ++v) {
        const uint32_t f = file_vertex(v);
        if (f >= positions.size()) positions.resize(size_t(f) + 1, Vec3(0.0f));
        positions[f] = mesh.positions[v];
      }
      if (!baked(mesh)) continue;
      for (size_t t = 0; t < mesh.triangle_count(); ++t) {
        for (int k = 0; k < 3; ++k) indices.push_back(file_vertex(mesh.indices[3 * t + size_t(k)]));
        face_material.push_back(mesh.material);
      }
    }
    const std::vector<char> buried = buried_faces(positions, indices);
    const SurfaceField field = [&](const Vec3& p, const Vec3& n, size_t face) -> std::optional<Rgb> {
      if (buried[face]) return std::nullopt;
      return value(scene.materials[face_material[face]], p, n);
    };
    rc::util::Progress progress("bake: onto the input",
                                fit == VertexFit::point ? positions.size() : indices.size() / 3,
                                fit == VertexFit::point ? "vertices" : "faces", gather.progress);
    out.per_file_vertex = fit_vertex_colours(positions, indices, field, fit, spacing, &out.stats, &progress);
  }
  out.gather = at_input.gather_count();
  out.sides = at_input.sides_count();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

std::vector<float> vertex_disk_radius(const RadiosityMesh& mesh) {
  std::vector<float> radius(mesh.vertex_count(), std::numeric_limits<float>::max());
  for (const auto& e : mesh.elements) {
    const Vec3 centroid = (mesh.positions[e[0]] + mesh.positions[e[1]] + mesh.positions[e[2]]) / 3.0f;
    for (uint32_t v : e) radius[v] = std::min(radius[v], 0.5f * glm::distance(centroid, mesh.positions[v]));
  }
  return radius;
}

std::optional<InputPoint> input_surface_under(const rc::scene::Scene& scene, const RadiosityMesh& mesh,
                                              size_t v, const Vec3& offset, float radius) {
  const Vec3 n = mesh.normals[v];
  const rc::scene::Ray ray{mesh.positions[v] + offset + radius * n, -n, 2.0f * radius};
  const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
  if (!hit || &scene.primitive_material(hit->geom_id, hit->prim_id) != &scene.materials[mesh.vertex_material[v]])
    return std::nullopt;
  rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
  // A vertex of a surface the mesher turned over, or of a twin behind one, faces the input's
  // back: the point is on that side.
  if (!si.front_face) si.ng = -si.ng, si.ns = -si.ns;
  if (glm::dot(si.ng, n) < kSameSideOfCrease) return std::nullopt;
  return InputPoint{ray, si};
}

/// How many points of a vertex's disk gather_at_vertices may draw per sample it takes.
constexpr uint32_t kDiskAttempts = 16;

Solution gather_at_vertices(const rc::scene::Scene& scene, const Solution& solution, BakeGather gather,
                            BakeGatherCount* count) {
  Solution out = solution;
  const RadiosityMesh& mesh = solution.mesh;
  const RadiosityView view(scene, solution, ViewMode::mesh, /*ambient=*/false);
  const std::vector<float> radius = vertex_disk_radius(mesh);
  const int rays = std::max(gather.rays, 1);
  std::atomic<uint64_t> gathered{0}, late{0};
  rc::util::Progress progress("bake: final gather", mesh.vertex_count(), "vertices", gather.progress);
  rc::util::parallel_for(mesh.vertex_count(), [&](size_t v) {
    progress.advance(1);
    if (std::chrono::steady_clock::now() >= gather.deadline) {
      ++late;
      return;
    }
    // The colour stands for the disk around the vertex (vertex_disk_radius), as the check reads
    // it: each ray starts at its own point of the input under the disk. On a scan one point's
    // face normal is a poor sample of the facets the disk holds, and a third of the points
    // under a remeshed vertex lie on facets turned more than 30° from it.
    const rc::Frame frame = rc::Frame::from_normal(mesh.normals[v]);
    rc::render::SampleContext ctx{
        rc::render::Sampler::for_pixel_sample(rc::render::SamplerKind::sobol, gather.seed, v, 0), 0};
    // Points that miss the input under the disk, or land past a crease, are drawn again, up to
    // kDiskAttempts per sample: a vertex at a crease or a silhouette may have a small share of
    // its disk on its side (under 10 % for some of the bunny's), and its N samples would
    // otherwise be a handful.
    const uint32_t attempts = uint32_t(rays) * kDiskAttempts;
    const rc::render::Sampler::SubSamples samples = ctx.sampler.split(attempts);
    Rgb sum(0.0f);
    int taken = 0;
    for (uint32_t j = 0; j < attempts && taken < rays; ++j) {
      rc::render::SampleContext sub{samples[j], 0};
      const rc::Vec2 u = rc::util::sample_uniform_disk(sub.sampler.uniform2()) * radius[v];
      const std::optional<InputPoint> under =
          input_surface_under(scene, mesh, v, frame.to_world(Vec3(u.x, u.y, 0.0f)), radius[v]);
      if (!under) continue;
      sum += view.gathered_sample(mesh_surface_point(under->si.p, under->si.ng), sub);
      ++taken;
    }
    if (taken == 0) return;  // no input surface under it (a corner between creases): the solve's value stays
    ++gathered;
    const Rgb e = sum / float(taken);
    out.vertex_irradiance[v] = e;
    out.vertex_radiosity[v] = scene.materials[mesh.vertex_material[v]].emission * rc::kPi + solution.vertex_albedo[v] * e;
  });
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& el = mesh.elements[e];
    out.element_radiosity[e] =
        (out.vertex_radiosity[el[0]] + out.vertex_radiosity[el[1]] + out.vertex_radiosity[el[2]]) * (1.0f / 3.0f);
  }
  if (count) *count = {gathered.load(), late.load()};
  return out;
}

void check_onto_output(const std::string& path, const rc::scene::Scene& scene) {
  const std::string& input = scene.model_files[size_t(onto_input_file(scene))];
  const std::string in_ext = rc::io::lower_extension(input), out_ext = rc::io::lower_extension(path);
  const bool in_gltf = in_ext == ".gltf" || in_ext == ".glb", out_gltf = out_ext == ".gltf" || out_ext == ".glb";
  std::error_code ec;
  if (fs::equivalent(input, path, ec))
    throw InputError("-o " + path + ": is the input model; --onto input never modifies its input");
  if ((in_gltf && !out_gltf) || (!in_gltf && !out_gltf && in_ext != out_ext))
    throw InputError("-o " + path +
                     ": --onto input writes the input's own format or glTF, and the input is " + input +
                     (in_gltf ? " (use .gltf or .glb)" : " (use " + in_ext + ", .gltf or .glb)"));
  const fs::path folder = fs::absolute(path).parent_path();
  if (!fs::is_directory(folder, ec))
    throw InputError("-o " + path + ": folder " + folder.string() + " does not exist");
}

void write_onto_input(const std::string& path, const rc::scene::Scene& scene, const InputColours& colours,
                      const ExportSettings& settings) {
  check_onto_output(path, scene);
  if (colours.file < 0 || size_t(colours.file) >= scene.model_files.size())
    throw std::logic_error("write_onto_input: no model file");
  const std::string& input = scene.model_files[size_t(colours.file)];
  if (!is_gltf(path) && !colours.wedges.empty())
    throw std::logic_error("write_onto_input: colours fitted for split vertices, written to " + path);
  if (is_gltf(path))
    write_onto_gltf(input, path, scene, colours, settings);
  else if (rc::io::lower_extension(input) == ".obj")
    write_onto_obj(input, path, colours, settings);
  else
    write_onto_ply(input, path, colours, settings);
}

}  // namespace gilt::radiosity::bake

// `gilt info SCENE`: what the scene holds and, for each method, which passes will run and which
// are skipped and why.

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "photonmap/photon_map.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/io/scene_io.h"

namespace gilt::cli {
namespace rc = gilt::raytrace_core;
namespace {

struct InfoOptions {
  std::string scene;
  rc::io::ExtraLighting lighting;
  std::string camera;  ///< --camera N|NAME; empty: the scene's own
  bool json = false;
};

const char* light_kind_name(rc::scene::LightKind k) {
  switch (k) {
    case rc::scene::LightKind::area_triangle: return "area triangles";
    case rc::scene::LightKind::area_sphere: return "area spheres";
    case rc::scene::LightKind::point: return "point";
    case rc::scene::LightKind::spot: return "spot";
    case rc::scene::LightKind::directional: return "directional";
    case rc::scene::LightKind::environment: return "environment";
  }
  return "?";
}

const char* material_kind_name(rc::scene::MaterialKind k) {
  switch (k) {
    case rc::scene::MaterialKind::diffuse: return "diffuse";
    case rc::scene::MaterialKind::glossy: return "glossy";
    case rc::scene::MaterialKind::mirror: return "mirror";
    case rc::scene::MaterialKind::dielectric: return "dielectric";
    case rc::scene::MaterialKind::metallic_roughness: return "metallic-roughness";
  }
  return "?";
}

std::string short_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", x);
  return text;
}

/// One method's plan: passes that run and passes skipped with the reason.
struct MethodPlan {
  std::string method;
  std::vector<std::string> runs, skipped;
};

std::vector<MethodPlan> plan_methods(const rc::scene::Scene& scene) {
  std::vector<MethodPlan> plans;
  const bool lit = !scene.lights().empty();
  // How a shadow ray's light is chosen (raytrace_core/scene/light_sampler.h).
  const rc::scene::LightSampler& sampler = scene.light_sampler();
  const std::string choice =
      sampler.node_count() > 1
          ? "chosen by a light BVH (" + std::to_string(sampler.node_count()) + " nodes, depth " +
                std::to_string(sampler.depth()) + ") by power, distance and orientation"
          : "chosen by power";
  const std::string nee =
      lit ? "next-event estimation over " + std::to_string(scene.lights().size()) + " light(s), " + choice : "";
  plans.push_back({"path", lit ? std::vector<std::string>{"camera paths with " + nee + ", MIS, Russian roulette"}
                               : std::vector<std::string>{"camera paths (the image will be black)"},
                   lit ? std::vector<std::string>{} : std::vector<std::string>{"light sampling: no lights"}});
  plans.push_back({"whitted", {"camera rays, shadow rays to point-sampled lights, mirror and glass recursion"}, {}});

  MethodPlan rad{"radiosity", {}, {}};
  const radiosity::solver::SolvePlan rp = radiosity::solver::plan_solve(scene, radiosity::solver::SolverSettings{});
  rad.runs.push_back("mesh: about " + std::to_string(rp.elements) + " elements, " + std::to_string(rp.vertices) +
                     " vertices (edge " + short_number(rp.max_edge) + "), adaptive subdivision at steep direct light");
  if (!rp.mesh_stage_seconds.empty()) {
    const auto tenths = [](double seconds) {
      char text[32];
      std::snprintf(text, sizeof text, "%.1f", seconds);
      return std::string(text);
    };
    double total = 0.0;
    std::string stages;
    for (const auto& [stage, seconds] : rp.mesh_stage_seconds) {
      total += seconds;
      stages += (stages.empty() ? "" : ", ") + stage + " " + tenths(seconds);
    }
    rad.runs.push_back("meshing took " + tenths(total) + " s on this machine (" + stages + ")");
  }
  rad.runs.push_back(std::string("solver: ") + radiosity::solver::to_string(rp.solver) + " (" + rp.solver_reason + ")");
  if (rp.contact_edges > 0)
    rad.runs.push_back("contact lines imprinted where surfaces touch (" + std::to_string(rp.contact_edges) + " edges)");
  if (rp.buried_faces > 0 || rp.buried_elements > 0)
    rad.skipped.push_back(short_number(100.0 * rp.buried_area / std::max(rp.meshed_area, 1e-300)) + " % of the surface area (" +
                          std::to_string(rp.buried_faces) + " input faces, " + std::to_string(rp.buried_elements) +
                          " elements) buried under or inside other surfaces");
  if (rp.convex_enclosure) rad.skipped.push_back("visibility rays: convex enclosure, nothing can occlude");
  else rad.runs.push_back("visibility rays only where " + std::to_string(rp.occluder_boxes) + " occluder box(es) may block");
  if (rp.punctual_lights > 0)
    rad.runs.push_back(std::to_string(rp.punctual_lights) + " punctual/environment light(s) shot without meshing");
  if (rp.specular_surfaces > 0)
    rad.runs.push_back(std::to_string(rp.specular_surfaces) + " mirror/glass surface(s) left to ray tracing (two-pass view)");
  if (!lit) rad.skipped.push_back("shooting: no lights, the radiosity is zero");
  plans.push_back(rad);

  const photonmap::MapNeeds needs = photonmap::map_needs(scene);
  MethodPlan photon{"photon", {}, {}};
  if (needs.caustic) photon.runs.push_back("caustic map (light, mirror/glass+, diffuse)");
  else photon.skipped.push_back("caustic map: " + needs.caustic_reason);
  if (needs.global) photon.runs.push_back("global map, irradiance precomputed at a site per 4th photon (paths of their own), final gather");
  else photon.skipped.push_back("global map and final gather: " + needs.global_reason);
  if (lit) photon.runs.push_back("direct light by light sampling with MIS against the gather rays");
  plans.push_back(photon);
  MethodPlan sppm{"sppm", {}, {}};
  if (lit) sppm.runs.push_back("per iteration: a visible point per pixel, direct light, photons, radius update");
  else sppm.skipped.push_back("photons: no lights (the image will be black)");
  plans.push_back(sppm);
  return plans;
}

/// Whether `named` is the camera the scene renders with (the file's first, or --camera's choice).
bool is_view(const rc::scene::Scene& scene, const rc::scene::NamedCamera& named) {
  if (!scene.camera) return false;
  const rc::scene::Camera& a = *scene.camera;
  const rc::scene::Camera& b = named.camera;
  return a.look_from == b.look_from && a.look_at == b.look_at && a.up == b.up && a.vfov_degrees == b.vfov_degrees &&
         a.aperture_radius == b.aperture_radius && a.focus_distance == b.focus_distance &&
         a.orthographic == b.orthographic && a.ortho_height == b.ortho_height;
}

/// One camera as info describes it: "perspective, 39.6° vertical" or "orthographic, 4 high".
std::string camera_text(const rc::scene::Camera& c) {
  char text[96];
  if (c.orthographic) std::snprintf(text, sizeof text, "orthographic, %g high", double(c.ortho_height));
  else std::snprintf(text, sizeof text, "perspective, %g degrees vertical", double(c.vfov_degrees));
  return text;
}

/// What info counts in a scene, for the text and the JSON alike.
struct SceneSummary {
  std::map<std::string, size_t> lights, materials;  ///< by kind
  size_t emissive = 0;   ///< materials
  size_t vertices = 0;
  size_t bytes = 0;      ///< geometry and BVH, estimated
  size_t textured = 0, texels = 0, texture_bytes = 0, texture_files = 0, cached_texture_files = 0,
         normal_mapped = 0;
  std::optional<rc::scene::TexturePlan> texture_plan;  ///< none without textures
};

/// Reads the scene's lights, materials, meshes and spheres; writes the summary's counts and
/// memory estimate.
void count_geometry(const rc::scene::Scene& scene, SceneSummary& s) {
  for (const rc::scene::Light& l : scene.lights()) ++s.lights[light_kind_name(l.kind)];
  for (const rc::scene::Material& m : scene.materials) ++s.materials[material_kind_name(m.kind)];
  for (const rc::scene::Material& m : scene.materials) s.emissive += m.is_emissive();
  // Memory: the scene's arrays plus Embree's BVH, estimated at 96 bytes per primitive (nodes
  // and primitive references; an order-of-magnitude figure, not a measurement).
  for (const rc::scene::TriangleMesh& m : scene.meshes) {
    s.vertices += m.positions.size();
    s.bytes += m.positions.size() * sizeof(rc::Vec3) + m.normals.size() * sizeof(rc::Vec3) +
               m.uvs.size() * sizeof(rc::Vec2) + m.tangents.size() * sizeof(glm::vec4) + m.indices.size() * sizeof(uint32_t);
  }
  const size_t bvh = scene.triangle_count() * 96 + scene.spheres.size() * 96;
  s.bytes += bvh + scene.spheres.size() * sizeof(rc::scene::Sphere);
}

/// Reads the scene's materials and texture set; writes the summary's texture counts, plan and
/// memory: the half-float MIP pyramids of the distinct files the materials read (what they take
/// in memory, or would take where the plan is OpenImageIO's cache).
void count_textures(const rc::scene::Scene& scene, SceneSummary& s) {
  s.textured = size_t(std::count_if(scene.materials.begin(), scene.materials.end(),
                                    [](const rc::scene::Material& m) { return m.is_textured(); }));
  if (const rc::scene::TextureSet* set = scene.texture_set()) {
    s.texels = set->texel_count();
    s.texture_bytes = set->pyramid_bytes();
    s.texture_files = set->file_count();
    s.cached_texture_files = set->cached_file_count();
    s.texture_plan = set->plan();
  }
}

/// Reads the scene's materials and the summary; adds to each method's plan what it does with
/// metallic-roughness materials, rough glass, albedo textures and normal maps; writes
/// s.normal_mapped.
void add_material_notes(const rc::scene::Scene& scene, SceneSummary& s, std::vector<MethodPlan>& plans) {
  // What each method does with glTF's metallic-roughness materials.
  const bool metallic_roughness = s.materials.count(material_kind_name(rc::scene::MaterialKind::metallic_roughness)) > 0;
  if (metallic_roughness)
    for (MethodPlan& p : plans) {
      if (p.method == "radiosity")
        p.runs.push_back("metallic-roughness: elements reflect the diffuse part; direct light in the view sees the whole BRDF");
      else if (p.method == "photon" || p.method == "sppm")
        p.runs.push_back("metallic-roughness: photons scatter by the whole BRDF; the final gather reads the diffuse part");
      else
        p.runs.push_back("metallic-roughness: GGX specular over a Lambertian base, sampled by visible normals");
    }
  // And with rough glass.
  if (std::any_of(scene.materials.begin(), scene.materials.end(),
                  [](const rc::scene::Material& m) { return m.is_rough_dielectric(); }))
    for (MethodPlan& p : plans) {
      if (p.method == "radiosity")
        p.runs.push_back("rough glass: not meshed; the view traces through it by sampling its GGX lobes");
      else if (p.method == "photon" || p.method == "sppm")
        p.runs.push_back("rough glass: camera paths and photons pass through by sampling its GGX lobes (caustics)");
      else if (p.method == "whitted")
        p.runs.push_back("rough glass: rendered as smooth glass (delta directions only)");
      else
        p.runs.push_back("rough glass: GGX reflection and refraction, lights sampled through it");
    }
  if (s.textured > 0)
    for (MethodPlan& p : plans) {
      if (p.method == "radiosity")
        p.runs.push_back("albedo textures: each element reflects its texture's mean over it; the view reads texels per pixel");
      else if (p.method == "photon" || p.method == "sppm")
        p.runs.push_back("albedo textures: read where photons land and at the points the camera sees");
      else
        p.runs.push_back("albedo textures: read at every hit (MIP-mapped, trilinear)");
    }
  s.normal_mapped =
      size_t(std::count_if(scene.materials.begin(), scene.materials.end(),
                           [](const rc::scene::Material& m) { return m.normal_texture.valid(); }));
  if (s.normal_mapped > 0)
    for (MethodPlan& p : plans)
      p.runs.push_back(p.method == "radiosity"
                           ? "normal and height maps: the view shades with them; elements keep their flat normals"
                           : "normal and height maps: tilt the shading normal at every hit");
}

/// --json. Reads the scene, the summary and the plans; writes one JSON object to stdout.
void print_info_json(const InfoOptions& o, const rc::scene::Scene& scene, const SceneSummary& s,
                     const std::vector<MethodPlan>& plans) {
  const rc::Bounds3& b = scene.bounds();
  nlohmann::json j = {{"command", "info"},
                      {"scene", o.scene},
                      {"triangles", scene.triangle_count()},
                      {"vertices", s.vertices},
                      {"meshes", scene.meshes.size()},
                      {"spheres", scene.spheres.size()},
                      {"lights", s.lights},
                      {"materials", s.materials},
                      {"emissive_materials", s.emissive},
                      {"bounds", {{"min", {b.lo.x, b.lo.y, b.lo.z}}, {"max", {b.hi.x, b.hi.y, b.hi.z}}}},
                      {"textures",
                       {{"images", scene.textures.size()},
                        {"textured_materials", s.textured},
                        {"normal_mapped_materials", s.normal_mapped},
                        {"files", s.texture_files},
                        {"cached_files", s.cached_texture_files},
                        {"texels", s.texels},
                        {"plan", s.texture_plan ? rc::scene::texture_plan_name(*s.texture_plan) : "none"},
                        {"memory_bytes", s.texture_bytes},
                        {"memory_budget_bytes", rc::scene::texture_memory_budget()}}},
                      {"memory_estimate_bytes", s.bytes}};
  j["cameras"] = nlohmann::json::array();
  for (const rc::scene::NamedCamera& c : scene.cameras)
    j["cameras"].push_back({{"name", c.name}, {"orthographic", c.camera.orthographic},
                            {"vfov_degrees", c.camera.vfov_degrees}, {"height", c.camera.ortho_height},
                            {"aspect", c.aspect}, {"view", is_view(scene, c)}});
  j["view"] = scene.camera ? camera_text(*scene.camera) : "none: the default view of the bounds";
  for (const MethodPlan& p : plans) j["methods"][p.method] = {{"runs", p.runs}, {"skipped", p.skipped}};
  std::cout << j.dump() << std::endl;
}

/// Reads the scene, the summary and the plans; prints them as text.
void print_info_text(const InfoOptions& o, const rc::scene::Scene& scene, const SceneSummary& s,
                     const std::vector<MethodPlan>& plans) {
  const rc::Bounds3& b = scene.bounds();
  std::printf("gilt info: %s\n", o.scene.c_str());
  std::printf("  geometry:  %zu triangles (%zu vertices) in %zu mesh(es), %zu sphere(s)\n", scene.triangle_count(),
              s.vertices, scene.meshes.size(), scene.spheres.size());
  std::printf("  bounds:    (%g, %g, %g) to (%g, %g, %g)\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
  std::printf("  lights:   ");
  if (s.lights.empty()) std::printf(" none");
  for (const auto& [kind, n] : s.lights) std::printf(" %zu %s;", n, kind.c_str());
  std::printf("\n  materials:");
  for (const auto& [kind, n] : s.materials) std::printf(" %zu %s;", n, kind.c_str());
  std::printf(" %zu emissive\n", s.emissive);
  std::printf("  cameras:  ");
  if (scene.cameras.empty()) std::printf(" none (the default view frames the bounds)");
  for (size_t i = 0; i < scene.cameras.size(); ++i)
    std::printf("%s %zu '%s' (%s)%s", i ? ";" : "", i, scene.cameras[i].name.c_str(),
                camera_text(scene.cameras[i].camera).c_str(), is_view(scene, scene.cameras[i]) ? " [the view]" : "");
  std::printf("\n");
  if (!scene.textures.empty()) {
    std::printf(
        "  textures:  %zu image(s) from %zu file(s) read by %zu material(s): %.1f Mtexel channels, %.1f MB "
        "as MIP pyramids\n",
        scene.textures.size(), s.texture_files, s.textured, double(s.texels) / 1e6,
        double(s.texture_bytes) / 1e6);
    // The budget in mebibytes, the unit of GILT_TEXTURE_MEMORY_MB.
    const double budget = double(rc::scene::texture_memory_budget()) / double(1 << 20);
    if (s.texture_plan.value_or(rc::scene::TexturePlan::in_memory) == rc::scene::TexturePlan::in_memory)
      std::printf(
          "  texture plan: in-memory pyramids, within the budget of %.0f MiB (GILT_TEXTURE_MEMORY_MB); %zu "
          "of %zu "
          "read back from the cache folder %s\n",
          budget, s.cached_texture_files, s.texture_files, rc::scene::texture_cache_folder().c_str());
    else
      std::printf(
          "  texture plan: OpenImageIO's cache, paging tiles in and out: the pyramids exceed the budget of "
          "%.0f MiB "
          "(GILT_TEXTURE_MEMORY_MB)\n",
          budget);
  }
  if (s.bytes < 1000000) std::printf("  memory:    about %.1f kB (geometry and BVH, estimated)\n", double(s.bytes) / 1e3);
  else std::printf("  memory:    about %.1f MB (geometry and BVH, estimated)\n", double(s.bytes) / 1e6);
  for (const MethodPlan& p : plans) {
    std::printf("  %s:\n", p.method.c_str());
    for (const std::string& r : p.runs) std::printf("    runs:    %s\n", r.c_str());
    for (const std::string& sk : p.skipped) std::printf("    skipped: %s\n", sk.c_str());
  }
}

/// `gilt info`: load the scene, count what it holds, plan each method, then print.
void run_info(const InfoOptions& o) {
  rc::scene::Scene scene = rc::io::load_scene(o.scene, o.lighting);
  if (!o.camera.empty()) rc::io::select_camera(scene, o.camera);
  for (const std::string& w : scene.warnings) std::cerr << "gilt: warning: " << w << "\n";
  SceneSummary summary;
  count_geometry(scene, summary);
  std::vector<MethodPlan> plans = plan_methods(scene);
  count_textures(scene, summary);
  add_material_notes(scene, summary, plans);
  if (o.json) print_info_json(o, scene, summary, plans);
  else print_info_text(o, scene, summary, plans);
}

}  // namespace

std::function<void()> add_info_command(CLI::App& app) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a scene and what each method will run or skip on it");
  cmd->add_option("scene", o->scene, "Scene file or built-in name")->required();
  cmd->add_flag("--json", o->json, "Print the description as one JSON object");
  add_lighting_options(*cmd, o->lighting);
  add_camera_option(*cmd, o->camera);
  return [o] { run_info(*o); };
}

}  // namespace gilt::cli

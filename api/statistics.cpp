#include "api/statistics.h"

#include <algorithm>

#include "raytrace_core/scene/texture.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"

namespace gilt::api {
namespace rc = gilt::raytrace_core;

nlohmann::json run_statistics(const rc::scene::Scene& scene, const std::string& method, const rc::render::RenderSettings& settings,
                              const MethodResult& result) {
  const rc::render::RenderStats& stats = result.stats;
  const double secs = std::max(stats.seconds, 1e-9);
  nlohmann::json j = {{"method", method},
                      {"width", settings.width},
                      {"height", settings.height},
                      {"spp", stats.spp},
                      {"seed", settings.seed},
                      {"sampler", rc::render::sampler_name(settings.sampler)},
                      {"light_sampler", rc::scene::light_sampling_name(scene.light_sampler().mode())},
                      {"threads", settings.threads > 0 ? settings.threads : rc::util::hardware_threads()},
                      {"ranks", rc::util::processes().count()},
                      {"triangles", scene.triangle_count()},
                      {"spheres", scene.spheres.size()},
                      {"lights", scene.lights().size()},
                      {"rays", stats.rays},
                      {"rays_per_second", double(stats.rays) / secs},
                      {"samples", stats.samples},
                      {"samples_per_second", double(stats.samples) / secs},
                      {"seconds", stats.seconds},
                      {"non_finite_samples", stats.non_finite},
                      {"notes", result.notes}};
  // The scene's textures: how they were held and how long they took to load (not in "seconds").
  const rc::scene::TextureSet* textures = scene.texture_set();
  j["texture_load_seconds"] = textures ? textures->load_seconds() : 0.0;
  if (textures)
    j["textures"] = {{"images", textures->size()},
                     {"files", textures->file_count()},
                     {"cached_files", textures->cached_file_count()},
                     {"plan", rc::scene::texture_plan_name(textures->plan())},
                     {"pyramid_bytes", textures->pyramid_bytes()},
                     {"load_seconds", textures->load_seconds()}};
  if (const auto& solution = result.solution) {
    j["radiosity"] = {{"elements", solution->mesh.element_count()}, {"shots", solution->shots},
                      {"residual", solution->residual}, {"seconds", solution->seconds}};
  }
  if (const auto& ps = result.photon) {
    j["photon"] = {{"global_photons", ps->global_photons},       {"caustic_photons", ps->caustic_photons},
                   {"paths", ps->paths},                         {"irradiance_points", ps->irradiance_points},
                   {"trace_seconds", ps->trace_seconds},         {"precompute_seconds", ps->precompute_seconds},
                   {"max_radius", ps->max_radius},               {"skipped", ps->skipped}};
  }
  if (const auto& sp = result.sppm) {
    j["sppm"] = {{"iterations", sp->iterations},
                 {"photons", sp->photons},
                 {"initial_radius", sp->initial_radius},
                 {"mean_final_radius", sp->mean_final_radius}};
  }
  return j;
}

nlohmann::json solution_statistics(const radiosity::solver::Solution& sol, const radiosity::solver::SolverSettings& settings) {
  const double secs = std::max(sol.seconds, 1e-9);
  nlohmann::json ladder = nlohmann::json::array();
  for (const radiosity::solver::LadderLevel& l : sol.ladder)
    ladder.push_back({{"link_tolerance", l.link_tolerance},
                      {"open_pairs", l.open_pairs},
                      {"links", l.links},
                      {"link_seconds", l.link_seconds},
                      {"iterations", l.iterations},
                      {"finishing_iterations", l.finishing_iterations},
                      {"first_residual", l.first_residual},
                      {"residual", l.residual},
                      {"iterate_seconds", l.iterate_seconds}});
  nlohmann::json mesh_stages = nlohmann::json::object();
  for (const auto& [stage, seconds] : sol.mesh_report.stage_seconds) mesh_stages[stage] = seconds;
  return {{"ranks", rc::util::processes().count()},
          {"elements", sol.mesh.element_count()},
          {"meshed_elements", sol.mesh_report.elements},
          {"vertices", sol.mesh.vertex_count()},
          {"max_edge", sol.mesh_report.max_edge},
          {"refined_elements", sol.refined_elements},
          {"contact_edges", sol.mesh_report.contact_edges},
          {"pieces_not_imprinted", sol.mesh_report.pieces_not_imprinted},
          {"pieces_not_remeshed", sol.mesh_report.pieces_not_remeshed},
          {"turned_elements", sol.mesh_report.turned_elements},
          {"two_sided_elements", sol.mesh_report.two_sided_elements},
          {"buried_faces", sol.mesh_report.buried_faces},
          {"buried_elements", sol.mesh_report.buried_elements},
          {"buried_area", sol.mesh_report.buried_area},
          {"meshed_area", sol.mesh_report.meshed_area},
          {"solver", radiosity::solver::to_string(sol.solver)},
          {"solver_reason", sol.solver_reason},
          {"patches", sol.patches},
          {"nodes", sol.nodes},
          {"links", sol.links},
          {"iterations", sol.iterations},
          {"final_gather", sol.final_gather},
          {"final_gather_note", sol.final_gather_note},
          {"link_tolerance", sol.link_tolerance},
          {"linking_stopped_by_time", sol.linking_stopped},
          {"shots", sol.shots},
          {"element_direct_samples", sol.element_direct_samples},
          {"residual", sol.residual},
          {"tail_added", sol.tail_added},
          {"chebyshev_beta", sol.chebyshev_beta},
          {"ladder", ladder},
          {"tolerance", settings.tolerance},
          {"form_factors", sol.form_factors},
          {"form_factors_per_second", double(sol.form_factors) / secs},
          {"shadow_rays", sol.shadow_rays},
          {"pairs_without_visibility_rays", sol.skipped_pairs},
          {"convex_enclosure", sol.convex_enclosure},
          {"seconds", sol.seconds},
          {"mesh_stage_seconds", mesh_stages},
          {"phase_seconds",
           {{"mesh", sol.mesh_seconds},
            {"direct", sol.direct_seconds},
            {"links", sol.link_seconds},
            {"iterations", sol.iterate_seconds},
            {"final_gather", sol.gather_seconds},
            {"shooting", sol.shoot_seconds}}},
          {"threads", settings.threads > 0 ? settings.threads : rc::util::hardware_threads()}};
}

}  // namespace gilt::api

// `gilt radiosity SCENE -o OUT.ply|.obj|.gltf|.glb`: solve, then export vertex colours.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <nlohmann/json.hpp>

#include "api/statistics.h"
#include "cli/commands.h"
#include "radiosity/solver/budget.h"
#include "radiosity/bake/check.h"
#include "radiosity/bake/export.h"
#include "radiosity/bake/lightmap.h"
#include "radiosity/bake/onto_input.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"
#include "raytrace_core/io/scene_io.h"

namespace gilt::cli {
namespace rc = gilt::raytrace_core;
namespace {

/// Share of --time that a bake's final gather (--bake-gather) keeps from the solve.
constexpr double kBakeGatherShare = 0.4;

struct RadiosityOptions {
  std::string scene, output, quantity = "radiance", onto = "elements", fit = "least-squares", check_points_file;
  radiosity::solver::SolverSettings solver;
  radiosity::bake::CheckSettings check;
  rc::io::ExtraLighting lighting;
  int check_points = 0;  ///< 0: no check
  int lightmap = 0;      ///< 0: no lightmap
  int bake_gather = 0;   ///< final-gather samples per baked point; 0: read the solution
  bool onto_given = false, fit_given = false;
  bool keep_vertices = false;  ///< --keep-vertices
  bool srgb8 = false, linear_float = false, json = false, quiet = false;
  float exposure = 0.0f;
};

void check_mesh_output(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext != ".ply" && ext != ".obj" && ext != ".gltf" && ext != ".glb")
    throw rc::InputError("-o " + path + ": unsupported mesh type (use .ply, .obj, .gltf or .glb)");
  const std::filesystem::path parent = std::filesystem::absolute(path).parent_path();
  if (!std::filesystem::is_directory(parent))
    throw rc::InputError("-o " + path + ": folder " + parent.string() + " does not exist");
}

/// What one `gilt radiosity` run carries from step to step. Each step's first comment says which
/// fields it reads and writes; the scene and the solution are the driver's, passed by reference.
struct RadiosityRun {
  radiosity::bake::ExportSettings ex;
  bool lightmap = false;    ///< --lightmap: bake onto the input model, in its UVs
  bool onto_input = false;  ///< the colours go onto the input model (--onto input or --lightmap)
  std::chrono::steady_clock::time_point start;  ///< before loading: --time covers the whole command
  double time_limit = 0.0;                      ///< --time (0: none), the whole command's
  double export_seconds = 0.0;                  ///< the bake and the write, after the solve
  radiosity::bake::BakeGather gather;
  radiosity::solver::BudgetFit budget_fit;
  radiosity::bake::VertexFit fit = radiosity::bake::VertexFit::least_squares;
  std::optional<radiosity::bake::InputColours> onto;
  radiosity::bake::SnapStats snap;
  std::optional<radiosity::bake::Lightmap> atlas;
  // --onto elements --bake-gather N: the vertices' light traced from the input under them.
  std::optional<radiosity::solver::Solution> vertex_gather;
  radiosity::bake::BakeGatherCount vertex_gather_count;
  double vertex_gather_seconds = 0.0;
  std::optional<radiosity::bake::CheckResult> check;
  std::optional<radiosity::bake::SurfaceCheckResult> surface_check;
  std::optional<radiosity::bake::SurfaceCheckResult> element_surface_check;  ///< --onto elements, beside `check`

  /// The solution written: the vertex gather's where there is one.
  const radiosity::solver::Solution& exported(const radiosity::solver::Solution& sol) const {
    return vertex_gather ? *vertex_gather : sol;
  }
};

/// Reads the options; writes run.ex, run.lightmap, run.onto_input and o.onto (--lightmap implies
/// --onto input). Throws InputError for flags that cannot go together, before anything is loaded.
void validate_radiosity_options(RadiosityOptions& o, RadiosityRun& run) {
  check_mesh_output(o.output);
  radiosity::bake::ExportSettings& ex = run.ex;
  ex.quantity = radiosity::bake::parse_quantity(o.quantity);
  ex.srgb8 = o.srgb8;
  ex.exposure = o.exposure;
  const bool lightmap = run.lightmap = o.lightmap > 0;
  if (lightmap && o.onto_given && o.onto != "input")
    throw rc::InputError("--lightmap bakes onto the input model, in its UVs: it cannot go with --onto " + o.onto);
  if (lightmap && o.fit_given) throw rc::InputError("--fit applies to vertex colours, not to --lightmap's texels");
  if (lightmap) o.onto = "input";
  const bool onto_input = run.onto_input = o.onto == "input";
  ex.linear_float = o.linear_float;
  if (o.srgb8 && (onto_input || std::filesystem::path(o.output).extension() != ".ply"))
    throw rc::InputError("--srgb8 applies to .ply output of --onto elements only");
  const std::string ext = std::filesystem::path(o.output).extension().string();
  if (o.linear_float && (onto_input || (ext != ".ply" && ext != ".obj")))
    throw rc::InputError("--linear-float applies to .ply and .obj output of --onto elements only");
  if (o.linear_float && o.srgb8) throw rc::InputError("--linear-float and --srgb8 ask for opposite colours");
  if (o.fit != "least-squares" && !onto_input) throw rc::InputError("--fit applies to --onto input only");
  if (o.keep_vertices && (!onto_input || lightmap || (ext != ".gltf" && ext != ".glb")))
    throw rc::InputError(
        "--keep-vertices applies to --onto input written as glTF (.gltf or .glb) only: OBJ and PLY "
        "keep the input's vertices anyway");
  if (!o.check_points_file.empty()) {
    if (o.check_points == 0) throw rc::InputError("--check-points writes the points of --check N: give --check too");
    const std::filesystem::path parent = std::filesystem::absolute(o.check_points_file).parent_path();
    if (!std::filesystem::is_directory(parent))
      throw rc::InputError("--check-points " + o.check_points_file + ": folder " + parent.string() + " does not exist");
  }
}

/// Reads o.scene, o.lighting, o.output, o.lightmap, run.lightmap and run.onto_input; writes
/// run.start (the clock --time runs on) and returns the scene, its warnings printed and the
/// output checked against it (a lightmap's layout before the solve, not after it).
rc::scene::Scene load_radiosity_scene(const RadiosityOptions& o, RadiosityRun& run) {
  run.start = std::chrono::steady_clock::now();
  rc::scene::Scene scene = rc::io::load_scene(o.scene, o.lighting);
  for (const std::string& w : scene.warnings) std::cerr << "gilt: warning: " << w << "\n";
  if (run.lightmap) {
    radiosity::bake::check_lightmap_output(o.output, scene);
    radiosity::bake::check_lightmap_layout(scene, o.lightmap);  // before the solve, not after it
  } else if (run.onto_input)
    radiosity::bake::check_onto_output(o.output, scene);
  return scene;
}

/// Reads the scene, o.quiet, o.json, o.bake_gather, o.output, o.lightmap, o.solver, run.onto_input
/// and run.start; writes o.solver.progress, o.solver.time_limit (what is left of --time for the
/// solve), the time it keeps back for the export (o.solver.after_seconds and
/// after_seconds_per_element), run.time_limit and run.gather (its deadline).
void plan_radiosity_budget(const rc::scene::Scene& scene, RadiosityOptions& o, RadiosityRun& run) {
  o.solver.progress = !o.quiet && !o.json;
  radiosity::bake::BakeGather& gather = run.gather;
  gather = radiosity::bake::BakeGather{o.bake_gather, o.solver.seed};
  gather.progress = o.solver.progress;
  run.ex.progress = o.solver.progress;
  const auto start = run.start;
  // --time covers the whole command: loading has used some of it. A final gather of the bake
  // takes what the solve leaves of kBakeGatherShare of it; points it cannot reach in time read
  // the solution.
  if (o.solver.time_limit > 0.0) {
    const double left = o.solver.time_limit - std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    gather.deadline = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(o.solver.time_limit));
    run.time_limit = o.solver.time_limit;
    o.solver.time_limit = std::max(1e-3, o.bake_gather > 0 ? (1.0 - kBakeGatherShare) * left : left);
    // The write is foretold, from the final mesh's size for the elements and from the input's
    // for a bake onto it, and kept back from the solve. With --bake-gather the bake's share and
    // deadline above take its place.
    const radiosity::bake::WriteForecast write =
        o.bake_gather > 0 ? radiosity::bake::WriteForecast{}
        : run.onto_input  ? radiosity::bake::onto_input_forecast(scene.triangle_count(), o.lightmap)
                          : radiosity::bake::write_forecast(o.output);
    o.solver.after_seconds = write.seconds;
    o.solver.after_seconds_per_element = write.seconds_per_element;
  }
}

/// Reads the scene and o.solver; writes run.budget_fit and returns the solution. Under a budget a
/// mesh left to gilt is sized to fit it (radiosity/solver/budget.h).
radiosity::solver::Solution solve_radiosity(const rc::scene::Scene& scene, const RadiosityOptions& o, RadiosityRun& run) {
  return o.solver.time_limit > 0.0 ? radiosity::solver::solve_within(scene, o.solver, o.solver.time_limit, &run.budget_fit)
                                   : radiosity::solver::solve(scene, o.solver);
}

/// Reads the solution's mesh warnings, run.budget_fit and o.json; writes them to stderr.
void print_solve_warnings(const radiosity::solver::Solution& sol, const RadiosityOptions& o, const RadiosityRun& run) {
  for (const std::string& w : sol.mesh_report.warnings) std::cerr << "gilt: warning: " << w << "\n";
  if (!run.budget_fit.note.empty() && !o.json) std::cerr << "gilt: " << run.budget_fit.note << "\n";
}

/// Reads the scene, the solution, the options and run.ex, run.gather; writes run.fit and the
/// output file, with run.atlas (--lightmap), run.onto (--onto input) or run.snap and the vertex
/// gather (--onto elements).
void export_radiosity(const rc::scene::Scene& scene, const radiosity::solver::Solution& sol, const RadiosityOptions& o,
                      RadiosityRun& run) {
  const radiosity::bake::ExportSettings& ex = run.ex;
  run.fit = o.fit == "point" ? radiosity::bake::VertexFit::point : radiosity::bake::VertexFit::least_squares;
  if (run.lightmap) {
    run.atlas = radiosity::bake::bake_lightmap(scene, sol, ex.quantity, o.lightmap, run.gather);
    radiosity::bake::write_lightmap(o.output, scene, *run.atlas, ex);
  } else if (run.onto_input) {
    run.onto =
        radiosity::bake::fit_input_colours(scene, sol, run.fit, ex.quantity, run.gather,
                                           radiosity::bake::input_vertices(o.output, scene, o.keep_vertices));
    radiosity::bake::write_onto_input(o.output, scene, *run.onto, ex);
  } else {
    if (o.bake_gather > 0) {
      // The gather ends where the write, foretold on the solution's mesh, still fits.
      if (run.time_limit > 0.0)
        run.gather.deadline -= std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(
            radiosity::bake::write_forecast(o.output).at(sol.mesh.element_count())));
      const auto gather_start = std::chrono::steady_clock::now();
      run.vertex_gather.emplace(radiosity::bake::gather_at_vertices(scene, sol, run.gather, &run.vertex_gather_count));
      run.vertex_gather_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - gather_start).count();
    }
    radiosity::bake::write_solution(o.output, scene, run.exported(sol), ex, &run.snap);
  }
}

/// --check N. Reads the scene, the solution, the options and what the export left in run; writes
/// o.check (points and seed), run.gather's deadline (none: the check gathers every point),
/// run.check, run.surface_check or run.element_surface_check, and the --check-points file.
void check_radiosity(const rc::scene::Scene& scene, const radiosity::solver::Solution& sol,
                     RadiosityOptions& o, RadiosityRun& run) {
  if (o.check_points <= 0) return;
  const radiosity::bake::ExportSettings& ex = run.ex;
  o.check.points = o.check_points;
  o.check.seed = o.solver.seed;
  const rc::util::ThreadLimit limit(o.solver.threads);
  // The check's own irradiance bake gathers every point, past any deadline.
  run.gather.deadline = std::chrono::steady_clock::time_point::max();
  // Each point is compared on the side of its face the bake read there.
  std::optional<radiosity::bake::SolutionAtInput> reader;
  radiosity::bake::BakedSide side;
  if (run.lightmap || run.onto_input) {
    reader.emplace(scene, sol, radiosity::bake::Quantity::irradiance);
    side = [&reader](const rc::Vec3& p, const rc::Vec3& n) { return reader->side(p, n); };
  }
  if (run.lightmap) {
    const radiosity::bake::Lightmap e = ex.quantity == radiosity::bake::Quantity::irradiance
                                      ? *run.atlas
                                      : radiosity::bake::bake_lightmap(scene, sol, radiosity::bake::Quantity::irradiance, o.lightmap, run.gather);
    run.surface_check = radiosity::bake::check_lightmap(scene, e, o.check, side);
  } else if (run.onto_input) {
    // The colours as irradiance, at random points inside the input's faces.
    const radiosity::bake::InputColours e =
        ex.quantity == radiosity::bake::Quantity::irradiance
            ? *run.onto
            : radiosity::bake::fit_input_colours(
                  scene, sol, run.fit, radiosity::bake::Quantity::irradiance, run.gather,
                  radiosity::bake::input_vertices(o.output, scene, o.keep_vertices));
    run.surface_check = radiosity::bake::check_input_colours(scene, e, o.check, side);
  } else {
    run.check = radiosity::bake::check_against_path_tracer(scene, run.exported(sol), o.check);
    // And at random points inside the input's faces, read from the elements as written: the
    // mesh write_solution exports (snapped, coincident faces dropped), in irradiance.
    const radiosity::solver::Solution& e = run.exported(sol);
    const radiosity::mesh::RadiosityMesh written = radiosity::bake::without_coincident(
        radiosity::bake::snapped_to_input(scene, e.mesh, 0.5f * e.mesh_report.max_edge));
    run.element_surface_check = radiosity::bake::check_element_colours(scene, written, e.vertex_irradiance, o.check);
  }
  if (run.surface_check && !o.check_points_file.empty())
    radiosity::bake::write_check_points(o.check_points_file, scene, *run.surface_check);
  if (run.check && !o.check_points_file.empty()) radiosity::bake::write_check_points(o.check_points_file, *run.check);
}

/// Reads the solution, the options and run's bakes; adds the JSON sections of the fit, the vertex
/// gather and the lightmap, those that ran.
void add_bake_json(nlohmann::json& j, const radiosity::solver::Solution& sol, const RadiosityOptions& o,
                   const RadiosityRun& run) {
  if (run.onto)
    j["fit"] = {
        {"method", o.fit},
        {"samples", run.onto->stats.samples},
        {"samples_without_solution", run.onto->stats.missing},
        {"buried_faces_left_out", run.onto->buried_faces},
        {"iterations", run.onto->stats.iterations},
        {"gather_rays", o.bake_gather},
        {"gathered_samples", run.onto->gather.gathered},
        {"samples_read_after_deadline", run.onto->gather.late},
        {"samples_from_the_back", run.onto->sides.back},
        {"samples_whose_sides_differ", run.onto->sides.differ},
        {"vertices", {{"fitted", run.onto->welded_vertices}, {"written", run.onto->written_vertices()}}},
        {"seconds", run.onto->seconds}};
  if (run.vertex_gather)
    j["vertex_gather"] = {{"gather_rays", o.bake_gather},
                          {"gathered_vertices", run.vertex_gather_count.gathered},
                          {"vertices_read_after_deadline", run.vertex_gather_count.late},
                          {"vertices", sol.mesh.vertex_count()},
                          {"seconds", run.vertex_gather_seconds}};
  if (const auto& atlas = run.atlas)
    j["lightmap"] = {{"size", atlas->size},
                     {"image", radiosity::bake::lightmap_image_path(o.output)},
                     {"uvs", atlas->stats.uv_source},
                     {"uv_set", atlas->stats.uv_set},
                     {"charts", atlas->stats.charts},
                     {"faces", atlas->stats.faces},
                     {"buried_faces_left_out", atlas->stats.buried_faces},
                     {"texels", atlas->stats.texels},
                     {"texels_per_unit", atlas->stats.texels_per_metre},
                     {"gather_rays", o.bake_gather},
                     {"gathered_points", atlas->stats.gather.gathered},
                     {"points_read_after_deadline", atlas->stats.gather.late},
                     {"points_from_the_back", atlas->stats.sides.back},
                     {"points_whose_sides_differ", atlas->stats.sides.differ},
                     {"layout_seconds", atlas->stats.layout_seconds},
                     {"bake_seconds", atlas->stats.bake_seconds}};
}

/// Reads o.check and run's check results; adds the JSON sections of the checks that ran.
void add_check_json(nlohmann::json& j, const RadiosityOptions& o, const RadiosityRun& run) {
  if (const auto& surface_check = run.surface_check)
    j["check"] = {{"points", surface_check->points},
                  {"samples", o.check.samples},
                  {"where", "random points inside the input's faces"},
                  {"unlit_points_left_out", surface_check->unlit},
                  {"relative_mse", surface_check->relative_mse},
                  {"reference_share", surface_check->reference_share},
                  {"mean_relative_error", surface_check->mean_relative_error},
                  {"mean_ratio", surface_check->mean_ratio},
                  {"seconds", surface_check->seconds}};
  if (const auto& check = run.check)
    j["check"] = {{"points", check->points},
                  {"samples", o.check.samples},
                  {"mean_relative_error", check->mean_relative_error},
                  {"relative_mean_absolute_error", check->relative_mean_absolute_error},
                  {"reference_noise", check->reference_noise},
                  {"seconds", check->seconds}};
  if (const auto& element_surface_check = run.element_surface_check)
    j["surface_check"] = {
        {"points", element_surface_check->points},
        {"samples", o.check.samples},
        {"where", "random points inside the input's faces, read from the exported elements"},
        {"covered", element_surface_check->covered},
        {"uncovered", element_surface_check->uncovered},
        {"covered_share", element_surface_check->covered_share()},
        {"unlit_points_left_out", element_surface_check->unlit},
        {"relative_mse", element_surface_check->relative_mse},
        {"reference_share", element_surface_check->reference_share},
        {"mean_relative_error", element_surface_check->mean_relative_error},
        {"mean_ratio", element_surface_check->mean_ratio},
        {"seconds", element_surface_check->seconds}};
}

/// --json. Reads the solution, the options and run; writes one JSON object to stdout.
void report_radiosity_json(const radiosity::solver::Solution& sol, const RadiosityOptions& o, const RadiosityRun& run) {
  const radiosity::bake::SnapStats& snap = run.snap;
  nlohmann::json j = api::solution_statistics(sol, o.solver);
  j.update(nlohmann::json{{"command", "radiosity"},
                          {"scene", o.scene},
                          {"quantity", o.quantity},
                          {"onto", o.onto},
                          {"vertices_moved_onto_input_far", snap.moved_far},
                          {"vertices_left_off_input", snap.not_moved},
                          {"largest_move_onto_input", snap.largest},
                          {"coincident_faces_merged", snap.coincident_merged},
                          {"coincident_back_to_back_pairs", snap.back_to_back},
                          {"output", o.output},
                          {"export_seconds", run.export_seconds},
                          {"export_seconds_kept_back", sol.seconds_kept_back}});
  add_bake_json(j, sol, o, run);
  add_check_json(j, o, run);
  std::cout << j.dump() << std::endl;
}

/// Reads the solution and o.solver; prints its mesh, solve, ladder, work and time lines.
void print_solve_report(const radiosity::solver::Solution& sol, const RadiosityOptions& o) {
  const double secs = std::max(sol.seconds, 1e-9);
  const int threads = o.solver.threads > 0 ? o.solver.threads : rc::util::hardware_threads();
  std::printf("gilt radiosity: %s, %d thread(s)\n", o.scene.c_str(), threads);
  std::printf("  mesh:    %zu elements (%zu as meshed), %zu vertices, target edge %.4g, %zu elements bisected at steep "
              "direct light\n",
              sol.mesh.element_count(), sol.mesh_report.elements, sol.mesh.vertex_count(), sol.mesh_report.max_edge,
              sol.refined_elements);
  if (sol.mesh_report.turned_elements > 0 || sol.mesh_report.two_sided_elements > 0)
    std::printf(
        "  sides:   %zu elements turned over (light reaches only their back), %zu given a twin facing the "
        "other way (light reaches both sides)\n",
        sol.mesh_report.turned_elements, sol.mesh_report.two_sided_elements);
  if (sol.mesh_report.contact_edges > 0 || sol.mesh_report.buried_area > 0.0)
    std::printf("  contact: %zu edges imprinted where surfaces touch; %.3g %% of the area buried under or inside "
                "other surfaces, removed (%zu input faces, %zu elements)\n",
                sol.mesh_report.contact_edges,
                100.0 * sol.mesh_report.buried_area / std::max(sol.mesh_report.meshed_area, 1e-300),
                sol.mesh_report.buried_faces, sol.mesh_report.buried_elements);
  char chebyshev[48] = "";
  if (sol.chebyshev_beta > 0.0) std::snprintf(chebyshev, sizeof chebyshev, " (Chebyshev, beta %.3g)", sol.chebyshev_beta);
  if (sol.solver == radiosity::solver::SolverKind::hierarchical)
    std::printf("  solve:   hierarchical (%s): %zu nodes, %zu links at tolerance %.3g%s, %d iterations%s, residual %.3g "
                "(tolerance %.3g%s), final gather %s (%.3g nodes per vertex)\n",
                sol.solver_reason.c_str(), sol.nodes, sol.links, sol.link_tolerance,
                sol.linking_stopped ? (sol.links > 0 ? " (finer linking stopped by --time)" : " (linking stopped by --time)") : "",
                sol.iterations, chebyshev, sol.residual,
                o.solver.tolerance, sol.tail_added ? "; the geometric tail added" : "", sol.final_gather_note.c_str(),
                double(sol.gather_nodes) / double(std::max<size_t>(1, sol.mesh.vertex_count())));
  if (sol.shot_without_links)
    std::printf("  solve:   no links fitted in the time: the reflected light shot progressively instead, %llu shots "
                "of %zu patches, residual %.3g\n",
                static_cast<unsigned long long>(sol.shots), sol.patches, sol.residual);
  if (sol.solver != radiosity::solver::SolverKind::hierarchical)
    std::printf("  solve:   progressive (%s): %llu shots, residual %.3g (tolerance %.3g)\n", sol.solver_reason.c_str(),
                static_cast<unsigned long long>(sol.shots), sol.residual, o.solver.tolerance);
  // A timed solve's ladder, level by level, when it had more than one.
  if (sol.ladder.size() > 1 || (sol.ladder.size() == 1 && sol.linking_stopped))
    for (const radiosity::solver::LadderLevel& l : sol.ladder)
      std::printf("  ladder:  tolerance %.3g: %zu links (%zu of %zu open pairs split) in %.3g s; %d iterations%s to "
                  "residual %.3g in %.3g s\n",
                  l.link_tolerance, l.links, l.splits, l.open_pairs, l.link_seconds, l.iterations + l.finishing_iterations,
                  l.finishing_iterations > 0 ? (" (" + std::to_string(l.finishing_iterations) + " finishing)").c_str() : "",
                  l.residual, l.iterate_seconds);
  std::printf("  work:    %llu form factors (%.3g/s), %llu shadow rays%s\n",
              static_cast<unsigned long long>(sol.form_factors), double(sol.form_factors) / secs,
              static_cast<unsigned long long>(sol.shadow_rays),
              sol.convex_enclosure ? " (convex enclosure: visibility rays skipped)" : "");
  char shooting[48] = "";
  if (sol.shot_without_links) std::snprintf(shooting, sizeof shooting, ", shooting %.3g", sol.shoot_seconds);
  if (sol.solver == radiosity::solver::SolverKind::hierarchical)
    std::printf("  time:    %.3f s (mesh %.3g, direct %.3g, links %.3g, iterations %.3g, final gather %.3g%s)\n",
                sol.seconds, sol.mesh_seconds, sol.direct_seconds, sol.link_seconds, sol.iterate_seconds,
                sol.gather_seconds, shooting);
  else
    std::printf("  time:    %.3f s (mesh %.3g, direct %.3g, shooting %.3g)\n", sol.seconds, sol.mesh_seconds,
                sol.direct_seconds, sol.shoot_seconds);
  if (sol.mesh_seconds >= 1.0) {
    std::printf("  mesh:    ");
    const auto& stages = sol.mesh_report.stage_seconds;
    for (size_t i = 0; i < stages.size(); ++i)
      std::printf("%s%s %.3g s", i ? ", " : "", stages[i].first.c_str(), stages[i].second);
    std::printf("\n");
  }
}

// The check inverts L = ρ E / π, which holds on Lambertian surfaces only: say so rather than
// print errors of nothing.
constexpr const char* kNothingChecked =
    "  check:   nothing compared: no %s could be checked; the check reads irradiance only on diffuse "
    "materials with albedo above zero in every channel (glossy and metallic-roughness surfaces are not "
    "checked yet)\n";

/// Reads o.check and run.check, run.element_surface_check (--onto elements); prints their lines.
void print_element_checks(const RadiosityOptions& o, const RadiosityRun& run) {
  const auto& check = run.check;
  if (check && check->points == 0)
    std::printf(kNothingChecked, "vertex");
  else if (check)
    std::printf("  check:   irradiance at %zu vertices against the path tracer (%d samples each): mean relative "
                "error %.3g %%, relative mean absolute error %.3g %%, reference noise %.3g %% (%.2f s)\n",
                check->points, o.check.samples, 100.0 * check->mean_relative_error,
                100.0 * check->relative_mean_absolute_error, 100.0 * check->reference_noise, check->seconds);
  if (run.element_surface_check) {
    const radiosity::bake::SurfaceCheckResult& e = *run.element_surface_check;
    if (e.points + e.unlit + e.uncovered == 0)
      std::printf("  check:   nothing compared at points inside the input's faces: none could be drawn and "
                  "seen (spheres, mirrors and glass are not drawn from; points with something lying on them are "
                  "left out)\n");
    else
      std::printf(
          "  check:   irradiance at %zu random points inside the input's faces, read from the exported "
          "elements, against the path tracer (%d samples each; %zu points no light reaches left out): "
          "relMSE %.4g (of which the reference's own noise %.4g), mean relative error %.3g %%, mean ratio "
          "%.4g, covered %.4g %% of points (%zu of %zu) (%.2f s)\n",
          e.points, o.check.samples, e.unlit, e.relative_mse, e.reference_share,
          100.0 * e.mean_relative_error, e.mean_ratio, 100.0 * e.covered_share(), e.covered,
          e.covered + e.uncovered, e.seconds);
  }
}

/// Reads --bake-gather and one bake's count; prints its gather line (none without a gather).
void print_bake_gather(const radiosity::bake::BakeGatherCount& g, int bake_gather) {
  if (bake_gather == 0) return;
  std::printf("  gather:  %d shadow and gather rays at each of %llu points", bake_gather,
              static_cast<unsigned long long>(g.gathered));
  if (g.late > 0)
    std::printf("; %llu points past --time read the solution instead", static_cast<unsigned long long>(g.late));
  std::printf("\n");
}

/// Warns, on stderr, when many of a bake's points lie on surfaces whose two sides take
/// different light: one colour per point can carry one side only.
void warn_sides(const radiosity::bake::BakeSides& s, const char* bake) {
  if (s.points == 0 || double(s.differ) < 0.01 * double(s.points)) return;
  std::fprintf(
      stderr,
      "gilt: warning: %s: %.3g %% of the baked points lie on surfaces lit on both sides, by irradiances "
      "more than %g times apart; a point carries the light of its face's front (the side its winding "
      "faces), so their backs show it too (--onto elements exports both sides)\n",
      bake, 100.0 * double(s.differ) / double(s.points), double(radiosity::bake::kSidesDiffer));
}

/// Reads the solution, the options and run's bakes and input-face check; prints the vertex
/// gather, onto, lightmap and check lines, and what was written.
void print_bake_report(const radiosity::solver::Solution& sol, const RadiosityOptions& o, const RadiosityRun& run) {
  const auto& onto = run.onto;
  const auto& atlas = run.atlas;
  const auto& surface_check = run.surface_check;
  if (run.vertex_gather)
    std::printf("  gather:  %llu of %zu vertices traced from the input surface under them, %d rays each (%llu read "
                "from the solution after the deadline), %.3g s\n",
                static_cast<unsigned long long>(run.vertex_gather_count.gathered), sol.mesh.vertex_count(),
                o.bake_gather, static_cast<unsigned long long>(run.vertex_gather_count.late),
                run.vertex_gather_seconds);
  if (onto)
    std::printf("  onto:    %s fit to the input's vertices: %llu samples (%llu without a solution; %zu buried "
                "faces left out), %.3g s\n",
                o.fit.c_str(), static_cast<unsigned long long>(onto->stats.samples),
                static_cast<unsigned long long>(onto->stats.missing), onto->buried_faces, onto->seconds);
  if (onto && !onto->wedges.empty())
    std::printf("           %zu %s, written as %zu vertices%s\n", onto->welded_vertices,
                o.keep_vertices ? "vertices in the file" : "positions welded", onto->written_vertices(),
                o.keep_vertices ? "" : ", split at creases, materials and shadow lines along edges");
  if (atlas)
    std::printf("  lightmap: %d x %d over %zu faces (%zu buried left out), %zu texels (%.3g %%); layout %.3g s, "
                "bake %.3g s\n            UVs: %s",
                atlas->size, atlas->size, atlas->stats.faces, atlas->stats.buried_faces, atlas->stats.texels,
                100.0 * double(atlas->stats.texels) / (double(atlas->size) * atlas->size),
                atlas->stats.layout_seconds, atlas->stats.bake_seconds, atlas->stats.uv_source.c_str());
  if (onto) print_bake_gather(onto->gather, o.bake_gather);
  if (onto) warn_sides(onto->sides, "--onto input");
  if (atlas && atlas->stats.uv_set < 0)
    std::printf(", %zu charts at %.4g texels per unit", atlas->stats.charts, atlas->stats.texels_per_metre);
  if (atlas) std::printf("\n            wrote %s\n", radiosity::bake::lightmap_image_path(o.output).c_str());
  if (atlas) print_bake_gather(atlas->stats.gather, o.bake_gather);
  if (atlas) warn_sides(atlas->stats.sides, "--lightmap");
  if (surface_check && surface_check->points == 0 && surface_check->unlit == 0)
    std::printf(kNothingChecked, "sampled point");
  else if (surface_check)
    std::printf(
        "  check:   irradiance at %zu random points inside the input's faces against the path tracer (%d "
        "samples each; %zu points no light reaches left out): relMSE %.4g (of which the reference's own "
        "noise %.4g), mean relative error %.3g %%, mean ratio %.4g (%.2f s)\n",
        surface_check->points, o.check.samples, surface_check->unlit, surface_check->relative_mse,
        surface_check->reference_share, 100.0 * surface_check->mean_relative_error, surface_check->mean_ratio,
        surface_check->seconds);
  std::printf("  wrote %s (%s)\n", o.output.c_str(), o.quantity.c_str());
}

/// `gilt radiosity`: validate the options, load the scene, plan the budget, solve, then (rank 0)
/// export, check and report.
void run_radiosity(RadiosityOptions& o) {
  RadiosityRun run;
  validate_radiosity_options(o, run);
  const rc::scene::Scene scene = load_radiosity_scene(o, run);
  plan_radiosity_budget(scene, o, run);
  const radiosity::solver::Solution sol = solve_radiosity(scene, o, run);
  // Under mpirun every rank took part in the solve; the bake, the export and the check are rank 0's.
  if (rc::util::processes().rank() > 0) return;
  print_solve_warnings(sol, o, run);
  const auto export_start = std::chrono::steady_clock::now();
  export_radiosity(scene, sol, o, run);
  run.export_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - export_start).count();
  check_radiosity(scene, sol, o, run);
  if (o.json) {
    report_radiosity_json(sol, o, run);
    return;
  }
  print_solve_report(sol, o);
  print_element_checks(o, run);
  print_bake_report(sol, o, run);
}

}  // namespace

void add_solver_options(CLI::App& cmd, radiosity::solver::SolverSettings& s) {
  auto* edge = cmd.add_option("--max-edge", s.mesh.max_edge, "Radiosity: target element edge length (scene units)")
                   ->check(CLI::PositiveNumber)
                   ->check(finite_number());
  cmd.add_option("--elements", s.mesh.elements, "Radiosity: approximate element count (default " +
                                                    std::to_string(radiosity::mesh::kDefaultElements) + ")")
      ->check(CLI::Range(1, 50000000))
      ->excludes(edge);
  cmd.add_flag_callback(
      "--one-sided", [&s] { s.mesh.two_sided = false; },
      "Radiosity: elements receive and send light on the side the input's faces are wound to face only "
      "(default: on every side light reaches, as the path tracer sees a diffuse surface)");
  cmd.add_option("--tolerance", s.tolerance, "Radiosity: stop when unshot power < T x emitted power (default 1e-3)")
      ->check(CLI::Range(1e-12, 1.0))
      ->check(finite_number());
  cmd.add_option("--subdivision-levels", s.subdivision_levels,
                 "Radiosity: adaptive subdivision may halve the edge length this many times (default 2; 0 = off)")
      ->check(CLI::Range(0, 8));
  cmd.add_option("--subdivision-threshold", s.subdivision_threshold,
                 "Radiosity: bisect elements whose direct light spreads by more than this fraction (default 0.6)")
      ->check(CLI::Range(1e-3, 1.0))
      ->check(finite_number());
  cmd.add_option_function<std::string>(
         "--solver",
         [&s](const std::string& name) {
           s.solver = name == "progressive"    ? radiosity::solver::SolverKind::progressive
                      : name == "hierarchical" ? radiosity::solver::SolverKind::hierarchical
                                               : radiosity::solver::SolverKind::automatic;
         },
         "Radiosity: progressive, hierarchical, or auto (hierarchical from " +
             std::to_string(radiosity::solver::kHierarchicalElements) + " elements; default)")
      ->check(CLI::IsMember({"auto", "progressive", "hierarchical"}));
  cmd.add_option("--link-tolerance", s.hierarchical.link_tolerance,
                 "Hierarchical radiosity: accept a link when the power it may carry wrongly is below this fraction "
                 "of the reflected power (default 2e-6; 2e-5 for gilt render's two-pass radiosity view)")
      ->check(CLI::Range(1e-12, 1.0))
      ->check(finite_number());
  cmd.add_option_function<std::string>(
         "--final-gather",
         [&s](const std::string& name) {
           s.hierarchical.final_gather = name == "on"    ? radiosity::solver::FinalGather::always
                                         : name == "off" ? radiosity::solver::FinalGather::never
                                                         : radiosity::solver::FinalGather::automatic;
         },
         "Hierarchical radiosity: gather at every vertex from the hierarchy at the end: on, off, or auto (default: "
         "when a probe at every 61st vertex or more predicts at most 4x the links' shadow rays, and under --time when "
         "it fits)")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  cmd.add_option("--gather-tolerance", s.hierarchical.gather_tolerance,
                 "Hierarchical radiosity: a cluster stands in for its elements in the vertex final gather when the "
                 "irradiance it may carry wrongly is below this fraction of the vertex's own (default 0.02)")
      ->check(CLI::Range(1e-6, 1.0))
      ->check(finite_number());
}

std::function<void()> add_radiosity_command(CLI::App& app) {
  auto o = std::make_shared<RadiosityOptions>();
  CLI::App* cmd = app.add_subcommand("radiosity", "Solve radiosity and export the mesh with vertex colours");
  cmd->add_option("scene", o->scene, "Scene file or built-in name")->required();
  cmd->add_option("-o,--output", o->output, "Output mesh (.ply, .obj, .gltf, .glb)")->required();
  add_solver_options(*cmd, o->solver);
  add_lighting_options(*cmd, o->lighting);
  cmd->add_option("--time", o->solver.time_limit, "Stop after this many seconds")
      ->check(CLI::PositiveNumber)
      ->check(finite_number());
  cmd->add_option("--quantity", o->quantity, "Vertex colour: radiance (default), irradiance or radiosity")
      ->check(CLI::IsMember({"radiance", "irradiance", "radiosity"}));
  cmd->add_option("--lightmap", o->lightmap,
                  "Bake the solution into a SIZE x SIZE half-float EXR atlas in a UV set laid out for it, and write "
                  "the input model as glTF with that UV set (implies --onto input)")
      ->check(CLI::Range(16, 16384));
  CLI::Option* onto = cmd->add_option("--onto", o->onto,
                  "elements: export gilt's element mesh (default); input: the input model file itself, with "
                  "vertex colours added (glTF/GLB)")
      ->check(CLI::IsMember({"elements", "input"}));
  CLI::Option* fit = cmd->add_option("--fit", o->fit,
                  "With --onto input: least-squares (default) fits the colours to the solution over each face; "
                  "point takes the solution at each vertex")
      ->check(CLI::IsMember({"least-squares", "point"}));
  cmd->add_flag(
      "--keep-vertices", o->keep_vertices,
      "With --onto input written as glTF: one colour per vertex of the input (per position of an OBJ "
      "or PLY input), instead of splitting vertices where the light jumps across an edge (creases, "
      "materials, shadow lines along edges)");
  cmd->add_option("--bake-gather", o->bake_gather,
                  "A final gather. Each baked point (with --onto input or --lightmap) or exported vertex (--onto "
                  "elements, at the input surface under it) takes its light from N shadow rays and N gather rays "
                  "that read the solution where they land, rather than from the solution there: no light leaks "
                  "across walls and roof lines the elements straddle, and a remeshed scan's vertices see the "
                  "input's own shape, at the cost of noise (default 0 = off). Under --time the solve keeps 60 % of "
                  "the budget")
      ->check(CLI::Range(0, 1 << 20));
  cmd->add_flag("--srgb8", o->srgb8,
                "PLY: only the 8-bit sRGB colours, without the float <quantity>_red/_green/_blue beside them");
  cmd->add_flag("--linear-float", o->linear_float,
                "PLY and OBJ: the quantity itself as linear float colours, unclamped, instead of display colours "
                "(what gilt wrote before; viewers show them wrongly)");
  cmd->add_option("--exposure", o->exposure,
                  "Display colours (PLY 8-bit, OBJ, glTF COLOR_0) show the quantity times 2^exposure")
      ->check(CLI::Range(-64.0f, 64.0f))
      ->check(finite_number());
  cmd->add_option("--threads", o->solver.threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_option("--seed", o->solver.seed, "Random seed for the visibility samples")
      ->check(unsigned_integer());
  cmd->add_option(
         "--check", o->check_points,
         "After solving, compare the irradiance at N vertices, and at N random points inside the input's "
         "faces read from the exported elements (with --onto input or --lightmap: at N random points "
         "inside the input's faces, as baked), with path-traced estimates")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--check-samples", o->check.samples, "Path-traced samples per checked vertex (default 4096)")
      ->check(CLI::Range(2, 100000000));
  cmd->add_option("--check-points", o->check_points_file,
                  "With --check: write every compared point as CSV, to score other bakes against the same "
                  "reference. With --onto input or --lightmap: its face's file vertices, barycentrics, albedo, "
                  "path-traced irradiance with its standard error, the baked value; with --onto elements: the "
                  "vertex, its position, normal and disk radius, the path-traced irradiance with its standard "
                  "error, the solved value");
  cmd->add_flag("--json", o->json, "Print the statistics as one JSON object");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress bar");
  return [o, onto, fit] {
    o->onto_given = onto->count() > 0;
    o->fit_given = fit->count() > 0;
    run_radiosity(*o);
  };
}

}  // namespace gilt::cli

#pragma once
// The statistics of a run and of a radiosity solve as JSON: what `gilt render --json` and
// `gilt radiosity --json` print, and what the Python module returns as dicts.

#include <string>

#include <nlohmann/json.hpp>

#include "api/methods.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::api {

/// A run's statistics: method, size, spp, seed, samplers, threads, the scene's size, rays,
/// samples, their rates, seconds, notes, and the method's own pass ("radiosity", "photon" or
/// "sppm").
nlohmann::json run_statistics(const raytrace_core::scene::Scene& scene, const std::string& method,
                              const raytrace_core::render::RenderSettings& settings,
                              const MethodResult& result);

/// A radiosity solve's statistics: the mesh (elements, vertices, what meshing repaired or
/// removed), the solver and why it was chosen, its work (shots, links, form factors, shadow
/// rays), the residual, and the seconds of each phase.
nlohmann::json solution_statistics(const radiosity::solver::Solution& solution, const radiosity::solver::SolverSettings& settings);

}  // namespace gilt::api

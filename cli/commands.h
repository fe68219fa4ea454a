#pragma once
// Subcommands of the gilt tool. Each registers its options on the app and returns the action to
// run once parsing succeeded.

#include <functional>

#include <CLI/CLI.hpp>

#include "radiosity/solver.h"

namespace gilt::cli {

/// `gilt render`: renders an image with a chosen method.
std::function<void()> add_render_command(CLI::App& app);

/// `gilt radiosity`: solves radiosity and exports the mesh with vertex colours.
std::function<void()> add_radiosity_command(CLI::App& app);

/// `gilt compare`: every method at every time budget against a reference, as a report.
std::function<void()> add_compare_command(CLI::App& app);

/// `gilt info`: describes a scene and the passes each method will run or skip.
std::function<void()> add_info_command(CLI::App& app);

/// Registers the radiosity meshing and solver options (--max-edge, --elements, --tolerance) on
/// a subcommand; both `render --method radiosity` and `radiosity` use them.
void add_solver_options(CLI::App& cmd, radiosity::SolverSettings& settings);

}  // namespace gilt::cli

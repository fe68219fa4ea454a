#pragma once
// Subcommands of the gilt tool. Each registers its options on the app and returns the action to
// run once parsing succeeded.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "radiosity/solver/solver.h"
#include "raytrace_core/io/scene_io.h"

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
void add_solver_options(CLI::App& cmd, radiosity::solver::SolverSettings& settings);

/// Registers --env, --env-scale and --env-rotate (light given on the command line) on a subcommand.
void add_lighting_options(CLI::App& cmd, raytrace_core::io::ExtraLighting& lighting);

/// Registers --camera N|NAME (one of the scene file's cameras) on a subcommand.
inline void add_camera_option(CLI::App& cmd, std::string& camera) {
  cmd.add_option("--camera", camera,
                 "View through one of the scene file's cameras: its number from 0 in file order, or its name "
                 "(gilt info lists them; default: the first)");
}

/// Check for floating-point options: the value must be a finite number. CLI::Range and
/// CLI::PositiveNumber let NaN through (it fails every comparison), so every float option has it.
inline const CLI::Validator& finite_number() {
  static const CLI::Validator check(
      [](std::string& text) {
        double value = 0.0;
        if (CLI::detail::lexical_cast(text, value) && std::isfinite(value)) return std::string();
        return "Value " + text + " is not a finite number";
      },
      "", "FINITE");
  return check;
}

/// Check for unsigned 64-bit options: a whole number in [0, 2^64). CLI11 itself reads "-1" and
/// numbers past the range as 2^64 − 1.
inline const CLI::Validator& unsigned_integer() {
  static const CLI::Validator check(
      [](std::string& text) {
        uint64_t value = 0;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (error == std::errc() && end == text.data() + text.size()) return std::string();
        return "Value " + text + " is not a whole number from 0 to 18446744073709551615";
      },
      "", "UINT64");
  return check;
}

}  // namespace gilt::cli

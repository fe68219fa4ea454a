#pragma once
// Subcommands of the gilt tool. Each registers its options on the app and returns the action to
// run once parsing succeeded.

#include <functional>

#include <CLI/CLI.hpp>

namespace gilt::cli {

/// `gilt render`: renders an image with a chosen method.
std::function<void()> add_render_command(CLI::App& app);

}  // namespace gilt::cli

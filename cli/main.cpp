// gilt: command-line front end. Exit codes: 0 success, 2 bad input (flags, files, numbers),
// 130 stopped by Ctrl-C (no output written), 1 an internal failure. Under `mpirun -np N` (a build
// with GILT_MPI) `gilt render` and `gilt radiosity` split their work across the ranks, and rank 0
// writes the output.

#include <csignal>
#include <exception>
#include <functional>
#include <iostream>

#include <CLI/CLI.hpp>

#include "cli/commands.h"
#include "cli/mpi_processes.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"

namespace {

/// The first Ctrl-C asks the run to stop at its next work item, so no output is half-written;
/// a second one ends the process at once.
extern "C" void on_interrupt(int) {
  gilt::raytrace_core::util::request_stop();
  std::signal(SIGINT, SIG_DFL);
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGINT, on_interrupt);
  const gilt::cli::MpiSession mpi(argc, argv);
  CLI::App app{"gilt: global illumination toolkit (path tracing, radiosity, photon mapping)", "gilt"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "gilt 0.1.0");
  std::function<void()> action;
  const auto render = gilt::cli::add_render_command(app);
  app.get_subcommand("render")->callback([&] { action = render; });
  const auto radiosity = gilt::cli::add_radiosity_command(app);
  app.get_subcommand("radiosity")->callback([&] { action = radiosity; });
  const auto compare = gilt::cli::add_compare_command(app);
  app.get_subcommand("compare")->callback([&] { action = compare; });
  const auto info = gilt::cli::add_info_command(app);
  app.get_subcommand("info")->callback([&] { action = info; });

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }
  try {
    if (mpi.ranks() > 1 && !app.got_subcommand("render") && !app.got_subcommand("radiosity"))
      throw gilt::raytrace_core::InputError("under mpirun only `gilt render` and `gilt radiosity` split their work across ranks: run " +
                                            app.get_subcommands().front()->get_name() + " as one process");
    action();
  } catch (const gilt::raytrace_core::InputError& e) {
    std::cerr << "gilt: error: " << e.what() << "\n";
    return 2;
  } catch (const gilt::raytrace_core::Interrupted&) {
    std::cerr << "gilt: interrupted: nothing was written\n";
    if (mpi.ranks() > 1) mpi.abort(130);  // the other ranks may be waiting in a collective
    return 130;
  } catch (const std::exception& e) {
    std::cerr << "gilt: internal error: " << e.what() << "\n";
    if (mpi.ranks() > 1) mpi.abort(1);
    return 1;
  }
  return 0;
}

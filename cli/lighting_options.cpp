// Light given on the command line: options shared by render, radiosity, compare and info.

#include "cli/commands.h"

namespace gilt::cli {

void add_lighting_options(CLI::App& cmd, raytrace_core::ExtraLighting& lighting) {
  cmd.add_option("--env", lighting.env_file,
                 "Light the scene with an environment image (.exr, .hdr; latitude-longitude, +y up), "
                 "replacing its own environment light")
      ->check(CLI::ExistingFile);
  cmd.add_option("--env-scale", lighting.env_scale, "Multiply the environment image's radiance by S (default 1)")
      ->check(finite_number())
      ->check(CLI::Range(0.0f, 1e30f));
  cmd.add_option("--env-rotate", lighting.env_rotate_degrees,
                 "Turn the environment image about +y by this many degrees (right-handed; default 0)")
      ->check(finite_number());
}

}  // namespace gilt::cli

// Light given on the command line: options shared by render, radiosity, compare and info.

#include <sstream>
#include <vector>

#include "cli/commands.h"

namespace gilt::cli {

void add_lighting_options(CLI::App& cmd, raytrace_core::io::ExtraLighting& lighting) {
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
  cmd.add_option_function<std::string>(
         "--sun",
         [&lighting](const std::string& text) {
           std::vector<float> v;
           std::stringstream in(text);
           std::string item;
           while (std::getline(in, item, ',')) {
             double x = 0.0;
             if (!CLI::detail::lexical_cast(item, x) || !std::isfinite(x))
               throw CLI::ValidationError("--sun", "'" + item + "' is not a finite number");
             v.push_back(float(x));
           }
           if (v.size() < 2 || v.size() > 3)
             throw CLI::ValidationError("--sun", "expected ELEVATION,AZIMUTH[,IRRADIANCE] in degrees and W/m²");
           if (!(v[0] >= -90.0f && v[0] <= 90.0f))
             throw CLI::ValidationError("--sun", "elevation must lie in [-90, 90] degrees");
           if (v.size() == 3 && !(v[2] >= 0.0f)) throw CLI::ValidationError("--sun", "irradiance must not be negative");
           lighting.sun = true;
           lighting.sun_elevation_degrees = v[0];
           lighting.sun_azimuth_degrees = v[1];
           lighting.sun_irradiance = v.size() == 3 ? v[2] : 1.0f;
         },
         "Add a sun: a 0.53-degree disk at ELEVATION above the horizon and AZIMUTH (0 along -z, 90 along "
         "+x), of IRRADIANCE W/m2 on a plane facing it (default 1)")
      ->type_name("ELEV,AZIM[,E]");
  cmd.add_option("--sky", lighting.sky_turbidity,
                 "Add Preetham's clear sky for the --sun position, of turbidity T (default 3; 2 very clear, 6 hazy), "
                 "replacing the scene's own environment light")
      ->expected(0, 1)
      ->default_str("3")
      ->check(finite_number())
      ->check(CLI::Range(1.7f, 10.0f));
}

}  // namespace gilt::cli

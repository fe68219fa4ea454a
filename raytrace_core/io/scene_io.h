#pragma once
// Loading scenes from files and by built-in name.

#include <string>
#include <vector>

#include "raytrace_core/scene/scene.h"

namespace gilt::raytrace_core::io {

/// Loads a scene file by extension (.obj with its .mtl, .gltf, .glb, .ply, .json) or a built-in
/// scene by name, and commits it. Throws InputError naming the file and, where known, the line
/// or field.
scene::Scene load_scene(const std::string& path_or_name);

/// Light given on the command line rather than in the scene file.
struct ExtraLighting {
  std::string env_file;             ///< an environment image (`--env`); empty: none
  float env_scale = 1.0f;           ///< its radiance multiplier (`--env-scale`)
  float env_rotate_degrees = 0.0f;  ///< its turn about +y (`--env-rotate`)
  bool sun = false;                 ///< a sun (`--sun ELEVATION,AZIMUTH[,IRRADIANCE]`): a 0.53° disk
  float sun_elevation_degrees = 45.0f, sun_azimuth_degrees = 0.0f, sun_irradiance = 1.0f;
  float sky_turbidity = 0.0f;       ///< > 0: Preetham's clear sky for the sun's position (`--sky`)
};

/// load_scene, with `extra`'s lights added before the commit. An environment image or a sky
/// replaces the scene's own environment light, with a warning; a sun is added to its lights.
scene::Scene load_scene(const std::string& path_or_name, const ExtraLighting& extra);

/// Makes camera `choice` of scene.cameras the scene's camera (`--camera N|NAME`): N counts from 0
/// in file order, else the name must match one exactly. The image's width follows the camera's
/// aspect ratio when it has one. Throws InputError naming the cameras there are.
void select_camera(scene::Scene& scene, const std::string& choice);

/// Loads a scene file without committing it (so callers may still edit it).
scene::Scene load_scene_file(const std::string& path);

/// Names of the built-in scenes: cornell, cornell-caustics, furnace, smallpt.
std::vector<std::string> builtin_scene_names();
/// True when `name` is a built-in scene.
bool is_builtin_scene(const std::string& name);
/// A built-in scene, not yet committed. Throws InputError for an unknown name.
scene::Scene builtin_scene(const std::string& name);

/// Parameters of the built-in `furnace` scene: a closed box of emission le and albedo rho.
scene::Scene furnace_scene(float le, float rho);

/// Applies p ↦ scale·p + offset to all geometry, lights and the camera (for scale tests).
void transform_scene(scene::Scene& scene, float scale, const Vec3& offset);

}  // namespace gilt::raytrace_core::io

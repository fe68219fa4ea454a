#pragma once
// Daylight from the command line: the sun's direction from elevation and azimuth, and a clear sky
// from the analytic model of Preetham, Shirley & Smits 1999 ("A Practical Analytic Model for
// Daylight", SIGGRAPH), made into an environment map so that every method samples it as it
// samples any other.
//
// Directions: +y up; azimuth 0 looks along −z (the environment map's centre column), 90° along
// +x. Units: the sky's radiance is its luminance over 100 klx, a bright sun's illuminance, so that
// next to a sun of irradiance 1 (gilt's default) the sky has its natural share of daylight.

#include <memory>

#include "raytrace_core/scene/environment_map.h"
#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::scene {

/// Unit direction towards a point at `elevation_degrees` above the horizon and azimuth
/// `azimuth_degrees` (see above).
Vec3 sky_direction(float elevation_degrees, float azimuth_degrees);

/// The sun's angular radius as seen from the Earth: 0.2665° (a disk of 0.533°).
inline constexpr float kSunAngularRadiusDegrees = 0.2665f;

/// Preetham's clear sky for a sun in direction `to_sun` (unit) and atmospheric turbidity
/// `turbidity` (2: very clear, 3: clear, 6: hazy; the model is fitted for 2–10), as a
/// width × width/2 latitude–longitude map in linear Rec.709 RGB. Below the horizon it is black:
/// the ground belongs to the scene. Throws InputError for a turbidity outside [1.7, 10].
std::shared_ptr<const EnvironmentMap> preetham_sky(const Vec3& to_sun, float turbidity, int width = 512);

}  // namespace gilt::raytrace_core::scene

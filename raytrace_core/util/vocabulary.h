#pragma once
// The words every room of raytrace_core and every caller speaks: the vectors, constants, frames
// and boxes of math.h, the colour of rgb.h and the error types of error.h. They live in util and
// are named here once more in the parent namespace, so that they read as rc::Vec3, rc::Rgb,
// rc::InputError everywhere (and unqualified inside any room). Every other name is reached
// through its room: rc::util::Rng, rc::scene::Scene, rc::io::load_scene, rc::render::render_image.
//
// math.h, rgb.h and error.h each include this header at their end, so whoever includes one of
// them has these names too; it includes the three first, so all of them are declared below
// whichever of the three is read first.

#include "raytrace_core/util/error.h"
#include "raytrace_core/util/math.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::raytrace_core {

// math.h
using util::Bounds3;
using util::DVec3;
using util::Frame;
using util::Vec2;
using util::Vec3;
using util::kInfinity;
using util::kInv2Pi;
using util::kInv4Pi;
using util::kInvPi;
using util::kOneMinusEpsilon;
using util::kPi;
using util::abs;
using util::is_finite;
using util::reflect;
using util::safe_sqrt;
using util::sqr;
// rgb.h (its operators are found with Rgb itself)
using util::Rgb;
using util::clamp;
using util::exp;
// error.h
using util::InputError;
using util::Interrupted;

}  // namespace gilt::raytrace_core

#pragma once
// gilt's exception types: bad input, which the command-line tool maps to exit code 2, and a run
// stopped on request (raytrace_core/util/parallel.h), which it maps to 130.

#include <stdexcept>
#include <string>

namespace gilt::raytrace_core::util {

/// Bad user input (a file, a flag, a number). The message names the file and, where known, the
/// line or field, e.g. "scene.obj:12: face refers to vertex 40 of 12".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A run stopped by request_stop() before it finished: its partial results are discarded.
class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

}  // namespace gilt::raytrace_core::util

// The parent namespace re-exports these names (rc::Vec3, rc::Rgb, rc::InputError ...).
#include "raytrace_core/util/vocabulary.h"

#pragma once
// The one exception type for bad input: the command-line tool maps it to exit code 2.

#include <stdexcept>
#include <string>

namespace gilt::raytrace_core {

/// Bad user input (a file, a flag, a number). The message names the file and, where known, the
/// line or field, e.g. "scene.obj:12: face refers to vertex 40 of 12".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace gilt::raytrace_core

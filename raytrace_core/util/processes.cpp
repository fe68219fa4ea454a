#include "raytrace_core/util/processes.h"

#include <algorithm>
#include <utility>

namespace gilt::raytrace_core::util {
namespace {

std::shared_ptr<const Processes>& installed() {
  static std::shared_ptr<const Processes> current = std::make_shared<const Processes>();
  return current;
}

}  // namespace

float Processes::max(float value) const {
  if (count() == 1) return value;
  const std::vector<std::byte> all = all_gather(std::as_bytes(std::span(&value, 1)));
  float largest = value;
  for (size_t i = 0; i + sizeof(float) <= all.size(); i += sizeof(float)) {
    float v;
    std::memcpy(&v, all.data() + i, sizeof v);
    largest = std::max(largest, v);
  }
  return largest;
}

const Processes& processes() { return *installed(); }

void set_processes(std::shared_ptr<const Processes> processes) {
  installed() = processes ? std::move(processes) : std::make_shared<const Processes>();
}

}  // namespace gilt::raytrace_core::util

#include "radiosity/solver/probe_fraction.h"

#include <algorithm>

namespace gilt::radiosity::solver {

double extended_fraction(int hits, int rays, int probe) {
  double a = 1.0, b = 1.0;
  for (int i = 0; i < probe; ++i) {
    a *= double(std::max(hits - i, 0)) / double(rays - i);
    b *= double(std::max(rays - hits - i, 0)) / double(rays - i);
  }
  return (double(hits) / double(rays) - a) / (1.0 - a - b);
}

double quartered_fraction(const std::array<int, 4>& hits, int rays_per_quarter) {
  std::array<double, 4> q;
  double all_open = 1.0, all_blocked = 1.0;
  for (int j = 0; j < 4; ++j) {
    q[j] = double(hits[j]) / double(rays_per_quarter);
    all_open *= q[j];
    all_blocked *= 1.0 - q[j];
  }
  const double mixed = 1.0 - all_open - all_blocked;
  double sum = 0.0;
  for (int j = 0; j < 4; ++j) sum += mixed > 0.0 ? (q[j] - all_open) / mixed : q[j];
  return sum / 4.0;
}

}  // namespace gilt::radiosity::solver

#include "radiosity/solver/ladder_forecast.h"

#include <algorithm>

namespace gilt::radiosity::solver {

LevelForecast foretell_level(const Trial& trial, double links_before, double merge_per_link, double gather_per_link,
                             double gathers) {
  const double scale = std::max(1.0, trial.scale);
  const double links = std::max(0.0, links_before) + std::max(0.0, trial.links) * scale;
  LevelForecast f;
  f.link = std::max(0.0, trial.seconds) * scale;
  f.merge = merge_per_link * links;
  f.iterate = gather_per_link * links * std::max(0.0, gathers);
  return f;
}

double trial_keep_back(double seconds_left, double scale) {
  if (!(seconds_left > 0.0)) return 0.0;
  return seconds_left * (1.0 - 1.0 / std::max(1.0, scale));
}

bool final_gather_fits(double seconds, double seconds_left) { return kFinalGatherMargin * seconds <= seconds_left; }

}  // namespace gilt::radiosity::solver

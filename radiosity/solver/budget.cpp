#include "radiosity/solver/budget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "raytrace_core/util/processes.h"

namespace gilt::radiosity::solver {

using mesh::kDefaultElements;

double fitted_elements(size_t pilot_elements, double pilot_seconds, double seconds, double most) {
  if (!(seconds > 0.0) || !(pilot_seconds > 0.0) || pilot_elements == 0) return 0.0;
  return std::min(double(pilot_elements) * std::sqrt(seconds / pilot_seconds), most);
}

Solution solve_within(const rc::scene::Scene& scene, SolverSettings settings, double seconds,
                      BudgetFit* fit) {
  BudgetFit local;
  BudgetFit& f = fit ? *fit : local;
  f = BudgetFit{};
  settings.time_limit = seconds;
  const bool gilts_choice = settings.mesh.elements == 0 && !(settings.mesh.max_edge > 0.0f) &&
                            scene.triangle_count() + scene.spheres.size() < size_t(kPilotElements / 2);
  if (!(seconds > 0.0) || !gilts_choice) return solve(scene, settings);

  SolverSettings pilot_settings = settings;
  pilot_settings.mesh.elements = kPilotElements;
  Solution pilot = solve(scene, pilot_settings);
  f.pilot_elements = pilot.mesh.element_count();
  f.pilot_seconds = pilot.seconds;
  const double left = seconds - pilot.seconds;
  const bool converged = pilot.residual <= settings.tolerance;
  f.fitted = true;
  // The count that fills what is left, were the cost to grow as n² from the pilot's, and at most
  // what the default request gives (scaled by how the pilot's mesh met its own request); rank
  // 0's, so that every process meshes alike.
  const double most = double(f.pilot_elements) * double(kDefaultElements) / double(kPilotElements);
  const double n =
      rc::util::processes().broadcast_value(converged ? fitted_elements(f.pilot_elements, pilot.seconds, left, most) : 0.0);
  char line[200];
  if (!(n > 1.25 * double(f.pilot_elements))) {
    std::snprintf(line, sizeof line, "radiosity: %zu elements, solved in %.3g s of a %.3g-s solve budget%s", f.pilot_elements,
                  pilot.seconds, seconds, converged ? "" : " (stopped: a finer mesh would not converge in time)");
    f.note = line;
    return pilot;
  }
  // The request that gives n elements, scaled by how the pilot's mesh met its own request.
  f.requested_elements = int(std::lround(n * double(kPilotElements) / double(f.pilot_elements)));
  settings.mesh.elements = f.requested_elements;
  settings.time_limit = std::max(1e-3, left);
  Solution final_solution = solve(scene, settings);
  std::snprintf(line, sizeof line,
                "radiosity: %zu elements fitted to a %.3g-s solve budget (a %zu-element pilot took %.3g s)",
                final_solution.mesh.element_count(), seconds, f.pilot_elements, f.pilot_seconds);
  f.note = line;
  return final_solution;
}

}  // namespace gilt::radiosity::solver

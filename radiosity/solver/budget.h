#pragma once
// A radiosity solve that chooses its mesh from a time budget.
//
// The default mesh (kDefaultElements) is sized for accuracy, not for time: under a short budget
// progressive refinement stops with much of the light unshot, and a coarser mesh solved to the
// end shows less error. On cornell at `--time 0.5` the default mesh stopped at a residual of
// 0.02-0.05 and rendered with 2.6-4.3 % mean relative error; fitted, about 2,000 elements
// converge in 0.2 s and render with 1.3-1.4 % (bench/README, "A budget for the mesh").

#include <string>

#include "radiosity/solver/solver.h"

namespace gilt::radiosity::solver {

/// Elements asked of the pilot solve that measures how long the scene takes.
inline constexpr int kPilotElements = 1000;

/// How solve_within sized the mesh.
struct BudgetFit {
  bool fitted = false;          ///< the element count followed the budget
  size_t pilot_elements = 0;    ///< the pilot's mesh (0: no pilot ran)
  double pilot_seconds = 0.0;
  int requested_elements = 0;   ///< asked of the final solve (0: the pilot was kept)
  std::string note;             ///< one line for the user: what was chosen and why
};

/// The element count at which a solve whose cost grows as the square of its element count, and
/// which took `pilot_seconds` at `pilot_elements`, takes `seconds`; at most `most`, 0 when there
/// is no time or no pilot to scale from.
double fitted_elements(size_t pilot_elements, double pilot_seconds, double seconds, double most);

/// Meshes and solves the committed scene within `seconds` (replacing settings.time_limit).
///
/// When the mesh's size is gilt's to choose (neither settings.mesh.elements nor max_edge is set,
/// and the input has fewer than kPilotElements / 2 triangles, so that its own triangles do not
/// set the element count), a pilot solve at kPilotElements elements measures the scene on this
/// machine. The final solve then gets the element count n at which a cost growing as n² from
/// the pilot's (progressive refinement's order; on cornell it grows as n^1.5, so the estimate
/// errs on the short side) fills what the pilot left of the budget, but never more than the
/// default mesh: a budget that affords more is better spent on the render's samples (on a glass
/// scene at `--time 4`, 6,788 fitted elements rendered at 1.11 % error, the default 3,904 at
/// 0.93 %). The pilot is kept when n is within 1.25 times its own count, or when it did not
/// converge itself. Otherwise one solve as asked, stopped at the budget. Under MPI the count is
/// rank 0's.
Solution solve_within(const rc::scene::Scene& scene, SolverSettings settings, double seconds, BudgetFit* fit = nullptr);

}  // namespace gilt::radiosity::solver

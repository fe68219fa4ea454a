#pragma once
// Foretelling the steps of a timed hierarchical solve (see solve_hierarchical): what one level of
// links costs to make, merge and iterate, from a trial on a fiftieth of its pairs and the costs
// the steps before it measured, and whether the final gather fits. Arithmetic only, so that tests
// can feed it measurements of their own.

#include <cstddef>

namespace gilt::radiosity::solver {

/// Seconds per link to sort and merge a level's links into the ordered ones, until a level has
/// been merged and measured (two cores: 17 M links in about 0.9 s on a furnished room).
inline constexpr double kMergeSecondsPerLink = 6e-8;
/// Seconds per link of one gather, until a level has been iterated and measured (two cores:
/// 19-36 ns on Šibenik and a furnished room, as busy as the machine was).
inline constexpr double kGatherSecondsPerLink = 3e-8;
/// Gathers foretold for the first level of a ladder, bounding the gains included: the first
/// three bounces above the direct light, which carry most of the reflected light at the albedos
/// of interiors; the iteration goes on while time is left (Šibenik's first level iterated 9
/// times). Foretelling all of them (8) made a furnished room at `--time 20` link nothing where
/// 17 M links and 8 gathers fitted in a quieter run.
inline constexpr int kFirstLevelGathers = 4;
/// A timed solve's first level may link this many decades coarser than the ladder's top.
inline constexpr int kFirstLevelDecades = 3;
/// The final gather runs only when this many times its foretold seconds fit in the time left.
inline constexpr double kFinalGatherMargin = 1.25;

/// What one level of links is foretold to cost, in seconds.
struct LevelForecast {
  double link = 0.0;     ///< refining its pairs
  double merge = 0.0;    ///< sorting its links and merging them into the ordered ones
  double iterate = 0.0;  ///< its gathers
  double total() const { return link + merge + iterate; }
};

/// What a trial measured: it refined every stride-th pair of a level in `seconds` and made
/// `links`; `scale` is the level's pairs over the trial's.
struct Trial {
  double seconds = 0.0;
  double links = 0.0;
  double scale = 1.0;
};

/// The level foretold from `trial`: linking at the trial's seconds per pair, `links_before`
/// (the links it keeps from the levels above) plus the trial's links per pair, merged at
/// `merge_per_link` seconds per link and gathered `gathers` times at `gather_per_link`.
LevelForecast foretell_level(const Trial& trial, double links_before, double merge_per_link, double gather_per_link,
                             double gathers);

/// The time a trial may take before it is known to be over: a trial that would scale to more
/// than `seconds_left` stops early. Returns how much of seconds_left it may leave unspent before
/// stopping (the Linker's keep-back): seconds_left × (1 − 1 / scale).
double trial_keep_back(double seconds_left, double scale);

/// Whether a final gather foretold to take `seconds` runs with `seconds_left` left:
/// kFinalGatherMargin × seconds ≤ seconds_left.
bool final_gather_fits(double seconds, double seconds_left);

}  // namespace gilt::radiosity::solver

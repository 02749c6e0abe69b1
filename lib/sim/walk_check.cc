#include "sim/walk_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace dgmm::sim {
namespace {

// The index (0 long, 1 lat, 2 turn) of a command's one non-zero component, or -1.
int PureComponent(const Eigen::RowVectorXd& c) {
  int k = -1;
  for (int j = 0; j < c.size(); ++j) {
    if (c(j) == 0) continue;
    if (k >= 0) return -1;
    k = j;
  }
  return k;
}

std::string Signed(double v) {
  std::ostringstream s;
  s << (v > 0 ? "+" : "") << v;
  return s.str();
}

// Three significant digits (0.497, not a rounded 0.50 beside the band's 0.5).
std::string Number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

}  // namespace

CommandedWalk CommandedWalkOf(const SimConfig& config, double leg_reach_m) {
  if (!config.robot || config.robot->controller.replay()) return {};
  const GaitDescription& g = config.robot->gait;
  const double stride = g.stride_m > 0 ? g.stride_m : g.stride_reach * leg_reach_m;
  return {stride, g.turn_rad, g.period_s > 0 ? config.command_duration_s / g.period_s : 0};
}

std::vector<WalkRatio> WalkRatios(const SampleSet& set, const CommandedWalk& want) {
  std::vector<WalkRatio> out;
  const bool named = set.command_dim_names == std::vector<std::string>{"long", "lat", "turn"};
  if (!named || set.x.cols() < 6 || !(want.cycles > 0)) return out;
  for (int c = 0; c < set.num_commands(); ++c) {
    const int k = PureComponent(set.commands.row(c));
    if (k < 0) continue;
    const int column = k < 2 ? k : 5;  // dx, dy, dyaw
    double sum = 0;
    int n = 0;
    for (int i = 0; i < set.size(); ++i) {
      if (set.command(i) == c) sum += set.x(i, column), ++n;
    }
    const double commanded = set.commands(c, k) * (k < 2 ? want.stride_m : want.turn_rad) * want.cycles;
    if (n == 0 || commanded == 0) continue;
    out.push_back({set.command_dim_names[k] + " " + Signed(set.commands(c, k)), sum / n / commanded, commanded,
                   k < 2 ? "m" : "rad"});
  }
  return out;
}

std::string WalkWarning(const std::vector<WalkRatio>& ratios, const WalkBand& band) {
  std::vector<WalkRatio> off;
  for (const WalkRatio& r : ratios) {
    if (!(r.ratio >= band.lo && r.ratio <= band.hi)) off.push_back(r);
  }
  if (off.empty()) return "";
  // Farthest from 1 first.
  std::sort(off.begin(), off.end(),
            [](const WalkRatio& a, const WalkRatio& b) { return std::abs(a.ratio - 1) > std::abs(b.ratio - 1); });
  std::ostringstream w;
  w << "gait: it does not walk the robot as it commands: ";
  const size_t shown = std::min<size_t>(off.size(), 3);
  for (size_t i = 0; i < shown; ++i) {
    w << (i ? ", " : "") << off[i].command << " moved it " << Number(off[i].ratio) << " of the commanded "
      << Number(std::abs(off[i].commanded)) << " " << off[i].unit;
  }
  if (off.size() > shown) w << " (and " << off.size() - shown << " more)";
  w << " per execution (the mean of a pure command's executions against stride or turn x cycles; outside "
    << band.lo << " to " << band.hi << " here. scripts/walk_table.py tables each gait pattern and slope; "
       "docs/simulation.md, \"Does it walk as commanded?\")";
  return w.str();
}

std::string TrackerNoiseWarning(double tracker_sd_m, const CommandedWalk& want, double share) {
  const double travel = 0.5 * want.stride_m * want.cycles;
  if (!(travel > 0) || !(tracker_sd_m > share * travel)) return "";
  return "noise.tracker_position_sd_m: " + Number(tracker_sd_m) + " m is " + Number(100 * tracker_sd_m / travel) +
         "% of the " + Number(travel) + " m a half command moves the robot in an execution (over " +
         Number(100 * share) + "%): the tracker's noise is a length of its own, not of the robot's, and such sets "
         "tell dgmm sim2real less of the robot's motion (docs/simulation.md, \"One robot at three sizes\"); give "
         "your tracker's noise in the config's noise block";
}

}  // namespace dgmm::sim

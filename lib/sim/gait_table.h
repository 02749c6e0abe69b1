#pragma once
// Timing of the generic gait (any number of legs): each leg's phase offset in the cycle and the
// duty factor, from a named pattern or user phases, and each foot's offset from its stance
// position over the cycle. MuJoCo-free.
#include <Eigen/Core>
#include <vector>

#include "sim/robot_description.h"

namespace dgmm::sim {

// Where a leg is, to order legs for the named patterns: side +1 left / -1 right, and its foot's
// forward coordinate (robot frame, m).
struct LegPlace {
  int side = 1;
  double forward_m = 0;
};

struct GaitTiming {
  std::vector<double> phase;  // per leg, in [0, 1)
  // Per leg, for commands that walk backwards: the named patterns' order of swings reversed in
  // time, (1 - phase) mod 1, so that the wave of swings runs from the trailing legs to the leading
  // ones whichever way the robot walks (identical to `phase` for tripod, trot and the alternating
  // tetrapod; user phases are kept as given).
  std::vector<double> phase_backward;
  double duty = 0.5;          // share of the cycle each foot is on the ground
  // A pattern that swings one side's legs and then the other's (the wave): a command with a
  // sideways part starts with the trailing side (LateralShift).
  bool side_sequential = false;
};

// Phase shift (0 or 0.5 of a cycle) for a command with sideways part `lateral` (> 0: to the
// left) of a side-sequential pattern whose legs (sides +1 left / -1 right) follow `phase`: half a
// cycle when the first leg to lift after the command starts is on the leading side, so that the
// trailing side lifts first. 0 for other patterns or no sideways part.
double LateralShift(const GaitTiming& timing, const std::vector<double>& phase, const std::vector<int>& sides,
                    double lateral);

// The pattern's timing for these legs: trot / crawl need 4 legs, tripod / tetrapod 6,
// alternating_tetrapod 8, each half on either side; alternating any equal number a side from 2
// (trot, tripod and the alternating tetrapod are its cases); wave any number from 3, one foot in
// the air at a time. auto picks the alternating pattern on equal sides (the trot, tripod and
// alternating tetrapod on 4, 6 and 8 legs) and the wave otherwise (a robot that lost a leg); custom
// takes gait.phases (one per leg).
// The tetrapod and the wave swing each side's legs from back to front when walking forwards.
// Throws InputError "<source>: robot.gait.pattern: ..." when the pattern needs another number of
// legs.
GaitTiming ResolveGait(const GaitDescription& gait, const std::vector<LegPlace>& legs, const std::string& source);

// A foot's offset from its stance position at fraction u in [0, 1) of its own cycle (u = 0:
// touch-down): on the ground (u < duty) it moves from +d/2 to -d/2 at constant speed; in the air
// it returns along a cosine profile and lifts by `lift` * sin(pi s). d is the foot's travel
// relative to the torso per stance.
Eigen::Vector3d FootOffset(double u, double duty, const Eigen::Vector2d& d, double lift);

// The sway share a gait uses: `sway` when given (>= 0); when negative, kDefaultSway for a
// statically stable duty factor (>= 0.75: at most one leg of four in the air) and 0 below.
double ResolveSway(double sway, double duty);

// Each leg's sway target: `share` of the way from the centroid of all stance points to the
// centroid of the other legs' (robot frame, horizontal): where the torso goes while that leg
// swings. For a rectangle of four feet, share / 3 of the way from the centre to the opposite foot.
// Scaled by the need: all of it when the centre lies on the edge of the other feet's polygon (the
// rectangle), none from a margin of a quarter of the lifted foot's distance from the centre (a
// hexapod lifting a middle foot), linearly in between.
std::vector<Eigen::Vector2d> SwayTargets(const std::vector<Eigen::Vector2d>& stance, double share);

// How much a leg at fraction u of its cycle weighs in the torso's sway: a raised cosine centred on
// mid-swing, as wide as the swing on either side (1 there, 0 a swing's length away), so that the
// weights of back-to-back swings add up to 1 and the torso blends from one target to the next.
double SwingWeight(double u, double duty);

}  // namespace dgmm::sim

#pragma once
// A first `robot` block for an MJCF nobody has described yet (`dgmm robot-draft`), read off the
// compiled model at its rest pose (first keyframe, else qpos0): the torso is the body with the free
// joint, the floor the plane on the world body, and a leg each jointed branch below the torso whose
// lowest geom that can touch the floor stands near the lowest of them all (a tail or a head above
// the feet is not a leg; a branch whose own branches stand on both sides of the forward axis is a
// body segment behind a spine joint, its legs drafted below it; the joints of either are held
// when driven, passive when not). A leg's joints are its driven hinges and slides from the torso (or its
// segment) to that geom, torso first; undriven ones are passive; its foot is that geom; its name the common prefix of
// its joints' names ("FR" of FR_hip_joint, FR_thigh_joint, FR_calf_joint), else its first body's.
// The draft is then bound as `dgmm simulate` binds a robot block, so what it lacks is said at once.
// No MuJoCo in this header.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/robot_description.h"

namespace dgmm::sim {

struct RobotDraftOptions {
  Eigen::Vector3d forward_axis = Eigen::Vector3d::UnitX();  // the robot's forward, torso frame
  // A branch is a leg when its lowest point lies within this share of the torso-to-ground depth
  // of the lowest branch (relative: a robot of any size).
  double foot_band = 0.25;
  bool IsValid(std::string* error) const;
};

struct RobotDraft {
  RobotDescription robot;
  double timestep_s = 0;           // the model's own (<option timestep>), for the config to keep
  std::vector<std::string> notes;  // what was guessed or left out, one line each
  std::string bind_error;          // empty: the draft binds as `dgmm simulate` would bind it
};

// Throws InputError "<mjcf_path>: <part>: <problem>" when no draft can be made: MuJoCo cannot load
// the file, not exactly one body has a free joint, no named plane lies on the world body, or no
// branch below the torso reaches the ground.
RobotDraft DraftRobot(const std::string& mjcf_path, const RobotDraftOptions& options = {});

}  // namespace dgmm::sim

#pragma once

#include <memory>
#include <string>
#include <vector>

#include "variational_formation_core/robots/unicycle_command.hpp"
#include "variational_formation/world/contact_log.hpp"
#include "variational_formation/world/wheel_odometry.hpp"
#include "variational_formation/world/world_settings.hpp"

struct mjModel_;
struct mjData_;

namespace vf {

/// A robot's velocity in its own frame (base_link): as cmd_vel and nav_msgs/Odometry's twist.
struct BaseTwist {
  double linearX = 0.0, linearY = 0.0;  ///< [m/s]
  double angularZ = 0.0;                ///< [rad/s]
};

/// A robot's joints, for sensor_msgs/JointState: names without the robot prefix.
struct JointReadings {
  std::vector<std::string> names;
  std::vector<double> position, velocity, effort;  ///< [rad or m], [rad/s or m/s], [N m or N]
};

/// A robot's body as seen from above, for markers [m]: a vertical cylinder, world frame.
struct BodyOutline {
  double x = 0.0, y = 0.0, z = 0.0;  ///< centre
  double radius = 0.0, halfHeight = 0.0;
};

/// A geom `obstacle_<k>` as the model has it, for markers: MuJoCo's type, pose and size [m].
struct ObstacleGeom {
  enum class Type { Cylinder, Box, Sphere, Other };
  Type type = Type::Other;
  double position[3] = {0.0, 0.0, 0.0};
  double quaternion[4] = {1.0, 0.0, 0.0, 0.0};  ///< w, x, y, z
  double size[3] = {0.0, 0.0, 0.0};              ///< MuJoCo's: radius and half height, or half sides
};

/**
 * N robots in a MuJoCo world (ROS-free; doc/robots.md, "The MuJoCo world"). Each robot is a
 * body `robot_<i>` whose motion MujocoWorld drives through named joints and velocity actuators:
 * - unicycle: joints and actuators `robot_<i>_left_wheel`, `robot_<i>_right_wheel` (hinges about
 *   the body's y axis; wheel radius and track from the settings); the body's origin is the axle;
 * - holonomic: joints and actuators `robot_<i>_x`, `robot_<i>_y` (slides along the world's axes)
 *   and `robot_<i>_yaw`.
 * buildWorldMjcf writes such models; a user's own MJCF must use the same names. Geoms named
 * `obstacle_<k>` are obstacles. Contacts between two robots, or a robot and an obstacle, are
 * counted by a ContactLog.
 */
class MujocoWorld {
 public:
  /**
   * Loads MJCF text (from memory) with `robots` robots; the settings' time step replaces the
   * model's. @throws InvalidInput "model: <source>: ..." if MuJoCo refuses the text or a robot's
   * body, joint or actuator is missing, or naming a bad setting.
   */
  MujocoWorld(const std::string& mjcf, const std::string& source, int robots, const WorldSettings& settings);
  /// As above, from an MJCF file (its includes and meshes relative to it).
  static std::unique_ptr<MujocoWorld> fromFile(const std::string& path, int robots, const WorldSettings& settings);
  ~MujocoWorld();
  MujocoWorld(const MujocoWorld&) = delete;
  MujocoWorld& operator=(const MujocoWorld&) = delete;

  int robotCount() const { return static_cast<int>(robots_.size()); }
  const WorldSettings& settings() const { return settings_; }

  /**
   * robot's cmd_vel: a unicycle takes linear [m/s] and angular [rad/s] (lateral ignored), turned
   * into wheel speeds that are scaled together into +-max_wheel_speed; a holonomic base takes
   * (linear, lateral) on the world's axes, scaled into max_speed, and angular as its yaw rate.
   * @return true if the command was scaled down (saturated).
   * @throws InvalidInput on a non-finite value or a bad robot index (the command is unchanged).
   */
  bool setCommand(int robot, double linear, double lateral, double angular);
  /// One physics step of time_step; records the contacts it found.
  /// @throws InvalidInput if the physics became unstable (MuJoCo's bad-acceleration reset).
  void step();
  /// Simulated time [s].
  double time() const;

  /// Ground truth: the body's pose on the floor [m, m, rad], heading in (-pi, pi].
  PlanarPose pose(int robot) const;
  /// Ground truth: the body's velocity in its own frame.
  BaseTwist twist(int robot) const;
  /// Unicycles: the pose integrated from the wheel angles since the start (drifts).
  /// @throws InvalidInput for holonomic robots.
  PlanarPose wheelOdometry(int robot) const;
  JointReadings joints(int robot) const;
  /// The forces [N] or torques [N m] of the robot's actuators at the last step.
  std::vector<double> actuatorForces(int robot) const;

  /// The cylinder geom `robot_<i>_body` (the built model's body), else a cylinder of the settings'
  /// body_radius about the body's origin.
  BodyOutline bodyOutline(int robot) const;
  /// The model's obstacles, in the order of their contact ids (obstacle_<k> is the k-th).
  std::vector<ObstacleGeom> obstacleGeoms() const;

  const ContactLog& contacts() const { return contacts_; }
  /// The pairs touching at the last step, with where they touch.
  const std::vector<Touch>& touches() const { return touches_; }
  /// The contacts that began at the last step.
  const std::vector<ContactEvent>& newContacts() const { return newContacts_; }

 private:
  struct Robot {
    int body = -1;
    std::vector<int> joints, actuators;  // wheel joints (left, right) or (x, y, yaw)
    std::vector<std::string> jointNames; // without the robot's prefix
    std::unique_ptr<WheelOdometry> odometry;
  };
  MujocoWorld(mjModel_* model, const std::string& source, int robots, const WorldSettings& settings);
  void bind(const std::string& source, int robots);
  void refresh() const;
  double jointPosition(int joint) const;
  std::vector<Touch> touching() const;
  const Robot& robot(int i) const;

  WorldSettings settings_;
  mjModel_* model_ = nullptr;
  mjData_* data_ = nullptr;
  std::vector<Robot> robots_;
  std::vector<int> participantOfBody_;  // root body id -> robot index, else -1
  std::vector<int> obstacleOfGeom_;     // geom id -> obstacle index, else -1
  ContactLog contacts_;
  std::vector<ContactEvent> newContacts_;
  std::vector<Touch> touches_;
  std::vector<int> bodyGeoms_;          // robot -> its geom robot_<i>_body, else -1
  int unstableSeen_ = 0;
  mutable bool stale_ = true;           // the body positions lag qpos until refresh()
};

}  // namespace vf

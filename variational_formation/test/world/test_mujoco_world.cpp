// The MuJoCo world alone (world/mujoco_world.hpp): how its robots follow cmd_vel, saturate,
// touch, and what their odometry says. No ROS: the shipped MujocoWorld, stepped by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/world/contact_log.hpp"
#include "variational_formation/world/mjcf_model.hpp"
#include "variational_formation/world/mujoco_world.hpp"
#include "variational_formation/world/step_response.hpp"

namespace vf {
namespace {

constexpr double kPi = 3.141592653589793;

WorldSettings settingsOf(WorldKinematics kinematics) {
  WorldSettings s;
  s.kinematics = kinematics;
  return s;
}

MujocoWorld worldOf(const WorldSettings& s, const std::vector<PlanarPose>& starts) {
  return MujocoWorld(buildWorldMjcf(s, starts), "test", static_cast<int>(starts.size()), s);
}

void runFor(MujocoWorld& world, double seconds) {
  const double end = world.time() + seconds;
  while (world.time() < end - 1e-9) world.step();
}

class StepResponseTest : public ::testing::TestWithParam<WorldKinematics> {};

// A cmd_vel step is followed within 5% once the rise time is over (the first time the speed is
// within 5% of the command), and stays so: no overshoot, droop or oscillation beyond 5%.
TEST_P(StepResponseTest, FollowsTheStepWithinFivePercentAfterTheRiseTime) {
  const WorldSettings s = settingsOf(GetParam());
  MujocoWorld world = worldOf(s, {PlanarPose{}});
  runFor(world, 0.2);  // settle on the floor
  const double command = 0.3, start = world.time();
  world.setCommand(0, command, 0.0, 0.0);
  double risen = -1.0, worstAfter = 0.0;
  while (world.time() - start < 3.0) {
    world.step();
    const double v = world.twist(0).linearX;
    if (risen < 0 && v >= 0.95 * command) risen = world.time() - start;
    if (risen >= 0) worstAfter = std::max(worstAfter, std::abs(v - command) / command);
  }
  const StepResponse r = measureStepResponse(s, command, 3.0);
  std::printf("%s: within 5%% from %.3f s; lag %.3f s, rise time (10-90%%) %.3f s; worst deviation afterwards "
              "%.2f%%; final %.4f m/s\n", kinematicsName(GetParam()).c_str(), risen, r.lag, r.riseTime,
              100 * worstAfter, r.final);
  ASSERT_GT(risen, 0.0);
  EXPECT_LT(risen, 0.5);
  EXPECT_LT(worstAfter, 0.05);
  EXPECT_GT(r.lag, s.timeStep);  // inertia: not instantaneous
  EXPECT_LT(r.lag, risen);
  EXPECT_NEAR(r.final, command, 0.01 * command);
  // The robot went straight: no turn, no drift sideways.
  EXPECT_NEAR(world.pose(0).heading, 0.0, 1e-3);
  EXPECT_NEAR(world.pose(0).y, 0.0, 1e-3);
}

INSTANTIATE_TEST_SUITE_P(Kinds, StepResponseTest,
                         ::testing::Values(WorldKinematics::Unicycle, WorldKinematics::Holonomic));

TEST(MujocoWorld, TurnsInPlace) {
  MujocoWorld world = worldOf(settingsOf(WorldKinematics::Unicycle), {{1.0, -2.0, 0.5}});
  runFor(world, 0.2);
  world.setCommand(0, 0.0, 0.0, 1.0);
  double turned = 0.0, previous = world.pose(0).heading, drift = 0.0;
  while (world.time() < 2.2) {
    world.step();
    const PlanarPose p = world.pose(0);
    turned += std::atan2(std::sin(p.heading - previous), std::cos(p.heading - previous));
    previous = p.heading;
    drift = std::max(drift, std::hypot(p.x - 1.0, p.y + 2.0));
  }
  std::printf("turned %.3f rad in 2 s at 1 rad/s; the axle moved up to %.2f mm\n", turned, 1000 * drift);
  // The wheels' and the caster's scrub load the servos, whose torque is proportional to their
  // speed error: the turn rate droops by some 12% below the command (doc/robots.md).
  EXPECT_GT(turned, 0.8 * 2.0);
  EXPECT_LT(turned, 2.0);
  EXPECT_LT(drift, 0.01);
  EXPECT_NEAR(world.twist(0).angularZ, 1.0, 0.15);
}

TEST(MujocoWorld, CommandsBeyondTheMotorLimitsSaturate) {
  const WorldSettings s = settingsOf(WorldKinematics::Unicycle);
  MujocoWorld world = worldOf(s, {PlanarPose{}});
  runFor(world, 0.2);
  // 5 m/s asks 152 rad/s of the wheels: scaled into max_wheel_speed, torques at their limit.
  EXPECT_TRUE(world.setCommand(0, 5.0, 0.0, 0.0));
  world.step();
  for (double f : world.actuatorForces(0)) EXPECT_DOUBLE_EQ(f, s.drive.maxWheelTorque);
  const double start = world.time(), topSpeed = s.drive.maxWheelSpeed * s.drive.wheelRadius;
  double worstTorque = 0.0, halfway = -1.0, v = 0.0;
  while (world.time() < 3.0) {
    world.step();
    v = world.twist(0).linearX;
    if (halfway < 0 && v >= 0.5 * topSpeed) halfway = world.time() - start;
    for (double f : world.actuatorForces(0)) worstTorque = std::max(worstTorque, std::abs(f));
  }
  std::printf("saturated: worst torque %.4f N m, half the top speed after %.3f s, final %.4f m/s (limit %.4f)\n",
              worstTorque, halfway, v, topSpeed);
  EXPECT_LE(worstTorque, s.drive.maxWheelTorque * (1 + 1e-12));
  // Two wheels at the torque limit cannot push 1 kg harder than 2 tau / (r m) on average.
  ASSERT_GT(halfway, 0.0);
  EXPECT_LT(0.5 * topSpeed / halfway, 2.0 * s.drive.maxWheelTorque / (s.drive.wheelRadius * s.mass));
  EXPECT_NEAR(v, topSpeed, 0.05 * topSpeed);
  // Within the limits nothing is scaled.
  EXPECT_FALSE(world.setCommand(0, 0.5, 0.0, 1.0));
  // A holonomic base: the speed is scaled into max_speed, the servo force held at max_force.
  const WorldSettings b = settingsOf(WorldKinematics::Holonomic);
  MujocoWorld base = worldOf(b, {PlanarPose{}});
  EXPECT_TRUE(base.setCommand(0, 3.0, 4.0, 0.0));
  base.step();
  EXPECT_DOUBLE_EQ(base.actuatorForces(0)[0], b.base.maxForce);
  runFor(base, 3.0);
  EXPECT_NEAR(base.twist(0).linearX, 0.6 * b.base.maxSpeed, 0.02);
  EXPECT_NEAR(base.twist(0).linearY, 0.8 * b.base.maxSpeed, 0.02);
}

class HeadOnTest : public ::testing::TestWithParam<WorldKinematics> {};

// Two robots driven into each other: one contact, between them, and bodies that do not pass
// through each other (the kinematic world would let them).
TEST_P(HeadOnTest, RegistersTheContactAndDoesNotInterpenetrate) {
  const WorldSettings s = settingsOf(GetParam());
  const bool unicycle = GetParam() == WorldKinematics::Unicycle;
  MujocoWorld world = worldOf(s, {{-0.5, 0.0, 0.0}, {0.5, 0.0, unicycle ? kPi : 0.0}});
  double closest = 1e9;
  std::vector<ContactEvent> events;
  while (world.time() < 4.0) {
    world.setCommand(0, 0.5, 0.0, 0.0);
    world.setCommand(1, unicycle ? 0.5 : -0.5, 0.0, 0.0);  // forwards, towards robot_0
    world.step();
    events.insert(events.end(), world.newContacts().begin(), world.newContacts().end());
    const PlanarPose a = world.pose(0), b = world.pose(1);
    // A unicycle's body is centred 0.4 radius behind its axle.
    const double offset = unicycle ? 0.4 * s.bodyRadius : 0.0;
    closest = std::min(closest, std::hypot(a.x - offset * std::cos(a.heading) - b.x + offset * std::cos(b.heading),
                                           a.y - offset * std::sin(a.heading) - b.y + offset * std::sin(b.heading)));
  }
  const ContactLog& log = world.contacts();
  std::printf("%s: %ld contacts, first %s; deepest %.2f mm, force up to %.1f N; closest centres %.4f m\n",
              kinematicsName(GetParam()).c_str(), log.count(), log.resultLines().c_str(),
              1000 * log.maxPenetration(), log.maxNormalForce(), closest);
  ASSERT_GE(log.count(), 1);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.front().first, "robot_0");
  EXPECT_EQ(events.front().second, "robot_1");
  ASSERT_TRUE(log.first().has_value());
  // 1 m apart, 0.21 m of bodies (less the unicycles' offsets), closing at 1 m/s after the lag.
  EXPECT_GT(log.first()->time, 0.5);
  EXPECT_LT(log.first()->time, 1.2);
  EXPECT_GT(log.maxNormalForce(), 0.0);
  EXPECT_LE(log.maxPenetration(), 0.01);
  EXPECT_GE(closest, 2.0 * s.bodyRadius - 0.01);
  EXPECT_EQ(log.active(), 1u);  // still pressed together at the end
}

INSTANTIATE_TEST_SUITE_P(Kinds, HeadOnTest, ::testing::Values(WorldKinematics::Unicycle, WorldKinematics::Holonomic));

// A robot driven into each kind of the scenario's obstacles (a disc, then a box) registers one
// contact with it and stops at its surface: no more than 1 cm inside it.
class ObstacleContactTest : public ::testing::TestWithParam<WorldKinematics> {};

TEST_P(ObstacleContactTest, RegistersTheContactAndDoesNotInterpenetrate) {
  const WorldSettings s = settingsOf(GetParam());
  const bool unicycle = GetParam() == WorldKinematics::Unicycle;
  StaticObstacle disc;  // centre 1 m ahead on x
  disc.x = 1.0;
  disc.radius = 0.2;
  StaticObstacle box;  // a wall 1 m ahead on y, from x = -1 to 1
  box.shape = StaticObstacle::Shape::Box;
  box.y = 1.1;
  box.halfX = 1.0;
  box.halfY = 0.1;
  for (int k : {0, 1}) {
    const bool towardsBox = k == 1;
    const double heading = towardsBox ? 0.5 * kPi : 0.0;
    // The obstacle in the model is obstacle_k: the disc alone first, then the box after a far-off disc.
    std::vector<StaticObstacle> obstacles = {disc, box};
    if (towardsBox) obstacles[0].x = 10.0;
    else obstacles.pop_back();
    MujocoWorld world(buildWorldMjcf(s, {{0.0, 0.0, unicycle ? heading : 0.0}}, obstacles), "test", 1, s);
    double deepest = 0.0;  // how far the body's edge went past the obstacle's surface [m]
    while (world.time() < 4.0) {
      if (unicycle) world.setCommand(0, 0.5, 0.0, 0.0);
      else world.setCommand(0, towardsBox ? 0.0 : 0.5, towardsBox ? 0.5 : 0.0, 0.0);
      world.step();
      const BodyOutline b = world.bodyOutline(0);
      const double gap = towardsBox ? (box.y - box.halfY) - (b.y + b.radius)
                                    : std::hypot(b.x - disc.x, b.y) - disc.radius - b.radius;
      deepest = std::max(deepest, -gap);
    }
    const ContactLog& log = world.contacts();
    std::printf("%s into the %s: %ld contacts, %s; deepest %.2f mm (MuJoCo), %.2f mm (body), force up to %.1f N\n",
                kinematicsName(GetParam()).c_str(), towardsBox ? "box" : "disc", log.count(),
                log.resultLines().c_str(), 1000 * log.maxPenetration(), 1000 * deepest, log.maxNormalForce());
    EXPECT_EQ(log.count(), 1) << k;
    ASSERT_TRUE(log.first().has_value());
    EXPECT_EQ(log.first()->first, "robot_0");
    EXPECT_EQ(log.first()->second, "obstacle_" + std::to_string(k));
    EXPECT_GT(log.maxNormalForce(), 0.0);
    EXPECT_LE(log.maxPenetration(), 0.01);
    EXPECT_LE(deepest, 0.01);
    EXPECT_EQ(log.active(), 1u);  // still pushing at the end
    // Where they touch: on the obstacle's surface, in front of the robot.
    ASSERT_EQ(world.touches().size(), 1u);
    const Touch& t = world.touches().front();
    if (towardsBox) EXPECT_NEAR(t.y, box.y - box.halfY, 0.01);
    else EXPECT_NEAR(std::hypot(t.x - disc.x, t.y), disc.radius, 0.01);
  }
}

INSTANTIATE_TEST_SUITE_P(Kinds, ObstacleContactTest,
                         ::testing::Values(WorldKinematics::Unicycle, WorldKinematics::Holonomic));

// Wheel odometry knows only the wheel angles: on a curving drive it leaves the true pose, more
// the further the robot goes. Ground truth is the body's pose: integrating its own velocity
// gives it back (to the integration error), however far it goes.
TEST(MujocoWorld, WheelOdometryDriftsAndGroundTruthDoesNot) {
  MujocoWorld world = worldOf(settingsOf(WorldKinematics::Unicycle), {{0.0, 0.0, 0.0}});
  runFor(world, 0.2);
  PlanarPose integrated = world.pose(0);
  double headingErrorAt2 = -1.0, truthError = 0.0;
  world.setCommand(0, 0.3, 0.0, 1.0);
  while (world.time() < 10.2) {
    const BaseTwist v = world.twist(0);
    const double heading = world.pose(0).heading, dt = world.settings().timeStep;
    world.step();
    integrated.x += dt * (v.linearX * std::cos(heading) - v.linearY * std::sin(heading));
    integrated.y += dt * (v.linearX * std::sin(heading) + v.linearY * std::cos(heading));
    const PlanarPose truth = world.pose(0);
    truthError = std::max(truthError, std::hypot(truth.x - integrated.x, truth.y - integrated.y));
    if (headingErrorAt2 < 0 && world.time() >= 2.2) {
      headingErrorAt2 = std::abs(std::remainder(world.wheelOdometry(0).heading - truth.heading, 2 * kPi));
    }
  }
  const PlanarPose truth = world.pose(0), odometry = world.wheelOdometry(0);
  const double odometryError = std::hypot(odometry.x - truth.x, odometry.y - truth.y);
  const double headingError = std::abs(std::remainder(odometry.heading - truth.heading, 2 * kPi));
  std::printf("after 10 s on a circle: wheel odometry %.1f mm and %.3f rad off (%.3f rad after 2 s); ground truth "
              "against its integrated velocity: %.3f mm\n", 1000 * odometryError, headingError, headingErrorAt2,
              1000 * truthError);
  EXPECT_GT(odometryError, 0.01);
  // Most of the heading error comes from the wheels slipping as they spin up, and it stays.
  EXPECT_GT(headingErrorAt2, 0.01);
  EXPECT_GT(headingError, 0.01);
  EXPECT_LT(truthError, 0.002);
  EXPECT_THROW(worldOf(settingsOf(WorldKinematics::Holonomic), {PlanarPose{}}).wheelOdometry(0), InvalidInput);
}

TEST(MujocoWorld, BadCommandsAreRefusedAndLeaveTheCommand) {
  MujocoWorld world = worldOf(settingsOf(WorldKinematics::Unicycle), {PlanarPose{}});
  world.setCommand(0, 0.2, 0.0, 0.0);
  EXPECT_THROW(world.setCommand(0, NAN, 0.0, 0.0), InvalidInput);
  EXPECT_THROW(world.setCommand(1, 0.0, 0.0, 0.0), InvalidInput);
  runFor(world, 1.0);
  EXPECT_NEAR(world.twist(0).linearX, 0.2, 0.01);
}

TEST(ContactLog, APairPressedTogetherIsOneContactUntilApart) {
  ContactLog log(2);
  EXPECT_EQ(log.resultLines(), "contacts: 0\nfirst_contact: ~\n");
  EXPECT_EQ(log.record(0.5, {{0, 1, 3.0, 0.001}}).size(), 1u);
  EXPECT_TRUE(log.record(0.502, {}).empty());               // flickers off
  EXPECT_TRUE(log.record(0.504, {{0, 1, 2.0, 0.002}}).empty());  // and on: the same contact
  EXPECT_EQ(log.record(0.7, {{1, 2, 1.0, 0.0}}).size(), 1u);  // robot_1 and obstacle_0
  EXPECT_EQ(log.record(0.9, {{0, 1, 1.0, 0.0}}).size(), 1u);  // apart for 0.4 s: a new one
  EXPECT_EQ(log.count(), 3);
  EXPECT_EQ(log.active(), 1u);
  EXPECT_DOUBLE_EQ(log.maxPenetration(), 0.002);
  EXPECT_DOUBLE_EQ(log.maxNormalForce(), 3.0);
  EXPECT_EQ(log.resultLines(), "contacts: 3\nfirst_contact: \"t = 0.5 s, robot_0 and robot_1\"\n");
  EXPECT_EQ(log.participantName(2), "obstacle_0");
}

}  // namespace
}  // namespace vf

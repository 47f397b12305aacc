// The MJCF model of a scenario's world (world/mjcf_model.hpp) and its settings
// (world/world_settings.hpp): MuJoCo accepts it, the robots are where robot_sim starts them,
// and bad input is refused with one line naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include <mujoco/mujoco.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/robots/unicycle_command.hpp"
#include "variational_formation_core/model/scenario.hpp"
#include "variational_formation/world/mjcf_model.hpp"
#include "variational_formation/world/mujoco_world.hpp"

namespace vf {
namespace {

// The one-line message of the InvalidInput that f throws ("no error" if none).
template <typename F>
std::string errorOf(F&& f) {
  try {
    return f(), "no error";
  } catch (const InvalidInput& e) {
    return e.what();
  }
}

Scenario hexagon() { return loadScenario(std::string(VF_SOURCE_DIR) + "/config/hexagon.yaml"); }

WorldSettings settingsOf(WorldKinematics kinematics) {
  WorldSettings s;
  s.kinematics = kinematics;
  return s;
}

// mj_loadXML on the text (through a file, as a user's model would come), then a check by `f`.
template <typename F>
void withModel(const std::string& mjcf, F&& f) {
  const std::string path = ::testing::TempDir() + "/vf_world_model.xml";
  FILE* out = std::fopen(path.c_str(), "w");
  ASSERT_NE(out, nullptr);
  std::fputs(mjcf.c_str(), out);
  std::fclose(out);
  char error[1000] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  ASSERT_NE(model, nullptr) << error;
  mjData* data = mj_makeData(model);
  mj_forward(model, data);
  f(model, data);
  mj_deleteData(data);
  mj_deleteModel(model);
}

TEST(MjcfModel, HolonomicBasesStandAtTheInitialPositions) {
  const Scenario s = hexagon();
  const WorldSettings settings = settingsOf(WorldKinematics::Holonomic);
  const std::vector<PlanarPose> starts = worldStartPoses(s, settings, 0);
  ASSERT_EQ(starts.size(), 6u);
  withModel(buildWorldMjcf(settings, starts), [&](const mjModel* m, const mjData* d) {
    EXPECT_EQ(m->opt.timestep, 0.002);
    EXPECT_EQ(m->nu, 18);  // x, y, yaw per robot
    for (int i = 0; i < 6; ++i) {
      const int body = mj_name2id(m, mjOBJ_BODY, ("robot_" + std::to_string(i)).c_str());
      ASSERT_GE(body, 0) << i;
      EXPECT_NEAR(d->xpos[3 * body], s.initialPositions(0, i), 1e-12);
      EXPECT_NEAR(d->xpos[3 * body + 1], s.initialPositions(1, i), 1e-12);
      EXPECT_NEAR(m->body_subtreemass[body], 1.0, 1e-12);
    }
    EXPECT_LT(mj_name2id(m, mjOBJ_BODY, "robot_6"), 0);
  });
}

TEST(MjcfModel, UnicyclesHaveTheirHandPointsAtTheInitialPositions) {
  const Scenario s = hexagon();
  WorldSettings settings = settingsOf(WorldKinematics::Unicycle);
  settings.handOffset = 0.15;
  const std::vector<PlanarPose> starts = worldStartPoses(s, settings, 7);
  withModel(buildWorldMjcf(settings, starts), [&](const mjModel* m, const mjData* d) {
    EXPECT_EQ(m->nu, 12);  // two wheels per robot
    for (int i = 0; i < 6; ++i) {
      const std::string name = "robot_" + std::to_string(i);
      const int body = mj_name2id(m, mjOBJ_BODY, name.c_str());
      ASSERT_GE(body, 0);
      const double heading = drawInitialHeading(7, i);  // as robot_sim draws it
      const double* q = d->xquat + 4 * body;
      EXPECT_NEAR(std::atan2(2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] * q[2] + q[3] * q[3])), heading, 1e-9);
      EXPECT_NEAR(d->xpos[3 * body] + 0.15 * std::cos(heading), s.initialPositions(0, i), 1e-9);
      EXPECT_NEAR(d->xpos[3 * body + 1] + 0.15 * std::sin(heading), s.initialPositions(1, i), 1e-9);
      EXPECT_NEAR(d->xpos[3 * body + 2], 0.033, 1e-12);  // the axle at wheel height
      EXPECT_NEAR(m->body_subtreemass[body], 1.0, 1e-12);
      for (const char* part : {"_left_wheel", "_right_wheel"}) {
        EXPECT_GE(mj_name2id(m, mjOBJ_JOINT, (name + part).c_str()), 0) << name << part;
        const int actuator = mj_name2id(m, mjOBJ_ACTUATOR, (name + part).c_str());
        ASSERT_GE(actuator, 0) << name << part;
        EXPECT_EQ(m->actuator_forcerange[2 * actuator + 1], 0.1);  // the torque limit
      }
    }
  });
}

TEST(MjcfModel, ObstaclesAreStaticGeomsNamedInOrder) {
  const WorldSettings settings = settingsOf(WorldKinematics::Holonomic);
  withModel(buildWorldMjcf(settings, {PlanarPose{}}, {{1.0, 2.0, 0.3, 0.5}, {-1.0, 0.0, 0.2, 0.4}}),
            [&](const mjModel* m, const mjData* d) {
              const int g = mj_name2id(m, mjOBJ_GEOM, "obstacle_1");
              ASSERT_GE(g, 0);
              EXPECT_EQ(m->geom_bodyid[g], 0);  // the world body: static
              EXPECT_NEAR(d->geom_xpos[3 * g], -1.0, 1e-12);
              EXPECT_NEAR(m->geom_size[3 * g], 0.2, 1e-12);
              EXPECT_GE(mj_name2id(m, mjOBJ_GEOM, "obstacle_0"), 0);
            });
  EXPECT_EQ(errorOf([&] { buildWorldMjcf(settings, {PlanarPose{}}, {{0.0, 0.0, 0.0, 1.0}}); }),
            "obstacles[0].radius: must be finite and > 0 m, got 0");
}

// The scenario's obstacles (the safety filter's, core/safety.hpp) are the world's: a disc a
// cylinder, a box a box of the same extent, a point a thin post, numbered as the scenario lists them.
TEST(MjcfModel, TheScenariosObstaclesBecomeStaticGeoms) {
  const Scenario s = parseScenario(R"(
name: obstacles
dimension: 2
kappa: 2
time_step: 0.02
steps: 10
agents:
  - {id: 0, initial_position: [0, 0], desired_position: [0, 0]}
  - {id: 1, initial_position: [1, 0], desired_position: [1, 0]}
edges: [[0, 1]]
safety: {radius: 0.25, sensing_radius: 1, gamma: 0.2}
obstacles:
  - {center: [2.0, -1.5], radius: 0.3}
  - {min: [-3.0, 1.0], max: [-1.0, 1.5]}
  - {center: [0.5, 2.0], radius: 0}
)", "obstacles.yaml");
  const std::vector<StaticObstacle> obstacles = worldObstacles(s);
  ASSERT_EQ(obstacles.size(), 3u);
  const WorldSettings settings = settingsOf(WorldKinematics::Unicycle);
  withModel(buildWorldMjcf(settings, worldStartPoses(s, settings, 0), obstacles),
            [&](const mjModel* m, const mjData* d) {
              const int disc = mj_name2id(m, mjOBJ_GEOM, "obstacle_0");
              const int box = mj_name2id(m, mjOBJ_GEOM, "obstacle_1");
              const int post = mj_name2id(m, mjOBJ_GEOM, "obstacle_2");
              ASSERT_GE(disc, 0);
              ASSERT_GE(box, 0);
              ASSERT_GE(post, 0);
              EXPECT_LT(mj_name2id(m, mjOBJ_GEOM, "obstacle_3"), 0);
              for (int g : {disc, box, post}) {
                EXPECT_EQ(m->geom_bodyid[g], 0) << g;  // the world body: static
                // Standing on the floor, 0.3 m high: taller than the robots' bodies.
                EXPECT_NEAR(d->geom_xpos[3 * g + 2], 0.15, 1e-12);
                // As stiff as the robots' bodies (not MuJoCo's default time constant of 0.02 s).
                EXPECT_EQ(m->geom_solref[2 * g], 0.005);
              }
              EXPECT_EQ(m->geom_type[disc], mjGEOM_CYLINDER);
              EXPECT_NEAR(d->geom_xpos[3 * disc], 2.0, 1e-12);
              EXPECT_NEAR(d->geom_xpos[3 * disc + 1], -1.5, 1e-12);
              EXPECT_NEAR(m->geom_size[3 * disc], 0.3, 1e-12);
              EXPECT_EQ(m->geom_type[box], mjGEOM_BOX);
              EXPECT_NEAR(d->geom_xpos[3 * box], -2.0, 1e-12);
              EXPECT_NEAR(d->geom_xpos[3 * box + 1], 1.25, 1e-12);
              EXPECT_NEAR(m->geom_size[3 * box], 1.0, 1e-12);
              EXPECT_NEAR(m->geom_size[3 * box + 1], 0.25, 1e-12);
              EXPECT_EQ(m->geom_type[post], mjGEOM_CYLINDER);
              EXPECT_NEAR(m->geom_size[3 * post], kMinObstacleHalfWidth, 1e-15);
            });
  // The world counts contacts with them as obstacle_0, obstacle_1, ... after the robots.
  const MujocoWorld world(buildWorldMjcf(settings, worldStartPoses(s, settings, 0), obstacles), "obstacles", 2,
                          settings);
  ASSERT_EQ(world.obstacleGeoms().size(), 3u);
  EXPECT_EQ(world.obstacleGeoms()[1].type, ObstacleGeom::Type::Box);
  EXPECT_NEAR(world.obstacleGeoms()[1].size[1], 0.25, 1e-12);
  StaticObstacle flat;
  flat.shape = StaticObstacle::Shape::Box;
  flat.halfX = 1.0;
  EXPECT_EQ(errorOf([&] { buildWorldMjcf(settings, {PlanarPose{}}, {flat}); }),
            "obstacles[0].half_y: must be finite and > 0 m, got 0");
  EXPECT_TRUE(worldObstacles(hexagon()).empty());
}

TEST(MjcfModel, ThreeDimensionalScenariosAreRefused) {
  const Scenario s = loadScenario(std::string(VF_SOURCE_DIR) + "/config/tetrahedron.yaml");
  EXPECT_EQ(errorOf([&] { worldStartPoses(s, WorldSettings{}, 0); }),
            "dimension: the MuJoCo world is planar (robots on a floor), got 3");
}

TEST(MjcfModel, BadSettingsAreRefusedByName) {
  struct Case {
    const char* name;
    double value;
    WorldKinematics kinematics;
    const char* error;
  };
  const Case cases[] = {
      {"time_step", 0.0, WorldKinematics::Holonomic, "time_step: must be finite and in [1e-06, 0.05] s, got 0"},
      {"time_step", 0.1, WorldKinematics::Unicycle, "time_step: must be finite and in [1e-06, 0.05] s, got 0.1"},
      {"real_time_factor", -1.0, WorldKinematics::Holonomic, "real_time_factor: must be finite and >= 0, got -1"},
      {"friction", NAN, WorldKinematics::Unicycle, "friction: must be finite and in [1e-06, 10], got nan"},
      {"mass", 0.0, WorldKinematics::Holonomic, "mass: must be finite and > 0 kg, got 0"},
      {"wheel_radius", -0.033, WorldKinematics::Unicycle, "wheel_radius: must be finite and > 0 m, got -0.033"},
      {"track", 0.3, WorldKinematics::Unicycle, "track: must be < 2 body_radius = 0.21 m, got 0.3"},
      {"max_wheel_torque", INFINITY, WorldKinematics::Unicycle,
       "max_wheel_torque: must be finite and > 0 N m, got inf"},
      {"wheel_armature", -1e-4, WorldKinematics::Unicycle, "wheel_armature: must be finite and >= 0 kg m^2, got -1e-04"},
      {"max_force", 0.0, WorldKinematics::Holonomic, "max_force: must be finite and > 0 N, got 0"},
  };
  for (const Case& c : cases) {
    WorldSettings s = settingsOf(c.kinematics);
    setWorldParameter(s, c.name, c.value);
    EXPECT_EQ(errorOf([&] { buildWorldMjcf(s, {PlanarPose{}}); }), c.error) << c.name;
  }
  // A drive's constants do not concern a holonomic base.
  WorldSettings base = settingsOf(WorldKinematics::Holonomic);
  setWorldParameter(base, "track", 1.0);
  EXPECT_NO_THROW(validateWorldSettings(base));
  EXPECT_EQ(errorOf([&] { setWorldParameter(base, "wheel_size", 1.0); }),
            "wheel_size: not a parameter of the MuJoCo world");
  EXPECT_EQ(errorOf([] { parseWorldKinematics("legged"); }), "kinematics: expected holonomic or unicycle, got 'legged'");
  EXPECT_EQ(errorOf([] { buildWorldMjcf(WorldSettings{}, {}); }), "robots: a world needs at least one robot");
  EXPECT_EQ(errorOf([] { buildWorldMjcf(WorldSettings{}, {PlanarPose{}, {NAN, 0.0, 0.0}}); }),
            "robot_1: start pose must be finite, got (nan, 0, 0)");
}

TEST(MjcfModel, UserModelsMustNameTheirRobots) {
  const WorldSettings settings = settingsOf(WorldKinematics::Holonomic);
  const std::string two = buildWorldMjcf(settings, {PlanarPose{}, {1.0, 0.0, 0.0}});
  EXPECT_NO_THROW(MujocoWorld(two, "two.xml", 2, settings));
  EXPECT_EQ(errorOf([&] { MujocoWorld(two, "two.xml", 3, settings); }), "model: two.xml: no body named robot_2");
  // Wheels are not a holonomic base's joints.
  EXPECT_EQ(errorOf([&] { MujocoWorld(two, "two.xml", 2, settingsOf(WorldKinematics::Unicycle)); }),
            "model: two.xml: unicycle robot robot_0 needs a joint and an actuator named robot_0_left_wheel");
  const std::string broken = errorOf([] { MujocoWorld("<mujoco><worldbody>", "bad.xml", 1, WorldSettings{}); });
  EXPECT_EQ(broken.rfind("model: bad.xml: ", 0), 0u) << broken;
  EXPECT_EQ(broken.find('\n'), std::string::npos) << broken;
  const std::string missing = errorOf([] { MujocoWorld::fromFile("/nonexistent/world.xml", 1, WorldSettings{}); });
  EXPECT_EQ(missing.rfind("model: /nonexistent/world.xml: ", 0), 0u) << missing;
}

}  // namespace
}  // namespace vf

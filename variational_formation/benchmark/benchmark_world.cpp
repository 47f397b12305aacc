// The MuJoCo world's real-time factor (doc/robots.md, "The MuJoCo world"): N robots on a grid
// 2 m apart, each driving a circle (0.3 m/s, 0.5 rad/s; holonomic bases one straight line each),
// stepped for 10 simulated seconds with the world's defaults, through the shipped MujocoWorld
// and the per-step work of mujoco_world (contacts; poses, velocities and joints at 100 Hz).
// usage: benchmark_world [--kinematics unicycle|holonomic] [--time_step S] N...
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "variational_formation/world/mjcf_model.hpp"
#include "variational_formation/world/mujoco_world.hpp"

int main(int argc, char** argv) {
  vf::WorldSettings settings;
  settings.kinematics = vf::WorldKinematics::Unicycle;
  std::vector<int> counts;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--kinematics" && a + 1 < argc) settings.kinematics = vf::parseWorldKinematics(argv[++a]);
    else if (arg == "--time_step" && a + 1 < argc) settings.timeStep = std::atof(argv[++a]);
    else counts.push_back(std::atoi(argv[a]));
  }
  const double seconds = 10.0;
  for (int n : counts) {
    std::vector<vf::PlanarPose> starts;
    const int side = static_cast<int>(std::ceil(std::sqrt(n)));
    for (int i = 0; i < n; ++i) starts.push_back({2.0 * (i % side), 2.0 * (i / side), 0.1 * i});  // circles of 0.6 m never meet
    vf::MujocoWorld world(vf::buildWorldMjcf(settings, starts), "benchmark", n, settings);
    for (int i = 0; i < n; ++i) {
      if (settings.kinematics == vf::WorldKinematics::Unicycle) world.setCommand(i, 0.3, 0.0, 0.5);
      else world.setCommand(i, 0.3, 0.1, 0.0);  // all alike: they never meet
    }
    const auto start = std::chrono::steady_clock::now();
    double nextPublish = 0.0, sink = 0.0;
    while (world.time() < seconds) {
      world.step();
      if (world.time() >= nextPublish) {
        nextPublish += 0.01;
        for (int i = 0; i < n; ++i) sink += world.pose(i).x + world.twist(i).linearX + world.joints(i).position[0];
      }
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%s, %d robots, time step %g s: %.2f simulated s per wall s (%.3f ms per step), %ld contacts%s\n",
                vf::kinematicsName(settings.kinematics).c_str(), n, settings.timeStep, seconds / wall,
                1000.0 * wall * settings.timeStep / seconds, world.contacts().count(), std::isfinite(sink) ? "" : "?");
  }
  return 0;
}

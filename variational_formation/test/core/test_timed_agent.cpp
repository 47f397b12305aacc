// TimedAgent: the time-driven agent. With every neighbour fresh it is the centralised run bit for
// bit; it holds while a neighbour is silent and resumes from rest; in robot mode it starts from
// the measured position without dividing the measurement noise by h.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test_support.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/manoeuvres/manoeuvre_integrator.hpp"
#include "variational_formation_core/robots/point_robot.hpp"
#include "variational_formation_core/common/standard_normal.hpp"
#include "variational_formation_core/agents/timed_agent.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {
namespace {

constexpr double kMaxAge = 0.5;  // [s]

std::vector<TimedAgent> makeAgents(const Scenario& s) {
  std::vector<TimedAgent> agents;
  for (int i = 0; i < s.agentCount(); ++i) agents.emplace_back(s, i, kMaxAge);
  return agents;
}

/// Every agent's current state to each of its neighbours, received at `now`, except from `silent`.
void exchange(std::vector<TimedAgent>& agents, double now, int silent = -1) {
  for (const TimedAgent& from : agents) {
    if (from.id() == silent) continue;
    for (TimedAgent& to : agents) {
      for (int j : to.neighbourIds()) {
        if (j != from.id()) continue;
        ASSERT_EQ(to.receive(from.id(), from.step(), from.position(), from.previousPosition(), now),
                  TimedAgent::Receipt::Accepted);
      }
    }
  }
}

std::vector<Positions> reference(const Scenario& s) {
  const Formation f = makeFormation(s);  // the integrator keeps a reference
  VariationalIntegrator vi(f, s.initialPositions, s.initialVelocities, s.timeStep,
                           s.dampingGain, StartMethod::Variational);
  std::vector<Positions> trajectory{vi.positions()};
  for (long k = 0; k < s.steps; ++k) {
    vi.step();
    trajectory.push_back(vi.positions());
  }
  return trajectory;
}

/// Synchronous loop: tick k uses the others' states of tick k - 1; positions must equal `expected`.
void expectSynchronousRunEquals(std::vector<TimedAgent>& agents, const std::vector<Positions>& expected,
                                const std::string& name) {
  const double period = agents[0].timeStep();
  for (std::size_t k = 1; k < expected.size(); ++k) {
    exchange(agents, static_cast<double>(k - 1) * period);
    for (TimedAgent& a : agents) {
      const TimedAgent::TickResult r = a.tick(static_cast<double>(k) * period);
      ASSERT_FALSE(r.holding) << name << " step " << k;
      ASSERT_EQ(r.step, static_cast<long>(k));
    }
    for (const TimedAgent& a : agents) {
      for (int c = 0; c < static_cast<int>(a.position().size()); ++c) {
        ASSERT_EQ(a.position()[c], expected[k](c, a.id())) << name << " agent " << a.id() << " step " << k;
      }
    }
  }
}

TEST(TimedAgent, FreshNeighboursReproduceTheCentralisedRunBitForBit) {
  for (const char* name : {"hexagon", "tetrahedron", "grid24", "free_particle"}) {
    Scenario s = loadScenario(test::configPath(name));
    s.steps = std::min<long>(s.steps, 400);
    std::vector<TimedAgent> agents = makeAgents(s);
    expectSynchronousRunEquals(agents, reference(s), name);
    EXPECT_EQ(agents[0].dropped(), 0);
  }
}

TEST(TimedAgent, ACommandAtTheNextTickIsTheCentralisedRunUnderThatCommandBitForBit) {
  Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));
  s.manoeuvre.clear();
  s.steps = 400;
  const Command c = test::command({0.4, -0.2, 0}, {0, 0, 0.3}, 1.3);
  // Set before the first tick: from step 0 on.
  CommandSchedule fromStart;
  fromStart.add(0, c);
  std::vector<TimedAgent> agents = makeAgents(s);
  for (TimedAgent& a : agents) a.setCommand(c);
  EXPECT_EQ(agents[0].command(), c);
  expectSynchronousRunEquals(agents, test::manoeuvreTrajectory(s, fromStart), "command from step 0");
  // Set after tick 150: from step 150 on (the node gains join the two commands there).
  CommandSchedule later;
  later.add(150, c);
  const std::vector<Positions> expected = test::manoeuvreTrajectory(s, later);
  std::vector<TimedAgent> second = makeAgents(s);
  expectSynchronousRunEquals(second, {expected.begin(), expected.begin() + 151}, "before the command");
  for (TimedAgent& a : second) a.setCommand(c);
  const double period = second[0].timeStep();
  for (std::size_t k = 151; k < expected.size(); ++k) {
    exchange(second, static_cast<double>(k - 1) * period);
    for (TimedAgent& a : second) a.tick(static_cast<double>(k) * period);
    for (const TimedAgent& a : second) {
      for (int d = 0; d < 2; ++d) ASSERT_EQ(a.position()[d], expected[k](d, a.id())) << "step " << k;
    }
  }
}

TEST(TimedAgent, TheScenarioManoeuvreRunsByTheAgentsOwnStepUntilACommandReplacesIt) {
  Scenario s = loadScenario(test::configPath("hexagon_manoeuvre"));
  s.steps = 900;
  std::vector<TimedAgent> agents = makeAgents(s);
  expectSynchronousRunEquals(agents, test::manoeuvreTrajectory(s, scheduleFromSegments(s.manoeuvre, s.timeStep)),
                             "hexagon_manoeuvre");
}

TEST(TimedAgent, BadCommandsAreRefusedAndLeaveTheCommand) {
  Scenario s = loadScenario(test::configPath("hexagon"));
  TimedAgent a(s, 0, kMaxAge);
  EXPECT_THROW(a.setCommand(test::command({NAN, 0, 0}, {0, 0, 0}, 1.0)), InvalidInput);
  EXPECT_THROW(a.setCommand(test::command({0, 0, 1.0}, {0, 0, 0}, 1.0)), InvalidInput);
  EXPECT_THROW(a.setCommand(test::command({0, 0, 0}, {0, 0, 0}, 0.0)), InvalidInput);
  EXPECT_EQ(a.command(), Command{});
}

TEST(TimedAgent, DampingGainSetBeforeTheRunGivesThatRunBitForBit) {
  Scenario s = loadScenario(test::configPath("hexagon"));
  std::vector<TimedAgent> agents = makeAgents(s);
  for (TimedAgent& a : agents) a.setDampingGain(5.0);
  s.dampingGain = 5.0;
  expectSynchronousRunEquals(agents, reference(s), "hexagon kappa 5");
  // The scenario's check of kappa (validateDynamics), also its upper end: at h = 0.014, kappa 1e6
  // would underflow e^{-kappa h} and freeze the agent.
  for (double bad : {-1.0, std::nan(""), HUGE_VAL, 1e6}) EXPECT_THROW(agents[0].setDampingGain(bad), InvalidInput);
  EXPECT_EQ(agents[0].dampingGain(), 5.0);
  try {
    agents[0].setDampingGain(-0.5);
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "kappa: must be finite and >= 0, got -0.5");
  }
}

TEST(TimedAgent, HoldsUntilEveryNeighbourIsHeardThenStartsFromTheScenario) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  std::vector<TimedAgent> agents = makeAgents(s);
  TimedAgent& a = agents[0];
  const std::vector<double> q0 = a.position();
  TimedAgent::TickResult r = a.tick(0.0);
  EXPECT_TRUE(r.holding);
  EXPECT_EQ(r.step, 1);
  ASSERT_EQ(r.stale.size(), a.neighbourIds().size());
  for (const auto& n : r.stale) {
    EXPECT_FALSE(n.heard);
    EXPECT_TRUE(std::isinf(n.age));
  }
  EXPECT_EQ(a.position(), q0);
  exchange(agents, 0.01);
  r = a.tick(0.02);
  EXPECT_FALSE(r.holding);
  EXPECT_TRUE(r.stale.empty());
  // A deferred start is still the scenario's start: agent 0 of the reference at step 1.
  const std::vector<Positions> expected = reference(s);
  EXPECT_EQ(a.position()[0], expected[1](0, 0));
  EXPECT_EQ(a.position()[1], expected[1](1, 0));
  EXPECT_EQ(a.heldTicks(), 1);
}

TEST(TimedAgent, HoldsWhileANeighbourIsSilentAndResumesFromRestWhenItReturns) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  const Formation f = makeFormation(s);
  std::vector<TimedAgent> agents = makeAgents(s);
  const double period = s.timeStep;  // rate 1
  double now = 0.0;
  for (int k = 0; k < 20; ++k, now += period) {
    exchange(agents, now);
    for (TimedAgent& a : agents) ASSERT_FALSE(a.tick(now + period).holding);
  }
  // Agent 1 goes silent at `lastHeard`: agent 0 moves on with its newest state until it is older
  // than maxAge, then holds.
  const double lastHeard = now - period;
  TimedAgent& a = agents[0];
  long heldFrom = -1;
  for (int k = 0; heldFrom < 0; ++k, now += period) {
    ASSERT_LT(k, 100);
    exchange(agents, now, 1);
    const std::vector<double> before = a.position();
    const TimedAgent::TickResult r = a.tick(now + period);
    const bool expectHold = now + period - lastHeard > kMaxAge;
    ASSERT_EQ(r.holding, expectHold) << "tick at " << now + period;
    if (r.holding) {
      heldFrom = r.step;
      ASSERT_EQ(r.stale.size(), 1u);
      EXPECT_EQ(r.stale[0].id, 1);
      EXPECT_TRUE(r.stale[0].heard);
      EXPECT_DOUBLE_EQ(r.stale[0].age, now + period - lastHeard);
      EXPECT_EQ(a.position(), before);
      EXPECT_EQ(a.commandedVelocity(), std::vector<double>(2, 0.0));
    } else {
      EXPECT_NE(a.position(), before);
    }
    for (std::size_t i = 2; i < agents.size(); ++i) agents[i].tick(now + period);
  }
  const std::vector<double> heldAt = a.position();
  for (int k = 0; k < 10; ++k, now += period) {
    exchange(agents, now, 1);
    EXPECT_TRUE(a.tick(now + period).holding);
    EXPECT_EQ(a.position(), heldAt);
    for (std::size_t i = 2; i < agents.size(); ++i) agents[i].tick(now + period);
  }
  const auto status = a.neighbourStatus(now);
  EXPECT_TRUE(status[0].stale);  // neighbourIds() lists agent 1 first (edge [0, 1])
  EXPECT_EQ(status[0].id, 1);

  // Agent 1 respawns and counts from step 0 again: accepted, keyed by receive time.
  TimedAgent respawned(s, 1, kMaxAge);
  ASSERT_EQ(a.receive(1, 0, respawned.position(), respawned.previousPosition(), now),
            TimedAgent::Receipt::Accepted);
  // While fresh, an older step of it (a reordered message) is ignored.
  EXPECT_EQ(a.receive(1, 0, {9.0, 9.0}, {9.0, 9.0}, now), TimedAgent::Receipt::Outdated);
  for (std::size_t i = 2; i < agents.size(); ++i) {
    a.receive(static_cast<long>(i), agents[i].step(), agents[i].position(), agents[i].previousPosition(), now);
  }
  // The first move after a hold is the variational start from rest, from the newest positions.
  Positions view = Positions::Zero(2, s.agentCount());
  view.col(0) << heldAt[0], heldAt[1];
  view.col(1) = s.initialPositions.col(1);
  for (int j = 2; j < s.agentCount(); ++j) view.col(j) << agents[j].position()[0], agents[j].position()[1];
  double g[2];
  f.agentGradient(0, view, g);
  const VariationalCoefficients c(s.timeStep, s.dampingGain);
  const TimedAgent::TickResult r = a.tick(now + period);
  EXPECT_FALSE(r.holding);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(a.position()[i], heldAt[i] + c.startGain * (0.0 - 0.5 * c.timeStep * g[i]));
  }
  EXPECT_GT(heldFrom, 20);
}

TEST(TimedAgent, OlderAndMalformedStatesAreRefusedAndCounted) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  TimedAgent a(s, 0, kMaxAge);
  using R = TimedAgent::Receipt;
  const std::vector<double> ok{3.0, 0.0};
  EXPECT_EQ(a.receive(1, 5, ok, ok, 0.0), R::Accepted);
  EXPECT_EQ(a.receive(1, 3, {7.0, 7.0}, ok, 0.1), R::Outdated);
  EXPECT_EQ(a.receive(1, 5, ok, ok, 0.1), R::Outdated);
  EXPECT_EQ(a.receive(1, 9, {4.0, 0.0}, ok, 0.2), R::Accepted);  // steps may jump
  EXPECT_EQ(a.receive(0, 1, ok, ok, 0.2), R::UnknownSender);      // itself
  EXPECT_EQ(a.receive(6, 1, ok, ok, 0.2), R::UnknownSender);
  EXPECT_EQ(a.receive(2, 1, {1.0}, ok, 0.2), R::WrongDimension);
  EXPECT_EQ(a.receive(2, 1, {std::nan(""), 0.0}, ok, 0.2), R::NonFinite);
  EXPECT_EQ(a.receive(2, 1, ok, {HUGE_VAL, 0.0}, 0.2), R::NonFinite);
  EXPECT_EQ(a.receive(2, -1, ok, ok, 0.2), R::NegativeStep);
  EXPECT_EQ(a.accepted(), 2);
  EXPECT_EQ(a.dropped(), 8);
  const auto status = a.neighbourStatus(0.3);
  EXPECT_EQ(status[0].id, 1);
  EXPECT_EQ(status[0].step, 9);
  EXPECT_EQ(status[0].accepted, 2);
  EXPECT_EQ(status[0].dropped, 2);
  EXPECT_DOUBLE_EQ(status[0].age, 0.1);
  EXPECT_FALSE(status[0].stale);
  EXPECT_FALSE(status[2].heard);  // neighbour 2 (third in the list: edges [0,1], [5,0], [0,2])
  EXPECT_EQ(status[2].id, 2);
  EXPECT_EQ(status[2].dropped, 4);
  // Once silent for longer than maxAge, a lower step is accepted (a restarted neighbour).
  EXPECT_EQ(a.receive(1, 2, ok, ok, 0.2 + kMaxAge + 0.01), R::Accepted);
  EXPECT_THROW(TimedAgent(s, 6, kMaxAge), InvalidInput);
  for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) EXPECT_THROW(TimedAgent(s, 0, bad), InvalidInput);
}

/// The synchronous run in robot mode: each tick starts from measure(agent's setpoint).
template <class Measure>
std::vector<Positions> robotRun(const Scenario& s, Measure measure, std::vector<Positions>* velocities) {
  std::vector<TimedAgent> agents = makeAgents(s);
  std::vector<Positions> trajectory;
  for (long k = 1; k <= s.steps; ++k) {
    exchange(agents, static_cast<double>(k - 1) * s.timeStep);
    Positions q(s.dimension, s.agentCount()), v(s.dimension, s.agentCount());
    for (TimedAgent& a : agents) {
      a.setMeasuredPosition(measure(a.position()));
      EXPECT_FALSE(a.tick(static_cast<double>(k) * s.timeStep).holding);
      for (int c = 0; c < s.dimension; ++c) {
        q(c, a.id()) = a.positionSetpoint()[c];
        v(c, a.id()) = a.commandedVelocity()[c];
      }
    }
    trajectory.push_back(q);
    if (velocities) velocities->push_back(v);
  }
  return trajectory;
}

TEST(TimedAgent, RobotModeWithExactMeasurementIsTheUpdateToRoundOff) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  const std::vector<Positions> expected = reference(s);
  const std::vector<Positions> robot = robotRun(s, [](const std::vector<double>& q) { return q; }, nullptr);
  double worst = 0.0;
  for (std::size_t k = 0; k < robot.size(); ++k) worst = std::max(worst, (robot[k] - expected[k + 1]).cwiseAbs().maxCoeff());
  // Positions are about 3 m (ulp 4.4e-16); the velocity form rounds differently at every step
  // and the rigid motions keep what they get. Measured: 2.0e-13 after 300 steps.
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(worst, 0.0);  // not the same operations: round-off, not identity
}

struct CommandNoise {
  double rms;    ///< per coordinate RMS of the change of agent 0's velocity command [m/s]
  double bound;  ///< 2h/(1 + e^{kappa h}) |H_00| sigma: the linearised sensitivity [m/s]
};

/// Runs the hexagon with time step h to time t = 1.4 s in robot mode with exact measurements, then
/// measures agent 0 with noise N(0, sigma^2) at the next tick, `samples` times from that state.
CommandNoise commandNoise(double h, double sigma, int samples) {
  Scenario s = loadScenario(test::configPath("hexagon"));
  s.timeStep = h;
  std::vector<TimedAgent> agents = makeAgents(s);
  const long steps = std::lround(1.4 / h);
  for (long k = 1; k <= steps; ++k) {
    exchange(agents, static_cast<double>(k - 1) * h);
    for (TimedAgent& a : agents) {
      a.setMeasuredPosition(a.position());
      a.tick(static_cast<double>(k) * h);
    }
  }
  exchange(agents, static_cast<double>(steps) * h);
  Positions q(2, s.agentCount());
  for (const TimedAgent& a : agents) q.col(a.id()) << a.position()[0], a.position()[1];
  const Eigen::Matrix2d h00 = makeFormation(s).hessian(q).topLeftCorner<2, 2>();
  TimedAgent clean = agents[0];
  clean.setMeasuredPosition(clean.position());
  clean.tick(static_cast<double>(steps + 1) * h);
  std::mt19937_64 engine(11);
  StandardNormal normal;
  double sum = 0.0;
  for (int m = 0; m < samples; ++m) {
    TimedAgent noisy = agents[0];
    std::vector<double> z = noisy.position();
    for (double& x : z) x += sigma * normal(engine);
    noisy.setMeasuredPosition(z);
    noisy.tick(static_cast<double>(steps + 1) * h);
    for (int c = 0; c < 2; ++c) sum += std::pow(noisy.commandedVelocity()[c] - clean.commandedVelocity()[c], 2);
  }
  const VariationalCoefficients coefficients(h, s.dampingGain);
  return {std::sqrt(sum / (2.0 * samples)), coefficients.startGain * h00.norm() / std::sqrt(2.0) * sigma};
}

TEST(TimedAgent, RobotModeVelocityCommandNoiseIsOrderNoiseNotNoiseOverH) {
  // Differencing measured positions would put sqrt(2) sigma / h into the command (1.0 m/s here).
  // The velocity form takes v_k from the previous command, so the measurement enters only
  // through the gradient: delta v = -2h/(1 + e^{kappa h}) H_00 n, of order h sigma.
  const double sigma = 0.01;  // [m], the robots' odometry noise
  const int samples = 4000;
  const CommandNoise coarse = commandNoise(0.014, sigma, samples);
  const CommandNoise fine = commandNoise(0.007, sigma, samples);
  std::printf("command noise for sigma %.3g m: %.4g m/s at h = 0.014 s (bound %.4g), %.4g m/s at h = 0.007 s\n",
              sigma, coarse.rms, coarse.bound, fine.rms);
  for (const CommandNoise& c : {coarse, fine}) {
    // The RMS of the linear map of the noise is exactly `bound`; the sample RMS of 2 x 4000
    // normals is within 5 sqrt(1 / (2 x 2 x 4000)) = 4% of it, plus the quadratic terms.
    EXPECT_NEAR(c.rms, c.bound, 0.06 * c.bound);
  }
  EXPECT_LT(coarse.rms, 0.05 * sigma / 0.014);
  // O(h sigma): halving h halves it (the state at t = 1.4 s differs a little between the two runs).
  EXPECT_NEAR(fine.rms / coarse.rms, 0.5, 0.05);
}

TEST(TimedAgent, RobotModeDrivesLaggingNoisyRobotsIntoTheShape) {
  // The closed loop of robots.launch without ROS: each tick the agent reads its robot's odometry,
  // commands the velocity, and the robot tracks it with a lag for one period (rate 1).
  Scenario s = loadScenario(test::configPath("hexagon"));
  s.steps = 600;
  const Formation f = makeFormation(s);
  std::vector<TimedAgent> agents = makeAgents(s);
  std::vector<PointRobot> robots;
  for (const TimedAgent& a : agents) robots.emplace_back(PointRobotSettings{0.1, 2.0, 20.0, 0.01}, a.position(), 100 + a.id());
  Positions q(2, s.agentCount()), v(2, s.agentCount());
  double lateError = 0.0;
  for (long k = 1; k <= s.steps; ++k) {
    exchange(agents, static_cast<double>(k - 1) * s.timeStep);
    for (TimedAgent& a : agents) {
      a.setMeasuredPosition(robots[a.id()].measuredPosition());
      ASSERT_FALSE(a.tick(static_cast<double>(k) * s.timeStep).holding);
      robots[a.id()].setCommand(a.commandedVelocity());
    }
    for (PointRobot& r : robots) r.advance(s.timeStep);
    for (const PointRobot& r : robots) {
      q.col(&r - robots.data()) << r.position()[0], r.position()[1];
      v.col(&r - robots.data()) << r.velocity()[0], r.velocity()[1];
    }
    if (k > s.steps - 200) lateError = std::max(lateError, f.maxDistanceError(q));
  }
  // The noise (1 cm) sets the floor: measured 0.0134 m over t = 5.6..8.4 s (seeds 100..105).
  std::printf("robots: max distance error over the last 200 steps %.4f m\n", lateError);
  EXPECT_LT(lateError, 0.02);
  EXPECT_TRUE(f.isCongruent(q, v));
}

TEST(TimedAgent, MeasuredPositionAndRestoreRejectBadValues) {
  const Scenario s = loadScenario(test::configPath("hexagon"));
  TimedAgent a(s, 0, kMaxAge);
  EXPECT_THROW(a.setMeasuredPosition({1.0}), InvalidInput);
  EXPECT_THROW(a.setMeasuredPosition({1.0, std::nan("")}), InvalidInput);
  EXPECT_THROW(a.restore(-1, {1.0, 2.0}), InvalidInput);
  EXPECT_THROW(a.restore(3, {1.0, 2.0, 3.0}), InvalidInput);
  a.restore(40, {1.0, 2.0});
  EXPECT_EQ(a.step(), 40);
  EXPECT_EQ(a.position(), (std::vector<double>{1.0, 2.0}));
}

}  // namespace
}  // namespace vf

// Manoeuvres (doc/maths.md §9): motion parameters, the exact discrete relative equilibrium,
// order 2 against the continuous model, steady tracking in 2D and 3D, a scale change, no
// command = today's run, the discrete laws in the frame moving at v*, and stability.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>

#include <Eigen/Geometry>

#include "test_support.hpp"
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/manoeuvres/manoeuvre_integrator.hpp"
#include "variational_formation_core/model/metrics.hpp"
#include "variational_formation_core/manoeuvres/commanded_frame.hpp"
#include "variational_formation_core/model/validation.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {
namespace {

/// Regular hexagon of side 2 with the 3 chords from agent 0 (minimally rigid).
Formation hexagon() {
  Positions shape(2, 6);
  for (int i = 0; i < 6; ++i) {
    shape(0, i) = 2.0 * std::cos(M_PI / 3.0 * i);
    shape(1, i) = 2.0 * std::sin(M_PI / 3.0 * i);
  }
  return Formation(2, shape, {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 5}, {5, 0}, {0, 2}, {0, 3}, {0, 4}});
}

/// A 3D bipyramid: a triangle in z = 0 and two apexes, 9 edges (3n - 6), rigid.
Formation bipyramid() {
  Positions shape(3, 5);
  shape << 1.5, -0.75, -0.75, 0.2, -0.1,  //
      0.0, 1.299038105676658, -1.299038105676658, 0.1, -0.2,  //
      0.0, 0.0, 0.0, 1.6, -1.4;
  return Formation(3, shape, {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 1}, {3, 2}, {4, 0}, {4, 1}, {4, 2}});
}

Positions perturbed(const Formation& f) {
  Positions q = f.desiredShape();
  for (int i = 0; i < q.cols(); ++i) {
    for (int a = 0; a < q.rows(); ++a) q(a, i) += 0.15 * std::sin(1.7 * i + 2.3 * a + 0.4);
  }
  return q;
}

using test::command;

// ---------------------------------------------------------------------------------------------
// Motion parameters

TEST(MotionParameters, GiveTheCentroidOffsetOnEveryScaledRotatedTranslatedCopy) {
  for (const Formation& f : {hexagon(), bipyramid(), test::tetrahedron()}) {
    const int d = f.dimension();
    // q = s R q* + t with an arbitrary rotation.
    Eigen::MatrixXd rot = Eigen::MatrixXd::Identity(d, d);
    if (d == 2) {
      rot << std::cos(0.7), -std::sin(0.7), std::sin(0.7), std::cos(0.7);
    } else {
      rot = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
    }
    Positions q = 1.7 * rot * f.desiredShape();
    q.colwise() += Eigen::VectorXd::LinSpaced(d, -3.0, 4.0);
    const Eigen::VectorXd c = q.rowwise().mean();
    for (int i = 0; i < f.agentCount(); ++i) {
      const MotionParameters mu = motionParameters(f, i);
      ASSERT_TRUE(mu.exact) << "agent " << i << ": " << mu.problem;
      double r[3];
      centroidOffset(f, mu, i, q, r);
      for (int a = 0; a < d; ++a) EXPECT_NEAR(r[a], q(a, i) - c(a), 1e-12) << "agent " << i;
    }
  }
}

TEST(MotionParameters, AreTheMinimumNormSolutionWithMoreNeighboursThanDimensions) {
  // In K4 (3D tetrahedron) every agent has 3 neighbours = d, in the hexagon agent 0 has 5 > 2.
  const Formation f = hexagon();
  const MotionParameters mu = motionParameters(f, 0);
  Eigen::MatrixXd edges(2, 5);
  for (int e = 0; e < 5; ++e) {
    edges.col(e) = f.desiredShape().col(0) - f.desiredShape().col(f.neighbours(0)[e].agent);
  }
  const Eigen::Map<const Eigen::VectorXd> w(mu.weights.data(), 5);
  // Minimum norm <=> w lies in the row space of E, i.e. is orthogonal to its null space.
  const Eigen::MatrixXd kernel = Eigen::FullPivLU<Eigen::MatrixXd>(edges).kernel();
  ASSERT_EQ(kernel.cols(), 3);
  EXPECT_LT((kernel.transpose() * w).norm(), 1e-12);
}

TEST(MotionParameters, AnAgentWhoseEdgesMissTheCentroidOffsetDoesNotQualify) {
  // Agent 3 hangs on agent 0 alone, and the edge does not point at the centroid.
  Positions shape(2, 4);
  shape << 0, 1, 0, 1.2, 0, 0, 1, 0.7;
  const Formation f(2, shape, {{0, 1}, {1, 2}, {2, 0}, {3, 0}});
  const MotionParameters mu = motionParameters(f, 3);
  EXPECT_FALSE(mu.exact);
  EXPECT_NE(mu.problem.find("agent 3"), std::string::npos) << mu.problem;
  EXPECT_THROW(checkFormationCanTurn(f, "manoeuvre"), InvalidInput);
  // ...unless only translating and scaling: no motion parameter is needed then.
  CommandSchedule translate;
  translate.add(0, command({1, 0, 0}, {0, 0, 0}, 1.2));
  EXPECT_NO_THROW(ManoeuvreIntegrator(f, shape, Velocities::Zero(2, 4), 0.01, 2.0, StartMethod::Variational, translate));
  CommandSchedule turn;
  turn.add(0, command({0, 0, 0}, {0, 0, 0.5}, 1.0));
  EXPECT_THROW(ManoeuvreIntegrator(f, shape, Velocities::Zero(2, 4), 0.01, 2.0, StartMethod::Variational, turn),
               InvalidInput);
}

TEST(MotionParameters, EveryShippedScenarioQualifiesToTurn) {
  for (const char* name : {"hexagon", "square", "tetrahedron", "tetrahedron_paper", "grid24", "lattice48",
                           "hexagon_manoeuvre"}) {
    const Formation f = makeFormation(loadScenario(test::configPath(name)));
    EXPECT_NO_THROW(checkFormationCanTurn(f, "manoeuvre")) << name;
  }
}

// ---------------------------------------------------------------------------------------------
// The discrete relative equilibrium

// Rigid motion q_k = c_0 + k h v + R(k h w) s q*_c is an exact solution of the forced update.
TEST(ManoeuvreUpdate, CommandedRigidMotionIsAnExactDiscreteSolution) {
  for (const Formation& f : {hexagon(), bipyramid()}) {
    const int d = f.dimension();
    const double h = 0.01, kappa = 3.0, s = 1.3;
    const Vector3 v(0.4, -0.3, d == 3 ? 0.2 : 0.0);
    const Vector3 w = d == 3 ? Vector3(0.3, -0.5, 0.6) : Vector3(0, 0, 0.8);
    const VariationalCoefficients c(h, kappa);
    const ManoeuvreGains g = manoeuvreGains(command(v, w, s), c);
    Eigen::VectorXd centroid = f.desiredShape().rowwise().mean();
    const auto at = [&](long k) {
      const Eigen::Matrix3d r = Eigen::AngleAxisd(k * h * w.norm(), w.normalized()).toRotationMatrix();
      Positions q(d, f.agentCount());
      for (int i = 0; i < f.agentCount(); ++i) {
        Vector3 x = Vector3::Zero();
        x.head(d) = s * (f.desiredShape().col(i) - centroid);
        q.col(i) = (r * x + Vector3(1.0, 2.0, 3.0) + k * h * v).head(d);
      }
      return q;
    };
    const Positions q0 = at(40), q1 = at(41), q2 = at(42);
    double worst = 0.0;
    for (int i = 0; i < f.agentCount(); ++i) {
      double grad[3], r[3], next[3];
      f.agentScaledGradient(i, q1, g.scaleSquared, grad);
      centroidOffset(f, motionParameters(f, i), i, q1, r);
      manoeuvreUpdate(c, g, d, q0.col(i).data(), q1.col(i).data(), grad, r, next);
      for (int a = 0; a < d; ++a) worst = std::max(worst, std::abs(next[a] - q2(a, i)));
    }
    std::cout << "dimension " << d << ": |q_{k+2} - exact| = " << worst << " m\n";
    EXPECT_LT(worst, 1e-13);
  }
}

// ---------------------------------------------------------------------------------------------
// Order 2 against the continuous model q'' = -kappa q' - grad V_s + kappa u + w* x (u - v*) (RK4).

struct Continuous {
  const Formation& f;
  double kappa;
  const std::vector<ManoeuvreSegment>& segments;
  std::vector<MotionParameters> mu;

  const Command& at(double t) const {
    for (const ManoeuvreSegment& s : segments) {
      if (t < s.until) return s.command;
    }
    return segments.back().command;
  }
  // u_i = v* + w* x r_i; returns (q', q'') for the state (q, p). Computed here with Eigen, not
  // with the scheme's gains.
  void rates(double t, const Positions& q, const Velocities& p, Velocities& dq, Accelerations& dp) const {
    const Command& c = at(t);
    const int d = f.dimension(), n = f.agentCount();
    const auto cross = [&](const Eigen::VectorXd& x) {
      Vector3 x3 = Vector3::Zero();
      x3.head(d) = x;
      return Eigen::VectorXd(c.angularRate.cross(x3).head(d));
    };
    Positions u(d, n);
    for (int i = 0; i < n; ++i) {
      double r[3];
      centroidOffset(f, mu[static_cast<std::size_t>(i)], i, q, r);
      u.col(i) = c.velocity.head(d) + cross(Eigen::Map<Eigen::VectorXd>(r, d));
    }
    dq = p;
    dp.resize(d, n);
    for (int i = 0; i < n; ++i) {
      double g[3];
      f.agentScaledGradient(i, q, c.scale * c.scale, g);
      dp.col(i) = -kappa * p.col(i) - Eigen::Map<Eigen::VectorXd>(g, d) + kappa * u.col(i) +
                  cross(u.col(i) - c.velocity.head(d));
    }
  }
  Positions run(Positions q, Velocities p, double h, double T) const {
    const long steps = std::lround(T / h);
    Velocities k1q, k2q, k3q, k4q;
    Accelerations k1p, k2p, k3p, k4p;
    for (long k = 0; k < steps; ++k) {
      const double t = k * h;  // the command of the interval [t, t + h], as the discrete scheme
      rates(t, q, p, k1q, k1p);
      rates(t, q + 0.5 * h * k1q, p + 0.5 * h * k1p, k2q, k2p);
      rates(t, q + 0.5 * h * k2q, p + 0.5 * h * k2p, k3q, k3p);
      rates(t, q + h * k3q, p + h * k3p, k4q, k4p);
      q += h / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
      p += h / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
    }
    return q;
  }
};

Positions runManoeuvre(const Formation& f, const Positions& q0, const Velocities& v0, double h, double kappa,
                       const std::vector<ManoeuvreSegment>& segments, double T) {
  ManoeuvreIntegrator integ(f, q0, v0, h, kappa, StartMethod::Variational, scheduleFromSegments(segments, h));
  const long steps = std::lround(T / h);
  for (long k = 0; k < steps; ++k) integ.step();
  return integ.positions();
}

void expectSecondOrder(const Formation& f, const std::vector<ManoeuvreSegment>& segments) {
  const double kappa = 2.0, T = 2.0;
  Continuous model{f, kappa, segments, {}};
  for (int i = 0; i < f.agentCount(); ++i) model.mu.push_back(motionParameters(f, i));
  const Positions q0 = perturbed(f);
  Velocities v0 = Velocities::Zero(f.dimension(), f.agentCount());
  v0(0, 1) = 0.3;
  // Command changes at 0.5, 1 and 1.5 s: on the grid of every h below (all powers of 2).
  const Positions reference = model.run(q0, v0, 1.0 / 4096, T);
  double previous = 0.0;
  std::vector<double> orders;
  for (double h : {1.0 / 32, 1.0 / 64, 1.0 / 128}) {
    const double error = (runManoeuvre(f, q0, v0, h, kappa, segments, T) - reference).norm();
    std::cout << "  dimension " << f.dimension() << ", h = " << h << ": error " << error;
    if (previous > 0.0) {
      orders.push_back(std::log2(previous / error));
      std::cout << ", order " << orders.back();
    }
    std::cout << '\n';
    previous = error;
  }
  for (double order : orders) EXPECT_NEAR(order, 2.0, 0.15);
}

TEST(ManoeuvreOrder, SecondOrderUnderACommandThatChangesOverTime2D) {
  std::vector<ManoeuvreSegment> segments(4);
  segments[0] = {0.5, command({0.5, 0, 0}, {0, 0, 0}, 1.0)};
  segments[1] = {1.0, command({0.5, 0.3, 0}, {0, 0, 0.6}, 1.0)};
  segments[2] = {1.5, command({0, 0.4, 0}, {0, 0, -0.4}, 1.4)};
  segments[3] = {1e9, command({-0.2, 0, 0}, {0, 0, 0.3}, 1.2)};
  expectSecondOrder(hexagon(), segments);
}

TEST(ManoeuvreOrder, SecondOrderUnderACommandThatChangesOverTime3D) {
  std::vector<ManoeuvreSegment> segments(3);
  segments[0] = {0.5, command({0.5, 0, 0.1}, {0.2, 0, 0.4}, 1.0)};
  segments[1] = {1.0, command({0, 0.3, 0}, {0, -0.5, 0.1}, 1.3)};
  segments[2] = {1e9, command({0.2, 0, -0.2}, {0.3, 0.3, 0.3}, 0.9)};
  expectSecondOrder(bipyramid(), segments);
}

// ---------------------------------------------------------------------------------------------
// Steady tracking after the transient

void expectSteadyTracking(const Formation& f, const Command& c, double kappa, double h, double T) {
  const int d = f.dimension();
  CommandSchedule schedule;
  schedule.add(0, c);
  ManoeuvreIntegrator integ(f, perturbed(f), Velocities::Zero(d, f.agentCount()), h, kappa,
                            StartMethod::Variational, schedule);
  const long steps = std::lround(T / h), window = std::lround(1.0 / h);
  for (long k = 0; k < steps; ++k) integ.step();
  const Positions before = integ.positions();
  for (long k = 0; k < window; ++k) integ.step();
  const Positions after = integ.positions();
  const double elapsed = window * h;

  // Centroid velocity, over the last second and from the last step.
  const Vector3 fromCentroid = [&] {
    Vector3 x = Vector3::Zero();
    x.head(d) = (after.rowwise().mean() - before.rowwise().mean()) / elapsed;
    return x;
  }();
  const double velocityError =
      std::max((fromCentroid - c.velocity).norm(), (centroidVelocity(integ.velocities()) - c.velocity).norm());
  // Each edge's direction turns at w*: the component normal to w* turns by |w*| t about it.
  const double rate = c.angularRate.norm();
  const Vector3 axis = c.angularRate / rate;
  double worstRate = 0.0, worstLength = 0.0;
  for (const Edge& e : f.edges()) {
    Vector3 a = Vector3::Zero(), b = Vector3::Zero();
    a.head(d) = before.col(e.tail) - before.col(e.head);
    b.head(d) = after.col(e.tail) - after.col(e.head);
    const Vector3 an = a - axis.dot(a) * axis, bn = b - axis.dot(b) * axis;
    if (an.norm() > 0.1 * a.norm()) {
      const double turned = std::atan2(axis.dot(an.cross(bn)), an.dot(bn));
      worstRate = std::max(worstRate, std::abs(turned / elapsed - rate) / rate);
    }
    worstLength = std::max(worstLength, std::abs(b.norm() / (c.scale * e.desiredDistance) - 1.0));
  }
  std::cout << "  dimension " << d << ": centroid velocity error " << velocityError << " m/s, edge turn rate error "
            << worstRate << " (relative), edge length error " << worstLength << " (relative)\n";
  EXPECT_LT(velocityError, 1e-3);
  EXPECT_LT(worstRate, 0.01);
  EXPECT_LT(worstLength, 1e-3);
}

TEST(ManoeuvreTracking, SteadyTranslateTurnScale2D) {
  expectSteadyTracking(hexagon(), command({0.8, -0.3, 0}, {0, 0, 0.5}, 1.3), 3.0, 0.01, 30.0);
}

TEST(ManoeuvreTracking, SteadyTranslateTurnScale3D) {
  expectSteadyTracking(bipyramid(), command({0.2, 0.5, -0.3}, {0.2, -0.3, 0.4}, 1.2), 3.0, 0.01, 30.0);
}

TEST(ManoeuvreTracking, ScaleChangeFromOneToOneAndAHalf) {
  const Formation f = hexagon();
  CommandSchedule schedule;
  schedule.add(500, command({0, 0, 0}, {0, 0, 0}, 1.5));
  ManoeuvreIntegrator integ(f, f.desiredShape(), Velocities::Zero(2, 6), 0.01, 4.0, StartMethod::Variational,
                            schedule);
  for (long k = 0; k < 500; ++k) integ.step();
  EXPECT_DOUBLE_EQ(integ.commandedScale(), 1.0);
  EXPECT_LT(std::abs(meanScaleError(f, integ.positions(), 1.0)), 1e-12);
  for (long k = 0; k < 2000; ++k) integ.step();
  EXPECT_DOUBLE_EQ(integ.commandedScale(), 1.5);
  const double worst = maxScaledDistanceError(f, integ.positions(), 1.5) / (1.5 * 2.0);
  std::cout << "  scale 1 -> 1.5: worst edge error " << worst << " (relative), mean scale error "
            << meanScaleError(f, integ.positions(), 1.5) << " after 20 s\n";
  EXPECT_LT(worst, 1e-3);
  EXPECT_LT(std::abs(meanScaleError(f, integ.positions(), 1.5)), 1e-3);
  // The centroid does not move: every agent pushes outwards symmetrically.
  EXPECT_LT((integ.positions().rowwise().mean() - f.desiredShape().rowwise().mean()).norm(), 1e-12);
}

// ---------------------------------------------------------------------------------------------
// No command: today's run, bit for bit

TEST(ManoeuvreNoCommand, EmptyAndZeroSchedulesGiveTodaysRunBitForBit) {
  for (const Formation& f : {hexagon(), bipyramid()}) {
    const Positions q0 = perturbed(f);
    Velocities v0 = Velocities::Zero(f.dimension(), f.agentCount());
    v0(0, 2) = 0.4;
    CommandSchedule zero;
    zero.add(0, Command{});
    zero.add(37, Command{});
    for (const CommandSchedule& schedule : {CommandSchedule{}, zero}) {
      for (StartMethod start : {StartMethod::Variational, StartMethod::Paper}) {
        VariationalIntegrator today(f, q0, v0, 0.01, 2.0, start);
        ManoeuvreIntegrator commanded(f, q0, v0, 0.01, 2.0, start, schedule);
        for (long k = 0; k < 400; ++k) {
          today.step();
          commanded.step();
          ASSERT_TRUE((today.positions().array() == commanded.positions().array()).all()) << "step " << k + 1;
        }
        EXPECT_EQ(today.energy(), commanded.energy());
        EXPECT_TRUE((today.momenta().array() == commanded.momenta().array()).all());
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Discrete laws

// Translation only: in the frame moving at v*, q'_k = q_k - k h v* is today's run from
// (q_0, v_0 - v*), so every law of today's scheme holds there.
TEST(ManoeuvreLaws, TranslationIsTodaysRunInTheFrameMovingAtTheCommand) {
  for (const Formation& f : {hexagon(), bipyramid()}) {
    const int d = f.dimension();
    const double h = 0.01, kappa = 2.0, s = 1.2;
    const Vector3 v(0.7, -0.4, d == 3 ? 0.3 : 0.0);
    const Positions q0 = perturbed(f);
    Velocities v0 = Velocities::Zero(d, f.agentCount());
    v0(1, 0) = 0.5;
    CommandSchedule schedule;
    schedule.add(0, command(v, Vector3::Zero(), s));
    ManoeuvreIntegrator commanded(f, q0, v0, h, kappa, StartMethod::Variational, schedule);
    // Today's scheme for the scaled shape: the same formation with s q* as desired shape.
    const Formation scaled(d, s * f.desiredShape(), [&] {
      std::vector<std::pair<int, int>> e;
      for (const Edge& x : f.edges()) e.emplace_back(x.tail, x.head);
      return e;
    }());
    VariationalIntegrator moving(scaled, q0, v0.colwise() - v.head(d), h, kappa, StartMethod::Variational);
    double worst = 0.0;
    for (long k = 1; k <= 2000; ++k) {
      commanded.step();
      moving.step();
      const Positions shifted = commanded.positions().colwise() - (static_cast<double>(k) * h) * v.head(d);
      worst = std::max(worst, (shifted - moving.positions()).cwiseAbs().maxCoeff());
    }
    std::cout << "  dimension " << d << ": |q_k - k h v* - q'_k| <= " << worst << " m over 2000 steps\n";
    // Round-off only: the formation travels 14 m (with the moving-frame start written as
    // q_0 + 2h/(1 + e^{kappa h}) v_0 + h v*, that is with p-_0 = v_0 instead, it was 3.5e-5 m).
    EXPECT_LT(worst, 1e-10);
  }
}

// sum_i v_{i,k} - n v* decays by exactly e^{-kappa h} per step (momentum in the moving frame),
// whatever the shape, the scale and a scale change.
TEST(ManoeuvreLaws, MomentumInTheMovingFrameDecaysByTheDampingFactor) {
  const Formation f = hexagon();
  const double h = 0.01, kappa = 3.0;
  const Vector3 v(0.6, 0.2, 0.0);
  CommandSchedule schedule;
  schedule.add(0, command(v, Vector3::Zero(), 1.0));
  schedule.add(300, command(v, Vector3::Zero(), 1.4));
  Velocities v0 = Velocities::Zero(2, 6);
  v0.col(3) << -0.4, 0.9;
  ManoeuvreIntegrator integ(f, perturbed(f), v0, h, kappa, StartMethod::Variational, schedule);
  const VariationalCoefficients c(h, kappa);
  integ.step();
  const Eigen::Vector2d first = integ.velocities().rowwise().sum() - 6.0 * v.head(2);
  double worst = 0.0;
  for (long k = 2; k <= 1500; ++k) {
    integ.step();
    const Eigen::Vector2d relative = integ.velocities().rowwise().sum() - 6.0 * v.head(2);
    worst = std::max(worst, (relative - std::pow(c.decay, k - 1) * first).norm() / first.norm());
  }
  std::cout << "  moving-frame momentum residual " << worst << " (relative to its start)\n";
  EXPECT_LT(worst, 1e-11);
}

// The discrete energy in the moving frame, 1/2 |v_k - v*|^2 + 1/2 (V_s(q_k) + V_s(q_{k+1})),
// decreases at every step when kappa > 0.
TEST(ManoeuvreLaws, EnergyInTheMovingFrameDecreases) {
  const Formation f = bipyramid();
  const double h = 0.01;
  const Vector3 v(0.3, -0.6, 0.2);
  CommandSchedule schedule;
  schedule.add(0, command(v, Vector3::Zero(), 1.1));
  Velocities v0 = Velocities::Zero(3, 5);
  v0.col(2) << 0.5, 0.1, -0.3;
  ManoeuvreIntegrator integ(f, perturbed(f), v0, h, 2.0, StartMethod::Variational, schedule);
  Positions previous = integ.positions();
  double last = std::numeric_limits<double>::infinity(), first = last;
  long increases = 0;
  for (long k = 0; k < 3000; ++k) {
    integ.step();
    const Velocities relative = integ.velocities().colwise() - v;
    const double energy = 0.5 * relative.squaredNorm() +
                          0.5 * (f.scaledPotential(previous, 1.21) + f.scaledPotential(integ.positions(), 1.21));
    if (energy > last + 1e-13 * first) ++increases;
    if (k == 0) first = energy;
    last = energy;
    previous = integ.positions();
  }
  std::cout << "  moving-frame energy after 30 s: " << last << '\n';
  EXPECT_EQ(increases, 0);
  EXPECT_LT(last, 1e-8);
}

// ---------------------------------------------------------------------------------------------
// Stability for the command magnitudes the doc allows: |w*| up to half the softest shape
// frequency (1.92 rad/s for this hexagon), any |v*|; and the loss of shape beyond the softest
// frequency, which the loader warns about.

double finalEdgeError(double rate, double speed, double kappa, double seconds) {
  const Formation f = hexagon();
  CommandSchedule schedule;
  schedule.add(0, command({speed, 0, 0}, {0, 0, rate}, 1.0));
  ManoeuvreIntegrator integ(f, perturbed(f), Velocities::Zero(2, 6), 0.01, kappa, StartMethod::Variational, schedule);
  const long steps = std::lround(seconds / 0.01);
  for (long k = 0; k < steps; ++k) integ.step();
  return maxScaledDistanceError(f, integ.positions(), 1.0);
}

TEST(ManoeuvreStability, AllowedMagnitudesHoldTheShape) {
  for (double kappa : {1.0, 4.0, 16.0}) {
    for (double rate : {-0.96, 0.25, 0.5, 0.96}) {
      for (double speed : {0.0, 1.0, 20.0}) {
        EXPECT_LT(finalEdgeError(rate, speed, kappa, 40.0), 1e-6) << "kappa " << kappa << " w " << rate << " v " << speed;
      }
    }
  }
}

TEST(ManoeuvreStability, TurningFasterThanTheSoftestShapeModeLosesTheShape) {
  EXPECT_GT(finalEdgeError(4.0, 0.0, 4.0, 40.0), 1e-3);
}

TEST(CommandedFrame, TurnsByTheIntegratedRateAndTakesTheScaleAndVelocityOfTheStep) {
  const double h = 0.01;
  CommandSchedule schedule;
  schedule.add(100, test::command({0.5, 0, 0}, {0, 0, 0.3}, 1.2));
  schedule.add(300, test::command({0, -1, 0}, {0, 0, -0.1}, 0.8));
  // Before the first entry: the zero command, no turn.
  CommandedFrame f = commandedFrame(schedule, 50, h);
  EXPECT_TRUE(f.rotation.isIdentity(0.0));
  EXPECT_EQ(f.scale, 1.0);
  EXPECT_TRUE(f.velocity.isZero(0.0));
  // Intervals 100..299 at 0.3 rad/s, then 300..449 at -0.1 rad/s: 0.6 - 0.15 = 0.45 rad about z.
  f = commandedFrame(schedule, 450, h);
  EXPECT_NEAR(std::atan2(f.rotation(1, 0), f.rotation(0, 0)), 0.45, 1e-14);
  EXPECT_NEAR(f.rotation(2, 2), 1.0, 1e-15);
  EXPECT_EQ(f.scale, 0.8);
  EXPECT_EQ(f.velocity, Vector3(0, -1, 0));
  // In 3D, turns about different axes compose in order: R2 R1.
  CommandSchedule spatial;
  spatial.add(0, test::command({0, 0, 0}, {0.2, 0, 0}, 1.0));
  spatial.add(10, test::command({0, 0, 0}, {0, 0.3, 0}, 1.0));
  const Eigen::Matrix3d r1 = Eigen::AngleAxisd(0.2 * 10 * h, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d r2 = Eigen::AngleAxisd(0.3 * 5 * h, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_TRUE(commandedFrame(spatial, 15, h).rotation.isApprox(r2 * r1, 1e-14));
}

}  // namespace
}  // namespace vf

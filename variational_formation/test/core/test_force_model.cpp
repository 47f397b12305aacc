// ForceModel, the seam of what acts on an agent: each potential against central differences,
// Noether's laws where a model claims a symmetry (and their failure where it does not), the
// campaign's fast path bit for bit against the per-agent path, and the integrators using the
// model's terms and step filter.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "test_support.hpp"
#include "variational_formation_core/model/force_model.hpp"
#include "variational_formation_core/safety/safety_stage.hpp"
#include "variational_formation_core/integrators/variational_integrator.hpp"

namespace vf {
namespace {

// Scattered positions in [-2, 2]^d, a different set for each seed (no symmetry to hide behind).
Positions scattered(int d, int n, unsigned seed) {
  Positions q(d, n);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < d; ++a) q(a, i) = 2.0 * std::sin(1.3 * seed + 2.1 * i + 0.7 * a + 0.4 * i * a);
  return q;
}

// A test term, not invariant: W = k/2 sum_i |q_i - p|^2 pulls every agent to the point p != 0.
class Anchor : public PotentialTerm {
 public:
  Anchor(double stiffness, Eigen::VectorXd point) : k_(stiffness), p_(std::move(point)) {}
  double potential(const Positions& q) const override {
    return 0.5 * k_ * (q.colwise() - p_).colwise().squaredNorm().sum();
  }
  void addAgentGradient(int agent, const Positions& q, double* out) const override {
    for (int a = 0; a < q.rows(); ++a) out[a] += k_ * (q(a, agent) - p_(a));
  }
  bool translationInvariant() const override { return false; }
  bool rotationInvariant() const override { return false; }

 private:
  double k_;
  Eigen::VectorXd p_;
};

// A test term of the kind collision avoidance adds, invariant under rigid motions:
// W = c sum_{i<j} 1/|q_i - q_j|^2 over every pair.
class PairRepulsion : public PotentialTerm {
 public:
  explicit PairRepulsion(double strength) : c_(strength) {}
  double potential(const Positions& q) const override {
    double w = 0.0;
    for (int i = 0; i < q.cols(); ++i)
      for (int j = i + 1; j < q.cols(); ++j) w += c_ / (q.col(i) - q.col(j)).squaredNorm();
    return w;
  }
  void addAgentGradient(int agent, const Positions& q, double* out) const override {
    for (int j = 0; j < q.cols(); ++j) {
      if (j == agent) continue;
      const Eigen::VectorXd z = q.col(agent) - q.col(j);
      const double r2 = z.squaredNorm();
      for (int a = 0; a < q.rows(); ++a) out[a] += -2.0 * c_ * z(a) / (r2 * r2);
    }
  }
  bool translationInvariant() const override { return true; }
  bool rotationInvariant() const override { return true; }

 private:
  double c_;
};

// The models under test, in 2D (triangle) and 3D (tetrahedron): V alone, and with each term.
struct Case {
  const char* name;
  ForceModel model;
};

std::vector<Case> cases() {
  const auto triangle = std::make_shared<const Formation>(test::triangle());
  const auto tetrahedron = std::make_shared<const Formation>(test::tetrahedron());
  std::vector<Case> all;
  for (const auto& f : {triangle, tetrahedron}) {
    const int d = f->dimension();
    ForceModel plain(f), anchored(f), repelled(f);
    anchored.addTerm(std::make_shared<Anchor>(0.7, Eigen::VectorXd::LinSpaced(d, 0.3, 1.1)));
    repelled.addTerm(std::make_shared<PairRepulsion>(0.05));
    all.push_back({d == 2 ? "V, 2D" : "V, 3D", plain});
    all.push_back({d == 2 ? "V + anchor, 2D" : "V + anchor, 3D", anchored});
    all.push_back({d == 2 ? "V + repulsion, 2D" : "V + repulsion, 3D", repelled});
  }
  return all;
}

TEST(ForceModel, GradientMatchesCentralDifferencesOfThePotential) {
  for (const Case& c : cases()) {
    for (double s2 : {1.0, 1.44}) {
      const int d = c.model.dimension(), n = c.model.agentCount();
      const Positions q = scattered(d, n, 7);
      const double eps = 1e-6;
      for (int i = 0; i < n; ++i) {
        double g[3];
        c.model.agentGradient(i, q, s2, g);
        for (int a = 0; a < d; ++a) {
          Positions qp = q, qm = q;
          qp(a, i) += eps;
          qm(a, i) -= eps;
          const double fd = (c.model.potential(qp, s2) - c.model.potential(qm, s2)) / (2 * eps);
          EXPECT_NEAR(g[a], fd, 1e-6 * std::max(1.0, std::abs(fd))) << c.name << " s^2 " << s2 << " agent " << i;
        }
      }
    }
  }
}

TEST(ForceModel, FormationAloneIsFormationsNumbersBitForBit) {
  const Formation f = test::tetrahedron();
  const ForceModel model(f);
  const Positions q = scattered(3, 4, 3);
  for (int i = 0; i < 4; ++i) {
    double a[3], b[3], c[3], e[3];
    model.agentGradient(i, q, a);
    f.agentGradient(i, q, b);
    model.agentGradient(i, q, 0.81, c);
    f.agentScaledGradient(i, q, 0.81, e);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(a[k], b[k]);
      EXPECT_EQ(c[k], e[k]);
    }
  }
  EXPECT_EQ(model.potential(q), f.potential(q));
  EXPECT_EQ(model.potential(q, 0.81), f.scaledPotential(q, 0.81));
}

// Noether: invariance under translations gives sum_i grad_i = 0 (linear momentum), under
// rotations sum_i q_i x grad_i = 0 (angular momentum). Where a model claims a symmetry both the
// potential's invariance and the law hold; where it does not, the laws visibly fail.
TEST(ForceModel, NoetherLawsHoldExactlyWhereTheModelClaimsTheSymmetry) {
  for (const Case& c : cases()) {
    const int d = c.model.dimension(), n = c.model.agentCount();
    const Positions q = scattered(d, n, 11);
    Gradients g;
    c.model.gradient(q, g);
    const double scale = g.cwiseAbs().maxCoeff();
    const double linear = g.rowwise().sum().norm();
    Eigen::Vector3d angular = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d qi = Eigen::Vector3d::Zero(), gi = Eigen::Vector3d::Zero();
      qi.head(d) = q.col(i);
      gi.head(d) = g.col(i);
      angular += qi.cross(gi);
    }
    Positions shifted = q;
    shifted.colwise() += Eigen::VectorXd::LinSpaced(d, 1.5, -0.4);
    const Eigen::MatrixXd rotation =
        d == 2 ? Eigen::MatrixXd(Eigen::Rotation2Dd(0.9).toRotationMatrix())
               : Eigen::MatrixXd(Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 2) / 3.0).toRotationMatrix());
    const Positions rotated = rotation * q;
    const double v = c.model.potential(q);
    if (c.model.translationInvariant()) {
      EXPECT_LT(linear, 1e-12 * scale) << c.name;
      EXPECT_NEAR(c.model.potential(shifted), v, 1e-12 * std::abs(v)) << c.name;
    } else {
      EXPECT_GT(linear, 1e-3 * scale) << c.name;
    }
    if (c.model.rotationInvariant()) {
      EXPECT_LT(angular.norm(), 1e-12 * scale * q.cwiseAbs().maxCoeff() * n) << c.name;
      EXPECT_NEAR(c.model.potential(rotated), v, 1e-12 * std::abs(v)) << c.name;
    } else {
      EXPECT_GT(angular.norm(), 1e-3 * scale) << c.name;
    }
  }
  EXPECT_TRUE(ForceModel(test::triangle()).translationInvariant() && ForceModel(test::triangle()).rotationInvariant());
}

TEST(ForceModel, LaneFastPathEqualsPerAgentPathBitForBit) {
  constexpr int kLanes = 8;
  for (const Case& c : cases()) {
    const int d = c.model.dimension(), n = c.model.agentCount();
    std::vector<Positions> lanes;
    std::vector<double> q(static_cast<std::size_t>(n * d * kLanes)), g(q.size(), -1.0);
    for (int l = 0; l < kLanes; ++l) {
      lanes.push_back(scattered(d, n, 100 + l));
      for (int i = 0; i < n; ++i)
        for (int a = 0; a < d; ++a) q[static_cast<std::size_t>((i * d + a) * kLanes + l)] = lanes.back()(a, i);
    }
    c.model.laneGradient<kLanes>(q.data(), g.data());
    for (int l = 0; l < kLanes; ++l) {
      for (int i = 0; i < n; ++i) {
        double expected[3];
        c.model.agentGradient(i, lanes[static_cast<std::size_t>(l)], expected);
        for (int a = 0; a < d; ++a)
          EXPECT_EQ(g[static_cast<std::size_t>((i * d + a) * kLanes + l)], expected[a]) << c.name << " lane " << l;
      }
    }
  }
}

// An added term reaches the update: the first variational step from rest is
// q_1 = q_0 - startGain h/2 (grad V + grad W)(q_0), with grad W written out here.
TEST(ForceModel, IntegratorStepsWithTheModelsAddedTerm) {
  const Formation f = test::triangle();
  Positions q0 = f.desiredShape();
  q0(0, 1) += 0.2;
  const double h = 0.01, kappa = 2.0, k = 0.7;
  const Eigen::Vector2d p(0.3, 1.1);
  VariationalIntegrator vi(f, q0, Positions::Zero(2, 3), h, kappa, StartMethod::Variational);
  vi.forceModel().addTerm(std::make_shared<Anchor>(k, p));
  vi.step();
  const VariationalCoefficients coefficients(h, kappa);
  for (int i = 0; i < 3; ++i) {
    double g[2];
    f.agentGradient(i, q0, g);
    for (int a = 0; a < 2; ++a) {
      const double expected = q0(a, i) + coefficients.startGain * (0.0 - 0.5 * h * (g[a] + k * (q0(a, i) - p(a))));
      EXPECT_NEAR(vi.positions()(a, i), expected, 1e-15) << i;
    }
  }
}

// The safety filter is the model's step filter: attached to the integrator it is the model's,
// and filterStep does what SafetyStage::apply does (nothing without a filter).
TEST(ForceModel, StepFilterIsTheSafetyStage) {
  const Formation f = test::triangle();
  Positions q = f.desiredShape() * 0.3;  // agents 0.3 m apart, closer than r after a step inwards
  Positions next = q * 0.5;
  const Positions unfiltered = next;
  ForceModel model(f);
  model.filterStep(q, 1, next);
  EXPECT_EQ(next, unfiltered);
  SafetySettings settings;
  settings.radius = 0.25;
  settings.sensingRadius = 1.0;
  settings.gamma = 0.2;
  auto stage = std::make_shared<SafetyStage>(settings, std::vector<Obstacle>{}, 0.01);
  model.setStepFilter(stage);
  EXPECT_EQ(model.stepFilter(), stage.get());
  model.filterStep(q, 1, next);
  Positions direct = unfiltered;
  SafetyStage(settings, {}, 0.01).apply(q, 1, direct);
  EXPECT_EQ(next, direct);
  EXPECT_NE(next, unfiltered);  // the filter did bind: the test is not vacuous
  VariationalIntegrator vi(f, q, Positions::Zero(2, 3), 0.01, 2.0, StartMethod::Variational);
  vi.attachSafety(stage);
  EXPECT_EQ(vi.forceModel().stepFilter(), stage.get());
}

}  // namespace
}  // namespace vf

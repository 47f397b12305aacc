#include "variational_formation_core/model/force_model.hpp"

#include <algorithm>

#include "variational_formation_core/safety/safety_stage.hpp"

namespace vf {

void ForceModel::gradient(const Positions& q, Gradients& out) const {
  out.resize(dimension(), agentCount());
  for (int i = 0; i < agentCount(); ++i) agentGradient(i, q, out.col(i).data());
}

double ForceModel::potential(const Positions& q, double scaleSquared) const {
  double v = scaleSquared == 1.0 ? formation_->potential(q) : formation_->scaledPotential(q, scaleSquared);
  for (const auto& term : terms_) v += term->potential(q);
  return v;
}

bool ForceModel::translationInvariant() const {
  return std::all_of(terms_.begin(), terms_.end(), [](const auto& t) { return t->translationInvariant(); });
}

bool ForceModel::rotationInvariant() const {
  return std::all_of(terms_.begin(), terms_.end(), [](const auto& t) { return t->rotationInvariant(); });
}

void ForceModel::filterStep(const Positions& q, long step, Positions& qNext) const {
  if (filter_) filter_->apply(q, step, qNext);
}

// V's gradient scattered edge by edge as Formation::agentGradient gathers it: agent j's terms
// arrive in the order of its neighbour list, and gamma (q_j - q_i) = -(gamma (q_i - q_j)) exactly.
template <int Lanes>
void ForceModel::laneGradient(const double* q, double* gradient) const {
  const int d = dimension();
  const int n = agentCount();
  std::fill(gradient, gradient + static_cast<std::ptrdiff_t>(n) * d * Lanes, 0.0);
  for (const Edge& e : formation_->edges()) {
    double* gi = gradient + e.tail * d * Lanes;
    double* gj = gradient + e.head * d * Lanes;
    const double* qi = q + e.tail * d * Lanes;
    const double* qj = q + e.head * d * Lanes;
    double gamma[Lanes];
    for (int l = 0; l < Lanes; ++l) gamma[l] = 0.0;
    for (int a = 0; a < d; ++a) {
      for (int l = 0; l < Lanes; ++l) {
        const double diff = qi[a * Lanes + l] - qj[a * Lanes + l];
        gamma[l] += diff * diff;
      }
    }
    for (int l = 0; l < Lanes; ++l) gamma[l] -= e.desiredDistanceSquared;
    for (int a = 0; a < d; ++a) {
      for (int l = 0; l < Lanes; ++l) {
        const double term = gamma[l] * (qi[a * Lanes + l] - qj[a * Lanes + l]);
        gi[a * Lanes + l] += term;
        gj[a * Lanes + l] -= term;
      }
    }
  }
  if (terms_.empty()) return;
  // The added terms lane by lane, through the same calls as agentGradient, on V's sums.
  Positions lane(d, n);
  for (int l = 0; l < Lanes; ++l) {
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < d; ++a) lane(a, i) = q[(i * d + a) * Lanes + l];
    for (int i = 0; i < n; ++i) {
      double g[3];
      for (int a = 0; a < d; ++a) g[a] = gradient[(i * d + a) * Lanes + l];
      addTerms(i, lane, g);
      for (int a = 0; a < d; ++a) gradient[(i * d + a) * Lanes + l] = g[a];
    }
  }
}

// RoaCampaign::kLanes.
template void ForceModel::laneGradient<8>(const double* q, double* gradient) const;

}  // namespace vf

#include "variational_formation_core/safety/safety_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace vf {

namespace {

// The largest violation of a half-space [m^2] or of the ball [m] a result may keep.
constexpr double kMaxViolation = 1e-12;

double dot(int d, const double* a, const double* b) {
  double s = 0.0;
  for (int k = 0; k < d; ++k) s += a[k] * b[k];
  return s;
}

/// Whether a candidate δ satisfies half-space c, allowing a tenth of the violation a result may keep.
bool satisfies(int d, const HalfSpace& c, const double* delta) {
  return dot(d, c.normal, delta) - c.bound >= -0.1 * kMaxViolation;
}

/**
 * G = A A^T of k <= 3 rows, Cholesky-factored in place (lower triangle); false if a row is
 * (nearly) a combination of the earlier ones, whose face another subset gives.
 */
struct Gram {
  int k = 0;
  double l[3][3] = {};

  bool factor(int d, const HalfSpace* const* rows, int count) {
    k = count;
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j <= i; ++j) {
        double s = dot(d, rows[i]->normal, rows[j]->normal);
        const double diagonal = s;
        for (int m = 0; m < j; ++m) s -= l[i][m] * l[j][m];
        if (i == j) {
          if (!(s > 1e-12 * diagonal)) return false;
          l[i][i] = std::sqrt(s);
        } else {
          l[i][j] = s / l[j][j];
        }
      }
    }
    return true;
  }

  /// Solves G x = y (k values).
  void solve(const double* y, double* x) const {
    double t[3];
    for (int i = 0; i < k; ++i) {
      double s = y[i];
      for (int m = 0; m < i; ++m) s -= l[i][m] * t[m];
      t[i] = s / l[i][i];
    }
    for (int i = k - 1; i >= 0; --i) {
      double s = t[i];
      for (int m = i + 1; m < k; ++m) s -= l[m][i] * x[m];
      x[i] = s / l[i][i];
    }
  }
};

/// A face's nearest point to δ0 and its multipliers.
struct Candidate {
  double delta[3] = {0.0, 0.0, 0.0};
  double lambda[3] = {0.0, 0.0, 0.0};
  double mu = 0.0;
  bool onSphere = false;
};

/**
 * The nearest point to δ0 of {a_s·δ = b_s for s in S} ∩ {|δ| <= ρ}: the affine projection p, or,
 * if |p| > ρ, the point of the sphere nearest p within the affine set (c + s u/|u|, c its
 * least-norm point, u = p - c). False if S is dependent or the set is empty.
 */
bool faceCandidate(int d, const double* delta0, const HalfSpace* const* rows, int k, double maxStep,
                   Candidate& out) {
  Gram g;
  if (!g.factor(d, rows, k)) return false;
  double residual[3], lambda[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < k; ++i) residual[i] = rows[i]->bound - dot(d, rows[i]->normal, delta0);
  g.solve(residual, lambda);
  double p[3];
  for (int a = 0; a < d; ++a) {
    p[a] = delta0[a];
    for (int i = 0; i < k; ++i) p[a] += lambda[i] * rows[i]->normal[a];
  }
  const double pp = dot(d, p, p);
  if (!(pp > maxStep * maxStep)) {
    for (int a = 0; a < d; ++a) out.delta[a] = p[a];
    for (int i = 0; i < k; ++i) out.lambda[i] = lambda[i];
    out.mu = 0.0;
    out.onSphere = false;
    return true;
  }
  if (k == d) return false;  // a single point outside the ball
  double bounds[3], beta[3] = {0.0, 0.0, 0.0}, c[3];
  for (int i = 0; i < k; ++i) bounds[i] = rows[i]->bound;
  g.solve(bounds, beta);
  for (int a = 0; a < d; ++a) {
    c[a] = 0.0;
    for (int i = 0; i < k; ++i) c[a] += beta[i] * rows[i]->normal[a];
  }
  const double s2 = maxStep * maxStep - dot(d, c, c);
  if (!(s2 >= 0.0)) return false;
  double u[3];
  for (int a = 0; a < d; ++a) u[a] = p[a] - c[a];
  const double un = std::sqrt(dot(d, u, u));
  const double s = std::sqrt(s2);
  if (!(un > 0.0)) return false;
  for (int a = 0; a < d; ++a) out.delta[a] = c[a] + (s / un) * u[a];
  // Stationarity: (1 + μ) δ - δ0 = A^T λ, with 1 + μ = |u| / s from the affine set's directions.
  out.mu = un / s - 1.0;
  double y[3];
  for (int i = 0; i < k; ++i) {
    y[i] = 0.0;
    for (int a = 0; a < d; ++a) y[i] += rows[i]->normal[a] * ((1.0 + out.mu) * out.delta[a] - delta0[a]);
  }
  g.solve(y, out.lambda);
  out.onSphere = true;
  return true;
}

}  // namespace

Projection projectDisplacement(int d, const double* delta0, const std::vector<HalfSpace>& constraints,
                               double maxStep) {
  Projection result;
  projectDisplacement(d, delta0, constraints, maxStep, result);
  return result;
}

void projectDisplacement(int d, const double* delta0, const std::vector<HalfSpace>& constraints, double maxStep,
                         Projection& result) {
  const std::size_t m = constraints.size();
  result.changed = false;
  result.feasible = true;
  result.multipliers.assign(m, 0.0);  // keeps the capacity: no allocation per step
  result.speedMultiplier = 0.0;
  result.active.clear();
  result.speedLimited = false;
  const double norm0 = std::sqrt(dot(d, delta0, delta0));
  bool inside = norm0 <= maxStep;
  for (std::size_t i = 0; inside && i < m; ++i) {
    inside = dot(d, constraints[i].normal, delta0) >= constraints[i].bound;
  }
  for (int a = 0; a < d; ++a) result.delta[a] = delta0[a];
  if (inside) return;  // nothing binds: δ0 itself
  // A non-finite δ0 (a diverging run) is no step to project: it is passed on untouched, so the
  // run sees the divergence, instead of δ = 0 holding the agent where it is.
  bool finite = true;
  for (int a = 0; a < d; ++a) finite = finite && std::isfinite(delta0[a]);
  if (!finite) return;
  result.changed = true;

  // Only half-spaces that reach into |δ| <= min(|δ0|, ρ) can bind (margin for rounding).
  const double reach = std::min(norm0, maxStep) * (1.0 + 1e-9);
  std::vector<const HalfSpace*> rows;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < m; ++i) {
    const HalfSpace& c = constraints[i];
    if (c.bound >= -std::sqrt(dot(d, c.normal, c.normal)) * reach) {
      rows.push_back(&c);
      index.push_back(i);
    }
  }
  const int n = static_cast<int>(rows.size());
  const auto feasible = [&](const double* delta) {
    if (std::sqrt(dot(d, delta, delta)) - maxStep > 0.1 * kMaxViolation) return false;
    for (const HalfSpace* c : rows) {
      if (!satisfies(d, *c, delta)) return false;
    }
    return true;
  };
  double best = std::numeric_limits<double>::infinity();
  Candidate chosen;
  int chosenRows[3] = {-1, -1, -1}, chosenSize = -1;
  bool chosenSigned = false;
  const auto consider = [&](const int* subset, int k) {
    const HalfSpace* face[3];
    for (int i = 0; i < k; ++i) face[i] = rows[static_cast<std::size_t>(subset[i])];
    Candidate c;
    if (!faceCandidate(d, delta0, face, k, maxStep, c) || !feasible(c.delta)) return;
    double dist = 0.0;
    for (int a = 0; a < d; ++a) dist += (c.delta[a] - delta0[a]) * (c.delta[a] - delta0[a]);
    // Where several faces give the same point (more than d half-spaces through it), keep one
    // whose multipliers are >= 0: its certificate is the valid one.
    bool signed_ = c.mu >= 0.0;
    for (int i = 0; i < k; ++i) signed_ = signed_ && c.lambda[i] >= 0.0;
    const double tie = 1e-12 * norm0 * norm0;
    if (dist < best - tie || (dist <= best + tie && signed_ && !chosenSigned)) {
      chosenSigned = signed_;
      best = std::min(best, dist);
      chosen = c;
      chosenSize = k;
      for (int i = 0; i < k; ++i) chosenRows[i] = subset[i];
    }
  };
  // Faces by size, then lexicographically: a fixed order, so ties resolve the same everywhere.
  int s[3] = {0, 0, 0};
  consider(s, 0);
  for (s[0] = 0; s[0] < n; ++s[0]) consider(s, 1);
  for (s[0] = 0; s[0] < n; ++s[0]) {
    for (s[1] = s[0] + 1; s[1] < n; ++s[1]) consider(s, 2);
  }
  for (s[0] = 0; d == 3 && s[0] < n; ++s[0]) {
    for (s[1] = s[0] + 1; s[1] < n; ++s[1]) {
      for (s[2] = s[1] + 1; s[2] < n; ++s[2]) consider(s, 3);
    }
  }

  if (chosenSize < 0) {
    // No face is feasible: with every b <= 0 only rounding can do that, and δ = 0 is safe.
    for (int a = 0; a < d; ++a) result.delta[a] = 0.0;
    for (std::size_t i = 0; i < m; ++i) result.feasible = result.feasible && constraints[i].bound <= 0.0;
    return;
  }
  for (int a = 0; a < d; ++a) result.delta[a] = chosen.delta[a];
  for (int i = 0; i < chosenSize; ++i) {
    const std::size_t c = index[static_cast<std::size_t>(chosenRows[i])];
    result.multipliers[c] = chosen.lambda[i];
    result.active.push_back(static_cast<int>(c));
  }
  result.speedMultiplier = chosen.mu;
  result.speedLimited = chosen.onSphere;

  // Rounding may leave a·δ below b by more than kMaxViolation: shrink δ toward 0, which
  // satisfies every b <= 0 (a b = 0 half-space then leaves only δ = 0).
  for (int pass = 0; pass < 4; ++pass) {
    double t = 1.0;
    bool violated = false;
    for (std::size_t i = 0; i < m; ++i) {
      const HalfSpace& c = constraints[i];
      const double violation = c.bound - dot(d, c.normal, result.delta);
      if (violation > kMaxViolation) {
        violated = true;
        result.feasible = result.feasible && c.bound <= 0.0;
        t = std::min(t, -c.bound / (violation - c.bound));
      }
    }
    const double norm = std::sqrt(dot(d, result.delta, result.delta));
    if (norm - maxStep > kMaxViolation) {
      violated = true;
      t = std::min(t, maxStep / norm);
    }
    if (!violated || !result.feasible) break;
    for (int a = 0; a < d; ++a) result.delta[a] *= pass < 3 ? t * (1.0 - 1e-12) : 0.0;
  }
}

void obstacleOffset(const Obstacle& o, int d, const double* q, double* w) {
  if (o.shape == Obstacle::Shape::Box) {
    for (int a = 0; a < d; ++a) w[a] = q[a] - std::min(std::max(q[a], o.min(a)), o.max(a));
    return;
  }
  double e[3], ee = 0.0;
  for (int a = 0; a < d; ++a) {
    e[a] = q[a] - o.centre(a);
    ee += e[a] * e[a];
  }
  const double norm = std::sqrt(ee);
  const double f = norm > o.radius ? 1.0 - o.radius / norm : 0.0;
  for (int a = 0; a < d; ++a) w[a] = f * e[a];
}

void safetyConstraints(const SafetySettings& s, int d, const double* q, const std::vector<SensedAgent>& sensed,
                       const std::vector<Obstacle>& obstacles, std::vector<HalfSpace>& out) {
  out.clear();
  const double r2 = s.radius * s.radius, reach2 = s.sensingRadius * s.sensingRadius;
  for (std::size_t j = 0; j < sensed.size(); ++j) {
    if (j > 0 && !(sensed[j].id > sensed[j - 1].id)) {
      throw std::invalid_argument("safetyConstraints: sensed agents must be in ascending id");
    }
    HalfSpace c;
    for (int a = 0; a < d; ++a) c.normal[a] = q[a] - sensed[j].position[a];
    const double zz = dot(d, c.normal, c.normal);
    // An old position widens r and R by its margin (doc/robots.md "Safety"); 0 keeps them as they are.
    const double margin = sensed[j].margin;
    const double reach = s.sensingRadius + margin, radius = s.radius + margin;
    if (!(zz < (margin == 0.0 ? reach2 : reach * reach))) continue;
    // doc/maths.md §10, pairs: 2 z·δ >= -(γ/2)(|z|^2 - r^2); agent j states the same with -z.
    // An agent of another formation does not: this one takes the whole, -γ(|z|^2 - r^2).
    const double share = sensed[j].reciprocates ? 0.5 : 1.0;
    for (int a = 0; a < d; ++a) c.normal[a] *= 2.0;
    c.bound = std::min(0.0, -share * s.gamma * (zz - (margin == 0.0 ? r2 : radius * radius)));
    c.source = sensed[j].id;
    out.push_back(c);
  }
  const double clearance2 = 0.25 * r2;  // (r/2)^2
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    HalfSpace c;
    obstacleOffset(obstacles[k], d, q, c.normal);
    const double ww = dot(d, c.normal, c.normal);
    if (!(ww < reach2)) continue;
    // doc/maths.md §10, obstacles: 2 w·δ >= -γ(|w|^2 - (r/2)^2).
    for (int a = 0; a < d; ++a) c.normal[a] *= 2.0;
    c.bound = std::min(0.0, -s.gamma * (ww - clearance2));
    c.source = -1 - static_cast<int>(k);
    out.push_back(c);
  }
}

void filterDisplacement(const SafetySettings& s, double timeStep, int d, const double* q, const double* delta0,
                        const std::vector<SensedAgent>& sensed, const std::vector<Obstacle>& obstacles, SafeStep& step) {
  safetyConstraints(s, d, q, sensed, obstacles, step.constraints);
  projectDisplacement(d, delta0, step.constraints, s.maxSpeed * timeStep, step.projection);
}

SafeStep filterDisplacement(const SafetySettings& s, double timeStep, int d, const double* q, const double* delta0,
                            const std::vector<SensedAgent>& sensed, const std::vector<Obstacle>& obstacles) {
  SafeStep step;
  filterDisplacement(s, timeStep, d, q, delta0, sensed, obstacles, step);
  return step;
}

void filterNextPosition(const SafetySettings& s, double timeStep, int d, const double* q, double* qNext,
                        const std::vector<SensedAgent>& sensed, const std::vector<Obstacle>& obstacles, SafeStep& step) {
  double delta0[3] = {0.0, 0.0, 0.0};
  for (int a = 0; a < d; ++a) delta0[a] = qNext[a] - q[a];
  filterDisplacement(s, timeStep, d, q, delta0, sensed, obstacles, step);
  if (step.projection.changed) {
    for (int a = 0; a < d; ++a) qNext[a] = q[a] + step.projection.delta[a];
  }
}

SafeStep filterNextPosition(const SafetySettings& s, double timeStep, int d, const double* q, double* qNext,
                            const std::vector<SensedAgent>& sensed, const std::vector<Obstacle>& obstacles) {
  SafeStep step;
  filterNextPosition(s, timeStep, d, q, qNext, sensed, obstacles, step);
  return step;
}

}  // namespace vf

#include "variational_formation_core/generators/globally_rigid_graph.hpp"

#include <algorithm>
#include <charconv>
#include <set>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

namespace {

std::vector<std::pair<int, int>> completeGraph(int n) {
  std::vector<std::pair<int, int>> edges;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) edges.emplace_back(i, j);
  return edges;
}

std::vector<std::pair<int, int>> nearestNeighbourGraph(const Positions& q, int k) {
  const int n = static_cast<int>(q.cols());
  std::set<std::pair<int, int>> edges;
  for (int i = 0; i < n; ++i) {
    std::vector<double> distance;
    for (int j = 0; j < n; ++j)
      if (j != i) distance.push_back((q.col(i) - q.col(j)).norm());
    std::nth_element(distance.begin(), distance.begin() + (k - 1), distance.end());
    const double reach = distance[static_cast<std::size_t>(k - 1)] * (1.0 + 1e-9);
    for (int j = 0; j < n; ++j) {
      if (j != i && (q.col(i) - q.col(j)).norm() <= reach) edges.insert({std::min(i, j), std::max(i, j)});
    }
  }
  return {edges.begin(), edges.end()};
}

}  // namespace

GloballyRigidGraph globallyRigidGraph(const std::string& spec, const Positions& desired) {
  const int n = static_cast<int>(desired.cols()), d = static_cast<int>(desired.rows());
  GloballyRigidGraph g;
  const auto finish = [&](std::vector<std::pair<int, int>> edges) {
    g.edges = std::move(edges);
    g.rigidity = classifyRigidity(Formation(d, desired, g.edges));
  };
  if (spec == "complete") {
    finish(completeGraph(n));
    g.description = "complete graph";
    return g;
  }
  if (spec.rfind("knn", 0) != 0 || (spec.size() > 3 && spec[3] != ':')) {
    throw InvalidInput("--graph: expected complete, knn or knn:K, got '" + spec + "'");
  }
  int k = d + 1;
  if (spec.size() > 3) {
    const char* first = spec.data() + 4;
    const char* last = spec.data() + spec.size();
    const auto parsed = std::from_chars(first, last, k);
    if (first == last || parsed.ec != std::errc() || parsed.ptr != last) {
      throw InvalidInput("--graph: knn:K needs an integer K, got '" + spec + "'");
    }
    if (k < d + 1) {
      throw InvalidInput("--graph: knn:K needs K >= d + 1 = " + std::to_string(d + 1) + " (fewer cannot be globally rigid), got " +
                         std::to_string(k));
    }
  }
  if (n < 2) {
    finish({});
    g.description = "a single agent";
    return g;
  }
  const int asked = k;
  for (k = std::min(k, n - 1);; ++k) {
    finish(nearestNeighbourGraph(desired, k));
    if (g.rigidity.rigidityClass == RigidityClass::GloballyRigid || k >= n - 1) break;
  }
  g.neighbours = k;
  g.description = std::to_string(k) + " nearest neighbours (knn:" + std::to_string(asked) +
                  (k > asked ? ", augmented to " + std::to_string(k) + " until globally rigid)" : ")");
  return g;
}

}  // namespace vf

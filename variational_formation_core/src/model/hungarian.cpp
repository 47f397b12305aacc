#include "variational_formation_core/model/hungarian.hpp"

#include <limits>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

std::vector<int> minimumCostAssignment(const Eigen::MatrixXd& cost) {
  if (cost.rows() != cost.cols()) throw InvalidInput("assignment: the cost matrix must be square");
  if (!cost.allFinite()) throw InvalidInput("assignment: every cost must be finite");
  const int n = static_cast<int>(cost.rows());
  const double inf = std::numeric_limits<double>::infinity();
  // 1-based, column 0 is the virtual start of each augmenting path. u, v: potentials with
  // u_i + v_j <= cost(i, j), equal on the assigned pairs (which makes them optimal).
  std::vector<double> u(n + 1, 0.0), v(n + 1, 0.0);
  std::vector<int> rowOf(n + 1, 0), previous(n + 1, 0);
  for (int i = 1; i <= n; ++i) {
    rowOf[0] = i;
    int column = 0;
    std::vector<double> slack(n + 1, inf);
    std::vector<bool> used(n + 1, false);
    // Dijkstra on the reduced costs until a free column is reached.
    do {
      used[column] = true;
      const int row = rowOf[column];
      double delta = inf;
      int next = 0;
      for (int j = 1; j <= n; ++j) {
        if (used[j]) continue;
        const double reduced = cost(row - 1, j - 1) - u[row] - v[j];
        if (reduced < slack[j]) {
          slack[j] = reduced;
          previous[j] = column;
        }
        if (slack[j] < delta) {
          delta = slack[j];
          next = j;
        }
      }
      for (int j = 0; j <= n; ++j) {
        if (used[j]) {
          u[rowOf[j]] += delta;
          v[j] -= delta;
        } else {
          slack[j] -= delta;
        }
      }
      column = next;
    } while (rowOf[column] != 0);
    // Flip the path back to its start.
    do {
      const int before = previous[column];
      rowOf[column] = rowOf[before];
      column = before;
    } while (column != 0);
  }
  std::vector<int> columnOf(n, -1);
  for (int j = 1; j <= n; ++j) columnOf[rowOf[j] - 1] = j - 1;
  return columnOf;
}

}  // namespace vf

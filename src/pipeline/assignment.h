// Global assignment of markers to candidates: the minimum-cost matching (Hungarian method,
// exact, O(n^3)) in which each marker takes at most one candidate, each candidate goes to at
// most one marker, and leaving a marker unassigned costs its own price. Small and dense: a
// frame has a few markers and a few dozen candidates, so a plain O(n^3) solver is microseconds.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

namespace softsight {

// A pair that may not be matched (outside the marker's gate, or not a candidate of its kind).
inline constexpr double kForbidden = std::numeric_limits<double>::infinity();

// `cost[m][c]`: the price of giving candidate c to marker m (kForbidden: never), every row of
// one length. `unassigned[m]`: the price of leaving marker m without a candidate (finite).
// Returns, per marker, the index of its candidate or -1. Among equal-cost matchings the result
// is deterministic (it depends only on the matrix). The solver keeps its buffers from call to
// call: a session solves one problem per frame without allocating once the sizes are reached.
class MinimumCostAssignment {
 public:
  const std::vector<int>& solve(const std::vector<std::vector<double>>& cost,
                                const std::vector<double>& unassigned);

 private:
  std::vector<double> u_, v_, minv_;
  std::vector<std::size_t> p_, way_;
  std::vector<char> used_;
  std::vector<int> result_;
};

// The same, with a solver of its own (tests, one-off problems).
std::vector<int> AssignMinimumCost(const std::vector<std::vector<double>>& cost,
                                   const std::vector<double>& unassigned);

}  // namespace softsight

#include "pipeline/assignment.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

namespace softsight {

std::vector<int> AssignMinimumCost(const std::vector<std::vector<double>>& cost,
                                   const std::vector<double>& unassigned) {
  MinimumCostAssignment solver;
  return solver.solve(cost, unassigned);
}

const std::vector<int>& MinimumCostAssignment::solve(const std::vector<std::vector<double>>& cost,
                                                     const std::vector<double>& unassigned) {
  const size_t markers = cost.size();
  CV_Assert(unassigned.size() == markers);
  const size_t candidates = markers == 0 ? 0 : cost[0].size();
  std::vector<int>& result = result_;
  result.assign(markers, -1);
  if (markers == 0) return result;
  // Square problem of side markers + candidates: row m may take candidate c or its own
  // "unassigned" column; a dummy row per candidate takes a candidate nobody gets, or a dummy
  // column, at no cost. Forbidden pairs get a price above any complete matching's, so they are
  // chosen only where nothing else is possible (never: the unassigned columns always are).
  const size_t n = markers + candidates;
  double finite_sum = 0.0;
  for (size_t m = 0; m < markers; ++m) {
    CV_Assert(cost[m].size() == candidates && std::isfinite(unassigned[m]));
    finite_sum += std::abs(unassigned[m]);
    for (double v : cost[m]) {
      if (std::isfinite(v)) finite_sum += std::abs(v);
    }
  }
  const double big = 2.0 * finite_sum + 1.0;
  const auto at = [&](size_t r, size_t c) -> double {
    if (r < markers) {
      if (c < candidates) return std::isfinite(cost[r][c]) ? cost[r][c] : big;
      return c - candidates == r ? unassigned[r] : big;
    }
    return 0.0;
  };
  // Kuhn-Munkres with potentials (1-based arrays, column 0 a sentinel).
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double>& u = u_;
  std::vector<double>& v = v_;
  std::vector<double>& minv = minv_;
  std::vector<size_t>& p = p_;
  std::vector<size_t>& way = way_;
  std::vector<char>& used = used_;
  u.assign(n + 1, 0.0);
  v.assign(n + 1, 0.0);
  minv.resize(n + 1);
  p.assign(n + 1, 0);
  way.assign(n + 1, 0);
  used.resize(n + 1);
  for (size_t i = 1; i <= n; ++i) {
    p[0] = i;
    size_t j0 = 0;
    std::fill(minv.begin(), minv.end(), kInf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[j0] = 1;
      const size_t i0 = p[j0];
      double delta = kInf;
      size_t j1 = 0;
      for (size_t j = 1; j <= n; ++j) {
        if (used[j]) continue;
        const double cur = at(i0 - 1, j - 1) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (size_t j = 0; j <= n; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const size_t j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  for (size_t j = 1; j <= n; ++j) {
    const size_t r = p[j] - 1, c = j - 1;
    if (r < markers && c < candidates && std::isfinite(cost[r][c])) {
      result[r] = static_cast<int>(c);
    }
  }
  return result;
}

}  // namespace softsight

// loglog_slope: least-squares slope of log(v) against log(d), for power-law checks in tests.
#pragma once

#include <cmath>
#include <vector>

namespace odo::test {

inline double loglog_slope(const std::vector<double>& d, const std::vector<double>& v) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double x = std::log(d[i]), y = std::log(v[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace odo::test

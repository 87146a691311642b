// Fit of the Chong-Kleeman coefficients k_L, k_R from repeated out-and-back runs.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>

#include "odo/analysis/csv.hpp"
#include "odo/analysis/error_model_tools.hpp"

namespace odo::analysis {
namespace {

using Mat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

constexpr int kMinRuns = 5;  // fewer cannot give a non-singular 3 x 3 sample covariance

Mat3 to_mat(const Cov3& c) {
  return Eigen::Map<const Mat3>(c.data());
}

// Bounds of the search in log(k^2): k from 1e-9 (no noise, for practical purposes) to the
// configurable maximum.
const double kLogK2Min = 2.0 * std::log(1e-9);
const double kLogK2Max = 2.0 * std::log(kErrorModelKMax);

}  // namespace

Result<std::vector<PoseError>> read_run_errors(std::istream& in, const std::string& source) {
  CsvReader csv(in, source);
  auto cols = csv.header({"ex", "ey", "etheta"}, {"run"});
  if (!cols) return std::move(cols).error();
  const std::array<const char*, 3> names{"ex", "ey", "etheta"};
  std::vector<PoseError> out;
  std::vector<std::string> f;
  while (csv.next(f)) {
    if (f.size() != csv.columns()) {
      return csv.error("expected " + std::to_string(csv.columns()) + " fields, found " +
                       std::to_string(f.size()));
    }
    PoseError e{};
    for (int i = 0; i < 3; ++i) {
      auto v = csv.parse_double(f[static_cast<std::size_t>((*cols)[i])], names[i]);
      if (!v) return std::move(v).error();
      if (std::fabs(*v) > kMaxReturnError)
        return csv.range_error(return_error_range(names[i], *v, i < 2 ? "m" : "rad"));
      e[i] = *v;
    }
    out.push_back(e);
  }
  if (static_cast<int>(out.size()) < kMinRuns) {
    return make_error(Errc::kParse, source + ": " + std::to_string(out.size()) +
                                        " runs found; the fit needs at least " +
                                        std::to_string(kMinRuns) + " (the paper used 60)");
  }
  return out;
}

void write_run_errors(std::ostream& out, const std::vector<PoseError>& e) {
  out << "run,ex,ey,etheta\n" << std::setprecision(17);
  for (std::size_t i = 0; i < e.size(); ++i)
    out << i + 1 << "," << e[i][0] << "," << e[i][1] << "," << e[i][2] << "\n";
}

namespace {

using Point2 = std::array<double, 2>;

// singular: true when the sample has no likelihood maximum (identical runs, or errors all on
// one line).
bool singular(const Mat3& s) {
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Mat3>(s).eigenvalues();
  return !(ev(0) > 1e-12 * ev(2)) || !(ev(2) > 0.0);
}

// nelder_mead: the minimum of f over the plane from the simplex start, start + (1, 0),
// start + (0, 1) (at most 5000 steps; stops when the simplex has shrunk to 1e-12).
template <class F>
Point2 nelder_mead(F f, const Point2& start) {
  std::array<Point2, 3> x{{start, {start[0] + 1.0, start[1]}, {start[0], start[1] + 1.0}}};
  std::array<double, 3> fx{f(x[0]), f(x[1]), f(x[2])};
  for (int it = 0; it < 5000; ++it) {
    std::array<int, 3> o{0, 1, 2};
    std::sort(o.begin(), o.end(), [&](int i, int j) { return fx[i] < fx[j]; });
    const auto best = x[o[0]], mid = x[o[1]], worst = x[o[2]];
    const double fb = fx[o[0]], fm = fx[o[1]], fw = fx[o[2]];
    if (std::fabs(worst[0] - best[0]) + std::fabs(worst[1] - best[1]) +
            std::fabs(mid[0] - best[0]) + std::fabs(mid[1] - best[1]) <
        1e-12) {
      break;
    }
    const Point2 c{(best[0] + mid[0]) / 2, (best[1] + mid[1]) / 2};
    auto along = [&](double t) {
      return Point2{c[0] + t * (worst[0] - c[0]), c[1] + t * (worst[1] - c[1])};
    };
    const auto xr = along(-1.0);
    const double fr = f(xr);
    if (fr < fb) {
      const auto xe = along(-2.0);
      const double fe = f(xe);
      x[o[2]] = fe < fr ? xe : xr;
      fx[o[2]] = std::min(fe, fr);
    } else if (fr < fm) {
      x[o[2]] = xr;
      fx[o[2]] = fr;
    } else {
      const auto xc = fr < fw ? along(-0.5) : along(0.5);
      const double fc = f(xc);
      if (fc < std::min(fr, fw)) {
        x[o[2]] = xc;
        fx[o[2]] = fc;
      } else {  // shrink towards the best vertex
        for (int i : {o[1], o[2]}) {
          x[i] = {(x[i][0] + best[0]) / 2, (x[i][1] + best[1]) / 2};
          fx[i] = f(x[i]);
        }
      }
    }
  }
  return x[static_cast<std::size_t>(std::min_element(fx.begin(), fx.end()) - fx.begin())];
}

}  // namespace

Result<FitResult> fit_error_model(const std::vector<PoseError>& errors, double d, double b) {
  if (static_cast<int>(errors.size()) < kMinRuns) {
    return make_error(Errc::kInvalidArgument, "the fit needs at least 5 runs");
  }
  FitResult r;
  r.runs = static_cast<int>(errors.size());
  r.sample = sample_covariance(errors, &r.mean);
  // Maximum likelihood uses the divisor n; sample_covariance uses n - 1.
  const double n = static_cast<double>(errors.size());
  const Mat3 s = to_mat(r.sample) * ((n - 1.0) / n);
  if (singular(s)) {
    return make_error(Errc::kInvalidArgument,
                      "the sample covariance of the run errors is singular (identical or "
                      "collinear errors): nothing to fit");
  }
  // The model is linear in k_L^2 and k_R^2: Sigma = k_L^2 A + k_R^2 B.
  const Mat3 a = to_mat(outback_covariance(d, b, {1.0, 0.0}));
  const Mat3 bm = to_mat(outback_covariance(d, b, {0.0, 1.0}));
  auto nll = [&](const Point2& p) {
    // Negative log-likelihood per run (constants dropped): log det Sigma + tr(Sigma^-1 S).
    const double u = std::clamp(p[0], kLogK2Min, kLogK2Max);
    const double v = std::clamp(p[1], kLogK2Min, kLogK2Max);
    const Mat3 sig = std::exp(u) * a + std::exp(v) * bm;
    const Eigen::LLT<Mat3> llt(sig);
    if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
    const double logdet = 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
    return logdet + (llt.solve(s)).trace();
  };
  // Start where the heading variance alone points: Sigma_tt = (k_L^2 + k_R^2) 2d/b^2.
  const double k2 = std::max(s(2, 2) / (a(2, 2) + bm(2, 2)), 1e-30);
  const double start = std::clamp(std::log(k2), kLogK2Min, kLogK2Max);
  // Nelder-Mead on (log k_L^2, log k_R^2): two parameters, a smooth objective.
  const Point2 best = nelder_mead(nll, {start, start});
  r.k.k_left = std::sqrt(std::exp(std::clamp(best[0], kLogK2Min, kLogK2Max)));
  r.k.k_right = std::sqrt(std::exp(std::clamp(best[1], kLogK2Min, kLogK2Max)));
  r.predicted = outback_covariance(d, b, r.k);
  return r;
}

}  // namespace odo::analysis

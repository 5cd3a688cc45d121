#include "tracking/integrity/consistency.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "models/errors.h"

namespace linetrack {

namespace {

constexpr double kSqrtPi = 1.7724538509055160273;

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t half = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + half, values.end());
  if (values.size() % 2 == 1) return values[half];
  const double upper = values[half];
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + half));
}

}  // namespace

double ChiSquareUpperTail(int dof, double x) {
  if (dof < 1) throw InputError("chi-square: degrees of freedom must be at least 1");
  if (!(x > 0.0)) return 1.0;
  const double half = 0.5 * x;
  const double decay = std::exp(-half);
  double sum = 0.0;
  if (dof % 2 == 0) {
    double term = 1.0;  // (x/2)^j / j!
    for (int j = 0; j < dof / 2; ++j) {
      sum += term;
      term *= half / (j + 1);
    }
    return std::min(1.0, decay * sum);
  }
  double term = std::sqrt(half) / (0.5 * kSqrtPi);  // (x/2)^(1/2) / Gamma(3/2)
  for (int j = 0; j <= (dof - 3) / 2 && dof >= 3; ++j) {
    sum += term;
    term *= half / (j + 1.5);
  }
  return std::min(1.0, std::erfc(std::sqrt(half)) + decay * sum);
}

double ChiSquareUpperQuantile(int dof, double upper_tail) {
  if (!(upper_tail > 0.0 && upper_tail < 1.0)) {
    throw InputError("chi-square quantile: the upper tail must lie in (0, 1)");
  }
  double lo = 0.0, hi = std::max(1.0, static_cast<double>(dof));
  while (ChiSquareUpperTail(dof, hi) > upper_tail)
    hi *= 2.0;
  while (hi - lo > 1e-12 * hi) {
    const double mid = 0.5 * (lo + hi);
    (ChiSquareUpperTail(dof, mid) > upper_tail ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double Nees(const Eigen::VectorXd& error, const Eigen::MatrixXd& covariance) {
  const Eigen::LLT<Eigen::MatrixXd> llt(covariance);
  if (llt.info() != Eigen::Success || !covariance.allFinite()) {
    return std::numeric_limits<double>::infinity();
  }
  return error.dot(llt.solve(error));
}

void CalibrationTally::Add(double nees, double sigma, double error) {
  nees_.push_back(nees);
  sigmas_.push_back(sigma);
  errors_.push_back(error);
}

CalibrationSummary CalibrationTally::Summary() const {
  CalibrationSummary s;
  s.dof = dof_;
  s.count = count();
  for (size_t i = 0; i < s.kLevels.size(); ++i) {
    s.quantiles[i] = ChiSquareUpperQuantile(dof_, 1.0 - s.kLevels[i]);
    const auto inside =
        std::count_if(nees_.begin(), nees_.end(), [&](double n) { return n <= s.quantiles[i]; });
    s.shares[i] = s.count > 0 ? static_cast<double>(inside) / s.count : 0.0;
  }
  double sum = 0.0;
  for (double n : nees_)
    sum += n;
  s.mean_nees = s.count > 0 ? sum / s.count : 0.0;
  s.median_sigma = Median(sigmas_);
  s.median_error = Median(errors_);
  return s;
}

std::string CalibrationSummary::Row(const std::string& label) const {
  std::ostringstream row;
  row << std::fixed << std::setprecision(2) << "| " << label << " | " << count << " | " << mean_nees
      << " (" << dof << ") |";
  for (size_t i = 0; i < kLevels.size(); ++i)
    row << std::setprecision(1) << " " << 100.0 * shares[i] << " % |";
  row << std::setprecision(4) << " " << median_sigma << " / " << median_error << " |";
  return row.str();
}

std::string CalibrationSummary::Table(const std::string& label, const std::string& unit) const {
  std::ostringstream table;
  table << "| estimate | count | mean NEES (dof) |";
  for (double level : kLevels)
    table << " within chi2 " << 100.0 * level << " % |";
  table << " median sigma / median error (" << unit << ") |\n| --- | --- | --- |";
  for (size_t i = 0; i < kLevels.size(); ++i)
    table << " --- |";
  table << " --- |\n" << Row(label) << "\n";
  return table.str();
}

}  // namespace linetrack

// Is a covariance honest? The chi-square distribution (exact, integer degrees of freedom), the
// normalised estimation error squared NEES = e' P^-1 e of an estimate against the truth, and a
// reliability table of many NEES values (docs/integrity.md, section 3) for the benches.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace linetrack {

// Upper tail P(X > x) of chi2(dof), dof >= 1: e^(-x/2) sum_{j < dof/2} (x/2)^j / j! for even
// dof; erfc(sqrt(x/2)) + e^(-x/2) sum_{j <= (dof-3)/2} (x/2)^(j+1/2) / Gamma(j + 3/2) for odd.
double ChiSquareUpperTail(int dof, double x);

// The x with ChiSquareUpperTail(dof, x) = upper_tail, upper_tail in (0, 1) (bisection to a
// relative 1e-12). E.g. dof 2, 0.01: 9.21; dof 3, 0.001: 16.27.
double ChiSquareUpperQuantile(int dof, double upper_tail);

// e' P^-1 e; infinite when P is not positive definite.
double Nees(const Eigen::VectorXd& error, const Eigen::MatrixXd& covariance);

// What a set of NEES values says about the covariances they came from: the share inside the
// chi-square regions of `kLevels`, and the median reported sigma beside the median actual error
// (of one quantity the caller chooses, e.g. the largest position axis and the position error).
struct CalibrationSummary {
  static constexpr std::array<double, 4> kLevels = {0.5, 0.9, 0.99, 0.999};
  int dof = 0;
  int count = 0;
  std::array<double, 4> quantiles = {};  // chi2(dof) quantiles at kLevels
  std::array<double, 4> shares = {};     // share of NEES <= quantiles[i]
  double mean_nees = 0.0;                // dof when calibrated
  double median_sigma = 0.0;
  double median_error = 0.0;

  // A Markdown table: a header line and a row "| label | count | mean NEES | shares | median
  // sigma / median error |" (sigma and error in the caller's units, `unit`).
  std::string Table(const std::string& label, const std::string& unit) const;
  // The row alone, for tables of several labels.
  std::string Row(const std::string& label) const;
};

// Collects NEES values (and sigma, error pairs) of one dimension.
class CalibrationTally {
 public:
  explicit CalibrationTally(int dof) : dof_(dof) {}

  // One estimate: its NEES, and a reported sigma with the actual error of the same quantity.
  void Add(double nees, double sigma, double error);
  CalibrationSummary Summary() const;
  int count() const { return static_cast<int>(nees_.size()); }

 private:
  int dof_;
  std::vector<double> nees_, sigmas_, errors_;
};

}  // namespace linetrack

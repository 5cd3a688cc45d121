#include "matching/quantiles.h"

#include <algorithm>
#include <cmath>

namespace linetrack {

double ChiSquareQuantile(double dof, double z) {
  const double k = std::max(dof, 1.0);
  const double c = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - c + z * std::sqrt(c), 3.0);
}

double NormalQuantile(double p) {
  const double q = std::sqrt(-2.0 * std::log(1.0 - p));
  return -(((((-7.784894002430293e-03 * q - 3.223964580411365e-01) * q - 2.400758277161838e+00) *
                 q -
             2.549732539343734e+00) *
                q +
            4.374664141464968e+00) *
               q +
           2.938163982698783e+00) /
         ((((7.784695709041462e-03 * q + 3.224671290700398e-01) * q + 2.445134137142996e+00) * q +
           3.754408661907416e+00) *
              q +
          1.0);
}

}  // namespace linetrack

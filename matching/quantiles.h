// Quantiles of the distributions the verification's tests use (closed-form approximations, no
// iteration): the gates and decisions of matching/ are read at these.
#pragma once

namespace linetrack {

// Wilson-Hilferty approximation of the chi-square quantile with `dof` degrees of freedom at
// standard normal quantile z.
double ChiSquareQuantile(double dof, double z);

// Standard normal quantile for p in (0.975, 1) (Acklam's rational approximation, upper tail;
// relative error below 1.2e-9).
double NormalQuantile(double p);

}  // namespace linetrack

// Internal: Gauss quadrature rules from the Golub-Welsch eigenvalue method.
#pragma once

#include <vector>

namespace lugrip::detail {

//! Nodes and weights of the n-point Gauss rule for the weight (1 - x^2)^alpha on [-1, 1]
//! (alpha > -1; alpha = 0 is Gauss-Legendre). Nodes ascending.
void gauss_gegenbauer(int n, double alpha, std::vector<double>& x, std::vector<double>& w);

//! n-point Gauss-Jacobi rule for the weight (1 - x)^alpha (1 + x)^beta on [-1, 1]
//! (alpha, beta > -1). Nodes ascending.
void gauss_jacobi(int n, double alpha, double beta, std::vector<double>& x, std::vector<double>& w);

}  // namespace lugrip::detail

#include "quadrature.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace lugrip::detail {

namespace {

// Eigenvalues of the symmetric tridiagonal matrix (diag d, off-diagonal e[i] between i and
// i+1) and the first component of each normalized eigenvector, by implicit QL iterations with
// Wilkinson-like shifts. Only the first row of the eigenvector matrix is accumulated.
void tridiagonal_eigen(std::vector<double>& d, std::vector<double> e, std::vector<double>& first) {
  const int n = static_cast<int>(d.size());
  first.assign(n, 0.0);
  first[0] = 1.0;
  e.push_back(0.0);
  for (int l = 0; l < n; ++l) {
    for (int sweep = 0; sweep < 60; ++sweep) {
      int m = l;
      for (; m < n - 1; ++m) {
        const double scale = std::fabs(d[m]) + std::fabs(d[m + 1]);
        if (std::fabs(e[m]) <= 1e-16 * scale) break;
      }
      if (m == l) break;
      // Shift from the leading 2x2 block.
      double g = (d[l + 1] - d[l]) / (2.0 * e[l]);
      double r = std::hypot(g, 1.0);
      g = d[m] - d[l] + e[l] / (g + std::copysign(r, g));
      double s = 1.0, c = 1.0, p = 0.0;
      bool deflated = false;
      for (int i = m - 1; i >= l; --i) {
        const double f = s * e[i];
        const double b = c * e[i];
        r = std::hypot(f, g);
        e[i + 1] = r;
        if (r == 0.0) {  // underflow: split the matrix here
          d[i + 1] -= p;
          e[m] = 0.0;
          deflated = true;
          break;
        }
        s = f / r;
        c = g / r;
        g = d[i + 1] - p;
        r = (d[i] - g) * s + 2.0 * c * b;
        p = s * r;
        d[i + 1] = g + p;
        g = c * r - b;
        const double z1 = first[i + 1];
        first[i + 1] = s * first[i] + c * z1;
        first[i] = c * first[i] - s * z1;
      }
      if (deflated) continue;
      d[l] -= p;
      e[l] = g;
      e[m] = 0.0;
    }
  }
}

}  // namespace

void gauss_gegenbauer(int n, double alpha, std::vector<double>& x, std::vector<double>& w) {
  gauss_jacobi(n, alpha, alpha, x, w);
  // Exact symmetry of the rule.
  for (int i = 0; i < n / 2; ++i) {
    const double xs = 0.5 * (x[n - 1 - i] - x[i]);
    const double ws = 0.5 * (w[i] + w[n - 1 - i]);
    x[i] = -xs;
    x[n - 1 - i] = xs;
    w[i] = w[n - 1 - i] = ws;
  }
  if (n % 2 == 1) x[n / 2] = 0.0;
}

void gauss_jacobi(int n, double alpha, double beta, std::vector<double>& x, std::vector<double>& w) {
  if (n < 1 || !(alpha > -1.0) || !(beta > -1.0)) throw std::invalid_argument("gauss_jacobi: bad arguments");
  const double ab = alpha + beta;
  std::vector<double> d(n), e(n > 1 ? n - 1 : 0), first;
  for (int j = 0; j < n; ++j) {
    const double s = 2.0 * j + ab;
    d[j] = (j == 0) ? (beta - alpha) / (ab + 2.0) : (beta * beta - alpha * alpha) / (s * (s + 2.0));
  }
  for (int j = 1; j < n; ++j) {
    const double jj = j, s = 2.0 * jj + ab;
    e[j - 1] = std::sqrt(4.0 * jj * (jj + alpha) * (jj + beta) * (jj + ab) / (s * s * (s + 1.0) * (s - 1.0)));
  }
  tridiagonal_eigen(d, e, first);
  // mu0 = int (1-x)^alpha (1+x)^beta dx = 2^(alpha+beta+1) B(alpha+1, beta+1)
  const double mu0 = std::exp((ab + 1.0) * std::log(2.0) + std::lgamma(alpha + 1.0) + std::lgamma(beta + 1.0) -
                              std::lgamma(ab + 2.0));
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return d[a] < d[b]; });
  x.resize(n);
  w.resize(n);
  for (int i = 0; i < n; ++i) {
    x[i] = d[order[i]];
    w[i] = mu0 * first[order[i]] * first[order[i]];
  }
}

}  // namespace lugrip::detail

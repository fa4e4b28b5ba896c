// Example 1 (C++): limit-surface values and one CoR estimate. Pair: 01_limit_surface.py.
#include <cstdio>

#include "lugrip/lugrip.hpp"

int main() {
  const lugrip::LimitSurface ls(4.0);  // k = 4: the paper's xi = 0.6354
  std::printf("xi(4) = %.6f\n", ls.xi());
  for (double c : {0.0, 0.5, 1.0, 1.5, 10.0})
    std::printf("c~ = %5.2f   f~* = %+.6f   tau~* = %.6f\n", c, ls.ft_star(c), ls.tau_star(c));

  // Construct (validates, builds tables) once; then step() per sample: noexcept, no allocation.
  lugrip::CorEstimator estimator(lugrip::object_params("small_resin_block"));
  lugrip::CorOutput out;
  const lugrip::Status status = estimator.step({5.0, 1.20, -4.15e-3}, out);  // f_n [N], f_t [N], tau [N m]
  std::printf("status %s: c~ = %.4f (c = %.3f mm), inside LS = %d, g = %.3f N mm, y = %.3f N mm\n",
              lugrip::to_string(status), out.c_tilde, out.c * 1e3, out.inside, out.g * 1e3, out.y * 1e3);
  return 0;
}

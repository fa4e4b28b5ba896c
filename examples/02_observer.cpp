// Example 02 (C++): the sliding-velocity observer on one simulated sliding maneuver.
//
// A slider (paper eqs. 1-2) is pressed against a fingertip with f_n = 3 N and pushed about a
// centre of rotation at c~ = 0.3 with a torque that ramps past the dry capacity g, holds and
// releases. The fingertip sensor reads the wrench the OBJECT exerts on the FINGERTIP
// (ContactModel::wrench_at); the observer gets only that wrench, sample by sample at 500 Hz,
// and estimates the slip velocity omega_hat and the slippage indicator S (eq. 37).
//
// Build: cmake -S . -B build/ex -DLUGRIP_BUILD_EXAMPLES=ON && cmake --build build/ex
// or by hand: g++ -std=c++17 -O2 -Iinclude examples/02_observer.cpp build/ex/liblugrip.a
// The Python twin is examples/02_observer.py.
#include <cmath>
#include <cstdio>

#include "lugrip/contact.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/params.hpp"
#include "lugrip/slider_model.hpp"

int main() {
  using namespace lugrip;
  const ContactParams params = table1_params();  // paper Table 1 (cardboard slider)
  const ContactModel model(params);              // LS tables: build once, share
  const double f_n = 3.0, c_tilde = 0.3, dt = 0.002;

  // Plant: J = 1e-4 kg m^2 about the CoR; target steady slip 0.2 rad/s at the peak load.
  SliderModel plant(model, 1e-4);
  const double g = model.g(f_n, c_tilde), sigma_1 = model.sigma_1(f_n, c_tilde);
  const double peak = g + sigma_1 * 0.2;  // eq. 2 at steady sliding: tau_e = g + sigma_1 omega

  // Observer with the default settings (Rosenbrock update, bandwidth mode: gain
  // l = 3000 / sigma_1, so omega_hat converges at 3000/s while sliding).
  Observer observer(model);
  SliderOutput truth;
  ObserverOutput est;  // caller-owned, reused every cycle: step() never allocates
  double sq_err = 0.0;
  int n = 0;
  std::printf("%6s %10s %10s %10s %6s %7s %s\n", "t [s]", "tau_e/g", "omega", "omega_hat", "S",
              "c~", "status");
  for (int i = 0; i < 1000; ++i) {
    const double t = i * dt;
    // 0.2 s rest, 0.6 s ramp, 0.6 s hold, 0.3 s release, rest
    double level = 0.0;
    if (t >= 0.2 && t < 0.8) level = (t - 0.2) / 0.6;
    else if (t >= 0.8 && t < 1.4) level = 1.0;
    else if (t >= 1.4 && t < 1.7) level = 1.0 - (t - 1.4) / 0.3;
    plant.step(SliderInput{f_n, c_tilde, level * peak, dt}, truth);

    double f_t = 0.0, tau = 0.0;  // what the fingertip sensor reads (noise-free here)
    model.wrench_at(f_n, c_tilde, truth.friction_torque, f_t, tau);
    observer.step(ObserverInput{f_n, f_t, tau, dt}, est);

    sq_err += (est.omega_hat - truth.omega) * (est.omega_hat - truth.omega);
    ++n;
    if (i % 50 == 0)
      std::printf("%6.2f %10.3f %10.5f %10.5f %6.3f %7.3f %s\n", t, level * peak / g, truth.omega,
                  est.omega_hat, est.S, est.c_tilde, to_string(est.status));
  }
  std::printf("RMSE of omega_hat over the maneuver: %.5f rad/s\n", std::sqrt(sq_err / n));
  return 0;
}

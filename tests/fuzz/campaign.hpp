// Adversarial campaign over the real-time components (CorEstimator, Observer, GraspController,
// SlipControl), shared by the seeded driver (seeded_campaign.cpp, run by ctest) and the
// libFuzzer target (fuzz_target.cpp). One "case" draws a component, its settings (field values
// at the edges of what validate() accepts, found by bisection, plus hostile values that must be
// rejected) and a sequence of hostile samples, then checks the promises of the headers:
//  * construction throws exactly when validate() rejects the settings;
//  * every floating output of step() is finite; |c~| <= c_max; the command is in [f_min, f_max];
//  * CorEstimator / Observer: a twin that never saw the rejected samples (InvalidSample,
//    SensorFault; NoContact for the estimator) gives bit-identical outputs on the others;
//  * GraspController: a command due while a present finger is invalid is held (never lowered);
//  * (seeded driver only) step() allocates nothing.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "lugrip/contact.hpp"
#include "lugrip/grasp_controller.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/settings_fields.hpp"
#include "lugrip/params.hpp"
#include "lugrip/slip_control.hpp"

namespace lugrip_fuzz {

using namespace lugrip;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDenorm = std::numeric_limits<double>::denorm_min();
constexpr double kMax = std::numeric_limits<double>::max();

// --- randomness: a seeded generator or the fuzzer's bytes ----------------------------------------
class Source {
 public:
  explicit Source(uint64_t seed) : rng_(seed) {}
  Source(const uint8_t* data, size_t size) : data_(data), size_(size), bytes_(true) {}

  uint64_t u64() {
    if (!bytes_) return rng_();
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v = (v << 8) | (pos_ < size_ ? data_[pos_++] : 0u);
    return v;
  }
  double uniform() { return static_cast<double>(u64() >> 11) * 0x1.0p-53; }  // [0, 1)
  bool chance(double p) { return uniform() < p; }
  int below(int n) { return static_cast<int>(u64() % static_cast<uint64_t>(n)); }
  bool exhausted() const { return bytes_ && pos_ >= size_; }

 private:
  std::mt19937_64 rng_{0};
  const uint8_t* data_ = nullptr;
  size_t size_ = 0, pos_ = 0;
  bool bytes_ = false;
};

// A value no range check should let through, or one at the edge of the representable doubles.
inline double hostile(Source& src) {
  static const double menu[] = {kNaN,    -kNaN,   kInf,   -kInf,  kDenorm, -kDenorm, 1e-310, -1e-310,
                                1e-300,  -1e-300, 1e300,  -1e300, kMax,    -kMax,    0.0,    -0.0,
                                1e-13,   1e15,    -1e15,  1e9,    -1e9,    1e6,      -1e6,   1e3};
  const int n = static_cast<int>(sizeof(menu) / sizeof(menu[0]));
  const int i = src.below(n + 1);
  if (i < n) return menu[i];
  uint64_t bits = src.u64();  // any bit pattern
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// A value near `typical` (sign random unless positive), or hostile with probability p_bad.
inline double sample(Source& src, double typical, double p_bad, bool positive = false) {
  if (src.chance(p_bad)) return hostile(src);
  const double v = typical * (2.0 * src.uniform() - (positive ? 0.0 : 1.0));
  return src.chance(0.02) ? v * 1e3 : v;
}

// --- settings at the edges of validity ----------------------------------------------------------
// A double field of a settings struct S; its accepted interval around the default is found by
// bisection on the ordered bit patterns of the doubles, so the campaign follows validate()
// wherever its bounds are.
// The fields come from the core's tables (lugrip/settings_fields.hpp, grasp_controller_fields.hpp):
// every number and switch of a table is drawn, a nested struct's as "cor.f_n_min".
template <class S, class T>
struct NumberField {
  std::string name;
  std::function<T*(S&)> ref;
};
template <class S>
using RealField = NumberField<S, double>;
template <class S>
using IntField = NumberField<S, int>;
template <class S>
using BoolField = NumberField<S, bool>;

// Total order of doubles as integers (negative values mapped below positive ones).
inline int64_t order_key(double v) {
  int64_t i;
  std::memcpy(&i, &v, sizeof i);
  return i >= 0 ? i : std::numeric_limits<int64_t>::min() - i;
}
inline double from_key(int64_t k) {
  const int64_t i = k >= 0 ? k : std::numeric_limits<int64_t>::min() - k;
  double v;
  std::memcpy(&v, &i, sizeof v);
  return v;
}

// lo <= hi: hi - lo without overflow, and the floor of their mean.
inline uint64_t gap(int64_t lo, int64_t hi) { return static_cast<uint64_t>(hi) - static_cast<uint64_t>(lo); }
inline int64_t midpoint(int64_t lo, int64_t hi) { return lo + static_cast<int64_t>(gap(lo, hi) / 2); }

// Edges of the accepted set along one field (others fixed): the extreme accepted values and the
// first rejected values just outside (when the edge is not +-inf).
struct Edges {
  std::vector<double> inside, outside;
};

template <class S, class Valid>
Edges find_edges(const S& base, const std::function<double*(S&)>& ref, Valid valid) {
  S s = base;
  const double d = *ref(s);
  auto ok = [&](int64_t key) {
    *ref(s) = from_key(key);
    const bool r = valid(s);
    *ref(s) = d;
    return r;
  };
  Edges e;
  const int64_t k0 = order_key(d), k_hi = order_key(kInf), k_lo = order_key(-kInf);
  // upward: largest accepted key
  if (ok(k_hi)) {
    e.inside.push_back(kInf);
  } else {
    int64_t a = k0, b = k_hi;  // ok(a), !ok(b)
    while (gap(a, b) > 1) {
      const int64_t m = midpoint(a, b);
      (ok(m) ? a : b) = m;
    }
    e.inside.push_back(from_key(a));
    e.outside.push_back(from_key(b));
  }
  if (ok(k_lo)) {
    e.inside.push_back(-kInf);
  } else {
    int64_t a = k0, b = k_lo;  // ok(a), !ok(b), b < a
    while (gap(b, a) > 1) {
      const int64_t m = midpoint(b, a);
      (ok(m) ? a : b) = m;
    }
    e.inside.push_back(from_key(a));
    e.outside.push_back(from_key(b));
  }
  return e;
}

template <class S, class Valid>
Edges find_int_edges(const S& base, const std::function<int*(S&)>& ref, Valid valid) {
  S s = base;
  const int d = *ref(s);
  auto ok = [&](int64_t v) {
    *ref(s) = static_cast<int>(v);
    const bool r = valid(s);
    *ref(s) = d;
    return r;
  };
  Edges e;
  int64_t a = d, b = std::numeric_limits<int>::max();
  if (ok(b)) {
    e.inside.push_back(static_cast<double>(b));
  } else {
    while (b - a > 1) {
      const int64_t m = a + (b - a) / 2;
      (ok(m) ? a : b) = m;
    }
    e.inside.push_back(static_cast<double>(a));
    e.outside.push_back(static_cast<double>(b));
  }
  a = d;
  b = std::numeric_limits<int>::min();
  if (ok(b)) {
    e.inside.push_back(static_cast<double>(b));
  } else {
    while (a - b > 1) {
      const int64_t m = b + (a - b) / 2;
      (ok(m) ? a : b) = m;
    }
    e.inside.push_back(static_cast<double>(a));
    e.outside.push_back(static_cast<double>(b));
  }
  return e;
}

// Draws a settings struct: each field keeps its default, or takes an edge value (inside, or
// with small probability just outside), a value near the edge, or a hostile value.
template <class S>
struct SettingsSpace {
  S base;
  std::vector<RealField<S>> reals;
  std::vector<IntField<S>> ints;
  std::vector<BoolField<S>> bools;  // every value is valid: drawn true or false
  std::vector<Edges> real_edges, int_edges;

  template <class Valid>
  void init(Valid valid) {
    for (auto& f : reals) real_edges.push_back(find_edges(base, f.ref, valid));
    for (auto& f : ints) int_edges.push_back(find_int_edges(base, f.ref, valid));
  }

  static double pick(Source& src, const Edges& e, double d, bool allow_invalid) {
    const int r = src.below(allow_invalid ? 100 : 80);
    if (r < 45) return d;
    if (r < 80 && !e.inside.empty()) {  // an accepted extreme, or a geometric step inside it
      const double v = e.inside[src.below(static_cast<int>(e.inside.size()))];
      if (!std::isfinite(v) || src.chance(0.6)) return v;
      const double t = src.uniform();
      // log-interpolate between the default and the edge (same sign), else linear
      if (v > 0.0 && d > 0.0) return std::exp(std::log(d) + t * (std::log(v) - std::log(d)));
      return d + t * (v - d);
    }
    if (r < 86 && !e.outside.empty()) return e.outside[src.below(static_cast<int>(e.outside.size()))];
    return hostile(src);
  }

  // allow_invalid false: only accepted values (edges and values between default and edge)
  S draw(Source& src, double p_field) const {
    S s = base;
    const bool allow_invalid = src.chance(0.4);
    for (size_t i = 0; i < reals.size(); ++i)
      if (src.chance(p_field)) *reals[i].ref(s) = pick(src, real_edges[i], *reals[i].ref(s), allow_invalid);
    for (size_t i = 0; i < ints.size(); ++i)
      if (src.chance(p_field)) {
        const double v = pick(src, int_edges[i], *ints[i].ref(s), allow_invalid);
        *ints[i].ref(s) = std::isfinite(v) && std::fabs(v) < 2.1e9 ? static_cast<int>(v) : -1;
      }
    for (const auto& f : bools)
      if (src.chance(p_field)) *f.ref(s) = src.chance(0.5);
    return s;
  }
};

// Adds every double, int and bool field of S's table to the space of Root (get: Root -> S);
// a nested struct's fields with its name as prefix. Enumerations are drawn by the cases
// themselves (valid and out-of-range values).
template <class S, class Root, class Get>
void add_table(SettingsSpace<Root>& space, Get get, const std::string& prefix) {
  lugrip::detail::for_each_entry(lugrip::FieldTable<S>::fields, [&](const auto& f) {
    using T = std::decay_t<decltype(std::declval<S&>().*(f.member))>;
    const auto m = f.member;
    const std::string name = prefix + f.name;
    if constexpr (std::is_same_v<T, double> || std::is_same_v<T, int> || std::is_same_v<T, bool>) {
      NumberField<Root, T> field{name, [get, m](Root& r) -> T* { return &(get(r).*m); }};
      if constexpr (std::is_same_v<T, double>) space.reals.push_back(field);
      else if constexpr (std::is_same_v<T, int>) space.ints.push_back(field);
      else space.bools.push_back(field);
    } else if constexpr (std::is_class_v<T>) {
      add_table<T>(space, [get, m](Root& r) -> T& { return get(r).*m; }, name + ".");
    } else {
      static_assert(std::is_enum_v<T>, "a field type the campaign cannot draw: add it to add_table");
    }
  });
}

// The space of S: its base value and every field of its table.
template <class S>
void add_table(SettingsSpace<S>& space) {
  add_table<S>(space, [](S& s) -> S& { return s; }, "");
}

// --- statistics ---------------------------------------------------------------------------------
struct Stats {
  long cases = 0, samples = 0;
  long settings_rejected = 0;   // drawn settings that validate() rejected (constructor threw)
  long ctor_mismatch = 0;       // constructor threw for valid settings or accepted invalid ones
  long non_finite = 0;          // floating outputs that were NaN or Inf
  long out_of_range = 0;        // command outside [f_min, f_max], |c~| > c_max, S outside [0, 1]
  long twin_mismatch = 0;       // twin that never saw the rejected samples disagrees
  long not_held = 0;            // command lowered while a present finger was invalid
  long unknown_status_ok = 0;   // out-of-enum finger status reported as Ok (a failure)
  long allocations = 0;         // operator new calls inside step() (seeded driver only)
  long rejected_samples = 0;    // samples the component rejected (InvalidSample, SensorFault, ...)
  std::array<long, 4> per_component{};
  std::string first_failure;    // description of the first failing case

  long failures() const { return ctor_mismatch + non_finite + out_of_range + twin_mismatch + not_held + allocations +
                               unknown_status_ok; }
};

// Hook for the seeded driver's allocation counter (returns the running count; null: not counted).
using AllocCounter = long (*)();

class Campaign {
 public:
  explicit Campaign(AllocCounter counter = nullptr) : count_(counter) {
    // contact parameters
    params_.base = table1_params();
    add_table(params_);
    params_.init([](const ContactParams& p) { return validate(p, nullptr); });
    // CoR estimator settings
    add_table(cor_);
    cor_.init([](const CorSettings& s) { return validate(s, nullptr); });
    // observer settings
    add_table(obs_);
    obs_.init([](const ObserverSettings& s) { return validate(s, nullptr); });
    // controller settings
    using G = GraspControllerSettings;
    add_table(ctl_);
    ctl_.init([](const G& s) { return validate(s, nullptr); });
  }

  // Contact models are expensive (limit-surface tables): a fixed pool built on first use,
  // the first few nominal, the rest with every field at an edge with probability 1/2.
  const ContactModel& model(int index) {
    if (models_.empty()) models_.resize(kModels);
    auto& m = models_[static_cast<size_t>(index % kModels)];
    if (!m) {
      ContactParams p = index == 0 ? table1_params() : object_params(index == 1 ? "plastic_bottle" : "aluminium_can");
      if (index >= 3) {
        Source src(1000 + static_cast<uint64_t>(index));
        for (int tries = 0; tries < 100; ++tries) {
          ContactParams q = p;
          for (size_t i = 0; i < params_.reals.size(); ++i)
            if (src.chance(0.5)) {
              const Edges& e = params_.real_edges[i];
              *params_.reals[i].ref(q) = e.inside[src.below(static_cast<int>(e.inside.size()))];
            }
          if (validate(q, nullptr)) {
            p = q;
            break;
          }
        }
      }
      m = std::make_unique<ContactModel>(p);
    }
    return *m;
  }
  static constexpr int kModels = 16;

  const SettingsSpace<ContactParams>& params_space() const { return params_; }
  const SettingsSpace<ObserverSettings>& observer_space() const { return obs_; }
  const SettingsSpace<GraspControllerSettings>& controller_space() const { return ctl_; }

  //! One case of `samples` samples; the component is drawn from the source.
  void run_case(Source& src, int samples, Stats& st) {
    ++st.cases;
    context_.clear();
    const int which = src.below(4);
    ++st.per_component[static_cast<size_t>(which)];
    switch (which) {
      case 0: cor_case(src, samples, st); break;
      case 1: observer_case(src, samples, st); break;
      case 2: controller_case(src, samples, st); break;
      default: slip_control_case(src, samples, st); break;
    }
  }

 private:
  long allocs() const { return count_ ? count_() : 0; }

  void fail(Stats& st, long& counter, const std::string& what) {
    ++counter;
    if (st.first_failure.empty()) st.first_failure = what + (context_.empty() ? "" : " with " + context_);
  }
  std::string context_;  // settings of the current case (for the failure report)

  template <class Settings, class Make>
  bool construct(const Settings& s, bool valid, Stats& st, Make make, const char* what) {
    bool threw = false;
    try {
      make();
    } catch (const std::invalid_argument&) {
      threw = true;
    }
    if (threw == valid) fail(st, st.ctor_mismatch, std::string(what) + ": constructor and validate() disagree");
    (void)s;
    if (threw) ++st.settings_rejected;
    return !threw;
  }

  // A wrench sample: a random walk around a load that slides now and then, with hostile values.
  struct Load {
    double f_n = 3.0, f_t = 0.3, tau = 0.002;
  };
  void walk(Source& src, Load& l) {
    l.f_n = std::fabs(l.f_n + 0.05 * (2.0 * src.uniform() - 1.0));
    if (l.f_n > 20.0) l.f_n = 20.0;
    l.f_t += 0.02 * (2.0 * src.uniform() - 1.0);
    l.tau += 0.0005 * (2.0 * src.uniform() - 1.0);
    if (src.chance(0.002)) l = Load{src.uniform() * 10.0, 2.0 * src.uniform() - 1.0, 0.02 * (2.0 * src.uniform() - 1.0)};
  }
  double maybe_bad(Source& src, double v, double p_bad) { return src.chance(p_bad) ? hostile(src) : v; }

  static bool finite_cor(const CorOutput& o) {
    return std::isfinite(o.c_tilde) && std::isfinite(o.c) && std::isfinite(o.ft_tilde) && std::isfinite(o.tau_tilde) &&
           std::isfinite(o.sigma) && std::isfinite(o.rho) && std::isfinite(o.g) && std::isfinite(o.sigma_1) &&
           std::isfinite(o.y);
  }
  static bool same_cor(const CorOutput& a, const CorOutput& b) {
    return std::memcmp(&a.c_tilde, &b.c_tilde, sizeof(double)) == 0 && a.c == b.c && a.g == b.g &&
           a.sigma_1 == b.sigma_1 && a.y == b.y && a.inside == b.inside && a.saturated == b.saturated;
  }
  static bool finite_obs(const ObserverOutput& o) {
    return std::isfinite(o.omega_hat) && std::isfinite(o.z_hat) && std::isfinite(o.S) && std::isfinite(o.c_tilde) &&
           std::isfinite(o.c) && std::isfinite(o.g) && std::isfinite(o.sigma_1) && std::isfinite(o.y) &&
           std::isfinite(o.tau_cor) && std::isfinite(o.ft_cor) && std::isfinite(o.gain) &&
           std::isfinite(o.c_tilde_unclipped) && std::isfinite(o.omega_object) && std::isfinite(o.v_slip);
  }
  static bool same_obs(const ObserverOutput& a, const ObserverOutput& b) {
    return a.status == b.status && a.omega_hat == b.omega_hat && a.z_hat == b.z_hat && a.S == b.S &&
           a.c_tilde == b.c_tilde && a.g == b.g && a.y == b.y && a.tau_cor == b.tau_cor && a.gain == b.gain;
  }
  static bool finite_ctl(const GraspControllerOutput& o) {
    return std::isfinite(o.force) && std::isfinite(o.static_force) && std::isfinite(o.dynamic_force) &&
           std::isfinite(o.floor) && std::isfinite(o.slippage) && std::isfinite(o.error) &&
           std::isfinite(o.integrator) && std::isfinite(o.dynamic_sample[0]) && std::isfinite(o.dynamic_sample[1]) &&
           std::isfinite(o.dynamic_peak) && std::isfinite(o.mean_c_tilde) && std::isfinite(o.pivot_time);
  }

  void cor_case(Source& src, int n, Stats& st) {
    const ContactModel& m = model(src.below(kModels));
    const CorSettings s = cor_.draw(src, 0.5);
    const bool valid = validate(s, nullptr);
    std::unique_ptr<CorEstimator> est, twin;
    if (!construct(s, valid, st, [&] { est = std::make_unique<CorEstimator>(m, s); twin = std::make_unique<CorEstimator>(m, s); }, "CorEstimator"))
      return;
    context_ = to_string(m.params()) + ", " + to_string(s);
    const double p_bad = 0.3 * std::pow(src.uniform(), 3.0);
    const double scale = src.chance(0.2) ? std::pow(10.0, 12.0 * src.uniform() - 6.0) : 1.0;
    Load l;
    CorOutput o, ot;
    for (int i = 0; i < n && !src.exhausted(); ++i) {
      walk(src, l);
      CorInput in{maybe_bad(src, l.f_n * scale, p_bad), maybe_bad(src, l.f_t * scale, p_bad),
                  maybe_bad(src, l.tau * scale, p_bad)};
      const long a0 = allocs();
      const Status status = est->step(in, o);
      if (allocs() != a0) fail(st, st.allocations, "CorEstimator::step allocated");
      ++st.samples;
      if (!finite_cor(o)) fail(st, st.non_finite, "CorEstimator: non-finite output");
      if (!(std::fabs(o.c_tilde) <= m.params().c_max)) fail(st, st.out_of_range, "CorEstimator: |c~| > c_max");
      if (status == Status::NoContact || status == Status::InvalidSample) {
        ++st.rejected_samples;
        continue;
      }
      twin->step(in, ot);
      if (!same_cor(o, ot)) fail(st, st.twin_mismatch, "CorEstimator: twin mismatch");
    }
  }

  void observer_case(Source& src, int n, Stats& st) {
    const ContactModel& m = model(src.below(kModels));
    ObserverSettings s = obs_.draw(src, 0.3);
    s.integrator = static_cast<Integrator>(src.chance(0.03) ? 7 : src.below(4));
    s.gain_mode = static_cast<GainMode>(src.chance(0.03) ? -1 : src.below(2));
    s.filter_force = src.chance(0.5);
    if (s.max_substeps > 50 && s.max_substeps <= kMaxObserverSubsteps && src.chance(0.9)) s.max_substeps = 50;  // keep cases fast
    const bool valid = validate(s, nullptr);
    std::unique_ptr<Observer> obs, twin;
    if (!construct(s, valid, st, [&] { obs = std::make_unique<Observer>(m, s); twin = std::make_unique<Observer>(m, s); }, "Observer"))
      return;
    context_ = to_string(m.params()) + ", " + to_string(s);
    const double p_bad = 0.2 * std::pow(src.uniform(), 3.0);
    Load l;
    ObserverOutput o, ot;
    double pending = 0.0;
    int prev = -1;
    for (int i = 0; i < n && !src.exhausted(); ++i) {
      walk(src, l);
      ObserverInput in{maybe_bad(src, l.f_n, p_bad), maybe_bad(src, l.f_t, p_bad), maybe_bad(src, l.tau, p_bad), 0.0};
      if (src.chance(0.1)) in.dt = src.chance(0.5) ? s.dt * (0.5 + src.uniform()) : hostile(src);
      const long a0 = allocs();
      const Status status = obs->step(in, o);
      if (allocs() != a0) fail(st, st.allocations, "Observer::step allocated");
      ++st.samples;
      if (!finite_obs(o)) fail(st, st.non_finite, "Observer: non-finite output");
      if (!(o.S >= 0.0 && o.S <= 1.0) || !(std::fabs(o.c_tilde) <= m.params().c_max))
        fail(st, st.out_of_range, "Observer: S outside [0, 1] or |c~| > c_max");
      const double dt = in.dt == 0.0 ? s.dt : in.dt;
      const bool dt_ok = std::isfinite(dt) && dt > 0.0;
      if (status == Status::InvalidSample || status == Status::SensorFault) {
        ++st.rejected_samples;
        pending = std::min(pending + (dt_ok ? dt : s.dt), 1.0e9);  // the skipped time
        // SensorFault re-initialises the state: the twin restarts as a copy of the observer
        if (status == Status::SensorFault) {
          *twin = *obs;
          pending = 0.0;
        }
        prev = (int)status;
        continue;
      }
      ObserverInput tin = in;
      tin.dt = pending + dt;
      pending = 0.0;
      twin->step(tin, ot);
      if (!same_obs(o, ot)) {
        if (std::getenv("LUGRIP_FUZZ_DEBUG"))
          std::fprintf(stderr, "i=%d st=%d/%d prev=%d in=(%g,%g,%g,%g) tdt=%g omega %g/%g z %g/%g S %g/%g c %g/%g g %g/%g y %g/%g taucor %g/%g gain %g/%g\n", i, (int)o.status, (int)ot.status, prev, in.f_n, in.f_t, in.tau, in.dt, tin.dt,
                       o.omega_hat, ot.omega_hat, o.z_hat, ot.z_hat, o.S, ot.S, o.c_tilde, ot.c_tilde, o.g, ot.g, o.y, ot.y, o.tau_cor, ot.tau_cor, o.gain, ot.gain);
        fail(st, st.twin_mismatch, "Observer: twin mismatch");
      }
      prev = (int)status;
    }
  }

  FingerInput finger(Source& src, double p_bad) {
    FingerInput f;
    f.omega_hat = sample(src, src.chance(0.3) ? 2.0 : 0.05, p_bad);
    f.slippage = sample(src, src.chance(0.1) ? 1.5 : 1.0, p_bad, true);
    f.c_tilde = sample(src, 1.5, p_bad);
    f.f_t = sample(src, 3.0, p_bad);
    f.omega_resolution = sample(src, 0.01, p_bad * 0.3, true);
    const int r = src.below(100);
    f.status = r < 70 ? Status::Ok
                      : static_cast<Status>(r < 97 ? src.below(7) : (src.chance(0.5) ? 7 + src.below(100) : -1 - src.below(100)));
    f.present = !src.chance(0.03);
    return f;
  }

  void controller_case(Source& src, int n, Stats& st) {
    const GraspControllerSettings s = ctl_.draw(src, 0.25);
    const bool valid = validate(s, nullptr);
    const ContactModel& m = model(src.below(kModels));
    std::unique_ptr<GraspController> c;
    if (!construct(s, valid, st, [&] { c = std::make_unique<GraspController>(m.params(), s); }, "GraspController"))
      return;
    context_ = to_string(s) + ", " + to_string(m.params());
    const double p_bad = 0.2 * std::pow(src.uniform(), 3.0);
    GraspControllerInput in;
    GraspControllerOutput o;
    for (int i = 0; i < n && !src.exhausted(); ++i) {
      for (auto& f : in.fingers) f = finger(src, p_bad);
      if (src.chance(0.002)) c->request_pivoting();
      if (src.chance(0.002)) c->request_slipping_avoidance();
      if (src.chance(0.001)) c->set_dynamic_enabled(src.chance(0.5));
      if (src.chance(0.0005)) c->reset(hostile(src));
      const double before = c->command();
      const long a0 = allocs();
      const Status status = c->step(in, o);
      if (allocs() != a0) fail(st, st.allocations, "GraspController::step allocated");
      ++st.samples;
      check_command(o, s, st, "GraspController");
      bool any_invalid = false, unknown = false, any_present = false;
      for (const auto& f : in.fingers) {
        if (!f.present) continue;
        any_present = true;
        const int code = static_cast<int>(f.status);
        if (code < 0 || code > 6) unknown = true;
        if (!is_valid(f.status) || !std::isfinite(f.omega_hat) || !std::isfinite(f.slippage) || f.slippage < 0.0 ||
            !std::isfinite(f.c_tilde) || !std::isfinite(f.f_t) || !std::isfinite(f.omega_resolution) ||
            f.omega_resolution < 0.0)
          any_invalid = true;
      }
      if (!any_present) any_invalid = true;
      if (any_invalid) {
        ++st.rejected_samples;
        if (o.command_issued && o.force < std::min(before, s.f_max)) fail(st, st.not_held, "GraspController: command lowered on invalid input");
        if (status == Status::Ok) {
          if (unknown)
            fail(st, st.unknown_status_ok, "GraspController: out-of-enum finger status reported as Ok");
          else
            fail(st, st.out_of_range, "GraspController: invalid input reported as Ok");
        }
      }
    }
  }

  void check_command(const GraspControllerOutput& o, const GraspControllerSettings& s, Stats& st, const char* who) {
    if (!finite_ctl(o)) fail(st, st.non_finite, std::string(who) + ": non-finite output");
    if (!(o.force >= s.f_min && o.force <= s.f_max)) fail(st, st.out_of_range, std::string(who) + ": command out of range");
  }

  void slip_control_case(Source& src, int n, Stats& st) {
    const ContactModel& m = model(src.below(kModels));
    SlipControlSettings s;
    s.observer = obs_.draw(src, 0.15);
    s.observer.integrator = static_cast<Integrator>(src.below(4));
    if (s.observer.max_substeps > 50 && s.observer.max_substeps <= kMaxObserverSubsteps) s.observer.max_substeps = 50;
    s.controller = ctl_.draw(src, 0.15);
    s.fingers = src.chance(0.02) ? src.below(5) - 1 : 1 + src.below(2);
    if (src.chance(0.5) && std::isfinite(s.observer.dt) && s.observer.dt > 0.0)
      s.controller.sensor_rate = 1.0 / s.observer.dt;
    else if (std::isfinite(s.controller.sensor_rate) && s.controller.sensor_rate > 0.0)
      s.observer.dt = 1.0 / s.controller.sensor_rate;
    const bool valid = validate(s, nullptr);
    std::unique_ptr<SlipControl> sc;
    if (!construct(s, valid, st, [&] { sc = std::make_unique<SlipControl>(m, s); }, "SlipControl")) return;
    context_ = to_string(s.controller) + ", " + to_string(m.params());
    const double p_bad = 0.1 * std::pow(src.uniform(), 3.0);
    std::array<Load, kMaxFingers> loads{};
    SlipControlInput in;
    SlipControlOutput o;
    for (int i = 0; i < n && !src.exhausted(); ++i) {
      for (int k = 0; k < kMaxFingers; ++k) {
        walk(src, loads[static_cast<size_t>(k)]);
        const Load& l = loads[static_cast<size_t>(k)];
        const double angle = 6.283185307179586 * src.uniform();
        in.fingers[static_cast<size_t>(k)] = FingerWrench{maybe_bad(src, l.f_n, p_bad), maybe_bad(src, l.f_t * std::cos(angle), p_bad),
                                                          maybe_bad(src, l.f_t * std::sin(angle), p_bad), maybe_bad(src, l.tau, p_bad)};
      }
      in.dt = src.chance(0.05) ? (src.chance(0.5) ? s.observer.dt * (0.5 + src.uniform()) : hostile(src)) : 0.0;
      if (src.chance(0.002)) sc->request_pivoting();
      if (src.chance(0.002)) sc->request_slipping_avoidance();
      if (src.chance(0.0005)) sc->reset(hostile(src));
      const double before = sc->command();
      const long a0 = allocs();
      const Status status = sc->step(in, o);
      if (allocs() != a0) fail(st, st.allocations, "SlipControl::step allocated");
      ++st.samples;
      check_command(o.controller, s.controller, st, "SlipControl");
      if (!(o.force == o.controller.force)) fail(st, st.out_of_range, "SlipControl: force differs from the controller's");
      for (int k = 0; k < s.fingers; ++k)
        if (!finite_obs(o.fingers[static_cast<size_t>(k)])) fail(st, st.non_finite, "SlipControl: non-finite observer output");
      if (status != Status::Ok) {
        ++st.rejected_samples;
        if (o.controller.command_issued && o.force < std::min(before, s.controller.f_max))
          fail(st, st.not_held, "SlipControl: command lowered on a bad cycle");
      }
    }
  }

  AllocCounter count_;
  SettingsSpace<ContactParams> params_;
  SettingsSpace<CorSettings> cor_;
  SettingsSpace<ObserverSettings> obs_;
  SettingsSpace<GraspControllerSettings> ctl_;
  std::vector<std::unique_ptr<ContactModel>> models_;
};

}  // namespace lugrip_fuzz

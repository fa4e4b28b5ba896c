// Identification: settings and the problem whose cost, gradient and Gauss-Newton matrix the
// Python optimiser calls.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <algorithm>
#include <vector>

#include "common.hpp"
#include "tables.hpp"

namespace lugrip_bind {

using namespace nb::literals;

void bind_identification(nb::module_& m) {
  using I64 = nb::ndarray<const int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
  nb::enum_<IdLoss>(m, "IdLoss", "Loss of the identification residuals.")
      .value("Squared", IdLoss::Squared)
      .value("Huber", IdLoss::Huber);
  nb::class_<IdentificationSettings> settings(m, "IdentificationSettings");
  settings.def(nb::init<>());
  def_fields_rw(settings);
  m.def("validate_identification_settings", &validation_message<IdentificationSettings>,
        "Empty string when valid, else one line per bad field.");
  {
    nb::class_<IdentificationProblem>(m, "IdentificationProblem")
        .def("__init__", [](IdentificationProblem* self, const In1& fn, const In1& ft, const In1& tau,
                            const In1& dt, const In1& omega, const In1& weight, const I64& starts,
                            const IdentificationSettings& s) {
          auto vec = [](const In1& a) { return std::vector<double>(a.data(), a.data() + a.shape(0)); };
          IdentificationData d;
          d.f_n = vec(fn);
          d.f_t = vec(ft);
          d.tau = vec(tau);
          d.dt = vec(dt);
          d.omega = vec(omega);
          d.weight = vec(weight);
          d.segment_start.assign(starts.data(), starts.data() + starts.shape(0));
          new (self) IdentificationProblem(std::move(d), s);
        }, "f_n"_a, "f_t"_a, "tau"_a, "dt"_a, "omega"_a, "weight"_a, "segment_start"_a, "settings"_a)
        .def_prop_ro("samples", &IdentificationProblem::samples)
        .def_prop_ro("segments", &IdentificationProblem::segments)
        .def("evaluate", [](const IdentificationProblem& prob, const ContactParams& p, bool derivatives,
                            bool want_omega_hat) {
          const size_t n = prob.samples(), m_seg = prob.segments();
          Out1<double> w_hat = new_array<double>(want_omega_hat ? n : 0);
          IdentificationEval ev;
          {
            nb::gil_scoped_release release;
            ev = prob.evaluate(p, derivatives, want_omega_hat ? w_hat.data() : nullptr);
          }
          auto grad = new_array<double>(kIdParams);
          std::copy(ev.gradient.begin(), ev.gradient.end(), grad.data());
          auto gn = new_array<double>(kIdParams * kIdParams);
          std::copy(ev.gauss_newton.begin(), ev.gauss_newton.end(), gn.data());
          auto sse = new_array<double>(m_seg), loss = new_array<double>(m_seg),
               wsum = new_array<double>(m_seg), sgrad = new_array<double>(m_seg * kIdParams);
          auto count = new_array<int64_t>(m_seg);
          for (size_t j = 0; j < m_seg; ++j) {
            const SegmentSums& s = ev.segments[j];
            sse.data()[j] = s.sse;
            loss.data()[j] = s.loss;
            wsum.data()[j] = s.weight;
            count.data()[j] = s.count;
            for (int k = 0; k < kIdParams; ++k) sgrad.data()[j * kIdParams + k] = s.gradient[k];
          }
          nb::dict d;
          d["cost"] = ev.cost;
          d["weight_sum"] = ev.weight_sum;
          d["scored"] = ev.scored;
          d["gradient"] = grad;
          d["gauss_newton"] = gn;
          d["segment_sse"] = sse;
          d["segment_loss"] = loss;
          d["segment_weight"] = wsum;
          d["segment_count"] = count;
          d["segment_gradient"] = sgrad;
          d["replica_error"] = ev.replica_error;
          d["reinitialized"] = ev.reinitialized;
          d["diverged"] = ev.diverged;
          d["truncated"] = ev.truncated;
          if (want_omega_hat) d["omega_hat"] = w_hat;
          return d;
        }, "params"_a, "derivatives"_a = true, "omega_hat"_a = false,
           "Cost (eq. 32 with weights and loss), gradient and Gauss-Newton matrix (6x6 row-major, "
           "natural parameter units), per-segment sums; omega_hat per sample on request.");
  }
}

}  // namespace lugrip_bind

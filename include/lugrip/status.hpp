// lugrip — per-sample status codes shared by every real-time component.
#pragma once

namespace lugrip {

//! What happened to one sample. Kept apart from errors (misuse raises at construction).
//! The integer values are stable and documented in the README.
enum class Status : int {
  Ok = 0,             //!< estimate computed from this sample
  Saturated = 1,      //!< |c~| clipped at c_max (translation-dominated load); estimate valid
  Degenerate = 2,     //!< wrench ~ 0 (no tangential force and no torque): previous CoR held
  NoContact = 3,      //!< normal force below the contact threshold: nothing updated
  InvalidSample = 4,  //!< NaN, Inf or out-of-range input: nothing updated, previous output held
  SensorFault = 5,    //!< too many invalid samples in a row: state was re-initialised
  Reinitialized = 6,  //!< first valid sample after a reset / contact loss: state initialised
};

//! Static description of a status; never allocates.
const char* to_string(Status s) noexcept;

//! True when the sample carried a usable estimate (Ok, Saturated, Degenerate, Reinitialized).
constexpr bool is_valid(Status s) noexcept {
  return s == Status::Ok || s == Status::Saturated || s == Status::Degenerate ||
         s == Status::Reinitialized;
}

}  // namespace lugrip

// lugrip — a struct's fields described once. Two kinds of entry:
//  * Field: name, member pointer and a short doc with the unit (the grasp controller's table,
//    grasp_controller_fields.hpp);
//  * Param: name, member, unit, valid range (two limits, one more accepted value), the names of
//    an enumeration's values and one doc line (the tables of settings_fields.hpp), plus Rule
//    entries for the bounds that involve another field.
// validate(), to_string(), the Python bindings, the parameter-file loader, the fuzz campaign and
// the documentation tables iterate over them. Header-only, no I/O, no allocation.
#pragma once

#include <limits>
#include <tuple>
#include <type_traits>
#include <utility>

namespace lugrip::detail {

template <class S, class T>
struct Field {
  const char* name;
  T S::*member;
  const char* doc;
};

template <class S, class T>
constexpr Field<S, T> field(const char* name, T S::*member, const char* doc) {
  return Field<S, T>{name, member, doc};
}

//! One end of a field's range: no bound (value NaN), or value, open (strict) or closed.
//! `text` spells the bound where the number would read badly ("1/3").
struct Limit {
  double value = std::numeric_limits<double>::quiet_NaN();
  bool open = false;
  const char* text = nullptr;
  constexpr bool present() const { return value == value; }
};

constexpr Limit none() { return Limit{}; }
constexpr Limit ge(double v, const char* text = nullptr) { return Limit{v, false, text}; }
constexpr Limit gt(double v, const char* text = nullptr) { return Limit{v, true, text}; }
constexpr Limit le(double v, const char* text = nullptr) { return Limit{v, false, text}; }
constexpr Limit lt(double v, const char* text = nullptr) { return Limit{v, true, text}; }

//! One setting: a number (floating or integer) within [lo, hi] (or equal to `also`), a switch,
//! an enumeration whose value i is named choices[i], or a nested settings struct (`nested`,
//! checked by its own validate()). A floating value must be finite unless a limit is infinite.
template <class S, class T>
struct Param {
  const char* name;
  T S::*member;
  const char* doc;   //!< one line, without the unit
  const char* unit;  //!< "-" dimensionless; "" a switch, an enumeration or a nested struct
  Limit lo{}, hi{};
  double also = std::numeric_limits<double>::quiet_NaN();  //!< one more accepted value (NaN: none)
  const char* also_text = nullptr;                         //!< what `also` means ("0 (off)")
  const char* const* choices = nullptr;                    //!< an enumeration's names, by value
  int n_choices = 0;

  //! The same entry accepting one more value outside [lo, hi].
  constexpr Param or_value(double v, const char* text) const {
    Param p = *this;
    p.also = v;
    p.also_text = text;
    return p;
  }
};

template <class S, class T>
constexpr Param<S, T> param(const char* name, T S::*member, const char* unit, Limit lo, Limit hi, const char* doc) {
  static_assert(std::is_arithmetic_v<T> && !std::is_same_v<T, bool>, "param(): a number");
  return Param<S, T>{name, member, doc, unit, lo, hi};
}

template <class S>
constexpr Param<S, bool> flag(const char* name, bool S::*member, const char* doc) {
  return Param<S, bool>{name, member, doc, ""};
}

template <class S, class E, int N>
constexpr Param<S, E> choice(const char* name, E S::*member, const char* const (&names)[N], const char* doc) {
  static_assert(std::is_enum_v<E>, "choice(): an enumeration");
  Param<S, E> p{name, member, doc, ""};
  p.choices = names;
  p.n_choices = N;
  return p;
}

template <class S, class T>
constexpr Param<S, T> nested(const char* name, T S::*member, const char* doc) {
  static_assert(std::is_class_v<T>, "nested(): a settings struct");
  return Param<S, T>{name, member, doc, ""};
}

//! A bound that involves another field (or a nested struct's): `field` names the field the
//! message is about, `value` reads it, `holds` is true when the rule holds or does not apply
//! (an operand invalid on its own: its own line says so; nothing is said about a field already
//! refused for its own range), `text` is the rule ("must be >= dt"),
//! `bound` (optional) the value the rule asks for, printed after the text.
template <class S>
struct Rule {
  const char* field;
  double (*value)(const S&);
  bool (*holds)(const S&);
  const char* text;
  double (*bound)(const S&) = nullptr;
};

//! Calls fn(field) for every entry of a table (a std::tuple of Field, Param or Rule).
template <class Tuple, class Fn>
constexpr void for_each_entry(const Tuple& table, Fn&& fn) {
  std::apply([&](const auto&... f) { (fn(f), ...); }, table);
}

}  // namespace lugrip::detail

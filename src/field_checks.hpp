// Internal: validate() and to_string() of a settings struct from its field table
// (lugrip/settings_fields.hpp): one line per bad field, "name = value: must be ...".
#pragma once

#include <cmath>
#include <string>
#include <type_traits>

#include "lugrip/settings_fields.hpp"

#include "format.hpp"

namespace lugrip::detail {

//! Appends each line of `lines` to `out`, prefixed ("cor." + "f_n_min = ...").
inline void append_prefixed(std::string& out, const std::string& lines, const std::string& prefix) {
  size_t start = 0;
  while (start < lines.size()) {
    const size_t end = lines.find('\n', start);
    out += prefix + lines.substr(start, end == std::string::npos ? std::string::npos : end - start) + "\n";
    if (end == std::string::npos) break;
    start = end + 1;
  }
}

inline std::string limit_text(const Limit& l) { return l.text ? std::string(l.text) : format_number(l.value); }

//! The value lies in the entry's range (a floating value also finite, unless a limit is
//! infinite and the value that limit).
template <class S, class T>
bool in_range(const Param<S, T>& f, double v) {
  if (f.also == f.also && v == f.also) return true;
  if (f.lo.present() && !(f.lo.open ? v > f.lo.value : v >= f.lo.value)) return false;
  if (f.hi.present() && !(f.hi.open ? v < f.hi.value : v <= f.hi.value)) return false;
  if constexpr (std::is_floating_point_v<T>) return std::isfinite(v) || (f.hi.present() && v == f.hi.value);
  return true;
}

//! "must be finite, > 0 and <= 10 [s]" from the entry's range.
template <class S, class T>
std::string range_rule(const Param<S, T>& f) {
  std::string bounds;
  if (f.lo.present() && std::isfinite(f.lo.value)) bounds = (f.lo.open ? "> " : ">= ") + limit_text(f.lo);
  if (f.hi.present() && std::isfinite(f.hi.value))
    bounds += (bounds.empty() ? "" : " and ") + std::string(f.hi.open ? "< " : "<= ") + limit_text(f.hi);
  const bool finite = std::is_floating_point_v<T> && !(f.hi.present() && std::isinf(f.hi.value));
  std::string rule = "must be ";
  if (finite) rule += bounds.find(" and ") == std::string::npos ? "finite and " : "finite, ";
  rule += bounds;
  if (f.also_text) rule += std::string(" or ") + f.also_text;
  if (*f.unit) rule += std::string(" [") + f.unit + "]";
  return rule;
}

template <class S, class T>
void check_entry(const S& s, const Param<S, T>& f, std::string& msg) {
  const T& v = s.*(f.member);
  const std::string head = std::string(f.name) + " = ";
  if constexpr (std::is_same_v<T, bool>) {
    (void)v;
  } else if constexpr (std::is_enum_v<T>) {
    const int i = static_cast<int>(v);
    if (!(i >= 0 && i < f.n_choices)) {
      std::string names;
      for (int k = 0; k < f.n_choices; ++k) names += (k ? ", " : "") + std::string(f.choices[k]);
      msg += head + std::to_string(i) + ": must be one of " + names + "\n";
    }
  } else if constexpr (std::is_arithmetic_v<T>) {
    if (!in_range(f, static_cast<double>(v)))
      msg += head + (std::is_integral_v<T> ? std::to_string(v) : format_number(static_cast<double>(v))) + ": " +
             range_rule(f) + "\n";
  } else {
    std::string sub;
    if (!validate(v, &sub)) append_prefixed(msg, sub, std::string(f.name) + ".");
  }
}

//! Every field's own range, then the rules; one line per bad field ("" when valid): a rule
//! says nothing about a field already refused.
template <class S>
std::string check_fields(const S& s) {
  std::string msg;
  for_each_entry(FieldTable<S>::fields, [&](const auto& f) { check_entry(s, f, msg); });
  for_each_entry(FieldTable<S>::rules, [&](const auto& r) {
    const std::string head = std::string(r.field) + " = ";
    if (r.holds(s) || msg.rfind(head, 0) == 0 || msg.find("\n" + head) != std::string::npos) return;
    msg += std::string(r.field) + " = " + format_number(r.value(s)) + ": " + r.text;
    if (r.bound) msg += " = " + format_number(r.bound(s));
    msg += "\n";
  });
  return msg;
}

//! The shared body of validate(): the message into *message (if not null), true when valid.
template <class S>
bool validate_fields(const S& s, std::string* message) {
  std::string msg = check_fields(s);
  const bool ok = msg.empty();
  if (message) *message = std::move(msg);
  return ok;
}

//! A value as Python would read it back (float('inf'), True, 'rosenbrock').
template <class S, class T>
std::string value_text(const S& s, const Param<S, T>& f) {
  const T& v = s.*(f.member);
  if constexpr (std::is_same_v<T, bool>) {
    return v ? "True" : "False";
  } else if constexpr (std::is_enum_v<T>) {
    const int i = static_cast<int>(v);
    return i >= 0 && i < f.n_choices ? "'" + std::string(f.choices[i]) + "'" : std::to_string(i);
  } else if constexpr (std::is_floating_point_v<T>) {
    if (std::isnan(v)) return "float('nan')";
    if (std::isinf(v)) return v > 0 ? "float('inf')" : "-float('inf')";
    return format_number(v);
  } else if constexpr (std::is_integral_v<T>) {
    return std::to_string(v);
  } else {
    return to_string(v);
  }
}

//! "Name(field=value, ...)" at full precision, every field of the table in order.
template <class S>
std::string print_fields(const S& s) {
  std::string out = std::string(FieldTable<S>::name) + "(";
  bool first = true;
  for_each_entry(FieldTable<S>::fields, [&](const auto& f) {
    out += (first ? "" : ", ") + std::string(f.name) + "=" + value_text(s, f);
    first = false;
  });
  return out + ")";
}

}  // namespace lugrip::detail

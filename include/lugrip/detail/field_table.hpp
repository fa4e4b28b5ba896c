// lugrip — a struct's fields described once: name, member pointer and a short doc with the unit.
// The tables themselves sit beside their structs (e.g. grasp_controller_fields.hpp); the Python
// bindings, the parameter-file loader and the tests iterate over them. Header-only, no I/O.
#pragma once

#include <tuple>
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

//! Calls fn(field) for every entry of a table (a std::tuple of Field).
template <class Tuple, class Fn>
constexpr void for_each_entry(const Tuple& table, Fn&& fn) {
  std::apply([&](const auto&... f) { (fn(f), ...); }, table);
}

}  // namespace lugrip::detail

// Field tables: each bound struct is described once (name, member, short doc) in tables.hpp;
// the helpers here turn a table into the nanobind attributes, the `fields` tuple Python builds
// its views and conversions from, and the columns of the batch calls.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <array>
#include <cstdint>
#include <deque>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "common.hpp"
#include "lugrip/detail/field_table.hpp"

namespace lugrip_bind {

// one Field type for the core's tables (lugrip/detail/field_table.hpp) and the bindings' own
using lugrip::detail::Field;
using lugrip::detail::field;

//! Specialised in tables.hpp: `static constexpr auto fields = std::make_tuple(field(...), ...);`
template <class S>
struct Table;

template <class S, class Fn>
void for_each_field(Fn&& fn) {
  std::apply([&](const auto&... f) { (fn(f), ...); }, Table<S>::fields);
}

using Pair = std::array<double, 2>;

//! std::array<double, 2> or std::array<int, 2>: one value per finger.
template <class T>
struct is_pair : std::false_type {};
template <class E>
struct is_pair<std::array<E, 2>> : std::bool_constant<std::is_arithmetic_v<E>> {};
template <class T>
inline constexpr bool is_pair_v = is_pair<T>::value;

//! Kind of a field for the Python side: float, int, bool, enum, pair (two floats) or struct.
template <class T>
constexpr const char* kind_name() {
  if constexpr (std::is_same_v<T, bool>) return "bool";
  else if constexpr (std::is_floating_point_v<T>) return "float";
  else if constexpr (std::is_integral_v<T>) return "int";
  else if constexpr (std::is_enum_v<T>) return "enum";
  else if constexpr (is_pair_v<T>) return "pair";
  else return "struct";
}

template <class S, class T>
constexpr const char* kind_of(const Field<S, T>&) {
  return kind_name<T>();
}
template <class S, class T>
constexpr const char* kind_of(const lugrip::detail::Param<S, T>&) {
  return kind_name<T>();
}

//! A text that lives as long as the module (nanobind keeps the pointer of a doc string).
inline const char* kept(std::string text) {
  static std::deque<std::string> store;
  store.push_back(std::move(text));
  return store.back().c_str();
}

//! The Python doc of a field: a Field's doc, or a Param's doc line with its unit ("... [N m]").
template <class S, class T>
const char* doc_of(const Field<S, T>& f) {
  return f.doc;
}
template <class S, class T>
const char* doc_of(const lugrip::detail::Param<S, T>& f) {
  return *f.unit ? kept(std::string(f.doc) + " [" + f.unit + "]") : f.doc;
}

//! ((name, kind, doc), ...) of a table.
template <class S>
nb::tuple field_tuple() {
  nb::list out;
  for_each_field<S>([&](const auto& f) { out.append(nb::make_tuple(f.name, kind_of(f), doc_of(f))); });
  return nb::tuple(out);
}

inline nb::dict limit_dict(const lugrip::detail::Limit& l) {
  nb::dict d;
  d["value"] = l.present() ? nb::cast(l.value) : nb::none();
  d["open"] = l.open;
  d["text"] = l.text ? nb::cast(std::string(l.text)) : nb::none();
  return d;
}

template <class T>
struct is_param : std::false_type {};
template <class S, class T>
struct is_param<lugrip::detail::Param<S, T>> : std::true_type {};

//! A Param table as the documentation reads it: `params` (one dict per field: name, kind, unit,
//! lo, hi, also, also_text, choices, doc) and `rules` ((field, text), ...).
template <class S, class Cls>
void def_param_table(Cls& cls) {
  nb::list params;
  for_each_field<S>([&](const auto& f) {
    nb::dict d;
    d["name"] = f.name;
    d["kind"] = kind_of(f);
    d["unit"] = f.unit;
    d["lo"] = limit_dict(f.lo);
    d["hi"] = limit_dict(f.hi);
    d["also"] = f.also == f.also ? nb::cast(f.also) : nb::none();
    d["also_text"] = f.also_text ? nb::cast(std::string(f.also_text)) : nb::none();
    nb::list choices;
    for (int k = 0; k < f.n_choices; ++k) choices.append(f.choices[k]);
    d["choices"] = nb::tuple(choices);
    d["doc"] = f.doc;
    params.append(d);
  });
  cls.attr("params") = nb::tuple(params);
  nb::list rules;
  lugrip::detail::for_each_entry(Table<S>::rules, [&](const auto& r) { rules.append(nb::make_tuple(r.field, r.text)); });
  cls.attr("rules") = nb::tuple(rules);
}

//! Read-only attributes of every field, plus `fields` on the class.
template <class S, class... Opts>
void def_fields_ro(nb::class_<S, Opts...>& cls) {
  for_each_field<S>([&](const auto& f) {
    using T = std::decay_t<decltype(std::declval<S>().*(f.member))>;
    if constexpr (is_pair_v<T>) {
      auto m = f.member;
      cls.def_prop_ro(f.name, [m](const S& s) { return nb::make_tuple((s.*m)[0], (s.*m)[1]); }, doc_of(f));
    } else {
      cls.def_ro(f.name, f.member, doc_of(f));
    }
  });
  cls.attr("fields") = field_tuple<S>();
}

//! Read-write attributes of every field, plus `fields` on the class; for a table of Param
//! entries (lugrip/settings_fields.hpp) also `params`, `rules` and the repr (to_string).
template <class S, class... Opts>
void def_fields_rw(nb::class_<S, Opts...>& cls) {
  for_each_field<S>([&](const auto& f) { cls.def_rw(f.name, f.member, doc_of(f)); });
  cls.attr("fields") = field_tuple<S>();
  using First = std::decay_t<decltype(std::get<0>(Table<S>::fields))>;
  if constexpr (is_param<First>::value) {
    def_param_table<S>(cls);
    // lugrip::to_string, found by argument-dependent lookup
    cls.def("__repr__", [](const S& s) { return to_string(s); });
  }
}

//! One numpy array per scalar field of S (two for a pair, none for a nested struct), named
//! <field><suffix> (a pair: <field>_0<suffix>, <field>_1<suffix>); bools stored as BoolT.
//! set() only writes into the arrays, so it runs with the GIL released.
template <class S, class BoolT = bool>
class Columns {
 public:
  explicit Columns(size_t n, const std::string& suffix = "") {
    for_each_field<S>([&](const auto& f) {
      using T = std::decay_t<decltype(std::declval<S>().*(f.member))>;
      const std::string name = f.name;
      if constexpr (std::is_same_v<T, bool>) add(name + suffix, new_array<BoolT>(n));
      else if constexpr (std::is_floating_point_v<T>) add(name + suffix, new_array<double>(n));
      else if constexpr (std::is_same_v<T, int64_t>) add(name + suffix, new_array<int64_t>(n));
      else if constexpr (std::is_integral_v<T> || std::is_enum_v<T>) add(name + suffix, new_array<int32_t>(n));
      else if constexpr (is_pair_v<T>) {
        using E = std::conditional_t<std::is_floating_point_v<typename T::value_type>, double, int32_t>;
        add(name + "_0" + suffix, new_array<E>(n));
        add(name + "_1" + suffix, new_array<E>(n));
      }
    });
  }

  void set(size_t i, const S& s) noexcept {
    size_t j = 0;
    for_each_field<S>([&](const auto& f) {
      using T = std::decay_t<decltype(std::declval<S>().*(f.member))>;
      const T& v = s.*(f.member);
      if constexpr (std::is_same_v<T, bool>) static_cast<BoolT*>(ptr_[j++])[i] = static_cast<BoolT>(v);
      else if constexpr (std::is_floating_point_v<T>) static_cast<double*>(ptr_[j++])[i] = v;
      else if constexpr (std::is_same_v<T, int64_t>) static_cast<int64_t*>(ptr_[j++])[i] = v;
      else if constexpr (std::is_integral_v<T> || std::is_enum_v<T>)
        static_cast<int32_t*>(ptr_[j++])[i] = static_cast<int32_t>(v);
      else if constexpr (is_pair_v<T>) {
        using E = std::conditional_t<std::is_floating_point_v<typename T::value_type>, double, int32_t>;
        static_cast<E*>(ptr_[j++])[i] = static_cast<E>(v[0]);
        static_cast<E*>(ptr_[j++])[i] = static_cast<E>(v[1]);
      }
    });
  }

  void into(nb::dict& d) const {
    for (size_t k = 0; k < names_.size(); ++k) d[names_[k].c_str()] = arrays_[k];
  }

 private:
  template <class T>
  void add(const std::string& name, Out1<T> a) {
    ptr_.push_back(a.data());
    arrays_.push_back(nb::cast(a));
    names_.push_back(name);
  }
  std::vector<std::string> names_;
  std::vector<nb::object> arrays_;
  std::vector<void*> ptr_;
};

}  // namespace lugrip_bind

// Internal: numbers in validation messages.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace lugrip::detail {

//! The shortest "%g" text that reads back as the same double ("0.1", "-1", "1e-07", "inf",
//! "nan"), for messages that name a bad value. Not for real-time code (allocates).
inline std::string format_number(double v) {
  char buf[40];
  for (int precision = 6; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (std::isnan(v) || std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

}  // namespace lugrip::detail

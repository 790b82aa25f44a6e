#pragma once
/// The one check of a tolerance flag's value (--eps, --vis-eps) shared by
/// the commands: finite and >= 0, or > 0 where 0 cannot be met; a
/// UsageError naming the flag otherwise. An absent optional flag passes.
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "cli/usage_error.h"

namespace flatrad {

/// `positive`: 0 refused too; `why`, said after the bound (e.g. why 0 is
/// refused), may be empty.
inline void check_tolerance(double value, const char* flag, bool positive = false, const char* why = "") {
    if (!(std::isfinite(value) && (positive ? value > 0 : value >= 0)))
        throw UsageError(fmt::format("{}: expected a finite number {} 0{}, got {}", flag, positive ? ">" : ">=", why, value));
}

inline void check_tolerance(const std::optional<double>& value, const char* flag, bool positive = false,
                            const char* why = "") {
    if (value) check_tolerance(*value, flag, positive, why);
}

}  // namespace flatrad

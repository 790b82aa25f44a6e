#pragma once
/// The median of repeated timings (`flatrad sweep`, --repeat): robust to
/// the odd slow run on a shared machine, where a mean would not be.
#include <algorithm>
#include <vector>

namespace flatrad {

/// The middle value (the mean of the two middle ones for an even count).
/// Pre: !v.empty().
inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace flatrad

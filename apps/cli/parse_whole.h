#pragma once
/// Numbers inside flag values that hold several (`--eps 0:0.04:800`,
/// `--eps 0.1,0.03`): each field must be a number and nothing else, so
/// that "1e-3x" or " 2" is refused rather than half-read.
#include <charconv>
#include <string>
#include <system_error>

namespace flatrad {

/// True when the whole of `s` is one number (std::from_chars syntax: no
/// leading '+' or spaces), stored in `v`.
inline bool parse_whole(const std::string& s, double& v) {
    const char* end = s.data() + s.size();
    const auto [ptr, ec] = std::from_chars(s.data(), end, v);
    return !s.empty() && ec == std::errc() && ptr == end;
}

inline bool parse_whole(const std::string& s, long& v) {
    const char* end = s.data() + s.size();
    const auto [ptr, ec] = std::from_chars(s.data(), end, v);
    return !s.empty() && ec == std::errc() && ptr == end;
}

}  // namespace flatrad

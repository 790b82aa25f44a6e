#pragma once
/// A bad command-line argument found after parsing (a value out of range, a
/// feature that has not landed yet). run_cli prints it as `error: MESSAGE`
/// and exits with status 2, like a parse error.
#include <stdexcept>
#include <string>

namespace flatrad {

class UsageError : public std::runtime_error {
public:
    explicit UsageError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace flatrad

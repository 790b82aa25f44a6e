#pragma once
/// Errors of flatrad (STYLE.md, "Errors").
///  - InputError: the user's scene or flags are wrong. Carries the file and the
///    JSON path (or flag) of the fault; only apps/ prints it, as
///    `error: FILE: PATH: MESSAGE`, and exits with status 2.
///  - FLATRAD_ASSERT: our own invariants; on in Debug builds and tests.
#include <stdexcept>
#include <string>

namespace flatrad {

class InputError : public std::runtime_error {
public:
    InputError(std::string file, std::string path, const std::string& message);
    const std::string& file() const { return m_file; }
    const std::string& path() const { return m_path; }
    const std::string& message() const { return m_message; }

private:
    std::string m_file, m_path, m_message;
};

/// Thrown by FLATRAD_ASSERT: a bug in flatrad, not in the input.
class InternalError : public std::logic_error {
public:
    using std::logic_error::logic_error;
};

[[noreturn]] void assertion_failed(const char* cond, const char* why, const char* file, int line);

}  // namespace flatrad

#if !defined(NDEBUG) || defined(FLATRAD_ENABLE_ASSERTS)
#define FLATRAD_ASSERT(cond, why) \
    ((cond) ? (void)0 : ::flatrad::assertion_failed(#cond, why, __FILE__, __LINE__))
#else
#define FLATRAD_ASSERT(cond, why) ((void)0)
#endif

#include "engine/error.h"

#include <fmt/format.h>

namespace flatrad {

InputError::InputError(std::string file, std::string path, const std::string& message)
    : std::runtime_error(path.empty() ? fmt::format("{}: {}", file, message)
                                      : fmt::format("{}: {}: {}", file, path, message)),
      m_file(std::move(file)),
      m_path(std::move(path)),
      m_message(message) {}

void assertion_failed(const char* cond, const char* why, const char* file, int line) {
    throw InternalError(fmt::format("internal error: {}:{}: {} ({})", file, line, why, cond));
}

}  // namespace flatrad

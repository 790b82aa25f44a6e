#include "cli/atomic_write.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

#include "cli/usage_error.h"

namespace flatrad {

namespace fs = std::filesystem;

void write_file_atomically(const fs::path& path, const std::string& text) {
    // Same directory as the target: a rename across file systems is a copy.
    const fs::path tmp = fs::path(path).concat(fmt::format(".tmp.{}", static_cast<long>(::getpid())));
    try {
        {
            std::ofstream file(tmp, std::ios::binary | std::ios::trunc);
            if (!file)
                throw std::runtime_error(
                    fmt::format("cannot create {}: {}", tmp.string(), std::strerror(errno)));
            file.write(text.data(), static_cast<std::streamsize>(text.size()));
            file.close();
            if (!file)
                throw std::runtime_error(fmt::format("cannot write {}: {}", tmp.string(),
                                                     std::strerror(errno)));
        }
        std::error_code ec;
        fs::rename(tmp, path, ec);
        if (ec)
            throw std::runtime_error(fmt::format("cannot rename {} to {}: {}", tmp.string(),
                                                 path.string(), ec.message()));
    } catch (...) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        throw;
    }
}

void check_output_path(const fs::path& path, const std::string& flag) {
    if (path.empty()) throw UsageError(flag + ": expected a file name, got an empty one");
    std::error_code ec;
    if (fs::is_directory(path, ec))
        throw UsageError(fmt::format("{} {}: is a directory; give a file name", flag, path.string()));
    const fs::path dir = path.parent_path();
    if (!dir.empty() && !fs::is_directory(dir, ec))
        throw UsageError(fmt::format("{} {}: directory {} does not exist", flag, path.string(),
                                     dir.string()));
}

}  // namespace flatrad

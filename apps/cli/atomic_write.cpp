#include "cli/atomic_write.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <iterator>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

#include "cli/usage_error.h"

namespace flatrad {

namespace fs = std::filesystem;

namespace {

// While a temporary file exists, SIGINT, SIGTERM and SIGHUP remove it before
// the signal takes its course, so that an interrupted run leaves nothing
// behind. (SIGKILL cannot be caught: killed during the few milliseconds of
// the write, a run can leave PATH.tmp.<pid>, never a partial PATH.)
// The handler may only touch async-signal-safe state: a fixed buffer and
// a flag. One write at a time per process (the CLI writes one file).
constexpr int cleanup_signals[] = {SIGINT, SIGTERM, SIGHUP};
char g_tmp_path[4096];
volatile std::sig_atomic_t g_tmp_armed = 0;
struct sigaction g_previous[std::size(cleanup_signals)];

extern "C" void remove_tmp_then_resignal(int sig) {
    if (g_tmp_armed) ::unlink(g_tmp_path);
    g_tmp_armed = 0;
    // Back to what was there before (usually the default: terminate), and
    // send the signal again; it is delivered once this handler returns.
    for (size_t k = 0; k < std::size(cleanup_signals); ++k)
        if (cleanup_signals[k] == sig) ::sigaction(sig, &g_previous[k], nullptr);
    ::raise(sig);
}

// Arms the handler for `tmp` for its lifetime (when the name fits the buffer).
class TemporaryFileGuard {
public:
    explicit TemporaryFileGuard(const fs::path& tmp) {
        const std::string& name = tmp.native();
        if (name.size() >= sizeof g_tmp_path) return;
        std::memcpy(g_tmp_path, name.c_str(), name.size() + 1);
        struct sigaction action {};
        action.sa_handler = remove_tmp_then_resignal;
        sigemptyset(&action.sa_mask);
        for (int sig : cleanup_signals) sigaddset(&action.sa_mask, sig);
        g_tmp_armed = 1;
        for (size_t k = 0; k < std::size(cleanup_signals); ++k)
            ::sigaction(cleanup_signals[k], &action, &g_previous[k]);
        m_armed = true;
    }
    ~TemporaryFileGuard() {
        if (!m_armed) return;
        g_tmp_armed = 0;
        for (size_t k = 0; k < std::size(cleanup_signals); ++k)
            ::sigaction(cleanup_signals[k], &g_previous[k], nullptr);
    }
    TemporaryFileGuard(const TemporaryFileGuard&) = delete;
    TemporaryFileGuard& operator=(const TemporaryFileGuard&) = delete;

private:
    bool m_armed = false;
};

}  // namespace

void write_file_atomically(const fs::path& path, const std::string& text) {
    // Same directory as the target: a rename across file systems is a copy.
    const fs::path tmp = fs::path(path).concat(fmt::format(".tmp.{}", static_cast<long>(::getpid())));
    const TemporaryFileGuard guard(tmp);
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

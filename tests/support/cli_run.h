#pragma once
// Driving the flatrad command line in-process from tests: run it with
// arguments and capture status, stdout and stderr; scratch directories.
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "cli/cli.h"

namespace flatrad::test {

struct Run {
    int status = -1;
    std::string out, err;
};

inline Run run(const std::vector<std::string>& args) {
    std::ostringstream out, err;
    Run r;
    r.status = flatrad::run_cli(args, out, err);
    r.out = out.str();
    r.err = err.str();
    return r;
}

// SPEC: an error is exactly one line on stderr, starting "error: ".
inline bool is_one_error_line(const std::string& err) {
    return err.rfind("error: ", 0) == 0 && err.find('\n') == err.size() - 1;
}

inline std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// A fresh directory under the system's temp dir, removed with its contents.
class TempDir {
public:
    TempDir() {
        static std::atomic<int> counter{0};
        m_path = std::filesystem::temp_directory_path() /
                 ("flatrad_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        std::filesystem::remove_all(m_path);
        std::filesystem::create_directories(m_path);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(m_path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    /// Writes `text` to a file `name` in the directory; returns its path.
    std::string file(const std::string& name, const std::string& text) const {
        const std::filesystem::path p = m_path / name;
        std::ofstream(p) << text;
        return p.string();
    }
    std::string path(const std::string& name) const { return (m_path / name).string(); }
    const std::filesystem::path& dir() const { return m_path; }

private:
    std::filesystem::path m_path;
};

}  // namespace flatrad::test

// An interrupted `flatrad solve -o RESULT.json` leaves no file behind
// (apps/cli/atomic_write.h, apps/cli/solve_command.h): the result is
// computed first and written whole through RESULT.json.tmp.<pid>, renamed
// at the end, and SIGINT / SIGTERM / SIGHUP during the write remove the
// temporary file. Each case forks a child that runs the real code and
// signals it; the parent checks what is left in the directory.
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <doctest/doctest.h>
#include <fmt/format.h>

#include "cli/atomic_write.h"
#include "cli/cli.h"

namespace fs = std::filesystem;

namespace {

class TempDir {
public:
    TempDir() {
        static int counter = 0;
        m_path = fs::temp_directory_path() /
                 fmt::format("flatrad_interrupt_test_{}_{}", static_cast<long>(::getpid()), counter++);
        fs::remove_all(m_path);
        fs::create_directories(m_path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(m_path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const fs::path& path() const { return m_path; }

    std::vector<std::string> names() const {
        std::vector<std::string> out;
        for (const auto& e : fs::directory_iterator(m_path)) out.push_back(e.path().filename().string());
        return out;
    }

private:
    fs::path m_path;
};

// A closed room crowded with two-sided plates: with --subdivide 60 the
// exact solve has 5040 elements. Its dense LU alone is 2/3 n^3 = 8.5e10
// flops on one thread (4.0 s in Release, 2026-12-02; the form factors
// another 2.0 s), a floor that faster visibility cannot lower, so a signal
// sent after half a second always finds it computing. (--subdivide 20 took
// 0.49 s once the exact visibility got fast, and the signal came too late.)
std::string crowded_room() {
    std::string surfaces =
        R"({"name": "room", "material": "white", "points": [[0, 0], [10, 0], [10, 10], [0, 10]], "closed": true, "side": "in"})";
    int k = 0;
    for (int row = 0; row < 8; ++row)
        for (int col = 0; col < 5; ++col, ++k) {
            const double x = 1 + 1.8 * col + 0.3 * (row % 2), y = 1 + 1.1 * row;
            surfaces += fmt::format(
                R"(, {{"name": "p{}", "material": "{}", "points": [[{}, {}], [{}, {}]], "side": "both"}})", k,
                k % 7 == 0 ? "lamp" : "white", x, y, x + 0.9, y + 0.35);
        }
    return R"({"flatrad": 1, "name": "crowded", "materials": {"white": {"reflectance": 0.6}, "lamp": {"emission": 1, "reflectance": 0.2}}, "surfaces": [)" +
           surfaces + "]}";
}

/// Forks; the child runs `body` and _exits with its value (no atexit
/// handlers, no doctest teardown in the child).
template <class Body>
pid_t fork_child(Body&& body) {
    const pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        const int devnull = ::open("/dev/null", O_WRONLY);
        if (devnull >= 0) ::dup2(devnull, STDERR_FILENO);  // the child's summary and errors
        int status = 99;
        try {
            status = body();
        } catch (...) {
            status = 98;
        }
        ::_exit(status);
    }
    return pid;
}

int wait_for(pid_t pid) {
    int status = 0;
    REQUIRE(::waitpid(pid, &status, 0) == pid);
    return status;
}

void interrupt_solve(int sig) {
    TempDir dir;
    const fs::path scene = dir.path() / "room.json";
    std::ofstream(scene) << crowded_room();
    const fs::path result = dir.path() / "room.result.json";

    const pid_t child = fork_child([&] {
        std::ostringstream out, err;
        return flatrad::run_cli({"solve", scene.string(), "-o", result.string(), "--method", "exact", "--subdivide", "60",
                                 "--threads", "1", "-q"},
                                out, err);
    });
    // Long enough to be inside the solve (reading takes milliseconds),
    // far too short for it to end.
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    REQUIRE(::kill(child, sig) == 0);
    const int status = wait_for(child);
    INFO("child status ", status);
    REQUIRE_MESSAGE(WIFSIGNALED(status), "the solve ended before the signal: make the scene heavier");
    CHECK(WTERMSIG(status) == sig);
    // Only the scene is left: no result, no temporary file.
    CHECK(dir.names() == std::vector<std::string>{"room.json"});
}

}  // namespace

TEST_CASE("interrupt: SIGINT during a solve leaves no result file and no temporary file") {
    interrupt_solve(SIGINT);
}

TEST_CASE("interrupt: SIGTERM during a solve leaves nothing") { interrupt_solve(SIGTERM); }

TEST_CASE("interrupt: SIGKILL during a solve leaves nothing (the result is written only at the end)") {
    interrupt_solve(SIGKILL);
}

TEST_CASE("interrupt: a signal in the middle of writing removes the temporary file") {
    // The child writes 4 MiB through write_file_atomically into a FIFO put
    // where its temporary file goes: the parent reads a little, so the
    // child is blocked half-way through its write, then signals it. An
    // existing result must survive untouched.
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
        CAPTURE(sig);
        TempDir dir;
        const fs::path result = dir.path() / "out.json";
        std::ofstream(result) << "previous";
        const std::string text(4 << 20, 'x');
        int ready[2];
        REQUIRE(::pipe(ready) == 0);
        const pid_t child = fork_child([&] {
            ::close(ready[0]);
            const fs::path tmp = fs::path(result).concat(fmt::format(".tmp.{}", static_cast<long>(::getpid())));
            if (::mkfifo(tmp.c_str(), 0600) != 0) return 97;
            const char byte = 1;
            if (::write(ready[1], &byte, 1) != 1) return 96;
            flatrad::write_file_atomically(result, text);
            return 0;
        });
        ::close(ready[1]);
        char byte = 0;
        REQUIRE(::read(ready[0], &byte, 1) == 1);  // the FIFO exists
        ::close(ready[0]);
        const fs::path tmp = fs::path(result).concat(fmt::format(".tmp.{}", static_cast<long>(child)));
        const int fifo = ::open(tmp.c_str(), O_RDONLY);
        REQUIRE(fifo >= 0);
        char buffer[4096];
        REQUIRE(::read(fifo, buffer, sizeof buffer) > 0);  // the write has begun
        REQUIRE(::kill(child, sig) == 0);
        const int status = wait_for(child);
        ::close(fifo);
        INFO("child status ", status);
        REQUIRE(WIFSIGNALED(status));
        CHECK(WTERMSIG(status) == sig);
        CHECK(dir.names() == std::vector<std::string>{"out.json"});  // the temporary file is gone
        std::ifstream in(result);
        std::string kept;
        in >> kept;
        CHECK(kept == "previous");
    }
}

TEST_CASE("interrupt: after a write the previous signal dispositions are back") {
    // write_file_atomically installs its handlers only while the temporary
    // file exists: an embedding program's own handler survives it.
    TempDir dir;
    struct sigaction mine {};
    mine.sa_handler = SIG_IGN;
    sigemptyset(&mine.sa_mask);
    struct sigaction saved {};
    REQUIRE(::sigaction(SIGHUP, &mine, &saved) == 0);
    flatrad::write_file_atomically(dir.path() / "a.json", "{}\n");
    struct sigaction now {};
    REQUIRE(::sigaction(SIGHUP, &saved, &now) == 0);
    const bool still_ignored = now.sa_handler == SIG_IGN;
    CHECK(still_ignored);
    CHECK(dir.names() == std::vector<std::string>{"a.json"});
}

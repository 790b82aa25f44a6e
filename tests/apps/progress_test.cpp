// Tests apps/cli/progress.h: the self-overwriting progress line. Without a
// terminal, the renderer is driven with a stream and an "is terminal" flag,
// and a clock the test moves by hand.
#include "cli/progress.h"

#include <chrono>
#include <cmath>
#include <functional>
#include <sstream>
#include <string>

#include <doctest/doctest.h>

using flatrad::ProgressLine;
using Clock = ProgressLine::Clock;

namespace {

const std::string erase = "\r\033[K";

// A clock that stands still until the test moves it.
struct FakeClock {
    Clock::time_point t{};
    std::function<Clock::time_point()> fn() {
        return [this] { return t; };
    }
};

size_t count(const std::string& s, const std::string& what) {
    size_t n = 0;
    for (size_t k = s.find(what); k != std::string::npos; k = s.find(what, k + 1)) ++n;
    return n;
}

}  // namespace

TEST_CASE("progress: a line that is not on a terminal writes nothing at all") {
    std::ostringstream os;
    FakeClock clock;
    {
        ProgressLine line(os, false, 80, clock.fn());
        CHECK_FALSE(line.enabled());
        auto report = line.callback("solve: ");
        for (int k = 0; k <= 10; ++k) {
            report("refine", k / 10.0);
            clock.t += std::chrono::seconds(1);
        }
        line.update("solve", -1);
        line.clear();
    }  // the destructor erases only what was drawn: nothing
    CHECK(os.str().empty());
}

TEST_CASE("progress: a test's string stream is never taken for the terminal") {
    std::ostringstream os;
    CHECK_FALSE(flatrad::is_terminal_stderr(os));
}

TEST_CASE("progress: drawn at most once per interval, erased when done") {
    std::ostringstream os;
    FakeClock clock;
    ProgressLine line(os, true, 80, clock.fn());
    REQUIRE(line.enabled());
    auto report = line.callback("solve: ");
    report("refine pass 1", 0.1);  // a task's first report is drawn at once
    CHECK(os.str() == erase + flatrad::progress_text("solve: refine pass 1", 0.1, 0.0, 80));
    clock.t += flatrad::progress_min_interval / 2;
    report("refine pass 1", 0.2);  // too soon: skipped
    CHECK(count(os.str(), erase) == 1);
    clock.t += flatrad::progress_min_interval;
    report("refine pass 2", 0.5);
    CHECK(count(os.str(), erase) == 2);
    CHECK(os.str().find("solve: refine pass 2") != std::string::npos);
    CHECK(os.str().find('\n') == std::string::npos);  // one line, overwritten in place

    line.clear();
    const std::string text = os.str();
    CHECK(text.size() >= erase.size());
    CHECK(text.substr(text.size() - erase.size()) == erase);  // ends with the line erased
    line.clear();                                              // nothing left to erase
    CHECK(os.str() == text);

    // A new task draws its first report at once, even within the interval.
    auto next = line.callback("sweep: ");
    next("solve", -1);
    CHECK(count(os.str(), erase) == 4);
    CHECK(os.str().find("sweep: solve") != std::string::npos);
}

TEST_CASE("progress: a thousand reports within the interval draw once") {
    std::ostringstream os;
    FakeClock clock;
    ProgressLine line(os, true, 80, clock.fn());
    auto report = line.callback();
    for (int k = 0; k < 1000; ++k) {
        report("gather", k / 1000.0);
        clock.t += std::chrono::microseconds(50);  // 1000 x 50 us = 50 ms < 100 ms
    }
    CHECK(count(os.str(), erase) == 1);
}

TEST_CASE("progress_text: bar and percentage, unknown fraction, cut to the width") {
    CHECK(flatrad::progress_text("solve", 0.5, 1.25, 80) == "solve  [##########..........]  50%  1.2 s");
    CHECK(flatrad::progress_text("solve", 0.0, 0.0, 80) == "solve  [....................]   0%  0.0 s");
    CHECK(flatrad::progress_text("solve", 1.0, 2.0, 80) == "solve  [####################] 100%  2.0 s");
    CHECK(flatrad::progress_text("solve", 1.0000001, 2.0, 80) == "solve  [####################] 100%  2.0 s");
    // Unknown: < 0 or NaN, no bar.
    CHECK(flatrad::progress_text("exact solve", -1, 3.0, 80) == "exact solve  3.0 s");
    CHECK(flatrad::progress_text("exact solve", std::nan(""), 3.0, 80) == "exact solve  3.0 s");
    // Never into the last column: a wrapped line cannot be overwritten.
    const std::string long_stage(200, 'x');
    CHECK(flatrad::progress_text(long_stage, 0.5, 1.0, 40).size() == 39);
    CHECK(flatrad::progress_text("solve", 0.5, 1.0, 1).empty());
}

TEST_CASE("progress: a terminal too narrow for a useful line gets none") {
    std::ostringstream os;
    ProgressLine line(os, true, 4);
    CHECK_FALSE(line.enabled());
    line.update("solve", 0.5);
    CHECK(os.str().empty());
}

#include "cli/progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>

#include <fmt/format.h>

namespace flatrad {

namespace {

// "\r" back to the first column, then ESC[K (erase in line, to its end).
constexpr const char* erase_line = "\r\033[K";

// Cells of the bar: 20 gives 5% steps, enough to see movement.
constexpr int bar_cells = 20;

// Narrower than this, a line would say nothing useful; nothing is drawn.
constexpr int min_useful_width = 8;

}  // namespace

bool is_terminal_stderr(const std::ostream& os) {
    if (os.rdbuf() != std::cerr.rdbuf() || ::isatty(STDERR_FILENO) != 1) return false;
    const char* term = std::getenv("TERM");
    return !(term && std::strcmp(term, "dumb") == 0);
}

int terminal_columns() {
    winsize ws{};
    if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return ws.ws_col;
    if (const char* columns = std::getenv("COLUMNS")) {
        const int c = std::atoi(columns);
        if (c > 0) return c;
    }
    return default_terminal_columns;
}

std::string progress_text(const std::string& stage, double fraction, double elapsed_s, int width) {
    std::string text = stage;
    if (fraction >= 0) {  // false for NaN too
        const double f = std::min(fraction, 1.0);
        const int filled = static_cast<int>(std::floor(f * bar_cells));
        text += fmt::format("  [{}{}] {:3.0f}%", std::string(static_cast<size_t>(filled), '#'),
                            std::string(static_cast<size_t>(bar_cells - filled), '.'), std::floor(100 * f));
    }
    text += fmt::format("  {:.1f} s", std::max(0.0, elapsed_s));
    const size_t room = static_cast<size_t>(std::max(0, width - 1));
    if (text.size() > room) text.resize(room);
    return text;
}

ProgressLine::ProgressLine(std::ostream& os, bool enabled, int width, std::function<Clock::time_point()> now)
    : m_os(os), m_enabled(enabled && width >= min_useful_width), m_width(width), m_now(std::move(now)) {
    m_start = m_last_draw = m_now();
}

ProgressLine::~ProgressLine() {
    try {
        clear();
    } catch (...) {
        // A destructor must not throw; a failed erase leaves a stale line.
    }
}

std::function<void(const std::string&, double)> ProgressLine::callback(const std::string& prefix) {
    {
        const std::lock_guard<std::mutex> lock(m_mutex);
        m_start = m_now();
        m_any_draw = false;
    }
    if (!m_enabled) return [](const std::string&, double) {};
    return [this, prefix](const std::string& stage, double fraction) { update(prefix + stage, fraction); };
}

void ProgressLine::update(const std::string& stage, double fraction) {
    if (!m_enabled) return;
    const std::lock_guard<std::mutex> lock(m_mutex);
    const Clock::time_point t = m_now();
    if (m_any_draw && t - m_last_draw < progress_min_interval) return;
    m_last_draw = t;
    m_any_draw = m_drawn = true;
    const double elapsed = std::chrono::duration<double>(t - m_start).count();
    m_os << erase_line << progress_text(stage, fraction, elapsed, m_width) << std::flush;
}

void ProgressLine::clear() {
    const std::lock_guard<std::mutex> lock(m_mutex);
    if (!m_drawn) return;
    m_os << erase_line << std::flush;
    m_drawn = false;
}

}  // namespace flatrad

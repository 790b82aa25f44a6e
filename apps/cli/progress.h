#pragma once
/// Progress of a long run on stderr: one self-overwriting line that draws
/// the hierarchical solver's progress reports (HierarchicalOptions::progress,
/// solver/hierarchical_solver.h), e.g.
///   solve: refine pass 2  [#########...........]  45%  3.2 s
///
/// Drawn only on a terminal: stdout stays pure JSON whatever happens, and
/// stderr that goes to a file or a pipe (a log, a test, CI) gets nothing
/// from here, not even an escape code. Each draw is "\r", "ESC[K" (erase to
/// the end of the line) and the text, cut to the terminal's width so that
/// it never wraps (a wrapped line could not be overwritten); at most one
/// draw per progress_min_interval, so that a solver reporting thousands of
/// times a second costs a terminal nothing. clear() (and the destructor)
/// erase the line, leaving the cursor at the start of an empty line, so
/// that what is printed next (a summary, an error) starts clean.
///
/// Conventions: a fraction in [0, 1] draws a bar and a percentage (values
/// just outside are clamped); a fraction < 0 or NaN means "unknown" and
/// draws the stage and the elapsed time only. The text is taken as ASCII
/// (it is cut by bytes).
#include <chrono>
#include <functional>
#include <iosfwd>
#include <mutex>
#include <string>

namespace flatrad {

/// At most ten draws a second: smooth to the eye, and cheap even for a
/// slow terminal or a remote session.
inline constexpr std::chrono::milliseconds progress_min_interval{100};

/// Width assumed when the terminal does not say (ioctl and $COLUMNS fail).
inline constexpr int default_terminal_columns = 80;

/// Whether `os` is this process's std::cerr and file descriptor 2 is a
/// terminal that understands "ESC[K" ($TERM is not "dumb"). False for any
/// other stream (a test's std::ostringstream), whatever fd 2 is.
bool is_terminal_stderr(const std::ostream& os);

/// Columns of the terminal on file descriptor 2, else $COLUMNS, else
/// default_terminal_columns.
int terminal_columns();

/// The text of one progress line (no "\r", no escape codes), at most
/// `width - 1` characters (the last column is left free: writing there
/// makes some terminals wrap). `elapsed_s` is the time since the task began.
std::string progress_text(const std::string& stage, double fraction, double elapsed_s, int width);

class ProgressLine {
public:
    using Clock = std::chrono::steady_clock;

    /// Draws on `os` when `enabled` (callers pass is_terminal_stderr(os) and
    /// not --quiet); a disabled line never writes anything. `width` is the
    /// terminal's (terminal_columns()); `now` is the clock, replaceable in
    /// tests.
    ProgressLine(std::ostream& os, bool enabled, int width = terminal_columns(),
                 std::function<Clock::time_point()> now = &Clock::now);
    ~ProgressLine();
    ProgressLine(const ProgressLine&) = delete;
    ProgressLine& operator=(const ProgressLine&) = delete;

    bool enabled() const { return m_enabled; }

    /// A callback for HierarchicalOptions::progress that draws `prefix` +
    /// stage. Starts a new task: the elapsed time counts from here, and the
    /// task's first report is drawn at once. The callback refers to this
    /// object, which must outlive the solve it is given to.
    std::function<void(const std::string& stage, double fraction)> callback(const std::string& prefix = "");

    /// Draws `stage` (and the fraction) unless the last draw was less than
    /// progress_min_interval ago. Thread-safe.
    void update(const std::string& stage, double fraction);

    /// Erases the line when something is drawn; otherwise writes nothing.
    void clear();

private:
    std::ostream& m_os;
    bool m_enabled;
    int m_width;
    std::function<Clock::time_point()> m_now;
    std::mutex m_mutex;
    Clock::time_point m_start, m_last_draw;
    bool m_drawn = false;       ///< a line is on screen
    bool m_any_draw = false;    ///< something was drawn since the task began
};

}  // namespace flatrad

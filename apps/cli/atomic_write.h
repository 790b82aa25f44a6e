#pragma once
/// Writing an output file so that it is never seen half-written.
#include <filesystem>
#include <string>

namespace flatrad {

/// Writes `text` to `path` through a temporary file in the same directory,
/// `PATH.tmp.<pid>`, renamed over `path` once complete (rename is atomic
/// within a file system, so a reader sees the old file or the whole new
/// one). On any failure the temporary file is removed, `path` is left as it
/// was, and std::runtime_error says what failed and why. SIGINT, SIGTERM
/// or SIGHUP during the write remove the temporary file too, then take
/// their previous course (by default: the process ends). Not thread-safe:
/// one write at a time per process.
void write_file_atomically(const std::filesystem::path& path, const std::string& text);

/// Throws UsageError unless `path` could be created: its directory exists
/// and `path` is not itself a directory. `flag` names the option in the
/// message. Checked before a solve so that a typo does not waste the run.
void check_output_path(const std::filesystem::path& path, const std::string& flag);

}  // namespace flatrad

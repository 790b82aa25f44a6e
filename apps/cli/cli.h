#pragma once
/// The `flatrad` command line (SPEC.md, "Command line"), as a function so
/// that tests can drive it in-process.
///
/// Output conventions: results (the result file without `-o`, the
/// `formfactor` object) go to `out` as pure JSON; help goes to `out`;
/// human summaries and errors go to `err`. An error is exactly one line,
/// `error: ...`.
///
/// Exit status: 0 done; 2 bad input (scene file) or bad arguments;
/// 1 anything else (an internal error, a failed write, out of memory).
#include <iosfwd>
#include <string>
#include <vector>

namespace flatrad {

/// Runs `flatrad` with the given arguments (argv[0] is the program name).
int run_cli(int argc, char** argv, std::ostream& out, std::ostream& err);

/// Same, with the arguments after the program name as strings.
int run_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace flatrad

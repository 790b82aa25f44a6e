#pragma once
/// The short human summary of a solve, printed on stderr (stdout stays
/// pure JSON).
#include <iosfwd>
#include <string>

#include "engine/scene.h"
#include "solver/solution.h"

namespace flatrad {

/// Scene name, method, patches and elements, time, energy balance (and a
/// warning when the linear solve stopped short of its residual) and the
/// `brightest` brightest patches (by mean radiosity over channels).
/// `written_to` names the result file, or is empty when it went to stdout.
void print_summary(std::ostream& os, const Scene& scene, const Solution& solution,
                   const std::string& written_to, int brightest = 5);

}  // namespace flatrad

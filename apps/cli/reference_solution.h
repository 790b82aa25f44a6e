#pragma once
/// The exact reference an approximate solution is measured against
/// (DESIGN.md §5, "how wrong": the error is only as good as its yardstick;
/// DESIGN.md §3, "The reference solver"). Used by `flatrad compare` (one
/// hierarchical solution) and `flatrad sweep` over whole solutions (many).
///
/// The reference must be much better than what it judges, so the exact
/// solver's own discretisation error is estimated and driven down:
///   1. solve exactly on a mesh M and on M halved (every element cut at its
///      midpoint); the estimate of the M solution's error is the relative
///      L2 distance between the two (cli/solution_error.h), and the
///      compared error is measured against the halved solution;
///   2. first M is K equal elements per patch (ReferenceOptions::subdivide;
///      halved while the pair would not fit, so that the reference always
///      comes with an estimate if one fits at all) and M halved is 2K;
///      while the estimate exceeds 1/reference_margin of the compared
///      error, K doubles (the old 2K solve is reused) as long as the new
///      pair fits in half the cap, the rest being left to grading;
///   3. when the next doubling would not fit, the mesh is graded instead:
///      each element of the last pair's M gets an indicator, the squared
///      length-weighted difference between its value and its halves' in
///      the finer solve (where the radiosity varies within it, or the
///      finer mesh moved it), and the elements above a threshold are cut
///      in 2, 4, ... 2^max_graded_level pieces by how far above it they
///      are (the error of constant elements falls as h^1.5 in this norm).
///      The threshold shares the target error equally over the elements,
///      raised until the new pair fits and M grows by at most
///      graded_growth (and by at least 1/graded_min_step, or the cap has
///      stopped it); then 1 on the new M. A slit under a table leg or
///      the gap between two books gets its elements without every wall
///      getting them too;
///   4. it stops when the estimate is reached, when no new pair fits
///      (exact_solver_memory_bytes, max_elements) or no element is left
///      to cut, or when the estimate is at rounding level
///      (reference_rounding_floor: a finer mesh cannot do better); then
///      the last solve is the reference with `reached` false and `stopped`
///      saying why.
/// The estimate is that of the pair's coarser solve; the halved reference
/// used is usually better still (its error shrinks with the elements), so
/// the estimate is conservative. The compared error is a function of the
/// candidate, so a caller judging several solutions passes the smallest of
/// their errors: the reference is then good enough for every one of them.
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "cli/solution_error.h"
#include "engine/scene.h"
#include "solver/solution.h"

namespace flatrad {

/// The reference must be this many times more accurate than what it judges
/// (a tenth: the judged error is then right to about 10%, one digit).
inline constexpr double reference_margin = 10;

/// Below this estimate the K and 2K solutions agree to rounding (the dense
/// LU's residual is ~1e-15 relative, amplified by the conditioning,
/// 1 / (1 - rho) up to 1000 in a white furnace): a finer mesh cannot do
/// better, so the doubling stops there whatever the target.
inline constexpr double reference_rounding_floor = 1e-12;

/// Default largest mesh: a dense LU of 8000 unknowns is ~3e11 flops and
/// 1.5 GB (three matrices), a minute or two on a small machine; the exact
/// solver's own memory limit (8 GiB) would allow ~19000, hours of work.
inline constexpr long default_reference_max_elements = 8000;

/// A graded step's M grows by at most this factor: the indicators come
/// from the last pair, and a smaller step lets the next pair's correct
/// them (the furnished room from K = 8: 2.9e-4 after one step of 1.36x,
/// 1.5e-4 and 1.2e-4 after two more; 14 steps of a few elements each
/// reached 1.2e-4 only after eleven).
inline constexpr double graded_growth = 1.5;

/// A graded step adds at least 1/graded_min_step of its mesh's elements,
/// or none is taken (the cap has stopped the search).
inline constexpr long graded_min_step = 20;

/// The most a graded step cuts one element: into 2^6 = 64 pieces.
inline constexpr int max_graded_level = 6;

struct ReferenceOptions {
    int subdivide = 16;                                   ///< first K, >= 1
    long max_elements = default_reference_max_elements;   ///< largest mesh (patches x K) tried, >= 1
    int threads = 0;                                      ///< 0: all cores
    /// Called before each exact solve with its K (0 for a graded mesh)
    /// and its elements, e.g. to log it; may be empty.
    std::function<void(long K, long elements)> on_solve;
};

/// Whether an exact solve at K fits: patches x K <= max_elements and within
/// the exact solver's memory limit.
bool reference_fits(const Scene& scene, long K, long max_elements);

/// Throws UsageError (naming --max-elements) unless one element per patch
/// fits under `max_elements` and the memory limit: the first K is halved
/// down to 1 while its pair does not fit, so that is all a reference needs
/// (what `flatrad compare` and `flatrad sweep` check before solving).
void check_reference_cap(const Scene& scene, long max_elements);

/// One pair of step 1: M against M halved.
struct ReferenceStep {
    long subdivide = 0;          ///< K of M; 0 when M is graded
    long elements = 0;           ///< M's elements
    double error_estimate = 0;   ///< relative L2 of the M solution against the halved one
    double compared_error = 0;   ///< the compared error against the halved solution
};

/// "K = 16 (5680 elements)", or "graded (3977 elements)" for K = 0.
std::string reference_mesh_name(long K, long elements);

struct Reference {
    /// Every exact solve, coarse to fine (K, 2K, 4K, ...); the last one is
    /// the reference. Kept so that callers can draw the exact solver's own
    /// error against its run time.
    std::vector<Solution> ladder;
    std::vector<long> ladder_subdivide;  ///< K of each ladder entry; 0 for a graded mesh
    /// Relative L2 (and max relative) of the last pair's coarser solve
    /// against its finer; +inf (NaN) when no pair was solved.
    double error_estimate = std::numeric_limits<double>::infinity();
    double estimate_max_relative = std::numeric_limits<double>::quiet_NaN();
    /// The same pair's CompareError::patch_relative: the reference's own
    /// error at each patch's scale (NaN when no pair was solved).
    PatchRelative estimate_patch_relative{std::numeric_limits<double>::quiet_NaN(),
                                          std::numeric_limits<double>::quiet_NaN(),
                                          std::numeric_limits<double>::quiet_NaN()};
    long estimate_from_subdivide = 0;  ///< K of that coarser solve; 0 when none or graded
    /// That coarser solve's mesh as reference_mesh_name writes it, and its
    /// halved one ("K = 8 (2840 elements) against K = 16 (5680 elements)");
    /// empty when no pair was solved.
    std::string estimate_from;
    bool reached = false;              ///< error_estimate <= compared error / reference_margin
    std::string stopped;               ///< why the doubling stopped short; empty when reached
    std::vector<ReferenceStep> steps;
    double time_total_s = 0;           ///< all exact solves together

    const Solution& solution() const { return ladder.back(); }
    long subdivide() const { return ladder_subdivide.back(); }  ///< 0 when graded
    std::string mesh_name() const { return reference_mesh_name(subdivide(), solution().stats.elements); }
};

/// Builds the reference for `scene` as above. `compared_error(candidate)`
/// is the error being judged, measured against a candidate reference (for
/// one solution S: compare_solutions(scene, S, candidate).relative_l2).
/// Pre: options.subdivide >= 1 and reference_fits(scene, 1,
/// options.max_elements): one element per patch fits, as the first K is
/// halved down to 1 while its pair does not (throws std::invalid_argument
/// otherwise: callers check it first, with a message naming their own
/// flags). Exceptions of the exact solver
/// (InputError for a scene it refuses) pass through.
Reference solve_reference(const Scene& scene, const ReferenceOptions& options,
                          const std::function<double(const Solution& candidate)>& compared_error);

}  // namespace flatrad

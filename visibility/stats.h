#pragma once
/// Counters every visibility method fills in, so that what a query cost (and
/// what it approximated) is visible in `stats` (DESIGN.md §4).
namespace flatrad {

struct VisibilityStats {
    long queries = 0;           ///< occluded exchanges asked for (shaft held a blocker)
    long unoccluded = 0;        ///< exchanges answered by crossed strings (empty shaft)
    long culled = 0;            ///< pairs that cannot see each other's lit side
    long clusters_visited = 0;  ///< hierarchy nodes visited by shaft culling
    long approximated = 0;      ///< clusters replaced by a mean (0 for exact)
    long blockers = 0;          ///< blocker pieces found inside shafts
    long events = 0;            ///< critical directions integrated over (direction bounds: bins)
    long separated = 0;         ///< shafts or sub-shafts closed by one blocker (answer 0 at once)
    long subshafts = 0;         ///< shafts split in two because they held many blockers
    long bounded = 0;           ///< answered by direction bounds within the tolerance (direction_bounds.h)
    long opaque = 0;            ///< shafts shown closed by a band of pieces across them (opaque_band.h)
    long banded = 0;            ///< answered by bands' upper bound within the tolerance (opaque_band.h)
    long slabs = 0;             ///< of opaque and banded: settled by a long shaft's slabs alone (multiscale.h)
    long screens = 0;           ///< closure screens shown closed (closure_screen.h, MultiscaleVisibility::shown_closed)
    long screened = 0;          ///< queries answered by a closure screen instead (counted by the caller)
    long boxed = 0;             ///< links dropped whole: every line between their ends' boxes shown blocked, or all but lines the caller may leave out (box_closure.h; counted by the caller)

    VisibilityStats& operator+=(const VisibilityStats& o) {
        queries += o.queries;
        unoccluded += o.unoccluded;
        culled += o.culled;
        clusters_visited += o.clusters_visited;
        approximated += o.approximated;
        blockers += o.blockers;
        events += o.events;
        separated += o.separated;
        subshafts += o.subshafts;
        bounded += o.bounded;
        opaque += o.opaque;
        banded += o.banded;
        slabs += o.slabs;
        screens += o.screens;
        screened += o.screened;
        boxed += o.boxed;
        return *this;
    }
};

}  // namespace flatrad

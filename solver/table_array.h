#pragma once
/// The directional tables of a cluster hierarchy (solver/directional.h),
/// one per table index, held as two arrays: every table's linear part (two
/// numbers), and samples only for the tables that have a slot.
///
/// Pay for what the scene uses (DESIGN.md §4): a link that reads or writes
/// a table through its linear part (every member faces every direction of
/// the link) never looks at the samples. In a round room every cluster link
/// is of that kind, and the operator's pull and push over 32 samples per
/// cluster were most of its memory traffic (272 MB per table array at 10^6
/// walls, against 16 MB for the linear parts). Which tables need samples is
/// decided from the links (HierarchicalSolver::sample_slots): those read or
/// written through samples, and every table below them, since a parent's
/// table is the sum of its children's (pull) and a child's arrivals include
/// its parent's (push).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "engine/error.h"
#include "solver/directional.h"

namespace flatrad {

class TableArray {
public:
    /// Layouts. Contents are left unspecified (clear() before use): every
    /// user zeroes its tables at the start of a pass anyway, and zeroing
    /// here too was a second pass over hundreds of MB per round at 10^6
    /// walls.
    /// `tables` tables, every one with samples.
    void reset_full(int tables) {
        m_slot = nullptr;
        assign(tables, tables);
    }

    /// `tables` tables, table t with samples at slot[t] >= 0 (slots 0 ..
    /// slotted - 1), none where slot[t] < 0. `slot` must outlive its use
    /// here.
    void reset(const std::vector<int32_t>& slot, int slotted) {
        m_slot = &slot;
        assign(static_cast<int>(slot.size()), slotted);
    }

    /// Zeroes every table (the layout stays).
    void clear() {
        std::fill(m_linear.begin(), m_linear.end(), 0.0);
        std::fill(m_samples.begin(), m_samples.end(), 0.0);
    }

    /// Zeroes table t.
    void clear(int t) {
        double* l = linear(t);
        l[0] = l[1] = 0;
        if (double* s = samples(t)) std::fill_n(s, directional_bins, 0.0);
    }

    int tables() const { return m_tables; }

    double* linear(int t) { return &m_linear[2 * static_cast<size_t>(t)]; }
    const double* linear(int t) const { return &m_linear[2 * static_cast<size_t>(t)]; }

    /// Table t's samples; null when it has none.
    double* samples(int t) {
        const int32_t s = slot(t);
        return s < 0 ? nullptr : &m_samples[static_cast<size_t>(s) * directional_bins];
    }
    const double* samples(int t) const {
        const int32_t s = slot(t);
        return s < 0 ? nullptr : &m_samples[static_cast<size_t>(s) * directional_bins];
    }

    /// Pull: parent += child. Push: child += parent. Where a parent has
    /// samples its children have them too (how the slots are chosen), and
    /// samples are summed where both have them; a parent with samples and
    /// a child without would lose light silently, so it is asserted.
    /// With `scale` (per bin, not null), the samples added are scaled by
    /// it (the child's share seen from outside the parent); the linear
    /// parts are added as they are (a table below which something is
    /// hidden is never read or written through its linear part).
    void sum_child(int parent, int child, const float* scale = nullptr) { add(parent, child, parent, child, scale); }
    void add_parent(int child, int parent, const float* scale = nullptr) { add(child, parent, parent, child, scale); }

private:
    void add(int dst, int src, [[maybe_unused]] int parent, [[maybe_unused]] int child, const float* scale) {
        double* dl = linear(dst);
        const double* sl = linear(src);
        dl[0] += sl[0];
        dl[1] += sl[1];
        double* ds = samples(dst);
        const double* ss = samples(src);
        FLATRAD_ASSERT(slot(parent) < 0 || slot(child) >= 0, "a table with samples above one without");
        if (ds && ss) {
            if (scale)
                for (int k = 0; k < directional_bins; ++k) ds[k] += scale[k] * ss[k];
            else
                for (int k = 0; k < directional_bins; ++k) ds[k] += ss[k];
        }
    }
    int32_t slot(int t) const { return m_slot ? (*m_slot)[static_cast<size_t>(t)] : t; }
    void assign(int tables, int slotted) {
        m_tables = tables;
        m_linear.resize(2 * static_cast<size_t>(tables));
        m_samples.resize(static_cast<size_t>(slotted) * directional_bins);
    }

    const std::vector<int32_t>* m_slot = nullptr;  // null: table t has slot t
    int m_tables = 0;
    std::vector<double> m_linear;
    std::vector<double> m_samples;
};

}  // namespace flatrad

#pragma once
/// Neumaier's compensated summation: long sums (totals, row sums, gathers)
/// keep an error of a few ulps of the result instead of growing with the
/// number of terms (STYLE.md, "Keeping the numerics honest").
#include <cmath>

namespace flatrad {

class CompensatedSum {
public:
    void add(double x) {
        const double t = m_sum + x;
        // The branch keeps the rounding error of whichever operand is smaller.
        if (std::abs(m_sum) >= std::abs(x))
            m_comp += (m_sum - t) + x;
        else
            m_comp += (x - t) + m_sum;
        m_sum = t;
    }
    double value() const { return m_sum + m_comp; }

private:
    double m_sum = 0, m_comp = 0;
};

}  // namespace flatrad

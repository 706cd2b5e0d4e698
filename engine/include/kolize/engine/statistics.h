#pragma once
/// \file
/// Small statistics shared by the demos, the benchmarks and the replay.

#include <algorithm>
#include <vector>

namespace kolize {

/// The median (upper median for an even count) of `values`; 0 when empty.
inline double median(std::vector<double> values) {
    if (values.empty()) {
        return 0;
    }
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    return values[values.size() / 2];
}

}  // namespace kolize

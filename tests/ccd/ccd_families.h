#pragma once
// Seeded random families of degenerate CCD queries, and the exact check of `robust`
// against the reference, shared by the differential test (a CI slice) and kolize-ccd-soak.
#include "ccd_reference.h"

#include "kolize/narrowphase/ccd.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace kolize::ccd::families {

enum class Kind { kVertexFace, kEdgeEdge };

/// One generated query: kind, positions, the time range to search and what made it.
struct Query {
    Kind kind = Kind::kVertexFace;
    std::array<Vec3, 4> start, end;
    double min_time = 0.0, max_time = 1.0;
    int family = 0;
    int scale_exponent = 0;  ///< coordinates were multiplied by 2^scale_exponent
    bool offset = false;     ///< translated by about 1e10 before scaling
};

/// Family names, indexed by Query::family.
const std::vector<std::string>& familyNames();

/// Query number `index` of the stream `seed`: its own generator is seeded from both, so any
/// query can be regenerated alone. `family` < 0 picks one at random.
Query generate(uint64_t seed, uint64_t index, int family = -1);

/// The robust settings under test, by mode index (every arithmetic mode).
struct Mode {
    std::string name;
    RobustSettings settings;
};
const std::vector<Mode>& modes();

/// Runs `robust` on q in the given mode and checks it against the reference decision d:
/// hit must agree, and when both hit, toi <= t* <= toi + toi_tolerance exactly. Returns a
/// description of the disagreement, or nothing.
std::optional<std::string> check(const Query& q, const Mode& mode, reference::Decision& d,
                                 CcdResult* result = nullptr);

/// The reference decision of q over its time range.
reference::Decision decide(const Query& q);

/// A simpler query that still fails `mode` the same way (coordinates zeroed, rounded to
/// fewer bits, motions removed, while the check still fails); q itself if none is found.
Query shrink(const Query& q, const Mode& mode);

/// The query as C++ source text (hex floats), for a regression test.
std::string describe(const Query& q);

}  // namespace kolize::ccd::families

#pragma once
// Exact continuous collision decision (private to the narrowphase library).
//
// Decides exactly whether linearly moving closed primitives touch during [t_lo, t_hi], and
// brackets the earliest such time. The robust method runs it on the candidates its
// floating-point inclusion search cannot reject; see ccd.h for the guarantee this gives and
// ccd_exact.cpp for the decomposition and the (filtered, then GMP) arithmetic.
#include "kolize/narrowphase/ccd.h"

#include <array>

namespace kolize::ccd::detail {

/// Outcome of an exact decision.
struct ExactContact {
    /// The closed primitives touch at some t in [t_lo, t_hi] (exact, no tolerance).
    bool hit = false;
    /// When `hit`: a double no later than the earliest contact time t* in [t_lo, t_hi] and
    /// at most `toi_tolerance` (plus one rounding to double) before it.
    double toi = 1.0;
};

/// How the decision computes. Both give the same answer; `kExactOnly` skips the interval
/// filter and exists for tests that check exactly that.
enum class Arithmetic { kFiltered, kExactOnly };

/// Vertex `start[0]`/`end[0]` against triangle `start[1..3]`/`end[1..3]`, exact, for
/// t in [t_lo, t_hi] with 0 <= t_lo <= t_hi <= 1 and 0 < toi_tolerance <= 1 (asserted).
/// Any finite double coordinates.
ExactContact vertexFaceExact(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                             double t_lo, double t_hi, double toi_tolerance,
                             Arithmetic arithmetic = Arithmetic::kFiltered);

/// Edge 0-1 against edge 2-3, exact, for t in [t_lo, t_hi] (see vertexFaceExact).
ExactContact edgeEdgeExact(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                           double t_lo, double t_hi, double toi_tolerance,
                           Arithmetic arithmetic = Arithmetic::kFiltered);

}  // namespace kolize::ccd::detail

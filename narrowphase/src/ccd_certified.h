#pragma once
// Certified floating-point CCD decision (private to the narrowphase library).
//
// Decides contact of linearly moving closed primitives in plain double arithmetic where a
// rigorous error bound proves the answer, in both directions: "no contact" and "contact,
// first at a time in [toi, toi + tolerance]". It answers "undecided" otherwise (exact
// touching, coplanar motion, double roots, near misses closer than about 1e-13 relative),
// and the robust method hands the rest of the range to the exact stage. See
// ccd_certified.cpp for the method and its error analysis.
#include "kolize/narrowphase/ccd.h"

#include <array>

namespace kolize::ccd::detail {

struct CertifiedOutcome {
    enum class Verdict { kNoContact, kContact, kUndecided };
    Verdict verdict = Verdict::kUndecided;
    /// kContact: no later than the first contact t* in the range, t* <= toi + tolerance.
    double toi = 1.0;
    /// kUndecided: no contact happens in [t_lo, resume_from); the rest is undecided.
    double resume_from = 0.0;
    int intervals = 0;  ///< time intervals examined (the work done)
    /// kUndecided: why, for statistics ("budget", "depth", "bracket", "at root", "end",
    /// "end zero", "coplanar", "overflow").
    const char* reason = "";
};

/// Vertex start[0]/end[0] against triangle start[1..3]/end[1..3] over [t_lo, t_hi] with
/// 0 <= t_lo <= t_hi <= 1 and tolerance >= 2^-52. Finite coordinates. Assumes the default
/// floating-point environment (round to nearest, no flush to zero).
CertifiedOutcome vertexFaceCertified(const std::array<Vec3, 4>& start,
                                     const std::array<Vec3, 4>& end, double t_lo, double t_hi,
                                     double tolerance);

/// Edge 0-1 against edge 2-3 (see vertexFaceCertified).
CertifiedOutcome edgeEdgeCertified(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                                   double t_lo, double t_hi, double tolerance);

}  // namespace kolize::ccd::detail

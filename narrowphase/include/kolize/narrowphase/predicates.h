#pragma once
/// \file
/// Exact orientation predicates on double coordinates.
///
/// `orient3d` and `orient2d` return the exact sign of a determinant of the input doubles
/// (no tolerance). Three stages, each taken only when the one before cannot decide:
///
///  1. **Filter**: the determinant in double with Shewchuk's a-priori error bound
///     ("errboundA", Shewchuk 1997) plus a guard against underflow. Decides almost every
///     call on random data.
///  2. **Expansion**: the determinant computed exactly as a floating-point expansion
///     (Shewchuk-style exact sums and products of doubles). Exact whenever every nonzero
///     input coordinate lies in [2^-256, 2^256]: all intermediate terms then stay in the
///     normal range, so no rounding is lost. This decides exact degeneracies (coplanar and
///     collinear points, coincident meshes).
///  3. **GMP**: rational arithmetic, for inputs outside that range. Always exact.
///
/// Inputs must be finite. Each call costs O(1); stage 1 is about 20 flops.
#include <Eigen/Core>

#include <cstdint>
#include <optional>

namespace kolize::narrowphase {

using Vec3 = Eigen::Vector3d;

/// The stages of a predicate, in the order they are tried.
enum class PredicateStage : std::uint8_t { kFilter = 0, kExpansion = 1, kGmp = 2 };

/// How many predicate calls each stage decided.
struct PredicateStats {
    std::uint64_t orient2d[3] = {0, 0, 0};  ///< indexed by PredicateStage
    std::uint64_t orient3d[3] = {0, 0, 0};  ///< indexed by PredicateStage

    void add(const PredicateStats& other);
    std::uint64_t calls() const;
    /// Calls not decided by the filter (expansion + GMP).
    std::uint64_t fallbacks() const;
};

/// Sign of det[b - a, c - a, d - a] = ((b - a) x (c - a)) . (d - a): +1 when d lies on the
/// side of the plane through a, b, c that the right-handed normal of (a, b, c) points to,
/// -1 on the other side, 0 when the four points are coplanar (or a, b, c are collinear).
/// Exact for finite inputs. `stats` (optional) counts the deciding stage.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
             PredicateStats* stats = nullptr);

/// Sign of det[b - a, c - a] in 2D: +1 when a, b, c turn counterclockwise, -1 clockwise,
/// 0 collinear. Exact for finite inputs.
int orient2d(double ax, double ay, double bx, double by, double cx, double cy,
             PredicateStats* stats = nullptr);

/// One stage on its own, for tests that check the stages agree: kFilter answers only when
/// its error bound allows (else nullopt); kExpansion answers only when the inputs lie in
/// its exact range (else nullopt); kGmp always answers.
std::optional<int> orient3dAt(PredicateStage stage, const Vec3& a, const Vec3& b, const Vec3& c,
                              const Vec3& d);
std::optional<int> orient2dAt(PredicateStage stage, double ax, double ay, double bx, double by,
                              double cx, double cy);

}  // namespace kolize::narrowphase

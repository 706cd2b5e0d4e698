// Named regression tests: queries that once broke the robust method, each with what broke.
// Every contact is checked exactly against the independent reference: hit, and
// toi <= t* <= toi + toi_tolerance in rationals.
#include "ccd_exact.h"  // narrowphase/src: the exact decision on its own
#include "ccd_reference.h"

#include "kolize/narrowphase/ccd.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace {

using namespace kolize::ccd;
namespace ref = kolize::ccd::reference;

enum class Kind { kVertexFace, kEdgeEdge };

/// The robust method and the exact stage in both arithmetics, at several box budgets and
/// hand-off tolerances, all find the contact at exactly t_star, never late.
void expectContactAt(Kind kind, const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                     const mpq_class& t_star) {
    ref::Decision d =
        kind == Kind::kVertexFace ? ref::vertexFace(start, end) : ref::edgeEdge(start, end);
    ASSERT_TRUE(d.hit());
    ASSERT_TRUE(d.atMostEarliest(t_star) && d.atLeastEarliest(t_star)) << "reference disagrees";
    auto check = [&](bool hit, double toi, double tolerance, const std::string& what) {
        SCOPED_TRACE(what);
        ASSERT_TRUE(hit);
        EXPECT_LE(ref::exact(toi), t_star) << "late: toi " << toi;
        EXPECT_GE(ref::exact(toi) + ref::exact(tolerance), t_star) << "too early: toi " << toi;
    };
    for (int max_boxes : {1, 2, 3, 10, 2000}) {
        for (double tolerance : {1e-8, 0.1, 1.0}) {
            RobustSettings s;
            s.max_boxes = max_boxes;
            s.tolerance = tolerance;
            const CcdResult r = kind == Kind::kVertexFace ? vertexFaceRobust({start, end}, s)
                                                          : edgeEdgeRobust({start, end}, s);
            check(r.hit, r.toi, s.toi_tolerance,
                  "robust, max_boxes " + std::to_string(max_boxes) + ", tolerance " +
                      std::to_string(tolerance));
        }
    }
    for (auto arithmetic : {detail::Arithmetic::kFiltered, detail::Arithmetic::kExactOnly}) {
        const detail::ExactContact e =
            kind == Kind::kVertexFace
                ? detail::vertexFaceExact(start, end, 0.0, 1.0, 1e-6, arithmetic)
                : detail::edgeEdgeExact(start, end, 0.0, 1.0, 1e-6, arithmetic);
        check(e.hit, e.toi, 1e-6,
              arithmetic == detail::Arithmetic::kFiltered ? "exact stage, filtered"
                                                          : "exact stage, exact only");
    }
}

// R1 (issue 15): coplanarity 1.5 (t - 1/3)(t - 1), contact at t* = 1/3 strictly inside the
// triangle. The double-interval pass divided the root t = 1 out of the polynomial but kept
// the sign it had at the window's start from before the division, which flipped it: the
// bisection of the root 1/3 ran to the wrong end and tested the vertex at t ~ 1, a miss.
TEST(CcdRegression, R1VertexFaceRootAtOneHidesContactAtOneThird) {
    expectContactAt(
        Kind::kVertexFace, {Vec3(0.25, 0.5, 0.5), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)},
        {Vec3(0.25, 0, -0.5), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)}, mpq_class(1, 3));
}

// R2 (issue 15): the same defect for edge-edge; polynomial 2 (t - 1)(3t - 1)(3t + 1),
// contact at t* = 1/3, reported as no contact.
TEST(CcdRegression, R2EdgeEdgeRootAtOneHidesContactAtOneThird) {
    expectContactAt(
        Kind::kEdgeEdge, {Vec3(0, 0, 1), Vec3(-1, 1, 0), Vec3(-1, 1, -1), Vec3(1, 1, 0)},
        {Vec3(1, -1, -1), Vec3(1, 1, -1), Vec3(0, -1, 0), Vec3(-1, 1, 1)}, mpq_class(1, 3));
}

// R3 (issue 15): roots 9/17 and 1, contact at t* = 9/17. With the flipped sign the root's
// interval shrank towards t = 1, where the vertex (past the face) is inside again: toi
// ~0.999999, late; with max_boxes <= 2 the window started at 0 and toi came out as 0.
TEST(CcdRegression, R3VertexFaceLateToiNearOne) {
    expectContactAt(Kind::kVertexFace,
                    {Vec3(0.5, 1, -1), Vec3(-0.5, 1, 1), Vec3(1.5, 1.5, -1), Vec3(-1, -1, -1.5)},
                    {Vec3(1.5, 2, 1), Vec3(-0.5, 1, 1), Vec3(2.5, 2.5, 1), Vec3(-1.5, 1.5, 1)},
                    mpq_class(9, 17));
}

// Found by kolize-ccd-soak (seed 2, query 80690, near-miss-ulps): edge B's ends are 1 ulp off
// grid points, so the coplanarity polynomial has nearly cancelling coefficients. The interval
// pass's linear root num / den came out as the wide interval [4/15, 3/5] around the contact
// at t* ~ 0.4 (exactly 2702159776422297 / 6755399441055743); exact times were never refined,
// so toi = 4/15 was reported, far too early.
TEST(CcdRegression, IntervalLinearRootWiderThanTheTolerance) {
    expectContactAt(
        Kind::kEdgeEdge,
        {Vec3(0, 0x1p-1, 0x1.8p+0), Vec3(0, 0x1.fffffffffffffp+0, 0x1p+1),
         Vec3(0x1p-1, 0x1.4p+0, 0x1.6000000000001p+0), Vec3(-0x1.8p+0, 0x1.6p+1, 0x1.bp+1)},
        {Vec3(0, 0x1p-1, 0x1.8p+0), Vec3(0, 0x1.fffffffffffffp+0, 0x1p+1),
         Vec3(0x1p-1, 0x1.4p+0, 0x1.6p+0), Vec3(-0x1.8p+0, 0x1.6p+1, 0x1.affffffffffffp+1)},
        mpq_class("2702159776422297/6755399441055743"));
}

}  // namespace

namespace {

/// The irrational contact of ccd_reference_test.cpp: t* = 1/sqrt 2.
const VertexFaceQuery kIrrational{{Vec3(0.25, 0, 1), Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)},
                                  {Vec3(0.25, 2, 1), Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 4)}};

// Issue 15: toi_tolerance <= 0 never returned when the first contact time is irrational (the
// bracket was halved forever); a NaN min_time or max_time silently answered "no contact".
// Both are refused now, with the setting's name in the message.
TEST(CcdRegression, BadSettingsAreRefusedNotHungOrIgnored) {
    for (double bad : {0.0, -1e-6, std::nan("")}) {
        RobustSettings s;
        s.toi_tolerance = bad;
        EXPECT_THROW(vertexFaceRobust(kIrrational, s), std::invalid_argument) << bad;
        EXPECT_THROW(edgeEdgeRobust({kIrrational.start, kIrrational.end}, s),
                     std::invalid_argument);
    }
    for (int which = 0; which < 2; ++which) {
        RobustSettings s;
        (which ? s.max_time : s.min_time) = std::nan("");
        try {
            vertexFaceRobust(kIrrational, s);
            ADD_FAILURE() << "NaN time bound accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("min_time"), std::string::npos) << e.what();
        }
    }
    VertexFaceQuery nan_point = kIrrational;
    nan_point.end[2].y() = std::nan("");
    EXPECT_THROW(vertexFaceRobust(nan_point), std::invalid_argument);
    nan_point.end[2].y() = INFINITY;
    EXPECT_THROW(vertexFaceRobust(nan_point), std::invalid_argument);
}

// The smallest tolerances still return, and still bracket the irrational contact exactly:
// below 2^-52 the tolerance acts as 2^-52 (toi is a double).
TEST(CcdRegression, TinyToiToleranceBracketsAnIrrationalContact) {
    for (double tolerance : {1e-300, 0x1p-52, 1e-12, 1e-6, double(INFINITY)}) {
        for (auto arithmetic : {RobustArithmetic::kCertified, RobustArithmetic::kSearchThenExact,
                                RobustArithmetic::kExactOnly}) {
            RobustSettings s;
            s.toi_tolerance = tolerance;
            s.arithmetic = arithmetic;
            const CcdResult r = vertexFaceRobust(kIrrational, s);
            ref::Decision d = ref::vertexFace(kIrrational.start, kIrrational.end);
            ASSERT_TRUE(r.hit);
            EXPECT_TRUE(d.atMostEarliest(ref::exact(r.toi))) << tolerance;
            if (std::isfinite(tolerance)) {
                EXPECT_TRUE(
                    d.atLeastEarliest(ref::exact(r.toi) + ref::exact(std::max(tolerance, 0x1p-52))))
                    << tolerance << " toi " << r.toi;
            }
        }
    }
}

TEST(CcdRegression, EmptyAndClampedTimeRanges) {
    RobustSettings s;
    s.min_time = 0.8;
    s.max_time = 0.7;  // empty
    EXPECT_FALSE(vertexFaceRobust(kIrrational, s).hit);
    s.min_time = -5;
    s.max_time = 7;  // clamped to [0, 1]
    const CcdResult r = vertexFaceRobust(kIrrational, s);
    EXPECT_TRUE(r.hit);
    EXPECT_NEAR(r.toi, std::sqrt(0.5), 1e-6);
}

}  // namespace

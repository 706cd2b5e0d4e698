// The exact reference (ccd_reference.h) checked on its own: against hand-derived contact
// times and against the data set's ground truth, which Wang et al. computed independently
// (Mathematica, symbolic solution of F(t, u, v) = 0).
#include "ccd_reference.h"

#include "kolize/narrowphase/ccd_dataset.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using namespace kolize::ccd;
namespace ref = kolize::ccd::reference;

/// The earliest contact is exactly t.
void expectEarliest(ref::Decision d, const mpq_class& t) {
    ASSERT_TRUE(d.hit());
    EXPECT_TRUE(d.atMostEarliest(t));
    EXPECT_TRUE(d.atLeastEarliest(t));
}

TEST(CcdReference, GenericCrossingAndMiss) {
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    expectEarliest(ref::vertexFace({Vec3(0.25, 0.25, 1), a, b, c}, {Vec3(0.25, 0.25, -2), a, b, c}),
                   mpq_class(1, 3));
    EXPECT_FALSE(ref::vertexFace({Vec3(2, 2, 1), a, b, c}, {Vec3(2, 2, -1), a, b, c}).hit());
    // The time range is honoured: the crossing at 1/3 lies outside [1/2, 1].
    EXPECT_FALSE(ref::vertexFace({Vec3(0.25, 0.25, 1), a, b, c}, {Vec3(0.25, 0.25, -2), a, b, c},
                                 mpq_class(1, 2), 1)
                     .hit());
}

TEST(CcdReference, IrrationalContactTime) {
    // The triangle turns about the x axis (c rises from (0, 4, 0) to (0, 4, 4)), so its
    // plane is z = t y; the vertex runs (0.25, 2t, 1), coplanar when 2 t^2 = 1: t* = 1/sqrt 2,
    // inside the triangle (x = 0.25, y = sqrt 2).
    const Vec3 a(0, 0, 0), b(4, 0, 0);
    ref::Decision d = ref::vertexFace({Vec3(0.25, 0, 1), a, b, Vec3(0, 4, 0)},
                                      {Vec3(0.25, 2, 1), a, b, Vec3(0, 4, 4)});
    ASSERT_TRUE(d.hit());
    ASSERT_EQ(d.contacts.size(), 1u);
    EXPECT_FALSE(d.contacts[0].rational);
    EXPECT_TRUE(d.atMostEarliest(mpq_class(70710678, 100000000)));
    EXPECT_FALSE(d.atMostEarliest(mpq_class(70710679, 100000000)));
    EXPECT_TRUE(d.atLeastEarliest(mpq_class(70710679, 100000000)));
    EXPECT_FALSE(d.atLeastEarliest(mpq_class(70710678, 100000000)));
    EXPECT_NEAR(d.earliestApproximation(), std::sqrt(0.5), 1e-9);
    // Moved beyond the hypotenuse (x = 3: x + y > 4) the same root is no contact.
    EXPECT_FALSE(
        ref::vertexFace({Vec3(3, 0, 1), a, b, Vec3(0, 4, 0)}, {Vec3(3, 2, 1), a, b, Vec3(0, 4, 4)})
            .hit());
}

TEST(CcdReference, CoplanarMotion) {
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    // Slides in the plane and enters at x = 0 (t = 1/2).
    expectEarliest(ref::vertexFace({Vec3(-1, 0.25, 0), a, b, c}, {Vec3(1, 0.25, 0), a, b, c}),
                   mpq_class(1, 2));
    EXPECT_FALSE(ref::vertexFace({Vec3(-1, 2, 0), a, b, c}, {Vec3(1, 2, 0), a, b, c}).hit());
    // Grazes the corner a only (the line x + y = 0), at t = 1/2.
    expectEarliest(ref::vertexFace({Vec3(-1, 1, 0), a, b, c}, {Vec3(1, -1, 0), a, b, c}),
                   mpq_class(1, 2));
    // Collinear edges meeting end to end at t = 2/3.
    const Vec3 a0(0, 0, 0), a1(1, 0, 0);
    expectEarliest(ref::edgeEdge({a0, a1, Vec3(2, 0, 0), Vec3(3, 0, 0)},
                                 {a0, a1, Vec3(0.5, 0, 0), Vec3(1.5, 0, 0)}),
                   mpq_class(2, 3));
}

TEST(CcdReference, TangentialDoubleRootAndHourglass) {
    // Coplanarity 2 (t - 1/2)^2: B's end touches A at the origin at t = 1/2.
    expectEarliest(
        ref::edgeEdge({Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -0.5, 1), Vec3(0, 0, -0.5)},
                      {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 0.5, 1), Vec3(0, 0, 0.5)}),
        mpq_class(1, 2));
    EXPECT_FALSE(
        ref::edgeEdge({Vec3(0x1p-40, 0, 0), Vec3(1, 0, 0), Vec3(0, -0.5, 1), Vec3(0, 0, -0.5)},
                      {Vec3(0x1p-40, 0, 0), Vec3(1, 0, 0), Vec3(0, 0.5, 1), Vec3(0, 0, 0.5)})
            .hit());
    expectEarliest(ref::edgeEdge({Vec3(-1, 0, -1), Vec3(1, 0, -1), Vec3(0, -1, 0), Vec3(0, 1, 0)},
                                 {Vec3(1, 0, 1), Vec3(-1, 0, 1), Vec3(0, -1, 0), Vec3(0, 1, 0)}),
                   mpq_class(1, 2));
}

// Issue 15's three queries, with the contact times the issue derived by hand.
TEST(CcdReference, IssueFifteenQueries) {
    expectEarliest(
        ref::vertexFace({Vec3(0.25, 0.5, 0.5), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)},
                        {Vec3(0.25, 0, -0.5), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)}),
        mpq_class(1, 3));
    expectEarliest(ref::edgeEdge({Vec3(0, 0, 1), Vec3(-1, 1, 0), Vec3(-1, 1, -1), Vec3(1, 1, 0)},
                                 {Vec3(1, -1, -1), Vec3(1, 1, -1), Vec3(0, -1, 0), Vec3(-1, 1, 1)}),
                   mpq_class(1, 3));
    expectEarliest(ref::vertexFace(
                       {Vec3(0.5, 1, -1), Vec3(-0.5, 1, 1), Vec3(1.5, 1.5, -1), Vec3(-1, -1, -1.5)},
                       {Vec3(1.5, 2, 1), Vec3(-0.5, 1, 1), Vec3(2.5, 2.5, 1), Vec3(-1.5, 1.5, 1)}),
                   mpq_class(9, 17));
}

TEST(CcdReference, AgreesWithTheDataSetGroundTruth) {
    const auto sets = readQueryFolder(KOLIZE_CCD_DATA_DIR);
    size_t checked = 0;
    for (const auto& set : sets) {
        for (size_t i = 0; i < set.queries.size(); ++i) {
            const LabeledQuery& q = set.queries[i];
            const ref::Decision d = set.kind == QueryKind::kVertexFace
                                        ? ref::vertexFace(q.start, q.end)
                                        : ref::edgeEdge(q.start, q.end);
            EXPECT_EQ(d.hit(), q.collides) << set.scene << " " << kindName(set.kind) << " #" << i;
            ++checked;
        }
    }
    EXPECT_EQ(checked, 4324u);
}

}  // namespace

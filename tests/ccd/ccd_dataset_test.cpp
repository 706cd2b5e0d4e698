// The robust CCD method over the whole Sample-Queries copy: zero false negatives is a hard
// requirement, at most 1% false positives the issue's target (the method is exact: 0).
#include "kolize/narrowphase/ccd_dataset.h"

#include "ccd_exact.h"  // narrowphase/src: the exact decision on its own

#include <gtest/gtest.h>

#include <gmpxx.h>

#include <cstdio>
#include <cstring>
#include <limits>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

namespace {

using namespace kolize::ccd;

TEST(CcdDataset, ReaderLoadsEveryQueryWithItsGroundTruth) {
    const auto sets = readQueryFolder(KOLIZE_CCD_DATA_DIR);
    size_t queries = 0, positives = 0;
    for (const auto& set : sets) {
        queries += set.queries.size();
        for (const auto& q : set.queries) {
            positives += q.collides;
        }
    }
    // Counts documented in assets/ccd-data/Sample-Queries/README.md.
    EXPECT_EQ(sets.size(), 18u);
    EXPECT_EQ(queries, 4324u);
    EXPECT_EQ(positives, 425u);
}

TEST(CcdDataset, ReaderRefusesInexactCoordinates) {
    const auto path = std::filesystem::temp_directory_path() / "kolize_ccd_bad.csv";
    {
        std::ofstream out(path);
        for (int i = 0; i < 8; ++i) {
            out << "1,3,0,1,0,1,0\n";  // 1/3 is not a double
        }
    }
    EXPECT_THROW(readQueryCsv(path.string()), std::runtime_error);
    std::filesystem::remove(path);
}

/// Writes 8 copies of `row` (one query) and reads them back.
std::vector<LabeledQuery> readRows(const std::string& row) {
    const auto path = std::filesystem::temp_directory_path() / "kolize_ccd_rows.csv";
    {
        std::ofstream out(path);
        for (int i = 0; i < 8; ++i) {
            out << row << "\n";
        }
    }
    struct Remove {
        std::filesystem::path p;
        ~Remove() { std::filesystem::remove(p); }
    } remove{path};
    return readQueryCsv(path.string());
}

// Issue 15: denominators above 2^1023 (coordinates below about 2^-970) did not fit a double
// and were refused with a misleading message. They are big integers now.
TEST(CcdDataset, ReaderParsesArbitraryExactDenominators) {
    const std::string two_1074 = mpz_class(mpz_class(1) << 1074).get_str();
    // 3 / 2^1074 = 3 times the smallest subnormal; 6 / 4 = 3 / 2 (not in lowest terms).
    const auto q = readRows("3," + two_1074 + ",6,4,-0,1,1");
    ASSERT_EQ(q.size(), 1u);
    EXPECT_EQ(q[0].start[0].x(), 3 * std::numeric_limits<double>::denorm_min());
    EXPECT_EQ(q[0].start[0].y(), 1.5);
    EXPECT_EQ(q[0].start[0].z(), 0.0);
    EXPECT_TRUE(q[0].collides);
    // Below the smallest subnormal, a third, a zero or negative denominator, not a number.
    for (const std::string& bad : std::vector<std::string>{
             "1," + two_1074 + "0,0,1,0,1,0", "1,3,0,1,0,1,0", "1,0,0,1,0,1,0", "1,-2,0,1,0,1,0",
             "1,2,x,1,0,1,0", "1,2,,1,0,1,0", "1,2,0,1,0,1,2"}) {
        try {
            readRows(bad);
            ADD_FAILURE() << "accepted " << bad.substr(0, 40);
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find(":1:"), std::string::npos) << e.what();
        }
    }
}

TEST(CcdDataset, WriterRoundTripsEveryDoubleExactly) {
    std::mt19937_64 rng(7);
    std::vector<LabeledQuery> queries(50);
    for (size_t n = 0; n < queries.size(); ++n) {
        for (int i = 0; i < 4; ++i) {
            for (int k = 0; k < 3; ++k) {
                double x;
                do {  // any finite double: subnormals, huge values, negative zero
                    const uint64_t bits = rng();
                    std::memcpy(&x, &bits, sizeof x);
                } while (!std::isfinite(x));
                queries[n].start[i][k] = x;
                queries[n].end[i][k] = n % 3 == 0 ? std::numeric_limits<double>::denorm_min() : -x;
            }
        }
        queries[n].collides = n % 2;
    }
    const auto path = std::filesystem::temp_directory_path() / "kolize_ccd_roundtrip.csv";
    writeQueryCsv(path.string(), queries);
    const auto back = readQueryCsv(path.string());
    std::filesystem::remove(path);
    ASSERT_EQ(back.size(), queries.size());
    for (size_t n = 0; n < queries.size(); ++n) {
        EXPECT_EQ(back[n].start, queries[n].start) << n;
        EXPECT_EQ(back[n].end, queries[n].end) << n;
        EXPECT_EQ(back[n].collides, queries[n].collides) << n;
    }
}

TEST(CcdDataset, RobustHasNoFalseNegativesAndAtMostOnePercentFalsePositives) {
    const auto sets = readQueryFolder(KOLIZE_CCD_DATA_DIR);
    const RobustSettings settings;
    size_t negatives = 0, false_positives = 0;
    for (const auto& set : sets) {
        for (size_t i = 0; i < set.queries.size(); ++i) {
            const LabeledQuery& q = set.queries[i];
            const CcdResult r = robustQuery(set.kind, q, settings);
            EXPECT_TRUE(r.hit || !q.collides)
                << "false negative: " << set.scene << " " << kindName(set.kind) << " #" << i;
            if (r.hit) {
                EXPECT_GE(r.toi, 0.0);
                EXPECT_LE(r.toi, 1.0);
            }
            if (r.hit && !q.collides) {
                ++false_positives;
                ADD_FAILURE() << "false positive (the decision is meant to be exact): " << set.scene
                              << " " << kindName(set.kind) << " #" << i;
            }
            negatives += !q.collides;
        }
    }
    // The issue's target. The method is exact, so the measured count is 0 (it was 210 of
    // 3899, 5.4%, when near-contacts ~1e-17 apart were accepted within a 1e-6 tolerance).
    EXPECT_LE(false_positives * 100, negatives) << false_positives << " of " << negatives;
}

// The interval filter must never change an answer: the exact-only arithmetic agrees on
// every query, and the two-stage robust method (floating-point search, then the exact
// decision from the search's first unexcluded time) finds the same earliest contact as the
// exact decision over the whole step. A search that excluded a box holding the first
// contact would show up here as a later toi.
TEST(CcdDataset, FilteredExactOnlyAndTwoStageDecisionsAgree) {
    const auto sets = readQueryFolder(KOLIZE_CCD_DATA_DIR);
    const RobustSettings settings;
    const double slack = settings.toi_tolerance + 1e-15;
    for (const auto& set : sets) {
        const bool vf = set.kind == QueryKind::kVertexFace;
        for (size_t i = 0; i < set.queries.size(); ++i) {
            SCOPED_TRACE(set.scene + " " + kindName(set.kind) + " #" + std::to_string(i));
            const LabeledQuery& q = set.queries[i];
            auto exact = [&](detail::Arithmetic arithmetic) {
                return vf ? detail::vertexFaceExact(q.start, q.end, 0.0, 1.0,
                                                    settings.toi_tolerance, arithmetic)
                          : detail::edgeEdgeExact(q.start, q.end, 0.0, 1.0, settings.toi_tolerance,
                                                  arithmetic);
            };
            const detail::ExactContact filtered = exact(detail::Arithmetic::kFiltered);
            const detail::ExactContact exact_only = exact(detail::Arithmetic::kExactOnly);
            const CcdResult two_stage = robustQuery(set.kind, q, settings);
            EXPECT_EQ(filtered.hit, q.collides);
            ASSERT_EQ(exact_only.hit, filtered.hit);
            ASSERT_EQ(two_stage.hit, filtered.hit);
            if (filtered.hit) {
                EXPECT_NEAR(exact_only.toi, filtered.toi, slack);
                EXPECT_NEAR(two_stage.toi, filtered.toi, slack);
            }
        }
    }
}

// The same agreement on random queries built to be degenerate: coordinates on a coarse
// grid of halves (so coplanar motion, parallel edges, shared points and exact touches are
// common and the filter often meets exact zeros), some nudged by a few units in the last
// place (near-misses the filter cannot resolve).
TEST(CcdRandomDegenerate, FilteredExactOnlyAndTwoStageDecisionsAgree) {
    const unsigned seed = 5;
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> grid(-4, 4), nudge(-3, 3), coin(0, 3);
    auto coordinate = [&] {
        double x = 0.5 * grid(rng);
        if (coin(rng) == 0) {
            x += nudge(rng) * 0x1p-52;
        }
        return x;
    };
    auto point = [&] { return Vec3(coordinate(), coordinate(), coordinate()); };
    const RobustSettings settings;
    const double slack = settings.toi_tolerance + 1e-15;
    int hits = 0;
    const int trials = 3000;
    for (int trial = 0; trial < trials; ++trial) {
        SCOPED_TRACE("seed " + std::to_string(seed) + ", trial " + std::to_string(trial));
        LabeledQuery q;
        for (int i = 0; i < 4; ++i) {
            q.start[i] = point();
            // Often a vertex keeps still or shares its motion with the previous one.
            const int motion = coin(rng);
            q.end[i] = motion == 0            ? q.start[i]
                       : motion == 1 && i > 0 ? q.start[i] + (q.end[i - 1] - q.start[i - 1])
                                              : point();
        }
        const QueryKind kind = trial % 2 ? QueryKind::kEdgeEdge : QueryKind::kVertexFace;
        auto exact = [&](detail::Arithmetic arithmetic) {
            return kind == QueryKind::kVertexFace
                       ? detail::vertexFaceExact(q.start, q.end, 0.0, 1.0, settings.toi_tolerance,
                                                 arithmetic)
                       : detail::edgeEdgeExact(q.start, q.end, 0.0, 1.0, settings.toi_tolerance,
                                               arithmetic);
        };
        const detail::ExactContact filtered = exact(detail::Arithmetic::kFiltered);
        const detail::ExactContact exact_only = exact(detail::Arithmetic::kExactOnly);
        const CcdResult two_stage = robustQuery(kind, q, settings);
        ASSERT_EQ(exact_only.hit, filtered.hit);
        ASSERT_EQ(two_stage.hit, filtered.hit);
        if (filtered.hit) {
            EXPECT_NEAR(exact_only.toi, filtered.toi, slack);
            EXPECT_NEAR(two_stage.toi, filtered.toi, slack);
        }
        hits += filtered.hit;
    }
    EXPECT_GT(hits, trials / 10) << "seed " << seed;
    EXPECT_LT(hits, trials * 9 / 10) << "seed " << seed;
}

}  // namespace

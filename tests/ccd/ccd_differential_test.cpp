// The robust method in every arithmetic mode against the independent exact reference, on a
// slice of the seeded degenerate families (ccd_families.h); kolize-ccd-soak runs the same
// check on a million queries (scripts/ccd-soak.sh).
#include "ccd_families.h"

#include <gtest/gtest.h>

#include <string>

namespace {

using namespace kolize::ccd;

/// Queries per family in the slice: a few seconds in Release, under a minute with ASan.
constexpr int kQueriesPerFamily = 150;

TEST(CcdDifferential, EveryModeAgreesWithTheReferenceOnEveryFamily) {
    const uint64_t seed = 15;
    const auto& names = families::familyNames();
    int total_hits = 0, total = 0;
    for (int family = 0; family < static_cast<int>(names.size()); ++family) {
        int hits = 0;
        for (int i = 0; i < kQueriesPerFamily; ++i) {
            const uint64_t index = static_cast<uint64_t>(family) * kQueriesPerFamily + i;
            const families::Query q = families::generate(seed, index, family);
            reference::Decision d = families::decide(q);
            hits += d.hit();
            for (const families::Mode& mode : families::modes()) {
                const auto failure = families::check(q, mode, d);
                if (failure) {
                    ADD_FAILURE() << "seed " << seed << " query " << index << " family "
                                  << names[family] << " mode " << mode.name << ": " << *failure
                                  << "\nquery:  " << families::describe(q)
                                  << "\nshrunk: " << families::describe(families::shrink(q, mode))
                                  << "\n(rerun: kolize-ccd-soak --seed " << seed << " --first "
                                  << index << " --queries 1 --family " << family << ")";
                }
            }
        }
        // Each family must produce contacts and misses, or it tests little.
        EXPECT_GT(hits, 0) << names[family];
        EXPECT_LT(hits, kQueriesPerFamily) << names[family];
        total_hits += hits;
        total += kQueriesPerFamily;
    }
    EXPECT_GT(total_hits * 10, total) << "under 10% contacts";
    EXPECT_LT(total_hits * 10, total * 9) << "over 90% contacts";
}

}  // namespace

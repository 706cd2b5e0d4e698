// The differential fuzzer's slice for CI: every kolize broadphase, a few seeded programs
// (both filter policies), checked against the fuzzer's model after every pair search and
// query. A failure prints the shrunk program as code. scripts/soak.sh runs the long version.

#include "broadphase_fuzz.h"

#include <kolize/kolize.h>

#include <gtest/gtest.h>

namespace kolize::fuzz {
namespace {

class Fuzz : public ::testing::TestWithParam<std::string> {};

TEST_P(Fuzz, RandomProgramsMatchTheModel) {
    const std::string name = GetParam();
    Result total;
    // Both filter policies with Bullet's hashed cache, and the default policy with a
    // MergedPairCache (the pair search hands it changes without lookups).
    for (const auto& [filters, cache] :
         {std::pair{FilterEvaluation::WhenAdded, PairCacheChoice::Hashed},
          std::pair{FilterEvaluation::EveryFrame, PairCacheChoice::Hashed},
          std::pair{FilterEvaluation::WhenAdded, PairCacheChoice::Merged}}) {
        BroadphaseSettings settings;
        settings.filters = filters;
        settings.ownPairCache = cache;
        SCOPED_TRACE(cache == PairCacheChoice::Merged ? "merged pair cache" : "hashed pair cache");
        for (std::uint32_t seed = 1; seed <= 3; ++seed) {
            const std::vector<Op> program = randomProgram(seed, 8000);
            const Result result = run(name, program, settings);
            if (result.failed) {
                const std::vector<Op> minimal = shrink(name, program, settings);
                FAIL() << "seed " << seed << ": " << result.failure << "\nshrunk to "
                       << minimal.size() << " operations:\n"
                       << asCode(minimal) << run(name, minimal, settings).failure;
            }
            total.searches += result.searches;
            total.queries += result.queries;
            total.truePairs += result.truePairs;
            total.queryHits += result.queryHits;
        }
    }
    // The programs mean something: pairs and query hits happened.
    EXPECT_GT(total.searches, 4000u);
    EXPECT_GT(total.queries, 7000u);
    EXPECT_GT(total.truePairs, 30000u);
    EXPECT_GT(total.queryHits, 5000u);
}

// The model itself catches a wrong answer: a broadphase that reports supersets (dbvt) must
// fail against it, so a passing kolize run is not a check that cannot fail.
TEST(FuzzModel, CatchesABroadphaseThatReportsExtraPairs) {
    const Result result = run("dbvt", randomProgram(1, 4000));
    EXPECT_TRUE(result.failed);
    EXPECT_FALSE(shrink("dbvt", randomProgram(1, 4000)).empty());
}

INSTANTIATE_TEST_SUITE_P(ExactBroadphases, Fuzz, ::testing::ValuesIn([] {
                             std::vector<std::string> names;
                             for (const std::string& name : broadphaseNames()) {
                                 if (isExactBroadphase(name)) {
                                     names.push_back(name);
                                 }
                             }
                             return names;
                         }()),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                             std::string name = param.param;
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

}  // namespace
}  // namespace kolize::fuzz

// The cell cores (grid, spatial tree, spatial hash) in 2D and 3D against the brute-force
// truth, under every sizing rule, with validate() after every operation; and the AVL and
// hash cell indexes on their own.

#include "core_kit.h"

#include <kolize/broadphase/cell_grid.h>

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

namespace kolize {
namespace {

using testkit::CoreScenario;
using testkit::CoreScenarioResult;

struct SizingCase {
    const char* name;
    CellGridSettings settings;
};

std::vector<SizingCase> sizingCases() {
    std::vector<SizingCase> cases;
    cases.push_back({"automatic", {}});
    CellGridSettings tiny;
    tiny.cellSize = 0.7;  // ordinary boxes cover many cells; big ones overflow
    cases.push_back({"small-fixed-cells", tiny});
    CellGridSettings coarse;
    coarse.cellSize = 100;  // everything in a few cells
    cases.push_back({"coarse-fixed-cells", coarse});
    CellGridSettings overflowAll;
    overflowAll.maxCellsPerObject = 1;  // anything covering two cells overflows
    cases.push_back({"single-cell-limit", overflowAll});
    CellGridSettings thesis;
    thesis.cellsPerAxis = 17;  // the thesis's equal-memory configuration
    cases.push_back({"thesis-17-per-axis", thesis});
    CellGridSettings region;
    region.cellSize = 3;
    region.regionMin = {-10, -10, -10};
    region.regionMax = {10, 10, 10};  // dense grid: most objects stick out or are outside
    cases.push_back({"small-fixed-region", region});
    CellGridSettings eager;
    eager.rechooseFactor = 1.05;  // re-chooses often
    cases.push_back({"eager-rechoosing", eager});
    return cases;
}

template <class Core, int D, class Scalar>
void runAllSizings(std::uint64_t seed) {
    for (const SizingCase& sizing : sizingCases()) {
        SCOPED_TRACE(sizing.name);
        Core core(sizing.settings);
        CoreScenario scenario;
        scenario.seed = seed;
        const CoreScenarioResult result = testkit::runCoreScenario<D, Scalar>(core, scenario);
        testkit::expectMeaningful(result);
        if (::testing::Test::HasFailure()) {
            return;
        }
    }
}

TEST(CellGrid, Grid3MatchesTheOracleUnderEverySizing) {
    runAllSizings<UniformGrid<3, float>, 3, float>(11);
}
TEST(CellGrid, Grid2MatchesTheOracleUnderEverySizing) {
    runAllSizings<UniformGrid<2, double>, 2, double>(12);
}
TEST(CellGrid, SpatialTree3MatchesTheOracleUnderEverySizing) {
    runAllSizings<SpatialTree<3, float>, 3, float>(13);
}
TEST(CellGrid, SpatialTree2MatchesTheOracleUnderEverySizing) {
    runAllSizings<SpatialTree<2, double>, 2, double>(14);
}
TEST(CellGrid, SpatialHash3MatchesTheOracleUnderEverySizing) {
    runAllSizings<SpatialHash<3, float>, 3, float>(15);
}
TEST(CellGrid, SpatialHash2MatchesTheOracleUnderEverySizing) {
    runAllSizings<SpatialHash<2, double>, 2, double>(16);
}

TEST(CellGrid, DenseScenesWithManyPairsPerCellMatchTheOracle) {
    CoreScenario crowded;
    crowded.seed = 21;
    crowded.world = 6;  // 150 boxes of size up to 8 in a 12-wide world: most overlap
    crowded.operations = 500;
    UniformGrid<3, float> grid;
    SpatialTree<3, float> tree;
    SpatialHash<3, float> hash;
    testkit::expectMeaningful(testkit::runCoreScenario<3, float>(grid, crowded), 3000);
    testkit::expectMeaningful(testkit::runCoreScenario<3, float>(tree, crowded), 3000);
    testkit::expectMeaningful(testkit::runCoreScenario<3, float>(hash, crowded), 3000);
}

TEST(CellGrid, CellSizeIsReChosenWhenThePopulationDrifts) {
    SpatialHash<3, double> hash;
    std::vector<Aabb<3, double>> boxes;
    std::size_t frames = 0;
    auto frame = [&] {
        hash.maintain();
        hash.findCandidates([](ObjectId, ObjectId) {});
        ++frames;
    };
    // 100 unit boxes, then they grow tenfold: the cell size must follow.
    for (ObjectId id = 0; id < 100; ++id) {
        const double x = 3.0 * id;
        hash.insert(id, {{x, 0, 0}, {x + 1, 1, 1}});
    }
    frame();
    const double first = hash.stats().cellSize;
    EXPECT_NEAR(first, 2.0, 1e-9);  // 2 x the median extent
    for (int f = 0; f < 10; ++f) {
        for (ObjectId id = 0; id < 100; ++id) {
            const double x = 30.0 * id;
            hash.update(id, {{x, 0, 0}, {x + 10, 10, 10}});
        }
        frame();
    }
    EXPECT_NEAR(hash.stats().cellSize, 20.0, 1e-9);
    EXPECT_EQ(hash.stats().rechoices, 2u);
    hash.validate();
}

TEST(CellGrid, DenseGridKeepsObjectsThatLeaveTheRegionAndReChoosesIt) {
    UniformGrid<3, double> grid;
    for (ObjectId id = 0; id < 200; ++id) {
        const double x = (id % 10) * 2.0, y = (id / 10 % 10) * 2.0, z = (id / 100) * 2.0;
        grid.insert(id, {{x, y, z}, {x + 1, y + 1, z + 1}});
    }
    grid.findCandidates([](ObjectId, ObjectId) {});
    // Everyone flies 1e6 away, in pairs that touch.
    std::size_t pairs = 0;
    for (int f = 0; f < 10; ++f) {
        for (ObjectId id = 0; id < 200; ++id) {
            const double x = 1e6 + 10.0 * (id / 2) + 0.5 * (id % 2);
            grid.update(id, {{x, 0, 0}, {x + 1, 1, 1}});
        }
        pairs = 0;
        grid.maintain();
        grid.findCandidates([&](ObjectId a, ObjectId b) { pairs += (a / 2 == b / 2) ? 1 : 0; });
        grid.validate();
    }
    EXPECT_EQ(pairs, 100u);
    EXPECT_GE(grid.stats().rechoices, 2u);
    EXPECT_EQ(grid.stats().overflow, 0u) << "after re-choosing, the region holds them again";
}

TEST(AvlIndex, StaysOrderedAndBalancedUnderRandomInsertsAndRemovals) {
    AvlIndex<3> tree;
    std::map<CellKey<3>, std::uint32_t, bool (*)(const CellKey<3>&, const CellKey<3>&)> model(
        keyLess<3>);
    std::mt19937_64 random(5);
    std::uniform_int_distribution<std::int64_t> coordinate(-6, 6);
    for (int step = 0; step < 4000; ++step) {
        const CellKey<3> key{coordinate(random), coordinate(random), coordinate(random) * 1000003};
        const auto found = model.find(key);
        if (found == model.end()) {
            const std::uint32_t handle = tree.acquire(key);
            tree.record(handle).count = 1;
            model.emplace(key, handle);
        } else {
            ASSERT_EQ(tree.find(key), found->second);
            tree.record(found->second).count = 0;
            tree.release(found->second);
            model.erase(found);
        }
        ASSERT_NO_THROW(tree.validate()) << "step " << step;
        ASSERT_EQ(tree.liveCount(), model.size());
        // Handles stay valid while their cell lives (no payload moves between nodes).
        for (const auto& [k, handle] : model) {
            ASSERT_EQ(tree.key(handle), k);
        }
        const double n = double(model.size());
        ASSERT_LE(tree.height(), 1.45 * std::log2(n + 2)) << "step " << step;
    }
    EXPECT_GT(model.size(), 200u);
}

TEST(HashIndex, FindsEveryLiveCellUnderRandomInsertsAndRemovals) {
    HashIndex<2> hash;
    std::map<CellKey<2>, std::uint32_t> model;
    std::mt19937_64 random(6);
    std::uniform_int_distribution<std::int64_t> coordinate(-20, 20);
    for (int step = 0; step < 6000; ++step) {
        // Huge and negative coordinates hash too.
        const CellKey<2> key{coordinate(random) * (std::int64_t(1) << 40), coordinate(random)};
        const auto found = model.find(key);
        if (found == model.end()) {
            const std::uint32_t handle = hash.acquire(key);
            hash.record(handle).count = 1;
            model.emplace(key, handle);
        } else {
            ASSERT_EQ(hash.find(key), found->second);
            hash.record(found->second).count = 0;
            hash.release(found->second);
            model.erase(found);
        }
        if (step % 10 == 0) {
            ASSERT_NO_THROW(hash.validate()) << "step " << step;
        }
    }
    ASSERT_NO_THROW(hash.validate());
    for (const auto& [key, handle] : model) {
        EXPECT_EQ(hash.find(key), handle);
    }
    EXPECT_GT(model.size(), 300u);
}

TEST(CellGrid, RejectsSettingsThatCannotWork) {
    using Hash = SpatialHash<3, float>;
    using Grid = UniformGrid<3, float>;
    CellGridSettings negative;
    negative.cellSize = -1;
    EXPECT_THROW(Hash{negative}, std::invalid_argument);
    CellGridSettings infinite;
    infinite.cellSize = HUGE_VAL;
    EXPECT_THROW(Hash{infinite}, std::invalid_argument);
    CellGridSettings noCells;
    noCells.maxCellsPerObject = 0;
    EXPECT_THROW(Hash{noCells}, std::invalid_argument);
    CellGridSettings tooMany;
    tooMany.maxCells = 1e12;
    EXPECT_THROW(Grid{tooMany}, std::invalid_argument);
}

}  // namespace
}  // namespace kolize

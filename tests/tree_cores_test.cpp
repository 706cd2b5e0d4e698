// The segment-tree cores (SegmentTreeSet, RangeTree) in 2D and 3D, below the adapter:
// seeded random operations with validate() after each one, candidate pairs and queries
// compared with the BruteForce oracle through the exact tests, and the candidate set
// compared with its definition (cell boxes overlapping on all axes).

#include <kolize/broadphase/brute_force.h>
#include <kolize/broadphase/range_tree.h>
#include <kolize/broadphase/segment_tree_set.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace kolize {
namespace {

using Pair = std::pair<ObjectId, ObjectId>;

Pair ordered(ObjectId a, ObjectId b) {
    return a < b ? Pair{a, b} : Pair{b, a};
}

/// Collects candidates, failing on a pair reported twice or an object paired with itself.
template <class Core>
std::set<Pair> candidatesOf(Core& core) {
    std::set<Pair> out;
    core.findCandidates([&](ObjectId a, ObjectId b) {
        EXPECT_NE(a, b) << "object paired with itself";
        EXPECT_TRUE(out.insert(ordered(a, b)).second)
            << "pair (" << a << ", " << b << ") reported twice";
    });
    return out;
}

template <int D>
bool cellsOverlap(const CellBox<D>& a, const CellBox<D>& b) {
    for (int axis = 0; axis < D; ++axis) {
        if (a.lo[axis] > b.hi[axis] || b.lo[axis] > a.hi[axis]) {
            return false;
        }
    }
    return true;
}

struct SceneCounts {
    std::size_t frames = 0;
    std::size_t exactPairs = 0;
    std::size_t candidates = 0;
    double objectsWithPartner = 0;
    std::size_t queryHits = 0;
    std::size_t queries = 0;
    std::size_t rayHits = 0;
    std::size_t rays = 0;
};

/// One seeded random scene driven into `Core` and into BruteForce side by side.
template <class Core, int D>
class RandomCoreScene {
  public:
    using Box = Aabb<D, float>;

    RandomCoreScene(std::uint32_t seed, const typename Core::Settings& settings)
        : random_(seed), core_(settings) {}

    void run(int frames, int initialObjects, int operationsPerFrame) {
        for (int i = 0; i < initialObjects && !::testing::Test::HasFailure(); ++i) {
            create();
            check();
        }
        for (int frame = 0; frame < frames && !::testing::Test::HasFailure(); ++frame) {
            for (int op = 0; op < operationsPerFrame && !::testing::Test::HasFailure(); ++op) {
                randomOperation();
                check();
            }
            checkFrame();
        }
    }

    const SceneCounts& counts() const { return counts_; }
    Core& core() { return core_; }

  private:
    double uniform(double lo, double hi) {
        return std::uniform_real_distribution<double>(lo, hi)(random_);
    }
    int pick(int count) { return std::uniform_int_distribution<int>(0, count - 1)(random_); }

    Box randomBox() {
        const int kind = pick(100);
        Box box;
        std::array<double, D> centre, half;
        for (int axis = 0; axis < D; ++axis) {
            centre[axis] = uniform(-40, 40);
            half[axis] = uniform(0.2, 4);
        }
        if (kind < 8 && !ids_.empty()) {  // touching an existing box face to face
            box = boxes_[ids_[pick(int(ids_.size()))]];
            const int axis = pick(D);
            box.lo[axis] = box.hi[axis];
            box.hi[axis] = box.hi[axis] + float(uniform(0.5, 3));
            return box;
        }
        if (kind < 15) {  // zero extent on one or all axes
            for (int axis = 0; axis < D; ++axis) {
                half[axis] = (kind < 11 || axis == 0) ? 0 : half[axis];
            }
        } else if (kind < 17) {  // huge
            for (int axis = 0; axis < D; ++axis) {
                half[axis] = uniform(20, 100);
            }
        } else if (kind < 19 && planes_ < 2) {  // a static plane's box
            ++planes_;
            for (int axis = 0; axis < D; ++axis) {
                box.lo[axis] = -1e18f;
                box.hi[axis] = 1e18f;
            }
            return box;
        } else if (kind < 27) {  // far outside the initial scene
            const double far = uniform(1e4, 1e7) * (pick(2) ? 1 : -1);
            centre[pick(D)] = far;
            for (int axis = 0; axis < D; ++axis) {
                half[axis] *= std::fabs(far) * 1e-6 + 1;
            }
        } else if (kind < 29) {  // beyond any tree: 1e15 .. 1e30
            centre[pick(D)] = std::pow(10.0, uniform(15, 30)) * (pick(2) ? 1 : -1);
        }
        for (int axis = 0; axis < D; ++axis) {
            box.lo[axis] = float(centre[axis] - half[axis]);
            box.hi[axis] = float(centre[axis] + half[axis]);
        }
        return box;
    }

    static bool isPlane(const Box& box) { return box.hi[0] >= 1e18f; }

    void create() {
        ObjectId id;
        if (!freeIds_.empty()) {
            id = freeIds_.back();
            freeIds_.pop_back();
        } else {
            id = ObjectId(boxes_.size());
            boxes_.emplace_back();
        }
        boxes_[id] = randomBox();
        ids_.push_back(id);
        core_.insert(id, boxes_[id]);
        oracle_.insert(id, boxes_[id]);
    }

    void randomOperation() {
        const int op = pick(100);
        if (op < 10 || ids_.size() < 20) {
            create();
            return;
        }
        const std::size_t index = std::size_t(pick(int(ids_.size())));
        const ObjectId id = ids_[index];
        if (op < 18) {
            planes_ -= isPlane(boxes_[id]) ? 1 : 0;
            core_.remove(id);
            oracle_.remove(id);
            ids_[index] = ids_.back();
            ids_.pop_back();
            freeIds_.push_back(id);
            return;
        }
        if (isPlane(boxes_[id])) {
            return;
        }
        Box box = boxes_[id];
        if (op < 85) {  // small move
            for (int axis = 0; axis < D; ++axis) {
                const float shift = float(uniform(-0.5, 0.5));
                box.lo[axis] += shift;
                box.hi[axis] += shift;
            }
        } else if (op < 92) {  // a flier: jumps far along one axis, keeps its size
            const int axis = pick(D);
            const float shift = float(uniform(-1, 1) * std::pow(10.0, uniform(2, 8)));
            box.lo[axis] += shift;
            box.hi[axis] += shift;
        } else {
            box = randomBox();
            if (isPlane(box)) {
                --planes_;
                return;
            }
        }
        boxes_[id] = box;
        core_.update(id, box);
        oracle_.update(id, box);
    }

    void check() {
        ASSERT_NO_THROW(core_.validate());
        ASSERT_EQ(core_.size(), oracle_.size());
    }

    std::set<Pair> exactOf(const std::set<Pair>& pairs) const {
        std::set<Pair> out;
        for (const Pair& pair : pairs) {
            if (overlaps(boxes_[pair.first], boxes_[pair.second])) {
                out.insert(pair);
            }
        }
        return out;
    }

    void checkFrame() {
        const std::set<Pair> candidates = candidatesOf(core_);
        ASSERT_NO_THROW(core_.validate());
        std::set<Pair> all;
        oracle_.findCandidates([&](ObjectId a, ObjectId b) { all.insert(ordered(a, b)); });
        const std::set<Pair> truth = exactOf(all);
        ASSERT_EQ(exactOf(candidates), truth) << "exact pairs differ from the oracle's";

        // The candidates are exactly the pairs whose cell boxes overlap.
        std::set<Pair> cellPairs;
        for (const Pair& pair : all) {
            if (cellsOverlap<D>(core_.cellsOf(pair.first), core_.cellsOf(pair.second))) {
                cellPairs.insert(pair);
            }
        }
        ASSERT_EQ(candidates, cellPairs) << "candidates are not the cell-overlap pairs";

        ++counts_.frames;
        counts_.exactPairs += truth.size();
        counts_.candidates += candidates.size();
        std::set<ObjectId> withPartner;
        std::size_t finite = 0;
        for (ObjectId id : ids_) {
            finite += isPlane(boxes_[id]) ? 0 : 1;
        }
        for (const Pair& pair : truth) {
            if (!isPlane(boxes_[pair.first]) && !isPlane(boxes_[pair.second])) {
                withPartner.insert(pair.first);
                withPartner.insert(pair.second);
            }
        }
        counts_.objectsWithPartner +=
            double(withPartner.size()) / double(std::max<std::size_t>(finite, 1));

        for (int query = 0; query < 4; ++query) {
            checkBoxQuery(randomBox());
            checkRayQuery(query);
        }
    }

    template <class Query>
    std::set<ObjectId> visited(Query&& query) {
        std::set<ObjectId> out;
        query([&](ObjectId id) {
            EXPECT_TRUE(out.insert(id).second) << "object " << id << " visited twice by a query";
        });
        return out;
    }

    void checkBoxQuery(const Box& box) {
        const std::set<ObjectId> seen = visited([&](auto&& visit) { core_.queryBox(box, visit); });
        std::set<ObjectId> hits, truth;
        for (ObjectId id : seen) {
            if (overlaps(boxes_[id], box)) {
                hits.insert(id);
            }
        }
        for (ObjectId id : ids_) {
            if (overlaps(boxes_[id], box)) {
                truth.insert(id);
            }
        }
        ASSERT_EQ(hits, truth) << "box query";
        counts_.queryHits += truth.size() > (std::size_t)planes_ ? 1 : 0;
        ++counts_.queries;
    }

    void checkRayQuery(int query) {
        Ray<D, float> ray;
        std::array<double, D> direction;
        double length = 0;
        for (int axis = 0; axis < D; ++axis) {
            ray.origin[axis] = float(uniform(-60, 60));
            direction[axis] = (query == 0 && axis != 1) ? 0 : uniform(-1, 1);
            length += direction[axis] * direction[axis];
        }
        length = std::sqrt(length);
        for (int axis = 0; axis < D; ++axis) {
            const double unit = direction[axis] / length;
            ray.inverseDirection[axis] = unit == 0 ? 1e18f : float(1 / unit);
            ray.sign[axis] = ray.inverseDirection[axis] < 0;
            if (query % 2) {
                const float size = float(uniform(0, 2));
                ray.expandLo[axis] = -size;
                ray.expandHi[axis] = size;
            }
        }
        ray.lambdaMax = float(uniform(2, 30));
        const std::set<ObjectId> seen = visited([&](auto&& visit) { core_.queryRay(ray, visit); });
        std::set<ObjectId> hits, truth;
        for (ObjectId id : seen) {
            if (rayHits(boxes_[id], ray)) {
                hits.insert(id);
            }
        }
        bool finiteHit = false;
        for (ObjectId id : ids_) {
            if (rayHits(boxes_[id], ray)) {
                truth.insert(id);
                finiteHit = finiteHit || !isPlane(boxes_[id]);
            }
        }
        ASSERT_EQ(hits, truth) << "ray query";
        counts_.rayHits += finiteHit ? 1 : 0;
        ++counts_.rays;
    }

    std::mt19937 random_;
    Core core_;
    BruteForce<D, float> oracle_;
    std::vector<Box> boxes_;
    std::vector<ObjectId> ids_;
    std::vector<ObjectId> freeIds_;
    int planes_ = 0;
    SceneCounts counts_;
};

template <class Core, int D>
void runRandomScenes(const typename Core::Settings& settings) {
    SceneCounts total;
    for (std::uint32_t seed : {11u, 12u, 13u}) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        RandomCoreScene<Core, D> scene(seed, settings);
        scene.run(/*frames=*/25, /*initialObjects=*/120, /*operationsPerFrame=*/25);
        if (::testing::Test::HasFailure()) {
            return;
        }
        const SceneCounts& counts = scene.counts();
        total.frames += counts.frames;
        total.exactPairs += counts.exactPairs;
        total.candidates += counts.candidates;
        total.objectsWithPartner += counts.objectsWithPartner;
        total.queryHits += counts.queryHits;
        total.queries += counts.queries;
        total.rayHits += counts.rayHits;
        total.rays += counts.rays;
    }
    // The sample means something: objects do overlap, queries and rays do hit.
    const double partnerRate = total.objectsWithPartner / double(total.frames);
    EXPECT_GT(partnerRate, 0.3) << "random scenes too sparse";
    EXPECT_LT(partnerRate, 0.95) << "random scenes too dense";
    EXPECT_GT(double(total.queryHits) / double(total.queries), 0.3);
    EXPECT_GT(double(total.rayHits) / double(total.rays), 0.2);
    EXPECT_LT(double(total.rayHits) / double(total.rays), 0.98);
    std::printf("[ D=%d ] exact pairs %zu, candidates %zu, objects with a partner %.0f%%\n", D,
                total.exactPairs, total.candidates, 100 * partnerRate);
}

SegmentTreeSettings thesisFlags() {
    SegmentTreeSettings settings;
    settings.traversal = SegmentTreeSettings::Traversal::ThesisFlags;
    return settings;
}

RangeTreeSettings wholeLists() {
    RangeTreeSettings settings;
    settings.searchSortedLists = false;
    return settings;
}

TEST(SegmentTreeSet3, RandomOperationsMatchTheOracle) {
    runRandomScenes<SegmentTreeSet<3, float>, 3>({});
}
TEST(SegmentTreeSet3, ThesisTraversalMatchesTheOracle) {
    runRandomScenes<SegmentTreeSet<3, float>, 3>(thesisFlags());
}
TEST(SegmentTreeSet2, RandomOperationsMatchTheOracle) {
    runRandomScenes<SegmentTreeSet<2, float>, 2>({});
}
TEST(SegmentTreeSet2, ThesisTraversalMatchesTheOracle) {
    runRandomScenes<SegmentTreeSet<2, float>, 2>(thesisFlags());
}
TEST(RangeTree3, RandomOperationsMatchTheOracle) {
    runRandomScenes<RangeTree<3, float>, 3>({});
}
TEST(RangeTree3, WholeListScanMatchesTheOracle) {
    runRandomScenes<RangeTree<3, float>, 3>(wholeLists());
}
TEST(RangeTree3, TreeOnTheLastAxisMatchesTheOracle) {
    RangeTreeSettings settings;
    settings.treeAxis = 2;
    runRandomScenes<RangeTree<3, float>, 3>(settings);
}
TEST(RangeTree2, RandomOperationsMatchTheOracle) {
    runRandomScenes<RangeTree<2, float>, 2>({});
}

}  // namespace
}  // namespace kolize

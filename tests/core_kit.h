#pragma once
// The core test kit: drives any kolize core (the concept of BruteForce in brute_force.h)
// through seeded random operations in D = 2 or 3 and checks it against the brute-force
// truth. Every operation is followed by validate(); every few operations the candidate
// pairs (no duplicates allowed; after the exact box test they must equal the true
// overlapping pairs) and random box and ray queries (supersets; after the exact test they
// must equal the truth) are compared. The result counts what was compared, so a test can
// check that its sample was meaningful.

#include <kolize/broadphase/aabb.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace kolize::testkit {

/// What a random scenario contains. Shares are per created or moved box.
struct CoreScenario {
    std::uint64_t seed = 1;
    int operations = 600;  ///< validate() after each
    int checkEvery = 7;    ///< pairs and queries compared every this many operations
    int maxObjects = 150;
    double world = 0;         ///< ordinary boxes live in [-world, world]^D; 0: 40 in 2D, 16 in 3D
    double hugeShare = 0.02;  ///< +-1e18 on some axes, like Bullet's static planes
    double farShare = 0.03;   ///< centred 1e6 .. 1e12 away
    double flatShare = 0.08;  ///< zero extent on one axis or all (points)
    double bigShare = 0.03;   ///< ten times the ordinary size
    double teleportShare = 0.2;  ///< moves that jump anywhere instead of a small step
};

/// What was compared, summed over the checks.
struct CoreScenarioResult {
    std::size_t checks = 0;
    std::size_t truePairs = 0;
    std::size_t candidates = 0;
    std::size_t boxQueries = 0;
    std::size_t boxHits = 0;
    std::size_t rayQueries = 0;
    std::size_t rayHits = 0;
};

template <int D, class Scalar>
class ScenarioBoxes {
  public:
    using Box = Aabb<D, Scalar>;
    explicit ScenarioBoxes(const CoreScenario& scenario)
        : scenario_(scenario), random_(scenario.seed) {
        if (scenario_.world == 0) {
            scenario_.world = D == 2 ? 40 : 16;
        }
    }

    Box make() {
        const double r = unit();
        Box box;
        if (r < scenario_.hugeShare) {
            // A plane-like slab: huge on all axes but one, or huge everywhere.
            const int thin = static_cast<int>(unit() * (D + 1));
            for (int axis = 0; axis < D; ++axis) {
                box.lo[axis] = Scalar(-1e18);
                box.hi[axis] = Scalar(1e18);
            }
            if (thin < D) {
                box.hi[thin] = Scalar(coordinate());
            }
            return box;
        }
        double centre[D];
        for (double& c : centre) {
            c = coordinate();
        }
        if (r < scenario_.hugeShare + scenario_.farShare) {
            const double far = std::pow(10.0, 6 + 6 * unit()) * (unit() < 0.5 ? -1 : 1);
            centre[static_cast<int>(unit() * D)] += far;
        }
        double size = 0.5 + 3.5 * unit();
        if (unit() < scenario_.bigShare) {
            size *= 10;
        }
        const bool flat = unit() < scenario_.flatShare;
        const int flatAxis = unit() < 0.5 ? -1 : static_cast<int>(unit() * D);
        for (int axis = 0; axis < D; ++axis) {
            const double half = flat && (flatAxis < 0 || flatAxis == axis) ? 0 : size * unit();
            box.lo[axis] = Scalar(centre[axis] - half);
            box.hi[axis] = Scalar(centre[axis] + half);
        }
        return box;
    }
    /// A small step, or (teleportShare) a new box.
    Box moved(const Box& box) {
        if (unit() < scenario_.teleportShare || std::fabs(double(box.lo[0])) > 1e17 ||
            std::fabs(double(box.hi[0])) > 1e17) {
            return make();
        }
        Box out = box;
        for (int axis = 0; axis < D; ++axis) {
            const Scalar step = Scalar(2 * unit() - 1);
            out.lo[axis] += step;
            out.hi[axis] += step;
        }
        return out;
    }
    /// A query box, sometimes a point or huge.
    Box query() {
        if (unit() < 0.05) {
            return make();
        }
        Box box;
        for (int axis = 0; axis < D; ++axis) {
            const double c = coordinate();
            const double half = unit() < 0.1 ? 0 : 8 * unit();
            box.lo[axis] = Scalar(c - half);
            box.hi[axis] = Scalar(c + half);
        }
        return box;
    }
    /// A ray prepared the way Bullet prepares one: normalised direction, inverse with
    /// 1e18 for zero components, signs, lambdaMax = length; sometimes axis-parallel, long,
    /// or swept with a box.
    Ray<D, Scalar> ray() {
        double from[D], to[D];
        for (int axis = 0; axis < D; ++axis) {
            from[axis] = coordinate() * 1.5;
            to[axis] = coordinate() * 1.5;
        }
        if (unit() < 0.25) {
            const int keep = static_cast<int>(unit() * D);
            for (int axis = 0; axis < D; ++axis) {
                if (axis != keep) {
                    to[axis] = from[axis];
                }
            }
        }
        if (unit() < 0.1) {
            for (int axis = 0; axis < D; ++axis) {
                to[axis] = from[axis] + (to[axis] - from[axis]) * 1e4;
            }
        }
        double length = 0;
        for (int axis = 0; axis < D; ++axis) {
            length += (to[axis] - from[axis]) * (to[axis] - from[axis]);
        }
        length = std::sqrt(length);
        if (length == 0) {
            to[0] += 1;
            length = 1;
        }
        Ray<D, Scalar> ray;
        const bool swept = unit() < 0.3;
        for (int axis = 0; axis < D; ++axis) {
            ray.origin[axis] = Scalar(from[axis]);
            const double direction = (to[axis] - from[axis]) / length;
            ray.inverseDirection[axis] = direction == 0 ? Scalar(1e18) : Scalar(1 / direction);
            ray.sign[axis] = ray.inverseDirection[axis] < 0 ? 1 : 0;
            ray.expandLo[axis] = swept ? Scalar(-3 * unit()) : Scalar(0);
            ray.expandHi[axis] = swept ? Scalar(3 * unit()) : Scalar(0);
        }
        ray.lambdaMax = Scalar(length);
        return ray;
    }
    double unit() { return std::uniform_real_distribution<double>(0, 1)(random_); }

  private:
    double coordinate() { return (2 * unit() - 1) * scenario_.world; }

    CoreScenario scenario_;
    std::mt19937_64 random_;
};

/// Runs the scenario on `core`; returns what was compared. Failures are gtest failures.
template <int D, class Scalar, class Core>
CoreScenarioResult runCoreScenario(Core& core, const CoreScenario& scenario) {
    using Box = Aabb<D, Scalar>;
    ScenarioBoxes<D, Scalar> boxes(scenario);
    std::vector<Box> box;
    std::vector<bool> live;
    std::vector<ObjectId> liveIds, freeIds;
    CoreScenarioResult result;
    auto validate = [&](int operation, const char* what) {
        try {
            core.validate();
        } catch (const std::exception& error) {
            ADD_FAILURE() << "validate() after operation " << operation << " (" << what
                          << "): " << error.what();
            return false;
        }
        if (core.size() != liveIds.size()) {
            ADD_FAILURE() << "size() " << core.size() << " != " << liveIds.size();
            return false;
        }
        return true;
    };
    for (int operation = 0; operation < scenario.operations; ++operation) {
        const double r = boxes.unit();
        const char* what;
        if (liveIds.empty() || (r < 0.3 && liveIds.size() < std::size_t(scenario.maxObjects))) {
            ObjectId id;
            if (!freeIds.empty()) {
                id = freeIds.back();
                freeIds.pop_back();
            } else {
                id = static_cast<ObjectId>(box.size());
                box.emplace_back();
                live.push_back(false);
            }
            box[id] = boxes.make();
            live[id] = true;
            liveIds.push_back(id);
            core.insert(id, box[id]);
            what = "insert";
        } else if (r < 0.4) {
            const std::size_t at = static_cast<std::size_t>(boxes.unit() * liveIds.size());
            const ObjectId id = liveIds[at];
            liveIds.erase(liveIds.begin() + static_cast<std::ptrdiff_t>(at));
            live[id] = false;
            freeIds.push_back(id);
            core.remove(id);
            what = "remove";
        } else {
            // Move a batch, as a frame does.
            const int moves = 1 + static_cast<int>(boxes.unit() * 20);
            for (int m = 0; m < moves; ++m) {
                const ObjectId id =
                    liveIds[static_cast<std::size_t>(boxes.unit() * liveIds.size())];
                box[id] = boxes.moved(box[id]);
                core.update(id, box[id]);
            }
            what = "update";
        }
        if (!validate(operation, what)) {
            return result;
        }
        if (operation % scenario.checkEvery != 0) {
            continue;
        }
        ++result.checks;
        // Pairs.
        std::set<std::pair<ObjectId, ObjectId>> reported;
        bool duplicate = false, dead = false;
        core.maintain();
        core.findCandidates([&](ObjectId a, ObjectId b) {
            ++result.candidates;
            if (a >= live.size() || b >= live.size() || !live[a] || !live[b] || a == b) {
                dead = true;
                return;
            }
            const auto pair = std::minmax(a, b);
            if (!reported.insert(pair).second) {
                duplicate = true;
            }
        });
        if (!validate(operation, "findCandidates")) {
            return result;
        }
        EXPECT_FALSE(duplicate) << "a candidate pair was reported twice, operation " << operation;
        EXPECT_FALSE(dead) << "a candidate names a dead or equal id, operation " << operation;
        std::set<std::pair<ObjectId, ObjectId>> truth, exact;
        for (std::size_t i = 0; i < liveIds.size(); ++i) {
            for (std::size_t j = i + 1; j < liveIds.size(); ++j) {
                if (overlaps(box[liveIds[i]], box[liveIds[j]])) {
                    truth.insert(std::minmax(liveIds[i], liveIds[j]));
                }
            }
        }
        for (const auto& pair : reported) {
            if (overlaps(box[pair.first], box[pair.second])) {
                exact.insert(pair);
            }
        }
        result.truePairs += truth.size();
        if (exact != truth) {
            std::size_t missing = 0;
            for (const auto& pair : truth) {
                missing += exact.count(pair) == 0 ? 1 : 0;
            }
            ADD_FAILURE() << "operation " << operation << ": " << missing << " of " << truth.size()
                          << " true pairs missing";
            return result;
        }
        // A box query and a ray query.
        const Box query = boxes.query();
        std::set<ObjectId> got, want;
        core.queryBox(query, [&](ObjectId id) {
            if (overlaps(box[id], query)) {
                got.insert(id);
            }
        });
        const Ray<D, Scalar> ray = boxes.ray();
        std::set<ObjectId> gotRay, wantRay;
        core.queryRay(ray, [&](ObjectId id) {
            if (rayHits(box[id], ray)) {
                gotRay.insert(id);
            }
        });
        for (ObjectId id : liveIds) {
            if (overlaps(box[id], query)) {
                want.insert(id);
            }
            if (rayHits(box[id], ray)) {
                wantRay.insert(id);
            }
        }
        ++result.boxQueries;
        result.boxHits += want.size();
        ++result.rayQueries;
        result.rayHits += wantRay.size();
        EXPECT_EQ(got, want) << "box query, operation " << operation;
        EXPECT_EQ(gotRay, wantRay) << "ray query, operation " << operation;
        if (got != want || gotRay != wantRay) {
            return result;
        }
        // Queries between frames must see moves made after the last pair search.
        for (int m = 0; m < 5 && !liveIds.empty(); ++m) {
            const ObjectId id = liveIds[static_cast<std::size_t>(boxes.unit() * liveIds.size())];
            box[id] = boxes.moved(box[id]);
            core.update(id, box[id]);
        }
        gotRay.clear();
        wantRay.clear();
        core.queryRay(ray, [&](ObjectId id) {
            if (rayHits(box[id], ray)) {
                gotRay.insert(id);
            }
        });
        for (ObjectId id : liveIds) {
            if (rayHits(box[id], ray)) {
                wantRay.insert(id);
            }
        }
        EXPECT_EQ(gotRay, wantRay) << "ray query after moves, operation " << operation;
        if (gotRay != wantRay) {
            return result;
        }
        // And a box query, each object at most once (the sweep applies moves at the next
        // maintain(): moved objects are visited apart from its sorted arrays).
        got.clear();
        want.clear();
        bool repeated = false;
        core.queryBox(query, [&](ObjectId id) {
            if (overlaps(box[id], query) && !got.insert(id).second) {
                repeated = true;
            }
        });
        for (ObjectId id : liveIds) {
            if (overlaps(box[id], query)) {
                want.insert(id);
            }
        }
        EXPECT_EQ(got, want) << "box query after moves, operation " << operation;
        EXPECT_FALSE(repeated) << "box query after moves reported an object twice, operation "
                               << operation;
        if (got != want || repeated) {
            return result;
        }
    }
    return result;
}

/// The sample must mean something: pairs and hits were actually compared.
inline void expectMeaningful(const CoreScenarioResult& result, std::size_t minPairs = 200) {
    EXPECT_GT(result.checks, 20u);
    EXPECT_GE(result.truePairs, minPairs) << "too few overlapping pairs to test anything";
    EXPECT_GT(result.boxHits, result.boxQueries / 2) << "box queries hit almost nothing";
    EXPECT_GT(result.rayHits, result.rayQueries / 2) << "rays hit almost nothing";
}

}  // namespace kolize::testkit

// The sweep core's own overlap tracking (drainChanges), checked against a plain brute force:
// a set of pairs kept only from the drained changes (each one re-tested exactly) must equal
// the truly overlapping pairs after every frame, under seeded random moves, jitter of
// near-equal coordinates, removals and ids re-used before the next maintain(); with many
// objects moved per frame (their moves applied in one insertion pass per axis) and with few
// (one object at a time). And the core test kit (candidates, box and ray queries, also
// between update() and the next maintain()) against its brute force.

#include <kolize/broadphase/sweep_and_prune.h>

#include "core_kit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace {

using Box = kolize::Aabb<3, float>;
using Pair = std::pair<kolize::ObjectId, kolize::ObjectId>;

template <class B>
bool overlap(const B& a, const B& b) {
    for (int axis = 0; axis < 3; ++axis) {
        if (a.hi[axis] < b.lo[axis] || b.hi[axis] < a.lo[axis]) {
            return false;
        }
    }
    return true;
}

Pair ordered(kolize::ObjectId a, kolize::ObjectId b) {
    return a < b ? Pair{a, b} : Pair{b, a};
}

/// A pair search: the drained changes, each tested exactly, kept in `tracked`. Returns how
/// many were drained.
template <class Core, class B>
std::size_t drainInto(Core& core, const std::vector<B>& boxes, std::set<Pair>& tracked) {
    std::size_t drained = 0;
    core.maintain();
    core.drainChanges([&](kolize::ObjectId a, kolize::ObjectId b) {
        ++drained;
        if (overlap(boxes[a], boxes[b])) {
            tracked.insert(ordered(a, b));
        } else {
            tracked.erase(ordered(a, b));
        }
    });
    return drained;
}

struct Tracked {
    std::size_t frames = 0, pairsSeen = 0, reusedBeforeMaintain = 0, changes = 0;
    std::size_t oneAxisMoves = 0, oneEndMoves = 0;
    std::size_t batched = 0, oneByOne = 0;  ///< the core's counters at the end
    std::size_t writtenAtUpdate = 0;
};

/// `opsPerFrame` random operations between two maintain() calls, `frames` times.
Tracked runTracked(std::uint32_t seed, bool lattice, int opsPerFrame, int frames) {
    std::printf("sweep tracking, seed %u, %s, %d operations per frame\n", seed,
                lattice ? "lattice" : "random", opsPerFrame);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0, 1);
    kolize::SweepAndPrune<3, float> core;
    constexpr int kObjects = 120;
    std::vector<Box> boxes(kObjects);
    std::vector<bool> live(kObjects, false);
    auto randomBox = [&](int id) {
        Box box;
        for (int axis = 0; axis < 3; ++axis) {
            // Lattice: unit boxes on integer corners, touching their neighbours exactly (the
            // near-equal coordinates jitter reorders).
            const float lo =
                lattice ? float(id % 5 + (axis == 1 ? id / 25 : (id / 5) % 5)) : 8 * unit(rng);
            box.lo[axis] = lo;
            box.hi[axis] = lo + (lattice ? 1.0f : 0.2f + 1.5f * unit(rng));
        }
        return box;
    };
    std::set<Pair> tracked;
    Tracked out;
    for (int frame = 0; frame < frames; ++frame) {
        for (int op = 0; op < opsPerFrame; ++op) {
            const int id = int(rng() % kObjects);
            const float roll = unit(rng);
            if (!live[id]) {
                boxes[id] = randomBox(id);
                core.insert(id, boxes[id]);
                live[id] = true;
            } else if (roll < 0.08f) {
                core.remove(id);
                live[id] = false;
                // A removed object's pairs go with it (the adapter erases them with its slot).
                for (auto it = tracked.begin(); it != tracked.end();) {
                    it = it->first == kolize::ObjectId(id) || it->second == kolize::ObjectId(id)
                             ? tracked.erase(it)
                             : std::next(it);
                }
                if (unit(rng) < 0.5f) {  // the id comes back before maintain()
                    boxes[id] = randomBox(id);
                    core.insert(id, boxes[id]);
                    live[id] = true;
                    ++out.reusedBeforeMaintain;
                }
            } else {
                Box& box = boxes[id];
                const float step = roll < 0.5f ? 1e-6f : 0.3f;  // jitter or a move
                const float shape = unit(rng);
                if (shape < 0.6f) {  // a translation on every axis
                    for (int axis = 0; axis < 3; ++axis) {
                        const float d = step * (2 * unit(rng) - 1);
                        box.lo[axis] += d;
                        box.hi[axis] += d;
                    }
                } else if (shape < 0.8f) {  // one axis only (a fall, a slide)
                    const int axis = int(rng() % 3);
                    const float d = step * (2 * unit(rng) - 1);
                    box.lo[axis] += d;
                    box.hi[axis] += d;
                    ++out.oneAxisMoves;
                } else {  // one end of one axis (a box that grows or shrinks on one side)
                    const int axis = int(rng() % 3);
                    const float d = step * unit(rng);
                    if (rng() % 2 == 0) {
                        box.lo[axis] = std::min(box.hi[axis], box.lo[axis] + (rng() % 2 ? d : -d));
                    } else {
                        box.hi[axis] = std::max(box.lo[axis], box.hi[axis] + (rng() % 2 ? d : -d));
                    }
                    ++out.oneEndMoves;
                }
                core.update(id, box);
            }
        }
        out.changes += drainInto(core, boxes, tracked);
        std::set<Pair> truth;
        for (int a = 0; a < kObjects; ++a) {
            for (int b = a + 1; b < kObjects; ++b) {
                if (live[a] && live[b] && overlap(boxes[a], boxes[b])) {
                    truth.insert({a, b});
                }
            }
        }
        EXPECT_EQ(tracked, truth) << "seed " << seed << ", frame " << frame;
        if (tracked != truth) {
            return out;
        }
        core.validate();
        out.pairsSeen += truth.size();
        ++out.frames;
    }
    out.batched = core.batchedSearches();
    out.oneByOne = core.oneByOneSearches();
    out.writtenAtUpdate = core.movesWrittenAtUpdate();
    return out;
}

TEST(SweepTracking, DrainedChangesKeepTheExactPairsUnderMovesJitterAndReusedIds) {
    // 40 operations per frame move about a third of the 120 objects (one insertion pass
    // per axis); 3 move one object in 40 (one at a time). The same number of operations.
    struct Mode {
        int opsPerFrame, frames;
        bool batched;
    };
    for (const Mode mode : {Mode{40, 200, true}, Mode{3, 2667, false}}) {
        for (std::uint32_t seed = 1; seed <= 4; ++seed) {
            for (bool lattice : {false, true}) {
                const Tracked t = runTracked(seed, lattice, mode.opsPerFrame, mode.frames);
                EXPECT_EQ(t.frames, std::size_t(mode.frames));
                // The sample means something: pairs, changes and re-used ids occurred.
                EXPECT_GT(t.pairsSeen, std::size_t(mode.frames) * 20);
                EXPECT_GT(t.changes, 1000u);
                EXPECT_GT(t.reusedBeforeMaintain, 50u);
                // Moves that keep some intervals (skipped axes must be exactly those).
                EXPECT_GT(t.oneAxisMoves, 500u);
                EXPECT_GT(t.oneEndMoves, 500u);
                // The frames took the way of applying moves this mode is for.
                EXPECT_GT(mode.batched ? t.batched : t.oneByOne, std::size_t(mode.frames) * 9 / 10);
                // After a batch the next frame's moves are written at update() (removals
                // and re-used ids among them).
                if (mode.batched) {
                    EXPECT_GT(t.writtenAtUpdate, std::size_t(mode.frames) * 20);
                }
            }
        }
    }
}

/// A stack's layer: 64 unit boxes, 8 x 8 side by side, touching exactly; inserted in `core`.
std::vector<Box> unitLayer(kolize::SweepAndPrune<3, float>& core) {
    std::vector<Box> boxes;
    for (int i = 0; i < 64; ++i) {
        const float x = float(i % 8), z = float(i / 8);
        boxes.push_back(Box{{x, 0, z}, {x + 1, 1, z + 1}});
        core.insert(kolize::ObjectId(i), boxes.back());
    }
    return boxes;
}

// A stack's layer whose lows and highs are equal but for a jitter of a few ulps, all moved
// every frame. One insertion pass per axis reorders the tied endpoints; the drained changes
// must still keep the exact pairs.
TEST(SweepTracking, ABatchOfTiedJitteringEndpointsKeepsTheExactPairs) {
    std::mt19937 rng(7);
    std::printf("tied jitter, seed 7\n");
    kolize::SweepAndPrune<3, float> core;
    std::vector<Box> boxes = unitLayer(core);
    std::set<Pair> tracked;
    auto drain = [&] { drainInto(core, boxes, tracked); };
    auto truth = [&] {
        std::set<Pair> out;
        for (kolize::ObjectId a = 0; a < boxes.size(); ++a) {
            for (kolize::ObjectId b = a + 1; b < boxes.size(); ++b) {
                if (overlap(boxes[a], boxes[b])) {
                    out.insert({a, b});
                }
            }
        }
        return out;
    };
    drain();
    ASSERT_EQ(tracked, truth());
    std::size_t changedFrames = 0;
    for (int frame = 0; frame < 300; ++frame) {
        for (kolize::ObjectId id = 0; id < boxes.size(); ++id) {
            Box& box = boxes[id];
            for (int axis = 0; axis < 3; ++axis) {
                // Up to 2 ulps either way, on each end apart: touching neighbours come apart
                // and meet again.
                const int ulps = int(rng() % 5) - 2;
                box.lo[axis] = std::nextafter(box.lo[axis], ulps < 0 ? -1e9f : 1e9f);
                if (ulps == 0 || std::abs(ulps) == 2) {
                    box.hi[axis] = std::nextafter(box.hi[axis], ulps < 0 ? -1e9f : 1e9f);
                }
                box.hi[axis] = std::max(box.hi[axis], box.lo[axis]);
            }
            core.update(id, box);
        }
        const std::set<Pair> before = tracked;
        drain();
        ASSERT_EQ(tracked, truth()) << "frame " << frame;
        changedFrames += tracked != before ? 1 : 0;
        core.validate();
    }
    EXPECT_GT(changedFrames, 100u) << "the jitter must make and break pairs";
    EXPECT_EQ(core.batchedSearches(), 300u);
}

// Boxes moved together keep every order: a pass swaps nothing. A lattice of unit boxes
// touching exactly, all translated by a quarter (exact in float) every frame.
TEST(SweepTracking, ABatchTranslatedTogetherSwapsNothing) {
    kolize::SweepAndPrune<3, float> core;
    std::vector<Box> boxes = unitLayer(core);
    core.maintain();
    std::size_t pairs = 0;
    core.drainChanges([&](kolize::ObjectId, kolize::ObjectId) { ++pairs; });
    EXPECT_EQ(pairs, 7u * 8 * 2 + 7 * 7 * 2) << "faces and diagonal corners touch";
    for (int frame = 0; frame < 10; ++frame) {
        for (kolize::ObjectId id = 0; id < boxes.size(); ++id) {
            for (int axis = 0; axis < 3; ++axis) {
                boxes[id].lo[axis] += 0.25f;
                boxes[id].hi[axis] += 0.25f;
            }
            core.update(id, boxes[id]);
        }
        core.maintain();
        core.drainChanges([&](kolize::ObjectId, kolize::ObjectId) { ++pairs; });
        core.validate();
    }
    EXPECT_EQ(core.batchedSearches(), 10u);
    EXPECT_EQ(core.swaps(), 0u);
    EXPECT_EQ(pairs, 7u * 8 * 2 + 7 * 7 * 2) << "no change recorded";
}

// A stack on its side: layers along x whose ends are tied but for a jitter that reorders the
// mins (and the maxes) of a layer among themselves every frame without passing an end of the
// other kind, so the pass over x is left out and x's runs stay unsorted (the same jitter on
// y and z, whose gaps are wider). Between those frames, what needs sorted arrays or reads
// the order: a frame of few moves (one object at a time, moveOne), objects created (merge)
// and removed (compact), a big move that does pass ends of the other kind, and box queries
// along x (whose scan must not stop inside an unsorted run). Pairs against a brute force
// after every frame, queries against the first-axis truth.
template <class Scalar>
void runUnsortedRuns(std::uint32_t seed) {
    using SBox = kolize::Aabb<3, Scalar>;
    std::printf("unsorted runs, seed %u\n", seed);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0, 1);
    kolize::SweepAndPrune<3, Scalar> core;
    constexpr kolize::ObjectId kSlots = 200;
    std::vector<SBox> boxes(kSlots);
    std::vector<bool> live(kSlots, false);
    // Layer k spans x in [k - 0.02, k + 1.02]: it overlaps its neighbours by 0.04, and its
    // ends are tied to theirs but for the jitter. In y and z a 4 x 4 grid, 0.1 apart.
    auto place = [&](kolize::ObjectId id) {
        const int layer = int(id % 8), cell = int((id / 8) % 16);
        SBox box;
        box.lo[0] = Scalar(layer - 0.02);
        box.hi[0] = Scalar(layer + 1.02);
        box.lo[1] = Scalar(1.1 * (cell % 4));
        box.hi[1] = box.lo[1] + 1;
        box.lo[2] = Scalar(1.1 * (cell / 4));
        box.hi[2] = box.lo[2] + 1;
        return box;
    };
    for (kolize::ObjectId id = 0; id < 128; ++id) {
        boxes[id] = place(id);
        live[id] = true;
        core.insert(id, boxes[id]);
    }
    std::set<Pair> tracked;
    std::vector<kolize::ObjectId> away;
    std::size_t queries = 0, queryHits = 0, bigMoves = 0, created = 0, removed = 0;
    std::size_t midFrameHits = 0;
    for (int frame = 0; frame < 240; ++frame) {
        const int kind = frame % 12;
        if (kind == 5) {  // a few objects move far, one at a time, and come back next frame
            for (int k = 0; k < 3; ++k) {
                const kolize::ObjectId id = kolize::ObjectId(rng() % kSlots);
                if (!live[id]) {
                    continue;
                }
                // By a multiple of 1.04: an end lands among the tied ends of the other kind
                // (a min at a layer's maxes), to be placed against each of them.
                const Scalar shift = Scalar(1.04 * (int(rng() % 4) - 2 + (k % 2 == 0 ? 0 : 1)));
                boxes[id].lo[0] += shift;
                boxes[id].hi[0] += shift;
                core.update(id, boxes[id]);
                away.push_back(id);
                ++bigMoves;
            }
        } else if (kind == 6) {
            for (kolize::ObjectId id : away) {
                if (live[id]) {
                    boxes[id] = place(id);
                    core.update(id, boxes[id]);
                }
            }
            away.clear();
        } else if (kind == 9) {  // objects created and removed
            for (int k = 0; k < 4; ++k) {
                const kolize::ObjectId id = kolize::ObjectId(rng() % kSlots);
                if (live[id]) {
                    core.remove(id);
                    live[id] = false;
                    for (auto it = tracked.begin(); it != tracked.end();) {
                        it =
                            it->first == id || it->second == id ? tracked.erase(it) : std::next(it);
                    }
                    ++removed;
                } else {
                    // Half of them with their min among a layer's tied maxes.
                    boxes[id] = place(id);
                    if (k % 2 == 0) {
                        boxes[id].lo[0] += Scalar(1.04);
                        boxes[id].hi[0] += Scalar(1.04);
                    }
                    live[id] = true;
                    core.insert(id, boxes[id]);
                    ++created;
                }
            }
        } else {  // every live object jitters by up to 1e-5 on each end
            for (kolize::ObjectId id = 0; id < kSlots; ++id) {
                if (!live[id]) {
                    continue;
                }
                for (int axis = 0; axis < 3; ++axis) {
                    boxes[id].lo[axis] += Scalar(2e-5 * unit(rng) - 1e-5);
                    boxes[id].hi[axis] += Scalar(2e-5 * unit(rng) - 1e-5);
                }
                core.update(id, boxes[id]);
            }
        }
        {
            // Before the search: the moves may sit written where their endpoints were (after
            // a frame of many moves), or wait in the moved list. A query still finds every
            // object that meets it (a superset), and the structure still validates.
            core.validate();
            SBox query;
            query.lo[0] = Scalar(std::floor(9 * unit(rng)) - 0.02);
            query.hi[0] = query.lo[0] + Scalar(0.04 + unit(rng));
            query.lo[1] = query.lo[2] = -10;
            query.hi[1] = query.hi[2] = 10;
            std::set<kolize::ObjectId> seen;
            core.queryBox(query, [&](kolize::ObjectId id) { seen.insert(id); });
            for (kolize::ObjectId id = 0; id < kSlots; ++id) {
                if (live[id] && !(boxes[id].hi[0] < query.lo[0]) &&
                    !(query.hi[0] < boxes[id].lo[0])) {
                    ASSERT_EQ(seen.count(id), 1u)
                        << "seed " << seed << ", frame " << frame << ": object " << id
                        << " missed by a query before the search";
                    ++midFrameHits;
                }
            }
        }
        drainInto(core, boxes, tracked);
        std::set<Pair> truth;
        for (kolize::ObjectId a = 0; a < kSlots; ++a) {
            for (kolize::ObjectId b = a + 1; b < kSlots; ++b) {
                if (live[a] && live[b] && overlap(boxes[a], boxes[b])) {
                    truth.insert({a, b});
                }
            }
        }
        ASSERT_EQ(tracked, truth) << "seed " << seed << ", frame " << frame;
        core.validate();
        for (int q = 0; q < 4; ++q) {
            // A query box whose end falls among a layer's tied mins, or its maxes, or
            // elsewhere.
            SBox query;
            const double at = std::floor(9 * unit(rng)) + (q == 0   ? -0.02
                                                           : q == 1 ? 1.02
                                                                    : unit(rng));
            query.lo[0] = Scalar(at - 0.5 * unit(rng));
            query.hi[0] = Scalar(at);
            query.lo[1] = query.lo[2] = -10;
            query.hi[1] = query.hi[2] = 10;
            std::set<kolize::ObjectId> seen, expected;
            core.queryBox(query, [&](kolize::ObjectId id) { seen.insert(id); });
            for (kolize::ObjectId id = 0; id < kSlots; ++id) {
                if (live[id] && !(boxes[id].hi[0] < query.lo[0]) &&
                    !(query.hi[0] < boxes[id].lo[0])) {
                    expected.insert(id);
                }
            }
            ASSERT_EQ(seen, expected) << "seed " << seed << ", frame " << frame << ", query on x ["
                                      << query.lo[0] << ", " << query.hi[0] << "]";
            ++queries;
            queryHits += expected.size();
        }
    }
    // Meaningful: passes were left out, the other paths all ran, the queries found objects.
    EXPECT_GT(core.passesLeftOut(), 300u);
    EXPECT_GT(core.oneByOneSearches(), 10u);
    // A jitter frame after a jitter frame has its moves written at update() (every live
    // object, 7 frames in 12), and so have the far moves after one (3 objects, a batch of
    // few).
    EXPECT_GT(core.movesWrittenAtUpdate(), 100u * 140u);
    EXPECT_GT(midFrameHits, 240u * 10u);
    EXPECT_GT(bigMoves, 20u);
    EXPECT_GT(created, 10u);
    EXPECT_GT(removed, 10u);
    EXPECT_GT(queryHits, 10 * queries);
}

TEST(SweepTracking, UnsortedRunsOfTiedEndsKeepPairsQueriesMergesAndSingleMovesExact) {
    runUnsortedRuns<float>(41);
    runUnsortedRuns<double>(42);
}

template <int D, class Scalar>
void runSweepKit(std::uint64_t seed) {
    // Pairs searched every 7 operations (most moves applied in one pass per axis) and after
    // every operation (a frame of 1-20 moves among up to 150 objects: mostly one by one).
    for (int every : {7, 1}) {
        SCOPED_TRACE("a pair search every " + std::to_string(every) + " operations");
        kolize::SweepAndPrune<D, Scalar> core;
        kolize::testkit::CoreScenario scenario;
        scenario.seed = seed;
        scenario.checkEvery = every;
        kolize::testkit::expectMeaningful(
            kolize::testkit::runCoreScenario<D, Scalar>(core, scenario));
        EXPECT_GT(every == 1 ? core.oneByOneSearches() : core.batchedSearches(), 20u);
    }
}

TEST(SweepCore, Sweep3MatchesTheOracle) {
    runSweepKit<3, float>(21);
}
TEST(SweepCore, Sweep2MatchesTheOracle) {
    runSweepKit<2, float>(22);
}
TEST(SweepCore, Sweep3DoubleMatchesTheOracle) {
    runSweepKit<3, double>(23);
}

}  // namespace

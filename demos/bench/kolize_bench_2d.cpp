// kolize-bench-2d: kolize's 2D cores against Box2D 2.4's broadphase (b2BroadPhase over
// b2DynamicTree) on 2D versions of the thesis's scenes (squares of edge 2 turning and
// moving in -500..500; B: 95% in a cluster square of edge 80).
//
// Both sides keep a persistent pair set, the way a physics engine does:
// - Box2D: MoveProxy for every object (a fat AABB is re-inserted only when the object
//   leaves it), UpdatePairs adds the pairs of the moved proxies, and pairs whose fat AABBs
//   stopped overlapping are dropped (what b2ContactManager::Collide does). Its set is a
//   superset: the extra pairs are counted against the exact truth.
// - kolize: update every object, candidates from the core, the exact box test, and the
//   frame's difference applied to the pair set (what kolize's Bullet adapter does).

#include "../common/split.h"

#include <kolize/broadphase/brute_force.h>
#include <kolize/broadphase/cell_grid.h>
#include <kolize/broadphase/pair_set.h>
#include <kolize/broadphase/range_tree.h>
#include <kolize/broadphase/segment_tree_set.h>
#include <kolize/engine/statistics.h>
#include <kolize/engine/thesis_scene.h>

#include <box2d/b2_broad_phase.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

using kolize::ObjectId;
using kolize::ThesisLayout;
using kolize::ThesisMotion;
using Box2 = kolize::Aabb<2, double>;
using Clock = std::chrono::steady_clock;

const char* kUsage =
    "usage: kolize-bench-2d [--scene A|B|all] [--motion slow|fast|all] [--n LIST]\n"
    "                       [--frames F] [--seed S] [--csv FILE]\n"
    "2D thesis scenes; kolize's 2D cores (grid, spatial-tree, spatial-hash, segment-trees,\n"
    "range-tree, brute-force)\n"
    "against Box2D 2.4's b2BroadPhase. Frame = update every object + pair set update;\n"
    "medians over the frames; missing / extra pairs against the exact truth, last frame.\n"
    "Defaults: all scenes and motions, N = 1000,3000,10000, 60 frames (15 at\n"
    "N >= 100000), seed 1. brute-force is skipped above N = 20000.\n"
    "--csv FILE also writes one row per run: scene,motion,n,broadphase,frame_ms,\n"
    "ratio_to_box2d,pairs,missing,extra,skipped.\n";

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "kolize-bench-2d: %s (try --help)\n", message.c_str());
    std::exit(2);
}

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

using kolize::median;

struct Result {
    double initMs = 0;
    double frameMs = 0;
    std::vector<std::uint64_t> pairs;  ///< the pair set after the last frame (PairSet keys)
};

/// The exact pairs of the scene's current boxes (sweep on x), as sorted PairSet keys.
std::vector<std::uint64_t> exactPairs(const std::vector<Box2>& boxes) {
    std::vector<ObjectId> order(boxes.size());
    for (ObjectId i = 0; i < order.size(); ++i) {
        order[i] = i;
    }
    std::sort(order.begin(), order.end(),
              [&](ObjectId a, ObjectId b) { return boxes[a].lo[0] < boxes[b].lo[0]; });
    std::vector<std::uint64_t> out;
    for (std::size_t i = 0; i < order.size(); ++i) {
        for (std::size_t j = i + 1;
             j < order.size() && boxes[order[j]].lo[0] <= boxes[order[i]].hi[0]; ++j) {
            if (kolize::overlaps(boxes[order[i]], boxes[order[j]])) {
                out.push_back(kolize::PairSet::keyOf(order[i], order[j]));
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

template <class Core>
Result runKolize(const kolize::ThesisSceneSettings& settings, int frames) {
    kolize::ThesisScene<2> scene(settings);
    Result result;
    Core core;
    kolize::PairSet pairs;
    std::uint32_t stamp = 0;
    auto findPairs = [&] {
        ++stamp;
        core.findCandidates([&](ObjectId a, ObjectId b) {
            if (kolize::overlaps(scene.boxes()[a], scene.boxes()[b])) {
                bool inserted = false;
                pairs.findOrInsert(a, b, inserted).stamp = stamp;
            }
        });
        pairs.retainIf([&](const kolize::PairSet::Entry& entry) { return entry.stamp == stamp; });
    };
    const Clock::time_point initStart = Clock::now();
    for (ObjectId i = 0; i < static_cast<ObjectId>(scene.size()); ++i) {
        core.insert(i, scene.boxes()[i]);
    }
    findPairs();
    result.initMs = msSince(initStart);
    std::vector<double> times;
    for (int frame = 0; frame < frames; ++frame) {
        scene.step();
        const Clock::time_point start = Clock::now();
        for (ObjectId i = 0; i < static_cast<ObjectId>(scene.size()); ++i) {
            core.update(i, scene.boxes()[i]);
        }
        findPairs();
        times.push_back(msSince(start));
    }
    result.frameMs = median(times);
    pairs.forEach([&](const kolize::PairSet::Entry& entry) { result.pairs.push_back(entry.key); });
    std::sort(result.pairs.begin(), result.pairs.end());
    return result;
}

/// Box2D's broadphase with a contact-manager-like persistent pair set.
class Box2dPairs {
  public:
    explicit Box2dPairs(kolize::PairSet& pairs) : pairs_(pairs) {}
    // Called by b2BroadPhase::UpdatePairs.
    void AddPair(void* a, void* b) {
        const auto ia = static_cast<ObjectId>(reinterpret_cast<std::uintptr_t>(a) - 1);
        const auto ib = static_cast<ObjectId>(reinterpret_cast<std::uintptr_t>(b) - 1);
        bool inserted = false;
        pairs_.findOrInsert(ia, ib, inserted);
    }

  private:
    kolize::PairSet& pairs_;
};

b2AABB toB2(const Box2& box) {
    b2AABB out;
    out.lowerBound.Set(float(box.lo[0]), float(box.lo[1]));
    out.upperBound.Set(float(box.hi[0]), float(box.hi[1]));
    return out;
}

Result runBox2d(const kolize::ThesisSceneSettings& settings, int frames) {
    kolize::ThesisScene<2> scene(settings);
    Result result;
    b2BroadPhase broadphase;
    kolize::PairSet pairs;
    Box2dPairs adder(pairs);
    std::vector<int> proxies(static_cast<std::size_t>(scene.size()));
    auto collide = [&] {
        broadphase.UpdatePairs(&adder);
        pairs.retainIf([&](const kolize::PairSet::Entry& entry) {
            return broadphase.TestOverlap(proxies[entry.first()], proxies[entry.second()]);
        });
    };
    const Clock::time_point initStart = Clock::now();
    for (std::size_t i = 0; i < proxies.size(); ++i) {
        proxies[i] = broadphase.CreateProxy(toB2(scene.boxes()[i]),
                                            reinterpret_cast<void*>(std::uintptr_t(i + 1)));
    }
    collide();
    result.initMs = msSince(initStart);
    std::vector<Box2> previous = scene.boxes();
    std::vector<double> times;
    for (int frame = 0; frame < frames; ++frame) {
        scene.step();
        const Clock::time_point start = Clock::now();
        for (std::size_t i = 0; i < proxies.size(); ++i) {
            const Box2& box = scene.boxes()[i];
            const b2Vec2 displacement(
                float((box.lo[0] + box.hi[0] - previous[i].lo[0] - previous[i].hi[0]) / 2),
                float((box.lo[1] + box.hi[1] - previous[i].lo[1] - previous[i].hi[1]) / 2));
            broadphase.MoveProxy(proxies[i], toB2(box), displacement);
        }
        collide();
        times.push_back(msSince(start));
        previous = scene.boxes();
    }
    result.frameMs = median(times);
    pairs.forEach([&](const kolize::PairSet::Entry& entry) { result.pairs.push_back(entry.key); });
    std::sort(result.pairs.begin(), result.pairs.end());
    return result;
}

long whole(const std::string& flag, const std::string& text, long max) {
    char* end = nullptr;
    const long value = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || value <= 0 || value > max) {
        fail(flag + " needs a whole number in [1, " + std::to_string(max) + "], got '" + text +
             "'");
    }
    return value;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<ThesisLayout> layouts = {ThesisLayout::Uniform, ThesisLayout::Clustered};
    std::vector<ThesisMotion> motions = {ThesisMotion::Slow, ThesisMotion::Fast};
    std::vector<int> counts = {1000, 3000, 10000};
    int frames = 60;
    std::uint32_t seed = 1;
    std::string csvPath;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--help" || flag == "-h") {
            std::printf("%s", kUsage);
            return 0;
        }
        if (i + 1 >= argc) {
            fail(flag + " needs a value");
        }
        const std::string value = argv[++i];
        if (flag == "--scene") {
            if (value == "A" || value == "B") {
                layouts = {value == "A" ? ThesisLayout::Uniform : ThesisLayout::Clustered};
            } else if (value != "all") {
                fail("--scene takes A, B or all, got '" + value + "'");
            }
        } else if (flag == "--motion") {
            if (value == "slow" || value == "fast") {
                motions = {value == "slow" ? ThesisMotion::Slow : ThesisMotion::Fast};
            } else if (value != "all") {
                fail("--motion takes slow, fast or all, got '" + value + "'");
            }
        } else if (flag == "--n") {
            counts.clear();
            for (const std::string& item : kolize::demo::split(value, ',')) {
                counts.push_back(static_cast<int>(whole("--n", item, 5000000)));
            }
        } else if (flag == "--frames") {
            frames = static_cast<int>(whole("--frames", value, 1000000));
        } else if (flag == "--seed") {
            seed = static_cast<std::uint32_t>(whole("--seed", value, 0xffffffffL));
        } else if (flag == "--csv") {
            csvPath = value;
        } else {
            fail("unknown option '" + flag + "'");
        }
    }
    std::FILE* csv = nullptr;
    if (!csvPath.empty()) {
        csv = std::fopen(csvPath.c_str(), "w");
        if (csv == nullptr) {
            fail("cannot write '" + csvPath + "'");
        }
        std::fprintf(csv,
                     "scene,motion,n,broadphase,frame_ms,ratio_to_box2d,pairs,missing,extra,"
                     "skipped\n");
    }
    using Runner = std::function<Result(const kolize::ThesisSceneSettings&, int)>;
    const std::vector<std::pair<std::string, Runner>> runners = {
        {"grid", runKolize<kolize::UniformGrid<2, double>>},
        {"spatial-tree", runKolize<kolize::SpatialTree<2, double>>},
        {"spatial-hash", runKolize<kolize::SpatialHash<2, double>>},
        {"segment-trees", runKolize<kolize::SegmentTreeSet<2, double>>},
        {"range-tree", runKolize<kolize::RangeTree<2, double>>},
        {"brute-force", runKolize<kolize::BruteForce<2, double>>},
        {"box2d", runBox2d},
    };
    std::printf(
        "kolize-bench-2d: 2D thesis scenes, seed %u; frame = update every object + "
        "pair set; medians; errors against the exact pairs in the last frame\n",
        seed);
    for (ThesisLayout layout : layouts) {
        for (ThesisMotion motion : motions) {
            for (int n : counts) {
                kolize::ThesisSceneSettings settings;
                settings.layout = layout;
                settings.motion = motion;
                settings.objects = n;
                settings.seed = seed;
                const int runFrames = n >= 100000 ? std::min(frames, 15) : frames;
                // The truth after the last frame: the same scene, stepped as often.
                kolize::ThesisScene<2> truthScene(settings);
                for (int f = 0; f < runFrames; ++f) {
                    truthScene.step();
                }
                const std::vector<std::uint64_t> truth = exactPairs(truthScene.boxes());
                std::printf(
                    "\n2D scene %s, %s motion, N = %d, %d frames (ratio: frame time / "
                    "Box2D's)\n",
                    kolize::layoutName(layout), kolize::motionName(motion), n, runFrames);
                std::printf("| %-13s | %9s | %9s | %6s | %8s | %7s | %7s |\n", "broadphase",
                            "init ms", "frame ms", "ratio", "pairs", "missing", "extra");
                std::printf(
                    "|---------------|-----------|-----------|--------|----------|-------"
                    "--|---------|\n");
                std::map<std::string, Result> results;
                for (const auto& [name, runner] : runners) {
                    if (name == "brute-force" && n > 20000) {
                        continue;
                    }
                    results[name] = runner(settings, runFrames);
                }
                const double box2d = results["box2d"].frameMs;
                for (const auto& [name, runner] : runners) {
                    if (results.count(name) == 0) {
                        std::printf("| %-13s | skipped: O(N^2)\n", name.c_str());
                        if (csv != nullptr) {
                            std::fprintf(csv, "%s,%s,%d,%s,,,,,,O(N^2)\n",
                                         kolize::layoutName(layout), kolize::motionName(motion), n,
                                         name.c_str());
                        }
                        continue;
                    }
                    const Result& result = results[name];
                    std::vector<std::uint64_t> missing, extra;
                    std::set_difference(truth.begin(), truth.end(), result.pairs.begin(),
                                        result.pairs.end(), std::back_inserter(missing));
                    std::set_difference(result.pairs.begin(), result.pairs.end(), truth.begin(),
                                        truth.end(), std::back_inserter(extra));
                    std::printf("| %-13s | %9.3f | %9.4f | %6.3f | %8zu | %7zu | %7zu |\n",
                                name.c_str(), result.initMs, result.frameMs, result.frameMs / box2d,
                                result.pairs.size(), missing.size(), extra.size());
                    if (csv != nullptr) {
                        std::fprintf(csv, "%s,%s,%d,%s,%.6f,%.6f,%zu,%zu,%zu,\n",
                                     kolize::layoutName(layout), kolize::motionName(motion), n,
                                     name.c_str(), result.frameMs, result.frameMs / box2d,
                                     result.pairs.size(), missing.size(), extra.size());
                    }
                }
                std::fflush(stdout);
            }
        }
    }
    if (csv != nullptr && std::fclose(csv) != 0) {
        fail("cannot write '" + csvPath + "'");
    }
    return 0;
}

// kolize-bench: the thesis's scenes (DIGEST section 7) as a pure broadphase benchmark, every
// broadphase side by side in one run. Per frame: setAabb for every proxy, then
// calculateOverlappingPairs through a btCollisionDispatcher. Reports init time (creating
// the proxies and the first pair search), the per-frame median, pairs, their errors against
// the exact truth in the last frame, candidates, and the peak heap the broadphase held.

#include "memory_meter.h"

#include "../common/split.h"

#include <kolize/broadphase/bullet_adapter.h>
#include <kolize/engine/pair_compare.h>
#include <kolize/engine/statistics.h>
#include <kolize/engine/store_only.h>
#include <kolize/engine/thesis_scene.h>
#include <kolize/kolize.h>

#include <btBulletCollisionCommon.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using kolize::ThesisLayout;
using kolize::ThesisMotion;

const char* kUsage =
    "usage: kolize-bench [options]\n"
    "The thesis's scenes: space -500..500, cubes of edge 2 turning and moving; A uniform,\n"
    "B with 95%% of the cubes in a cluster cube of edge 80. Per frame: setAabb for every\n"
    "proxy + calculateOverlappingPairs. Times are medians over the frames.\n"
    "  --scene A|B|all          (default all)\n"
    "  --motion slow|fast|all   (default all)\n"
    "  --n LIST                 object counts, comma separated\n"
    "                           (default 250,500,750,1000,1500,2000,3000,10000,100000)\n"
    "  --frames F               frames per run (default 60; at most 15 for N >= 100000)\n"
    "  --broadphase LIST        comma separated; an entry may carry settings after a colon:\n"
    "                           NAME:cell=X (fixed cell edge), NAME:factor=X (cell edge in\n"
    "                           median extents), NAME:cells-per-object=X (dense grid\n"
    "                           budget), NAME:per-axis=K (thesis sizing: K cells\n"
    "                           per axis over the scene); for segment-trees and range-tree:\n"
    "                           NAME:divisions=S (the thesis's S, leaf width = scene / S),\n"
    "                           NAME:unit=U (fixed leaf width), segment-trees:traversal=thesis\n"
    "                           (the thesis's flag walk), NAME:incremental=off (enumerate\n"
    "                           every frame), range-tree:lists=whole (scan node lists whole),\n"
    "                           NAME:cache=merged (kolize broadphases: a MergedPairCache\n"
    "                           instead of Bullet's hashed pair cache).\n"
    "                           Default: the kolize broadphases,\n"
    "                           grid:per-axis=17 and spatial-tree:per-axis=17 (the thesis's\n"
    "                           configuration), dbvt, sap, sap-noray, sap32, brute-force,\n"
    "                           store-only (the lower bound: stores the boxes, finds no\n"
    "                           pairs; column x store-only = frame time / store-only's).\n"
    "                           Names: %s, store-only\n"
    "  --s-sweep LIST           the thesis's S sweep (tables 2.1, 2.2) instead: each tree\n"
    "                           broadphase given (default segment-trees, range-tree) with\n"
    "                           divisions = each S; prints frame time, candidates, pairs and\n"
    "                           the candidates the exact test rejected (thesis: 100,500,1000,\n"
    "                           1500,2000,5000)\n"
    "  --seed S                 scene seed (default 1)\n"
    "  --csv FILE               also write one row per run\n"
    "  --cache-share on|off     kolize broadphases: run each once more into a pair cache\n"
    "                           that only counts, and print the share of the frame spent\n"
    "                           in the pair cache (hashing or merging, filters, pair records)\n"
    "                           and the pairs added and removed per frame (default off)\n"
    "  --help                   this text\n"
    "brute-force and simple are skipped above N = 20000 (O(N^2) per frame); sap and\n"
    "sap-noray above 32766 objects (btAxisSweep3's 16-bit handles); sap32 above 50000\n"
    "(each createProxy sorts the new handle in: minutes of init at N = 100000). With both\n"
    "motions, a closing table puts slow and fast side by side (thesis table 2.7).\n";

struct Options {
    std::vector<ThesisLayout> layouts = {ThesisLayout::Uniform, ThesisLayout::Clustered};
    std::vector<ThesisMotion> motions = {ThesisMotion::Slow, ThesisMotion::Fast};
    std::vector<int> counts = {250, 500, 750, 1000, 1500, 2000, 3000, 10000, 100000};
    int frames = 60;
    std::vector<std::string> broadphases;
    std::uint32_t seed = 1;
    std::string csv;
    std::vector<int> sweep;  ///< S values of --s-sweep, empty without it
    bool cacheShare = false;
};

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "kolize-bench: %s (try --help)\n", message.c_str());
    std::exit(2);
}

using kolize::demo::split;

double number(const std::string& what, const std::string& text) {
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !(value > 0) || !std::isfinite(value)) {
        fail(what + " needs a positive number, got '" + text + "'");
    }
    return value;
}

/// A broadphase name with optional settings: "grid", "grid:per-axis=17".
struct Entry {
    std::string label;
    std::string name;
    kolize::BroadphaseSettings settings;
};

Entry parseEntry(const std::string& text) {
    Entry entry;
    entry.label = text;
    const std::vector<std::string> parts = split(text, ':');
    entry.name = parts.empty() ? "" : parts[0];
    const auto& names = kolize::broadphaseNames();
    if (std::find(names.begin(), names.end(), entry.name) == names.end() &&
        !kolize::isStoreOnly(entry.name)) {
        fail("unknown broadphase '" + entry.name + "'; valid: " + kolize::broadphaseNameList() +
             ", store-only");
    }
    for (std::size_t i = 1; i < parts.size(); ++i) {
        const std::vector<std::string> keyValue = split(parts[i], '=');
        if (keyValue.size() != 2) {
            fail("setting '" + parts[i] + "' of '" + text + "' is not KEY=VALUE");
        }
        const std::string& key = keyValue[0];
        const std::string& word = keyValue[1];
        if (key == "traversal" && (word == "thesis" || word == "stabbing")) {
            entry.settings.segmentTrees.traversal =
                word == "thesis" ? kolize::SegmentTreeSettings::Traversal::ThesisFlags
                                 : kolize::SegmentTreeSettings::Traversal::Stabbing;
            continue;
        }
        if (key == "incremental" && (word == "on" || word == "off")) {
            entry.settings.segmentTrees.incremental = entry.settings.rangeTree.incremental =
                word == "on";
            continue;
        }
        if (key == "cache" && (word == "merged" || word == "hashed")) {
            entry.settings.ownPairCache = kolize::pairCacheNamed(word);
            continue;
        }
        if (key == "lists" && (word == "search" || word == "whole")) {
            entry.settings.rangeTree.searchSortedLists = word == "search";
            continue;
        }
        const double value = number(key, word);
        if (key == "divisions") {
            entry.settings.segmentTrees.cells.divisions = entry.settings.rangeTree.cells.divisions =
                static_cast<int>(value);
        } else if (key == "unit") {
            entry.settings.segmentTrees.cells.unit = entry.settings.rangeTree.cells.unit = value;
        } else if (key == "cell") {
            entry.settings.cells.cellSize = value;
        } else if (key == "factor") {
            entry.settings.cells.sizeFactor = value;
        } else if (key == "cells-per-object") {
            entry.settings.cells.cellsPerObject = value;
        } else if (key == "per-axis") {
            entry.settings.cells.cellsPerAxis = static_cast<int>(value);
        } else {
            fail("unknown setting '" + key + "' in '" + text +
                 "' (cell, factor, cells-per-object, per-axis, divisions, unit, "
                 "traversal=thesis|stabbing, incremental=on|off, lists=search|whole, "
                 "cache=merged|hashed)");
        }
    }
    return entry;
}

Options parse(int argc, char** argv) {
    Options options;
    std::vector<std::string> broadphases;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--help" || flag == "-h") {
            std::printf(kUsage, kolize::broadphaseNameList().c_str());
            std::exit(0);
        }
        if (i + 1 >= argc) {
            fail(flag.rfind("--", 0) == 0 ? flag + " needs a value"
                                          : "unknown argument '" + flag + "'");
        }
        const std::string value = argv[++i];
        if (flag == "--scene") {
            if (value == "A") {
                options.layouts = {ThesisLayout::Uniform};
            } else if (value == "B") {
                options.layouts = {ThesisLayout::Clustered};
            } else if (value != "all") {
                fail("--scene takes A, B or all, got '" + value + "'");
            }
        } else if (flag == "--motion") {
            if (value == "slow") {
                options.motions = {ThesisMotion::Slow};
            } else if (value == "fast") {
                options.motions = {ThesisMotion::Fast};
            } else if (value != "all") {
                fail("--motion takes slow, fast or all, got '" + value + "'");
            }
        } else if (flag == "--n") {
            options.counts.clear();
            for (const std::string& item : split(value, ',')) {
                const double n = number("--n", item);
                if (n != std::floor(n) || n > 5e6) {
                    fail("--n needs whole numbers up to 5000000, got '" + item + "'");
                }
                options.counts.push_back(static_cast<int>(n));
            }
        } else if (flag == "--frames") {
            const double frames = number("--frames", value);
            if (frames != std::floor(frames) || frames > 1e6) {
                fail("--frames needs a whole number, got '" + value + "'");
            }
            options.frames = static_cast<int>(frames);
        } else if (flag == "--broadphase") {
            broadphases = split(value, ',');
        } else if (flag == "--s-sweep") {
            for (const std::string& item : split(value, ',')) {
                const double divisions = number("--s-sweep", item);
                if (divisions != std::floor(divisions) || divisions > 1e7) {
                    fail("--s-sweep needs whole numbers, got '" + item + "'");
                }
                options.sweep.push_back(static_cast<int>(divisions));
            }
        } else if (flag == "--seed") {
            options.seed = static_cast<std::uint32_t>(number("--seed", value));
        } else if (flag == "--csv") {
            options.csv = value;
        } else if (flag == "--cache-share") {
            if (value != "on" && value != "off") {
                fail("--cache-share takes on or off, got '" + value + "'");
            }
            options.cacheShare = value == "on";
        } else {
            fail("unknown option '" + flag + "'");
        }
    }
    if (broadphases.empty() && !options.sweep.empty()) {
        broadphases = {"segment-trees", "range-tree"};
    } else if (broadphases.empty()) {
        for (const std::string& name : kolize::broadphaseNames()) {
            if (kolize::isExactBroadphase(name) && name != "brute-force") {
                broadphases.push_back(name);
            }
        }
        broadphases.insert(broadphases.end(),
                           {"grid:per-axis=17", "spatial-tree:per-axis=17", "dbvt", "sap",
                            "sap-noray", "sap32", "brute-force", "store-only"});
    }
    options.broadphases = broadphases;
    for (const std::string& text : broadphases) {
        parseEntry(text);  // fails early on a bad entry
    }
    return options;
}

using kolize::median;

struct Row {
    std::string label;
    std::string skipped;  ///< why the run was skipped, or empty
    double initMs = 0;
    double frameMs = 0;
    std::size_t pairs = 0;
    std::size_t missing = 0;
    std::size_t extra = 0;
    std::size_t candidates = 0;  ///< kolize broadphases: candidates in the last frame
    std::size_t peakBytes = 0;
    /// --cache-share, the run with CountingPairCache: pairs added and removed per frame.
    double addedPerFrame = 0, removedPerFrame = 0;
};

/// A pair cache that only counts: what a broadphase's frame costs without Bullet's pair
/// cache (its hashing, the filters it asks, the pair records). For --cache-share.
class CountingPairCache : public btHashedOverlappingPairCache {
  public:
    btBroadphasePair* addOverlappingPair(btBroadphaseProxy*, btBroadphaseProxy*) override {
        ++count;
        ++added;
        return &dummy;
    }
    void* removeOverlappingPair(btBroadphaseProxy*, btBroadphaseProxy*, btDispatcher*) override {
        --count;
        ++removed;
        return nullptr;
    }
    int getNumOverlappingPairs() const override { return count; }
    btBroadphasePair dummy;
    int count = 0;
    std::size_t added = 0, removed = 0;
};

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

btVector3 vec(const std::array<double, 3>& v) {
    return btVector3(btScalar(v[0]), btScalar(v[1]), btScalar(v[2]));
}

/// One broadphase on one scene. `counting`: into a CountingPairCache (no error check).
Row run(const Entry& entry, const kolize::ThesisSceneSettings& sceneSettings, int frames,
        bool counting = false) {
    Row row;
    row.label = entry.label;
    const int n = sceneSettings.objects;
    row.skipped = kolize::measurementSkipReason(entry.name, n);
    if (!row.skipped.empty()) {
        return row;
    }
    kolize::ThesisScene<3> scene(sceneSettings);
    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher(&configuration);
    kolize::BroadphaseSettings settings = entry.settings;
    const btScalar bound = btScalar(sceneSettings.halfSpace * 1.01);
    settings.worldMin = btVector3(-bound, -bound, -bound);
    settings.worldMax = btVector3(bound, bound, bound);
    settings.maxProxies = std::max(n + 2, 2);
    CountingPairCache countingCache;
    if (counting) {
        settings.pairCache = &countingCache;
    }
    kolize::bench::resetPeak();
    std::unique_ptr<btBroadphaseInterface> broadphase =
        kolize::makeMeasuredBroadphase(entry.name, settings);
    std::vector<btBroadphaseProxy*> proxies(static_cast<std::size_t>(n));
    const Clock::time_point initStart = Clock::now();
    for (int i = 0; i < n; ++i) {
        const auto& box = scene.boxes()[static_cast<std::size_t>(i)];
        proxies[static_cast<std::size_t>(i)] = broadphase->createProxy(
            vec(box.lo), vec(box.hi), BOX_SHAPE_PROXYTYPE,
            reinterpret_cast<void*>(static_cast<std::uintptr_t>(i + 1)), 1, -1, &dispatcher);
    }
    broadphase->calculateOverlappingPairs(&dispatcher);
    row.initMs = msSince(initStart);
    std::vector<double> frameMs;
    const std::size_t addedBefore = countingCache.added, removedBefore = countingCache.removed;
    for (int frame = 0; frame < frames; ++frame) {
        scene.step();
        const Clock::time_point start = Clock::now();
        for (int i = 0; i < n; ++i) {
            const auto& box = scene.boxes()[static_cast<std::size_t>(i)];
            broadphase->setAabb(proxies[static_cast<std::size_t>(i)], vec(box.lo), vec(box.hi),
                                &dispatcher);
        }
        broadphase->calculateOverlappingPairs(&dispatcher);
        frameMs.push_back(msSince(start));
    }
    row.frameMs = median(frameMs);
    row.peakBytes = kolize::bench::peakBytesSinceReset();
    if (counting) {
        row.addedPerFrame = double(countingCache.added - addedBefore) / std::max(frames, 1);
        row.removedPerFrame = double(countingCache.removed - removedBefore) / std::max(frames, 1);
        for (btBroadphaseProxy* proxy : proxies) {
            broadphase->destroyProxy(proxy, &dispatcher);
        }
        broadphase.reset();  // before its pair cache
        return row;
    }
    // Errors of the last frame against the exact truth.
    std::vector<kolize::ProxyBox> boxes;
    boxes.reserve(proxies.size());
    for (int i = 0; i < n; ++i) {
        const auto& box = scene.boxes()[static_cast<std::size_t>(i)];
        boxes.push_back({proxies[static_cast<std::size_t>(i)], vec(box.lo), vec(box.hi)});
    }
    const std::vector<kolize::UidPair> reported =
        kolize::cachedPairs(*broadphase->getOverlappingPairCache());
    const kolize::PairDifference difference =
        kolize::comparePairs(kolize::exactPairs(boxes, nullptr), reported);
    row.pairs = reported.size();
    row.missing = difference.missing.size();
    row.extra = difference.extra.size();
    if (const auto* ours = dynamic_cast<const kolize::BroadphaseAdapter*>(broadphase.get())) {
        row.candidates = ours->stats().candidatesLastFrame;
    }
    for (btBroadphaseProxy* proxy : proxies) {
        broadphase->destroyProxy(proxy, &dispatcher);
    }
    return row;
}

bool isBullet(const std::string& name) {
    return !kolize::isExactBroadphase(name) && name != "simple" && !kolize::isStoreOnly(name);
}

void progress(const std::string& what) {
    static const bool terminal = isatty(STDERR_FILENO) != 0;
    if (terminal) {
        std::fprintf(stderr, "\r%-70s", what.c_str());
    }
}

kolize::ThesisSceneSettings sceneFor(const Options& options, ThesisLayout layout,
                                     ThesisMotion motion, int n) {
    kolize::ThesisSceneSettings settings;
    settings.layout = layout;
    settings.motion = motion;
    settings.objects = n;
    settings.seed = options.seed;
    return settings;
}

/// The thesis's S sweep (its tables 2.1 and 2.2): every tree broadphase with each S, the
/// frame time against the cost of quantisation (candidates the exact test rejected).
void sweepDivisions(const Options& options, const std::vector<Entry>& entries) {
    for (const Entry& entry : entries) {
        if (entry.name != "segment-trees" && entry.name != "range-tree") {
            fail("--s-sweep takes segment-trees and range-tree only, got '" + entry.label + "'");
        }
    }
    std::printf(
        "S sweep: leaf width U = tuned scene extent / S; rejected = candidates the exact box "
        "test turned down (the cost of quantisation)\n");
    for (ThesisLayout layout : options.layouts) {
        for (ThesisMotion motion : options.motions) {
            for (int n : options.counts) {
                const kolize::ThesisSceneSettings sceneSettings =
                    sceneFor(options, layout, motion, n);
                std::printf("\nscene %s, %s motion, N = %d, %d frames\n",
                            kolize::layoutName(layout), kolize::motionName(motion), n,
                            options.frames);
                std::printf("| %-26s | %6s | %9s | %10s | %8s | %10s | %9s |\n", "broadphase", "S",
                            "frame ms", "candidates", "pairs", "rejected", "rejected%");
                std::printf("|%s|%s|%s|%s|%s|%s|%s|\n", std::string(28, '-').c_str(),
                            std::string(8, '-').c_str(), std::string(11, '-').c_str(),
                            std::string(12, '-').c_str(), std::string(10, '-').c_str(),
                            std::string(12, '-').c_str(), std::string(11, '-').c_str());
                for (const Entry& base : entries) {
                    for (int divisions : options.sweep) {
                        Entry entry = base;
                        entry.settings.segmentTrees.cells.divisions = divisions;
                        entry.settings.rangeTree.cells.divisions = divisions;
                        progress("S sweep " + entry.label + " S=" + std::to_string(divisions));
                        const Row row = run(entry, sceneSettings, options.frames);
                        progress("");
                        const std::size_t rejected =
                            row.candidates > row.pairs ? row.candidates - row.pairs : 0;
                        std::printf(
                            "| %-26s | %6d | %9.4f | %10zu | %8zu | %10zu | %8.1f%% |\n",
                            entry.label.c_str(), divisions, row.frameMs, row.candidates, row.pairs,
                            rejected,
                            row.candidates > 0 ? 100.0 * double(rejected) / row.candidates : 0.0);
                    }
                }
                std::fflush(stdout);
            }
        }
    }
}

/// One broadphase's frame times under slow and fast motion (thesis table 2.7).
struct MotionPair {
    ThesisLayout layout;
    int n;
    std::string label;
    double slowMs = -1;
    double fastMs = -1;
};

void printMotionTable(const std::vector<MotionPair>& pairs) {
    std::printf(
        "\nslow against fast motion (thesis table 2.7): frame ms, and fast / slow\n"
        "| %-5s | %7s | %-26s | %9s | %9s | %9s |\n",
        "scene", "N", "broadphase", "slow ms", "fast ms", "fast/slow");
    std::printf("|%s|%s|%s|%s|%s|%s|\n", std::string(7, '-').c_str(), std::string(9, '-').c_str(),
                std::string(28, '-').c_str(), std::string(11, '-').c_str(),
                std::string(11, '-').c_str(), std::string(11, '-').c_str());
    for (const MotionPair& pair : pairs) {
        if (pair.slowMs < 0 || pair.fastMs < 0) {
            continue;
        }
        std::printf("| %-5s | %7d | %-26s | %9.4f | %9.4f | %9.2f |\n",
                    kolize::layoutName(pair.layout), pair.n, pair.label.c_str(), pair.slowMs,
                    pair.fastMs, pair.slowMs > 0 ? pair.fastMs / pair.slowMs : 0.0);
    }
}

}  // namespace

int main(int argc, char** argv) {
    kolize::bench::countBulletAllocations();
    const Options options = parse(argc, argv);
    std::vector<Entry> entries;
    for (const std::string& text : options.broadphases) {
        entries.push_back(parseEntry(text));
    }
    std::FILE* csv = nullptr;
    if (!options.csv.empty()) {
        csv = std::fopen(options.csv.c_str(), "w");
        if (csv == nullptr) {
            fail("cannot write '" + options.csv + "'");
        }
        std::fprintf(csv,
                     "scene,motion,n,broadphase,skipped,init_ms,frame_ms,ratio_to_best_bullet,"
                     "pairs,missing,extra,candidates,peak_bytes,x_store_only\n");
    }
    std::printf(
        "kolize-bench: thesis scenes, Bullet %d, %s precision, seed %u; frame = setAabb "
        "x N + calculateOverlappingPairs; times are medians; errors in the last frame\n",
        btGetVersion(), sizeof(btScalar) == 8 ? "double" : "float", options.seed);
    if (!options.sweep.empty()) {
        sweepDivisions(options, entries);
        return 0;
    }
    std::vector<MotionPair> motionPairs;
    for (ThesisLayout layout : options.layouts) {
        for (ThesisMotion motion : options.motions) {
            for (int n : options.counts) {
                const kolize::ThesisSceneSettings sceneSettings =
                    sceneFor(options, layout, motion, n);
                const int frames = n >= 100000 ? std::min(options.frames, 15) : options.frames;
                std::vector<Row> rows;
                for (const Entry& entry : entries) {
                    progress(std::string("scene ") + kolize::layoutName(layout) + " " +
                             kolize::motionName(motion) + " N=" + std::to_string(n) + ": " +
                             entry.label);
                    rows.push_back(run(entry, sceneSettings, frames));
                }
                progress("");
                double best = 0;
                std::string bestName;
                for (std::size_t i = 0; i < rows.size(); ++i) {
                    if (rows[i].skipped.empty() && isBullet(entries[i].name) &&
                        (best == 0 || rows[i].frameMs < best)) {
                        best = rows[i].frameMs;
                        bestName = rows[i].label;
                    }
                }
                // The lower bound measured in this run: store-only's frame time.
                double storeOnly = 0;
                for (std::size_t i = 0; i < rows.size(); ++i) {
                    if (rows[i].skipped.empty() && kolize::isStoreOnly(entries[i].name)) {
                        storeOnly = rows[i].frameMs;
                    }
                }
                auto timesStoreOnly = [&](const Row& row) {
                    return storeOnly > 0 && row.skipped.empty() ? row.frameMs / storeOnly : 0.0;
                };
                std::printf(
                    "\nscene %s, %s motion, N = %d, %d frames (ratio: frame time / best "
                    "of Bullet's, %s)\n",
                    kolize::layoutName(layout), kolize::motionName(motion), n, frames,
                    bestName.empty() ? "none run" : bestName.c_str());
                std::printf("| %-26s | %9s | %9s | %6s | %8s | %7s | %7s | %10s | %8s | %7s |\n",
                            "broadphase", "init ms", "frame ms", "ratio", "pairs", "missing",
                            "extra", "candidates", "peak MiB", "x store");
                std::printf("|%s|%s|%s|%s|%s|%s|%s|%s|%s|%s|\n", std::string(28, '-').c_str(),
                            std::string(11, '-').c_str(), std::string(11, '-').c_str(),
                            std::string(8, '-').c_str(), std::string(10, '-').c_str(),
                            std::string(9, '-').c_str(), std::string(9, '-').c_str(),
                            std::string(12, '-').c_str(), std::string(10, '-').c_str(),
                            std::string(9, '-').c_str());
                for (const Row& row : rows) {
                    if (!row.skipped.empty()) {
                        std::printf("| %-26s | skipped: %s\n", row.label.c_str(),
                                    row.skipped.c_str());
                    } else {
                        char candidates[32] = "-";
                        if (kolize::isExactBroadphase(split(row.label, ':')[0])) {
                            std::snprintf(candidates, sizeof candidates, "%zu", row.candidates);
                        }
                        char store[32] = "-";
                        if (storeOnly > 0) {
                            std::snprintf(store, sizeof store, "%.1f", timesStoreOnly(row));
                        }
                        std::printf(
                            "| %-26s | %9.3f | %9.4f | %6.3f | %8zu | %7zu | %7zu | %10s | %8.2f "
                            "| %7s |\n",
                            row.label.c_str(), row.initMs, row.frameMs,
                            best > 0 ? row.frameMs / best : 0.0, row.pairs, row.missing, row.extra,
                            candidates, double(row.peakBytes) / (1024.0 * 1024.0), store);
                    }
                    if (row.skipped.empty()) {
                        auto same = [&](const MotionPair& pair) {
                            return pair.layout == layout && pair.n == n && pair.label == row.label;
                        };
                        auto at = std::find_if(motionPairs.begin(), motionPairs.end(), same);
                        if (at == motionPairs.end()) {
                            at = motionPairs.insert(motionPairs.end(),
                                                    MotionPair{layout, n, row.label});
                        }
                        (motion == ThesisMotion::Slow ? at->slowMs : at->fastMs) = row.frameMs;
                    }
                    if (csv != nullptr) {
                        std::fprintf(csv, "%s,%s,%d,%s,%s,%.6f,%.6f,%.6f,%zu,%zu,%zu,%zu,%zu,",
                                     kolize::layoutName(layout), kolize::motionName(motion), n,
                                     row.label.c_str(), row.skipped.c_str(), row.initMs,
                                     row.frameMs, best > 0 ? row.frameMs / best : 0.0, row.pairs,
                                     row.missing, row.extra, row.candidates, row.peakBytes);
                        // x_store_only: empty when store-only did not run.
                        if (timesStoreOnly(row) > 0) {
                            std::fprintf(csv, "%.4f", timesStoreOnly(row));
                        }
                        std::fprintf(csv, "\n");
                    }
                }
                for (std::size_t at = 0; options.cacheShare && at < rows.size(); ++at) {
                    const Row& row = rows[at];
                    if (!row.skipped.empty() || !kolize::isExactBroadphase(entries[at].name)) {
                        continue;
                    }
                    progress(entries[at].label + " with a counting pair cache");
                    const Row bare = run(entries[at], sceneSettings, frames, true);
                    progress("");
                    std::printf(
                        "pair cache share, %s: %.4f ms per frame, %.4f with a pair cache that "
                        "only counts: %s %.4f ms (%.0f%%); %.0f pairs added and "
                        "%.0f removed per frame\n",
                        row.label.c_str(), row.frameMs, bare.frameMs,
                        entries[at].settings.ownPairCache == kolize::PairCacheChoice::Merged
                            ? "the merged pair cache"
                            : "Bullet's pair cache",
                        row.frameMs - bare.frameMs,
                        row.frameMs > 0 ? 100 * (row.frameMs - bare.frameMs) / row.frameMs : 0.0,
                        bare.addedPerFrame, bare.removedPerFrame);
                }
                std::fflush(stdout);
            }
        }
    }
    if (options.motions.size() > 1) {
        printMotionTable(motionPairs);
    }
    if (csv != nullptr) {
        std::fclose(csv);
    }
    return 0;
}

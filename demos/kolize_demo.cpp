// kolize-demo: the falling-boxes world (Bullet benchmark style) run with every broadphase,
// side by side in one process: step time, broadphase time, pairs, and pair errors against
// the exact truth, checked every frame.

#include <kolize/engine/falling_boxes.h>
#include <kolize/engine/pair_compare.h>
#include <kolize/engine/statistics.h>
#include <kolize/engine/pair_stream.h>
#include <kolize/kolize.h>

#include <btBulletDynamicsCommon.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using kolize::FallingBoxesSettings;

const char* kUsage =
    "usage: kolize-demo [options]\n"
    "  --broadphase NAME|all   broadphase to run (default all): %s\n"
    "  --frames N              steps per run (default 200)\n"
    "  --layers N              layers of 8 x 8 boxes (default 47: 3008 boxes)\n"
    "  --ground box|plane|both static ground (default both)\n"
    "  --record FILE           record the first run's broadphase calls as a pair stream\n"
    "  --replay FILE           replay a pair stream into the broadphases instead\n"
    "  --help                  this text\n";

struct Options {
    std::vector<std::string> broadphases = kolize::broadphaseNames();
    int frames = 200;
    int layers = 47;
    std::vector<bool> planeGrounds = {false, true};
    std::string record;
    std::string replay;
};

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "kolize-demo: %s (try --help)\n", message.c_str());
    std::exit(2);
}

int positive(const std::string& flag, const char* text) {
    char* end = nullptr;
    const long value = std::strtol(text, &end, 10);
    if (end == text || *end != '\0' || value <= 0 || value > 1000000) {
        fail(flag + " needs a positive whole number, got '" + text + "'");
    }
    return static_cast<int>(value);
}

Options parse(int argc, char** argv) {
    Options options;
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
        const char* value = argv[++i];
        if (flag == "--broadphase") {
            const auto& names = kolize::broadphaseNames();
            if (std::string(value) == "all") {
                options.broadphases = names;
            } else if (std::find(names.begin(), names.end(), value) != names.end()) {
                options.broadphases = {value};
            } else {
                fail(std::string("unknown broadphase '") + value + "'; valid: all, " +
                     kolize::broadphaseNameList());
            }
        } else if (flag == "--frames") {
            options.frames = positive(flag, value);
        } else if (flag == "--layers") {
            options.layers = positive(flag, value);
        } else if (flag == "--ground") {
            const std::string ground = value;
            if (ground == "box") {
                options.planeGrounds = {false};
            } else if (ground == "plane") {
                options.planeGrounds = {true};
            } else if (ground == "both") {
                options.planeGrounds = {false, true};
            } else {
                fail("--ground takes box, plane or both, got '" + ground + "'");
            }
        } else if (flag == "--record") {
            options.record = value;
        } else if (flag == "--replay") {
            options.replay = value;
        } else {
            fail("unknown option '" + flag + "'");
        }
    }
    return options;
}

using kolize::median;

struct Row {
    std::string broadphase;
    double stepMs = 0;
    double broadphaseMs = 0;
    std::size_t pairs = 0;
    std::size_t falseNegatives = 0;
    std::size_t falsePositives = 0;
};

void progress(const std::string& what, int done, int total) {
    static const bool terminal = isatty(STDERR_FILENO) != 0;
    if (terminal) {
        std::fprintf(stderr, "\r%-40s %4d/%d", what.c_str(), done, total);
        if (done == total) {
            std::fprintf(stderr, "\n");
        }
    } else if (done == total) {
        std::fprintf(stderr, "%s: %d frames done\n", what.c_str(), total);
    }
}

Row runWorld(const std::string& name, const FallingBoxesSettings& settings, int frames,
             kolize::PairStream* record) {
    std::unique_ptr<btBroadphaseInterface> inner = kolize::makeBroadphase(name);
    std::unique_ptr<btBroadphaseInterface> broadphase;
    std::unique_ptr<btBroadphaseInterface> keepInner;
    if (record != nullptr) {
        broadphase = std::make_unique<kolize::RecordingBroadphase>(*inner, *record);
        keepInner = std::move(inner);
    } else {
        broadphase = std::move(inner);
    }
    kolize::FallingBoxesWorld scene(std::move(broadphase), settings);
    const btOverlappingPairCache* cache = scene.broadphase().getOverlappingPairCache();
    std::vector<double> stepMs, broadphaseMs;
    Row row{name};
    const std::string label =
        std::string(settings.groundIsPlane ? "plane" : "box") + " ground, " + name;
    for (int frame = 0; frame < frames; ++frame) {
        const auto start = std::chrono::steady_clock::now();
        scene.step();
        stepMs.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
        broadphaseMs.push_back(1000 * scene.lastBroadphaseSeconds());
        const std::vector<kolize::UidPair> reported = kolize::cachedPairs(*cache);
        const kolize::PairDifference difference =
            kolize::comparePairs(kolize::exactPairs(scene.proxyBoxes(), cache), reported);
        row.falseNegatives += difference.missing.size();
        row.falsePositives += difference.extra.size();
        row.pairs = reported.size();
        if (frame % 10 == 9 || frame + 1 == frames) {
            progress(label, frame + 1, frames);
        }
    }
    row.stepMs = median(stepMs);
    row.broadphaseMs = median(broadphaseMs);
    return row;
}

void printTable(const std::string& title, const std::vector<Row>& rows) {
    std::printf("\n%s\n", title.c_str());
    std::printf("| %-13s | %14s | %20s | %8s | %15s | %15s |\n", "broadphase", "median step ms",
                "median broadphase ms", "pairs", "false negatives", "false positives");
    std::printf("|%s|%s|%s|%s|%s|%s|\n", std::string(15, '-').c_str(), std::string(16, '-').c_str(),
                std::string(22, '-').c_str(), std::string(10, '-').c_str(),
                std::string(17, '-').c_str(), std::string(17, '-').c_str());
    for (const Row& row : rows) {
        // A replay has no world step: its step column shows "-".
        char step[32] = "-";
        if (row.stepMs >= 0) {
            std::snprintf(step, sizeof step, "%.3f", row.stepMs);
        }
        std::printf("| %-13s | %14s | %20.3f | %8zu | %15zu | %15zu |\n", row.broadphase.c_str(),
                    step, row.broadphaseMs, row.pairs, row.falseNegatives, row.falsePositives);
    }
    std::fflush(stdout);
}

int replayStream(const Options& options) {
    kolize::PairStream stream;
    try {
        stream = kolize::PairStream::load(options.replay);
    } catch (const std::exception& error) {
        fail(error.what());
    }
    std::vector<Row> rows;
    for (const std::string& name : options.broadphases) {
        const kolize::ReplayResult result = kolize::replay(stream, name);
        Row row{name};
        row.stepMs = -1;
        row.broadphaseMs = 1000 * result.medianFrameSeconds();
        row.pairs = result.frames.empty() ? 0 : result.frames.back().reportedPairs;
        row.falseNegatives = result.totalMissing();
        row.falsePositives = result.totalExtra();
        rows.push_back(row);
        progress("replay " + name, static_cast<int>(result.frames.size()),
                 static_cast<int>(result.frames.size()));
    }
    printTable("replay of " + options.replay + " (" + std::to_string(stream.frames()) +
                   " frames; no world step; broadphase ms = setAabb calls + pairs)",
               rows);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const Options options = parse(argc, argv);
    if (!options.replay.empty()) {
        return replayStream(options);
    }
    FallingBoxesSettings settings;
    settings.layers = options.layers;
    const int boxes = settings.layers * settings.boxesPerRow * settings.boxesPerRow;
    std::printf(
        "kolize-demo: %d falling unit boxes (%d layers of %d x %d), %d frames of 1/60 s, "
        "Bullet %d, %s precision; false negatives / positives summed over all frames, "
        "against the exact AABB pairs\n",
        boxes, settings.layers, settings.boxesPerRow, settings.boxesPerRow, options.frames,
        btGetVersion(), sizeof(btScalar) == 8 ? "double" : "float");
    kolize::PairStream stream;
    bool recorded = false;
    for (bool plane : options.planeGrounds) {
        settings.groundIsPlane = plane;
        std::vector<Row> rows;
        for (const std::string& name : options.broadphases) {
            const bool recordThis = !options.record.empty() && !recorded;
            rows.push_back(
                runWorld(name, settings, options.frames, recordThis ? &stream : nullptr));
            recorded = recorded || recordThis;
        }
        printTable(plane ? "ground: static plane (AABB +-1e18)" : "ground: static box", rows);
    }
    if (!options.record.empty()) {
        try {
            stream.save(options.record);
        } catch (const std::exception& error) {
            fail(error.what());
        }
        std::printf("\nrecorded %zu frames to %s\n", stream.frames(), options.record.c_str());
    }
    return 0;
}

// kolize-demo: any registered scene (the thesis's streams, Bullet-benchmark worlds, meshes,
// extreme and stiff cases) run with every chosen broadphase side by side in one process.
// Per run: init and per-frame times, pairs and their errors against the exact truth checked
// every frame, the dynamics' health (penetration, escaped bodies, NaN, energy), optionally
// drift from a fine-step reference, a replay of one recorded stream into every broadphase,
// and a bit-for-bit comparison with btSimpleBroadphase under deterministic pair order.

#include "common/cli.h"

#include <kolize/engine/pair_compare.h>
#include <kolize/engine/pair_stream.h>
#include <kolize/engine/scene.h>
#include <kolize/engine/statistics.h>
#include <kolize/engine/store_only.h>
#include <kolize/engine/world_scene.h>
#include <kolize/broadphase/bullet_adapter.h>
#include <kolize/kolize.h>
#include <kolize/narrowphase/mesh_stages.h>

#include <btBulletDynamicsCommon.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

const char* kUsage =
    "usage: kolize-demo [options]\n"
    "Runs scenes with broadphases side by side; checks every frame's pairs against the exact\n"
    "AABB pairs and reports times (medians over frames), errors and the dynamics' health.\n"
    "  --scene NAME|LIST|all     scenes, comma separated (default boxes,boxes-plane)\n"
    "  --broadphase NAME|LIST|all  broadphases, comma separated (default all); a kolize\n"
    "                            broadphase may carry :cache=merged or :cache=hashed\n"
    "  --n N                     moving objects (default: the scene's own count)\n"
    "  --frames F                frames per run (default 200)\n"
    "  --seed S                  scene seed (default 1)\n"
    "  --motion slow|fast        speed of the thesis scenes (default slow)\n"
    "  --timestep T              seconds per frame, e.g. 0.01 or 1/60 (default 1/60)\n"
    "  --substeps K              solver steps per frame, each T/K (default 1)\n"
    "  --bullet-ccd auto|on|off  Bullet's own CCD for dynamic bodies (default auto: on in\n"
    "                            scenes with fast objects; kolize mesh bodies: its mesh CCD)\n"
    "  --mesh-method M           kolize, gimpact or gimpact-0: how the mesh-world scenes'\n"
    "                            meshes collide (default kolize; kolize-mesh-world compares)\n"
    "  --reference-substeps K    also run each scene with K times the substeps and report\n"
    "                            the bodies' drift from it at the last frame\n"
    "  --pair-cache hashed|merged  kolize broadphases: Bullet's hashed pair cache (the\n"
    "                            default) or kolize's MergedPairCache\n"
    "  --fat-margin F            kolize broadphases: fat-box margin, a fraction of each\n"
    "                            box's extent (default 0.05; 0 turns fat boxes off)\n"
    "  --replay-check            record an untimed run of the first broadphase and replay\n"
    "                            that one stream into every broadphase (identical input)\n"
    "  --determinism             Bullet's deterministic pair order on; compare every body\n"
    "                            bit for bit with a run of `simple`, every frame\n"
    "  --record FILE             record the first scene's broadphase calls (an untimed run of\n"
    "                            the first broadphase) as a pair stream\n"
    "  --replay FILE             replay a pair stream into the broadphases instead\n"
    "  --replay-rounds R         replays interleave the broadphases in R rounds; each one's\n"
    "                            time is the median of its rounds (default 3)\n"
    "  --csv FILE, --json FILE   also write one record per run\n"
    "  --list-scenes             print the scenes as CSV and exit\n"
    "  --help                    this text\n"
    "scenes: %s\n"
    "broadphases: %s\n";

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "kolize-demo: %s (try --help)\n", message.c_str());
    std::exit(2);
}

struct Options {
    std::vector<std::string> scenes = {"boxes", "boxes-plane"};
    std::vector<std::string> broadphases = kolize::broadphaseNames();
    kolize::SceneOptions scene;
    int frames = 200;
    int referenceSubsteps = 0;
    double fatMargin = -1;  ///< < 0: the broadphases' default
    std::string pairCache;  ///< empty: the broadphases' default
    int replayRounds = 3;
    bool replayCheck = false;
    bool determinism = false;
    std::string record, replay, csv, json;
};

std::vector<std::string> sceneNames() {
    std::vector<std::string> out;
    for (const kolize::SceneInfo& info : kolize::sceneList()) {
        out.push_back(info.name);
    }
    return out;
}

void listScenes() {
    std::printf("name,group,objects,dynamics,rays,meshes,continuous,summary\n");
    for (const kolize::SceneInfo& info : kolize::sceneList()) {
        std::printf("%s,%s,%d,%d,%d,%d,%d,\"%s\"\n", info.name.c_str(), info.group.c_str(),
                    info.defaultObjects, info.needs.dynamics, info.needs.rays, info.needs.meshes,
                    info.needs.continuous, info.summary.c_str());
    }
}

/// A --broadphase entry is a name, or a kolize broadphase's name with ":cache=merged" or
/// ":cache=hashed" (the pair cache it makes), so that both caches run side by side.
constexpr std::string_view kCacheSetting = ":cache=";

std::string baseName(const std::string& entry) { return entry.substr(0, entry.find(':')); }

kolize::BroadphaseSettings forEntry(kolize::BroadphaseSettings settings, const std::string& entry) {
    const std::size_t at = entry.find(kCacheSetting);
    if (at != std::string::npos) {
        settings.ownPairCache = kolize::pairCacheNamed(entry.substr(at + kCacheSetting.size()));
    }
    return settings;
}

std::vector<std::string> broadphaseEntries(const std::string& flag, const std::string& value,
                                           kolize::demo::Fail fail) {
    std::vector<std::string> out;
    for (const std::string& item : kolize::demo::split(value, ',')) {
        const std::string base = baseName(item), suffix = item.substr(base.size());
        if (!suffix.empty()) {
            const std::string cache = suffix.substr(std::min(suffix.size(), kCacheSetting.size()));
            if (suffix.compare(0, kCacheSetting.size(), kCacheSetting) != 0 ||
                (cache != "merged" && cache != "hashed") || !kolize::isExactBroadphase(base)) {
                fail(flag + ": '" + item + "': a kolize broadphase takes :cache=merged or " +
                     ":cache=hashed, nothing else");
            }
        }
        for (const std::string& name :
             kolize::demo::chosen(flag, base, kolize::broadphaseNames(), fail)) {
            out.push_back(name + suffix);
        }
    }
    if (out.empty()) {
        fail(flag + " needs at least one name");
    }
    return out;
}

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--help" || flag == "-h") {
            std::printf(kUsage, kolize::sceneNameList().c_str(),
                        kolize::broadphaseNameList().c_str());
            std::exit(0);
        }
        if (flag == "--list-scenes") {
            listScenes();
            std::exit(0);
        }
        if (flag == "--replay-check" || flag == "--determinism") {
            (flag == "--determinism" ? options.determinism : options.replayCheck) = true;
            continue;
        }
        if (flag.rfind("--", 0) != 0) {
            fail("unknown argument '" + flag + "'");
        }
        if (i + 1 >= argc) {
            fail(flag + " needs a value");
        }
        const std::string value = argv[++i];
        if (flag == "--scene") {
            options.scenes = kolize::demo::chosen(flag, value, sceneNames(), fail);
        } else if (flag == "--broadphase") {
            options.broadphases = broadphaseEntries(flag, value, fail);
        } else if (flag == "--n") {
            options.scene.objects = int(kolize::demo::wholeNumber(flag, value, 1, 10000000, fail));
        } else if (flag == "--frames") {
            options.frames = int(kolize::demo::wholeNumber(flag, value, 1, 1000000, fail));
        } else if (flag == "--replay-rounds") {
            options.replayRounds = int(kolize::demo::wholeNumber(flag, value, 1, 100, fail));
        } else if (flag == "--seed") {
            options.scene.seed =
                std::uint32_t(kolize::demo::wholeNumber(flag, value, 0, 4294967295L, fail));
        } else if (flag == "--motion") {
            if (value != "slow" && value != "fast") {
                fail("--motion takes slow or fast, got '" + value + "'");
            }
            options.scene.motion = value;
        } else if (flag == "--timestep") {
            options.scene.timeStep = kolize::demo::seconds(flag, value, fail);
        } else if (flag == "--substeps") {
            options.scene.substeps = int(kolize::demo::wholeNumber(flag, value, 1, 1000, fail));
        } else if (flag == "--bullet-ccd") {
            if (value != "auto" && value != "on" && value != "off") {
                fail("--bullet-ccd takes auto, on or off, got '" + value + "'");
            }
            options.scene.bulletCcd = value == "auto" ? -1 : value == "on" ? 1 : 0;
        } else if (flag == "--mesh-method") {
            if (value != "kolize" && value != "gimpact" && value != "gimpact-0") {
                fail("--mesh-method takes kolize, gimpact or gimpact-0, got '" + value + "'");
            }
            options.scene.meshMethod = value;
        } else if (flag == "--reference-substeps") {
            options.referenceSubsteps = int(kolize::demo::wholeNumber(flag, value, 2, 1000, fail));
        } else if (flag == "--fat-margin") {
            options.fatMargin = kolize::demo::realNumber(flag, value, 0, 10, "a number", fail);
        } else if (flag == "--pair-cache") {
            if (value != "merged" && value != "hashed") {
                fail("--pair-cache takes merged or hashed, got '" + value + "'");
            }
            options.pairCache = value;
        } else if (flag == "--record") {
            options.record = value;
        } else if (flag == "--replay") {
            options.replay = value;
        } else if (flag == "--csv") {
            options.csv = value;
        } else if (flag == "--json") {
            options.json = value;
        } else {
            fail("unknown option '" + flag + "'");
        }
    }
    return options;
}

// --- one run's record, printed as a table row and written as CSV / JSON ---

/// A field: text, and whether JSON writes it as a number.
struct Field {
    std::string key;
    std::string text;
    bool number = false;
};

struct Record {
    std::vector<Field> fields;
    void text(const std::string& key, const std::string& value) {
        fields.push_back({key, value, false});
    }
    void number(const std::string& key, double value, int decimals = 6) {
        char buffer[64];
        std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
        fields.push_back({key, buffer, true});
    }
    void count(const std::string& key, long long value) {
        fields.push_back({key, std::to_string(value), true});
    }
    /// Not applicable: empty in CSV, null in JSON.
    void empty(const std::string& key) { fields.push_back({key, "", true}); }
    const std::string& operator[](const std::string& key) const {
        static const std::string none;
        for (const Field& field : fields) {
            if (field.key == key) {
                return field.text;
            }
        }
        return none;
    }
};

std::string csvQuoted(const std::string& text) {
    if (text.find_first_of(",\"\n") == std::string::npos) {
        return text;
    }
    std::string out = "\"";
    for (char c : text) {
        out += c == '"' ? std::string("\"\"") : std::string(1, c);
    }
    return out + "\"";
}

std::string jsonQuoted(const std::string& text) {
    std::string out = "\"";
    for (char c : text) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char buffer[8];
            std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
            out += buffer;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

void writeFiles(const Options& options, const std::vector<Record>& records) {
    if (!options.csv.empty()) {
        std::ofstream out(options.csv);
        for (std::size_t i = 0; i < records.size() && out; ++i) {
            if (i == 0) {
                for (std::size_t j = 0; j < records[i].fields.size(); ++j) {
                    out << (j ? "," : "") << records[i].fields[j].key;
                }
                out << '\n';
            }
            for (std::size_t j = 0; j < records[i].fields.size(); ++j) {
                out << (j ? "," : "") << csvQuoted(records[i].fields[j].text);
            }
            out << '\n';
        }
        if (!out) {
            fail("cannot write '" + options.csv + "'");
        }
    }
    if (!options.json.empty()) {
        std::ofstream out(options.json);
        out << "[\n";
        for (std::size_t i = 0; i < records.size(); ++i) {
            out << "  {";
            for (std::size_t j = 0; j < records[i].fields.size(); ++j) {
                const Field& field = records[i].fields[j];
                out << (j ? ", " : "") << jsonQuoted(field.key) << ": "
                    << (field.number ? (field.text.empty() ? "null" : field.text)
                                     : jsonQuoted(field.text));
            }
            out << "}" << (i + 1 < records.size() ? "," : "") << "\n";
        }
        out << "]\n";
        if (!out) {
            fail("cannot write '" + options.json + "'");
        }
    }
}

void progress(const std::string& what, int done, int total) {
    static const bool terminal = isatty(STDERR_FILENO) != 0;
    if (terminal) {
        std::fprintf(stderr, "\r%-50s %5d/%d", what.c_str(), done, total);
        if (done == total) {
            std::fprintf(stderr, "\n");
        }
    } else if (done == total) {
        std::fprintf(stderr, "%s: %d frames done\n", what.c_str(), total);
    }
}

// --- running a scene ---

struct RunResult {
    Record record;
    std::vector<btVector3> finalPositions;
    std::vector<std::uint64_t> hashes;  ///< per frame, with --determinism
    std::string stages;  ///< mesh-world scenes with kolize's narrowphase: describeStages
};

/// What the demo assembled for a scene, and why.
void printPipeline(const kolize::SceneInfo& info, const kolize::SceneOptions& options) {
    const kolize::SceneNeeds& needs = info.needs;
    std::string stages = needs.dynamics ? "Bullet world (broadphase, narrowphase, solver)"
                                        : "broadphase stream (setAabb + pair search only)";
    if (needs.rays) {
        stages += ", ray casts (timed apart)";
    }
    const bool meshBodies = info.group == "mesh-world";
    if (needs.meshes) {
        stages += meshBodies ? ", mesh bodies (" + options.meshMethod + " narrowphase)"
                             : ", triangle meshes";
    }
    const bool ccd = options.bulletCcd < 0 ? needs.continuous : options.bulletCcd > 0;
    if (needs.dynamics && ccd) {
        stages += meshBodies && options.meshMethod == "kolize" ? ", kolize's mesh CCD"
                  : meshBodies                                 ? ", no CCD (GImpact has none)"
                                                               : ", Bullet's CCD";
    }
    std::printf("pipeline: %s\n  why: %s%s\n", stages.c_str(), info.pipelineWhy.c_str(),
                needs.dynamics && options.bulletCcd >= 0 && ccd != needs.continuous
                    ? (ccd ? "; Bullet's CCD on by --bullet-ccd" : "; CCD off by --bullet-ccd")
                    : "");
}

/// `settings` with the command line's broadphase options applied.
kolize::BroadphaseSettings withOptions(kolize::BroadphaseSettings settings,
                                       const Options& options) {
    if (options.fatMargin >= 0) {
        settings.fatMargin = btScalar(options.fatMargin);
    }
    if (!options.pairCache.empty()) {
        settings.ownPairCache = kolize::pairCacheNamed(options.pairCache);
    }
    return settings;
}

kolize::BroadphaseSettings settingsFor(const kolize::SceneInfo& info,
                                       const kolize::SceneOptions& sceneOptions,
                                       const Options& options) {
    return withOptions(kolize::broadphaseSettingsFor(info, sceneOptions), options);
}

RunResult runScene(const std::string& sceneName, const std::string& name,
                   const kolize::SceneOptions& sceneOptions, const Options& options,
                   kolize::PairStream* record, bool hashes) {
    RunResult result;
    Record& r = result.record;
    const kolize::SceneInfo& info = kolize::findScene(sceneName);
    const int objects = sceneOptions.objects > 0 ? sceneOptions.objects : info.defaultObjects;
    r.text("scene", sceneName);
    r.text("broadphase", name);
    r.text("mode", "live");
    r.text("precision", sizeof(btScalar) == 8 ? "double" : "float");
    r.count("objects", objects);
    r.count("frames", options.frames);
    r.count("seed", sceneOptions.seed);
    r.text("motion", info.needs.dynamics ? "" : sceneOptions.motion);
    r.number("timestep", sceneOptions.timeStep, 8);
    r.count("substeps", sceneOptions.substeps);
    const bool ccd =
        sceneOptions.bulletCcd < 0 ? info.needs.continuous : sceneOptions.bulletCcd > 0;
    r.text("bullet_ccd", !info.needs.dynamics ? "" : ccd ? "on" : "off");
    // Room for the scene's static bodies too (broadphaseSettingsFor gives 64).
    const std::string skipped = kolize::measurementSkipReason(baseName(name), objects + 64);
    if (!skipped.empty()) {
        r.text("status", "skipped: " + skipped);
        return result;
    }
    try {
        const kolize::BroadphaseSettings settings =
            forEntry(settingsFor(info, sceneOptions, options), name);
        std::unique_ptr<btBroadphaseInterface> inner =
            kolize::makeBroadphase(baseName(name), settings);
        std::unique_ptr<btBroadphaseInterface> broadphase;
        if (record != nullptr) {
            broadphase = std::make_unique<kolize::RecordingBroadphase>(*inner, *record);
        } else {
            broadphase = std::move(inner);
        }
        const Clock::time_point initStart = Clock::now();
        std::unique_ptr<kolize::Scene> scene =
            kolize::makeScene(sceneName, std::move(broadphase), sceneOptions);
        const double initMs =
            std::chrono::duration<double, std::milli>(Clock::now() - initStart).count();
        if (hashes && scene->world() != nullptr) {
            scene->world()->getDispatchInfo().m_deterministicOverlappingPairs = true;
        }
        const btOverlappingPairCache* cache = scene->broadphase().getOverlappingPairCache();
        std::vector<double> stepMs, broadphaseMs, rayMs;
        std::size_t pairs = 0, truePairs = 0, missing = 0, extra = 0, missingFrames = 0;
        double maxPenetration = 0, energyMax = 0, energyStart = 0;
        int escaped = 0, nonFinite = 0;
        const std::string label = sceneName + ", " + name;
        for (int frame = 0; frame < options.frames; ++frame) {
            const Clock::time_point start = Clock::now();
            scene->step();
            stepMs.push_back(
                std::chrono::duration<double, std::milli>(Clock::now() - start).count());
            broadphaseMs.push_back(1000 * scene->lastBroadphaseSeconds());
            rayMs.push_back(1000 * scene->lastRaySeconds());
            const std::vector<kolize::UidPair> reported = kolize::cachedPairs(*cache);
            const std::vector<kolize::UidPair> truth =
                kolize::exactPairs(scene->proxyBoxes(), scene->filter());
            const kolize::PairDifference difference = kolize::comparePairs(truth, reported);
            missing += difference.missing.size();
            extra += difference.extra.size();
            missingFrames += difference.missing.empty() ? 0 : 1;
            pairs = reported.size();
            truePairs = truth.size();
            const kolize::SceneState state = scene->state();
            const double energy = state.kineticEnergy + state.potentialEnergy;
            if (frame == 0) {
                energyStart = energyMax = energy;
            }
            energyMax = std::max(energyMax, energy);
            maxPenetration = std::max(maxPenetration, state.maxPenetration);
            escaped = std::max(escaped, state.escaped);
            nonFinite = std::max(nonFinite, state.nonFinite);
            if (const auto* world = dynamic_cast<const kolize::WorldScene*>(scene.get());
                hashes && world != nullptr) {
                result.hashes.push_back(world->stateHash());
            }
            if (frame % 10 == 9 || frame + 1 == options.frames) {
                progress(label, frame + 1, options.frames);
            }
        }
        result.finalPositions = scene->positions();
        if (auto* world = dynamic_cast<kolize::WorldScene*>(scene.get());
            world != nullptr && info.group == "mesh-world" && sceneOptions.meshMethod == "kolize") {
            result.stages = kolize::describeStages(kolize::narrowphaseStages(&world->dispatcher()));
        }
        // What the broadphase used: for "auto", the core it chose last and why.
        const auto* adapter = dynamic_cast<const kolize::BroadphaseAdapter*>(&scene->broadphase());
        r.text("core", adapter != nullptr ? adapter->coreDescription() : name);
        r.number("init_ms", initMs, 3);
        r.number("step_ms", kolize::median(stepMs), 4);
        r.number("broadphase_ms", kolize::median(broadphaseMs), 4);
        if (info.needs.rays) {
            r.number("ray_ms", kolize::median(rayMs), 4);
        } else {
            r.empty("ray_ms");
        }
        r.count("pairs", static_cast<long long>(pairs));
        r.count("true_pairs", static_cast<long long>(truePairs));
        r.count("missing", static_cast<long long>(missing));
        r.count("extra", static_cast<long long>(extra));
        r.count("missing_frames", static_cast<long long>(missingFrames));
        if (info.needs.dynamics) {
            r.number("max_penetration", maxPenetration, 6);
            r.count("escaped", escaped);
            r.count("nonfinite", nonFinite);
            r.number("energy_start", energyStart, 3);
            r.number("energy_max", energyMax, 3);
        } else {
            for (const char* key :
                 {"max_penetration", "escaped", "nonfinite", "energy_start", "energy_max"}) {
                r.empty(key);
            }
        }
        r.text("status", "ok");
    } catch (const std::exception& error) {
        r.text("status", std::string("error: ") + error.what());
    }
    return result;
}

/// Puts the fields in the documented CSV order; absent ones empty.
Record ordered(const Record& record) {
    static const char* kKeys[] = {"scene",
                                  "broadphase",
                                  "core",
                                  "mode",
                                  "precision",
                                  "objects",
                                  "frames",
                                  "seed",
                                  "motion",
                                  "timestep",
                                  "substeps",
                                  "bullet_ccd",
                                  "init_ms",
                                  "step_ms",
                                  "broadphase_ms",
                                  "rest_ms",
                                  "rest_frames",
                                  "rounds",
                                  "ray_ms",
                                  "pairs",
                                  "true_pairs",
                                  "missing",
                                  "extra",
                                  "missing_frames",
                                  "max_penetration",
                                  "escaped",
                                  "nonfinite",
                                  "energy_start",
                                  "energy_max",
                                  "drift_mean",
                                  "drift_max",
                                  "identical_to_simple",
                                  "first_difference_frame",
                                  "status"};
    Record out;
    for (const char* key : kKeys) {
        bool found = false;
        for (const Field& field : record.fields) {
            if (field.key == key) {
                out.fields.push_back(field);
                found = true;
                break;
            }
        }
        if (!found) {
            out.empty(key);
        }
    }
    return out;
}

void printTable(const std::string& title, const std::vector<Record>& rows,
                const kolize::SceneNeeds& needs, bool drift, bool identical) {
    std::printf("\n%s\n", title.c_str());
    std::string header = "| broadphase    | init ms  | step ms  | bp ms    |";
    const bool rest = std::any_of(rows.begin(), rows.end(),
                                  [](const Record& row) { return !row["rest_ms"].empty(); });
    if (rest) {
        header += " rest ms  |";
    }
    if (needs.rays) {
        header += " ray ms   |";
    }
    header += " pairs    | true     | missing  | extra    |";
    if (needs.dynamics) {
        header += " max pen m | escaped | NaN |";
    }
    if (drift) {
        header += " drift mean m | drift max m |";
    }
    if (identical) {
        header += " = simple   |";
    }
    std::printf("%s\n", header.c_str());
    std::string rule;
    for (char c : header) {
        rule += c == '|' ? '|' : '-';
    }
    std::printf("%s\n", rule.c_str());
    for (const Record& row : rows) {
        const std::string& status = row["status"];
        if (status != "ok") {
            std::printf("| %-13s | %s\n", row["broadphase"].c_str(), status.c_str());
            continue;
        }
        auto cell = [&](const char* key, int width) {
            const std::string& text = row[key];
            std::printf(" %*s |", width, text.empty() ? "-" : text.c_str());
        };
        std::printf("| %-13s |", row["broadphase"].c_str());
        cell("init_ms", 8);
        cell("step_ms", 8);
        cell("broadphase_ms", 8);
        if (rest) {
            cell("rest_ms", 8);
        }
        if (needs.rays) {
            cell("ray_ms", 8);
        }
        cell("pairs", 8);
        cell("true_pairs", 8);
        cell("missing", 8);
        cell("extra", 8);
        if (needs.dynamics) {
            cell("max_penetration", 9);
            cell("escaped", 7);
            cell("nonfinite", 3);
        }
        if (drift) {
            cell("drift_mean", 12);
            cell("drift_max", 11);
        }
        if (identical) {
            const std::string& same = row["identical_to_simple"];
            const std::string& at = row["first_difference_frame"];
            std::printf(" %-10s |", same == "no"   ? ("no @" + at).c_str()
                                    : same.empty() ? "-"
                                                   : same.c_str());
        }
        std::printf("\n");
    }
    for (const Record& row : rows) {
        if (row["broadphase"] == "auto" && !row["core"].empty()) {
            std::printf("  %s\n", row["core"].c_str());
        }
    }
    std::fflush(stdout);
}

void addDrift(Record& record, const std::vector<btVector3>& positions,
              const std::vector<btVector3>& reference) {
    if (positions.empty() || positions.size() != reference.size()) {
        return;
    }
    double sum = 0, worst = 0;
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const double distance = double((positions[i] - reference[i]).length());
        sum += distance;
        worst = std::max(worst, distance);
    }
    record.number("drift_mean", sum / double(positions.size()), 6);
    record.number("drift_max", worst, 6);
}

std::vector<Record> replayRecords(const kolize::PairStream& stream, const Options& options,
                                  const std::string& sceneName,
                                  const kolize::BroadphaseSettings& settings) {
    std::vector<Record> rows;
    // store-only (stores the boxes, finds no pairs) is the floor every replay is read against.
    std::vector<std::string> names = options.broadphases;
    if (std::find(names.begin(), names.end(), "store-only") == names.end()) {
        names.push_back("store-only");
    }
    // Rounds interleave the contenders (the machine is shared): each round replays every
    // broadphase once, and a broadphase's time is the median of its rounds' medians.
    const std::size_t rounds = std::size_t(std::max(1, options.replayRounds));
    std::vector<std::vector<double>> frameSeconds(names.size()), restSeconds(names.size());
    std::vector<kolize::ReplayResult> firstRound(names.size());
    std::vector<std::string> errors(names.size());
    for (std::size_t round = 0; round < rounds; ++round) {
        for (std::size_t i = 0; i < names.size(); ++i) {
            if (!errors[i].empty()) {
                continue;
            }
            try {
                kolize::ReplayResult result =
                    kolize::replay(stream, baseName(names[i]), forEntry(settings, names[i]));
                frameSeconds[i].push_back(result.medianFrameSeconds());
                restSeconds[i].push_back(result.medianRestingSeconds());
                if (round == 0) {
                    firstRound[i] = std::move(result);
                }
            } catch (const std::exception& error) {
                errors[i] = error.what();
            }
            progress("replay " + sceneName + ", " + names[i], int(round + 1), int(rounds));
        }
    }
    for (std::size_t i = 0; i < names.size(); ++i) {
        Record r;
        r.text("scene", sceneName);
        r.text("broadphase", names[i]);
        r.text("mode", "replay");
        r.text("precision", sizeof(btScalar) == 8 ? "double" : "float");
        r.count("frames", static_cast<long long>(stream.frames()));
        if (errors[i].empty()) {
            const kolize::ReplayResult& result = firstRound[i];
            r.number("broadphase_ms", 1000 * kolize::median(frameSeconds[i]), 4);
            if (result.restingFrames() > 0) {
                r.number("rest_ms", 1000 * kolize::median(restSeconds[i]), 4);
            }
            r.count("rest_frames", static_cast<long long>(result.restingFrames()));
            r.count("rounds", static_cast<long long>(rounds));
            const kolize::ReplayFrame last =
                result.frames.empty() ? kolize::ReplayFrame{} : result.frames.back();
            r.count("pairs", static_cast<long long>(last.reportedPairs));
            r.count("true_pairs", static_cast<long long>(last.truePairs));
            r.count("missing", static_cast<long long>(result.totalMissing()));
            r.count("extra", static_cast<long long>(result.totalExtra()));
            long long missingFrames = 0;
            for (const kolize::ReplayFrame& frame : result.frames) {
                missingFrames += frame.missing > 0 ? 1 : 0;
            }
            r.count("missing_frames", missingFrames);
            r.text("status", "ok");
        } else {
            r.text("status", "error: " + errors[i]);
        }
        rows.push_back(ordered(r));
    }
    return rows;
}

int replayFile(const Options& options) {
    kolize::PairStream stream;
    try {
        stream = kolize::PairStream::load(options.replay);
    } catch (const std::exception& error) {
        fail(error.what());
    }
    const std::vector<Record> rows =
        replayRecords(stream, options, options.replay, withOptions({}, options));
    kolize::SceneNeeds needs;
    needs.dynamics = false;
    printTable("replay of " + options.replay + " (" + std::to_string(stream.frames()) +
                   " frames; no world step; bp ms = setAabb calls + pair search)",
               rows, needs, false, false);
    writeFiles(options, rows);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const Options options = parse(argc, argv);
    // Fail on an unwritable output before the runs, not after them.
    for (const std::string& path : {options.csv, options.json}) {
        if (!path.empty() && !std::ofstream(path)) {
            fail("cannot write '" + path + "'");
        }
    }
    if (!options.replay.empty()) {
        return replayFile(options);
    }
    std::printf(
        "kolize-demo: Bullet %d, %s precision, seed %u, %d frames; times are medians "
        "over frames; missing / extra pairs summed over all frames against the exact "
        "AABB pairs\n",
        btGetVersion(), sizeof(btScalar) == 8 ? "double" : "float", options.scene.seed,
        options.frames);
    std::vector<Record> all;
    kolize::PairStream recorded;
    bool recordedOnce = false;
    for (const std::string& sceneName : options.scenes) {
        const kolize::SceneInfo& info = kolize::findScene(sceneName);
        std::printf("\n== scene %s (%s): %s\n", sceneName.c_str(), info.group.c_str(),
                    info.summary.c_str());
        printPipeline(info, options.scene);
        const bool determinism = options.determinism && info.needs.dynamics;
        // An untimed run of the first broadphase first: the first timed run is not on a cold
        // machine (caches, page faults, clock ramp-up), and recording (--replay-check,
        // --record) does not slow a timed run.
        kolize::PairStream stream;
        kolize::PairStream* record = nullptr;
        if (options.replayCheck) {
            record = &stream;
        } else if (!options.record.empty() && !recordedOnce) {
            record = &recorded;
            recordedOnce = true;
        }
        Options warmUp = options;
        warmUp.frames = record != nullptr ? options.frames : std::min(options.frames, 10);
        runScene(sceneName, options.broadphases.front(), options.scene, warmUp, record, false);
        if (record == &stream && !options.record.empty() && !recordedOnce) {
            recorded = stream;
            recordedOnce = true;
        }
        std::vector<std::uint64_t> simpleHashes;
        if (determinism) {
            simpleHashes =
                runScene(sceneName, "simple", options.scene, options, nullptr, true).hashes;
        }
        std::vector<btVector3> reference;
        const bool drift = options.referenceSubsteps > 0 && info.needs.dynamics;
        kolize::SceneOptions referenceOptions = options.scene;
        referenceOptions.substeps *= options.referenceSubsteps;
        std::vector<Record> rows;
        std::string stages;
        for (const std::string& name : options.broadphases) {
            RunResult run = runScene(sceneName, name, options.scene, options, nullptr, determinism);
            if (stages.empty()) {
                stages = run.stages;
            }
            if (drift && run.record["status"] == "ok") {
                const RunResult fine =
                    runScene(sceneName, name, referenceOptions, options, nullptr, false);
                addDrift(run.record, run.finalPositions, fine.finalPositions);
            }
            if (determinism && run.record["status"] == "ok") {
                const auto mismatch = std::mismatch(run.hashes.begin(), run.hashes.end(),
                                                    simpleHashes.begin(), simpleHashes.end());
                const bool same =
                    mismatch.first == run.hashes.end() && mismatch.second == simpleHashes.end();
                run.record.text("identical_to_simple", same ? "yes" : "no");
                if (!same) {
                    run.record.count("first_difference_frame", mismatch.first - run.hashes.begin());
                }
            }
            rows.push_back(ordered(run.record));
        }
        char title[160];
        if (info.needs.dynamics) {
            std::snprintf(title, sizeof title,
                          "scene %s, live, %d objects, step %.5g s x %d substeps",
                          sceneName.c_str(), std::stoi(rows.front()["objects"]),
                          options.scene.timeStep, options.scene.substeps);
        } else {
            std::snprintf(title, sizeof title, "scene %s, live, %d objects, %s motion",
                          sceneName.c_str(), std::stoi(rows.front()["objects"]),
                          options.scene.motion.c_str());
        }
        printTable(title, rows, info.needs, drift, determinism);
        if (!stages.empty()) {
            std::printf(
                "narrowphase stages (kolize's stage planner, %s's run; "
                "kolize-mesh-world compares it with every stage forced on):\n%s",
                options.broadphases.front().c_str(), stages.c_str());
        }
        all.insert(all.end(), rows.begin(), rows.end());
        if (options.replayCheck && !stream.events.empty()) {
            const std::vector<Record> replayed = replayRecords(
                stream, options, sceneName, settingsFor(info, options.scene, options));
            kolize::SceneNeeds streamNeeds;
            streamNeeds.dynamics = false;
            printTable("scene " + sceneName + ", replay of " + options.broadphases.front() +
                           "'s recorded stream (" + std::to_string(stream.frames()) +
                           " pair searches; identical input for every broadphase)",
                       replayed, streamNeeds, false, false);
            all.insert(all.end(), replayed.begin(), replayed.end());
        }
    }
    if (!options.record.empty()) {
        try {
            recorded.save(options.record);
        } catch (const std::exception& error) {
            fail(error.what());
        }
        std::printf("\nrecorded %zu frames to %s\n", recorded.frames(), options.record.c_str());
    }
    writeFiles(options, all);
    int errors = 0;
    for (const Record& row : all) {
        errors += row["status"].rfind("error", 0) == 0 ? 1 : 0;
    }
    if (errors > 0) {
        std::fprintf(stderr, "kolize-demo: %d run(s) failed; see the status column\n", errors);
        return 1;
    }
    return 0;
}

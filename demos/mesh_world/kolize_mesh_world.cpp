// kolize-mesh-world: the mesh-body scenes (group mesh-world) once per mesh method (kolize's
// narrowphase, GImpact with margin 0 and with its default margin), stepped side by side:
// each frame steps every method's world once, in an order that rotates per frame, so the
// machine's noise hits them alike. Per scene and method: the median step and narrowphase
// time, contacts, the deepest contact, energy gained, escaped (tunnelled) bodies, NaN, and an
// exact audit of the contacts every few frames (contact_audit.h): pairs whose manifold claims
// a penetration the exact triangle test does not find (invented), and exactly intersecting
// pairs without a contact (missing); and the meshes' penetration, measured exactly
// (separationDepth: the shortest translation that parts the meshes), whatever the method
// reports as its contacts' depths.

#include "../common/cli.h"
#include "../common/split.h"

#include <kolize/engine/scene.h>
#include <kolize/engine/statistics.h>
#include <kolize/engine/world_scene.h>
#include <kolize/kolize.h>
#include <kolize/narrowphase/bullet_mesh.h>
#include <kolize/narrowphase/mesh_stages.h>

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

const char* const kUsage =
    "usage: kolize-mesh-world [options]\n"
    "  --scene LIST        mesh-world scenes, comma separated, or all (default all)\n"
    "  --method LIST       kolize (its stage planner deciding), kolize-margin (the same with\n"
    "                      a contact margin), kolize-all-on (every stage forced on),\n"
    "                      gimpact-0, gimpact (default all five)\n"
    "  --contact-margin M  kolize-margin's contact margin in metres (default 0.005)\n"
    "  --frames N          frames per run (default 180)\n"
    "  --n N               objects (default: the scene's)\n"
    "  --timestep T        seconds per frame, e.g. 1/120 (default 1/60)\n"
    "  --substeps K        solver substeps per frame (default 1)\n"
    "  --ccd auto|on|off   CCD (kolize: its mesh CCD; default: on where the scene needs it)\n"
    "  --audit-every K     exact contact audit every K-th frame, 0 = never (default 5)\n"
    "  --penetration on|off  the audit also measures each audited pair's penetration\n"
    "                      (the shortest translation that parts the meshes; default on)\n"
    "  --broadphase NAME   the broadphase of every run (default sweep)\n"
    "  --seed S            scene seed (default 1)\n"
    "  --csv FILE          also write one line per scene and method\n";

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "kolize-mesh-world: %s (try --help)\n", message.c_str());
    std::exit(2);
}

const std::vector<std::string> kMethods = {"kolize", "kolize-margin", "kolize-all-on", "gimpact-0",
                                           "gimpact"};

struct Options {
    std::vector<std::string> scenes;
    std::vector<std::string> methods = kMethods;
    double contactMargin = 0.005;
    int frames = 180;
    int auditEvery = 5;
    bool penetration = true;
    std::string broadphase = "sweep";
    std::string csv;
    kolize::SceneOptions scene;
};

std::vector<std::string> meshWorldScenes() {
    std::vector<std::string> out;
    for (const kolize::SceneInfo& info : kolize::sceneList()) {
        if (info.group == "mesh-world") {
            out.push_back(info.name);
        }
    }
    return out;
}

Options parse(int argc, char** argv) {
    Options options;
    options.scenes = meshWorldScenes();
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--help" || flag == "-h") {
            std::printf("%s", kUsage);
            std::exit(0);
        }
        if (i + 1 >= argc) {
            fail(flag.rfind("--", 0) == 0 ? flag + " needs a value"
                                          : "unknown argument '" + flag + "'");
        }
        const std::string value = argv[++i];
        if (flag == "--scene") {
            options.scenes = kolize::demo::chosen(flag, value, meshWorldScenes(), fail);
        } else if (flag == "--method") {
            options.methods = kolize::demo::chosen(flag, value, kMethods, fail);
        } else if (flag == "--contact-margin") {
            options.contactMargin = kolize::demo::realNumber(flag, value, 0, 1, "metres", fail);
        } else if (flag == "--frames") {
            options.frames = int(kolize::demo::wholeNumber(flag, value, 1, 1000000, fail));
        } else if (flag == "--n") {
            options.scene.objects = int(kolize::demo::wholeNumber(flag, value, 1, 100000, fail));
        } else if (flag == "--timestep") {
            options.scene.timeStep = kolize::demo::seconds(flag, value, fail);
        } else if (flag == "--substeps") {
            options.scene.substeps = int(kolize::demo::wholeNumber(flag, value, 1, 1000, fail));
        } else if (flag == "--ccd") {
            if (value != "auto" && value != "on" && value != "off") {
                fail("--ccd takes auto, on or off, got '" + value + "'");
            }
            options.scene.bulletCcd = value == "auto" ? -1 : value == "on" ? 1 : 0;
        } else if (flag == "--penetration") {
            if (value != "on" && value != "off") {
                fail("--penetration takes on or off, got '" + value + "'");
            }
            options.penetration = value == "on";
        } else if (flag == "--audit-every") {
            options.auditEvery = int(kolize::demo::wholeNumber(flag, value, 0, 1000000, fail));
        } else if (flag == "--broadphase") {
            const std::vector<std::string> names = kolize::broadphaseNames();
            if (std::find(names.begin(), names.end(), value) == names.end()) {
                fail("--broadphase: unknown name '" + value + "'");
            }
            options.broadphase = value;
        } else if (flag == "--seed") {
            options.scene.seed =
                std::uint32_t(kolize::demo::wholeNumber(flag, value, 0, 4294967295L, fail));
        } else if (flag == "--csv") {
            options.csv = value;
        } else {
            fail("unknown option '" + flag + "'");
        }
    }
    return options;
}

/// One method's run of one scene.
struct Run {
    std::string method;
    std::unique_ptr<kolize::Scene> scene;
    kolize::WorldScene* world = nullptr;
    std::vector<double> stepMs, narrowMs, integrateMs, contacts;
    double initialEnergy = 0, energyGain = 0, deepest = 0;
    int escaped = 0, nonFinite = 0;
    kolize::ContactAudit audit;
};

double mean(const std::vector<double>& values) {
    double sum = 0;
    for (double v : values) {
        sum += v;
    }
    return values.empty() ? 0 : sum / double(values.size());
}

int contactPoints(kolize::WorldScene& world) {
    int points = 0;
    btCollisionDispatcher& dispatcher = world.dispatcher();
    for (int i = 0; i < dispatcher.getNumManifolds(); ++i) {
        points += dispatcher.getManifoldByIndexInternal(i)->getNumContacts();
    }
    return points;
}

void stepOnce(Run& run, bool audit, const kolize::AuditSettings& settings) {
    run.world->setContactAudit(audit, settings);
    const auto start = std::chrono::steady_clock::now();
    run.scene->step();
    run.stepMs.push_back(
        1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    run.narrowMs.push_back(1e3 * run.world->lastNarrowphaseSeconds());
    run.integrateMs.push_back(1e3 * run.world->lastIntegrateSeconds());
    run.contacts.push_back(contactPoints(*run.world));
    const kolize::SceneState state = run.scene->state();
    run.energyGain =
        std::max(run.energyGain, state.kineticEnergy + state.potentialEnergy - run.initialEnergy);
    run.deepest = std::max(run.deepest, state.maxPenetration);
    run.escaped = std::max(run.escaped, state.escaped);
    run.nonFinite = std::max(run.nonFinite, state.nonFinite);
    if (audit) {
        run.audit += run.world->lastAudit();
    }
}

}  // namespace

int main(int argc, char** argv) {
    const Options options = parse(argc, argv);
    std::FILE* csv = nullptr;
    if (!options.csv.empty() && (csv = std::fopen(options.csv.c_str(), "w")) == nullptr) {
        fail("cannot write '" + options.csv + "'");
    }
    if (csv != nullptr) {
        std::fprintf(csv,
                     "scene,method,frames,timestep,substeps,ccd,step_ms,narrow_ms,narrow_mean_ms,"
                     "integrate_ms,"
                     "contacts,deepest_m,energy_gain_j,escaped,nonfinite,audited_pairs,"
                     "intersecting,invented,missing,max_false_depth_m,rounding_ties,"
                     "mesh_queries,convex_mesh_queries,sphere_tests,sphere_rejects,"
                     "sphere_skipped,tree_queries,no_tree,node_tests,triangle_tests,"
                     "intersecting_triangles,toi_calls,toi_skipped_slow,toi_hits,"
                     "max_penetration_m,mean_penetration_m\n");
    }
    std::printf(
        "kolize-mesh-world: Bullet %d, %s precision, broadphase %s, seed %u, %d frames of %.5g s "
        "(%d substeps); times are medians over frames (narr mean: the mean), the methods stepped "
        "in turn each frame; "
        "contacts audited exactly every %d frames\n",
        btGetVersion(), sizeof(btScalar) == 8 ? "double" : "float", options.broadphase.c_str(),
        options.scene.seed, options.frames, options.scene.timeStep, options.scene.substeps,
        options.auditEvery);
    for (const std::string& sceneName : options.scenes) {
        const kolize::SceneInfo& info = kolize::findScene(sceneName);
        std::printf("\n== scene %s: %s\n", sceneName.c_str(), info.summary.c_str());
        std::vector<Run> runs;
        for (const std::string& method : options.methods) {
            kolize::SceneOptions sceneOptions = options.scene;
            const bool allOn = method == "kolize-all-on";
            const bool margin = method == "kolize-margin";
            sceneOptions.meshMethod = allOn || margin ? "kolize" : method;
            Run run;
            run.method = method;
            run.scene = kolize::makeScene(
                sceneName,
                kolize::makeBroadphase(options.broadphase,
                                       kolize::broadphaseSettingsFor(info, sceneOptions)),
                sceneOptions);
            run.world = static_cast<kolize::WorldScene*>(run.scene.get());
            if (allOn) {
                kolize::registerNarrowphase(&run.world->dispatcher(),
                                            kolize::MeshStageSettings::allOn());
            }
            if (margin) {
                kolize::MeshStageSettings settings;
                settings.contact_margin = options.contactMargin;
                kolize::registerNarrowphase(&run.world->dispatcher(), settings);
            }
            const kolize::SceneState state = run.scene->state();
            run.initialEnergy = state.kineticEnergy + state.potentialEnergy;
            runs.push_back(std::move(run));
        }
        kolize::AuditSettings auditSettings;
        auditSettings.penetration = options.penetration;
        for (int frame = 0; frame < options.frames; ++frame) {
            const bool audit = options.auditEvery > 0 && frame % options.auditEvery == 0;
            for (std::size_t k = 0; k < runs.size(); ++k) {
                stepOnce(runs[(k + std::size_t(frame)) % runs.size()], audit, auditSettings);
            }
        }
        std::printf("%-13s %8s %9s %9s %9s %8s %9s %10s %7s %4s %7s %6s %8s %7s %10s %9s %9s\n",
                    "method", "step ms", "narrow ms", "narr mean", "integr ms", "contacts",
                    "deepest", "energy+ J", "escaped", "NaN", "audited", "inters", "invented",
                    "missing", "false dep", "pen max", "pen mean");
        for (Run& run : runs) {
            const double step = kolize::median(run.stepMs), narrow = kolize::median(run.narrowMs),
                         narrowMean = mean(run.narrowMs),
                         integrate = kolize::median(run.integrateMs),
                         contacts = kolize::median(run.contacts);
            const double penetrationMean =
                run.audit.penetrationPairs > 0
                    ? run.audit.sumPenetration / run.audit.penetrationPairs
                    : 0;
            std::printf(
                "%-13s %8.3f %9.3f %9.3f %9.3f %8.0f %9.2e %10.3g %7d %4d %7d %6d %8d %7d %10.2e "
                "%9.2e %9.2e\n",
                run.method.c_str(), step, narrow, narrowMean, integrate, contacts, run.deepest,
                run.energyGain, run.escaped, run.nonFinite, run.audit.pairs, run.audit.intersecting,
                run.audit.invented, run.audit.missing, run.audit.maxFalseDepth,
                run.audit.maxPenetration, penetrationMean);
            if (csv != nullptr) {
                std::fprintf(
                    csv,
                    "%s,%s,%d,%.8g,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%d,%d,%d,%d,"
                    "%d,%.6g,%d,",
                    sceneName.c_str(), run.method.c_str(), options.frames, options.scene.timeStep,
                    options.scene.substeps, run.world->world()->meshCcd() ? 1 : 0, step, narrow,
                    narrowMean, integrate, contacts, run.deepest, run.energyGain, run.escaped,
                    run.nonFinite, run.audit.pairs, run.audit.intersecting, run.audit.invented,
                    run.audit.missing, run.audit.maxFalseDepth, run.audit.roundingTies);
                // The stage planner's counters (kolize's methods; GImpact has none: zeros).
                kolize::MeshStageStats stages;
                if (run.method.rfind("kolize", 0) == 0) {
                    stages = kolize::narrowphaseStages(&run.world->dispatcher());
                }
                const auto count = [](std::uint64_t value) {
                    return static_cast<unsigned long long>(value);
                };
                std::fprintf(
                    csv,
                    "%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%.6g,%.6g\n",
                    count(stages.mesh_mesh_queries + stages.mesh_scenery_queries),
                    count(stages.convex_mesh_queries), count(stages.object_sphere_tests),
                    count(stages.object_sphere_rejects),
                    count(stages.sphere_skipped_auto + stages.sphere_skipped_off),
                    count(stages.tree_queries), count(stages.no_tree_tiny + stages.no_tree_off),
                    count(stages.node_sphere_tests + stages.node_box_tests),
                    count(stages.triangle_tests), count(stages.intersecting_pairs),
                    count(stages.toi_calls), count(stages.toi_skipped_slow), count(stages.toi_hits),
                    run.audit.maxPenetration, penetrationMean);
            }
        }
        const auto kolizeRun = std::find_if(runs.begin(), runs.end(),
                                            [](const Run& run) { return run.method == "kolize"; });
        if (kolizeRun != runs.end()) {
            std::printf(
                "kolize's stages (its stage planner, summed over the frames):\n%s",
                kolize::describeStages(kolize::narrowphaseStages(&kolizeRun->world->dispatcher()))
                    .c_str());
        }
        for (const Run& run : runs) {
            if (kolizeRun != runs.end() && run.method == "kolize-all-on") {
                std::printf(
                    "stage planner: narrowphase %.1f%% faster than every stage on "
                    "(mean per frame)\n",
                    100 * (1 - mean(kolizeRun->narrowMs) / std::max(1e-9, mean(run.narrowMs))));
            } else if (kolizeRun != runs.end() && run.method != "kolize") {
                std::printf("narrowphase time per frame (mean), kolize / %s: %.2f\n",
                            run.method.c_str(),
                            mean(kolizeRun->narrowMs) / std::max(1e-9, mean(run.narrowMs)));
            }
        }
    }
    if (csv != nullptr) {
        std::fclose(csv);
    }
    return 0;
}

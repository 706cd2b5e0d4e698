// kolize-report's mesh-world section, from kolize-mesh-world's CSV: the mesh-body scenes with
// kolize's narrowphase against GImpact (margin 0 and default) in the same run, per time step
// from 1/30 to 1/480 s: step and narrowphase time, penetration, tunnelled bodies, and the exact
// audit's invented and missing contacts; error against run time as plots.

#include "report.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace report {

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

fs::path meshWorld() {
    std::error_code error;
    const fs::path self = fs::read_symlink("/proc/self/exe", error);
    const fs::path dir = error ? fs::current_path() : self.parent_path();
    for (const fs::path& candidate :
         {dir / "kolize-mesh-world", dir.parent_path() / "kolize-mesh-world"}) {
        if (access(candidate.c_str(), X_OK) == 0) {
            return candidate;
        }
    }
    return {};
}

struct Step {
    std::string label;  ///< "1/60"
    double seconds;
};

/// One run of one method on one scene at one time step.
struct Row {
    double stepMs = kNaN, narrowMean = kNaN, contacts = kNaN, deepest = kNaN;
    int escaped = 0, nonFinite = 0, invented = 0, missing = 0, intersecting = 0;
    double falseDepth = kNaN;
    /// The exact penetration (separationDepth) over the audited pairs: largest and mean.
    double penetrationMax = kNaN, penetrationMean = kNaN;
};

Row rowOf(const Csv& csv, std::size_t r) {
    Row row;
    row.stepMs = csv.number(r, "step_ms");
    row.narrowMean = csv.number(r, "narrow_mean_ms");
    row.contacts = csv.number(r, "contacts");
    row.deepest = csv.number(r, "deepest_m");
    row.escaped = int(csv.number(r, "escaped"));
    row.nonFinite = int(csv.number(r, "nonfinite"));
    row.invented = int(csv.number(r, "invented"));
    row.missing = int(csv.number(r, "missing"));
    row.intersecting = int(csv.number(r, "intersecting"));
    row.falseDepth = csv.number(r, "max_false_depth_m");
    row.penetrationMax = csv.number(r, "max_penetration_m");
    row.penetrationMean = csv.number(r, "mean_penetration_m");
    return row;
}

}  // namespace

void meshWorldSection(Context& context) {
    context.heading("Mesh bodies in Bullet worlds: kolize against GImpact");
    const fs::path binary = meshWorld();
    const std::vector<Step> steps =
        context.quick ? std::vector<Step>{{"1/60", 1.0 / 60}, {"1/120", 1.0 / 120}}
                      : std::vector<Step>{{"1/30", 1.0 / 30},
                                          {"1/60", 1.0 / 60},
                                          {"1/120", 1.0 / 120},
                                          {"1/240", 1.0 / 240},
                                          {"1/480", 1.0 / 480}};
    const double simulated = context.quick ? 0.25 : 2.0;  // seconds per run
    context.add(
        "The mesh-world scenes (kolize's registry; `--mesh-method` in kolize-demo): every body a "
        "triangle mesh from assimp-testmodels or a box mesh, colliding mesh against mesh with "
        "kolize's narrowphase (`kolize::MeshShape`, `registerNarrowphase`, its mesh CCD where the "
        "scene is fast) or with GImpact (`btGImpactMeshShape`, margin 0 and its default margin; "
        "GImpact bodies have no CCD: Bullet's swept sphere is for convex shapes). "
        "`kolize-mesh-world` steps the three worlds of a scene in turn, frame by frame, each over "
        "the same broadphase (sweep). Every 5th frame an exact audit queries every overlapping "
        "body pair with kolize's exact triangle test at the poses the narrowphase saw: "
        "*invented* are pairs whose manifold claims a penetration deeper than 0.1 mm while the "
        "meshes are apart, *missing* intersecting pairs without a contact, and *penetration* is "
        "measured there too, whatever a method reports as its contacts' depths: the shortest "
        "translation (over 27 directions, by bisection with the exact test) after which the two "
        "meshes no longer overlap as solids (`kolize::separationDepth`; a closed mesh holding "
        "the other counts), its largest and mean value over the overlapping pairs. Each run "
        "simulates " +
        fmt(simulated) + " s.\n\n");
    std::map<std::string, Csv> byStep;
    std::vector<std::string> shown;
    for (const Step& step : steps) {
        Csv csv;
        std::string line;
        const int frames = std::max(1, int(std::lround(simulated / step.seconds)));
        const std::string name = "mesh-world-" + std::to_string(int(std::lround(1 / step.seconds)));
        if (context.runCsv(name, binary,
                           {"--timestep", step.label, "--frames", std::to_string(frames)}, csv,
                           line)) {
            byStep[step.label] = csv;
        }
        shown.push_back(line);
    }
    // kolize without its mesh CCD on the wall, per time step: what the CCD buys.
    std::map<std::string, Csv> noCcdByStep;
    for (const Step& step : steps) {
        Csv csv;
        std::string line;
        const int frames = std::max(1, int(std::lround(simulated / step.seconds)));
        if (context.runCsv(
                "mesh-world-no-ccd-" + std::to_string(int(std::lround(1 / step.seconds))), binary,
                {"--scene", "mesh-wall", "--ccd", "off", "--method", "kolize", "--timestep",
                 step.label, "--frames", std::to_string(frames)},
                csv, line)) {
            noCcdByStep[step.label] = csv;
        }
        shown.push_back(line);
    }
    const bool haveNoCcd = noCcdByStep.count("1/60") != 0;
    const Csv noCcd = haveNoCcd ? noCcdByStep.at("1/60") : Csv();
    context.commands(shown);
    if (byStep.count("1/60") == 0) {
        context.add("*No data: kolize-mesh-world did not run (see the failures above).*\n");
        return;
    }

    // 1. The table at 1/60 s.
    const Csv& main = byStep.at("1/60");
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> slow;
    int invented = 0, missing = 0, kolizeTunnelled = 0;
    for (const std::string& scene : main.distinct("scene")) {
        double gimpactZero = kNaN;
        for (std::size_t r : main.where({{"scene", scene}, {"method", "gimpact-0"}})) {
            gimpactZero = main.number(r, "narrow_mean_ms");
        }
        for (std::size_t r : main.where({{"scene", scene}})) {
            const std::string method = main.at(r, "method");
            const Row row = rowOf(main, r);
            const double ratio = row.narrowMean / gimpactZero;
            if (method == "kolize") {
                invented += row.invented;
                missing += row.missing;
                kolizeTunnelled += scene == "mesh-wall" ? row.escaped : 0;
                if (!(ratio <= 0.5)) {
                    slow.push_back(scene + " (" + times(ratio) + ")");
                }
            }
            rows.push_back({scene, method, fmt(row.stepMs), fmt(row.narrowMean),
                            method == "gimpact-0" ? "1x" : times(ratio), fmt(row.contacts),
                            fmt(row.deepest), std::to_string(row.escaped),
                            std::to_string(row.nonFinite), std::to_string(row.intersecting),
                            std::to_string(row.invented), std::to_string(row.missing),
                            fmt(row.falseDepth), fmt(row.penetrationMax),
                            fmt(row.penetrationMean)});
        }
    }
    context.add(
        "At 1/60 s (step: median ms per frame; narrowphase: mean ms per frame, as resting "
        "bodies fall asleep; deepest: the deepest contact a method reports, GImpact's "
        "default margin included; escaped: bodies past the wall or out of the bowl or "
        "floor; penetration: measured exactly, largest and mean):\n\n");
    context.add(
        markdownTable({"scene", "method", "step ms", "narrowphase ms", "/ gimpact-0", "contacts",
                       "deepest m", "escaped", "NaN", "touching pairs", "invented", "missing",
                       "false depth m", "penetration max m", "penetration mean m"},
                      rows));

    // 2. The stage planner at 1/60 s: what kolize's planner ran and skipped per scene, against
    // the run with every stage forced on (kolize-all-on) in the same frames.
    std::vector<std::vector<std::string>> stageRows;
    const auto share = [](double part, double whole) {
        return whole > 0 ? fmt(100 * part / whole) + "%" : std::string("-");
    };
    for (const std::string& scene : main.distinct("scene")) {
        double planned = kNaN, allOn = kNaN, allOnSpheres = kNaN, allOnTrees = kNaN;
        for (std::size_t r : main.where({{"scene", scene}, {"method", "kolize-all-on"}})) {
            allOn = main.number(r, "narrow_mean_ms");
            allOnSpheres = main.number(r, "sphere_tests");
            allOnTrees = main.number(r, "tree_queries");
        }
        for (std::size_t r : main.where({{"scene", scene}, {"method", "kolize"}})) {
            planned = main.number(r, "narrow_mean_ms");
            const double queries = main.number(r, "mesh_queries");
            const double spheres = main.number(r, "sphere_tests");
            const double toiCalls = main.number(r, "toi_calls");
            stageRows.push_back(
                {scene, fmt(queries), fmt(main.number(r, "convex_mesh_queries")),
                 fmt(spheres) + " (all on " + fmt(allOnSpheres) + ")",
                 share(main.number(r, "sphere_rejects"), spheres),
                 fmt(main.number(r, "sphere_skipped")),
                 fmt(main.number(r, "tree_queries")) + " (all on " + fmt(allOnTrees) + ")",
                 fmt(main.number(r, "no_tree")), fmt(main.number(r, "triangle_tests")),
                 share(main.number(r, "intersecting_triangles"), main.number(r, "triangle_tests")),
                 fmt(toiCalls) + " (" + fmt(main.number(r, "toi_skipped_slow")) + " slow)",
                 std::isnan(allOn) ? "-" : share(allOn - planned, allOn)});
        }
    }
    if (!stageRows.empty()) {
        context.add(
            "\nThe stage planner at 1/60 s (kolize's run; counts summed over the frames; the "
            "`kolize-all-on` run in the same frames has every stage forced on, its sphere tests "
            "and tree queries in brackets). mesh queries: mesh-mesh and mesh-scenery "
            "processCollision calls; convex-mesh: pairs left to Bullet's convex-triangle path "
            "(no kolize triangle stage); sphere rejects: share of the object-sphere tests "
            "that ended the query; skipped: queries whose pair had turned the sphere stage off "
            "(it rejected under 5% of 64 queries in a row); without tree: tiny pairs (at most "
            "144 triangle pairs), their root volumes tested, then every triangle pair "
            "directly; toi calls: calculateTimeOfImpact, "
            "of which slow: neither body past its CCD motion threshold, no time of impact "
            "computed; saved: narrowphase time per frame (mean) against every stage on, "
            "measured, so noise may make it negative. The contacts are the same either way "
            "(`BulletMeshStages` tests).\n\n");
        context.add(
            markdownTable({"scene", "mesh queries", "convex-mesh", "sphere tests", "sphere rejects",
                           "sphere skipped", "tree queries", "without tree", "triangle tests",
                           "intersecting", "toi calls", "saved"},
                          stageRows));
    }

    // 3. Error against run time, per time step.
    std::vector<std::vector<std::string>> errorRows;
    std::map<std::string, std::vector<std::string>> pile, wall;
    std::vector<std::string> deeper;  // scene and step where kolize penetrates deeper than GImpact
    for (const Step& step : steps) {
        if (byStep.count(step.label) == 0) {
            continue;
        }
        const Csv& csv = byStep.at(step.label);
        for (const std::string& scene : csv.distinct("scene")) {
            auto largest = [&](const std::string& method) {
                double out = kNaN;
                for (std::size_t r : csv.where({{"scene", scene}, {"method", method}})) {
                    out = csv.number(r, "max_penetration_m");
                }
                return out;
            };
            // Exact contacts against exact contacts (GImpact margin 0), contacts with a margin
            // against contacts with a margin (GImpact's default): a margin holds resting
            // meshes apart, by contacts the audit counts as invented.
            for (const auto& [ours, theirs] :
                 {std::pair<const char*, const char*>{"kolize", "gimpact-0"},
                  std::pair<const char*, const char*>{"kolize-margin", "gimpact"}}) {
                if (largest(ours) > largest(theirs)) {
                    deeper.push_back(scene + " at " + step.label + " (" + ours + " " +
                                     fmt(largest(ours)) + " m, " + theirs + " " +
                                     fmt(largest(theirs)) + " m)");
                }
            }
        }
        for (std::size_t r : csv.where({})) {
            const std::string scene = csv.at(r, "scene"), method = csv.at(r, "method");
            const Row row = rowOf(csv, r);
            errorRows.push_back({step.label, scene, method, fmt(row.stepMs), fmt(row.deepest),
                                 fmt(row.penetrationMax), fmt(row.penetrationMean),
                                 std::to_string(row.escaped), std::to_string(row.invented)});
            const std::string point = std::to_string(row.stepMs) + " " +
                                      std::to_string(row.deepest) + " " +
                                      std::to_string(row.escaped) + " \"" + step.label + "\" " +
                                      std::to_string(row.penetrationMax);
            if (scene == "mesh-pile") {
                pile[method].push_back(point);
            } else if (scene == "mesh-wall") {
                wall[method].push_back(point);
            }
        }
        if (noCcdByStep.count(step.label) != 0) {
            const Csv& csv = noCcdByStep.at(step.label);
            for (std::size_t r : csv.where({})) {
                const Row row = rowOf(csv, r);
                errorRows.push_back({step.label, "mesh-wall", "kolize, no CCD", fmt(row.stepMs),
                                     fmt(row.deepest), fmt(row.penetrationMax),
                                     fmt(row.penetrationMean), std::to_string(row.escaped),
                                     std::to_string(row.invented)});
                wall["kolize, no CCD"].push_back(
                    std::to_string(row.stepMs) + " " + std::to_string(row.deepest) + " " +
                    std::to_string(row.escaped) + " \"" + step.label + "\"");
            }
        }
    }
    context.add(
        "\nError against run time: every scene and method per time step (one frame = "
        "one step; kolize with its mesh CCD in mesh-wall, and without it, `--ccd off`):\n\n");
    context.add(markdownTable({"time step", "scene", "method", "step ms", "deepest m",
                               "penetration max m", "penetration mean m", "escaped", "invented"},
                              errorRows));
    auto plotOf = [&](const std::string& name, const std::string& title,
                      std::map<std::string, std::vector<std::string>>& series, int column,
                      const std::string& ylabel, bool logY) {
        if (series.empty()) {
            return;
        }
        std::string body, plots = "plot ";
        int index = 0;
        for (auto& [method, lines] : series) {
            std::sort(lines.begin(), lines.end(), [](const std::string& a, const std::string& b) {
                return std::stod(a) < std::stod(b);
            });
            const std::string block = "m" + std::to_string(index++);
            body += dataBlock(block, lines);
            plots += "$" + block + " using 1:" + std::to_string(column) +
                     " with linespoints lw 2 pt " + std::to_string(5 + 2 * index) + " title \"" +
                     method + "\", $" + block + " using 1:" + std::to_string(column) +
                     ":4 with labels font \",8\" offset char 0,0.9 notitle, \\\n     ";
        }
        plots.resize(plots.size() - 9);
        body += "set title \"" + title + "\"\nset logscale x\n" +
                std::string(logY ? "set logscale y\n" : "") +
                "set grid\nset key top right\nset xlabel \"median step time (ms)\"\nset ylabel \"" +
                ylabel + "\"\n" + plots + "\n";
        context.add(context.plot(name, title, body, 1000, 450));
    };
    context.add("\n");
    plotOf("mesh-pile-error", "mesh-pile: penetration (measured exactly) against step time", pile,
           5, "largest penetration (m)", true);
    context.add("\n");
    plotOf("mesh-wall-error", "mesh-wall: tunnelled bodies against step time", wall, 3,
           "bodies past the wall", false);

    // 4. Reading.
    context.add("\n\n**Reading.** Exact audit at 1/60 s: kolize " + std::to_string(invented) +
                " invented and " + std::to_string(missing) + " missing contacts over every scene");
    if (haveNoCcd && noCcd.size() > 0) {
        context.add("; mesh-wall: " + std::to_string(kolizeTunnelled) +
                    " bodies tunnelled with kolize's mesh CCD, " + fmt(noCcd.number(0, "escaped")) +
                    " without it (`--ccd off`)");
    }
    context.add(
        ". Narrowphase target (at most 0.5x GImpact margin 0 per frame, every scene): " +
        std::string(slow.empty() ? "met on every scene" : "not met on " + join(slow, ", ")) +
        ". Penetration (the largest measured penetration no deeper than GImpact's per scene and "
        "time step: kolize against GImpact margin 0, kolize-margin against GImpact's default "
        "margin): " +
        std::string(deeper.empty() ? "met everywhere" : "deeper on " + join(deeper, "; ")) +
        ". The deepest contact a method reports is not its penetration (compare the columns).\n");
}

}  // namespace report

// kolize-report's Bullet-world sections, all from kolize-demo CSV: pair output live and
// replayed against the exact truth (and Bullet's dbvt / SAP), ray timings, determinism
// against `simple`, dynamics accuracy against time, numerical stability in float and double.

#include "report.h"

#include <kolize/kolize.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

namespace report {

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Registered scenes (kolize-demo --list-scenes).
struct SceneList {
    std::vector<std::string> names;
    std::map<std::string, std::string> group;
    std::set<std::string> dynamics, rays;

    /// The registered scenes in `subset`, in registry order.
    std::vector<std::string> among(const std::set<std::string>& subset) const {
        std::vector<std::string> out;
        for (const std::string& name : names) {
            if (subset.count(name) != 0) {
                out.push_back(name);
            }
        }
        return out;
    }
    std::vector<std::string> inGroups(const std::set<std::string>& groups) const {
        std::vector<std::string> out;
        for (const std::string& name : names) {
            if (groups.count(group.at(name)) != 0) {
                out.push_back(name);
            }
        }
        return out;
    }
    /// The wanted scenes that are registered; the others appended to `missing`.
    std::vector<std::string> present(const std::vector<std::string>& wanted,
                                     std::vector<std::string>& missing) const {
        std::vector<std::string> out;
        for (const std::string& name : wanted) {
            (group.count(name) != 0 ? out : missing).push_back(name);
        }
        return out;
    }
};

/// Options that size every demo run: small in --quick.
std::vector<std::string> sizing(const Context& context) {
    return context.quick ? std::vector<std::string>{"--n", "128", "--frames", "20"}
                         : std::vector<std::string>{"--frames", "100"};
}

/// "exact", "missing / extra", "skipped" or "**error**" for one run.
std::string errorsCell(const Csv& csv, std::size_t row) {
    const std::string& status = csv.at(row, "status");
    if (status != "ok") {
        return status.rfind("skipped", 0) == 0 ? "skipped" : "**error**";
    }
    const std::string& missing = csv.at(row, "missing");
    const std::string& extra = csv.at(row, "extra");
    return missing == "0" && extra == "0" ? "exact" : missing + " / " + extra;
}

/// One row of `csv` for scene, broadphase and mode, or -1.
long find(const Csv& csv, const std::string& scene, const std::string& broadphase,
          const std::string& mode) {
    const auto rows = csv.where({{"scene", scene}, {"broadphase", broadphase}, {"mode", mode}});
    return rows.empty() ? -1 : long(rows.front());
}

/// A table: one row per scene, one column per broadphase, the cell from `cell` ("" when the
/// run is absent), after the `lead` columns.
template <class Cell, class Lead>
std::string sceneByBroadphase(const std::vector<std::string>& scenes,
                              const std::vector<std::string>& broadphases,
                              const std::vector<std::string>& leadHeader, Lead lead, Cell cell) {
    std::vector<std::string> header = {"scene"};
    header.insert(header.end(), leadHeader.begin(), leadHeader.end());
    header.insert(header.end(), broadphases.begin(), broadphases.end());
    std::vector<std::vector<std::string>> rows;
    for (const std::string& scene : scenes) {
        std::vector<std::string> row = {scene};
        for (const std::string& text : lead(scene)) {
            row.push_back(text);
        }
        for (const std::string& broadphase : broadphases) {
            row.push_back(cell(scene, broadphase));
        }
        rows.push_back(row);
    }
    return markdownTable(header, rows);
}

/// The broadphase with the smallest `column` for `scene` in `mode`: "name (x ms)"; with a
/// reference broadphase also its multiple of that one's. "" when none ran. store-only (the
/// floor, which finds no pairs) is not a contender.
std::string fastest(const Csv& csv, const std::string& scene,
                    const std::vector<std::string>& broadphases, const std::string& mode,
                    const std::string& column, const std::string& reference = "") {
    std::string best;
    double bestMs = kNaN, referenceMs = kNaN;
    for (const std::string& broadphase : broadphases) {
        const long row = broadphase == "store-only" ? -1 : find(csv, scene, broadphase, mode);
        const double ms = row < 0 ? kNaN : csv.number(std::size_t(row), column);
        referenceMs = broadphase == reference ? ms : referenceMs;
        if (std::isfinite(ms) && !(ms >= bestMs)) {
            bestMs = ms;
            best = broadphase;
        }
    }
    if (best.empty()) {
        return best;
    }
    return best + " (" + fmt(bestMs) + " ms" +
           (reference.empty() ? "" : ", " + times(bestMs / referenceMs) + " " + reference + "'s") +
           ")";
}

std::string orNone(const std::vector<std::string>& items) {
    return items.empty() ? "none" : join(items, "; ");
}

bool loadScenes(Context& context, SceneList& scenes) {
    std::string shown;
    if (!context.runner.run("scenes", {context.demo.string(), "--list-scenes"}, shown,
                            context.data / "scenes.csv")) {
        context.add("**Failed:** `" + shown + "`\n\n");
        return false;
    }
    Csv csv;
    if (!context.load("scenes.csv", csv)) {
        return false;
    }
    for (std::size_t r = 0; r < csv.size(); ++r) {
        const std::string& name = csv.at(r, "name");
        scenes.names.push_back(name);
        scenes.group[name] = csv.at(r, "group");
        if (csv.at(r, "dynamics") == "1") {
            scenes.dynamics.insert(name);
        }
        if (csv.at(r, "rays") == "1") {
            scenes.rays.insert(name);
        }
    }
    context.add("Scenes registered in this build (`" + shown +
                "`, `data/scenes.csv`): " + join(scenes.names, ", ") + ".\n\n");
    return true;
}

void pairSections(Context& context, const SceneList& scenes, Csv& pairs) {
    context.heading("Pair output against the exact truth, live and replayed");
    std::vector<std::string> args = {"--scene", "all", "--broadphase", "all", "--replay-check"};
    const std::vector<std::string> size = sizing(context);
    args.insert(args.end(), size.begin(), size.end());
    if (!context.measure("pairs", context.demo, args, pairs)) {
        return;
    }
    const std::vector<std::string> broadphases = pairs.distinct("broadphase");
    auto objects = [&](const std::string& scene) {
        const long row = find(pairs, scene, broadphases.front(), "live");
        return std::vector<std::string>{row < 0 ? "" : pairs.at(row, "objects"),
                                        row < 0 ? "" : pairs.at(row, "true_pairs")};
    };
    context.add(
        "Every scene with every broadphase. Cells: missing / extra pairs against the exact "
        "AABB pairs (Bullet's TestAabbAgainstAabb2 over the boxes the broadphase was given, "
        "with the pair cache's filter), **summed over all frames**; `exact` = 0 / 0. *Live*: "
        "each broadphase in its own Bullet world. *Replay*: the first broadphase's live run "
        "recorded and that one stream replayed into every broadphase (identical input, no "
        "world). `true pairs` = exact pairs in the last frame.\n\n### Live\n\n");
    for (const char* mode : {"live", "replay"}) {
        if (mode == std::string("replay")) {
            context.add("\n### Replay of one recorded stream\n\n");
        }
        context.add(sceneByBroadphase(scenes.names, broadphases, {"objects", "true pairs"}, objects,
                                      [&](const std::string& scene, const std::string& broadphase) {
                                          const long row = find(pairs, scene, broadphase, mode);
                                          return row < 0 ? std::string()
                                                         : errorsCell(pairs, std::size_t(row));
                                      }));
    }
    context.add(
        "\n### Pairs reported in the last frame (live) and broadphase ms per frame "
        "(replay: identical input)\n\n");
    context.add(sceneByBroadphase(
        scenes.names, broadphases, {"true pairs"},
        [&](const std::string& scene) { return std::vector<std::string>{objects(scene)[1]}; },
        [&](const std::string& scene, const std::string& broadphase) {
            const long live = find(pairs, scene, broadphase, "live");
            const long replay = find(pairs, scene, broadphase, "replay");
            if (live < 0 || pairs.at(live, "status") != "ok") {
                return std::string("-");
            }
            return pairs.at(live, "pairs") + " / " +
                   (replay < 0 ? "-" : fmt(pairs.number(replay, "broadphase_ms")) + " ms");
        }));

    // Reading: exactness of kolize's broadphases; Bullet's errors; fastest per scene.
    std::map<std::string, int> exact, runs;
    std::map<std::string, double> extraOf, missingOf;
    std::vector<std::string> differences, errors, fastestPerScene;
    for (std::size_t r = 0; r < pairs.size(); ++r) {
        const std::string& broadphase = pairs.at(r, "broadphase");
        const std::string& mode = pairs.at(r, "mode");
        const std::string& status = pairs.at(r, "status");
        if (status.rfind("error", 0) == 0) {
            errors.push_back(pairs.at(r, "scene") + " " + broadphase + " " + mode + ": " + status);
        }
        if (status != "ok") {
            continue;
        }
        const bool zero = pairs.at(r, "missing") == "0" && pairs.at(r, "extra") == "0";
        if (broadphase == "store-only") {
            continue;  // the floor: finds no pairs by design
        }
        if (kolize::isExactBroadphase(broadphase)) {
            ++runs[mode];
            exact[mode] += zero ? 1 : 0;
            if (!zero) {
                differences.push_back(pairs.at(r, "scene") + " " + broadphase + " " + mode + " (" +
                                      errorsCell(pairs, r) + ")");
            }
        } else {
            extraOf[broadphase + " " + mode] += pairs.number(r, "extra");
            missingOf[broadphase + " " + mode] += pairs.number(r, "missing");
        }
    }
    for (const std::string& scene : scenes.names) {
        const std::string best =
            fastest(pairs, scene, broadphases, "replay", "broadphase_ms", "dbvt");
        if (!best.empty()) {
            fastestPerScene.push_back(scene + ": " + best);
        }
    }
    std::vector<std::string> bullet;
    for (const auto& [key, extra] : extraOf) {
        bullet.push_back(key + ": " + fmt(extra) + " extra, " + fmt(missingOf[key]) + " missing");
    }
    context.add(
        "\n**Reading:** kolize's exact broadphases were exact in " + std::to_string(exact["live"]) +
        " of " + std::to_string(runs["live"]) + " live runs and " +
        std::to_string(exact["replay"]) + " of " + std::to_string(runs["replay"]) +
        " replayed runs; differences: " + orNone(differences) +
        ". Bullet's, summed over scenes and frames: " + orNone(bullet) +
        ". Runs that failed: " + orNone(errors) +
        ". Fastest broadphase per scene on the replayed stream: " + orNone(fastestPerScene) +
        ".\n");

    // The floor: every replay against store-only's on the same stream.
    context.heading("Each scene's frame split: the store-only floor and the broadphase's own work");
    context.add(
        "Replayed streams (identical input; no world): `store-only` only stores the boxes and "
        "finds no pairs, the least any drop-in broadphase can cost on that stream. Cells: ms "
        "per frame above the floor (the broadphase's own work), and in brackets the whole "
        "frame as a multiple of the floor.\n\n");
    std::vector<std::string> floorReading;
    context.add(sceneByBroadphase(
        scenes.names, broadphases, {"floor ms"},
        [&](const std::string& scene) {
            const long row = find(pairs, scene, "store-only", "replay");
            return std::vector<std::string>{row < 0 ? "-"
                                                    : fmt(pairs.number(row, "broadphase_ms"))};
        },
        [&](const std::string& scene, const std::string& broadphase) {
            const long row = find(pairs, scene, broadphase, "replay");
            const long floorRow = find(pairs, scene, "store-only", "replay");
            if (row < 0 || floorRow < 0 || pairs.at(row, "status") != "ok") {
                return std::string("-");
            }
            const double ms = pairs.number(row, "broadphase_ms");
            const double floorMs = pairs.number(floorRow, "broadphase_ms");
            return fmt(std::max(0.0, ms - floorMs)) + " (" + fmt(ms / floorMs) + "x)";
        }));
    for (const std::string& scene : scenes.names) {
        const long floorRow = find(pairs, scene, "store-only", "replay");
        const std::string best = fastest(pairs, scene, broadphases, "replay", "broadphase_ms", "");
        const long bestRow =
            best.empty() ? -1 : find(pairs, scene, best.substr(0, best.find(' ')), "replay");
        if (floorRow >= 0 && bestRow >= 0) {
            floorReading.push_back(scene + " " +
                                   fmt(pairs.number(bestRow, "broadphase_ms") /
                                       pairs.number(floorRow, "broadphase_ms")) +
                                   "x");
        }
    }
    context.add("\n**Reading:** the fastest broadphase's frame as a multiple of the floor: " +
                orNone(floorReading) + ".\n");

    // Rays: only scenes that cast them.
    context.heading("Ray casts");
    const std::vector<std::string> rayScenes = scenes.among(scenes.rays);
    if (rayScenes.empty()) {
        context.add("No registered scene casts rays, so there are no ray timings.\n");
        return;
    }
    context.add(
        "Median ms per frame spent in the scene's ray casts (live runs above), for the "
        "scenes that cast rays:\n\n");
    std::vector<std::string> rayReading;
    context.add(sceneByBroadphase(
        rayScenes, broadphases, {}, [](const std::string&) { return std::vector<std::string>{}; },
        [&](const std::string& scene, const std::string& broadphase) {
            const long row = find(pairs, scene, broadphase, "live");
            return row < 0 ? std::string("-") : fmt(pairs.number(row, "ray_ms"));
        }));
    for (const std::string& scene : rayScenes) {
        rayReading.push_back(scene + ": " +
                             fastest(pairs, scene, broadphases, "live", "ray_ms", "dbvt"));
    }
    context.add("\n**Reading:** fastest ray casts: " + orNone(rayReading) + ".\n");
}

void determinismSection(Context& context, const SceneList& scenes) {
    context.heading("Determinism: bit-identical to `simple`?");
    const std::vector<std::string> dynamic = scenes.among(scenes.dynamics);
    if (dynamic.empty()) {
        context.add("No registered scene has dynamics.\n");
        return;
    }
    std::vector<std::string> broadphases;
    for (const std::string& name : kolize::broadphaseNames()) {
        if (name != "simple" && name != "sap32") {
            broadphases.push_back(name);
        }
    }
    std::vector<std::string> args = {"--scene", join(dynamic, ","), "--broadphase",
                                     join(broadphases, ","), "--determinism"};
    const std::vector<std::string> size = sizing(context);
    args.insert(args.end(), size.begin(), size.end());
    Csv csv;
    if (!context.measure("determinism", context.demo, args, csv)) {
        return;
    }
    context.add(
        "With Bullet's deterministic pair order (`m_deterministicOverlappingPairs`), "
        "every dynamic body's transform and velocities hashed bit for bit every frame "
        "and compared with a run of `simple` (exact pairs, O(N^2)). Cells: `yes`, or "
        "`no @ F` with the first differing frame.\n\n");
    std::vector<std::string> same, differ;
    context.add(sceneByBroadphase(
        dynamic, broadphases, {}, [](const std::string&) { return std::vector<std::string>{}; },
        [&](const std::string& scene, const std::string& broadphase) {
            const long row = find(csv, scene, broadphase, "live");
            if (row < 0) {
                return std::string();
            }
            const std::string& identical = csv.at(row, "identical_to_simple");
            if (identical.empty()) {
                return csv.at(row, "status");
            }
            const std::string what = broadphase + " on " + scene;
            if (identical == "yes") {
                same.push_back(what);
                return identical;
            }
            differ.push_back(what + " from frame " + csv.at(row, "first_difference_frame"));
            return "no @ " + csv.at(row, "first_difference_frame");
        }));
    std::vector<std::string> kolizeDiffer;
    for (const std::string& item : differ) {
        if (kolize::isExactBroadphase(split(item, ' ')[0])) {
            kolizeDiffer.push_back(item);
        }
    }
    context.add("\n**Reading:** " + std::to_string(same.size()) + " of " +
                std::to_string(same.size() + differ.size()) +
                " runs bit-identical to simple. Differences of kolize's exact broadphases: " +
                orNone(kolizeDiffer) + "; all differences: " + orNone(differ) + ".\n");
}

void dynamicsSection(Context& context, const SceneList& scenes) {
    context.heading("Dynamics: accuracy against run time (time step, substeps, Bullet's CCD)");
    std::vector<std::string> missing;
    const std::vector<std::string> wanted =
        context.quick
            ? std::vector<std::string>{"boxes", "escape", "tall-stack"}
            : std::vector<std::string>{"boxes", "pyramid", "mixed-sizes", "escape", "tall-stack"};
    const std::vector<std::string> chosen = scenes.present(wanted, missing);
    if (!missing.empty()) {
        context.add("*Not registered in this build, so not measured: " + join(missing, ", ") +
                    ".*\n\n");
    }
    if (chosen.empty()) {
        return;
    }
    struct Step {
        int perSecond;  ///< frames per second: time step 1/perSecond
        int substeps;
    };
    const std::vector<Step> steps =
        context.quick ? std::vector<Step>{{60, 1}, {60, 2}, {60, 4}}
                      : std::vector<Step>{{30, 1}, {30, 2}, {30, 4}, {30, 8}, {30, 16},
                                          {60, 1}, {60, 2}, {60, 4}, {60, 8}};
    const double seconds = context.quick ? 0.5 : 2;  // simulated time per run
    struct Point {
        std::string scene, label, ccd;
        double stepMs, penetration, escaped, drift;
    };
    std::vector<Point> points;
    std::vector<std::string> commands;
    for (const Step& step : steps) {
        for (const char* ccd : {"off", "on"}) {
            const int rate = step.perSecond * step.substeps;  // 1 / h
            const std::string name = "dynamics-" + std::to_string(step.perSecond) + "x" +
                                     std::to_string(step.substeps) + "-ccd-" + ccd;
            std::vector<std::string> args = {"--scene",
                                             join(chosen, ","),
                                             "--broadphase",
                                             "dbvt",
                                             "--timestep",
                                             "1/" + std::to_string(step.perSecond),
                                             "--substeps",
                                             std::to_string(step.substeps),
                                             "--bullet-ccd",
                                             ccd,
                                             "--reference-substeps",
                                             std::to_string(960 / rate),
                                             "--frames",
                                             std::to_string(int(seconds * step.perSecond))};
            if (context.quick) {
                args.insert(args.end(), {"--n", "128"});
            }
            std::string shown;
            Csv csv;
            const bool ran = context.runCsv(name, context.demo, args, csv, shown);
            commands.push_back(shown);
            if (!ran) {
                continue;
            }
            for (std::size_t r = 0; r < csv.size(); ++r) {
                if (csv.at(r, "status") != "ok") {
                    continue;
                }
                points.push_back(
                    {csv.at(r, "scene"),
                     "1/" + std::to_string(step.perSecond) + " x" + std::to_string(step.substeps),
                     ccd, csv.number(r, "step_ms"), csv.number(r, "max_penetration"),
                     csv.number(r, "escaped"), csv.number(r, "drift_max")});
            }
        }
    }
    context.commands(commands);
    context.add(
        "Each scene with Bullet's dbvt (the dynamics do not depend on which exact broadphase "
        "finds the pairs; see the determinism section), " +
        fmt(seconds) +
        " s of simulated time per run, time step T x substeps K giving h = T / K from 1/" +
        std::to_string(steps.front().perSecond * steps.front().substeps) + " to 1/" +
        std::to_string(steps.back().perSecond * steps.back().substeps) +
        " s, Bullet's CCD off and on. Error measures (max over frames): deepest penetration "
        "(m), escaped bodies (tunnelled out of the scene's container), and the largest drift "
        "of a body's final position from a reference run at h = 1/960 s. x = median ms per "
        "step. Pareto: no other configuration is both cheaper and at least as accurate.\n\n");
    std::string reading;
    for (const std::string& scene : chosen) {
        std::vector<Point> mine;
        for (const Point& p : points) {
            if (p.scene == scene) {
                mine.push_back(p);
            }
        }
        std::sort(mine.begin(), mine.end(),
                  [](const Point& a, const Point& b) { return a.stepMs < b.stepMs; });
        std::vector<std::pair<double, double>> pen, drift;
        for (const Point& p : mine) {
            pen.push_back({p.stepMs, p.penetration});
            drift.push_back({p.stepMs, p.drift});
        }
        const std::vector<bool> penFront = paretoFront(pen);
        const std::vector<bool> driftFront = paretoFront(drift);
        std::vector<std::vector<std::string>> rows;
        std::string body;
        std::map<std::string, std::vector<std::string>> series;
        std::vector<std::string> penBest, driftBest;
        for (std::size_t i = 0; i < mine.size(); ++i) {
            const Point& p = mine[i];
            rows.push_back({p.label, p.ccd, fmt(p.stepMs), fmt(p.penetration), fmt(p.escaped),
                            fmt(p.drift), penFront[i] ? "pen" : "", driftFront[i] ? "drift" : ""});
            series[p.ccd].push_back(std::to_string(p.stepMs) + " " + std::to_string(p.penetration) +
                                    " " + std::to_string(p.escaped) + " " +
                                    std::to_string(p.drift) + " \"" + p.label + "\"");
            if (penFront[i]) {
                penBest.push_back(p.label + " ccd " + p.ccd + " (" + fmt(p.stepMs) + " ms, " +
                                  fmt(p.penetration) + " m)");
            }
            if (driftFront[i]) {
                driftBest.push_back(p.label + " ccd " + p.ccd + " (" + fmt(p.stepMs) + " ms, " +
                                    fmt(p.drift) + " m)");
            }
        }
        context.add("### " + scene + "\n\n" +
                    markdownTable({"T x K", "Bullet CCD", "step ms", "max penetration m", "escaped",
                                   "drift max m", "Pareto (pen)", "Pareto (drift)"},
                                  rows) +
                    "\n");
        for (const auto& [ccd, lines] : series) {
            body += dataBlock("ccd" + ccd, lines);
        }
        body += "set multiplot layout 1,3 title \"" + scene +
                ": error against ms per step (labels: time step x substeps)\"\n"
                "set logscale x\nset grid\nset key top right\nset xlabel \"ms per step\"\n";
        const std::vector<std::pair<int, std::string>> panels = {
            {2, "max penetration (m)"}, {3, "escaped bodies"}, {4, "drift max (m)"}};
        for (const auto& [column, title] : panels) {
            body += "set title \"" + title + "\"\nset ylabel \"" + title + "\"\nplot ";
            bool first = true;
            for (const auto& entry : series) {
                const std::string& ccd = entry.first;
                const std::string col = std::to_string(column);
                body += std::string(first ? "" : ", \\\n     ") + "$ccd" + ccd + " using 1:" + col +
                        " with points pt 7 title \"CCD " + ccd + "\", $ccd" + ccd +
                        " using 1:" + col + ":5 with labels font \",7\" offset char 0,0.8 notitle";
                first = false;
            }
            body += "\n";
        }
        body += "unset multiplot\n";
        context.add(
            context.plot("dynamics-" + scene, scene + ": error against time", body, 1500, 450));
        reading += "- " + scene + ": Pareto for penetration: " + orNone(penBest) +
                   "; for drift: " + orNone(driftBest) + ".\n";
    }
    context.add("\n**Reading:**\n\n" + reading);
}

void stabilitySection(Context& context, const SceneList& scenes, const Csv& pairs) {
    context.heading("Numerical stability: extreme and stiff scenes, float and double");
    const std::vector<std::string> chosen = scenes.inGroups({"extreme", "stiff"});
    if (chosen.empty()) {
        context.add(
            "*No scene of the groups extreme or stiff is registered in this build, so "
            "this table is empty.*\n");
        return;
    }
    Csv doubles;
    bool haveDouble = false;
    if (!context.doubleDemo.empty()) {
        std::vector<std::string> args = {"--scene", join(chosen, ","), "--broadphase", "all"};
        const std::vector<std::string> size = sizing(context);
        args.insert(args.end(), size.begin(), size.end());
        haveDouble = context.measure("stability-double", context.doubleDemo, args, doubles);
    } else {
        context.add("*No double-precision column: " + context.doubleDemoNote +
                    " (scripts/report.sh builds one in build-double/).*\n\n");
    }
    context.add(
        "Float: the live runs of the pair-output section. Double: the same scenes with a "
        "kolize-demo built against Bullet's -float64 libraries. Cells: pairs (`exact` or "
        "missing / extra summed over frames), NaN bodies (max over frames), energy growth "
        "(max - start, J). A crash would show as a failed command at the end of the report; "
        "CI also runs the whole test suite under ASan + UBSan (`.ci/run`).\n\n");
    std::vector<std::vector<std::string>> rows;
    int inexact = 0, nonFinite = 0, failed = 0, total = 0;
    double worstGrowth = kNaN;
    std::string worstWhere;
    auto cells = [&](const Csv& csv, const std::string& scene, const std::string& broadphase,
                     const std::string& precision) {
        const long row = find(csv, scene, broadphase, "live");
        if (row < 0) {
            return std::vector<std::string>{"-", "-", "-"};
        }
        ++total;
        const std::string pairsCell = errorsCell(csv, std::size_t(row));
        if (csv.at(row, "status") != "ok") {
            failed += pairsCell == "**error**" ? 1 : 0;
            return std::vector<std::string>{pairsCell, "-", "-"};
        }
        inexact += kolize::isExactBroadphase(broadphase) && pairsCell != "exact" ? 1 : 0;
        nonFinite += csv.number(row, "nonfinite") > 0 ? 1 : 0;
        const double growth = csv.number(row, "energy_max") - csv.number(row, "energy_start");
        if (std::isfinite(growth) && !(growth <= worstGrowth)) {
            worstGrowth = growth;
            worstWhere = scene + " " + broadphase + " " + precision;
        }
        return std::vector<std::string>{pairsCell, csv.at(row, "nonfinite"), fmt(growth)};
    };
    for (const std::string& scene : chosen) {
        for (const std::string& broadphase : pairs.distinct("broadphase")) {
            std::vector<std::string> row = {scene, broadphase};
            for (const std::string& cell : cells(pairs, scene, broadphase, "float")) {
                row.push_back(cell);
            }
            if (haveDouble) {
                for (const std::string& cell : cells(doubles, scene, broadphase, "double")) {
                    row.push_back(cell);
                }
            }
            rows.push_back(row);
        }
    }
    std::vector<std::string> header = {"scene", "broadphase", "float pairs", "float NaN",
                                       "float energy growth J"};
    if (haveDouble) {
        header.insert(header.end(), {"double pairs", "double NaN", "double energy growth J"});
    }
    context.add(markdownTable(header, rows));
    context.add("\n**Reading:** " + std::to_string(total) + " runs" +
                (haveDouble ? " (float and double)" : " (float only)") +
                "; kolize's exact "
                "broadphases not exact in " +
                std::to_string(inexact) +
                "; runs with NaN "
                "bodies: " +
                std::to_string(nonFinite) + "; runs that ended in an error: " +
                std::to_string(failed) + "; largest energy growth " + fmt(worstGrowth) + " J (" +
                (worstWhere.empty() ? std::string("-") : worstWhere) + ").\n");
}

}  // namespace

void demoSections(Context& context) {
    SceneList scenes;
    context.heading("Bullet worlds (kolize-demo)");
    if (context.demo.empty()) {
        std::string shown;
        context.runTool("kolize-demo", {}, {}, shown);
        return;
    }
    if (!loadScenes(context, scenes)) {
        return;
    }
    Csv pairs;
    pairSections(context, scenes, pairs);
    determinismSection(context, scenes);
    dynamicsSection(context, scenes);
    stabilitySection(context, scenes, pairs);
}

}  // namespace report

// kolize-report's broadphase sections, all from kolize-bench and kolize-bench-2d CSV: the
// thesis's tables, scaling, parameter sweeps, the store-only lower bound, 2D vs Box2D.

#include "report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

namespace report {

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The thesis's methods and the kolize broadphase that implements each.
const std::vector<std::pair<std::string, std::string>> kMethods = {
    {"A", "grid"}, {"B", "spatial-tree"}, {"C", "segment-trees"}, {"D", "range-tree"}};

const std::vector<std::string> kScenes = {"A", "B"};

std::string sceneTitle(const std::string& scene) {
    return scene == "A" ? "A (uniform)" : "B (clustered)";
}

/// The value of `column` for one kolize-bench run, NaN when skipped or absent.
double benchValue(const Csv& csv, const std::string& scene, const std::string& motion,
                  const std::string& label, int n, const std::string& column) {
    for (std::size_t row : csv.where({{"scene", scene},
                                      {"motion", motion},
                                      {"broadphase", label},
                                      {"n", std::to_string(n)}})) {
        if (csv.at(row, "skipped").empty()) {
            return csv.number(row, column);
        }
    }
    return kNaN;
}

std::vector<int> counts(const Csv& csv) {
    std::set<int> out;
    for (const std::string& n : csv.distinct("n")) {
        out.insert(std::stoi(n));
    }
    return {out.begin(), out.end()};
}

std::string csvList(const std::vector<int>& values) {
    std::vector<std::string> words;
    for (int v : values) {
        words.push_back(std::to_string(v));
    }
    return join(words, ",");
}

/// "A < C < D < B" from method -> value; "-" when a value is missing.
std::string ranking(const std::map<std::string, double>& values) {
    std::vector<std::pair<double, std::string>> order;
    for (const auto& [method, value] : values) {
        if (!std::isfinite(value)) {
            return "-";
        }
        order.push_back({value, method});
    }
    std::sort(order.begin(), order.end());
    std::vector<std::string> names;
    for (const auto& entry : order) {
        names.push_back(entry.second);
    }
    return join(names, " < ");
}

/// Of the method pairs ordered in both, how many are in the same order: "5/6".
std::string pairsInOrder(const std::map<std::string, double>& a,
                         const std::map<std::string, double>& b, int& same, int& total) {
    int here = 0, compared = 0;
    for (auto i = a.begin(); i != a.end(); ++i) {
        for (auto j = std::next(i); j != a.end(); ++j) {
            const double bi = b.at(i->first), bj = b.at(j->first);
            if (std::isfinite(i->second) && std::isfinite(j->second) && std::isfinite(bi) &&
                std::isfinite(bj)) {
                ++compared;
                here += (i->second < j->second) == (bi < bj) ? 1 : 0;
            }
        }
    }
    same += here;
    total += compared;
    return std::to_string(here) + "/" + std::to_string(compared);
}

/// Gnuplot data lines "x y" for one broadphase of a bench CSV: N against f(row).
template <class F>
std::vector<std::string> seriesOverN(const Csv& csv, const std::string& scene,
                                     const std::string& motion, const std::string& label, F f) {
    std::vector<std::string> lines;
    for (int n : counts(csv)) {
        for (std::size_t row : csv.where({{"scene", scene},
                                          {"motion", motion},
                                          {"broadphase", label},
                                          {"n", std::to_string(n)}})) {
            const double y = f(row);
            if (csv.at(row, "skipped").empty() && std::isfinite(y) && y > 0) {
                lines.push_back(std::to_string(n) + " " + std::to_string(y));
            }
        }
    }
    return lines;
}

/// Two log-log panels (scenes A and B), one line per label, y from `f`.
template <class F>
std::string perScenePlot(const Csv& csv, const std::string& motion,
                         const std::vector<std::string>& labels, const std::string& ylabel,
                         const std::string& title, F f) {
    std::string body;
    for (const std::string& scene : kScenes) {
        for (std::size_t i = 0; i < labels.size(); ++i) {
            body += dataBlock("s" + scene + std::to_string(i),
                              seriesOverN(csv, scene, motion, labels[i], f));
        }
    }
    body += "set multiplot layout 1,2 title \"" + title +
            "\"\nset logscale xy\nset grid\nset key top left\nset xlabel \"N (objects)\"\n"
            "set ylabel \"" +
            ylabel + "\"\n";
    for (const std::string& scene : kScenes) {
        body += "set title \"scene " + sceneTitle(scene) + "\"\nplot ";
        for (std::size_t i = 0; i < labels.size(); ++i) {
            body += std::string(i > 0 ? ", \\\n     " : "") + "$s" + scene + std::to_string(i) +
                    " using 1:2 with linespoints title \"" + labels[i] + "\"";
        }
        body += "\n";
    }
    return body + "unset multiplot\n";
}

}  // namespace

void thesisSection(Context& context) {
    context.heading("The thesis's tables 2.3-2.7, reproduced");
    const std::vector<int> ns =
        context.quick ? std::vector<int>{250, 1000, 3000}
                      : std::vector<int>{250, 500, 750, 1000, 1250, 1500, 1750, 2000, 3000};
    const std::vector<std::string> labels = {"grid",
                                             "spatial-tree",
                                             "spatial-hash",
                                             "segment-trees",
                                             "range-tree",
                                             "grid:per-axis=17",
                                             "spatial-tree:per-axis=17",
                                             "dbvt",
                                             "sap",
                                             "sap-noray",
                                             "store-only"};
    Csv csv;
    Csv thesis;
    if (!context.measure("thesis", context.bench,
                         {"--n", csvList(ns), "--frames", context.quick ? "10" : "60",
                          "--broadphase", join(labels, ",")},
                         csv)) {
        return;
    }
    try {
        thesis = Csv::read(context.thesisTables);
    } catch (const std::exception& error) {
        context.runner.fail("read " + context.thesisTables.string(), error.what());
        context.add("*The thesis's numbers could not be read: " + std::string(error.what()) +
                    "*\n");
        return;
    }
    context.add(
        "The thesis's scenes (DIGEST section 7: space -500..500, cubes of edge 2, B with 95% in "
        "a cluster of edge 80), " +
        std::to_string(ns.size()) +
        " object counts. The thesis's times (Athlon 64, 2008; `assets/thesis/tables.csv`) and "
        "kolize's (this machine) are not comparable in absolute terms, so both are shown as "
        "**ratios to method C (segment trees) at the same N**: below 1 is faster than C. "
        "kolize's A and B are its default `grid` and `spatial-tree` (automatic cell size); "
        "the thesis's configuration, 17 cells per axis, is shown as `A 17^3` / `B 17^3`. "
        "Init = creating the proxies + the first pair search; detection = one frame's "
        "`setAabb` for every object + `calculateOverlappingPairs` (median over the frames). "
        "The thesis's tables 2.3-2.6 use calm motion, here `slow`.\n\n");
    struct TableSpec {
        std::string table, quantity, scene, column, title;
    };
    const std::vector<TableSpec> specs = {
        {"2.3", "init", "A", "init_ms", "Table 2.3: initialisation, uniform (A)"},
        {"2.4", "init", "B", "init_ms", "Table 2.4: initialisation, clustered (B)"},
        {"2.5", "detection", "A", "frame_ms", "Table 2.5: detection, uniform (A)"},
        {"2.6", "detection", "B", "frame_ms", "Table 2.6: detection, clustered (B)"}};
    auto thesisValue = [&](const std::string& table, const std::string& motion,
                           const std::string& method, const std::string& scene, int n) {
        const auto rows = thesis.where({{"table", table},
                                        {"motion", motion},
                                        {"method", method},
                                        {"scene", scene},
                                        {"n", std::to_string(n)}});
        return rows.empty() ? kNaN : thesis.number(rows.front(), "seconds");
    };
    const std::vector<std::string> extras = {
        "grid:per-axis=17", "spatial-tree:per-axis=17", "spatial-hash", "dbvt", "sap", "sap-noray",
        "store-only"};
    std::string summary;
    for (const TableSpec& spec : specs) {
        std::vector<std::vector<std::string>> rows;
        int holds = 0, winners = 0, compared = 0, pairsSame = 0, pairsTotal = 0;
        for (int n : counts(csv)) {
            const double thesisC = thesisValue(spec.table, "calm", "C", spec.scene, n);
            const double kolizeC =
                benchValue(csv, spec.scene, "slow", "segment-trees", n, spec.column);
            if (!std::isfinite(thesisC)) {
                continue;  // an N the thesis did not measure
            }
            std::map<std::string, double> thesisRatios, kolizeRatios;
            std::vector<std::string> row = {std::to_string(n), fmt(kolizeC)};
            for (const auto& [method, label] : kMethods) {
                thesisRatios[method] =
                    thesisValue(spec.table, "calm", method, spec.scene, n) / thesisC;
                kolizeRatios[method] =
                    benchValue(csv, spec.scene, "slow", label, n, spec.column) / kolizeC;
                if (method != "C") {
                    row.push_back(fmt(thesisRatios[method]) + " / " + fmt(kolizeRatios[method]));
                }
            }
            for (const std::string& label : extras) {
                row.push_back(
                    fmt(benchValue(csv, spec.scene, "slow", label, n, spec.column) / kolizeC));
            }
            const std::string thesisOrder = ranking(thesisRatios);
            const std::string kolizeOrder = ranking(kolizeRatios);
            row.push_back(thesisOrder);
            row.push_back(kolizeOrder);
            row.push_back(thesisOrder == kolizeOrder ? "holds" : "differs");
            row.push_back(pairsInOrder(thesisRatios, kolizeRatios, pairsSame, pairsTotal));
            ++compared;
            holds += thesisOrder == kolizeOrder ? 1 : 0;
            winners += thesisOrder.substr(0, 1) == kolizeOrder.substr(0, 1) ? 1 : 0;
            rows.push_back(row);
        }
        context.add("### " + spec.title + "\n\n");
        context.add(markdownTable(
            {"N", "C ms (kolize)", "A thesis / kolize", "B thesis / kolize", "D thesis / kolize",
             "A 17^3", "B 17^3", "spatial-hash", "dbvt", "sap", "sap-noray", "store-only",
             "thesis ranking", "kolize ranking", "ranking", "method pairs in the same order"},
            rows));
        const std::string line =
            "Table " + spec.table + ": the thesis's ranking " +
            (holds == compared && compared > 0 ? "holds" : "differs") + " (same order at " +
            std::to_string(holds) + " of " + std::to_string(compared) +
            " N; same fastest method at " + std::to_string(winners) + " of " +
            std::to_string(compared) + "; " + std::to_string(pairsSame) + " of " +
            std::to_string(pairsTotal) + " method pairs in the thesis's order).";
        context.add("\n**Reading:** " + line + "\n\n");
        summary += "- " + line + "\n";
    }

    // Table 2.7: fast / slow per method and scene, medians over the N both measured.
    context.add("### Table 2.7: slow against fast motion\n\n");
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> thesisSensitive, kolizeSensitive;
    for (const std::string& scene : kScenes) {
        for (const auto& [method, label] : kMethods) {
            std::vector<double> thesisRatios, kolizeRatios;
            for (int n : counts(csv)) {
                const double thesisRatio = thesisValue("2.7", "fast", method, scene, n) /
                                           thesisValue("2.7", "slow", method, scene, n);
                if (!std::isfinite(thesisRatio)) {
                    continue;  // an N the thesis did not measure
                }
                thesisRatios.push_back(thesisRatio);
                kolizeRatios.push_back(benchValue(csv, scene, "fast", label, n, "frame_ms") /
                                       benchValue(csv, scene, "slow", label, n, "frame_ms"));
            }
            const double t = medianOf(thesisRatios);
            const double k = medianOf(kolizeRatios);
            rows.push_back({scene, method + " (" + label + ")", times(t), times(k)});
            if (t > 1.25) {
                thesisSensitive.push_back(method + "/" + scene);
            }
            if (k > 1.25) {
                kolizeSensitive.push_back(method + "/" + scene);
            }
        }
    }
    context.add(markdownTable(
        {"scene", "method", "thesis fast/slow (median over N)", "kolize fast/slow"}, rows));
    const std::string line27 =
        "Table 2.7: slower by more than 25% under fast motion: thesis " +
        (thesisSensitive.empty() ? std::string("none") : join(thesisSensitive, ", ")) +
        "; kolize " +
        (kolizeSensitive.empty() ? std::string("none") : join(kolizeSensitive, ", ")) + " (" +
        (thesisSensitive == kolizeSensitive ? "the same" : "not the same") + ").";
    context.add("\n**Reading:** " + line27 +
                " The thesis measured N = 500 ... 3000; kolize's "
                "medians use the N of this run that the thesis also has.\n\n");
    summary += "- " + line27 + "\n";
    context.add(context.plot(
        "thesis-detection", "detection time per frame against N",
        perScenePlot(
            csv, "slow",
            {"grid", "spatial-tree", "segment-trees", "range-tree", "dbvt", "sap", "store-only"},
            "ms per frame (median)",
            "kolize-bench, thesis scenes, slow motion: detection time per frame",
            [&](std::size_t row) { return csv.number(row, "frame_ms"); })));
    context.add("\n**Summary of the thesis comparison:**\n\n" + summary);
}

void scalingSection(Context& context) {
    context.heading("Scaling to 100 000 objects");
    const std::vector<int> ns = context.quick ? std::vector<int>{1000, 3000, 10000}
                                              : std::vector<int>{1000, 3000, 10000, 30000, 100000};
    const std::vector<std::string> labels = {"grid",          "spatial-tree", "spatial-hash",
                                             "segment-trees", "range-tree",   "dbvt",
                                             "sap",           "store-only"};
    Csv csv;
    if (!context.measure("scaling", context.bench,
                         {"--motion", "slow", "--n", csvList(ns), "--frames",
                          context.quick ? "5" : "30", "--broadphase", join(labels, ",")},
                         csv)) {
        return;
    }
    context.add(
        "Time per object per frame (µs, median frame / N), slow motion. A flat line "
        "is linear scaling. `sap` stops at 32 766 proxies (btAxisSweep3's 16-bit "
        "handles). Frames: " +
        std::string(context.quick ? "5" : "30 (15 at N = 100 000)") + ".\n\n");
    context.add(context.plot(
        "scaling", "time per object against N, log-log",
        perScenePlot(csv, "slow", labels, "µs per object per frame",
                     "kolize-bench, slow motion: time per object per frame against N",
                     [&](std::size_t row) {
                         return 1000 * csv.number(row, "frame_ms") / csv.number(row, "n");
                     })));
    std::string reading;
    for (const std::string& scene : kScenes) {
        std::vector<std::string> header = {"broadphase"};
        const std::vector<int> runCounts = counts(csv);
        for (int n : runCounts) {
            header.push_back("N=" + std::to_string(n));
        }
        header.push_back("slope (log t / log N)");
        std::vector<std::vector<std::string>> rows;
        std::string fastest;
        double fastestMs = kNaN;
        const int largest = runCounts.back();
        for (const std::string& label : labels) {
            std::vector<std::string> row = {label};
            double firstN = kNaN, firstMs = kNaN, lastN = kNaN, lastMs = kNaN;
            for (int n : runCounts) {
                const double ms = benchValue(csv, scene, "slow", label, n, "frame_ms");
                row.push_back(fmt(1000 * ms / n));
                if (std::isfinite(ms)) {
                    if (!std::isfinite(firstN)) {
                        firstN = n;
                        firstMs = ms;
                    }
                    lastN = n;
                    lastMs = ms;
                }
                if (n == largest && label != "store-only" && std::isfinite(ms) &&
                    !(ms >= fastestMs)) {
                    fastestMs = ms;
                    fastest = label;
                }
            }
            row.push_back(
                lastN > firstN ? fmt(std::log(lastMs / firstMs) / std::log(lastN / firstN)) : "-");
            rows.push_back(row);
        }
        context.add("### Scene " + sceneTitle(scene) + ", µs per object per frame\n\n" +
                    markdownTable(header, rows) + "\n");
        reading += "- scene " + sceneTitle(scene) + ": fastest at N = " + std::to_string(largest) +
                   ": " + fastest + " (" + fmt(fastestMs) + " ms per frame, " +
                   fmt(1000 * fastestMs / largest) + " µs per object).\n";
    }
    context.add("**Reading** (slope 1 = linear in N):\n\n" + reading);
}

void sweepSection(Context& context) {
    context.heading("Error against run time: cell size and S sweeps");
    const int n = context.quick ? 1000 : 3000;
    std::vector<std::string> labels;
    for (const char* name : {"grid", "spatial-hash"}) {
        labels.push_back(name);
        for (const char* factor : {"0.5", "1", "2", "4", "8"}) {
            labels.push_back(std::string(name) + ":factor=" + factor);
        }
    }
    for (const char* name : {"segment-trees", "range-tree"}) {
        labels.push_back(name);
        for (const char* s : {"100", "500", "1000", "1500", "2000", "5000"}) {
            labels.push_back(std::string(name) + ":divisions=" + s);
        }
    }
    for (const char* name : {"dbvt", "sap", "sap-noray", "store-only"}) {
        labels.push_back(name);
    }
    Csv csv;
    if (!context.measure("sweep", context.bench,
                         {"--motion", "slow", "--n", std::to_string(n), "--frames",
                          context.quick ? "5" : "30", "--broadphase", join(labels, ",")},
                         csv)) {
        return;
    }
    context.add(
        "One point per configuration, N = " + std::to_string(n) +
        ", slow motion. x: for kolize's broadphases the candidate pairs the exact box test "
        "rejected in the last frame (their output is exact; the rejected candidates are the "
        "cost of the cell size or S); for Bullet's, the extra pairs they report (false "
        "positives the narrowphase then pays for). y: ms per frame. `factor` = cell edge in "
        "median object extents; `divisions` = the thesis's S (leaf width = scene / S). "
        "Pareto-optimal points (no other point is at least as good on both axes and better on "
        "one) are marked; store-only (finds no pairs) is the floor line.\n\n");
    std::string body, plots, reading;
    for (const std::string& scene : kScenes) {
        struct Point {
            std::string label;
            double x, y;
            bool pareto = false;
        };
        std::vector<Point> points;
        double floorMs = kNaN;
        for (const std::string& label : labels) {
            const double ms = benchValue(csv, scene, "slow", label, n, "frame_ms");
            if (label == "store-only") {
                floorMs = ms;
                continue;
            }
            const bool bullet = label == "dbvt" || label.rfind("sap", 0) == 0;
            const double x = bullet ? benchValue(csv, scene, "slow", label, n, "extra")
                                    : benchValue(csv, scene, "slow", label, n, "candidates") -
                                          benchValue(csv, scene, "slow", label, n, "pairs");
            if (std::isfinite(ms) && std::isfinite(x)) {
                points.push_back({label, x, ms});
            }
        }
        std::vector<std::pair<double, double>> xy;
        for (const Point& p : points) {
            xy.push_back({p.x, p.y});
        }
        const std::vector<bool> front = paretoFront(xy);
        for (std::size_t i = 0; i < points.size(); ++i) {
            points[i].pareto = front[i];
        }
        std::vector<std::vector<std::string>> rows;
        std::vector<std::string> frontLines, frontNames;
        std::map<std::string, std::vector<std::string>> families;
        std::vector<Point> sorted = points;
        std::sort(sorted.begin(), sorted.end(),
                  [](const Point& a, const Point& b) { return a.x < b.x; });
        for (const Point& p : sorted) {
            rows.push_back(
                {p.label, fmt(p.y), fmt(p.x), times(p.y / floorMs), p.pareto ? "**yes**" : ""});
            // One series per family; labels only on the front and on Bullet's points.
            const std::string family = split(p.label, ':')[0];
            const bool bullet = family == "dbvt" || family.rfind("sap", 0) == 0;
            families[bullet ? "Bullet" : family].push_back(
                std::to_string(p.x + 1) + " " + std::to_string(p.y) + " \"" +
                (p.pareto || bullet ? p.label : "") + "\"");
            if (p.pareto) {
                frontLines.push_back(std::to_string(p.x + 1) + " " + std::to_string(p.y));
                frontNames.push_back(p.label + " (" + fmt(p.y) + " ms)");
            }
        }
        context.add("### Scene " + sceneTitle(scene) + "\n\n" +
                    markdownTable({"configuration", "ms per frame", "rejected / extra pairs",
                                   "x store-only", "Pareto"},
                                  rows) +
                    "\n");
        plots += "set title \"scene " + sceneTitle(scene) + "\"\nplot ";
        int index = 0;
        for (const auto& [family, lines] : families) {
            const std::string block = "f" + scene + std::to_string(index++);
            body += dataBlock(block, lines);
            plots += "$" + block + " using 1:2 with points pt " + std::to_string(4 + 2 * index) +
                     " ps 1.3 lc " + std::to_string(index) + " title \"" + family + "\", $" +
                     block +
                     " using 1:2:3 with labels font \",8\" offset char 0,0.9 notitle, \\\n     ";
        }
        body += dataBlock("front" + scene, frontLines);
        plots += "$front" + scene + " using 1:2 with lines lw 2 title \"Pareto front\"";
        if (std::isfinite(floorMs)) {
            plots +=
                ", " + std::to_string(floorMs) + " with lines dt 2 lc black title \"store-only\"";
        }
        plots += "\n";
        reading += "- scene " + sceneTitle(scene) + ": Pareto front " + join(frontNames, ", ") +
                   "; store-only floor " + fmt(floorMs) + " ms.\n";
    }
    body += "set multiplot layout 1,2 title \"Error against run time, N = " + std::to_string(n) +
            " (x: rejected candidates for kolize, extra pairs for Bullet's)\"\nset logscale xy\n"
            "set grid\nset key top right\nset xlabel \"rejected or extra pairs + 1 (last frame)\"\n"
            "set ylabel \"ms per frame\"\n" +
            plots + "unset multiplot\n";
    context.add(context.plot("sweep", "error against run time", body, 1400, 600));
    context.add("\n**Reading:**\n\n" + reading);
}

void lowerBoundSection(Context& context) {
    context.heading("The lower bound: multiples of store-only");
    context.add(
        "`store-only` (`engine/include/kolize/engine/store_only.h`) is a valid "
        "`btBroadphaseInterface` that only stores the boxes it is given and finds no pairs. "
        "Timed by the same driver in the same run, its frame time is what any drop-in "
        "broadphase must spend receiving Bullet's calls (`setAabb` x N, a virtual call and a "
        "store each, + `calculateOverlappingPairs`). Every other broadphase's frame time as a "
        "multiple of it (`x_store_only` in the CSV), from the scaling run (slow motion):\n\n");
    Csv csv;
    if (!context.load("scaling.csv", csv)) {
        return;
    }
    std::string reading;
    for (const std::string& scene : kScenes) {
        std::vector<std::string> header = {"broadphase"};
        const std::vector<int> ns = counts(csv);
        for (int n : ns) {
            header.push_back("N=" + std::to_string(n));
        }
        std::vector<std::vector<std::string>> rows;
        std::vector<std::string> labels = csv.distinct("broadphase");
        std::string best;
        double bestMultiple = kNaN;
        for (const std::string& label : labels) {
            std::vector<std::string> row = {label};
            for (int n : ns) {
                const double multiple = benchValue(csv, scene, "slow", label, n, "x_store_only");
                row.push_back(
                    label == "store-only"
                        ? fmt(1e6 * benchValue(csv, scene, "slow", label, n, "frame_ms") / n) +
                              " ns/object"
                        : times(multiple));
                if (n == ns.back() && label != "store-only" && !std::isnan(multiple) &&
                    !(multiple >= bestMultiple)) {
                    bestMultiple = multiple;
                    best = label;
                }
            }
            rows.push_back(row);
        }
        context.add("### Scene " + sceneTitle(scene) + "\n\n" + markdownTable(header, rows) + "\n");
        reading += "- scene " + sceneTitle(scene) + ", N = " + std::to_string(ns.back()) +
                   ": closest to the lower bound is " + best + " at " + times(bestMultiple) +
                   " store-only's frame time.\n";
    }
    context.add("**Reading:**\n\n" + reading);
}

void box2dSection(Context& context) {
    context.heading("2D: kolize's cores against Box2D's dynamic tree");
    const std::vector<int> ns =
        // Not 100 000: 2D scene B then packs 95 000 squares into an 80 x 80 cluster,
        // 19 million true pairs, seconds per frame for every broadphase.
        context.quick ? std::vector<int>{1000, 3000} : std::vector<int>{1000, 3000, 10000};
    Csv csv;
    if (!context.measure("bench2d", context.bench2d,
                         {"--n", csvList(ns), "--frames", context.quick ? "5" : "60"}, csv)) {
        return;
    }
    context.add(
        "The thesis's scenes in 2D (squares of edge 2 in -500..500). Both sides keep a "
        "persistent pair set; Box2D's `b2BroadPhase` (fat AABBs in a `b2DynamicTree`) "
        "reports a superset, counted as extra pairs against the exact truth in the "
        "last frame. Cells: frame time / Box2D's frame time (below 1 = faster).\n\n");
    std::vector<std::string> cores;
    for (const std::string& name : csv.distinct("broadphase")) {
        if (name != "box2d") {
            cores.push_back(name);
        }
    }
    std::vector<std::string> header = {"scene", "motion", "N", "box2d ms", "box2d extra"};
    header.insert(header.end(), cores.begin(), cores.end());
    header.push_back("kolize missing+extra");
    std::vector<std::vector<std::string>> rows;
    std::map<std::string, std::vector<double>> ratios;
    for (const std::string& scene : csv.distinct("scene")) {
        for (const std::string& motion : csv.distinct("motion")) {
            for (int n : counts(csv)) {
                auto value = [&](const std::string& name, const std::string& column) {
                    const auto found = csv.where({{"scene", scene},
                                                  {"motion", motion},
                                                  {"n", std::to_string(n)},
                                                  {"broadphase", name}});
                    return found.empty() ? kNaN : csv.number(found.front(), column);
                };
                std::vector<std::string> row = {scene, motion, std::to_string(n),
                                                fmt(value("box2d", "frame_ms")),
                                                fmt(value("box2d", "extra"))};
                double errors = 0;
                for (const std::string& core : cores) {
                    const double ratio = value(core, "ratio_to_box2d");
                    row.push_back(fmt(ratio));
                    ratios[core].push_back(ratio);
                    const double wrong = value(core, "missing") + value(core, "extra");
                    errors += std::isfinite(wrong) ? wrong : 0;
                }
                row.push_back(fmt(errors));
                rows.push_back(row);
            }
        }
    }
    context.add(markdownTable(header, rows));
    std::vector<std::string> medians;
    for (const std::string& core : cores) {
        medians.push_back(core + " " + times(medianOf(ratios[core])));
    }
    context.add("\n**Reading:** median frame time as a multiple of Box2D's over all runs: " +
                join(medians, ", ") + ".\n\n");
    std::string body;
    for (const std::string& scene : kScenes) {
        for (std::size_t i = 0; i < cores.size(); ++i) {
            std::vector<std::string> lines;
            for (int n : counts(csv)) {
                for (std::size_t row : csv.where({{"scene", scene},
                                                  {"motion", "slow"},
                                                  {"n", std::to_string(n)},
                                                  {"broadphase", cores[i]}})) {
                    if (std::isfinite(csv.number(row, "ratio_to_box2d"))) {
                        lines.push_back(std::to_string(n) + " " + csv.at(row, "ratio_to_box2d"));
                    }
                }
            }
            body += dataBlock("s" + scene + std::to_string(i), lines);
        }
    }
    body +=
        "set multiplot layout 1,2 title \"kolize-bench-2d, slow motion: frame time / "
        "Box2D's\"\nset logscale xy\nset grid\nset key top left\nset xlabel \"N\"\n"
        "set ylabel \"frame time / Box2D's\"\n";
    for (const std::string& scene : kScenes) {
        body += "set title \"scene " + sceneTitle(scene) +
                "\"\nplot 1 with lines dt 2 lc "
                "black title \"Box2D\"";
        for (std::size_t i = 0; i < cores.size(); ++i) {
            body += ", \\\n     $s" + scene + std::to_string(i) +
                    " using 1:2 with linespoints title \"" + cores[i] + "\"";
        }
        body += "\n";
    }
    body += "unset multiplot\n";
    context.add(context.plot("box2d", "2D cores against Box2D", body));
}

}  // namespace report

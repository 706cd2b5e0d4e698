/// kolize-ccd-bench [DIR] [--csv FILE] [--sweep FILE] [--repeat N] [--passes N]
///
/// Runs every CCD method over a data set laid out as `<scene>/<vertex-face|edge-edge>/*.csv`
/// (the Sample-Queries format, see assets/ccd-data/Sample-Queries/README.md) and compares
/// with the ground truth. Prints, per method, data set and kind: false negatives, false
/// positives, mean and median microseconds per query, overall and split into colliding
/// and non-colliding queries. `--csv` writes one row per method, data set and kind (plus
/// `all` rows per method and kind); `--sweep` runs every method at tolerances 1e-8 ... 1e-1
/// and writes one row per method, tolerance and kind (error against run time). A query's
/// time is the median over `--passes` passes (default 3) of the mean of `--repeat`
/// consecutive runs (default 3).
#include "kolize/narrowphase/ccd_dataset.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

namespace {

using namespace kolize::ccd;

/// A method under test at one tolerance.
struct Method {
    std::string name;
    std::function<CcdResult(QueryKind, const LabeledQuery&)> run;
};

/// The method with its default settings, or with `tolerance` when given (a distance for
/// `cubic`, the hand-off ratio of the floating-point stage for `robust`).
Method makeMethod(const std::string& name, std::optional<double> tolerance = std::nullopt) {
    if (name == "cubic") {
        CubicSettings s;
        s.tolerance = tolerance.value_or(s.tolerance);
        return {name, [s](QueryKind k, const LabeledQuery& q) { return cubicQuery(k, q, s); }};
    }
    RobustSettings s;
    s.tolerance = tolerance.value_or(s.tolerance);
    return {name, [s](QueryKind k, const LabeledQuery& q) { return robustQuery(k, q, s); }};
}

/// Per-query outcome: answer and time.
struct Sample {
    bool truth;
    bool hit;
    double us;
};

struct Stats {
    size_t queries = 0, positives = 0, fn = 0, fp = 0;
    double mean = 0, median = 0, mean_pos = 0, median_pos = 0, mean_neg = 0, median_neg = 0;
};

void meanMedian(std::vector<double> v, double& mean, double& median) {
    if (v.empty()) {
        mean = median = 0.0;
        return;
    }
    mean = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    median = v[v.size() / 2];
}

Stats summarize(const std::vector<Sample>& samples) {
    Stats s;
    std::vector<double> all, pos, neg;
    for (const Sample& x : samples) {
        ++s.queries;
        s.positives += x.truth;
        s.fn += x.truth && !x.hit;
        s.fp += !x.truth && x.hit;
        all.push_back(x.us);
        (x.truth ? pos : neg).push_back(x.us);
    }
    meanMedian(all, s.mean, s.median);
    meanMedian(pos, s.mean_pos, s.median_pos);
    meanMedian(neg, s.mean_neg, s.median_neg);
    return s;
}

/// Timing of one query: `passes` times, the mean of `repeat` consecutive runs; the query's
/// time is the median over the passes. Passes go over the whole set in turn, so a burst of
/// load on a shared machine (a preemption costs milliseconds, a query microseconds) spoils
/// one pass of a few queries, not their reported time.
std::vector<Sample> runSet(const Method& m, const QuerySet& set, int repeat, int passes) {
    std::vector<std::vector<double>> times(set.queries.size());
    std::vector<Sample> out(set.queries.size());
    for (int pass = 0; pass < passes; ++pass) {
        for (size_t q = 0; q < set.queries.size(); ++q) {
            CcdResult r;
            const auto t0 = std::chrono::steady_clock::now();
            for (int i = 0; i < repeat; ++i) {
                r = m.run(set.kind, set.queries[q]);
            }
            const auto t1 = std::chrono::steady_clock::now();
            times[q].push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() / repeat);
            out[q] = {set.queries[q].collides, r.hit, 0.0};
        }
    }
    for (size_t q = 0; q < out.size(); ++q) {
        std::nth_element(times[q].begin(), times[q].begin() + passes / 2, times[q].end());
        out[q].us = times[q][passes / 2];
    }
    return out;
}

std::string defaultDir() {
    const char* shared = "../shared/ccd-data/Sample-Queries";
    if (std::filesystem::is_directory(shared)) {
        return shared;
    }
    return KOLIZE_CCD_DATA_DIR;
}

int usage() {
    std::cerr << "usage: kolize-ccd-bench [DIR] [--csv FILE] [--sweep FILE] [--repeat N] "
                 "[--passes N]\n";
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::string dir, csv_path, sweep_path;
    int repeat = 3, passes = 3;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if ((a == "--csv" || a == "--sweep" || a == "--repeat" || a == "--passes") &&
            i + 1 < argc) {
            const std::string v = argv[++i];
            if (a == "--csv") {
                csv_path = v;
            } else if (a == "--sweep") {
                sweep_path = v;
            } else if (a == "--repeat") {
                repeat = std::max(1, std::atoi(v.c_str()));
            } else {
                passes = std::max(1, std::atoi(v.c_str()));
            }
        } else if (!a.empty() && a[0] != '-' && dir.empty()) {
            dir = a;
        } else {
            return usage();
        }
    }
    if (dir.empty()) {
        dir = defaultDir();
    }
    std::vector<QuerySet> sets;
    try {
        sets = readQueryFolder(dir);
    } catch (const std::exception& e) {
        std::cerr << "kolize-ccd-bench: " << e.what() << "\n";
        return 1;
    }
    size_t total = 0;
    for (const auto& s : sets) {
        total += s.queries.size();
    }
    std::printf(
        "data: %s (%zu queries in %zu sets); a query's time: median over %d passes of the "
        "mean of %d runs\n\n",
        dir.c_str(), total, sets.size(), passes, repeat);

    std::ofstream csv;
    if (!csv_path.empty()) {
        csv.open(csv_path);
        csv << "method,dataset,kind,queries,positives,false_negatives,false_positives,mean_us,"
               "median_us\n";
    }
    const char* header = "%-8s %-28s %-11s %6s %5s %4s %4s | %8s %8s | %8s %8s | %8s %8s\n";
    const char* row =
        "%-8s %-28s %-11s %6zu %5zu %4zu %4zu | %8.3f %8.3f | %8.3f %8.3f | %8.3f %8.3f\n";
    std::printf(header, "method", "dataset", "kind", "N", "pos", "FN", "FP", "mean_us", "med_us",
                "mean+", "med+", "mean-", "med-");
    for (const std::string name : {"cubic", "robust"}) {
        const Method m = makeMethod(name);
        std::vector<Sample> per_kind[2];
        for (const QuerySet& set : sets) {
            const auto samples = runSet(m, set, repeat, passes);
            auto& acc = per_kind[set.kind == QueryKind::kEdgeEdge];
            acc.insert(acc.end(), samples.begin(), samples.end());
            const Stats s = summarize(samples);
            std::printf(row, name.c_str(), set.scene.c_str(), kindName(set.kind), s.queries,
                        s.positives, s.fn, s.fp, s.mean, s.median, s.mean_pos, s.median_pos,
                        s.mean_neg, s.median_neg);
            if (csv) {
                csv << name << ',' << set.scene << ',' << kindName(set.kind) << ',' << s.queries
                    << ',' << s.positives << ',' << s.fn << ',' << s.fp << ',' << s.mean << ','
                    << s.median << '\n';
            }
        }
        std::vector<Sample> both;
        for (int k = 0; k < 2; ++k) {
            both.insert(both.end(), per_kind[k].begin(), per_kind[k].end());
            const QueryKind kind = k ? QueryKind::kEdgeEdge : QueryKind::kVertexFace;
            const Stats s = summarize(per_kind[k]);
            std::printf(row, name.c_str(), "all", kindName(kind), s.queries, s.positives, s.fn,
                        s.fp, s.mean, s.median, s.mean_pos, s.median_pos, s.mean_neg, s.median_neg);
            if (csv) {
                csv << name << ",all," << kindName(kind) << ',' << s.queries << ',' << s.positives
                    << ',' << s.fn << ',' << s.fp << ',' << s.mean << ',' << s.median << '\n';
            }
        }
        const Stats s = summarize(both);
        std::printf(row, name.c_str(), "all", "both", s.queries, s.positives, s.fn, s.fp, s.mean,
                    s.median, s.mean_pos, s.median_pos, s.mean_neg, s.median_neg);
        std::printf("\n");
    }
    std::printf(
        "N: queries, pos: colliding queries (ground truth), FN/FP: false negatives/"
        "positives;\ntimes in microseconds per query: all, colliding (+), "
        "non-colliding (-). Default settings:\ncubic tolerance %g (scene units), robust "
        "tolerance %g (hand-off ratio; its answers are exact at any tolerance).\n",
        CubicSettings{}.tolerance, RobustSettings{}.tolerance);

    if (!sweep_path.empty()) {
        std::ofstream sweep(sweep_path);
        sweep << "method,tolerance,kind,queries,false_negatives,false_positives,mean_us\n";
        std::printf("\ntolerance sweep (all data sets)\n%-8s %9s %-11s %5s %5s %9s\n", "method",
                    "tolerance", "kind", "FN", "FP", "mean_us");
        for (const std::string name : {"cubic", "robust"}) {
            for (int e = -8; e <= -1; ++e) {
                const double tol = std::pow(10.0, e);
                const Method m = makeMethod(name, tol);
                std::vector<Sample> per_kind[3];
                for (const QuerySet& set : sets) {
                    const auto samples = runSet(m, set, repeat, passes);
                    auto& acc = per_kind[set.kind == QueryKind::kEdgeEdge];
                    acc.insert(acc.end(), samples.begin(), samples.end());
                    per_kind[2].insert(per_kind[2].end(), samples.begin(), samples.end());
                }
                for (int k = 0; k < 3; ++k) {
                    const char* kind =
                        k == 2 ? "both"
                               : kindName(k ? QueryKind::kEdgeEdge : QueryKind::kVertexFace);
                    const Stats s = summarize(per_kind[k]);
                    std::printf("%-8s %9.0e %-11s %5zu %5zu %9.3f\n", name.c_str(), tol, kind, s.fn,
                                s.fp, s.mean);
                    sweep << name << ',' << tol << ',' << kind << ',' << s.queries << ',' << s.fn
                          << ',' << s.fp << ',' << s.mean << '\n';
                }
            }
        }
    }
    return 0;
}

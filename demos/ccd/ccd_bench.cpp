/// kolize-ccd-bench [DIR...] [--csv FILE] [--sweep FILE] [--repeat N] [--passes N]
///
/// Runs every CCD method over one or more data sets laid out as
/// `<scene>/<vertex-face|edge-edge>/*.csv` (the Sample-Queries format, see
/// assets/ccd-data/Sample-Queries/README.md; kolize-ccd-record writes queries of kolize's
/// own mesh CCD runs in it) and compares with the ground truth. Methods: `cubic` (thesis
/// baseline), `robust` (default settings) and `robust-search` (RobustArithmetic::
/// kSearchThenExact, the inclusion search before the exact stage). Prints, per method,
/// data set and kind: false negatives, false positives, mean and median microseconds per
/// query, overall and split into colliding (+) and non-colliding (-) queries, and the
/// percentage the exact stage decided. `--csv` writes one row per method, data set and kind
/// (plus `all` rows per folder, method and kind); `--sweep` runs every method at tolerances
/// 1e-8 ... 1e-1 over the first folder and writes one row per method, tolerance and kind.
/// A query's time is the median over `--passes` passes (default 3) of the mean of
/// `--repeat` consecutive runs (default 3).
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
    if (name == "robust-search") {
        s.arithmetic = RobustArithmetic::kSearchThenExact;
    }
    return {name, [s](QueryKind k, const LabeledQuery& q) { return robustQuery(k, q, s); }};
}

/// Per-query outcome: answer and time.
struct Sample {
    bool truth;
    bool hit;
    bool exact;  ///< the exact stage decided
    double us;
};

struct Stats {
    size_t queries = 0, positives = 0, fn = 0, fp = 0, exact = 0;
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
        s.exact += x.exact;
        all.push_back(x.us);
        (x.truth ? pos : neg).push_back(x.us);
    }
    meanMedian(all, s.mean, s.median);
    meanMedian(pos, s.mean_pos, s.median_pos);
    meanMedian(neg, s.mean_neg, s.median_neg);
    return s;
}

/// Timing of every method on every query of a set: `passes` times, the mean of `repeat`
/// consecutive runs; a query's time is the median over the passes. The methods take turns
/// on each query and the passes go over the whole set in turn, so a burst of load on a
/// shared machine (a preemption costs milliseconds, a query microseconds) spoils one pass of
/// a few queries, not their reported time, and hits every method alike.
std::vector<std::vector<Sample>> runSet(const std::vector<Method>& methods, const QuerySet& set,
                                        int repeat, int passes) {
    const size_t n = set.queries.size();
    std::vector<std::vector<std::vector<double>>> times(methods.size(),
                                                        std::vector<std::vector<double>>(n));
    std::vector<std::vector<Sample>> out(methods.size(), std::vector<Sample>(n));
    for (int pass = 0; pass < passes; ++pass) {
        for (size_t q = 0; q < n; ++q) {
            for (size_t m = 0; m < methods.size(); ++m) {
                CcdResult r;
                const auto t0 = std::chrono::steady_clock::now();
                for (int i = 0; i < repeat; ++i) {
                    r = methods[m].run(set.kind, set.queries[q]);
                }
                const auto t1 = std::chrono::steady_clock::now();
                times[m][q].push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() /
                                      repeat);
                out[m][q] = {set.queries[q].collides, r.hit, r.decided_exactly, 0.0};
            }
        }
    }
    for (size_t m = 0; m < methods.size(); ++m) {
        for (size_t q = 0; q < n; ++q) {
            std::nth_element(times[m][q].begin(), times[m][q].begin() + passes / 2,
                             times[m][q].end());
            out[m][q].us = times[m][q][passes / 2];
        }
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
    std::cerr << "usage: kolize-ccd-bench [DIR...] [--csv FILE] [--sweep FILE] [--repeat N] "
                 "[--passes N]\n";
    return 2;
}

const char* kHeader = "%-13s %-28s %-11s %6s %5s %4s %4s | %8s %8s | %8s %8s | %8s %8s | %6s\n";
const char* kRow =
    "%-13s %-28s %-11s %6zu %5zu %4zu %4zu | %8.3f %8.3f | %8.3f %8.3f | %8.3f %8.3f | %6.2f\n";

void printRow(const std::string& method, const std::string& dataset, const char* kind,
              const Stats& s, std::ofstream& csv, const std::string& folder) {
    const double exact = s.queries ? 100.0 * s.exact / s.queries : 0.0;
    std::printf(kRow, method.c_str(), dataset.c_str(), kind, s.queries, s.positives, s.fn, s.fp,
                s.mean, s.median, s.mean_pos, s.median_pos, s.mean_neg, s.median_neg, exact);
    if (csv) {
        csv << folder << ',' << method << ',' << dataset << ',' << kind << ',' << s.queries << ','
            << s.positives << ',' << s.fn << ',' << s.fp << ',' << s.mean << ',' << s.median << ','
            << s.mean_pos << ',' << s.median_pos << ',' << s.mean_neg << ',' << s.median_neg << ','
            << exact << '\n';
    }
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> dirs;
    std::string csv_path, sweep_path;
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
        } else if (!a.empty() && a[0] != '-') {
            dirs.push_back(a);
        } else {
            return usage();
        }
    }
    if (dirs.empty()) {
        dirs.push_back(defaultDir());
    }
    std::vector<std::vector<QuerySet>> folders;
    for (const std::string& dir : dirs) {
        try {
            folders.push_back(readQueryFolder(dir));
        } catch (const std::exception& e) {
            std::cerr << "kolize-ccd-bench: " << e.what() << "\n";
            return 1;
        }
    }
    std::ofstream csv;
    if (!csv_path.empty()) {
        csv.open(csv_path);
        csv << "folder,method,dataset,kind,queries,positives,false_negatives,false_positives,"
               "mean_us,median_us,mean_colliding_us,median_colliding_us,mean_noncolliding_us,"
               "median_noncolliding_us,exact_percent\n";
    }
    std::vector<Method> methods;
    for (const char* name : {"cubic", "robust", "robust-search"}) {
        methods.push_back(makeMethod(name));
    }
    std::printf(
        "a query's time: median over %d passes of the mean of %d runs; methods take turns\n",
        passes, repeat);
    for (size_t f = 0; f < folders.size(); ++f) {
        const std::vector<QuerySet>& sets = folders[f];
        size_t total = 0;
        for (const auto& set : sets) {
            total += set.queries.size();
        }
        std::printf("\ndata: %s (%zu queries in %zu sets)\n", dirs[f].c_str(), total, sets.size());
        std::printf(kHeader, "method", "dataset", "kind", "N", "pos", "FN", "FP", "mean_us",
                    "med_us", "mean+", "med+", "mean-", "med-", "exact%");
        std::vector<std::vector<Sample>> per_kind[2];
        std::vector<std::vector<std::pair<std::string, Stats>>> rows(methods.size());
        for (int k = 0; k < 2; ++k) {
            per_kind[k].resize(methods.size());
        }
        for (const QuerySet& set : sets) {
            const auto samples = runSet(methods, set, repeat, passes);
            for (size_t m = 0; m < methods.size(); ++m) {
                auto& acc = per_kind[set.kind == QueryKind::kEdgeEdge][m];
                acc.insert(acc.end(), samples[m].begin(), samples[m].end());
                printRow(methods[m].name, set.scene, kindName(set.kind), summarize(samples[m]), csv,
                         dirs[f]);
            }
        }
        for (size_t m = 0; m < methods.size(); ++m) {
            std::vector<Sample> both;
            for (int k = 0; k < 2; ++k) {
                both.insert(both.end(), per_kind[k][m].begin(), per_kind[k][m].end());
                printRow(methods[m].name, "all",
                         kindName(k ? QueryKind::kEdgeEdge : QueryKind::kVertexFace),
                         summarize(per_kind[k][m]), csv, dirs[f]);
            }
            printRow(methods[m].name, "all", "both", summarize(both), csv, dirs[f]);
        }
    }
    std::printf(
        "\nN: queries, pos: colliding queries (ground truth), FN/FP: false negatives/"
        "positives;\ntimes in microseconds per query: all, colliding (+), non-colliding (-); "
        "exact%%: decided by the exact stage.\nDefault settings: cubic tolerance %g (scene "
        "units); robust-search hand-off tolerance %g (its answers are exact at any tolerance).\n",
        CubicSettings{}.tolerance, RobustSettings{}.tolerance);

    const std::vector<QuerySet>& sets = folders.front();
    if (!sweep_path.empty()) {
        std::ofstream sweep(sweep_path);
        sweep << "method,tolerance,kind,queries,false_negatives,false_positives,mean_us\n";
        std::printf("\ntolerance sweep (%s)\n%-13s %9s %-11s %5s %5s %9s\n", dirs.front().c_str(),
                    "method", "tolerance", "kind", "FN", "FP", "mean_us");
        for (const std::string name : {"cubic", "robust-search"}) {
            for (int e = -8; e <= -1; ++e) {
                const double tol = std::pow(10.0, e);
                const Method m = makeMethod(name, tol);
                std::vector<Sample> per_kind[3];
                for (const QuerySet& set : sets) {
                    const auto samples = runSet({m}, set, repeat, passes).front();
                    auto& acc = per_kind[set.kind == QueryKind::kEdgeEdge];
                    acc.insert(acc.end(), samples.begin(), samples.end());
                    per_kind[2].insert(per_kind[2].end(), samples.begin(), samples.end());
                }
                for (int k = 0; k < 3; ++k) {
                    const char* kind =
                        k == 2 ? "both"
                               : kindName(k ? QueryKind::kEdgeEdge : QueryKind::kVertexFace);
                    const Stats s = summarize(per_kind[k]);
                    std::printf("%-13s %9.0e %-11s %5zu %5zu %9.3f\n", name.c_str(), tol, kind,
                                s.fn, s.fp, s.mean);
                    sweep << name << ',' << tol << ',' << kind << ',' << s.queries << ',' << s.fn
                          << ',' << s.fp << ',' << s.mean << '\n';
                }
            }
        }
    }
    return 0;
}

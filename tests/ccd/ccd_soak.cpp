/// kolize-ccd-soak [--queries N] [--seed S] [--first I] [--family F] [--shrink K]
/// kolize-ccd-soak --data DIR
///
/// Differential soak of the robust CCD method against the exact reference (ccd_reference.h):
/// N queries (default 1 000 000) from the seeded degenerate families of ccd_families.h,
/// queries I .. I + N - 1 of stream S (default seed 1, first 0), each decided once by the
/// reference and then by `robust` in every arithmetic mode. Hit must agree, and toi <= t*
/// <= toi + toi_tolerance exactly. Every disagreement prints its seed, query index, family
/// and mode (rerun it alone with --first I --queries 1); the first K (default 3) are also
/// shrunk and printed as source text. Ends with a table per family and mode; exit status 1
/// if anything disagreed.
///
/// With --data, checks a query folder in the Sample-Queries layout instead (the shipped data
/// set, or one written by kolize-ccd-record): every label against the reference, and every
/// mode of `robust` against the reference as above.
#include "ccd_families.h"

#include "kolize/narrowphase/ccd_dataset.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace kolize::ccd;

namespace {

int checkData(const std::string& dir) {
    const auto& modes = families::modes();
    uint64_t total = 0, label_errors = 0, disagreements = 0;
    std::printf("%-34s %-11s %8s %8s %7s %13s\n", "data set", "kind", "queries", "contacts",
                "labels", "disagreements");
    for (const QuerySet& set : readQueryFolder(dir)) {
        uint64_t hits = 0, labels = 0, wrong = 0;
        for (size_t i = 0; i < set.queries.size(); ++i) {
            families::Query q;
            q.kind = set.kind == QueryKind::kVertexFace ? families::Kind::kVertexFace
                                                        : families::Kind::kEdgeEdge;
            q.start = set.queries[i].start;
            q.end = set.queries[i].end;
            reference::Decision d = families::decide(q);
            hits += d.hit();
            if (d.hit() != set.queries[i].collides) {
                ++labels;
                std::printf("LABEL %s %s #%zu: file says %d, reference %d\n", set.scene.c_str(),
                            kindName(set.kind), i, set.queries[i].collides, d.hit());
            }
            for (const families::Mode& mode : modes) {
                if (const auto failure = families::check(q, mode, d)) {
                    ++wrong;
                    std::printf("DISAGREEMENT %s %s #%zu mode %s: %s\n", set.scene.c_str(),
                                kindName(set.kind), i, mode.name.c_str(), failure->c_str());
                }
            }
        }
        std::printf("%-34s %-11s %8zu %8llu %7llu %13llu\n", set.scene.c_str(), kindName(set.kind),
                    set.queries.size(), static_cast<unsigned long long>(hits),
                    static_cast<unsigned long long>(labels),
                    static_cast<unsigned long long>(wrong));
        total += set.queries.size();
        label_errors += labels;
        disagreements += wrong;
    }
    std::printf("\n%s: %llu queries, %zu modes each: %llu wrong labels, %llu disagreements\n",
                dir.c_str(), static_cast<unsigned long long>(total), modes.size(),
                static_cast<unsigned long long>(label_errors),
                static_cast<unsigned long long>(disagreements));
    return label_errors || disagreements ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc == 3 && std::string(argv[1]) == "--data") {
        try {
            return checkData(argv[2]);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "kolize-ccd-soak: %s\n", e.what());
            return 2;
        }
    }
    uint64_t queries = 1000000, seed = 1, first = 0;
    int family = -1, shrink_budget = 3;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        const char* v = argv[i + 1];
        if (a == "--queries") {
            queries = std::strtoull(v, nullptr, 10);
        } else if (a == "--seed") {
            seed = std::strtoull(v, nullptr, 10);
        } else if (a == "--first") {
            first = std::strtoull(v, nullptr, 10);
        } else if (a == "--family") {
            family = std::atoi(v);
        } else if (a == "--shrink") {
            shrink_budget = std::atoi(v);
        } else {
            std::fprintf(stderr, "unknown option %s\n", a.c_str());
            return 2;
        }
    }
    if (argc % 2 == 0) {
        std::fprintf(stderr,
                     "usage: kolize-ccd-soak [--queries N] [--seed S] [--first I] [--family F] "
                     "[--shrink K]\n");
        return 2;
    }
    const auto& names = families::familyNames();
    const auto& modes = families::modes();
    struct Count {
        uint64_t queries = 0, hits = 0, disagreements = 0, exact = 0;
        double reference_seconds = 0, robust_seconds = 0;
    };
    std::vector<std::vector<Count>> counts(names.size(), std::vector<Count>(modes.size()));
    uint64_t disagreements = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (uint64_t n = 0; n < queries; ++n) {
        const uint64_t index = first + n;
        const families::Query q = families::generate(seed, index, family);
        const auto r0 = std::chrono::steady_clock::now();
        reference::Decision d = families::decide(q);
        const double reference_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
        for (size_t m = 0; m < modes.size(); ++m) {
            Count& c = counts[q.family][m];
            ++c.queries;
            c.hits += d.hit();
            c.reference_seconds += reference_seconds;
            const auto m0 = std::chrono::steady_clock::now();
            CcdResult result;
            const auto failure = families::check(q, modes[m], d, &result);
            c.exact += result.decided_exactly;
            c.robust_seconds +=
                std::chrono::duration<double>(std::chrono::steady_clock::now() - m0).count();
            if (!failure) {
                continue;
            }
            ++c.disagreements;
            ++disagreements;
            std::printf("DISAGREEMENT seed %llu query %llu family %s mode %s: %s\n",
                        static_cast<unsigned long long>(seed),
                        static_cast<unsigned long long>(index), names[q.family].c_str(),
                        modes[m].name.c_str(), failure->c_str());
            if (shrink_budget > 0) {
                --shrink_budget;
                std::printf("  query:  %s\n", families::describe(q).c_str());
                std::printf("  shrunk: %s\n",
                            families::describe(families::shrink(q, modes[m])).c_str());
            }
            std::fflush(stdout);
        }
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("\n%-24s %-26s %10s %10s %13s %7s %9s %9s\n", "family", "mode", "queries",
                "contacts", "disagreements", "exact%", "ref_us", "check_us");
    for (size_t f = 0; f < names.size(); ++f) {
        for (size_t m = 0; m < modes.size(); ++m) {
            const Count& c = counts[f][m];
            if (c.queries) {
                std::printf(
                    "%-24s %-26s %10llu %10llu %13llu %7.1f %9.1f %9.1f\n", names[f].c_str(),
                    modes[m].name.c_str(), static_cast<unsigned long long>(c.queries),
                    static_cast<unsigned long long>(c.hits),
                    static_cast<unsigned long long>(c.disagreements), 100.0 * c.exact / c.queries,
                    1e6 * c.reference_seconds / c.queries, 1e6 * c.robust_seconds / c.queries);
            }
        }
    }
    std::printf(
        "\nseed %llu, queries %llu .. %llu (%llu queries, %zu modes each), %.1f s: %llu "
        "disagreements\n",
        static_cast<unsigned long long>(seed), static_cast<unsigned long long>(first),
        static_cast<unsigned long long>(first + queries - 1),
        static_cast<unsigned long long>(queries), modes.size(), seconds,
        static_cast<unsigned long long>(disagreements));
    return disagreements ? 1 : 0;
}

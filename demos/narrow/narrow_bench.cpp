// kolize-narrow-bench: mesh against mesh, every kolize tree kind and leaf size side by side
// with FCL's bounding volumes and Bullet's GImpact, on the same meshes and seeded poses, in
// one run. Each repetition visits the methods in a fresh seeded order; times are medians
// (and minima) of single calls; every answer is compared with the exact reference, so a
// speed run is also a correctness run.

#include "method.h"

#include <kolize/narrowphase/reference.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

namespace kolize::narrowbench {
namespace {

const char* kUsage =
    "usage: kolize-narrow-bench [options]\n"
    "Mesh against mesh: kolize's trees, FCL (if built with it) and GImpact at seeded poses,\n"
    "interleaved, medians over repetitions, every answer checked against the exact reference.\n"
    "  --pairs LIST    mesh pairs, comma-separated, or 'all' (default all):\n"
    "                  spider, MotionCaptureROM, Wuson, Wuson-duck, HUMAN, duck-SphereWithLight\n"
    "  --poses N       poses per random class (deep, shallow, near, apart, apart-obb;\n"
    "                  default 6); a mesh\n"
    "                  against its own copy also gets the coincident pose and three shifted ones\n"
    "  --reps N        timed repetitions of every method at every pose (default 7)\n"
    "  --methods LIST  names or groups (kolize, fcl, gimpact), comma-separated (default all);\n"
    "                  --list prints them\n"
    "  --modes LIST    yesno, pairs, contacts (default all three)\n"
    "  --classes LIST  pose classes (deep, shallow, near, apart, coincident, shifted; default "
    "all)\n"
    "  --seed N        pose seed (default 1)\n"
    "  --quick         2 poses per class, 3 repetitions, fewer kolize configurations (CI)\n"
    "  --csv FILE      one row per pair, pose, method and mode\n"
    "  --list          print the pairs and methods and exit\n"
    "Exits 1 when an exact kolize method disagrees with the reference, 2 on bad arguments.\n";

[[noreturn]] void usageError(const std::string& message) {
    std::fprintf(stderr, "kolize-narrow-bench: %s (try --help)\n", message.c_str());
    std::exit(2);
}

struct PairSpec {
    const char* name;
    const char* a;
    const char* b;
};

const std::vector<PairSpec>& pairSpecs() {
    static const std::vector<PairSpec> specs = {
        {"spider", "spider", "spider"},
        {"MotionCaptureROM", "MotionCaptureROM", "MotionCaptureROM"},
        {"Wuson", "Wuson", "Wuson"},
        {"Wuson-duck", "Wuson", "duck"},
        {"HUMAN", "HUMAN", "HUMAN"},
        {"duck-SphereWithLight", "duck", "SphereWithLight"},
    };
    return specs;
}

std::vector<std::string> fclNames() {
#ifdef KOLIZE_WITH_FCL
    return {"fcl-obb", "fcl-obbrss", "fcl-rss", "fcl-kios", "fcl-kdop18", "fcl-aabb"};
#else
    return {};
#endif
}

std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (!item.empty()) {
            out.push_back(item);
        }
    }
    return out;
}

int positive(const std::string& flag, const std::string& value) {
    char* end = nullptr;
    const long n = std::strtol(value.c_str(), &end, 10);
    if (end == value.c_str() || *end != '\0' || n < 1 || n > 1000000) {
        usageError(flag + " needs a whole number >= 1, got '" + value + "'");
    }
    return int(n);
}

struct Options {
    std::vector<std::string> pairs;
    int poses = 6, reps = 7;
    std::uint32_t seed = 1;
    bool quick = false;
    std::vector<std::string> methods;
    std::vector<Mode> modes = {Mode::kYesNo, Mode::kPairs, Mode::kContacts};
    std::vector<workload::PoseClass> classes = workload::allPoseClasses();
    std::string csv;
};

std::unique_ptr<Method> makeMethod(const std::string& name) {
    if (name.rfind("kolize-", 0) == 0) {
        return std::move(kolizeMethods({name})[0]);
    }
    if (name == "gimpact" || name == "gimpact-margin0") {
        return gimpactMethod(name == "gimpact-margin0");
    }
#ifdef KOLIZE_WITH_FCL
    if (name.rfind("fcl-", 0) == 0) {
        return fclMethod(name.substr(4));
    }
#endif
    throw std::invalid_argument("unknown method '" + name + "' (--list prints them)");
}

std::vector<std::string> expandMethods(const std::vector<std::string>& requested, bool quick) {
    std::vector<std::string> out;
    auto add = [&](const std::vector<std::string>& names) {
        out.insert(out.end(), names.begin(), names.end());
    };
    for (const std::string& r : requested) {
        if (r == "kolize") {
            add(kolizeMethodNames(quick));
        } else if (r == "fcl") {
            add(fclNames());
        } else if (r == "gimpact") {
            add({"gimpact-margin0", "gimpact"});
        } else {
            add({r});
        }
    }
    return out;
}

Options parse(int argc, char** argv) {
    Options o;
    std::string pairs = "all", methods = "kolize,fcl,gimpact", modes;
    bool posesGiven = false, repsGiven = false;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--help" || flag == "-h") {
            std::printf("%s", kUsage);
            std::exit(0);
        }
        if (flag == "--quick") {
            o.quick = true;
            continue;
        }
        if (flag == "--list") {
            std::printf("pairs:");
            for (const PairSpec& p : pairSpecs()) {
                std::printf(" %s", p.name);
            }
            std::printf("\nmethods:");
            for (const std::string& m : expandMethods({"kolize", "fcl", "gimpact"}, false)) {
                std::printf(" %s", m.c_str());
            }
            std::printf("\n");
            std::exit(0);
        }
        if (flag != "--pairs" && flag != "--poses" && flag != "--reps" && flag != "--methods" &&
            flag != "--modes" && flag != "--seed" && flag != "--csv" && flag != "--classes") {
            usageError("unknown option '" + flag + "'");
        }
        if (i + 1 >= argc) {
            usageError(flag + " needs a value");
        }
        const std::string value = argv[++i];
        if (flag == "--pairs") {
            pairs = value;
        } else if (flag == "--poses") {
            o.poses = positive(flag, value);
            posesGiven = true;
        } else if (flag == "--reps") {
            o.reps = positive(flag, value);
            repsGiven = true;
        } else if (flag == "--methods") {
            methods = value;
        } else if (flag == "--modes") {
            modes = value;
        } else if (flag == "--classes") {
            o.classes.clear();
            for (const std::string& c : split(value)) {
                bool known = false;
                for (workload::PoseClass k : workload::allPoseClasses()) {
                    if (c == workload::poseClassName(k)) {
                        o.classes.push_back(k);
                        known = true;
                    }
                }
                if (!known) {
                    usageError("unknown pose class '" + c + "' (--help lists them)");
                }
            }
        } else if (flag == "--seed") {
            o.seed = std::uint32_t(positive(flag, value));
        } else {
            o.csv = value;
        }
    }
    if (o.quick) {
        o.poses = posesGiven ? o.poses : 2;
        o.reps = repsGiven ? o.reps : 3;
    }
    for (const std::string& p : split(pairs)) {
        if (p == "all") {
            for (const PairSpec& s : pairSpecs()) {
                o.pairs.push_back(s.name);
            }
            continue;
        }
        if (std::none_of(pairSpecs().begin(), pairSpecs().end(),
                         [&](const PairSpec& s) { return p == s.name; })) {
            usageError("unknown pair '" + p + "' (--list prints them)");
        }
        o.pairs.push_back(p);
    }
    o.methods = expandMethods(split(methods), o.quick);
    for (const std::string& m : o.methods) {
        try {
            makeMethod(m);
        } catch (const std::exception& e) {
            usageError(e.what());
        }
    }
    if (!modes.empty()) {
        o.modes.clear();
        for (const std::string& m : split(modes)) {
            if (m == "yesno") {
                o.modes.push_back(Mode::kYesNo);
            } else if (m == "pairs") {
                o.modes.push_back(Mode::kPairs);
            } else if (m == "contacts") {
                o.modes.push_back(Mode::kContacts);
            } else {
                usageError("unknown mode '" + m + "' (yesno, pairs, contacts)");
            }
        }
    }
    return o;
}

const workload::WorkloadMesh& mesh(const std::string& name) {
    static std::map<std::string, workload::WorkloadMesh> cache;
    auto it = cache.find(name);
    if (it == cache.end()) {
        for (const workload::ModelFile& m : workload::standardModels()) {
            if (name == m.name) {
                it = cache.emplace(name, workload::loadModel(m.path, name)).first;
            }
        }
    }
    return it->second;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty()      ? NAN
           : v.size() % 2 ? v[v.size() / 2]
                          : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

struct Row {
    std::string pair, meshA, meshB;
    std::size_t trianglesA = 0, trianglesB = 0;
    std::string poseClass;
    int pose = 0;
    std::string method, mode;
    double medianUs = 0, minUs = 0;
    int reps = 0;
    std::size_t truePairs = 0, foundPairs = 0, missing = 0, extra = 0;
    bool yesNoWrong = false;
    Outcome outcome;
    BuildInfo build;
};

void writeCsv(const std::string& path, const std::vector<Row>& rows) {
    std::ofstream out(path);
    out << "pair,mesh_a,mesh_b,triangles_a,triangles_b,class,pose,method,mode,median_us,min_us,"
           "reps,true_pairs,found_pairs,missing,extra,yesno_wrong,bv_tests,sphere_tests,"
           "triangle_tests,predicate_fallbacks,build_us_per_triangle,bytes_per_node,nodes\n";
    out.precision(6);
    for (const Row& r : rows) {
        out << r.pair << ',' << r.meshA << ',' << r.meshB << ',' << r.trianglesA << ','
            << r.trianglesB << ',' << r.poseClass << ',' << r.pose << ',' << r.method << ','
            << r.mode << ',' << r.medianUs << ',' << r.minUs << ',' << r.reps << ',' << r.truePairs
            << ',' << r.foundPairs << ',' << r.missing << ',' << r.extra << ',' << int(r.yesNoWrong)
            << ',' << r.outcome.bvTests << ',' << r.outcome.sphereTests << ','
            << r.outcome.triangleTests << ',' << r.outcome.predicateFallbacks << ','
            << r.build.microsPerTriangle << ',' << r.build.bytesPerNode << ',' << r.build.nodes
            << '\n';
    }
    if (!out) {
        std::fprintf(stderr, "kolize-narrow-bench: cannot write '%s'\n", path.c_str());
        std::exit(1);
    }
}

/// Median over poses of per-pose time ratios num/den (same pair, class, mode).
double ratio(const std::vector<Row>& rows, const std::string& pair, const std::string& poseClass,
             const std::string& mode, const std::string& num, const std::string& den) {
    std::map<int, double> n, d;
    for (const Row& r : rows) {
        if (r.pair == pair && r.poseClass == poseClass && r.mode == mode) {
            if (r.method == num) {
                n[r.pose] = r.medianUs;
            } else if (r.method == den) {
                d[r.pose] = r.medianUs;
            }
        }
    }
    std::vector<double> ratios;
    for (const auto& [pose, t] : n) {
        if (d.count(pose) && d[pose] > 0) {
            ratios.push_back(t / d[pose]);
        }
    }
    return median(ratios);
}

int run(const Options& o) {
    std::vector<Row> rows;
    bool kolizeWrong = false;
    std::uint64_t timedCalls = 0;
    const auto runStart = std::chrono::steady_clock::now();
    for (std::size_t pi = 0; pi < o.pairs.size(); ++pi) {
        const PairSpec& spec =
            *std::find_if(pairSpecs().begin(), pairSpecs().end(),
                          [&](const PairSpec& s) { return o.pairs[pi] == s.name; });
        const workload::WorkloadMesh& a = mesh(spec.a);
        const workload::WorkloadMesh& b = mesh(spec.b);
        const bool same = std::string(spec.a) == spec.b;
        const narrowphase::MeshModel obbA(a.mesh), obbB(b.mesh);
        std::vector<workload::WorkloadPose> poses;
        for (workload::PoseClass kind : o.classes) {
            const bool exact =
                kind == workload::PoseClass::kCoincident || kind == workload::PoseClass::kShifted;
            if (exact && !same) {
                continue;
            }
            const std::uint32_t seed = o.seed * 1000 + std::uint32_t(pi) * 10 + std::uint32_t(kind);
            for (const workload::WorkloadPose& p :
                 workload::makePoses(a, obbA, b, same ? obbA : obbB, kind, o.poses, seed)) {
                poses.push_back(p);
            }
        }
        std::vector<std::unique_ptr<Method>> methods;
        for (const std::string& name : o.methods) {
            methods.push_back(makeMethod(name));
            methods.back()->prepare(a, same ? a : b);
        }
        std::fprintf(stderr, "%s: %zu x %zu triangles, %zu poses, %zu methods\n", spec.name,
                     a.mesh->triangleCount(), b.mesh->triangleCount(), poses.size(),
                     methods.size());
        std::map<std::string, int> classIndex;
        for (std::size_t p = 0; p < poses.size(); ++p) {
            const workload::WorkloadPose& pose = poses[p];
            const std::string poseClass = workload::poseClassName(pose.kind);
            const int index = classIndex[poseClass]++;
            const auto refStart = std::chrono::steady_clock::now();
            const std::vector<TrianglePair> reference =
                narrowphase::referencePairs(*a.mesh, pose.a, *(same ? a : b).mesh, pose.b);
            const double referenceUs = std::chrono::duration<double, std::micro>(
                                           std::chrono::steady_clock::now() - refStart)
                                           .count();
            Row base;
            base.pair = spec.name;
            base.meshA = a.name;
            base.meshB = b.name;
            base.trianglesA = a.mesh->triangleCount();
            base.trianglesB = b.mesh->triangleCount();
            base.poseClass = poseClass;
            base.pose = index;
            base.truePairs = reference.size();
            {
                Row r = base;
                r.method = "reference";
                r.mode = "pairs";
                r.medianUs = r.minUs = referenceUs;
                r.reps = 1;
                r.foundPairs = reference.size();
                rows.push_back(r);
            }
            struct Job {
                Method* method;
                Mode mode;
                std::vector<double> times;
                Outcome outcome;
            };
            std::vector<Job> jobs;
            for (const auto& m : methods) {
                for (Mode mode : o.modes) {
                    if (m->supports(mode)) {
                        jobs.push_back({m.get(), mode, {}, {}});
                    }
                }
            }
            // Warm-up call (untimed) gives the answer that is checked.
            for (Job& j : jobs) {
                j.method->run(pose.a, pose.b, j.mode);
                j.method->collect(j.outcome);
            }
            std::mt19937 order(o.seed * 7919u + std::uint32_t(pi * 1000 + p));
            std::vector<std::size_t> visit(jobs.size());
            for (std::size_t i = 0; i < visit.size(); ++i) {
                visit[i] = i;
            }
            for (int rep = 0; rep < o.reps; ++rep) {
                std::shuffle(visit.begin(), visit.end(), order);
                for (std::size_t i : visit) {
                    Job& j = jobs[i];
                    const auto start = std::chrono::steady_clock::now();
                    j.method->run(pose.a, pose.b, j.mode);
                    const auto end = std::chrono::steady_clock::now();
                    j.times.push_back(
                        std::chrono::duration<double, std::micro>(end - start).count());
                    ++timedCalls;
                }
            }
            for (Job& j : jobs) {
                Row r = base;
                r.method = j.method->name();
                r.mode = modeName(j.mode);
                r.medianUs = median(j.times);
                r.minUs = *std::min_element(j.times.begin(), j.times.end());
                r.reps = o.reps;
                r.outcome = j.outcome;
                r.build = j.method->buildInfo();
                std::vector<TrianglePair> found = j.outcome.pairs;
                std::sort(found.begin(), found.end());
                found.erase(std::unique(found.begin(), found.end()), found.end());
                r.foundPairs = found.size();
                r.yesNoWrong = j.outcome.intersecting != !reference.empty();
                if (j.mode == Mode::kYesNo) {
                    for (const TrianglePair& f : found) {
                        r.yesNoWrong = r.yesNoWrong ||
                                       !std::binary_search(reference.begin(), reference.end(), f);
                    }
                } else {
                    std::vector<TrianglePair> diff;
                    std::set_difference(reference.begin(), reference.end(), found.begin(),
                                        found.end(), std::back_inserter(diff));
                    r.missing = diff.size();
                    diff.clear();
                    std::set_difference(found.begin(), found.end(), reference.begin(),
                                        reference.end(), std::back_inserter(diff));
                    r.extra = diff.size();
                }
                const bool exactKolize = r.method.rfind("kolize-", 0) == 0 &&
                                         r.method.find("-facing") == std::string::npos;
                if (exactKolize && (r.missing || r.extra || r.yesNoWrong)) {
                    kolizeWrong = true;
                    std::fprintf(stderr, "MISMATCH %s %s pose %d %s %s: %zu missing, %zu extra%s\n",
                                 spec.name, poseClass.c_str(), index, r.method.c_str(),
                                 r.mode.c_str(), r.missing, r.extra,
                                 r.yesNoWrong ? ", yes/no wrong" : "");
                }
                r.outcome.pairs.clear();
                rows.push_back(std::move(r));
            }
        }
    }
    const double minutes =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - runStart).count() / 60;

    // Summary: ratios of kolize's default (OBB tree, leaf 4) to FCL-OBB and GImpact.
    std::printf("kolize-narrow-bench: %zu rows, %llu timed calls, %.1f minutes\n", rows.size(),
                (unsigned long long)timedCalls, minutes);
    std::printf("\nmedian over poses of per-pose time ratios, kolize-obb-4 / other\n");
    std::printf("%-22s %-10s %10s %10s %10s %12s %12s\n", "pair", "class", "yesno/FCL", "pairs/FCL",
                "cont/FCL", "cont/GI-m0", "kolize us");
    for (const std::string& pair : o.pairs) {
        for (workload::PoseClass kind : workload::allPoseClasses()) {
            const std::string c = workload::poseClassName(kind);
            std::vector<double> us;
            for (const Row& r : rows) {
                if (r.pair == pair && r.poseClass == c && r.method == "kolize-obb-4" &&
                    r.mode == "pairs") {
                    us.push_back(r.medianUs);
                }
            }
            if (us.empty()) {
                continue;
            }
            std::printf("%-22s %-10s %10.3f %10.3f %10.3f %12.3f %12.2f\n", pair.c_str(), c.c_str(),
                        ratio(rows, pair, c, "yesno", "kolize-obb-4", "fcl-obb"),
                        ratio(rows, pair, c, "pairs", "kolize-obb-4", "fcl-obb"),
                        ratio(rows, pair, c, "contacts", "kolize-obb-4", "fcl-obb"),
                        ratio(rows, pair, c, "contacts", "kolize-obb-4", "gimpact-margin0"),
                        median(us));
        }
    }
    std::printf("\nexactness over every pose (pairs and contacts modes; yes/no in every mode)\n");
    std::printf("%-24s %-9s %10s %10s %10s %12s\n", "method", "mode", "missing", "extra",
                "yesno-err", "median us");
    std::vector<std::pair<std::string, std::string>> seen;
    for (const Row& r : rows) {
        const auto key = std::make_pair(r.method, r.mode);
        if (std::find(seen.begin(), seen.end(), key) != seen.end()) {
            continue;
        }
        seen.push_back(key);
        std::size_t missing = 0, extra = 0, wrong = 0;
        std::vector<double> us;
        for (const Row& s : rows) {
            if (s.method == r.method && s.mode == r.mode) {
                missing += s.missing;
                extra += s.extra;
                wrong += s.yesNoWrong;
                us.push_back(s.medianUs);
            }
        }
        std::printf("%-24s %-9s %10zu %10zu %10zu %12.2f\n", r.method.c_str(), r.mode.c_str(),
                    missing, extra, wrong, median(us));
    }
    if (!o.csv.empty()) {
        writeCsv(o.csv, rows);
    }
    if (kolizeWrong) {
        std::fprintf(stderr,
                     "kolize-narrow-bench: an exact kolize method disagreed with the "
                     "reference (MISMATCH lines above)\n");
        return 1;
    }
    return 0;
}

}  // namespace
}  // namespace kolize::narrowbench

int main(int argc, char** argv) {
    try {
        return kolize::narrowbench::run(kolize::narrowbench::parse(argc, argv));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kolize-narrow-bench: %s\n", e.what());
        return 1;
    }
}

// kolize-report: runs the whole measurement matrix with the sibling programs (kolize-bench,
// kolize-bench-2d, kolize-demo and optionally a double-precision kolize-demo) and writes
// reports/REPORT.md with the tables, gnuplot plots (PNG) and the CSV they come from.

#include "report.h"

#include <LinearMath/btScalar.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <stdexcept>
#include <thread>

namespace report {

namespace {

const char* kUsage =
    "usage: kolize-report [--quick] [--out DIR] [--double-demo PATH]\n"
    "Runs kolize-bench, kolize-bench-2d and kolize-demo (found next to this program) over\n"
    "the whole matrix and writes DIR/REPORT.md, the plots (DIR/*.png, their gnuplot scripts\n"
    "DIR/*.gp) and the data (DIR/data/*.csv, child logs in DIR/data/logs/).\n"
    "  --quick             small N and few frames (a few minutes; what CI runs)\n"
    "  --out DIR           output folder (default reports)\n"
    "  --double-demo PATH  a kolize-demo built with -DKOLIZE_DOUBLE_PRECISION=ON, for the\n"
    "                      float/double columns of the stability table\n"
    "  --help              this text\n"
    "Exits 1 when any child command fails (the report lists it), 2 on bad arguments.\n";

[[noreturn]] void usageError(const std::string& message) {
    std::fprintf(stderr, "kolize-report: %s (try --help)\n", message.c_str());
    std::exit(2);
}

fs::path selfDirectory() {
    std::error_code error;
    const fs::path self = fs::read_symlink("/proc/self/exe", error);
    return error ? fs::current_path() : self.parent_path();
}

/// The program `name` next to this one or one folder up (build/demos/report/ -> build/demos/).
fs::path sibling(const fs::path& dir, const std::string& name) {
    for (const fs::path& candidate : {dir / name, dir.parent_path() / name}) {
        if (access(candidate.c_str(), X_OK) == 0) {
            return candidate;
        }
    }
    return {};
}

std::string cpuModel() {
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line;
    while (std::getline(cpuinfo, line)) {
        if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
            return line.substr(line.find(':') + 2);
        }
    }
    return "unknown";
}

std::string now() {
    const std::time_t t = std::time(nullptr);
    char text[64];
    std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S %Z", std::localtime(&t));
    return text;
}

std::string orUnknown(const std::string& text) {
    return text.empty() ? "unknown" : text;
}

}  // namespace

void Context::commands(const std::vector<std::string>& shown) {
    add("Command" + std::string(shown.size() > 1 ? "s" : "") + ":\n\n```sh\n" + join(shown, "\n") +
        "\n```\n\n");
}

bool Context::runTool(const std::string& name, const fs::path& binary,
                      std::vector<std::string> args, std::string& shown) {
    if (binary.empty()) {
        shown = name + " (program not found next to kolize-report)";
        runner.fail(shown, "not found");
        add("*Not run: the program for this section was not found next to kolize-report.*\n\n");
        return false;
    }
    args.insert(args.begin(), binary.string());
    if (!runner.run(name, args, shown, data / (name + ".txt"))) {
        add("**Failed:** `" + shown + "` (" + runner.failures().back().what + "; log `" +
            runner.shellLine({runner.failures().back().log}) + "`).\n\n");
        return false;
    }
    return true;
}

bool Context::runCsv(const std::string& name, const fs::path& binary, std::vector<std::string> args,
                     Csv& csv, std::string& shown) {
    const fs::path path = data / (name + ".csv");
    std::error_code ignored;
    fs::remove(path, ignored);
    args.push_back("--csv");
    args.push_back(path.string());
    runTool(name, binary, args, shown);
    return fs::exists(path) && load(name + ".csv", csv);
}

bool Context::load(const std::string& file, Csv& csv) {
    try {
        csv = Csv::read(data / file);
        return true;
    } catch (const std::exception& error) {
        runner.fail("read " + (data / file).string(), error.what());
        add("**Failed:** " + std::string(error.what()) + "\n\n");
        return false;
    }
}

}  // namespace report

int main(int argc, char** argv) {
    using namespace report;
    Context context;
    context.out = "reports";
    std::string doubleDemo;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--help" || flag == "-h") {
            std::printf("%s", kUsage);
            return 0;
        }
        if (flag == "--quick") {
            context.quick = true;
            continue;
        }
        if (flag != "--out" && flag != "--double-demo") {
            usageError("unknown option '" + flag + "'");
        }
        if (i + 1 >= argc || std::string(argv[i + 1]).empty()) {
            usageError(flag + " needs a value");
        }
        if (flag == "--out") {
            context.out = argv[++i];
        } else {
            doubleDemo = argv[++i];
        }
    }
    const auto start = std::chrono::steady_clock::now();
    context.data = context.out / "data";
    std::error_code error;
    fs::create_directories(context.data, error);
    if (error) {
        std::fprintf(stderr, "kolize-report: cannot create '%s': %s\n",
                     context.data.string().c_str(), error.message().c_str());
        return 1;
    }
    const fs::path self = selfDirectory();
    context.runner = Runner(context.data / "logs", fs::current_path());
    context.bench = sibling(self, "kolize-bench");
    context.bench2d = sibling(self, "kolize-bench-2d");
    context.demo = sibling(self, "kolize-demo");
    // The fuzzer is built with the tests: build/tests/ beside build/demos/.
    context.fuzz = sibling(self.parent_path().parent_path() / "tests", "kolize-fuzz");
    context.thesisTables = fs::path(KOLIZE_SOURCE_DIR) / "assets/thesis/tables.csv";
    if (doubleDemo.empty()) {
        context.doubleDemoNote = "no --double-demo given";
    } else if (access(doubleDemo.c_str(), X_OK) != 0) {
        context.doubleDemoNote = "--double-demo '" + doubleDemo + "' not found";
    } else {
        context.doubleDemo = fs::absolute(doubleDemo);
    }
    if (system("gnuplot -e 'set terminal pngcairo' >/dev/null 2>&1") != 0) {
        context.terminal = "png";
    }

    const std::string commit = orUnknown(firstLineOf("git -C '" + std::string(KOLIZE_SOURCE_DIR) +
                                                     "' describe --always --dirty --abbrev=10"));
    context.add("# kolize report\n\nGenerated by `kolize-report" +
                std::string(context.quick ? " --quick" : "") + "` (" +
                (context.quick ? "quick mode: small N and few frames, a smoke test; run "
                                 "without --quick for the numbers"
                               : "full run") +
                ").\n\n");
    context.add(markdownTable(
        {"machine", ""},
        {{"date", now()},
         {"git commit", commit},
         {"CPU", cpuModel()},
         {"nproc", std::to_string(std::thread::hardware_concurrency())},
         {"Bullet", std::to_string(btGetVersion()) + " (Debian's build; kolize-report itself " +
                        (sizeof(btScalar) == 8 ? "double" : "float") + ")"},
         {"compiler", __VERSION__},
         {"gnuplot terminal", context.terminal}}));
    context.add(
        "\nTimes are medians over frames; the machine may be shared and noisy, so compare "
        "ratios within one run. Every number below is computed by this program from the CSV "
        "in `data/`; every section gives the command that produced its data. Sections: thesis "
        "tables 2.3-2.7, scaling, error against run time (sweeps), the store-only lower bound, "
        "2D against Box2D, then the Bullet worlds from kolize-demo: pair output live and "
        "replayed, rays, determinism, dynamics accuracy against time, numerical stability; then "
        "the narrowphase (mesh against mesh) against FCL and GImpact; mesh bodies in Bullet "
        "worlds against GImpact; the differential "
        "fuzzer's table.\n");

    using Section = void (*)(Context&);
    for (Section section :
         {thesisSection, scalingSection, sweepSection, lowerBoundSection, box2dSection,
          demoSections, narrowSection, meshWorldSection, fuzzSection}) {
        section(context);
    }

    const double minutes =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / 60;
    context.heading("Run");
    context.add("The report took " + fmt(minutes) + " minutes.\n\n");
    const auto& failures = context.runner.failures();
    if (failures.empty()) {
        context.add("Every command succeeded.\n");
    } else {
        std::vector<std::vector<std::string>> rows;
        for (const Failure& failure : failures) {
            rows.push_back({"`" + failure.command + "`", failure.what,
                            failure.log.empty() ? "" : "`" + failure.log + "`"});
        }
        context.add("**" + std::to_string(failures.size()) +
                    " command(s) failed**; their sections are incomplete:\n\n" +
                    markdownTable({"command", "result", "log"}, rows));
    }
    const fs::path reportPath = context.out / "REPORT.md";
    std::ofstream file(reportPath);
    file << context.markdown;
    file.close();
    if (!file) {
        std::fprintf(stderr, "kolize-report: cannot write '%s'\n", reportPath.string().c_str());
        return 1;
    }
    std::fprintf(stderr, "kolize-report: wrote %s (%.1f minutes)%s\n", reportPath.string().c_str(),
                 minutes,
                 failures.empty() ? "" : "; some commands FAILED, see the end of the report");
    return failures.empty() ? 0 : 1;
}

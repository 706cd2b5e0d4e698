#pragma once
// kolize-report: the shared state of one report run and the sections.

#include "report_util.h"

#include <string>
#include <vector>

namespace report {

struct Context {
    bool quick = false;
    fs::path out;   ///< reports/
    fs::path data;  ///< reports/data/
    std::string terminal = "pngcairo";
    fs::path bench, bench2d, demo;  ///< sibling binaries (empty: not found)
    fs::path fuzz;                  ///< build/tests/kolize-fuzz (empty: not built)
    fs::path doubleDemo;            ///< --double-demo (empty: not given or not found)
    std::string doubleDemoNote;     ///< why the double column is missing, if it is
    fs::path thesisTables;          ///< assets/thesis/tables.csv
    Runner runner{{}, {}};
    std::string markdown;

    void add(const std::string& text) { markdown += text; }
    /// "## title" and a line that says where the data is.
    void heading(const std::string& title) { add("\n## " + title + "\n\n"); }
    /// The commands that produced a section, to rerun them.
    void commands(const std::vector<std::string>& shown);
    /// Runs `binary` (empty: records "not found") with args; stdout to data/<name>.txt.
    bool runTool(const std::string& name, const fs::path& binary, std::vector<std::string> args,
                 std::string& shown);
    std::string plot(const std::string& name, const std::string& alt, const std::string& body,
                     int width = 1200, int height = 500) {
        return report::plot(runner, out, terminal, name, alt, body, width, height);
    }
    /// Reads data/<file>, or records the problem as a failure and returns false.
    bool load(const std::string& file, Csv& csv);
    /// Runs `binary` with args + --csv data/<name>.csv and reads that CSV, also after a
    /// failed run when it wrote one (the failure is recorded either way).
    bool runCsv(const std::string& name, const fs::path& binary, std::vector<std::string> args,
                Csv& csv, std::string& shown);
    /// runCsv, then the command under the section's heading.
    bool measure(const std::string& name, const fs::path& binary,
                 const std::vector<std::string>& args, Csv& csv) {
        std::string shown;
        const bool loaded = runCsv(name, binary, args, csv, shown);
        commands({shown});
        return loaded;
    }
};

void thesisSection(Context& context);
void scalingSection(Context& context);
void sweepSection(Context& context);
void lowerBoundSection(Context& context);
void box2dSection(Context& context);
void demoSections(Context& context);
void narrowSection(Context& context);
void meshWorldSection(Context& context);
void fuzzSection(Context& context);

}  // namespace report

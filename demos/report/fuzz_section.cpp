// kolize-report: the differential fuzzer's table (tests/fuzz, kolize-fuzz): every kolize
// broadphase and filter mode, operations, searches and queries checked, mismatches, crashes.

#include "report.h"

#include <kolize/kolize.h>

#include <fstream>
#include <sstream>

namespace report {

void fuzzSection(Context& context) {
    context.heading("Robustness: the differential fuzzer");
    const std::string operations = context.quick ? "20000" : "1000000";
    context.add(
        "`kolize-fuzz` (tests/fuzz) runs seeded programs of everything a Bullet app does to a "
        "broadphase, nonsense input and re-entrant callbacks included, and checks every pair "
        "search and query against a plain model of the contract (README: the contract of a "
        "kolize broadphase). " +
        operations +
        " operations per broadphase and filter mode; a crash counts as such (the program is "
        "run as a child), a mismatch prints the seed and the shrunk program in the log.\n\n");
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> shownAll;
    std::size_t total = 0, bad = 0;
    for (const std::string& name : kolize::broadphaseNames()) {
        if (!kolize::isExactBroadphase(name)) {
            continue;
        }
        for (const bool everyFrame : {false, true}) {
            std::vector<std::string> args = {"--broadphase", name, "--operations", operations};
            if (everyFrame) {
                args.push_back("--every-frame");
            }
            const std::string tag = "fuzz-" + name + (everyFrame ? "-every-frame" : "");
            std::string shown;
            const bool ok = context.runTool(tag, context.fuzz, args, shown);
            shownAll.push_back(shown);
            std::ifstream in(context.data / (tag + ".txt"));
            std::string line, word, ops = "?", searches = "?", queries = "?", mismatches = "?";
            std::getline(in, line);
            std::istringstream fields(line);
            std::vector<std::string> words;
            while (fields >> word) {
                words.push_back(word);
            }
            if (words.size() >= 9) {
                ops = words[2];
                searches = words[4];
                queries = words[6];
                mismatches = words[8];
            }
            const bool crashed = !ok && mismatches != "1";
            total += 1;
            bad += ok ? 0 : 1;
            rows.push_back({name, everyFrame ? "every frame" : "when added", ops, searches, queries,
                            mismatches, crashed ? "1" : "0"});
        }
    }
    context.commands({shownAll.empty() ? "" : shownAll.front() + " (and the same per name)"});
    context.add(markdownTable(
        {"broadphase", "filters", "operations", "searches", "queries", "mismatches", "crashes"},
        rows));
    context.add("\n**Reading:** " + std::to_string(total - bad) + " of " + std::to_string(total) +
                " runs without a mismatch or crash.\n");
}

}  // namespace report

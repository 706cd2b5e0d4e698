#include "kolize/narrowphase/ccd_dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace kolize::ccd {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& path, size_t line, const std::string& what) {
    throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

/// A decimal integer as a double, or fail if it does not convert exactly. strtod rounds
/// correctly and "%.0f" prints a double's exact integer value, so a round trip through
/// both proves exactness (numbers here exceed 64-bit integers, e.g. denominators 2^107).
double exactInteger(const std::string& text, const std::string& path, size_t line) {
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(value)) {
        fail(path, line, "expected an integer, got '" + text + "'");
    }
    char buffer[400];
    std::snprintf(buffer, sizeof buffer, "%.0f", value);
    std::string canonical = text[0] == '+' ? text.substr(1) : text;
    if (canonical == "-0") {
        canonical = "0";
    }
    if (canonical != buffer && !(value == 0.0 && canonical == "0")) {
        fail(path, line, "integer " + text + " is not exactly representable as a double");
    }
    return value;
}

/// num / den as a double, refusing anything that would round.
double exactRatio(const std::string& num_text, const std::string& den_text, const std::string& path,
                  size_t line) {
    const double num = exactInteger(num_text, path, line);
    const double den = exactInteger(den_text, path, line);
    int exponent = 0;
    if (!(den > 0.0) || std::frexp(den, &exponent) != 0.5) {
        fail(path, line, "denominator is not a positive power of two");
    }
    const double value = std::ldexp(num, 1 - exponent);  // den = 2^(exponent - 1)
    if (std::ldexp(value, exponent - 1) != num) {
        fail(path, line, "coordinate underflows a double");
    }
    return value;
}

}  // namespace

const char* kindName(QueryKind kind) {
    return kind == QueryKind::kVertexFace ? "vertex-face" : "edge-edge";
}

std::vector<LabeledQuery> readQueryCsv(const std::string& path) {
    std::ifstream in(path);
    if (!in) {
        throw std::runtime_error("cannot open " + path);
    }
    std::vector<LabeledQuery> queries;
    std::string text;
    size_t line = 0;
    LabeledQuery current;
    while (std::getline(in, text)) {
        if (text.empty() || text == "\r") {
            continue;
        }
        ++line;
        std::vector<std::string> v;
        size_t from = 0;
        for (size_t comma; (comma = text.find(',', from)) != std::string::npos; from = comma + 1) {
            v.push_back(text.substr(from, comma - from));
        }
        v.push_back(text.substr(from));
        if (!v.back().empty() && v.back().back() == '\r') {
            v.back().pop_back();
        }
        if (v.size() != 7 || (v[6] != "0" && v[6] != "1")) {
            fail(path, line, "expected 7 comma-separated integers, the last 0 or 1");
        }
        const int slot = static_cast<int>((line - 1) % 8);
        Vec3 p(exactRatio(v[0], v[1], path, line), exactRatio(v[2], v[3], path, line),
               exactRatio(v[4], v[5], path, line));
        (slot < 4 ? current.start[slot] : current.end[slot - 4]) = p;
        if (slot == 0) {
            current.collides = v[6] == "1";
        } else if (current.collides != (v[6] == "1")) {
            fail(path, line, "ground truth differs within one query");
        }
        if (slot == 7) {
            queries.push_back(current);
        }
    }
    if (line % 8 != 0) {
        fail(path, line, "row count is not a multiple of 8");
    }
    return queries;
}

std::vector<QuerySet> readQueryFolder(const std::string& root) {
    // Any folder named after a kind holds that kind's CSVs; its parent's path relative to
    // `root` names the scene, so both a data set folder and its parent are accepted.
    std::vector<std::pair<fs::path, QueryKind>> dirs;
    for (const auto& entry : fs::recursive_directory_iterator(root)) {
        if (!entry.is_directory()) {
            continue;
        }
        for (QueryKind kind : {QueryKind::kVertexFace, QueryKind::kEdgeEdge}) {
            if (entry.path().filename() == kindName(kind)) {
                dirs.emplace_back(entry.path(), kind);
            }
        }
    }
    std::sort(dirs.begin(), dirs.end());
    std::vector<QuerySet> sets;
    for (const auto& [dir, kind] : dirs) {
        std::vector<fs::path> files;
        for (const auto& entry : fs::directory_iterator(dir)) {
            if (entry.path().extension() == ".csv") {
                files.push_back(entry.path());
            }
        }
        std::sort(files.begin(), files.end());
        QuerySet set{fs::relative(dir.parent_path(), root).generic_string(), kind, {}};
        for (const auto& file : files) {
            auto queries = readQueryCsv(file.string());
            set.queries.insert(set.queries.end(), queries.begin(), queries.end());
        }
        if (!set.queries.empty()) {
            sets.push_back(std::move(set));
        }
    }
    if (sets.empty()) {
        throw std::runtime_error("no <scene>/<vertex-face|edge-edge>/*.csv under " + root);
    }
    return sets;
}

}  // namespace kolize::ccd

#include "kolize/narrowphase/ccd_dataset.h"

#include <gmp.h>

#include <algorithm>
#include <cctype>
#include <cstring>
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

/// An integer's decimal digits (optional sign), or fail.
void parseInteger(const std::string& text, mpz_t out, const std::string& path, size_t line) {
    const size_t sign_chars = !text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0;
    const bool plain = text.size() > sign_chars &&
                       std::all_of(text.begin() + sign_chars, text.end(),
                                   [](unsigned char c) { return std::isdigit(c) != 0; });
    if (!plain || mpz_set_str(out, text.c_str() + (text[0] == '+' ? 1 : 0), 10) != 0) {
        fail(path, line, "expected an integer, got '" + text + "'");
    }
}

/// GMP numbers of one conversion, released on every path.
struct RatioScratch {
    mpz_t num, den;
    mpq_t value, back;
    RatioScratch() {
        mpz_inits(num, den, nullptr);
        mpq_inits(value, back, nullptr);
    }
    ~RatioScratch() {
        mpz_clears(num, den, nullptr);
        mpq_clears(value, back, nullptr);
    }
    RatioScratch(const RatioScratch&) = delete;
    RatioScratch& operator=(const RatioScratch&) = delete;
};

/// num / den as a double, refusing anything that would round. Both are integers of any
/// size (GMP): the coordinate must equal a double exactly, e.g. 3 / 2^1074 or 6 / 4.
double exactRatio(const std::string& num_text, const std::string& den_text, const std::string& path,
                  size_t line) {
    RatioScratch r;
    parseInteger(num_text, r.num, path, line);
    parseInteger(den_text, r.den, path, line);
    if (mpz_sgn(r.den) <= 0) {
        fail(path, line, "denominator " + den_text + " is not positive");
    }
    mpq_set_num(r.value, r.num);
    mpq_set_den(r.value, r.den);
    mpq_canonicalize(r.value);
    const double x = mpq_get_d(r.value);  // truncated; exact when the value is a double
    mpq_set_d(r.back, x);
    if (!std::isfinite(x) || !mpq_equal(r.back, r.value)) {
        fail(path, line,
             "coordinate " + num_text + "/" + den_text +
                 " is not exactly representable as a double");
    }
    return x;
}

/// x exactly as "num,den" (den a power of two).
std::string exactText(double x) {
    mpq_t q;
    mpq_init(q);
    mpq_set_d(q, x);
    char* num = mpz_get_str(nullptr, 10, mpq_numref(q));
    char* den = mpz_get_str(nullptr, 10, mpq_denref(q));
    std::string text = std::string(num) + "," + den;
    void (*release)(void*, size_t);
    mp_get_memory_functions(nullptr, nullptr, &release);
    release(num, std::strlen(num) + 1);
    release(den, std::strlen(den) + 1);
    mpq_clear(q);
    return text;
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

void writeQueryCsv(const std::string& path, const std::vector<LabeledQuery>& queries) {
    std::ofstream out(path);
    if (!out) {
        throw std::runtime_error("cannot write " + path);
    }
    for (const LabeledQuery& q : queries) {
        for (int row = 0; row < 8; ++row) {
            const Vec3& p = row < 4 ? q.start[row] : q.end[row - 4];
            if (!p.allFinite()) {
                throw std::runtime_error("writeQueryCsv: a coordinate is not finite");
            }
            out << exactText(p.x()) << ',' << exactText(p.y()) << ',' << exactText(p.z()) << ','
                << (q.collides ? 1 : 0) << '\n';
        }
    }
    if (!out) {
        throw std::runtime_error("error writing " + path);
    }
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

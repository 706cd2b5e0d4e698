#include "report_util.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace report {

Csv Csv::read(const fs::path& path) {
    std::ifstream file(path);
    if (!file) {
        throw std::runtime_error("cannot read '" + path.string() + "'");
    }
    std::stringstream text;
    text << file.rdbuf();
    return parse(text.str(), path.string());
}

Csv Csv::parse(const std::string& text, const std::string& origin) {
    std::vector<std::vector<std::string>> records;
    std::vector<std::string> record;
    std::string field;
    bool quoted = false;
    bool any = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (quoted) {
            if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
                field += '"';
                ++i;
            } else if (c == '"') {
                quoted = false;
            } else {
                field += c;
            }
        } else if (c == '"') {
            quoted = true;
            any = true;
        } else if (c == ',') {
            record.push_back(field);
            field.clear();
            any = true;
        } else if (c == '\n' || c == '\r') {
            if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
                ++i;
            }
            if (any || !field.empty()) {
                record.push_back(field);
                records.push_back(record);
            }
            record.clear();
            field.clear();
            any = false;
        } else {
            field += c;
            any = true;
        }
    }
    if (any || !field.empty()) {
        record.push_back(field);
        records.push_back(record);
    }
    if (records.empty()) {
        throw std::runtime_error("'" + origin + "' is empty (no CSV header)");
    }
    Csv csv;
    csv.origin_ = origin;
    for (std::size_t i = 0; i < records[0].size(); ++i) {
        csv.index_[records[0][i]] = i;
    }
    for (std::size_t r = 1; r < records.size(); ++r) {
        if (records[r].size() != records[0].size()) {
            throw std::runtime_error("'" + origin + "' row " + std::to_string(r + 1) + " has " +
                                     std::to_string(records[r].size()) + " fields, the header " +
                                     std::to_string(records[0].size()));
        }
        csv.rows_.push_back(std::move(records[r]));
    }
    return csv;
}

const std::string& Csv::at(std::size_t row, const std::string& column) const {
    const auto found = index_.find(column);
    if (found == index_.end()) {
        throw std::runtime_error("'" + origin_ + "' has no column '" + column + "'");
    }
    return rows_.at(row)[found->second];
}

double Csv::number(std::size_t row, const std::string& column) const {
    const std::string& text = at(row, column);
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0') {
        return std::numeric_limits<double>::quiet_NaN();
    }
    return value;
}

std::vector<std::size_t> Csv::where(const std::map<std::string, std::string>& equal) const {
    std::vector<std::size_t> out;
    for (std::size_t r = 0; r < rows_.size(); ++r) {
        if (std::all_of(equal.begin(), equal.end(),
                        [&](const auto& kv) { return at(r, kv.first) == kv.second; })) {
            out.push_back(r);
        }
    }
    return out;
}

std::vector<std::string> Csv::distinct(const std::string& column) const {
    std::vector<std::string> out;
    for (std::size_t r = 0; r < rows_.size(); ++r) {
        if (std::find(out.begin(), out.end(), at(r, column)) == out.end()) {
            out.push_back(at(r, column));
        }
    }
    return out;
}

std::string join(const std::vector<std::string>& parts, const std::string& separator) {
    std::string out;
    for (std::size_t i = 0; i < parts.size(); ++i) {
        out += (i > 0 ? separator : "") + parts[i];
    }
    return out;
}

std::string fmt(double value) {
    if (!std::isfinite(value)) {
        return "-";
    }
    char text[64];
    const double magnitude = std::fabs(value);
    if (magnitude >= 100 || value == std::floor(value)) {
        std::snprintf(text, sizeof text, "%.0f", value);
    } else if (magnitude >= 10) {
        std::snprintf(text, sizeof text, "%.1f", value);
    } else if (magnitude >= 1) {
        std::snprintf(text, sizeof text, "%.2f", value);
    } else {
        std::snprintf(text, sizeof text, "%.3g", value);
    }
    return text;
}

std::string times(double value) {
    return std::isfinite(value) ? fmt(value) + "x" : "-";
}

std::string markdownTable(const std::vector<std::string>& header,
                          const std::vector<std::vector<std::string>>& rows) {
    std::string out = "| " + join(header, " | ") + " |\n|";
    for (std::size_t i = 0; i < header.size(); ++i) {
        out += i == 0 ? "---|" : "--:|";
    }
    out += "\n";
    for (const auto& row : rows) {
        out += "| " + join(row, " | ") + " |\n";
    }
    return out;
}

double medianOf(std::vector<double> values) {
    values.erase(
        std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }),
        values.end());
    if (values.empty()) {
        return std::numeric_limits<double>::quiet_NaN();
    }
    std::sort(values.begin(), values.end());
    const std::size_t mid = values.size() / 2;
    return values.size() % 2 == 1 ? values[mid] : (values[mid - 1] + values[mid]) / 2;
}

std::vector<bool> paretoFront(const std::vector<std::pair<double, double>>& points) {
    std::vector<bool> front(points.size(), false);
    for (std::size_t i = 0; i < points.size(); ++i) {
        const auto& p = points[i];
        front[i] = std::isfinite(p.first) && std::isfinite(p.second);
        for (std::size_t j = 0; j < points.size() && front[i]; ++j) {
            const auto& q = points[j];
            if (q.first <= p.first && q.second <= p.second &&
                (q.first < p.first || q.second < p.second)) {
                front[i] = false;
            }
        }
    }
    return front;
}

namespace {

std::string quote(const std::string& word) {
    if (!word.empty() &&
        word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                               "0123456789-_./=:,+") == std::string::npos) {
        return word;
    }
    std::string out = "'";
    for (char c : word) {
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    }
    return out + "'";
}

}  // namespace

std::string Runner::shellLine(const std::vector<std::string>& argv) const {
    std::vector<std::string> words;
    for (const std::string& arg : argv) {
        std::string word = arg;
        const fs::path path(arg);
        if (path.is_absolute() && !base_.empty()) {
            const fs::path relative = path.lexically_relative(base_);
            if (!relative.empty() && *relative.begin() != "..") {
                word = relative.string();
            }
        }
        words.push_back(quote(word));
    }
    return join(words, " ");
}

void Runner::fail(const std::string& command, const std::string& what) {
    failures_.push_back({command, what, ""});
    std::fprintf(stderr, "kolize-report: FAILED (%s): %s\n", what.c_str(), command.c_str());
}

bool Runner::run(const std::string& name, const std::vector<std::string>& argv, std::string& shown,
                 const fs::path& stdoutPath, const fs::path& workDir) {
    shown = shellLine(argv);
    if (!workDir.empty()) {
        shown = "(cd " + quote(shellLine({fs::absolute(workDir).string()})) + " && " + shown + ")";
    }
    fs::create_directories(logDir_);
    const fs::path log = logDir_ / (name + ".log");
    std::fprintf(stderr, "kolize-report: %s\n", shown.c_str());
    const pid_t pid = fork();
    if (pid < 0) {
        fail(shown, std::string("fork failed: ") + std::strerror(errno));
        return false;
    }
    if (pid == 0) {
        const int logFd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int outFd = stdoutPath.empty()
                              ? logFd
                              : open(stdoutPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (logFd < 0 || outFd < 0 || (!workDir.empty() && chdir(workDir.c_str()) != 0)) {
            _exit(126);
        }
        dup2(outFd, STDOUT_FILENO);
        dup2(logFd, STDERR_FILENO);
        std::vector<char*> args;
        for (const std::string& arg : argv) {
            args.push_back(const_cast<char*>(arg.c_str()));
        }
        args.push_back(nullptr);
        execvp(args[0], args.data());
        std::fprintf(stderr, "cannot run %s: %s\n", args[0], std::strerror(errno));
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        return true;
    }
    const std::string what = WIFEXITED(status)
                                 ? "exit code " + std::to_string(WEXITSTATUS(status))
                                 : "killed by signal " + std::to_string(WTERMSIG(status));
    fail(shown, what);
    failures_.back().log = log.string();
    return false;
}

std::string firstLineOf(const std::string& shellCommand) {
    std::FILE* pipe = popen((shellCommand + " 2>/dev/null").c_str(), "r");
    if (pipe == nullptr) {
        return "";
    }
    std::array<char, 512> buffer{};
    std::string line;
    if (std::fgets(buffer.data(), int(buffer.size()), pipe) != nullptr) {
        line = buffer.data();
    }
    pclose(pipe);
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) {
        line.pop_back();
    }
    return line;
}

std::string dataBlock(const std::string& name, const std::vector<std::string>& lines) {
    return "$" + name + " << EOD\n" + join(lines, "\n") + (lines.empty() ? "" : "\n") + "EOD\n";
}

std::string plot(Runner& runner, const fs::path& dir, const std::string& terminal,
                 const std::string& name, const std::string& alt, const std::string& body,
                 int width, int height) {
    const fs::path script = dir / (name + ".gp");
    {
        std::ofstream out(script);
        out << "set terminal " << terminal << " size " << width << "," << height
            << " noenhanced\nset output \"" << name << ".png\"\n"
            << body;
    }
    std::string shown;
    if (!runner.run("gnuplot-" + name, {"gnuplot", name + ".gp"}, shown, {}, dir)) {
        return "*(plot failed: `" + shown + "`; see the failures at the end)*\n";
    }
    return "![" + alt + "](" + name + ".png)\n\n*Plot script: `" + name + ".gp`.*\n";
}

}  // namespace report

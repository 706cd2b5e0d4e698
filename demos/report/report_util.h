#pragma once
// kolize-report's building blocks: CSV tables, child processes whose failures are recorded,
// Markdown tables, number formatting, gnuplot.

#include "../common/split.h"

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace report {

namespace fs = std::filesystem;

/// A CSV file (RFC 4180 quoting) read whole.
class Csv {
  public:
    /// Throws std::runtime_error naming the file when it is missing, empty or a row has the
    /// wrong number of fields.
    static Csv read(const fs::path& path);
    static Csv parse(const std::string& text, const std::string& origin);

    std::size_t size() const { return rows_.size(); }
    bool has(const std::string& column) const { return index_.count(column) != 0; }
    /// The field; throws std::runtime_error for an unknown column.
    const std::string& at(std::size_t row, const std::string& column) const;
    /// The field as a number; NaN when empty or not a number.
    double number(std::size_t row, const std::string& column) const;
    /// Rows whose fields equal the given values.
    std::vector<std::size_t> where(const std::map<std::string, std::string>& equal) const;
    /// Distinct values of a column in order of first appearance.
    std::vector<std::string> distinct(const std::string& column) const;

  private:
    std::string origin_;
    std::map<std::string, std::size_t> index_;
    std::vector<std::vector<std::string>> rows_;
};

using kolize::demo::split;
std::string join(const std::vector<std::string>& parts, const std::string& separator);

/// "1.23", "45.6", "789", "0.00123"; "-" for NaN.
std::string fmt(double value);
/// fmt(value) + "x".
std::string times(double value);

/// A Markdown table.
std::string markdownTable(const std::vector<std::string>& header,
                          const std::vector<std::vector<std::string>>& rows);

/// The median of the finite values; NaN when there are none.
double medianOf(std::vector<double> values);

/// For each (x, y) point (smaller is better on both): true when no other point is at least as
/// good on both and better on one. Points with a non-finite coordinate are never on it.
std::vector<bool> paretoFront(const std::vector<std::pair<double, double>>& points);

/// One child command that failed.
struct Failure {
    std::string command;
    std::string what;  ///< "exit code 3", "killed by signal 9", "not found"
    std::string log;
};

/// Runs children, each with its output in a log file, and remembers the failures.
class Runner {
  public:
    Runner(fs::path logDir, fs::path shownBase)
        : logDir_(std::move(logDir)), base_(std::move(shownBase)) {}
    /// Runs `argv` (argv[0] a path) in `workDir` (empty: the current one) with stdout to
    /// `stdoutPath` (empty: the log) and stderr to the log data/logs/<name>.log. Returns
    /// true on exit code 0; else records a Failure. `shown` gets the command as a shell line.
    bool run(const std::string& name, const std::vector<std::string>& argv, std::string& shown,
             const fs::path& stdoutPath = {}, const fs::path& workDir = {});
    /// Records a failure that happened without running anything (e.g. a missing binary).
    void fail(const std::string& command, const std::string& what);
    const std::vector<Failure>& failures() const { return failures_; }
    /// The shell line for argv: paths under the working directory shown relative to it.
    std::string shellLine(const std::vector<std::string>& argv) const;

  private:
    fs::path logDir_;
    fs::path base_;
    std::vector<Failure> failures_;
};

/// The first line of a command's standard output, or "" (for machine information).
std::string firstLineOf(const std::string& shellCommand);

}  // namespace report

namespace report {

/// A gnuplot data block: `$name << EOD`, the lines, `EOD`.
std::string dataBlock(const std::string& name, const std::vector<std::string>& lines);

/// Writes <dir>/<name>.gp (terminal, size, output <name>.png, then `body`) and runs gnuplot
/// in `dir`. Returns the Markdown for the image, or a line naming the failed command.
std::string plot(Runner& runner, const fs::path& dir, const std::string& terminal,
                 const std::string& name, const std::string& alt, const std::string& body,
                 int width = 1200, int height = 500);

}  // namespace report

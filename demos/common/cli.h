#pragma once
// Command-line values shared by the demos: whole numbers in a range, times in seconds and
// lists of names, each refused with a one-line message through the program's `fail`.

#include "split.h"

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

namespace kolize::demo {

using Fail = void (*)(const std::string& message);

/// A bound for a message: "0", "1", "0.5", "10".
inline std::string boundText(double x) {
    std::string text = std::to_string(x);
    text.erase(text.find_last_not_of('0') + 1);
    if (!text.empty() && text.back() == '.') {
        text.pop_back();
    }
    return text;
}

/// `text` as a whole number in low..high, else fail(...) naming `flag` (fail must not return).
inline long wholeNumber(const std::string& flag, const std::string& text, long low, long high,
                        Fail fail) {
    char* end = nullptr;
    const long value = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || value < low || value > high) {
        fail(flag + " needs a whole number in " + std::to_string(low) + ".." +
             std::to_string(high) + ", got '" + text + "'");
    }
    return value;
}

/// `text` as a number in [low, high] (`what` names it in the message, e.g. "metres"), else
/// fail(...) naming `flag`.
inline double realNumber(const std::string& flag, const std::string& text, double low, double high,
                         const std::string& what, Fail fail) {
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !(value >= low) || !(value <= high)) {
        fail(flag + " needs " + what + " in " + boundText(low) + ".." + boundText(high) +
             ", got '" + text + "'");
    }
    return value;
}

/// `text` ("0.01" or "1/60") as seconds in (0, 10], else fail(...) naming `flag`.
inline double seconds(const std::string& flag, const std::string& text, Fail fail) {
    const std::size_t slash = text.find('/');
    char* end = nullptr;
    double value = std::strtod(text.c_str(), &end);
    if (slash != std::string::npos && end == text.c_str() + slash) {
        const double divisor = std::strtod(text.c_str() + slash + 1, &end);
        value = divisor != 0 ? value / divisor : 0;
    }
    if (text.empty() || *end != '\0' || !(value > 0) || !(value <= 10)) {
        fail(flag + " needs a time in seconds in (0, 10], e.g. 0.01 or 1/60, got '" + text + "'");
    }
    return value;
}

/// "all" -> `valid`; else the comma-separated names of `text`, each of which must be in
/// `valid` (fail(...) naming the flag, the name and the valid ones otherwise).
inline std::vector<std::string> chosen(const std::string& flag, const std::string& text,
                                       const std::vector<std::string>& valid, Fail fail) {
    if (text == "all") {
        return valid;
    }
    const std::vector<std::string> out = split(text, ',');
    if (out.empty()) {
        fail(flag + " needs at least one name");
    }
    for (const std::string& name : out) {
        if (std::find(valid.begin(), valid.end(), name) == valid.end()) {
            std::string names;
            for (const std::string& v : valid) {
                names += (names.empty() ? "" : ", ") + v;
            }
            fail(flag + ": unknown name '" + name + "'; valid: all, " + names);
        }
    }
    return out;
}

}  // namespace kolize::demo

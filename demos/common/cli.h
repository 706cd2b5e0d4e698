#pragma once
// Command-line values shared by the demos: whole numbers in a range and times in seconds,
// each refused with a one-line message through the program's `fail`.

#include <cstdlib>
#include <string>

namespace kolize::demo {

using Fail = void (*)(const std::string& message);

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

}  // namespace kolize::demo

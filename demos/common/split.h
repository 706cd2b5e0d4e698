#pragma once
// Splitting command-line lists and CSV-like lines, shared by the demos and the report.

#include <sstream>
#include <string>
#include <vector>

namespace kolize::demo {

/// The pieces of `text` between `separator`s (no quoting): "a,b" -> {"a", "b"}; "" -> {}.
inline std::vector<std::string> split(const std::string& text, char separator) {
    std::vector<std::string> out;
    std::stringstream stream(text);
    for (std::string item; std::getline(stream, item, separator);) {
        out.push_back(item);
    }
    return out;
}

}  // namespace kolize::demo

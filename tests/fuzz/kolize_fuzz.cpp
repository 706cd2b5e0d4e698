// kolize-fuzz: the differential fuzzer on the command line, for soak runs.
//   kolize-fuzz --broadphase NAME --operations N [--seed S] [--programs P] [--every-frame]
//               [--merged-cache]
// Runs P programs of N/P operations (seeds S, S+1, ...), prints one line with operations,
// searches, queries and mismatches; on the first mismatch prints the seed and the shrunk
// program as code and exits with 1.

#include "broadphase_fuzz.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

int main(int argc, char** argv) {
    std::string name = "grid";
    std::size_t operations = 100000, programs = 0;
    std::uint32_t seed = 1;
    kolize::BroadphaseSettings settings;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&]() -> const char* {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "kolize-fuzz: %s needs a value\n", arg.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (arg == "--broadphase") {
            name = value();
        } else if (arg == "--operations") {
            operations = std::strtoull(value(), nullptr, 10);
        } else if (arg == "--seed") {
            seed = std::uint32_t(std::strtoul(value(), nullptr, 10));
        } else if (arg == "--programs") {
            programs = std::strtoull(value(), nullptr, 10);
        } else if (arg == "--every-frame") {
            settings.filters = kolize::FilterEvaluation::EveryFrame;
        } else if (arg == "--merged-cache") {
            settings.ownPairCache = kolize::PairCacheChoice::Merged;
        } else {
            std::fprintf(stderr,
                         "usage: kolize-fuzz --broadphase NAME --operations N [--seed S] "
                         "[--programs P] [--every-frame] [--merged-cache]\n");
            return 2;
        }
    }
    if (programs == 0) {
        programs = operations / 5000 + 1;
    }
    const std::size_t each = operations / programs + 1;
    std::size_t done = 0, searches = 0, queries = 0;
    for (std::size_t p = 0; p < programs; ++p) {
        const std::uint32_t programSeed = seed + std::uint32_t(p);
        const auto program = kolize::fuzz::randomProgram(programSeed, each);
        const kolize::fuzz::Result result = kolize::fuzz::run(name, program, settings);
        done += result.operations;
        searches += result.searches;
        queries += result.queries;
        if (result.failed) {
            const auto minimal = kolize::fuzz::shrink(name, program, settings);
            std::printf("%s operations %zu searches %zu queries %zu mismatches 1 seed %u\n",
                        name.c_str(), done, searches, queries, programSeed);
            std::printf("%s\nshrunk to %zu operations:\n%s", result.failure.c_str(), minimal.size(),
                        kolize::fuzz::asCode(minimal).c_str());
            return 1;
        }
    }
    std::printf("%s operations %zu searches %zu queries %zu mismatches 0 seeds %u..%u\n",
                name.c_str(), done, searches, queries, seed, seed + std::uint32_t(programs) - 1);
    return 0;
}

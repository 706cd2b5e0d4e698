/// kolize-ccd-tunneling-demo [--csv FILE]
///
/// The discrete-time problem: a small cube (edge 0.2) is fired along +x at a thin static
/// plate (thickness 0.01, 2 x 2) at increasing speeds (distance per step). Every trial
/// truly hits the plate during the step (the contact starts at a uniformly drawn time).
/// Discrete checks test for overlap at the end of each of 1, 2, 4, 8, 16 substeps; the
/// continuous test is meshCcd over the two 12-triangle meshes. Prints the missed fraction
/// per speed and method and the mean time per step; `--csv` writes one row per method and
/// speed: method,substeps,speed,trials,missed,mean_us.
///
/// The discrete overlap test is the exact test for two axis-aligned boxes (both stay
/// axis-aligned: pure translation), i.e. the cheapest possible discrete check; a general
/// mesh overlap test would cost more per substep.
#include "ccd_scenes.h"

#include "kolize/narrowphase/mesh_ccd.h"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace {

using namespace kolize::ccd;
using scenes::boxMesh;
using scenes::Random;
using Trial = scenes::ThinWall::Trial;

bool boxesOverlap(const Vec3& lo_a, const Vec3& hi_a, const Vec3& lo_b, const Vec3& hi_b) {
    return (lo_a.array() <= hi_b.array()).all() && (lo_b.array() <= hi_a.array()).all();
}

}  // namespace

int main(int argc, char** argv) {
    std::string csv_path;
    for (int i = 1; i < argc; ++i) {
        if (std::string(argv[i]) == "--csv" && i + 1 < argc) {
            csv_path = argv[++i];
        } else {
            std::fprintf(stderr, "usage: kolize-ccd-tunneling-demo [--csv FILE]\n");
            return 2;
        }
    }
    const scenes::ThinWall wall;
    const double edge = scenes::ThinWall::kEdge;
    const Vec3 &plate_lo = wall.plate_lo, &plate_hi = wall.plate_hi;
    const MovingMesh& plate = wall.plate;
    const std::vector<double> speeds{0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10};
    const std::vector<int> substeps{1, 2, 4, 8, 16};
    constexpr int kTrials = 200;

    std::ofstream csv;
    if (!csv_path.empty()) {
        csv.open(csv_path);
        csv << "method,substeps,speed,trials,missed,mean_us\n";
    }
    std::printf(
        "missed collisions out of %d per speed (distance per step; cube edge %.2f, "
        "plate thickness %.2f)\n\n%8s",
        kTrials, edge, plate_hi.x() - plate_lo.x(), "speed");
    for (int n : substeps) {
        std::printf(" %9s%-3d", "discrete", n);
    }
    std::printf(" %12s\n", "continuous");
    std::vector<double> total_us(substeps.size() + 1, 0.0);
    Random random;
    for (double v : speeds) {
        std::vector<Trial> trials;
        for (int i = 0; i < kTrials; ++i) {
            trials.push_back(scenes::ThinWall::trial(v, random));
        }
        std::printf("%8.2f", v);
        for (size_t m = 0; m <= substeps.size(); ++m) {
            int missed = 0;
            const auto t0 = std::chrono::steady_clock::now();
            for (const Trial& t : trials) {
                bool hit = false;
                if (m < substeps.size()) {
                    for (int k = 1; k <= substeps[m] && !hit; ++k) {
                        const Vec3 shift = t.motion * (static_cast<double>(k) / substeps[m]);
                        hit = boxesOverlap(t.lo + shift, t.hi + shift, plate_lo, plate_hi);
                    }
                } else {
                    hit = meshCcd(boxMesh(t.lo, t.hi, t.motion), plate).hit;
                }
                missed += !hit;
            }
            const double us =
                std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0)
                    .count() /
                kTrials;
            total_us[m] += us;
            std::printf(" %12d", missed);
            if (csv) {
                csv << (m < substeps.size() ? "discrete" : "continuous") << ','
                    << (m < substeps.size() ? substeps[m] : 0) << ',' << v << ',' << kTrials << ','
                    << missed << ',' << us << '\n';
            }
        }
        std::printf("\n");
    }
    std::printf("%8s", "mean us");
    for (double us : total_us) {
        std::printf(" %12.3f", us / speeds.size());
    }
    std::printf("\n\nmean us: time per step and trial, averaged over speeds.\n");
    return 0;
}

// The sweep core of two commits, fed the same recorded pair stream: A.h and B.h are the two
// versions of sweep_and_prune.h with their names made distinct (scripts/sweep-ab.sh does
// that). Only the core's work is timed (update, maintain, drainChanges), no adapter and no
// pair cache. The two run alternately, R rounds; printed: each one's median total and median
// frame over the rounds, their ratios, and whether they drained the same changed pairs.
#include <kolize/engine/pair_stream.h>

#include "A.h"
#include "B.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
using Box = kolize::Aabb<3, float>;

struct Event {
    kolize::StreamEvent::Op op;
    kolize::ObjectId id;
    Box box;
};

struct Run {
    double total = 0, medianFrame = 0;
    std::size_t checksum = 0;
};

template <class Core>
Run run(const std::vector<Event>& events) {
    Core core;
    std::vector<Box> last;
    std::vector<double> frames;
    Run out;
    Clock::time_point start = Clock::now();
    for (const Event& e : events) {
        switch (e.op) {
            case kolize::StreamEvent::Op::Create:
                if (last.size() <= e.id) {
                    last.resize(e.id + 1);
                }
                last[e.id] = e.box;
                core.insert(e.id, e.box);
                break;
            case kolize::StreamEvent::Op::Destroy:
                core.remove(e.id);
                break;
            case kolize::StreamEvent::Op::SetAabb:
                if (!(last[e.id] == e.box)) {  // as the adapter: unchanged boxes stop there
                    last[e.id] = e.box;
                    core.update(e.id, e.box);
                }
                break;
            case kolize::StreamEvent::Op::EndFrame: {
                core.maintain();
                core.drainChanges([&](kolize::ObjectId a, kolize::ObjectId b) {
                    out.checksum = out.checksum * 31 + a * 7919 + b;
                });
                const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
                frames.push_back(seconds);
                out.total += seconds;
                start = Clock::now();
                break;
            }
        }
    }
    std::sort(frames.begin(), frames.end());
    out.medianFrame = frames.empty() ? 0 : frames[frames.size() / 2];
    return out;
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return values[values.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: sweep_ab ROUNDS STREAM...\n");
        return 2;
    }
    const int rounds = std::max(1, std::atoi(argv[1]));
    for (int file = 2; file < argc; ++file) {
        const kolize::PairStream stream = kolize::PairStream::load(argv[file]);
        std::vector<Event> events;
        for (const kolize::StreamEvent& e : stream.events) {
            Event event{e.op, e.object, {}};
            for (int axis = 0; axis < 3; ++axis) {
                event.box.lo[axis] = float(e.aabbMin[axis]);
                event.box.hi[axis] = float(e.aabbMax[axis]);
            }
            events.push_back(event);
        }
        std::vector<double> totalA, totalB, frameA, frameB;
        bool same = true;
        for (int round = 0; round < rounds; ++round) {
            const Run a = run<kolize::SweepA<3, float>>(events);
            const Run b = run<kolize::SweepB<3, float>>(events);
            totalA.push_back(a.total);
            totalB.push_back(b.total);
            frameA.push_back(a.medianFrame);
            frameB.push_back(b.medianFrame);
            same = same && a.checksum == b.checksum;
        }
        std::printf(
            "%s: total A %.2f ms, B %.2f ms (B/A %.2f); median frame A %.4f ms, B %.4f ms "
            "(B/A %.2f); changes drained %s\n",
            argv[file], 1e3 * median(totalA), 1e3 * median(totalB), median(totalB) / median(totalA),
            1e3 * median(frameA), 1e3 * median(frameB), median(frameB) / median(frameA),
            same ? "identical" : "DIFFERENT");
    }
    return 0;
}

#pragma once
/// \file
/// The sweep's axes (internal to SweepAndPrune, see sweep_and_prune.h): the endpoint layout,
/// the overlap test by endpoint positions, and the three ways an axis' order is restored
/// after its ends took new values: an insertion pass over the whole axis, one end swapped to
/// its place (sortAway), and the check that leaves a pass out (kindOrderHolds). Each works on
/// one axis' array and every object's positions; a pair whose overlap may have changed goes
/// to `record(a, b)`.

#include <kolize/broadphase/aabb.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

namespace kolize {
namespace sweep_detail {

/// One box endpoint in a sorted axis: its value, its object, and whether it is a max. The
/// order: by value, and a min before a max of equal value (closed intervals: touching boxes
/// overlap).
template <class Scalar>
struct Endpoint {
    Scalar value_;
    std::uint32_t code;  ///< id * 2 + (1 for a max)

    static Endpoint make(Scalar value, ObjectId id, bool isMax) {
        return Endpoint{value, id * 2 + (isMax ? 1u : 0u)};
    }
    Scalar value() const { return value_; }
    void setValue(Scalar value) { value_ = value; }
    ObjectId id() const { return code >> 1; }
    bool isMax() const { return (code & 1) != 0; }
    friend bool before(const Endpoint& a, const Endpoint& b) {
        return a.value_ < b.value_ || (a.value_ == b.value_ && !a.isMax() && b.isMax());
    }
};

/// For float, the order is one integer comparison: the value's bits mapped to an unsigned
/// that sorts like the value (-0 taken as +0, so that they compare equal), then the max
/// flag, then the id.
template <>
struct Endpoint<float> {
    std::uint64_t key;

    static std::uint32_t ordered(float value) {
        std::uint32_t bits;
        const float canonical = value == 0 ? 0.0f : value;
        std::memcpy(&bits, &canonical, sizeof bits);
        return (bits & 0x80000000u) != 0 ? ~bits : bits | 0x80000000u;
    }
    static Endpoint make(float value, ObjectId id, bool isMax) {
        return Endpoint{(std::uint64_t(ordered(value)) << 32) | (isMax ? 0x80000000u : 0u) | id};
    }
    float value() const {
        const std::uint32_t high = std::uint32_t(key >> 32);
        const std::uint32_t bits = (high & 0x80000000u) != 0 ? high & 0x7fffffffu : ~high;
        float out;
        std::memcpy(&out, &bits, sizeof out);
        return out;
    }
    void setValue(float value) { storeHighHalf(key, ordered(value)); }
    ObjectId id() const { return ObjectId(key & 0x7fffffffu); }
    bool isMax() const { return (key & 0x80000000u) != 0; }
    friend bool before(const Endpoint& a, const Endpoint& b) { return a.key < b.key; }

  private:
    /// `key`'s high half set to `high`, its low half kept. A store of the high half alone
    /// where the layout allows: a batch's moves write six endpoints each, spread over three
    /// arrays, and a read-modify-write of the whole key waits for each line first (the
    /// stack's awake frames, with the writes at update(): the core 25 us per frame with it,
    /// 18 without).
    static void storeHighHalf(std::uint64_t& key, std::uint32_t high) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
        std::memcpy(reinterpret_cast<unsigned char*>(&key) + 4, &high, sizeof high);
#else
        key = (std::uint64_t(high) << 32) | (key & 0xffffffffu);
#endif
    }
};

/// Per object: the positions of its min and max on every axis (2 * axis + 0 / 1), kept
/// apart from the boxes so that swaps touch dense memory.
template <int D>
using Positions = std::array<std::uint32_t, 2 * D>;

/// Whether the intervals with endpoint positions `first` and `second` overlap on every
/// axis but `skip`, and `overlap` (a swap passes whether the two ends differ in kind: one
/// chain of ands, as fast as the copies it replaced, where and-ing the result afterwards
/// cost the ragdolls' pass 4-6%). Branch-free: in a swap the outcome is a coin toss,
/// while a change is recorded for few swaps (with `skip` a constant, as in
/// insertionPass, the skipped axis costs nothing).
template <int D>
bool overlapsOnOtherAxes(const Positions<D>& first, const Positions<D>& second, int skip,
                         bool overlap = true) {
    for (int axis = 0; axis < D; ++axis) {
        overlap &= axis == skip || (first[2 * axis + 1] >= second[2 * axis]) &
                                       (second[2 * axis + 1] >= first[2 * axis]);
    }
    return overlap;
}

/// What an insertion pass did: the ends it moved past others, and whether that was under
/// half the range whose positions it rewrote (then the next pass writes each end's position
/// as it moves instead).
struct PassResult {
    std::size_t passed = 0;
    bool fewSwaps = false;
};

/// One insertion sort over `axis`, whose moved endpoints hold their new values at their old
/// places. The positions on this axis are stale during the pass (the overlap tests read the
/// other axes only): kWriteEach writes each endpoint's position as it moves (when the last
/// pass over this axis moved ends fewer times than half the range it rewrote: a stack's
/// sideways jitter); else they are written once over the range that changed, at the end (a
/// pile, whose ends pass many others). The axis is a constant: the overlap test then reads
/// the other axes' positions of the moving endpoint from registers.
template <int D, int axis, bool kWriteEach, class Endpoint, class Record>
PassResult insertionPass(std::vector<Endpoint>& axisEdges, std::vector<Positions<D>>& positions,
                         Record&& record) {
    // Raw pointers: the arrays do not change size here, and the compiler need not reload
    // them after every store or recorded change.
    Endpoint* const edges = axisEdges.data();
    Positions<D>* const at = positions.data();
    const std::size_t n = axisEdges.size();
    std::size_t first = n, last = 0, passed = 0;
    for (std::size_t i = 1; i < n; ++i) {
        if (!before(edges[i], edges[i - 1])) {
            continue;
        }
        const Endpoint moving = edges[i];
        const ObjectId id = moving.id();
        const bool isMax = moving.isMax();
        const Positions<D> mine = at[id];
        std::size_t to = i;
        do {
            const Endpoint next = edges[to - 1];
            // Branch-free until the rare outcome (see overlapsOnOtherAxes).
            if (overlapsOnOtherAxes<D>(mine, at[next.id()], axis, next.isMax() != isMax)) {
                record(id, next.id());
            }
            edges[to] = next;
            if (kWriteEach) {
                at[next.id()][2 * axis + (next.isMax() ? 1 : 0)] = std::uint32_t(to);
            }
            --to;
        } while (to > 0 && before(moving, edges[to - 1]));
        passed += i - to;
        edges[to] = moving;
        if (kWriteEach) {
            at[id][2 * axis + (isMax ? 1 : 0)] = std::uint32_t(to);
        }
        first = std::min(first, to);
        last = i;
    }
    if (!kWriteEach) {
        for (std::size_t k = first; k <= last && k < n; ++k) {
            at[edges[k].id()][2 * axis + (edges[k].isMax() ? 1 : 0)] = std::uint32_t(k);
        }
    }
    return PassResult{passed, first <= last && 2 * passed < last - first};
}

/// Whether `edges` orders every min against every max as their values (and kinds, a min
/// first at equal values) do; `inOrder`: whether it is sorted outright. The ends of one
/// kind between two ends of the other (a run) may be in any order: one scan checks each
/// end against the largest of the run before its own, which by transitivity orders it
/// against every end of the other kind.
/// Stops at the first end out of that order. Branch-free otherwise: in a pile the
/// runs are short and where they end a coin toss.
template <class Endpoint>
bool kindOrderHolds(const std::vector<Endpoint>& edges, bool& inOrder) {
    inOrder = true;
    if (edges.empty()) {
        return true;
    }
    // The first run is checked against a smallest end of the other kind (no end is
    // before it).
    Endpoint lastRun = edges[0], run = edges[0];  // the largest of each run
    std::size_t at = 1;
    while (at < edges.size() && edges[at].isMax() == edges[0].isMax()) {
        inOrder &= !before(edges[at], edges[at - 1]);
        run = before(run, edges[at]) ? edges[at] : run;
        ++at;
    }
    for (; at < edges.size(); ++at) {
        const Endpoint edge = edges[at];
        const Endpoint previous = edges[at - 1];
        inOrder &= !before(edge, previous);
        const bool newRun = edge.isMax() != previous.isMax();
        lastRun = newRun ? run : lastRun;
        run = newRun || before(run, edge) ? edge : run;
        if (!before(lastRun, edge)) {
            return false;
        }
    }
    return true;
}

/// Insertion with a hole: the endpoint at `where` on `axis` moves by kStep (-1 down, +1 up)
/// past every endpoint it now precedes (follows), each of those one place the other way. A
/// passed endpoint of the other kind (a min passing a max or the reverse) is where two
/// intervals start or stop overlapping on this axis: recorded when the other axes overlap.
/// The moving object's positions on the other axes do not change meanwhile, so they are
/// read once. Dead objects' endpoints (removed, compacted at the next maintain()) are
/// passed like any other; a change they take part in is dropped by drainChanges. Returns
/// the endpoints passed.
template <int D, int kStep, class Endpoint, class Record>
std::size_t sortAway(std::vector<Endpoint>& edges, std::vector<Positions<D>>& positions, int axis,
                     std::uint32_t where, Record&& record) {
    const Endpoint moving = edges[where];
    const ObjectId id = moving.id();
    const bool isMax = moving.isMax();
    const Positions<D> mine = positions[id];
    const std::uint32_t end = kStep > 0 ? std::uint32_t(edges.size() - 1) : 0;
    std::size_t passed = 0;
    while (where != end) {
        const Endpoint next = edges[where + kStep];
        if (!(kStep > 0 ? before(next, moving) : before(moving, next))) {
            break;
        }
        const ObjectId other = next.id();
        Positions<D>& theirs = positions[other];
        // Branch-free until the rare outcome: the kinds differ about half the time, at
        // random, while a change is recorded for few swaps.
        if (overlapsOnOtherAxes<D>(mine, theirs, axis, next.isMax() != isMax)) {
            record(id, other);
        }
        edges[where] = next;
        theirs[2 * axis + (next.isMax() ? 1 : 0)] = where;
        where += kStep;
        ++passed;
    }
    edges[where] = moving;
    positions[id][2 * axis + (isMax ? 1 : 0)] = where;
    return passed;
}

}  // namespace sweep_detail
}  // namespace kolize

#pragma once
/// \file
/// SweepAndPrune<D, Scalar>: exact incremental sweep and prune (broadphase "sweep").
///
/// Per axis, one array of the objects' box endpoints sorted by value (a min before a max
/// of equal value: closed intervals, touching boxes overlap). A moved box's endpoints are
/// carried to their new places by adjacent swaps, as Bullet's btAxisSweep3 does; a min
/// passing another object's max (or the reverse) is where the two intervals start or stop
/// overlapping on that axis, and when their other axes overlap, the pair is recorded as
/// changed. Work per frame: O(moved objects + swaps); objects at rest cost nothing.
///
/// Unlike btAxisSweep3: the endpoints are the exact box coordinates (no quantisation, so no
/// world bounds and no extra pairs), ids are 32-bit (no 16-bit handle limit), and objects
/// created or removed between two frames are merged in (or compacted out) once per frame,
/// in O(N + their overlaps), instead of one O(N) insertion each.
///
/// The core tracks overlaps itself (kTracksOverlaps): the adapter takes the changed pairs
/// from drainChanges and tests only those. A pair appears there whenever the boxes' overlap
/// may have changed (a superset: each swap of a min and a max of two objects whose other
/// axes overlap, and every pair of an object merged in). queryBox scans the first axis up
/// to the box's end, queryRay visits every object: use another core where queries matter.

#include <kolize/broadphase/aabb.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace kolize {

/// Settings of the sweep core (it has none that change its answers).
struct SweepSettings {};

template <int D, class Scalar>
class SweepAndPrune {
  public:
    using Box = Aabb<D, Scalar>;
    using Settings = SweepSettings;
    /// The adapter takes changed pairs from drainChanges instead of querying for candidates.
    static constexpr bool kTracksOverlaps = true;

    explicit SweepAndPrune(const Settings& = {}) {}

    /// Adds object `id` (ids are dense; `id` must not be live); merged in at the next
    /// maintain().
    void insert(ObjectId id, const Box& box) {
        if (id >= objects_.size()) {
            objects_.resize(std::size_t(id) + 1);
        }
        Object& object = objects_[id];
        object.box = box;
        object.state = State::Pending;
        object.pendingAt = static_cast<std::uint32_t>(pending_.size());
        pending_.push_back(id);
        ++size_;
    }

    /// Moves object `id`: its endpoints swap their way to the new values.
    void update(ObjectId id, const Box& box) {
        Object& object = objects_[id];
        object.box = box;
        if (object.state == State::Pending) {
            return;
        }
        for (int axis = 0; axis < D; ++axis) {
            std::vector<Endpoint>& edges = axes_[axis];
            const std::uint32_t low = object.at[axis][0], high = object.at[axis][1];
            const Scalar oldLow = edges[low].value, oldHigh = edges[high].value;
            if (oldLow == box.lo[axis] && oldHigh == box.hi[axis]) {
                continue;
            }
            edges[low].value = box.lo[axis];
            edges[high].value = box.hi[axis];
            // Growing first (only adds overlaps), then shrinking (only removes them).
            if (box.lo[axis] < oldLow) {
                sortDown(axis, low);
            }
            if (box.hi[axis] > oldHigh) {
                sortUp(axis, object.at[axis][1]);
            }
            if (box.lo[axis] > oldLow) {
                sortUp(axis, object.at[axis][0]);
            }
            if (box.hi[axis] < oldHigh) {
                sortDown(axis, object.at[axis][1]);
            }
        }
    }

    /// Removes object `id`; its endpoints are compacted out at the next maintain().
    void remove(ObjectId id) {
        Object& object = objects_[id];
        if (object.state == State::Pending) {
            const std::uint32_t at = object.pendingAt;
            pending_[at] = pending_.back();
            objects_[pending_[at]].pendingAt = at;
            pending_.pop_back();
        } else {
            ++dead_;
        }
        object.state = State::Dead;
        --size_;
    }

    /// Before every pair search: compacts removed objects' endpoints out and merges the
    /// created ones in, recording every pair of a merged object whose boxes overlap.
    void maintain() {
        if (dead_ > 0) {
            compact();
        }
        if (!pending_.empty()) {
            merge();
        }
    }

    /// Calls `changed(a, b)` for every pair recorded since the last call (possibly several
    /// times), then forgets them.
    template <class Sink>
    void drainChanges(Sink&& changed) {
        for (const Change& change : changes_) {
            if (objects_[change.a].state == State::Sorted &&
                objects_[change.b].state == State::Sorted) {
                changed(change.a, change.b);
            }
        }
        changes_.clear();
    }

    /// Calls `candidate(a, b)` once for every pair whose boxes overlap (a sweep along the
    /// first axis; for tests and for an all-pairs search).
    template <class Sink>
    void findCandidates(Sink&& candidate) {
        maintain();
        changes_.clear();
        std::vector<ObjectId> active;
        for (const Endpoint& edge : axes_[0]) {
            const ObjectId id = edge.id();
            if (objects_[id].state != State::Sorted) {
                continue;
            }
            if (edge.isMax()) {
                active.erase(std::find(active.begin(), active.end(), id));
                continue;
            }
            for (ObjectId other : active) {
                if (overlapsOnOtherAxes(id, other, 0)) {
                    candidate(other, id);
                }
            }
            active.push_back(id);
        }
    }

    /// Objects whose first-axis interval meets the box's (a superset; pending objects all).
    template <class Visit>
    void queryBox(const Box& box, Visit&& visit) const {
        for (ObjectId id : pending_) {
            visit(id);
        }
        const std::vector<Endpoint>& edges = axes_[0];
        for (std::size_t at = 0; at < edges.size() && !(edges[at].value > box.hi[0]); ++at) {
            const ObjectId id = edges[at].id();
            if (!edges[at].isMax() && objects_[id].state == State::Sorted &&
                !(objects_[id].box.hi[0] < box.lo[0])) {
                visit(id);
            }
        }
    }

    /// Every live object (the adapter's exact test decides).
    template <class Visit>
    void queryRay(const Ray<D, Scalar>& /*ray*/, Visit&& visit) const {
        for (ObjectId id = 0; id < objects_.size(); ++id) {
            if (objects_[id].state == State::Sorted || objects_[id].state == State::Pending) {
                visit(id);
            }
        }
    }

    std::size_t size() const { return size_; }
    /// Endpoint swaps so far (the work of update()), and changed pairs recorded.
    std::size_t swaps() const { return swaps_; }
    std::size_t changesRecorded() const { return changesRecorded_; }

    /// Checks the arrays' order, the endpoint positions and values against the boxes, and
    /// the counts; throws std::logic_error.
    void validate() const {
        auto fail = [](const std::string& what) {
            throw std::logic_error("SweepAndPrune: " + what);
        };
        std::size_t sorted = 0, pending = 0, dead = 0;
        for (ObjectId id = 0; id < objects_.size(); ++id) {
            const Object& object = objects_[id];
            if (object.state == State::Sorted) {
                ++sorted;
                for (int axis = 0; axis < D; ++axis) {
                    for (int end = 0; end < 2; ++end) {
                        const std::uint32_t at = object.at[axis][end];
                        if (at >= axes_[axis].size() || axes_[axis][at].id() != id ||
                            axes_[axis][at].isMax() != (end == 1)) {
                            fail("endpoint position of object " + std::to_string(id) + " wrong");
                        }
                        const Scalar value = end == 0 ? object.box.lo[axis] : object.box.hi[axis];
                        if (axes_[axis][at].value != value) {
                            fail("endpoint value of object " + std::to_string(id) + " stale");
                        }
                    }
                }
            } else if (object.state == State::Pending) {
                ++pending;
                if (object.pendingAt >= pending_.size() || pending_[object.pendingAt] != id) {
                    fail("pending list broken at object " + std::to_string(id));
                }
            }
        }
        for (int axis = 0; axis < D; ++axis) {
            const std::vector<Endpoint>& edges = axes_[axis];
            for (std::size_t at = 1; at < edges.size(); ++at) {
                if (before(edges[at], edges[at - 1])) {
                    fail("axis " + std::to_string(axis) + " not sorted at " + std::to_string(at));
                }
            }
            std::size_t deadEdges = 0;
            for (const Endpoint& edge : edges) {
                deadEdges += objects_[edge.id()].state == State::Sorted ? 0 : 1;
            }
            dead = deadEdges / 2;
            if (edges.size() != 2 * (sorted + dead)) {
                fail("axis " + std::to_string(axis) + " holds the wrong number of endpoints");
            }
        }
        if (pending != pending_.size() || dead != dead_ || sorted + pending != size_) {
            fail("object counts disagree");
        }
    }

    std::size_t memoryBytes() const {
        std::size_t bytes = objects_.capacity() * sizeof(Object) +
                            changes_.capacity() * sizeof(Change) +
                            (pending_.capacity() + active_.capacity() + newActive_.capacity() +
                             activeAt_.capacity()) *
                                sizeof(std::uint32_t) +
                            scratch_.capacity() * sizeof(Endpoint);
        for (const std::vector<Endpoint>& edges : axes_) {
            bytes += edges.capacity() * sizeof(Endpoint);
        }
        return bytes;
    }

  private:
    enum class State : std::uint8_t { Absent, Pending, Sorted, Dead };
    struct Endpoint {
        Scalar value;
        std::uint32_t code;  ///< id * 2 + (1 for a max)
        ObjectId id() const { return code >> 1; }
        bool isMax() const { return (code & 1) != 0; }
    };
    struct Object {
        Box box{};
        std::array<std::array<std::uint32_t, 2>, D> at{};  ///< positions of min and max
        std::uint32_t pendingAt = 0;
        State state = State::Absent;
    };
    struct Change {
        ObjectId a, b;
    };

    /// The endpoints' order: by value, a min before a max of equal value.
    static bool before(const Endpoint& a, const Endpoint& b) {
        return a.value < b.value || (a.value == b.value && !a.isMax() && b.isMax());
    }

    /// Whether objects a and b overlap on every axis but `skip`, by the positions of their
    /// endpoints (the arrays' present order, which later swaps start from).
    bool overlapsOnOtherAxes(ObjectId a, ObjectId b, int skip) const {
        const Object& first = objects_[a];
        const Object& second = objects_[b];
        for (int axis = 0; axis < D; ++axis) {
            if (axis != skip && (first.at[axis][1] < second.at[axis][0] ||
                                 second.at[axis][1] < first.at[axis][0])) {
                return false;
            }
        }
        return true;
    }

    /// Swaps the endpoint at `at` with its neighbour at `at + 1` and records a change when a
    /// min and a max of two sorted objects pass each other.
    void swapUp(int axis, std::uint32_t at) {
        std::vector<Endpoint>& edges = axes_[axis];
        const Endpoint lower = edges[at], upper = edges[at + 1];
        ++swaps_;
        if (lower.isMax() != upper.isMax() && lower.id() != upper.id() &&
            objects_[lower.id()].state == State::Sorted &&
            objects_[upper.id()].state == State::Sorted &&
            overlapsOnOtherAxes(lower.id(), upper.id(), axis)) {
            changes_.push_back(Change{lower.id(), upper.id()});
            ++changesRecorded_;
        }
        edges[at] = upper;
        edges[at + 1] = lower;
        objects_[upper.id()].at[axis][upper.isMax() ? 1 : 0] = at;
        objects_[lower.id()].at[axis][lower.isMax() ? 1 : 0] = at + 1;
    }
    void sortDown(int axis, std::uint32_t at) {
        const std::vector<Endpoint>& edges = axes_[axis];
        while (at > 0 && before(edges[at], edges[at - 1])) {
            swapUp(axis, at - 1);
            --at;
        }
    }
    void sortUp(int axis, std::uint32_t at) {
        const std::vector<Endpoint>& edges = axes_[axis];
        while (at + 1 < edges.size() && before(edges[at + 1], edges[at])) {
            swapUp(axis, at);
            ++at;
        }
    }

    void compact() {
        for (int axis = 0; axis < D; ++axis) {
            std::vector<Endpoint>& edges = axes_[axis];
            std::size_t kept = 0;
            for (const Endpoint& edge : edges) {
                if (objects_[edge.id()].state == State::Sorted) {
                    edges[kept++] = edge;
                }
            }
            edges.resize(kept);
            reindex(axis);
        }
        for (Object& object : objects_) {
            if (object.state == State::Dead) {
                object.state = State::Absent;
            }
        }
        dead_ = 0;
    }

    void reindex(int axis) {
        const std::vector<Endpoint>& edges = axes_[axis];
        for (std::uint32_t at = 0; at < edges.size(); ++at) {
            objects_[edges[at].id()].at[axis][edges[at].isMax() ? 1 : 0] = at;
        }
    }

    /// Merges the pending objects' endpoints into the arrays, then records every pair of a
    /// merged object whose boxes overlap: one sweep along the axis where the boxes overlap
    /// least, comparing a merged object with everything open and another with the merged
    /// objects open.
    void merge() {
        for (ObjectId id : pending_) {
            objects_[id].state = State::Sorted;
        }
        for (int axis = 0; axis < D; ++axis) {
            scratch_.clear();
            for (ObjectId id : pending_) {
                scratch_.push_back(Endpoint{objects_[id].box.lo[axis], id * 2});
                scratch_.push_back(Endpoint{objects_[id].box.hi[axis], id * 2 + 1});
            }
            std::sort(scratch_.begin(), scratch_.end(), before);
            std::vector<Endpoint>& edges = axes_[axis];
            const std::size_t old = edges.size();
            edges.insert(edges.end(), scratch_.begin(), scratch_.end());
            std::inplace_merge(edges.begin(), edges.begin() + long(old), edges.end(), before);
            reindex(axis);
        }
        const int axis = sweepAxis();
        active_.clear();
        newActive_.clear();
        if (activeAt_.size() < objects_.size()) {
            activeAt_.resize(objects_.size());
        }
        auto isNew = [&](ObjectId id) { return objects_[id].pendingAt != kSettled; };
        for (const Endpoint& edge : axes_[axis]) {
            const ObjectId id = edge.id();
            if (objects_[id].state != State::Sorted) {
                continue;
            }
            std::vector<ObjectId>& list = isNew(id) ? newActive_ : active_;
            if (edge.isMax()) {
                const std::uint32_t at = activeAt_[id];
                list[at] = list.back();
                activeAt_[list[at]] = at;
                list.pop_back();
                continue;
            }
            if (isNew(id)) {
                for (ObjectId other : active_) {
                    if (overlapsOnOtherAxes(id, other, axis)) {
                        changes_.push_back(Change{other, id});
                    }
                }
            }
            for (ObjectId other : newActive_) {
                if (overlapsOnOtherAxes(id, other, axis)) {
                    changes_.push_back(Change{other, id});
                }
            }
            activeAt_[id] = static_cast<std::uint32_t>(list.size());
            list.push_back(id);
        }
        for (ObjectId id : pending_) {
            objects_[id].pendingAt = kSettled;
        }
        pending_.clear();
    }

    /// The axis along which the boxes' intervals overlap least (extent over spread).
    int sweepAxis() const {
        int best = 0;
        double bestCrowding = HUGE_VAL;
        for (int axis = 0; axis < D; ++axis) {
            const std::vector<Endpoint>& edges = axes_[axis];
            if (edges.empty()) {
                return 0;
            }
            const double spread = double(edges.back().value) - double(edges.front().value);
            double extents = 0;
            for (const Endpoint& edge : edges) {
                extents += edge.isMax() ? double(edge.value) : -double(edge.value);
            }
            const double crowding = spread > 0 ? extents / spread : HUGE_VAL;
            if (crowding < bestCrowding) {
                bestCrowding = crowding;
                best = axis;
            }
        }
        return best;
    }

    static constexpr std::uint32_t kSettled = 0xffffffffu;

    std::array<std::vector<Endpoint>, D> axes_;
    std::vector<Object> objects_;
    std::vector<ObjectId> pending_;
    std::vector<Change> changes_;
    std::vector<Endpoint> scratch_;
    std::vector<ObjectId> active_, newActive_;
    std::vector<std::uint32_t> activeAt_;
    std::size_t size_ = 0;
    std::size_t dead_ = 0;
    std::size_t swaps_ = 0;
    std::size_t changesRecorded_ = 0;
};

}  // namespace kolize

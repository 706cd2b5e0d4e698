#pragma once
/// \file
/// SweepAndPrune<D, Scalar>: exact incremental sweep and prune (broadphase "sweep").
///
/// Per axis, one array of the objects' box endpoints sorted by value (a min before a max
/// of equal value: closed intervals, touching boxes overlap), except that ends of one kind
/// between two of the other may be left out of order among themselves (see applyMoves:
/// every min is still ordered against every max). A moved box's endpoints are
/// carried to their new places by adjacent swaps, as Bullet's btAxisSweep3 does; a min
/// passing another object's max (or the reverse) is where the two intervals start or stop
/// overlapping on that axis, and when their other axes overlap, the pair is recorded as
/// changed. Moves are applied at the next pair search (maintain()): one object at a time
/// when under one in eight moved, else one insertion pass per axis (a jittering stack's
/// tied endpoints swap in a contiguous array; after such a frame update() writes the new
/// values at once), and none on an axis where no min passed a max. Work per frame: O(moved objects
/// + swaps), plus O(N) per changed axis for a pass or its check; objects at rest cost nothing, and
/// an axis on which no moved box changed its interval is not touched.
///
/// Unlike btAxisSweep3: the endpoints are the exact box coordinates (no quantisation, so no
/// world bounds and no extra pairs), ids are 32-bit (no 16-bit handle limit), and objects
/// created or removed between two frames are merged in (or compacted out) once per frame,
/// in O(N + their overlaps), instead of one O(N) insertion each.
///
/// The core tracks overlaps itself (tracksOverlaps()): the adapter takes the changed pairs
/// from drainChanges and tests only those. A pair appears there whenever the boxes' overlap
/// may have changed (a superset: each swap of a min and a max of two objects whose other
/// axes overlap, and every pair of an object merged in). queryBox scans the first axis up
/// to the first max past the box's end, queryRay visits every object: use another core
/// where queries matter.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/sweep_axis.h>

#include <algorithm>
#include <array>
#include <cmath>
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
    bool tracksOverlaps() const { return true; }
    /// Ids are stored in 31 bits with the float layout.
    static constexpr ObjectId kMaxId = 0x7fffffffu;

    explicit SweepAndPrune(const Settings& = {}) {}

    /// Adds object `id` (ids are dense; `id` must not be live); merged in at the next
    /// maintain(). Throws std::length_error past kMaxId.
    void insert(ObjectId id, const Box& box) {
        if (id > kMaxId) {
            throw std::length_error("kolize sweep: more than 2^31 objects");
        }
        if (id >= state_.size()) {
            const std::size_t size = std::size_t(id) + 1;
            state_.resize(size, State::Absent);
            boxes_.resize(size);
            next_.resize(size);
            dirty_.resize(size, 0);
            at_.resize(size);
            pendingAt_.resize(size, kSettled);
        }
        boxes_[id] = box;
        state_[id] = State::Pending;
        pendingAt_[id] = static_cast<std::uint32_t>(pending_.size());
        pending_.push_back(id);
        ++size_;
    }

    /// Moves object `id` to `box`, applied at the next maintain() (or pair search): there
    /// the moved objects' endpoints swap their way to the new values, one object at a time
    /// when few moved, else in one insertion pass per axis (see applyMoves). After a search
    /// in which many moved, the next frame's moves write their endpoints' values at once,
    /// where the endpoints are (the pass restores the order): the object is then touched
    /// once per frame, not once here and once more at the search.
    void update(ObjectId id, const Box& box) {
        if (state_[id] == State::Pending) {
            boxes_[id] = box;
            return;
        }
        if (writeAtUpdate_ && state_[id] == State::Sorted) {
            writeValues(id, box);
            ++writtenMoves_;
            return;
        }
        next_[id] = box;
        if (!dirty_[id]) {
            dirty_[id] = 1;
            moved_.push_back(id);
        }
    }

    /// Removes object `id`; its endpoints are compacted out at the next maintain().
    void remove(ObjectId id) {
        if (state_[id] == State::Pending) {
            const std::uint32_t at = pendingAt_[id];
            pending_[at] = pending_.back();
            pendingAt_[pending_[at]] = at;
            pending_.pop_back();
            pendingAt_[id] = kSettled;
        } else {
            ++dead_;
        }
        state_[id] = State::Dead;
        --size_;
    }

    /// Before every pair search: applies the moves, compacts removed objects' endpoints out
    /// and merges the created ones in, recording every pair of a merged object whose boxes
    /// overlap.
    void maintain() {
        if (!moved_.empty() || writtenMoves_ > 0) {
            applyMoves();
        } else {
            writeAtUpdate_ = false;  // a frame without moves: the next may have a few
        }
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
            if (state_[change.a] == State::Sorted && state_[change.b] == State::Sorted) {
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
            if (state_[id] != State::Sorted) {
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

    /// Objects whose first-axis interval meets the box's (a superset; pending objects and
    /// objects moved since the last maintain() all, once each; every object while moves
    /// written at update() wait for their pass).
    template <class Visit>
    void queryBox(const Box& box, Visit&& visit) const {
        if (writtenMoves_ > 0) {
            // The arrays hold new values at old places: no order to stop the scan by.
            for (ObjectId id = 0; id < state_.size(); ++id) {
                if (state_[id] == State::Sorted || state_[id] == State::Pending) {
                    visit(id);
                }
            }
            return;
        }
        for (ObjectId id : pending_) {
            visit(id);
        }
        for (ObjectId id : moved_) {
            if (state_[id] == State::Sorted) {
                visit(id);
            }
        }
        // Past a max above the box's end, every later min is above it too (the axis orders
        // each min against each max; a run of mins may be unsorted, see kindOrderHolds).
        const std::vector<Endpoint>& edges = axes_[0];
        for (std::size_t at = 0; at < edges.size(); ++at) {
            const Endpoint& edge = edges[at];
            if (edge.isMax()) {
                if (edge.value() > box.hi[0]) {
                    break;
                }
                continue;
            }
            const ObjectId id = edge.id();
            if (!(edge.value() > box.hi[0]) && state_[id] == State::Sorted && !dirty_[id] &&
                !(edges[at_[id][1]].value() < box.lo[0])) {
                visit(id);
            }
        }
    }

    /// Every live object (the adapter's exact test decides).
    template <class Visit>
    void queryRay(const Ray<D, Scalar>& /*ray*/, Visit&& visit) const {
        for (ObjectId id = 0; id < state_.size(); ++id) {
            if (state_[id] == State::Sorted || state_[id] == State::Pending) {
                visit(id);
            }
        }
    }

    std::size_t size() const { return size_; }
    /// Endpoint swaps so far (the work of applying moves), and changed pairs recorded.
    std::size_t swaps() const { return swaps_; }
    std::size_t changesRecorded() const { return changesRecorded_; }
    /// Pair searches whose moves were applied in one insertion pass per axis, and those
    /// applied one object at a time.
    std::size_t batchedSearches() const { return batchedSearches_; }
    /// Axis passes left out because no min passed a max (see applyMoves).
    std::size_t passesLeftOut() const { return passesLeftOut_; }
    /// Moves whose endpoint values update() wrote at once (see update).
    std::size_t movesWrittenAtUpdate() const { return movesWrittenAtUpdate_; }
    std::size_t oneByOneSearches() const { return oneByOneSearches_; }

    /// Checks the arrays' order (unless moves written at update() wait for their pass), the
    /// endpoint positions and values against the boxes, and the counts; throws
    /// std::logic_error.
    void validate() const {
        auto fail = [](const std::string& what) {
            throw std::logic_error("SweepAndPrune: " + what);
        };
        std::size_t sorted = 0, pending = 0, dead = 0;
        for (ObjectId id = 0; id < state_.size(); ++id) {
            if (state_[id] == State::Sorted) {
                ++sorted;
                for (int axis = 0; axis < D; ++axis) {
                    for (int end = 0; end < 2; ++end) {
                        const std::uint32_t at = at_[id][2 * axis + end];
                        if (at >= axes_[axis].size() || axes_[axis][at].id() != id ||
                            axes_[axis][at].isMax() != (end == 1)) {
                            fail("endpoint position of object " + std::to_string(id) + " wrong");
                        }
                        if (end == 1 &&
                            axes_[axis][at].value() < axes_[axis][at_[id][2 * axis]].value()) {
                            fail("inverted interval of object " + std::to_string(id));
                        }
                        const Scalar kept = end == 1 ? boxes_[id].hi[axis] : boxes_[id].lo[axis];
                        if (!(axes_[axis][at].value() == kept)) {
                            fail("endpoint value of object " + std::to_string(id) +
                                 " differs from its box");
                        }
                    }
                }
            } else if (state_[id] == State::Pending) {
                ++pending;
                if (pendingAt_[id] >= pending_.size() || pending_[pendingAt_[id]] != id) {
                    fail("pending list broken at object " + std::to_string(id));
                }
            }
        }
        for (int axis = 0; axis < D; ++axis) {
            const std::vector<Endpoint>& edges = axes_[axis];
            bool inOrder = true;
            if (!sweep_detail::kindOrderHolds(axes_[axis], inOrder) && writtenMoves_ == 0) {
                fail("axis " + std::to_string(axis) +
                     " orders a min and a max against their values");
            }
            if (sorted_[axis] && !inOrder && writtenMoves_ == 0) {
                fail("axis " + std::to_string(axis) + " marked sorted but is not");
            }
            std::size_t deadEdges = 0;
            for (const Endpoint& edge : edges) {
                deadEdges += state_[edge.id()] == State::Sorted ? 0 : 1;
            }
            dead = deadEdges / 2;
            if (edges.size() != 2 * (sorted + dead)) {
                fail("axis " + std::to_string(axis) + " holds the wrong number of endpoints");
            }
        }
        std::size_t flagged = 0;
        for (ObjectId id = 0; id < dirty_.size(); ++id) {
            flagged += dirty_[id];
        }
        for (ObjectId id : moved_) {
            if (!dirty_[id]) {
                fail("moved object " + std::to_string(id) + " not flagged");
            }
        }
        if (flagged != moved_.size()) {
            fail("moved list and flags disagree");
        }
        if (pending != pending_.size() || dead != dead_ || sorted + pending != size_) {
            fail("object counts disagree");
        }
    }

    std::size_t memoryBytes() const {
        std::size_t bytes = state_.capacity() + dirty_.capacity() +
                            (boxes_.capacity() + next_.capacity()) * sizeof(Box) +
                            moved_.capacity() * sizeof(ObjectId) +
                            at_.capacity() * sizeof(Positions) +
                            changes_.capacity() * sizeof(Change) +
                            (pendingAt_.capacity() + pending_.capacity() + active_.capacity() +
                             newActive_.capacity() + activeAt_.capacity()) *
                                sizeof(std::uint32_t) +
                            scratch_.capacity() * sizeof(Endpoint);
        for (const std::vector<Endpoint>& edges : axes_) {
            bytes += edges.capacity() * sizeof(Endpoint);
        }
        return bytes;
    }

  private:
    using Endpoint = sweep_detail::Endpoint<Scalar>;
    static std::array<bool, D> filled(bool value) {
        std::array<bool, D> out;
        out.fill(value);
        return out;
    }
    using Positions = sweep_detail::Positions<D>;
    enum class State : std::uint8_t { Absent, Pending, Sorted, Dead };
    struct Change {
        ObjectId a, b;
    };
    static constexpr std::uint32_t kSettled = 0xffffffffu;
    /// Moves are applied in one pass per axis when at least one sorted object in this many
    /// moved.
    static constexpr std::size_t kBatchFrom = 8;

    /// Whether objects a and b overlap on every axis but `skip`, by the positions of their
    /// endpoints (the arrays' present order, which later swaps start from).
    bool overlapsOnOtherAxes(ObjectId a, ObjectId b, int skip) const {
        return sweep_detail::overlapsOnOtherAxes<D>(at_[a], at_[b], skip);
    }

    /// Records a pair whose overlap may have changed (see drainChanges).
    void record(ObjectId a, ObjectId b) {
        changes_.push_back(Change{a, b});
        ++changesRecorded_;
    }
    /// record() as the `record` of sweep_detail's passes.
    auto recorder() {
        return [this](ObjectId a, ObjectId b) { record(a, b); };
    }

    /// Applies the moves since the last maintain(). Few moved objects (under one in
    /// kBatchFrom of the sorted ones) go one at a time (moveOne: their endpoints swap to
    /// their places, the arrays sorted after each). Many go in one pass per axis: every
    /// moved endpoint takes its new value where it is, then an insertion sort over the axis
    /// swaps exactly the endpoints whose order changed, and the positions are written once
    /// at the end (or as each end moves, when the axis' last pass moved few). Same-kind endpoints
    /// of a stack's layer, which jitter reorders by the thousand each frame, then cost a move in a
    /// contiguous array each instead of a position update of another object.
    ///
    /// An axis on which no min passed a max needs no pass at all: only the order among ends
    /// of one kind changed, which no overlap depends on (kindOrderHolds checks it in one
    /// scan). A resting stack's jitter reorders the tied ends of each layer every frame but
    /// moves few of them past an end of the other kind; its vertical axis is then left
    /// as it is, its runs of mins (or maxes) out of order among themselves.
    ///
    /// Why a batch records every pair whose overlap changed: on each axis the insertion sort
    /// swaps every pair of endpoints whose order changed exactly once, and a swap of a min
    /// and a max is recorded when the other axes overlap by the positions at that moment
    /// (new for the axes already sorted, old for the others). A pair that stops overlapping
    /// is recorded at its first change (every other relation still as before: overlapping);
    /// one that starts, at its last (every other relation already as after).
    ///
    /// Whether the next frame's moves write their values at update(): when this one's were
    /// many. A frame of few moves that finds them written takes the passes all the same,
    /// and the one after goes one at a time again.
    void applyMoves() {
        std::size_t live = writtenMoves_;
        for (ObjectId id : moved_) {
            live += state_[id] == State::Sorted ? 1 : 0;
        }
        const std::size_t sorted = size_ - pending_.size();
        const bool many = live * kBatchFrom >= sorted;
        movesWrittenAtUpdate_ += writtenMoves_;
        if (writtenMoves_ == 0 && !many) {
            sortAxes();  // moveOne's swaps stop at the first neighbour in order
            for (ObjectId id : moved_) {
                dirty_[id] = 0;
                if (state_[id] == State::Sorted) {
                    moveOne(id, next_[id]);
                }
            }
            ++oneByOneSearches_;
        } else {
            for (ObjectId id : moved_) {
                dirty_[id] = 0;
                if (state_[id] == State::Sorted) {
                    writeValues(id, next_[id]);
                }
            }
            for (int axis = 0; axis < D; ++axis) {
                if (!valuesChanged_[axis]) {
                    continue;
                }
                valuesChanged_[axis] = false;
                // An axis whose last check failed (a pile: ends of both kinds pass each
                // other every frame) is checked again only after 8 passes.
                bool inOrder = false;
                if (checkAfter_[axis] > 0) {
                    --checkAfter_[axis];
                } else if (sweep_detail::kindOrderHolds(axes_[axis], inOrder)) {
                    // No min passed a max: no overlap changed on this axis, and the pass
                    // (which would only reorder ends of one kind) is left out.
                    sorted_[axis] = inOrder;
                    ++passesLeftOut_;
                    continue;
                } else {
                    checkAfter_[axis] = 8;
                }
                insertionPass<0>(axis);
                sorted_[axis] = true;
            }
            ++batchedSearches_;
        }
        writeAtUpdate_ = many;
        writtenMoves_ = 0;
        moved_.clear();
    }

    /// A batch's move: the object's endpoints take the new values where they are (an axis
    /// whose interval did not change is left alone, and its pass too if no object changed
    /// there).
    void writeValues(ObjectId id, const Box& box) {
        Box& old = boxes_[id];
        const Positions& at = at_[id];
        for (int axis = 0; axis < D; ++axis) {
            if (old.lo[axis] == box.lo[axis] && old.hi[axis] == box.hi[axis]) {
                continue;
            }
            axes_[axis][at[2 * axis]].setValue(box.lo[axis]);
            axes_[axis][at[2 * axis + 1]].setValue(box.hi[axis]);
            valuesChanged_[axis] = true;
        }
        old = box;
    }

    /// One insertion sort over `which` (sweep_detail::insertionPass), the axis made a
    /// constant.
    template <int kFrom>
    void insertionPass(int which) {
        // The axis as a constant: the overlap test then reads the other axes' positions of
        // the moving endpoint from registers.
        if constexpr (kFrom + 1 < D) {
            if (which != kFrom) {
                insertionPass<kFrom + 1>(which);
                return;
            }
        }
        const sweep_detail::PassResult result =
            fewSwaps_[kFrom]
                ? sweep_detail::insertionPass<D, kFrom, true>(axes_[kFrom], at_, recorder())
                : sweep_detail::insertionPass<D, kFrom, false>(axes_[kFrom], at_, recorder());
        swaps_ += result.passed;
        fewSwaps_[kFrom] = result.fewSwaps;
    }

    /// Sorts the axes left with unsorted runs (no pair is recorded: only ends of one kind
    /// swap).
    void sortAxes() {
        for (int axis = 0; axis < D; ++axis) {
            if (!sorted_[axis]) {
                insertionPass<0>(axis);
                sorted_[axis] = true;
            }
        }
    }

    /// Moves one object to `box` in sorted arrays: its endpoints swap their way to the new
    /// values.
    void moveOne(ObjectId id, const Box& box) {
        Box& old = boxes_[id];
        for (int axis = 0; axis < D; ++axis) {
            // An axis whose interval did not change costs nothing: falling and sliding
            // bodies change one or two of the three, and the object's box is one cache line
            // where the endpoints are six.
            if (old.lo[axis] == box.lo[axis] && old.hi[axis] == box.hi[axis]) {
                continue;
            }
            old.lo[axis] = box.lo[axis];
            old.hi[axis] = box.hi[axis];
            std::vector<Endpoint>& edges = axes_[axis];
            const std::uint32_t low = at_[id][2 * axis], high = at_[id][2 * axis + 1];
            edges[low].setValue(box.lo[axis]);
            edges[high].setValue(box.hi[axis]);
            // Whether an endpoint has to move at all is one well-predicted test: jitter
            // rarely passes a neighbour, while its direction would be a coin toss. A max
            // moving up goes first and one moving down last, so that the min is never
            // blocked by its own max (and neither ever passes the other).
            if (high + 1 < edges.size() && before(edges[high + 1], edges[high])) {
                sortUp(axis, high);
            }
            if (low > 0 && before(edges[low], edges[low - 1])) {
                sortDown(axis, low);
            } else if (before(edges[low + 1], edges[low])) {
                sortUp(axis, low);
            }
            const std::uint32_t max = at_[id][2 * axis + 1];
            if (before(edges[max], edges[max - 1])) {
                sortDown(axis, max);
            }
        }
    }

    /// The endpoint at `at` moves down (up) past every endpoint it now precedes (follows):
    /// sweep_detail::sortAway.
    void sortDown(int axis, std::uint32_t at) {
        swaps_ += sweep_detail::sortAway<D, -1>(axes_[axis], at_, axis, at, recorder());
    }
    void sortUp(int axis, std::uint32_t at) {
        swaps_ += sweep_detail::sortAway<D, +1>(axes_[axis], at_, axis, at, recorder());
    }

    void compact() {
        for (int axis = 0; axis < D; ++axis) {
            std::vector<Endpoint>& edges = axes_[axis];
            std::size_t kept = 0;
            for (const Endpoint& edge : edges) {
                if (state_[edge.id()] == State::Sorted) {
                    edges[kept++] = edge;
                }
            }
            edges.resize(kept);
            reindex(axis);
        }
        for (State& state : state_) {
            if (state == State::Dead) {
                state = State::Absent;
            }
        }
        dead_ = 0;
    }

    void reindex(int axis) {
        const std::vector<Endpoint>& edges = axes_[axis];
        for (std::uint32_t at = 0; at < edges.size(); ++at) {
            at_[edges[at].id()][2 * axis + (edges[at].isMax() ? 1 : 0)] = at;
        }
    }

    /// Merges the pending objects' endpoints into the arrays, then records every pair of a
    /// merged object whose boxes overlap: one sweep along the axis where the boxes overlap
    /// least, comparing a merged object with everything open and another with the merged
    /// objects open.
    void merge() {
        sortAxes();  // the merge needs sorted arrays
        for (ObjectId id : pending_) {
            state_[id] = State::Sorted;
        }
        for (int axis = 0; axis < D; ++axis) {
            scratch_.clear();
            for (ObjectId id : pending_) {
                scratch_.push_back(Endpoint::make(boxes_[id].lo[axis], id, false));
                scratch_.push_back(Endpoint::make(boxes_[id].hi[axis], id, true));
            }
            std::sort(scratch_.begin(), scratch_.end(),
                      [](const Endpoint& a, const Endpoint& b) { return before(a, b); });
            std::vector<Endpoint>& edges = axes_[axis];
            const std::size_t old = edges.size();
            edges.insert(edges.end(), scratch_.begin(), scratch_.end());
            std::inplace_merge(edges.begin(), edges.begin() + long(old), edges.end(),
                               [](const Endpoint& a, const Endpoint& b) { return before(a, b); });
            reindex(axis);
        }
        const int axis = sweepAxis();
        active_.clear();
        newActive_.clear();
        if (activeAt_.size() < state_.size()) {
            activeAt_.resize(state_.size());
        }
        auto isNew = [&](ObjectId id) { return pendingAt_[id] != kSettled; };
        for (const Endpoint& edge : axes_[axis]) {
            const ObjectId id = edge.id();
            if (state_[id] != State::Sorted) {
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
            pendingAt_[id] = kSettled;
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
            const double spread = double(edges.back().value()) - double(edges.front().value());
            double extents = 0;
            for (const Endpoint& edge : edges) {
                extents += edge.isMax() ? double(edge.value()) : -double(edge.value());
            }
            const double crowding = spread > 0 ? extents / spread : HUGE_VAL;
            if (crowding < bestCrowding) {
                bestCrowding = crowding;
                best = axis;
            }
        }
        return best;
    }

    std::array<std::vector<Endpoint>, D> axes_;
    std::vector<State> state_;
    std::vector<Box> boxes_;           ///< every object's box (its endpoints' values, once sorted)
    std::vector<Box> next_;            ///< a moved object's box, applied at the next maintain()
    std::vector<std::uint8_t> dirty_;  ///< 1: in moved_
    std::vector<ObjectId> moved_;      ///< objects moved since the last maintain()
    std::vector<Positions> at_;
    std::vector<std::uint32_t> pendingAt_;  ///< index in pending_, or kSettled
    std::vector<ObjectId> pending_;
    std::vector<Change> changes_;
    std::vector<Endpoint> scratch_;
    std::vector<ObjectId> active_, newActive_;
    std::vector<std::uint32_t> activeAt_;
    std::size_t size_ = 0;
    std::size_t dead_ = 0;
    std::size_t swaps_ = 0;
    std::size_t passesLeftOut_ = 0;
    /// Whether update() writes a sorted object's new values at once (after a search in
    /// which many moved), the moves it wrote since the last maintain(), and in all.
    bool writeAtUpdate_ = false;
    std::size_t writtenMoves_ = 0;
    std::size_t movesWrittenAtUpdate_ = 0;
    std::array<bool, D> valuesChanged_{};  ///< per axis: a batch wrote new values there
    /// Per axis: sorted outright (else only each min against each max, see kindOrderHolds).
    std::array<bool, D> sorted_ = filled(true);
    std::array<std::uint8_t, D> checkAfter_{};  ///< per axis: passes until its next check
    std::array<bool, D> fewSwaps_{};            ///< per axis: whether its last pass moved few ends
    std::size_t changesRecorded_ = 0;
    std::size_t batchedSearches_ = 0;
    std::size_t oneByOneSearches_ = 0;
};

}  // namespace kolize

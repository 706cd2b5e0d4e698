#pragma once
/// \file
/// CellCore: the object bookkeeping SegmentTreeSet and RangeTree share. It keeps each live
/// object's box and its cell box, tunes the leaf width U from the scene, grows the derived
/// core's segment trees to cover every object, and clamps what cannot be covered.
///
/// The cell box of an object is floor(box / U) per axis (see CellQuantizer), except on an
/// axis with a segment tree where the raw cells leave the limits +-kCellLimit (a +-1e18
/// plane, an object flown absurdly far): there it is clamped to the tree's window. Clamping
/// is monotone, so any two overlapping boxes keep overlapping cell boxes; windows only grow,
/// and when one grows every clamped object is clamped again. Invariant, checked by
/// validate(): every live object's cell box is exactly clamp(cells(box), windows).
///
/// Tuning: the first insert, every insert that doubles the live count since the last
/// tuning, the first findCandidates, and any later one after the count grew by a quarter
/// recompute U (tuneScene); when it changed, the trees are rebuilt. That is amortised
/// O(log N) per insert and keeps U fitted to a scene that is built up over time.
///
/// Updates: an object whose box stays inside the coordinates that map to its cells (kept
/// per object) costs a few comparisons; only a changed cell box reaches the derived core.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/live_ids.h>
#include <kolize/broadphase/segment_tree.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace kolize {

/// An object's cell range on every axis.
template <int D>
struct CellBox {
    std::array<Cell, D> lo{};
    std::array<Cell, D> hi{};
    bool operator==(const CellBox& other) const { return lo == other.lo && hi == other.hi; }
    bool operator!=(const CellBox& other) const { return !(*this == other); }
};

/// An entry of a segment-tree node: the object, its first cell on the tree's axis (which
/// tells whether this node is the object's first), and its cell ranges on the other axes in
/// increasing axis order, so candidate tests need no lookup outside the node. The ranges are
/// kept as (lo..., -hi...): an entry overlaps a box on those axes exactly when every value
/// is <= the box's reach (hi..., -lo...), one comparison of 2(D-1) lanes.
template <int D>
struct CellEntry {
    ObjectId id = 0;
    Cell lo = 0;
    std::array<Cell, 2 * (D - 1)> other{};

    Cell otherLo(int k) const { return other[k]; }
    Cell otherHi(int k) const { return -other[D - 1 + k]; }
};

/// (hi..., -lo...) of a range on the other axes; see CellEntry.
template <int D>
using Reach = std::array<Cell, 2 * (D - 1)>;

/// The k-th axis other than `axis`.
constexpr int otherAxis(int axis, int k) {
    return k < axis ? k : k + 1;
}

/// The entry of `cells` for a tree on `axis`.
template <int D>
CellEntry<D> cellEntry(ObjectId id, const CellBox<D>& cells, int axis) {
    CellEntry<D> entry;
    entry.id = id;
    entry.lo = cells.lo[axis];
    for (int k = 0; k < D - 1; ++k) {
        entry.other[k] = cells.lo[otherAxis(axis, k)];
        entry.other[D - 1 + k] = -cells.hi[otherAxis(axis, k)];
    }
    return entry;
}

/// The reach of an entry's other-axis ranges.
template <int D>
Reach<D> reachOf(const CellEntry<D>& e) {
    Reach<D> reach;
    for (int k = 0; k < D - 1; ++k) {
        reach[k] = e.otherHi(k);
        reach[D - 1 + k] = -e.otherLo(k);
    }
    return reach;
}

/// Four cells, one per lane (GCC / Clang vector extension: SSE2 on x86-64, NEON on ARM,
/// plain code elsewhere).
using CellLanes = std::int32_t __attribute__((vector_size(16)));

inline CellLanes loadLanes(const Cell* cells) {
    CellLanes out;
    std::memcpy(&out, cells, sizeof out);
    return out;
}

/// Whether entry e overlaps, on the axes other than its tree's, the ranges with `reach`.
template <int D>
inline bool othersOverlap(const CellEntry<D>& e, const Reach<D>& reach) {
    if constexpr (D == 3) {
        const CellLanes outside = loadLanes(e.other.data()) > loadLanes(reach.data());
        return (outside[0] | outside[1] | outside[2] | outside[3]) == 0;
    } else {
        bool inside = true;
        for (int i = 0; i < 2 * (D - 1); ++i) {
            inside &= e.other[i] <= reach[i];
        }
        return inside;
    }
}

/// Whether two cell boxes overlap on every axis.
template <int D>
inline bool cellsOverlap(const CellBox<D>& a, const CellBox<D>& b) {
    for (int axis = 0; axis < D; ++axis) {
        if (a.lo[axis] > b.hi[axis] || b.lo[axis] > a.hi[axis]) {
            return false;
        }
    }
    return true;
}

/// Candidates kept between frames (when `incremental` is on). The candidate set is the
/// pairs whose cell boxes overlap, and cell boxes change rarely when objects move little:
/// so the set of the last frame is kept as a plain list, pairs whose cell boxes no longer
/// overlap are dropped while it is read, and each object whose cell box changed adds the
/// new pairs its box grew into (queries of the grown slabs only). A pair that overlaps now
/// and did not before meets the grown part of at least one of its objects; the rules in
/// acceptNewPair make exactly one of them add it, so the list never holds a pair twice and
/// needs no hashing. When many objects changed cells, the derived core enumerates all pairs
/// instead, and keeps them when the motion is slow enough for the next frame to be
/// incremental.
///
/// Derived must provide (all called by CellCore only):
///   bool hasTree(int axis) const;
///   SegmentTree<...>& treeOf(int axis);  const version too
///   void resetTrees(const CellBox<D>& rootCells);  — empty trees with these root ranges
///   void store(ObjectId id);                        — add entries for cells(id)
///   void unstore(ObjectId id);                      — remove all of id's entries
///   void restore(ObjectId id, const CellBox<D>& old);  — cells(id) changed from `old`
///   void visitCells(const CellBox<D>& query, Visit&& visit) const;
///                                      — each object whose cell box overlaps `query`, once
///   void enumerateAll(Sink&& candidate);  — every cell-overlap pair, once
template <class Derived, int D, class Scalar>
class CellCore {
  public:
    using Box = Aabb<D, Scalar>;

    CellCore(const CellTuning& tuning, bool incremental)
        : tuning_(tuning), incremental_(incremental) {
        if (tuning.unit < 0 || !std::isfinite(tuning.unit) || tuning.divisions < 1) {
            throw std::invalid_argument(
                "kolize: cell tuning needs divisions >= 1 and a finite unit >= 0 (0 = tune)");
        }
    }

    /// Adds object `id` (ids are dense; `id` must not be live). O(log) amortised, plus
    /// the entries of its canonical decompositions.
    void insert(ObjectId id, const Box& box) {
        if (id >= boxes_.size()) {
            boxes_.resize(id + 1);
            cells_.resize(id + 1);
            stay_.resize(id + 1);
            changeIndex_.resize(id + 1, 0);
        }
        boxes_[id] = box;
        live_.insert(id);
        if ((!built_ || live_.size() >= 2 * tunedCount_) && retune()) {
            return;  // rebuilt, `id` included
        }
        place(id);
    }

    /// Moves live object `id` to `box`. Nothing structural happens while its cell box stays.
    void update(ObjectId id, const Box& box) {
        boxes_[id] = box;
        if (staysInItsCells(id, box)) {
            return;
        }
        const CellBox<D> raw = rawCells(box);
        stay_[id] = stayOf(raw);
        if (growFor(raw)) {
            reclampAll(id);
        }
        const CellBox<D> next = clamped(raw);
        if (next != cells_[id]) {
            const CellBox<D> old = cells_[id];
            cells_[id] = next;
            derived().restore(id, old);
            noteChange(id, &old);
        }
    }

    /// Removes live object `id`.
    void remove(ObjectId id) {
        derived().unstore(id);
        noteRemoval(id);
        live_.remove(id);
        tunedCount_ = std::min(tunedCount_, live_.size());
    }

    std::size_t size() const { return live_.size(); }

    /// The leaf width U in use.
    double unit() const { return quantizer_.unit(); }

    /// How the candidates were found so far: frames served from the kept set, and frames
    /// that enumerated every pair.
    std::size_t incrementalFrames() const { return incrementalFrames_; }
    std::size_t fullFrames() const { return fullFrames_; }

    /// The cell box of live object `id`.
    const CellBox<D>& cellsOf(ObjectId id) const { return cells_[id]; }

    /// Calls `visit(id)` once for every live object whose cell box overlaps the cells of
    /// `box` (derived().visitCells: the segment-tree set walks one current tree, the range
    /// tree its tree with the sorted-list windows).
    template <class Visit>
    void queryBox(const Box& box, Visit&& visit) const {
        if (!live_.empty()) {
            derived().visitCells(cellsForQuery(box), visit);
        }
    }

    /// Calls `visit(id)` once for every live object whose cells meet the ray's bounds; the
    /// adapter's exact test does the rest. A ray longer than 16 cells is cut into pieces of
    /// about 16 cells (at most 1024), each queried through its own bounds, so that a long
    /// diagonal ray reports the objects near it rather than every object in its bounding
    /// box. An object is reported from the first piece it meets: the pieces' cell boxes
    /// advance monotonically on every axis, so the pieces an object meets are consecutive,
    /// and the first is the one whose predecessor it does not meet.
    template <class Visit>
    void queryRay(const Ray<D, Scalar>& ray, Visit&& visit) const {
        if (live_.empty()) {
            return;
        }
        const CellBox<D> whole = cellsForQuery(rayBounds(ray, 0, 1));
        std::int64_t longest = 0;
        bool finite = true;
        for (int axis = 0; axis < D; ++axis) {
            longest = std::max(longest, std::int64_t(whole.hi[axis]) - whole.lo[axis]);
            finite =
                finite && std::isfinite(double(ray.lambdaMax) / double(ray.inverseDirection[axis]));
        }
        const int pieces =
            finite ? static_cast<int>(std::min<std::int64_t>(longest / 16 + 1, 1024)) : 1;
        if (pieces == 1) {
            derived().visitCells(whole, visit);
            return;
        }
        CellBox<D> previous;
        for (int piece = 0; piece < pieces; ++piece) {
            const CellBox<D> cells =
                cellsForQuery(rayBounds(ray, double(piece) / pieces, double(piece + 1) / pieces));
            derived().visitCells(cells, [&](ObjectId id) {
                if (piece == 0 || !cellsOverlap(cells_[id], previous)) {
                    visit(id);
                }
            });
            previous = cells;
        }
    }

    /// The box a ray query must cover between fractions `from` and `to` of the segment: the
    /// piece's bounds, with a margin for the rounding in Bullet's slab test (relative to the
    /// whole segment), grown by the swept box as expandedForRay does.
    static Box rayBounds(const Ray<D, Scalar>& ray, double from = 0, double to = 1) {
        Box out;
        for (int axis = 0; axis < D; ++axis) {
            const double origin = double(ray.origin[axis]);
            const double span = double(ray.lambdaMax) / double(ray.inverseDirection[axis]);
            const double margin = 1e-5 * (std::fabs(origin) + std::fabs(span) + 1);
            const double start = origin + span * from, end = origin + span * to;
            const double lo = std::min(start, end) - margin + double(ray.expandLo[axis]);
            const double hi = std::max(start, end) + margin + double(ray.expandHi[axis]);
            out.lo[axis] = static_cast<Scalar>(std::isnan(lo) ? -HUGE_VAL : lo);
            out.hi[axis] = static_cast<Scalar>(std::isnan(hi) ? HUGE_VAL : hi);
        }
        return out;
    }

  protected:
    /// The derived core's findCandidates: every pair whose cell boxes overlap, once, from
    /// the kept set or from derived().enumerateAll (see the class comment).
    template <class Sink>
    void emitCandidates(Sink& candidate) {
        retuneBeforeFrame();
        const std::size_t n = live_.size();
        if (keptValid_ && !changesOverflowed_ && changes_.size() * kIncrementalShare <= n) {
            ++incrementalFrames_;
            std::size_t kept = 0;
            for (const KeptPair& pair : kept_) {
                // A pair of objects that neither changed cells nor went away still overlaps;
                // an inserted object (perhaps under a removed one's id) has no old pairs.
                const std::uint32_t a = changeIndex_[pair.first], b = changeIndex_[pair.second];
                if ((a != 0 || b != 0) &&
                    (isGone(pair.first, a) || isGone(pair.second, b) ||
                     !cellsOverlap(cells_[pair.first], cells_[pair.second]))) {
                    continue;
                }
                candidate(pair.first, pair.second);
                kept_[kept++] = pair;
            }
            kept_.resize(kept);
            for (const Change& change : changes_) {
                if (isLive(change.id)) {
                    addGrownPairs(change, candidate);
                }
            }
        } else {
            ++fullFrames_;
            const bool keep = incremental_ && !changesOverflowed_;
            kept_.clear();
            derived().enumerateAll([&](ObjectId a, ObjectId b) {
                candidate(a, b);
                if (keep) {
                    kept_.push_back(KeptPair{a, b});
                }
            });
            keptValid_ = keep;
        }
        for (const Change& change : changes_) {
            changeIndex_[change.id] = 0;
        }
        for (ObjectId id : removed_) {
            changeIndex_[id] = 0;
        }
        changes_.clear();
        removed_.clear();
        changesOverflowed_ = false;
    }

    /// Called by the derived core before finding pairs: retunes at the first frame (a
    /// scene loaded object by object gets the U of the whole scene, not of the first half
    /// it saw) and whenever the live count has grown by a quarter since the last tuning.
    /// Amortised O(1) per insert.
    void retuneBeforeFrame() {
        const bool first = !sawFrame_ && live_.size() != tunedCount_;
        sawFrame_ = true;
        if (live_.size() >= 2 && (first || live_.size() * 4 >= tunedCount_ * 5)) {
            retune();
        }
    }

    Derived& derived() { return static_cast<Derived&>(*this); }
    const Derived& derived() const { return static_cast<const Derived&>(*this); }

    /// The cells of `box` clamped to the trees' windows: a query box that any stored object
    /// overlapping `box` overlaps too.
    /// A NaN bound counts as unbounded on its side, as the exact test lets it overlap all;
    /// an inverted box [lo > hi] as [hi, lo], which every box the exact test accepts covers.
    CellBox<D> cellsForQuery(Box box) const {
        for (int axis = 0; axis < D; ++axis) {
            if (box.lo[axis] > box.hi[axis]) {
                std::swap(box.lo[axis], box.hi[axis]);
            }
            box.lo[axis] = std::isnan(box.lo[axis]) ? Scalar(-HUGE_VAL) : box.lo[axis];
            box.hi[axis] = std::isnan(box.hi[axis]) ? Scalar(HUGE_VAL) : box.hi[axis];
        }
        return clamped(rawCells(box));
    }

    /// Checks the live list, and that every live object's cell box is what its box maps to.
    void validateObjects(const std::string& what) const {
        live_.validate(what);
        for (ObjectId id : live_) {
            if (cells_[id] != clamped(rawCells(boxes_[id]))) {
                throw std::logic_error(what + ": cell box of object " + std::to_string(id) +
                                       " is not its box's cells in the current windows");
            }
            for (int axis = 0; axis < D; ++axis) {
                if (cells_[id].lo[axis] > cells_[id].hi[axis]) {
                    throw std::logic_error(what + ": inverted cell box of object " +
                                           std::to_string(id));
                }
            }
        }
    }

    /// For SegmentTree::validate: the stored cell range on `axis` of a live object.
    auto storedRangeOn(int axis) const {
        return [this, axis](ObjectId id, std::int64_t& lo, std::int64_t& hi) {
            if (!isLive(id)) {
                return false;
            }
            lo = cells_[id].lo[axis];
            hi = cells_[id].hi[axis];
            return true;
        };
    }

    bool isLive(ObjectId id) const { return live_.contains(id); }

    std::size_t objectMemoryBytes() const {
        return boxes_.capacity() * sizeof(Box) + cells_.capacity() * sizeof(CellBox<D>) +
               stay_.capacity() * sizeof(Stay) + live_.memoryBytes() +
               changeIndex_.capacity() * sizeof(std::uint32_t) +
               scratch_.capacity() * sizeof(double) + kept_.capacity() * sizeof(KeptPair) +
               changes_.capacity() * sizeof(Change) + removed_.capacity() * sizeof(ObjectId);
    }

    const std::vector<ObjectId>& live() const { return live_.ids(); }
    const CellBox<D>& cells(ObjectId id) const { return cells_[id]; }

  private:
    /// The kept set is updated when at most 1 / kIncrementalShare of the objects changed
    /// cells; changes beyond 1 / kKeepShare are not recorded and the next frame enumerates
    /// everything without keeping it (fast motion: keeping would not pay).
    static constexpr std::size_t kIncrementalShare = 4;
    static constexpr std::size_t kKeepShare = 2;
    /// changeIndex_ of an object removed (and not re-inserted) since the last frame.
    static constexpr std::uint32_t kRemovedMark = 0xffffffffu;

    /// An object whose cell box changed since the last frame: its box then (`old`), or
    /// `inserted` when it was not there.
    struct Change {
        ObjectId id = 0;
        bool inserted = false;
        CellBox<D> old;
    };

    void noteChange(ObjectId id, const CellBox<D>* old) {
        if (!incremental_ || changesOverflowed_) {
            return;
        }
        if (changeIndex_[id] != 0 && changeIndex_[id] != kRemovedMark) {
            changes_[changeIndex_[id] - 1].inserted |= old == nullptr;
            return;
        }
        if (changes_.size() * kKeepShare > live_.size()) {
            changesOverflowed_ = true;
            return;
        }
        changes_.push_back(Change{id, old == nullptr, old != nullptr ? *old : CellBox<D>{}});
        changeIndex_[id] = static_cast<std::uint32_t>(changes_.size());
    }

    /// Marks a removed object, so that the kept set checks its pairs.
    void noteRemoval(ObjectId id) {
        if (!incremental_ || changesOverflowed_ || changeIndex_[id] != 0) {
            return;
        }
        changeIndex_[id] = kRemovedMark;
        removed_.push_back(id);
    }

    /// Whether a kept pair's object was removed or (re-)inserted since the last frame.
    bool isGone(ObjectId id, std::uint32_t changeIndex) const {
        return changeIndex == kRemovedMark ||
               (changeIndex != 0 && (!isLive(id) || changes_[changeIndex - 1].inserted));
    }

    /// The cell box `id` had at the last frame; false when it had none (inserted since).
    bool oldCellsOf(ObjectId id, const CellBox<D>*& old) const {
        const std::uint32_t index = changeIndex_[id];
        if (index == 0) {
            old = &cells_[id];
            return true;
        }
        const Change& change = changes_[index - 1];
        old = &change.old;
        return !change.inserted;
    }

    /// Adds (and reports) the new pairs of `change.id` that its own queries are responsible
    /// for: the objects whose cells meet its grown part (all of it when inserted).
    template <class Sink>
    void addGrownPairs(const Change& change, Sink& candidate) {
        const ObjectId id = change.id;
        const CellBox<D>& now = cells_[id];
        std::array<CellBox<D>, 2 * D> slabs;
        int count = 0;
        if (change.inserted) {
            slabs[count++] = now;
        } else {
            for (int axis = 0; axis < D; ++axis) {
                if (now.lo[axis] < change.old.lo[axis]) {
                    slabs[count] = now;
                    slabs[count++].hi[axis] = std::min(now.hi[axis], Cell(change.old.lo[axis] - 1));
                }
                if (now.hi[axis] > change.old.hi[axis]) {
                    slabs[count] = now;
                    slabs[count++].lo[axis] = std::max(now.lo[axis], Cell(change.old.hi[axis] + 1));
                }
            }
        }
        for (int s = 0; s < count; ++s) {
            derived().visitCells(slabs[s], [&](ObjectId other) {
                if (acceptNewPair(change, other, slabs, s)) {
                    kept_.push_back(KeptPair{id, other});
                    candidate(id, other);
                }
            });
        }
    }

    /// Whether `change.id`, having found `other` in its grown slab `s`, adds the pair: it is
    /// new (their cells did not overlap at the last frame), `other` is not met by an earlier
    /// slab, and, when `other` changed too and could find the pair itself, the rule picks
    /// exactly one of them: the smaller id, unless the larger one's grown part misses the
    /// pair's common cells (then only the larger one's queries find it).
    bool acceptNewPair(const Change& change, ObjectId other,
                       const std::array<CellBox<D>, 2 * D>& slabs, int s) const {
        const ObjectId id = change.id;
        if (other == id) {
            return false;
        }
        for (int earlier = 0; earlier < s; ++earlier) {
            if (cellsOverlap(cells_[other], slabs[earlier])) {
                return false;
            }
        }
        const CellBox<D>* otherOld = nullptr;
        const bool otherExisted = oldCellsOf(other, otherOld);
        if (!change.inserted && otherExisted && cellsOverlap(change.old, *otherOld)) {
            return false;  // kept already
        }
        if (changeIndex_[other] == 0 || id < other) {
            return true;
        }
        // `other` changed and has the smaller id: it adds the pair if its grown part meets
        // the common cells, i.e. unless they lie inside its old box.
        if (!otherExisted) {
            return false;
        }
        const CellBox<D>& mine = cells_[id];
        const CellBox<D>& theirs = cells_[other];
        for (int axis = 0; axis < D; ++axis) {
            const Cell lo = std::max(mine.lo[axis], theirs.lo[axis]);
            const Cell hi = std::min(mine.hi[axis], theirs.hi[axis]);
            if (lo < otherOld->lo[axis] || hi > otherOld->hi[axis]) {
                return false;
            }
        }
        return true;
    }

    CellBox<D> rawCells(const Box& box) const {
        CellBox<D> out;
        for (int axis = 0; axis < D; ++axis) {
            out.lo[axis] = static_cast<Cell>(quantizer_.cellOf(double(box.lo[axis])));
            out.hi[axis] = static_cast<Cell>(quantizer_.cellOf(double(box.hi[axis])));
        }
        return out;
    }

    /// The coordinates for which the raw cells certainly stay what they are: per axis and
    /// bound, box.lo[axis] in [loLower, loUpper] and box.hi[axis] in [hiLower, hiUpper].
    /// A few comparisons instead of a quantisation, for the many objects that move
    /// within their cells.
    struct Stay {
        std::array<Scalar, D> loLower, loUpper, hiLower, hiUpper;
    };

    bool staysInItsCells(ObjectId id, const Box& box) const {
        const Stay& stay = stay_[id];
        bool inside = true;
        for (int axis = 0; axis < D; ++axis) {
            inside &= box.lo[axis] >= stay.loLower[axis] && box.lo[axis] <= stay.loUpper[axis] &&
                      box.hi[axis] >= stay.hiLower[axis] && box.hi[axis] <= stay.hiUpper[axis];
        }
        return inside;
    }

    Stay stayOf(const CellBox<D>& raw) const {
        Stay out;
        for (int axis = 0; axis < D; ++axis) {
            stayInterval(raw.lo[axis], out.loLower[axis], out.loUpper[axis]);
            stayInterval(raw.hi[axis], out.hiLower[axis], out.hiUpper[axis]);
        }
        return out;
    }

    /// [lower, upper]: values whose cell is certainly `cell`, i.e. [cell U, (cell + 1) U)
    /// shrunk by a relative margin of 1e-6: far above the rounding of x / U and of the
    /// conversion to a float Scalar, far below what makes a difference to how often the
    /// shortcut applies. The saturated cells +-(kCellLimit + 1) are open on their far side.
    void stayInterval(Cell cell, Scalar& lower, Scalar& upper) const {
        constexpr Scalar kInfinity = std::numeric_limits<Scalar>::infinity();
        const double unit = quantizer_.unit();
        const double from = double(cell) * unit, to = from + unit;
        lower = cell <= -kCellLimit - 1
                    ? -kInfinity
                    : static_cast<Scalar>(from + 1e-6 * (std::fabs(from) + unit));
        upper = cell >= kCellLimit + 1 ? kInfinity
                                       : static_cast<Scalar>(to - 1e-6 * (std::fabs(to) + unit));
    }

    static bool withinLimits(Cell lo, Cell hi) { return lo >= -kCellLimit && hi <= kCellLimit; }

    /// Grows each tree to cover the raw range on its axis when that is within the limits.
    bool growFor(const CellBox<D>& raw) {
        bool grew = false;
        for (int axis = 0; axis < D; ++axis) {
            if (derived().hasTree(axis) && withinLimits(raw.lo[axis], raw.hi[axis]) &&
                (raw.lo[axis] < window_.lo[axis] || raw.hi[axis] > window_.hi[axis])) {
                grew = derived().treeOf(axis).growToCover(raw.lo[axis], raw.hi[axis]) || grew;
            }
        }
        if (grew) {
            refreshWindows();
        }
        return grew;
    }

    CellBox<D> clamped(CellBox<D> raw) const {
        for (int axis = 0; axis < D; ++axis) {
            raw.lo[axis] = std::min(std::max(raw.lo[axis], window_.lo[axis]), window_.hi[axis]);
            raw.hi[axis] = std::min(std::max(raw.hi[axis], window_.lo[axis]), window_.hi[axis]);
        }
        return raw;
    }

    /// Copies the trees' windows (an axis without a tree: the saturation limits, where
    /// clamping changes nothing).
    void refreshWindows() {
        for (int axis = 0; axis < D; ++axis) {
            const bool tree = derived().hasTree(axis);
            window_.lo[axis] =
                static_cast<Cell>(tree ? derived().treeOf(axis).windowLo() : -kCellLimit - 1);
            window_.hi[axis] =
                static_cast<Cell>(tree ? derived().treeOf(axis).windowHi() : kCellLimit + 1);
        }
    }

    /// After a window grew: clamps every clamped object again (except `skip`, which the
    /// caller handles). Windows grow O(log) times per doubling of the occupied range.
    void reclampAll(ObjectId skip) {
        for (ObjectId id : live_) {
            if (id == skip) {
                continue;
            }
            const CellBox<D> next = clamped(rawCells(boxes_[id]));
            if (next != cells_[id]) {
                const CellBox<D> old = cells_[id];
                cells_[id] = next;
                derived().restore(id, old);
                noteChange(id, &old);
            }
        }
    }

    /// Stores a newly live object.
    void place(ObjectId id) {
        const CellBox<D> raw = rawCells(boxes_[id]);
        stay_[id] = stayOf(raw);
        if (growFor(raw)) {
            reclampAll(id);
        }
        cells_[id] = clamped(raw);
        derived().store(id);
        noteChange(id, nullptr);
    }

    /// Tunes U for the live objects; when it changed, rebuilds the trees with every live
    /// object and returns true.
    bool retune() {
        const TunedScene scene = tuneScene(boxes_, live_.ids(), tuning_, scratch_);
        tunedCount_ = live_.size();
        if (built_ && scene.unit == quantizer_.unit()) {
            return false;
        }
        quantizer_ = CellQuantizer(scene.unit);
        built_ = true;
        // Root: the tuned scene (-D, +D), then grown to cover every object within limits.
        CellBox<D> root;
        for (int axis = 0; axis < D; ++axis) {
            root.lo[axis] =
                static_cast<Cell>(std::max(quantizer_.cellOf(-scene.halfExtent), -kCellLimit));
            root.hi[axis] =
                static_cast<Cell>(std::min(quantizer_.cellOf(scene.halfExtent), kCellLimit));
        }
        derived().resetTrees(root);
        refreshWindows();
        for (ObjectId id : live_) {
            growFor(rawCells(boxes_[id]));
        }
        for (ObjectId id : live_) {
            const CellBox<D> raw = rawCells(boxes_[id]);
            stay_[id] = stayOf(raw);
            cells_[id] = clamped(raw);
            derived().store(id);
        }
        keptValid_ = false;
        return true;
    }

    CellTuning tuning_;
    CellQuantizer quantizer_;
    bool built_ = false;
    bool sawFrame_ = false;
    std::size_t tunedCount_ = 0;
    std::vector<Box> boxes_;
    std::vector<CellBox<D>> cells_;
    std::vector<Stay> stay_;
    CellBox<D> window_;  ///< the trees' windows, see refreshWindows
    LiveIds live_;
    std::vector<double> scratch_;

    bool incremental_;
    struct KeptPair {
        ObjectId first, second;
    };
    std::vector<KeptPair> kept_;
    std::size_t incrementalFrames_ = 0;
    std::size_t fullFrames_ = 0;
    bool keptValid_ = false;
    std::vector<Change> changes_;
    /// Per id: 1 + its index in changes_, kRemovedMark, or 0 when untouched this frame.
    std::vector<std::uint32_t> changeIndex_;
    std::vector<ObjectId> removed_;
    bool changesOverflowed_ = false;
};

}  // namespace kolize

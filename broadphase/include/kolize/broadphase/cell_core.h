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
/// Tuning: the first insert, and every insert that doubles the live count since the last
/// tuning, recomputes U (tuneScene); when it changed, the trees are rebuilt. That is
/// amortised O(log N) per insert and keeps U fitted to a scene that is built up over time.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/segment_tree.h>

#include <array>
#include <cmath>
#include <cstdint>
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
/// tells whether this node is the object's first), and its cell range on the other axes in
/// increasing axis order, so candidate tests need no lookup outside the node.
template <int D>
struct CellEntry {
    ObjectId id = 0;
    Cell lo = 0;
    std::array<Cell, D - 1> otherLo{};
    std::array<Cell, D - 1> otherHi{};
};

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
        entry.otherLo[k] = cells.lo[otherAxis(axis, k)];
        entry.otherHi[k] = cells.hi[otherAxis(axis, k)];
    }
    return entry;
}

/// Whether entries a and b overlap on the axes other than their tree's, from `from` on.
template <int D>
inline bool othersOverlap(const CellEntry<D>& a, const CellEntry<D>& b, int from = 0) {
    for (int k = from; k < D - 1; ++k) {
        if (a.otherLo[k] > b.otherHi[k] || b.otherLo[k] > a.otherHi[k]) {
            return false;
        }
    }
    return true;
}

/// Derived must provide (all called by CellCore only):
///   bool hasTree(int axis) const;
///   SegmentTree<...>& treeOf(int axis);  const version too
///   void resetTrees(const CellBox<D>& rootCells);  — empty trees with these root ranges
///   void store(ObjectId id);                        — add entries for cells(id)
///   void unstore(ObjectId id);                      — remove all of id's entries
///   void restore(ObjectId id, const CellBox<D>& old);  — cells(id) changed from `old`
template <class Derived, int D, class Scalar>
class CellCore {
  public:
    using Box = Aabb<D, Scalar>;

    explicit CellCore(const CellTuning& tuning) : tuning_(tuning) {
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
            position_.resize(id + 1, kAbsent);
        }
        boxes_[id] = box;
        position_[id] = static_cast<std::uint32_t>(live_.size());
        live_.push_back(id);
        if (!built_ || live_.size() >= 2 * tunedCount_) {
            retune();
            return;
        }
        const CellBox<D> raw = rawCells(box);
        if (growFor(raw)) {
            reclampAll(id);
        }
        cells_[id] = clamped(raw);
        derived().store(id);
    }

    /// Moves live object `id` to `box`. Nothing structural happens while its cell box stays.
    void update(ObjectId id, const Box& box) {
        boxes_[id] = box;
        const CellBox<D> raw = rawCells(box);
        if (growFor(raw)) {
            reclampAll(id);
        }
        const CellBox<D> next = clamped(raw);
        if (next != cells_[id]) {
            const CellBox<D> old = cells_[id];
            cells_[id] = next;
            derived().restore(id, old);
        }
    }

    /// Removes live object `id`.
    void remove(ObjectId id) {
        derived().unstore(id);
        const std::uint32_t at = position_[id];
        const ObjectId last = live_.back();
        live_[at] = last;
        position_[last] = at;
        live_.pop_back();
        position_[id] = kAbsent;
        tunedCount_ = std::min(tunedCount_, live_.size());
    }

    std::size_t size() const { return live_.size(); }

    /// The leaf width U in use.
    double unit() const { return quantizer_.unit(); }

    /// The cell box of live object `id`.
    const CellBox<D>& cellsOf(ObjectId id) const { return cells_[id]; }

    /// Calls `visit(id)` once for every live object whose cells meet the ray's bounds
    /// (rayBounds), through the derived core's queryBox; the adapter's exact test does the
    /// rest.
    template <class Visit>
    void queryRay(const Ray<D, Scalar>& ray, Visit&& visit) const {
        derived().queryBox(rayBounds(ray), visit);
    }

    /// The box a ray query must cover: the segment's bounds (with a relative margin for the
    /// rounding in Bullet's slab test), grown by the swept box as expandedForRay does.
    static Box rayBounds(const Ray<D, Scalar>& ray) {
        Box out;
        for (int axis = 0; axis < D; ++axis) {
            const double origin = double(ray.origin[axis]);
            const double end = origin + double(ray.lambdaMax) / double(ray.inverseDirection[axis]);
            const double margin = 1e-5 * (std::fabs(origin) + std::fabs(end - origin) + 1);
            const double lo = std::min(origin, end) - margin + double(ray.expandLo[axis]);
            const double hi = std::max(origin, end) + margin + double(ray.expandHi[axis]);
            out.lo[axis] = static_cast<Scalar>(std::isnan(lo) ? -HUGE_VAL : lo);
            out.hi[axis] = static_cast<Scalar>(std::isnan(hi) ? HUGE_VAL : hi);
        }
        return out;
    }

  protected:
    Derived& derived() { return static_cast<Derived&>(*this); }
    const Derived& derived() const { return static_cast<const Derived&>(*this); }

    /// The cells of `box` clamped to the trees' windows: a query box that any stored object
    /// overlapping `box` overlaps too.
    /// A NaN bound counts as unbounded on its side, as the exact test lets it overlap all;
    /// an inverted box [lo > hi] as [hi, lo], which every box the exact test accepts covers.
    CellBox<D> queryCells(Box box) const {
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
        std::size_t present = 0;
        for (std::size_t id = 0; id < position_.size(); ++id) {
            if (position_[id] == kAbsent) {
                continue;
            }
            ++present;
            if (position_[id] >= live_.size() || live_[position_[id]] != id) {
                throw std::logic_error(what + ": live list broken at id " + std::to_string(id));
            }
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
        if (present != live_.size()) {
            throw std::logic_error(what + ": live list and index disagree");
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

    bool isLive(ObjectId id) const { return id < position_.size() && position_[id] != kAbsent; }

    std::size_t objectMemoryBytes() const {
        return boxes_.capacity() * sizeof(Box) + cells_.capacity() * sizeof(CellBox<D>) +
               (position_.capacity() + live_.capacity()) * sizeof(std::uint32_t) +
               scratch_.capacity() * sizeof(double);
    }

    const std::vector<ObjectId>& live() const { return live_; }
    const CellBox<D>& cells(ObjectId id) const { return cells_[id]; }

  private:
    static constexpr std::uint32_t kAbsent = 0xffffffffu;

    CellBox<D> rawCells(const Box& box) const {
        CellBox<D> out;
        for (int axis = 0; axis < D; ++axis) {
            out.lo[axis] = static_cast<Cell>(quantizer_.cellOf(double(box.lo[axis])));
            out.hi[axis] = static_cast<Cell>(quantizer_.cellOf(double(box.hi[axis])));
        }
        return out;
    }

    static bool withinLimits(Cell lo, Cell hi) { return lo >= -kCellLimit && hi <= kCellLimit; }

    /// Grows each tree to cover the raw range on its axis when that is within the limits.
    bool growFor(const CellBox<D>& raw) {
        bool grew = false;
        for (int axis = 0; axis < D; ++axis) {
            if (derived().hasTree(axis) && withinLimits(raw.lo[axis], raw.hi[axis])) {
                grew = derived().treeOf(axis).growToCover(raw.lo[axis], raw.hi[axis]) || grew;
            }
        }
        return grew;
    }

    CellBox<D> clamped(CellBox<D> raw) const {
        for (int axis = 0; axis < D; ++axis) {
            if (!derived().hasTree(axis)) {
                continue;
            }
            const auto& tree = derived().treeOf(axis);
            const std::int64_t lo = tree.windowLo(), hi = tree.windowHi();
            raw.lo[axis] = static_cast<Cell>(
                std::min<std::int64_t>(std::max<std::int64_t>(raw.lo[axis], lo), hi));
            raw.hi[axis] = static_cast<Cell>(
                std::min<std::int64_t>(std::max<std::int64_t>(raw.hi[axis], lo), hi));
        }
        return raw;
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
            }
        }
    }

    void retune() {
        const TunedScene scene = tuneScene(boxes_, live_, tuning_, scratch_);
        tunedCount_ = live_.size();
        if (built_ && scene.unit == quantizer_.unit()) {
            // Keep the trees; store the newest object as insert would have.
            const ObjectId id = live_.back();
            const CellBox<D> raw = rawCells(boxes_[id]);
            if (growFor(raw)) {
                reclampAll(id);
            }
            cells_[id] = clamped(raw);
            derived().store(id);
            return;
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
        for (ObjectId id : live_) {
            growFor(rawCells(boxes_[id]));
        }
        for (ObjectId id : live_) {
            cells_[id] = clamped(rawCells(boxes_[id]));
            derived().store(id);
        }
    }

    CellTuning tuning_;
    CellQuantizer quantizer_;
    bool built_ = false;
    std::size_t tunedCount_ = 0;
    std::vector<Box> boxes_;
    std::vector<CellBox<D>> cells_;
    std::vector<std::uint32_t> position_;
    std::vector<ObjectId> live_;
    std::vector<double> scratch_;
};

}  // namespace kolize

#pragma once
/// \file
/// CellGrid<D, Scalar, Index>: the cell-based cores. One template, three cell indexes
/// (cell_index.h), three broadphases:
///
/// | name           | core                  | cells                                   |
/// |----------------|-----------------------|-----------------------------------------|
/// | `grid`         | UniformGrid<D, S>     | dense array over a region (method A)    |
/// | `spatial-tree` | SpatialTree<D, S>     | non-empty cells in an AVL tree (B)      |
/// | `spatial-hash` | SpatialHash<D, S>     | non-empty cells in a hash table         |
///
/// Every object lists the cells its box covers (one entry per cell, in intrusive per-cell
/// lists; entries come from a pool). A pair is a candidate when the two objects share a
/// cell, and it is reported only from one canonical cell, the one at the per-axis maximum
/// of their first cells, so there are no duplicates and no per-query marks. The adapter then
/// applies the exact box test.
///
/// Overflow set: objects whose box covers more than `maxCellsPerObject` cells (a ground
/// box, a +-1e18 plane) and, for the dense grid, objects entirely outside its region are
/// kept in a list instead of cells. They are swept against each other along x and look up
/// the cells their (clamped) box covers, so nothing is ever dropped and a few huge objects
/// cost O(cells) each, not O(N^2). For the dense grid, objects that stick out of the region
/// are clamped into its border cells (clamping is monotone, so shared cells stay shared).
///
/// Cell size: fixed by the settings, or chosen automatically (see CellGridSettings) at the
/// first pair search and re-chosen when the population drifts far from what it was chosen
/// for. Until the first pair search, objects wait unbinned and queries scan them all.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/cell_grid_settings.h>
#include <kolize/broadphase/cell_index.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace kolize {

/// Counters of a cell core (memory, structure, behaviour) for reports.
struct CellGridStats {
    double cellSize = 0;
    std::size_t liveCells = 0;
    std::size_t allocatedCells = 0;  ///< dense grid: all cells of the region
    std::size_t entries = 0;         ///< object-cell memberships
    std::size_t overflow = 0;        ///< objects in the overflow set
    std::size_t rechoices = 0;       ///< times the cell size was chosen
};

template <int D, class Scalar, class Index>
class CellGrid {
  public:
    using Box = Aabb<D, Scalar>;
    using Settings = CellGridSettings;
    using Key = typename Index::Key;
    using Range = typename Index::Range;
    using Coord = typename Index::Coord;

    /// Throws std::invalid_argument for settings that cannot work.
    explicit CellGrid(const Settings& settings = {}) : settings_(settings) {
        auto require = [](bool good, const std::string& what) {
            if (!good) {
                throw std::invalid_argument("kolize CellGridSettings: " + what);
            }
        };
        require(settings.cellSize >= 0 && std::isfinite(settings.cellSize),
                "cellSize must be finite and >= 0 (0: automatic), got " +
                    std::to_string(settings.cellSize));
        require(settings.sizeFactor > 0,
                "sizeFactor must be > 0, got " + std::to_string(settings.sizeFactor));
        require(settings.maxCellsPerObject >= 1, "maxCellsPerObject must be >= 1, got " +
                                                     std::to_string(settings.maxCellsPerObject));
        require(settings.rechooseFactor >= 0, "rechooseFactor must be >= 0 (0: never), got " +
                                                  std::to_string(settings.rechooseFactor));
        require(settings.cellsPerObject > 0,
                "cellsPerObject must be > 0, got " + std::to_string(settings.cellsPerObject));
        require(settings.maxCells >= 1 && settings.maxCells <= 2147483648.0,
                "maxCells must be in [1, 2^31], got " + std::to_string(settings.maxCells));
        require(settings.cellsPerAxis >= 0, "cellsPerAxis must be >= 0 (0: automatic), got " +
                                                std::to_string(settings.cellsPerAxis));
    }

    void insert(ObjectId id, const Box& box) {
        if (id >= objects_.size()) {
            objects_.resize(id + 1);
        }
        Object& object = objects_[id];
        object = Object{};
        object.box = box;
        object.state = State::Waiting;
        ++size_;
        if (chosen_) {
            place(id);
        } else {
            waiting_.push_back(id);
        }
    }

    /// Re-bins the object only when the cells its box covers change.
    void update(ObjectId id, const Box& box) {
        Object& object = objects_[id];
        object.box = box;
        contentDirty_ = true;  // the ray clip bounds may shrink
        if (object.state == State::Waiting) {
            return;
        }
        const Range range = rangeOf(box);
        // Same cells: nothing to do (unless a clamped box has left the dense region).
        if (object.state == State::InCells && range == object.range && !isOutside(box)) {
            growContent(box);  // rays are clipped to the binned boxes' bounds
            return;
        }
        if (object.state == State::InCells && !belongsInOverflow(box, range)) {
            rebin(id, range);
            return;
        }
        unplace(id);
        place(id, range);
    }

    void remove(ObjectId id) {
        Object& object = objects_[id];
        contentDirty_ = true;
        if (object.state == State::Waiting) {
            eraseFrom(waiting_, id);
        } else {
            unplace(id);
        }
        object.state = State::Absent;
        --size_;
    }

    /// Before every pair search: chooses the cell size at the first one, and re-chooses it
    /// (re-binning every object) when the population has drifted. O(1) in most frames.
    void maintain() {
        if (needsChoice()) {
            choose();
        }
        ++framesSinceChoice_;
    }

    /// Each candidate pair once: pairs sharing a canonical cell, overflow objects swept
    /// against each other and looked up in the cells they cover.
    template <class Sink>
    void findCandidates(Sink&& candidate) {
        if (!chosen_) {
            choose();
        }
        index_.forEachLive([&](std::uint32_t cell, const CellRecord& record) {
            if (record.count < 2) {
                return;
            }
            bool keyKnown = false;
            Key key{};
            for (std::uint32_t e = record.head; e != kNone; e = entries_[e].next) {
                const ObjectId a = entries_[e].object;
                const Object& first = objects_[a];
                for (std::uint32_t f = entries_[e].next; f != kNone; f = entries_[f].next) {
                    const ObjectId b = entries_[f].object;
                    const Object& second = objects_[b];
                    if (!(first.single && second.single)) {
                        if (!keyKnown) {
                            key = index_.key(cell);
                            keyKnown = true;
                        }
                        if (!isCanonical(key, first.range, second.range)) {
                            continue;
                        }
                    }
                    candidate(a, b);
                }
            }
        });
        overflowCandidates(candidate);
    }

    /// Objects whose cells meet the box's cells, and every overflow object.
    template <class Visit>
    void queryBox(const Box& box, Visit&& visit) const {
        if (!chosen_) {
            forEachObject(visit);
            return;
        }
        const Range range = rangeOf(box);
        visitCells(range, visit);
        for (ObjectId id : overflow_) {
            visit(id);
        }
    }

    /// Objects in the cells along the ray (and around it, by the ray's swept box), and
    /// every overflow object. The ray is clipped to the bounds of the binned objects and
    /// walked in steps of at most one cell per axis; each step visits the cells of the
    /// step's box that the previous step did not. The walk is widened by a bound on the
    /// rounding of Bullet's slab test in Scalar (which accepts boxes a few roundings of the
    /// coordinates off the exact ray: metres, for a ray starting 1e8 out in float); when
    /// that makes the walk dearer than the live cells, or the ray is not finite, the live
    /// cells within the clipped bounds are visited instead.
    template <class Visit>
    void queryRay(const Ray<D, Scalar>& ray, Visit&& visit) const {
        if (!chosen_) {
            forEachObject(visit);
            return;
        }
        for (ObjectId id : overflow_) {
            visit(id);
        }
        if (index_.liveCount() == 0) {
            return;
        }
        if (contentDirty_) {
            recomputeContent();
        }
        const double lambda = double(ray.lambdaMax);
        const double roundings = 8 * double(std::numeric_limits<Scalar>::epsilon()) + 0x1p-46;
        std::array<double, D> origin{}, direction{}, lo{}, hi{}, pad{};
        bool finite = std::isfinite(lambda) && lambda >= 0;
        for (int axis = 0; axis < D; ++axis) {
            origin[axis] = double(ray.origin[axis]);
            const double inverse = double(ray.inverseDirection[axis]);
            const double expandLo = double(ray.expandLo[axis]);
            const double expandHi = double(ray.expandHi[axis]);
            // Bullet marks an axis the ray does not move along with a huge inverse.
            const bool still = !(std::fabs(inverse) < 1e17);
            direction[axis] = still ? 0.0 : 1.0 / inverse;
            const double magnitude =
                std::fabs(origin[axis]) + std::fabs(direction[axis]) * lambda +
                std::max(std::fabs(contentLo_[axis]), std::fabs(contentHi_[axis])) +
                std::fabs(expandLo) + std::fabs(expandHi);
            pad[axis] =
                roundings * magnitude + 1e-9 * cellSize_ +
                (still && std::isfinite(inverse) && inverse != 0 ? lambda / std::fabs(inverse) : 0);
            lo[axis] = contentLo_[axis] - expandHi - pad[axis];
            hi[axis] = contentHi_[axis] - expandLo + pad[axis];
            finite = finite && std::isfinite(origin[axis]) && std::isfinite(direction[axis]) &&
                     std::isfinite(pad[axis]) && std::isfinite(lo[axis]) &&
                     std::isfinite(hi[axis]) && !(still && std::isnan(inverse));
        }
        if (!finite) {
            visitAllBinned(visit);
            return;
        }
        double t0 = 0, t1 = lambda;
        for (int axis = 0; axis < D; ++axis) {
            if (direction[axis] == 0) {
                if (origin[axis] < lo[axis] || origin[axis] > hi[axis]) {
                    return;
                }
                continue;
            }
            double enter = (lo[axis] - origin[axis]) / direction[axis];
            double exit = (hi[axis] - origin[axis]) / direction[axis];
            if (enter > exit) {
                std::swap(enter, exit);
            }
            t0 = std::max(t0, enter);
            t1 = std::min(t1, exit);
        }
        if (!(t0 <= t1)) {
            return;
        }
        // The box of the clipped segment, widened: what the walk, or the fallback, covers.
        auto segmentBox = [&](double a, double b) {
            Box part;
            for (int axis = 0; axis < D; ++axis) {
                const double pa = origin[axis] + a * direction[axis];
                const double pb = origin[axis] + b * direction[axis];
                part.lo[axis] =
                    roundedDown(std::min(pa, pb) + double(ray.expandLo[axis]) - pad[axis]);
                part.hi[axis] =
                    roundedUp(std::max(pa, pb) + double(ray.expandHi[axis]) + pad[axis]);
            }
            return part;
        };
        double fastest = 0, cellsPerStep = 1;
        for (int axis = 0; axis < D; ++axis) {
            fastest = std::max(fastest, std::fabs(direction[axis]));
        }
        const double stepLength = fastest > 0 ? 0.5 * cellSize_ / fastest : (t1 - t0) + 1;
        for (int axis = 0; axis < D; ++axis) {
            const double width = std::fabs(direction[axis]) * stepLength + 2 * pad[axis] +
                                 double(ray.expandHi[axis]) - double(ray.expandLo[axis]);
            cellsPerStep *= width / cellSize_ + 2;
        }
        const double steps = std::ceil((t1 - t0) / stepLength) + 1;
        if (!(steps * cellsPerStep <= 4.0 * double(index_.liveCount()) + 64)) {
            // A long walk through mostly empty space, or a wide one: the live cells in the
            // segment's bounds cost less.
            visitCells(rangeOf(segmentBox(t0, t1)), visit);
            return;
        }
        std::vector<std::uint32_t>& seen = seenStamp_;
        seen.resize(objects_.size(), 0);
        if (++stamp_ == 0) {
            std::fill(seen.begin(), seen.end(), 0);
            stamp_ = 1;
        }
        Range previous{};
        bool havePrevious = false;
        for (std::size_t step = 0; step < std::size_t(steps); ++step) {
            const double a = t0 + double(step) * stepLength;
            if (a > t1) {
                break;
            }
            const Range range = rangeOf(segmentBox(a, std::min(t1, a + stepLength)));
            index_.forEachLiveIn(range, [&](std::uint32_t cell) {
                if (havePrevious && previous.contains(index_.key(cell))) {
                    return;
                }
                for (std::uint32_t e = index_.record(cell).head; e != kNone; e = entries_[e].next) {
                    const ObjectId id = entries_[e].object;
                    if (seen[id] != stamp_) {
                        seen[id] = stamp_;
                        visit(id);
                    }
                }
            });
            previous = range;
            havePrevious = true;
        }
    }

    std::size_t size() const { return size_; }

    /// Checks every object's cells against its box, the per-cell lists, the overflow set
    /// and the index; throws std::logic_error.
    void validate() const {
        auto fail = [](const std::string& what) {
            throw std::logic_error(std::string("CellGrid (") + Index::kName + "): " + what);
        };
        std::size_t live = 0, entries = 0, overflow = 0;
        for (ObjectId id = 0; id < objects_.size(); ++id) {
            const Object& object = objects_[id];
            if (object.state == State::Absent) {
                continue;
            }
            ++live;
            if (object.state == State::Waiting) {
                if (chosen_) {
                    fail("object " + std::to_string(id) + " waits after the cell size was chosen");
                }
                continue;
            }
            if (object.state == State::Overflow) {
                ++overflow;
                if (overflow_[object.overflowAt] != id) {
                    fail("overflow index of object " + std::to_string(id) + " is wrong");
                }
                continue;
            }
            const Range range = rangeOf(object.box);
            if (range != object.range || belongsInOverflow(object.box, range)) {
                fail("object " + std::to_string(id) + " is binned under a stale cell range");
            }
            std::size_t cells = 0;
            for (std::uint32_t e = object.firstEntry; e != kNone; e = entries_[e].nextOfObject) {
                ++cells;
                if (entries_[e].object != id || !range.contains(index_.key(entries_[e].cell))) {
                    fail("entry of object " + std::to_string(id) + " in a wrong cell");
                }
            }
            if (double(cells) != range.cellCount()) {
                fail("object " + std::to_string(id) + " is in " + std::to_string(cells) +
                     " cells, its box covers " + std::to_string(range.cellCount()));
            }
            if (object.single != (cells == 1)) {
                fail("single-cell flag of object " + std::to_string(id) + " is wrong");
            }
            entries += cells;
        }
        if (live != size_ || overflow != overflow_.size()) {
            fail("object counts disagree");
        }
        if (!chosen_ && waiting_.size() != live) {
            fail("waiting list disagrees");
        }
        std::size_t listed = 0;
        index_.forEachLive([&](std::uint32_t cell, const CellRecord& record) {
            std::uint32_t count = 0, previous = kNone;
            for (std::uint32_t e = record.head; e != kNone; e = entries_[e].next) {
                if (entries_[e].cell != cell || entries_[e].previous != previous) {
                    fail("cell list broken");
                }
                previous = e;
                ++count;
            }
            if (count != record.count) {
                fail("cell count wrong");
            }
            listed += count;
        });
        if (listed != entries) {
            fail("cells list " + std::to_string(listed) + " entries, objects own " +
                 std::to_string(entries));
        }
        index_.validate();
    }

    std::size_t memoryBytes() const {
        return objects_.capacity() * sizeof(Object) + entries_.capacity() * sizeof(Entry) +
               (overflow_.capacity() + waiting_.capacity() + freeEntries_.capacity() +
                seenStamp_.capacity() + sortScratch_.capacity()) *
                   sizeof(std::uint32_t) +
               index_.memoryBytes();
    }

    CellGridStats stats() const {
        CellGridStats out;
        out.cellSize = cellSize_;
        out.liveCells = index_.liveCount();
        if constexpr (Index::kBounded) {
            out.allocatedCells = index_.cellCount();
        } else {
            out.allocatedCells = index_.liveCount();
        }
        out.entries = entries_.size() - freeEntries_.size();
        out.overflow = overflow_.size();
        out.rechoices = rechoices_;
        return out;
    }
    const Index& index() const { return index_; }

  private:
    enum class State : std::uint8_t { Absent, Waiting, InCells, Overflow };
    static constexpr std::uint32_t kNone = 0xffffffffu;
    /// Cell coordinates are kept within +-2^62 so that differences never overflow.
    static constexpr double kKeyLimit = 4.6e18;

    struct Object {
        Box box{};
        Range range{};
        std::uint32_t firstEntry = kNone;
        std::uint32_t overflowAt = 0;
        State state = State::Absent;
        bool single = false;
        bool outside = false;  ///< dense grid: in the overflow set for being outside the region
    };
    struct Entry {
        ObjectId object = 0;
        std::uint32_t cell = 0;
        std::uint32_t next = kNone;
        std::uint32_t previous = kNone;
        std::uint32_t nextOfObject = kNone;
    };

    static double largestExtent(const Box& box) {
        double extent = 0;
        for (int axis = 0; axis < D; ++axis) {
            extent = std::max(extent, double(box.hi[axis]) - double(box.lo[axis]));
        }
        return extent;
    }
    /// Mean largest extent over a sample of at most 512 objects, each capped at extentCap_
    /// so that a few planes do not dominate: the drift statistic.
    double sampledMeanExtent() const {
        const std::size_t stride = objects_.size() / 512 + 1;
        double sum = 0;
        std::size_t counted = 0;
        for (std::size_t id = 0; id < objects_.size(); id += stride) {
            if (objects_[id].state != State::Absent) {
                sum += std::min(largestExtent(objects_[id].box), extentCap_);
                ++counted;
            }
        }
        return counted > 0 ? sum / double(counted) : 0;
    }

    /// A double as Scalar, rounded towards -inf / +inf (saturating at the Scalar range).
    static Scalar roundedDown(double x) {
        Scalar s = static_cast<Scalar>(x);
        return double(s) > x ? std::nextafter(s, -std::numeric_limits<Scalar>::infinity()) : s;
    }
    static Scalar roundedUp(double x) {
        Scalar s = static_cast<Scalar>(x);
        return double(s) < x ? std::nextafter(s, std::numeric_limits<Scalar>::infinity()) : s;
    }
    /// Every binned object once.
    template <class Visit>
    void visitAllBinned(Visit& visit) const {
        for (ObjectId id = 0; id < objects_.size(); ++id) {
            if (objects_[id].state == State::InCells) {
                visit(id);
            }
        }
    }

    Range rangeOf(const Box& box) const {
        Range range;
        for (int axis = 0; axis < D; ++axis) {
            range.lo[axis] = coordinate(double(box.lo[axis]), axis);
            range.hi[axis] = coordinate(double(box.hi[axis]), axis);
        }
        return range;
    }
    Coord coordinate(double x, int axis) const {
        double c = (x - origin_[axis]) * inverseCellSize_;
        // Clamp first (a NaN to the low end: no undefined conversion), then floor by
        // truncation (std::floor is a library call on baseline x86-64, and this runs for
        // every setAabb).
        if constexpr (Index::kBounded) {
            c = c >= 0.0 ? std::min(c, double(dims_[axis]) - 0.5) : 0.0;
        } else {
            c = c >= -kKeyLimit ? std::min(c, kKeyLimit) : -kKeyLimit;
        }
        const std::int64_t truncated = static_cast<std::int64_t>(c);
        return static_cast<Coord>(truncated - (c < double(truncated) ? 1 : 0));
    }
    bool isOutside(const Box& box) const {
        if constexpr (Index::kBounded) {
            for (int axis = 0; axis < D; ++axis) {
                if (double(box.hi[axis]) < regionLo_[axis] ||
                    double(box.lo[axis]) > regionHi_[axis]) {
                    return true;
                }
            }
        }
        return false;
    }
    bool belongsInOverflow(const Box& box, const Range& range) const {
        if (range.cellCount() > settings_.maxCellsPerObject || isOutside(box)) {
            return true;
        }
        if constexpr (!Index::kBounded) {
            for (int axis = 0; axis < D; ++axis) {
                if (std::fabs(double(range.lo[axis])) >= kKeyLimit / 2 ||
                    std::fabs(double(range.hi[axis])) >= kKeyLimit / 2) {
                    return true;
                }
            }
        }
        return false;
    }
    static bool isCanonical(const Key& cell, const Range& a, const Range& b) {
        for (int axis = 0; axis < D; ++axis) {
            if (cell[axis] != std::max(a.lo[axis], b.lo[axis])) {
                return false;
            }
        }
        return true;
    }

    void place(ObjectId id) { place(id, rangeOf(objects_[id].box)); }
    void place(ObjectId id, const Range& range) {
        Object& object = objects_[id];
        object.range = range;
        if (belongsInOverflow(object.box, range)) {
            object.state = State::Overflow;
            object.overflowAt = static_cast<std::uint32_t>(overflow_.size());
            object.outside = isOutside(object.box);
            outside_ += object.outside ? 1 : 0;
            overflow_.push_back(id);
            return;
        }
        object.state = State::InCells;
        object.single = range.lo == range.hi;
        object.firstEntry = kNone;
        forEachCellIn(range, [&](const Key& key) { addEntry(id, key); });
        growContent(object.box);
    }
    /// Moves a binned object to new cells, touching only the cells that change.
    void rebin(ObjectId id, const Range& range) {
        Object& object = objects_[id];
        if (object.single && range.lo == range.hi) {
            dropEntry(object.firstEntry);
            object.firstEntry = kNone;
            addEntry(id, range.lo);
            object.range = range;
            growContent(object.box);
            return;
        }
        std::uint32_t* link = &object.firstEntry;
        while (*link != kNone) {
            const std::uint32_t e = *link;
            if (range.contains(index_.key(entries_[e].cell))) {
                link = &entries_[e].nextOfObject;
            } else {
                *link = entries_[e].nextOfObject;
                dropEntry(e);
            }
        }
        const Range old = object.range;
        forEachCellIn(range, [&](const Key& key) {
            if (!old.contains(key)) {
                addEntry(id, key);
            }
        });
        object.range = range;
        object.single = range.lo == range.hi;
        growContent(object.box);
    }
    void addEntry(ObjectId id, const Key& key) {
        const std::uint32_t cell = index_.acquire(key);
        const std::uint32_t e = newEntry();
        Entry& entry = entries_[e];
        CellRecord& record = index_.record(cell);
        entry.object = id;
        entry.cell = cell;
        entry.previous = kNone;
        entry.next = record.head;
        if (record.head != kNone) {
            entries_[record.head].previous = e;
        }
        record.head = e;
        ++record.count;
        entry.nextOfObject = objects_[id].firstEntry;
        objects_[id].firstEntry = e;
    }
    /// Unlinks the entry from its cell (releasing the cell when it empties) and frees it;
    /// the caller unlinks it from its object's list.
    void dropEntry(std::uint32_t e) {
        Entry& entry = entries_[e];
        CellRecord& record = index_.record(entry.cell);
        if (entry.previous != kNone) {
            entries_[entry.previous].next = entry.next;
        } else {
            record.head = entry.next;
        }
        if (entry.next != kNone) {
            entries_[entry.next].previous = entry.previous;
        }
        if (--record.count == 0) {
            index_.release(entry.cell);
        }
        freeEntries_.push_back(e);
    }
    void growContent(const Box& box) {
        for (int axis = 0; axis < D; ++axis) {
            contentLo_[axis] = std::min(contentLo_[axis], double(box.lo[axis]));
            contentHi_[axis] = std::max(contentHi_[axis], double(box.hi[axis]));
        }
    }
    void unplace(ObjectId id) {
        Object& object = objects_[id];
        if (object.state == State::Overflow) {
            const std::uint32_t at = object.overflowAt;
            overflow_[at] = overflow_.back();
            objects_[overflow_[at]].overflowAt = at;
            overflow_.pop_back();
            outside_ -= object.outside ? 1 : 0;
            object.outside = false;
        } else if (object.state == State::InCells) {
            for (std::uint32_t e = object.firstEntry; e != kNone;) {
                const std::uint32_t nextOfObject = entries_[e].nextOfObject;
                dropEntry(e);
                e = nextOfObject;
            }
            object.firstEntry = kNone;
        }
        object.state = State::Waiting;
    }
    std::uint32_t newEntry() {
        if (!freeEntries_.empty()) {
            const std::uint32_t e = freeEntries_.back();
            freeEntries_.pop_back();
            return e;
        }
        entries_.emplace_back();
        return static_cast<std::uint32_t>(entries_.size() - 1);
    }
    static void eraseFrom(std::vector<ObjectId>& list, ObjectId id) {
        list.erase(std::find(list.begin(), list.end(), id));
    }

    template <class Visit>
    void forEachObject(Visit&& visit) const {
        for (ObjectId id = 0; id < objects_.size(); ++id) {
            if (objects_[id].state != State::Absent) {
                visit(id);
            }
        }
    }

    /// Visits every object binned in the live cells of `range` once, from the canonical
    /// cell shared by the range and the object's own cells.
    template <class Visit>
    void visitCells(const Range& range, Visit& visit) const {
        index_.forEachLiveIn(range, [&](std::uint32_t cell) {
            Key key{};
            bool keyKnown = false;
            for (std::uint32_t e = index_.record(cell).head; e != kNone; e = entries_[e].next) {
                const Object& object = objects_[entries_[e].object];
                if (!object.single) {
                    if (!keyKnown) {
                        key = index_.key(cell);
                        keyKnown = true;
                    }
                    if (!isCanonical(key, range, object.range)) {
                        continue;
                    }
                }
                visit(entries_[e].object);
            }
        });
    }

    template <class Sink>
    void overflowCandidates(Sink& candidate) {
        if (overflow_.empty()) {
            return;
        }
        // Overflow against overflow: sort by min x, sweep.
        sortScratch_.assign(overflow_.begin(), overflow_.end());
        std::sort(sortScratch_.begin(), sortScratch_.end(), [&](ObjectId a, ObjectId b) {
            return objects_[a].box.lo[0] < objects_[b].box.lo[0];
        });
        for (std::size_t i = 0; i < sortScratch_.size(); ++i) {
            const Box& a = objects_[sortScratch_[i]].box;
            for (std::size_t j = i + 1;
                 j < sortScratch_.size() && objects_[sortScratch_[j]].box.lo[0] <= a.hi[0]; ++j) {
                candidate(sortScratch_[i], sortScratch_[j]);
            }
        }
        // Overflow against binned objects: the cells each overflow box covers (clamped to
        // the region for the dense grid).
        for (ObjectId id : overflow_) {
            const Range range = rangeOf(objects_[id].box);
            auto visit = [&](ObjectId other) { candidate(id, other); };
            visitCells(range, visit);
        }
    }

    /// Re-choose when the population has drifted (see CellGridSettings::rechooseFactor);
    /// at most every 8 frames, so a population that no choice can fit does not thrash.
    bool needsChoice() const {
        if (!chosen_) {
            return true;
        }
        if (settings_.rechooseFactor == 0 || framesSinceChoice_ < 8 || size_ < 16) {
            return false;
        }
        const double factor = settings_.rechooseFactor;
        const bool automaticSize = settings_.cellSize == 0 || settings_.cellsPerAxis > 0;
        if (automaticSize &&
            (double(size_) > double(chosenSize_) * 2 || double(size_) * 2 < double(chosenSize_))) {
            return true;
        }
        // The extent statistic is sampled every 8th frame only.
        if (automaticSize && framesSinceChoice_ % 8 == 0) {
            const double mean = sampledMeanExtent();
            if (mean > chosenMeanExtent_ * factor || mean * factor < chosenMeanExtent_) {
                return true;
            }
        }
        if constexpr (Index::kBounded) {
            return outside_ > size_ / 16 + 8 && !regionFixed();
        }
        return false;
    }
    void recomputeContent() const {
        contentLo_.fill(HUGE_VAL);
        contentHi_.fill(-HUGE_VAL);
        for (const Object& object : objects_) {
            if (object.state != State::InCells) {
                continue;
            }
            for (int axis = 0; axis < D; ++axis) {
                contentLo_[axis] = std::min(contentLo_[axis], double(object.box.lo[axis]));
                contentHi_[axis] = std::max(contentHi_[axis], double(object.box.hi[axis]));
            }
        }
        contentDirty_ = false;
    }
    bool regionFixed() const {
        for (int axis = 0; axis < D; ++axis) {
            if (!(settings_.regionMin[axis] < settings_.regionMax[axis])) {
                return false;
            }
        }
        return true;
    }

    /// Chooses cell size (and region) from the current objects, then bins them all.
    void choose() {
        std::vector<ObjectId> all;
        all.reserve(size_);
        forEachObject([&](ObjectId id) { all.push_back(id); });
        // Median of the largest extent, from a sample of at most 4097 objects.
        const std::size_t stride = all.size() / 4097 + 1;
        std::vector<double> extents;
        for (std::size_t i = 0; i < all.size(); i += stride) {
            extents.push_back(largestExtent(objects_[all[i]].box));
        }
        double median = 0;
        if (!extents.empty()) {
            std::nth_element(extents.begin(), extents.begin() + extents.size() / 2, extents.end());
            median = extents[extents.size() / 2];
        }
        // Bounds of the ordinary objects (not more than 64 median extents wide), without the
        // extreme 1/256 of them on each side.
        std::array<double, D> lo{}, hi{};
        bool haveBounds = false;
        {
            std::vector<double> los, his;
            for (int axis = 0; axis < D; ++axis) {
                los.clear();
                his.clear();
                for (ObjectId id : all) {
                    const Box& box = objects_[id].box;
                    if (median > 0 && largestExtent(box) > 64 * median) {
                        continue;
                    }
                    los.push_back(double(box.lo[axis]));
                    his.push_back(double(box.hi[axis]));
                }
                if (los.empty()) {
                    break;
                }
                const std::size_t cut = settings_.cellsPerAxis > 0 ? 0 : los.size() / 256;
                std::nth_element(los.begin(), los.begin() + cut, los.end());
                std::nth_element(his.begin(), his.end() - 1 - cut, his.end());
                lo[axis] = los[cut];
                hi[axis] = his[his.size() - 1 - cut];
                haveBounds = axis == D - 1;
            }
        }
        if (!haveBounds) {
            lo.fill(0);
            hi.fill(1);
        }
        double widest = 0;
        for (int axis = 0; axis < D; ++axis) {
            widest = std::max(widest, hi[axis] - lo[axis]);
        }
        double size;
        if (settings_.cellsPerAxis > 0) {
            size = widest / settings_.cellsPerAxis;
        } else if (settings_.cellSize > 0) {
            size = settings_.cellSize;
        } else {
            size = settings_.sizeFactor * median;
            if (!(size > 0)) {
                // Only points: aim at about one object per cell.
                size = widest / std::max(1.0, std::pow(double(all.size()), 1.0 / D));
            }
        }
        if (!(size > 0) || !std::isfinite(size)) {
            size = 1;
        }
        if constexpr (Index::kBounded) {
            if (regionFixed()) {
                for (int axis = 0; axis < D; ++axis) {
                    lo[axis] = settings_.regionMin[axis];
                    hi[axis] = settings_.regionMax[axis];
                }
            }
            const double budget =
                settings_.cellSize > 0 || settings_.cellsPerAxis > 0
                    ? settings_.maxCells
                    : std::min(settings_.maxCells,
                               std::max(4096.0, settings_.cellsPerObject * double(all.size())));
            // Enlarge the cells until the region fits the budget.
            for (int attempt = 0; attempt < 200; ++attempt) {
                double cells = 1;
                for (int axis = 0; axis < D; ++axis) {
                    cells *= std::max(1.0, std::ceil((hi[axis] - lo[axis]) / size));
                }
                if (cells <= budget) {
                    break;
                }
                size *= std::max(1.01, std::pow(cells / budget, 1.0 / D));
            }
            Key dims{};
            for (int axis = 0; axis < D; ++axis) {
                dims[axis] =
                    static_cast<Coord>(std::max(1.0, std::ceil((hi[axis] - lo[axis]) / size)));
                regionLo_[axis] = lo[axis];
                regionHi_[axis] = lo[axis] + double(dims[axis]) * size;
            }
            dims_ = dims;
            index_.reset(dims);
        } else {
            index_.clear();
        }
        origin_ = lo;
        cellSize_ = size;
        inverseCellSize_ = 1 / size;
        extentCap_ = size * settings_.maxCellsPerObject;
        entries_.clear();
        freeEntries_.clear();
        overflow_.clear();
        outside_ = 0;
        framesSinceChoice_ = 0;
        waiting_.clear();
        contentLo_.fill(HUGE_VAL);
        contentHi_.fill(-HUGE_VAL);
        chosen_ = true;
        for (ObjectId id : all) {
            objects_[id].state = State::Waiting;
            objects_[id].firstEntry = kNone;
            place(id);
        }
        chosenSize_ = size_;
        chosenMeanExtent_ = sampledMeanExtent();
        ++rechoices_;
    }

    Settings settings_;
    Index index_;
    std::vector<Object> objects_;
    std::vector<Entry> entries_;
    std::vector<std::uint32_t> freeEntries_;
    std::vector<ObjectId> overflow_;
    std::vector<ObjectId> waiting_;
    std::vector<ObjectId> sortScratch_;
    mutable std::vector<std::uint32_t> seenStamp_;
    mutable std::uint32_t stamp_ = 0;
    std::size_t size_ = 0;

    bool chosen_ = false;
    double cellSize_ = 1;
    double inverseCellSize_ = 1;
    double extentCap_ = HUGE_VAL;
    std::array<double, D> origin_{};
    std::array<double, D> regionLo_{};
    std::array<double, D> regionHi_{};
    Key dims_{};
    std::size_t outside_ = 0;
    std::size_t framesSinceChoice_ = 0;
    /// Bounds of the binned boxes, for clipping rays: grown by every placement, recomputed
    /// by the first ray after a pair search.
    mutable std::array<double, D> contentLo_{};
    mutable std::array<double, D> contentHi_{};
    mutable bool contentDirty_ = false;
    std::size_t chosenSize_ = 0;
    double chosenMeanExtent_ = 0;
    std::size_t rechoices_ = 0;
};

template <int D, class Scalar>
using UniformGrid = CellGrid<D, Scalar, DenseIndex<D>>;
template <int D, class Scalar>
using SpatialTree = CellGrid<D, Scalar, AvlIndex<D>>;
template <int D, class Scalar>
using SpatialHash = CellGrid<D, Scalar, HashIndex<D>>;

}  // namespace kolize

#pragma once
/// \file
/// AutoCore<D, Scalar>: the core of broadphase "auto". It holds one of kolize's cores at a
/// time (grid, spatial-hash, sweep) and picks it from what it measures of the scene
/// (SceneMeasure, filled in by the adapter): object count, how many move and how far against
/// their size, how crowded the cells would be, how many endpoints a sorted sweep would pass,
/// and the rays and box queries per frame. When the scene changes it switches: the adapter
/// rebuilds the new core from the current boxes without touching the pair cache (no pair
/// lost, no cached algorithm freed).
///
/// The rules (measured with kolize-demo over the scene registry, see README):
/// - under 64 objects: sweep, whatever they do (the registry's small worlds, 5-40 bodies,
///   cost it 0.0006-0.003 ms per frame, the other cores up to 6x that);
/// - the spread of sizes does not decide. Until the sweep applied many moves in one pass per
///   axis, sizes spread over 30x took the segment trees (mixed-sizes: the sweep's one-by-one
///   updates made large boxes' ends pass many small ones'); now, replayed over 300 frames,
///   mixed-sizes costs the sweep 0.014 ms, the grid 0.068 and the segment trees 0.073, and in
///   two synthetic streams of sizes spread 1e4x moving fast the sweep or the grid was fastest,
///   never the segment trees: auto no longer holds them;
/// - many long rays (at least max(16, N/64) per frame, reaching 8 box sizes or more; CCD's
///   short sweeps do not count): spatial-hash, whose ray walk visits few
///   cells and no empty ones (sweep tests every object per ray; measured on mixed-rays and
///   bench-raycast: spatial-hash's rays 1.08 and 0.62 ms, grid's 1.08 and 2.04, sweep's
///   3.09 and 3.48);
/// - at rest (under half an object moved per frame): the present core, which costs nothing
///   while no box changes. Before the first decision that is no decision: a world that has
///   not moved yet keeps the starting core, and auto looks again every 8 frames until
///   something moves (offset-1e6's bodies rest for their first frames, until
///   their speed reaches a float step; judged from those frames, it took the sweep, which
///   then took 2-3x the grid's time for 96 frames);
/// - resting jitter (objects move every frame but their fat boxes hold every move and no
///   pair starts or stops overlapping, as in a stack or pyramid that does not fall
///   asleep): grid, whose fat boxes and pair certificates absorb the moves, where the
///   sweep's endpoints swap among the near-equal coordinates of a stack (pyramid, moving
///   frames replayed: grid 0.026-0.029 ms, sweep 0.064-0.068);
/// - slow motion (the moving objects move less than a fifth of their size per frame, as in
///   most Bullet worlds, resting or settling) in which the sweep swaps much: the endpoints
///   passed per moved object (SceneMeasure::swapsPerMove: while the sweep runs, as it does
///   from the start, its own count; under another core an estimate) at least
///   30 x (1 + half the grid's crowding), under 0.1 pair changes per move: grid. The count
///   is what the sweep pays: an axis on which no min passed a max is not sorted, and ends of
///   one kind that pass each other there are not counted (the estimate counts every order
///   change). Since the sweep leaves such axes out, the worlds this rule was fitted on
///   (offset-1e6's float steps far from the origin, the first frames of bench-1000-stack)
///   count under 30 and keep the sweep, which there takes less time than the grid (replayed
///   over 100 frames: offset-1e6's median frame 0.055 ms against 0.063, bench-1000-stack's
///   frames 2-17 0.05-0.24 ms against 0.16-0.61);
/// - slow motion otherwise: sweep. (mixed-terrain, mixed-plane and offset-1e4 passed 43-110
///   per move in the sweep's old one-by-one updates, most of them ends of boxes falling with
///   them that had not moved yet; applied in one pass, mixed-terrain counts 5-27 and the sweep
///   takes half of the grid's time.)
/// - faster motion in which a moved box passes under 4 endpoints (bodies flying apart, or
///   falling together): sweep, whose cost does not grow with the distance a box goes. The
///   estimate under another core counts the order changes among a sample of one frame's
///   moves, and the moves against the boxes that stayed only for the share that stayed:
///   escape's bodies flying apart, set against every box where it stood, seemed to pass
///   2-10 (the grid until frame 160, at 3x the sweep's time); among each other they pass
///   about 1 (the sweep from frame 32). Thesis A's fast cubes pass 8: the grid, at half the
///   sweep's time;
/// - faster motion otherwise, and the dense grid would crowd (its cells, enlarged to fit its
///   budget of cells per object over the objects' bounds, would put more than 16 + 2x as
///   many other objects beside an object as the sparse cells do: a cluster in a large space, as the
///   thesis's scene B with 33 at 300 objects and 340 at 3000; escape's 300 bodies flying
///   apart have 14, where grid takes a quarter of spatial-hash's time): spatial-hash,
///   whose cells keep their size wherever the objects are
///   (thesis B fast, 3000 objects: spatial-hash 0.25x of dbvt, segment-trees 0.32x, grid
///   1.4x, kolize-bench);
/// - faster motion otherwise: grid.
/// The starting core is the sweep, the choice of every Bullet benchmark scene but the rays'
/// and of most of the registry: a world that keeps it pays no switch and no frames on
/// another core (when auto started on the grid, its two grid frames and its switch to the
/// sweep sat on the ramp of a world that starts falling and raised its median frame:
/// mixed-terrain's, over 100 frames replayed, was 1.3x the sweep's). The first decision
/// (after two pair searches, or later if nothing moved) switches at once: the starting
/// core was nobody's choice. So does the first decision made from a full
/// window (16 frames or more; the first is often made from two; the adapter evaluates at
/// frame 18, after frames 2-17, and then every 32): a pyramid that jitters is seen as such
/// from its first full window on. After that a choice must win two evaluations
/// in a row (every 32 frames), and every choice after the second switch stands at least 128
/// frames, so a scene on a threshold does not flip back and forth.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/cell_grid.h>
#include <kolize/broadphase/sweep_and_prune.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace kolize {

/// What the adapter measured of the scene since the last evaluation.
struct SceneMeasure {
    std::size_t objects = 0;
    double frames = 0;          ///< pair searches covered
    double movedPerFrame = 0;   ///< objects whose box changed, per frame
    double relativeMotion = 0;  ///< mean over those moves of motion / box size
    /// Moves looked at (a sample of those above) for relativeMotion and fatExitsPerMove.
    double movesLookedAt = 0;
    /// Share of those moves that left the object's fat box (BroadphaseSettings::fatMargin;
    /// measured against a shadow fat box while the sweep runs).
    double fatExitsPerMove = 0;
    /// Pairs that started or stopped overlapping (added to or removed from the pair cache),
    /// per moved object.
    double pairChangesPerMove = 0;
    /// Endpoints that a sorted sweep's moved box would pass per move (each axis, both
    /// ends), estimated under any core: a sample of the moves against the endpoints of a
    /// sample of the boxes, scaled to all of them.
    double swapsPerMove = 0;
    double medianSize = 0;  ///< median largest extent of the sampled boxes
    /// Centres of a sample of the boxes (at most 1024, planes and boxes over 1e6 left out).
    std::vector<std::array<double, 3>> centres;
    double raysPerFrame = 0;
    double rayLength = 0;  ///< mean reach of the rays, in median box sizes (sampled sizes)
    double boxQueriesPerFrame = 0;
    /// When set, medianSize, centres, rayLength and the swapsPerMove estimate are left to it
    /// (a sample of the boxes: 20-30 us per 1000 objects), and AutoCore calls it only when a
    /// rule needs them: the sweep's slow motion with few counted swaps needs none.
    std::function<void(SceneMeasure&)> sampleBoxes;
};

/// Settings of broadphase "auto": the settings of the cores it may use.
struct AutoSettings {
    CellGridSettings cells;
    /// Evaluate every this many pair searches (default 32).
    int evaluateEvery = 32;
};

template <int D, class Scalar>
class AutoCore {
  public:
    using Box = Aabb<D, Scalar>;
    using Settings = AutoSettings;
    enum class Kind : std::uint8_t { Grid, SpatialHash, Sweep };

    explicit AutoCore(const Settings& settings = {})
        : settings_(settings), grid_(settings.cells), hash_(settings.cells) {}

    static const char* kindName(Kind kind) {
        switch (kind) {
            case Kind::Grid:
                return "grid";
            case Kind::SpatialHash:
                return "spatial-hash";
            case Kind::Sweep:
                return "sweep";
        }
        return "?";
    }

    /// Under this many objects (not planes: all live boxes) the sweep (registry, replayed:
    /// tall-stack's 40 bodies, mass-ratio-stack's 20 and the mesh worlds' 5-24 cost the
    /// sweep 0.0006-0.003 ms, the other cores up to 6x that: mesh-wall's 9 boxes, a 40 m
    /// wall among 0.5 m bodies, took the segment trees for their spread of sizes). No rule
    /// looks at their motion, so the adapter does not sample it.
    static constexpr std::size_t kFewObjects = 64;

    Kind kind() const { return kind_; }
    /// True until an evaluation has seen motion (or sizes or rays that decide alone): the
    /// adapter evaluates every 8 frames meanwhile, not every evaluateEvery.
    bool undecided() const { return evaluations_ == 0; }
    bool tracksOverlaps() const { return kind_ == Kind::Sweep; }
    /// Why the present core was chosen (for kolize-demo), and how many switches so far.
    const std::string& reason() const { return reason_; }
    std::size_t switches() const { return switches_; }

    /// Given the scene's measure, the core it should use (the rules above, with the
    /// hysteresis); sets reason().
    Kind decide(SceneMeasure measure) {
        framesSinceSwitch_ += std::size_t(measure.frames);
        // While the sweep runs, its swaps are counted, not estimated: the estimate (sampled
        // moves against the boxes at this evaluation) misses where a world moved away from
        // the sampled moves (mixed-terrain's falling bodies: estimated 18 per move at frame
        // 32, counted 49 in the frames sampled then).
        swapsCounted_ = kind_ == Kind::Sweep && updates_ > updatesSeen_;
        if (swapsCounted_) {
            measure.swapsPerMove =
                double(sweep_.swaps() - swapsSeen_) / double(updates_ - updatesSeen_);
        }
        swapsSeen_ = sweep_.swaps();
        updatesSeen_ = updates_;
        const Kind wanted = rule(measure);
        if (waiting_) {
            reason_ = ruleReason_;
            return kind_;  // nothing moved yet: no evidence, no decision
        }
        ++evaluations_;
        // The first decision takes effect at once (even when it keeps the starting core), and
        // so does the first made from a full window: the first, often from two frames, is a
        // guess (dense-pile's first two frames look fast; its pile is slow from frame 32 on,
        // where the sweep takes a fifth of the grid's time). Later ones must win twice in a
        // row.
        const bool fullWindow = measure.frames >= kFullWindow;
        const bool atOnce = evaluations_ == 1 || (fullWindow && !fullWindowSeen_);
        fullWindowSeen_ = fullWindowSeen_ || fullWindow;
        if (wanted == kind_) {
            pending_ = kind_;
            reason_ = ruleReason_;
            return kind_;
        }
        if (wanted != pending_ && !atOnce) {
            pending_ = wanted;  // must win once more
            return kind_;
        }
        if (framesSinceSwitch_ < 128 && switches_ > 1) {
            return kind_;
        }
        return wanted;
    }

    /// Drops every object and makes `kind` the active core; the adapter inserts the
    /// objects again.
    void switchTo(Kind kind, const std::string& why) {
        grid_ = UniformGrid<D, Scalar>(settings_.cells);
        hash_ = SpatialHash<D, Scalar>(settings_.cells);
        sweep_ = SweepAndPrune<D, Scalar>();
        swapsSeen_ = 0;
        updatesSeen_ = updates_;
        kind_ = kind;
        pending_ = kind;
        reason_ = why;
        framesSinceSwitch_ = 0;
        ++switches_;
    }

    /// The reason the last decide() gave for its rule (even when it did not switch).
    const std::string& lastRuleReason() const { return ruleReason_; }

    // --- the core concept: forwarded to the active core ---
    void insert(ObjectId id, const Box& box) {
        dispatch([&](auto& core) { core.insert(id, box); });
    }
    void update(ObjectId id, const Box& box) {
        ++updates_;
        dispatch([&](auto& core) { core.update(id, box); });
    }
    void remove(ObjectId id) {
        dispatch([&](auto& core) { core.remove(id); });
    }
    void maintain() {
        dispatch([&](auto& core) { core.maintain(); });
    }
    template <class Sink>
    void findCandidates(Sink&& sink) {
        dispatch([&](auto& core) { core.findCandidates(sink); });
    }
    template <class Sink>
    void drainChanges(Sink&& sink) {
        if (kind_ == Kind::Sweep) {
            sweep_.drainChanges(sink);
        }
    }
    template <class Visit>
    void queryBox(const Box& box, Visit&& visit) const {
        dispatch([&](const auto& core) { core.queryBox(box, visit); });
    }
    template <class Visit>
    void queryRay(const Ray<D, Scalar>& ray, Visit&& visit) const {
        dispatch([&](const auto& core) { core.queryRay(ray, visit); });
    }
    void validate() const {
        dispatch([&](const auto& core) { core.validate(); });
    }
    std::size_t memoryBytes() const {
        return grid_.memoryBytes() + hash_.memoryBytes() + sweep_.memoryBytes();
    }

  private:
    /// Rays shorter than this many median box sizes (Bullet's CCD sweeps of one step's
    /// motion) are cheap in every core and do not decide.
    static constexpr double kLongRay = 8;
    /// Resting jitter: over a window of at least kJitterWindow frames (not the first
    /// evaluation's two), under kJitterFatExits of the moves left a fat box and under
    /// kJitterPairChanges pairs changed per move. Measured on recorded streams (replayed,
    /// medians of the moving frames): the pyramid (0 and 0; grid 0.019 ms, sweep 0.080,
    /// store-only 0.011) against bench-1000-stack's settling windows (under 0.001, but
    /// 0.019-0.037 pair changes per move: the sweep 0.063, grid 0.073) and
    /// bench-convex-pack's (0.0035-0.0066, 0.0049-0.011); every other scene of the
    /// registry leaves a fat box in over 0.07 of its moves.
    /// Slow motion with many swaps: the grid when the endpoints passed per moved object
    /// (counted under the sweep, estimated under the others) reach kManySwaps times (1 +
    /// half the grid's crowding). A sweep's moved object
    /// costs about 0.07 us + 4 ns per endpoint passed + 0.2 us per pair change (fitted);
    /// the grid's grows with the others beside it. Chosen on 20 recorded streams of the
    /// registry, the features of one 32-frame window against the replayed times of the
    /// next. Replayed with the rule, it put auto on the grid in 9 windows (the first of
    /// pyramid and bench-1000-stack, offset-1e6's from frame 96 on: 50-75 passed, 0.75
    /// others), where the grid took 0.30-0.77x of the sweep's time, and in none where the
    /// sweep was faster; it keeps the sweep for falling boxes (bench-3000-boxes: 39-84
    /// passed, 4-15 others, the sweep 0.55-0.65x of the grid) and bench-prim-mesh (27-36,
    /// 6-12). That was fitted before the sweep left out the axes where no min passed a max
    /// and before auto started on the sweep; now those three worlds count fewer passes and
    /// keep the sweep, and only ends that pass ends of the other kind by the hundred (x
    /// intervals that touch end to end, Auto.SlowMotionThatPassesManyEndpointsTakesTheGrid)
    /// reach the grid.
    static constexpr double kManySwaps = 30;
    /// ... and under this many pair changes per move: every change costs the grid a pair
    /// look where the sweep has found it already (the windows where the grid won had at
    /// most 0.054; falling boxes that pile up, 0.1-1.5).
    static constexpr double kManySwapsPairChanges = 0.1;
    /// Fast motion in which a moved box passes under this many endpoints: the sweep. A fast
    /// move costs the sweep about 30 ns + 12 ns per endpoint passed (far jumps), the grid
    /// 70-100 ns (replayed, per moved object): escape's bodies flying apart pass 1-4 from
    /// frame 64 on (the sweep 0.45-0.7x of the grid's time), thesis A's fast cubes 12 (the
    /// grid 0.4x of the sweep's), dense-pile's first frames, falling in lockstep, none.
    static constexpr double kFewSwapsFast = 4;
    static constexpr double kJitterWindow = 16;
    /// A measure over at least this many frames is a full window (see decide()).
    static constexpr double kFullWindow = 16;
    static constexpr double kJitterFatExits = 0.01;
    /// ... from at least this many moves looked at (see SceneMeasure::movesLookedAt).
    static constexpr double kJitterLookedAt = 16;
    static constexpr double kJitterPairChanges = 0.002;

    /// Fills the sampled fields of `m` if it has a sampler that was not called yet (keeping
    /// a counted swapsPerMove).
    void needSamples(SceneMeasure& m) const {
        if (m.sampleBoxes) {
            const double counted = m.swapsPerMove;
            const auto sample = std::move(m.sampleBoxes);
            m.sampleBoxes = nullptr;
            sample(m);
            if (swapsCounted_) {
                m.swapsPerMove = counted;
            }
        }
    }

    Kind rule(SceneMeasure& m) {
        const double n = double(m.objects);
        waiting_ = false;
        if (m.objects < kFewObjects) {
            ruleReason_ = std::to_string(m.objects) +
                          " objects: a sweep over so few costs least, whatever they do";
            return Kind::Sweep;
        }
        const bool manyRays = m.raysPerFrame >= std::max(16.0, n / 64);
        if (manyRays) {
            needSamples(m);  // the rays' length in median box sizes
        }
        if (manyRays && m.rayLength >= kLongRay) {
            ruleReason_ = std::to_string(int(m.raysPerFrame)) + " rays per frame, " +
                          shortNumber(m.rayLength) +
                          " box sizes long: the sparse cells walk rays through few cells";
            return Kind::SpatialHash;
        }
        if (m.movedPerFrame < 0.5) {
            // Before the first decision, a world that has not moved tells nothing about its
            // motion (offset-1e6's bodies start moving when their speed first reaches a float
            // step, after a few frames): the starting core stays and auto looks again 8
            // frames later.
            waiting_ = evaluations_ == 0;
            ruleReason_ = waiting_ ? "no motion yet: the start's core until something moves"
                                   : "at rest (" + shortNumber(m.movedPerFrame) +
                                         " objects moved per frame): the present core costs "
                                         "nothing";
            return kind_;
        }
        // (Without moves looked at, no move left a fat box for want of evidence: a world
        // that just grew past kFewObjects, whose moves were not sampled, is not jitter.)
        if (m.frames >= kJitterWindow && m.movedPerFrame >= 0.5 &&
            m.movesLookedAt >= kJitterLookedAt && m.fatExitsPerMove < kJitterFatExits &&
            m.pairChangesPerMove < kJitterPairChanges) {
            ruleReason_ = "resting, jittering (" + std::to_string(int(m.movedPerFrame)) +
                          " objects moved per frame; " + shortNumber(m.fatExitsPerMove) +
                          " of the moves left a fat box, " + shortNumber(m.pairChangesPerMove) +
                          " pair changes per move): the fat boxes and pair certificates hold "
                          "still where sorted endpoints would swap";
            return Kind::Grid;
        }
        if (m.movedPerFrame < 0.5 || m.relativeMotion < 0.2) {
            const std::string motion = "slow motion (" + std::to_string(int(m.movedPerFrame)) +
                                       " objects moved per frame, by " +
                                       shortNumber(m.relativeMotion) + " of their size)";
            // The crowding (a sort of the sampled centres' cells) only matters from kManySwaps
            // on: below, the sweep whatever it is.
            if (!swapsCounted_) {
                needSamples(m);  // the estimate
            }
            const bool many = m.swapsPerMove >= kManySwaps;
            if (many) {
                needSamples(m);
            }
            const double crowd = many ? crowding(m, denseCell(m, sparseCell(m))) : 0;
            const std::string swaps =
                shortNumber(m.swapsPerMove) +
                (swapsCounted_ ? " endpoints passed per moved object (counted)"
                               : " endpoints passed per moved object") +
                (many ? "; " + shortNumber(crowd) + " others in an object's grid cell" : "");
            // The first evaluation's pair changes are the world's first pairs, not motion.
            const double pairChanges = evaluations_ > 0 ? m.pairChangesPerMove : 0;
            if (many && m.swapsPerMove >= kManySwaps * (1 + crowd / 2) &&
                pairChanges < kManySwapsPairChanges) {
                ruleReason_ = motion + ", but sorted endpoints would swap much (" + swaps +
                              "): the grid's cells and fat boxes do not see the order";
                return Kind::Grid;
            }
            ruleReason_ = motion + ": sorted endpoints move few places (" + swaps + "; " +
                          shortNumber(m.pairChangesPerMove) + " pair changes per move)";
            return Kind::Sweep;
        }
        if (!swapsCounted_) {
            needSamples(m);
        }
        if (m.swapsPerMove < kFewSwapsFast) {
            ruleReason_ = "fast motion (" + shortNumber(m.relativeMotion) +
                          " of their size per frame), but sorted endpoints move few places (" +
                          shortNumber(m.swapsPerMove) + " endpoints passed per moved object" +
                          (swapsCounted_ ? ", counted" : "") +
                          "): the sweep does not care how far a box goes";
            return Kind::Sweep;
        }
        needSamples(m);
        const double sparse = sparseCell(m), dense = denseCell(m, sparse);
        const double crowdSparse = crowding(m, sparse), crowdDense = crowding(m, dense);
        if (crowdDense > 16 + 2 * crowdSparse) {
            ruleReason_ = "fast motion (" + shortNumber(m.relativeMotion) +
                          " of their size per frame), crowded: the dense grid's cells (" +
                          shortNumber(dense) + ") would put " + shortNumber(crowdDense) +
                          " others beside an object, the sparse cells (" + shortNumber(sparse) +
                          ") " + shortNumber(crowdSparse);
            return Kind::SpatialHash;
        }
        ruleReason_ = "fast motion (" + shortNumber(m.relativeMotion) +
                      " of their size per frame), spread out: one cell size fits";
        return Kind::Grid;
    }

    /// The cell edge of the sparse cores (spatial-hash), as CellGridSettings sizes it.
    double sparseCell(const SceneMeasure& m) const {
        return settings_.cells.cellSize > 0 ? settings_.cells.cellSize
                                            : settings_.cells.sizeFactor * m.medianSize;
    }
    /// The dense grid's cell edge: the sparse one, enlarged so that the sampled centres'
    /// bounds need at most its budget of cells.
    double denseCell(const SceneMeasure& m, double sparse) const {
        if (settings_.cells.cellSize > 0 || m.centres.empty() || !(sparse > 0)) {
            return sparse;
        }
        double volume = 1;
        for (int axis = 0; axis < 3; ++axis) {
            double lo = HUGE_VAL, hi = -HUGE_VAL;
            for (const auto& c : m.centres) {
                lo = std::min(lo, c[axis]);
                hi = std::max(hi, c[axis]);
            }
            volume *= std::max(hi - lo, sparse);
        }
        const double cells = std::max(1.0, std::min(settings_.cells.cellsPerObject *
                                                        double(std::max<std::size_t>(m.objects, 1)),
                                                    settings_.cells.maxCells));
        return std::max(sparse, std::cbrt(volume / cells));
    }
    /// Expected number of other objects whose centre shares an object's cell of edge `cell`,
    /// from the sampled centres, scaled to all objects.
    static double crowding(const SceneMeasure& m, double cell) {
        const std::size_t samples = m.centres.size();
        if (samples < 2 || !(cell > 0)) {
            return 0;
        }
        // A cell's three indices hashed into one word (sorting words is several times
        // faster than sorting triples; two cells share a hash with odds of about
        // samples^2 / 2^64, which would count one more sharing pair).
        std::vector<std::uint64_t> keys;
        keys.reserve(samples);
        for (const auto& c : m.centres) {
            std::uint64_t key = 0;
            for (int axis = 0; axis < 3; ++axis) {
                const auto index =
                    static_cast<long long>(std::floor(std::clamp(c[axis] / cell, -1e15, 1e15)));
                key = mix(key ^ (static_cast<std::uint64_t>(index) + std::uint64_t(axis)));
            }
            keys.push_back(key);
        }
        std::sort(keys.begin(), keys.end());
        double sharing = 0;  // ordered pairs of sampled centres in one cell
        for (std::size_t at = 0; at < samples;) {
            std::size_t end = at;
            while (end < samples && keys[end] == keys[at]) {
                ++end;
            }
            const double run = double(end - at);
            sharing += run * (run - 1);
            at = end;
        }
        const double n = double(std::max(m.objects, samples));
        return sharing / double(samples) * (n - 1) / double(samples - 1);
    }

    /// A 64-bit mixing function (splitmix64's finaliser).
    static std::uint64_t mix(std::uint64_t x) {
        x += 0x9e3779b97f4a7c15u;
        x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9u;
        x = (x ^ (x >> 27)) * 0x94d049bb133111ebu;
        return x ^ (x >> 31);
    }

    static std::string shortNumber(double x) {
        char text[32];
        std::snprintf(text, sizeof text, "%.2g", x);
        return text;
    }

    /// Calls f with the active core (const or not, as `self` is).
    template <class Self, class F>
    static void dispatchOn(Self& self, F&& f) {
        switch (self.kind_) {
            case Kind::Grid:
                f(self.grid_);
                return;
            case Kind::SpatialHash:
                f(self.hash_);
                return;
            case Kind::Sweep:
                f(self.sweep_);
                return;
        }
    }
    template <class F>
    void dispatch(F&& f) {
        dispatchOn(*this, f);
    }
    template <class F>
    void dispatch(F&& f) const {
        dispatchOn(*this, f);
    }

    Settings settings_;
    UniformGrid<D, Scalar> grid_;
    SpatialHash<D, Scalar> hash_;
    SweepAndPrune<D, Scalar> sweep_;
    Kind kind_ = Kind::Sweep;
    Kind pending_ = Kind::Sweep;
    std::string reason_ = "the start: no measure yet, the sweep";
    std::string ruleReason_;
    std::size_t evaluations_ = 0;  ///< evaluations that decided (saw motion, spread or rays)
    bool waiting_ = false;         ///< the last rule found no motion before any decision
    bool fullWindowSeen_ = false;  ///< a decision was made from a full window
    /// Core updates so far; at the last evaluation, those and the sweep's swaps; whether the
    /// last evaluation counted the swaps (the sweep ran) instead of taking the estimate.
    std::size_t updates_ = 0, updatesSeen_ = 0, swapsSeen_ = 0;
    bool swapsCounted_ = false;
    std::size_t framesSinceSwitch_ = 0;
    std::size_t switches_ = 0;
};

}  // namespace kolize

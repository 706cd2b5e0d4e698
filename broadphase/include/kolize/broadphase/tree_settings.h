#pragma once
/// \file
/// Settings of the segment-tree cores ("segment-trees", "range-tree"), with documented
/// defaults. Kept apart from the cores so that settings.h stays light.

namespace kolize {

/// How a tree core chooses its leaf width U (thesis formula 3.2: U = scene size / S).
struct CellTuning {
    /// S: the tuned scene extent 2D is cut into this many leaf cells. D is thesis formula
    /// 3.3, 1.5 x the distance of the farthest object from the origin, except that kolize
    /// ignores box centres more than twice as far as the 99th percentile of the distances,
    /// so that a few far objects do not coarsen everyone's cells. More cells: fewer false
    /// candidates, but more cell changes and deeper trees. The thesis chose 1000 (its table
    /// 2.1: 2000 marginally faster, 1000 less memory). U is tuned at the first insert and
    /// the first pair search, and again when the live count has doubled since (at an insert)
    /// or grown by a quarter (at a pair search); a changed U rebuilds the trees.
    int divisions = 1000;
    /// A fixed leaf width U > 0 instead of tuning; 0 (the default) tunes from the scene.
    double unit = 0;
};

/// Settings of SegmentTreeSet (broadphase "segment-trees").
struct SegmentTreeSettings {
    /// Leaf width: U = tuned scene extent / cells.divisions (default S = 1000, the thesis's).
    CellTuning cells;
    enum class Traversal {
        Stabbing,     ///< one stabbing path per object on the cheapest axis (default)
        ThesisFlags,  ///< the thesis's per-axis flag walk, for comparison
    };
    /// How candidate pairs are found; both give the same set. With Stabbing only the
    /// stabbing axis's tree is kept current each frame (the others catch up when chosen).
    Traversal traversal = Traversal::Stabbing;
    /// With Stabbing: keep the candidate set between frames and update it from the objects
    /// whose cell box changed, while few did (default). false: enumerate every frame.
    /// Same set either way.
    bool incremental = true;
};

/// Settings of RangeTree (broadphase "range-tree").
struct RangeTreeSettings {
    /// Leaf width: U = tuned scene extent / cells.divisions (default S = 1000, the thesis's).
    CellTuning cells;
    /// The axis of the segment tree (default 0, x, as in the thesis). The nodes' lists are
    /// sorted along the next axis (y for x).
    int treeAxis = 0;
    /// true (default): searches the sorted lists for the window of overlapping entries.
    /// false: scans the lists whole, as a segment tree would; for measuring what the
    /// sorting buys. Both give the same candidates.
    bool searchSortedLists = true;
    /// Keep the candidate set between frames and update it from the objects whose cell box
    /// changed, while few did (default). false: enumerate every frame. Same set either way.
    bool incremental = true;
};

}  // namespace kolize

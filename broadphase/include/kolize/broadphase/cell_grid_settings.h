#pragma once
/// \file
/// Settings of the cell-based broadphases (`grid`, `spatial-tree`, `spatial-hash`), kept
/// apart from the core so that kolize/broadphase/settings.h stays light.

#include <array>

namespace kolize {

/// Settings of the cell-based cores, with their defaults.
struct CellGridSettings {
    /// Cell edge. 0 (default): automatic, `sizeFactor` x the median over the objects of
    /// their box's largest extent; the dense grid enlarges it further so that its region
    /// needs at most `cellsPerObject` x N cells (and never more than `maxCells`).
    double cellSize = 0;
    /// Cell edge in median object extents for the automatic rule (default 2: a typical
    /// object covers 1 or 2 cells per axis).
    double sizeFactor = 2;
    /// Objects whose box covers more cells than this go to the overflow set (default 64).
    double maxCellsPerObject = 64;
    /// Automatic sizing is re-done (all objects re-binned) when the number of objects has
    /// doubled or halved, or their mean extent has grown or shrunk by this factor, since the
    /// last choice; and, for the dense grid, when more than 1/16 of the objects are outside
    /// its region. Default 2; 0 disables re-choosing.
    double rechooseFactor = 2;
    /// Dense grid: cells allowed per object by the automatic rule (memory budget, default 4:
    /// coarser cells re-bin less often under fast motion, measured with kolize-bench)
    /// and the hard cap on the number of cells (default 2^22, 64 MiB of cell records).
    double cellsPerObject = 4;
    double maxCells = double(1u << 22);
    /// Dense grid: a fixed region [regionMin, regionMax] (first D coordinates used); when
    /// not set (regionMin >= regionMax on some axis, the default) the region is chosen
    /// automatically: the bounds of the objects' boxes without the extreme 1/256 per side.
    std::array<double, 3> regionMin{0, 0, 0};
    std::array<double, 3> regionMax{0, 0, 0};
    /// > 0: the thesis's configuration instead of the automatic rule: the cell edge is the
    /// largest extent of the objects' bounds divided by this (thesis: 17 cells per axis, its
    /// equal-memory setting against the segment trees); for the dense grid the region is
    /// those bounds. Default 0 (off).
    int cellsPerAxis = 0;
};

}  // namespace kolize

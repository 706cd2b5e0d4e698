#pragma once
// Heap accounting for the benchmark programs: every operator new and every Bullet
// btAlignedAlloc of the process goes through a counter, so a run can report the peak
// number of bytes a broadphase held above a baseline. Linking memory_meter.cpp into a
// program replaces its global operator new / delete.

#include <cstddef>

namespace kolize::bench {

/// Routes Bullet's allocations through the counter too. Call once, before any Bullet
/// object is made.
void countBulletAllocations();

/// Bytes allocated now.
std::size_t currentBytes();

/// Starts a measurement: the peak is reset to the current level, which is the baseline.
void resetPeak();

/// Highest level since resetPeak(), minus the baseline then.
std::size_t peakBytesSinceReset();

}  // namespace kolize::bench

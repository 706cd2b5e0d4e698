#pragma once
/// \file
/// kolize: drop-in replacements for Bullet's broadphase.
///
///     #include <kolize/kolize.h>
///     auto broadphase = kolize::makeBroadphase("grid");
///     btDiscreteDynamicsWorld world(dispatcher, broadphase.get(), solver, configuration);
///
/// Bullet's own broadphases are available under the same factory for comparison.

#include <kolize/broadphase/settings.h>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace kolize {

/// Makes the broadphase called `name`. Names (see broadphaseNames()):
/// - "auto": for a scene you do not know: measures it (object count, share and speed of the
///   moving objects, cell crowding, endpoints a sorted sweep would pass, rays per frame) every
///   32 frames and uses the core that suits it (sweep, grid or spatial-hash), switching when the
///   scene changes without losing a pair (BroadphaseAdapter::coreDescription() says what it chose
///   and why).
/// - "grid": uniform grid (thesis method A): a dense array of cells over a region chosen
///   from the objects, with an overflow set for huge and outside objects. Best for
///   objects spread evenly. Settings: settings.cells.
/// - "spatial-tree": regular spatial tree (method B): only non-empty cells, in an AVL tree;
///   unbounded. Settings: settings.cells.
/// - "spatial-hash": the same sparse cells in a hash table; unbounded.
/// - "sweep": exact incremental sweep and prune: sorted box endpoints per axis, updated by
///   swaps at the pair search (one insertion pass per axis when many objects moved), so a
///   frame costs O(moved objects + endpoint swaps). Best where objects move a little each
///   frame (piles, stacks, falling and settling worlds, any sizes); box queries scan one axis
///   and rays test every object.
/// - "brute-force": kolize's exact reference (tests every pair; O(N^2) per frame).
/// - "segment-trees": the thesis's set of segment trees, one per axis (settings.segmentTrees).
/// - "range-tree": the thesis's range tree, one segment tree with sorted node lists
///   (settings.rangeTree).
/// - "dbvt": Bullet's btDbvtBroadphase.
/// - "sap": Bullet's btAxisSweep3 over settings.worldMin/worldMax, with its ray accelerator.
/// - "sap-noray": the same without the ray accelerator.
/// - "sap32": Bullet's bt32BitAxisSweep3.
/// - "simple": Bullet's btSimpleBroadphase.
/// kolize's broadphases report exactly the pairs whose AABBs overlap (closed intervals)
/// and pass the pair cache's filters; Bullet's report supersets.
/// Throws std::invalid_argument for an unknown name (the message lists the valid ones)
/// or for invalid settings.
std::unique_ptr<btBroadphaseInterface> makeBroadphase(std::string_view name,
                                                      const BroadphaseSettings& settings = {});

/// All names makeBroadphase accepts, kolize's first.
const std::vector<std::string>& broadphaseNames();

/// The names, comma separated, for messages and help texts.
std::string broadphaseNameList();

/// True for the names whose pair output is exact (kolize's own broadphases).
bool isExactBroadphase(std::string_view name);

/// The pair cache named "merged" (kolize::MergedPairCache) or "hashed" (Bullet's
/// btHashedOverlappingPairCache), for BroadphaseSettings::ownPairCache. Throws
/// std::invalid_argument for any other name.
PairCacheChoice pairCacheNamed(std::string_view name);

}  // namespace kolize

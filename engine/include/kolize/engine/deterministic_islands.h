#pragma once
/// \file
/// Simulation islands that do not depend on the pair cache's order.
///
/// Bullet's btSimulationIslandManager unites the bodies of every overlapping pair in the
/// order of the pair cache's array, which depends on the order in which the broadphase
/// added and removed pairs; the roots of the union-find, and with them the island ids and
/// the order in which the solver visits islands and joints, follow that order. So two
/// broadphases that report exactly the same pairs can still give different (each valid)
/// simulations once joints are involved, even with btDispatcherInfo::
/// m_deterministicOverlappingPairs on (which sorts the dispatch and the manifolds, not the
/// unions). DeterministicIslandManager unites the pairs in sorted order of the bodies'
/// island tags instead, when m_deterministicOverlappingPairs is on (otherwise exactly as
/// Bullet does), so the world evolves bit for bit alike over any broadphase reporting the
/// same pairs.
///
///     kolize::WithDeterministicIslands<btDiscreteDynamicsWorld> world(dispatcher, broadphase,
///                                                                    solver, configuration);
///     world.getDispatchInfo().m_deterministicOverlappingPairs = true;
///
/// Cost: one sort of the pairs that merge islands per step, O(P log P).

#include <BulletCollision/CollisionDispatch/btSimulationIslandManager.h>

#include <new>
#include <utility>
#include <vector>

namespace kolize {

class DeterministicIslandManager : public btSimulationIslandManager {
  public:
    void updateActivationState(btCollisionWorld* world, btDispatcher* dispatcher) override;

  private:
    std::vector<std::pair<int, int>> unions_;
};

/// `World` (btDiscreteDynamicsWorld or a class derived from it) with its island manager
/// replaced by a DeterministicIslandManager; constructor arguments are forwarded.
template <class World>
class WithDeterministicIslands : public World {
  public:
    template <class... Args>
    explicit WithDeterministicIslands(Args&&... args) : World(std::forward<Args>(args)...) {
        // The world owns its island manager (btAlignedAlloc + placement new, freed the same
        // way by its destructor through the virtual destructor).
        if (this->m_ownsIslandManager) {
            this->m_islandManager->~btSimulationIslandManager();
            btAlignedFree(this->m_islandManager);
        }
        void* memory = btAlignedAlloc(sizeof(DeterministicIslandManager), 16);
        this->m_islandManager = new (memory) DeterministicIslandManager();
        this->m_ownsIslandManager = true;
    }
};

}  // namespace kolize

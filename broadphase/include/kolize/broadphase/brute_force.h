#pragma once
/// \file
/// BruteForce<D>: the reference core. Every pair of live objects is a candidate; every
/// query visits every live object. O(N^2) pairs per frame, O(N) per query, no structure
/// that could be wrong. kolize's exact broadphases are tested against it, and it ships in
/// the library as the oracle (broadphase name "brute-force").

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/live_ids.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace kolize {

/// Settings of the brute-force core (it has none that change its answers).
struct BruteForceSettings {};

template <int D, class Scalar>
class BruteForce {
  public:
    using Box = Aabb<D, Scalar>;
    using Settings = BruteForceSettings;

    explicit BruteForce(const Settings& = {}) {}

    /// Adds object `id` (ids are dense; `id` must not be live).
    void insert(ObjectId id, const Box& /*box*/) { live_.insert(id); }

    /// Nothing to do: the brute-force core keeps no geometry.
    void update(ObjectId /*id*/, const Box& /*box*/) {}

    /// Removes live object `id` in O(1).
    void remove(ObjectId id) { live_.remove(id); }

    /// Nothing to tune.
    void maintain() {}

    /// Calls `candidate(a, b)` once for every unordered pair of live objects.
    template <class Sink>
    void findCandidates(Sink&& candidate) const {
        const std::vector<ObjectId>& ids = live_.ids();
        const std::size_t n = ids.size();
        for (std::size_t i = 0; i < n; ++i) {
            for (std::size_t j = i + 1; j < n; ++j) {
                candidate(ids[i], ids[j]);
            }
        }
    }

    /// Calls `visit(id)` for every live object (a superset of those overlapping `box`).
    template <class Visit>
    void queryBox(const Box& /*box*/, Visit&& visit) const {
        for (ObjectId id : live_) {
            visit(id);
        }
    }

    /// Calls `visit(id)` for every live object (a superset of those the ray reaches).
    template <class Visit>
    void queryRay(const Ray<D, Scalar>& /*ray*/, Visit&& visit) const {
        for (ObjectId id : live_) {
            visit(id);
        }
    }

    std::size_t size() const { return live_.size(); }

    /// Checks that the live list and the position index agree; throws std::logic_error.
    void validate() const { live_.validate("BruteForce"); }

    /// Bytes held by the core.
    std::size_t memoryBytes() const { return live_.memoryBytes(); }

  private:
    LiveIds live_;
};

}  // namespace kolize

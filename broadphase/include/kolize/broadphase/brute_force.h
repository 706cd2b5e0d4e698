#pragma once
/// \file
/// BruteForce<D>: the reference core. Every pair of live objects is a candidate; every
/// query visits every live object. O(N^2) pairs per frame, O(N) per query, no structure
/// that could be wrong. kolize's exact broadphases are tested against it, and it ships in
/// the library as the oracle (broadphase name "brute-force").

#include <kolize/broadphase/aabb.h>

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
    void insert(ObjectId id, const Box& /*box*/) {
        if (id >= position_.size()) {
            position_.resize(id + 1, kAbsent);
        }
        position_[id] = static_cast<std::uint32_t>(live_.size());
        live_.push_back(id);
    }

    /// Nothing to do: the brute-force core keeps no geometry.
    void update(ObjectId /*id*/, const Box& /*box*/) {}

    /// Removes live object `id` in O(1).
    void remove(ObjectId id) {
        const std::uint32_t at = position_[id];
        const ObjectId last = live_.back();
        live_[at] = last;
        position_[last] = at;
        live_.pop_back();
        position_[id] = kAbsent;
    }

    /// Calls `candidate(a, b)` once for every unordered pair of live objects.
    template <class Sink>
    void findCandidates(Sink&& candidate) const {
        const std::size_t n = live_.size();
        for (std::size_t i = 0; i < n; ++i) {
            for (std::size_t j = i + 1; j < n; ++j) {
                candidate(live_[i], live_[j]);
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
    void validate() const {
        std::size_t present = 0;
        for (std::size_t id = 0; id < position_.size(); ++id) {
            if (position_[id] == kAbsent) {
                continue;
            }
            ++present;
            if (position_[id] >= live_.size() || live_[position_[id]] != id) {
                throw std::logic_error("BruteForce: position index broken at id " +
                                       std::to_string(id));
            }
        }
        if (present != live_.size()) {
            throw std::logic_error("BruteForce: live list and index disagree");
        }
    }

    /// Bytes held by the core.
    std::size_t memoryBytes() const {
        return live_.capacity() * sizeof(ObjectId) + position_.capacity() * sizeof(std::uint32_t);
    }

  private:
    static constexpr std::uint32_t kAbsent = 0xffffffffu;
    std::vector<ObjectId> live_;
    std::vector<std::uint32_t> position_;
};

}  // namespace kolize

#pragma once
/// \file
/// LiveIds: the set of live object ids of a core, as a dense list (for iteration) with a
/// position index (for O(1) removal by swapping with the last).

#include <kolize/broadphase/aabb.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace kolize {

class LiveIds {
  public:
    /// Adds `id` (must not be live).
    void insert(ObjectId id) {
        if (id >= position_.size()) {
            position_.resize(id + 1, kAbsent);
        }
        position_[id] = static_cast<std::uint32_t>(ids_.size());
        ids_.push_back(id);
    }
    /// Removes live `id` in O(1); the last id takes its place in the list.
    void remove(ObjectId id) {
        const std::uint32_t at = position_[id];
        const ObjectId last = ids_.back();
        ids_[at] = last;
        position_[last] = at;
        ids_.pop_back();
        position_[id] = kAbsent;
    }
    bool contains(ObjectId id) const { return id < position_.size() && position_[id] != kAbsent; }
    std::size_t size() const { return ids_.size(); }
    bool empty() const { return ids_.empty(); }
    const std::vector<ObjectId>& ids() const { return ids_; }
    std::vector<ObjectId>::const_iterator begin() const { return ids_.begin(); }
    std::vector<ObjectId>::const_iterator end() const { return ids_.end(); }

    /// Checks that list and index agree; throws std::logic_error naming `owner`.
    void validate(const std::string& owner) const {
        std::size_t present = 0;
        for (std::size_t id = 0; id < position_.size(); ++id) {
            if (position_[id] == kAbsent) {
                continue;
            }
            ++present;
            if (position_[id] >= ids_.size() || ids_[position_[id]] != id) {
                throw std::logic_error(owner + ": live list broken at id " + std::to_string(id));
            }
        }
        if (present != ids_.size()) {
            throw std::logic_error(owner + ": live list and index disagree");
        }
    }
    std::size_t memoryBytes() const {
        return (ids_.capacity() + position_.capacity()) * sizeof(std::uint32_t);
    }

  private:
    static constexpr std::uint32_t kAbsent = 0xffffffffu;
    std::vector<ObjectId> ids_;
    std::vector<std::uint32_t> position_;
};

}  // namespace kolize

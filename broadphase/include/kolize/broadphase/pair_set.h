#pragma once
/// \file
/// PairSet: the set of overlapping pairs found in the previous frame, with a per-pair
/// frame stamp, so that each frame only the difference reaches Bullet's pair cache.
///
/// Open addressing with linear probing; removal by backward shift (no tombstones), so the
/// table never degrades however many pairs come and go. Expected O(1) per operation.

#include <kolize/broadphase/aabb.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

namespace kolize {

class PairSet {
  public:
    /// One stored pair. `first < second` always.
    struct Entry {
        std::uint64_t key = kEmpty;
        std::uint32_t stamp = 0;
        /// Whether the pair is currently in Bullet's pair cache (the filters let it in).
        bool inCache = false;

        ObjectId first() const { return static_cast<ObjectId>(key >> 32); }
        ObjectId second() const { return static_cast<ObjectId>(key & 0xffffffffu); }
    };

    static std::uint64_t keyOf(ObjectId a, ObjectId b) {
        return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
    }

    /// Finds the pair or inserts it with stamp 0; `inserted` tells which. The reference is
    /// valid until the next insertion or sweep.
    Entry& findOrInsert(ObjectId a, ObjectId b, bool& inserted) {
        if ((size_ + 1) * 4 > table_.size() * 3) {
            grow();
        }
        const std::uint64_t key = keyOf(a, b);
        std::size_t at = slotOf(key);
        while (table_[at].key != kEmpty) {
            if (table_[at].key == key) {
                inserted = false;
                return table_[at];
            }
            at = (at + 1) & mask_;
        }
        table_[at] = Entry{key, 0, false};
        ++size_;
        inserted = true;
        return table_[at];
    }

    /// Removes every entry for which `keep(entry)` returns false. `keep` may inspect and
    /// modify the entry (e.g. clear its inCache flag) but must not touch the set.
    template <class Keep>
    void retainIf(Keep&& keep) {
        if (size_ == 0) {
            return;
        }
        // Start right after an empty slot: backward shifts then never move an entry across
        // the starting point, so every entry is examined exactly once.
        std::size_t start = 0;
        while (table_[start].key != kEmpty) {
            ++start;
        }
        std::size_t at = (start + 1) & mask_;
        for (std::size_t steps = 0; steps < table_.size();) {
            if (table_[at].key != kEmpty && !keep(table_[at])) {
                // A later entry of the cluster may shift into this slot: stay and look again.
                eraseAt(at);
                continue;
            }
            at = (at + 1) & mask_;
            ++steps;
        }
    }

    template <class Visit>
    void forEach(Visit&& visit) const {
        for (const Entry& entry : table_) {
            if (entry.key != kEmpty) {
                visit(entry);
            }
        }
    }

    std::size_t size() const { return size_; }
    void clear() {
        table_.assign(table_.size(), Entry{});
        size_ = 0;
    }
    std::size_t memoryBytes() const { return table_.capacity() * sizeof(Entry); }

    /// Checks that every entry is reachable from its home slot; throws std::logic_error.
    void validate() const {
        std::size_t count = 0;
        for (std::size_t i = 0; i < table_.size(); ++i) {
            if (table_[i].key == kEmpty) {
                continue;
            }
            ++count;
            if (table_[i].first() >= table_[i].second()) {
                throw std::logic_error("PairSet: pair not ordered");
            }
            for (std::size_t at = slotOf(table_[i].key); at != i; at = (at + 1) & mask_) {
                if (table_[at].key == kEmpty) {
                    throw std::logic_error("PairSet: entry unreachable from its home slot");
                }
            }
        }
        if (count != size_) {
            throw std::logic_error("PairSet: size disagrees with the table");
        }
    }

  private:
    static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);

    std::size_t slotOf(std::uint64_t key) const {
        // A 64-bit mix (splitmix64's finaliser) spreads neighbouring ids over the table.
        key ^= key >> 30;
        key *= 0xbf58476d1ce4e5b9ull;
        key ^= key >> 27;
        key *= 0x94d049bb133111ebull;
        key ^= key >> 31;
        return static_cast<std::size_t>(key) & mask_;
    }

    void eraseAt(std::size_t hole) {
        std::size_t next = (hole + 1) & mask_;
        while (table_[next].key != kEmpty) {
            const std::size_t home = slotOf(table_[next].key);
            // Move `next` into the hole unless its home lies cyclically in (hole, next].
            const bool homeBetween =
                hole <= next ? (home > hole && home <= next) : (home > hole || home <= next);
            if (!homeBetween) {
                table_[hole] = table_[next];
                hole = next;
            }
            next = (next + 1) & mask_;
        }
        table_[hole] = Entry{};
        --size_;
    }

    void grow() {
        std::vector<Entry> old;
        old.swap(table_);
        table_.assign(old.empty() ? 64 : old.size() * 2, Entry{});
        mask_ = table_.size() - 1;
        size_ = 0;
        for (const Entry& entry : old) {
            if (entry.key == kEmpty) {
                continue;
            }
            std::size_t at = slotOf(entry.key);
            while (table_[at].key != kEmpty) {
                at = (at + 1) & mask_;
            }
            table_[at] = entry;
            ++size_;
        }
    }

    std::vector<Entry> table_;
    std::size_t mask_ = 0;
    std::size_t size_ = 0;
};

}  // namespace kolize

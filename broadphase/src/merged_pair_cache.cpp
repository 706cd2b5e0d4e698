#include <kolize/broadphase/merged_pair_cache.h>

#include <BulletCollision/BroadphaseCollision/btCollisionAlgorithm.h>
#include <BulletCollision/BroadphaseCollision/btDispatcher.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

namespace kolize {

namespace {

std::uint32_t biased(int uid) {
    return static_cast<std::uint32_t>(uid) ^ 0x80000000u;
}

/// What cleanOverlappingPair does, as Bullet's caches do it.
void freeAlgorithm(btBroadphasePair& pair, btDispatcher* dispatcher) {
    if (pair.m_algorithm != nullptr && dispatcher != nullptr) {
        pair.m_algorithm->~btCollisionAlgorithm();
        dispatcher->freeCollisionAlgorithm(pair.m_algorithm);
        pair.m_algorithm = nullptr;
    }
}

bool contains(const btBroadphasePair& pair, const btBroadphaseProxy* proxy) {
    return pair.m_pProxy0 == proxy || pair.m_pProxy1 == proxy;
}

}  // namespace

void MergedPairCache::sortByKey(std::vector<Order>& order, std::vector<Order>& scratch) {
    // LSD radix sort, 11 bits a pass: stable, so one key's changes keep the order they were
    // made in. Digits on which all keys agree (most of a uid's high bits) are skipped.
    constexpr int kBits = 11;
    constexpr std::uint64_t kMask = (1u << kBits) - 1;
    std::uint64_t differ = 0;
    for (const Order& entry : order) {
        differ |= entry.key ^ order.front().key;
    }
    scratch.resize(order.size());
    std::vector<std::size_t> start(std::size_t(1) << kBits);
    for (int shift = 0; shift < 64; shift += kBits) {
        if (((differ >> shift) & kMask) == 0) {
            continue;
        }
        std::fill(start.begin(), start.end(), 0);
        for (const Order& entry : order) {
            ++start[(entry.key >> shift) & kMask];
        }
        std::size_t sum = 0;
        for (std::size_t& count : start) {
            const std::size_t here = count;
            count = sum;
            sum += here;
        }
        for (const Order& entry : order) {
            scratch[start[(entry.key >> shift) & kMask]++] = entry;
        }
        order.swap(scratch);
    }
}

std::uint64_t MergedPairCache::keyOf(const btBroadphaseProxy* proxy0,
                                     const btBroadphaseProxy* proxy1) {
    const int a = proxy0->m_uniqueId, b = proxy1->m_uniqueId;
    const int lo = a < b ? a : b, hi = a < b ? b : a;
    return (std::uint64_t(biased(lo)) << 32) | biased(hi);
}

int MergedPairCache::indexOf(std::uint64_t key) const {
    const auto it = std::lower_bound(keys_.begin(), keys_.end(), key);
    return it != keys_.end() && *it == key ? static_cast<int>(it - keys_.begin()) : -1;
}

bool MergedPairCache::needsBroadphaseCollision(btBroadphaseProxy* proxy0,
                                               btBroadphaseProxy* proxy1) const {
    if (filter_ != nullptr) {
        return filter_->needBroadphaseCollision(proxy0, proxy1);
    }
    return (proxy0->m_collisionFilterGroup & proxy1->m_collisionFilterMask) != 0 &&
           (proxy1->m_collisionFilterGroup & proxy0->m_collisionFilterMask) != 0;
}

btBroadphasePair* MergedPairCache::addOverlappingPair(btBroadphaseProxy* proxy0,
                                                      btBroadphaseProxy* proxy1) {
    if (!needsBroadphaseCollision(proxy0, proxy1)) {
        return nullptr;
    }
    flushTrustedChanges();
    const std::uint64_t key = keyOf(proxy0, proxy1);
    const btBroadphasePair fresh(*proxy0, *proxy1);
    const int at = indexOf(key);
    if (at >= 0) {
        btBroadphasePair& pair = pairs_[at];
        if (isHole(pair)) {  // removed since the last flush: it comes back as a new pair
            pair = fresh;    // still listed in holes_: the flush skips it
            --tombstones_;
            ++count_;
            if (ghost_ != nullptr) {
                ghost_->addOverlappingPair(fresh.m_pProxy0, fresh.m_pProxy1);
                return findPair(proxy0, proxy1);  // the callback may have changed the cache
            }
        }
        return &pairs_[at];
    }
    const auto waiting = addedIndex_.find(key);
    if (waiting != addedIndex_.end()) {
        return &added_[waiting->second].pair;
    }
    addedIndex_.emplace(key, static_cast<std::uint32_t>(added_.size()));
    added_.push_back(Waiting{key, fresh});
    ++count_;
    if (ghost_ != nullptr) {
        ghost_->addOverlappingPair(fresh.m_pProxy0, fresh.m_pProxy1);
        return findPair(proxy0, proxy1);  // the callback may have changed the cache
    }
    return &added_.back().pair;
}

void MergedPairCache::removeAt(int at, btDispatcher* dispatcher) {
    btBroadphasePair& pair = pairs_[at];
    freeAlgorithm(pair, dispatcher);
    btBroadphaseProxy* proxy0 = pair.m_pProxy0;
    btBroadphaseProxy* proxy1 = pair.m_pProxy1;
    pair.m_pProxy0 = nullptr;
    pair.m_pProxy1 = nullptr;
    holes_.push_back(std::size_t(at));
    ++tombstones_;
    --count_;
    if (ghost_ != nullptr) {
        ghost_->removeOverlappingPair(proxy0, proxy1, dispatcher);
    }
}

void* MergedPairCache::removeOverlappingPair(btBroadphaseProxy* proxy0, btBroadphaseProxy* proxy1,
                                             btDispatcher* dispatcher) {
    flushTrustedChanges();
    const std::uint64_t key = keyOf(proxy0, proxy1);
    const int at = indexOf(key);
    if (at >= 0 && !isHole(pairs_[at])) {
        void* info = pairs_[at].m_internalInfo1;
        removeAt(at, dispatcher);
        return info;
    }
    const auto waiting = addedIndex_.find(key);
    if (waiting == addedIndex_.end()) {
        return nullptr;
    }
    btBroadphasePair& pair = added_[waiting->second].pair;
    addedIndex_.erase(waiting);
    freeAlgorithm(pair, dispatcher);
    void* info = pair.m_internalInfo1;
    btBroadphaseProxy* first = pair.m_pProxy0;
    btBroadphaseProxy* second = pair.m_pProxy1;
    pair.m_pProxy0 = nullptr;
    pair.m_pProxy1 = nullptr;
    --count_;
    if (ghost_ != nullptr) {
        ghost_->removeOverlappingPair(first, second, dispatcher);
    }
    return info;
}

btBroadphasePair* MergedPairCache::addAbsentPair(btBroadphaseProxy* proxy0,
                                                 btBroadphaseProxy* proxy1) {
    standIn_ = btBroadphasePair(*proxy0, *proxy1);
    changes_.push_back(
        Change{keyOf(proxy0, proxy1), standIn_.m_pProxy0, standIn_.m_pProxy1, nullptr, true});
    ++count_;
    if (ghost_ != nullptr) {
        ghost_->addOverlappingPair(standIn_.m_pProxy0, standIn_.m_pProxy1);
    }
    return &standIn_;
}

void MergedPairCache::removePresentPair(btBroadphaseProxy* proxy0, btBroadphaseProxy* proxy1,
                                        btDispatcher* dispatcher) {
    const btBroadphasePair pair(*proxy0, *proxy1);
    changes_.push_back(
        Change{keyOf(proxy0, proxy1), pair.m_pProxy0, pair.m_pProxy1, dispatcher, false});
    --count_;
    if (ghost_ != nullptr) {
        ghost_->removeOverlappingPair(pair.m_pProxy0, pair.m_pProxy1, dispatcher);
    }
}

void MergedPairCache::flush() const {
    if (walking_ > 0 || (changes_.empty() && added_.empty() && tombstones_ == 0)) {
        return;
    }
    // The changes in key order: changes_ itself when it came sorted and nothing waits
    // (a full search's changes), else order_.
    const bool direct = added_.empty() && std::is_sorted(changes_.begin(), changes_.end(),
                                                         [](const Change& a, const Change& b) {
                                                             return a.key < b.key;
                                                         });
    if (!direct) {
        sortChanges();
    }
    const std::size_t m = direct ? changes_.size() : order_.size();
    auto keyAt = [&](std::size_t j) { return direct ? changes_[j].key : order_[j].key; };
    auto indexAt = [&](std::size_t j) { return direct ? j : std::size_t(order_[j].index); };
    // 1. Each key's changes, applied in the order made: a pair in the array is replaced or
    // becomes a hole in place; a new one is listed for insertion.
    inserts_.clear();
    const std::size_t n = keys_.size();
    std::size_t at = 0;
    for (std::size_t j = 0; j < m;) {
        const std::uint64_t key = keyAt(j);
        at = gallop(at, key);
        const bool inArray = at < n && keys_[at] == key;
        bool present = inArray && !isHole(pairs_[int(at)]);
        btBroadphasePair pair = inArray ? pairs_[int(at)] : btBroadphasePair();
        for (; j < m && keyAt(j) == key; ++j) {
            const std::size_t index = indexAt(j);
            if (index < added_.size()) {  // a waiting add (never of a pair in the array)
                if (!present) {
                    pair = added_[index].pair;
                    present = true;
                }
                continue;
            }
            const Change& change = changes_[index - added_.size()];
            if (change.add && !present) {
                pair = btBroadphasePair();
                pair.m_pProxy0 = change.proxy0;
                pair.m_pProxy1 = change.proxy1;
                present = true;
            } else if (!change.add && present) {
                freeAlgorithm(pair, change.dispatcher);
                present = false;
            }
        }
        if (inArray) {
            if (!present && !isHole(pairs_[int(at)])) {
                holes_.push_back(at);
            }
            if (!present) {
                pair.m_pProxy0 = pair.m_pProxy1 = nullptr;
            }
            pairs_[int(at)] = pair;  // a hole revived stays in holes_: skipped below
        } else if (present) {
            inserts_.push_back(Insert{at, key, pair});
        }
    }
    // 2. Holes out, moving the runs between them down. An insert's place shifts down by
    // the holes before it.
    std::sort(holes_.begin(), holes_.end());
    std::size_t write = n, removed = 0, hole = 0, insert = 0;
    for (std::size_t h = 0; h < holes_.size(); ++h) {
        const std::size_t index = holes_[h];
        if ((h > 0 && index == holes_[h - 1]) || !isHole(pairs_[int(index)])) {
            continue;  // listed twice, or revived
        }
        for (; insert < inserts_.size() && inserts_[insert].at <= index; ++insert) {
            inserts_[insert].at -= removed;
        }
        if (removed == 0) {
            write = index;
        } else {
            moveRun(hole + 1, index, write);
            write += index - hole - 1;
        }
        hole = index;
        ++removed;
    }
    if (removed > 0) {
        moveRun(hole + 1, n, write);
        for (; insert < inserts_.size(); ++insert) {
            inserts_[insert].at -= removed;
        }
    }
    std::size_t size = n - removed;
    // 3. Inserts in, from the last, moving the runs between them up.
    const std::size_t grown = size + inserts_.size();
    keys_.resize(std::max(size, grown));
    pairs_.resize(int(std::max(size, grown)));
    std::size_t end = size;
    for (std::size_t k = inserts_.size(); k-- > 0;) {
        const Insert& entry = inserts_[k];
        moveRun(entry.at, end, entry.at + k + 1);  // [at, end) goes up past k + 1 inserts
        keys_[entry.at + k] = entry.key;
        pairs_[int(entry.at + k)] = entry.pair;
        end = entry.at;
    }
    size = grown;
    holes_.clear();
    added_.clear();
    addedIndex_.clear();
    changes_.clear();
    tombstones_ = 0;
    count_ = size;
}

void MergedPairCache::sortChanges() const {
    // In key order; among one key's changes, in the order made (the waiting adds came
    // before every trusted change).
    order_.clear();
    for (std::size_t i = 0; i < added_.size(); ++i) {
        if (!isHole(added_[i].pair)) {
            order_.push_back(Order{added_[i].key, static_cast<std::uint32_t>(i)});
        }
    }
    for (std::size_t i = 0; i < changes_.size(); ++i) {
        order_.push_back(Order{changes_[i].key, static_cast<std::uint32_t>(added_.size() + i)});
    }
    auto before = [](const Order& a, const Order& b) {
        return a.key < b.key || (a.key == b.key && a.index < b.index);
    };
    if (!std::is_sorted(order_.begin(), order_.end(), before)) {
        if (order_.size() < 4096) {
            std::sort(order_.begin(), order_.end(), before);
        } else {
            sortByKey(order_, orderScratch_);
        }
    }
}

std::size_t MergedPairCache::gallop(std::size_t from, std::uint64_t key) const {
    // Doubling steps, then a binary search: dense changes cost O(1) each, sparse ones
    // O(log distance).
    const std::size_t n = keys_.size();
    std::size_t step = 1, lo = from;
    while (lo + step < n && keys_[lo + step] < key) {
        lo += step;
        step *= 2;
    }
    const std::size_t hi = std::min(n, lo + step + 1);
    return static_cast<std::size_t>(std::lower_bound(keys_.begin() + std::ptrdiff_t(lo),
                                                     keys_.begin() + std::ptrdiff_t(hi), key) -
                                    keys_.begin());
}

void MergedPairCache::moveRun(std::size_t from, std::size_t to, std::size_t dest) const {
    if (from >= to || from == dest) {
        return;
    }
    const std::size_t count = to - from;
    std::memmove(static_cast<void*>(keys_.data() + dest), keys_.data() + from,
                 count * sizeof(std::uint64_t));
    std::memmove(static_cast<void*>(&pairs_[int(dest)]),
                 static_cast<const void*>(&pairs_[int(from)]), count * sizeof(btBroadphasePair));
}

btBroadphasePair* MergedPairCache::getOverlappingPairArrayPtr() {
    flush();
    return pairs_.size() == 0 ? nullptr : &pairs_[0];
}

const btBroadphasePair* MergedPairCache::getOverlappingPairArrayPtr() const {
    flush();
    return pairs_.size() == 0 ? nullptr : &pairs_[0];
}

btBroadphasePairArray& MergedPairCache::getOverlappingPairArray() {
    flush();
    return pairs_;
}

void MergedPairCache::cleanOverlappingPair(btBroadphasePair& pair, btDispatcher* dispatcher) {
    freeAlgorithm(pair, dispatcher);
}

void MergedPairCache::cleanProxyFromPairs(btBroadphaseProxy* proxy, btDispatcher* dispatcher) {
    flush();
    for (int at = 0; at < pairs_.size(); ++at) {
        if (contains(pairs_[at], proxy)) {
            cleanOverlappingPair(pairs_[at], dispatcher);
        }
    }
}

void MergedPairCache::removeOverlappingPairsContainingProxy(btBroadphaseProxy* proxy,
                                                            btDispatcher* dispatcher) {
    flush();
    ++walking_;
    for (int at = 0; at < pairs_.size(); ++at) {
        if (contains(pairs_[at], proxy)) {
            removeAt(at, dispatcher);
        }
    }
    --walking_;
    // A waiting pair of the proxy (added by a ghost callback meanwhile) goes too.
    for (std::size_t k = 0; k < added_.size(); ++k) {
        const btBroadphasePair pair = added_[k].pair;
        if (contains(pair, proxy)) {
            removeOverlappingPair(pair.m_pProxy0, pair.m_pProxy1, dispatcher);
        }
    }
    flush();
}

void MergedPairCache::visitAll(btOverlapCallback* callback, btDispatcher* dispatcher) {
    flush();
    ++walking_;
    for (int at = pairs_.size() - 1; at >= 0; --at) {
        if (!isHole(pairs_[at]) && callback->processOverlap(pairs_[at])) {
            removeAt(at, dispatcher);
        }
    }
    --walking_;
    if (tombstones_ > 0) {
        flush();
    }
}

void MergedPairCache::processAllOverlappingPairs(btOverlapCallback* callback,
                                                 btDispatcher* dispatcher) {
    visitAll(callback, dispatcher);
}

void MergedPairCache::processAllOverlappingPairs(btOverlapCallback* callback,
                                                 btDispatcher* dispatcher,
                                                 const btDispatcherInfo& /*dispatchInfo*/) {
    visitAll(callback, dispatcher);
}

btBroadphasePair* MergedPairCache::findPair(btBroadphaseProxy* proxy0, btBroadphaseProxy* proxy1) {
    flushTrustedChanges();
    const std::uint64_t key = keyOf(proxy0, proxy1);
    const int at = indexOf(key);
    if (at >= 0) {
        return isHole(pairs_[at]) ? nullptr : &pairs_[at];
    }
    const auto waiting = addedIndex_.find(key);
    return waiting == addedIndex_.end() ? nullptr : &added_[waiting->second].pair;
}

void MergedPairCache::validate() const {
    auto fail = [](const std::string& what) {
        throw std::logic_error("kolize MergedPairCache: " + what);
    };
    if (keys_.size() != std::size_t(pairs_.size())) {
        fail("keys and pairs differ in length");
    }
    std::size_t holes = 0;
    for (std::size_t at = 0; at < keys_.size(); ++at) {
        if (at > 0 && !(keys_[at - 1] < keys_[at])) {
            fail("keys not strictly ascending at " + std::to_string(at));
        }
        const btBroadphasePair& pair = pairs_[static_cast<int>(at)];
        if (isHole(pair)) {
            ++holes;
            continue;
        }
        if (pair.m_pProxy1 == nullptr || keyOf(pair.m_pProxy0, pair.m_pProxy1) != keys_[at] ||
            pair.m_pProxy0->m_uniqueId > pair.m_pProxy1->m_uniqueId) {
            fail("pair " + std::to_string(at) + " does not match its key");
        }
    }
    if (holes != tombstones_) {
        fail("hole count " + std::to_string(holes) + ", recorded " + std::to_string(tombstones_));
    }
    if (changes_.empty() && added_.empty() && count_ != keys_.size() - holes) {
        fail("count " + std::to_string(count_) + " but " + std::to_string(keys_.size() - holes) +
             " pairs");
    }
}

}  // namespace kolize

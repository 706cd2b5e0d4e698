#include "broadphase_fuzz.h"

#include <kolize/broadphase/bullet_adapter.h>
#include <kolize/kolize.h>

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <LinearMath/btAabbUtil2.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

namespace kolize::fuzz {

namespace {

using Key = std::pair<int, int>;

Key keyOf(int a, int b) {
    return a < b ? Key{a, b} : Key{b, a};
}

// ---------------------------------------------------------------------------------------
// The generator
// ---------------------------------------------------------------------------------------

class Generator {
  public:
    Generator(std::uint32_t seed, int objects) : random_(seed), target_(objects) {}

    std::vector<Op> program(std::size_t count) {
        std::vector<Op> out;
        while (out.size() < count) {
            out.push_back(next(int(out.size())));
        }
        return out;
    }

  private:
    double uniform(double lo, double hi) {
        return std::uniform_real_distribution<double>(lo, hi)(random_);
    }
    int pick(int count) { return std::uniform_int_distribution<int>(0, count - 1)(random_); }
    btVector3 vec(double x, double y, double z) {
        return btVector3(btScalar(x), btScalar(y), btScalar(z));
    }

    /// A box: mostly ordinary, plus the kinds that break broadphases.
    void box(btVector3& lo, btVector3& hi, bool allowBad) {
        const int kind = pick(100);
        btVector3 centre = vec(uniform(-30, 30), uniform(-30, 30), uniform(-30, 30));
        btVector3 half = vec(uniform(0.2, 3), uniform(0.2, 3), uniform(0.2, 3));
        if (kind < 10 && !boxes_.empty()) {  // touching an existing box face to face
            const auto& other = boxes_[std::size_t(pick(int(boxes_.size())))];
            const int axis = pick(3);
            lo = other.first;
            hi = other.second;
            const btScalar size = btScalar(uniform(0.2, 2));
            lo[axis] = other.second[axis];
            hi[axis] = other.second[axis] + size;
            return;
        }
        if (kind < 16) {  // zero extent on some axes
            for (int axis = 0; axis < 3; ++axis) {
                if (pick(2) == 0) {
                    half[axis] = 0;
                }
            }
        } else if (kind < 19) {  // huge
            half = vec(uniform(20, 100), uniform(20, 100), uniform(20, 100));
        } else if (kind < 21 && planes_ < 2) {  // a static plane's box
            ++planes_;
            const btScalar p = btScalar(1e18);
            lo = btVector3(-p, -p, -p);
            hi = btVector3(p, p, p);
            return;
        } else if (kind < 28) {  // far outside any initial bounds
            const double far = std::pow(10.0, uniform(4, 12));
            centre = vec(far * (pick(2) ? 1 : -1), uniform(-1e3, 1e3), far);
            half *= btScalar(far * 1e-6 + 1);
        } else if (allowBad && kind < 31) {  // nonsense
            lo = centre - half;
            hi = centre + half;
            const int axis = pick(3);
            switch (pick(3)) {
                case 0:
                    lo[axis] = std::numeric_limits<btScalar>::quiet_NaN();
                    break;
                case 1:
                    hi[axis] = std::numeric_limits<btScalar>::infinity();
                    break;
                default:
                    std::swap(lo[axis], hi[axis]);
                    lo[axis] += 1;
                    break;
            }
            return;
        }
        lo = centre - half;
        hi = centre + half;
    }

    int liveTarget() { return live_.empty() ? -1 : live_[std::size_t(pick(int(live_.size())))]; }

    Op next(int index) {
        Op op;
        const int roll = pick(1000);
        const int live = int(live_.size());
        if (live < target_ / 2 || (roll < 80 && live < 2 * target_)) {
            op.kind = Op::Kind::Create;
            op.id = index;
            box(op.lo, op.hi, true);
            op.group = 1 << pick(3);
            op.mask = pick(4) == 0 ? (0x7 & ~op.group) : -1;
            live_.push_back(index);
            if (std::isfinite(op.lo.x()) && op.lo.x() <= op.hi.x()) {
                boxes_.emplace_back(op.lo, op.hi);
            }
            return op;
        }
        if (roll < 140) {
            op.kind = Op::Kind::Destroy;
            op.id = liveTarget();
            live_.erase(std::find(live_.begin(), live_.end(), op.id));
            return op;
        }
        if (roll < 560) {
            op.kind = Op::Kind::Move;
            op.id = liveTarget();
            const int how = pick(10);
            if (how < 7) {  // small moves and jitter, from a fresh random base
                btVector3 lo, hi;
                box(lo, hi, false);
                const btScalar step = btScalar(how < 3 ? 1e-4 : 0.3);
                const btVector3 shift = vec(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) * step;
                op.lo = lo + shift;
                op.hi = hi + shift;
                op.other = 1;  // a move relative to the object's box (resolved at run time)
                op.lo2 = shift;
            } else {
                box(op.lo, op.hi, true);  // teleport, maybe to nonsense
            }
            return op;
        }
        if (roll < 590) {
            op.kind = Op::Kind::SetFilter;
            op.id = liveTarget();
            op.group = 1 << pick(3);
            op.mask = pick(3) == 0 ? (0x7 & ~op.group) : -1;
            return op;
        }
        if (roll < 610) {
            op.kind = Op::Kind::Refresh;
            op.id = liveTarget();
            op.group = 1 << pick(3);
            op.mask = pick(3) == 0 ? (0x7 & ~op.group) : -1;
            return op;
        }
        if (roll < 740) {
            op.kind = Op::Kind::Search;
            return op;
        }
        if (roll < 960) {
            op.kind = roll < 850 ? Op::Kind::AabbQuery : Op::Kind::RayQuery;
            if (op.kind == Op::Kind::AabbQuery) {
                const int how = pick(20);
                if (how == 0) {
                    const btScalar big = btScalar(how == 0 && pick(2) ? 1e30 : 3e38);
                    op.lo = btVector3(-big, -big, -big);
                    op.hi = btVector3(big, big, big);
                } else {
                    box(op.lo, op.hi, true);
                    if (how < 3) {
                        op.hi *= 4;  // larger queries
                    }
                }
            } else {
                btVector3 from, to, unused;
                box(from, unused, false);
                box(to, unused, false);
                if (pick(4) == 0) {  // from far away
                    const btVector3 direction = (to - from).normalized();
                    from = to - direction * btScalar(std::pow(10.0, uniform(3, 12)));
                }
                op.lo = from;
                op.hi = pick(30) == 0 ? from : to;
                if (pick(3) == 0) {
                    op.expandHi = vec(uniform(0, 2), uniform(0, 2), uniform(0, 2));
                    op.expandLo = -op.expandHi;
                    if (pick(10) == 0) {
                        std::swap(op.expandLo, op.expandHi);  // inverted: nonsense
                    }
                }
            }
            if (pick(3) == 0) {
                op.action = Op::Action(1 + pick(5));
                op.actionAt = pick(4);
                op.id2 = index;  // CreateOne's new object
                op.other = liveTarget();
                box(op.lo2, op.hi2, false);
                if (op.action == Op::Action::CreateOne) {
                    live_.push_back(index);
                }
            }
            return op;
        }
        if (roll < 980) {
            op.kind = Op::Kind::RemovePair;
            op.id = liveTarget();
            op.other = liveTarget();
            return op;
        }
        if (roll < 995) {
            op.kind = Op::Kind::RemoveAllOf;
            op.id = liveTarget();
            return op;
        }
        op.kind = Op::Kind::ResetPool;
        live_.clear();
        planes_ = 0;
        return op;
    }

    std::mt19937 random_;
    int target_;
    std::vector<int> live_;
    std::vector<std::pair<btVector3, btVector3>> boxes_;
    int planes_ = 0;
};

// ---------------------------------------------------------------------------------------
// The model and the runner
// ---------------------------------------------------------------------------------------

/// A query box is empty when inverted or NaN on some axis; infinite bounds are fine.
bool usableQuery(const btVector3& lo, const btVector3& hi) {
    for (int axis = 0; axis < 3; ++axis) {
        if (!(lo[axis] <= hi[axis])) {
            return false;
        }
    }
    return true;
}

/// A box a proxy may have: finite and ordered (else the broadphase rejects it).
bool goodBox(const btVector3& lo, const btVector3& hi) {
    for (int axis = 0; axis < 3; ++axis) {
        if (!(std::isfinite(lo[axis]) && std::isfinite(hi[axis]) && lo[axis] <= hi[axis])) {
            return false;
        }
    }
    return true;
}

/// Installed like btGhostPairCallback: every add and remove the cache makes, once.
class Recorder : public btOverlappingPairCallback {
  public:
    btBroadphasePair* addOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b) override {
        if (!pairs.insert(order(a, b)).second) {
            ++duplicateAdds;
        }
        return nullptr;
    }
    void* removeOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b,
                                btDispatcher*) override {
        if (pairs.erase(order(a, b)) == 0) {
            ++unknownRemoves;
        }
        return nullptr;
    }
    void removeOverlappingPairsContainingProxy(btBroadphaseProxy* proxy, btDispatcher*) override {
        for (auto it = pairs.begin(); it != pairs.end();) {
            it = (it->first == proxy || it->second == proxy) ? pairs.erase(it) : std::next(it);
        }
    }
    static std::pair<const void*, const void*> order(const void* a, const void* b) {
        return a < b ? std::make_pair(a, b) : std::make_pair(b, a);
    }
    std::set<std::pair<const void*, const void*>> pairs;
    int duplicateAdds = 0, unknownRemoves = 0;
};

class Runner {
  public:
    Runner(const std::string& name, BroadphaseSettings settings)
        : name_(name), everyFrame_(settings.filters == FilterEvaluation::EveryFrame) {
        settings.onBadAabb = [](const BadAabbReport&) {};  // nonsense on purpose: no prints
        broadphase_ = makeBroadphase(name, settings);
        adapter_ = dynamic_cast<BroadphaseAdapter*>(broadphase_.get());
        cache_ = broadphase_->getOverlappingPairCache();
        cache_->setInternalGhostPairCallback(&recorder_);
    }
    ~Runner() {
        for (auto& entry : objects_) {
            if (entry.second.proxy != nullptr) {
                try {
                    broadphase_->destroyProxy(entry.second.proxy, nullptr);
                } catch (...) {
                }
            }
        }
    }

    Result execute(const std::vector<Op>& program) {
        for (std::size_t i = 0; i < program.size() && !result_.failed; ++i) {
            at_ = i;
            try {
                apply(program[i]);
            } catch (const std::exception& error) {
                fail(std::string("exception: ") + error.what());
            }
        }
        return result_;
    }

  private:
    struct Object {
        btBroadphaseProxy* proxy = nullptr;
        bool parked = false;  ///< created with a bad box, waiting for a valid one
        btVector3 lo, hi;
        int group = 1, mask = -1;
    };

    void fail(const std::string& what) {
        if (!result_.failed) {
            result_.failed = true;
            result_.failure = name_ + ", operation " + std::to_string(at_) + ": " + what;
            result_.failedAt = at_;
        }
    }

    Object* find(int id) {
        const auto it = objects_.find(id);
        return it == objects_.end() ? nullptr : &it->second;
    }
    int idOf(const btBroadphaseProxy* proxy) const {
        const auto it = byProxy_.find(proxy);
        return it == byProxy_.end() ? -1 : it->second;
    }

    void create(int id, const btVector3& lo, const btVector3& hi, int group, int mask) {
        Object object;
        object.lo = lo;
        object.hi = hi;
        object.group = group;
        object.mask = mask;
        object.parked = !goodBox(lo, hi);
        clients_.emplace_back();
        object.proxy = broadphase_->createProxy(lo, hi, 0, &clients_.back(), group, mask, nullptr);
        objects_[id] = object;
        byProxy_[object.proxy] = id;
        ++result_.operations;
    }
    void destroy(int id) {
        Object& object = objects_[id];
        btBroadphaseProxy* proxy = object.proxy;
        byProxy_.erase(proxy);
        objects_.erase(id);
        broadphase_->destroyProxy(proxy, nullptr);
        for (auto it = verdicts_.begin(); it != verdicts_.end();) {
            it = (it->first.first == id || it->first.second == id) ? verdicts_.erase(it)
                                                                   : std::next(it);
        }
        // destroyProxy must take the proxy's pairs out of the cache at once.
        for (int i = 0; i < cache_->getNumOverlappingPairs(); ++i) {
            const btBroadphasePair& pair = cache_->getOverlappingPairArrayPtr()[i];
            if (pair.m_pProxy0 == proxy || pair.m_pProxy1 == proxy) {
                fail("a pair of a destroyed proxy is still in the cache");
            }
        }
        ++result_.operations;
    }
    void move(int id, const btVector3& lo, const btVector3& hi) {
        Object& object = objects_[id];
        broadphase_->setAabb(object.proxy, lo, hi, nullptr);
        if (goodBox(lo, hi)) {  // a bad box is rejected: the proxy keeps its last valid one
            object.lo = lo;
            object.hi = hi;
            object.parked = false;
        }
        ++result_.operations;
    }

    bool accepts(const Object& a, const Object& b) const {
        return (a.group & b.mask) != 0 && (b.group & a.mask) != 0;
    }
    bool boxesOverlap(const Object& a, const Object& b) const {
        return TestAabbAgainstAabb2(a.lo, a.hi, b.lo, b.hi);
    }

    void search() {
        broadphase_->calculateOverlappingPairs(nullptr);
        ++result_.operations;
        ++result_.searches;
        // The model: overlapping pairs keep the verdict of the search where their overlap
        // began (unless the user took them out of the cache); new ones are asked now.
        std::map<Key, bool> verdicts;
        std::set<Key> expected;
        for (auto a = objects_.begin(); a != objects_.end(); ++a) {
            if (a->second.parked) {
                continue;
            }
            for (auto b = std::next(a); b != objects_.end(); ++b) {
                if (b->second.parked || !boxesOverlap(a->second, b->second)) {
                    continue;
                }
                const Key key = keyOf(a->first, b->first);
                const auto known = verdicts_.find(key);
                const bool verdict = !everyFrame_ && known != verdicts_.end() && !lost_.count(key)
                                         ? known->second
                                         : accepts(a->second, b->second);
                verdicts[key] = verdict;
                if (verdict) {
                    expected.insert(key);
                }
            }
        }
        verdicts_.swap(verdicts);
        lost_.clear();
        std::set<Key> cached;
        for (int i = 0; i < cache_->getNumOverlappingPairs(); ++i) {
            const btBroadphasePair& pair = cache_->getOverlappingPairArrayPtr()[i];
            const int a = idOf(pair.m_pProxy0), b = idOf(pair.m_pProxy1);
            if (a < 0 || b < 0) {
                return fail("the cache holds a pair of a proxy that is not alive");
            }
            if (!cached.insert(keyOf(a, b)).second) {
                return fail("the cache holds a pair twice");
            }
        }
        if (cached != expected) {
            std::vector<Key> missing, extra;
            std::set_difference(expected.begin(), expected.end(), cached.begin(), cached.end(),
                                std::back_inserter(missing));
            std::set_difference(cached.begin(), cached.end(), expected.begin(), expected.end(),
                                std::back_inserter(extra));
            std::ostringstream out;
            out << missing.size() << " pairs missing, " << extra.size() << " extra";
            const Key first = missing.empty() ? extra[0] : missing[0];
            out << "; first " << (missing.empty() ? "extra" : "missing") << " (" << first.first
                << ", " << first.second << ")";
            return fail(out.str());
        }
        if (recorder_.duplicateAdds != 0 || recorder_.unknownRemoves != 0) {
            return fail("the ghost callback saw a pair added twice or an unknown removed");
        }
        result_.truePairs += expected.size();
        if (adapter_ != nullptr) {
            try {
                adapter_->validate();
            } catch (const std::logic_error& error) {
                fail(std::string("validate: ") + error.what());
            }
        }
    }

    /// The proxies a query must report (alive, valid box, accepted by `test`), by id.
    std::set<int> queryTruth(const std::function<bool(const Object&)>& test) {
        std::set<int> out;
        for (const auto& entry : objects_) {
            if (!entry.second.parked && test(entry.second)) {
                out.insert(entry.first);
            }
        }
        return out;
    }

    struct Checked {
        std::set<int> start;          ///< what the query must report
        std::set<int> destroyedHere;  ///< destroyed by the callback meanwhile
        std::vector<int> reported;
    };

    /// A hit: it must be alive now and due; then the op's action at its actionAt-th hit.
    void onHit(const btBroadphaseProxy* proxy, Checked& checked, const Op& op, int depth) {
        const int id = idOf(proxy);
        if (id < 0) {
            return fail("a query reported a proxy that is not alive");
        }
        if (!checked.start.count(id)) {
            return fail("a query reported object " + std::to_string(id) +
                        ", which it should not report");
        }
        checked.reported.push_back(id);
        if (depth > 0 || int(checked.reported.size()) - 1 != op.actionAt) {
            return;
        }
        switch (op.action) {
            case Op::Action::None:
                break;
            case Op::Action::CreateOne:
                if (find(op.id2) == nullptr) {
                    create(op.id2, op.lo2, op.hi2, 1, -1);
                }
                break;
            case Op::Action::DestroyHit:
                checked.destroyedHere.insert(id);
                destroy(id);
                break;
            case Op::Action::DestroyOther:
                if (find(op.other) != nullptr) {
                    checked.destroyedHere.insert(op.other);
                    destroy(op.other);
                }
                break;
            case Op::Action::MoveHit:
                move(id, op.lo2, op.hi2);
                break;
            case Op::Action::QueryAgain: {
                Op nested;
                nested.kind = Op::Kind::AabbQuery;
                nested.lo = op.lo2;
                nested.hi = op.hi2;
                aabbQuery(nested, depth + 1);
                break;
            }
        }
    }

    void finishQuery(const Checked& checked, const char* what) {
        ++result_.queries;
        result_.queryHits += checked.start.size();
        std::set<int> reported(checked.reported.begin(), checked.reported.end());
        if (reported.size() != checked.reported.size()) {
            return fail(std::string(what) + " reported a proxy twice");
        }
        for (int id : checked.start) {
            if (!reported.count(id) && !checked.destroyedHere.count(id)) {
                return fail(std::string(what) + " missed object " + std::to_string(id));
            }
        }
    }

    void aabbQuery(const Op& op, int depth) {
        struct Callback : btBroadphaseAabbCallback {
            std::function<void(const btBroadphaseProxy*)> hit;
            bool process(const btBroadphaseProxy* proxy) override {
                hit(proxy);
                return true;
            }
        } callback;
        Checked checked;
        if (usableQuery(op.lo, op.hi)) {  // an inverted or NaN box is empty
            checked.start = queryTruth([&](const Object& object) {
                return TestAabbAgainstAabb2(object.lo, object.hi, op.lo, op.hi);
            });
        }
        callback.hit = [&](const btBroadphaseProxy* proxy) { onHit(proxy, checked, op, depth); };
        broadphase_->aabbTest(op.lo, op.hi, callback);
        ++result_.operations;
        finishQuery(checked, "aabbTest");
    }

    void rayQuery(const Op& op) {
        struct Callback : btBroadphaseRayCallback {
            std::function<void(const btBroadphaseProxy*)> hit;
            bool process(const btBroadphaseProxy* proxy) override {
                hit(proxy);
                return true;
            }
        } callback;
        // Prepared as btCollisionWorld::rayTest prepares its own.
        const btVector3 from = op.lo, to = op.hi;
        btVector3 direction = to - from;
        direction.normalize();
        for (int axis = 0; axis < 3; ++axis) {
            callback.m_rayDirectionInverse[axis] = direction[axis] == btScalar(0)
                                                       ? btScalar(BT_LARGE_FLOAT)
                                                       : btScalar(1) / direction[axis];
            callback.m_signs[axis] = callback.m_rayDirectionInverse[axis] < 0.0;
        }
        callback.m_lambda_max = direction.dot(to - from);
        Checked checked;
        if (usableQuery(op.expandLo, op.expandHi)) {  // an inverted swept box is empty
            checked.start = queryTruth([&](const Object& object) {
                // Bullet's convention (btDbvt::rayTestInternal): [min - aabbMax, max - aabbMin].
                const btVector3 bounds[2] = {object.lo - op.expandHi, object.hi - op.expandLo};
                btScalar lambda;
                return btRayAabb2(from, callback.m_rayDirectionInverse, callback.m_signs, bounds,
                                  lambda, 0, callback.m_lambda_max);
            });
        }
        callback.hit = [&](const btBroadphaseProxy* proxy) { onHit(proxy, checked, op, 0); };
        broadphase_->rayTest(from, to, callback, op.expandLo, op.expandHi);
        ++result_.operations;
        finishQuery(checked, "rayTest");
    }

    void apply(const Op& op) {
        Object* object = op.id >= 0 ? find(op.id) : nullptr;
        switch (op.kind) {
            case Op::Kind::Create:
                if (find(op.id) == nullptr) {
                    create(op.id, op.lo, op.hi, op.group, op.mask);
                }
                return;
            case Op::Kind::Destroy:
                if (object != nullptr) {
                    destroy(op.id);
                }
                return;
            case Op::Kind::Move:
                if (object != nullptr) {
                    if (op.other == 1 && !object->parked && object->hi.x() < btScalar(1e17)) {
                        move(op.id, object->lo + op.lo2, object->hi + op.lo2);  // relative
                    } else {
                        move(op.id, op.lo, op.hi);
                    }
                }
                return;
            case Op::Kind::SetFilter:
                if (object != nullptr) {
                    object->proxy->m_collisionFilterGroup = object->group = op.group;
                    object->proxy->m_collisionFilterMask = object->mask = op.mask;
                    ++result_.operations;
                }
                return;
            case Op::Kind::Refresh:
                if (object != nullptr) {
                    const Object old = *object;
                    destroy(op.id);
                    create(op.id, old.lo, old.hi, op.group, op.mask);
                }
                return;
            case Op::Kind::Search:
                search();
                return;
            case Op::Kind::AabbQuery:
                aabbQuery(op, 0);
                return;
            case Op::Kind::RayQuery:
                rayQuery(op);
                return;
            case Op::Kind::RemovePair: {
                Object* other = find(op.other);
                if (object != nullptr && other != nullptr && op.id != op.other) {
                    // Only a pair that was in the cache is lost (removing one that is not is
                    // a no-op for Bullet and tells the broadphase nothing).
                    if (cache_->findPair(object->proxy, other->proxy) != nullptr) {
                        lost_.insert(keyOf(op.id, op.other));
                    }
                    cache_->removeOverlappingPair(object->proxy, other->proxy, nullptr);
                    ++result_.operations;
                }
                return;
            }
            case Op::Kind::RemoveAllOf:
                if (object != nullptr) {
                    for (const auto& entry : objects_) {
                        if (entry.first != op.id &&
                            cache_->findPair(object->proxy, entry.second.proxy) != nullptr) {
                            lost_.insert(keyOf(op.id, entry.first));
                        }
                    }
                    cache_->removeOverlappingPairsContainingProxy(object->proxy, nullptr);
                    ++result_.operations;
                }
                return;
            case Op::Kind::ResetPool:
                while (!objects_.empty()) {
                    destroy(objects_.begin()->first);
                }
                broadphase_->resetPool(nullptr);
                ++result_.operations;
                return;
        }
    }

    std::string name_;
    bool everyFrame_;
    std::unique_ptr<btBroadphaseInterface> broadphase_;
    BroadphaseAdapter* adapter_ = nullptr;
    btOverlappingPairCache* cache_ = nullptr;
    Recorder recorder_;
    std::map<int, Object> objects_;
    std::map<const btBroadphaseProxy*, int> byProxy_;
    std::map<Key, bool> verdicts_;
    std::set<Key> lost_;
    std::deque<char> clients_;  // one stable address per proxy ever made
    Result result_;
    std::size_t at_ = 0;
};

std::string vector(const btVector3& v) {
    std::ostringstream out;
    out.precision(std::numeric_limits<btScalar>::max_digits10);
    out << "btVector3(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
    return out.str();
}

}  // namespace

std::vector<Op> randomProgram(std::uint32_t seed, std::size_t count, int objects) {
    return Generator(seed, objects).program(count);
}

Result run(const std::string& name, const std::vector<Op>& program,
           const BroadphaseSettings& settings) {
    Runner runner(name, settings);
    return runner.execute(program);
}

std::vector<Op> shrink(const std::string& name, const std::vector<Op>& program,
                       const BroadphaseSettings& settings) {
    std::vector<Op> current = program;
    if (!run(name, current, settings).failed) {
        return current;
    }
    // Everything after the failing operation is irrelevant.
    current.resize(run(name, current, settings).failedAt + 1);
    for (std::size_t chunk = current.size() / 2; chunk >= 1; chunk /= 2) {
        for (std::size_t start = 0; start + chunk <= current.size();) {
            std::vector<Op> candidate;
            candidate.insert(candidate.end(), current.begin(), current.begin() + long(start));
            candidate.insert(candidate.end(), current.begin() + long(start + chunk), current.end());
            if (!candidate.empty() && run(name, candidate, settings).failed) {
                current.swap(candidate);
            } else {
                start += chunk;
            }
        }
    }
    return current;
}

std::string asCode(const std::vector<Op>& program) {
    std::ostringstream out;
    out << "// btBroadphaseInterface& bp; std::map<int, btBroadphaseProxy*> p; char c["
        << program.size() << "];\n";
    for (const Op& op : program) {
        const std::string id = "p[" + std::to_string(op.id) + "]";
        switch (op.kind) {
            case Op::Kind::Create:
                out << id << " = bp.createProxy(" << vector(op.lo) << ", " << vector(op.hi)
                    << ", 0, &c[" << op.id << "], " << op.group << ", " << op.mask
                    << ", nullptr);\n";
                break;
            case Op::Kind::Destroy:
                out << "bp.destroyProxy(" << id << ", nullptr);\n";
                break;
            case Op::Kind::Move:
                if (op.other == 1) {
                    out << "// relative move by " << vector(op.lo2) << "\n";
                }
                out << "bp.setAabb(" << id << ", " << vector(op.lo) << ", " << vector(op.hi)
                    << ", nullptr);\n";
                break;
            case Op::Kind::SetFilter:
                out << id << "->m_collisionFilterGroup = " << op.group << "; " << id
                    << "->m_collisionFilterMask = " << op.mask << ";\n";
                break;
            case Op::Kind::Refresh:
                out << "// refresh " << id << " with group " << op.group << ", mask " << op.mask
                    << " (destroyProxy + createProxy)\n";
                break;
            case Op::Kind::Search:
                out << "bp.calculateOverlappingPairs(nullptr);  // check the pairs\n";
                break;
            case Op::Kind::AabbQuery:
                out << "bp.aabbTest(" << vector(op.lo) << ", " << vector(op.hi)
                    << ", callback);  // action " << int(op.action) << " at hit " << op.actionAt
                    << "\n";
                break;
            case Op::Kind::RayQuery:
                out << "bp.rayTest(" << vector(op.lo) << ", " << vector(op.hi) << ", rayCallback, "
                    << vector(op.expandLo) << ", " << vector(op.expandHi) << ");  // action "
                    << int(op.action) << " at hit " << op.actionAt << "\n";
                break;
            case Op::Kind::RemovePair:
                out << "bp.getOverlappingPairCache()->removeOverlappingPair(" << id << ", p["
                    << op.other << "], nullptr);\n";
                break;
            case Op::Kind::RemoveAllOf:
                out << "bp.getOverlappingPairCache()->removeOverlappingPairsContainingProxy(" << id
                    << ", nullptr);\n";
                break;
            case Op::Kind::ResetPool:
                out << "// destroy every proxy, then\nbp.resetPool(nullptr);\n";
                break;
        }
    }
    return out.str();
}

}  // namespace kolize::fuzz

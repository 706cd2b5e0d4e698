#pragma once
/// \file
/// A differential fuzzer for btBroadphaseInterface implementations: seeded random sequences
/// of everything a Bullet application can do to a broadphase (create, destroy, move,
/// teleport, touching, zero-extent, +-1e18 and far boxes, NaN / infinite / inverted boxes,
/// filter changes in place and by re-adding, pair searches, box and ray queries with nonsense
/// input, callbacks that create, destroy and move proxies during queries, pairs removed from
/// the cache by the user, resetPool), checked after every pair search and every query
/// against a plain model of the contract (written independently of the adapter: a list of
/// boxes, a double loop, and Bullet's own box and ray tests). A failing sequence is shrunk
/// to a minimal one and printed as C++ code.

#include <kolize/broadphase/settings.h>

#include <LinearMath/btVector3.h>

#include <cstdint>
#include <string>
#include <vector>

namespace kolize::fuzz {

/// One operation. Objects are named by the index of the Create operation that made them;
/// an operation on an object that does not exist (never made, or destroyed) is skipped, so
/// that any subsequence of operations is a valid program.
struct Op {
    enum class Kind : std::uint8_t {
        Create,       ///< object `id` with box and filter
        Destroy,      ///< object `id`
        Move,         ///< object `id` to box
        SetFilter,    ///< object `id`'s group and mask, in place
        Refresh,      ///< object `id` destroyed and created again with a new filter
        Search,       ///< calculateOverlappingPairs, then the pair check
        AabbQuery,    ///< aabbTest(box), with `action` in the callback
        RayQuery,     ///< rayTest(from = box.lo, to = box.hi, swept box expandLo..Hi)
        RemovePair,   ///< the user removes pair (id, other) from the cache
        RemoveAllOf,  ///< the user calls removeOverlappingPairsContainingProxy(id)
        ResetPool,    ///< resetPool (does something only when no proxy is alive)
    };
    /// What a query callback does at its k-th hit (k = actionAt).
    enum class Action : std::uint8_t {
        None,
        CreateOne,     ///< creates object `id2` (an extra Create) with box2
        DestroyHit,    ///< destroys the proxy just reported
        DestroyOther,  ///< destroys object `other`
        MoveHit,       ///< moves the proxy just reported to box2
        QueryAgain,    ///< a nested aabbTest(box2), checked like any query
    };
    Kind kind = Kind::Search;
    int id = -1;
    int other = -1;
    btVector3 lo{0, 0, 0}, hi{0, 0, 0};
    btVector3 expandLo{0, 0, 0}, expandHi{0, 0, 0};
    int group = 1, mask = -1;
    Action action = Action::None;
    int actionAt = 0;
    int id2 = -1;
    btVector3 lo2{0, 0, 0}, hi2{0, 0, 0};
};

/// What a run found.
struct Result {
    std::size_t operations = 0;  ///< operations carried out (skipped ones not counted)
    std::size_t searches = 0;    ///< pair searches checked
    std::size_t queries = 0;     ///< box and ray queries checked
    std::size_t truePairs = 0;   ///< pairs the model expected, summed over searches
    std::size_t queryHits = 0;   ///< proxies the model expected queries to report
    bool failed = false;
    std::string failure;       ///< the first mismatch, or the exception's message
    std::size_t failedAt = 0;  ///< index of the operation that failed
};

/// A seeded random program of `count` operations over about `objects` objects.
std::vector<Op> randomProgram(std::uint32_t seed, std::size_t count, int objects = 120);

/// Runs `program` on broadphase `name` (kolize's exact broadphases: the pair cache must
/// equal the model; the filters are evaluated as `settings.filters` says). Stops at the
/// first mismatch. Exceptions from the broadphase count as failures.
Result run(const std::string& name, const std::vector<Op>& program,
           const BroadphaseSettings& settings = {});

/// The shortest subsequence of a failing `program` found that still fails (delta
/// debugging: chunks, then single operations, removed while the failure stays).
std::vector<Op> shrink(const std::string& name, const std::vector<Op>& program,
                       const BroadphaseSettings& settings = {});

/// The program as C++ statements over a `btBroadphaseInterface& bp` (for a bug report).
std::string asCode(const std::vector<Op>& program);

}  // namespace kolize::fuzz

#pragma once
// kolize-narrow-bench: one mesh-against-mesh method (a kolize configuration, an FCL
// bounding volume, GImpact, the reference) behind one interface, so that the benchmark can
// interleave them.

#include <kolize/engine/narrow_workload.h>
#include <kolize/narrowphase/mesh_query.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace kolize::narrowbench {

using narrowphase::Pose;
using narrowphase::TrianglePair;

enum class Mode { kYesNo, kPairs, kContacts };
const char* modeName(Mode mode);

/// What one query reported, and the work it counted (0 where a method does not count).
struct Outcome {
    bool intersecting = false;
    std::vector<TrianglePair> pairs;  ///< filled by collect(), after the timed call
    std::uint64_t bvTests = 0;        ///< node-pair volume tests (kolize: spheres + boxes)
    std::uint64_t sphereTests = 0;    ///< of which node-sphere tests
    std::uint64_t triangleTests = 0;
    std::uint64_t predicateFallbacks = 0;  ///< orient calls past the static filter
};

/// Build cost and memory of a method's structures for one mesh.
struct BuildInfo {
    double microsPerTriangle = 0;
    double bytesPerNode = 0;
    std::size_t nodes = 0;
};

class Method {
  public:
    virtual ~Method() = default;
    virtual std::string name() const = 0;
    virtual bool supports(Mode mode) const = 0;
    /// Builds the structures for meshes a and b (b may be a itself); timed by the caller's
    /// buildInfo() afterwards. Called once per mesh pair.
    virtual void prepare(const workload::WorkloadMesh& a, const workload::WorkloadMesh& b) = 0;
    virtual BuildInfo buildInfo() const = 0;
    /// The timed call: one query at the given poses.
    virtual void run(const Pose& a, const Pose& b, Mode mode) = 0;
    /// The last run's answer and counters (untimed).
    virtual void collect(Outcome& out) = 0;
};

std::vector<std::unique_ptr<Method>> kolizeMethods(const std::vector<std::string>& names);
/// Every kolize configuration name the bench knows.
std::vector<std::string> kolizeMethodNames(bool quick);

std::unique_ptr<Method> gimpactMethod(bool zeroMargin);

#ifdef KOLIZE_WITH_FCL
/// "obb", "obbrss", "rss", "kios", "kdop18", "aabb".
std::unique_ptr<Method> fclMethod(const std::string& bv);
#endif

}  // namespace kolize::narrowbench

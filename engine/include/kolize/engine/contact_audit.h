#pragma once
/// \file
/// An independent check of a world's contacts: every overlapping pair of two bodies whose
/// exact triangle meshes are known is queried exactly (kolize's mesh query, yes/no, closed:
/// touching counts) at the poses the narrowphase saw, and compared with the pair's contact
/// manifold, whichever algorithm made it (kolize's, GImpact's, Bullet's convex ones).

#include <kolize/narrowphase/mesh_model.h>

#include <map>
#include <memory>

class btCollisionWorld;
class btCollisionObject;

namespace kolize {

/// Exact meshes by body: each in its body frame (the body's world transform places it).
using ExactMeshes =
    std::map<const btCollisionObject*, std::shared_ptr<const narrowphase::MeshModel>>;

/// What an audit found (sums over the audited steps).
struct ContactAudit {
    int pairs = 0;         ///< overlapping pairs of two bodies with exact meshes
    int intersecting = 0;  ///< of those, pairs whose meshes share a point
    /// Pairs whose manifold claims a penetration (a point deeper than kInventedDepth) while
    /// the meshes are apart: a contact that is not there (a margin's, or a stale point).
    int invented = 0;
    /// Intersecting pairs without a manifold point (none at all, or none closer than
    /// kInventedDepth): a contact that is there and was not reported.
    int missing = 0;
    /// Pairs whose claim disagreed with one order of the exact test and agreed with the other
    /// (touching at the rounding's scale): neither invented nor missing.
    int roundingTies = 0;
    double maxFalseDepth = 0;  ///< deepest claimed penetration among the invented pairs (m)
    /// The meshes' penetration (separationDepth, measured when AuditSettings::penetration is
    /// on): the largest over the pairs, and the sum and count of the pairs that penetrate.
    double maxPenetration = 0;
    double sumPenetration = 0;
    int penetrationPairs = 0;
    int steps = 0;  ///< audited steps
    ContactAudit& operator+=(const ContactAudit& other);
};

/// Claims of penetration shallower than this (m) are not counted as invented: a point the
/// solver left touching may read a hair inside after the float round trip.
constexpr double kInventedDepth = 1e-4;

/// What an audit measures besides the claims.
struct AuditSettings {
    /// Measure each pair's penetration (separationDepth): one exact yes/no query per pair
    /// apart, about 30-80 per pair that overlaps. Default off.
    bool penetration = false;
};

/// How deep two meshes interpenetrate, independently of any method's contacts: the
/// shortest translation of B, along the 26 directions of a cube's faces, edges and corners
/// and the direction from A's origin to B's, after which the meshes no longer overlap as
/// solids, found by bisection to 2^-14 of the pair's reach. Solids overlap when their
/// surfaces share a point (kolize's exact test) or a closed mesh (every directed edge matched
/// by its reverse: meshMassProperties) holds a vertex of the other (generalized winding
/// number at least 1/2); an open mesh (a bowl, scenery) is a surface only. For convex shapes, an
/// upper bound on the penetration depth (the shortest separating translation over all directions)
/// and at most 1/cos 27.6 deg = 1.13 times it (the directions' covering angle); for others, the
/// bisection finds one place along each direction where the overlap ends. 0 for meshes apart. The
/// reach is measured from the pose translations: meshes far from their origins get a coarser
/// bisection, never a wrong one.
double separationDepth(const narrowphase::MeshModel& a, const narrowphase::Pose& poseA,
                       const narrowphase::MeshModel& b, const narrowphase::Pose& poseB);

/// Audits `world` now (call it after the narrowphase, before the bodies move). Bodies not
/// in `meshes` are skipped. The exact test is exact on B's vertices as moved (rounded) into
/// A's frame, so a pair counts as invented only when apart with either mesh as A, and as
/// missing only when touching both ways (a pair touching at the rounding's scale, ~1e-16 of
/// its size, is neither). Cost: one exact yes/no query per overlapping pair with meshes, two
/// for a pair whose claim disagrees with the first.
ContactAudit auditContacts(const btCollisionWorld& world, const ExactMeshes& meshes,
                           const AuditSettings& settings = {});

}  // namespace kolize

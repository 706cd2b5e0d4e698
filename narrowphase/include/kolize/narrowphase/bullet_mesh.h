#pragma once
/// \file
/// The narrowphase inside Bullet: a mesh shape over a narrowphase MeshModel, the collision
/// algorithms that give it exact contacts and times of impact, and their registration on a
/// dispatcher. With bullet_mesh_world.h (the CCD world, which adds BulletDynamics) this is
/// the narrowphase's only Bullet adapter: everything below it (mesh_model.h, mesh_query.h,
/// triangle_test.h, mesh_ccd.h) knows nothing of Bullet.
///
/// Use:
/// \code
///   auto model = kolize::makeMeshModel(kolize::narrowphase::TriangleMesh::fromArrays(
///       "duck", xyz, vertexCount, indices, indexCount));     // throws MeshError on bad data
///   kolize::MeshShape shape(model);                          // bodies may share `model`
///   kolize::registerNarrowphase(&dispatcher);                // once per dispatcher
/// \endcode
///
/// Contacts (mesh against mesh, and mesh against btBvhTriangleMeshShape scenery) come from
/// the exactly intersecting triangle pairs (mesh_query.h, QueryMode::kContacts): no pair that
/// does not touch makes a contact, so there are no ghost contacts; separated meshes make
/// none unless a contact margin is set (MeshStageSettings::contact_margin: while the meshes
/// are apart, triangle pairs apart by at most it make separated contacts, one candidate
/// point each, halfway between their closest points, with a positive distance and the
/// normal along them; never a penetration. Meshes that intersect get only the contacts of
/// their intersecting pairs: a separated point within Bullet's breaking threshold of a
/// penetrating one would replace it in the manifold, getCacheEntry). Bullet's closest-point
/// queries (contactTest, contactPairTest) with the callback's m_closestDistanceThreshold get
/// the same separated contacts up to that distance, with or without a contact margin. The
/// intersecting pairs are grouped into patches (pairs whose triangles share a vertex index on
/// either mesh). Per patch, the normal n and the depth come from a separating-axis test on the
/// patch's own triangles: the candidate directions are their face normals (A's outward, B's
/// reversed; outward is the winding's side for a closed mesh, the side away from the body's origin
/// for an open one, and for btBvhTriangleMeshShape scenery, which is two-sided as in Bullet, the
/// side towards the mesh body's origin: a bowl wound either way holds what falls in; the 64 with
/// the longest intersections) and NARROWPHASE.md's `normalize(sum of w (n_A - n_B))` (w the
/// segment's length, the square root of the overlap area for coplanar pairs); the one along which
/// A's patch vertices and B's overlap least is n (from A towards B), the overlap is the depth. For
/// a box resting on a face this is that face's normal and the exact overlap, also when the box is
/// tilted so that only a corner or an edge goes in (where the weighted sum alone tilts by the side
/// faces' share). The depth is local (v1): it sees only the touched triangles. The pairs are taken
/// in (A's triangle, B's triangle) order, so the contacts depend on the set of pairs only (not on
/// the order a query found them in: mesh_stages.h may skip the tree). A patch's candidate points:
/// where both meshes are closed (or one is scenery), the vertices of its triangles that lie inside
/// the other mesh, each at its own depth (how far it moves along the normal until it leaves the
/// other mesh through the face of a triangle it was paired with), when those vertices span an
/// area; otherwise the points of its intersection curve, at the patch's depth. A box tilted into
/// a floor then holds on its sunken corners, as Bullet's box-box clipping does, not on the curve
/// around them, about which it would turn further in (mesh-floor at 1/120 s: the deepest
/// penetration 1.0-2.1 mm -> 0.5-0.75 mm, GImpact 1.1-2.7). An open mesh has no inside: its
/// patches keep the curve. Up to 4 points per manifold are chosen from the candidates of every
/// patch (and the near pairs' points): the deepest, the farthest from it, then the two that
/// maximise the spanned area (Bullet's sortCachedPoints rule). Each point carries its patch's
/// normal, its depth, and the triangle ids of its pair through setShapeIdentifiersA/B(0,
/// triangle) (scenery: its part and triangle); the kept points that the bodies' motion parted or
/// slid past the breaking threshold are dropped before the new ones go in. The
/// manifold is persistent: Bullet's refreshContactPoints() drops the points that moved apart, as
/// for its own algorithms. A body at rest is mostly held by these kept points (the solver leaves it
/// touching or a hair apart, where the exact test finds no new pair); contactTest/contactPairTest
/// then report nothing until the meshes touch. When the exact test finds the meshes apart, a kept
/// point's distance (recomputed by Bullet from where the point was on the bodies) reads as touching
/// (0) at most: no penetration is claimed between meshes that do not intersect, so nothing is
/// pushed apart that is not in contact.
///
/// Continuous collision: the mesh algorithms' calculateTimeOfImpact is the exact first
/// contact of the two moving meshes (kolize::ccd::meshCcd; see MeshContactAlgorithm), and
/// kolize::MeshCcdWorld (bullet_mesh_world.h) is the world that calls it and stops fast mesh
/// bodies there; a plain btDiscreteDynamicsWorld gives MeshShape bodies no CCD at all.
///
/// Convex shapes against a MeshShape: the mesh's tree is queried with the convex's box, then
/// Bullet's own convex-triangle algorithms (GJK/EPA per triangle, btConvexTriangleCallback)
/// make the contacts, as for a btBvhTriangleMeshShape, and with its known weakness: a convex
/// across an edge between two triangles of one flat face can get a sideways normal from the
/// triangle it barely overlaps (Bullet's internal-edge contacts; no filter here yet).
#include "kolize/narrowphase/mesh_model.h"
#include "kolize/narrowphase/mesh_query.h"
#include "kolize/narrowphase/mesh_stages.h"

#include <BulletCollision/BroadphaseCollision/btCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btActivatingCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btCollisionCreateFunc.h>
#include <BulletCollision/CollisionDispatch/btConvexConcaveCollisionAlgorithm.h>
#include <BulletCollision/CollisionShapes/btConcaveShape.h>

#include <cstdint>
#include <memory>
#include <vector>

class btCollisionDispatcher;
class btPersistentManifold;

namespace kolize {

/// Builds the model a MeshShape needs: an OBB tree with `leafSize` triangles per leaf (1..8),
/// or with the default 0, 1 for meshes of up to kSmallMesh triangles and 4 above. (A box
/// mesh used as a ground has leaves of 4 triangles from different faces, each as large as
/// the box: every node of a mesh resting on it overlaps them, and the query visits all of
/// its leaves; with one triangle per leaf the top face's leaves are flat and reject them.)
/// Bad mesh data is refused by TriangleMesh itself (narrowphase::MeshError naming the mesh
/// and the element: non-finite vertex, index out of range, no triangles).
constexpr int kSmallMesh = 64;
std::shared_ptr<const narrowphase::MeshModel> makeMeshModel(narrowphase::TriangleMesh mesh,
                                                            int leafSize = 0);

/// Volume integrals of a closed mesh (density 1), in its model frame.
struct MeshMassProperties {
    bool closed = false;  ///< every directed edge (i, j) matched by exactly one (j, i)
    double volume = 0;    ///< > 0 for a closed mesh (winding inverted meshes are flipped)
    narrowphase::Vec3 centroid = narrowphase::Vec3::Zero();
    /// Inertia tensor per unit density about the centroid, model axes.
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

/// Volume, centroid and inertia of `mesh` (divergence theorem, one tetrahedron per triangle
/// from the origin). O(triangles log triangles) for the closedness check. For an open mesh
/// `closed` is false and the other fields hold the integrals of the open surface's cone,
/// which are meaningless.
MeshMassProperties meshMassProperties(const narrowphase::TriangleMesh& mesh);

/// A Bullet concave shape (m_shapeType CUSTOM_CONCAVE_SHAPE_TYPE, which Bullet 3.24 also
/// calls SDF_SHAPE_PROXYTYPE: registerNarrowphase() must be called on every dispatcher that
/// sees it, else convex pairs take Bullet's SDF path) over a narrowphase MeshModel.
///
/// The model (mesh and OBB tree) is shared: many shapes, and many bodies per shape, may use
/// one. Scaling makes a shape its own scaled model (see setLocalScaling). Margin: 0 by
/// default; it only widens the broadphase box (contacts stay exact).
class MeshShape : public btConcaveShape {
  public:
    BT_DECLARE_ALIGNED_ALLOCATOR();

    /// Throws std::invalid_argument for a null model or a model whose tree is not an OBB
    /// tree (the Bullet algorithms query OBB trees only).
    explicit MeshShape(std::shared_ptr<const narrowphase::MeshModel> model);

    /// The model queries use: the shared model, or this shape's scaled copy.
    const narrowphase::MeshModel& model() const { return *scaled_; }
    const std::shared_ptr<const narrowphase::MeshModel>& sharedModel() const { return scaled_; }
    /// The unscaled model the shape was made from.
    const std::shared_ptr<const narrowphase::MeshModel>& baseModel() const { return base_; }
    /// Mass properties of the scaled mesh (computed with the model).
    const MeshMassProperties& massProperties() const { return mass_; }
    /// The mean longest edge of its triangles (scaled model; 0 without triangles). Of two
    /// meshes, the one with the larger is the frame of their query (MeshMeshAlgorithm).
    double meanTriangleSize() const { return meanTriangleSize_; }

    /// Box around the tree's root volume (scaled model) moved by `t`, cut down to the box
    /// around the moved model-space vertex box (the root OBB of a cube has arbitrary axes),
    /// widened by the margin, rounded outward to btScalar. O(1).
    void getAabb(const btTransform& t, btVector3& aabbMin, btVector3& aabbMax) const override;
    /// Calls `callback` once for every triangle whose box meets [aabbMin, aabbMax] (scaled
    /// model frame, closed), in the tree's depth-first order, with part 0 and the triangle's
    /// index in the mesh. O(log n + triangles reported) for a small box.
    void processAllTriangles(btTriangleCallback* callback, const btVector3& aabbMin,
                             const btVector3& aabbMax) const override;
    /// Closed mesh: the diagonal of the inertia tensor of the solid about its centroid,
    /// mass / volume as density (exact when the model axes are principal axes, as for the
    /// boxes and symmetric meshes; use massProperties() for the full tensor). Open mesh:
    /// the inertia of a solid box of the vertices' axis-aligned bounds (contained in the
    /// root volume).
    void calculateLocalInertia(btScalar mass, btVector3& inertia) const override;
    /// Scales the model frame (vertices multiplied per axis). Scaling other than (1, 1, 1)
    /// builds this shape's own scaled model (O(n log n), not shared); (1, 1, 1) goes back
    /// to the shared one. Throws std::invalid_argument, naming the mesh and the scale, for
    /// a zero, negative or non-finite component; the shape is unchanged then.
    void setLocalScaling(const btVector3& scaling) override;
    const btVector3& getLocalScaling() const override { return scaling_; }
    const char* getName() const override { return "KolizeMesh"; }

  private:
    void adoptModel(std::shared_ptr<const narrowphase::MeshModel> model);

    std::shared_ptr<const narrowphase::MeshModel> base_;
    std::shared_ptr<const narrowphase::MeshModel> scaled_;
    MeshMassProperties mass_;
    btVector3 scaling_{1, 1, 1};
    narrowphase::Obb root_;                                   ///< the tree's root volume
    narrowphase::Vec3 boundsLo_ = narrowphase::Vec3::Zero();  ///< the vertices' box
    narrowphase::Vec3 boundsHi_ = narrowphase::Vec3::Zero();
    double meanTriangleSize_ = 0;
};

/// One contact in the world, before it goes to Bullet: on the meshes X (the first) and Y.
struct MeshContact {
    /// On the intersection curve, or halfway from a vertex inside the other mesh to where it
    /// leaves it along the normal: point +- normal * depth / 2 are the two bodies' points.
    narrowphase::Vec3 point = narrowphase::Vec3::Zero();
    narrowphase::Vec3 normal = narrowphase::Vec3::Zero();  ///< unit, from X towards Y
    /// Penetration (>= 0); for a pair apart within the contact margin, minus its distance.
    double depth = 0;
    std::int32_t partX = 0, triangleX = -1, partY = 0, triangleY = -1;
};

/// Whether Bullet's integrator would run CCD for `object` this step: an active rigid body,
/// neither static nor kinematic, with a motion threshold (setCcdMotionThreshold > 0) that
/// the motion of its origin from its world to its interpolation transform exceeds (Bullet's
/// integrateTransforms rule, `threshold^2 < motion^2`).
bool exceedsCcdMotionThreshold(const btCollisionObject& object);

/// What the two exact mesh algorithms share: the manifold (the dispatcher's, or one of its
/// own), the mesh query, the last contacts and the moving meshes of the time of impact (off
/// Bullet's fixed-size algorithm pool).
///
/// Time of impact (calculateTimeOfImpact, Bullet's continuous entry point, which Bullet
/// 3.24's btDiscreteDynamicsWorld never calls: see bullet_mesh_world.h for the world that
/// does). The step is Bullet's: each body moves from its world transform (the start of the
/// step) to its interpolation transform (where the integrator will put it), as Bullet's own
/// convex algorithms read them; a static or kinematic body, or one that is not active,
/// stays at its world transform. Between the two, a body translates on the segment and
/// turns at constant angular velocity (slerp), as Bullet's integrator moves it. The step is
/// cut into pieces of at most 0.1 rad of turn (at most 64; Bullet's integrator turns a body
/// by at most pi/4 per step, 8 pieces), in each of which every vertex moves on its chord, and
/// kolize::ccd::meshCcd finds the earliest vertex-face or edge-edge contact of the chords,
/// piece by piece. For a translating body (one piece) that is the exact first contact, never
/// late and at most 1e-6 of the step early; for a turning one it is the chords' (a vertex at
/// distance r from the axis is within 1.2e-3 r of its arc; the thesis used one chord per
/// step). The result is that time as a fraction of the step, rounded down to btScalar, or 1
/// when:
/// - neither body exceedsCcdMotionThreshold (a slow pair keeps 1, and costs nothing);
/// - the pair touched at the start of the step (the last processCollision, which Bullet runs
///   for the same step before any time of impact, made contacts) and no vertex moves, relative
///   to the other body, by more than the smaller CCD motion threshold of the fast bodies
///   along one of those contacts' normals: sliding along or leaving a contact is the
///   contacts' business, while a body that turns about its contact, sweeping the rest of
///   itself into the other, is still stopped;
/// - a transform, or a vertex moved by it, is not finite;
/// - the meshes do not touch during the step.
/// Like Bullet's algorithms, a time of impact below the hit fraction of a body that moves over
/// the step lowers it (setHitFraction); nothing else changes. `info` and `resultOut` are not used
/// (null is fine). Cost: O(vertices) to move both meshes, then meshCcd's (its time slices and
/// per-feature hierarchies).
class MeshContactAlgorithm : public btActivatingCollisionAlgorithm {
  public:
    ~MeshContactAlgorithm() override;
    void getAllContactManifolds(btManifoldArray& manifolds) override;
    /// The contacts made by the last processCollision (world frame; X = body0 for two meshes,
    /// the MeshShape against scenery).
    const std::vector<MeshContact>& lastContacts() const;

  protected:
    /// meshCcd over the moving meshes the caller filled in (State), reported as the class
    /// comment says for the bodies `body0`, `body1`.
    btScalar reportTimeOfImpact(btCollisionObject* body0, btCollisionObject* body1);
    MeshContactAlgorithm(const btCollisionAlgorithmConstructionInfo& ci,
                         const btCollisionObjectWrapper* body0,
                         const btCollisionObjectWrapper* body1);
    struct State;
    btPersistentManifold* manifold_ = nullptr;
    bool ownManifold_ = false;
    std::unique_ptr<State> state_;
};

/// MeshShape against MeshShape: the exact mesh query, contacts from its triangle pairs; the
/// time of impact of the two whole meshes (MeshContactAlgorithm).
class MeshMeshAlgorithm : public MeshContactAlgorithm {
  public:
    MeshMeshAlgorithm(const btCollisionAlgorithmConstructionInfo& ci,
                      const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1);
    void processCollision(const btCollisionObjectWrapper* body0,
                          const btCollisionObjectWrapper* body1, const btDispatcherInfo& info,
                          btManifoldResult* resultOut) override;
    /// See MeshContactAlgorithm. body0 and body1 in the algorithm's order (the pair's).
    btScalar calculateTimeOfImpact(btCollisionObject* body0, btCollisionObject* body1,
                                   const btDispatcherInfo& info,
                                   btManifoldResult* resultOut) override;

    struct CreateFunc : btCollisionAlgorithmCreateFunc {
        btCollisionAlgorithm* CreateCollisionAlgorithm(
            btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
            const btCollisionObjectWrapper* body1) override;
    };
};

/// A convex shape against a MeshShape (either order): the tree gives the triangles in the
/// convex's box, Bullet's convex-triangle algorithm the contacts. Never the SDF path.
/// Time of impact (calculateTimeOfImpact): as for two meshes (MeshContactAlgorithm: the same
/// step, rules and result), the mesh against a closed triangle surface that contains the
/// convex shape with its margin (built on the first call from 122 supporting vertices and
/// their hull; rebuilt when the shape, its scaling, margin or box change, or it no longer
/// fits). For a box or any other polytope without a rounding margin the surface is its own
/// faces and the time is exact as for two meshes. Around a round shape (a sphere, capsule,
/// cylinder, cone, a hull's rounded margin) the surface stands off the shape (a sphere's by
/// 5.8% of its radius): the time against it is where conservative advancement (Bullet's GJK
/// distances to the mesh's triangles) starts, or the start of the step when the mesh starts
/// nearer the shape than that standoff, and the advance goes to within 5e-4 of the shape's
/// angular motion disc of the shape itself; a body that only passes through the standoff
/// gets 1. Never later than the first contact as far as GJK's distances are exact (for a
/// turning body, the chords' as for two meshes). A body gliding past a round shape within a
/// few tolerances over a long motion can run out of the advance's 256 steps and then gets
/// the time reached (early). "Touching at the start" means the pair's manifold holds points.
/// A fast convex body also gets Bullet's own CCD (its swept sphere in
/// btDiscreteDynamicsWorld::integrateTransforms sweeps through MeshShape's
/// processAllTriangles, the mesh held where it is).
class ConvexMeshAlgorithm : public btActivatingCollisionAlgorithm {
  public:
    ConvexMeshAlgorithm(const btCollisionAlgorithmConstructionInfo& ci,
                        const btCollisionObjectWrapper* body0,
                        const btCollisionObjectWrapper* body1, bool meshFirst);
    ~ConvexMeshAlgorithm() override;
    void processCollision(const btCollisionObjectWrapper* body0,
                          const btCollisionObjectWrapper* body1, const btDispatcherInfo& info,
                          btManifoldResult* resultOut) override;
    btScalar calculateTimeOfImpact(btCollisionObject* body0, btCollisionObject* body1,
                                   const btDispatcherInfo& info,
                                   btManifoldResult* resultOut) override;
    void getAllContactManifolds(btManifoldArray& manifolds) override;

    struct CreateFunc : btCollisionAlgorithmCreateFunc {
        btCollisionAlgorithm* CreateCollisionAlgorithm(
            btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
            const btCollisionObjectWrapper* body1) override;
    };
    /// Mesh as body0, convex as body1.
    struct SwappedCreateFunc : btCollisionAlgorithmCreateFunc {
        btCollisionAlgorithm* CreateCollisionAlgorithm(
            btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
            const btCollisionObjectWrapper* body1) override;
    };

  private:
    struct Ccd;  ///< the time of impact's surface and buffers, made on the first call
    btConvexTriangleCallback triangles_;
    bool meshFirst_;
    std::unique_ptr<Ccd> ccd_;
};

/// A MeshShape against Bullet's static concave scenery, any order: btBvhTriangleMeshShape
/// (scaled too, and btMultimaterialTriangleMeshShape: each contact carries the scenery
/// triangle's part and index, which its getMaterialProperties takes),
/// btHeightfieldTerrainShape and btStaticPlaneShape (Bullet itself has no
/// algorithm for two concave shapes: without these a mesh body fell through a static plane
/// or a heightfield). The scenery's processAllTriangles gives its triangles in the mesh's box
/// (triangles with a corner that is not finite left out); they become a small narrowphase
/// mesh in world coordinates (vertices welded where exactly equal), queried exactly against
/// the mesh. Its model (tree) is built, O(k log k) for k triangles, only when a call collects
/// other triangles than the pair's last call did (compared bit for bit, O(k)); a body resting
/// or sliding on scenery reuses it for many steps (MeshStageStats::scenery_models_built).
/// Contacts as for two meshes, the scenery's part and triangle index on each point.
/// A static plane is a half-space, as for Bullet's convex shapes: the vertices of the mesh's
/// triangles on or below it are the candidates (or, when none is, those within the contact
/// margin above), each at its own depth, normal along the plane's; up to 4 chosen as for two
/// meshes, the plane's ids -1. O(vertices + triangles) per call once the mesh's bounding
/// sphere reaches the plane.
/// Time of impact (MeshContactAlgorithm): the mesh against the scenery's triangles in the
/// box around the mesh at the start and at the end of the step (scenery frame); the scenery
/// stays at its world transform (Bullet's triangle-mesh scenery is static). Against a plane:
/// the first time a vertex that starts above it reaches it (vertices already on or in it are
/// the contacts').
class BvhMeshAlgorithm : public MeshContactAlgorithm {
  public:
    BvhMeshAlgorithm(const btCollisionAlgorithmConstructionInfo& ci,
                     const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1,
                     bool meshFirst);
    void processCollision(const btCollisionObjectWrapper* body0,
                          const btCollisionObjectWrapper* body1, const btDispatcherInfo& info,
                          btManifoldResult* resultOut) override;
    /// See MeshContactAlgorithm. body0 and body1 in the algorithm's order (the pair's).
    btScalar calculateTimeOfImpact(btCollisionObject* body0, btCollisionObject* body1,
                                   const btDispatcherInfo& info,
                                   btManifoldResult* resultOut) override;

    struct CreateFunc : btCollisionAlgorithmCreateFunc {
        btCollisionAlgorithm* CreateCollisionAlgorithm(
            btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
            const btCollisionObjectWrapper* body1) override;
    };
    /// Scenery as body0, mesh as body1.
    struct SwappedCreateFunc : btCollisionAlgorithmCreateFunc {
        btCollisionAlgorithm* CreateCollisionAlgorithm(
            btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
            const btCollisionObjectWrapper* body1) override;
    };

  private:
    bool meshFirst_;
};

/// Registers the algorithms above on `dispatcher`, in both its contact-point
/// (registerCollisionCreateFunc) and closest-point (registerClosestPointsCreateFunc) tables:
/// MeshShape against MeshShape, against every convex shape type in both orders, and against
/// TRIANGLE_MESH_SHAPE_PROXYTYPE, SCALED_TRIANGLE_MESH_SHAPE_PROXYTYPE,
/// MULTIMATERIAL_TRIANGLE_MESH_PROXYTYPE, TERRAIN_SHAPE_PROXYTYPE and STATIC_PLANE_PROXYTYPE in
/// both orders (BvhMeshAlgorithm).
/// Compounds keep Bullet's compound algorithm, which dispatches their children to these
/// pairs. The create functions are static: they outlive every dispatcher. Throws
/// std::invalid_argument for a null dispatcher, and for a configuration whose collision
/// algorithm pool has elements smaller than these algorithms (Bullet's pool would hand out
/// too small blocks; btDefaultCollisionConfiguration's are large enough).
/// The stage planner (mesh_stages.h) runs with the default settings (auto everywhere).
void registerNarrowphase(btCollisionDispatcher* dispatcher);
/// The same with the stage planner's `stages` (mesh_stages.h). The settings and the counters
/// (narrowphaseStages) belong to the dispatcher; registering again replaces the settings,
/// also for its existing pairs, and zeroes the counters. Call it between steps. Throws
/// std::invalid_argument also for settings out of range, naming the field; nothing is
/// registered then.
void registerNarrowphase(btCollisionDispatcher* dispatcher, const MeshStageSettings& stages);

}  // namespace kolize

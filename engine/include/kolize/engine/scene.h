#pragma once
/// \file
/// Scenes by name: the thesis's broadphase streams and real Bullet worlds (benchmark-style
/// worlds, assimp meshes, extreme and stiff cases), built over any broadphase. One registry
/// shared by kolize-demo, kolize-report, the benchmarks and the tests.
///
/// A scene says what it needs (SceneNeeds); the demo assembles only those stages and prints
/// why. Every frame: Scene::step(), then proxyBoxes() gives the exact truth's input and
/// state() the dynamics' health (penetration, escaped bodies, NaN, energy).

#include <kolize/broadphase/settings.h>
#include <kolize/engine/pair_compare.h>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace kolize {

class TimedDynamicsWorld;

/// The pipeline stages a scene uses. The demo builds nothing else.
struct SceneNeeds {
    /// A btDiscreteDynamicsWorld with narrowphase and solver steps the scene. False: a pure
    /// broadphase stream (the thesis's scenes): setAabb + calculateOverlappingPairs only.
    bool dynamics = true;
    /// Rays are cast through the broadphase every frame (timed separately).
    bool rays = false;
    /// Triangle meshes: a static btBvhTriangleMeshShape, or convex hulls loaded by assimp.
    bool meshes = false;
    /// Objects fast enough to pass through others in one step: Bullet's CCD (motion
    /// threshold and swept sphere) is switched on for them.
    bool continuous = false;
};

/// What the caller chooses. Every scene accepts every field; fields a scene has no use for
/// are ignored and the scene's description says which it uses.
struct SceneOptions {
    int objects = 0;              ///< moving objects; 0: the scene's default count
    std::uint32_t seed = 1;       ///< the same seed gives the same scene
    std::string motion = "slow";  ///< "slow" or "fast": the thesis scenes' speeds
    double timeStep = 1.0 / 60;   ///< seconds per frame (world scenes)
    int substeps = 1;             ///< fixed solver substeps per frame (timeStep / substeps each)
    /// Bullet's own CCD for every dynamic body: -1 scene default (on when
    /// SceneNeeds::continuous), 0 off, 1 on.
    int bulletCcd = -1;
    std::string assetDir = "/usr/share/assimp/models";  ///< Debian's assimp-testmodels
    /// How the mesh-body scenes (group "mesh-world") collide their meshes: "kolize"
    /// (kolize::MeshShape, exact contacts; with CCD on, kolize's mesh CCD stops fast bodies),
    /// "gimpact" (btGImpactMeshShape, its default margin), "gimpact-0" (margin 0). Other
    /// scenes ignore it.
    std::string meshMethod = "kolize";
};

/// One registered scene.
struct SceneInfo {
    std::string name;     ///< e.g. "thesis-A", "boxes", "offset-1e6"
    std::string summary;  ///< one line for --help and reports
    std::string group;    ///< "thesis", "bullet", "mesh", "extreme", "stiff"
    int defaultObjects = 0;
    SceneNeeds needs;
    /// Why each stage is in or out, one short clause per stage, e.g. "no rays: nothing casts".
    std::string pipelineWhy;
    /// The box (same centre and half extent on every axis) where the scene's objects start;
    /// the offset scenes put the centre far out. Bullet's SAP quantises over it.
    double worldCentre = 0;
    double worldHalfExtent = 1000;
};

/// The dynamics' health after a frame (world scenes; a stream scene leaves zeros).
struct SceneState {
    double maxPenetration = 0;   ///< deepest contact in the dispatcher's manifolds (m, >= 0)
    int nonFinite = 0;           ///< bodies with a NaN or infinite position or velocity
    double kineticEnergy = 0;    ///< of the dynamic bodies
    double potentialEnergy = 0;  ///< gravity, relative to y = 0
    int escaped = 0;             ///< dynamic bodies that left the scene's container (tunnelled)
    int rayHits = 0;             ///< closest-hit ray casts that hit something this frame
};

/// A scene over one broadphase, built by makeScene.
class Scene {
  public:
    virtual ~Scene() = default;
    const SceneInfo& info() const { return info_; }
    /// One frame.
    virtual void step() = 0;
    virtual btBroadphaseInterface& broadphase() = 0;
    /// The world, or null for a stream scene.
    virtual TimedDynamicsWorld* world() { return nullptr; }
    /// Every proxy with the box the broadphase was last given (input of exactPairs).
    virtual std::vector<ProxyBox> proxyBoxes() const = 0;
    /// The pair cache's filter for exactPairs (null: no filter).
    virtual const btOverlappingPairCache* filter() const { return nullptr; }
    /// Seconds of the last frame spent in the broadphase: setAabb calls + pair finding.
    virtual double lastBroadphaseSeconds() const = 0;
    /// Seconds of the last frame spent in ray casts (0 when the scene casts none).
    virtual double lastRaySeconds() const { return 0; }
    virtual SceneState state() const { return {}; }
    /// Centre of mass of every dynamic body (for drift against a reference run).
    virtual std::vector<btVector3> positions() const { return {}; }
    /// Objects that move (dynamic bodies or stream objects).
    virtual int movingObjects() const = 0;

  protected:
    explicit Scene(SceneInfo info) : info_(std::move(info)) {}
    SceneInfo info_;
};

/// Every registered scene, in the order --help lists them.
const std::vector<SceneInfo>& sceneList();

/// The scene names, comma separated.
std::string sceneNameList();

/// The registered scene `name`, or throws std::invalid_argument listing the valid names.
const SceneInfo& findScene(std::string_view name);

/// Broadphase settings for the scene: SAP's world box from SceneInfo's centre and half
/// extent, room for every proxy.
BroadphaseSettings broadphaseSettingsFor(const SceneInfo& info, const SceneOptions& options);

/// Builds scene `name` over `broadphase` (owned by the scene and outliving its world).
/// Throws std::invalid_argument for an unknown name or bad options and std::runtime_error
/// when an asset cannot be read (the message names the file).
std::unique_ptr<Scene> makeScene(std::string_view name,
                                 std::unique_ptr<btBroadphaseInterface> broadphase,
                                 const SceneOptions& options = {});

}  // namespace kolize

#include "scene_builders.h"

#include <kolize/engine/falling_boxes.h>
#include <kolize/engine/thesis_scene.h>

#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <stdexcept>

namespace kolize {

namespace {

/// The thesis's scenes as a pure broadphase stream: one proxy per cube, setAabb for every
/// proxy and calculateOverlappingPairs each frame, through a btCollisionDispatcher (no
/// narrowphase runs: the proxies have no collision objects).
class ThesisStreamScene : public Scene {
  public:
    ThesisStreamScene(SceneInfo info, std::unique_ptr<btBroadphaseInterface> broadphase,
                      const ThesisSceneSettings& settings)
        : Scene(std::move(info)),
          scene_(settings),
          dispatcher_(&configuration_),
          broadphase_(std::move(broadphase)) {
        if (!broadphase_) {
            throw std::invalid_argument("scene '" + info_.name + "': no broadphase given");
        }
        proxies_.reserve(std::size_t(scene_.size()));
        for (int i = 0; i < scene_.size(); ++i) {
            const auto& box = scene_.boxes()[std::size_t(i)];
            proxies_.push_back(broadphase_->createProxy(
                lo(box), hi(box), BOX_SHAPE_PROXYTYPE,
                reinterpret_cast<void*>(static_cast<std::uintptr_t>(i + 1)), 1, -1, &dispatcher_));
        }
    }
    ~ThesisStreamScene() override {
        for (btBroadphaseProxy* proxy : proxies_) {
            broadphase_->destroyProxy(proxy, &dispatcher_);
        }
    }

    void step() override {
        scene_.step();
        const auto start = std::chrono::steady_clock::now();
        for (int i = 0; i < scene_.size(); ++i) {
            const auto& box = scene_.boxes()[std::size_t(i)];
            broadphase_->setAabb(proxies_[std::size_t(i)], lo(box), hi(box), &dispatcher_);
        }
        broadphase_->calculateOverlappingPairs(&dispatcher_);
        lastSeconds_ =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    btBroadphaseInterface& broadphase() override { return *broadphase_; }
    std::vector<ProxyBox> proxyBoxes() const override {
        std::vector<ProxyBox> out;
        out.reserve(proxies_.size());
        for (int i = 0; i < scene_.size(); ++i) {
            const auto& box = scene_.boxes()[std::size_t(i)];
            out.push_back({proxies_[std::size_t(i)], lo(box), hi(box)});
        }
        return out;
    }
    double lastBroadphaseSeconds() const override { return lastSeconds_; }
    int movingObjects() const override { return scene_.size(); }

  private:
    static btVector3 lo(const ThesisScene<3>::Box& box) {
        return btVector3(btScalar(box.lo[0]), btScalar(box.lo[1]), btScalar(box.lo[2]));
    }
    static btVector3 hi(const ThesisScene<3>::Box& box) {
        return btVector3(btScalar(box.hi[0]), btScalar(box.hi[1]), btScalar(box.hi[2]));
    }

    ThesisScene<3> scene_;
    btDefaultCollisionConfiguration configuration_;
    btCollisionDispatcher dispatcher_;
    std::unique_ptr<btBroadphaseInterface> broadphase_;
    std::vector<btBroadphaseProxy*> proxies_;
    double lastSeconds_ = 0;
};

ThesisMotion parseMotion(const std::string& motion) {
    if (motion == "slow") {
        return ThesisMotion::Slow;
    }
    if (motion == "fast") {
        return ThesisMotion::Fast;
    }
    throw std::invalid_argument("motion must be slow or fast, got '" + motion + "'");
}

std::unique_ptr<Scene> buildThesis(const SceneInfo& info,
                                   std::unique_ptr<btBroadphaseInterface> broadphase,
                                   const SceneOptions& options) {
    ThesisSceneSettings settings;
    settings.layout = info.name == "thesis-A" ? ThesisLayout::Uniform : ThesisLayout::Clustered;
    settings.motion = parseMotion(options.motion);
    settings.objects = options.objects > 0 ? options.objects : info.defaultObjects;
    settings.seed = options.seed;
    return std::make_unique<ThesisStreamScene>(info, std::move(broadphase), settings);
}

std::unique_ptr<Scene> buildBoxes(const SceneInfo& info,
                                  std::unique_ptr<btBroadphaseInterface> broadphase,
                                  const SceneOptions& options) {
    FallingBoxesSettings settings;
    settings.groundIsPlane = info.name == "boxes-plane";
    settings.timeStep = options.timeStep;
    const int objects = options.objects > 0 ? options.objects : info.defaultObjects;
    const int perLayer = settings.boxesPerRow * settings.boxesPerRow;
    settings.layers = std::max(1, (objects + perLayer - 1) / perLayer);
    return std::make_unique<FallingBoxesWorld>(std::move(broadphase), settings, options);
}

SceneNeeds streamNeeds() {
    SceneNeeds needs;
    needs.dynamics = false;
    return needs;
}

const char* kStreamWhy =
    "pure broadphase stream (thesis experiment): no world, narrowphase or solver; no rays; "
    "no meshes; no continuous stages (boxes only)";
const char* kBoxesWhy =
    "dynamics: boxes fall and stack; no rays: nothing casts; no meshes: boxes and a ground "
    "only; no continuous stages: falling speeds stay below a box size per step";

}  // namespace

const std::vector<SceneEntry>& sceneEntries() {
    static const std::vector<SceneEntry> entries = [] {
        std::vector<SceneEntry> list;
        auto add = [&](SceneInfo info, SceneBuilder builder) {
            list.push_back({std::move(info), builder});
        };
        // The thesis's scenes live in -500..500; the boxes start within a few metres.
        auto thesis = [&](const char* name, const char* summary) {
            add({name, summary, "thesis", 1000, streamNeeds(), kStreamWhy, 0, 500 * 1.01},
                buildThesis);
        };
        auto boxes = [&](const char* name, const char* summary) {
            add({name, summary, "bullet", 3008, SceneNeeds{}, kBoxesWhy, 0, 1000}, buildBoxes);
        };
        thesis("thesis-A",
               "the thesis's scene A: 1000 turning cubes (edge 2) spread uniformly over "
               "-500..500, slow or fast (--motion)");
        thesis("thesis-B",
               "the thesis's scene B: 95% of 1000 turning cubes in a cluster of edge 80, the "
               "rest uniform over -500..500, slow or fast (--motion)");
        boxes("boxes",
              "Bullet's benchmark: 3000 unit boxes (layers of 8 x 8) falling onto a static "
              "ground box");
        boxes("boxes-plane",
              "the same 3000 boxes falling onto a static plane (its AABB is +-1e18)");
        addWorldScenes(list);
        addMeshBodyScenes(list);
        addBulletBenchmarkScenes(list);
        return list;
    }();
    return entries;
}

const std::vector<SceneInfo>& sceneList() {
    static const std::vector<SceneInfo> list = [] {
        std::vector<SceneInfo> out;
        for (const SceneEntry& entry : sceneEntries()) {
            out.push_back(entry.info);
        }
        return out;
    }();
    return list;
}

std::string sceneNameList() {
    std::string out;
    for (const SceneInfo& info : sceneList()) {
        out += (out.empty() ? "" : ", ") + info.name;
    }
    return out;
}

const SceneInfo& findScene(std::string_view name) {
    for (const SceneEntry& entry : sceneEntries()) {
        if (entry.info.name == name) {
            return entry.info;
        }
    }
    throw std::invalid_argument("unknown scene '" + std::string(name) +
                                "'; valid: " + sceneNameList());
}

BroadphaseSettings broadphaseSettingsFor(const SceneInfo& info, const SceneOptions& options) {
    BroadphaseSettings settings;
    const btScalar low = btScalar(info.worldCentre - info.worldHalfExtent);
    const btScalar high = btScalar(info.worldCentre + info.worldHalfExtent);
    settings.worldMin = btVector3(low, low, low);
    settings.worldMax = btVector3(high, high, high);
    const int objects = options.objects > 0 ? options.objects : info.defaultObjects;
    settings.maxProxies = std::max(settings.maxProxies, objects + 64);
    return settings;
}

std::unique_ptr<Scene> makeScene(std::string_view name,
                                 std::unique_ptr<btBroadphaseInterface> broadphase,
                                 const SceneOptions& options) {
    if (options.objects < 0) {
        throw std::invalid_argument("scene '" + std::string(name) +
                                    "': the object count must not be negative");
    }
    for (const SceneEntry& entry : sceneEntries()) {
        if (entry.info.name == name) {
            return entry.build(entry.info, std::move(broadphase), options);
        }
    }
    findScene(name);  // throws, listing the names
    return nullptr;
}

}  // namespace kolize

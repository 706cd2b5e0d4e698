// kolize's configurations as benchmark methods: tree kind, leaf size and query settings.

#include "method.h"

#include <chrono>
#include <stdexcept>

namespace kolize::narrowbench {

using namespace narrowphase;

const char* modeName(Mode mode) {
    switch (mode) {
        case Mode::kYesNo:
            return "yesno";
        case Mode::kPairs:
            return "pairs";
        case Mode::kContacts:
            return "contacts";
    }
    return "?";
}

namespace {

/// "kolize-obb-4", optionally with a suffix: "-nosphere" (no sphere stages), "-thesis"
/// (descent A first, then B), "-larger" (descend the larger node: FCL's rule), "-front" (restart
/// from the last front: at a repeated pose, the coherence best case), "-facing" (the thesis's
/// facing-the-motion filter, B moving towards A).
struct Config {
    TreeKind kind = TreeKind::kObb;
    int leaf = 4;
    std::string variant;
};

Config parse(const std::string& name) {
    const std::string prefix = "kolize-";
    if (name.rfind(prefix, 0) != 0) {
        throw std::invalid_argument("not a kolize method: '" + name + "'");
    }
    std::string rest = name.substr(prefix.size());
    Config c;
    const std::size_t dash = rest.find('-');
    const std::string kind = rest.substr(0, dash);
    bool found = false;
    for (TreeKind k : {TreeKind::kSphere, TreeKind::kAabb, TreeKind::kObb, TreeKind::kKdop6,
                       TreeKind::kKdop14, TreeKind::kKdop18, TreeKind::kKdop26}) {
        if (kind == treeKindName(k)) {
            c.kind = k;
            found = true;
        }
    }
    if (!found || dash == std::string::npos) {
        throw std::invalid_argument("unknown kolize method '" + name +
                                    "' (kolize-KIND-LEAF[-VARIANT], e.g. kolize-obb-4)");
    }
    rest = rest.substr(dash + 1);
    const std::size_t dash2 = rest.find('-');
    c.leaf = std::stoi(rest.substr(0, dash2));
    if (dash2 != std::string::npos) {
        c.variant = rest.substr(dash2 + 1);
        if (c.variant != "nosphere" && c.variant != "thesis" && c.variant != "front" &&
            c.variant != "facing" && c.variant != "larger") {
            throw std::invalid_argument("unknown variant in '" + name +
                                        "' (nosphere, thesis, larger, front, facing)");
        }
    }
    if (c.leaf < 1 || c.leaf > 8) {
        throw std::invalid_argument("leaf size in '" + name + "' outside 1..8");
    }
    return c;
}

class KolizeMethod : public Method {
  public:
    explicit KolizeMethod(std::string name) : name_(std::move(name)), config_(parse(name_)) {}
    std::string name() const override { return name_; }
    /// Every configuration answers all-pairs queries; yes/no and contacts (the same
    /// traversal, one stopping early, one adding geometry) run at leaf sizes 1, 4 and 8.
    bool supports(Mode mode) const override {
        if (mode == Mode::kPairs) {
            return true;
        }
        return config_.variant != "facing" &&
               (config_.leaf == 1 || config_.leaf == 4 || config_.leaf == 8);
    }
    void prepare(const workload::WorkloadMesh& a, const workload::WorkloadMesh& b) override {
        const TreeSettings settings{config_.kind, config_.leaf};
        // Build time: median of three builds of A's tree.
        std::vector<double> seconds;
        for (int i = 0; i < 3; ++i) {
            const auto start = std::chrono::steady_clock::now();
            modelA_ = std::make_unique<MeshModel>(a.mesh, settings);
            seconds.push_back(
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
        std::sort(seconds.begin(), seconds.end());
        build_.microsPerTriangle = seconds[1] * 1e6 / double(a.mesh->triangleCount());
        build_.bytesPerNode = double(modelA_->bytesPerNode());
        build_.nodes = modelA_->nodeCount();
        modelB_ = a.mesh == b.mesh ? nullptr : std::make_unique<MeshModel>(b.mesh, settings);
        centerB_ = b.center;
        centerA_ = a.center;
        query_.resetFront();
    }
    BuildInfo buildInfo() const override { return build_; }
    void run(const Pose& a, const Pose& b, Mode mode) override {
        QuerySettings s;
        s.mode = mode == Mode::kYesNo   ? QueryMode::kYesNo
                 : mode == Mode::kPairs ? QueryMode::kAllPairs
                                        : QueryMode::kContacts;
        s.sphere_pretest = config_.variant != "nosphere";
        s.descent = config_.variant == "thesis"   ? Descent::kFirstThenSecond
                    : config_.variant == "larger" ? Descent::kLarger
                                                  : Descent::kBoth;
        s.use_front = config_.variant == "front";
        if (config_.variant == "facing") {
            // B moves towards A: its relative motion is from B's centre to A's, in A's frame.
            s.facing_filter = true;
            s.motion = a.rotation.transpose() * ((a.rotation * centerA_ + a.translation) -
                                                 (b.rotation * centerB_ + b.translation));
        }
        query_.run(*modelA_, a, modelB_ ? *modelB_ : *modelA_, b, s);
    }
    void collect(Outcome& out) override {
        const QueryResult& r = query_.result();
        out.intersecting = r.intersecting;
        out.pairs = r.pairs;
        out.bvTests = r.counters.bv_tests + r.counters.node_sphere_tests;
        out.sphereTests = r.counters.node_sphere_tests;
        out.triangleTests = r.counters.triangle_tests;
        out.predicateFallbacks = r.counters.predicates.fallbacks();
    }

  private:
    std::string name_;
    Config config_;
    std::unique_ptr<MeshModel> modelA_, modelB_;
    Vec3 centerA_, centerB_;
    MeshQuery query_;
    BuildInfo build_;
};

}  // namespace

std::vector<std::string> kolizeMethodNames(bool quick) {
    std::vector<std::string> names;
    for (TreeKind k : {TreeKind::kObb, TreeKind::kSphere, TreeKind::kAabb, TreeKind::kKdop6,
                       TreeKind::kKdop14, TreeKind::kKdop18, TreeKind::kKdop26}) {
        for (int leaf = 1; leaf <= 8; ++leaf) {
            if (quick && leaf != 4 && !(k == TreeKind::kObb && (leaf == 1 || leaf == 8))) {
                continue;
            }
            names.push_back(std::string("kolize-") + treeKindName(k) + "-" + std::to_string(leaf));
        }
    }
    for (const char* variant : {"nosphere", "thesis", "larger", "front", "facing"}) {
        names.push_back(std::string("kolize-obb-4-") + variant);
    }
    return names;
}

std::vector<std::unique_ptr<Method>> kolizeMethods(const std::vector<std::string>& names) {
    std::vector<std::unique_ptr<Method>> out;
    for (const std::string& n : names) {
        out.push_back(std::make_unique<KolizeMethod>(n));
    }
    return out;
}

}  // namespace kolize::narrowbench

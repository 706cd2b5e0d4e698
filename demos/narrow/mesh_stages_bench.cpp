// kolize-mesh-stages: what the stage planner of the Bullet mesh algorithms (mesh_stages.h)
// saves. A world of box meshes resting or piled on a triangle-mesh floor runs with the
// planner's automatic choices and with every stage forced on, interleaved, repeated; the
// time of the narrowphase (the dispatcher's dispatchAllCollisionPairs) and of the whole step
// are medians over the repetitions. Both runs must end in the same state bit for bit (the
// planner only skips work): a speed run is also a correctness run. --query-sweep times single
// resting box-box queries with and without tree, which is where the tiny-pair limit comes from.

#include <kolize/narrowphase/bullet_mesh.h>
#include <kolize/narrowphase/mesh_stages.h>

#include <btBulletDynamicsCommon.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
using kolize::MeshStageSettings;
using kolize::narrowphase::Index3;
using kolize::narrowphase::TriangleMesh;
using kolize::narrowphase::Vec3;

const char* kUsage =
    "usage: kolize-mesh-stages [options]\n"
    "The stage planner's automatic choices against every stage forced on, in a world of box\n"
    "meshes on a triangle-mesh floor: narrowphase and step times (medians of interleaved\n"
    "repetitions), the stages that ran and were skipped and why; exits 1 when the two runs\n"
    "do not end bit for bit in the same state.\n"
    "  --scene stacks|pile  stacks: columns of boxes resting from the start; pile: boxes\n"
    "                       dropped at seeded places (default stacks)\n"
    "  --n N                boxes (default 64)\n"
    "  --grid G             faces of G x G quads: 12 G^2 triangles per box (default 1);\n"
    "                       'mixed' alternates G = 1 and 3\n"
    "  --frames F           timed frames per run (default 300)\n"
    "  --warmup W           untimed frames before them (default 60)\n"
    "  --reps R             repetitions of each mode, interleaved (default 5)\n"
    "  --seed S             pile places (default 1)\n"
    "  --sphere M, --tree M the planner run's sphere stage and tree: auto, on or off\n"
    "                       (default auto; the comparison run has every stage on)\n"
    "  --tiny-limit L       the planner run's tiny_pair_limit (default: MeshStageSettings')\n"
    "  --csv FILE           one row per run\n"
    "  --query-sweep        time single resting queries with and without tree instead\n";

[[noreturn]] void usageError(const std::string& message) {
    std::fprintf(stderr, "kolize-mesh-stages: %s (try --help)\n", message.c_str());
    std::exit(2);
}

/// A box [-h, h] whose faces are g x g grids of quads (12 g^2 outward-wound triangles).
TriangleMesh gridBoxMesh(double h, int g) {
    std::vector<Vec3> vertices;
    std::vector<Index3> triangles;
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = -1; side <= 1; side += 2) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            const std::int32_t first = std::int32_t(vertices.size());
            for (int j = 0; j <= g; ++j) {
                for (int i = 0; i <= g; ++i) {
                    Vec3 p;
                    p[axis] = side * h;
                    p[u] = h * (-1 + 2.0 * i / g);
                    p[v] = h * (-1 + 2.0 * j / g);
                    vertices.push_back(p);
                }
            }
            for (int j = 0; j < g; ++j) {
                for (int i = 0; i < g; ++i) {
                    const std::int32_t a = first + j * (g + 1) + i, b = a + 1, c = a + g + 2,
                                       d = a + g + 1;
                    if (side > 0) {
                        triangles.push_back({a, b, c});
                        triangles.push_back({a, c, d});
                    } else {
                        triangles.push_back({a, c, b});
                        triangles.push_back({a, d, c});
                    }
                }
            }
        }
    }
    return TriangleMesh("box " + std::to_string(g), vertices, triangles);
}

struct Options {
    std::string scene = "stacks";
    int n = 64;
    int grid = 1;  // 0: mixed
    int frames = 300;
    int warmup = 60;
    int reps = 5;
    unsigned seed = 1;
    std::string csv;
    bool querySweep = false;
    MeshStageSettings planner;
};

kolize::StageMode parseMode(const std::string& text, const std::string& option) {
    if (text == "auto") {
        return kolize::StageMode::kAuto;
    }
    if (text == "on") {
        return kolize::StageMode::kOn;
    }
    if (text == "off") {
        return kolize::StageMode::kOff;
    }
    usageError(option + " needs auto, on or off, not '" + text + "'");
}

/// A dispatcher that times its narrowphase.
class TimedDispatcher : public btCollisionDispatcher {
  public:
    using btCollisionDispatcher::btCollisionDispatcher;
    void dispatchAllCollisionPairs(btOverlappingPairCache* pairs, const btDispatcherInfo& info,
                                   btDispatcher* dispatcher) override {
        const auto start = Clock::now();
        btCollisionDispatcher::dispatchAllCollisionPairs(pairs, info, dispatcher);
        seconds += std::chrono::duration<double>(Clock::now() - start).count();
    }
    double seconds = 0;
};

struct World {
    World(const Options& o, const MeshStageSettings& stages) {
        kolize::registerNarrowphase(&dispatcher, stages);
        world.setGravity(btVector3(0, 0, -10));
        const int half = 12;
        floor = std::make_unique<btTriangleMesh>();
        for (int j = -half; j < half; ++j) {
            for (int i = -half; i < half; ++i) {
                const btVector3 a(i, j, 0), b(i + 1, j, 0), c(i + 1, j + 1, 0), d(i, j + 1, 0);
                floor->addTriangle(a, b, c);
                floor->addTriangle(a, c, d);
            }
        }
        add(std::make_shared<btBvhTriangleMeshShape>(floor.get(), true), btVector3(0, 0, 0), 0, 0);
        const double h = 0.25;
        auto gridOf = [&](int i) { return o.grid > 0 ? o.grid : (i % 2 == 0 ? 1 : 3); };
        std::shared_ptr<btCollisionShape> shapes[4];
        auto shapeOf = [&](int g) {
            if (!shapes[g]) {
                shapes[g] =
                    std::make_shared<kolize::MeshShape>(kolize::makeMeshModel(gridBoxMesh(h, g)));
            }
            return shapes[g];
        };
        if (o.scene == "stacks") {
            // Columns of 4, touching (1e-3 deep), 0.75 apart: every pair rests.
            const int columns = (o.n + 3) / 4;
            const int side = int(std::ceil(std::sqrt(double(columns))));
            for (int i = 0; i < o.n; ++i) {
                const int column = i / 4, level = i % 4;
                const double x = 0.75 * (column % side - side / 2) + 0.5;
                const double y = 0.75 * (column / side - side / 2) + 0.5;
                add(shapeOf(gridOf(i)),
                    btVector3(btScalar(x), btScalar(y),
                              btScalar(h + level * (2 * h - 1e-3) - 1e-3)),
                    1, 0);
            }
        } else {
            std::mt19937 random(o.seed);
            const double extent = std::max(1.0, 0.3 * std::sqrt(double(o.n)));
            std::uniform_real_distribution<double> place(-extent, extent), turn(-3.14, 3.14);
            for (int i = 0; i < o.n; ++i) {
                const double x = place(random), y = place(random), yaw = turn(random);
                add(shapeOf(gridOf(i)),
                    btVector3(btScalar(x), btScalar(y), btScalar(h + 0.6 * (i % 8) + 0.05)), 1,
                    yaw);
            }
        }
    }
    ~World() {
        for (int i = world.getNumCollisionObjects() - 1; i >= 0; --i) {
            world.removeCollisionObject(world.getCollisionObjectArray()[i]);
        }
        kolize::releaseNarrowphaseStages(&dispatcher);
    }
    void add(std::shared_ptr<btCollisionShape> shape, const btVector3& origin, btScalar mass,
             double yaw) {
        btVector3 inertia(0, 0, 0);
        if (mass > 0) {
            shape->calculateLocalInertia(mass, inertia);
        }
        btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, shape.get(), inertia);
        info.m_startWorldTransform.setIdentity();
        info.m_startWorldTransform.setOrigin(origin);
        info.m_startWorldTransform.setRotation(btQuaternion(btVector3(0, 0, 1), btScalar(yaw)));
        bodies.push_back(std::make_unique<btRigidBody>(info));
        bodies.back()->setActivationState(DISABLE_DEACTIVATION);  // every frame does the work
        world.addRigidBody(bodies.back().get());
        keep.push_back(std::move(shape));
    }
    /// FNV-1a over every body's transform and velocities.
    std::uint64_t checksum() const {
        std::uint64_t hash = 1469598103934665603ull;
        auto mix = [&](const btVector3& v) {
            for (int k = 0; k < 3; ++k) {
                const btScalar value = v[k];
                unsigned char bytes[sizeof value];
                std::memcpy(bytes, &value, sizeof value);
                for (unsigned char byte : bytes) {
                    hash = (hash ^ byte) * 1099511628211ull;
                }
            }
        };
        for (const auto& body : bodies) {
            const btTransform& t = body->getWorldTransform();
            for (int r = 0; r < 3; ++r) {
                mix(t.getBasis()[r]);
            }
            mix(t.getOrigin());
            mix(body->getLinearVelocity());
            mix(body->getAngularVelocity());
        }
        return hash;
    }

    btDefaultCollisionConfiguration configuration;
    TimedDispatcher dispatcher{&configuration};
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
    std::unique_ptr<btTriangleMesh> floor;
    std::vector<std::shared_ptr<btCollisionShape>> keep;
    std::vector<std::unique_ptr<btRigidBody>> bodies;
};

struct Run {
    double narrowMs = 0;  // per frame
    double stepMs = 0;
    std::uint64_t checksum = 0;
    kolize::MeshStageStats stats;
};

Run runOnce(const Options& o, const MeshStageSettings& stages) {
    World w(o, stages);
    for (int f = 0; f < o.warmup; ++f) {
        w.world.stepSimulation(btScalar(1.0 / 60), 0);
    }
    kolize::resetNarrowphaseStages(&w.dispatcher);
    w.dispatcher.seconds = 0;
    const auto start = Clock::now();
    for (int f = 0; f < o.frames; ++f) {
        w.world.stepSimulation(btScalar(1.0 / 60), 0);
    }
    const double total = std::chrono::duration<double>(Clock::now() - start).count();
    Run run;
    run.narrowMs = 1e3 * w.dispatcher.seconds / o.frames;
    run.stepMs = 1e3 * total / o.frames;
    run.checksum = w.checksum();
    run.stats = kolize::narrowphaseStages(&w.dispatcher);
    return run;
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Single queries of two boxes, with and without tree, the median time of blocks of
/// queries: resting (one 1e-3 into the other, turned a little: many triangle pairs touch)
/// and near (apart by 0.01 along x, object spheres overlapping: the tree's root test ends it).
void querySweep() {
    namespace np = kolize::narrowphase;
    std::printf("%-8s %-10s %-8s %12s %12s %12s\n", "pose", "triangles", "pairs", "tree (us)",
                "direct (us)", "direct/tree");
    const int grids[][2] = {{1, 1}, {1, 2}, {2, 2}, {1, 3}, {2, 3}, {3, 3}};
    for (const char* pose : {"resting", "near"}) {
        for (const auto& g : grids) {
            const auto a = kolize::makeMeshModel(gridBoxMesh(0.25, g[0]));
            const auto b = kolize::makeMeshModel(gridBoxMesh(0.25, g[1]));
            np::Pose pa, pb;
            if (std::strcmp(pose, "resting") == 0) {
                pb.translation = Vec3(0.05, 0.02, 0.5 - 1e-3);
                pb.rotation = Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix();
            } else {
                pb.translation = Vec3(0.51, 0.2, 0.1);
            }
            double us[2];
            for (int direct = 0; direct < 2; ++direct) {
                np::QuerySettings s;
                s.mode = np::QueryMode::kContacts;
                s.use_front = true;
                s.use_tree = direct == 0;
                np::MeshQuery query;
                std::vector<double> blocks;
                for (int block = 0; block < 21; ++block) {
                    const auto start = Clock::now();
                    for (int k = 0; k < 2000; ++k) {
                        query.run(*a, pa, *b, pb, s);
                    }
                    blocks.push_back(
                        std::chrono::duration<double, std::micro>(Clock::now() - start).count() /
                        2000);
                }
                us[direct] = median(blocks);
            }
            const std::size_t na = a->mesh().triangleCount(), nb = b->mesh().triangleCount();
            std::printf("%-8s %3zu x %-4zu %-8zu %12.3f %12.3f %12.2f\n", pose, na, nb, na * nb,
                        us[0], us[1], us[1] / us[0]);
        }
    }
}

int parseInt(const char* text, const char* option, int lo) {
    char* end = nullptr;
    const long value = std::strtol(text, &end, 10);
    if (end == text || *end != '\0' || value < lo || value > 1000000) {
        usageError(std::string(option) + " needs a whole number of at least " + std::to_string(lo));
    }
    return int(value);
}

}  // namespace

int main(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&]() -> const char* {
            if (i + 1 >= argc) {
                usageError(arg + " needs a value");
            }
            return argv[++i];
        };
        if (arg == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        } else if (arg == "--scene") {
            o.scene = value();
            if (o.scene != "stacks" && o.scene != "pile") {
                usageError("unknown scene '" + o.scene + "'; valid: stacks, pile");
            }
        } else if (arg == "--n") {
            o.n = parseInt(value(), "--n", 1);
        } else if (arg == "--grid") {
            const std::string g = value();
            o.grid = g == "mixed" ? 0 : parseInt(g.c_str(), "--grid", 1);
            if (o.grid > 3) {
                usageError("--grid needs 1, 2, 3 or mixed");
            }
        } else if (arg == "--frames") {
            o.frames = parseInt(value(), "--frames", 1);
        } else if (arg == "--warmup") {
            o.warmup = parseInt(value(), "--warmup", 0);
        } else if (arg == "--reps") {
            o.reps = parseInt(value(), "--reps", 1);
        } else if (arg == "--seed") {
            o.seed = unsigned(parseInt(value(), "--seed", 0));
        } else if (arg == "--sphere") {
            o.planner.sphere_stage = parseMode(value(), arg);
        } else if (arg == "--tree") {
            o.planner.tree = parseMode(value(), arg);
        } else if (arg == "--tiny-limit") {
            o.planner.tiny_pair_limit = parseInt(value(), "--tiny-limit", 0);
        } else if (arg == "--csv") {
            o.csv = value();
        } else if (arg == "--query-sweep") {
            o.querySweep = true;
        } else {
            usageError("unknown option '" + arg + "'");
        }
    }
    if (o.querySweep) {
        querySweep();
        return 0;
    }
    std::FILE* csv = nullptr;
    if (!o.csv.empty()) {
        csv = std::fopen(o.csv.c_str(), "w");
        if (!csv) {
            usageError("cannot write '" + o.csv + "'");
        }
        std::fprintf(csv, "scene,n,grid,frames,mode,rep,narrow_ms,step_ms,checksum\n");
    }
    const MeshStageSettings modes[2] = {o.planner, MeshStageSettings::allOn()};
    const char* names[2] = {"planner", "all-on"};
    std::vector<double> narrow[2], step[2];
    Run last[2];
    bool same = true;
    for (int rep = 0; rep < o.reps; ++rep) {
        for (int k = 0; k < 2; ++k) {
            const int mode = (rep + k) % 2;  // alternate which mode goes first
            last[mode] = runOnce(o, modes[mode]);
            narrow[mode].push_back(last[mode].narrowMs);
            step[mode].push_back(last[mode].stepMs);
            if (csv) {
                std::fprintf(csv, "%s,%d,%s,%d,%s,%d,%.6f,%.6f,%016llx\n", o.scene.c_str(), o.n,
                             o.grid ? std::to_string(o.grid).c_str() : "mixed", o.frames,
                             names[mode], rep, last[mode].narrowMs, last[mode].stepMs,
                             (unsigned long long)last[mode].checksum);
            }
        }
        same = same && last[0].checksum == last[1].checksum;
    }
    if (csv) {
        std::fclose(csv);
    }
    std::printf("scene %s, %d boxes (grid %s), %d frames after %d, %d repetitions\n",
                o.scene.c_str(), o.n, o.grid ? std::to_string(o.grid).c_str() : "mixed", o.frames,
                o.warmup, o.reps);
    for (int mode = 0; mode < 2; ++mode) {
        std::printf(
            "\n[%s] narrowphase %.3f ms/frame (min %.3f, max %.3f), step %.3f ms/frame "
            "(min %.3f, max %.3f), checksum %016llx\n",
            names[mode], median(narrow[mode]),
            *std::min_element(narrow[mode].begin(), narrow[mode].end()),
            *std::max_element(narrow[mode].begin(), narrow[mode].end()), median(step[mode]),
            *std::min_element(step[mode].begin(), step[mode].end()),
            *std::max_element(step[mode].begin(), step[mode].end()),
            (unsigned long long)last[mode].checksum);
        std::fputs(kolize::describeStages(last[mode].stats).c_str(), stdout);
    }
    const double saved = median(narrow[1]) - median(narrow[0]);
    std::printf(
        "\ntime saved against every stage on: narrowphase %.3f ms/frame (%.1f%%), step "
        "%.3f ms/frame (%.1f%%)\n",
        saved, 100 * saved / median(narrow[1]), median(step[1]) - median(step[0]),
        100 * (median(step[1]) - median(step[0])) / median(step[1]));
    if (!same) {
        std::printf("ERROR: the runs ended in different states: the planner changed an answer\n");
        return 1;
    }
    std::printf("same final state bit for bit in every repetition\n");
    return 0;
}

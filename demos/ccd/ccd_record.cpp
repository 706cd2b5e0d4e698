/// kolize-ccd-record [--out DIR] [--model PATH] [--every N]
///
/// Records the vertex-face and edge-edge queries that kolize's own mesh CCD (meshCcd) runs,
/// as benchmark data in the Sample-Queries format (readable by kolize-ccd-bench and checked
/// against the exact reference by `kolize-ccd-soak --data DIR`). Scenes:
///   wuson               the mesh demo's 48 scenarios: a copy of the model (default
///                       assimp's Wuson.ply, 3732 triangles) fired at itself while turning;
///   thin-wall           the tunneling demo's cube fired at a thin plate, 8 speeds;
///   thin-wall-spinning  the same cube spinning about a random axis while it flies.
/// Each query is replayed over the whole step [0, 1] (meshCcd asked about one time slice),
/// so its label T says whether the primitives touch during [0, 1]: true for every query
/// that hit in its slice, otherwise decided again by `robust` over the whole step. Every
/// colliding query is written, and every N-th non-colliding one (default 20); repeated
/// queries (the same pair in several slices) once. Writes DIR/<scene>/<kind>/data.csv
/// (default DIR: ccd-mesh-queries) and prints what it recorded.
#include "ccd_scenes.h"
#include "model_loader.h"

#include "kolize/narrowphase/ccd_dataset.h"

#include <Eigen/Geometry>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace kolize::ccd;

/// Collects the queries of one scene.
class Recorder : public QueryObserver {
  public:
    explicit Recorder(int every) : every_(every) {}

    void observe(bool edge_edge, const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                 const RobustSettings&, const CcdResult& result) override {
        Kind& kind = kinds_[edge_edge];
        ++kind.observed;
        std::string key(reinterpret_cast<const char*>(start.data()), sizeof start);
        key.append(reinterpret_cast<const char*>(end.data()), sizeof end);
        if (!kind.seen.insert(std::move(key)).second) {
            return;
        }
        LabeledQuery q{start, end, result.hit};
        if (!q.collides) {
            const RobustSettings whole_step;  // no observer: not recorded again
            q.collides = robustQuery(edge_edge ? QueryKind::kEdgeEdge : QueryKind::kVertexFace, q,
                                     whole_step)
                             .hit;
        }
        if (q.collides || kind.misses++ % every_ == 0) {
            kind.queries.push_back(q);
        }
    }

    /// Writes DIR/scene/<kind>/data.csv and prints a line per kind.
    void write(const std::filesystem::path& dir, const std::string& scene) const {
        for (int k = 0; k < 2; ++k) {
            const QueryKind kind = k ? QueryKind::kEdgeEdge : QueryKind::kVertexFace;
            const auto folder = dir / scene / kindName(kind);
            std::filesystem::create_directories(folder);
            writeQueryCsv((folder / "data.csv").string(), kinds_[k].queries);
            size_t colliding = 0;
            for (const LabeledQuery& q : kinds_[k].queries) {
                colliding += q.collides;
            }
            std::printf("%-20s %-11s %10zu %10zu %10zu %10zu\n", scene.c_str(), kindName(kind),
                        kinds_[k].observed, kinds_[k].seen.size(), colliding,
                        kinds_[k].queries.size() - colliding);
        }
    }

  private:
    struct Kind {
        size_t observed = 0, misses = 0;
        std::set<std::string> seen;
        std::vector<LabeledQuery> queries;
    };
    int every_;
    Kind kinds_[2];
};

MeshCcdSettings recordingInto(Recorder& recorder) {
    MeshCcdSettings s;
    s.primitive.observer = &recorder;
    return s;
}

/// The cube of the thin-wall trial, spinning by up to 1 radian about a random axis through
/// its centre while it flies (vertices still move linearly between the two poses).
MovingMesh spinningCube(const scenes::ThinWall::Trial& t, scenes::Random& random) {
    MovingMesh m = scenes::boxMesh(t.lo, t.hi, t.motion);
    const Vec3 centre = 0.5 * (t.lo + t.hi);
    const Vec3 axis =
        Vec3(random.next() - 0.5, random.next() - 0.5, random.next() - 0.5).normalized();
    const Eigen::AngleAxisd start_pose(6.3 * random.next(), axis.unitOrthogonal());
    const Eigen::AngleAxisd turn(random.next(), axis);
    for (size_t v = 0; v < m.start.size(); ++v) {
        const Vec3 local = start_pose * (m.start[v] - centre);
        m.start[v] = centre + local;
        m.end[v] = centre + t.motion + turn * local;
    }
    return m;
}

int usage() {
    std::fprintf(stderr, "usage: kolize-ccd-record [--out DIR] [--model PATH] [--every N]\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::filesystem::path out = "ccd-mesh-queries";
    std::string model = "/usr/share/assimp/models/PLY/Wuson.ply";
    int every = 20;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (i + 1 >= argc) {
            return usage();
        }
        if (a == "--out") {
            out = argv[++i];
        } else if (a == "--model") {
            model = argv[++i];
        } else if (a == "--every") {
            every = std::atoi(argv[++i]);
            if (every < 1) {
                return usage();
            }
        } else {
            return usage();
        }
    }
    MovingMesh fixed;
    if (!loadModel(model, fixed, "kolize-ccd-record")) {
        return 1;
    }
    std::printf("%-20s %-11s %10s %10s %10s %10s\n", "scene", "kind", "observed", "distinct",
                "colliding", "kept-miss");
    try {
        {
            Recorder recorder(every);
            const MeshCcdSettings s = recordingInto(recorder);
            scenes::forEachFiredCopy(fixed,
                                     [&](const MovingMesh& moving) { meshCcd(moving, fixed, s); });
            recorder.write(out, "wuson");
        }
        const scenes::ThinWall wall;
        const std::vector<double> speeds{0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10};
        for (const bool spinning : {false, true}) {
            Recorder recorder(every);
            const MeshCcdSettings s = recordingInto(recorder);
            scenes::Random random;
            for (double speed : speeds) {
                for (int trial = 0; trial < 50; ++trial) {
                    const auto t = scenes::ThinWall::trial(speed, random);
                    const MovingMesh cube =
                        spinning ? spinningCube(t, random) : scenes::boxMesh(t.lo, t.hi, t.motion);
                    meshCcd(cube, wall.plate, s);
                }
            }
            recorder.write(out, spinning ? "thin-wall-spinning" : "thin-wall");
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kolize-ccd-record: %s\n", e.what());
        return 1;
    }
    std::printf("\nwrote %s/<scene>/<vertex-face|edge-edge>/data.csv\n", out.string().c_str());
    return 0;
}

#include <kolize/engine/narrow_workload.h>

#include <kolize/narrowphase/mesh_query.h>

#ifdef KOLIZE_WITH_ASSIMP
#include <kolize/engine/assets.h>
#endif

#include <Eigen/Geometry>

#include <sys/stat.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <stdexcept>

namespace kolize::workload {

using narrowphase::Index3;
using narrowphase::MeshQuery;
using narrowphase::ObbNode;
using narrowphase::QueryMode;
using narrowphase::QuerySettings;
using narrowphase::RelativePose;

namespace {

bool isDirectory(const std::string& path) {
    struct stat info;
    return stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode);
}

/// Records the box centre and radius, scaling every vertex by the power of two that puts
/// the radius in (0.5, 1] (exact: no degeneracy is lost).
WorkloadMesh placed(std::string name, std::vector<Vec3> vertices, std::vector<Index3> triangles) {
    Vec3 lo = vertices.at(0), hi = lo;
    for (const Vec3& v : vertices) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
    }
    Vec3 center = 0.5 * (lo + hi);
    double radius = 0;
    for (const Vec3& v : vertices) {
        radius = std::max(radius, (v - center).norm());
    }
    const double scale = radius > 0 ? std::ldexp(1.0, -int(std::ceil(std::log2(radius)))) : 1.0;
    for (Vec3& v : vertices) {
        v *= scale;
    }
    WorkloadMesh out;
    out.name = name;
    out.center = center * scale;
    out.radius = radius * scale;
    out.mesh = std::make_shared<const TriangleMesh>(std::move(name), std::move(vertices),
                                                    std::move(triangles));
    return out;
}

Eigen::Matrix3d randomRotation(std::mt19937& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
    q.normalize();
    return q.toRotationMatrix();
}

Vec3 randomDirection(std::mt19937& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    Vec3 d(n(rng), n(rng), n(rng));
    return d.normalized();
}

}  // namespace

std::string assimpModelsDirectory() {
    if (const char* env = std::getenv("KOLIZE_ASSIMP_MODELS")) {
        return isDirectory(env) ? env : "";
    }
    for (const char* candidate : {"/usr/share/assimp/models", "/usr/share/assimp-testmodels"}) {
        if (isDirectory(candidate)) {
            return candidate;
        }
    }
    return "";
}

WorkloadMesh loadModel(const std::string& relativePath, const std::string& name) {
    const std::string directory = assimpModelsDirectory();
    if (directory.empty()) {
        throw std::runtime_error("model '" + relativePath +
                                 "': Debian's assimp-testmodels not found (install it: "
                                 "scripts/deps.sh, or set KOLIZE_ASSIMP_MODELS)");
    }
#ifdef KOLIZE_WITH_ASSIMP
    const LoadedMesh loaded = loadMesh(directory + "/" + relativePath);
    std::vector<Vec3> vertices;
    vertices.reserve(loaded.vertices.size());
    for (const btVector3& v : loaded.vertices) {
        vertices.emplace_back(double(v.x()), double(v.y()), double(v.z()));
    }
    std::vector<Index3> triangles(loaded.triangles.begin(), loaded.triangles.end());
    return placed(name, std::move(vertices), std::move(triangles));
#else
    throw std::runtime_error("model '" + relativePath +
                             "': kolize's engine was built without assimp (KOLIZE_WITH_ASSIMP)");
#endif
}

const std::vector<ModelFile>& standardModels() {
    static const std::vector<ModelFile> models = {
        {"spider", "OBJ/spider.obj"},   {"MotionCaptureROM", "ASE/MotionCaptureROM.ase"},
        {"Wuson", "OBJ/WusonOBJ.obj"},  {"duck", "Collada/duck.dae"},
        {"HUMAN", "BLEND/HUMAN.blend"}, {"SphereWithLight", "AC/SphereWithLight.ac"},
        {"Wuson-ply", "PLY/Wuson.ply"},
    };
    return models;
}

WorkloadMesh uvSphere(int rings, int segments) {
    std::vector<Vec3> v;
    std::vector<Index3> t;
    v.emplace_back(0, 0, 1);
    for (int i = 1; i < rings; ++i) {
        const double theta = M_PI * i / rings;
        for (int j = 0; j < segments; ++j) {
            const double phi = 2 * M_PI * j / segments;
            v.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                           std::cos(theta));
        }
    }
    v.emplace_back(0, 0, -1);
    const int south = int(v.size()) - 1;
    auto ring = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
    for (int j = 0; j < segments; ++j) {
        t.push_back({0, ring(1, j), ring(1, j + 1)});
        t.push_back({south, ring(rings - 1, j + 1), ring(rings - 1, j)});
    }
    for (int i = 1; i + 1 < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            t.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
            t.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
        }
    }
    return placed("uv-sphere-" + std::to_string(rings) + "x" + std::to_string(segments),
                  std::move(v), std::move(t));
}

WorkloadMesh torus(int rings, int segments, double tube) {
    std::vector<Vec3> v;
    std::vector<Index3> t;
    const double major = 1.0 - tube;
    for (int i = 0; i < rings; ++i) {
        const double u = 2 * M_PI * i / rings;
        for (int j = 0; j < segments; ++j) {
            const double w = 2 * M_PI * j / segments;
            const double r = major + tube * std::cos(w);
            v.emplace_back(r * std::cos(u), r * std::sin(u), tube * std::sin(w));
        }
    }
    auto at = [&](int i, int j) { return (i % rings) * segments + (j % segments); };
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            t.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            t.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    }
    return placed("torus-" + std::to_string(rings) + "x" + std::to_string(segments), std::move(v),
                  std::move(t));
}

WorkloadMesh subdividedBox(int n) {
    std::vector<Vec3> v;
    std::vector<Index3> t;
    // Six faces, each an (n+1)^2 grid of its own vertices (the seams repeat vertices).
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = -1; side <= 1; side += 2) {
            const int base = int(v.size());
            const int u = (axis + 1) % 3, w = (axis + 2) % 3;
            for (int i = 0; i <= n; ++i) {
                for (int j = 0; j <= n; ++j) {
                    Vec3 p;
                    p[axis] = side;
                    p[u] = -1.0 + 2.0 * i / n;
                    p[w] = -1.0 + 2.0 * j / n;
                    v.push_back(p);
                }
            }
            for (int i = 0; i < n; ++i) {
                for (int j = 0; j < n; ++j) {
                    const int a = base + i * (n + 1) + j, b = a + n + 1;
                    if (side > 0) {
                        t.push_back({a, b, b + 1});
                        t.push_back({a, b + 1, a + 1});
                    } else {
                        t.push_back({a, b + 1, b});
                        t.push_back({a, a + 1, b + 1});
                    }
                }
            }
        }
    }
    return placed("box-" + std::to_string(n), std::move(v), std::move(t));
}

WorkloadMesh sheetWithDegenerates(int n) {
    std::vector<Vec3> v;
    std::vector<Index3> t;
    // Coordinates are multiples of 2^-20, so p + k * e stays exact for the 2^-10 steps e
    // below: the collinear triangles are exactly collinear.
    auto snap = [](double x) { return std::round(x * 0x1p20) * 0x1p-20; };
    for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j) {
            const double x = -0.7 + 1.4 * i / n, y = -0.7 + 1.4 * j / n;
            v.emplace_back(snap(x), snap(y), snap(0.15 * std::sin(3 * x) * std::cos(2 * y)));
        }
    }
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            const int a = i * (n + 1) + j, b = a + n + 1;
            const int cell = i * n + j;
            if (cell % 7 == 3) {
                t.push_back({a, a, b});  // repeated vertex
            } else {
                t.push_back({a, b, b + 1});
            }
            if (cell % 11 == 5) {
                const Vec3 e(0x1p-10, 0x1p-11, 0x1p-12);
                const int p = int(v.size());
                v.push_back(v[a]);
                v.push_back(v[a] + e);
                v.push_back(v[a] + 2 * e);
                t.push_back({p, p + 1, p + 2});  // collinear
            }
            t.push_back({a, b + 1, a + 1});
        }
    }
    return placed("sheet-" + std::to_string(n), std::move(v), std::move(t));
}

const char* poseClassName(PoseClass kind) {
    switch (kind) {
        case PoseClass::kDeep:
            return "deep";
        case PoseClass::kShallow:
            return "shallow";
        case PoseClass::kNear:
            return "near";
        case PoseClass::kApart:
            return "apart";
        case PoseClass::kApartObb:
            return "apart-obb";
        case PoseClass::kCoincident:
            return "coincident";
        case PoseClass::kShifted:
            return "shifted";
    }
    return "?";
}

const std::vector<PoseClass>& allPoseClasses() {
    static const std::vector<PoseClass> classes = {
        PoseClass::kDeep,     PoseClass::kShallow,    PoseClass::kNear,   PoseClass::kApart,
        PoseClass::kApartObb, PoseClass::kCoincident, PoseClass::kShifted};
    return classes;
}

std::vector<WorkloadPose> makePoses(const WorkloadMesh& a, const MeshModel& modelA,
                                    const WorkloadMesh& b, const MeshModel& modelB, PoseClass kind,
                                    int count, std::uint32_t seed) {
    std::vector<WorkloadPose> out;
    if (kind == PoseClass::kCoincident || kind == PoseClass::kShifted) {
        if (a.mesh != b.mesh) {
            throw std::invalid_argument(std::string(poseClassName(kind)) +
                                        " poses need a mesh against its own copy, not '" + a.name +
                                        "' against '" + b.name + "'");
        }
        if (kind == PoseClass::kCoincident) {
            out.push_back({kind, Pose{}, Pose{}});
        } else {
            for (int axis = 0; axis < 3; ++axis) {
                Pose shifted;
                shifted.translation[axis] = 0x1p-8;
                out.push_back({kind, Pose{}, shifted});
            }
        }
        return out;
    }
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    MeshQuery query;
    QuerySettings yesNo;
    yesNo.mode = QueryMode::kYesNo;
    const double r = 0.5 * (a.radius + b.radius);
    const double sMax = (a.radius + b.radius) * 1.001 + 1e-9;
    const narrowphase::Obb& rootA = modelA.tree<ObbNode>().nodes()[0].volume;
    const narrowphase::Obb& rootB = modelB.tree<ObbNode>().nodes()[0].volume;
    for (int attempt = 0; int(out.size()) < count && attempt < 50 * count; ++attempt) {
        Pose pa, pb;
        pa.rotation = randomRotation(rng);
        pb.rotation = randomRotation(rng);
        pa.translation = -(pa.rotation * a.center);
        const Vec3 direction = randomDirection(rng);
        // B's centre at s * direction, A's at the origin.
        auto at = [&](double s) {
            Pose p = pb;
            p.translation = s * direction - pb.rotation * b.center;
            return p;
        };
        auto meets = [&](double s) {
            return query.run(modelA, pa, modelB, at(s), yesNo).intersecting;
        };
        // Scan inwards for the first intersecting distance, then bisect the transition.
        double free = sMax, inside = -1;
        for (int k = 1; k <= 48; ++k) {
            const double s = sMax * (1.0 - k / 48.0);
            if (meets(s)) {
                inside = s;
                break;
            }
            free = s;
        }
        if (inside < 0) {
            continue;
        }
        for (int k = 0; k < 44; ++k) {
            const double s = 0.5 * (inside + free);
            (meets(s) ? inside : free) = s;
        }
        double s = 0;
        switch (kind) {
            case PoseClass::kDeep:
                s = (0.3 + 0.5 * unit(rng)) * inside;
                break;
            case PoseClass::kShallow:
                s = std::max(0.0, inside - (1e-3 + 9e-3 * unit(rng)) * r);
                break;
            case PoseClass::kNear:
                s = free + (0.002 + 0.018 * unit(rng)) * r;
                break;
            case PoseClass::kApart: {
                // World AABBs (of the vertices, as Bullet's broadphase sees them) overlap for
                // s in an interval; its upper end per axis is (hiA - loB) / d (d > 0).
                Vec3 loA = Vec3::Constant(1e300), hiA = -loA, loB = loA, hiB = -loA;
                for (const Vec3& v : a.mesh->vertices()) {
                    const Vec3 w = pa.rotation * v + pa.translation;
                    loA = loA.cwiseMin(w);
                    hiA = hiA.cwiseMax(w);
                }
                const Pose b0 = at(0.0);
                for (const Vec3& v : b.mesh->vertices()) {
                    const Vec3 w = b0.rotation * v + b0.translation;
                    loB = loB.cwiseMin(w);
                    hiB = hiB.cwiseMax(w);
                }
                double boxInside = 1e300;
                for (int k = 0; k < 3; ++k) {
                    if (direction[k] > 0) {
                        boxInside = std::min(boxInside, (hiA[k] - loB[k]) / direction[k]);
                    } else if (direction[k] < 0) {
                        boxInside = std::min(boxInside, (loA[k] - hiB[k]) / direction[k]);
                    }
                }
                const double lower = free + 0.02 * r;
                if (boxInside <= lower) {
                    continue;
                }
                s = lower + (boxInside - lower) * unit(rng);
                break;
            }
            case PoseClass::kApartObb: {
                // The root boxes overlap on an interval of s (convex sets on a line).
                double boxInside = free, boxFree = 4 * sMax;
                for (int k = 0; k < 44; ++k) {
                    const double m = 0.5 * (boxInside + boxFree);
                    const bool overlaps =
                        narrowphase::overlap(rootA, rootB, RelativePose(pa, at(m)));
                    (overlaps ? boxInside : boxFree) = m;
                }
                const double lower = free + 0.02 * r;
                if (boxInside <= lower) {
                    continue;  // this direction has no apart-but-boxes-overlap range
                }
                s = lower + (boxInside - lower) * unit(rng);
                break;
            }
            default:
                break;
        }
        out.push_back({kind, pa, at(s)});
    }
    return out;
}

}  // namespace kolize::workload
